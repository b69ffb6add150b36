/* The Scanline kernel's projected box of a triangle, bracketed from cheaper projections (block_raster_impl.h,
 * br_scan_setup): the block traversal's leaf tests already project the vertices as x (1/z), the kernel
 * divides x / z; where the two provably round to the same sample range, the set-up takes it and skips its
 * six divisions. Its own header so that tests/test_box_bracket.c checks it against the division. */
#ifndef MS_BOX_BRACKET_H
#define MS_BOX_BRACKET_H
#include "visibility/lanes16.h"

/* The kernel's row or column range of a triangle in front of C, from the leaf test's projections
 * q_v = fl(c_v fl(1/z_v)) instead of the kernel's fl(c_v / z_v): the lanes (returned mask) where the two
 * provably give the same i0 = max(ceil(clamp(min_v - slack)), 0) and i1 = min(floor(clamp(max_v + slack)),
 * k - 1), with those values in i0, i1. Why it holds: q_v and the kernel's p_v are both c_v / z_v times
 * (1 + e) with |e| <= 2u + u^2 resp. u (u = 2^-24, round to nearest), so |q_v - p_v| < 3.01 u |q_v|, plus
 * 2^-149 where a product or quotient is subnormal. q_v -+ (2^-20 |q_v| + 2^-100), rounded, therefore
 * bracket p_v (the rounding of the bracket moves it by at most u of itself, far inside the 16 u); min,
 * max, the rounded subtraction or addition of the slack, the clamps, ceil and floor are all monotone, so
 * the kernel's i0 (i1) lies between the values computed from the lower and the upper brackets, and where
 * those agree it is that value. Lanes with |q_v| > 2^100 or NaN (z tiny, non-finite input) are left to
 * the division, and so are lanes with z > 2^100 (the caller: there 1 / z may be subnormal). */
static inline unsigned br_box_bracket(const l16 q[3], l16 slack, l16 minus1, l16 kf, l16 k1, l16 *i0, l16 *i1)
{
    const l16 rel = l16_set1(1.0f / 1048576.0f), tiny = l16_set1(0x1p-100f), big = l16_set1(0x1p100f), zero = l16_set1(0.0f);
    unsigned fin = 0xFFFFu;
    l16 lo[3], hi[3];
    for (int v = 0; v < 3; v++) {
        const l16 aq = l16_abs(q[v]);
        fin &= l16_le(aq, big);
        const l16 d = l16_add(l16_mul(aq, rel), tiny);
        lo[v] = l16_sub(q[v], d);
        hi[v] = l16_add(q[v], d);
    }
    const l16 minl = l16_min(l16_min(lo[0], lo[1]), lo[2]), minh = l16_min(l16_min(hi[0], hi[1]), hi[2]);
    const l16 maxl = l16_max(l16_max(lo[0], lo[1]), lo[2]), maxh = l16_max(l16_max(hi[0], hi[1]), hi[2]);
    const l16 a0 = l16_max(l16_ceil(l16_min(l16_max(l16_sub(minl, slack), minus1), kf)), zero);
    const l16 b0 = l16_max(l16_ceil(l16_min(l16_max(l16_sub(minh, slack), minus1), kf)), zero);
    const l16 a1 = l16_min(l16_floor(l16_min(l16_max(l16_add(maxl, slack), minus1), kf)), k1);
    const l16 b1 = l16_min(l16_floor(l16_min(l16_max(l16_add(maxh, slack), minus1), kf)), k1);
    *i0 = a0;
    *i1 = a1;
    return fin & l16_le(b0, a0) & l16_le(b1, a1);   /* a <= b by monotonicity: equal */
}

#endif
