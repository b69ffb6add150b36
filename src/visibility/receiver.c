/* Front masks and the resolution of V and S (receiver.h). */
#include "receiver.h"
#include "core/vec.h"
#include "light/light_frame.h"
#include "raster/raster.h"
#include "core/cpu.h"
#include "disk_mask.h"
#include "light/pattern.h"
#include "accel/ray_triangle.h"
#include <math.h>
#include <string.h>

int ms_mask_count(const uint64_t *m, int n)
{
    /* Exact on every instance, so no cap applies (MS_ISA_AUTO): the best the CPU has (a portable popcount
     * is a libgcc call per word, which made counting the masks cost more than the weights). */
    switch (ms_isa_select(MS_ISA_AUTO, MS_ISA_ALL)) {
    case MS_ISA_AVX512: return ms_mask_count_avx512(m, n);
    case MS_ISA_AVX2: return ms_mask_count_avx2(m, n);
    default: return ms_mask_count_scalar(m, n);
    }
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

/* The samples in front of q's plane (the horizon alone), as ms_front_mask without the shape. */
static int horizon_mask(const ms_render_ctx *ctx, const ms_shadow_query *q, const float *pts, uint64_t *front)
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

int ms_front_mask(const ms_render_ctx *ctx, const ms_shadow_query *q, const float *pts, uint64_t *front)
{
    const int nf = horizon_mask(ctx, q, pts, front);
    if (ctx->light.shape == MS_LIGHT_RECT || nf == 0) return nf;
    /* A disk: the samples off it neither count nor are traced, exactly like those behind the horizon, so
     * every method (which starts from or traces only the front mask) honours the shape unchanged. The grid's
     * disk in vector lanes (disk_mask.h): every instance gives the same mask; the context's cap picks one, so
     * that a capped run (the scalar test suite) runs the portable one. */
    if (ctx->pattern == MS_PATTERN_GRID && ctx->light.shape == MS_LIGHT_DISK && ctx->k % 16 == 0 && ctx->k <= 64) {   /* its rows: 16-lane chunks */
        float u, v;
        ms_grid_shift(q->px, q->py, ctx->seed, &u, &v);
        switch (ms_isa_select(ctx->isa_cap, MS_ISA_ALL)) {
        case MS_ISA_AVX512: ms_grid_disk_mask_avx512(ctx->k, u, v, front); break;
        case MS_ISA_AVX2: ms_grid_disk_mask_avx2(ctx->k, u, v, front); break;
        default: ms_grid_disk_mask_scalar(ctx->k, u, v, front); break;
        }
    } else
        ms_shape_mask_apply(ctx->pattern, &ctx->light, ctx->k, q->px, q->py, ctx->seed, front);
    return ms_mask_count(front, ctx->mask_words);
}

typedef void (*grid_weights_fn)(const ms_grid *g, const float rel0[3], const float h[3], int k, const uint64_t *front,
                                const uint64_t *vis, float *wf, float *wv);

/* A textured light's weight sums: w_i (the form-factor weight, as the stratified path has it) times the
 * luminance of sample i's texel, over the front (wf) and visible (wv, when vis is not NULL) samples, and
 * the w-weighted mean texel colour over the front samples into rgb (when not NULL). Scalar, per sample:
 * only penumbra pixels and the shading of textured lights come here. */
static void textured_sums(const ms_render_ctx *ctx, const ms_shadow_query *q, const float *pts, const uint64_t *front,
                          const uint64_t *vis, float *wf, float *wv, float *rgb)
{
    const ms_light *L = &ctx->light;
    ms_light_frame F;
    ms_light_frame_of(L, &F);
    float nl[3];   /* the light's unit normal */
    v3_normalize(nl, F.normal);
    float own[3 * MS_SAMPLES_MAX], st[2 * MS_SAMPLES_MAX];
    if (!pts) { ms_pattern_points(ctx->pattern, L, ctx->k, q->px, q->py, ctx->seed, own); pts = own; }
    ms_pattern_st(ctx->pattern, ctx->k, q->px, q->py, ctx->seed, st);
    double sf = 0.0, sv = 0.0, sw = 0.0, c[3] = { 0.0, 0.0, 0.0 };
    for (int i = 0; i < ctx->samples; i++) {
        if (!ms_mask_get(front, i)) continue;
        float d[3], col[3];
        v3_sub(d, pts + 3 * i, q->p);
        const float r2 = v3_dot(d, d);
        const float w = ms_maxf(v3_dot(d, q->n), 0.0f) * ms_maxf(-v3_dot(d, nl), 0.0f) / (r2 * r2);
        const float y = ms_light_texel(L, st[2 * i], st[2 * i + 1], rgb ? col : NULL);
        sf += (double)(w * y);
        if (vis && ms_mask_get(vis, i)) sv += (double)(w * y);
        if (rgb) { sw += (double)w; for (int a = 0; a < 3; a++) c[a] += (double)(w * col[a]); }
    }
    if (wf) *wf = (float)sf;
    if (wv) *wv = (float)sv;
    if (rgb) for (int a = 0; a < 3; a++) rgb[a] = sw > 0.0 ? (float)(c[a] / sw) : 0.0f;
}

void ms_light_texture_mean(const ms_render_ctx *ctx, const ms_shadow_query *q, float rgb[3])
{
    if (!ctx->light.texture) { rgb[0] = rgb[1] = rgb[2] = 1.0f; return; }
    uint64_t front[MS_SAMPLES_MAX / 64];
    float pts[3 * MS_SAMPLES_MAX];
    ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, q->px, q->py, ctx->seed, pts);
    ms_front_mask(ctx, q, ctx->pattern == MS_PATTERN_GRID ? NULL : pts, front);
    textured_sums(ctx, q, pts, front, NULL, NULL, NULL, rgb);
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
    if (L->texture) {
        float wf, wv;
        textured_sums(ctx, q, pts, front, vis, &wf, &wv, NULL);
        *s = wf > 0.0f ? wv / wf : *v;
        return 1;
    }
    ms_light_frame F;
    ms_light_frame_of(L, &F);
    float nl[3];   /* the light's unit normal */
    v3_normalize(nl, F.normal);
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
        /* The instance of the capped ISA (ms_isa_select; the probe is cached: a few loads and compares). */
        static const grid_weights_fn by_isa[] = {
            [MS_ISA_SCALAR] = ms_grid_weights_scalar,
            [MS_ISA_AVX2] = ms_grid_weights_avx2,
            [MS_ISA_AVX512] = ms_grid_weights_avx512,
        };
        if (-v3_dot(rel0, nl) > 0.0f)   /* else every cos theta_l <= 0: all weights 0 */
            by_isa[ms_isa_select(ctx->isa_cap, MS_ISA_ALL)](&g, rel0, h, k, front, vis, &wf, &wv);
    }
    *s = wf > 0.0f ? wv / wf : *v;
    return 1;
}

void ms_segment_axes(const float p[3], const float *pts, int first, int n, int pref, int mw, uint64_t *axes)
{
    for (int base = first; base < first + n; base += 16) {
        float d[3][16];
        for (int l = 0; l < 16; l++)
            for (int a = 0; a < 3; a++) d[a][l] = pts[3 * (base - first + l) + a] - p[a];
        const int kz = ms_wt_packet_axis(d[0], d[1], d[2], 16, pref, NULL);
        for (int l = 0; l < 16; l++) {
            const float dl[3] = { d[0][l], d[1][l], d[2][l] };
            const int s = base + l, a = kz >= 0 ? kz : ms_wt_max_axis(dl);
            axes[(size_t)a * mw + (s >> 6)] |= UINT64_C(1) << (s & 63);
        }
    }
}
