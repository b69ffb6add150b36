/* Method "mft": multi-frusta tracing of soft shadows (Benthin & Wald 2009), shared declarations of its
 * driver (mft.c) and of its per-ISA block tracer (mft_impl.h: mft_scalar.c, mft_avx2.c, mft_avx512.c).
 *
 * A block is up to 16 pixels of a 4x4 pixel block, one per SIMD lane; each lane carries its receiver point
 * C (the frustum's apex), the bit mask of its still-live rays (the front mask on entry, the visible
 * samples on return) and its rays as per-sample arrays: the direction d = P - C to every light sample
 * P and the watertight test's shear (sx, sy) with one shear axis per 16-sample packet, exactly as method
 * "raytrace" forms them (raytrace_impl.h), so that both decide every ray/triangle pair by the same
 * floating-point operations and give the same masks. */
#ifndef MS_MFT_H
#define MS_MFT_H
#include <stdint.h>
#include "shadow/microraster/block_traverse.h"
#include "core/cpu.h"
#include "light/pattern.h"
#include "microshadow.h"

/* Per frame, read-only. A lane's live rectangle is in cells of the light's k x k strata: sample (i, j)
 * of both shared patterns lies in cell [i, i+1) x [j, j+1) of the light (pattern.h), so the corners of
 * the cell rectangle, widened by `margin` cells for the rounding of the stored points, bound its rays. */
typedef struct ms_mft_frame {
    int k, samples, mask_words;
    float near, far;
    double lp[3], ls[3], lt[3];   /* light corner and edges */
    double margin;                /* cells */
    int flags;
    ms_pattern pattern;           /* the samples: ms_pattern_points_range */
    int cells;                    /* 1: sample (i, j) lies in cell (i, j) (grid, stratified); 0: interleaved
                                   * (N/16 points per pixel, the whole light as rectangle, no footprints) */
    ms_light light;
    int shear_axis;               /* the light's preferred shear axis (ms_light_shear_axis), ms_wt_packet_axis's pref */
    uint32_t seed;
    const struct ms_alpha *alpha; /* alpha-tested triangles (alpha.h), NULL: none */
} ms_mft_frame;

/* Flags: near-first child order; frustum shrinking of the traversal's bounds too (the paper's FS; CR,
 * the corner rays' recomputation, is always on). */
enum { MS_MFT_ORDER = 1, MS_MFT_FS = 2 };

typedef struct ms_mft_lane {
    float c[3], n[3];             /* receiver point and its normal facing the camera */
    uint32_t skip;                /* its own triangle */
    uint32_t px, py;              /* its pixel: its samples */
    ms_grid grid;                 /* the grid pattern's points of the pixel (ms_grid_for_pixel), once per lane */
    uint64_t *mask;               /* mask_words words: live rays */
    /* Its rays, formed per 16-sample packet when first tested (ms_mft_rays; ready: one bit per packet). */
    float *d[3], *sx, *sy;        /* per sample */
    float *inv[3];                /* per sample: 1 / d (the interleaved groups' box test), NULL: not formed */
    signed char *kz;              /* per packet: the shear axis, -1: lanes tested one by one */
    uint64_t ready[4];
    float m[3][3];                /* rows: X - C -> (cell a, cell b, c) with X = C + c (P - C) + a S/k + b T/k */
    float m_l1[3];                /* the rows' L1 norms */
    int has_m;                    /* 0: C in the light's plane, no footprint */
    float foot_slack;             /* cells */
} ms_mft_lane;

typedef struct ms_mft_block {
    int n;
    ms_mft_lane lane[MS_BLOCK_LANES];
} ms_mft_block;

/* The interleaved mode (mft_group_impl.h): a block's rays regrouped by their place on the light. Each
 * pixel's N/16 points are a (0, m, 2)-net (pattern.c), so each cell of a g x g grid over the light (g^2 =
 * N/16) holds exactly one point of every pixel: a group is the (up to) 16 rays of one cell, ray q from the
 * block's query q, nearby receivers to nearby points, a thin frustum; the N/16 groups of a block traverse 16
 * at a time. Rays are formed as method raytrace forms them (ms_mft_rays: the pixel's 16-sample packets,
 * their shear axis and per-ray shear), so ray q of a group has its own shear axis kz[q]. */
typedef struct ms_mft_group {
    float d[3][MS_BLOCK_LANES], sx[MS_BLOCK_LANES], sy[MS_BLOCK_LANES];
    float inv[3][MS_BLOCK_LANES];        /* 1 / d: raytrace's box test */
    float p[3][MS_BLOCK_LANES];          /* the sample points (the alpha test's segment ends) */
    signed char kz[MS_BLOCK_LANES];      /* -1: the ray is tested alone (ms_wt_segment) */
    uint16_t sample[MS_BLOCK_LANES];     /* the ray's sample index in its pixel's set */
    unsigned live;                       /* slots with a live ray */
    int kz_all;                          /* the axis every live ray shares, -1 if none */
    unsigned alone;                      /* slots with kz < 0 */
} ms_mft_group;

typedef struct ms_mft_rayblock {
    int nq;                              /* queries (slots) */
    float c[3][MS_BLOCK_LANES];          /* their receiver points */
    uint32_t skip[MS_BLOCK_LANES];       /* their own triangles */
    uint64_t *mask[MS_BLOCK_LANES];      /* their masks: the front mask in, the visible samples out */
    int n, cap;                          /* groups */
    ms_mft_group *g;
    /* form_n > 0: the groups' rays are still to be formed (every query's N/16 = form_n samples one per
     * cell, slot = set): the points by cell [cell][axis][slot], each slot's sample in each cell [cell][slot], each
     * slot's cell of each sample, and the slots present. */
    int form_n;
    const float *cell_pts;
    const uint16_t *sample_of;
    const int *set_cell;
    unsigned present;
    /* Per cell, the box of the points of every set formed so far ([lo x, y, z, hi x, y, z][cell], n cells), or
     * NULL: a group whose every present slot is live starts from it and the box of the present receivers
     * (mft_group_impl.h). */
    const float *cell_box;
    int shear_axis;                      /* the frame's (ms_mft_frame), for the packets' axes */
} ms_mft_rayblock;

/* Counters after the traversal's (block_traverse.h), named in mft.c. */
enum {
    MS_MFT_FRUSTA = MS_BT_COUNTERS, MS_MFT_LEAF_LANES_CULLED, MS_MFT_PAIRS, MS_MFT_CULLED_HORIZON, MS_MFT_CULLED_PLANE,
    MS_MFT_CULLED_CORNER, MS_MFT_CULLED_FOOTPRINT, MS_MFT_PAIRS_TESTED, MS_MFT_ISEC16, MS_MFT_FRUSTA_EARLY_OUT,
    MS_MFT_RECT_SHRINKS, MS_MFT_CULLED_BOX, MS_MFT_RAY_BOX, MS_MFT_COUNTERS
};

/* The directions from c to the four corners of cell rectangle r (columns r[0]..r[1], rows r[2]..r[3]),
 * widened by the frame's margin: corner order (a0,b0), (a1,b0), (a0,b1), (a1,b1). */
void ms_mft_corners(const ms_mft_frame *f, const float c[3], const int r[4], float d[4][3]);

/* Forms packet ch (samples 16 ch .. 16 ch + 15) of lane L's rays, as method raytrace forms them. */
void ms_mft_rays(const ms_mft_frame *f, ms_mft_lane *L, int ch);
/* The same from the packet's 16 sample points (the pattern's, ms_pattern_points_range). */
void ms_mft_rays_from(const ms_mft_frame *f, ms_mft_lane *L, int ch, const float *pts);

typedef void (*ms_mft_fn)(const ms_mft_frame *f, ms_mft_block *blk, const ms_bvh *b, const ms_bvh_shallow *sh,
                          uint64_t *cnt);
void ms_mft_block_scalar(const ms_mft_frame *, ms_mft_block *, const ms_bvh *, const ms_bvh_shallow *, uint64_t *);
void ms_mft_block_avx2(const ms_mft_frame *, ms_mft_block *, const ms_bvh *, const ms_bvh_shallow *, uint64_t *);
void ms_mft_block_avx512(const ms_mft_frame *, ms_mft_block *, const ms_bvh *, const ms_bvh_shallow *, uint64_t *);
typedef void (*ms_mft_group_fn)(const ms_mft_frame *f, ms_mft_rayblock *rb, const ms_bvh *b, const ms_bvh_shallow *sh,
                                uint64_t *cnt);
void ms_mft_groups_scalar(const ms_mft_frame *, ms_mft_rayblock *, const ms_bvh *, const ms_bvh_shallow *, uint64_t *);
void ms_mft_groups_avx2(const ms_mft_frame *, ms_mft_rayblock *, const ms_bvh *, const ms_bvh_shallow *, uint64_t *);
void ms_mft_groups_avx512(const ms_mft_frame *, ms_mft_rayblock *, const ms_bvh *, const ms_bvh_shallow *, uint64_t *);
/* The instance for isa (NULL if this CPU lacks it) and the one for a cap. */
ms_mft_fn ms_mft_isa(ms_isa isa);
ms_mft_fn ms_mft_select(ms_isa cap, ms_isa *chosen);

#endif
