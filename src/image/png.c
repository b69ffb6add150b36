/* Tone-mapped sRGB PNG row by row through libpng (image_rows.h): the whole-frame writer is one band of every
 * row, so a streamed frame's PNG equals the in-memory one byte for byte. */
#include "image_rows.h"
#include "png_rows.h"
#include <errno.h>
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>

static unsigned char to_srgb8(float x)
{
    if (!(x > 0.0f)) return 0;
    if (x >= 1.0f) return 255;
    float s = x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
    return (unsigned char)lrintf(s * 255.0f);
}

struct ms_png_rows {
    png_structp png;
    png_infop info;
    FILE *out;
    int W, H, next_y;
    unsigned char *row;   /* one row of 8-bit RGB */
    char message[200];    /* libpng's error, kept for ours */
};

/* libpng reports errors by longjmp; the message is kept for the one line we print. */
static void on_png_error(png_structp png, png_const_charp msg)
{
    ms_png_rows *p = png_get_error_ptr(png);
    snprintf(p->message, sizeof p->message, "%s", msg);
    png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp msg) { (void)png; (void)msg; }

static void png_failed(ms_png_rows *p, const char *path, char *err, size_t errlen)
{
    if (ferror(p->out)) snprintf(err, errlen, "%s: write failed: %s", path, strerror(errno ? errno : EIO));
    else snprintf(err, errlen, "%s: PNG write failed: %s", path, p->message);
}

static void png_release(ms_png_rows *p)
{
    png_destroy_write_struct(&p->png, &p->info);
    free(p->row);
    free(p);
}

/* The calls that may longjmp, each in a function of its own (nothing of the caller's is live across them). */
static int png_header(ms_png_rows *p)
{
    if (setjmp(png_jmpbuf(p->png))) return -1;
    errno = 0;
    png_init_io(p->png, p->out);
    png_set_IHDR(p->png, p->info, (png_uint_32)p->W, (png_uint_32)p->H, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(p->png, p->info, PNG_sRGB_INTENT_PERCEPTUAL);   /* as libpng's simplified API wrote it */
    png_write_info(p->png, p->info);
    return 0;
}

static int png_trailer(ms_png_rows *p)
{
    if (setjmp(png_jmpbuf(p->png))) return -1;
    errno = 0;
    png_write_end(p->png, p->info);
    return 0;
}

ms_png_rows *ms_png_rows_begin(int W, int H, FILE *out, const char *path, char *err, size_t errlen)
{
    ms_png_rows *p = calloc(1, sizeof *p);
    if (p) p->row = malloc(3 * (size_t)W);
    if (!p || !p->row) { if (p) free(p); snprintf(err, errlen, "%s: out of memory", path); return NULL; }
    p->out = out;
    p->W = W;
    p->H = H;
    p->png = png_create_write_struct(PNG_LIBPNG_VER_STRING, p, on_png_error, on_png_warning);
    if (p->png) p->info = png_create_info_struct(p->png);
    if (!p->png || !p->info) { snprintf(err, errlen, "%s: out of memory", path); png_release(p); return NULL; }
    if (png_header(p)) { png_failed(p, path, err, errlen); png_release(p); return NULL; }
    return p;
}

int ms_png_rows_write(ms_png_rows *p, const ms_frame *band, const char *path, char *err, size_t errlen)
{
    if (setjmp(png_jmpbuf(p->png))) { png_failed(p, path, err, errlen); return -1; }
    errno = 0;
    /* Misses show a dark background; lit surfaces are exposed so the 99th percentile of unshadowed
     * radiance is white, then clipped (no curve: shadows keep their linear falloff). */
    for (int y = 0; y < band->height; y++) {
        const size_t base = (size_t)y * (size_t)p->W;
        for (int x = 0; x < p->W; x++) {
            unsigned char *o = p->row + 3 * (size_t)x;
            const size_t i = base + (size_t)x;
            if (band->vis[i] < 0.0f) { o[0] = 28; o[1] = 30; o[2] = 38; continue; }
            for (int c = 0; c < 3; c++) o[c] = to_srgb8(band->rgb[3 * i + c] * band->exposure);
        }
        png_write_row(p->png, p->row);
    }
    p->next_y += band->height;
    return 0;
}

int ms_png_rows_end(ms_png_rows *p, int ok, const char *path, char *err, size_t errlen)
{
    int rc = 0;
    if (ok && p->next_y != p->H) {
        snprintf(err, errlen, "%s: %d of %d rows written", path, p->next_y, p->H);
        rc = -1;
    } else if (ok && png_trailer(p)) {
        png_failed(p, path, err, errlen);
        rc = -1;
    }
    png_release(p);
    return rc;
}

ms_status ms_png_write_stream(const ms_frame *f, FILE *out, const char *path, char *err, size_t errlen)
{
    ms_png_rows *p = ms_png_rows_begin(f->width, f->height, out, path, err, errlen);
    if (!p) return MS_ERR_IO;
    const int rc = ms_png_rows_write(p, f, path, err, errlen);
    return ms_png_rows_end(p, rc == 0, path, err, errlen) || rc ? MS_ERR_IO : MS_OK;
}
