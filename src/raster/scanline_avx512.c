/* AVX-512 Scanline kernels: sixteen scanlines per instruction. The per-scanline work of sec. 4 (bounds
 * a*y + b, max of lower and min of upper bounds, ceil/floor, the shift/mask) maps lane for lane onto
 * 16-wide float and integer vectors; the rounding conversions come for free with the embedded rounding
 * mode, and the variable shifts (vpsllv/vpsrlv) give 0 for counts >= the lane width, which is exactly the
 * behaviour the paper had to emulate. Setup is the scalar one (raster_internal.h). */
#include <immintrin.h>
#include "raster_internal.h"

/* Per-triangle data of the row loop: for each of the (up to) five edges a lower and an upper bound
 * a*y + b on x, neutral (0 resp. k-1) where the edge is not of that kind, and the scanline range. */
typedef struct ms_scan_vec {
    float al[8], bl[8], au[8], bu[8];
    int y0, y1;
} ms_scan_vec;

#define MS_SHUF(v, a, b, c, d) _mm_shuffle_ps((v), (v), _MM_SHUFFLE(d, c, b, a))

static inline __m128 ms_hmin3(__m128 v) { return _mm_min_ps(_mm_min_ps(v, MS_SHUF(v, 1, 2, 0, 3)), MS_SHUF(v, 2, 0, 1, 3)); }
static inline __m128 ms_hmax3(__m128 v) { return _mm_max_ps(_mm_max_ps(v, MS_SHUF(v, 1, 2, 0, 3)), MS_SHUF(v, 2, 0, 1, 3)); }
/* Lane i of v broadcast to all lanes (i in a general register). */
static inline __m128 ms_lane(__m128 v, int i) { return _mm_permutevar_ps(v, _mm_set1_epi32(i)); }

/* The setup of raster_internal.h (ms_tri_setup_run + ms_scan_setup_run), vectorised and branch-free but
 * for the rejections: the three vertices (and the three edges) are the lanes of SoA vectors, the five
 * edge equations lanes of 8-wide ones, the slope divisions one vdivps. Same choices of operands (shortest
 * sides), same clip-edge and flat-edge rules, so that it agrees with the scalar kernels away from ties. */
static inline __attribute__((always_inline)) int ms_scan_vec_setup(const ms_raster_frame *f, const float tri[9],
                                                                   ms_scan_vec *sv)
{
    const int k = f->k;
    const float kf = (float)k;
    /* SoA: lane i = vertex i. */
    const __m128 px = _mm_setr_ps(tri[0], tri[3], tri[6], 0.0f);
    const __m128 py = _mm_setr_ps(tri[1], tri[4], tri[7], 0.0f);
    const __m128 pz = _mm_setr_ps(tri[2], tri[5], tri[8], 0.0f);
    const __m128 dx = _mm_sub_ps(px, _mm_set1_ps(f->c[0]));
    const __m128 dy = _mm_sub_ps(py, _mm_set1_ps(f->c[1]));
    const __m128 dz = _mm_sub_ps(pz, _mm_set1_ps(f->c[2]));
    /* World edge opposite vertex i: P[i+2] - P[i+1]. */
    const __m128 wx = _mm_sub_ps(MS_SHUF(px, 2, 0, 1, 3), MS_SHUF(px, 1, 2, 0, 3));
    const __m128 wy = _mm_sub_ps(MS_SHUF(py, 2, 0, 1, 3), MS_SHUF(py, 1, 2, 0, 3));
    const __m128 wz = _mm_sub_ps(MS_SHUF(pz, 2, 0, 1, 3), MS_SHUF(pz, 1, 2, 0, 3));
    __m128 v[3], ed[3];
    for (int r = 0; r < 3; r++) {
        const __m128 m0 = _mm_set1_ps(f->m[r][0]), m1 = _mm_set1_ps(f->m[r][1]), m2 = _mm_set1_ps(f->m[r][2]);
        /* mul + add, not FMA, to round exactly like the scalar setup */
        v[r] = _mm_add_ps(_mm_add_ps(_mm_mul_ps(m0, dx), _mm_mul_ps(m1, dy)), _mm_mul_ps(m2, dz));
        ed[r] = _mm_add_ps(_mm_add_ps(_mm_mul_ps(m0, wx), _mm_mul_ps(m1, wy)), _mm_mul_ps(m2, wz));
    }
    const __m128 zmin = ms_hmin3(v[2]), zmax = ms_hmax3(v[2]);
    const float zmin_s = _mm_cvtss_f32(zmin), zmax_s = _mm_cvtss_f32(zmax);
    if (!(zmax_s >= f->near && zmin_s <= f->far)) return 0;

    const __m128 len2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(v[0], v[0]), _mm_mul_ps(v[1], v[1])), _mm_mul_ps(v[2], v[2]));
    const __m128 elen2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(ed[0], ed[0]), _mm_mul_ps(ed[1], ed[1])), _mm_mul_ps(ed[2], ed[2]));
    const __m128 la = MS_SHUF(len2, 1, 2, 0, 3), lb = MS_SHUF(len2, 2, 0, 1, 3);
    const __mmask8 va_longest = _mm_cmp_ps_mask(la, lb, _CMP_GE_OQ) & _mm_cmp_ps_mask(la, elen2, _CMP_GE_OQ);
    const __mmask8 e_longest = (__mmask8)(~va_longest & _mm_cmp_ps_mask(elen2, lb, _CMP_GE_OQ));
    __m128 X[3], Y[3];
    for (int r = 0; r < 3; r++) {
        const __m128 va = MS_SHUF(v[r], 1, 2, 0, 3), vb = MS_SHUF(v[r], 2, 0, 1, 3);
        X[r] = _mm_mask_blend_ps(va_longest, va, vb);
        Y[r] = _mm_mask_blend_ps(e_longest, ed[r], vb);
    }
    /* U, V, W in lanes 0..2 (ex, ey, ez = their x, y, z components). */
    __m128 ex = _mm_sub_ps(_mm_mul_ps(X[1], Y[2]), _mm_mul_ps(X[2], Y[1]));
    __m128 ey = _mm_sub_ps(_mm_mul_ps(X[2], Y[0]), _mm_mul_ps(X[0], Y[2]));
    __m128 ez = _mm_sub_ps(_mm_mul_ps(X[0], Y[1]), _mm_mul_ps(X[1], Y[0]));
    /* Normal from the two shortest edges: lane i holds E[i+1] x E[i+2]; take the lane of the longest. */
    __m128 c1[3], c2[3];
    for (int r = 0; r < 3; r++) { c1[r] = MS_SHUF(ed[r], 1, 2, 0, 3); c2[r] = MS_SHUF(ed[r], 2, 0, 1, 3); }
    const __m128 nx = _mm_sub_ps(_mm_mul_ps(c1[1], c2[2]), _mm_mul_ps(c1[2], c2[1]));
    const __m128 ny = _mm_sub_ps(_mm_mul_ps(c1[2], c2[0]), _mm_mul_ps(c1[0], c2[2]));
    const __m128 nz = _mm_sub_ps(_mm_mul_ps(c1[0], c2[1]), _mm_mul_ps(c1[1], c2[0]));
    const float e0 = _mm_cvtss_f32(elen2), e1 = _mm_cvtss_f32(MS_SHUF(elen2, 1, 1, 1, 1)), e2 = _mm_cvtss_f32(MS_SHUF(elen2, 2, 2, 2, 2));
    const int long_i = e0 >= e1 ? (e0 >= e2 ? 0 : 2) : (e1 >= e2 ? 1 : 2);
    const float l0 = _mm_cvtss_f32(len2), l1 = _mm_cvtss_f32(MS_SHUF(len2, 1, 1, 1, 1)), l2 = _mm_cvtss_f32(MS_SHUF(len2, 2, 2, 2, 2));
    const int near_i = l0 <= l1 ? (l0 <= l2 ? 0 : 2) : (l1 <= l2 ? 1 : 2);
    __m128 sx = ms_lane(nx, long_i), sy = ms_lane(ny, long_i), sz = ms_lane(nz, long_i);
    const __m128 dall = _mm_add_ps(_mm_add_ps(_mm_mul_ps(v[0], sx), _mm_mul_ps(v[1], sy)), _mm_mul_ps(v[2], sz));
    __m128 d = ms_lane(dall, near_i);
    const float d_s = _mm_cvtss_f32(d);
    if (!(d_s != 0.0f)) return 0;
    if (f->cull_backfaces) {
        const float (*m)[3] = (const float (*)[3])f->m;
        const float detm = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        if (d_s * detm > 0.0f) return 0;
    }
    /* Two-sided: flip by D's sign bit, without a branch. */
    const __m128 sgn = _mm_and_ps(d, _mm_set1_ps(-0.0f));
    ex = _mm_xor_ps(ex, sgn); ey = _mm_xor_ps(ey, sgn); ez = _mm_xor_ps(ez, sgn);
    sx = _mm_xor_ps(sx, sgn); sy = _mm_xor_ps(sy, sgn); sz = _mm_xor_ps(sz, sgn);
    d = _mm_xor_ps(d, sgn);
    /* Clip edges in lanes 3 (N) and 4 (F); the constant edge (0, 0, 1) where not needed, and in the pads. */
    const __m128 nearv = _mm_set1_ps(f->near), farv = _mm_set1_ps(f->far);
    const int need_n = zmin_s < f->near, need_f = zmax_s > f->far;
    const __m128 nN_x = need_n ? _mm_mul_ps(_mm_sub_ps(_mm_setzero_ps(), nearv), sx) : _mm_setzero_ps();
    const __m128 nN_y = need_n ? _mm_mul_ps(_mm_sub_ps(_mm_setzero_ps(), nearv), sy) : _mm_setzero_ps();
    const __m128 nN_z = need_n ? _mm_sub_ps(d, _mm_mul_ps(nearv, sz)) : _mm_set1_ps(1.0f);
    const __m128 nF_x = need_f ? _mm_mul_ps(farv, sx) : _mm_setzero_ps();
    const __m128 nF_y = need_f ? _mm_mul_ps(farv, sy) : _mm_setzero_ps();
    const __m128 nF_z = need_f ? _mm_sub_ps(_mm_mul_ps(farv, sz), d) : _mm_set1_ps(1.0f);
    const __m128 hi_pad_x = _mm_move_ss(_mm_setzero_ps(), nF_x);
    const __m128 hi_pad_y = _mm_move_ss(_mm_setzero_ps(), nF_y);
    const __m128 hi_pad_z = _mm_move_ss(_mm_set1_ps(1.0f), nF_z);
    const __m256 EX = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_mask_blend_ps(0x8, ex, nN_x)), hi_pad_x, 1);
    const __m256 EY = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_mask_blend_ps(0x8, ey, nN_y)), hi_pad_y, 1);
    const __m256 EZ = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_mask_blend_ps(0x8, ez, nN_z)), hi_pad_z, 1);

    /* Scanline setup over the 8 lanes (ms_scan_setup_run). */
    const __m256 absmask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
    const __m256 ax = _mm256_mul_ps(_mm256_and_ps(EX, absmask), _mm256_set1_ps(kf));
    const __m256 ay = _mm256_mul_ps(_mm256_and_ps(EY, absmask), _mm256_set1_ps(kf));
    const __m256 az = _mm256_and_ps(EZ, absmask);
    const __m256 flat = _mm256_set1_ps(MS_FLAT_EDGE);
    const __mmask8 steep = _mm256_cmp_ps_mask(ax, _mm256_mul_ps(flat, _mm256_max_ps(ay, az)), _CMP_GT_OQ);
    const __mmask8 flat_y = (__mmask8)(~steep & _mm256_cmp_ps_mask(ay, _mm256_mul_ps(flat, az), _CMP_GT_OQ));
    const __mmask8 constant = (__mmask8)~(steep | flat_y);
    if (_mm256_mask_cmp_ps_mask(constant, EZ, _mm256_setzero_ps(), _CMP_LT_OQ)) return 0;
    /* One division for the slopes (-1/e_x) and the flat edges' y bounds (-e_z/e_y). */
    const __m512 num = _mm512_insertf32x8(_mm512_set1_ps(-1.0f), _mm256_sub_ps(_mm256_setzero_ps(), EZ), 1);
    const __m512 den = _mm512_insertf32x8(_mm512_castps256_ps512(_mm256_mask_blend_ps(steep, _mm256_set1_ps(1.0f), EX)),
                                          _mm256_mask_blend_ps(flat_y, _mm256_set1_ps(1.0f), EY), 1);
    const __m512 q = _mm512_div_ps(num, den);
    const __m256 r = _mm512_castps512_ps256(q);
    const __m256 a = _mm256_mul_ps(EY, r), b = _mm256_mul_ps(EZ, r);
    const __mmask8 lower = _mm256_mask_cmp_ps_mask(steep, EX, _mm256_setzero_ps(), _CMP_GT_OQ);
    const __mmask8 upper = (__mmask8)(steep & ~lower);
    _mm256_storeu_ps(sv->al, _mm256_maskz_mov_ps(lower, a));
    _mm256_storeu_ps(sv->bl, _mm256_maskz_mov_ps(lower, b));
    _mm256_storeu_ps(sv->au, _mm256_maskz_mov_ps(upper, a));
    _mm256_storeu_ps(sv->bu, _mm256_mask_blend_ps(upper, _mm256_set1_ps(kf - 1.0f), b));

    /* Scanline range: projected vertices when in front of C, then the flat edges' bounds. */
    int y0 = 0, y1 = k - 1;
    if (zmin_s > 0.0f) {
        const __m128 ys = _mm_div_ps(v[1], _mm_mask_blend_ps(0x8, v[2], _mm_set1_ps(1.0f)));
        const __m128 lim_lo = _mm_set1_ps(-1.0f), lim_hi = _mm_set1_ps(kf);
        const __m128 ylo = _mm_min_ps(_mm_max_ps(_mm_sub_ps(ms_hmin3(ys), _mm_set1_ps(MS_BOX_SLACK)), lim_lo), lim_hi);
        const __m128 yhi = _mm_min_ps(_mm_max_ps(_mm_add_ps(ms_hmax3(ys), _mm_set1_ps(MS_BOX_SLACK)), lim_lo), lim_hi);
        y0 = _mm_cvt_roundss_si32(ylo, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
        y1 = _mm_cvt_roundss_si32(yhi, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    }
    if (flat_y) {
        const __m256 yb = _mm256_min_ps(_mm256_max_ps(_mm512_extractf32x8_ps(q, 1), _mm256_set1_ps(-1.0f)), _mm256_set1_ps(kf));
        const __mmask8 up = _mm256_mask_cmp_ps_mask(flat_y, EY, _mm256_setzero_ps(), _CMP_GT_OQ);
        const __mmask8 dn = (__mmask8)(flat_y & ~up);
        float yv[8];
        _mm256_storeu_ps(yv, yb);
        for (int i = 0; i < 5; i++) {
            if (up >> i & 1) { const int c = ms_ceil_i(yv[i]); if (c > y0) y0 = c; }
            if (dn >> i & 1) { const int c = ms_floor_i(yv[i]); if (c < y1) y1 = c; }
        }
    }
    if (y0 < 0) y0 = 0;
    if (y1 > k - 1) y1 = k - 1;
    sv->y0 = y0;
    sv->y1 = y1;
    return y0 <= y1;
}

/* First and last covered sample of scanlines ybase..ybase+15, as l in [0, k] and h in [-1, k-1] (empty
 * when l > h); rows outside [y0, y1] are marked in *rows. */
static inline __attribute__((always_inline)) void ms_interval16(const ms_scan_vec *v, int ybase, float kf, __m512i *l,
                                                                __m512i *h, __mmask16 *rows)
{
    const __m512i yi = _mm512_add_epi32(_mm512_set1_epi32(ybase),
                                        _mm512_set_epi32(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0));
    const __m512 y = _mm512_cvtepi32_ps(yi);
    __m512 lo = _mm512_setzero_ps(), hi = _mm512_set1_ps(kf - 1.0f);
    for (int e = 0; e < 5; e++) {
        lo = _mm512_max_ps(lo, _mm512_fmadd_ps(_mm512_set1_ps(v->al[e]), y, _mm512_set1_ps(v->bl[e])));
        hi = _mm512_min_ps(hi, _mm512_fmadd_ps(_mm512_set1_ps(v->au[e]), y, _mm512_set1_ps(v->bu[e])));
    }
    lo = _mm512_min_ps(lo, _mm512_set1_ps(kf));
    hi = _mm512_max_ps(hi, _mm512_set1_ps(-1.0f));
    *l = _mm512_cvt_roundps_epi32(lo, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
    *h = _mm512_cvt_roundps_epi32(hi, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    *rows = _mm512_cmp_epi32_mask(yi, _mm512_set1_epi32(v->y0), _MM_CMPINT_NLT) &
            _mm512_cmp_epi32_mask(yi, _mm512_set1_epi32(v->y1), _MM_CMPINT_LE);
}

void ms_scanline_16_avx512(const ms_raster_frame *f, const float tri[9], void *out)
{
    ms_scan_vec v;
    if (!ms_scan_vec_setup(f, tri, &v)) return;
    __m512i l, h;
    __mmask16 rows;
    ms_interval16(&v, 0, 16.0f, &l, &h, &rows);
    /* Bits [l, h] of each 16-bit word, in 32-bit lanes: (ones << l) & (ones >> (15 - h)). */
    const __m512i ones = _mm512_set1_epi32(0xFFFF);
    const __m512i cov = _mm512_maskz_and_epi32(rows, _mm512_sllv_epi32(ones, l),
                                               _mm512_srlv_epi32(ones, _mm512_sub_epi32(_mm512_set1_epi32(15), h)));
    __m256i *b = (__m256i *)out;
    _mm256_storeu_si256(b, _mm256_andnot_si256(_mm512_cvtepi32_epi16(cov), _mm256_loadu_si256(b)));
}

void ms_scanline_32_avx512(const ms_raster_frame *f, const float tri[9], void *out)
{
    ms_scan_vec v;
    if (!ms_scan_vec_setup(f, tri, &v)) return;
    uint32_t *buf = (uint32_t *)out;
    const __m512i ones = _mm512_set1_epi32(-1);
    for (int ybase = v.y0 & ~15; ybase <= v.y1; ybase += 16) {
        __m512i l, h;
        __mmask16 rows;
        ms_interval16(&v, ybase, 32.0f, &l, &h, &rows);
        const __m512i cov = _mm512_maskz_and_epi32(
            rows, _mm512_sllv_epi32(ones, l), _mm512_srlv_epi32(ones, _mm512_sub_epi32(_mm512_set1_epi32(31), h)));
        _mm512_storeu_si512(buf + ybase, _mm512_andnot_si512(cov, _mm512_loadu_si512(buf + ybase)));
    }
}

void ms_scanline_64_avx512(const ms_raster_frame *f, const float tri[9], void *out)
{
    ms_scan_vec v;
    if (!ms_scan_vec_setup(f, tri, &v)) return;
    uint64_t *buf = (uint64_t *)out;
    const __m512i ones = _mm512_set1_epi64(-1);
    const __m512i c63 = _mm512_set1_epi64(63);
    for (int ybase = v.y0 & ~15; ybase <= v.y1; ybase += 16) {
        __m512i l, h;
        __mmask16 rows;
        ms_interval16(&v, ybase, 64.0f, &l, &h, &rows);
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
