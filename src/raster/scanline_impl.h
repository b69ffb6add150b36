/* Scalar bit-parallel scanline kernel (Woop 2010, sec. 4), instantiated once per buffer width through
 * core/perk_each.h (MS_K, MS_WORD). */
#define MS_ROWS_FN MS_KFN(ms_scan_rows)
#define MS_KERNEL_FN MS_KFN(ms_scanline)
#define MS_HALFPLANE_FN MS_KFN(ms_clear_halfplane)

/* Clears the covered interval of scanlines y0..y1. nl and nu are compile-time constants at every call
 * site, so each (nl, nu) pair gets its own unrolled, branch-free loop: the paper's specialised loops by
 * edge sign. The paper needs 16 (which of U, V, W, N, F is a lower bound); setup sorts the edges into
 * lower and upper lists, so only the counts matter, and edges that setup dropped (clip edges not
 * reached, edges parallel to x) never cost a loop operation. */
static inline __attribute__((always_inline)) void MS_ROWS_FN(MS_WORD *buf, const ms_scan_setup *s, const int nl,
                                                             const int nu)
{
    const float kmax = (float)(MS_K - 1);
    /* fy counts along in float (exact: small integers), no int-to-float conversion per row. */
    float fy = (float)s->y0;
    for (int y = s->y0; y <= s->y1; y++, fy += 1.0f) {
        float lo = 0.0f, hi = kmax;
        for (int e = 0; e < nl; e++) lo = ms_maxf(lo, s->al[e] * fy + s->bl[e]);
        for (int e = 0; e < nu; e++) hi = ms_minf(hi, s->au[e] * fy + s->bu[e]);
        /* Clamp so that both ends convert to [0, k] resp. [-1, k-1]: shift counts stay below the width of
         * the arithmetic type (the paper's shift-modulo concern, undefined behaviour in C). */
        const int l = ms_ceil_i(ms_minf(lo, (float)MS_K));
        const int h = ms_floor_i(ms_maxf(hi, -1.0f));
#if MS_K < 64
        /* Bits [l, h] as (1 << (h+1)) - (1 << l) in 64-bit arithmetic; an empty interval (h+1 <= l) gives
         * 0 through the max, which replaces the paper's not(lower > upper) term. */
        const int e1 = h + 1 > l ? h + 1 : l;
        const uint64_t covered = (UINT64_C(1) << e1) - (UINT64_C(1) << l);
#else
        /* Bits [l, h] as (ones << l) & (ones >> (63 - h)) on clamped counts, zeroed when empty. */
        const int ls = l < 63 ? l : 63, hs = h > 0 ? h : 0;
        const uint64_t covered = (~UINT64_C(0) << ls) & (~UINT64_C(0) >> (63 - hs)) & -(uint64_t)(l <= h);
#endif
        buf[y] &= (MS_WORD)~covered;
    }
}

void MS_KERNEL_FN(const ms_raster_frame *f, const float tri[9], void *out)
{
    ms_tri_setup t;
    ms_scan_setup s;
    if (!ms_tri_setup_run(f, tri, &t) || !ms_scan_setup_run(f, &t, &s)) return;
    MS_WORD *buf = (MS_WORD *)out;
#define MS_CASE(L, U) \
    case (L) * 8 + (U): MS_ROWS_FN(buf, &s, L, U); break;
    switch (s.nl * 8 + s.nu) {
        MS_CASE(0, 0) MS_CASE(0, 1) MS_CASE(0, 2) MS_CASE(0, 3) MS_CASE(0, 4) MS_CASE(0, 5)
        MS_CASE(1, 0) MS_CASE(1, 1) MS_CASE(1, 2) MS_CASE(1, 3) MS_CASE(1, 4)
        MS_CASE(2, 0) MS_CASE(2, 1) MS_CASE(2, 2) MS_CASE(2, 3)
        MS_CASE(3, 0) MS_CASE(3, 1) MS_CASE(3, 2)
        MS_CASE(4, 0) MS_CASE(4, 1)
        MS_CASE(5, 0)
    default: break;
    }
#undef MS_CASE
}

/* Clears every sample (x, y) with e . (x, y, 1) >= 0: a "triangle" of one active edge over the whole
 * buffer, through the same setup and row loop, so that a half-plane (the receiver's horizon) is decided
 * exactly like a triangle edge. */
void MS_HALFPLANE_FN(const float e[3], void *out)
{
    ms_raster_frame f = { .k = MS_K };
    ms_tri_setup t = { .n = 1, .x0 = 0, .x1 = MS_K - 1, .y0 = 0, .y1 = MS_K - 1 };
    ms_scan_setup s;
    t.e[0][0] = e[0]; t.e[0][1] = e[1]; t.e[0][2] = e[2];
    if (!ms_scan_setup_run(&f, &t, &s)) return;
    MS_WORD *buf = (MS_WORD *)out;
    if (s.nl) MS_ROWS_FN(buf, &s, 1, 0);
    else if (s.nu) MS_ROWS_FN(buf, &s, 0, 1);
    else MS_ROWS_FN(buf, &s, 0, 0);   /* flat edge: whole rows in [y0, y1]; constant: all */
}

#undef MS_HALFPLANE_FN
#undef MS_ROWS_FN
#undef MS_KERNEL_FN
