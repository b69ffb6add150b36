/* Watertight ray/triangle intersection (Woop, Benthin, Wald, "Watertight Ray/Triangle Intersection",
 * JCGT 2(1), 2013), shared by every ray test of ours: BVH closest and any hit (bvh_traverse.c), the
 * shadow segments of raytrace, mft and hpc (src/shadow/raytrace/, mft/, hpc/: the scalar segment tests
 * below, ms_wt_segment and ms_wt_segment_sheared, and their SIMD lane forms) and Embree's primary t
 * (src/primary/primary_embree.c).
 *
 * Per ray (ms_wt_prepare): kz = the axis of largest |d|, kx, ky the next two (swapped when d[kz] < 0
 * to keep the winding), and the shear Sx = dx/dz, Sy = dy/dz, Sz = 1/dz that maps the ray onto the
 * +z axis. Per triangle: the vertices relative to the origin, sheared to 2D; the edge functions
 * U, V, W in float, recomputed in double when any is exactly 0 (the float products are exact in
 * double, so the sign of a near-zero edge is exact); a hit when all three have one sign. Two
 * triangles sharing an edge compute its edge function from the same two sheared vertices, with
 * opposite signs bit for bit (round-to-nearest is symmetric), so no ray passes between them
 * whatever the rounding (sec. 3). This needs the products to be rounded as written: no FMA
 * contraction (GCC's default for -std=c11 is -ffp-contract=off; the pragma below is for clang).
 *
 * Departures from the paper, all deliberate:
 *  - two-sided (its non-culling variant): accept U, V, W all >= 0 or all <= 0;
 *  - t is not the paper's T / det but the distance to the triangle's plane, ((v - o) . N) / (d . N)
 *    (as Moller-Trumbore and Embree compute it) with N from the two shortest edges (ms_wt_normal,
 *    kept per triangle by the BVH) and v the vertex nearest the origin (ms_wt_offset), clamped into
 *    the range of the vertices' depths
 *    Sz * (v - o)[kz] (where the hit lies; it bounds t for zero-area triangles, whose N is noise).
 *    T / det interpolates the vertices' depths with barycentrics rounded to ulps of the vertices'
 *    distance over the projected triangle's width, which a ray grazing a long triangle amplifies: in
 *    Dabrovic Sponza a receiver 1.6e-5 beside a crease got t = +1.9e-4 instead of -5.2e-4 on its
 *    neighbour, i.e. false occlusion (the plane form is accurate to the rounding of the distance);
 *  - the t range is decided on that t itself (the paper compares T with t_far * det), so a hit
 *    means exactly "t in [tmin, tmax]" for the t we report and the closest hit is the minimum over
 *    the triangles whatever order they are tested in, which the BVH tests compare bit for bit with
 *    brute force. The division happens only for rays that passed the edge tests. The shadow segments
 *    (ms_wt_segment_sheared: raytrace, mft, hpc), which need only the any-hit answer, compare the plane
 *    distance with tmin and tmax scaled by d . N, without a division or the clamp, and share one shear
 *    axis over 16 lanes (ms_wt_packet_axis);
 *  - u, v are the weights of vertices 1 and 2 (V / det, W / det), as Moller-Trumbore's were.
 *
 * Zero-area triangles need no special case: a repeated vertex gives U = V = W = 0 or mixed signs, so
 * never a hit; a triangle of three collinear vertices is hit only by rays that pass within rounding of
 * its segment, at a t between its vertices' depths (the clamp of ms_wt_hit_t). A
 * sliver, however thin, is hit exactly where it is, so a closed mesh with slivers stays closed. */
#ifndef MS_RAY_TRIANGLE_H
#define MS_RAY_TRIANGLE_H
#include <math.h>
#include "core/vec.h"   /* ms_maxf */

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

typedef struct ms_wt_ray {
    float o[3], d[3];
    int kx, ky, kz;
    float sx, sy, sz;
} ms_wt_ray;

/* The axis of largest |d[a]| (the first on ties). */
static inline int ms_wt_max_axis(const float d[3])
{
    const float x = fabsf(d[0]), y = fabsf(d[1]), z = fabsf(d[2]);
    return x >= y ? (x >= z ? 0 : 2) : (y >= z ? 1 : 2);
}

static inline void ms_wt_prepare(ms_wt_ray *w, const float o[3], const float d[3])
{
    const int kz = ms_wt_max_axis(d);
    int kx = kz + 1 == 3 ? 0 : kz + 1, ky = kx + 1 == 3 ? 0 : kx + 1;
    if (d[kz] < 0.0f) { const int s = kx; kx = ky; ky = s; }
    w->o[0] = o[0]; w->o[1] = o[1]; w->o[2] = o[2];
    w->d[0] = d[0]; w->d[1] = d[1]; w->d[2] = d[2];
    w->kx = kx; w->ky = ky; w->kz = kz;
    /* d = 0 gives NaNs here, and NaN fails every test below: no hit. */
    w->sx = d[kx] / d[kz];
    w->sy = d[ky] / d[kz];
    w->sz = 1.0f / d[kz];
}

/* 2D edge function x0*y1 - y0*x1 of two sheared vertices; *_d: the same in double, exact products. */
static inline float ms_wt_edge(float x0, float y0, float x1, float y1) { return x0 * y1 - y0 * x1; }
static inline float ms_wt_edge_d(float x0, float y0, float x1, float y1)
{
    return (float)((double)x0 * (double)y1 - (double)y0 * (double)x1);
}

/* The quantities of one ray/triangle pair (sec. 3): edge functions U, V, W, det = U + V + W, and the
 * vertices' depths along the ray (ray parameters of their kz planes). */
typedef struct ms_wt_eval { float u, v, w, det, za, zb, zc; } ms_wt_eval;

static inline void ms_wt_evaluate(const ms_wt_ray *r, const float tri[9], ms_wt_eval *e)
{
    const int kx = r->kx, ky = r->ky, kz = r->kz;
    float A[3], B[3], C[3];
    for (int a = 0; a < 3; a++) { A[a] = tri[a] - r->o[a]; B[a] = tri[3 + a] - r->o[a]; C[a] = tri[6 + a] - r->o[a]; }
    const float ax = A[kx] - r->sx * A[kz], ay = A[ky] - r->sy * A[kz];
    const float bx = B[kx] - r->sx * B[kz], by = B[ky] - r->sy * B[kz];
    const float cx = C[kx] - r->sx * C[kz], cy = C[ky] - r->sy * C[kz];
    float U = ms_wt_edge(cx, cy, bx, by), V = ms_wt_edge(ax, ay, cx, cy), W = ms_wt_edge(bx, by, ax, ay);
    if (U == 0.0f || V == 0.0f || W == 0.0f) {
        U = ms_wt_edge_d(cx, cy, bx, by);
        V = ms_wt_edge_d(ax, ay, cx, cy);
        W = ms_wt_edge_d(bx, by, ax, ay);
    }
    e->u = U; e->v = V; e->w = W;
    e->det = U + V + W;
    e->za = r->sz * A[kz]; e->zb = r->sz * B[kz]; e->zc = r->sz * C[kz];
}

/* The plane's normal N, the cross product of the two shortest edges (E_a x E_b = E_b x E_c = E_c x E_a
 * for the cyclic edges E_a = v1 - v0, E_b = v2 - v1, E_c = v0 - v2): a sliver's two long edges are
 * nearly parallel and their cross product loses its direction (a 10 x 0.02 triangle: 1e-4 of its
 * vertices' distance in the plane offset). The BVH keeps it per triangle (ms_bvh.tri_n). */
static inline void ms_wt_normal(const float tri[9], float n[3])
{
    float E[3][3], le[3];
    for (int i = 0; i < 3; i++) {
        const int j = i + 1 == 3 ? 0 : i + 1;
        for (int a = 0; a < 3; a++) E[i][a] = tri[3 * j + a] - tri[3 * i + a];
        le[i] = E[i][0] * E[i][0] + E[i][1] * E[i][1] + E[i][2] * E[i][2];
    }
    const int lng = le[0] >= le[1] ? (le[0] >= le[2] ? 0 : 2) : (le[1] >= le[2] ? 1 : 2);
    const float *x = E[lng + 1 == 3 ? 0 : lng + 1], *y = E[lng + 2 >= 3 ? lng - 1 : lng + 2];
    n[0] = x[1] * y[2] - x[2] * y[1];
    n[1] = x[2] * y[0] - x[0] * y[2];
    n[2] = x[0] * y[1] - x[1] * y[0];
}

/* The origin's offset from the plane, (v - o) . N, from the vertex v nearest the origin, which rounds
 * least: t = offset / (d . N). */
static inline float ms_wt_offset(const float o[3], const float tri[9], const float n[3])
{
    float V[3][3], lv[3];
    for (int i = 0; i < 3; i++) {
        for (int a = 0; a < 3; a++) V[i][a] = tri[3 * i + a] - o[a];
        lv[i] = V[i][0] * V[i][0] + V[i][1] * V[i][1] + V[i][2] * V[i][2];
    }
    const int nr = lv[0] <= lv[1] ? (lv[0] <= lv[2] ? 0 : 2) : (lv[1] <= lv[2] ? 1 : 2);
    return V[nr][0] * n[0] + V[nr][1] * n[1] + V[nr][2] * n[2];
}

/* The hit distance for a ray that passed the edge tests, n the triangle's ms_wt_normal: the plane
 * distance, clamped into the vertices' depth range (NaN, from d . N = 0, becomes its low end). */
static inline float ms_wt_hit_t(const ms_wt_ray *r, const float tri[9], const float n[3], const ms_wt_eval *e)
{
    const float t = ms_wt_offset(r->o, tri, n) / (r->d[0] * n[0] + r->d[1] * n[1] + r->d[2] * n[2]);
    const float lo = e->za < e->zb ? (e->za < e->zc ? e->za : e->zc) : (e->zb < e->zc ? e->zb : e->zc);
    const float hi = e->za > e->zb ? (e->za > e->zc ? e->za : e->zc) : (e->zb > e->zc ? e->zb : e->zc);
    return !(t >= lo) ? lo : t > hi ? hi : t;
}

/* 1 and t, u, v when the ray hits the triangle (two-sided) with t in [tmin, tmax]; n: its ms_wt_normal. */
static inline int ms_wt_intersect(const ms_wt_ray *r, const float tri[9], const float n[3], float tmin, float tmax,
                                  float *t, float *u, float *v)
{
    ms_wt_eval e;
    ms_wt_evaluate(r, tri, &e);
    if ((e.u < 0.0f || e.v < 0.0f || e.w < 0.0f) && (e.u > 0.0f || e.v > 0.0f || e.w > 0.0f)) return 0;
    if (e.det == 0.0f) return 0;
    const float tt = ms_wt_hit_t(r, tri, n, &e);
    if (!(tt >= tmin && tt <= tmax)) return 0;   /* also rejects NaN (a zero direction) */
    *t = tt;
    *u = e.v / e.det;
    *v = e.w / e.det;
    return 1;
}

/* ---- shadow segments: any hit, t in [tmin, tmax], the receiver's 16-sample packets ---- */

/* The shear axis one packet of n rays shares (raytrace, mft and hpc choose it alike, so that their
 * answers agree bit for bit). Any kz with d[kz] != 0 keeps the test watertight (the per-ray choice of the
 * largest |d| only bounds the shear); the rays of a packet point at one small light, so one axis usually
 * serves all lanes. The rule: the light's own axis pref (ms_light_shear_axis: the largest component of its
 * normal; -1: none) when every lane has |d[pref]| >= max|d| / 2, else lane 0's largest under the same
 * condition, else -1 and the lanes are tested one by one (ms_wt_segment). Either way |Sx|, |Sy| <= 2: as
 * accurate as the per-ray choice within a factor of 2. pref comes first so that segments to one light are
 * sheared alike wherever they start: axis-aligned rectangles merged along the other axes are then decided
 * exactly as their pieces (accel/coplanar.h), which the per-ray largest axis would not give the many
 * segments that leave a light sideways. dx, dy, dz: the lanes' direction components. *kz0: the packet's axis,
 * or lane 0's largest when it has none. */
static inline int ms_wt_packet_axis(const float *dx, const float *dy, const float *dz, int n, int pref, int *kz0)
{
    const float d0[3] = { dx[0], dy[0], dz[0] };
    const float *const d[3] = { dx, dy, dz };
    const int k0 = ms_wt_max_axis(d0);
    int okp = pref >= 0, ok0 = 1;
    for (int l = 0; l < n; l++) {
        const float m = ms_maxf(fabsf(dx[l]), ms_maxf(fabsf(dy[l]), fabsf(dz[l])));
        if (pref >= 0) okp &= 2.0f * fabsf(d[pref][l]) >= m && m > 0.0f;
        ok0 &= 2.0f * fabsf(d[k0][l]) >= m && m > 0.0f;
    }
    const int kz = okp ? pref : ok0 ? k0 : -1;
    if (kz0) *kz0 = kz >= 0 ? kz : k0;
    return kz;
}

/* 1 if the triangle blocks the segment from o to o + d at a parameter in [tmin, tmax], with the ray's own
 * shear (the lanes of a packet without a shared axis). n: the triangle's ms_wt_normal. */
static inline int ms_wt_segment(const float o[3], const float d[3], const float tri[9], const float n[3], float tmin,
                                float tmax)
{
    ms_wt_ray w;
    float t, u, v;
    ms_wt_prepare(&w, o, d);
    return ms_wt_intersect(&w, tri, n, tmin, tmax, &t, &u, &v);
}

/* The same with the packet's shared axis kz (ms_wt_packet_axis, >= 0) and this lane's shear sx = d[kx] /
 * d[kz], sy = d[ky] / d[kz] (kx, ky: the next two axes, cyclic; the winding swap of the paper is not
 * needed: the test is two-sided; Sz is not needed, t comes from the plane). A, B, C: the vertices minus
 * o; num: ms_wt_offset(o, tri, n). The t range is tested on the plane distance num against tmin and tmax
 * scaled by d . n (sign adjusted), without a division: only the any-hit answer is needed. The edge
 * functions are redone in double when any is exactly 0 (as ms_wt_evaluate does). This is the scalar form;
 * the packet tracers' SIMD lane loops compute the very same operations (raytrace_impl.h, mft_impl.h). */
static inline int ms_wt_segment_sheared(const float A[3], const float B[3], const float C[3], int kz, float sx,
                                        float sy, const float d[3], const float n[3], float num, float tmin, float tmax)
{
    const int kx = kz + 1 == 3 ? 0 : kz + 1, ky = kx + 1 == 3 ? 0 : kx + 1;
    const float ax = A[kx] - sx * A[kz], ay = A[ky] - sy * A[kz], bx = B[kx] - sx * B[kz], by = B[ky] - sy * B[kz];
    const float cx = C[kx] - sx * C[kz], cy = C[ky] - sy * C[kz];
    float u = ms_wt_edge(cx, cy, bx, by), v = ms_wt_edge(ax, ay, cx, cy), w = ms_wt_edge(bx, by, ax, ay);
    if (u == 0.0f || v == 0.0f || w == 0.0f) {
        u = ms_wt_edge_d(cx, cy, bx, by);
        v = ms_wt_edge_d(ax, ay, cx, cy);
        w = ms_wt_edge_d(bx, by, ax, ay);
    }
    if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return 0;
    const float det = u + v + w;
    const float den = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
    const float ns = den < 0.0f ? -num : num, aden = fabsf(den);
    return det != 0.0f && aden > 0.0f && ns >= tmin * aden && ns <= tmax * aden;
}

/* Conservative box test to match (sec. 4 and Ize, "Robust BVH Ray Traversal", JCGT 2013): the
 * triangle test decides on vertices rounded relative to the origin and sheared, so it may report a
 * hit for a ray that passes, exactly, a few ulps of the vertices' distance outside the triangle, and
 * so outside its box: a ray through a shared vertex on a box face may be given to the triangle of a
 * box it does not enter. Boxes are therefore widened in every axis by a margin e = MS_WT_BOX_REL
 * times the largest of the root box's coordinates relative to the ray origin and the origin's own
 * (2^-16, about 250 ulps of any vertex's distance: far above those few ulps, far below anything that
 * costs culling); one margin per ray, or per packet, bounds every node's own. It is folded into two
 * shifted origins, o + e and o - e, so that the slab test costs what it did: lo = bmin - (o + e),
 * hi = bmax - (o - e); counting |o| in e keeps it far above the rounding of o +- e. The slab
 * distances are then widened by Ize's 1 + 2 gamma(3) on top, for the slab test's own rounding.
 * The coordinates are the scene's frame's (docs/design.md, "The scene's frame"): a loaded scene's lie within
 * 6 half-extents h of the origin wherever it is in the world (src/scene/scene_frame.c), so for a shadow
 * ray, whose origin is on the geometry and whose root box is the scene's, e <= 2^-16 (6h + |light|) is a
 * fixed fraction of the scene, as tight 100 km out as at home. (In world coordinates the |o| term would grow
 * with the distance: at 1e5 it is wider than a 0.2-wide model, and nothing is culled.) */
#define MS_WT_BOX_REL (1.0f / 65536.0f)

/* The shifted origins for a ray from o in a BVH whose root box is [lo, hi]. */
static inline void ms_wt_box_origins(const float lo[3], const float hi[3], const float o[3], float o_lo[3],
                                     float o_hi[3])
{
    float m = 0.0f;
    for (int a = 0; a < 3; a++) {
        const float l = fabsf(lo[a] - o[a]), h = fabsf(hi[a] - o[a]), c = fabsf(o[a]);
        m = l > m ? l : m;
        m = h > m ? h : m;
        m = c > m ? c : m;
    }
    const float e = m * MS_WT_BOX_REL;
    for (int a = 0; a < 3; a++) { o_lo[a] = o[a] + e; o_hi[a] = o[a] - e; }
}

/* Ize's widening of the exit distance, t_far * (1 + 2 gamma(3)) with gamma(n) = n u / (1 - n u),
 * taken here with u = 2^-23 (twice the bound for round-to-nearest, as the code always had). */
#define MS_WT_FAR_SCALE (1.0f + 2.0f * 3.5762786e-07f)

#endif
