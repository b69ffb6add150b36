/* Each sample on an occluder set that decides it as raytrace does (exact_split.h). */
#include "exact_split.h"
#include "visibility/receiver.h"
#include "light/pattern.h"
#include "visibility/occluders.h"
#include "light/light_frame.h"
#include "accel/ray_triangle.h"
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* 1 when every segment from p to a point of the hull of pts (n points) has 2 |d_a| > |d_c| for both other axes c,
 * by a margin far above the rounding of the sample points and of d = L - p (ulps of the coordinates), so that
 * ms_wt_packet_axis keeps a for every packet of those segments once a is its candidate. d is affine over the
 * hull; where d_a keeps one strict sign, 2 |d_a| - |d_c| = min(2 |d_a| - d_c, 2 |d_a| + d_c) is the least of two
 * affine functions, each least at a hull point, so checking it at the hull points proves it everywhere. */
static int proves_axis(const float p[3], const float (*pts)[3], int n, int a)
{
    double mag = 0.0, d[8][3];
    for (int h = 0; h < n; h++)
        for (int c = 0; c < 3; c++) {
            const double m = fabs((double)pts[h][c]) + fabs((double)p[c]);   /* no fmax: a call without -ffast-math */
            mag = m > mag ? m : mag;
            d[h][c] = (double)pts[h][c] - (double)p[c];
        }
    const double margin = 1e-5 * mag;
    for (int h = 0; h < n; h++) {
        if (!(d[h][a] * d[0][a] > 0.0)) return 0;   /* d_a changes sign (or is 0) over the hull */
        for (int c = 0; c < 3; c++)
            if (c != a && !(2.0 * fabs(d[h][a]) - fabs(d[h][c]) > margin)) return 0;
    }
    return 1;
}

/* ms_receiver_axes (exact_split.h): the rule (ms_wt_packet_axis) takes pref wherever every lane of a packet
 * allows it, so a receiver whose whole light proves pref (proves_axis over the light's hull) has every segment
 * on it; else per packet of 16 samples: on the grid a packet is 16 points of one row, p0 + i ds + j dt, bounded
 * by the row segment's two ends as the light is by its hull, so pref (or, without one, lane 0's largest axis,
 * computed as the methods compute it) is proved there; the packets no proof settles take the rule itself on
 * their points. */
void ms_receiver_axes(const ms_render_ctx *ctx, const ms_shadow_query *q, const float (*hull)[3], int n_hull,
                      int pref, float *pts, uint64_t *ax)
{
    const size_t mw = (size_t)ctx->mask_words;
    memset(ax, 0, 3 * mw * sizeof *ax);
    if (pref >= 0 && proves_axis(q->p, hull, n_hull, pref)) {
        memset(ax + (size_t)pref * mw, 0xff, mw * sizeof *ax);   /* bits past samples: the front masks clear them */
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
            int a = pref;
            if (a < 0) {
                const float d0[3] = { ends[0][0] - q->p[0], ends[0][1] - q->p[1], ends[0][2] - q->p[2] };
                a = ms_wt_max_axis(d0);
            }
            if (proves_axis(q->p, (const float (*)[3])ends, 2, a)) {
                ax[(size_t)a * mw + (size_t)(first >> 6)] |= UINT64_C(0xffff) << (first & 63);
                continue;
            }
            ms_grid_points(&g, first, 16, pts + 3 * first);
        }
        ms_segment_axes(q->p, pts + 3 * first, first, 16, pref, (int)mw, ax);
    }
}

int ms_exact_split_visibility(const ms_shadow_method *sm, void *state, const ms_render_ctx *ctx,
                              const ms_exact_split *split, const ms_shadow_query *q, const uint32_t *scene_prim,
                              size_t n, const uint64_t *front, uint64_t *vis, int whole, int threads,
                              uint64_t *counters)
{
    const size_t mw = (size_t)ctx->mask_words;
    /* The sets besides the merged one: one per axis of split->axes, the axes whose state is one set's joined. */
    void *set_state[3];
    ms_render_ctx set_ctx[3];
    unsigned set_axes[3];
    int ns = 0;
    for (int a = 0; a < 3; a++) {
        if (!(split->axes >> a & 1u)) continue;
        int s = 0;
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
    /* The merged set's samples: the front masks less the samples of the split axes, for every query in place
     * (most have all their samples there); the queries with samples elsewhere kept with their axes, per thread. */
    const size_t nn = n ? n : 1, rec = 3 * mw;   /* a kept query: its axes (3 masks) */
    const int nt = whole && threads > 1 ? threads : 1;
    uint64_t *sel = malloc(nn * mw * sizeof *sel);
    size_t *kept_n = calloc((size_t)nt, sizeof *kept_n), *kept_cap = calloc((size_t)nt, sizeof *kept_cap);
    size_t **kept_i = calloc((size_t)nt, sizeof *kept_i);
    uint64_t **kept_ax = calloc((size_t)nt, sizeof *kept_ax);
    int failed = !sel || !kept_n || !kept_cap || !kept_i || !kept_ax;
    float hull[8][3], hull_box[6];
    const int n_hull = ms_light_hull(&ctx->light, hull, hull_box), pref = ms_light_shear_axis(&ctx->light);
    if (!failed) {
#pragma omp parallel num_threads(nt) reduction(| : failed)
        {
            const int t = omp_get_thread_num();
            float *pts = malloc((size_t)ctx->samples * 3 * sizeof *pts);
            uint64_t ax[3 * (MS_SAMPLES_MAX / 64)];
            failed |= !pts;
#pragma omp for schedule(static)
            for (size_t i = 0; i < n; i++) {
                if (!pts) continue;
                ms_receiver_axes(ctx, &q[i], (const float (*)[3])hull, n_hull, pref, pts, ax);
                uint64_t out = 0;
                for (size_t w = 0; w < mw; w++) {
                    uint64_t m = 0;
                    for (int a = 0; a < 3; a++)
                        if (split->axes >> a & 1u) m |= ax[(size_t)a * mw + w];
                    sel[i * mw + w] = front[i * mw + w] & ~m;
                    out |= front[i * mw + w] & m;
                }
                if (!out) continue;
                if (kept_n[t] == kept_cap[t]) {
                    const size_t cap = kept_cap[t] ? 2 * kept_cap[t] : 256;
                    size_t *ni = realloc(kept_i[t], cap * sizeof *ni);
                    if (ni) kept_i[t] = ni;
                    uint64_t *na = ni ? realloc(kept_ax[t], cap * rec * sizeof *na) : NULL;
                    if (na) kept_ax[t] = na;
                    if (!ni || !na) { free(pts); pts = NULL; failed = 1; continue; }
                    kept_cap[t] = cap;
                }
                kept_i[t][kept_n[t]] = i;
                memcpy(kept_ax[t] + kept_n[t]++ * rec, ax, rec * sizeof *ax);
            }
            free(pts);
        }
    }
    if (!failed)
        failed = whole ? sm->visibility_all(state, ctx, q, n, sel, vis, counters) != 0
                       : sm->visibility(state, ctx, q, (int)n, sel, vis, counters) != 0;
    /* The kept queries, compacted, over each other set with the samples of its axes; ORed into vis. */
    size_t m = 0;
    for (int t = 0; t < nt && !failed; t++) m += kept_n[t];
    const size_t mm = m ? m : 1;
    ms_shadow_query *cq = NULL;
    size_t *cidx = NULL;
    uint64_t *cfront = NULL, *cvis = NULL;
    if (!failed && m) {
        cq = malloc(mm * sizeof *cq);
        cidx = malloc(mm * sizeof *cidx);
        cfront = malloc(mm * mw * sizeof *cfront);
        cvis = malloc(mm * mw * sizeof *cvis);
        failed = !cq || !cidx || !cfront || !cvis;
    }
    for (int s = 0; s < ns && !failed && m; s++) {
        size_t k = 0;
        for (int t = 0; t < nt; t++)
            for (size_t c = 0; c < kept_n[t]; c++) {
                const size_t i = kept_i[t][c];
                const uint64_t *ax = kept_ax[t] + c * rec;
                uint64_t any = 0;
                for (size_t w = 0; w < mw; w++) {
                    uint64_t msk = 0;
                    for (int a = 0; a < 3; a++)
                        if (set_axes[s] >> a & 1u) msk |= ax[(size_t)a * mw + w];
                    cfront[k * mw + w] = front[i * mw + w] & msk;
                    any |= cfront[k * mw + w];
                }
                if (!any) continue;
                cq[k] = q[i];
                cq[k].prim = ms_ctx_skip_prim(&set_ctx[s], scene_prim[i]);
                cidx[k++] = i;
            }
        if (!k) continue;
        if (whole ? sm->visibility_all(set_state[s], &set_ctx[s], cq, k, cfront, cvis, counters)
                  : sm->visibility(set_state[s], &set_ctx[s], cq, (int)k, cfront, cvis, counters)) {
            failed = 1;
            break;
        }
        for (size_t c = 0; c < k; c++)
            for (size_t w = 0; w < mw; w++) vis[cidx[c] * mw + w] |= cvis[c * mw + w];
    }
    free(sel);
    for (int t = 0; kept_i && t < nt; t++) free(kept_i[t]);
    for (int t = 0; kept_ax && t < nt; t++) free(kept_ax[t]);
    free(kept_i);
    free(kept_ax);
    free(kept_n);
    free(kept_cap);
    free(cq);
    free(cidx);
    free(cfront);
    free(cvis);
    return failed ? -1 : 0;
}
