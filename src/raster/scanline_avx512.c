/* AVX-512 Scanline kernels: sixteen scanlines per instruction. The per-scanline work of sec. 4 (bounds
 * a*y + b, max of lower and min of upper bounds, ceil/floor, the shift/mask) maps lane for lane onto
 * 16-wide float and integer vectors; the rounding conversions come for free with the embedded rounding
 * mode, and the variable shifts (vpsllv/vpsrlv) give 0 for counts >= the lane width, which is exactly the
 * behaviour the paper had to emulate.
 *
 * The triangle setup is the one of raster_internal.h (same operands, same roundings, so that it agrees
 * with the scalar kernels away from ties), laid out for 8-lane vectors and free of data-dependent
 * branches but for the rejections: lanes 0..2 carry the three vertices, lanes 4..6 the three edges, and
 * every choice the scalar setup makes with a comparison (shortest sides, nearest vertex, longest edge,
 * which clip edges) becomes a mask or a permutation index. A mispredicted branch costs about 15 cycles,
 * a sixth of the whole setup; and the edges are flipped to D > 0 only where the lower/upper split needs
 * it, so that the slope division, the longest wait, starts early. */
#include <immintrin.h>
#include <stddef.h>
#include "raster_internal.h"

_Static_assert(offsetof(ms_raster_frame, near) == offsetof(ms_raster_frame, c) + 3 * sizeof(float),
               "the setup loads c[0..2] with the float after it");

/* Per-triangle data of the row loop: for each of the (up to) five edges a lower and an upper bound
 * a*y + b on x, neutral (0 resp. k-1) where the edge is not of that kind, and the scanline range.
 * The rows evaluate 3 edge lanes, or 5 when a clip edge is active. */
typedef struct ms_scan_vec {
    float al[8], bl[8], au[8], bu[8];
    int y0, y1;
} ms_scan_vec;

static inline __m256i ms_idx8(int a, int b, int c, int d, int e, int f, int g, int h)
{
    return _mm256_setr_epi32(a, b, c, d, e, f, g, h);
}

static inline __attribute__((always_inline)) int ms_scan_vec_setup(const ms_raster_frame *f, const float tri[9],
                                                                   ms_scan_vec *sv, const int clip)
{
    const int k = f->k;
    const float kf = (float)k;
    /* World coordinates: lane i = P_i - C, lane 4+i = P_{i+2} - P_{i+1} (the edge opposite vertex i), by
     * two-source permutations of the first eight floats and of (C, the ninth float); lanes 3 and 7 are
     * x - x = 0. Plain loads: f->c is followed by f->near, so four floats are there to read. */
    const __m256 T = _mm256_loadu_ps(tri);
    const __m256 S = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f->c)), _mm_broadcast_ss(tri + 8), 1);
    const __m256i ia[3] = { ms_idx8(0, 3, 6, 0, 6, 0, 3, 0), ms_idx8(1, 4, 7, 0, 7, 1, 4, 0), ms_idx8(2, 5, 12, 0, 12, 2, 5, 0) };
    const __m256i ib[3] = { ms_idx8(8, 8, 8, 0, 3, 6, 0, 0), ms_idx8(9, 9, 9, 0, 4, 7, 1, 0), ms_idx8(10, 10, 10, 0, 5, 12, 2, 0) };
    __m256 W[3];
    for (int a = 0; a < 3; a++)
        W[a] = _mm256_sub_ps(_mm256_permutex2var_ps(T, ia[a], S), _mm256_permutex2var_ps(T, ib[a], S));
    /* Light-index coordinates V[r] = row r of m times W (mul + add, not FMA, to round like the scalar
     * setup), for the depth range and the projected box only; the edges come from W (see the scalar
     * setup for why). */
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
    const __m256 zmin = _mm256_min_ps(_mm256_min_ps(zl, _mm256_permutexvar_ps(rot1, zl)), _mm256_permutexvar_ps(rot2, zl));
    const __m256 zmax = _mm256_max_ps(_mm256_max_ps(zh, _mm256_permutexvar_ps(rot1, zh)), _mm256_permutexvar_ps(rot2, zh));
    const float zmin_s = _mm256_cvtss_f32(zmin), zmax_s = _mm256_cvtss_f32(zmax);
    if (!(zmax_s >= f->near && zmin_s <= f->far)) return 0;
    const __mmask8 need = (__mmask8)(0x07 | (zmin_s < f->near) << 3 | (zmax_s > f->far) << 4);
    /* The caller instantiates the setup with and without clip edges: without (the common case) the
     * slope division starts right after the edge equations instead of waiting for the normal. */
    if ((need != 0x07) != clip) return -1;

    /* Squared world lengths: lanes 0..2 of the vectors from C, 4..6 of the edges. */
    const __m256 L = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(W[0], W[0]), _mm256_mul_ps(W[1], W[1])),
                                   _mm256_mul_ps(W[2], W[2]));
    const __m256 L1 = _mm256_permutexvar_ps(rot1, L), L2 = _mm256_permutexvar_ps(rot2, L);
    const __m256 Le = _mm256_permutexvar_ps(ms_idx8(4, 5, 6, 7, 4, 5, 6, 7), L);
    /* Edge i's operands (the two shortest sides of the triangle C, P_{i+1}, P_{i+2}) as permutation
     * indices into W: x = A_{i+2} if A_{i+1} is the longest side, else A_{i+1}; y = A_{i+2} if the edge
     * is the longest, else the edge. Lanes 4..6 compute the normal candidates E_{i+1} x E_{i+2} (their
     * indices are the same either way, so the masks need no lane restriction). */
    const __mmask8 va_longest = _mm256_cmp_ps_mask(L1, L2, _CMP_GE_OQ) & _mm256_cmp_ps_mask(L1, Le, _CMP_GE_OQ);
    const __mmask8 e_longest = (__mmask8)(~va_longest & _mm256_cmp_ps_mask(Le, L2, _CMP_GE_OQ));
    const __m256i ix = _mm256_mask_blend_epi32(va_longest, ms_idx8(1, 2, 0, 3, 5, 6, 4, 7), ms_idx8(2, 0, 1, 3, 5, 6, 4, 7));
    const __m256i iy = _mm256_mask_blend_epi32(e_longest, ms_idx8(4, 5, 6, 3, 6, 4, 5, 7), ms_idx8(2, 0, 1, 3, 6, 4, 5, 7));
    __m256 X[3], Y[3];
    for (int r = 0; r < 3; r++) { X[r] = _mm256_permutexvar_ps(ix, W[r]); Y[r] = _mm256_permutexvar_ps(iy, W[r]); }
    /* World normals u (of the edge planes through C, and in lanes 4..6 of the triangle's plane)... */
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

    /* Normal from the two shortest edges (the candidate of the longest edge), D from the vertex nearest
     * C. One-hot lane masks that pick the lowest lane among equals, like the scalar comparison chains
     * (lane i wins over a higher lane on >=, over a lower one only on >), then compress + broadcast:
     * no trip through a general register. */
    const __mmask8 long_m = (__mmask8)((_mm256_mask_cmp_ps_mask(0x30, L, L1, _CMP_GE_OQ) | _mm256_mask_cmp_ps_mask(0x40, L, L1, _CMP_GT_OQ)) &
                                       (_mm256_mask_cmp_ps_mask(0x10, L, L2, _CMP_GE_OQ) | _mm256_mask_cmp_ps_mask(0x60, L, L2, _CMP_GT_OQ)));
    const __mmask8 near_m = (__mmask8)((_mm256_mask_cmp_ps_mask(0x03, L, L1, _CMP_LE_OQ) | _mm256_mask_cmp_ps_mask(0x04, L, L1, _CMP_LT_OQ)) &
                                       (_mm256_mask_cmp_ps_mask(0x01, L, L2, _CMP_LE_OQ) | _mm256_mask_cmp_ps_mask(0x06, L, L2, _CMP_LT_OQ)));
#define MS_PICK(m, v) _mm256_broadcastss_ps(_mm256_castps256_ps128(_mm256_maskz_compress_ps((m), (v))))
    const __m256 d = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(MS_PICK(near_m, W[0]), MS_PICK(long_m, ux)),
                                                 _mm256_mul_ps(MS_PICK(near_m, W[1]), MS_PICK(long_m, uy))),
                                   _mm256_mul_ps(MS_PICK(near_m, W[2]), MS_PICK(long_m, uz)));
    /* The light-space normal, for the clip edges only (dead code without them). */
    const __m256 sx = MS_PICK(long_m, ex), sy = MS_PICK(long_m, ey), sz = MS_PICK(long_m, ez);
#undef MS_PICK

    /* Clip edges in lanes 3 (N = (-near sx, -near sy, d - near sz)) and 4 (F = (far sx, far sy,
     * far sz - d)); negation is exact, so N's terms are F's form with the sign flipped. Lanes not in use
     * become the constant edge (0, 0, 1). Departure in form only: the edges stay unflipped (D may be
     * negative) until the lower/upper split, because flipping all of an edge's coefficients leaves its
     * bound -(e_y y + e_z)/e_x bit for bit the same: the slope division need not wait for D. */
    const __m256 cl = _mm256_setr_ps(0, 0, 0, f->near, f->far, 0, 0, 0);
    const __m256 neg3 = _mm256_setr_ps(0, 0, 0, -0.0f, 0, 0, 0, 0);
    const __m256 EX = clip ? _mm256_maskz_mov_ps(need, _mm256_mask_blend_ps(0x07, _mm256_xor_ps(_mm256_mul_ps(cl, sx), neg3), ex))
                           : _mm256_maskz_mov_ps(0x07, ex);
    const __m256 EY = clip ? _mm256_maskz_mov_ps(need, _mm256_mask_blend_ps(0x07, _mm256_xor_ps(_mm256_mul_ps(cl, sy), neg3), ey))
                           : _mm256_maskz_mov_ps(0x07, ey);
    const __m256 EZu = clip ? _mm256_mask_blend_ps(need, _mm256_set1_ps(1.0f),
                                                   _mm256_mask_blend_ps(0x07, _mm256_xor_ps(_mm256_sub_ps(_mm256_mul_ps(cl, sz), d), neg3), ez))
                            : _mm256_mask_blend_ps(0x07, _mm256_set1_ps(1.0f), ez);
    /* One division for the slopes (-1/e_x, lanes 0..7; garbage where e_x is 0, masked below) and the
     * projected vertices (y/z in lanes 8..10, x/z in 12..14), like the scalar 1/z and products up to
     * rounding, which the box slack absorbs. */
    const __m256 num_hi = _mm256_permutex2var_ps(V[1], ms_idx8(0, 1, 2, 3, 8, 9, 10, 11), V[0]);
    const __m256 den_hi = _mm256_mask_blend_ps(0x88, _mm256_permutexvar_ps(ms_idx8(0, 1, 2, 3, 0, 1, 2, 3), V[2]),
                                               _mm256_set1_ps(1.0f));
    const __m512 q = _mm512_div_ps(_mm512_insertf32x8(_mm512_set1_ps(-1.0f), num_hi, 1),
                                   _mm512_insertf32x8(_mm512_castps256_ps512(EX), den_hi, 1));

    const float d_s = _mm256_cvtss_f32(d);
    if (!(d_s != 0.0f)) return 0;
    if (f->cull_backfaces && d_s > 0.0f) return 0; /* world D > 0: facing away from C */

    /* Scanline setup over the 8 lanes (ms_scan_setup_run); the classification uses magnitudes only. */
    const __m256 absmask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
    const __m256 ax = _mm256_mul_ps(_mm256_and_ps(EX, absmask), _mm256_set1_ps(kf));
    const __m256 ay = _mm256_mul_ps(_mm256_and_ps(EY, absmask), _mm256_set1_ps(kf));
    const __m256 az = _mm256_and_ps(EZu, absmask);
    const __m256 flat = _mm256_set1_ps(MS_FLAT_EDGE);
    const __mmask8 steep = _mm256_cmp_ps_mask(ax, _mm256_mul_ps(flat, _mm256_max_ps(ay, az)), _CMP_GT_OQ);
    const __mmask8 flat_y = (__mmask8)(~steep & _mm256_cmp_ps_mask(ay, _mm256_mul_ps(flat, az), _CMP_GT_OQ));
    const __mmask8 constant = (__mmask8)~(steep | flat_y);
    /* Two-sided: the active edges flipped by D's sign bit (the paper culls D <= 0). */
    const __m256 sgn = _mm256_and_ps(d, _mm256_set1_ps(-0.0f));
    const __m256 EZ = _mm256_mask_xor_ps(EZu, need, EZu, sgn);
    if (_mm256_mask_cmp_ps_mask(constant, EZ, _mm256_setzero_ps(), _CMP_LT_OQ)) return 0;
    const __m256 r = _mm512_castps512_ps256(q);
    const __m256 a = _mm256_mul_ps(EY, r), b = _mm256_mul_ps(EZu, r);
    const __mmask8 lower = _mm256_mask_cmp_ps_mask(steep, _mm256_xor_ps(EX, sgn), _mm256_setzero_ps(), _CMP_GT_OQ);
    const __mmask8 upper = (__mmask8)(steep & ~lower);
    /* Stored: the rows broadcast them back with loads. */
    _mm256_storeu_ps(sv->al, _mm256_maskz_mov_ps(lower, a));
    _mm256_storeu_ps(sv->bl, _mm256_maskz_mov_ps(lower, b));
    _mm256_storeu_ps(sv->au, _mm256_maskz_mov_ps(upper, a));
    _mm256_storeu_ps(sv->bu, _mm256_mask_blend_ps(upper, _mm256_set1_ps(kf - 1.0f), b));
    /* Sample range: the box of the projected vertices when in front of C (lane 0: y, lane 4: x), then
     * the flat edges' bounds on y. */
    int y0 = 0, y1 = k - 1;
    if (zmin_s > 0.0f) {
        const __m256 p = _mm512_extractf32x8_ps(q, 1);
        const __m256 p1 = _mm256_permutexvar_ps(rot1, p), p2 = _mm256_permutexvar_ps(rot2, p);
        const __m256 lim_lo = _mm256_set1_ps(-1.0f), lim_hi = _mm256_set1_ps(kf), slack = _mm256_set1_ps(MS_BOX_SLACK);
        const __m256 lo = _mm256_min_ps(_mm256_max_ps(_mm256_sub_ps(_mm256_min_ps(_mm256_min_ps(p, p1), p2), slack), lim_lo), lim_hi);
        const __m256 hi = _mm256_min_ps(_mm256_max_ps(_mm256_add_ps(_mm256_max_ps(_mm256_max_ps(p, p1), p2), slack), lim_lo), lim_hi);
        const __m256i ilo = _mm256_max_epi32(_mm256_cvtps_epi32(_mm256_round_ps(lo, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC)),
                                             _mm256_setzero_si256());
        const __m256i ihi = _mm256_min_epi32(_mm256_cvtps_epi32(_mm256_round_ps(hi, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)),
                                             _mm256_set1_epi32(k - 1));
        if (_mm256_cmp_epi32_mask(ilo, ihi, _MM_CMPINT_NLE) & 0x11) return 0;
        y0 = _mm256_cvtsi256_si32(ilo);
        y1 = _mm256_cvtsi256_si32(ihi);
    }
    if (flat_y) {
        /* Rare (an edge parallel to the scanlines): its own division. */
        const __m256 yb = _mm256_min_ps(_mm256_max_ps(_mm256_div_ps(_mm256_sub_ps(_mm256_setzero_ps(), EZu),
                                                                    _mm256_mask_blend_ps(flat_y, _mm256_set1_ps(1.0f), EY)),
                                                      _mm256_set1_ps(-1.0f)),
                                        _mm256_set1_ps(kf));
        const __mmask8 up = _mm256_mask_cmp_ps_mask(flat_y, _mm256_xor_ps(EY, sgn), _mm256_setzero_ps(), _CMP_GT_OQ);
        const __mmask8 dn = (__mmask8)(flat_y & ~up);
        float yv[8];
        _mm256_storeu_ps(yv, yb);
        ms_flat_y_bounds(yv, (unsigned)up, (unsigned)dn, k, &y0, &y1);
    }
    sv->y0 = y0;
    sv->y1 = y1;
    return y0 <= y1;
}

/* First and last covered sample of scanlines ybase..ybase+15, over the first NE edge lanes; rows
 * outside [y0, y1] are marked in *rows. No clamping: every bound that is out of range, and NaN,
 * converts to a shift count (l, or width-1-h) of at least the lane width, or to the integer indefinite
 * value, whose shifts give 0 lanes: an empty interval, as clamping would. */
static inline __attribute__((always_inline)) void ms_interval16(const ms_scan_vec *v, const int ne, int ybase, float kf,
                                                                __m512i *l, __m512i *h, __mmask16 *rows)
{
    const __m512i yi = _mm512_add_epi32(_mm512_set1_epi32(ybase),
                                        _mm512_set_epi32(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0));
    const __m512 y = _mm512_cvtepi32_ps(yi);
    __m512 lo[5], hi[5];
    for (int e = 0; e < ne; e++) {
        lo[e] = _mm512_fmadd_ps(_mm512_set1_ps(v->al[e]), y, _mm512_set1_ps(v->bl[e]));
        hi[e] = _mm512_fmadd_ps(_mm512_set1_ps(v->au[e]), y, _mm512_set1_ps(v->bu[e]));
    }
    /* Pairwise, for a short dependency chain; max(x, 0) and min(x, k-1) are the buffer's edges. */
    __m512 l01 = _mm512_max_ps(lo[0], lo[1]), h01 = _mm512_min_ps(hi[0], hi[1]);
    __m512 l2 = _mm512_max_ps(lo[2], _mm512_setzero_ps()), h2 = _mm512_min_ps(hi[2], _mm512_set1_ps(kf - 1.0f));
    if (ne == 5) {
        l2 = _mm512_max_ps(l2, _mm512_max_ps(lo[3], lo[4]));
        h2 = _mm512_min_ps(h2, _mm512_min_ps(hi[3], hi[4]));
    }
    *l = _mm512_cvt_roundps_epi32(_mm512_max_ps(l01, l2), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
    *h = _mm512_cvt_roundps_epi32(_mm512_min_ps(h01, h2), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    *rows = _mm512_cmp_epi32_mask(yi, _mm512_set1_epi32(v->y0), _MM_CMPINT_NLT) &
            _mm512_cmp_epi32_mask(yi, _mm512_set1_epi32(v->y1), _MM_CMPINT_LE);
}

static inline __attribute__((always_inline)) void ms_rows16(const ms_scan_vec *v, const int ne, void *out)
{
    __m512i l, h;
    __mmask16 rows;
    ms_interval16(v, ne, 0, 16.0f, &l, &h, &rows);
    /* Bits [l, h] of each 16-bit word, in 32-bit lanes: (ones << l) & (ones >> (15 - h)). */
    const __m512i ones = _mm512_set1_epi32(0xFFFF);
    const __m512i cov = _mm512_maskz_and_epi32(rows, _mm512_sllv_epi32(ones, l),
                                               _mm512_srlv_epi32(ones, _mm512_sub_epi32(_mm512_set1_epi32(15), h)));
    __m256i *b = (__m256i *)out;
    _mm256_storeu_si256(b, _mm256_andnot_si256(_mm512_cvtepi32_epi16(cov), _mm256_loadu_si256(b)));
}

static inline __attribute__((always_inline)) void ms_rows32(const ms_scan_vec *v, const int ne, void *out)
{
    uint32_t *buf = (uint32_t *)out;
    const __m512i ones = _mm512_set1_epi32(-1);
    for (int ybase = v->y0 & ~15; ybase <= v->y1; ybase += 16) {
        __m512i l, h;
        __mmask16 rows;
        ms_interval16(v, ne, ybase, 32.0f, &l, &h, &rows);
        const __m512i cov = _mm512_maskz_and_epi32(
            rows, _mm512_sllv_epi32(ones, l), _mm512_srlv_epi32(ones, _mm512_sub_epi32(_mm512_set1_epi32(31), h)));
        _mm512_storeu_si512(buf + ybase, _mm512_andnot_si512(cov, _mm512_loadu_si512(buf + ybase)));
    }
}

static inline __attribute__((always_inline)) void ms_rows64(const ms_scan_vec *v, const int ne, void *out)
{
    uint64_t *buf = (uint64_t *)out;
    const __m512i ones = _mm512_set1_epi64(-1);
    const __m512i c63 = _mm512_set1_epi64(63);
    for (int ybase = v->y0 & ~15; ybase <= v->y1; ybase += 16) {
        __m512i l, h;
        __mmask16 rows;
        ms_interval16(v, ne, ybase, 64.0f, &l, &h, &rows);
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

/* Without an active clip edge (the common case) the setup is shorter and the rows evaluate three
 * edge lanes instead of five. */
#define MS_SCANLINE_AVX512(K)                                                                  \
    void ms_scanline_##K##_avx512(const ms_raster_frame *f, const float tri[9], void *out)     \
    {                                                                                          \
        ms_scan_vec v;                                                                         \
        const int r = ms_scan_vec_setup(f, tri, &v, 0);                                        \
        if (r > 0) ms_rows##K(&v, 3, out);                                                     \
        else if (r < 0 && ms_scan_vec_setup(f, tri, &v, 1) > 0) ms_rows##K(&v, 5, out);        \
    }
MS_SCANLINE_AVX512(16)
MS_SCANLINE_AVX512(32)
MS_SCANLINE_AVX512(64)
