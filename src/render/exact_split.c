/* Each sample on an occluder set that decides it as raytrace does (exact_split.h). */
#include "exact_split.h"
#include "visibility/receiver.h"
#include "light/pattern.h"
#include "visibility/occluders.h"
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* The axis every segment from p to the light is sheared along (ms_segment_axes), when the light's hull (its n
 * points) proves it, else -1: d = L - p is affine over the light, so where d_a keeps one strict sign |d_a| is
 * affine too (its least value at a hull point), and every |d_c| is convex (its greatest value at a hull point);
 * where d_c keeps one sign as well, |d_a| - |d_c| is affine and is checked at each hull point. It must exceed a
 * margin far above the rounding of the sample points and of d (ulps of the coordinates): then every sample's
 * largest axis is a, and so is every packet's (ms_wt_packet_axis: lane 0's largest, every lane within a factor
 * 2). */
static int one_axis(const float p[3], const float (*hull)[3], int n)
{
    double mag = 0.0, d[8][3], lo[3], hi[3];
    int fixed[3];   /* 1: d_c has one strict sign over the hull */
    for (int c = 0; c < 3; c++) {
        mag = fmax(mag, fabs((double)p[c]));
        lo[c] = INFINITY;
        hi[c] = 0.0;
        fixed[c] = 1;
        for (int h = 0; h < n; h++) {
            mag = fmax(mag, fabs((double)hull[h][c]));
            d[h][c] = (double)hull[h][c] - (double)p[c];
            lo[c] = fmin(lo[c], fabs(d[h][c]));
            hi[c] = fmax(hi[c], fabs(d[h][c]));
            fixed[c] &= d[h][c] * d[0][c] > 0.0;
        }
    }
    const double margin = 1e-5 * mag;
    for (int a = 0; a < 3; a++) {
        if (!fixed[a]) continue;
        int ok = 1;
        for (int c = 0; c < 3 && ok; c++) {
            if (c == a) continue;
            if (!fixed[c]) { ok = lo[a] - hi[c] > margin; continue; }
            for (int h = 0; h < n && ok; h++) ok = fabs(d[h][a]) - fabs(d[h][c]) > margin;
        }
        if (ok) return a;
    }
    return -1;
}

/* Query q's segments by shear axis (ms_segment_axes: bit s of ax + a * mask_words), pts scratch for its sample
 * points. Proved for the whole light where one_axis can, else per packet of 16 samples: on the grid a packet
 * is 16 points of one row, p0 + i ds + j dt, whose segment's two ends bound it as the hull does the light;
 * the packets one_axis cannot prove take the rule itself on their points. */
static void receiver_axes(const ms_render_ctx *ctx, const ms_shadow_query *q, const float (*hull)[3], int n_hull,
                          float *pts, uint64_t *ax)
{
    const size_t mw = (size_t)ctx->mask_words;
    memset(ax, 0, 3 * mw * sizeof *ax);
    const int a = one_axis(q->p, hull, n_hull);
    if (a >= 0) {
        memset(ax + (size_t)a * mw, 0xff, mw * sizeof *ax);   /* bits past samples: the front masks clear them */
        return;
    }
    ms_grid g;
    const int grid = ctx->pattern == MS_PATTERN_GRID;
    if (grid) ms_grid_for_pixel(&ctx->light, ctx->k, q->px, q->py, ctx->seed, &g);
    else ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, q->px, q->py, ctx->seed, pts);
    for (int first = 0; first < ctx->samples; first += 16) {
        if (grid) {
            float ends[2][3];
            ms_grid_points(&g, first, 1, ends[0]);
            ms_grid_points(&g, first + 15, 1, ends[1]);
            const int pa = one_axis(q->p, (const float (*)[3])ends, 2);
            if (pa >= 0) {
                ax[(size_t)pa * mw + (size_t)(first >> 6)] |= UINT64_C(0xffff) << (first & 63);
                continue;
            }
            ms_grid_points(&g, first, 16, pts + 3 * first);
        }
        ms_segment_axes(q->p, pts + 3 * first, first, 16, (int)mw, ax);
    }
}

/* The method over the queries of q whose `sel` masks (their front masks restricted to one set's axes) hold
 * any sample, compacted; their visible masks ORed into vis. */
static int run_set(const ms_shadow_method *sm, void *state, const ms_render_ctx *ctx, const ms_shadow_query *q,
                   const uint32_t *scene_prim, size_t n, const uint64_t *sel, uint64_t *vis, int whole,
                   uint64_t *counters, ms_shadow_query *cq, size_t *idx, uint64_t *cfront, uint64_t *cvis)
{
    const size_t mw = (size_t)ctx->mask_words;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        uint64_t any = 0;
        for (size_t w = 0; w < mw; w++) any |= sel[i * mw + w];
        if (!any) continue;
        cq[m] = q[i];
        cq[m].prim = ms_ctx_skip_prim(ctx, scene_prim[i]);
        memcpy(cfront + m * mw, sel + i * mw, mw * sizeof *cfront);
        idx[m++] = i;
    }
    if (!m) return 0;
    if (whole ? sm->visibility_all(state, ctx, cq, m, cfront, cvis, counters)
              : sm->visibility(state, ctx, cq, (int)m, cfront, cvis, counters))
        return -1;
    for (size_t c = 0; c < m; c++)
        for (size_t w = 0; w < mw; w++) vis[idx[c] * mw + w] |= cvis[c * mw + w];
    return 0;
}

int ms_exact_split_visibility(const ms_shadow_method *sm, void *state, const ms_render_ctx *ctx,
                              const ms_exact_split *split, const ms_shadow_query *q, const uint32_t *scene_prim,
                              size_t n, const uint64_t *front, uint64_t *vis, int whole, int threads,
                              uint64_t *counters)
{
    const size_t mw = (size_t)ctx->mask_words;
    /* The sets: 0 the merged one, then one per axis of split->axes, the axes whose state is one set's joined. */
    void *set_state[4] = { state };
    ms_render_ctx set_ctx[4];
    set_ctx[0] = *ctx;
    unsigned set_axes[4] = { 7u & ~split->axes };
    int ns = 1;
    for (int a = 0; a < 3; a++) {
        if (!(split->axes >> a & 1u)) continue;
        int s = 1;
        while (s < ns && set_state[s] != split->state[a]) s++;
        if (s == ns) {
            set_state[s] = split->state[a];
            set_ctx[s] = *ctx;
            set_ctx[s].bvh = split->bvh[a];
            set_ctx[s].alpha = split->alpha[a];
            set_ctx[s].prim_map = split->prim_map[a];
            set_ctx[s].prim_merged = NULL;
            set_axes[s] = 0;
            ns++;
        }
        set_axes[s] |= 1u << a;
    }
    const size_t nn = n ? n : 1;
    uint64_t *axes = malloc(nn * 3 * mw * sizeof *axes), *sel = malloc(nn * mw * sizeof *sel);
    uint64_t *cfront = malloc(nn * mw * sizeof *cfront), *cvis = malloc(nn * mw * sizeof *cvis);
    ms_shadow_query *cq = malloc(nn * sizeof *cq);
    size_t *idx = malloc(nn * sizeof *idx);
    int failed = !axes || !sel || !cfront || !cvis || !cq || !idx;
    float hull[8][3], hull_box[6];
    const int n_hull = ms_light_hull(&ctx->light, hull, hull_box);
    if (!failed) {
        memset(vis, 0, n * mw * sizeof *vis);
#pragma omp parallel num_threads(whole ? threads : 1) reduction(| : failed)
        {
            float *pts = malloc((size_t)ctx->samples * 3 * sizeof *pts);
            failed |= !pts;
#pragma omp for schedule(static)
            for (size_t i = 0; i < n; i++) {
                if (!pts) continue;
                receiver_axes(ctx, &q[i], (const float (*)[3])hull, n_hull, pts, axes + i * 3 * mw);
            }
            free(pts);
        }
    }
    for (int s = 0; s < ns && !failed; s++) {
        for (size_t i = 0; i < n; i++)
            for (size_t w = 0; w < mw; w++) {
                uint64_t m = 0;
                for (int a = 0; a < 3; a++)
                    if (set_axes[s] >> a & 1u) m |= axes[(i * 3 + (size_t)a) * mw + w];
                sel[i * mw + w] = front[i * mw + w] & m;
            }
        failed = run_set(sm, set_state[s], &set_ctx[s], q, scene_prim, n, sel, vis, whole, counters, cq, idx, cfront, cvis) != 0;
    }
    free(axes);
    free(sel);
    free(cfront);
    free(cvis);
    free(cq);
    free(idx);
    return failed ? -1 : 0;
}
