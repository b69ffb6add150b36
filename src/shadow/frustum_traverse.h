/* Per-pixel light-frustum traversal of the BVH for the micro-rasterization methods (microraster.c).
 * Instantiated per buffer width for scalar and AVX2 from frustum_traverse_impl.h, and for AVX-512 in
 * frustum_traverse_avx512.c; all take the same decisions. The best instance the CPU runs is chosen at
 * run time; the scalar one is always built (forced by MS_FORCE_SCALAR=1), and MS_TRAVERSE_ISA=scalar
 * or avx2 caps the choice, to compare the instances in one process. */
#ifndef MS_FRUSTUM_TRAVERSE_H
#define MS_FRUSTUM_TRAVERSE_H
#include <stdint.h>
#include "../accel/bvh.h"
#include "../raster/raster.h"

enum {
    MS_FT_FRUSTA, MS_FT_NODES_VISITED, MS_FT_NODES_CULLED_FRUSTUM, MS_FT_NODES_CULLED_OCCLUDED,
    MS_FT_TRIANGLES, MS_FT_EARLY_OUT, MS_FT_TRACED_EDGE_ON, MS_FT_COUNTERS
};

enum { MS_FT_CULL_OCCLUDED = 1, MS_FT_ORDER_CHILDREN = 2 };

/* Slack, in samples per unit depth, for rounding at the frustum's sides and in the projection. */
#define MS_TRAV_SIDE_SLACK 0.01f

/* Rasterizes every triangle (but `skip`) of the frustum from f->c to the light into buf (k x k, all
 * ones on entry), stopping when buf is all zero. */
typedef void (*ms_frustum_trace_fn)(const ms_bvh *b, const ms_raster_frame *f, ms_raster_fn raster, uint32_t skip,
                                    void *buf, uint64_t *counters, int flags);

ms_frustum_trace_fn ms_frustum_trace_select(int k, int scalar_only);
const char *ms_frustum_trace_isa(int scalar_only);

/* Rasterizes the triangles of leaf n (but `skip`) into buf; returns how many. Shared by every instance. */
static inline uint64_t ms_ft_raster_leaf(const ms_bvh *b, const ms_bvh_node *n, const ms_raster_frame *f,
                                         ms_raster_fn raster, uint32_t skip, void *buf)
{
    uint64_t count = 0;
    for (uint32_t i = n->first; i < n->first + n->count; i++) {
        if (i == skip) continue;
        raster(f, b->tri + 9 * (size_t)i, buf);
        count++;
    }
    return count;
}

#endif
