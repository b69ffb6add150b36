/* The micro-rasterization methods over the multi-frusta traversal (block_traverse.h): the 4x4 pixel
 * block's frusta traverse the shallow BVH together, and in a leaf each triangle is first tested for all
 * sixteen pixels at once (lane = pixel) against what the kernel's own set-up would decide: the depth
 * range, the receiver's horizon and the sample rectangle of the pixel's still-visible samples; then, per
 * pixel that remains, against the visible samples of its buffer under the triangle's box (the coverage
 * test); only then is it rasterized by the kernel. The rectangle shrinks as samples are occluded (the
 * paper's corner-ray recomputation, "CR"), a pixel whose buffer empties leaves the block, and the block
 * stops when none is left. The buffers equal those of the per-pixel traversal: every test is
 * conservative with respect to the kernel (see block_raster_impl.h). */
#ifndef MS_BLOCK_RASTER_H
#define MS_BLOCK_RASTER_H
#include <stdint.h>
#include "block_traverse.h"
#include "raster/raster.h"
#include "core/perk.h"

/* The occluder cache: the shallow-BVH leaves that cleared the most samples in the caller's
 * previous block (the blocks of one call come in spatial order, so their occluders are much the same),
 * processed first in the next block, before the traversal, which then skips them. Exact: a buffer loses
 * the union of what its triangles clear, in any order, and every leaf is still processed once. What it
 * buys is order: the near-first traversal meets the big occluders late where they are near the light
 * (the big-light Sponza's shaft), and until then the rectangle and coverage tests have little to cull.
 * 128 leaves: with the coverage tests at the leaves and above them, every sample cleared early culls more, and
 * the gain grew up to 128 leaves; beyond that the bookkeeping costs what it saves (figures in the lab notebook:
 * 2026-11-26-block-traversal-row-scans-and-order.md, 2026-11-30-ground-penumbra.md). */
#define MS_BLOCK_CACHE 128
typedef struct ms_block_leaf_cache {
    int n;                              /* the leaves to process first (shallow node indices), best first */
    uint32_t node[MS_BLOCK_CACHE];
    int n_next;                         /* the current block's best leaves so far, by samples cleared */
    uint32_t next_node[MS_BLOCK_CACHE];
    uint64_t next_score[MS_BLOCK_CACHE];
    uint64_t *pre_bits;                 /* one bit per shallow node: processed before this block's traversal */
    /* The coverage tests of node and leaf boxes (block_raster_impl.h, br_leaf_lanes) in the current block:
     * lanes tested and lanes culled; and whether inner nodes take the test in this block (decided from the
     * previous block's share culled). */
    uint32_t cover_tested, cover_culled;
    int node_cover;
} ms_block_leaf_cache;

/* The block as the caller hands it over: up to 16 pixels, each with its frame, its buffer (the front
 * mask on entry, the visible mask on return) and its hit triangle; and the caller's leaf cache over the
 * shallow BVH it passes (NULL: none, e.g. another tree's pass). */
typedef struct ms_block_input {
    int n;
    const ms_raster_frame *frame[MS_BLOCK_LANES];
    void *buf[MS_BLOCK_LANES];
    uint32_t skip[MS_BLOCK_LANES];
    ms_block_leaf_cache *cache;   /* NULL: none */
    /* The interior boxes' pass with silhouettes (block_box_impl.h): per prim of the BVH passed (its leaf order),
     * the box it stands for (min x, y, z, max x, y, z); the kernel's row loop for five edges must exist (the
     * SIMD Scanline). NULL: the BVH's triangles. */
    const float (*box)[6];
    /* Per lane, added to (NULL: not counted): the (triangle, pixel) pairs that reached the leaf tests and the
     * triangles rasterized, for the cost of each pixel class (microraster.c). */
    uint32_t *lane_tests, *lane_rast;
} ms_block_input;

enum {
    MS_BR_LEAF_LANES_CULLED = MS_BT_COUNTERS, /* pixels dropped at a leaf by their own frustum */
    MS_BR_TRI_LANES,                   /* (triangle, pixel) pairs reaching the leaf tests */
    MS_BR_CULLED_DEPTH, MS_BR_CULLED_RECT, MS_BR_CULLED_CORNER, MS_BR_CULLED_COVERAGE,
    MS_BR_RASTERIZED, MS_BR_PIXELS_EARLY_OUT, MS_BR_RECT_SHRINKS,
    MS_BR_SHARED_SETUP,                /* of the rasterizations, those set up for several pixels at once */
    MS_BR_SHARED_SETUP_CLIP,           /* of those, the ones with a near or far clip edge */
    MS_BR_NODE_LANES_CULLED,           /* pixels dropped just above the leaves by the coverage test */
    MS_BR_COUNTERS
};

/* Flags: MS_BR_FRUSTUM_SHRINK also narrows a pixel's traversal frustum to its rectangle (the paper's
 * "FS"); MS_BR_ORDER visits nearer children first; MS_BR_NO_LANE_SETUP leaves every triangle's set-up to
 * the kernel pixel by pixel (to measure and test the shared set-up, block_raster_impl.h br_scan_setup). */
enum { MS_BR_ORDER = 1, MS_BR_FRUSTUM_SHRINK = 2, MS_BR_NO_LANE_SETUP = 4 };

typedef void (*ms_block_raster_fn)(const ms_block_input *in, const ms_bvh *b, const ms_bvh_shallow *sh,
                                   ms_raster_fn raster, float near, float far, uint64_t *cnt, int flags);

ms_block_raster_fn ms_block_raster_select(int k, ms_isa cap, ms_isa *chosen);
ms_block_raster_fn ms_block_raster_isa(int k, ms_isa isa);

#define MS_BR_PARAMS                                                                                   \
    (const ms_block_input *in, const ms_bvh *b, const ms_bvh_shallow *sh, ms_raster_fn raster, float near, \
     float far, uint64_t *cnt, int flags)
MS_PERK_DECLARE(void, ms_block_raster, scalar, MS_BR_PARAMS);
MS_PERK_DECLARE(void, ms_block_raster, avx2, MS_BR_PARAMS);
MS_PERK_DECLARE(void, ms_block_raster, avx512, MS_BR_PARAMS);

#endif
