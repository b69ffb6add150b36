/* Surface shading of a visible point (docs/shading.md): its material (glTF metallic-roughness), its
 * shading normal, and its radiance from the light with the two shadow factors:
 *   L_o = emission * ( c_diff/pi * E_unshadowed(n_s) * S  +  F * LTC_GGX(n_s, v, roughness) * S_spec )
 * with c_diff = base (1 - metallic), F0 = mix(0.04, base, metallic) and F = F0 + (1 - F0)(1 - n_s.v)^5
 * (Schlick at the view angle: an approximation, the LTC table carries no Fresnel term). S is the
 * form-factor ratio of every method (receiver.h); S_spec the same ratio estimator with specular-lobe
 * weights. Triangles without a material keep the original Lambertian grey (albedo 0.8, no specular). */
#ifndef MS_SHADE_H
#define MS_SHADE_H
#include "microshadow.h"
#include "shadow/method.h"
#include "primary/primary.h"

#define MS_DEFAULT_ALBEDO 0.8f

typedef struct ms_surface {
    float n[3];          /* unit shading normal, on the side of the geometric normal that faces the eye */
    float v[3];          /* unit direction to the eye */
    float diffuse[3];    /* c_diff */
    float f0[3];         /* specular reflectance at normal incidence */
    float roughness;     /* perceptual (glTF); GGX alpha = roughness^2 */
    int specular;        /* 0: Lambert only */
    float emissive[3];   /* emitted radiance (material emission x strength x texture), added once per pixel */
} ms_surface;

/* Barycentric coordinates b of p (on the triangle's plane) in tri (9 floats). */
void ms_barycentric(const float *tri, const float p[3], float b[3]);

/* The shading normal of scene triangle t at barycentrics b: its vertex normals (ms_scene.tri_normal)
 * interpolated and normalised into n, as frames shade (before any normal map; on the side the file gave it).
 * 1, or 0 with n untouched where the triangle has no usable vertex normals. */
int ms_interpolated_normal(const ms_scene *s, size_t t, const float b[3], float n[3]);

/* The tangent frame of scene triangle t where its mesh has no tangents: T = dP/du over UV set `set` (not
 * normalised) and w (+-1) such that w n x T runs up the image (towards decreasing glTF v), as normal maps
 * read it (docs/shading.md). 1, or 0 for degenerate UVs. */
int ms_uv_tangent(const ms_scene *s, size_t t, int32_t set, const float n[3], float T[3], float *w);

/* The surface at a primary hit h of the frame (h->prim: leaf-order id of bvh), seen from eye; shading
 * MS_SHADING_DIFFUSE keeps the base colour as c_diff and drops the specular lobe and the emission. */
void ms_surface_at(const ms_scene *s, const ms_bvh *bvh, const ms_hit *h, const float eye[3], ms_shading shading,
                   ms_surface *out);

/* S_spec = sum_i w_i v_i / sum_i w_i over the front samples, w_i = f_GGX(v, l_i) max(n_s.l_i, 0)
 * max(cos theta_l,i, 0) / r_i^2: the specular lobe's share of the light that is unoccluded, from the same
 * masks as V and S (pts as for ms_resolve_vs). S_spec = V where V is 0 or 1 (exact) and where every
 * weight is 0. */
float ms_resolve_spec(const ms_render_ctx *ctx, const ms_shadow_query *q, const float *pts, const uint64_t *front,
                      const uint64_t *vis, const ms_surface *sf);

/* Linear radiance of the point into rgb[3] with shadow factors s and s_spec; *unshadowed gets the
 * luminance without shadow (for the exposure). */
void ms_shade(const ms_light *l, const float p[3], const ms_surface *sf, float s, float s_spec, float rgb[3],
              float *unshadowed);

#endif
