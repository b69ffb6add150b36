/* ms_render_outputs (microshadow.h): a frame rendered and written, the whole frame in memory or streamed band by
 * band (frame_stream.h, #24 item 2, docs/memory.md).
 *
 * Streamed, the float outputs (PFM, EXR) take each band's rows as they finish. The PNG cannot: its exposure
 * maps the 99th percentile of the whole frame's unshadowed luminance to white. The choice: each band's
 * radiance and luminance go to a scratch file beside the PNG (20 bytes a pixel on disk, none in memory), a
 * histogram of the luminances' upper 16 bits is gathered meanwhile; at the end one pass over the scratch file
 * counts the lower 16 bits inside the bucket that holds the percentile's rank, which gives the exact value
 * (the same float the whole frame's sort picks), and a second pass writes the PNG's rows. */
#include "frame_stream.h"
#include "frame_aa.h"
#include "core/abi.h"
#include "image/output_stream.h"
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* A float's bits as an unsigned key in the floats' order (negatives flipped below the positives). */
static uint32_t order_key(float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    return u & 0x80000000u ? ~u : u | 0x80000000u;
}

static float key_float(uint32_t k)
{
    const uint32_t u = k & 0x80000000u ? k & 0x7fffffffu : ~k;
    float v;
    memcpy(&v, &u, 4);
    return v;
}

static int io_all(int fd, void *buf, size_t len, off_t at, int write, char *err, size_t errlen)
{
    char *p = buf;
    size_t done = 0;
    while (done < len) {
        const ssize_t r = write ? pwrite(fd, p + done, len - done, at + (off_t)done) : pread(fd, p + done, len - done, at + (off_t)done);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) {
            snprintf(err, errlen, "the PNG's scratch file: %s failed: %s", write ? "write" : "read", r < 0 ? strerror(errno) : "end of file");
            return -1;
        }
        done += (size_t)r;
    }
    return 0;
}

/* The streamed PNG's state: the scratch file, the histograms, a band's buffers. The file holds the rendered
 * frame's luminances first (Wi x Hi floats: with anti-aliasing the exposure is the s-times larger frame's, as
 * frame_shade.c computes it before the resolve), then a record per output pixel (W x H). */
typedef struct png_spill {
    int fd;
    int W, H, band_rows;   /* the output's size and a band's output rows */
    int Wi, Hi, s;         /* the rendered frame's size, s times the output's */
    float *rec;            /* a band's records (r, g, b, and -INFINITY on a miss), or its luminances */
    float *rgb, *vis;      /* a band as the PNG writer takes it */
    uint64_t *hist;        /* 65536 buckets */
    uint64_t nlum;
} png_spill;

static off_t rec_at(const png_spill *s, int y) { return (off_t)s->Wi * s->Hi * 4 + (off_t)y * s->W * 16; }

static void spill_free(png_spill *s)
{
    if (s->fd >= 0) close(s->fd);
    free(s->rec);
    free(s->rgb);
    free(s->vis);
    free(s->hist);
}

/* A band: its output rows from y0 (band: the output's pixels, resolved), and the rendered frame's luminances of
 * its rows (n_lum from the rendered frame's row y0 * s). */
static int spill_band(png_spill *s, const ms_frame *band, const float *lum, size_t n_lum, int y0, char *err, size_t errlen)
{
    for (size_t i = 0; i < n_lum; i++)
        if (lum[i] != -INFINITY) {
            s->hist[order_key(lum[i]) >> 16]++;
            s->nlum++;
        }
    if (io_all(s->fd, (void *)lum, n_lum * 4, (off_t)y0 * s->s * s->Wi * 4, 1, err, errlen)) return -1;
    const size_t n = (size_t)s->W * (size_t)band->height;
    for (size_t i = 0; i < n; i++) {
        memcpy(&s->rec[4 * i], &band->rgb[3 * i], 3 * sizeof(float));
        s->rec[4 * i + 3] = band->vis[i] < 0.0f ? -INFINITY : 0.0f;   /* light 0's plane: a miss for every light */
    }
    return io_all(s->fd, s->rec, n * 16, rec_at(s, y0), 1, err, errlen);
}

/* The exposure the whole frame would get (frame_shade.c): 1 / the luminance of rank 0.99 (nlum - 1) in
 * ascending order, or 1. */
static int spill_exposure(png_spill *s, float *exposure, char *err, size_t errlen)
{
    *exposure = 1.0f;
    if (!s->nlum) return 0;
    uint64_t rank = (uint64_t)(0.99 * (double)(s->nlum - 1)), below = 0;
    uint32_t hi = 0;
    while (below + s->hist[hi] <= rank) below += s->hist[hi++];
    rank -= below;
    memset(s->hist, 0, 65536 * sizeof *s->hist);   /* now the lower 16 bits within bucket hi */
    const int band_i = s->band_rows * s->s;
    for (int y0 = 0; y0 < s->Hi; y0 += band_i) {
        const int rows = s->Hi - y0 < band_i ? s->Hi - y0 : band_i;
        const size_t n = (size_t)s->Wi * (size_t)rows;
        if (io_all(s->fd, s->rec, n * 4, (off_t)y0 * s->Wi * 4, 0, err, errlen)) return -1;
        for (size_t i = 0; i < n; i++) {
            const float v = s->rec[i];
            if (v == -INFINITY) continue;
            const uint32_t k = order_key(v);
            if (k >> 16 == hi) s->hist[k & 0xffffu]++;
        }
    }
    uint32_t lo = 0;
    below = 0;
    while (below + s->hist[lo] <= rank) below += s->hist[lo++];
    const float p99 = key_float(hi << 16 | lo);
    if (p99 > 0.0f) *exposure = 1.0f / p99;
    return 0;
}

static int spill_png(png_spill *s, ms_outputs_stream *os, float exposure, char *err, size_t errlen)
{
    for (int y0 = 0; y0 < s->H; y0 += s->band_rows) {
        const int rows = s->H - y0 < s->band_rows ? s->H - y0 : s->band_rows;
        const size_t n = (size_t)s->W * (size_t)rows;
        if (io_all(s->fd, s->rec, n * 16, rec_at(s, y0), 0, err, errlen)) return -1;
        for (size_t i = 0; i < n; i++) {
            memcpy(&s->rgb[3 * i], &s->rec[4 * i], 3 * sizeof(float));
            s->vis[i] = s->rec[4 * i + 3] == -INFINITY ? -1.0f : 0.0f;   /* the PNG writer's miss test */
        }
        ms_frame band;
        memset(&band, 0, sizeof band);
        band.width = s->W;
        band.height = rows;
        band.rgb = s->rgb;
        band.vis = s->vis;
        band.exposure = exposure;
        if (ms_outputs_stream_rows(os, &band, y0, 1, err, errlen)) return -1;
    }
    return 0;
}

/* The resolved band's planes (anti-aliasing: the output's rows of a band, allocated once for the largest). */
static int resolved_alloc(ms_frame *r, size_t px, int nl)
{
    memset(r, 0, sizeof *r);
    const size_t np = (size_t)(nl > 0 ? nl : 1) * px;
    r->rgb = malloc(px * 3 * sizeof *r->rgb);
    r->vis = malloc(np * sizeof *r->vis);
    r->shadow = malloc(np * sizeof *r->shadow);
    r->shadow_spec = malloc(np * sizeof *r->shadow_spec);
    r->front = malloc(np * sizeof *r->front);
    return r->rgb && r->vis && r->shadow && r->shadow_spec && r->front ? 0 : -1;
}

static void resolved_free(ms_frame *r)
{
    free(r->rgb); free(r->vis); free(r->shadow); free(r->shadow_spec); free(r->front);
}

/* The banded job's frame into the outputs. With anti-aliasing each band of the s-times larger frame is resolved
 * (frame_aa.h, the whole frame's resolve, pixel for pixel) into whole output rows before it is written. */
static ms_status stream_frame(ms_frame_job *job, int band_rows, double exposure_ev, const ms_output *outs, int n,
                        ms_stats *stats, char *err, size_t errlen)
{
    int Wi, Hi, s, front_scale;
    ms_frame_job_size(job, &Wi, &Hi);
    ms_frame_job_aa(job, &s, &front_scale);
    const int W = Wi / s, H = Hi / s, out_rows = band_rows / s;
    const int nl = ms_frame_job_frame(job)->n_lights;
    const char *first = NULL;   /* the outputs' first path names a NaN, as ms_outputs_write does */
    for (int k = 0; k < n && !first; k++) first = outs[k].path;
    ms_outputs_stream *os;
    if (ms_outputs_stream_open(outs, n, W, H, nl, &os, err, errlen)) return MS_ERR_IO;
    const char *png = ms_outputs_stream_png_path(os);
    png_spill sp = { .fd = -1, .W = W, .H = H, .band_rows = out_rows, .Wi = Wi, .Hi = Hi, .s = s };
    const size_t bpix = (size_t)Wi * (size_t)band_rows, opix = (size_t)W * (size_t)out_rows;
    float *lum = NULL;
    ms_frame res;   /* the resolved band */
    memset(&res, 0, sizeof res);
    ms_status rc = MS_OK;
    if (s > 1 && resolved_alloc(&res, opix, nl)) {
        snprintf(err, errlen, "out of memory for a resolved band of %dx%d", W, out_rows);
        rc = MS_ERR_NO_MEMORY;
    }
    if (png && !rc) {
        lum = malloc(bpix * sizeof *lum);
        sp.rec = malloc(bpix * 4 > opix * 16 ? bpix * 4 : opix * 16);
        sp.rgb = malloc(opix * 3 * sizeof(float));
        sp.vis = malloc(opix * sizeof(float));
        sp.hist = calloc(65536, sizeof *sp.hist);
        if (!lum || !sp.rec || !sp.rgb || !sp.vis || !sp.hist) {
            snprintf(err, errlen, "out of memory for a band of %dx%d", Wi, band_rows);
            rc = MS_ERR_NO_MEMORY;
        } else if ((sp.fd = ms_outputs_spill(png, err, errlen)) < 0) rc = MS_ERR_IO;
    }
    ms_frame band;
    memset(&band, 0, sizeof band);
    for (int y0 = 0; y0 < Hi && !rc; y0 += band_rows) {
        const int rows = Hi - y0 < band_rows ? Hi - y0 : band_rows;
        const int brc = ms_frame_job_band_render(job, y0, rows, err, errlen);
        if (brc) rc = brc > 0 ? (ms_status)brc : MS_ERR_INVALID;
        int by0, got;
        while (!rc && (got = ms_frame_job_band_take(job, &band, &by0, lum, err, errlen)) != 0) {
            if (got < 0) { rc = MS_ERR_NO_MEMORY; break; }
            ms_frame r = res;
            if (s > 1) {
                if (!band.front) r.front = NULL;   /* not handed out (the interleaved filter's window) */
                if (!band.shadow_spec) r.shadow_spec = NULL;
                ms_frame_aa_resolve_into(&band, s, front_scale, &r);
            }
            const ms_frame *ob = s > 1 ? &r : &band;
            const int oy0 = by0 / s;
            if (first && ms_band_check_finite(ob, oy0, first, err, errlen)) rc = MS_ERR_IO;
            else if (ms_outputs_stream_rows(os, ob, oy0, 0, err, errlen)) rc = MS_ERR_IO;
            else if (png && spill_band(&sp, ob, lum, (size_t)Wi * (size_t)band.height, oy0, err, errlen)) rc = MS_ERR_IO;
        }
    }
    resolved_free(&res);
    ms_frame meta;   /* what the end needs of the frame: its stats, and its exposure for the check */
    memset(&meta, 0, sizeof meta);
    meta.stats = band.stats;
    meta.stats.stream_rows = out_rows;
    meta.width = W;
    meta.height = H;
    if (!rc && png) {
        float exposure;
        if (spill_exposure(&sp, &exposure, err, errlen)) rc = MS_ERR_IO;
        meta.exposure = exposure * (float)exp2(exposure_ev);
        /* The exposure's own check (a frame of no rows but with its radiance), as ms_outputs_write makes it. */
        ms_frame ex = meta;
        ex.height = 0;
        ex.rgb = sp.rgb;
        if (!rc && ms_frame_check_finite(&ex, png, err, errlen)) rc = MS_ERR_IO;
        if (!rc && spill_png(&sp, os, meta.exposure, err, errlen)) rc = MS_ERR_IO;
    }
    spill_free(&sp);
    free(lum);
    if (rc) ms_outputs_stream_abort(os);
    else if (ms_outputs_stream_commit(os, &meta, err, errlen)) rc = MS_ERR_IO;
    if (stats) *stats = meta.stats;
    return rc;
}

ms_status ms_render_outputs_abi(const ms_abi *abi, const ms_scene *scene, const ms_render_options *opt,
                                double exposure_ev, const ms_output *outs, int n, ms_stats *stats, char *err,
                                size_t errlen)
{
    const ms_status ast = ms_abi_check(abi, "ms_render_outputs", err, errlen);
    if (ast) return ast;
    ms_render_options own;
    opt = ms_abi_options(opt, MS_ABI_SIZE(abi, render_options), &own, sizeof own);
    if (stats) memset(stats, 0, sizeof *stats);
    int mode = (int)opt->stream;
    if (mode < MS_STREAM_AUTO || mode > MS_STREAM_OFF) { snprintf(err, errlen, "unknown stream mode %d", mode); return MS_ERR_INVALID; }
    if (mode != MS_STREAM_OFF && ms_outputs_streamable(outs, n, err, errlen)) {
        if (mode == MS_STREAM_ON) return MS_ERR_INVALID;
        mode = MS_STREAM_OFF;   /* a caller's own writer takes the whole frame */
    }
    ms_frame_job *job;
    int band_rows;
    const ms_status crc = ms_frame_job_create_stream(scene, opt, mode, &job, &band_rows, err, errlen);
    if (crc) return crc;
    ms_status rc;
    if (band_rows) rc = stream_frame(job, band_rows, exposure_ev, outs, n, stats, err, errlen);
    else {
        ms_frame frame;
        memset(&frame, 0, sizeof frame);
        rc = ms_frame_job_render(job, NULL, ms_frame_job_tiles(job, NULL, NULL), err, errlen);
        if (rc == MS_OK) rc = ms_frame_job_finish(job, &frame, err, errlen);
        if (rc == 0) {
            frame.exposure *= (float)exp2(exposure_ev);
            if (ms_outputs_write(&frame, outs, n, err, errlen)) rc = MS_ERR_IO;
            if (stats) *stats = frame.stats;
        }
        ms_frame_free(&frame);
    }
    ms_frame_job_free(job);
    return rc;
}
