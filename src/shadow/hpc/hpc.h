/* Hierarchical penumbra casting (Laine & Aila 2005), the engine shared by methods "hpc" and
 * "hpc-scanline" (hpc.c; the methods in hpc_method.c). */
#ifndef MS_HPC_H
#define MS_HPC_H
#include <stddef.h>
#include <stdint.h>
#include "shadow/method.h"
#include "raster/raster.h"

/* Where the blocker triangles come from: batches in any order, each triangle once. next writes up to max
 * triangles (9 floats each) and their ids (the prim id a receiver on that triangle carries, so that its own
 * triangle never blocks it) and returns how many, 0 at the end, (size_t)-1 on failure. rewind (may be
 * NULL) starts over. */
typedef struct hpc_source {
    void *user;
    int (*rewind)(void *user);
    size_t (*next)(void *user, float *tri, uint32_t *ids, size_t max);
} hpc_source;

#define HPC_N_COUNTERS 23
#define HPC_COUNTER_SORT_US 16   /* filled by the method (hpc_method.c): the sort is the source's */

/* For n receivers with their front masks (receiver.h), writes the visible masks: the front samples that no
 * triangle of src blocks. scanline: leaves micro-rasterize with `raster` (the Scanline kernel for ctx->k)
 * instead of testing samples one by one. Adds HPC_N_COUNTERS counters. 0, or -1 out of memory or when the
 * source fails. */
int ms_hpc_cast(const ms_render_ctx *ctx, int scanline, ms_raster_fn raster, const ms_shadow_query *q, size_t n,
                const uint64_t *front, uint64_t *vis, const hpc_source *src, uint64_t *counters);

/* Coarse blocker sorting (sec. 3.3): the order of n triangles (9 floats each) bucketed by area, largest
 * bucket first, stable within a bucket, in two linear passes (a histogram of log2 areas, then placement).
 * Returns a malloc'ed permutation, NULL when out of memory. */
uint32_t *ms_hpc_area_order(const float *tri, size_t n);

#endif
