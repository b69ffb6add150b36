/* 3D edge functions (Dachsbacher, Slusallek, Davidovic, Engelhardt, Phillips, Georgiev, "3D Rasterization
 * - Unifying Rasterization and Ray Casting"; ../shared/papers/dachsbacher-3d-rasterization.txt): the one
 * per-pixel decision every 3D-rasterization primary ("3dr-*", primary_3dr.c) and the consistent BVH caster (primary_bvh.c, --consistent) share, so all of
 * them give the same hit triangle and the same t at every pixel, bit for bit.
 *
 * Set-up (ms_e3_setup), in the appendix's homogeneous form with one code path for both kinds of camera:
 * the "eye" E = (e, w) is the eye point with w = 1 (pinhole, fisheye, latlong, parabolic) or the view
 * direction with w = 0 (orthographic: the eye at infinity). The edge (a, b) spans the plane through a, b
 * and E, normal m = (w b - e) x (a - b) (w = 1: the paper's eq. 1 in its stable form p1 x (p0 - p1) with
 * the vertices relative to the eye; w = 0: the plane through the edge containing the view direction, as
 * the appendix's D_12ed). A ray (o, d) scores V = k + m . q, with q = d and k = 0 for a point eye (every
 * ray starts at e, which lies in every edge plane), and q = o, k = -m . a for the orthographic camera (d
 * is the same for every ray and lies in the plane): both are the appendix's 4x4 determinant of a, b, E
 * and the ray, up to a factor. Evaluated directly per pixel, as the paper does.
 *
 * Departures from the paper, all for exact consistency (its sec. 4.2) in floating point:
 *  - everything in double, from the float vertices and float rays of ms_camera_ray;
 *  - each edge's m and k are computed from its two vertices in a canonical order (lexicographically
 *    smaller vertex first), then negated (exact) to point into the triangle: two triangles sharing the
 *    edge compute bit-identical |V| with opposite signs, so no ray passes between them and none is
 *    claimed twice, whatever the rounding;
 *  - ties (V exactly 0) by the top-left rule carried to 3D as a symbolic perturbation of the ray by
 *    eps right + eps^2 (-up) + eps^3 forward: the triangle owns the ray on that edge iff its inward m has,
 *    lexicographically, a positive component along right, else along -up (image y grows downwards), else
 *    along forward. For planar cameras this is the paper's V_i,x > 0, then V_i,y rule; as every edge is
 *    decided at the same perturbed ray, a pixel centre on a vertex shared by a closed fan is owned by
 *    exactly one triangle of the fan (the paper's vertex rule);
 *  - two-sided (microshadow's visibility has no back faces): the inward sign is the triangle's
 *    orientation sigma, the sign of its D_123E; sigma = 0 (edge-on or degenerate) is never hit;
 *  - t (eq. 2, the ratio of the tetrahedron's volume to the sum of the edge functions) is computed as
 *    the plane distance N . (p0 - o) / N . d with N = (p1 - p0) x (p2 - p0), which is eq. 2 for a point
 *    eye and the appendix's -D_123e / D_123d for the orthographic camera; a hit needs t > 0 in float. */
#ifndef MS_EDGE3D_H
#define MS_EDGE3D_H
#include <math.h>
#include <stdint.h>
#include "camera/camera.h"
#include "visibility/alpha.h"

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

typedef struct ms_e3_tri {
    double m[3][3];      /* inward edge normals (edge i from vertex i to i+1) */
    double k[3];         /* inward constants (0 for a point eye) */
    unsigned char tie[3];/* 1: the triangle owns rays with V_i exactly 0 */
    double n[3];         /* plane normal (p1 - p0) x (p2 - p0) */
    double p0[3];
    int ok;              /* 0: degenerate or edge-on, never hit */
} ms_e3_tri;

/* The camera as the set-up sees it: E and the tie-break frame. */
typedef struct ms_e3_cam {
    double e[3];         /* eye point (w = 1) or view direction (w = 0) */
    int w;
    double right[3], down[3], forward[3];
} ms_e3_cam;

void ms_e3_cam_init(ms_e3_cam *c, const ms_camera_basis *b);
/* Per triangle (9 floats). */
void ms_e3_setup(const ms_e3_cam *c, const float tri[9], ms_e3_tri *t);

/* The ray's scored point: d for a point eye, o for the orthographic camera. */
static inline const float *ms_e3_q(const ms_e3_cam *c, const float o[3], const float d[3])
{
    return c->w ? d : o;
}

/* The per-pixel decision: 1 and t when the ray (o, d) hits the triangle (q = ms_e3_q(o, d)). */
static inline int ms_e3_hit(const ms_e3_tri *T, const float o[3], const float d[3], const float q[3], float *t)
{
    if (!T->ok) return 0;
    const double qx = q[0], qy = q[1], qz = q[2];
    for (int i = 0; i < 3; i++) {
        const double v = T->k[i] + (T->m[i][0] * qx + T->m[i][1] * qy + T->m[i][2] * qz);
        if (v > 0.0) continue;
        if (v == 0.0 && T->tie[i]) continue;
        return 0;   /* negative, tie not owned, or NaN (no ray) */
    }
    const double num = T->n[0] * (T->p0[0] - (double)o[0]) + T->n[1] * (T->p0[1] - (double)o[1]) +
                       T->n[2] * (T->p0[2] - (double)o[2]);
    const double den = T->n[0] * (double)d[0] + T->n[1] * (double)d[1] + T->n[2] * (double)d[2];
    const float tt = (float)(num / den);
    if (!(tt > 0.0f && tt < INFINITY)) return 0;
    *t = tt;
    return 1;
}

/* The upper bound of each inward edge function over a set of rays, for culling tiles: 0 when some edge's
 * bound is below zero (no ray of the set can pass; conservative, with a margin for rounding), else 1.
 * Planar cameras: the four corner rays' scored points q (V is affine in the image position). */
int ms_e3_tile_planar(const ms_e3_tri *T, const double q[4][3], double qmag);
/* Curved cameras (the paper's sec. 4.1 generalised; see edge3d.c): the unit directions of a cone, axis a,
 * half-angle alpha (radians). */
int ms_e3_tile_cone(const ms_e3_tri *T, const double a[3], double alpha);

/* Triangle screen bounds for the rasterizers, conservative against ms_e3_hit: pixel ranges [x0,x1] x
 * [y0,y1] (inclusive), up to two x ranges (a latlong image wraps). Returns the number of boxes (0: the
 * triangle cannot be hit by any pixel's ray). */
typedef struct ms_e3_box { int x0, y0, x1, y1; } ms_e3_box;
int ms_e3_bounds(const ms_camera_basis *b, const float tri[9], ms_e3_box box[2]);

/* Where a primary accepts a hit: alpha-tested triangles count only where opaque (alpha.h, the one decision
 * every method shares), so every primary that uses ms_e3_hit looks through the same texels. a: the frame's
 * table (leaf-order ids; NULL: every triangle opaque, e.g. a streamed scene). */
static inline int ms_e3_accept(const ms_alpha *a, uint32_t prim, const float o[3], const float d[3])
{
    return !ms_alpha_tested(a, prim) || ms_alpha_ray_occludes(a, prim, o, d);
}

#endif
