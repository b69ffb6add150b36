/* A frame job's end (frame_job.h): the frame-global finish (the tiles other jobs rendered, the interleaved
 * filter, shading, anti-aliasing, the stats), or a streamed frame's bands rendered and handed out in order. */

#include "frame_job.h"
#include "core/abi.h"
#include "light/pattern.h"
#include "light/light_shape.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include "visibility/occluders.h"
#include "frame_shade.h"
#include "shadow_frame.h"
#include "exact_split.h"
#include "shade.h"
#include "render_materialise.h"
#include "interleave_filter.h"
#include "budget.h"
#include "frame_stream.h"
#include "frame_aa.h"
#include "sun_place.h"
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The frame's stats once every tile is rendered (finish, or a streamed frame's last band). */
static void job_stats(ms_frame_job *j, ms_stats *st)
{
    const size_t nl = j->nlights;
    st->triangles = j->scene->n_tris;
    st->load_s = j->scene->load_s;
    st->samples = j->samples;
    st->samples_per_pixel = j->spp * (j->aa_split ? j->aa_s * j->aa_s : 1);
    st->threads = j->threads;
    st->width = j->W;
    st->height = j->H;
    st->aa = j->aa_s * j->aa_s;
    st->method = j->sm->name;
    st->primary = j->pm->name;
    if (j->pm->counters) {
        uint64_t c[3];
        j->pm->counters(j->pstate, c);
        st->primary_setups = c[0];
        st->primary_edge_evals = c[1];
        st->primary_nodes = c[2];
    }
    ms_isa kisa = MS_ISA_AUTO, tisa = MS_ISA_AUTO;
    if (j->sm->isa_used) j->sm->isa_used(j->sstate[nl - 1], &kisa, &tisa);
    st->kernel_isa = kisa == MS_ISA_AUTO ? "none" : ms_isa_name(kisa);
    st->traversal_isa = tisa == MS_ISA_AUTO ? "none" : ms_isa_name(tisa);
    st->pattern = ms_pattern_name(j->opt.pattern);
    st->shadow_factor_s /= j->threads;   /* thread-seconds to seconds */
    st->total_s = omp_get_wtime() - j->t_start + j->scene->load_s;
}

ms_status ms_frame_job_finish(ms_frame_job *j, ms_frame *out, char *err, size_t errlen)
{
    if (j->band_rows) { snprintf(err, errlen, "ms_frame_job_finish: a streamed job's frame is written band by band"); return MS_ERR_INVALID; }
    memset(out, 0, sizeof *out);
    ms_frame *f = &j->frame;
    ms_stats *st = &f->stats;
    const int W = j->W, H = j->H;
    const size_t npix = (size_t)W * H, nl = j->nlights;
    /* Hit points (and surfaces) of the tiles other jobs rendered: the filter and the shading need them all. */
    int *missing = malloc((size_t)j->ntiles * sizeof *missing), nm = 0;
    if (!missing) { snprintf(err, errlen, "out of memory for a %dx%d frame", W, H); return MS_ERR_NO_MEMORY; }
    for (int t = 0; t < j->ntiles; t++)
        if (!j->traced[t]) missing[nm++] = t;
    const double tp = omp_get_wtime();
    if (nm) {
        fj_trace_tiles(j, missing, nm, 0);
        fj_surface_tiles(j, missing, nm);
    }
    free(missing);
    st->primary_s += omp_get_wtime() - tp;
    /* The interleaved pattern's filter belongs to its shadow cost (timed in shadow_s and on its own). */
    if (j->ctx.pattern == MS_PATTERN_INTERLEAVED && !j->opt.no_filter) {
        const double tf = omp_get_wtime(), cf = fj_process_cpu_s();
        /* S_spec through the same filter, with the same raw V deciding the neighbours (one pass for both). */
        int ferr = 0;
        for (size_t l = 0; l < nl && !ferr; l++)
            ferr = ms_interleave_filter(W, H, j->hits, f->front + l * npix, f->vis + l * npix, f->shadow + l * npix,
                                        j->surf ? f->shadow_spec + l * npix : NULL, j->threads);
        if (ferr) {
            snprintf(err, errlen, "out of memory for the interleaved filter of a %dx%d frame", W, H);
            return MS_ERR_NO_MEMORY;
        }
        st->filter_s = omp_get_wtime() - tf;
        st->shadow_s += st->filter_s;
        st->shadow_cpu_s += fj_process_cpu_s() - cf;
    }
    if (ms_frame_shade(j->scene, &j->ctx, j->lights, nl, j->hits, j->surf, j->threads, 0, f, NULL)) {
        snprintf(err, errlen, "out of memory for the textured lights of a %dx%d frame", W, H);
        return MS_ERR_NO_MEMORY;
    }
    if (j->aa_s > 1 && ms_frame_aa_resolve(f, j->aa_s, j->aa_split ? j->aa_s * j->aa_s : 1)) {
        snprintf(err, errlen, "out of memory resolving the anti-aliased %dx%d frame", W / j->aa_s, H / j->aa_s);
        return MS_ERR_NO_MEMORY;
    }

    job_stats(j, st);
    *out = *f;
    memset(f, 0, sizeof *f);
    return 0;
}

int ms_frame_job_band_render(ms_frame_job *j, int y0, int rows, char *err, size_t errlen)
{
    if (!j->band_rows || y0 != j->rendered_to || y0 % TILE || rows < 1 || rows > j->band_rows || (rows % TILE && y0 + rows != j->H) ||
        y0 + rows > j->H) {
        snprintf(err, errlen, "ms_frame_job_band_render: rows %d..%d are not the next band of whole tile rows", y0, y0 + rows);
        return -1;
    }
    /* Without the filter the planes hold this band alone (light l's plane at l * W * rows, as in a frame of that
     * height); with it they keep the window from y_base (shifted in ms_frame_job_band_take). */
    if (!j->band_filter) {
        j->y_base = y0;
        j->rows_held = rows;
    }
    const int ty0 = y0 / TILE, ty1 = (y0 + rows + TILE - 1) / TILE, n = (ty1 - ty0) * j->tx;
    int *tiles = malloc((size_t)n * sizeof *tiles);
    if (!tiles) { snprintf(err, errlen, "out of memory"); return -1; }
    for (int i = 0; i < n; i++) tiles[i] = ty0 * j->tx + i;
    const int rc = ms_frame_job_render(j, tiles, n, err, errlen);
    free(tiles);
    if (!rc) j->rendered_to = y0 + rows;
    return rc;
}

/* Moves rows from .. rendered_to of every plane of the window to its start. */
static void window_shift(ms_frame_job *j, int from)
{
    const size_t W = (size_t)j->W, cap = W * (size_t)j->rows_held, off = (size_t)(from - j->y_base) * W;
    const size_t keep = (size_t)(j->rendered_to - from) * W;
    memmove(j->hits, j->hits + off, keep * sizeof *j->hits);
    if (j->surf) memmove(j->surf, j->surf + off, keep * sizeof *j->surf);
    ms_frame *f = &j->frame;
    for (size_t l = 0; l < j->nlights; l++) {
        memmove(f->vis + l * cap, f->vis + l * cap + off, keep * sizeof *f->vis);
        memmove(f->shadow + l * cap, f->shadow + l * cap + off, keep * sizeof *f->shadow);
        memmove(f->shadow_spec + l * cap, f->shadow_spec + l * cap + off, keep * sizeof *f->shadow_spec);
        memmove(f->front + l * cap, f->front + l * cap + off, keep * sizeof *f->front);
    }
    j->y_base = from;
}

int ms_frame_job_band_take(ms_frame_job *j, ms_frame *band, int *y0, float *lum, char *err, size_t errlen)
{
    const int a = j->emitted_to, W = j->W;
    int b = j->band_filter ? a + j->band_rows : j->rendered_to;
    if (b > j->H) b = j->H;
    /* The filter reads two rows below the band: ready once they are rendered (or the frame ends there). */
    if (a >= j->rendered_to || (j->band_filter && j->rendered_to < (b + 2 < j->H ? b + 2 : j->H))) return 0;
    ms_frame *f = &j->frame, bf = *f;
    bf.height = b - a;
    const size_t off = (size_t)(a - j->y_base) * (size_t)W;
    if (j->band_filter) {
        const size_t cap = (size_t)W * (size_t)j->rows_held, bn = (size_t)W * (size_t)(b - a);
        const double tf = omp_get_wtime();
        for (size_t l = 0; l < j->nlights; l++)
            if (ms_interleave_filter_rows(W, j->H, j->hits, f->front + l * cap, f->vis + l * cap, f->shadow + l * cap,
                                          f->shadow_spec + l * cap, j->y_base, j->rows_held, a, b, j->band_vis + l * bn,
                                          j->band_shadow + l * bn, j->band_spec + l * bn, j->threads)) {
                snprintf(err, errlen, "out of memory for the interleaved filter of a %d-pixel-wide band", W);
                return -1;
            }
        const double dt = omp_get_wtime() - tf;
        f->stats.filter_s += dt;
        f->stats.shadow_s += dt;
        bf.vis = j->band_vis;
        bf.shadow = j->band_shadow;
        bf.shadow_spec = j->band_spec;
        bf.front = NULL;   /* not handed out: the window's */
    }
    if (ms_frame_shade(j->scene, &j->ctx, j->lights, j->nlights, j->hits + off, j->surf ? j->surf + off : NULL, j->threads, a,
                       &bf, lum)) {
        snprintf(err, errlen, "out of memory for the textured lights of a %dx%d band", W, b - a);
        return -1;
    }
    j->emitted_to = b;
    if (j->band_filter && b < j->H) window_shift(j, b - 2);   /* the next band's filter reads rows b - 2, b - 1 */
    if (b == j->H) job_stats(j, &f->stats);
    bf.stats = f->stats;
    *band = bf;
    *y0 = a;
    return 1;
}

void ms_frame_job_size(const ms_frame_job *j, int *W, int *H)
{
    *W = j->W;
    *H = j->H;
}

void ms_frame_job_aa(const ms_frame_job *j, int *s, int *front_scale)
{
    *s = j->aa_s;
    *front_scale = j->aa_split ? j->aa_s * j->aa_s : 1;
}
