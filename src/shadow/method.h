/* The shadow-method interface: a shadow method answers, for visible points, which of their front light
 * samples no triangle occludes. It sees the render context every method shares (visibility/context.h). To
 * add a method: implement ms_shadow_method in its own folder under src/shadow/ and list it in registry.c
 * (CONTRIBUTING.md). */
#ifndef MS_METHOD_H
#define MS_METHOD_H
#include <stddef.h>
#include <stdint.h>
#include "microshadow.h"
#include "visibility/context.h"

typedef struct ms_shadow_method {
    const char *name;
    const char *primary;          /* primary-visibility method it pairs with ("bvh", "embree") */
    int needs_grid;               /* 1: only the grid pattern fits (micro-rasterization) */
    int streams;                  /* 1: reads the triangles once in batches, never all at once: a procedural
                                   * scene is streamed (primary "depth", no BVH), not materialised */
    int occluders;                /* what it takes of a light's occluders (visibility/occluders.h, MS_OCC_*):
                                   * MS_OCC_CULL: the culled BVH in ctx->bvh with ctx->prim_map (when the
                                   * options ask for the cull; MS_OCC_CULL_BY_DEFAULT: unless they refuse it);
                                   * MS_OCC_INTERIOR: ctx->interior; MS_OCC_MERGE: coplanar rectangles merged
                                   * in that BVH (ties may move). 0: the scene's
                                   * BVH alone (streamed or own-indexed methods, and Embree, the baseline as
                                   * its users run it) */
    /* Optional (NULL: never): 1 when the method, created with ctx (its k, ISA cap and traversal), rasterizes the
     * interior boxes whole (ctx->interior_box_bvh), for which the driver finds them on a finer grid
     * (MS_OCC_INTERIOR_SILHOUETTE, visibility/occluders.h). */
    int (*interior_silhouettes)(const ms_render_ctx *ctx);
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
    /* 1: visibility takes a batch of queries under a light with an outline (the sun, the sphere:
     * ctx->outline_per_query) and answers each on its own light (ms_ctx_for_query), as it would one query at
     * a time, so that it keeps what it shares across queries (the micro-rasterization methods' 4x4 blocks).
     * 0: the drivers call it one query at a time with the query's outline in ctx->light. */
    int outlines;
} ms_shadow_method;

/* Known shadow methods, compiled in or not (registry.c). */
const ms_shadow_method *ms_find_shadow_method(const char *name);
/* "auto" (MS_AUTO_METHOD): the method measured fastest for the pattern (registry.c says from which figures). */
const char *ms_auto_method(ms_pattern pattern);

#endif
