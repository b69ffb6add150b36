/* The watertight ray/triangle test for 16 rays at once, in lanes16.h's operations (included per ISA by the
 * methods' instance files after lanes16.h), with method raytrace's answers (accel/ray_triangle.h for the rest). */
#ifndef MS_VISIBILITY_WT_RAYS16_H
#define MS_VISIBILITY_WT_RAYS16_H
#include "lanes16.h"

/* raytrace's packet_triangle (raytrace_impl.h) for 16 rays, the same operations in the same order, with fewer
 * compares (the same answers for finite edge functions: some edge exactly 0 iff the least |edge| is 0; mixed
 * signs iff the least is < 0 and the largest > 0). A[v]: vertex v relative to each ray's origin, permuted to
 * the ray's axes (x, y, then the shear axis z); sx, sy: the rays' shears; d: their directions (world axes);
 * num: (v - origin) . N per ray (ms_wt_offset). The rays of bits that the triangle blocks within [near, far];
 * *edge0: those with an edge function exactly 0, which the caller redoes in double as raytrace does (rare).
 * Shared by mft's packets and groups (mft_impl.h, mft_group_impl.h) and hpc's 16-sample test (hpc_impl.h). */
static inline unsigned ms_wt_rays16(const l16 A[3][3], l16 sx, l16 sy, const l16 d[3], const float N[3], l16 num,
                                    float near, float far, unsigned bits, unsigned *edge0)
{
    const l16 ax = l16_sub(A[0][0], l16_mul(sx, A[0][2])), ay = l16_sub(A[0][1], l16_mul(sy, A[0][2]));
    const l16 bx = l16_sub(A[1][0], l16_mul(sx, A[1][2])), by = l16_sub(A[1][1], l16_mul(sy, A[1][2]));
    const l16 cx = l16_sub(A[2][0], l16_mul(sx, A[2][2])), cy = l16_sub(A[2][1], l16_mul(sy, A[2][2]));
    const l16 u = l16_sub(l16_mul(cx, by), l16_mul(cy, bx));
    const l16 v = l16_sub(l16_mul(ax, cy), l16_mul(ay, cx));
    const l16 w = l16_sub(l16_mul(bx, ay), l16_mul(by, ax));
    const l16 zero = l16_set1(0.0f);
    const unsigned z = l16_le(l16_min(l16_min(l16_abs(u), l16_abs(v)), l16_abs(w)), zero);
    const unsigned mixed = l16_lt(l16_min(l16_min(u, v), w), zero) & l16_gt(l16_max(l16_max(u, v), w), zero);
    const l16 det = l16_add(l16_add(u, v), w);
    const l16 den = l16_add(l16_add(l16_mul(d[0], l16_set1(N[0])), l16_mul(d[1], l16_set1(N[1]))), l16_mul(d[2], l16_set1(N[2])));
    const l16 ns = l16_select(l16_lt(den, zero), l16_sub(zero, num), num), aden = l16_abs(den);
    *edge0 = bits & z;
    return bits & ~z & ~mixed & l16_gt(l16_abs(det), zero) & l16_gt(aden, zero) & l16_le(l16_mul(l16_set1(near), aden), ns) &
           l16_le(ns, l16_mul(l16_set1(far), aden));
}

#endif
