/* The float images of V and S: PFM (written here: a header and raw floats, rows bottom to top as the
 * format requires) or OpenEXR (through OpenEXRCore, one FLOAT channel "V" resp. "S", ZIP compressed);
 * and the whole frame or lightmap as one EXR (R, G, B, S, V; with several lights S0, S1, ..., V0, V1, ...).
 * Row by row (image_rows.h): a PFM row goes to its offset from the end, an EXR by its 16-row ZIP blocks; the
 * whole-frame writers are one band of every row. */
#include "image_rows.h"
#include "float_rows.h"
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

#define MAX_LIGHT_CHANNELS 64
#define MAX_CHANNELS (3 + 2 * MAX_LIGHT_CHANNELS)

/* One channel of an EXR: its name, where it lives in a band (which plane: rgb's component c, or light l's V
 * or S) and so its first pixel and the floats from one pixel to the next. */
typedef struct exr_channel { char name[12]; char plane; int index; } exr_channel;

struct ms_float_rows {
    ms_image_kind kind;
    int W, H, nl, pfm, next_y;
    FILE *out;
    const char *path;
    long pfm_header;              /* PFM: bytes before the bottom row */
    unsigned char *pfm_row;       /* PFM: one row, little-endian */
    exr_sink sink;
    exr_context_t ctx;
    exr_encode_pipeline_t enc;
    int part, lines, enc_init;
    exr_channel ch[MAX_CHANNELS];
    int nch;
};

/* The band's first value of channel c, and its stride in floats. */
static const float *channel_data(const ms_frame *band, const exr_channel *c, int *stride)
{
    const size_t npix = (size_t)band->width * (size_t)band->height;
    *stride = 1;
    switch (c->plane) {
    case 'C': *stride = 3; return band->rgb + c->index;
    case 'V': return band->vis + (size_t)c->index * npix;
    default: return band->shadow + (size_t)c->index * npix;
    }
}

/* The channels of kind in the file's order: sorted by name, as OpenEXR keeps channel lists ("V10" before
 * "V2"; readers find them by name). One light: "V" resp. "S" (and in the RGB file S and V); several: V0, V1... */
static int exr_channels(ms_float_rows *r)
{
    const int nl = r->nl;
    int n = 0;
    if (r->kind == MS_IMAGE_EXR_RGB) {
        static const char *const rgb[3] = { "B", "G", "R" };
        for (int c = 0; c < 3; c++) {
            snprintf(r->ch[n].name, sizeof r->ch[n].name, "%s", rgb[c]);
            r->ch[n].plane = 'C';
            r->ch[n++].index = 2 - c;
        }
    }
    for (int which = 0; which < 2; which++) {   /* S before V: the file's order is by name */
        const char p = which ? 'V' : 'S';
        if (r->kind == MS_IMAGE_VIS && p != 'V') continue;
        if (r->kind == MS_IMAGE_SHADOW && p != 'S') continue;
        const int first = n;
        for (int l = 0; l < nl; l++) {
            if (nl == 1) snprintf(r->ch[n].name, sizeof r->ch[n].name, "%c", p);
            else snprintf(r->ch[n].name, sizeof r->ch[n].name, "%c%d", p, l);
            r->ch[n].plane = p;
            r->ch[n++].index = l;
        }
        for (int a = first + 1; a < n; a++)
            for (int b = a; b > first && strcmp(r->ch[b - 1].name, r->ch[b].name) > 0; b--) {
                const exr_channel t = r->ch[b]; r->ch[b] = r->ch[b - 1]; r->ch[b - 1] = t;
            }
    }
    return n;
}

static int exr_failed(ms_float_rows *r, exr_result_t rc, char *err, size_t errlen)
{
    if (r->sink.saved_errno) snprintf(err, errlen, "%s: write failed: %s", r->path, strerror(r->sink.saved_errno));
    else snprintf(err, errlen, "%s: EXR write failed: %s", r->path, exr_get_default_error_message(rc));
    return -1;
}

static void rows_free(ms_float_rows *r)
{
    if (r->enc_init) exr_encoding_destroy(r->ctx, &r->enc);
    if (r->ctx) exr_finish(&r->ctx);
    free(r->pfm_row);
    free(r);
}

ms_float_rows *ms_float_rows_begin(ms_image_kind kind, int W, int H, int n_lights, FILE *out, const char *path,
                                   char *err, size_t errlen)
{
    const char *what = kind == MS_IMAGE_VIS ? "visibility" : kind == MS_IMAGE_SHADOW ? "shadow factor" : "RGB";
    const int exr = ends_with(path, ".exr"), pfm = kind != MS_IMAGE_EXR_RGB && ends_with(path, ".pfm");
    if (!exr && !pfm) {
        snprintf(err, errlen, kind == MS_IMAGE_EXR_RGB ? "%s: the %s image must end in .exr" : "%s: the %s image must end in .pfm or .exr",
                 path, what);
        return NULL;
    }
    /* Several lights: an EXR gets one channel per light (V0, V1, ... in light order), a PFM light 0. */
    const int nl = pfm || n_lights < 1 ? 1 : n_lights;
    if (nl > MAX_LIGHT_CHANNELS) { snprintf(err, errlen, "%s: more than %d lights for one EXR", path, MAX_LIGHT_CHANNELS); return NULL; }
    ms_float_rows *r = calloc(1, sizeof *r);
    if (!r) { snprintf(err, errlen, "%s: out of memory", path); return NULL; }
    r->kind = kind;
    r->W = W;
    r->H = H;
    r->nl = nl;
    r->pfm = pfm;
    r->out = out;
    r->path = path;
    if (pfm) {
        r->pfm_row = malloc(4 * (size_t)W);
        if (!r->pfm_row) { snprintf(err, errlen, "%s: out of memory", path); rows_free(r); return NULL; }
        /* Negative scale: little-endian floats. The rows go by pwrite to their places after the header. */
        errno = 0;
        const int hl = fprintf(out, "Pf\n%d %d\n-1.0\n", W, H);
        if (hl < 0 || fflush(out) != 0) {
            snprintf(err, errlen, "%s: write failed: %s", path, strerror(errno ? errno : EIO));
            rows_free(r);
            return NULL;
        }
        r->pfm_header = hl;
        return r;
    }
    r->nch = exr_channels(r);
    r->sink.fd = fileno(out);
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.user_data = &r->sink;
    init.write_fn = exr_sink_write;
    init.error_handler_fn = exr_quiet;
    exr_result_t rc = exr_start_write(&r->ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    /* A one-channel file's part is named after its channel, any other "rgb" (as the files always were). */
    const char *part_name = r->nch == 1 ? r->ch[0].name : "rgb";
    if (rc == EXR_ERR_SUCCESS) rc = exr_add_part(r->ctx, part_name, EXR_STORAGE_SCANLINE, &r->part);
    if (rc == EXR_ERR_SUCCESS) rc = exr_initialize_required_attr_simple(r->ctx, r->part, W, H, EXR_COMPRESSION_ZIP);
    for (int c = 0; c < r->nch && rc == EXR_ERR_SUCCESS; c++)
        rc = exr_add_channel(r->ctx, r->part, r->ch[c].name, EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1);
    if (rc == EXR_ERR_SUCCESS) rc = exr_write_header(r->ctx);
    r->lines = 1;
    if (rc == EXR_ERR_SUCCESS) rc = exr_get_scanlines_per_chunk(r->ctx, r->part, &r->lines);
    if (rc != EXR_ERR_SUCCESS) { exr_failed(r, rc, err, errlen); rows_free(r); return NULL; }
    return r;
}

static int pfm_rows(ms_float_rows *r, const ms_frame *band, int y0, char *err, size_t errlen)
{
    const float *plane = r->kind == MS_IMAGE_VIS ? band->vis : band->shadow;
    for (int y = 0; y < band->height; y++) {
        const float *row = plane + (size_t)y * (size_t)r->W;
        for (int x = 0; x < r->W; x++) {
            uint32_t u;
            memcpy(&u, &row[x], 4);
            unsigned char *b = r->pfm_row + 4 * (size_t)x;
            b[0] = (unsigned char)u; b[1] = (unsigned char)(u >> 8); b[2] = (unsigned char)(u >> 16); b[3] = (unsigned char)(u >> 24);
        }
        const off_t at = (off_t)r->pfm_header + (off_t)(r->H - 1 - (y0 + y)) * (off_t)r->W * 4;
        size_t done = 0, len = 4 * (size_t)r->W;
        while (done < len) {
            const ssize_t w = pwrite(fileno(r->out), r->pfm_row + done, len - done, at + (off_t)done);
            if (w < 0 && errno == EINTR) continue;
            if (w <= 0) { snprintf(err, errlen, "%s: write failed: %s", r->path, strerror(w < 0 ? errno : EIO)); return -1; }
            done += (size_t)w;
        }
    }
    return 0;
}

int ms_float_rows_write(ms_float_rows *r, const ms_frame *band, int y0, char *err, size_t errlen)
{
    if (y0 != r->next_y || (y0 + band->height != r->H && band->height % (r->pfm ? 1 : r->lines))) {
        snprintf(err, errlen, "%s: rows %d..%d out of order or not whole blocks", r->path, y0, y0 + band->height);
        return -1;
    }
    r->next_y = y0 + band->height;
    if (r->pfm) return pfm_rows(r, band, y0, err, errlen);
    exr_result_t rc = EXR_ERR_SUCCESS;
    for (int y = y0; rc == EXR_ERR_SUCCESS && y < y0 + band->height; y += r->lines) {
        exr_chunk_info_t ci;
        rc = exr_write_scanline_chunk_info(r->ctx, r->part, y, &ci);
        if (rc != EXR_ERR_SUCCESS) break;
        rc = r->enc_init ? exr_encoding_update(r->ctx, r->part, &ci, &r->enc) : exr_encoding_initialize(r->ctx, r->part, &ci, &r->enc);
        if (rc != EXR_ERR_SUCCESS) break;
        for (int c = 0; c < r->nch; c++) {
            int stride;
            const float *d = channel_data(band, &r->ch[c], &stride);
            r->enc.channels[c].encode_from_ptr = (const uint8_t *)(d + (size_t)(y - y0) * (size_t)r->W * (size_t)stride);
            r->enc.channels[c].user_pixel_stride = (int32_t)(sizeof(float) * (size_t)stride);
            r->enc.channels[c].user_line_stride = (int32_t)(sizeof(float) * (size_t)r->W * (size_t)stride);
        }
        if (!r->enc_init) {
            r->enc_init = 1;
            rc = exr_encoding_choose_default_routines(r->ctx, r->part, &r->enc);
            if (rc != EXR_ERR_SUCCESS) break;
        }
        rc = exr_encoding_run(r->ctx, r->part, &r->enc);
    }
    return rc == EXR_ERR_SUCCESS ? 0 : exr_failed(r, rc, err, errlen);
}

int ms_float_rows_end(ms_float_rows *r, int ok, char *err, size_t errlen)
{
    int rc = 0;
    if (ok && r->next_y != r->H) {
        snprintf(err, errlen, "%s: %d of %d rows written", r->path, r->next_y, r->H);
        rc = -1;
    }
    if (!r->pfm) {
        if (r->enc_init) exr_encoding_destroy(r->ctx, &r->enc);
        r->enc_init = 0;
        const exr_result_t fin = exr_finish(&r->ctx);
        r->ctx = NULL;
        if (ok && !rc && fin != EXR_ERR_SUCCESS) rc = exr_failed(r, fin, err, errlen);
    }
    rows_free(r);
    return rc;
}

static int write_whole(ms_image_kind kind, const ms_frame *f, FILE *out, const char *path, char *err, size_t errlen)
{
    ms_float_rows *r = ms_float_rows_begin(kind, f->width, f->height, f->n_lights, out, path, err, errlen);
    if (!r) return -1;
    const int rc = ms_float_rows_write(r, f, 0, err, errlen);
    return ms_float_rows_end(r, rc == 0, err, errlen) || rc ? -1 : 0;
}

ms_status ms_vis_write_stream(const ms_frame *f, FILE *out, const char *path, char *err, size_t errlen)
{
    return write_whole(MS_IMAGE_VIS, f, out, path, err, errlen) ? MS_ERR_IO : MS_OK;
}

ms_status ms_shadow_write_stream(const ms_frame *f, FILE *out, const char *path, char *err, size_t errlen)
{
    return write_whole(MS_IMAGE_SHADOW, f, out, path, err, errlen) ? MS_ERR_IO : MS_OK;
}

ms_status ms_exr_write_stream(const ms_frame *f, FILE *out, const char *path, char *err, size_t errlen)
{
    return write_whole(MS_IMAGE_EXR_RGB, f, out, path, err, errlen) ? MS_ERR_IO : MS_OK;
}
