/* AVX-512 instances of the frustum traversal (chosen at run time; see frustum_traverse_impl.h for the
 * method). Same tests, same arithmetic and so the same decisions, counters and visiting order as the
 * AVX2 instance; what differs is the layout:
 *   - the two children of a node are adjacent 32-byte nodes: one 64-byte load, their 16 corners in one
 *     zmm per coordinate, one frustum test, one division and one min/max reduction for both;
 *   - the projection and coverage work is done only when a child survives the frustum test;
 *   - a pushed node keeps its coverage test as a column mask and a row mask, so that the test on pop
 *     is a few vector ANDs against the buffer;
 *   - the frame's matrix, C and the clip constants are broadcast once per pixel. */
#include "frustum_traverse.h"
#include <immintrin.h>

#define INLINE static inline __attribute__((always_inline))

/* Per-pixel constants, broadcast once. */
typedef struct trav_consts {
    __m512 m[3][3];   /* m[r][a] in every lane */
    __m512 csub;      /* lanes 0-2 / 8-10: C, the other lanes unused */
    __m512 slack, hi, near, far;
} trav_consts;

/* Coverage of a node as bit masks: columns i0..i1 and rows j0..j1 of the buffer it may reach. */
typedef struct trav_cov { uint64_t cols, rows; } trav_cov;

typedef struct trav_pair {
    int out[2];       /* culled by the frustum */
    int front[2];     /* every corner has z > 0 */
    __m512 x, y, z;   /* lanes 0-7: corners of the first node, 8-15: of the second */
} trav_pair;

INLINE void consts_init(trav_consts *t, const ms_raster_frame *f, int K)
{
    for (int r = 0; r < 3; r++)
        for (int a = 0; a < 3; a++) t->m[r][a] = _mm512_set1_ps(f->m[r][a]);
    t->csub = _mm512_setr_ps(f->c[0], f->c[1], f->c[2], 0, 0, 0, 0, 0, f->c[0], f->c[1], f->c[2], 0, 0, 0, 0, 0);
    t->slack = _mm512_set1_ps(MS_TRAV_SIDE_SLACK);
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

/* Corners and frustum test of nodes p[0] and p[1] (only p[0] when `one`). The corners are computed as
 * in frustum_traverse_impl.h, operation for operation: base = m (bmin - C) summed left to right, the
 * edges m[r][a] (bmax[a] - bmin[a]), and each corner base + edge x + edge y + edge z, adding only the
 * edges its bits select (the AVX2 code's fma by 0 or 1 rounds the same). */
INLINE void view_pair(const trav_consts *t, const ms_bvh_node *p, int one, trav_pair *v)
{
    const __m512 L = one ? _mm512_maskz_loadu_ps(0x00FF, p) : _mm512_loadu_ps(p);
    /* lanes 0-2: bmin - C, lanes 4-6: bmax - bmin; same at 8-10, 12-14 for the second node. */
    const __m512i lo_to_hi = _mm512_setr_epi32(0, 0, 0, 0, 0, 1, 2, 0, 0, 0, 0, 0, 8, 9, 10, 0);
    const __m512 sub = _mm512_mask_permutexvar_ps(t->csub, 0x7070, lo_to_hi, L);
    const __m512 d = _mm512_maskz_sub_ps(0x7777, L, sub);
    __m512 rel[3], e[3];
    for (int a = 0; a < 3; a++) {
        const __m512i ir = _mm512_setr_epi32(a, a, a, a, a, a, a, a, 8 + a, 8 + a, 8 + a, 8 + a, 8 + a, 8 + a, 8 + a, 8 + a);
        rel[a] = _mm512_permutexvar_ps(ir, d);
        e[a] = _mm512_permutexvar_ps(_mm512_add_epi32(ir, _mm512_set1_epi32(4)), d);
    }
    __m512 c[3];
    for (int r = 0; r < 3; r++) {
        __m512 base = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(t->m[r][0], rel[0]), _mm512_mul_ps(t->m[r][1], rel[1])),
                                    _mm512_mul_ps(t->m[r][2], rel[2]));
        /* corner bits: x = lane bit 0, y = bit 1, z = bit 2 */
        base = _mm512_mask_add_ps(base, 0xAAAA, base, _mm512_mul_ps(t->m[r][0], e[0]));
        base = _mm512_mask_add_ps(base, 0xCCCC, base, _mm512_mul_ps(t->m[r][1], e[1]));
        c[r] = _mm512_mask_add_ps(base, 0xF0F0, base, _mm512_mul_ps(t->m[r][2], e[2]));
    }
    const __m512 xs = c[0], ys = c[1], zs = c[2];
    const __m512 az = _mm512_mul_ps(_mm512_abs_ps(zs), t->slack);
    const __m512 naz = _mm512_sub_ps(_mm512_setzero_ps(), az);
    const __m512 top = _mm512_fmadd_ps(t->hi, zs, az);
    const uint64_t o4 = (uint64_t)_mm512_cmp_ps_mask(xs, naz, _CMP_LT_OQ) |
                        (uint64_t)_mm512_cmp_ps_mask(xs, top, _CMP_GT_OQ) << 16 |
                        (uint64_t)_mm512_cmp_ps_mask(ys, naz, _CMP_LT_OQ) << 32 |
                        (uint64_t)_mm512_cmp_ps_mask(ys, top, _CMP_GT_OQ) << 48;
    const uint64_t o2 = (uint64_t)_mm512_cmp_ps_mask(zs, t->near, _CMP_LT_OQ) |
                        (uint64_t)_mm512_cmp_ps_mask(zs, t->far, _CMP_GT_OQ) << 16;
    /* A node is out when, for some plane, all 8 of its corners are: a 0xFF byte (even bytes: first node). */
    const uint64_t all = bytes_all_ones(o4) | bytes_all_ones(o2);
    v->out[0] = (all & 0x0080008000800080ull) != 0;
    v->out[1] = (all & 0x8000800080008000ull) != 0;
    const unsigned fr = _mm512_cmp_ps_mask(zs, _mm512_setzero_ps(), _CMP_GT_OQ);
    v->front[0] = (fr & 0xFF) == 0xFF;
    v->front[1] = (fr >> 8) == 0xFF;
    v->x = xs; v->y = ys; v->z = zs;
}

/* The smallest z of each node's corners. */
INLINE void zmin_pair(const trav_pair *v, float *z0, float *z1)
{
    __m512 z = _mm512_min_ps(v->z, _mm512_shuffle_f32x4(v->z, v->z, 0xB1));
    z = _mm512_min_ps(z, _mm512_permute_ps(z, 0x4E));
    z = _mm512_min_ps(z, _mm512_permute_ps(z, 0xB1));
    *z0 = _mm512_cvtss_f32(z);
    *z1 = _mm512_cvtss_f32(_mm512_castps128_ps512(_mm512_extractf32x4_ps(z, 2)));
}

/* Coverage masks of both nodes (as covers_live in frustum_traverse_impl.h: the projected bounds, widened
 * by the slack, rounded inwards to samples, clamped to the buffer). cols = 0 when no sample is inside;
 * all ones when a node is not wholly in front of C. */
INLINE void cov_pair(const trav_consts *t, const trav_pair *v, int K, trav_cov *cv)
{
    const __m512 iz = _mm512_div_ps(_mm512_set1_ps(1.0f), v->z);
    const __m512 px = _mm512_mul_ps(v->x, iz), py = _mm512_mul_ps(v->y, iz);
    /* 128-bit blocks: [px node0, px node1, py node0, py node1], 4 corners each after one min/max. */
    const __m512 a = _mm512_shuffle_f32x4(px, py, 0x88), b = _mm512_shuffle_f32x4(px, py, 0xDD);
    const __m512 mn = _mm512_min_ps(a, b);
    const __m512 nmx = _mm512_sub_ps(_mm512_setzero_ps(), _mm512_max_ps(a, b));
    /* Per block: lane 0 the min, lane 1 minus the max. */
    __m512 r = _mm512_min_ps(_mm512_unpacklo_ps(mn, nmx), _mm512_unpackhi_ps(mn, nmx));
    r = _mm512_min_ps(r, _mm512_permute_ps(r, 0x4E));
    /* ceil(lo - slack) and, negated, floor(hi + slack); clamped to [0, K-1]. */
    r = _mm512_roundscale_ps(_mm512_sub_ps(r, t->slack), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
    r = _mm512_max_ps(r, _mm512_setr_ps(0, 1 - K, 0, 0, 0, 1 - K, 0, 0, 0, 1 - K, 0, 0, 0, 1 - K, 0, 0));
    /* lo <= hi per block, compared as floats (as the scalar code) before converting. */
    const __m512 nhi = _mm512_sub_ps(_mm512_setzero_ps(), _mm512_permute_ps(r, 0xB1));
    const unsigned ok = _mm512_cmp_ps_mask(r, nhi, _CMP_LE_OQ);
    _Alignas(64) int32_t q[16];
    _mm512_store_si512(q, _mm512_cvttps_epi32(r));
    for (int h = 0; h < 2; h++) {
        if (!v->front[h]) { cv[h].cols = cv[h].rows = ~0ull; continue; }
        if (!((ok >> (4 * h)) & (ok >> (8 + 4 * h)) & 1)) { cv[h].cols = cv[h].rows = 0; continue; }
        const int i0 = q[4 * h], i1 = -q[4 * h + 1], j0 = q[8 + 4 * h], j1 = -q[8 + 4 * h + 1];
        cv[h].cols = (~0ull >> (63 - (i1 - i0))) << i0;
        cv[h].rows = (~0ull >> (63 - (j1 - j0))) << j0;
    }
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

INLINE void trace(const ms_bvh *b, const ms_raster_frame *f, ms_raster_fn raster, uint32_t skip, void *buf,
                  uint64_t *cnt, int flags, const int K)
{
    const int cull_occluded = flags & MS_FT_CULL_OCCLUDED, order = flags & MS_FT_ORDER_CHILDREN;
    trav_consts t;
    consts_init(&t, f, K);
    uint32_t stack[MS_BVH_STACK];
    trav_cov covs[MS_BVH_STACK];
    int sp = 0;
    trav_pair v;
    view_pair(&t, &b->nodes[0], 1, &v);
    cnt[MS_FT_NODES_VISITED]++;
    if (v.out[0]) { cnt[MS_FT_NODES_CULLED_FRUSTUM]++; return; }
    uint64_t visited = 0, culled_frustum = 0, culled_occluded = 0, triangles = 0;
    uint32_t ni = 0;
    for (;;) {
        const ms_bvh_node *n = &b->nodes[ni];
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                if (i == skip) continue;
                raster(f, b->tri + 9 * (size_t)i, buf);
                triangles++;
            }
            if (all_zero(buf, K)) { cnt[MS_FT_EARLY_OUT]++; break; }
        } else {
            const uint32_t c0 = n->first;
            view_pair(&t, &b->nodes[c0], 0, &v);
            visited += 2;
            int k0 = !v.out[0], k1 = !v.out[1];
            culled_frustum += (uint64_t)(!k0 + !k1);
            trav_cov cv[2] = { { ~0ull, ~0ull }, { ~0ull, ~0ull } };
            if (cull_occluded && (k0 | k1) && (v.front[0] | v.front[1])) {
                cov_pair(&t, &v, K, cv);
                if (k0 && !covers(buf, cv[0], K)) { k0 = 0; culled_occluded++; }
                if (k1 && !covers(buf, cv[1], K)) { k1 = 0; culled_occluded++; }
            }
            if (k0 && k1) {
                float z0, z1;
                int far = 1;   /* the child pushed for later */
                if (order) {
                    zmin_pair(&v, &z0, &z1);
                    far = z1 < z0 ? 0 : 1;
                }
                covs[sp] = cv[far];
                stack[sp++] = c0 + (uint32_t)far;
                ni = c0 + (uint32_t)!far;
                continue;
            }
            if (k0) { ni = c0; continue; }
            if (k1) { ni = c0 + 1; continue; }
        }
        /* The buffer has changed since these nodes were pushed: some may be fully occluded by now. */
        for (;;) {
            if (sp == 0) goto done;
            --sp;
            if (!cull_occluded || covers(buf, covs[sp], K)) break;
            culled_occluded++;
        }
        ni = stack[sp];
    }
done:
    cnt[MS_FT_NODES_VISITED] += visited;
    cnt[MS_FT_NODES_CULLED_FRUSTUM] += culled_frustum;
    cnt[MS_FT_NODES_CULLED_OCCLUDED] += culled_occluded;
    cnt[MS_FT_TRIANGLES] += triangles;
}

void ms_frustum_trace_k16_avx512(const ms_bvh *b, const ms_raster_frame *f, ms_raster_fn raster, uint32_t skip,
                                 void *buf, uint64_t *cnt, int flags)
{
    trace(b, f, raster, skip, buf, cnt, flags, 16);
}

void ms_frustum_trace_k32_avx512(const ms_bvh *b, const ms_raster_frame *f, ms_raster_fn raster, uint32_t skip,
                                 void *buf, uint64_t *cnt, int flags)
{
    trace(b, f, raster, skip, buf, cnt, flags, 32);
}

void ms_frustum_trace_k64_avx512(const ms_bvh *b, const ms_raster_frame *f, ms_raster_fn raster, uint32_t skip,
                                 void *buf, uint64_t *cnt, int flags)
{
    trace(b, f, raster, skip, buf, cnt, flags, 64);
}
