/* The plug-in interfaces: a primary-visibility method finds what each pixel sees, a shadow method
 * answers V for visible points. Both see the same render context, so every method works on the same
 * hit points and the same light samples. To add a method: implement one of these structs in its own
 * file and list it in registry.c. */
#ifndef MS_METHOD_H
#define MS_METHOD_H
#include <stddef.h>
#include <stdint.h>
#include "microshadow.h"
#include "../accel/bvh.h"
#include "../camera/camera.h"

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
     * what each buys. */
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

typedef struct ms_shadow_method {
    const char *name;
    const char *primary;          /* primary-visibility method it pairs with ("bvh", "embree") */
    int needs_grid;               /* 1: only the grid pattern fits (micro-rasterization) */
    int streams;                  /* 1: reads the triangles once in batches, never all at once: a procedural
                                   * scene is streamed (primary "depth", no BVH), not materialised */
    int n_counters;
    const char *counter_names[MS_MAX_COUNTERS];
    /* Per-frame set-up (shared, read-only afterwards); 0 or -1 with a message in err. */
    int (*create)(const ms_render_ctx *ctx, void **state, char *err, size_t errlen);
    /* For n queries: front + i*ctx->mask_words holds the samples in front of query i's plane (receiver.h);
     * the method writes to vis + i*ctx->mask_words the subset no triangle occludes (a sample behind is
     * never visible). Thread-safe; adds to counters[n_counters] (thread-private). 0, or -1 when out of
     * memory. */
    int (*visibility)(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, int n,
                      const uint64_t *front, uint64_t *vis, uint64_t *counters);
    void (*destroy)(void *state);
    /* Optional whole-frame entry (NULL: per tile through visibility). For methods that need every receiver of
     * the frame at once (hpc: triangle order over a hierarchy of all hit points): n queries, their front and
     * visible masks as for visibility; called once per frame from one thread (the method threads itself,
     * ctx->threads), counters summed over its threads. The renderer resolves V and S from the masks as for
     * every method (ms_resolve_vs). 0, or -1 when out of memory. */
    int (*visibility_all)(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, size_t n,
                          const uint64_t *front, uint64_t *vis, uint64_t *counters);
    /* With visibility_all: 1 when a receiver's masks do not depend on the other receivers of the call (hpc:
     * every sample decided by raytrace's exact test), so a frame may be split into parts (ms_frame_job, e.g.
     * over MPI ranks) with the same answer; 0 (hpc-scanline: which triangles its hierarchy rasterizes for a
     * receiver, and so its rounding at their edges, depends on all receivers): only whole frames. */
    int split_exact;
    /* Optional (NULL: the method has no ISA-dispatched code): the instruction sets its kernel and its
     * traversal run, as chosen by create under ctx->isa_cap, for ms_stats. */
    void (*isa_used)(const void *state, ms_isa *kernel, ms_isa *traversal);
    /* Optional (NULL: n_counters and counter_names): the counters this state fills, when they depend on
     * the frame's options (e.g. the traversal); returns their number and sets *names, or -1 for the
     * static ones. */
    int (*counters_used)(const void *state, const char *const **names);
} ms_shadow_method;

typedef struct ms_hit {
    float p[3], n[3];
    uint32_t prim;               /* UINT32_MAX: the ray missed */
} ms_hit;

typedef struct ms_primary_method {
    const char *name;
    int (*create)(const ms_render_ctx *ctx, void **state, char *err, size_t errlen);
    /* Hits for pixels [x0,x1) x [y0,y1), row-major into out. Thread-safe. */
    void (*trace)(void *state, const ms_render_ctx *ctx, int x0, int y0, int x1, int y1, ms_hit *out);
    void (*destroy)(void *state);
} ms_primary_method;

/* Known methods, compiled in or not (registry.c). */
const ms_shadow_method *ms_find_shadow_method(const char *name);
const ms_primary_method *ms_find_primary_method(const char *name);

/* Finishes a hit from a ray and a hit triangle: the point o + t d (not lifted: the horizon and the near
 * range make V independent of which side of the surface rounding puts it), and the unit normal facing
 * the ray's origin. Shared by every primary method so that all agree on the receiver. */
void ms_hit_finish(const ms_render_ctx *ctx, const float o[3], const float d[3], float t, uint32_t prim,
                   ms_hit *h);

/* The reference answer for one point (raytrace.c): writes to vis the front samples that are unoccluded and
 * returns their number. pts: scratch for 3*k*k floats; cnt: the raytrace method's 3 counters. */
int ms_raytrace_visible_samples(const ms_render_ctx *ctx, const ms_shadow_query *q, float *pts,
                                const uint64_t *front, uint64_t *vis, uint64_t *cnt);

#endif
