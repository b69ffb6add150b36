/* The AVX-512 operations under scanline_simd_impl.h (see simd_avx2.h for the AVX2 ones; both define
 * the same names). Setup vectors are 8 lanes (__m256) with k-masks; the rows are 16 scanlines per
 * instruction (__m512, __mmask16). What makes this variant fast is kept here: two-source permutes for
 * the world vectors, compress for the one-hot lane picks, one 16-lane division for the slopes and the
 * projected box, embedded rounding in the row conversions. */
#ifndef MS_SIMD_AVX512_H
#define MS_SIMD_AVX512_H
#include <immintrin.h>
#include <stddef.h>
#include "raster_internal.h"

#define SI static inline __attribute__((always_inline))

_Static_assert(offsetof(ms_raster_frame, near) == offsetof(ms_raster_frame, c) + 3 * sizeof(float),
               "the setup loads c[0..2] with the float after it");

/* --- setup: 8 float lanes, masks ------------------------------------------------------------------ */
typedef __m256 vf;
typedef __m256i vi;
typedef __mmask8 vm;

#define V_CMP(a, b, P) _mm256_cmp_ps_mask((a), (b), (P))
/* The comparison in lanes m only (0 elsewhere). */
#define V_CMP_IN(m, a, b, P) _mm256_mask_cmp_ps_mask((m), (a), (b), (P))
SI vm m_lanes(unsigned bits) { return (vm)bits; }
SI vm m_and(vm a, vm b) { return (vm)(a & b); }
SI vm m_andnot(vm a, vm b) { return (vm)(~a & b); }
SI vm m_or(vm a, vm b) { return (vm)(a | b); }
SI unsigned m_bits(vm m) { return m; }
SI vf v_perm(vf v, vi idx) { return _mm256_permutexvar_ps(idx, v); }
/* b where m, else a */
SI vi v_blend_idx(vm m, vi a, vi b) { return _mm256_mask_blend_epi32(m, a, b); }
SI vf v_select(vm m, vf a, vf b) { return _mm256_mask_blend_ps(m, a, b); }
SI vf v_maskz(vm m, vf v) { return _mm256_maskz_mov_ps(m, v); }
/* a ^ b in lanes m, a elsewhere */
SI vf v_mask_xor(vf a, vm m, vf b) { return _mm256_mask_xor_ps(a, m, a, b); }
SI vm vi_cmpgt(vi a, vi b) { return _mm256_cmp_epi32_mask(a, b, _MM_CMPINT_NLE); }

/* World coordinates: lane i = P_i - C, lane 4+i = P_{i+2} - P_{i+1} (the edge opposite vertex i), by
 * two-source permutations of the first eight floats and of (C, the ninth float); lanes 3 and 7 are
 * x - x = 0. Plain loads: f->c is followed by f->near, so four floats are there to read. */
SI void ms_world(const ms_raster_frame *f, const float tri[9], vf W[3])
{
    const __m256 T = _mm256_loadu_ps(tri);
    const __m256 S = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f->c)), _mm_broadcast_ss(tri + 8), 1);
    const __m256i ia[3] = { _mm256_setr_epi32(0, 3, 6, 0, 6, 0, 3, 0), _mm256_setr_epi32(1, 4, 7, 0, 7, 1, 4, 0),
                            _mm256_setr_epi32(2, 5, 12, 0, 12, 2, 5, 0) };
    const __m256i ib[3] = { _mm256_setr_epi32(8, 8, 8, 0, 3, 6, 0, 0), _mm256_setr_epi32(9, 9, 9, 0, 4, 7, 1, 0),
                            _mm256_setr_epi32(10, 10, 10, 0, 5, 12, 2, 0) };
    for (int a = 0; a < 3; a++)
        W[a] = _mm256_sub_ps(_mm256_permutex2var_ps(T, ia[a], S), _mm256_permutex2var_ps(T, ib[a], S));
}

/* The one-hot lane picks of the setup: the vertex nearest C (lanes 0..2 of the squared lengths L) and
 * the longest edge (lanes 4..6), the lowest lane among equals like the scalar comparison chains (lane i
 * wins over a higher lane on >=, over a lower one only on >). L1, L2: L rotated within each triple. */
typedef __mmask8 vpick;
SI void ms_picks(vf L, vf L1, vf L2, vpick *near, vpick *longest)
{
    *longest = (vpick)((_mm256_mask_cmp_ps_mask(0x30, L, L1, _CMP_GE_OQ) | _mm256_mask_cmp_ps_mask(0x40, L, L1, _CMP_GT_OQ)) &
                       (_mm256_mask_cmp_ps_mask(0x10, L, L2, _CMP_GE_OQ) | _mm256_mask_cmp_ps_mask(0x60, L, L2, _CMP_GT_OQ)));
    *near = (vpick)((_mm256_mask_cmp_ps_mask(0x03, L, L1, _CMP_LE_OQ) | _mm256_mask_cmp_ps_mask(0x04, L, L1, _CMP_LT_OQ)) &
                    (_mm256_mask_cmp_ps_mask(0x01, L, L2, _CMP_LE_OQ) | _mm256_mask_cmp_ps_mask(0x06, L, L2, _CMP_LT_OQ)));
}
/* The picked lane in every lane: compress + broadcast, no trip through a general register. */
SI vf v_pick(vpick p, vf v) { return _mm256_broadcastss_ps(_mm256_castps256_ps128(_mm256_maskz_compress_ps(p, v))); }

/* The division: one 16-lane vdivps for the slopes -1/e_x (lanes 0..7) and the projected vertices (y/z in
 * lanes 8..10, x/z in 12..14), like the scalar 1/z and products up to rounding, which the box slack
 * absorbs. It starts as soon as EX is known. */
typedef struct ms_quot { __m512 q; } ms_quot;
SI void ms_divide(vf EX, const vf V[3], ms_quot *d)
{
    const __m256 num_hi = _mm256_permutex2var_ps(V[1], _mm256_setr_epi32(0, 1, 2, 3, 8, 9, 10, 11), V[0]);
    const __m256 den_hi = _mm256_mask_blend_ps(0x88, _mm256_permutexvar_ps(_mm256_setr_epi32(0, 1, 2, 3, 0, 1, 2, 3), V[2]),
                                               _mm256_set1_ps(1.0f));
    d->q = _mm512_div_ps(_mm512_insertf32x8(_mm512_set1_ps(-1.0f), num_hi, 1),
                         _mm512_insertf32x8(_mm512_castps256_ps512(EX), den_hi, 1));
}
SI vf ms_quot_slopes(const ms_quot *d) { return _mm512_castps512_ps256(d->q); }
/* y/z in lanes 0..2, x/z in lanes 4..6 */
SI vf ms_quot_box(const ms_quot *d, const vf V[3])
{
    (void)V;
    return _mm512_extractf32x8_ps(d->q, 1);
}

/* --- rows: 16 scanlines per instruction ----------------------------------------------------------- */
#define MS_R 16
typedef __m512 rf;
typedef __m512i ri;
typedef __mmask16 rm; /* rows inside [y0, y1] */

SI ri r_iota(int ybase)
{
    return _mm512_add_epi32(_mm512_set1_epi32(ybase), _mm512_set_epi32(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0));
}
SI rf r_cvt(ri v) { return _mm512_cvtepi32_ps(v); }
SI rf r_fmadd(float a, rf y, float b) { return _mm512_fmadd_ps(_mm512_set1_ps(a), y, _mm512_set1_ps(b)); }
SI rf r_max(rf a, rf b) { return _mm512_max_ps(a, b); }
SI rf r_min(rf a, rf b) { return _mm512_min_ps(a, b); }
SI rf r_set1(float a) { return _mm512_set1_ps(a); }
/* Rounding conversions with the embedded rounding mode. */
SI ri r_ceil_i(rf v) { return _mm512_cvt_roundps_epi32(v, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC); }
SI ri r_floor_i(rf v) { return _mm512_cvt_roundps_epi32(v, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC); }
SI rm r_rows(ri yi, int y0, int y1)
{
    return _mm512_cmp_epi32_mask(yi, _mm512_set1_epi32(y0), _MM_CMPINT_NLT) & _mm512_cmp_epi32_mask(yi, _mm512_set1_epi32(y1), _MM_CMPINT_LE);
}
/* Bits [l, h] of each row in 32-bit lanes, (ones << l) & (ones >> (top - h)), 0 outside the rows. */
SI ri r_cover32(ri l, ri h, rm rows, int ones, int top)
{
    const __m512i o = _mm512_set1_epi32(ones);
    return _mm512_maskz_and_epi32(rows, _mm512_sllv_epi32(o, l), _mm512_srlv_epi32(o, _mm512_sub_epi32(_mm512_set1_epi32(top), h)));
}
/* buf[0..15] &= ~cov (k = 16: the lanes hold 16-bit rows, narrowed). */
SI void r_clear16(uint16_t *buf, const ri cov[16 / MS_R])
{
    __m256i *b = (__m256i *)buf;
    _mm256_storeu_si256(b, _mm256_andnot_si256(_mm512_cvtepi32_epi16(cov[0]), _mm256_loadu_si256(b)));
}
SI void r_clear32(uint32_t *buf, ri cov) { _mm512_storeu_si512(buf, _mm512_andnot_si512(cov, _mm512_loadu_si512(buf))); }
/* k = 64: the 16 rows' bounds widened to 64-bit lanes, 8 rows per instruction. */
SI void r_clear64(uint64_t *buf, ri l, ri h, rm rows)
{
    const __m512i ones = _mm512_set1_epi64(-1), c63 = _mm512_set1_epi64(63);
    for (int half = 0; half < 2; half++) {
        const __m512i l64 = _mm512_cvtepi32_epi64(half ? _mm512_extracti64x4_epi64(l, 1) : _mm512_castsi512_si256(l));
        const __m512i h64 = _mm512_cvtepi32_epi64(half ? _mm512_extracti64x4_epi64(h, 1) : _mm512_castsi512_si256(h));
        const __mmask8 r8 = (__mmask8)(half ? rows >> 8 : rows);
        const __m512i cov = _mm512_maskz_and_epi64(r8, _mm512_sllv_epi64(ones, l64), _mm512_srlv_epi64(ones, _mm512_sub_epi64(c63, h64)));
        uint64_t *p = buf + 8 * half;
        _mm512_storeu_si512(p, _mm512_andnot_si512(cov, _mm512_loadu_si512(p)));
    }
}

#endif
