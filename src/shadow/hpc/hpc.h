/* Hierarchical penumbra casting (Laine & Aila 2005), the engine shared by methods "hpc" and
 * "hpc-scanline" (hpc_engine.h: the method, its departures and its files; the per-ISA part hpc_impl.h, compiled
 * as hpc_scalar.c, hpc_avx2.c, hpc_avx512.c; the choice in hpc.c; the methods in hpc_method.c). */
#ifndef MS_HPC_H
#define MS_HPC_H
#include <stddef.h>
#include <stdint.h>
#include "shadow/method.h"
#include "raster/raster.h"
#include "core/cpu.h"
#include "core/test_hooks.h"

/* Where the blocker triangles come from: batches in any order, each triangle once. next writes up to max
 * triangles (9 floats each) and their ids (the prim id a receiver on that triangle carries, so that its own
 * triangle never blocks it) and returns how many, 0 at the end, (size_t)-1 on failure. rewind (may be
 * NULL) starts over. total: how many triangles there are at most, 0 when not known (a streamed scene); a
 * cast's batch buffers are no larger than that, which matters when one cast answers one point (a sphere's
 * or sun's queries, one at a time) and the scene is small. */
typedef struct hpc_source {
    void *user;
    int (*rewind)(void *user);
    size_t (*next)(void *user, float *tri, uint32_t *ids, size_t max);
    size_t total;
} hpc_source;

#define HPC_N_COUNTERS 31
#define HPC_COUNTER_SORT_US 16   /* filled by the method (hpc_method.c): the sort is the source's */

/* For n receivers with their front masks (receiver.h), writes the visible masks: the front samples that no
 * triangle of src blocks. scanline: leaves micro-rasterize with `raster` (the Scanline kernel for ctx->k)
 * instead of testing samples one by one. Adds HPC_N_COUNTERS counters. 0, or -1 out of memory or when the
 * source fails. */
int ms_hpc_cast(const ms_render_ctx *ctx, int scanline, ms_raster_fn raster, const ms_shadow_query *q, size_t n,
                const uint64_t *front, uint64_t *vis, const hpc_source *src, uint64_t *counters);

/* The engine's instances (hpc_impl.h): the same masks and counters on every ISA. ms_hpc_cast runs the one
 * ms_hpc_cast_select picks under ctx->isa_cap. */
typedef int (*ms_hpc_cast_fn)(const ms_render_ctx *, int, ms_raster_fn, const ms_shadow_query *, size_t,
                              const uint64_t *, uint64_t *, const hpc_source *, uint64_t *);
int ms_hpc_cast_scalar(const ms_render_ctx *, int, ms_raster_fn, const ms_shadow_query *, size_t, const uint64_t *,
                       uint64_t *, const hpc_source *, uint64_t *);
int ms_hpc_cast_avx2(const ms_render_ctx *, int, ms_raster_fn, const ms_shadow_query *, size_t, const uint64_t *,
                     uint64_t *, const hpc_source *, uint64_t *);
int ms_hpc_cast_avx512(const ms_render_ctx *, int, ms_raster_fn, const ms_shadow_query *, size_t, const uint64_t *,
                       uint64_t *, const hpc_source *, uint64_t *);
/* The instance for isa (NULL if this CPU lacks it) and the one for a cap (*chosen set when found). */
ms_hpc_cast_fn ms_hpc_cast_isa(ms_isa isa);
ms_hpc_cast_fn ms_hpc_cast_select(ms_isa cap, ms_isa *chosen);

#ifdef MS_TEST_HOOKS
/* Measuring switches (bench_hpc --off), each turning one part of the engine off, and the faults test_hpc
 * injects; test hooks (core/test_hooks.h), so only in the tests' and benchmarks' copy of the library. 0, the
 * default, is the engine as designed. Process-wide and read when a cast starts: set it before rendering, never
 * during. A switch changes the work, not the answers; a fault (BREAK) the answers. The letters are the paper's
 * (sec. 3.3, Fig. 3). */
enum {
    MS_HPC_OFF_UMBRA = 1,        /* A: umbra bits (and the rebuild) */
    MS_HPC_OFF_PLANE_SETS = 2,   /* B: active plane sets: every plane of a volume tested at every node */
    MS_HPC_OFF_LAZY = 4,         /* C: lazy volumes: V_Gk built for every triangle, before the traversal */
    MS_HPC_OFF_ON_DEMAND = 8,    /* D: on-demand masks: every receiver gets its mask before the first triangle */
    MS_HPC_OFF_SORT = 16,        /* coarse blocker sorting: the scene's order (hpc_method.c) */
    MS_HPC_OFF_SIMD_SAMPLES = 32,/* the 16-lane sample test: one sample at a time (the scalar form) */
    MS_HPC_OFF_SIMD_PLANES = 64, /* the 16-lane volume tests: one plane at a time */
    MS_HPC_OFF_FOOTPRINT = 128,  /* hpc's footprint test (hpc_footprint.c): the group volumes V_Gk, as the paper */
    MS_HPC_OFF_PAIRS = 256,      /* hpc's pairs (hpc_pair_batch, hpc_triangle.c): every triangle cast alone */
    MS_HPC_OFF_LEAF_FOOTPRINT = 512, /* hpc's leaf footprint (hpc_leaf_bound_impl.h): every receiver's own
                                      * footprint only */
    MS_HPC_ALL_LEAF_FOOTPRINT = 1024, /* the leaf footprint rule off: on every leaf, not only where it pays (leaf_fp_pays) */
    MS_HPC_OFF_RECT = 2048,      /* hpc's rectangle pairs (hpc_leaf_bound_impl.h): each triangle of such a pair
                                  * bounded alone */
    MS_HPC_OFF_SURE = 4096,      /* hpc's sure lanes (footprint_sure_lanes): every candidate sample to the exact test */
    MS_HPC_BREAK_LEAF_BOUND = 8192,  /* not a measurement: the leaf footprint without its bound over the leaf's
                                      * grid origins (wrong on purpose), so that test_hpc can show its scene
                                      * depends on it */
    MS_HPC_BREAK_RECT = 16384,   /* not a measurement: a rectangle pair's leaf footprint from its first triangle
                                  * alone (wrong on purpose), so that test_hpc can show its scene depends on it */
    MS_HPC_BREAK_SURE = 32768,   /* not a measurement: the sure lanes (footprint_sure_lanes) with their margin on
                                  * the wrong side of the edges, -s (wrong on purpose), so that test_hpc can show
                                  * its scene depends on it */
    MS_HPC_OFF_LEAF_LANES = 65536, /* hpc's leaf lanes (hpc_leaf_lanes_impl.h): a leaf's samples handed to each
                                    * receiver in turn instead of tested for its 16 receivers at once */
    MS_HPC_OFF_TSURE = 131072,   /* hpc's t_sure (hpc_tsure.c): the sure lanes' t range tested, never proven */
    MS_HPC_BREAK_TSURE = 262144  /* not a measurement: t_sure true for every receiver and triangle (wrong on
                                  * purpose), so that test_hpc can show its scene depends on it */
};
extern int ms_hpc_switches;
#endif

/* Coarse blocker sorting (sec. 3.3): the order of n triangles (9 floats each) bucketed by area, largest
 * bucket first, stable within a bucket, in two linear passes (a histogram of log2 areas, then placement).
 * Returns a malloc'ed permutation, NULL when out of memory. */
uint32_t *ms_hpc_area_order(const float *tri, size_t n);

#endif
