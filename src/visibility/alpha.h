/* Alpha-tested occluders (issue 15, item 6; docs/design.md, "Visibility, precisely"): the ONE decision every
 * method asks once its own geometric test has found that a segment (or a camera ray) meets a triangle whose
 * material is alpha-tested. The answer is a pure function of (triangle, P, L) — or of (triangle, o, d) for a
 * ray — so that every method, every ISA and every traversal gives bit-identical decisions:
 *
 *   - the barycentrics of the point X where the line P + u (L - P) meets the triangle's plane, in double
 *     precision from the triangle's vertices (the BVH's leaf-order copy: the scene's floats) and d = L - P
 *     formed in double: with N = e1 x e2 (e1 = v1 - v0, e2 = v2 - v0), u = ((v0 - P) . N) / (d . N),
 *     X - v0 = (P - v0) + u d, b1 = (X - v0) . (e2 x N) / |N|^2, b2 = (X - v0) . (N x e1) / |N|^2 (the
 *     vectors per triangle precomputed at set-up);
 *   - the UVs of the material's texture set interpolated with them (double);
 *   - alpha = the material's alpha factor times the texture's value there: the base-colour texture's alpha
 *     channel (glTF; bilinear with repeat, texel centres at (i + 0.5) / width, like the base colour in
 *     shade.c, but computed in double) or the MTL map_d value (its alpha channel, or its red channel when
 *     the image is opaque everywhere, i.e. a grey mask), the same filter;
 *   - the triangle occludes there iff alpha >= cutoff. A line parallel to the plane (d . N = 0), a degenerate
 *     triangle (N = 0), UVs that are not finite, or a material whose texture is missing: the factor alone
 *     decides.
 *
 * Set-up (ms_alpha_build, once per frame or accel): a flag byte per leaf-order triangle (0 opaque: an opaque
 * scene pays one load, or nothing when ms_alpha is absent), and for alpha-tested triangles the vertex and
 * edge vectors in double, the UVs, factor and cutoff, and the alpha channel of their textures copied (one byte
 * per texel), so that the structure outlives the scene (ms_accel). */
#ifndef MS_ALPHA_H
#define MS_ALPHA_H
#include <stddef.h>
#include <stdint.h>
#include "microshadow.h"
#include "visibility/context.h"
#include "accel/bvh.h"
#include "raster/raster.h"

typedef struct ms_alpha_tri {
    double v0[3], n[3];          /* vertex 0 and the plane normal N = e1 x e2, in double */
    double g1[3], g2[3];         /* (e2 x N) / |N|^2 and (N x e1) / |N|^2: b1, b2 = (X - v0) . g1, g2 */
    double uv[6];                /* (u, v) of the three vertices in the material's texture set */
    float factor, cutoff;        /* alpha = factor * texture; occludes iff alpha >= cutoff */
    int32_t map;                 /* index into ms_alpha.maps, -1: none */
} ms_alpha_tri;

typedef struct ms_alpha_map {
    int width, height;
    uint8_t *a;                  /* width * height alpha values, row 0 at v = 0 */
} ms_alpha_map;

typedef struct ms_alpha {
    uint8_t *flag;               /* per leaf-order triangle: 0 opaque, 1 alpha-tested */
    uint32_t *slot;              /* per leaf-order triangle: its index into tri (flagged ones only) */
    ms_alpha_tri *tri;
    size_t n_tris, n_alpha;
    ms_alpha_map *maps;
    size_t n_maps;
} ms_alpha;

/* The alpha set-up of the scene's triangles in the BVH's leaf order. *out = NULL (and 0) when no triangle is
 * alpha-tested: callers then skip every test. 0, or -1 when out of memory. */
int ms_alpha_build(const ms_scene *s, const ms_bvh *b, ms_alpha **out);
void ms_alpha_free(ms_alpha *a);

/* 1 when leaf-order triangle prim needs the alpha test (a NULL table: none does). */
static inline int ms_alpha_tested(const ms_alpha *a, uint32_t prim) { return a && a->flag[prim]; }

/* The alpha of triangle prim (alpha-tested) where the line o + u d meets its plane. */
double ms_alpha_value(const ms_alpha *a, uint32_t prim, const double o[3], const double d[3]);

/* 1 when alpha-tested triangle prim occludes the segment from P to L where the segment's line meets its plane
 * (alpha >= cutoff), 0 where it is transparent there. The shadow methods' decision. */
int ms_alpha_segment_occludes(const ms_alpha *a, uint32_t prim, const float P[3], const float L[3]);

/* The same for a camera ray o + t d (t > 0 along d; d need not be unit): 1 when the hit counts, 0 when the
 * ray passes through a transparent texel. For primary methods (closest hit with this as the any-hit filter);
 * t is not needed: the line alone decides. */
int ms_alpha_ray_occludes(const ms_alpha *a, uint32_t prim, const float o[3], const float d[3]);

/* The same as a BVH closest-hit filter (ms_bvh_closest_filter; user: the const ms_alpha *): 1 for an opaque
 * triangle, else ms_alpha_ray_occludes on the ray's origin and direction. For primary methods. */
int ms_alpha_ray_filter(const void *user, uint32_t prim, const ms_ray *r);

/* ---- For the micro-rasterization methods (microraster.c, block_raster_impl.h, hpc.c) ----
 *
 * A query's alpha context, hung on its ms_raster_frame (frame.alpha) when ctx->alpha is set. The kernels never see
 * it: the traversals route an alpha-tested triangle through ms_alpha_raster instead of the kernel. */
typedef struct ms_alpha_pixel {
    const ms_render_ctx *ctx;
    const ms_shadow_query *q;
} ms_alpha_pixel;

/* Clears from covered (ctx->mask_words words, bit s = sample s of q's pattern) every sample where alpha-tested
 * triangle prim is transparent: ms_alpha_segment_occludes(q->p, L_s), L_s the pattern's sample point
 * (ms_pattern_points_range, the floats every method traces). */
void ms_alpha_filter_mask(const ms_render_ctx *ctx, const ms_shadow_query *q, uint32_t prim, uint64_t *covered);

/* An alpha-tested triangle into a k x k buffer (k*k/64 words, bit s = sample s): the kernel rasterizes its
 * coverage into a scratch buffer of ones as it would into buf; of the covered samples still visible in buf,
 * those where it is opaque (ms_alpha_filter_mask) are cleared in buf. Cost: one more kernel call into
 * the scratch, its clear and merge (k*k/64 words), and one alpha lookup per covered visible sample, which
 * dominates: measured (bench/bench_alpha, k = 32, AVX-512) ~330 cycles per covered visible sample, a median
 * of ~8 800 cycles per (point, triangle) pair against 208 for the kernel alone (docs/shading.md). */
void ms_alpha_raster(const ms_alpha_pixel *ap, const ms_raster_frame *f, ms_raster_fn raster, const float tri[9],
                     uint32_t prim, void *buf);

/* The traversals' call for every triangle they would hand to the kernel: the kernel itself for an opaque
 * triangle (one load and a predicted branch when the frame has no alpha context), ms_alpha_raster for an
 * alpha-tested one. */
/* 1 when frame f tests triangle prim for alpha (its samples go through ms_alpha_raster), 0 when it is opaque. */
static inline int ms_frame_alpha_tested(const ms_raster_frame *f, uint32_t prim)
{
    const ms_alpha_pixel *ap = (const ms_alpha_pixel *)f->alpha;
    return ap && ap->ctx->alpha->flag[prim];
}

static inline void ms_raster_or_alpha(const ms_raster_frame *f, ms_raster_fn raster, const float tri[9], uint32_t prim,
                                      void *buf)
{
    if (ms_frame_alpha_tested(f, prim)) ms_alpha_raster((const ms_alpha_pixel *)f->alpha, f, raster, tri, prim, buf);
    else raster(f, tri, buf);
}

#endif
