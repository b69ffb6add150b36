/* Multi-frusta traversal (Benthin & Wald 2009, sec. 4): the light frusta of a 4x4 pixel block, one per
 * SIMD lane (lanes16.h), traverse the shallow BVH (accel/bvh.h) together; a node is tested against all
 * sixteen at once and visited for the lanes whose frustum may reach it. Used by the micro-rasterization
 * methods (block_raster_impl.h) and by method "mft" (mft_impl.h), which differ only in their leaves.
 *
 * A frustum is culled against a node by interval arithmetic, as in the paper's Appendix A: its segments
 * are X = C + t d for t in [near, far] and d in a box [dlo, dhi] per world axis (the bounds of the
 * directions to the corners of its sample rectangle; the samples are convex combinations of the
 * corners, so the box holds every segment's direction). Per axis, C + t d meets the slab [bmin, bmax] for
 * some d in the box only if t dhi >= bmin - C and t dlo <= bmax - C; each is a bound on t (lower or
 * upper by the sign of dhi resp. dlo), and the node survives if the bounds of the three axes and
 * [near, far] leave some t. Departure: the paper's slab test assumes the common-direction case (each
 * axis' direction interval of one sign, its offset table); a shadow frustum from a point below a light
 * often straddles zero on the light's own axes, so both signs are handled, per lane, by selects. The
 * test is conservative in floating point: node boxes are widened by a world margin that covers the
 * rounding of bmin - C, a zero direction bound is replaced by a tiny one of the same side (the box only
 * grows), and the final comparison allows a relative 2^-16. A lane may also carry a box of apexes
 * (ms_block_frusta_set_lane_box): then the lower bound uses the box's high corner and the upper its low. */
#ifndef MS_BLOCK_TRAVERSE_H
#define MS_BLOCK_TRAVERSE_H
#include <stdint.h>
#include "accel/bvh.h"

#define MS_BLOCK_LANES 16

typedef struct ms_block_frusta {
    float c[3][MS_BLOCK_LANES];        /* apex per lane: the receiver point C (the low corner of a box of apexes) */
    float chi[3][MS_BLOCK_LANES];      /* the box's high corner: c for a single apex */
    float rlo[3][MS_BLOCK_LANES];      /* 1 / dlo per axis (dlo never 0) */
    float rhi[3][MS_BLOCK_LANES];      /* 1 / dhi */
    unsigned pos_hi[3], neg_lo[3];     /* lanes whose dhi > 0, whose dlo < 0, per axis */
    float near, far;
    float margin;                      /* world widening of node boxes */
    unsigned live;                     /* lanes still tracing */
} ms_block_frusta;

/* Traversal counters (Table 1 of the paper): a 16-wide node test is one "AABB test". */
enum {
    MS_BT_BLOCKS, MS_BT_AABB_TESTS, MS_BT_LEAVES, MS_BT_TRIS_ACCESSED, MS_BT_BLOCKS_EARLY_OUT, MS_BT_COUNTERS
};

/* Lanes of a 16-bit set; portable (no popcnt instruction off the ISA files, and no libgcc call). */
static inline int ms_bt_popcount16(unsigned m)
{
    m = m - ((m >> 1) & 0x5555u);
    m = (m & 0x3333u) + ((m >> 2) & 0x3333u);
    m = (m + (m >> 4)) & 0x0F0Fu;
    return (int)((m + (m >> 8)) & 0x1Fu);
}

/* Starts a block: no live lane; near/far segment range; margin from the scene's extent (the root box). */
void ms_block_frusta_init(ms_block_frusta *f, const ms_bvh_node *root, float near, float far);
/* Sets lane i's frustum from its apex and the directions to the four corners of its sample rectangle
 * (world vectors corner - C, as exact as the caller has them), widening the box by rel times the
 * magnitudes involved, and makes the lane live. */
void ms_block_frusta_set_lane(ms_block_frusta *f, int lane, const float c[3], const float d[4][3], float rel);
/* Sets lane i to segments from any point of the box [clo, chi] to any point of the box [plo, phi] (method
 * mft's interleaved groups: 16 rays from 16 receivers). Per axis X(t) = (1 - t) C + t P lies in
 * [clo + t (plo - clo), chi + t (phi - chi)] for t in [0, 1], so the slab test above holds with the apex
 * clo and the direction bound dlo = plo - clo on the upper side and chi, dhi = phi - chi on the lower;
 * widened by rel times the magnitudes, as ms_block_frusta_set_lane. */
void ms_block_frusta_set_lane_box(ms_block_frusta *f, int lane, const float clo[3], const float chi[3], const float plo[3],
                                  const float phi[3], float rel);

#endif
