/* AVX-512 instances of the frustum traversal (chosen at run time; see frustum_traverse_impl.h for the
 * method, frustum_traverse_loop.h for the loop they share). Same tests and the same arithmetic as the AVX2 and scalar instances, so the same decisions,
 * counters and visiting order; what differs is the layout:
 *   - the two children of a node are adjacent nodes: their 16 corners in one zmm per coordinate, one
 *     frustum test, one division and one min/max reduction for both;
 *   - the projection and coverage work is done only when a child survives the frustum test;
 *   - a pushed node keeps its coverage test as a column mask and a row mask, so that the test on pop is
 *     a few vector ANDs against the buffer;
 *   - the frame's matrix, C and the clip constants are broadcast once per pixel;
 *   - the grandchildren (or a leaf's triangles) are prefetched while the children are tested.
 * The traversal is bound by the latency from a node to the decision where to go next (mispredicted
 * branches wait for it), so the code shortens that chain where it can without changing a rounding. */
#include "frustum_traverse.h"
#include <immintrin.h>

#define INLINE static inline __attribute__((always_inline))

/* Per-pixel constants. */
typedef struct trav_consts {
    __m512 m[3][3];   /* m[r][a] in every lane */
    __m512 c[3];
    __m512 slack, nslack, hi, near, far;
} trav_consts;

/* Coverage of a node as bit masks: columns i0..i1 and rows j0..j1 of the buffer it may reach. */
typedef struct trav_cov { uint64_t cols, rows; } trav_cov;

typedef struct trav_pair {
    unsigned out;     /* bit h: node h is culled by the frustum */
    unsigned front;   /* bit h: every corner of node h has z > 0 */
    __m512 x, y, z;   /* lanes 0-7: corners of node 0, 8-15: of node 1 */
    __m512 zmin;      /* the smallest corner z of each node, in all its lanes */
} trav_pair;

INLINE void consts_init(trav_consts *t, const ms_raster_frame *f, int K)
{
    for (int r = 0; r < 3; r++)
        for (int a = 0; a < 3; a++) t->m[r][a] = _mm512_set1_ps(f->m[r][a]);
    for (int a = 0; a < 3; a++) t->c[a] = _mm512_set1_ps(f->c[a]);
    t->slack = _mm512_set1_ps(MS_TRAV_SIDE_SLACK);
    t->nslack = _mm512_set1_ps(-MS_TRAV_SIDE_SLACK);
    t->hi = _mm512_set1_ps((float)(K - 1) + MS_TRAV_SIDE_SLACK);
    t->near = _mm512_set1_ps(f->near);
    t->far = _mm512_set1_ps(f->far);
}

/* High bit of every byte of m that is 0xFF (no carries between bytes). */
INLINE uint64_t bytes_all_ones(uint64_t m)
{
    const uint64_t lo7 = 0x7F7F7F7F7F7F7F7Full;
    uint64_t t = ~m;
    return ~(((t & lo7) + lo7) | t) & ~lo7;
}

/* Corners and frustum test of nodes p[0] and q[0] (q = p for the root alone). The corners are computed
 * as in frustum_traverse_impl.h, operation for operation: base = m (bmin - C) summed left to right, the
 * edges m[r][a] (bmax[a] - bmin[a]), and each corner base + edge x + edge y + edge z, adding only the
 * edges its bits select (the AVX2 code's fma by 0 or 1 rounds the same). */
INLINE void view_pair(const trav_consts *t, const ms_bvh_node *p, const ms_bvh_node *q, trav_pair *v)
{
    /* Broadcast loads: node 0 in lanes 0-7, node 1 in 8-15 (shorter than a load and permutes). */
    __m512 rel[3], e[3];
    for (int a = 0; a < 3; a++) {
        const __m512 lo = _mm512_mask_broadcastss_ps(_mm512_set1_ps(p->bmin[a]), 0xFF00, _mm_load_ss(&q->bmin[a]));
        const __m512 hi = _mm512_mask_broadcastss_ps(_mm512_set1_ps(p->bmax[a]), 0xFF00, _mm_load_ss(&q->bmax[a]));
        rel[a] = _mm512_sub_ps(lo, t->c[a]);
        e[a] = _mm512_sub_ps(hi, lo);
    }
    __m512 c[3], base[3], ed[3][3];
    for (int r = 0; r < 3; r++) {
        base[r] = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(t->m[r][0], rel[0]), _mm512_mul_ps(t->m[r][1], rel[1])),
                                _mm512_mul_ps(t->m[r][2], rel[2]));
        for (int a = 0; a < 3; a++) ed[r][a] = _mm512_mul_ps(t->m[r][a], e[a]);
        /* corner bits: x = lane bit 0, y = bit 1, z = bit 2 */
        __m512 s = _mm512_mask_add_ps(base[r], 0xAAAA, base[r], ed[r][0]);
        s = _mm512_mask_add_ps(s, 0xCCCC, s, ed[r][1]);
        c[r] = _mm512_mask_add_ps(s, 0xF0F0, s, ed[r][2]);
    }
    /* Rounding is monotone, so the smallest corner z is the corner that adds exactly the negative edges:
     * computed beside the corners rather than reduced from them. */
    const __m512 zero = _mm512_setzero_ps();
    __m512 zm = _mm512_add_ps(base[2], _mm512_min_ps(ed[2][0], zero));
    zm = _mm512_add_ps(zm, _mm512_min_ps(ed[2][1], zero));
    v->zmin = _mm512_add_ps(zm, _mm512_min_ps(ed[2][2], zero));
    const __m512 xs = c[0], ys = c[1], zs = c[2];
    const __m512 abz = _mm512_abs_ps(zs);
    const __m512 az = _mm512_mul_ps(abz, t->slack);
    const __m512 naz = _mm512_mul_ps(abz, t->nslack);   /* = -az exactly, one step shorter */
    /* mul + add like the portable instance's hi * z + az (an FMA would round differently); hi * z runs
     * beside az, so the chain is no longer. */
    const __m512 top = _mm512_add_ps(_mm512_mul_ps(t->hi, zs), az);
    const uint64_t o4 = (uint64_t)_mm512_cmp_ps_mask(xs, naz, _CMP_LT_OQ) |
                        (uint64_t)_mm512_cmp_ps_mask(xs, top, _CMP_GT_OQ) << 16 |
                        (uint64_t)_mm512_cmp_ps_mask(ys, naz, _CMP_LT_OQ) << 32 |
                        (uint64_t)_mm512_cmp_ps_mask(ys, top, _CMP_GT_OQ) << 48;
    const uint64_t o2 = (uint64_t)_mm512_cmp_ps_mask(zs, t->near, _CMP_LT_OQ) |
                        (uint64_t)_mm512_cmp_ps_mask(zs, t->far, _CMP_GT_OQ) << 16;
    /* A node is out when, for some plane, all 8 of its corners are: a 0xFF byte (even bytes: node 0). */
    const uint64_t all = bytes_all_ones(o4) | bytes_all_ones(o2);
    v->out = (unsigned)((all & 0x0080008000800080ull) != 0) | (unsigned)((all & 0x8000800080008000ull) != 0) << 1;
    const unsigned fr = _mm512_cmp_ps_mask(zs, zero, _CMP_GT_OQ);
    v->front = (unsigned)((fr & 0xFF) == 0xFF) | (unsigned)((fr >> 8) == 0xFF) << 1;
    v->x = xs; v->y = ys; v->z = zs;
}

/* Coverage masks of both nodes (as covers_live in frustum_traverse_impl.h: the projected bounds, widened
 * by the slack, rounded inwards to samples, clamped to the buffer). cols or rows = 0 when no sample is
 * inside; both all ones when a node is not wholly in front of C, which covers a live sample since the
 * buffer is never all zero during the traversal (it stops at the first leaf that makes it so). */
INLINE void cov_pair(const trav_consts *t, const trav_pair *v, int K, trav_cov *cv)
{
    const __m512 iz = _mm512_div_ps(_mm512_set1_ps(1.0f), v->z);
    const __m512 px = _mm512_mul_ps(v->x, iz), py = _mm512_mul_ps(v->y, iz);
    /* 128-bit blocks: [px node0, px node1, py node0, py node1], 4 corners each after one min/max. */
    const __m512 a = _mm512_shuffle_f32x4(px, py, 0x88), b = _mm512_shuffle_f32x4(px, py, 0xDD);
    const __m512 mn = _mm512_min_ps(a, b);
    /* Sign flip, exact (a zero's sign does not survive the slack subtraction below). */
    const __m512 nmx = _mm512_xor_ps(_mm512_max_ps(a, b), _mm512_set1_ps(-0.0f));
    /* Per block: lane 0 the min, lane 1 minus the max. */
    __m512 r = _mm512_min_ps(_mm512_unpacklo_ps(mn, nmx), _mm512_unpackhi_ps(mn, nmx));
    r = _mm512_min_ps(r, _mm512_permute_ps(r, 0x4E));
    /* ceil(lo - slack) and, negated, floor(hi + slack); clamped to [0, K-1]. */
    r = _mm512_roundscale_ps(_mm512_sub_ps(r, t->slack), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
    r = _mm512_max_ps(r, _mm512_setr_ps(0, 1 - K, 0, 0, 0, 1 - K, 0, 0, 0, 1 - K, 0, 0, 0, 1 - K, 0, 0));
    /* Per 64-bit lane 0 of a block: [lo, -hi] as int32; the mask (~0 >> (63 - (hi - lo))) << lo, built
     * in registers (a store and narrow reloads would stall store forwarding). An empty range, lo > hi,
     * gives a shift count of 64 or more and so 0, as the scalar code's float test lo <= hi: both are
     * integral and >= 0 resp. <= K-1, and one too large for int32 converts to INT_MIN, which again
     * gives a count of 64 or more. */
    const __m512i q = _mm512_cvttps_epi32(r);
    const __m512i lo = _mm512_and_si512(q, _mm512_set1_epi64(0xFFFFFFFF)), nhi_i = _mm512_srai_epi64(q, 32);
    const __m512i w = _mm512_add_epi64(_mm512_add_epi64(nhi_i, lo), _mm512_set1_epi64(63));
    __m512i m = _mm512_sllv_epi64(_mm512_srlv_epi64(_mm512_set1_epi64(-1), w), lo);
    /* not wholly in front of C: may cover anything */
    const __mmask8 fr = (__mmask8)((v->front & 1) | (v->front & 2) << 1);
    m = _mm512_mask_mov_epi64(_mm512_set1_epi64(-1), (__mmask8)(fr | fr << 4), m);
    const __m128i x01 = _mm512_castsi512_si128(m), x23 = _mm512_extracti64x2_epi64(m, 1);
    const __m128i y01 = _mm512_extracti64x2_epi64(m, 2), y23 = _mm512_extracti64x2_epi64(m, 3);
    cv[0].cols = (uint64_t)_mm_cvtsi128_si64(x01);
    cv[1].cols = (uint64_t)_mm_cvtsi128_si64(x23);
    cv[0].rows = (uint64_t)_mm_cvtsi128_si64(y01);
    cv[1].rows = (uint64_t)_mm_cvtsi128_si64(y23);
}

/* 1 if a visible sample lies in the masked rows and columns of buf. */
INLINE int covers(const void *buf, trav_cov cv, int K)
{
    if (K == 16) {
        const __m256i w = _mm256_loadu_si256(buf);
        return _mm256_mask_test_epi16_mask((__mmask16)cv.rows, w, _mm256_set1_epi16((short)cv.cols)) != 0;
    }
    if (K == 32) {
        const __m512i m = _mm512_set1_epi32((int)cv.cols);
        const uint32_t *b = buf;
        return (_mm512_mask_test_epi32_mask((__mmask16)cv.rows, _mm512_loadu_si512(b), m) |
                _mm512_mask_test_epi32_mask((__mmask16)(cv.rows >> 16), _mm512_loadu_si512(b + 16), m)) != 0;
    }
    const __m512i m = _mm512_set1_epi64((long long)cv.cols);
    const uint64_t *b = buf;
    __mmask8 any = 0;
    for (int blk = 0; blk < 8; blk++)
        any |= _mm512_mask_test_epi64_mask((__mmask8)(cv.rows >> (8 * blk)), _mm512_loadu_si512(b + 8 * blk), m);
    return any != 0;
}

INLINE int all_zero(const void *buf, int K)
{
    if (K == 16) {
        const __m256i w = _mm256_loadu_si256(buf);
        return _mm256_testz_si256(w, w);
    }
    const __m512i *p = buf;
    __m512i acc = _mm512_loadu_si512(p);
    for (int i = 1; i < K * K / 512; i++) acc = _mm512_or_si512(acc, _mm512_loadu_si512(p + i));
    return _mm512_test_epi64_mask(acc, acc) == 0;
}

/* The next step's data, fetched while this step's tests run: an interior child's pair of children, a
 * leaf child's first triangles. */
INLINE void prefetch_children(const ms_bvh *b, const ms_bvh_node *cn)
{
    for (int h = 0; h < 2; h++) {
        const char *p = cn[h].count ? (const char *)(b->tri + 9 * (size_t)cn[h].first)
                                    : (const char *)&b->nodes[cn[h].first];
        _mm_prefetch(p, _MM_HINT_T0);
        _mm_prefetch(p + 63, _MM_HINT_T0);
    }
}

/* The loop's operations (frustum_traverse_loop.h): the two children tested in one pass; a pushed node
 * keeps its coverage masks. */
INLINE int root_out(const trav_consts *t, const ms_bvh *b)
{
    trav_pair v;
    view_pair(t, &b->nodes[0], &b->nodes[0], &v);
    return v.out & 1;
}

INLINE void children(const trav_consts *t, const ms_bvh *b, const ms_bvh_node *n, const void *buf, int cull_occluded,
                     int keep[2], trav_cov cv[2], float z[2], uint64_t *culled_frustum, uint64_t *culled_occluded,
                     const int K)
{
    const ms_bvh_node *cn = &b->nodes[n->first];
    trav_pair v;
    view_pair(t, cn, cn + 1, &v);
    prefetch_children(b, cn);
    int k0 = !(v.out & 1), k1 = !(v.out & 2);
    *culled_frustum += (uint64_t)(!k0 + !k1);
    cv[0] = cv[1] = (trav_cov){ ~0ull, ~0ull };
    if (cull_occluded && (k0 | k1) && v.front) {
        cov_pair(t, &v, K, cv);
        if (k0 && !covers(buf, cv[0], K)) { k0 = 0; ++*culled_occluded; }
        if (k1 && !covers(buf, cv[1], K)) { k1 = 0; ++*culled_occluded; }
    }
    keep[0] = k0;
    keep[1] = k1;
    z[0] = _mm512_cvtss_f32(v.zmin);
    z[1] = _mm512_cvtss_f32(_mm512_castps256_ps512(_mm512_extractf32x8_ps(v.zmin, 1)));
}

#define FT_CTX trav_consts
#define FT_SAVED trav_cov
#define MS_PERK_IMPL "shadow/microraster/frustum_traverse_avx512_impl.h"
#include "core/perk_each.h"
