/* Materials at hit points, the specular shadow factor and the shaded radiance (shade.h). */
#include "shade.h"
#include "primary/primary.h"
#include "brdf_ggx.h"
#include "ltc.h"
#include "light/pattern.h"
#include "core/vec.h"
#include "light/light_frame.h"
#include "visibility/receiver.h"
#include <math.h>
#include <string.h>

static float srgb_to_linear(uint8_t c)
{
    const float x = (float)c / 255.0f;
    return x <= 0.04045f ? x / 12.92f : powf((x + 0.055f) / 1.055f, 2.4f);
}

/* Texel index i (a floor, held in a float) wrapped into 0..n-1 by the sampler's mode; in double so that
 * huge UVs do not overflow an int. */
static long long wrap_index(float i, long long n, int mode)
{
    if (mode == MS_WRAP_CLAMP) return i <= 0.0f ? 0 : i >= (float)n ? n - 1 : (long long)i;
    const long long period = mode == MS_WRAP_MIRROR ? 2 * n : n;
    long long k = (long long)fmod((double)i, (double)period);
    if (k < 0) k += period;
    return k < n ? k : period - 1 - k;
}

/* The texture at (u, v) (texel centres at (i + 0.5) / width) through the material's sampling: its
 * transform, then bilinear or nearest, with repeat (glTF's default), clamp or mirrored repeat. Colour
 * channels sRGB-decoded when srgb, else raw / 255 (normal maps). */
static int texture_rgba(const ms_texture *t, const ms_texture_sampling *sm, float u, float v, int srgb, float out[4])
{
    if (sm->transformed) {
        const float *m = sm->transform;
        const float tu = m[0] * u + m[2] * v + m[4], tv = m[1] * u + m[3] * v + m[5];
        u = tu;
        v = tv;
    }
    const long long w = t->width, h = t->height;
    for (int c = 0; c < 4; c++) out[c] = 0.0f;
    /* A transform can take finite UVs to infinity or NaN (found by rendering the fuzz corpora): nothing is
     * read there. Below 1e30, u * w (w <= MS_MAX_IMAGE_SIZE) stays finite and the index arithmetic exact. */
    if (!(fabsf(u) < 1e30f) || !(fabsf(v) < 1e30f)) return 0;
    if (sm->nearest) {
        const long long x = wrap_index(floorf(u * (float)w), w, sm->wrap_s), y = wrap_index(floorf(v * (float)h), h, sm->wrap_t);
        const uint8_t *px = t->rgba + 4 * ((size_t)y * (size_t)w + (size_t)x);
        for (int c = 0; c < 3; c++) out[c] = srgb ? srgb_to_linear(px[c]) : (float)px[c] / 255.0f;
        out[3] = (float)px[3] / 255.0f;
        return 1;
    }
    const float x = u * (float)w - 0.5f, y = v * (float)h - 0.5f;
    const float fx0 = floorf(x), fy0 = floorf(y);
    const float fx = x - fx0, fy = y - fy0;
    long long x0, y0, x1, y1;
    if (sm->wrap_s == MS_WRAP_REPEAT) {   /* the original repeat arithmetic, kept bit for bit */
        x0 = (long long)fmod((double)fx0, (double)w);
        if (x0 < 0) x0 += w;
        x1 = (x0 + 1) % w;
    } else {
        x0 = wrap_index(fx0, w, sm->wrap_s);
        x1 = wrap_index(fx0 + 1.0f, w, sm->wrap_s);
    }
    if (sm->wrap_t == MS_WRAP_REPEAT) {
        y0 = (long long)fmod((double)fy0, (double)h);
        if (y0 < 0) y0 += h;
        y1 = (y0 + 1) % h;
    } else {
        y0 = wrap_index(fy0, h, sm->wrap_t);
        y1 = wrap_index(fy0 + 1.0f, h, sm->wrap_t);
    }
    const long long xs[2] = { x0, x1 }, ys[2] = { y0, y1 };
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            const float wgt = (i ? fx : 1.0f - fx) * (j ? fy : 1.0f - fy);
            const uint8_t *px = t->rgba + 4 * ((size_t)ys[j] * (size_t)w + (size_t)xs[i]);
            for (int c = 0; c < 3; c++) out[c] += wgt * (srgb ? srgb_to_linear(px[c]) : (float)px[c] / 255.0f);
            out[3] += wgt * (float)px[3] / 255.0f;
        }
    return 1;
}

/* The material's texture tex at the hit (barycentrics b of triangle t, UV set set); 0 when it has none
 * there (no UVs, non-finite UVs or UVs the texture transform takes beyond 1e30, an empty texture). */
static int lookup(const ms_scene *s, size_t t, const float b[3], int32_t tex, int32_t set, const ms_texture_sampling *sm,
                  int srgb, float out[4])
{
    if (tex < 0 || (size_t)tex >= s->n_textures || set < 0 || set >= MS_MAX_UV_SETS || !s->tri_uv[set]) return 0;
    const float *uv = s->tri_uv[set] + 6 * t;
    const float u = b[0] * uv[0] + b[1] * uv[2] + b[2] * uv[4], v = b[0] * uv[1] + b[1] * uv[3] + b[2] * uv[5];
    const ms_texture *tx = &s->textures[tex];
    if (!isfinite(u) || !isfinite(v) || !tx->rgba || tx->width <= 0 || tx->height <= 0) return 0;
    return texture_rgba(tx, sm, u, v, srgb, out);
}

int ms_uv_tangent(const ms_scene *s, size_t t, int32_t set, const float n[3], float T[3], float *w)
{
    float B[3], nb[3];
    const float *p = s->tri + 9 * t, *uv = s->tri_uv[set] + 6 * t;
    float e1[3], e2[3];
    v3_sub(e1, p + 3, p);
    v3_sub(e2, p + 6, p);
    const float du1 = uv[2] - uv[0], dv1 = uv[3] - uv[1], du2 = uv[4] - uv[0], dv2 = uv[5] - uv[1];
    const float r = du1 * dv2 - du2 * dv1;
    if (!(fabsf(r) > 0.0f)) return 0;
    for (int c = 0; c < 3; c++) {
        T[c] = (e1[c] * dv2 - e2[c] * dv1) / r;   /* dP/du */
        B[c] = (e1[c] * du2 - e2[c] * du1) / r;   /* -dP/dv: up the image */
    }
    v3_cross(nb, n, T);
    *w = v3_dot(nb, B) < 0.0f ? -1.0f : 1.0f;
    return 1;
}

/* The normal map's perturbation of the unit shading normal n (before it is turned to the eye): texel t ->
 * (x, y, z) = 2 t - 1 (linear), x and y times the scale; n' = normalize(x T + y B + z n) with T the tangent
 * made orthogonal to n and B = w n x T (glTF). The tangent: the scene's (the asset's TANGENT, or MikkTSpace
 * at load) interpolated at the hit; else one frame per triangle, T = dP/du and w such that B runs up the
 * image (towards decreasing glTF v), which MikkTSpace's frame equals where the triangle's UVs are an affine
 * map of a flat patch (docs/shading.md). */
static void normal_map(const ms_scene *s, size_t t, const float b[3], const ms_material *m, float n[3])
{
    float tex[4];
    if (!lookup(s, t, b, m->normal_texture, m->normal_uv, &m->normal_sampling, 0, tex)) return;
    float T[3] = { 0, 0, 0 }, nb[3], tn[3], out[3];
    const float *tg = s->tri_tangent ? s->tri_tangent + 12 * t : NULL;
    for (int k = 0; tg && k < 12; k++)
        if (!isfinite(tg[k])) tg = NULL;
    float w = 1.0f;
    if (tg) {
        for (int k = 0; k < 3; k++) v3_madd(T, T, tg + 4 * k, b[k]);
        w = tg[3] < 0.0f ? -1.0f : 1.0f;
    } else if (!ms_uv_tangent(s, t, m->normal_uv, n, T, &w))
        return;   /* degenerate UVs: no tangent frame */
    v3_madd(T, T, n, -v3_dot(n, T));
    if (!v3_finite(T) || !(v3_len(T) > 1e-20f)) return;
    v3_normalize(T, T);
    v3_cross(nb, n, T);
    v3_scale(nb, nb, w);
    for (int c = 0; c < 3; c++) tn[c] = 2.0f * tex[c] - 1.0f;
    tn[0] *= m->normal_scale;
    tn[1] *= m->normal_scale;
    for (int c = 0; c < 3; c++) out[c] = tn[0] * T[c] + tn[1] * nb[c] + tn[2] * n[c];
    if (!v3_finite(out) || !(v3_len(out) > 1e-12f)) return;
    v3_normalize(n, out);
}

void ms_barycentric(const float *tri, const float p[3], float b[3])
{
    float e1[3], e2[3], d[3], n[3], c1[3], c2[3];
    v3_sub(e1, tri + 3, tri);
    v3_sub(e2, tri + 6, tri);
    v3_sub(d, p, tri);
    v3_cross(n, e1, e2);
    const float nn = v3_dot(n, n);
    if (!(nn > 0.0f)) { b[0] = 1.0f; b[1] = b[2] = 0.0f; return; }
    v3_cross(c1, d, e2);
    v3_cross(c2, e1, d);
    b[1] = v3_dot(c1, n) / nn;
    b[2] = v3_dot(c2, n) / nn;
    b[0] = 1.0f - b[1] - b[2];
}

int ms_interpolated_normal(const ms_scene *s, size_t t, const float b[3], float n[3])
{
    if (!s->tri_normal) return 0;
    const float *vn = s->tri_normal + 9 * t;
    float ni[3] = { 0, 0, 0 };
    for (int k = 0; k < 3; k++) v3_madd(ni, ni, vn + 3 * k, b[k]);
    if (!(v3_finite(ni) && v3_len(ni) > 1e-12f)) return 0;
    v3_normalize(n, ni);
    return 1;
}

void ms_surface_at(const ms_scene *s, const ms_bvh *bvh, const ms_hit *h, const float eye[3], ms_shading shading,
                   ms_surface *out)
{
    memset(out, 0, sizeof *out);
    memcpy(out->n, h->n, sizeof out->n);
    v3_sub(out->v, eye, h->p);
    v3_normalize(out->v, out->v);
    for (int c = 0; c < 3; c++) out->diffuse[c] = MS_DEFAULT_ALBEDO;
    out->roughness = 1.0f;
    if (!bvh || !bvh->tri_source || h->prim == UINT32_MAX) return;
    const size_t t = bvh->tri_source[h->prim];
    const uint32_t mi = s->tri_material ? s->tri_material[t] : MS_NO_MATERIAL;
    const ms_material *m = mi < s->n_materials ? &s->materials[mi] : NULL;
    float b[3];
    ms_barycentric(s->tri + 9 * t, h->p, b);
    float ns[3];
    memcpy(ns, h->n, sizeof ns);
    ms_interpolated_normal(s, t, b, ns);
    /* The normal map perturbs the interpolated normal on its own side of the surface; then the result is
     * turned to the eye's side of the surface like h->n. */
    if (m && m->normal_map) normal_map(s, t, b, m, ns);
    if (v3_dot(ns, h->n) < 0.0f) v3_scale(ns, ns, -1.0f);
    memcpy(out->n, ns, sizeof ns);
    if (!m) return;
    float base[4] = { m->base_color[0], m->base_color[1], m->base_color[2], m->base_color[3] }, tex[4];
    if (lookup(s, t, b, m->base_color_texture, m->base_color_uv, &m->base_color_sampling, 1, tex))
        for (int c = 0; c < 4; c++) base[c] *= tex[c];
    for (int c = 0; c < 3; c++) out->emissive[c] = m->emissive[c];
    if (m->emissive_map && lookup(s, t, b, m->emissive_texture, m->emissive_uv, &m->emissive_sampling, 1, tex))
        for (int c = 0; c < 3; c++) out->emissive[c] *= tex[c];
    float metal = m->metallic, rough = m->roughness;
    if (m->mr_map && lookup(s, t, b, m->mr_texture, m->mr_uv, &m->mr_sampling, 0, tex)) {
        metal *= tex[2];
        rough *= tex[1];
    }
    for (int c = 0; c < 3; c++) {
        out->diffuse[c] = base[c] * (1.0f - metal);
        out->f0[c] = 0.04f * (1.0f - metal) + base[c] * metal;
    }
    out->roughness = rough;
    out->specular = 1;
    if (shading == MS_SHADING_DIFFUSE) {   /* what a lightmap gives an engine's unlit base colour */
        for (int c = 0; c < 3; c++) { out->diffuse[c] = base[c]; out->emissive[c] = 0.0f; }
        out->specular = 0;
    }
}

float ms_resolve_spec(const ms_render_ctx *ctx, const ms_shadow_query *q, const float *pts, const uint64_t *front,
                      const uint64_t *vis, const ms_surface *sf)
{
    const int nw = ctx->mask_words, k = ctx->k;
    const int nf = ms_mask_count(front, nw), nv = ms_mask_count(vis, nw);
    const float v = nf ? (float)nv / (float)nf : 0.0f;
    if (nv == 0 || nv == nf) return v;   /* exact: the light wholly hidden or wholly visible */
    const ms_light *L = &ctx->light;
    ms_light_frame F;
    ms_light_frame_of(L, &F);
    float nl[3];   /* the light's unit normal */
    v3_normalize(nl, F.normal);
    /* The lobe weight of ms_ggx_f_cos with what is constant per pixel taken out: D G2 / (4 n.v) with
     * n.h^2 = (n.l + n.v)^2 / |v + l|^2 (no normalisation of h) and Lambda(v) once. */
    const float alpha = ms_ggx_alpha(sf->roughness), a2 = alpha * alpha;
    const float cv = v3_dot(sf->n, sf->v);
    if (!(cv > 0.0f)) return v;   /* the eye below the shading normal's plane: no lobe */
    const float lv = cv >= 1.0f ? 0.0f : 0.5f * (-1.0f + sqrtf(1.0f + a2 * (1.0f - cv * cv) / (cv * cv)));
    ms_grid g;
    if (!pts) ms_grid_for_pixel(L, k, q->px, q->py, ctx->seed, &g);
    double wf = 0.0, wv = 0.0;
    for (int s = 0; s < ctx->samples; s++) {
        if (!ms_mask_get(front, s)) continue;
        float lp[3], d[3];
        if (pts) memcpy(lp, pts + 3 * s, sizeof lp);
        else {
            const int i = s % k, j = s / k;
            for (int c = 0; c < 3; c++) lp[c] = g.p0[c] + (float)i * g.ds[c] + (float)j * g.dt[c];
        }
        v3_sub(d, lp, q->p);
        const float r2 = v3_dot(d, d);
        if (!(r2 > 0.0f)) continue;
        const float inv_r = 1.0f / sqrtf(r2);
        const float cl = -v3_dot(d, nl) * inv_r;
        const float nl_ = v3_dot(d, sf->n) * inv_r;
        if (!(cl > 0.0f) || !(nl_ > 0.0f)) continue;
        const float vl = v3_dot(d, sf->v) * inv_r;
        const float hh = 2.0f + 2.0f * vl;   /* |v + l|^2 */
        if (!(hh > 0.0f)) continue;
        const float nh2 = (nl_ + cv) * (nl_ + cv) / hh;
        const float d0 = nh2 * (a2 - 1.0f) + 1.0f;
        const float ll = nl_ >= 1.0f ? 0.0f : 0.5f * (-1.0f + sqrtf(1.0f + a2 * (1.0f - nl_ * nl_) / (nl_ * nl_)));
        /* D G2 / (4 n.v) * cos_l / r^2, dropping the constants a2 / (4 pi n.v) common to every sample. */
        const float w = cl / (r2 * d0 * d0 * (1.0f + lv + ll));
        wf += w;
        if (ms_mask_get(vis, s)) wv += w;
    }
    return wf > 0.0 ? (float)(wv / wf) : v;
}

void ms_shade(const ms_light *l, const float p[3], const ms_surface *sf, float s, float s_spec, float rgb[3],
              float *unshadowed)
{
    const float irr = ms_light_irradiance(l, p, sf->n);
    const float em[3] = { l->emission.x, l->emission.y, l->emission.z };
    float spec[3] = { 0, 0, 0 };
    if (sf->specular) {
        const float ltc = ms_ltc_ggx(l, p, sf->n, sf->v, sf->roughness);
        float c = 1.0f - ms_maxf(ms_minf(v3_dot(sf->n, sf->v), 1.0f), 0.0f);
        const float c5 = c * c * c * c * c;
        for (int i = 0; i < 3; i++) spec[i] = (sf->f0[i] + (1.0f - sf->f0[i]) * c5) * ltc;
    }
    float lum = 0.0f;
    static const float Y[3] = { 0.2126f, 0.7152f, 0.0722f };
    for (int i = 0; i < 3; i++) {
        const float d = irr * sf->diffuse[i] / (float)M_PI;   /* the order the grey-only shading had */
        rgb[i] = d * em[i] * s + spec[i] * em[i] * s_spec;
        lum += Y[i] * em[i] * (d + spec[i]);
    }
    *unshadowed = lum;
}
