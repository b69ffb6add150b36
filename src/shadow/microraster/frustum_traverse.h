/* Per-pixel light-frustum traversal of the BVH for the micro-rasterization methods (microraster.c).
 * One loop (frustum_traverse_loop.h) over per-ISA node tests: scalar and AVX2 from
 * frustum_traverse_impl.h, AVX-512 in frustum_traverse_avx512.c; all take the same decisions. The best
 * instance the CPU runs under the caller's ISA cap is chosen at run time; the scalar one is always
 * built. */
#ifndef MS_FRUSTUM_TRAVERSE_H
#define MS_FRUSTUM_TRAVERSE_H
#include <stdint.h>
#include "accel/bvh.h"
#include "raster/raster.h"
#include "core/perk.h"
#include "visibility/alpha.h"

enum {
    MS_FT_FRUSTA, MS_FT_NODES_VISITED, MS_FT_NODES_CULLED_FRUSTUM, MS_FT_NODES_CULLED_OCCLUDED,
    MS_FT_TRIANGLES, MS_FT_EARLY_OUT, MS_FT_TRACED_EDGE_ON, MS_FT_COUNTERS
};

enum { MS_FT_CULL_OCCLUDED = 1, MS_FT_ORDER_CHILDREN = 2 };

/* Slack, in samples per unit depth, for rounding at the frustum's sides and in the projection (light space:
 * position- and scale-free; the projected coordinates are the scene frame's, scene_frame.c). */
#define MS_TRAV_SIDE_SLACK 0.01f

/* Rasterizes every triangle (but `skip`) of the frustum from f->c to the light into buf (k x k, all
 * ones on entry), stopping when buf is all zero. */
typedef void (*ms_frustum_trace_fn)(const ms_bvh *b, const ms_raster_frame *f, ms_raster_fn raster, uint32_t skip,
                                    void *buf, uint64_t *counters, int flags);

/* The best instance for k that the CPU runs at or below cap (MS_ISA_AUTO: no cap); *chosen (may be
 * NULL) is set to its ISA. NULL for a k other than 16, 32, 64. */
ms_frustum_trace_fn ms_frustum_trace_select(int k, ms_isa cap, ms_isa *chosen);
/* Exactly the instance of that ISA; NULL when the CPU lacks it or k is not 16, 32, 64. */
ms_frustum_trace_fn ms_frustum_trace_isa(int k, ms_isa isa);

#define MS_FT_PARAMS \
    (const ms_bvh *b, const ms_raster_frame *f, ms_raster_fn raster, uint32_t skip, void *buf, uint64_t *cnt, int flags)
MS_PERK_DECLARE(void, ms_frustum_trace, scalar, MS_FT_PARAMS);
MS_PERK_DECLARE(void, ms_frustum_trace, avx2, MS_FT_PARAMS);
MS_PERK_DECLARE(void, ms_frustum_trace, avx512, MS_FT_PARAMS);

/* Rasterizes the triangles of leaf n (but `skip`) into buf; returns how many. Shared by every instance. An
 * alpha-tested triangle clears only its opaque samples (alpha.h, ms_alpha_raster), so the coverage cull that
 * reads buf afterwards never sees it as a full occluder. */
static inline uint64_t ms_ft_raster_leaf(const ms_bvh *b, const ms_bvh_node *n, const ms_raster_frame *f,
                                         ms_raster_fn raster, uint32_t skip, void *buf)
{
    uint64_t count = 0;
    for (uint32_t i = n->first; i < n->first + n->count; i++) {
        if (i == skip) continue;
        ms_raster_or_alpha(f, raster, b->tri + 9 * (size_t)i, i, buf);   /* alpha-tested: filtered coverage */
        count++;
    }
    return count;
}

#endif
