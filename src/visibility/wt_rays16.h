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
/* The sheared vertices' three edge functions U, V, W (ray_triangle.h's ms_wt_edge of the sheared pairs) and which
 * rays have one exactly 0 (*zero) or strictly mixed signs (*mixed); A, sx, sy as below. */
static inline void ms_wt_edges16(const l16 A[3][3], l16 sx, l16 sy, l16 uvw[3], unsigned *zero, unsigned *mixed)
{
    const l16 ax = l16_sub(A[0][0], l16_mul(sx, A[0][2])), ay = l16_sub(A[0][1], l16_mul(sy, A[0][2]));
    const l16 bx = l16_sub(A[1][0], l16_mul(sx, A[1][2])), by = l16_sub(A[1][1], l16_mul(sy, A[1][2]));
    const l16 cx = l16_sub(A[2][0], l16_mul(sx, A[2][2])), cy = l16_sub(A[2][1], l16_mul(sy, A[2][2]));
    const l16 u = l16_sub(l16_mul(cx, by), l16_mul(cy, bx));
    const l16 v = l16_sub(l16_mul(ax, cy), l16_mul(ay, cx));
    const l16 w = l16_sub(l16_mul(bx, ay), l16_mul(by, ax));
    const l16 z0 = l16_set1(0.0f);
    *zero = l16_le(l16_min(l16_min(l16_abs(u), l16_abs(v)), l16_abs(w)), z0);
    *mixed = l16_lt(l16_min(l16_min(u, v), w), z0) & l16_gt(l16_max(l16_max(u, v), w), z0);
    uvw[0] = u; uvw[1] = v; uvw[2] = w;
}

static inline unsigned ms_wt_rays16(const l16 A[3][3], l16 sx, l16 sy, const l16 d[3], const float N[3], l16 num,
                                    float near, float far, unsigned bits, unsigned *edge0)
{
    l16 uvw[3];
    unsigned z, mixed;
    ms_wt_edges16(A, sx, sy, uvw, &z, &mixed);
    const l16 zero = l16_set1(0.0f);
    const l16 det = l16_add(l16_add(uvw[0], uvw[1]), uvw[2]);
    const l16 den = l16_add(l16_add(l16_mul(d[0], l16_set1(N[0])), l16_mul(d[1], l16_set1(N[1]))), l16_mul(d[2], l16_set1(N[2])));
    const l16 ns = l16_select(l16_lt(den, zero), l16_sub(zero, num), num), aden = l16_abs(den);
    *edge0 = bits & z;
    return bits & ~z & ~mixed & l16_gt(l16_abs(det), zero) & l16_gt(aden, zero) & l16_le(l16_mul(l16_set1(near), aden), ns) &
           l16_le(ns, l16_mul(l16_set1(far), aden));
}

/* ms_wt_offset (ray_triangle.h) per ray: (v - o) . N from the vertex nearest each ray's origin, the same operations
 * and the same choice on ties. V[v]: vertex v relative to each ray's origin (world axes). */
static inline l16 ms_wt_offset16(const l16 V[3][3], const float N[3])
{
    l16 lv[3], vn[3];
    for (int v = 0; v < 3; v++)
        lv[v] = l16_add(l16_add(l16_mul(V[v][0], V[v][0]), l16_mul(V[v][1], V[v][1])), l16_mul(V[v][2], V[v][2]));
    /* nr = lv0 <= lv1 ? (lv0 <= lv2 ? 0 : 2) : (lv1 <= lv2 ? 1 : 2) */
    const unsigned le01 = l16_le(lv[0], lv[1]), p0 = le01 & l16_le(lv[0], lv[2]), p1 = ~le01 & l16_le(lv[1], lv[2]);
    for (int x = 0; x < 3; x++) vn[x] = l16_select(p0, V[0][x], l16_select(p1, V[1][x], V[2][x]));
    return l16_add(l16_add(l16_mul(vn[0], l16_set1(N[0])), l16_mul(vn[1], l16_set1(N[1]))), l16_mul(vn[2], l16_set1(N[2])));
}

/* ms_wt_segment (ray_triangle.h) for 16 rays at once, each with its own shear axis (the lanes of a packet whose
 * rays share none: ms_wt_packet_axis gave -1), the same operations per lane: kz the axis of largest |d| (the first
 * on ties), Sx = d[kx] / d[kz], Sy = d[ky] / d[kz], Sz = 1 / d[kz] (divisions, as ms_wt_prepare), the edge
 * functions, det, and the plane distance divided by d . N and clamped into the vertices' depths Sz (v - o)[kz]
 * (ms_wt_hit_t), tested against [near, far]. ms_wt_prepare also swaps kx and ky when d[kz] < 0, to keep the
 * winding; that swap exchanges each vertex's two sheared coordinates, which negates U, V, W and det exactly
 * (a*b - c*d and c*d - a*b round to opposite values), so no answer of this two-sided test changes and it is left
 * out. A[v]: vertex v relative to each ray's origin (world axes); num: ms_wt_offset per ray. Returns the rays of
 * bits the triangle blocks; *edge0: those with an edge function exactly 0, which the caller redoes with
 * ms_wt_segment (in double, rare). */
static inline unsigned ms_wt_rays16_own(const l16 A[3][3], const l16 d[3], const float N[3], l16 num, float near, float far,
                                        unsigned bits, unsigned *edge0)
{
    const l16 zero = l16_set1(0.0f);
    const l16 x = l16_abs(d[0]), y = l16_abs(d[1]), z = l16_abs(d[2]);
    const unsigned xy = l16_le(y, x), xz = l16_le(z, x), yz = l16_le(z, y);
    const unsigned m0 = xy & xz, m1 = ~xy & yz;   /* kz = 0, kz = 1; else 2 */
#define MS_SEL3(a0, a1, a2) l16_select(m0, a0, l16_select(m1, a1, a2))
    const l16 dz = MS_SEL3(d[0], d[1], d[2]), dx = MS_SEL3(d[1], d[2], d[0]), dy = MS_SEL3(d[2], d[0], d[1]);
    const l16 sx = l16_div(dx, dz), sy = l16_div(dy, dz), sz = l16_div(l16_set1(1.0f), dz);
    l16 P[3][3], zv[3];
    for (int v = 0; v < 3; v++) {
        P[v][0] = MS_SEL3(A[v][1], A[v][2], A[v][0]);
        P[v][1] = MS_SEL3(A[v][2], A[v][0], A[v][1]);
        P[v][2] = MS_SEL3(A[v][0], A[v][1], A[v][2]);
        zv[v] = l16_mul(sz, P[v][2]);
    }
#undef MS_SEL3
    l16 uvw[3];
    unsigned ez, mixed;
    ms_wt_edges16((const l16 (*)[3])P, sx, sy, uvw, &ez, &mixed);
    const l16 det = l16_add(l16_add(uvw[0], uvw[1]), uvw[2]);
    const l16 den = l16_add(l16_add(l16_mul(d[0], l16_set1(N[0])), l16_mul(d[1], l16_set1(N[1]))), l16_mul(d[2], l16_set1(N[2])));
    const l16 t = l16_div(num, den);
    /* ms_wt_hit_t: lo = za < zb ? (za < zc ? za : zc) : (zb < zc ? zb : zc), hi alike with >; NaN goes to lo */
    const unsigned ab = l16_lt(zv[0], zv[1]), ac = l16_lt(zv[0], zv[2]), bc = l16_lt(zv[1], zv[2]);
    const l16 lo = l16_select(ab, l16_select(ac, zv[0], zv[2]), l16_select(bc, zv[1], zv[2]));
    const unsigned gab = l16_gt(zv[0], zv[1]), gac = l16_gt(zv[0], zv[2]), gbc = l16_gt(zv[1], zv[2]);
    const l16 hi = l16_select(gab, l16_select(gac, zv[0], zv[2]), l16_select(gbc, zv[1], zv[2]));
    const l16 tt = l16_select(l16_le(lo, t), l16_select(l16_gt(t, hi), hi, t), lo);
    *edge0 = bits & ez;
    return bits & ~ez & ~mixed & ~l16_le(l16_abs(det), zero) & l16_le(l16_set1(near), tt) & l16_le(tt, l16_set1(far));
}

#endif
