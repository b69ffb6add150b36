/* Base-colour textures: PNG through libpng's simplified API into RGBA8, with the size checked against
 * the limits before any pixel memory is allocated. JPEG is refused (one line): PNG is the one decoder
 * microshadow links. */
#include "scene_internal.h"
#include "microshadow.h"
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

long ms_soup_add_texture_memory(ms_tri_soup *soup, const unsigned char *buf, size_t len, const char *what,
                                int flip_rows, char *err, size_t errlen)
{
    if (len >= 3 && buf[0] == 0xFF && buf[1] == 0xD8 && buf[2] == 0xFF) {
        snprintf(err, errlen, "%s: JPEG textures are not supported (use PNG)", what);
        return -1;
    }
    if (len < 8 || png_sig_cmp(buf, 0, 8)) { snprintf(err, errlen, "%s: not a PNG image", what); return -1; }
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&img, buf, len)) {
        snprintf(err, errlen, "%s: bad PNG: %s", what, img.message);
        return -1;
    }
    if (img.width == 0 || img.height == 0 || img.width > MS_MAX_TEXTURE_SIDE || img.height > MS_MAX_TEXTURE_SIDE) {
        snprintf(err, errlen, "%s: a %ux%u texture (at most %d a side)", what, img.width, img.height, MS_MAX_TEXTURE_SIDE);
        png_image_free(&img);
        return -1;
    }
    const size_t bytes = (size_t)img.width * img.height * 4;
    if (bytes > MS_MAX_TEXTURE_BYTES - soup->tex_bytes) {
        snprintf(err, errlen, "%s: the scene's textures exceed %zu MiB decoded", what, MS_MAX_TEXTURE_BYTES >> 20);
        png_image_free(&img);
        return -1;
    }
    img.format = PNG_FORMAT_RGBA;   /* colour stays sRGB-encoded: shade.c converts at lookup */
    uint8_t *px = malloc(bytes);
    ms_texture *t = px ? realloc(soup->tex, (soup->n_tex + 1) * sizeof *t) : NULL;
    if (!t) {
        free(px);
        png_image_free(&img);
        snprintf(err, errlen, "%s: out of memory for a %ux%u texture", what, img.width, img.height);
        return -1;
    }
    soup->tex = t;
    /* A negative row stride makes libpng write the rows bottom-up. */
    const png_int_32 stride = (png_int_32)(4 * img.width);
    if (!png_image_finish_read(&img, NULL, px, flip_rows ? -stride : stride, NULL)) {
        snprintf(err, errlen, "%s: bad PNG: %s", what, img.message);
        free(px);
        png_image_free(&img);
        return -1;
    }
    t[soup->n_tex].width = (int)img.width;
    t[soup->n_tex].height = (int)img.height;
    t[soup->n_tex].rgba = px;
    soup->tex_bytes += bytes;
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
