/* Penumbra volumes (hpc_volume.h; Laine & Aila 2005, sec. 3.2, "MAKE-PENUMBRA-VOLUME").
 *
 * As the paper: every vertex-edge pair between the polygon and the triangle spans a candidate plane; the
 * candidates with all polygon vertices on one side and all triangle vertices on the other are kept, and
 * the triangle's plane caps the volume when the whole polygon lies on one side of it. Each kept plane is
 * a valid bound on its own (a point x = l + s (t - l), s >= 1, with l on the polygon and t on the
 * triangle, lies on t's side of a plane separating them), so keeping a subset when degenerate duplicates
 * overflow HPC_MAX_PLANES is still conservative.
 *
 * Departure: the planes are found in double and classified with a tolerance of 1e-9 of the geometry's
 * size, and the tests allow the caller's margin eps (hpc.c derives it from the rounding of the exact
 * per-sample test), so that a relation the reference ray test calls blocked is never culled here. */
#include "hpc_volume.h"
#include "core/vec.h"
#include <math.h>
#include <string.h>

/* fmin and fmax are library calls without -ffast-math (a visible share of a cast); the values here are
 * finite. */
static inline double dmin(double a, double b) { return a < b ? a : b; }
static inline double dmax(double a, double b) { return a > b ? a : b; }

/* Adds the plane through e0, e1 and v if it separates the polygon (on its non-positive side) from the
 * blocker's nt points; oriented so that the blocker's side is positive. */
static void try_plane(hpc_volume *v, const double e0[3], const double e1[3], const double w[3], const double *poly,
                      int np, const double (*tv)[3], int nt, double tol)
{
    double a[3], b[3], n[3];
    d3_sub(a, e1, e0);
    d3_sub(b, w, e0);
    d3_cross(n, a, b);
    const double len = sqrt(d3_dot(n, n));
    if (!(len > 0.0)) return;
    for (int i = 0; i < 3; i++) n[i] /= len;
    const double d = -d3_dot(n, e0);
    double pmin = INFINITY, pmax = -INFINITY, tmin = INFINITY, tmax = -INFINITY;
    for (int i = 0; i < np; i++) {
        const double s = d3_dot(n, poly + 3 * i) + d;
        pmin = dmin(pmin, s);
        pmax = dmax(pmax, s);
    }
    for (int i = 0; i < nt; i++) {
        const double s = d3_dot(n, tv[i]) + d;
        tmin = dmin(tmin, s);
        tmax = dmax(tmax, s);
    }
    double sign;
    if (pmax <= tol && tmin >= -tol) sign = 1.0;
    else if (pmin >= -tol && tmax <= tol) sign = -1.0;
    else return;
    /* Everything on the plane: it separates nothing. */
    if (dmax(dmax(fabs(pmin), fabs(pmax)), dmax(fabs(tmin), fabs(tmax))) <= tol) return;
    if (v->n >= HPC_MAX_PLANES - 1) return;   /* one slot kept for the cap */
    float *p = v->pl[v->n++];
    for (int i = 0; i < 3; i++) p[i] = (float)(sign * n[i]);
    p[3] = (float)(sign * d);
}

int hpc_volume_build(hpc_volume *v, const double *poly, int np, const float tri[9], float eps)
{
    return hpc_volume_build_points(v, poly, np, tri, 3, eps);
}

/* Departure: the paper's blocker is a triangle; here it may be nt <= 4 points (hpc casts two triangles that
 * share an edge as one job, hpc_triangle.c), and the candidates span every pair of its points, so that the planes
 * separate the polygon from the points' convex hull whatever their order or shape. For a triangle the pairs
 * are its three edges, as before. */
int hpc_volume_build_points(hpc_volume *v, const double *poly, int np, const float *pts, int nt, float eps)
{
    memset(v, 0, sizeof *v);
    v->eps = eps;
    if (!isfinite(eps) || nt < 3 || nt > 4) { v->unbounded = 1; return 0; }
    double tv[4][3], size = 0.0;
    for (int i = 0; i < nt; i++)
        for (int a = 0; a < 3; a++) { tv[i][a] = pts[3 * i + a]; size = dmax(size, fabs(tv[i][a])); }
    for (int i = 0; i < 3 * np; i++) size = dmax(size, fabs(poly[i]));
    const double tol = 1e-9 * size;
    /* Blocker edge x polygon vertex (the outline's edges first, then the diagonals), polygon edge x blocker
     * vertex (every vertex-edge pair). */
    for (int e = 0; e < nt; e++)
        for (int i = 0; i < np; i++) try_plane(v, tv[e], tv[(e + 1) % nt], poly + 3 * i, poly, np, tv, nt, tol);
    for (int e = 0; e + 2 < nt; e++)
        for (int f = e + 2; f < nt && !(e == 0 && f == nt - 1); f++)
            for (int i = 0; i < np; i++) try_plane(v, tv[e], tv[f], poly + 3 * i, poly, np, tv, nt, tol);
    for (int e = 0; e < np; e++)
        for (int i = 0; i < nt; i++) try_plane(v, poly + 3 * e, poly + 3 * ((e + 1) % np), tv[i], poly, np, tv, nt, tol);
    /* The cap: the plane of the first three points, when the polygon lies strictly on one side of it; moved
     * towards the polygon by as much as a further point of the blocker lies on the polygon's side (a flat pair
     * rounded to float leaves its fourth point off the plane by ulps), so that every point of the blocker is on
     * the inner side: a shadowed point l + s (t - l), s >= 1, then lies at least as far inside as t. */
    double a[3], b[3], n[3];
    d3_sub(a, tv[1], tv[0]);
    d3_sub(b, tv[2], tv[0]);
    d3_cross(n, a, b);
    const double len = sqrt(d3_dot(n, n));
    if (len > 0.0) {
        for (int i = 0; i < 3; i++) n[i] /= len;
        const double d = -d3_dot(n, tv[0]);
        double pmin = INFINITY, pmax = -INFINITY;
        for (int i = 0; i < np; i++) {
            const double s = d3_dot(n, poly + 3 * i) + d;
            pmin = dmin(pmin, s);
            pmax = dmax(pmax, s);
        }
        const double sign = pmin > tol ? -1.0 : pmax < -tol ? 1.0 : 0.0;   /* inside: away from the polygon */
        double shift = 0.0;   /* how far a further point lies on the polygon's side */
        for (int i = 3; i < nt; i++) shift = dmax(shift, -sign * (d3_dot(n, tv[i]) + d));
        const double pnear = sign < 0.0 ? pmin : -pmax;   /* the polygon's nearest distance, on its side */
        if (sign != 0.0 && pnear - shift > tol) {
            float *p = v->pl[v->n++];
            for (int i = 0; i < 3; i++) p[i] = (float)(sign * n[i]);
            p[3] = (float)(sign * d + shift);
        }
    }
    if (v->n == 0) v->unbounded = 1;
    for (int i = 0; i < v->n; i++)
        for (int a = 0; a < 4; a++) v->soa[a][i] = v->pl[i][a];
    return v->n;
}

int hpc_volume_box(const hpc_volume *v, uint32_t act, const float lo[3], const float hi[3], uint32_t *out,
                   uint64_t *tests)
{
    act &= v->n >= 32 ? UINT32_MAX : (UINT32_C(1) << v->n) - 1u;
    uint32_t keep = act;
    while (act) {
        const int i = __builtin_ctz(act);
        act &= act - 1u;
        const float *p = v->pl[i];
        float mx = p[3], mn = p[3];
        for (int a = 0; a < 3; a++) {
            const float x = p[a] * lo[a], y = p[a] * hi[a];
            mx += x > y ? x : y;
            mn += x > y ? y : x;
        }
        ++*tests;
        if (mx < -v->eps) return 0;
        if (mn >= v->eps) keep &= ~(UINT32_C(1) << i);   /* wholly inside, with room for rounding */
    }
    *out = keep;
    return 1;
}

int hpc_volume_point(const hpc_volume *v, uint32_t act, const float p[3], uint64_t *tests)
{
    act &= v->n >= 32 ? UINT32_MAX : (UINT32_C(1) << v->n) - 1u;
    while (act) {
        const int i = __builtin_ctz(act);
        act &= act - 1u;
        const float *q = v->pl[i];
        ++*tests;
        if (q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3] < -v->eps) return 0;
    }
    return 1;
}
