/* Tone-mapped sRGB PNG through libpng's simplified API. */
#include "microshadow.h"
#include "microshadow.h"
#include <errno.h>
#include <math.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>

static unsigned char to_srgb8(float x)
{
    if (!(x > 0.0f)) return 0;
    if (x >= 1.0f) return 255;
    float s = x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
    return (unsigned char)lrintf(s * 255.0f);
}

int ms_png_write_stream(const ms_frame *f, FILE *out, const char *path, char *err, size_t errlen)
{
    size_t n = (size_t)f->width * f->height;
    unsigned char *px = malloc(3 * n);
    if (!px) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
    /* Misses show a dark background; lit surfaces are exposed so the 99th percentile of unshadowed
     * radiance is white, then clipped (no curve: shadows keep their linear falloff). */
    for (size_t i = 0; i < n; i++) {
        if (f->vis[i] < 0.0f) { px[3 * i] = 28; px[3 * i + 1] = 30; px[3 * i + 2] = 38; continue; }
        for (int c = 0; c < 3; c++) px[3 * i + c] = to_srgb8(f->rgb[3 * i + c] * f->exposure);
    }
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = (png_uint_32)f->width;
    img.height = (png_uint_32)f->height;
    img.format = PNG_FORMAT_RGB;
    errno = 0;
    int ok = png_image_write_to_stdio(&img, out, 0, px, 0, NULL);
    free(px);
    if (!ok && ferror(out)) snprintf(err, errlen, "%s: write failed: %s", path, strerror(errno ? errno : EIO));
    else if (!ok) snprintf(err, errlen, "%s: PNG write failed: %s", path, img.message);
    png_image_free(&img);
    return ok ? 0 : -1;
}
