/* AVX-512 Scanline kernels: sixteen scanlines per instruction. The per-scanline work of sec. 4 (bounds
 * a*y + b, max of lower and min of upper bounds, ceil/floor, the shift/mask) maps lane for lane onto
 * 16-wide float and integer vectors; the rounding conversions come for free with the embedded rounding
 * mode, and the variable shifts (vpsllv/vpsrlv) give 0 for counts >= the lane width, which is exactly the
 * behaviour the paper had to emulate. Setup is the scalar one (raster_internal.h). */
#include <immintrin.h>
#include "raster_internal.h"

/* Lower and upper bounds padded to 4 each with neutral ones (0 and k-1), so that every group of 16
 * scanlines runs the same straight-line code whatever the edge signs. */
typedef struct ms_scan_vec {
    __m512 al[4], bl[4], au[4], bu[4];
} ms_scan_vec;

static inline __attribute__((always_inline)) int ms_scan_vec_setup(const ms_raster_frame *f, const float tri[9],
                                                                   ms_scan_setup *s, ms_scan_vec *v)
{
    ms_tri_setup t;
    if (!ms_tri_setup_run(f, tri, &t) || !ms_scan_setup_run(f, &t, s)) return 0;
    const float kmax = (float)(f->k - 1);
    for (int e = 0; e < 4; e++) {
        v->al[e] = _mm512_set1_ps(e < s->nl ? s->al[e] : 0.0f);
        v->bl[e] = _mm512_set1_ps(e < s->nl ? s->bl[e] : 0.0f);
        v->au[e] = _mm512_set1_ps(e < s->nu ? s->au[e] : 0.0f);
        v->bu[e] = _mm512_set1_ps(e < s->nu ? s->bu[e] : kmax);
    }
    return 1;
}

/* First and last covered sample of scanlines ybase..ybase+15, as l in [0, k] and h in [-1, k-1] (empty
 * when l > h); rows outside [y0, y1] are marked in *rows. */
static inline __attribute__((always_inline)) void ms_interval16(const ms_scan_vec *v, const ms_scan_setup *s, int ybase,
                                                                float kf, __m512i *l, __m512i *h, __mmask16 *rows)
{
    const __m512i yi = _mm512_add_epi32(_mm512_set1_epi32(ybase),
                                        _mm512_set_epi32(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0));
    const __m512 y = _mm512_cvtepi32_ps(yi);
    __m512 lo = _mm512_setzero_ps(), hi = _mm512_set1_ps(kf - 1.0f);
    for (int e = 0; e < 4; e++) {
        lo = _mm512_max_ps(lo, _mm512_fmadd_ps(v->al[e], y, v->bl[e]));
        hi = _mm512_min_ps(hi, _mm512_fmadd_ps(v->au[e], y, v->bu[e]));
    }
    lo = _mm512_min_ps(lo, _mm512_set1_ps(kf));
    hi = _mm512_max_ps(hi, _mm512_set1_ps(-1.0f));
    *l = _mm512_cvt_roundps_epi32(lo, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
    *h = _mm512_cvt_roundps_epi32(hi, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    *rows = _mm512_cmp_epi32_mask(yi, _mm512_set1_epi32(s->y0), _MM_CMPINT_NLT) &
            _mm512_cmp_epi32_mask(yi, _mm512_set1_epi32(s->y1), _MM_CMPINT_LE);
}

void ms_scanline_16_avx512(const ms_raster_frame *f, const float tri[9], void *out)
{
    ms_scan_setup s;
    ms_scan_vec v;
    if (!ms_scan_vec_setup(f, tri, &s, &v)) return;
    __m512i l, h;
    __mmask16 rows;
    ms_interval16(&v, &s, 0, 16.0f, &l, &h, &rows);
    /* Bits [l, h] of each 16-bit word, in 32-bit lanes: (ones << l) & (ones >> (15 - h)). */
    const __m512i ones = _mm512_set1_epi32(0xFFFF);
    const __m512i cov = _mm512_maskz_and_epi32(rows, _mm512_sllv_epi32(ones, l),
                                               _mm512_srlv_epi32(ones, _mm512_sub_epi32(_mm512_set1_epi32(15), h)));
    __m256i *b = (__m256i *)out;
    _mm256_storeu_si256(b, _mm256_andnot_si256(_mm512_cvtepi32_epi16(cov), _mm256_loadu_si256(b)));
}

void ms_scanline_32_avx512(const ms_raster_frame *f, const float tri[9], void *out)
{
    ms_scan_setup s;
    ms_scan_vec v;
    if (!ms_scan_vec_setup(f, tri, &s, &v)) return;
    uint32_t *buf = (uint32_t *)out;
    const __m512i ones = _mm512_set1_epi32(-1);
    for (int ybase = s.y0 & ~15; ybase <= s.y1; ybase += 16) {
        __m512i l, h;
        __mmask16 rows;
        ms_interval16(&v, &s, ybase, 32.0f, &l, &h, &rows);
        const __m512i cov = _mm512_maskz_and_epi32(
            rows, _mm512_sllv_epi32(ones, l), _mm512_srlv_epi32(ones, _mm512_sub_epi32(_mm512_set1_epi32(31), h)));
        _mm512_storeu_si512(buf + ybase, _mm512_andnot_si512(cov, _mm512_loadu_si512(buf + ybase)));
    }
}

void ms_scanline_64_avx512(const ms_raster_frame *f, const float tri[9], void *out)
{
    ms_scan_setup s;
    ms_scan_vec v;
    if (!ms_scan_vec_setup(f, tri, &s, &v)) return;
    uint64_t *buf = (uint64_t *)out;
    const __m512i ones = _mm512_set1_epi64(-1);
    const __m512i c63 = _mm512_set1_epi64(63);
    for (int ybase = s.y0 & ~15; ybase <= s.y1; ybase += 16) {
        __m512i l, h;
        __mmask16 rows;
        ms_interval16(&v, &s, ybase, 64.0f, &l, &h, &rows);
        for (int half = 0; half < 2; half++) {
            const __m512i l64 = _mm512_cvtepi32_epi64(half ? _mm512_extracti64x4_epi64(l, 1) : _mm512_castsi512_si256(l));
            const __m512i h64 = _mm512_cvtepi32_epi64(half ? _mm512_extracti64x4_epi64(h, 1) : _mm512_castsi512_si256(h));
            const __mmask8 r8 = (__mmask8)(half ? rows >> 8 : rows);
            const __m512i cov = _mm512_maskz_and_epi64(r8, _mm512_sllv_epi64(ones, l64),
                                                       _mm512_srlv_epi64(ones, _mm512_sub_epi64(c63, h64)));
            uint64_t *p = buf + ybase + 8 * half;
            _mm512_storeu_si512(p, _mm512_andnot_si512(cov, _mm512_loadu_si512(p)));
        }
    }
}
