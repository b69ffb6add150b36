/* Front masks and the resolution of V and S (receiver.h). */
#include "receiver.h"
#include "../core/vec.h"
#include "../raster/raster.h"
#include <math.h>
#include <string.h>

int ms_mask_count(const uint64_t *m, int n)
{
    int c = 0;
    for (int i = 0; i < n; i++) c += __builtin_popcountll(m[i]);
    return c;
}

void ms_horizon_edge(const ms_grid *g, const float p[3], const float n[3], float h[3])
{
    float rel[3];
    v3_sub(rel, g->p0, p);
    h[0] = v3_dot(g->ds, n);
    h[1] = v3_dot(g->dt, n);
    h[2] = v3_dot(rel, n);
}

/* Relative margin beyond which the corner test's verdict matches the row loop's: both evaluate the same
 * affine function, with rounding far below 1e-5 of its terms. */
#define HORIZON_MARGIN 1e-5f

int ms_front_mask(const ms_render_ctx *ctx, const ms_shadow_query *q, const float *pts, uint64_t *front)
{
    const int k = ctx->k, ns = ctx->samples, nw = ctx->mask_words;
    if (pts) {
        memset(front, 0, (size_t)nw * sizeof *front);
        for (int s = 0; s < ns; s++) {
            float d[3];
            v3_sub(d, pts + 3 * s, q->p);
            if (v3_dot(d, q->n) > 0.0f) front[s >> 6] |= UINT64_C(1) << (s & 63);
        }
        return ms_mask_count(front, nw);
    }
    ms_grid g;
    float h[3];
    ms_grid_for_pixel(&ctx->light, k, q->px, q->py, ctx->seed, &g);
    ms_horizon_edge(&g, q->p, q->n, h);
    /* h is affine in (i, j): its corners bound it. The whole light in front (the common case) or behind
     * needs no rows. */
    const float km = (float)(k - 1);
    const float c0 = h[2], c1 = h[2] + km * h[0], c2 = h[2] + km * h[1], c3 = h[2] + km * (h[0] + h[1]);
    const float lo = ms_minf(ms_minf(c0, c1), ms_minf(c2, c3)), hi = ms_maxf(ms_maxf(c0, c1), ms_maxf(c2, c3));
    const float margin = HORIZON_MARGIN * (fabsf(h[0]) * km + fabsf(h[1]) * km + fabsf(h[2]));
    if (lo > margin) { memset(front, 0xFF, (size_t)nw * sizeof *front); return ns; }
    if (!(hi >= -margin)) { memset(front, 0, (size_t)nw * sizeof *front); return 0; }
    /* Behind = h <= 0, i.e. the edge -h covers the sample (ties to "behind": front is strict). */
    const float e[3] = { -h[0], -h[1], -h[2] };
    memset(front, 0xFF, (size_t)nw * sizeof *front);
    ms_raster_clear_halfplane(k, e, front);
    return ms_mask_count(front, nw);
}

/* Adds the weights of row j's front samples to wf[] and of its visible ones to wv[] (16 lane sums). With
 * d = L - P, cos theta_r = d . n / r = (h . (i, j, 1)) / r (n is unit) and cos theta_l = b / r with
 * b = -d . n_l, so w = a b / r^4. On the grid every sample lies on the light's plane, b is the same for all
 * of them and cancels in S: the rows sum a / r^4. Written as 16 independent lanes (no reduction inside
 * the loop) so that it vectorises without reassociating float sums, and sums in the same order on every
 * ISA. */
#define WLANES 16
static void grid_row_weights(const ms_grid *g, const float rel0[3], const float h[3], int k, int j,
                             uint64_t fbits, uint64_t vbits, float wf[WLANES], float wv[WLANES])
{
    static const uint32_t bit[WLANES] = { 1u << 0, 1u << 1, 1u << 2, 1u << 3, 1u << 4, 1u << 5, 1u << 6, 1u << 7,
                                          1u << 8, 1u << 9, 1u << 10, 1u << 11, 1u << 12, 1u << 13, 1u << 14, 1u << 15 };
    const float fj = (float)j;
    const float bx = rel0[0] + fj * g->dt[0], by = rel0[1] + fj * g->dt[1], bz = rel0[2] + fj * g->dt[2];
    const float hb = h[2] + fj * h[1];
    for (int i0 = 0; i0 < k; i0 += WLANES) {
        const uint32_t fb = (uint32_t)(fbits >> i0) & 0xFFFFu, vb = (uint32_t)(vbits >> i0) & 0xFFFFu;
        if (!fb) continue;
        for (int l = 0; l < WLANES; l++) {
            const float fi = (float)(i0 + l);
            const float dx = bx + fi * g->ds[0], dy = by + fi * g->ds[1], dz = bz + fi * g->ds[2];
            const float r2 = dx * dx + dy * dy + dz * dz;
            const float a = ms_maxf(hb + fi * h[0], 0.0f);
            const float w = a / (r2 * r2);
            wf[l] += (fb & bit[l]) ? w : 0.0f;
            wv[l] += (vb & bit[l]) ? w : 0.0f;
        }
    }
}

static uint64_t mask_row(const uint64_t *m, int k, int j)
{
    const int bit = j * k;
    const uint64_t w = m[bit >> 6] >> (bit & 63);
    return k == 64 ? w : w & ((UINT64_C(1) << k) - 1);
}

int ms_resolve_vs(const ms_render_ctx *ctx, const ms_shadow_query *q, const float *pts, const uint64_t *front,
                  const uint64_t *vis, float *v, float *s)
{
    const int nw = ctx->mask_words, k = ctx->k;
    const int nf = ms_mask_count(front, nw), nv = ms_mask_count(vis, nw);
    if (nv == 0 || nv == nf) {
        /* No front sample visible, all of them, or none in front: S = V. */
        *v = nf ? (float)nv / (float)nf : 0.0f;
        *s = *v;
        return 0;
    }
    *v = (float)nv / (float)nf;
    const ms_light *L = &ctx->light;
    const float es[3] = { L->edge_s.x, L->edge_s.y, L->edge_s.z }, et[3] = { L->edge_t.x, L->edge_t.y, L->edge_t.z };
    float nl[3];
    v3_cross(nl, es, et);
    v3_normalize(nl, nl);
    float wf = 0.0f, wv = 0.0f;
    if (pts) {
        for (int i = 0; i < ctx->samples; i++) {
            if (!ms_mask_get(front, i)) continue;
            float d[3];
            v3_sub(d, pts + 3 * i, q->p);
            const float r2 = v3_dot(d, d);
            const float w = ms_maxf(v3_dot(d, q->n), 0.0f) * ms_maxf(-v3_dot(d, nl), 0.0f) / (r2 * r2);
            wf += w;
            if (ms_mask_get(vis, i)) wv += w;
        }
    } else {
        ms_grid g;
        float h[3], rel0[3];
        ms_grid_for_pixel(L, k, q->px, q->py, ctx->seed, &g);
        ms_horizon_edge(&g, q->p, q->n, h);
        v3_sub(rel0, g.p0, q->p);
        float lf[WLANES] = { 0 }, lv[WLANES] = { 0 };
        if (-v3_dot(rel0, nl) > 0.0f)   /* else every cos theta_l <= 0: all weights 0 */
            for (int j = 0; j < k; j++) {
                const uint64_t fb = mask_row(front, k, j);
                if (fb) grid_row_weights(&g, rel0, h, k, j, fb, mask_row(vis, k, j), lf, lv);
            }
        for (int l = 0; l < WLANES; l++) { wf += lf[l]; wv += lv[l]; }
    }
    *s = wf > 0.0f ? wv / wf : *v;
    return 1;
}
