/* Each sample on an occluder set that decides it as raytrace does (visibility/occluders.h, for_axis).
 *
 * A light's merged rectangles (accel/coplanar.h) decide a segment exactly as the scene's own triangles do
 * unless the watertight test shears that segment along an axis the rectangles were merged along. For a
 * method that must answer as raytrace does (MS_OCC_MERGE_EXACT: mft, hpc) the driver therefore splits each
 * receiver's samples by their segment's shear axis (ms_segment_axes): those of an axis the merge is exact
 * for go to the merged set, those of another to the set merged along every axis but that one (for_axis),
 * or, when it has none, to the scene's own triangles; the visible masks are ORed. The method itself sees
 * only queries with fewer samples in front. */
#ifndef MS_EXACT_SPLIT_H
#define MS_EXACT_SPLIT_H
#include <stddef.h>
#include <stdint.h>
#include "shadow/method.h"

typedef struct ms_exact_split {
    unsigned axes;                  /* the axes whose segments leave the merged set; 0: no split */
    void *state[3];                 /* per such axis: the method's state over the set its segments go to */
    const ms_bvh *bvh[3];           /* ... that set's triangles, alpha table and prim map (ms_render_ctx) */
    const struct ms_alpha *alpha[3];
    const uint32_t *prim_map[3];
} ms_exact_split;

/* The method's visible masks (vis, mw words per query) for the n queries q with front masks front, where ctx
 * (the merged set, its light the queries' own) and state decide the samples of every axis outside split->axes
 * and split's sets the others. scene_prim[i]: query i's hit triangle in the scene's BVH, which each set maps to
 * its own prim (ms_ctx_skip_prim). whole: through sm->visibility_all (one call per set, over `threads`
 * threads), else sm->visibility (from one thread). counters as the method's. 0, or -1 out of memory or when
 * the method fails. */
int ms_exact_split_visibility(const ms_shadow_method *sm, void *state, const ms_render_ctx *ctx,
                              const ms_exact_split *split, const ms_shadow_query *q, const uint32_t *scene_prim,
                              size_t n, const uint64_t *front, uint64_t *vis, int whole, int threads,
                              uint64_t *counters);

/* Query q's segments by shear axis, as ms_segment_axes gives them over its ctx->samples sample points (bit s of
 * ax + a * ctx->mask_words; bits past the samples may be set), mostly proved from the light's hull (hull, n_hull:
 * ms_light_hull of ctx->light; pref: its ms_light_shear_axis) without forming the points. pts: scratch of
 * 3 * ctx->samples floats. */
void ms_receiver_axes(const ms_render_ctx *ctx, const ms_shadow_query *q, const float (*hull)[3], int n_hull,
                      int pref, float *pts, uint64_t *ax);

#endif
