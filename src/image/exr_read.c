/* EXR decoding for light textures (exr_read.h), through OpenEXRCore (the C API the writers use) reading
 * from memory: the scene loader has the file's bytes already (bounded by its size limit), so a hostile
 * file cannot make OpenEXR read elsewhere, and OpenEXR's own size limits are set to ours so that its
 * header checks refuse huge windows before anything is allocated for them. */
#include "exr_read.h"
#include "microshadow.h"
#include <math.h>
#include <openexr.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_CHANNELS 16   /* a chunk's buffers grow with the channels, decoded or not */

int ms_is_exr(const void *bytes, size_t len)
{
    static const unsigned char magic[4] = { 0x76, 0x2f, 0x31, 0x01 };
    return len >= 4 && memcmp(bytes, magic, 4) == 0;
}

typedef struct exr_mem { const unsigned char *p; size_t n; } exr_mem;

static int64_t mem_read(exr_const_context_t ctx, void *user, void *buf, uint64_t sz, uint64_t off,
                        exr_stream_error_func_ptr_t error_cb)
{
    (void)ctx; (void)error_cb;
    const exr_mem *m = user;
    if (off >= m->n) return 0;
    const uint64_t k = sz < m->n - off ? sz : m->n - off;
    memcpy(buf, m->p + off, (size_t)k);
    return (int64_t)k;
}

static int64_t mem_size(exr_const_context_t ctx, void *user)
{
    (void)ctx;
    return (int64_t)((const exr_mem *)user)->n;
}

/* OpenEXR's messages would go to stderr; ours is the one line. */
static void quiet(exr_const_context_t ctx, exr_result_t code, const char *msg) { (void)ctx; (void)code; (void)msg; }

int ms_exr_decode_linear(const char *name, const void *bytes, size_t len, int max_side, float **rgb, int *w, int *h,
                         char *err, size_t errlen)
{
    *rgb = NULL;
    exr_mem mem = { bytes, len };
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.user_data = &mem;
    init.read_fn = mem_read;
    init.size_fn = mem_size;
    init.error_handler_fn = quiet;
    init.max_image_width = init.max_image_height = max_side;
    init.max_tile_width = init.max_tile_height = max_side;
    exr_context_t ctx = NULL;
    exr_result_t r = exr_start_read(&ctx, name, &init);
    if (r != EXR_ERR_SUCCESS) {
        snprintf(err, errlen, "%s: not a readable EXR image (%s)", name, exr_get_default_error_message(r));
        if (ctx) exr_finish(&ctx);
        return -1;
    }
    float *out = NULL;
    int rc = -1;
    exr_storage_t storage;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *chl = NULL;
    if (exr_get_storage(ctx, 0, &storage) != EXR_ERR_SUCCESS || exr_get_data_window(ctx, 0, &dw) != EXR_ERR_SUCCESS ||
        exr_get_channels(ctx, 0, &chl) != EXR_ERR_SUCCESS || !chl) {
        snprintf(err, errlen, "%s: EXR header without a data window or channels", name);
        goto done;
    }
    if (storage != EXR_STORAGE_SCANLINE) {
        snprintf(err, errlen, "%s: %s EXR images are not supported (scanline images are)", name,
                 storage == EXR_STORAGE_TILED ? "tiled" : "deep");
        goto done;
    }
    const int64_t W = (int64_t)dw.max.x - dw.min.x + 1, H = (int64_t)dw.max.y - dw.min.y + 1;
    if (W < 1 || H < 1 || W > max_side || H > max_side) {
        snprintf(err, errlen, "%s: the image is %lldx%lld; a light texture is at most %dx%d", name, (long long)W,
                 (long long)H, max_side, max_side);
        goto done;
    }
    if (chl->num_channels > MAX_CHANNELS) {
        snprintf(err, errlen, "%s: %d channels (at most %d)", name, chl->num_channels, MAX_CHANNELS);
        goto done;
    }
    int want[3] = { -1, -1, -1 }, grey = -1;   /* R, G, B; Y */
    for (int c = 0; c < chl->num_channels; c++) {
        const exr_attr_chlist_entry_t *e = &chl->entries[c];
        if (e->x_sampling != 1 || e->y_sampling != 1) {
            char cn[33];   /* the file's name for it, made printable: the message is one line */
            snprintf(cn, sizeof cn, "%s", e->name.str ? e->name.str : "");
            for (char *q = cn; *q; q++)
                if ((unsigned char)*q < 0x20 || *q == 0x7f) *q = '?';
            snprintf(err, errlen, "%s: channel '%s' is subsampled (not supported)", name, cn);
            goto done;
        }
        if (!strcmp(e->name.str, "R")) want[0] = c;
        else if (!strcmp(e->name.str, "G")) want[1] = c;
        else if (!strcmp(e->name.str, "B")) want[2] = c;
        else if (!strcmp(e->name.str, "Y")) grey = c;
    }
    if (want[0] < 0 || want[1] < 0 || want[2] < 0) {
        if (grey < 0) { snprintf(err, errlen, "%s: no R, G and B (or Y) channels", name); goto done; }
        want[0] = want[1] = want[2] = -1;
    }
    int lines = 0;
    if (exr_get_scanlines_per_chunk(ctx, 0, &lines) != EXR_ERR_SUCCESS || lines < 1) {
        snprintf(err, errlen, "%s: EXR without a scanline chunk size", name);
        goto done;
    }
    out = calloc((size_t)W * (size_t)H * 3, sizeof *out);
    if (!out) { snprintf(err, errlen, "%s: out of memory for a %lldx%lld texture", name, (long long)W, (long long)H); goto done; }
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    int dec_init = 0;
    r = EXR_ERR_SUCCESS;
    for (int64_t y = dw.min.y; y <= dw.max.y && r == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t ci;
        r = exr_read_scanline_chunk_info(ctx, 0, (int)y, &ci);
        if (r != EXR_ERR_SUCCESS) break;
        r = dec_init ? exr_decoding_update(ctx, 0, &ci, &dec) : exr_decoding_initialize(ctx, 0, &ci, &dec);
        if (r != EXR_ERR_SUCCESS) break;
        const int64_t row0 = (int64_t)ci.start_y - dw.min.y;
        if (row0 < 0 || row0 + ci.height > H) { r = EXR_ERR_CORRUPT_CHUNK; break; }
        for (int c = 0; c < dec.channel_count; c++) dec.channels[c].decode_to_ptr = NULL;   /* skip the others */
        for (int k = 0; k < 3; k++) {
            const int c = want[k] >= 0 ? want[k] : grey;
            if (k > 0 && c == grey) continue;   /* Y decoded once, into R; copied to G, B below */
            dec.channels[c].decode_to_ptr = (uint8_t *)(out + (size_t)row0 * (size_t)W * 3 + k);
            dec.channels[c].user_pixel_stride = 3 * sizeof(float);
            dec.channels[c].user_line_stride = (int32_t)(3 * sizeof(float) * (size_t)W);
            dec.channels[c].user_bytes_per_element = sizeof(float);
            dec.channels[c].user_data_type = EXR_PIXEL_FLOAT;
        }
        if (!dec_init) {
            r = exr_decoding_choose_default_routines(ctx, 0, &dec);
            dec_init = 1;
            if (r != EXR_ERR_SUCCESS) break;
        }
        r = exr_decoding_run(ctx, 0, &dec);
    }
    if (dec_init) exr_decoding_destroy(ctx, &dec);
    if (r != EXR_ERR_SUCCESS) {
        snprintf(err, errlen, "%s: EXR decoding failed (%s)", name, exr_get_default_error_message(r));
        goto done;
    }
    const size_t n = (size_t)W * (size_t)H;
    for (size_t i = 0; i < n; i++) {
        if (want[0] < 0) out[3 * i + 1] = out[3 * i + 2] = out[3 * i];
        for (int k = 0; k < 3; k++)
            if (!(out[3 * i + k] >= 0.0f) || !isfinite(out[3 * i + k])) {
                snprintf(err, errlen, "%s: texel (%zu, %zu) is negative, NaN or infinite (%g)", name, i % (size_t)W,
                         i / (size_t)W, (double)out[3 * i + k]);
                goto done;
            } else if (out[3 * i + k] > MS_MAX_LIGHT_TEXEL) {
                /* beyond it, emission sums could overflow float (microshadow.h: MS_MAX_LIGHT_TEXEL) */
                snprintf(err, errlen, "%s: texel (%zu, %zu) is %g, above the limit of %g for a light texture (scale the "
                         "light's emission instead)", name, i % (size_t)W, i / (size_t)W, (double)out[3 * i + k],
                         (double)MS_MAX_LIGHT_TEXEL);
                goto done;
            }
    }
    *rgb = out;
    out = NULL;
    *w = (int)W;
    *h = (int)H;
    rc = 0;
done:
    free(out);
    exr_finish(&ctx);
    return rc;
}
