/* The float images of V and S: PFM (written here: a header and raw floats, rows bottom to top as the
 * format requires) or OpenEXR (through OpenEXRCore, one FLOAT channel "V" resp. "S", ZIP compressed);
 * and the whole frame or lightmap as one EXR (R, G, B, S, V; with several lights S0, S1, ..., V0, V1, ...). */
#include "microshadow.h"
#include "microshadow.h"
#include <errno.h>
#include <openexr.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

const char *const ms_float_image_suffixes[] = { ".pfm", ".exr", NULL };

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

static int write_pfm(const ms_frame *f, const float *data, FILE *out)
{
    /* Negative scale: little-endian floats. */
    fprintf(out, "Pf\n%d %d\n-1.0\n", f->width, f->height);
    for (int y = f->height - 1; y >= 0; y--) {
        const float *row = data + (size_t)y * f->width;
        for (int x = 0; x < f->width; x++) {
            float v = row[x];
            unsigned char b[4];
            uint32_t u;
            memcpy(&u, &v, 4);
            b[0] = (unsigned char)u; b[1] = (unsigned char)(u >> 8); b[2] = (unsigned char)(u >> 16); b[3] = (unsigned char)(u >> 24);
            fwrite(b, 1, 4, out);
        }
    }
    return 0;   /* write errors surface at the flush */
}

/* OpenEXRCore writes through our callback into the staging file's descriptor, and its errors come
 * back to us instead of being printed (they would name the staging file). */
typedef struct exr_sink { int fd; int saved_errno; } exr_sink;

static int64_t exr_sink_write(exr_const_context_t ctx, void *user, const void *buf, uint64_t sz, uint64_t offset,
                              exr_stream_error_func_ptr_t error_cb)
{
    (void)ctx; (void)error_cb;
    exr_sink *s = user;
    const char *p = buf;
    uint64_t done = 0;
    while (done < sz) {
        ssize_t w = pwrite(s->fd, p + done, (size_t)(sz - done), (off_t)(offset + done));
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) { s->saved_errno = w < 0 ? errno : EIO; return -1; }
        done += (uint64_t)w;
    }
    return (int64_t)done;
}

static void exr_quiet(exr_const_context_t ctx, exr_result_t code, const char *msg) { (void)ctx; (void)code; (void)msg; }

/* One channel of an EXR: its name, its first pixel and the floats from one pixel to the next. */
typedef struct exr_channel { const char *name; const float *data; int stride; } exr_channel;

/* Channels must come in the file's order: sorted by name (OpenEXR keeps channel lists sorted). */
static int write_exr(const ms_frame *f, const exr_channel *ch, int nch, FILE *out, const char *path,
                     char *err, size_t errlen)
{
    exr_sink sink = { fileno(out), 0 };
    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.user_data = &sink;
    init.write_fn = exr_sink_write;
    init.error_handler_fn = exr_quiet;
    exr_result_t r = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    int part = 0;
    exr_encode_pipeline_t enc;
    int enc_init = 0;
    if (r == EXR_ERR_SUCCESS) r = exr_add_part(ctx, nch == 1 ? ch[0].name : "rgb", EXR_STORAGE_SCANLINE, &part);
    if (r == EXR_ERR_SUCCESS) r = exr_initialize_required_attr_simple(ctx, part, f->width, f->height, EXR_COMPRESSION_ZIP);
    for (int c = 0; c < nch && r == EXR_ERR_SUCCESS; c++)
        r = exr_add_channel(ctx, part, ch[c].name, EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1);
    if (r == EXR_ERR_SUCCESS) r = exr_write_header(ctx);
    int lines = 1;
    if (r == EXR_ERR_SUCCESS) r = exr_get_scanlines_per_chunk(ctx, part, &lines);
    for (int y = 0; r == EXR_ERR_SUCCESS && y < f->height; y += lines) {
        exr_chunk_info_t ci;
        r = exr_write_scanline_chunk_info(ctx, part, y, &ci);
        if (r != EXR_ERR_SUCCESS) break;
        r = enc_init ? exr_encoding_update(ctx, part, &ci, &enc) : exr_encoding_initialize(ctx, part, &ci, &enc);
        if (r != EXR_ERR_SUCCESS) break;
        for (int c = 0; c < nch; c++) {
            enc.channels[c].encode_from_ptr = (const uint8_t *)(ch[c].data + (size_t)y * f->width * ch[c].stride);
            enc.channels[c].user_pixel_stride = (int32_t)(sizeof(float) * (size_t)ch[c].stride);
            enc.channels[c].user_line_stride = (int32_t)(sizeof(float) * (size_t)f->width * ch[c].stride);
        }
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
        if (sink.saved_errno) snprintf(err, errlen, "%s: write failed: %s", path, strerror(sink.saved_errno));
        else snprintf(err, errlen, "%s: EXR write failed: %s", path, exr_get_default_error_message(r));
        return -1;
    }
    return 0;
}

static int write_float_image(const ms_frame *f, const float *data, const char *channel, const char *what, FILE *out,
                             const char *path, char *err, size_t errlen)
{
    if (ends_with(path, ".pfm")) return write_pfm(f, data, out);
    if (ends_with(path, ".exr")) {
        const exr_channel ch = { channel, data, 1 };
        return write_exr(f, &ch, 1, out, path, err, errlen);
    }
    snprintf(err, errlen, "%s: the %s image must end in .pfm or .exr", path, what);
    return -1;
}

#define MAX_LIGHT_CHANNELS 64

/* Several lights: an EXR gets one channel per light (V0, V1, ... in light order), a PFM light 0. */
static int write_per_light(const ms_frame *f, const float *data, const char *channel, const char *what, FILE *out,
                           const char *path, char *err, size_t errlen)
{
    const int nl = f->n_lights > 1 ? f->n_lights : 1;
    if (nl == 1 || !ends_with(path, ".exr")) return write_float_image(f, data, channel, what, out, path, err, errlen);
    if (nl > MAX_LIGHT_CHANNELS) { snprintf(err, errlen, "%s: more than %d lights for one EXR", path, MAX_LIGHT_CHANNELS); return -1; }
    char names[MAX_LIGHT_CHANNELS][8];
    exr_channel ch[MAX_LIGHT_CHANNELS];
    const size_t npix = (size_t)f->width * (size_t)f->height;
    /* OpenEXR stores channels sorted by name: "V10" before "V2"; readers find them by name. */
    for (int l = 0; l < nl; l++) {
        snprintf(names[l], sizeof names[l], "%s%d", channel, l);
        ch[l] = (exr_channel){ names[l], data + (size_t)l * npix, 1 };
    }
    for (int a = 1; a < nl; a++)
        for (int b = a; b > 0 && strcmp(ch[b - 1].name, ch[b].name) > 0; b--) {
            const exr_channel t = ch[b]; ch[b] = ch[b - 1]; ch[b - 1] = t;
        }
    return write_exr(f, ch, nl, out, path, err, errlen);
}

int ms_vis_write_stream(const ms_frame *f, FILE *out, const char *path, char *err, size_t errlen)
{
    return write_per_light(f, f->vis, "V", "visibility", out, path, err, errlen);
}

int ms_shadow_write_stream(const ms_frame *f, FILE *out, const char *path, char *err, size_t errlen)
{
    return write_per_light(f, f->shadow, "S", "shadow factor", out, path, err, errlen);
}

int ms_exr_write_stream(const ms_frame *f, FILE *out, const char *path, char *err, size_t errlen)
{
    if (!ends_with(path, ".exr")) { snprintf(err, errlen, "%s: the RGB image must end in .exr", path); return -1; }
    const int nl = f->n_lights > 1 ? f->n_lights : 1;
    if (nl == 1) {
        const exr_channel ch[5] = { { "B", f->rgb + 2, 3 }, { "G", f->rgb + 1, 3 }, { "R", f->rgb, 3 },
                                    { "S", f->shadow, 1 }, { "V", f->vis, 1 } };
        return write_exr(f, ch, 5, out, path, err, errlen);
    }
    /* Several lights: R, G, B (their sum) and every light's S and V as in --shadow/--vis: S0, S1, ..., V0, ... */
    if (nl > MAX_LIGHT_CHANNELS) { snprintf(err, errlen, "%s: more than %d lights for one EXR", path, MAX_LIGHT_CHANNELS); return -1; }
    char names[2][MAX_LIGHT_CHANNELS][12];
    exr_channel ch[3 + 2 * MAX_LIGHT_CHANNELS] = { { "B", f->rgb + 2, 3 }, { "G", f->rgb + 1, 3 }, { "R", f->rgb, 3 } };
    const size_t npix = (size_t)f->width * (size_t)f->height;
    int n = 3;
    for (int which = 0; which < 2; which++) {   /* S before V: the file's order is by name */
        const int first = n;
        for (int l = 0; l < nl; l++) {
            snprintf(names[which][l], sizeof names[which][l], "%c%d", which ? 'V' : 'S', l);
            ch[n++] = (exr_channel){ names[which][l], (which ? f->vis : f->shadow) + (size_t)l * npix, 1 };
        }
        for (int a = first + 1; a < n; a++)
            for (int b = a; b > first && strcmp(ch[b - 1].name, ch[b].name) > 0; b--) {
                const exr_channel t = ch[b]; ch[b] = ch[b - 1]; ch[b - 1] = t;
            }
    }
    return write_exr(f, ch, n, out, path, err, errlen);
}
