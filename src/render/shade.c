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

/* Bilinear lookup with repeat (glTF's default sampler), texel centres at (i + 0.5) / width. */
static void texture_rgba(const ms_texture *t, float u, float v, float out[4])
{
    const float x = u * (float)t->width - 0.5f, y = v * (float)t->height - 0.5f;
    const float fx0 = floorf(x), fy0 = floorf(y);
    const float fx = x - fx0, fy = y - fy0;
    /* Wrap in double so that huge UVs do not overflow an int. */
    const long long w = t->width, h = t->height;
    long long x0 = (long long)fmod((double)fx0, (double)w), y0 = (long long)fmod((double)fy0, (double)h);
    if (x0 < 0) x0 += w;
    if (y0 < 0) y0 += h;
    const long long x1 = (x0 + 1) % w, y1 = (y0 + 1) % h;
    for (int c = 0; c < 4; c++) out[c] = 0.0f;
    const long long xs[2] = { x0, x1 }, ys[2] = { y0, y1 };
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            const float wgt = (i ? fx : 1.0f - fx) * (j ? fy : 1.0f - fy);
            const uint8_t *px = t->rgba + 4 * ((size_t)ys[j] * (size_t)w + (size_t)xs[i]);
            for (int c = 0; c < 3; c++) out[c] += wgt * srgb_to_linear(px[c]);
            out[3] += wgt * (float)px[3] / 255.0f;
        }
}

/* Barycentric coordinates of p (on the triangle's plane) in tri. */
static void barycentric(const float *tri, const float p[3], float b[3])
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

void ms_surface_at(const ms_scene *s, const ms_bvh *bvh, const ms_hit *h, const float eye[3], ms_surface *out)
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
    barycentric(s->tri + 9 * t, h->p, b);
    if (s->tri_normal) {
        const float *vn = s->tri_normal + 9 * t;
        float ns[3] = { 0, 0, 0 };
        for (int k = 0; k < 3; k++) v3_madd(ns, ns, vn + 3 * k, b[k]);
        /* Interpolated, normalised, and turned to the eye's side of the surface like h->n. */
        if (v3_finite(ns) && v3_len(ns) > 1e-12f) {
            v3_normalize(ns, ns);
            if (v3_dot(ns, h->n) < 0.0f) v3_scale(ns, ns, -1.0f);
            memcpy(out->n, ns, sizeof ns);
        }
    }
    if (!m) return;
    float base[4] = { m->base_color[0], m->base_color[1], m->base_color[2], m->base_color[3] };
    if (m->base_color_texture >= 0 && (size_t)m->base_color_texture < s->n_textures && m->base_color_uv >= 0 &&
        m->base_color_uv < MS_MAX_UV_SETS && s->tri_uv[m->base_color_uv]) {
        const float *uv = s->tri_uv[m->base_color_uv] + 6 * t;
        const float u = b[0] * uv[0] + b[1] * uv[2] + b[2] * uv[4], v = b[0] * uv[1] + b[1] * uv[3] + b[2] * uv[5];
        const ms_texture *tx = &s->textures[m->base_color_texture];
        if (isfinite(u) && isfinite(v) && tx->rgba && tx->width > 0 && tx->height > 0) {
            float tex[4];
            texture_rgba(tx, u, v, tex);
            for (int c = 0; c < 4; c++) base[c] *= tex[c];
        }
    }
    const float metal = m->metallic;
    for (int c = 0; c < 3; c++) {
        out->diffuse[c] = base[c] * (1.0f - metal);
        out->f0[c] = 0.04f * (1.0f - metal) + base[c] * metal;
    }
    out->roughness = m->roughness;
    out->specular = 1;
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
