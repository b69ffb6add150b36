/* PNG decoding for light textures (png_read.h), through libpng's simplified API. */
#include "png_read.h"
#include <png.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ms_png_decode_linear(const char *name, const void *bytes, size_t len, int max_side, float **rgb, int *w, int *h,
                         char *err, size_t errlen)
{
    *rgb = NULL;
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&img, bytes, len)) {
        snprintf(err, errlen, "%s: not a readable PNG image (%s)", name, img.message);
        return -1;
    }
    if (img.width < 1 || img.height < 1 || img.width > (png_uint_32)max_side || img.height > (png_uint_32)max_side) {
        snprintf(err, errlen, "%s: the image is %ux%u; a light texture is at most %dx%d", name, (unsigned)img.width,
                 (unsigned)img.height, max_side, max_side);
        png_image_free(&img);
        return -1;
    }
    img.format = PNG_FORMAT_LINEAR_RGB;   /* 16-bit linear: libpng undoes the sRGB curve */
    const size_t n = (size_t)img.width * img.height;
    uint16_t *px = malloc(n * 3 * sizeof *px);
    float *out = malloc(n * 3 * sizeof *out);
    if (!px || !out) {
        snprintf(err, errlen, "%s: out of memory for a %ux%u texture", name, (unsigned)img.width, (unsigned)img.height);
        png_image_free(&img);
        free(px);
        free(out);
        return -1;
    }
    if (!png_image_finish_read(&img, NULL, px, 0, NULL)) {
        snprintf(err, errlen, "%s: PNG decoding failed (%s)", name, img.message);
        png_image_free(&img);
        free(px);
        free(out);
        return -1;
    }
    for (size_t i = 0; i < 3 * n; i++) out[i] = (float)px[i] * (1.0f / 65535.0f);
    free(px);
    *rgb = out;
    *w = (int)img.width;
    *h = (int)img.height;
    return 0;
}
