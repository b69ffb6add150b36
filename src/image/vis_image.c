/* The float images of V and S: PFM (written here: a header and raw floats, rows bottom to top as the
 * format requires) or OpenEXR (through OpenEXRCore, one FLOAT channel "V" resp. "S", ZIP compressed). */
#include "microshadow.h"
#include "atomic_file.h"
#include <openexr.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

static int write_pfm(const ms_frame *f, const float *data, const char *path, char *err, size_t errlen)
{
    ms_atomic_file a;
    if (ms_atomic_open(&a, path, err, errlen)) return -1;
    /* Negative scale: little-endian floats. */
    fprintf(a.f, "Pf\n%d %d\n-1.0\n", f->width, f->height);
    for (int y = f->height - 1; y >= 0; y--) {
        const float *row = data + (size_t)y * f->width;
        for (int x = 0; x < f->width; x++) {
            float v = row[x];
            unsigned char b[4];
            uint32_t u;
            memcpy(&u, &v, 4);
            b[0] = (unsigned char)u; b[1] = (unsigned char)(u >> 8); b[2] = (unsigned char)(u >> 16); b[3] = (unsigned char)(u >> 24);
            fwrite(b, 1, 4, a.f);
        }
    }
    return ms_atomic_commit(&a, err, errlen);
}

static int write_exr(const ms_frame *f, const float *data, const char *channel, const char *path, char *err,
                     size_t errlen)
{
    ms_atomic_file a;
    if (ms_atomic_open(&a, path, err, errlen)) return -1;
    /* OpenEXRCore writes by file name: write over the temporary we own, then rename it. */
    fclose(a.f);
    a.f = NULL;
    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_result_t r = exr_start_write(&ctx, a.tmp, EXR_WRITE_FILE_DIRECTLY, &init);
    int part = 0;
    exr_encode_pipeline_t enc;
    int enc_init = 0;
    if (r == EXR_ERR_SUCCESS) r = exr_add_part(ctx, "vis", EXR_STORAGE_SCANLINE, &part);
    if (r == EXR_ERR_SUCCESS) r = exr_initialize_required_attr_simple(ctx, part, f->width, f->height, EXR_COMPRESSION_ZIP);
    if (r == EXR_ERR_SUCCESS) r = exr_add_channel(ctx, part, channel, EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1);
    if (r == EXR_ERR_SUCCESS) r = exr_write_header(ctx);
    int lines = 1;
    if (r == EXR_ERR_SUCCESS) r = exr_get_scanlines_per_chunk(ctx, part, &lines);
    for (int y = 0; r == EXR_ERR_SUCCESS && y < f->height; y += lines) {
        exr_chunk_info_t ci;
        r = exr_write_scanline_chunk_info(ctx, part, y, &ci);
        if (r != EXR_ERR_SUCCESS) break;
        r = enc_init ? exr_encoding_update(ctx, part, &ci, &enc) : exr_encoding_initialize(ctx, part, &ci, &enc);
        if (r != EXR_ERR_SUCCESS) break;
        enc.channels[0].encode_from_ptr = (const uint8_t *)(data + (size_t)y * f->width);
        enc.channels[0].user_pixel_stride = (int32_t)sizeof(float);
        enc.channels[0].user_line_stride = (int32_t)(sizeof(float) * (size_t)f->width);
        if (!enc_init) {
            r = exr_encoding_choose_default_routines(ctx, part, &enc);
            enc_init = 1;
            if (r != EXR_ERR_SUCCESS) break;
        }
        r = exr_encoding_run(ctx, part, &enc);
    }
    if (enc_init) exr_encoding_destroy(ctx, &enc);
    exr_result_t fin = ctx ? exr_finish(&ctx) : EXR_ERR_SUCCESS;
    if (r == EXR_ERR_SUCCESS) r = fin;
    if (r != EXR_ERR_SUCCESS) {
        snprintf(err, errlen, "%s: EXR write failed: %s", path, exr_get_default_error_message(r));
        ms_atomic_abort(&a);
        return -1;
    }
    if (rename(a.tmp, path) != 0) {
        snprintf(err, errlen, "%s: cannot rename into place", path);
        ms_atomic_abort(&a);
        return -1;
    }
    return 0;
}

static int write_float_image(const ms_frame *f, const float *data, const char *channel, const char *what,
                             const char *path, char *err, size_t errlen)
{
    if (ends_with(path, ".pfm")) return write_pfm(f, data, path, err, errlen);
    if (ends_with(path, ".exr")) return write_exr(f, data, channel, path, err, errlen);
    snprintf(err, errlen, "%s: the %s image must end in .pfm or .exr", path, what);
    return -1;
}

int ms_write_vis(const ms_frame *f, const char *path, char *err, size_t errlen)
{
    return write_float_image(f, f->vis, "V", "visibility", path, err, errlen);
}

int ms_write_shadow(const ms_frame *f, const char *path, char *err, size_t errlen)
{
    return write_float_image(f, f->shadow, "S", "shadow factor", path, err, errlen);
}
