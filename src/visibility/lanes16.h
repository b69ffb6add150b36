/* Sixteen float lanes, one per frustum of a 4x4 pixel block (Benthin & Wald 2009: "one frustum per
 * SIMD lane"), for the multi-frusta traversals. One set of operations, three implementations chosen by
 * the including file's target (core/cpu.h): AVX-512 (one zmm, mask registers), AVX2 (two ymm halves) and
 * portable C (arrays the compiler may vectorize). Every operation is one IEEE single-precision operation
 * per lane (no FMA contraction, correctly rounded division), and min/max return the second operand
 * unless the first is strictly smaller/larger (the SSE rule, written the same way in C), so the three
 * give bit-identical lanes and masks. Masks are 16-bit lane sets (bit i = lane i). */
#ifndef MS_LANES16_H
#define MS_LANES16_H
#include <stdint.h>
#include "core/cpu.h"

#if defined(MS_TARGET_AVX512)
#include <immintrin.h>
typedef __m512 l16;
#define L16_INLINE static inline __attribute__((always_inline))
L16_INLINE l16 l16_set1(float x) { return _mm512_set1_ps(x); }
L16_INLINE l16 l16_load(const float *p) { return _mm512_loadu_ps(p); }
L16_INLINE void l16_store(float *p, l16 a) { _mm512_storeu_ps(p, a); }
L16_INLINE l16 l16_add(l16 a, l16 b) { return _mm512_add_ps(a, b); }
L16_INLINE l16 l16_sub(l16 a, l16 b) { return _mm512_sub_ps(a, b); }
L16_INLINE l16 l16_mul(l16 a, l16 b) { return _mm512_mul_ps(a, b); }
L16_INLINE l16 l16_div(l16 a, l16 b) { return _mm512_div_ps(a, b); }
L16_INLINE l16 l16_min(l16 a, l16 b) { return _mm512_min_ps(a, b); }
L16_INLINE l16 l16_max(l16 a, l16 b) { return _mm512_max_ps(a, b); }
L16_INLINE l16 l16_abs(l16 a) { return _mm512_abs_ps(a); }
L16_INLINE l16 l16_sqrt(l16 a) { return _mm512_sqrt_ps(a); }
L16_INLINE l16 l16_ceil(l16 a) { return _mm512_roundscale_ps(a, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC); }
L16_INLINE l16 l16_floor(l16 a) { return _mm512_roundscale_ps(a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC); }
L16_INLINE void l16_store_int(int32_t *p, l16 a) { _mm512_storeu_si512((void *)p, _mm512_cvttps_epi32(a)); }
L16_INLINE unsigned l16_lt(l16 a, l16 b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
L16_INLINE unsigned l16_le(l16 a, l16 b) { return _mm512_cmp_ps_mask(a, b, _CMP_LE_OQ); }
L16_INLINE unsigned l16_gt(l16 a, l16 b) { return _mm512_cmp_ps_mask(a, b, _CMP_GT_OQ); }
/* Lane i from a where bit i of m is set, else from b. */
L16_INLINE l16 l16_select(unsigned m, l16 a, l16 b) { return _mm512_mask_blend_ps((__mmask16)m, b, a); }
/* A lane permutation (indices 0..15), loaded once and applied to many vectors: lane i of l16_perm(a, p)
 * is lane p[i] of a. */
typedef __m512i l16i;
L16_INLINE l16i l16i_load(const int32_t *p) { return _mm512_loadu_si512((const void *)p); }
L16_INLINE l16 l16_perm(l16 a, l16i p) { return _mm512_permutexvar_ps(p, a); }
/* Sixteen 64-bit words, one per lane (bit sets, e.g. 16 receivers' open samples of one mask word): which lanes
 * have bit b, and bit b cleared on lanes m. */
typedef struct l16w { __m512i lo, hi; } l16w;
L16_INLINE l16w l16w_load(const uint64_t *p) { return (l16w){ _mm512_loadu_si512((const void *)p), _mm512_loadu_si512((const void *)(p + 8)) }; }
L16_INLINE unsigned l16w_bit(l16w w, int b)
{
    const __m512i m = _mm512_set1_epi64((long long)(UINT64_C(1) << b));
    return (unsigned)_mm512_test_epi64_mask(w.lo, m) | (unsigned)_mm512_test_epi64_mask(w.hi, m) << 8;
}
L16_INLINE l16w l16w_clear(l16w w, unsigned m, int b)
{
    const __m512i x = _mm512_set1_epi64((long long)(UINT64_C(1) << b));
    return (l16w){ _mm512_mask_andnot_epi64(w.lo, (__mmask8)(m & 0xffu), x, w.lo), _mm512_mask_andnot_epi64(w.hi, (__mmask8)(m >> 8), x, w.hi) };
}
#elif defined(MS_TARGET_AVX2)
#include <immintrin.h>
typedef struct l16 { __m256 lo, hi; } l16;
#define L16_INLINE static inline __attribute__((always_inline))
#define L16_OP(name, intr) \
    L16_INLINE l16 name(l16 a, l16 b) { return (l16){ intr(a.lo, b.lo), intr(a.hi, b.hi) }; }
L16_INLINE l16 l16_set1(float x) { return (l16){ _mm256_set1_ps(x), _mm256_set1_ps(x) }; }
L16_INLINE l16 l16_load(const float *p) { return (l16){ _mm256_loadu_ps(p), _mm256_loadu_ps(p + 8) }; }
L16_INLINE void l16_store(float *p, l16 a) { _mm256_storeu_ps(p, a.lo); _mm256_storeu_ps(p + 8, a.hi); }
L16_OP(l16_add, _mm256_add_ps)
L16_OP(l16_sub, _mm256_sub_ps)
L16_OP(l16_mul, _mm256_mul_ps)
L16_OP(l16_div, _mm256_div_ps)
L16_OP(l16_min, _mm256_min_ps)
L16_OP(l16_max, _mm256_max_ps)
L16_INLINE l16 l16_abs(l16 a)
{
    const __m256 s = _mm256_set1_ps(-0.0f);
    return (l16){ _mm256_andnot_ps(s, a.lo), _mm256_andnot_ps(s, a.hi) };
}
L16_INLINE l16 l16_sqrt(l16 a) { return (l16){ _mm256_sqrt_ps(a.lo), _mm256_sqrt_ps(a.hi) }; }
L16_INLINE l16 l16_ceil(l16 a) { return (l16){ _mm256_ceil_ps(a.lo), _mm256_ceil_ps(a.hi) }; }
L16_INLINE l16 l16_floor(l16 a) { return (l16){ _mm256_floor_ps(a.lo), _mm256_floor_ps(a.hi) }; }
L16_INLINE void l16_store_int(int32_t *p, l16 a)
{
    _mm256_storeu_si256((__m256i *)p, _mm256_cvttps_epi32(a.lo));
    _mm256_storeu_si256((__m256i *)(p + 8), _mm256_cvttps_epi32(a.hi));
}
#define L16_CMP(name, pred)                                                                   \
    L16_INLINE unsigned name(l16 a, l16 b)                                                    \
    {                                                                                         \
        return (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(a.lo, b.lo, pred)) |                \
               (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(a.hi, b.hi, pred)) << 8;            \
    }
L16_CMP(l16_lt, _CMP_LT_OQ)
L16_CMP(l16_le, _CMP_LE_OQ)
L16_CMP(l16_gt, _CMP_GT_OQ)
/* A lane mask back to vector form: lane i all ones where bit i is set. */
L16_INLINE __m256 l16_mask8(unsigned m)
{
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    const __m256i v = _mm256_and_si256(_mm256_set1_epi32((int)m), bit);
    return _mm256_castsi256_ps(_mm256_cmpeq_epi32(v, bit));
}
L16_INLINE l16 l16_select(unsigned m, l16 a, l16 b)
{
    return (l16){ _mm256_blendv_ps(b.lo, a.lo, l16_mask8(m & 0xFF)), _mm256_blendv_ps(b.hi, a.hi, l16_mask8(m >> 8)) };
}
/* Lane permutation: each half picks from both halves (vpermps on each, then a blend on index >= 8). */
typedef struct l16i { __m256i lo, hi; __m256 up_lo, up_hi; } l16i;
L16_INLINE l16i l16i_load(const int32_t *p)
{
    const __m256i lo = _mm256_loadu_si256((const __m256i *)p), hi = _mm256_loadu_si256((const __m256i *)(p + 8));
    const __m256i seven = _mm256_set1_epi32(7);
    return (l16i){ lo, hi, _mm256_castsi256_ps(_mm256_cmpgt_epi32(lo, seven)), _mm256_castsi256_ps(_mm256_cmpgt_epi32(hi, seven)) };
}
L16_INLINE l16 l16_perm(l16 a, l16i p)
{
    return (l16){ _mm256_blendv_ps(_mm256_permutevar8x32_ps(a.lo, p.lo), _mm256_permutevar8x32_ps(a.hi, p.lo), p.up_lo),
                  _mm256_blendv_ps(_mm256_permutevar8x32_ps(a.lo, p.hi), _mm256_permutevar8x32_ps(a.hi, p.hi), p.up_hi) };
}
#else
#include <math.h>
typedef struct l16 { float v[16]; } l16;
#define L16_INLINE static inline
#define L16_OP(name, expr)                                         \
    L16_INLINE l16 name(l16 a, l16 b)                              \
    {                                                              \
        l16 r;                                                     \
        for (int i = 0; i < 16; i++) { float x = a.v[i], y = b.v[i]; r.v[i] = (expr); } \
        return r;                                                  \
    }
L16_INLINE l16 l16_set1(float x) { l16 r; for (int i = 0; i < 16; i++) r.v[i] = x; return r; }
L16_INLINE l16 l16_load(const float *p) { l16 r; for (int i = 0; i < 16; i++) r.v[i] = p[i]; return r; }
L16_INLINE void l16_store(float *p, l16 a) { for (int i = 0; i < 16; i++) p[i] = a.v[i]; }
L16_OP(l16_add, x + y)
L16_OP(l16_sub, x - y)
L16_OP(l16_mul, x * y)
L16_OP(l16_div, x / y)
L16_OP(l16_min, x < y ? x : y)
L16_OP(l16_max, x > y ? x : y)
L16_INLINE l16 l16_abs(l16 a) { l16 r; for (int i = 0; i < 16; i++) r.v[i] = a.v[i] < 0.0f ? -a.v[i] : a.v[i] + 0.0f; return r; }
/* Correctly rounded, as the SSE/AVX square roots (IEEE 754). */
L16_INLINE l16 l16_sqrt(l16 a) { l16 r; for (int i = 0; i < 16; i++) r.v[i] = sqrtf(a.v[i]); return r; }
/* Ceiling and floor of values within int range (the callers clamp first): exact by truncation and one
 * step, as ms_ceil_i (ceilf/floorf are library calls without SSE4.1). */
L16_INLINE l16 l16_ceil(l16 a)
{
    l16 r;
    for (int i = 0; i < 16; i++) { const int t = (int)a.v[i]; r.v[i] = (float)(t + ((float)t < a.v[i])); }
    return r;
}
L16_INLINE l16 l16_floor(l16 a)
{
    l16 r;
    for (int i = 0; i < 16; i++) { const int t = (int)a.v[i]; r.v[i] = (float)(t - ((float)t > a.v[i])); }
    return r;
}
L16_INLINE void l16_store_int(int32_t *p, l16 a) { for (int i = 0; i < 16; i++) p[i] = (int32_t)a.v[i]; }
#define L16_CMP(name, op)                                                          \
    L16_INLINE unsigned name(l16 a, l16 b)                                         \
    {                                                                              \
        unsigned m = 0;                                                            \
        for (int i = 0; i < 16; i++) m |= (unsigned)(a.v[i] op b.v[i]) << i;       \
        return m;                                                                  \
    }
L16_CMP(l16_lt, <)
L16_CMP(l16_le, <=)
L16_CMP(l16_gt, >)
L16_INLINE l16 l16_select(unsigned m, l16 a, l16 b)
{
    l16 r;
    for (int i = 0; i < 16; i++) r.v[i] = (m >> i & 1) ? a.v[i] : b.v[i];
    return r;
}
typedef struct l16i { int32_t v[16]; } l16i;
L16_INLINE l16i l16i_load(const int32_t *p) { l16i r; for (int i = 0; i < 16; i++) r.v[i] = p[i]; return r; }
L16_INLINE l16 l16_perm(l16 a, l16i p) { l16 r; for (int i = 0; i < 16; i++) r.v[i] = a.v[p.v[i] & 15]; return r; }
#endif

#if !defined(MS_TARGET_AVX512)
/* l16w (above) as plain words: AVX2 has no 64-bit mask compares worth the shuffles, and integer bits are the same
 * on every path. */
typedef struct l16w { uint64_t w[16]; } l16w;
static inline l16w l16w_load(const uint64_t *p) { l16w r; for (int i = 0; i < 16; i++) r.w[i] = p[i]; return r; }
static inline unsigned l16w_bit(l16w w, int b)
{
    unsigned m = 0;
    for (int i = 0; i < 16; i++) m |= (unsigned)(w.w[i] >> b & 1u) << i;
    return m;
}
static inline l16w l16w_clear(l16w w, unsigned m, int b)
{
    for (int i = 0; i < 16; i++) w.w[i] &= ~((uint64_t)(m >> i & 1u) << b);
    return w;
}
#endif

#endif
