/* PNG into memory through libpng's simplified API (png_image_write_to_memory): asked once for the size, then
 * written into a buffer of that size. */
#include "png_encode.h"
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ms_png_encode(const uint8_t *px, int w, int h, int channels, const char *what, unsigned char **out, size_t *len,
                  char *err, size_t errlen)
{
    static const png_uint_32 formats[5] = { 0, PNG_FORMAT_GRAY, PNG_FORMAT_GA, PNG_FORMAT_RGB, PNG_FORMAT_RGBA };
    *out = NULL;
    *len = 0;
    if (w < 1 || h < 1 || channels < 1 || channels > 4) {
        snprintf(err, errlen, "%s: cannot encode a %dx%d image of %d channels", what, w, h, channels);
        return -1;
    }
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = (png_uint_32)w;
    img.height = (png_uint_32)h;
    img.format = formats[channels];
    png_alloc_size_t n = 0;
    if (!png_image_write_to_memory(&img, NULL, &n, 0, px, 0, NULL) || n == 0) {
        snprintf(err, errlen, "%s: PNG encoding failed: %s", what, img.message);
        png_image_free(&img);
        return -1;
    }
    unsigned char *buf = malloc(n);
    if (!buf) { snprintf(err, errlen, "%s: out of memory for a %zu-byte PNG", what, (size_t)n); return -1; }
    if (!png_image_write_to_memory(&img, buf, &n, 0, px, 0, NULL)) {
        snprintf(err, errlen, "%s: PNG encoding failed: %s", what, img.message);
        png_image_free(&img);
        free(buf);
        return -1;
    }
    png_image_free(&img);
    *out = buf;
    *len = (size_t)n;
    return 0;
}
