/* Material textures into RGBA8, told apart by content: PNG (libpng's simplified API: 8- and 16-bit,
 * paletted, grey), JPEG (libjpeg-turbo's TurboJPEG API, which reports errors and never exits), WebP
 * (libwebp: lossy and lossless, with or without alpha; glTF's EXT_texture_webp) and KTX2 (texture_ktx2.c).
 * The size is checked against the limits from the header before any pixel memory is allocated. */
#include "scene_internal.h"
#include "microshadow.h"
#include <png.h>
#include <turbojpeg.h>
#include <webp/decode.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ms_texture_size_ok(unsigned w, unsigned h, size_t budget, const char *what, char *err, size_t errlen)
{
    if (w == 0 || h == 0 || w > MS_MAX_TEXTURE_SIDE || h > MS_MAX_TEXTURE_SIDE) {
        snprintf(err, errlen, "%s: a %ux%u texture (at most %d a side)", what, w, h, MS_MAX_TEXTURE_SIDE);
        return 0;
    }
    if ((size_t)w * h * 4 > budget) {
        snprintf(err, errlen, "%s: the scene's textures exceed %zu MiB decoded", what, MS_MAX_TEXTURE_BYTES >> 20);
        return 0;
    }
    return 1;
}

static int decode_png(const unsigned char *buf, size_t len, const char *what, int flip_rows, size_t budget,
                      ms_texture *out, char *err, size_t errlen)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&img, buf, len)) {
        snprintf(err, errlen, "%s: bad PNG: %s", what, img.message);
        return -1;
    }
    if (!ms_texture_size_ok(img.width, img.height, budget, what, err, errlen)) { png_image_free(&img); return -1; }
    /* Colour stays sRGB-encoded (shade.c converts at lookup). A 16-bit file without gAMA/sRGB chunks is
     * sRGB-encoded too (glTF's textures are), not the linear data libpng assumes by default; it is
     * reduced to 8 bits. Palettes and grey are expanded by libpng. */
    img.format = PNG_FORMAT_RGBA;
    img.flags |= PNG_IMAGE_FLAG_16BIT_sRGB;
    const size_t bytes = (size_t)img.width * img.height * 4;
    uint8_t *px = malloc(bytes);
    if (!px) {
        png_image_free(&img);
        snprintf(err, errlen, "%s: out of memory for a %ux%u texture", what, img.width, img.height);
        return -1;
    }
    /* A negative row stride makes libpng write the rows bottom-up. */
    const png_int_32 stride = (png_int_32)(4 * img.width);
    if (!png_image_finish_read(&img, NULL, px, flip_rows ? -stride : stride, NULL)) {
        snprintf(err, errlen, "%s: bad PNG: %s", what, img.message);
        free(px);
        png_image_free(&img);
        return -1;
    }
    out->width = (int)img.width;
    out->height = (int)img.height;
    out->rgba = px;
    return 0;
}

static int decode_jpeg(const unsigned char *buf, size_t len, const char *what, int flip_rows, size_t budget,
                       ms_texture *out, char *err, size_t errlen)
{
    if (len > (size_t)0xFFFFFFFFu) { snprintf(err, errlen, "%s: a JPEG of more than 4 GiB", what); return -1; }
    tjhandle tj = tjInitDecompress();
    if (!tj) { snprintf(err, errlen, "%s: cannot start the JPEG decoder", what); return -1; }
    int w = 0, h = 0, sub = 0, cs = 0, rc = -1;
    uint8_t *px = NULL;
    if (tjDecompressHeader3(tj, buf, (unsigned long)len, &w, &h, &sub, &cs)) {
        snprintf(err, errlen, "%s: bad JPEG: %s", what, tjGetErrorStr2(tj));
        goto out;
    }
    if (w < 1 || h < 1) { snprintf(err, errlen, "%s: bad JPEG: no frame header (a file cut short?)", what); goto out; }
    if (!ms_texture_size_ok((unsigned)w, (unsigned)h, budget, what, err, errlen)) goto out;
    if (!(px = malloc((size_t)w * (size_t)h * 4))) {
        snprintf(err, errlen, "%s: out of memory for a %dx%d texture", what, w, h);
        goto out;
    }
    /* TJFLAG_LIMITSCANS: a progressive file of more than 500 scans is an error (each scan is a pass over
     * the whole coefficient buffer: a small file could cost minutes). A warning (e.g. a truncated file,
     * whose missing rows libjpeg fills) still gives a whole image: it is used. */
    const int flags = TJFLAG_LIMITSCANS | TJFLAG_ACCURATEDCT | (flip_rows ? TJFLAG_BOTTOMUP : 0);
    if (tjDecompress2(tj, buf, (unsigned long)len, px, w, 4 * w, h, TJPF_RGBA, flags) &&
        tjGetErrorCode(tj) != TJERR_WARNING) {
        snprintf(err, errlen, "%s: bad JPEG: %s", what, tjGetErrorStr2(tj));
        goto out;
    }
    out->width = w;
    out->height = h;
    out->rgba = px;
    px = NULL;
    rc = 0;
out:
    free(px);
    tjDestroy(tj);
    return rc;
}

/* A WebP image (a still one: animated files are refused by the simple decoder) into RGBA8; its rows top first, or
 * reversed with flip_rows. */
static int decode_webp(const unsigned char *buf, size_t len, const char *what, int flip_rows, size_t budget,
                       ms_texture *out, char *err, size_t errlen)
{
    int w = 0, h = 0;
    if (!WebPGetInfo(buf, len, &w, &h)) { snprintf(err, errlen, "%s: not a WebP image libwebp can decode", what); return -1; }
    if (!ms_texture_size_ok((unsigned)w, (unsigned)h, budget, what, err, errlen)) return -1;
    const size_t row = (size_t)w * 4;
    unsigned char *px = malloc(row * (size_t)h);
    if (!px) { snprintf(err, errlen, "%s: out of memory for a %dx%d texture", what, w, h); return -1; }
    if (!WebPDecodeRGBAInto(buf, len, px, row * (size_t)h, (int)row)) {
        free(px);
        snprintf(err, errlen, "%s: corrupt WebP data", what);
        return -1;
    }
    if (flip_rows)
        for (size_t y = 0; y < (size_t)h / 2; y++) {
            unsigned char *a = px + y * row, *b = px + ((size_t)h - 1 - y) * row;
            for (size_t i = 0; i < row; i++) { const unsigned char t = a[i]; a[i] = b[i]; b[i] = t; }
        }
    out->rgba = px;
    out->width = w;
    out->height = h;
    return 0;
}

static const unsigned char ktx2_id[12] = { 0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n' };

int ms_texture_decode(const unsigned char *buf, size_t len, const char *what, int flip_rows, size_t budget,
                      ms_texture *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (len >= 3 && buf[0] == 0xFF && buf[1] == 0xD8 && buf[2] == 0xFF)
        return decode_jpeg(buf, len, what, flip_rows, budget, out, err, errlen);
    if (len >= 12 && !memcmp(buf, ktx2_id, 12)) return ms_texture_decode_ktx2(buf, len, what, flip_rows, budget, out, err, errlen);
    if (len >= 8 && !png_sig_cmp(buf, 0, 8)) return decode_png(buf, len, what, flip_rows, budget, out, err, errlen);
    if (len >= 12 && !memcmp(buf, "RIFF", 4) && !memcmp(buf + 8, "WEBP", 4))
        return decode_webp(buf, len, what, flip_rows, budget, out, err, errlen);
    snprintf(err, errlen, "%s: not a PNG, JPEG, WebP or KTX2 image", what);
    return -1;
}

long ms_soup_add_texture_memory(ms_tri_soup *soup, const unsigned char *buf, size_t len, const char *what,
                                int flip_rows, char *err, size_t errlen)
{
    ms_texture t;
    if (ms_texture_decode(buf, len, what, flip_rows, MS_MAX_TEXTURE_BYTES - soup->tex_bytes, &t, err, errlen)) return -1;
    ms_texture *a = realloc(soup->tex, (soup->n_tex + 1) * sizeof *a);
    if (!a) {
        free(t.rgba);
        snprintf(err, errlen, "%s: out of memory for a %dx%d texture", what, t.width, t.height);
        return -1;
    }
    soup->tex = a;
    a[soup->n_tex] = t;
    soup->tex_bytes += (size_t)t.width * (size_t)t.height * 4;
    return (long)soup->n_tex++;
}

long ms_soup_add_texture_file(ms_tri_soup *soup, const char *path, int flip_rows, char *err, size_t errlen)
{
    char *buf;
    size_t len;
    if (ms_read_input(path, MS_MAX_MESH_BYTES, MS_INPUT_AUX, &buf, &len, err, errlen)) return -1;
    const long r = ms_soup_add_texture_memory(soup, (const unsigned char *)buf, len, path, flip_rows, err, errlen);
    free(buf);
    return r;
}
