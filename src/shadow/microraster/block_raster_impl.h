/* The micro-rasterization methods' multi-frusta traversal (block_raster.h), instantiated per k through
 * core/perk_each.h (MS_K, MS_WORD) for each ISA (block_raster_{scalar,avx2,avx512}.c); the loop is
 * block_traverse_loop.h, the lanes lanes16.h.
 *
 * Exactness: the per-pixel traversal hands every triangle of a surviving leaf to the kernel; here a
 * triangle is dropped for a pixel only where the kernel would change nothing in its buffer:
 *   - depth: the kernel's own test, recomputed with its arithmetic operation for operation
 *     (raster_internal.h, ms_tri_setup_run: light-index vertices m (P - C) summed left to right, the same
 *     error bound MS_Z_REL), so the decision is the kernel's;
 *   - rectangle: when the kernel would bound the triangle by its projected box (its zmin > 0), that box,
 *     again recomputed as the kernel computes it (x * (1/z), the same slack, clamp and rounding to
 *     sample indices), against the rectangle of the buffer's visible samples: the kernel clears only
 *     samples inside its box, and outside the rectangle there is nothing left to clear;
 *   - coverage: the same box against the visible samples of the rows it spans.
 * The horizon needs no test of its own: it is rasterized into the buffer before the traversal (the
 * front mask), so the rectangle and the coverage tests already exclude the samples behind the receiver
 * (a separate per-vertex plane test dropped too few of the triangle-pixel pairs to pay for itself).
 * Before the triangles, a leaf's box is tested the same way for all sixteen pixels (br_leaf_lanes):
 * against each pixel's rectangle frustum and, projected, against its visible samples (the per-pixel
 * traversal's node tests, frustum_traverse_impl.h), so that a pixel skips a leaf it cannot change.
 * The paper's corner rays are here the rays through the rectangle's corners (the pixel's light-index
 * space makes them the corners of a box of sample indices): the rectangle test is the frustum's side
 * planes against the triangle, the corner-ray test (large rectangles only) the triangle's edge planes
 * against the corner rays, and the paper's shrinking (CR) is the rectangle recomputed after a leaf in
 * which the pixel rasterized. */
#include <string.h>
#include "block_raster.h"
#include "visibility/lanes16.h"
#include "raster/raster_internal.h"
#include "frustum_traverse.h"   /* MS_TRAV_SIDE_SLACK; alpha.h */
#include "block_setup.h"      /* br_tri, br_scan_setup */

#ifndef MS_BR_COMMON
#define MS_BR_COMMON
/* A leaf's triangles that are some pixel's own (never occluding): few, usually none. */
#define BR_MAX_SKIP MS_BLOCK_LANES
/* The coverage test at the nodes just above the leaves (br_node_lanes) pays only where it culls: a block takes
 * it when more than 2 in 10 of the previous block's coverage tests culled, and keeps it while more than 1 in 10
 * do (a penumbra block behind a scanned statue culls often; one behind thin bars or foliage almost never). */
#define BR_NODE_COVER_ON 2
#define BR_NODE_COVER_KEEP 1
#define BR_NODE_COVER_DEN 10
/* Smallest rectangle (in samples) for which the corner-ray test runs. */
#define BR_CORNER_AREA 16.0f
typedef struct br_state {
    ms_block_frusta *fr;
    uint64_t *bt_cnt;
    const ms_bvh *b;
    const ms_block_input *in;
    ms_raster_fn raster;
    int flags;
    float m[3][3][MS_BLOCK_LANES];   /* lane frames' m[r][a] */
    float mabs2[3][MS_BLOCK_LANES];  /* |m[2][a]| */
    float rx0[MS_BLOCK_LANES], rx1[MS_BLOCK_LANES], ry0[MS_BLOCK_LANES], ry1[MS_BLOCK_LANES];
    int rect[MS_BLOCK_LANES][4];
    /* The Scanline kernel's set-up for many pixels at once (br_scan_setup): its row loop, NULL when the
     * kernel is not the SIMD Scanline (or a lane's frame culls back faces), and the lanes' frames' mt,
     * near and far. */
    ms_scan_rows_fn rows, rows5;
    float mt[3][3][MS_BLOCK_LANES];
    float near_l[MS_BLOCK_LANES], far_l[MS_BLOCK_LANES];
    /* The leaf cache (block_raster.h, ms_block_leaf_cache; in->cache not NULL): each lane's visible
     * samples as of its last rectangle update (a leaf's score is what it cleared), the shallow BVH's nodes
     * (leaf indices) and how many cached leaves were processed before the traversal. */
    int vis[MS_BLOCK_LANES];
    const ms_bvh_node *nodes;
    int n_pre;
} br_state;

/* The lanes of the leaf tests (br_pairs). With AVX-512 they hold (triangle, pixel) pairs, packed sixteen to
 * a vector: in a leaf a triangle reaches a few of the block's sixteen pixels, so one pixel per lane left
 * most lanes idle, and a permutation that gives each lane its pixel's operands is one instruction. With
 * AVX2 (two halves: a permutation is three instructions and a blend) the packed layout was slower, and the
 * lanes stay pixels, one triangle at a time; so in the portable build. */
#if defined(MS_TARGET_AVX512)
#define BR_PACK 1
#else
#define BR_PACK 0
#endif
/* The smallest number of lanes (the pixel layout: a block's pixels that rasterize one triangle; the packed
 * layout: a vector's pairs that pass the tests before coverage) for which the Scanline set-up is computed for
 * them together (br_scan_setup) rather than by the kernel pair by pair: below it the shared set-up's fixed
 * cost, the same for one lane as for sixteen, outweighs the kernel calls it replaces. */
#define BR_LANE_SETUP_MIN 4

#if BR_PACK
/* A leaf group's vertices, lane = triangle (the packed layout's L->tv): the nt triangles (9 floats each) read
 * as nine contiguous vectors and transposed by permutations; lanes from nt on are left as they fall (no pair
 * refers to them). Nine gathers did the same slower: a gather loads lane by lane. Float q of triangle j is
 * element 9j + q of the 144, in register (9j + q) >> 4; br_tv_from[q][p - 1] holds the lanes j whose element
 * lies in registers 2p and 2p + 1 (p = 1..3) or in register 8 (p = 4), register pair 0 and 1 the rest. */
static const uint16_t br_tv_from[9][4] = {
    {0x00f0, 0x0700, 0x7800, 0x8000}, {0x0070, 0x0780, 0x7800, 0x8000}, {0x0070, 0x0780, 0x3800, 0xc000},
    {0x0070, 0x0780, 0x3800, 0xc000}, {0x0070, 0x0780, 0x3800, 0xc000}, {0x0078, 0x0780, 0x3800, 0xc000},
    {0x0078, 0x0380, 0x3c00, 0xc000}, {0x0078, 0x0380, 0x3c00, 0xc000}, {0x0078, 0x0380, 0x3c00, 0xc000}};

static inline void br_group_vertices(const float *tri, int nt, l16 tv[9])
{
    __m512 r[9];
    for (int i = 0; i < 9; i++) {   /* masked: nothing past the group's last float is read */
        const int left = 9 * nt - 16 * i;
        r[i] = _mm512_maskz_loadu_ps((__mmask16)(left >= 16 ? 0xFFFFu : left <= 0 ? 0u : (1u << left) - 1u), tri + 16 * i);
    }
    const __m512i idx0 = _mm512_setr_epi32(0, 9, 18, 27, 36, 45, 54, 63, 72, 81, 90, 99, 108, 117, 126, 135);
    for (int q = 0; q < 9; q++) {
        const __m512i idx = _mm512_add_epi32(idx0, _mm512_set1_epi32(q));
        __m512 o = _mm512_permutex2var_ps(r[0], idx, r[1]);
        o = _mm512_mask_mov_ps(o, br_tv_from[q][0], _mm512_permutex2var_ps(r[2], idx, r[3]));
        o = _mm512_mask_mov_ps(o, br_tv_from[q][1], _mm512_permutex2var_ps(r[4], idx, r[5]));
        o = _mm512_mask_mov_ps(o, br_tv_from[q][2], _mm512_permutex2var_ps(r[6], idx, r[7]));
        tv[q] = _mm512_mask_mov_ps(o, br_tv_from[q][3], _mm512_permutexvar_ps(idx, r[8]));
    }
}
#endif

/* The four corner directions of lane rectangle r (columns r[0]..r[1], rows r[2]..r[3]) from C: sample
 * (i, j) is C + mt[2] + i mt[0] + j mt[1] (raster.h). */
static inline void br_corner_dirs(const ms_raster_frame *f, const int r[4], float d[4][3])
{
    for (int c = 0; c < 4; c++) {
        const float i = (float)r[c & 1], j = (float)r[2 + (c >> 1)];
        for (int a = 0; a < 3; a++) d[c][a] = f->mt[2][a] + i * f->mt[0][a] + j * f->mt[1][a];
    }
}

/* A leaf's state for its (triangle, pixel) pairs (br_pairs). */
typedef struct br_leaf_ctx {
    l16 m[3][3], ma[3], c[3], rx0, rx1, ry0, ry1;   /* the pixels' frames and rectangles (pixel layout) */
    l16 mt[3][3], near_l, far_l;                    /* the pixels' set-up operands (pixel layout) */
    l16 tv[9];                                      /* the triangle group's vertices (lane = triangle) */
    uint32_t first;                                 /* the group's first triangle */
    unsigned rasterized;                            /* pixels that rasterized something */
    uint64_t c_depth, c_rect, c_corner, c_cov, c_rast, c_shared, c_shared_clip;
} br_leaf_ctx;
#endif

#include "block_buffer_impl.h"   /* br_live_rect, br_count, br_covers: per k */

/* Lane l's rectangle from its buffer (0: the buffer is empty), and its traversal frustum from the
 * rectangle when `frustum` is set. Rectangles only shrink: rows outside the current one are not read
 * (`first`: there is none yet). */
static inline int MS_KFN(br_update_lane)(br_state *s, int l, int frustum, int first)
{
    int r[4];
    const int j0 = first ? 0 : s->rect[l][2], j1 = first ? MS_K - 1 : s->rect[l][3];
    if (s->in->cache) s->vis[l] = MS_KFN(br_count)((const MS_WORD *)s->in->buf[l]);
    if (!MS_KFN(br_live_rect)((const MS_WORD *)s->in->buf[l], j0, j1, r)) return 0;
    memcpy(s->rect[l], r, sizeof r);
    s->rx0[l] = (float)r[0]; s->rx1[l] = (float)r[1];
    s->ry0[l] = (float)r[2]; s->ry1[l] = (float)r[3];
    if (frustum) {
        float d[4][3];
        br_corner_dirs(s->in->frame[l], r, d);
        ms_block_frusta_set_lane(s->fr, l, s->in->frame[l]->c, d, 1e-5f);
    }
    return 1;
}

/* The lanes of mask whose rectangle frustum (light-index space: i in [rx0, rx1], j in [ry0, ry1] on the
 * plane z = 1, segment parameter in [near, far]) may meet the box of leaf n: the per-pixel traversal's
 * node test (frustum_traverse_impl.h, the same slack) for all sixteen pixels at once, against each
 * pixel's rectangle rather than the whole buffer. All eight corners outside one plane through C (or
 * beyond near or far) cull: the box, hence every triangle in it, then lies wholly outside the frustum
 * of the visible samples. */
static inline unsigned MS_KFN(br_leaf_lanes)(const br_state *s, const ms_bvh_node *n, unsigned mask,
                                             const l16 m[3][3], const l16 c[3])
{
    l16 base[3], col[3][3];
    l16 rel[3];
    for (int a = 0; a < 3; a++) rel[a] = l16_sub(l16_set1(n->bmin[a]), c[a]);
    for (int r = 0; r < 3; r++) {
        base[r] = l16_add(l16_add(l16_mul(m[r][0], rel[0]), l16_mul(m[r][1], rel[1])), l16_mul(m[r][2], rel[2]));
        for (int a = 0; a < 3; a++) col[a][r] = l16_mul(m[r][a], l16_set1(n->bmax[a] - n->bmin[a]));
    }
    const l16 sl = l16_set1(MS_TRAV_SIDE_SLACK);
    const l16 x0 = l16_sub(l16_load(s->rx0), sl), x1 = l16_add(l16_load(s->rx1), sl);
    const l16 y0 = l16_sub(l16_load(s->ry0), sl), y1 = l16_add(l16_load(s->ry1), sl);
    const l16 near = l16_set1(s->fr->near), far = l16_set1(s->fr->far);
    unsigned out_xl = 0xFFFF, out_xh = 0xFFFF, out_yl = 0xFFFF, out_yh = 0xFFFF, out_n = 0xFFFF, out_f = 0xFFFF;
    unsigned front = 0xFFFF;
    const l16 inf = l16_set1(INFINITY), zero = l16_set1(0.0f), one = l16_set1(1.0f);
    l16 px0 = inf, py0 = inf, px1 = l16_sub(zero, inf), py1 = l16_sub(zero, inf);
    for (int corner = 0; corner < 8; corner++) {
        l16 p[3];
        for (int r = 0; r < 3; r++) {
            p[r] = base[r];
            if (corner & 1) p[r] = l16_add(p[r], col[0][r]);
            if (corner & 2) p[r] = l16_add(p[r], col[1][r]);
            if (corner & 4) p[r] = l16_add(p[r], col[2][r]);
        }
        /* Side planes x = x0 z etc.: through C, so the tests hold whatever the sign of z. */
        out_xl &= l16_lt(p[0], l16_mul(x0, p[2]));
        out_xh &= l16_gt(p[0], l16_mul(x1, p[2]));
        out_yl &= l16_lt(p[1], l16_mul(y0, p[2]));
        out_yh &= l16_gt(p[1], l16_mul(y1, p[2]));
        out_n &= l16_lt(p[2], near);
        out_f &= l16_gt(p[2], far);
        front &= l16_gt(p[2], zero);
        const l16 iz = l16_div(one, p[2]);
        const l16 qx = l16_mul(p[0], iz), qy = l16_mul(p[1], iz);
        px0 = l16_min(px0, qx); px1 = l16_max(px1, qx);
        py0 = l16_min(py0, qy); py1 = l16_max(py1, qy);
    }
    unsigned keep = mask & ~(out_xl | out_xh | out_yl | out_yh | out_n | out_f);
    /* Coverage (the per-pixel traversal's occlusion cull): in front of C the box projects inside the hull
     * of its corners' projections; if that holds no visible sample, nothing in the leaf changes the
     * buffer. */
    unsigned cand = keep & front;
    if (cand) {
        /* The projected box in sample indices (slack, clamp, rounding), within each lane's rectangle. */
        const l16 lo1 = l16_set1(-1.0f), hi1 = l16_set1((float)MS_K);
        const l16 ax0 = l16_max(l16_ceil(l16_min(l16_max(l16_sub(px0, sl), lo1), hi1)), l16_load(s->rx0));
        const l16 ax1 = l16_min(l16_floor(l16_min(l16_max(l16_add(px1, sl), lo1), hi1)), l16_load(s->rx1));
        const l16 ay0 = l16_max(l16_ceil(l16_min(l16_max(l16_sub(py0, sl), lo1), hi1)), l16_load(s->ry0));
        const l16 ay1 = l16_min(l16_floor(l16_min(l16_max(l16_add(py1, sl), lo1), hi1)), l16_load(s->ry1));
        const unsigned empty = cand & (l16_gt(ax0, ax1) | l16_gt(ay0, ay1));
        keep &= ~empty;
        cand &= ~empty;
        int32_t xa[MS_BLOCK_LANES], xb[MS_BLOCK_LANES], ya[MS_BLOCK_LANES], yb[MS_BLOCK_LANES];
        l16_store_int(xa, ax0); l16_store_int(xb, ax1); l16_store_int(ya, ay0); l16_store_int(yb, ay1);
        /* No branch on the outcome (data: a branch on it mispredicts). */
        unsigned covered = 0;
        for (; cand; cand &= cand - 1) {
            const int l = __builtin_ctz(cand);
            covered |= (unsigned)MS_KFN(br_covers)((const MS_WORD *)s->in->buf[l], xa[l], xb[l], ya[l], yb[l]) << l;
        }
        const unsigned tested = keep & front;
        keep &= covered | ~tested;
        if (s->in->cache) {   /* the block's share culled: br_node_lanes */
            s->in->cache->cover_tested += (uint32_t)ms_bt_popcount16(tested);
            s->in->cache->cover_culled += (uint32_t)ms_bt_popcount16(tested & ~covered);
        }
    }
    return keep;
}

/* Lane e's rows from the shared set-up: the kernel's row loop over its three or five edges. */
static inline void MS_KFN(br_rows)(const br_state *s, const br_setup *su, int e, void *buf, br_leaf_ctx *L)
{
    const int ne = (su->clip >> e & 1) ? 5 : 3;
    (ne == 5 ? s->rows5 : s->rows)(&su->v, e, buf);
    L->c_shared++;
    L->c_shared_clip += ne == 5;
}

/* The sample indices of the light-index box [xlo, xhi] x [ylo, yhi], clamped before rounding, within the
 * rectangle [rx0, rx1] x [ry0, ry1]. */
static inline void MS_KFN(br_index_box)(l16 xlo, l16 xhi, l16 ylo, l16 yhi, l16 rx0, l16 rx1, l16 ry0, l16 ry1, l16 *bx0,
                                        l16 *bx1, l16 *by0, l16 *by1)
{
    const l16 lo1 = l16_set1(-1.0f), hi1 = l16_set1((float)MS_K);
    *bx0 = l16_max(l16_ceil(l16_min(l16_max(xlo, lo1), hi1)), rx0);
    *bx1 = l16_min(l16_floor(l16_min(l16_max(xhi, lo1), hi1)), rx1);
    *by0 = l16_max(l16_ceil(l16_min(l16_max(ylo, lo1), hi1)), ry0);
    *by1 = l16_min(l16_floor(l16_min(l16_max(yhi, lo1), hi1)), ry1);
}

/* The kernel's box of a projected triangle (xs, ys: its vertices in light-index space): its slack, its clamp,
 * its rounding to sample indices; then within the rectangle [rx0, rx1] x [ry0, ry1]. */
static inline void MS_KFN(br_sample_box)(const l16 xs[3], const l16 ys[3], l16 rx0, l16 rx1, l16 ry0, l16 ry1, l16 *bx0,
                                         l16 *bx1, l16 *by0, l16 *by1)
{
    const l16 slack = l16_set1(MS_BOX_SLACK);
    const l16 xlo = l16_sub(l16_min(l16_min(xs[0], xs[1]), xs[2]), slack);
    const l16 xhi = l16_add(l16_max(l16_max(xs[0], xs[1]), xs[2]), slack);
    const l16 ylo = l16_sub(l16_min(l16_min(ys[0], ys[1]), ys[2]), slack);
    const l16 yhi = l16_add(l16_max(l16_max(ys[0], ys[1]), ys[2]), slack);
    MS_KFN(br_index_box)(xlo, xhi, ylo, yhi, rx0, rx1, ry0, ry1, bx0, bx1, by0, by1);
}

/* Corner rays (the paper's corner-ray culling, in light-index space): a triangle whose box holds visible
 * samples may still miss the whole rectangle box x rows (a long thin triangle across it). Its three edge
 * planes through C (x, y, z: its vertices in the pixel's light frame), oriented towards the opposite vertex:
 * the lanes where the four corners of the rectangle [cx0, cx1] x [cy0, cy1] lie outside one of them, so that
 * no sample inside does (convexity). Worth its cost only for large rectangles, where the kernel call it saves
 * is dear and the miss likely; a margin of 1e-5 of the terms' magnitudes leaves any doubt to the kernel. */
static inline unsigned MS_KFN(br_corner_out)(const l16 x[3], const l16 y[3], const l16 z[3], l16 cx0, l16 cx1, l16 cy0,
                                             l16 cy1)
{
    const l16 zero = l16_set1(0.0f), one = l16_set1(1.0f);
    l16 n1[3];
    for (int v = 0; v < 3; v++) n1[v] = l16_add(l16_add(l16_abs(x[v]), l16_abs(y[v])), l16_abs(z[v]));
    const l16 pmax = l16_add(l16_add(cx1, cy1), one);   /* |i| + |j| + 1 at any corner */
    unsigned out = 0;
    for (int e = 0; e < 3; e++) {
        const int va = (e + 1) % 3, vb = (e + 2) % 3;
        const l16 ex = l16_sub(l16_mul(y[va], z[vb]), l16_mul(z[va], y[vb]));
        const l16 ey = l16_sub(l16_mul(z[va], x[vb]), l16_mul(x[va], z[vb]));
        const l16 ez = l16_sub(l16_mul(x[va], y[vb]), l16_mul(y[va], x[vb]));
        const l16 tol = l16_mul(l16_mul(n1[va], n1[vb]), l16_set1(1e-5f));
        const l16 side = l16_add(l16_add(l16_mul(ex, x[e]), l16_mul(ey, y[e])), l16_mul(ez, z[e]));
        const l16 tc = l16_mul(tol, n1[e]);
        const unsigned pos = l16_gt(side, tc), neg = l16_lt(side, l16_sub(zero, tc));
        const l16 tp = l16_mul(tol, pmax), ntp = l16_sub(zero, tp);
        unsigned pos_out = pos, neg_out = neg;
        for (int corner = 0; corner < 4; corner++) {
            const l16 pi = (corner & 1) ? cx1 : cx0, pj = (corner & 2) ? cy1 : cy0;
            const l16 val = l16_add(l16_add(l16_mul(ex, pi), l16_mul(ey, pj)), ez);
            pos_out &= l16_lt(val, ntp);   /* inside is positive: the corner is outside */
            neg_out &= l16_gt(val, tp);
        }
        out |= pos_out | neg_out;
    }
    return out;
}

/* The leaf tests of a group of the leaf's triangles. Packed layout (BR_PACK): lane e is the (triangle,
 * pixel) pair (first + pt[e], pl[e]), e < np, the pairs sixteen to a vector. In a leaf a triangle reaches on
 * average a few of the block's pixels (3.4 of 16 on the big-light Sponza), so the per-triangle tests with
 * one pixel per lane left most lanes idle; packed, a leaf of 16 triangles costs a few vector passes
 * instead of 16. Each lane's operands are its pixel's (lane permutations of the pixel-layout vectors) and
 * its triangle's, and every operation is the per-pixel one, so each pair's decisions and set-up are bit for
 * bit those of the pixel layout. The pairs come in triangle order and each is tested against its pixel's
 * buffer (the coverage test) and rasterized before the next, so every decision also sees the same buffer.
 * Pixel layout: lane e is pixel e, for triangle first + pt[0] and the pixels of the lane mask np. */
static inline void MS_KFN(br_pairs)(const br_state *s, br_leaf_ctx *L, const int32_t *pt, const int32_t *pl, int np)
{
    const ms_block_input *in = s->in;
    const l16 near = l16_set1(s->fr->near), far = l16_set1(s->fr->far), zero = l16_set1(0.0f);
    const l16 zrel = l16_set1(MS_Z_REL), one = l16_set1(1.0f);
#if BR_PACK
    /* Lane e: pair e, pixel pl[e] and triangle first + pt[e]; lanes from np on are padding. */
    const unsigned lanes = np == MS_BLOCK_LANES ? 0xFFFFu : (1u << np) - 1u;
    const l16i P = l16i_load(pl), T = l16i_load(pt);
#define BR_PIX(v) l16_perm(v, P)
#define BR_TRI(q) l16_perm(L->tv[q], T)
#else
    /* Lane e: pixel e, triangle first + pt[0] for the pixels of `np` (a lane mask here). */
    const unsigned lanes = (unsigned)np;
    const float *tri = s->b->tri + 9 * (size_t)(L->first + (uint32_t)pt[0]);
    (void)pl;
#define BR_PIX(v) (v)
#define BR_TRI(q) l16_set1(tri[q])
#endif
    l16 m[3][3], ma[3], c[3];
    for (int a = 0; a < 3; a++) {
        c[a] = BR_PIX(L->c[a]);
        ma[a] = BR_PIX(L->ma[a]);
        for (int r = 0; r < 3; r++) m[r][a] = BR_PIX(L->m[r][a]);
    }
    const l16 rx0 = BR_PIX(L->rx0), rx1 = BR_PIX(L->rx1), ry0 = BR_PIX(L->ry0), ry1 = BR_PIX(L->ry1);
    l16 tv[3][3];
    for (int v = 0; v < 3; v++)
        for (int k = 0; k < 3; k++) tv[v][k] = BR_TRI(3 * v + k);
    l16 x[3], y[3], z[3], zlo[3], zhi[3], av[3][3];
    for (int v = 0; v < 3; v++) {
        l16 *a = av[v], aa[3];
        for (int k = 0; k < 3; k++) { a[k] = l16_sub(tv[v][k], c[k]); aa[k] = l16_abs(a[k]); }
        x[v] = l16_add(l16_add(l16_mul(m[0][0], a[0]), l16_mul(m[0][1], a[1])), l16_mul(m[0][2], a[2]));
        y[v] = l16_add(l16_add(l16_mul(m[1][0], a[0]), l16_mul(m[1][1], a[1])), l16_mul(m[1][2], a[2]));
        z[v] = l16_add(l16_add(l16_mul(m[2][0], a[0]), l16_mul(m[2][1], a[1])), l16_mul(m[2][2], a[2]));
        const l16 zerr = l16_mul(l16_add(l16_add(l16_mul(ma[0], aa[0]), l16_mul(ma[1], aa[1])), l16_mul(ma[2], aa[2])), zrel);
        zlo[v] = l16_sub(z[v], zerr);
        zhi[v] = l16_add(z[v], zerr);
    }
    const l16 zmin = l16_min(l16_min(zlo[0], zlo[1]), zlo[2]);
    const l16 zmax = l16_max(l16_max(zhi[0], zhi[1]), zhi[2]);
    const unsigned depth_ok = l16_le(near, zmax) & l16_le(zmin, far);
    const unsigned front = l16_gt(zmin, zero);
    l16 xs[3], ys[3];
    for (int v = 0; v < 3; v++) {
        const l16 inv = l16_div(one, z[v]);
        xs[v] = l16_mul(x[v], inv);
        ys[v] = l16_mul(y[v], inv);
    }
    l16 bx0, bx1, by0, by1;
    MS_KFN(br_sample_box)(xs, ys, rx0, rx1, ry0, ry1, &bx0, &bx1, &by0, &by1);
    const unsigned miss = front & (l16_gt(bx0, bx1) | l16_gt(by0, by1));
    L->c_depth += (uint64_t)ms_bt_popcount16(lanes & ~depth_ok);
    L->c_rect += (uint64_t)ms_bt_popcount16(lanes & depth_ok & miss);
    unsigned pass = lanes & depth_ok & ~miss;
    if (!pass) return;
    /* Corner rays (the paper's corner-ray culling, in light-index space): br_corner_out. */
    const l16 cx0 = l16_select(front, bx0, rx0), cx1 = l16_select(front, bx1, rx1);
    const l16 cy0 = l16_select(front, by0, ry0), cy1 = l16_select(front, by1, ry1);
    const l16 area = l16_mul(l16_add(l16_sub(cx1, cx0), one), l16_add(l16_sub(cy1, cy0), one));
    /* Per lane: which lanes share the vector (the block's pixels, or packed pairs) changes no
     * decision, and no counter. */
    const unsigned large = pass & l16_gt(area, l16_set1(BR_CORNER_AREA));
    if (large) {
        const unsigned out = MS_KFN(br_corner_out)(x, y, z, cx0, cx1, cy0, cy1) & large;
        L->c_corner += (uint64_t)ms_bt_popcount16(out);
        pass &= ~out;
        if (!pass) return;
    }
    int32_t ix0[MS_BLOCK_LANES], ix1[MS_BLOCK_LANES], iy0[MS_BLOCK_LANES], iy1[MS_BLOCK_LANES];
    l16_store_int(ix0, bx0); l16_store_int(ix1, bx1); l16_store_int(iy0, by0); l16_store_int(iy1, by1);
    br_setup su;
    su.rows = su.clip = su.kernel = 0;
#if BR_PACK
    /* The Scanline set-up of every pair that passed, in one pass (the coverage test below may still drop
     * a few: cheaper than a second pass over the ones that remain), when enough passed. */
    const int shared = s->rows && ms_bt_popcount16(pass) >= BR_LANE_SETUP_MIN;
    if (shared) {
        l16 mt[3][3];
        for (int r = 0; r < 3; r++)
            for (int a = 0; a < 3; a++) mt[r][a] = BR_PIX(L->mt[r][a]);
        br_tri tr;
        br_tri_lanes(tv, &tr);
        br_scan_setup(pass, av, &tr, mt, BR_PIX(L->near_l), BR_PIX(L->far_l), x, y, z, zmin, zmax, MS_K, &su);
    }
    for (unsigned p = pass; p; p &= p - 1) {
        const int e = __builtin_ctz(p), l = pl[e];
        const uint32_t t = L->first + (uint32_t)pt[e];
        /* Behind C somewhere (front clear): the kernel scans its whole rectangle, which holds visible
         * samples by construction. */
        if ((front >> e & 1) && !MS_KFN(br_covers)((const MS_WORD *)in->buf[l], ix0[e], ix1[e], iy0[e], iy1[e])) { L->c_cov++; continue; }
        L->c_rast++;
        L->rasterized |= 1u << l;
        if (in->lane_rast) in->lane_rast[l]++;
        /* An alpha-tested triangle clears only its opaque samples (alpha.h): ms_alpha_raster's, per pixel;
         * a lane the set-up left to the kernel likewise. */
        if (shared && !(su.kernel >> e & 1) && !ms_frame_alpha_tested(in->frame[l], t)) {
            if (su.rows >> e & 1) MS_KFN(br_rows)(s, &su, e, in->buf[l], L);
            continue;   /* else the set-up found nothing to clear, as the kernel would */
        }
        ms_raster_or_alpha(in->frame[l], s->raster, s->b->tri + 9 * (size_t)t, t, in->buf[l]);
    }
#else
    const uint32_t t = L->first + (uint32_t)pt[0];
    /* The pixels that pass the coverage test; those set up together below, the others by the kernel. */
    unsigned cover = 0;
    for (unsigned p = pass; p; p &= p - 1) {
        const int l = __builtin_ctz(p);
        /* Behind C somewhere (front clear): the kernel scans its whole rectangle, which holds visible
         * samples by construction. */
        if ((front >> l & 1) && !MS_KFN(br_covers)((const MS_WORD *)in->buf[l], ix0[l], ix1[l], iy0[l], iy1[l])) { L->c_cov++; continue; }
        cover |= 1u << l;
    }
    if (!cover) return;
    L->c_rast += (uint64_t)ms_bt_popcount16(cover);
    L->rasterized |= cover;
    if (in->lane_rast)
        for (unsigned p = cover; p; p &= p - 1) in->lane_rast[__builtin_ctz(p)]++;
    unsigned by_kernel = cover;
    if (s->rows && ms_bt_popcount16(cover) >= BR_LANE_SETUP_MIN) {
        /* An alpha-tested triangle clears only its opaque samples (alpha.h): ms_alpha_raster's, per pixel. */
        unsigned alpha = 0;
        for (unsigned p = cover; p; p &= p - 1) {
            const int l = __builtin_ctz(p);
            if (ms_frame_alpha_tested(in->frame[l], t)) alpha |= 1u << l;
        }
        br_tri tr;
        br_tri_lanes(tv, &tr);
        br_scan_setup(cover & ~alpha, av, &tr, L->mt, L->near_l, L->far_l, x, y, z, zmin, zmax, MS_K, &su);
        by_kernel = alpha | su.kernel;
        for (unsigned p = su.rows; p; p &= p - 1) {
            const int l = __builtin_ctz(p);
            MS_KFN(br_rows)(s, &su, l, in->buf[l], L);
        }
    }
    for (; by_kernel; by_kernel &= by_kernel - 1) {
        const int l = __builtin_ctz(by_kernel);
        /* An alpha-tested triangle clears only its opaque samples (alpha.h): the rectangle, coverage and
         * early-out tests that read the buffer afterwards see only what it really occludes. */
        ms_raster_or_alpha(in->frame[l], s->raster, tri, t, in->buf[l]);
    }
#endif
#undef BR_PIX
#undef BR_TRI
}

#include "block_box_impl.h"   /* br_box: the interior boxes' pass */

static void MS_KFN(br_leaf)(br_state *s, const ms_bvh_node *n, unsigned mask, int pre)
{
    if (!pre && s->n_pre) {
        /* Processed before the traversal (the leaf cache, ms_block_raster) and counted then. */
        const uint32_t id = (uint32_t)(n - s->nodes);
        if (s->in->cache->pre_bits[id >> 6] >> (id & 63) & 1) {
            s->bt_cnt[MS_BT_LEAVES]--;
            s->bt_cnt[MS_BT_TRIS_ACCESSED] -= n->count;
            return;
        }
    }
    ms_block_frusta *fr = s->fr;
    uint64_t *cnt = s->bt_cnt;
    const ms_block_input *in = s->in;
    /* The pixels whose own triangle is in this leaf. */
    uint32_t skip_tri[BR_MAX_SKIP];
    unsigned skip_lane[BR_MAX_SKIP];
    int nskip = 0;
    for (unsigned m = mask; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        if (in->skip[l] - n->first < n->count) { skip_tri[nskip] = in->skip[l]; skip_lane[nskip++] = 1u << l; }
    }
    br_leaf_ctx L;
    for (int a = 0; a < 3; a++) {
        L.c[a] = l16_load(fr->c[a]);
        L.ma[a] = l16_load(s->mabs2[a]);
        for (int r = 0; r < 3; r++) {
            L.m[r][a] = l16_load(s->m[r][a]);
            L.mt[r][a] = l16_load(s->mt[r][a]);
        }
    }
    const unsigned before = mask & fr->live;
    mask = MS_KFN(br_leaf_lanes)(s, n, before, L.m, L.c);
    cnt[MS_BR_LEAF_LANES_CULLED] += (uint64_t)ms_bt_popcount16(before & ~mask);
    if (!mask) return;
    L.rx0 = l16_load(s->rx0); L.rx1 = l16_load(s->rx1); L.ry0 = l16_load(s->ry0); L.ry1 = l16_load(s->ry1);
    L.near_l = l16_load(s->near_l);
    L.far_l = l16_load(s->far_l);
    L.rasterized = 0;
    L.c_depth = L.c_rect = L.c_corner = L.c_cov = L.c_rast = L.c_shared = L.c_shared_clip = 0;
    uint64_t tri_lanes = 0;
    /* The live pixels do not change within a leaf (a pixel retires after it, below). */
    const unsigned live = mask & fr->live;
#if BR_PACK
    /* The live pixels' indices in order, the pair lists' pixels of a triangle every live pixel meets. */
    const __m512i lane_index = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512i live_list = _mm512_maskz_compress_epi32((__mmask16)live, lane_index);
    const int n_live = ms_bt_popcount16(live);
#endif
    const uint32_t end = n->first + n->count;
    if (in->box) {   /* the interior boxes' pass: one silhouette per box and pixel */
        for (uint32_t j = n->first; j < end; j++) MS_KFN(br_box)(s, &L, in->box[j], live);
        tri_lanes = (uint64_t)n->count * (uint64_t)ms_bt_popcount16(live);
        for (unsigned p = in->lane_tests ? live : 0; p; p &= p - 1) in->lane_tests[__builtin_ctz(p)] += n->count;
    }
    for (uint32_t g = in->box ? end : n->first; g < end; g += MS_BLOCK_LANES) {
        const int nt = end - g < MS_BLOCK_LANES ? (int)(end - g) : MS_BLOCK_LANES;
        L.first = g;
#if BR_PACK
        br_group_vertices(s->b->tri + 9 * (size_t)g, nt, L.tv);
        /* All the group's pairs first, then sixteen at a time: the index vectors are then loaded from
         * stores long done (loaded right after sixteen scalar stores, they waited on store forwarding). */
        int32_t pt[MS_BLOCK_LANES * MS_BLOCK_LANES + MS_BLOCK_LANES], pl[MS_BLOCK_LANES * MS_BLOCK_LANES + MS_BLOCK_LANES];
        int np = 0;
        for (int j = 0; j < nt; j++) {
            unsigned lanes = live;
            for (int q = 0; q < nskip; q++)
                if (skip_tri[q] == g + (uint32_t)j) lanes &= ~skip_lane[q];
            tri_lanes += (uint64_t)ms_bt_popcount16(lanes);
            if (lanes == live) {   /* the usual case: every live pixel, two vector stores (the tail is padding) */
                _mm512_storeu_si512((void *)(pl + np), live_list);
                _mm512_storeu_si512((void *)(pt + np), _mm512_set1_epi32(j));
                np += n_live;
                continue;
            }
            for (; lanes; lanes &= lanes - 1) {
                pt[np] = j;
                pl[np++] = __builtin_ctz(lanes);
            }
        }
        if (!np) continue;
        if (in->lane_tests) {   /* a pixel's pairs: the group's triangles, less its own */
            for (unsigned p = live; p; p &= p - 1) in->lane_tests[__builtin_ctz(p)] += (uint32_t)nt;
            for (int q = 0; q < nskip; q++)
                if (skip_tri[q] - g < (uint32_t)nt && (live & skip_lane[q])) in->lane_tests[__builtin_ctz(skip_lane[q])]--;
        }
        for (int e = np; e % MS_BLOCK_LANES; e++) { pt[e] = pt[0]; pl[e] = pl[0]; }   /* valid operands, unused */
        for (int e = 0; e < np; e += MS_BLOCK_LANES)
            MS_KFN(br_pairs)(s, &L, pt + e, pl + e, np - e < MS_BLOCK_LANES ? np - e : MS_BLOCK_LANES);
#else
        int32_t pt[1], pl[1] = { 0 };
        for (int j = 0; j < nt; j++) {
            unsigned lanes = live;
            for (int q = 0; q < nskip; q++)
                if (skip_tri[q] == g + (uint32_t)j) lanes &= ~skip_lane[q];
            tri_lanes += (uint64_t)ms_bt_popcount16(lanes);
            if (in->lane_tests)
                for (unsigned p = lanes; p; p &= p - 1) in->lane_tests[__builtin_ctz(p)]++;
            pt[0] = j;
            if (lanes) MS_KFN(br_pairs)(s, &L, pt, pl, (int)lanes);
        }
#endif
    }
    cnt[MS_BR_TRI_LANES] += tri_lanes;
    cnt[MS_BR_CULLED_DEPTH] += L.c_depth;
    cnt[MS_BR_CULLED_RECT] += L.c_rect;
    cnt[MS_BR_CULLED_CORNER] += L.c_corner;
    cnt[MS_BR_CULLED_COVERAGE] += L.c_cov;
    cnt[MS_BR_RASTERIZED] += L.c_rast;
    cnt[MS_BR_SHARED_SETUP] += L.c_shared;
    cnt[MS_BR_SHARED_SETUP_CLIP] += L.c_shared_clip;
    /* Shrink the rectangles of the pixels that rasterized (CR), and retire those left with nothing. */
    const int fs = s->flags & MS_BR_FRUSTUM_SHRINK;
    unsigned rasterized = L.rasterized;
    uint64_t cleared = 0;
    for (; rasterized; rasterized &= rasterized - 1) {
        const int l = __builtin_ctz(rasterized);
        int old[4];
        memcpy(old, s->rect[l], sizeof old);
        const int vis_before = s->vis[l];
        if (!MS_KFN(br_update_lane)(s, l, fs, 0)) {
            cleared += (uint64_t)vis_before;
            s->vis[l] = 0;
            fr->live &= ~(1u << l);
            cnt[MS_BR_PIXELS_EARLY_OUT]++;
            continue;
        }
        cleared += (uint64_t)(vis_before - s->vis[l]);
        cnt[MS_BR_RECT_SHRINKS] += memcmp(old, s->rect[l], sizeof old) != 0;
    }
    ms_block_leaf_cache *ca = in->cache;
    if (ca && cleared) {
        /* The block's MS_BLOCK_CACHE best leaves: insertion into a short sorted list, most leaves rejected
         * by its last score. */
        const uint32_t id = (uint32_t)(n - s->nodes);
        int i = ca->n_next < MS_BLOCK_CACHE ? ca->n_next++ : MS_BLOCK_CACHE;
        if (i == MS_BLOCK_CACHE && ca->next_score[MS_BLOCK_CACHE - 1] >= cleared) return;
        if (i == MS_BLOCK_CACHE) i = MS_BLOCK_CACHE - 1;
        for (; i > 0 && ca->next_score[i - 1] < cleared; i--) {
            ca->next_score[i] = ca->next_score[i - 1];
            ca->next_node[i] = ca->next_node[i - 1];
        }
        ca->next_score[i] = cleared;
        ca->next_node[i] = id;
    }
}

/* Of the lanes m, those whose pixel child n's box can change, where n lies just above the leaves and the
 * block takes the test (BR_NODE_COVER_ON): the leaf's lane test (br_leaf_lanes: the pixel's rectangle frustum
 * and, projected, its visible samples), so that a pixel whose visible samples the box misses skips both
 * leaves' tests. Conservative as at a leaf: nothing in the box can clear a sample outside its projection.
 * Departure from the paper, whose frusta test only the sides at inner nodes. */
static inline unsigned MS_KFN(br_node_lanes)(const br_state *s, const ms_bvh_node *n, unsigned m)
{
    if (!m || n->count || !s->in->cache || !s->in->cache->node_cover) return m;
    const ms_bvh_node *ch = &s->nodes[n->first];
    if (!ch[0].count || !ch[1].count) return m;
    l16 M[3][3], C[3];
    for (int a = 0; a < 3; a++) {
        C[a] = l16_load(s->fr->c[a]);
        for (int r = 0; r < 3; r++) M[r][a] = l16_load(s->m[r][a]);
    }
    const unsigned keep = MS_KFN(br_leaf_lanes)(s, n, m, M, C);
    s->bt_cnt[MS_BR_NODE_LANES_CULLED] += (uint64_t)ms_bt_popcount16(m & ~keep);
    return keep;
}
#define BT_STATE br_state
#define BT_LEAF(s, n, mask) MS_KFN(br_leaf)(s, n, mask, 0)
#define BT_FN MS_KFN(br_traverse)
#define BT_CHILDREN(s, c, mask, order, ml, mr, right_first) \
    do { \
        MS_CAT(BT_FN, _children)((s)->fr, c, mask, order, &(ml), &(mr), &(right_first)); \
        tests += 2; \
        (ml) = MS_KFN(br_node_lanes)(s, &(c)[0], ml); \
        (mr) = MS_KFN(br_node_lanes)(s, &(c)[1], mr); \
    } while (0)
#include "block_traverse_loop.h"
#undef BT_STATE
#undef BT_LEAF
#undef BT_FN
#undef BT_CHILDREN

void MS_KFN(ms_block_raster)(const ms_block_input *in, const ms_bvh *b, const ms_bvh_shallow *sh, ms_raster_fn raster,
                             float near, float far, uint64_t *cnt, int flags)
{
    ms_block_frusta fr;
    br_state s;
    ms_block_frusta_init(&fr, &sh->nodes[0], near, far);
    s.fr = &fr;
    s.bt_cnt = cnt;
    s.b = b;
    s.in = in;
    s.raster = raster;
    s.flags = flags;
    s.rows = (flags & MS_BR_NO_LANE_SETUP) ? NULL : ms_raster_rows(raster, MS_K, 3);
    s.rows5 = ms_raster_rows(raster, MS_K, 5);
    memset(s.m, 0, sizeof s.m);
    memset(s.mabs2, 0, sizeof s.mabs2);
    memset(s.mt, 0, sizeof s.mt);
    memset(s.near_l, 0, sizeof s.near_l);
    memset(s.far_l, 0, sizeof s.far_l);
    memset(s.vis, 0, sizeof s.vis);
    for (int l = 0; l < MS_BLOCK_LANES; l++) {
        s.rx0[l] = s.ry0[l] = 1.0f;
        s.rx1[l] = s.ry1[l] = 0.0f;
    }
    for (int l = 0; l < in->n; l++) {
        const ms_raster_frame *f = in->frame[l];
        for (int r = 0; r < 3; r++)
            for (int a = 0; a < 3; a++) s.m[r][a][l] = f->m[r][a];
        for (int a = 0; a < 3; a++) s.mabs2[a][l] = fabsf(f->m[2][a]);
        for (int r = 0; r < 3; r++)
            for (int a = 0; a < 3; a++) s.mt[r][a][l] = f->mt[r][a];
        s.near_l[l] = f->near;
        s.far_l[l] = f->far;
        if (f->cull_backfaces || f->k != MS_K) s.rows = NULL;
        /* The starting frustum bounds the front samples (the horizon already cleared the rest). */
        MS_KFN(br_update_lane)(&s, l, 1, 1);
    }
    s.nodes = sh->nodes;
    s.n_pre = 0;
    ms_block_leaf_cache *ca = in->cache;
    if (ca) {
        ca->n_next = 0;
        /* The previous block's best occluders first, best first (near-first did worse), for the lanes whose
         * frustum reaches the leaf's box (the traversal's node test: lanes its ancestors' tests would drop
         * are culled by the leaf's own tests; without it every live lane pays the leaf's tests). */
        for (int i = 0; i < ca->n && fr.live; i++) {
            const ms_bvh_node *n = &sh->nodes[ca->node[i]];
            l16 tlo;
            const unsigned mask = MS_CAT(MS_KFN(br_traverse), _node)(&fr, n, &tlo) & fr.live;
            cnt[MS_BT_AABB_TESTS]++;
            if (!mask) continue;   /* not marked: the traversal's own test of the box drops it too */
            ca->pre_bits[ca->node[i] >> 6] |= 1ull << (ca->node[i] & 63);
            s.n_pre++;
            cnt[MS_BT_LEAVES]++;
            cnt[MS_BT_TRIS_ACCESSED] += n->count;
            MS_KFN(br_leaf)(&s, n, mask, 1);
        }
    }
    MS_KFN(br_traverse)(&s, sh, flags & MS_BR_ORDER);
    if (ca) {
        /* The next block's choice of the node coverage test, with hysteresis (runs of penumbra blocks). */
        ca->node_cover = (uint64_t)ca->cover_culled * BR_NODE_COVER_DEN >
                         (uint64_t)ca->cover_tested * (ca->node_cover ? BR_NODE_COVER_KEEP : BR_NODE_COVER_ON);
        ca->cover_tested = ca->cover_culled = 0;
        for (int i = 0; i < ca->n; i++) ca->pre_bits[ca->node[i] >> 6] = 0;
        ca->n = ca->n_next;
        memcpy(ca->node, ca->next_node, sizeof ca->node);
    }
}
