/* The AVX2 + FMA operations under scanline_simd_impl.h, the same names as simd_avx512.h with AVX2 means:
 * masks are compare results (all-ones lanes) or their movemask bits; the two-source permutations are
 * vpermps of the triangle's floats plus a blend; the one-hot picks are a tzcnt of the movemask and a
 * vpermps broadcast instead of compress; two 8-lane divisions instead of one 16-lane one (the box's only
 * when the triangle is in front of C); vroundps + vcvtps2dq instead of embedded rounding. Rows: 8
 * scanlines per group in 32-bit lanes, 4 per instruction for k = 64 in 64-bit lanes. The AVX2 variable
 * shifts (vpsllvd/vpsrlvd/vpsllvq/vpsrlvq) give 0 for counts >= the lane width, like the AVX-512 ones:
 * out-of-range bounds need no clamping. */
#ifndef MS_SIMD_AVX2_H
#define MS_SIMD_AVX2_H
#include <immintrin.h>
#include "raster_internal.h"

#define SI static inline __attribute__((always_inline))

/* --- setup: 8 float lanes, masks as vectors ------------------------------------------------------- */
typedef __m256 vf;
typedef __m256i vi;
typedef __m256 vm;

#define V_CMP(a, b, P) _mm256_cmp_ps((a), (b), (P))
#define V_CMP_IN(m, a, b, P) _mm256_and_ps((m), _mm256_cmp_ps((a), (b), (P)))
/* All ones in lane i where bit i of bits is set. */
SI vm m_lanes(unsigned bits)
{
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32((int)bits), bit), bit));
}
SI vm m_and(vm a, vm b) { return _mm256_and_ps(a, b); }
SI vm m_andnot(vm a, vm b) { return _mm256_andnot_ps(a, b); }
SI vm m_or(vm a, vm b) { return _mm256_or_ps(a, b); }
SI unsigned m_bits(vm m) { return (unsigned)_mm256_movemask_ps(m); }
SI vf v_perm(vf v, vi idx) { return _mm256_permutevar8x32_ps(v, idx); }
SI vi v_blend_idx(vm m, vi a, vi b)
{
    return _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(a), _mm256_castsi256_ps(b), m));
}
SI vf v_select(vm m, vf a, vf b) { return _mm256_blendv_ps(a, b, m); }
SI vf v_maskz(vm m, vf v) { return _mm256_and_ps(m, v); }
SI vf v_mask_xor(vf a, vm m, vf b) { return _mm256_xor_ps(a, _mm256_and_ps(m, b)); }
SI vm vi_cmpgt(vi a, vi b) { return _mm256_castsi256_ps(_mm256_cmpgt_epi32(a, b)); }

/* World coordinates: lane i = P_i - C, lane 4+i = P_{i+2} - P_{i+1} (the edge opposite vertex i),
 * lanes 3 and 7 = x - x = 0. Coordinate a of vertex i is tri[3i + a]: x and y come from the first eight
 * floats, z from floats 1..8 (one lane further on), so both loads stay inside the triangle. */
SI void ms_world(const ms_raster_frame *f, const float tri[9], vf W[3])
{
    const __m256 T01 = _mm256_loadu_ps(tri), T2 = _mm256_loadu_ps(tri + 1);
    for (int a = 0; a < 3; a++) {
        const __m256 src = a == 2 ? T2 : T01;
        const int o = a == 2 ? 1 : a;
        const __m256i ia = _mm256_setr_epi32(o, 3 + o, 6 + o, 0, 6 + o, o, 3 + o, 0);
        const __m256i ib = _mm256_setr_epi32(0, 0, 0, 0, 3 + o, 6 + o, o, 0);
        W[a] = _mm256_sub_ps(_mm256_permutevar8x32_ps(src, ia),
                             _mm256_blend_ps(_mm256_permutevar8x32_ps(src, ib), _mm256_set1_ps(f->c[a]), 0x07));
    }
}

/* The one-hot lane picks (see simd_avx512.h), as broadcast permutation indices: both in one movemask,
 * the near bits in 0..2, the longest-edge bits in 4..6. tzcnt of an empty mask (NaN lengths only) is
 * 32, i.e. lane 0: defined, and the result is garbage either way. */
typedef __m256i vpick;
SI void ms_picks(vf L, vf L1, vf L2, vpick *near, vpick *longest)
{
    const __m256 c1 = _mm256_blend_ps(_mm256_blend_ps(_mm256_cmp_ps(L, L1, _CMP_LT_OQ), _mm256_cmp_ps(L, L1, _CMP_LE_OQ), 0x03),
                                      _mm256_blend_ps(_mm256_cmp_ps(L, L1, _CMP_GT_OQ), _mm256_cmp_ps(L, L1, _CMP_GE_OQ), 0x30), 0xF0);
    const __m256 c2 = _mm256_blend_ps(_mm256_blend_ps(_mm256_cmp_ps(L, L2, _CMP_LT_OQ), _mm256_cmp_ps(L, L2, _CMP_LE_OQ), 0x01),
                                      _mm256_blend_ps(_mm256_cmp_ps(L, L2, _CMP_GT_OQ), _mm256_cmp_ps(L, L2, _CMP_GE_OQ), 0x10), 0xF0);
    const unsigned pick = (unsigned)_mm256_movemask_ps(_mm256_and_ps(c1, c2));
    *longest = _mm256_set1_epi32((int)_tzcnt_u32(pick & 0x70u));
    *near = _mm256_set1_epi32((int)_tzcnt_u32(pick & 0x07u));
}
SI vf v_pick(vpick p, vf v) { return _mm256_permutevar8x32_ps(v, p); }

/* The slopes' 8-lane division now; the projected box's only when asked for (in front of C). */
typedef struct ms_quot { __m256 r; } ms_quot;
SI void ms_divide(vf EX, const vf V[3], ms_quot *d)
{
    (void)V;
    d->r = _mm256_div_ps(_mm256_set1_ps(-1.0f), EX);
}
SI vf ms_quot_slopes(const ms_quot *d) { return d->r; }
SI vf ms_quot_box(const ms_quot *d, const vf V[3])
{
    (void)d;
    const __m256 num = _mm256_permute2f128_ps(V[1], V[0], 0x20);
    const __m256 den = _mm256_blend_ps(_mm256_permute2f128_ps(V[2], V[2], 0x00), _mm256_set1_ps(1.0f), 0x88);
    return _mm256_div_ps(num, den);
}

/* --- rows: 8 scanlines per group ------------------------------------------------------------------ */
#define MS_R 8
typedef __m256 rf;
typedef __m256i ri;
typedef __m256i rm; /* all ones: rows outside [y0, y1] */

SI ri r_iota(int ybase) { return _mm256_add_epi32(_mm256_set1_epi32(ybase), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)); }
SI rf r_cvt(ri v) { return _mm256_cvtepi32_ps(v); }
SI rf r_fmadd(float a, rf y, float b) { return _mm256_fmadd_ps(_mm256_set1_ps(a), y, _mm256_set1_ps(b)); }
SI rf r_max(rf a, rf b) { return _mm256_max_ps(a, b); }
SI rf r_min(rf a, rf b) { return _mm256_min_ps(a, b); }
SI rf r_set1(float a) { return _mm256_set1_ps(a); }
SI ri r_ceil_i(rf v) { return _mm256_cvtps_epi32(_mm256_round_ps(v, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC)); }
SI ri r_floor_i(rf v) { return _mm256_cvtps_epi32(_mm256_round_ps(v, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)); }
SI rm r_rows(ri yi, int y0, int y1)
{
    return _mm256_or_si256(_mm256_cmpgt_epi32(_mm256_set1_epi32(y0), yi), _mm256_cmpgt_epi32(yi, _mm256_set1_epi32(y1)));
}
SI ri r_cover32(ri l, ri h, rm rows, int ones, int top)
{
    const __m256i o = _mm256_set1_epi32(ones);
    return _mm256_andnot_si256(rows, _mm256_and_si256(_mm256_sllv_epi32(o, l), _mm256_srlv_epi32(o, _mm256_sub_epi32(_mm256_set1_epi32(top), h))));
}
/* k = 16: the second factor of the cover keeps every lane below 2^16, so the unsigned saturating pack
 * is a plain narrowing; packus interleaves 128-bit halves (rows 0-3, 8-11, 4-7, 12-15), vpermq puts
 * them in order. */
SI void r_clear16(uint16_t *buf, const ri cov[16 / MS_R])
{
    const __m256i c16 = _mm256_permute4x64_epi64(_mm256_packus_epi32(cov[0], cov[1]), 0xD8);
    __m256i *p = (__m256i *)buf;
    _mm256_storeu_si256(p, _mm256_andnot_si256(c16, _mm256_loadu_si256(p)));
}
SI void r_clear32(uint32_t *buf, ri cov)
{
    __m256i *p = (__m256i *)buf;
    _mm256_storeu_si256(p, _mm256_andnot_si256(cov, _mm256_loadu_si256(p)));
}
/* k = 64: sign-extended to 64-bit counts (negative, indefinite values become huge, hence 0 bits), four
 * rows per instruction. */
SI void r_clear64(uint64_t *buf, ri l, ri h, rm out)
{
    const __m256i ones = _mm256_set1_epi64x(-1), c63 = _mm256_set1_epi64x(63);
    for (int half = 0; half < 2; half++) {
        const __m256i l64 = _mm256_cvtepi32_epi64(half ? _mm256_extracti128_si256(l, 1) : _mm256_castsi256_si128(l));
        const __m256i h64 = _mm256_cvtepi32_epi64(half ? _mm256_extracti128_si256(h, 1) : _mm256_castsi256_si128(h));
        const __m256i o64 = _mm256_cvtepi32_epi64(half ? _mm256_extracti128_si256(out, 1) : _mm256_castsi256_si128(out));
        const __m256i cov = _mm256_andnot_si256(o64, _mm256_and_si256(_mm256_sllv_epi64(ones, l64),
                                                                      _mm256_srlv_epi64(ones, _mm256_sub_epi64(c63, h64))));
        __m256i *p = (__m256i *)(buf + 4 * half);
        _mm256_storeu_si256(p, _mm256_andnot_si256(cov, _mm256_loadu_si256(p)));
    }
}

#endif
