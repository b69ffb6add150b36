/* The SIMD Scanline kernel, written once for AVX2 and AVX-512 over the per-ISA operations of
 * simd_avx2.h / simd_avx512.h (the file's MS_TARGET_* macro picks them), instantiated per k through
 * core/perk_each.h: ms_scanline_<k>_avx2, ms_scanline_<k>_avx512.
 *
 * The setup is the one of raster_internal.h (same operands, same roundings: mul + add wherever the
 * scalar setup multiplies then adds, so that it agrees with the scalar kernels away from ties), laid out
 * for 8-lane vectors and free of data-dependent branches but for the rejections: lanes 0..2 carry the
 * three vertices, lanes 4..6 the three edges, and every choice the scalar setup makes with a comparison
 * (shortest sides, nearest vertex, longest edge, which clip edges) becomes a mask or a permutation index.
 * A mispredicted branch costs about 15 cycles, a sixth of the whole setup; and the edges are flipped to
 * D > 0 only where the lower/upper split needs it, so that the slope division, the longest wait, starts
 * early. The rows evaluate the bounds a*y + b of MS_R scanlines per instruction (16 with AVX-512, 8 with
 * AVX2) with the same FMA and the same max/min order in both ISAs, so both fill identical buffers
 * (test_kernels reports any scanline where they differ); the rounding conversions and the variable
 * shifts, which give 0 for counts >= the lane width, are exactly the behaviour the paper had to
 * emulate with clamps. */
#ifndef MS_SCANLINE_SIMD_COMMON
#define MS_SCANLINE_SIMD_COMMON
#if defined(MS_TARGET_AVX512)
#include "simd_avx512.h"
#elif defined(MS_TARGET_AVX2)
#include "simd_avx2.h"
#else
#error "scanline_simd_impl.h is for the _avx2.c and _avx512.c files"
#endif

SI vi ms_idx8(int a, int b, int c, int d, int e, int f, int g, int h) { return _mm256_setr_epi32(a, b, c, d, e, f, g, h); }

/* 1: rows to do; 0: nothing to rasterize; -1: the other instance (clip or not) is needed. */
SI int ms_scan_vec_setup(const ms_raster_frame *f, const float tri[9], ms_scan_vec *sv, const int clip)
{
    const int k = f->k;
    const float kf = (float)k;
    vf W[3];
    ms_world(f, tri, W);
    /* Light-index coordinates V[r] = row r of m times W (mul + add, not FMA, to round like the scalar
     * setup), for the depth range and the projected box only; the edges come from W (see the scalar
     * setup for why). */
    vf V[3];
    for (int r = 0; r < 3; r++)
        V[r] = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(f->m[r][0]), W[0]),
                                           _mm256_mul_ps(_mm256_set1_ps(f->m[r][1]), W[1])),
                             _mm256_mul_ps(_mm256_set1_ps(f->m[r][2]), W[2]));
    /* The other two lanes of each lane's triple (vertices 0..2, edges 4..6). */
    const vi rot1 = ms_idx8(1, 2, 0, 3, 5, 6, 4, 7), rot2 = ms_idx8(2, 0, 1, 3, 6, 4, 5, 7);
    /* Depth range widened by the rounding bound of raster_internal.h (MS_Z_REL), same operations. */
    const vf absm = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
    const vf zerr = _mm256_mul_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(fabsf(f->m[2][0])), _mm256_and_ps(W[0], absm)),
                                    _mm256_mul_ps(_mm256_set1_ps(fabsf(f->m[2][1])), _mm256_and_ps(W[1], absm))),
                      _mm256_mul_ps(_mm256_set1_ps(fabsf(f->m[2][2])), _mm256_and_ps(W[2], absm))),
        _mm256_set1_ps(MS_Z_REL));
    const vf zl = _mm256_sub_ps(V[2], zerr), zh = _mm256_add_ps(V[2], zerr);
    const vf zmin = _mm256_min_ps(_mm256_min_ps(zl, v_perm(zl, rot1)), v_perm(zl, rot2));
    const vf zmax = _mm256_max_ps(_mm256_max_ps(zh, v_perm(zh, rot1)), v_perm(zh, rot2));
    const float zmin_s = _mm256_cvtss_f32(zmin), zmax_s = _mm256_cvtss_f32(zmax);
    if (!(zmax_s >= f->near && zmin_s <= f->far)) return 0;
    const unsigned need = 0x07u | (unsigned)(zmin_s < f->near) << 3 | (unsigned)(zmax_s > f->far) << 4;
    /* The caller instantiates the setup with and without clip edges: without (the common case) the
     * slope division starts right after the edge equations instead of waiting for the normal. */
    if ((need != 0x07) != clip) return -1;

    /* Squared world lengths: lanes 0..2 of the vectors from C, 4..6 of the edges. */
    const vf L = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(W[0], W[0]), _mm256_mul_ps(W[1], W[1])), _mm256_mul_ps(W[2], W[2]));
    const vf L1 = v_perm(L, rot1), L2 = v_perm(L, rot2);
    const vf Le = v_perm(L, ms_idx8(4, 5, 6, 7, 4, 5, 6, 7));
    /* Edge i's operands (the two shortest sides of the triangle C, P_{i+1}, P_{i+2}) as permutation
     * indices into W: x = A_{i+2} if A_{i+1} is the longest side, else A_{i+1}; y = A_{i+2} if the edge
     * is the longest, else the edge. Lanes 4..6 compute the normal candidates E_{i+1} x E_{i+2} (their
     * indices are the same either way, so the masks need no lane restriction). */
    const vm va_longest = m_and(V_CMP(L1, L2, _CMP_GE_OQ), V_CMP(L1, Le, _CMP_GE_OQ));
    const vm e_longest = m_andnot(va_longest, V_CMP(Le, L2, _CMP_GE_OQ));
    const vi ix = v_blend_idx(va_longest, ms_idx8(1, 2, 0, 3, 5, 6, 4, 7), ms_idx8(2, 0, 1, 3, 5, 6, 4, 7));
    const vi iy = v_blend_idx(e_longest, ms_idx8(4, 5, 6, 3, 6, 4, 5, 7), ms_idx8(2, 0, 1, 3, 6, 4, 5, 7));
    vf X[3], Y[3];
    for (int r = 0; r < 3; r++) { X[r] = v_perm(W[r], ix); Y[r] = v_perm(W[r], iy); }
    /* World normals u (of the edge planes through C, and in lanes 4..6 of the triangle's plane)... */
    const vf ux = _mm256_sub_ps(_mm256_mul_ps(X[1], Y[2]), _mm256_mul_ps(X[2], Y[1]));
    const vf uy = _mm256_sub_ps(_mm256_mul_ps(X[2], Y[0]), _mm256_mul_ps(X[0], Y[2]));
    const vf uz = _mm256_sub_ps(_mm256_mul_ps(X[0], Y[1]), _mm256_mul_ps(X[1], Y[0]));
    /* ...and in light space, M^T u (rows ds, dt, p0 - C). */
    vf et[3];
    for (int r = 0; r < 3; r++)
        et[r] = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(f->mt[r][0]), ux),
                                            _mm256_mul_ps(_mm256_set1_ps(f->mt[r][1]), uy)),
                              _mm256_mul_ps(_mm256_set1_ps(f->mt[r][2]), uz));
    const vf ex = et[0], ey = et[1], ez = et[2];

    /* Normal from the two shortest edges (the candidate of the longest edge), D from the vertex nearest
     * C; D is the world D, whose sign is the light-space D's times det(m)'s, a factor the edges drop as
     * well. */
    vpick pn, pl;
    ms_picks(L, L1, L2, &pn, &pl);
    const vf d = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(v_pick(pn, W[0]), v_pick(pl, ux)),
                                             _mm256_mul_ps(v_pick(pn, W[1]), v_pick(pl, uy))),
                               _mm256_mul_ps(v_pick(pn, W[2]), v_pick(pl, uz)));
    /* The light-space normal, for the clip edges only (dead code without them). */
    const vf sx = v_pick(pl, ex), sy = v_pick(pl, ey), sz = v_pick(pl, ez);

    /* Clip edges in lanes 3 (N = (-near sx, -near sy, d - near sz)) and 4 (F = (far sx, far sy,
     * far sz - d)); negation is exact, so N's terms are F's form with the sign flipped. Lanes not in use
     * become the constant edge (0, 0, 1). Departure in form only: the edges stay unflipped (D may be
     * negative) until the lower/upper split, because flipping all of an edge's coefficients leaves its
     * bound -(e_y y + e_z)/e_x bit for bit the same: the slope division need not wait for D. */
    const vm needv = m_lanes(clip ? need : 0x07u);
    vf EX, EY, EZu;
    if (clip) {
        const vf cl = _mm256_setr_ps(0, 0, 0, f->near, f->far, 0, 0, 0);
        const vf neg3 = _mm256_setr_ps(0, 0, 0, -0.0f, 0, 0, 0, 0);
        EX = v_maskz(needv, _mm256_blend_ps(_mm256_xor_ps(_mm256_mul_ps(cl, sx), neg3), ex, 0x07));
        EY = v_maskz(needv, _mm256_blend_ps(_mm256_xor_ps(_mm256_mul_ps(cl, sy), neg3), ey, 0x07));
        EZu = v_select(needv, _mm256_set1_ps(1.0f), _mm256_blend_ps(_mm256_xor_ps(_mm256_sub_ps(_mm256_mul_ps(cl, sz), d), neg3), ez, 0x07));
    } else {
        EX = _mm256_blend_ps(_mm256_setzero_ps(), ex, 0x07);
        EY = _mm256_blend_ps(_mm256_setzero_ps(), ey, 0x07);
        EZu = _mm256_blend_ps(_mm256_set1_ps(1.0f), ez, 0x07);
    }
    /* Slopes -1/e_x (garbage where e_x is 0, masked below); it does not wait for D. */
    ms_quot q;
    ms_divide(EX, V, &q);

    const float d_s = _mm256_cvtss_f32(d);
    if (!(d_s != 0.0f)) return 0;
    if (f->cull_backfaces && d_s > 0.0f) return 0; /* world D > 0: facing away from C */

    /* Scanline setup over the 8 lanes (ms_scan_setup_run); the classification uses magnitudes only. */
    const vf ax = _mm256_mul_ps(_mm256_and_ps(EX, absm), _mm256_set1_ps(kf));
    const vf ay = _mm256_mul_ps(_mm256_and_ps(EY, absm), _mm256_set1_ps(kf));
    const vf az = _mm256_and_ps(EZu, absm);
    const vf flat = _mm256_set1_ps(MS_FLAT_EDGE);
    const vm steep = V_CMP(ax, _mm256_mul_ps(flat, _mm256_max_ps(ay, az)), _CMP_GT_OQ);
    const vm flat_y = m_andnot(steep, V_CMP(ay, _mm256_mul_ps(flat, az), _CMP_GT_OQ));
    /* Two-sided: the active edges flipped by D's sign bit (the paper culls D <= 0). */
    const vf sgn = _mm256_and_ps(d, _mm256_set1_ps(-0.0f));
    const vf EZ = v_mask_xor(EZu, needv, sgn);
    /* an edge constant and negative over the buffer */
    if (m_bits(m_andnot(m_or(steep, flat_y), V_CMP(EZ, _mm256_setzero_ps(), _CMP_LT_OQ)))) return 0;
    const vf r = ms_quot_slopes(&q);
    const vf a = _mm256_mul_ps(EY, r), b = _mm256_mul_ps(EZu, r);
    const vm lower = V_CMP_IN(steep, _mm256_xor_ps(EX, sgn), _mm256_setzero_ps(), _CMP_GT_OQ);
    const vm upper = m_andnot(lower, steep);
    /* Stored: the rows broadcast them back with loads. */
    _mm256_storeu_ps(sv->al, v_maskz(lower, a));
    _mm256_storeu_ps(sv->bl, v_maskz(lower, b));
    _mm256_storeu_ps(sv->au, v_maskz(upper, a));
    _mm256_storeu_ps(sv->bu, v_select(upper, _mm256_set1_ps(kf - 1.0f), b));
    /* Sample range: the box of the projected vertices when in front of C (lane 0: y, lane 4: x), then
     * the flat edges' bounds on y. */
    int y0 = 0, y1 = k - 1;
    if (zmin_s > 0.0f) {
        const vf p = ms_quot_box(&q, V);
        const vf p1 = v_perm(p, rot1), p2 = v_perm(p, rot2);
        const vf lim_lo = _mm256_set1_ps(-1.0f), lim_hi = _mm256_set1_ps(kf), slack = _mm256_set1_ps(MS_BOX_SLACK);
        const vf lo = _mm256_min_ps(_mm256_max_ps(_mm256_sub_ps(_mm256_min_ps(_mm256_min_ps(p, p1), p2), slack), lim_lo), lim_hi);
        const vf hi = _mm256_min_ps(_mm256_max_ps(_mm256_add_ps(_mm256_max_ps(_mm256_max_ps(p, p1), p2), slack), lim_lo), lim_hi);
        /* vroundps in both ISAs: AVX-512 has embedded rounding for 512-bit conversions only. */
        const vi ilo = _mm256_max_epi32(_mm256_cvtps_epi32(_mm256_round_ps(lo, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC)),
                                        _mm256_setzero_si256());
        const vi ihi = _mm256_min_epi32(_mm256_cvtps_epi32(_mm256_round_ps(hi, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)),
                                        _mm256_set1_epi32(k - 1));
        if (m_bits(vi_cmpgt(ilo, ihi)) & 0x11) return 0;
        y0 = _mm256_cvtsi256_si32(ilo);
        y1 = _mm256_cvtsi256_si32(ihi);
    }
    const unsigned flat_bits = m_bits(flat_y);
    if (flat_bits) {
        /* Rare (an edge parallel to the scanlines): its own division. */
        const vf yb = _mm256_min_ps(_mm256_max_ps(_mm256_div_ps(_mm256_sub_ps(_mm256_setzero_ps(), EZu),
                                                                v_select(flat_y, _mm256_set1_ps(1.0f), EY)),
                                                  _mm256_set1_ps(-1.0f)),
                                    _mm256_set1_ps(kf));
        const unsigned up = m_bits(V_CMP_IN(flat_y, _mm256_xor_ps(EY, sgn), _mm256_setzero_ps(), _CMP_GT_OQ));
        float yv[8];
        _mm256_storeu_ps(yv, yb);
        ms_flat_y_bounds(yv, up, flat_bits & ~up, k, &y0, &y1);
    }
    sv->y0 = y0;
    sv->y1 = y1;
    return y0 <= y1;
}

/* The row data as the rows read it: edge e's coefficients at al[e * st] etc. (st = 1: an ms_scan_vec;
 * st = 16: one lane of an ms_scan_lanes). */
typedef struct ms_scan_view {
    const float *al, *bl, *au, *bu;
    int st, y0, y1;
} ms_scan_view;

/* First and last covered sample of scanlines ybase..ybase+MS_R-1, over the first NE edge lanes, and
 * the rows inside [y0, y1]. No clamping: every bound that is out of range, and NaN, converts to a shift
 * count (l, or width-1-h) of at least the lane width, or to the integer indefinite value, whose shifts
 * give 0 lanes: an empty interval, as clamping would. */
SI void ms_interval(const ms_scan_view *v, const int ne, int ybase, float kf, ri *l, ri *h, rm *rows)
{
    const ri yi = r_iota(ybase);
    const rf y = r_cvt(yi);
    rf lo[5], hi[5];
    for (int e = 0; e < ne; e++) {
        lo[e] = r_fmadd(v->al[e * v->st], y, v->bl[e * v->st]);
        hi[e] = r_fmadd(v->au[e * v->st], y, v->bu[e * v->st]);
    }
    /* Pairwise, for a short dependency chain; max(x, 0) and min(x, k-1) are the buffer's edges. */
    const rf l01 = r_max(lo[0], lo[1]), h01 = r_min(hi[0], hi[1]);
    rf l2 = r_max(lo[2], r_set1(0.0f)), h2 = r_min(hi[2], r_set1(kf - 1.0f));
    if (ne == 5) {
        l2 = r_max(l2, r_max(lo[3], lo[4]));
        h2 = r_min(h2, r_min(hi[3], hi[4]));
    }
    *l = r_ceil_i(r_max(l01, l2));
    *h = r_floor_i(r_min(h01, h2));
    *rows = r_rows(yi, v->y0, v->y1);
}
#endif /* MS_SCANLINE_SIMD_COMMON */

/* ---- per k ---- */
SI void MS_KFN(ms_simd_rows)(const ms_scan_view *v, const int ne, void *out)
{
    MS_WORD *buf = (MS_WORD *)out;
#if MS_K == 16
    /* All 16 rows, no loop branch to mispredict. Bits [l, h] of each 16-bit word in 32-bit lanes. */
    ri cov[16 / MS_R];
    for (int g = 0; g < 16 / MS_R; g++) {
        ri l, h;
        rm rows;
        ms_interval(v, ne, MS_R * g, 16.0f, &l, &h, &rows);
        cov[g] = r_cover32(l, h, rows, 0xFFFF, 15);
    }
    r_clear16(buf, cov);
#else
    for (int ybase = v->y0 & ~(MS_R - 1); ybase <= v->y1; ybase += MS_R) {
        ri l, h;
        rm rows;
        ms_interval(v, ne, ybase, (float)MS_K, &l, &h, &rows);
#if MS_K == 32
        r_clear32(buf + ybase, r_cover32(l, h, rows, -1, 31));
#else
        r_clear64(buf + ybase, l, h, rows);
#endif
    }
#endif
}

/* The row loop alone, three edges or five (with the clip edges' lanes), for the block traversal's set-up
 * of one triangle for many pixels (block_raster_impl.h, br_scan_setup): raster_internal.h,
 * ms_raster_rows. */
SI void MS_KFN(ms_lane_rows)(const ms_scan_lanes *v, int lane, const int ne, void *out)
{
    const ms_scan_view w = { &v->al[0][lane], &v->bl[0][lane], &v->au[0][lane], &v->bu[0][lane], MS_SCAN_LANES, v->y0[lane], v->y1[lane] };
    MS_KFN(ms_simd_rows)(&w, ne, out);
}
void MS_KFN(ms_scanline_rows3)(const ms_scan_lanes *v, int lane, void *out) { MS_KFN(ms_lane_rows)(v, lane, 3, out); }
void MS_KFN(ms_scanline_rows5)(const ms_scan_lanes *v, int lane, void *out) { MS_KFN(ms_lane_rows)(v, lane, 5, out); }

/* Without an active clip edge (the common case) the setup is shorter and the rows evaluate three edge
 * lanes instead of five. */
void MS_KFN(ms_scanline)(const ms_raster_frame *f, const float tri[9], void *out)
{
    ms_scan_vec v;
    const int r = ms_scan_vec_setup(f, tri, &v, 0);
    const int ne = r > 0 ? 3 : r < 0 && ms_scan_vec_setup(f, tri, &v, 1) > 0 ? 5 : 0;
    if (ne) {
        const ms_scan_view w = { v.al, v.bl, v.au, v.bu, 1, v.y0, v.y1 };
        MS_KFN(ms_simd_rows)(&w, ne, out);
    }
}
