/* What every primary and shadow method of a frame (or a points call) sees: the render context, so that
 * all work on the same hit points and the same light samples, and one visible point, the shadow query.
 * Below both method families (docs/design.md, "Layers"). */
#ifndef MS_CONTEXT_H
#define MS_CONTEXT_H
#include <stddef.h>
#include <stdint.h>
#include "microshadow.h"
#include "accel/bvh.h"
#include "camera/camera.h"

typedef struct ms_render_ctx {
    const ms_scene *scene;
    const ms_bvh *bvh;             /* triangles in leaf order; prim ids index bvh->tri */
    ms_camera_basis cam;
    ms_light light;
    ms_pattern pattern;
    int k, samples;                /* N = k*k samples in all; samples: per pixel, k*k, or k*k/16 for the
                                    * interleaved pattern (ms_pattern_spp); always a multiple of 16 */
    int mask_words;                /* 64-bit words of one sample mask: ceil(samples / 64), bits past
                                    * samples 0 (receiver.h) */
    uint32_t seed;
    float near, far;               /* occluding range of the segment parameter from hit point to sample */
    int threads;
    /* Switches of the micro-rasterization methods (zero: the defaults). isa_cap caps the instruction set
     * of the kernels and the traversal (MS_ISA_AUTO: the CPU's best); no_occlusion_cull and
     * no_child_order switch off the traversal's coverage test and near-first child order, to measure
     * what each buys: no driver sets them (they are not among the render options), only tests that build
     * a context themselves. */
    ms_isa isa_cap;
    int no_occlusion_cull, no_child_order;
    ms_traversal traversal;            /* micro-raster methods: block or per-pixel traversal */
    int queries_in_order;              /* 1: queries come in proximity order (the points API), so block
                                        * methods group consecutive ones; 0: by 4x4 pixel block (frames) */
    int frustum_shrink;
    ms_embree_mode embree_mode;        /* embree: how rays are handed over, and when the receiver is filtered */
    ms_embree_filter embree_filter;
    /* Alpha-tested triangles (alpha.h: ms_alpha_build), NULL when every triangle is opaque. A method that finds
     * a segment or ray meeting a flagged triangle asks ms_alpha_segment_occludes / ms_alpha_ray_occludes. */
    const struct ms_alpha *alpha;
    /* With a light's occluders (occluders.h) in bvh and alpha: the occluder prim of each prim of the scene's
     * BVH, whose ids the primary's hits carry (UINT32_MAX: culled); NULL: the same ids. Receivers' prim ids
     * go through ms_ctx_skip_prim. */
    const uint32_t *prim_map;
    /* With merged coplanar faces in bvh (occluders.h): per prim of the scene's BVH, 1 when a receiver on it
     * is to be answered by the driver on the scene's own triangles; NULL: none. */
    const uint8_t *prim_merged;
    /* The light's interior boxes (occluders.h, accel/interior.h) as triangles, NULL: none. Every segment
     * one of them meets is occluded; the micro-rasterization methods rasterize them first. */
    const ms_bvh *interior;
    /* The same boxes whole (with interior): a BVH with one prim per box, and per prim (its leaf order) the box,
     * min x, y, z, max x, y, z. */
    const ms_bvh *interior_box_bvh;
    const float (*interior_box)[6];
    int consistent_primary;            /* bvh primary: the 3D edge-function test (edge3d.h) in its leaves */
    /* 1: light is a shape with an outline (light_shape.h: the sun, the sphere) and each query's own light is
     * its outline seen from the query's point (ms_ctx_for_query). Set by the drivers only for a method that
     * declares .outlines (shadow/method.h); the others are called one query at a time with the outline
     * itself in light. */
    int outline_per_query;
} ms_render_ctx;

/* One visible point: the pixel, its hit point, the unit geometric normal facing the camera (its plane is
 * the receiver's horizon), and the hit triangle, which never occludes (UINT32_MAX: none, for points of
 * the points API that lie on no triangle). */
typedef struct ms_shadow_query {
    float p[3];
    float n[3];
    uint32_t prim;
    uint32_t px, py;
} ms_shadow_query;

/* The context query q is answered in: ctx itself, or, when ctx->outline_per_query, a copy in *own whose light
 * is q's own, the outline of ctx->light seen from q->p, made by the same call (the shape's outline hook) on
 * the same floats as the drivers' one-query-at-a-time path, so own equals the context that path hands the
 * method, field for field. A query the outline refuses (inside a sphere) never reaches a method. */
const ms_render_ctx *ms_ctx_for_query(const ms_render_ctx *ctx, const ms_shadow_query *q, ms_render_ctx *own);

/* The prim id a shadow method skips for a receiver on the scene's triangle prim (ctx->prim_map). */
/* The context of the interior boxes' own pass (a method that leaves them to the driver: MS_OCC_INTERIOR_PASS in
 * occluders.h): c with its boxes as the occluders and nothing else (no receiver is on a box: no prim to skip). */
static inline void ms_ctx_interior_pass(const ms_render_ctx *c, ms_render_ctx *out)
{
    *out = *c;
    out->bvh = c->interior;
    out->interior = NULL;
    out->interior_box_bvh = NULL;
    out->interior_box = NULL;
    out->alpha = NULL;
    out->prim_map = NULL;
    out->prim_merged = NULL;
}

static inline uint32_t ms_ctx_skip_prim(const ms_render_ctx *ctx, uint32_t prim)
{
    return ctx->prim_map && prim != UINT32_MAX ? ctx->prim_map[prim] : prim;
}

/* The occluding range of the segment parameter from the hit point (0) to the light sample (1): occluders
 * closer than MS_SEGMENT_NEAR to the receiver are ignored (its own surface, whichever side rounding left
 * the hit point on), and those within 1 - MS_SEGMENT_FAR of the light's plane (a light set into a
 * ceiling). Frames, points and bakes use the same, so that they agree bit for bit (test_points). */
#define MS_SEGMENT_NEAR 1e-4f
#define MS_SEGMENT_FAR (1.0f - 1e-4f)

/* The one way to fill a render context: zero, then the scene, its BVH (NULL: a streamed scene), the light,
 * (NULL: set by the caller), the pattern with k samples per side (samples per point and mask words follow from the pattern), the
 * seed, the threads and the segment range; the instruction-set cap MS_ISA_AUTO. The camera, the alpha
 * table and the methods' switches are the caller's to set afterwards. */
void ms_render_ctx_init(ms_render_ctx *ctx, const ms_scene *scene, const ms_bvh *bvh, const ms_light *light,
                        ms_pattern pattern, int k, uint32_t seed, int threads);

#endif
