/* AVX2 + FMA Scanline kernels, for CPUs without AVX-512: eight scanlines per instruction (four 64-bit
 * words for k = 64).
 *
 * The setup is the one of scanline_avx512.c, the same operations on the same lanes in the same order
 * (mul + add wherever the scalar setup multiplies then adds, so that it agrees with the scalar kernels
 * away from ties), with the AVX-512 features replaced: masks are compare results (vectors) or their
 * movemask bits; the two-source permutations are vpermps of the triangle's floats plus a blend; the
 * one-hot picks are a tzcnt of the movemask and a vpermps broadcast; the 16-lane division is two 8-lane
 * ones; embedded rounding is vroundps followed by vcvtps2dq. The rows use the same FMA and the same
 * max/min order as the AVX-512 rows, so both variants fill identical buffers (test_kernels reports
 * any scanline where they differ).
 *
 * The AVX2 variable shifts (vpsllvd/vpsrlvd/vpsllvq/vpsrlvq) give 0 for counts >= the lane width, like
 * the AVX-512 ones: out-of-range bounds need no clamping. */
#include <immintrin.h>
#include "raster_internal.h"

/* Per-triangle data of the row loop (as in scanline_avx512.c): for each of the (up to) five edges a lower
 * and an upper bound a*y + b on x, neutral (0 resp. k-1) where the edge is not of that kind, and the
 * scanline range. */
typedef struct ms_scan_vec {
    float al[8], bl[8], au[8], bu[8];
    int y0, y1;
} ms_scan_vec;

static inline __m256i ms_idx8(int a, int b, int c, int d, int e, int f, int g, int h)
{
    return _mm256_setr_epi32(a, b, c, d, e, f, g, h);
}

/* All ones in lane i where bit i of m is set: the AVX2 form of a k-mask. */
static inline __m256 ms_lanes(int m)
{
    const __m256i bit = ms_idx8(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(m), bit), bit));
}

static inline __m256i ms_blendv_idx(__m256i a, __m256i b, __m256 m)
{
    return _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(a), _mm256_castsi256_ps(b), m));
}

static inline __attribute__((always_inline)) int ms_scan_vec_setup(const ms_raster_frame *f, const float tri[9],
                                                                   ms_scan_vec *sv, const int clip)
{
    const int k = f->k;
    const float kf = (float)k;
    /* World coordinates: lane i = P_i - C, lane 4+i = P_{i+2} - P_{i+1} (the edge opposite vertex i),
     * lanes 3 and 7 = x - x = 0. Coordinate a of vertex i is tri[3i + a]: x and y come from the first
     * eight floats, z from floats 1..8 (one lane further on), so both loads stay inside the triangle. */
    const __m256 T01 = _mm256_loadu_ps(tri), T2 = _mm256_loadu_ps(tri + 1);
    __m256 W[3];
    for (int a = 0; a < 3; a++) {
        const __m256 src = a == 2 ? T2 : T01;
        const int o = a == 2 ? 1 : a;
        const __m256i ia = ms_idx8(o, 3 + o, 6 + o, 0, 6 + o, o, 3 + o, 0);
        const __m256i ib = ms_idx8(0, 0, 0, 0, 3 + o, 6 + o, o, 0);
        W[a] = _mm256_sub_ps(_mm256_permutevar8x32_ps(src, ia),
                             _mm256_blend_ps(_mm256_permutevar8x32_ps(src, ib), _mm256_set1_ps(f->c[a]), 0x07));
    }
    /* Light-index coordinates V[r] = row r of m times W (mul + add, not FMA, to round like the scalar
     * setup), for the depth range and the projected box only; the edges come from W. */
    __m256 V[3];
    for (int r = 0; r < 3; r++)
        V[r] = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(f->m[r][0]), W[0]),
                                           _mm256_mul_ps(_mm256_set1_ps(f->m[r][1]), W[1])),
                             _mm256_mul_ps(_mm256_set1_ps(f->m[r][2]), W[2]));
    /* The other two lanes of each lane's triple (vertices 0..2, edges 4..6). */
    const __m256i rot1 = ms_idx8(1, 2, 0, 3, 5, 6, 4, 7), rot2 = ms_idx8(2, 0, 1, 3, 6, 4, 5, 7);
    /* Depth range widened by the rounding bound of raster_internal.h (MS_Z_REL), same operations. */
    const __m256 absm = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
    const __m256 zerr = _mm256_mul_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(fabsf(f->m[2][0])), _mm256_and_ps(W[0], absm)),
                                    _mm256_mul_ps(_mm256_set1_ps(fabsf(f->m[2][1])), _mm256_and_ps(W[1], absm))),
                      _mm256_mul_ps(_mm256_set1_ps(fabsf(f->m[2][2])), _mm256_and_ps(W[2], absm))),
        _mm256_set1_ps(MS_Z_REL));
    const __m256 zl = _mm256_sub_ps(V[2], zerr), zh = _mm256_add_ps(V[2], zerr);
    const __m256 zmin = _mm256_min_ps(_mm256_min_ps(zl, _mm256_permutevar8x32_ps(zl, rot1)), _mm256_permutevar8x32_ps(zl, rot2));
    const __m256 zmax = _mm256_max_ps(_mm256_max_ps(zh, _mm256_permutevar8x32_ps(zh, rot1)), _mm256_permutevar8x32_ps(zh, rot2));
    const float zmin_s = _mm256_cvtss_f32(zmin), zmax_s = _mm256_cvtss_f32(zmax);
    if (!(zmax_s >= f->near && zmin_s <= f->far)) return 0;
    const int need = 0x07 | (zmin_s < f->near) << 3 | (zmax_s > f->far) << 4;
    /* Instantiated with and without clip edges, as in the AVX-512 variant. */
    if ((need != 0x07) != clip) return -1;

    /* Squared world lengths: lanes 0..2 of the vectors from C, 4..6 of the edges. */
    const __m256 L = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(W[0], W[0]), _mm256_mul_ps(W[1], W[1])),
                                   _mm256_mul_ps(W[2], W[2]));
    const __m256 L1 = _mm256_permutevar8x32_ps(L, rot1), L2 = _mm256_permutevar8x32_ps(L, rot2);
    const __m256 Le = _mm256_permutevar8x32_ps(L, ms_idx8(4, 5, 6, 7, 4, 5, 6, 7));
    /* Edge i's operands (the two shortest sides of the triangle C, P_{i+1}, P_{i+2}) as permutation
     * indices into W; lanes 4..6 compute the normal candidates E_{i+1} x E_{i+2}. */
    const __m256 va_longest = _mm256_and_ps(_mm256_cmp_ps(L1, L2, _CMP_GE_OQ), _mm256_cmp_ps(L1, Le, _CMP_GE_OQ));
    const __m256 e_longest = _mm256_andnot_ps(va_longest, _mm256_cmp_ps(Le, L2, _CMP_GE_OQ));
    const __m256i ix = ms_blendv_idx(ms_idx8(1, 2, 0, 3, 5, 6, 4, 7), ms_idx8(2, 0, 1, 3, 5, 6, 4, 7), va_longest);
    const __m256i iy = ms_blendv_idx(ms_idx8(4, 5, 6, 3, 6, 4, 5, 7), ms_idx8(2, 0, 1, 3, 6, 4, 5, 7), e_longest);
    __m256 X[3], Y[3];
    for (int r = 0; r < 3; r++) {
        X[r] = _mm256_permutevar8x32_ps(W[r], ix);
        Y[r] = _mm256_permutevar8x32_ps(W[r], iy);
    }
    /* World normals u (of the edge planes through C; lanes 4..6: of the triangle's plane)... */
    const __m256 ux = _mm256_sub_ps(_mm256_mul_ps(X[1], Y[2]), _mm256_mul_ps(X[2], Y[1]));
    const __m256 uy = _mm256_sub_ps(_mm256_mul_ps(X[2], Y[0]), _mm256_mul_ps(X[0], Y[2]));
    const __m256 uz = _mm256_sub_ps(_mm256_mul_ps(X[0], Y[1]), _mm256_mul_ps(X[1], Y[0]));
    /* ...and in light space, M^T u (rows ds, dt, p0 - C). */
    __m256 et[3];
    for (int r = 0; r < 3; r++)
        et[r] = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(f->mt[r][0]), ux),
                                            _mm256_mul_ps(_mm256_set1_ps(f->mt[r][1]), uy)),
                              _mm256_mul_ps(_mm256_set1_ps(f->mt[r][2]), uz));
    const __m256 ex = et[0], ey = et[1], ez = et[2];

    /* Normal from the two shortest edges (the candidate of the longest edge, lanes 4..6), D from the
     * vertex nearest C (lanes 0..2): one-hot masks that pick the lowest lane among equals, like the
     * scalar comparison chains (a lane wins over a higher lane on >=, over a lower one only on >). Both
     * in one movemask: the near bits in 0..2, the longest-edge bits in 4..6. */
    const __m256 c1 = _mm256_blend_ps(_mm256_blend_ps(_mm256_cmp_ps(L, L1, _CMP_LT_OQ), _mm256_cmp_ps(L, L1, _CMP_LE_OQ), 0x03),
                                      _mm256_blend_ps(_mm256_cmp_ps(L, L1, _CMP_GT_OQ), _mm256_cmp_ps(L, L1, _CMP_GE_OQ), 0x30), 0xF0);
    const __m256 c2 = _mm256_blend_ps(_mm256_blend_ps(_mm256_cmp_ps(L, L2, _CMP_LT_OQ), _mm256_cmp_ps(L, L2, _CMP_LE_OQ), 0x01),
                                      _mm256_blend_ps(_mm256_cmp_ps(L, L2, _CMP_GT_OQ), _mm256_cmp_ps(L, L2, _CMP_GE_OQ), 0x10), 0xF0);
    const unsigned pick = (unsigned)_mm256_movemask_ps(_mm256_and_ps(c1, c2));
    /* tzcnt of an empty mask (NaN lengths only) is 32, i.e. lane 0: defined, and the result is garbage
     * either way. */
    const __m256i il = _mm256_set1_epi32((int)_tzcnt_u32(pick & 0x70u));
    const __m256i in = _mm256_set1_epi32((int)_tzcnt_u32(pick & 0x07u));
    /* World D, whose sign is the light-space D's times det(m)'s, a factor the edges drop as well. */
    const __m256 d = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_permutevar8x32_ps(W[0], in), _mm256_permutevar8x32_ps(ux, il)),
                                                 _mm256_mul_ps(_mm256_permutevar8x32_ps(W[1], in), _mm256_permutevar8x32_ps(uy, il))),
                                   _mm256_mul_ps(_mm256_permutevar8x32_ps(W[2], in), _mm256_permutevar8x32_ps(uz, il)));
    /* The light-space normal, for the clip edges only (dead code without them). */
    const __m256 sx = _mm256_permutevar8x32_ps(ex, il), sy = _mm256_permutevar8x32_ps(ey, il),
                 sz = _mm256_permutevar8x32_ps(ez, il);

    /* Clip edges in lanes 3 (N) and 4 (F), unflipped until the lower/upper split (see
     * scanline_avx512.c); lanes not in use become the constant edge (0, 0, 1). */
    const __m256 needv = clip ? ms_lanes(need) : ms_lanes(0x07);
    __m256 EX, EY, EZu;
    if (clip) {
        const __m256 cl = _mm256_setr_ps(0, 0, 0, f->near, f->far, 0, 0, 0);
        const __m256 neg3 = _mm256_setr_ps(0, 0, 0, -0.0f, 0, 0, 0, 0);
        EX = _mm256_and_ps(needv, _mm256_blend_ps(_mm256_xor_ps(_mm256_mul_ps(cl, sx), neg3), ex, 0x07));
        EY = _mm256_and_ps(needv, _mm256_blend_ps(_mm256_xor_ps(_mm256_mul_ps(cl, sy), neg3), ey, 0x07));
        EZu = _mm256_blendv_ps(_mm256_set1_ps(1.0f),
                               _mm256_blend_ps(_mm256_xor_ps(_mm256_sub_ps(_mm256_mul_ps(cl, sz), d), neg3), ez, 0x07),
                               needv);
    } else {
        EX = _mm256_blend_ps(_mm256_setzero_ps(), ex, 0x07);
        EY = _mm256_blend_ps(_mm256_setzero_ps(), ey, 0x07);
        EZu = _mm256_blend_ps(_mm256_set1_ps(1.0f), ez, 0x07);
    }
    /* Slopes -1/e_x (garbage where e_x is 0, masked below); it does not wait for D. */
    const __m256 r = _mm256_div_ps(_mm256_set1_ps(-1.0f), EX);

    const float d_s = _mm256_cvtss_f32(d);
    if (!(d_s != 0.0f)) return 0;
    if (f->cull_backfaces && d_s > 0.0f) return 0; /* world D > 0: facing away from C */

    /* Scanline setup over the 8 lanes (ms_scan_setup_run); the classification uses magnitudes only. */
    const __m256 absmask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
    const __m256 ax = _mm256_mul_ps(_mm256_and_ps(EX, absmask), _mm256_set1_ps(kf));
    const __m256 ay = _mm256_mul_ps(_mm256_and_ps(EY, absmask), _mm256_set1_ps(kf));
    const __m256 az = _mm256_and_ps(EZu, absmask);
    const __m256 flat = _mm256_set1_ps(MS_FLAT_EDGE);
    const __m256 steep = _mm256_cmp_ps(ax, _mm256_mul_ps(flat, _mm256_max_ps(ay, az)), _CMP_GT_OQ);
    const __m256 flat_y = _mm256_andnot_ps(steep, _mm256_cmp_ps(ay, _mm256_mul_ps(flat, az), _CMP_GT_OQ));
    /* Two-sided: the active edges flipped by D's sign bit (the paper culls D <= 0). */
    const __m256 sgn = _mm256_and_ps(d, _mm256_set1_ps(-0.0f));
    const __m256 EZ = _mm256_xor_ps(EZu, _mm256_and_ps(needv, sgn));
    const __m256 neg_const = _mm256_andnot_ps(_mm256_or_ps(steep, flat_y), _mm256_cmp_ps(EZ, _mm256_setzero_ps(), _CMP_LT_OQ));
    if (_mm256_movemask_ps(neg_const)) return 0;
    const __m256 a = _mm256_mul_ps(EY, r), b = _mm256_mul_ps(EZu, r);
    const __m256 lower = _mm256_and_ps(steep, _mm256_cmp_ps(_mm256_xor_ps(EX, sgn), _mm256_setzero_ps(), _CMP_GT_OQ));
    const __m256 upper = _mm256_andnot_ps(lower, steep);
    _mm256_storeu_ps(sv->al, _mm256_and_ps(lower, a));
    _mm256_storeu_ps(sv->bl, _mm256_and_ps(lower, b));
    _mm256_storeu_ps(sv->au, _mm256_and_ps(upper, a));
    _mm256_storeu_ps(sv->bu, _mm256_blendv_ps(_mm256_set1_ps(kf - 1.0f), b, upper));
    /* Sample range: the box of the projected vertices when in front of C (y/z in lanes 0..2, x/z in
     * 4..6; the minimum in lanes 0 and 4), then the flat edges' bounds on y. */
    int y0 = 0, y1 = k - 1;
    if (zmin_s > 0.0f) {
        const __m256 num = _mm256_permute2f128_ps(V[1], V[0], 0x20);
        const __m256 den = _mm256_blend_ps(_mm256_permute2f128_ps(V[2], V[2], 0x00), _mm256_set1_ps(1.0f), 0x88);
        const __m256 p = _mm256_div_ps(num, den);
        const __m256 p1 = _mm256_permutevar8x32_ps(p, rot1), p2 = _mm256_permutevar8x32_ps(p, rot2);
        const __m256 lim_lo = _mm256_set1_ps(-1.0f), lim_hi = _mm256_set1_ps(kf), slack = _mm256_set1_ps(MS_BOX_SLACK);
        const __m256 lo = _mm256_min_ps(_mm256_max_ps(_mm256_sub_ps(_mm256_min_ps(_mm256_min_ps(p, p1), p2), slack), lim_lo), lim_hi);
        const __m256 hi = _mm256_min_ps(_mm256_max_ps(_mm256_add_ps(_mm256_max_ps(_mm256_max_ps(p, p1), p2), slack), lim_lo), lim_hi);
        const __m256i ilo = _mm256_max_epi32(_mm256_cvtps_epi32(_mm256_round_ps(lo, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC)),
                                             _mm256_setzero_si256());
        const __m256i ihi = _mm256_min_epi32(_mm256_cvtps_epi32(_mm256_round_ps(hi, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)),
                                             _mm256_set1_epi32(k - 1));
        if (_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(ilo, ihi))) & 0x11) return 0;
        y0 = _mm256_cvtsi256_si32(ilo);
        y1 = _mm256_cvtsi256_si32(ihi);
    }
    const int flat_bits = _mm256_movemask_ps(flat_y);
    if (flat_bits) {
        /* Rare (an edge parallel to the scanlines): its own division. */
        const __m256 yb = _mm256_min_ps(_mm256_max_ps(_mm256_div_ps(_mm256_sub_ps(_mm256_setzero_ps(), EZu),
                                                                    _mm256_blendv_ps(_mm256_set1_ps(1.0f), EY, flat_y)),
                                                      _mm256_set1_ps(-1.0f)),
                                        _mm256_set1_ps(kf));
        const int up = _mm256_movemask_ps(_mm256_and_ps(flat_y, _mm256_cmp_ps(_mm256_xor_ps(EY, sgn), _mm256_setzero_ps(), _CMP_GT_OQ)));
        const int dn = flat_bits & ~up;
        float yv[8];
        _mm256_storeu_ps(yv, yb);
        ms_flat_y_bounds(yv, (unsigned)up, (unsigned)dn, k, &y0, &y1);
    }
    sv->y0 = y0;
    sv->y1 = y1;
    return y0 <= y1;
}

/* First and last covered sample of scanlines ybase..ybase+7, over the first NE edge lanes; *out marks
 * (all ones) the rows outside [y0, y1]. No clamping, as in the AVX-512 rows: out-of-range bounds and NaN
 * convert to shift counts of at least the lane width, or to the integer indefinite value, and shift to
 * 0: an empty interval. */
static inline __attribute__((always_inline)) void ms_interval8(const ms_scan_vec *v, const int ne, int ybase, float kf,
                                                               __m256i *l, __m256i *h, __m256i *out)
{
    const __m256i yi = _mm256_add_epi32(_mm256_set1_epi32(ybase), ms_idx8(0, 1, 2, 3, 4, 5, 6, 7));
    const __m256 y = _mm256_cvtepi32_ps(yi);
    __m256 lo[5], hi[5];
    for (int e = 0; e < ne; e++) {
        lo[e] = _mm256_fmadd_ps(_mm256_set1_ps(v->al[e]), y, _mm256_set1_ps(v->bl[e]));
        hi[e] = _mm256_fmadd_ps(_mm256_set1_ps(v->au[e]), y, _mm256_set1_ps(v->bu[e]));
    }
    /* Pairwise, for a short dependency chain; max(x, 0) and min(x, k-1) are the buffer's edges. */
    const __m256 l01 = _mm256_max_ps(lo[0], lo[1]), h01 = _mm256_min_ps(hi[0], hi[1]);
    __m256 l2 = _mm256_max_ps(lo[2], _mm256_setzero_ps()), h2 = _mm256_min_ps(hi[2], _mm256_set1_ps(kf - 1.0f));
    if (ne == 5) {
        l2 = _mm256_max_ps(l2, _mm256_max_ps(lo[3], lo[4]));
        h2 = _mm256_min_ps(h2, _mm256_min_ps(hi[3], hi[4]));
    }
    *l = _mm256_cvtps_epi32(_mm256_round_ps(_mm256_max_ps(l01, l2), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC));
    *h = _mm256_cvtps_epi32(_mm256_round_ps(_mm256_min_ps(h01, h2), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC));
    *out = _mm256_or_si256(_mm256_cmpgt_epi32(_mm256_set1_epi32(v->y0), yi), _mm256_cmpgt_epi32(yi, _mm256_set1_epi32(v->y1)));
}

static inline __attribute__((always_inline)) void ms_rows16(const ms_scan_vec *v, const int ne, void *buf_)
{
    /* Bits [l, h] of each 16-bit word, in 32-bit lanes: (ones << l) & (ones >> (15 - h)); the second
     * factor keeps every lane below 2^16, so the unsigned saturating pack is a plain narrowing. Both
     * groups of 8 rows always, as the AVX-512 variant does its 16: no loop branch to mispredict. */
    const __m256i ones = _mm256_set1_epi32(0xFFFF), c15 = _mm256_set1_epi32(15);
    __m256i cov[2];
    for (int g = 0; g < 2; g++) {
        __m256i l, h, out;
        ms_interval8(v, ne, 8 * g, 16.0f, &l, &h, &out);
        cov[g] = _mm256_andnot_si256(out, _mm256_and_si256(_mm256_sllv_epi32(ones, l),
                                                           _mm256_srlv_epi32(ones, _mm256_sub_epi32(c15, h))));
    }
    /* packus interleaves 128-bit halves: rows 0-3, 8-11, 4-7, 12-15; vpermq puts them in order. */
    const __m256i c16 = _mm256_permute4x64_epi64(_mm256_packus_epi32(cov[0], cov[1]), 0xD8);
    __m256i *p = (__m256i *)buf_;
    _mm256_storeu_si256(p, _mm256_andnot_si256(c16, _mm256_loadu_si256(p)));
}

static inline __attribute__((always_inline)) void ms_rows32(const ms_scan_vec *v, const int ne, void *buf_)
{
    uint32_t *buf = (uint32_t *)buf_;
    const __m256i ones = _mm256_set1_epi32(-1), c31 = _mm256_set1_epi32(31);
    for (int ybase = v->y0 & ~7; ybase <= v->y1; ybase += 8) {
        __m256i l, h, out;
        ms_interval8(v, ne, ybase, 32.0f, &l, &h, &out);
        const __m256i cov = _mm256_andnot_si256(out, _mm256_and_si256(_mm256_sllv_epi32(ones, l),
                                                                      _mm256_srlv_epi32(ones, _mm256_sub_epi32(c31, h))));
        __m256i *p = (__m256i *)(buf + ybase);
        _mm256_storeu_si256(p, _mm256_andnot_si256(cov, _mm256_loadu_si256(p)));
    }
}

static inline __attribute__((always_inline)) void ms_rows64(const ms_scan_vec *v, const int ne, void *buf_)
{
    uint64_t *buf = (uint64_t *)buf_;
    const __m256i ones = _mm256_set1_epi64x(-1), c63 = _mm256_set1_epi64x(63);
    for (int ybase = v->y0 & ~7; ybase <= v->y1; ybase += 8) {
        __m256i l, h, out;
        ms_interval8(v, ne, ybase, 64.0f, &l, &h, &out);
        /* Sign-extended to 64-bit counts: negative (indefinite) values become huge, hence 0 bits. */
        for (int half = 0; half < 2; half++) {
            const __m256i l64 = _mm256_cvtepi32_epi64(half ? _mm256_extracti128_si256(l, 1) : _mm256_castsi256_si128(l));
            const __m256i h64 = _mm256_cvtepi32_epi64(half ? _mm256_extracti128_si256(h, 1) : _mm256_castsi256_si128(h));
            const __m256i o64 = _mm256_cvtepi32_epi64(half ? _mm256_extracti128_si256(out, 1) : _mm256_castsi256_si128(out));
            const __m256i cov = _mm256_andnot_si256(o64, _mm256_and_si256(_mm256_sllv_epi64(ones, l64),
                                                                          _mm256_srlv_epi64(ones, _mm256_sub_epi64(c63, h64))));
            __m256i *p = (__m256i *)(buf + ybase + 4 * half);
            _mm256_storeu_si256(p, _mm256_andnot_si256(cov, _mm256_loadu_si256(p)));
        }
    }
}

/* Without an active clip edge (the common case) the setup is shorter and the rows evaluate three
 * edge lanes instead of five. */
#define MS_SCANLINE_AVX2(K)                                                                  \
    void ms_scanline_##K##_avx2(const ms_raster_frame *f, const float tri[9], void *out)     \
    {                                                                                        \
        ms_scan_vec v;                                                                       \
        const int r = ms_scan_vec_setup(f, tri, &v, 0);                                      \
        if (r > 0) ms_rows##K(&v, 3, out);                                                   \
        else if (r < 0 && ms_scan_vec_setup(f, tri, &v, 1) > 0) ms_rows##K(&v, 5, out);      \
    }
MS_SCANLINE_AVX2(16)
MS_SCANLINE_AVX2(32)
MS_SCANLINE_AVX2(64)
