/* A frame job's tiles (frame_job.h): the progress and cancellation shared by its phases, the primary hits and
 * surfaces of a set of tiles, and ms_frame_job_render, which renders them with every light's shadow pass
 * (frame_job_shadow.c). */

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

/* CPU seconds of all the process's threads: on a shared machine, where wall time depends on the
 * neighbours, the figure to compare methods by. */
double fj_process_cpu_s(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts)) return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* One tile done. The callback runs on whichever thread finished a tile, one thread at a time and with
 * fractions that only grow (a late smaller count is dropped): reporting from thread 0 alone, as before,
 * said nothing at all when the other threads took every tile (a small frame), and missed the final 1. */
void fj_progress_tick(ms_frame_job *j)
{
    long d;
#pragma omp atomic capture
    d = ++j->done;
    if (!j->opt.progress) return;
#pragma omp critical(ms_frame_progress)
    if (d > j->reported && !j->cancelled) {
        j->reported = d;
        if (j->opt.progress(j->opt.progress_user, (double)d / (double)j->total)) {
#pragma omp atomic write
            j->cancelled = 1;
        }
    }
}

/* 1 once the progress callback cancelled the frame: a tile not begun is skipped. */
int fj_cancelled(ms_frame_job *j)
{
    int c;
#pragma omp atomic read
    c = j->cancelled;
    return c;
}

int ms_frame_job_tiles(const ms_frame_job *j, int *tiles_x, int *tiles_y)
{
    if (tiles_x) *tiles_x = j->tx;
    if (tiles_y) *tiles_y = j->ty;
    return j->ntiles;
}

int ms_frame_job_splittable(const ms_frame_job *j)
{
    return !j->sm->visibility_all || j->sm->split_exact;
}

ms_frame *ms_frame_job_frame(ms_frame_job *j) { return &j->frame; }

/* Primary hits of tiles[0..n) (tiles == NULL: 0..n-1) into j->hits. */
void fj_trace_tiles(ms_frame_job *j, const int *tiles, int n, int tick)
{
#pragma omp parallel for schedule(dynamic, 1) num_threads(j->threads)
    for (int i = 0; i < n; i++) {
        if (tick && fj_cancelled(j)) continue;
        const int t = tiles ? tiles[i] : i;
        int x0, y0, x1, y1;
        tile_rect(j, t, &x0, &y0, &x1, &y1);
        ms_hit tile[TILE * TILE];
        j->pm->trace(j->pstate, &j->ctx, x0, y0, x1, y1, tile);
        for (int y = y0; y < y1; y++)
            memcpy(&j->hits[(size_t)(y - j->y_base) * j->W + x0], &tile[(y - y0) * (x1 - x0)], (size_t)(x1 - x0) * sizeof *tile);
        j->traced[t] = 1;
        if (tick) fj_progress_tick(j);
    }
}

/* The surfaces of the hits of tiles[0..n) (tiles == NULL: 0..n-1), when the scene has any. */
void fj_surface_tiles(ms_frame_job *j, const int *tiles, int n)
{
    if (!j->surf) return;
#pragma omp parallel for schedule(dynamic, 1) num_threads(j->threads)
    for (int i = 0; i < n; i++) {
        int x0, y0, x1, y1;
        tile_rect(j, tiles ? tiles[i] : i, &x0, &y0, &x1, &y1);
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) {
                const size_t p = (size_t)(y - j->y_base) * j->W + x;
                float viewer[3];   /* the eye, or up the pixel's own ray for an orthographic camera */
                ms_camera_viewer(&j->ctx.cam, j->hits[p].p, viewer);
                ms_surface_at(j->scene, &j->bvh, &j->hits[p], viewer, j->opt.shading, &j->surf[p]);
            }
    }
}

ms_status ms_frame_job_render(ms_frame_job *j, const int *tiles, int n, char *err, size_t errlen)
{
    const ms_shadow_method *sm = j->sm;
    const int whole = !tiles && n == j->ntiles && !j->rendered_any;
    if (!tiles && n != j->ntiles) { snprintf(err, errlen, "ms_frame_job_render: tiles is NULL but n is not the frame's %d tiles", j->ntiles); return MS_ERR_INVALID; }
    for (int i = 0; tiles && i < n; i++)
        if (tiles[i] < 0 || tiles[i] >= j->ntiles) { snprintf(err, errlen, "ms_frame_job_render: tile %d is not in [0, %d)", tiles[i], j->ntiles); return MS_ERR_INVALID; }
    if (!whole && !ms_frame_job_splittable(j)) {
        snprintf(err, errlen, "method '%s' renders only whole frames (the receivers its hierarchy rasterizes triangles for, "
                 "and so its rounding at their edges, depend on all of the frame's pixels)", sm->name);
        return MS_ERR_INVALID;
    }
    j->rendered_any = 1;
    ms_stats *st = &j->frame.stats;
    const double t0 = omp_get_wtime();
    fj_trace_tiles(j, tiles, n, 1);
    if (fj_cancelled(j)) { snprintf(err, errlen, "cancelled by the progress callback"); return MS_ERR_CANCELLED; }
    const double t1 = omp_get_wtime();
    const double c1 = fj_process_cpu_s();

    /* The surfaces are timed with the shadow phase (a lookup per pixel, far below the shadow cost). Each
     * light in turn, with its own state and planes; the hits and surfaces are shared. */
    fj_surface_tiles(j, tiles, n);
    pass_sums p;
    memset(&p, 0, sizeof p);
    int failed = 0;
    for (size_t l = 0; l < j->nlights && !failed && !fj_cancelled(j); l++) failed = fj_shadow_pass(j, l, tiles, n, whole, &p) != 0;
    if (fj_cancelled(j)) { snprintf(err, errlen, "cancelled by the progress callback"); return MS_ERR_CANCELLED; }
    if (failed) {
        snprintf(err, errlen, "out of memory in the shadow phase of method '%s'", sm->name);
        return MS_ERR_NO_MEMORY;
    }
    st->primary_s += t1 - t0;
    st->shadow_s += omp_get_wtime() - t1;
    st->shadow_cpu_s += fj_process_cpu_s() - c1;
    for (int c = 0; c < MS_MAX_COUNTERS; c++) st->counter[c] += p.counters[c];
    st->visible_pixels += p.visible / j->nlights;   /* every light's pass counts each visible pixel once */
    st->penumbra_pixels += p.penumbra;
    st->receivers_on_merged += p.on_merged;
    st->shadow_rays += p.segments;
    st->shadow_factor_s += p.resolve_thread_s;
    return 0;
}
