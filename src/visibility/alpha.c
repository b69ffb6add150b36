/* The alpha test of alpha-tested occluders (alpha.h). */
#include "alpha.h"
#include "core/vec.h"
#include "light/pattern.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

void ms_alpha_free(ms_alpha *a)
{
    if (!a) return;
    for (size_t i = 0; i < a->n_maps; i++) free(a->maps[i].a);
    free(a->maps);
    free(a->flag);
    free(a->slot);
    free(a->tri);
    free(a);
}

/* The alpha map of scene texture t: its alpha channel, or (grey = 1, an MTL map_d) its red channel when the
 * alpha channel is 255 everywhere. 0, or -1 when out of memory. */
static int copy_map(const ms_texture *t, int grey, ms_alpha_map *m)
{
    const size_t n = (size_t)t->width * (size_t)t->height;
    m->width = t->width;
    m->height = t->height;
    if (!(m->a = malloc(n ? n : 1))) return -1;
    int channel = 3;
    if (grey) {
        size_t i = 0;
        while (i < n && t->rgba[4 * i + 3] == 255) i++;
        if (i == n) channel = 0;
    }
    for (size_t i = 0; i < n; i++) m->a[i] = t->rgba[4 * i + (size_t)channel];
    return 0;
}

int ms_alpha_build(const ms_scene *s, const ms_bvh *b, ms_alpha **out)
{
    *out = NULL;
    if (!b || !s->tri_material || !s->materials || !b->tri_source) return 0;
    size_t n_alpha = 0;
    for (uint32_t i = 0; i < b->n_tris; i++) {
        const uint32_t mi = s->tri_material[b->tri_source[i]];
        n_alpha += mi < s->n_materials && s->materials[mi].alpha_mode != MS_ALPHA_OPAQUE;
    }
    if (!n_alpha) return 0;
    ms_alpha *a = calloc(1, sizeof *a);
    if (!a) return -1;
    a->n_tris = b->n_tris;
    a->n_alpha = n_alpha;
    a->flag = calloc(b->n_tris, 1);
    a->slot = calloc(b->n_tris, sizeof *a->slot);
    a->tri = calloc(n_alpha, sizeof *a->tri);
    /* map_of[2 t + grey]: the copy of texture t as a base-colour alpha (0) or as an MTL map_d (1). */
    int32_t *map_of = malloc((2 * s->n_textures + 1) * sizeof *map_of);
    a->maps = calloc(2 * s->n_textures + 1, sizeof *a->maps);
    if (!a->flag || !a->slot || !a->tri || !map_of || !a->maps) { free(map_of); ms_alpha_free(a); return -1; }
    for (size_t t = 0; t < 2 * s->n_textures; t++) map_of[t] = -1;
    size_t k = 0;
    for (uint32_t i = 0; i < b->n_tris; i++) {
        const size_t src = b->tri_source[i];
        const uint32_t mi = s->tri_material[src];
        if (mi >= s->n_materials || s->materials[mi].alpha_mode == MS_ALPHA_OPAQUE) continue;
        const ms_material *m = &s->materials[mi];
        ms_alpha_tri *at = &a->tri[k];
        a->flag[i] = 1;
        a->slot[i] = (uint32_t)k++;
        const float *v = b->tri + 9 * (size_t)i;
        double e1[3], e2[3];
        for (int c = 0; c < 3; c++) {
            at->v0[c] = v[c];
            e1[c] = (double)v[3 + c] - (double)v[c];
            e2[c] = (double)v[6 + c] - (double)v[c];
        }
        d3_cross(at->n, e1, e2);
        const double nn = at->n[0] * at->n[0] + at->n[1] * at->n[1] + at->n[2] * at->n[2];
        d3_cross(at->g1, e2, at->n);
        d3_cross(at->g2, at->n, e1);
        for (int c = 0; c < 3; c++) {   /* a degenerate triangle (nn = 0): g = 0, and ms_alpha_value sees N = 0 */
            at->g1[c] = nn > 0.0 ? at->g1[c] / nn : 0.0;
            at->g2[c] = nn > 0.0 ? at->g2[c] / nn : 0.0;
        }
        at->factor = m->base_color[3];
        at->cutoff = m->alpha_cutoff;
        at->map = -1;
        const int grey = m->alpha_mode == MS_ALPHA_MASK_MAP;
        const int32_t tex = grey ? m->alpha_texture : m->base_color_texture;
        const int set = m->base_color_uv;
        const float *uv = tex >= 0 && (size_t)tex < s->n_textures && set >= 0 && set < MS_MAX_UV_SETS && s->tri_uv[set]
                              ? s->tri_uv[set] + 6 * src : NULL;
        int finite = uv != NULL;
        for (int c = 0; finite && c < 6; c++) finite = isfinite(uv[c]);
        const ms_texture *tx = finite ? &s->textures[tex] : NULL;
        if (!tx || !tx->rgba || tx->width < 1 || tx->height < 1) continue;   /* the factor alone decides */
        for (int c = 0; c < 6; c++) at->uv[c] = uv[c];
        const ms_texture_sampling *sm = &m->base_color_sampling;   /* KHR_texture_transform: affine, per vertex */
        for (int k = 0; k < 3 && sm->transformed && !grey; k++) {
            const float *q = sm->transform, u0 = uv[2 * k], v0 = uv[2 * k + 1];
            at->uv[2 * k] = q[0] * u0 + q[2] * v0 + q[4];
            at->uv[2 * k + 1] = q[1] * u0 + q[3] * v0 + q[5];
        }
        int32_t *mo = &map_of[2 * (size_t)tex + (size_t)grey];
        if (*mo < 0) {
            if (copy_map(tx, grey, &a->maps[a->n_maps])) { free(map_of); ms_alpha_free(a); return -1; }
            *mo = (int32_t)a->n_maps++;
        }
        at->map = *mo;
    }
    free(map_of);
    *out = a;
    return 0;
}

/* i mod n for a texel index held in a double (huge or negative UVs): the common in-range case without fmod. */
static size_t wrap(double i, int n)
{
    if (i >= 0.0 && i < n) return (size_t)i;
    double w = fmod(i, n);
    if (w < 0) w += n;
    return (size_t)w;
}

/* Bilinear with repeat, texel centres at (i + 0.5) / width (shade.c's sampler), in double; 0..1. */
static double map_bilinear(const ms_alpha_map *m, double u, double v)
{
    const double x = u * m->width - 0.5, y = v * m->height - 0.5;
    const double fx0 = floor(x), fy0 = floor(y);
    const double fx = x - fx0, fy = y - fy0;
    const size_t x0 = wrap(fx0, m->width), y0 = wrap(fy0, m->height);
    const size_t x1 = x0 + 1 == (size_t)m->width ? 0 : x0 + 1, y1 = y0 + 1 == (size_t)m->height ? 0 : y0 + 1;
    const size_t W = (size_t)m->width;
    const double a00 = m->a[y0 * W + x0], a10 = m->a[y0 * W + x1], a01 = m->a[y1 * W + x0], a11 = m->a[y1 * W + x1];
    return ((1.0 - fx) * (1.0 - fy) * a00 + fx * (1.0 - fy) * a10 + (1.0 - fx) * fy * a01 + fx * fy * a11) * (1.0 / 255.0);
}

double ms_alpha_value(const ms_alpha *a, uint32_t prim, const double o[3], const double d[3])
{
    const ms_alpha_tri *t = &a->tri[a->slot[prim]];
    if (t->map < 0) return t->factor;
    const double *n = t->n;
    const double den = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
    if (den == 0.0 || !isfinite(den)) return t->factor;   /* parallel, or a degenerate triangle */
    const double s[3] = { o[0] - t->v0[0], o[1] - t->v0[1], o[2] - t->v0[2] };
    const double u = -(s[0] * n[0] + s[1] * n[1] + s[2] * n[2]) / den;
    const double x[3] = { s[0] + u * d[0], s[1] + u * d[1], s[2] + u * d[2] };   /* X - v0 */
    const double b1 = x[0] * t->g1[0] + x[1] * t->g1[1] + x[2] * t->g1[2];
    const double b2 = x[0] * t->g2[0] + x[1] * t->g2[1] + x[2] * t->g2[2];
    const double b0 = 1.0 - b1 - b2;
    const double tu = b0 * t->uv[0] + b1 * t->uv[2] + b2 * t->uv[4];
    const double tv = b0 * t->uv[1] + b1 * t->uv[3] + b2 * t->uv[5];
    if (!isfinite(tu) || !isfinite(tv)) return t->factor;
    return t->factor * map_bilinear(&a->maps[t->map], tu, tv);
}

int ms_alpha_segment_occludes(const ms_alpha *a, uint32_t prim, const float P[3], const float L[3])
{
    const double o[3] = { P[0], P[1], P[2] };
    const double d[3] = { (double)L[0] - (double)P[0], (double)L[1] - (double)P[1], (double)L[2] - (double)P[2] };
    return ms_alpha_value(a, prim, o, d) >= (double)a->tri[a->slot[prim]].cutoff;
}

int ms_alpha_ray_occludes(const ms_alpha *a, uint32_t prim, const float o[3], const float d[3])
{
    const double od[3] = { o[0], o[1], o[2] }, dd[3] = { d[0], d[1], d[2] };
    return ms_alpha_value(a, prim, od, dd) >= (double)a->tri[a->slot[prim]].cutoff;
}

void ms_alpha_filter_mask(const ms_render_ctx *ctx, const ms_shadow_query *q, uint32_t prim, uint64_t *covered)
{
    float pts[3 * 64];
    for (int w = 0; w < ctx->mask_words; w++) {
        uint64_t bits = covered[w];
        if (!bits) continue;
        /* The word's samples from its lowest covered one to its highest, in one call (one grid set-up). */
        const int lo = __builtin_ctzll(bits), hi = 63 - __builtin_clzll(bits);
        ms_pattern_points_range(ctx->pattern, &ctx->light, ctx->k, q->px, q->py, ctx->seed, 64 * w + lo, hi - lo + 1, pts);
        for (; bits; bits &= bits - 1) {
            const int b = __builtin_ctzll(bits);
            if (!ms_alpha_segment_occludes(ctx->alpha, prim, q->p, pts + 3 * (b - lo))) covered[w] &= ~(UINT64_C(1) << b);
        }
    }
}

void ms_alpha_raster(const ms_alpha_pixel *ap, const ms_raster_frame *f, ms_raster_fn raster, const float tri[9],
                     uint32_t prim, void *buf)
{
    _Alignas(64) uint64_t scratch[64];
    const int mw = ap->ctx->mask_words;   /* k*k/64 (the grid: k = 16, 32, 64) */
    uint64_t *b = buf;                    /* the query's mask words (receiver.h) */
    memset(scratch, 0xFF, (size_t)mw * sizeof *scratch);
    raster(f, tri, scratch);
    uint64_t any = 0;
    for (int w = 0; w < mw; w++) any |= scratch[w] = ~scratch[w] & b[w];
    if (!any) return;
    ms_alpha_filter_mask(ap->ctx, ap->q, prim, scratch);
    for (int w = 0; w < mw; w++) b[w] &= ~scratch[w];
}

int ms_alpha_ray_filter(const void *user, uint32_t prim, const ms_ray *r)
{
    const ms_alpha *a = user;
    return !a->flag[prim] || ms_alpha_ray_occludes(a, prim, r->o, r->d);
}
