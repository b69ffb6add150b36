/* hpc_t_sure: where the sure lanes (footprint_sure_lanes, hpc_footprint_impl.h) need not even test the exact test's
 * t range. Compiled once (hpc_engine.h). */
#include "hpc_engine.h"
#include <math.h>

/* Whether every segment from a receiver in the box pc +- h to a sample of the light meets triangle t's plane well
 * inside the exact test's range, so that wherever the exact test's edge functions surely pass
 * (footprint_sure_lanes) it reports a hit, whatever its shear axis, without its t range's operations. With
 * alpha = N . p, xi = N . x (x the sample) and gamma = N . v (v any vertex: N, ms_wt_normal's, is not exactly
 * normal to the third edge), the exact test's t is (gamma - alpha) / (xi - alpha) up to its rounding: the plane
 * offset num = (v - p) . N from a vertex rounded relative to p (at most 5 u M |N|_1, M >= |v - p|inf) and d . N
 * from the direction formed in float (at most 3 u S |N|_1 for the product and 4 u S |N|_1 for d itself, S >=
 * |p0| + |p| bounds every partial sum, the grid's points lying on the light). So when the ranges of alpha over
 * the box, gamma over the vertices and xi over the light's polygon (the samples' cells, pattern.h) are
 * separated in that order (or its reverse), with gamma - alpha >= 2 near D + E and xi - gamma >= 2 (1 - far) D +
 * E, D >= |xi - alpha|, E = 16 u (M + S) |N|_1 above all those errors, the computed test lies in [near, far]
 * for every lane: ms_wt_rays16's plane-distance form, and the scalar form's division clamped to the vertices'
 * depths (ms_wt_hit_t: the exact hit lies within them, the clamp moves t by rounding only). In double. */
/* fmin and fmax are library calls without -ffast-math (as hpc_volume.c notes); the values here are finite. */
static inline double tmin_d(double a, double b) { return a < b ? a : b; }
static inline double tmax_d(double a, double b) { return a > b ? a : b; }

int hpc_t_sure(const shared *sh, const float pc[3], const float h[3], const tri_job *t)
{
    const float *N = t->N;
    double n1 = 0.0, a0 = 0.0, ah = 0.0, hmax = 0.0, pmax = 0.0, lmax = 0.0, M = 0.0;
    for (int a = 0; a < 3; a++) {
        n1 += fabs((double)N[a]);
        a0 += (double)N[a] * pc[a];
        ah += fabs((double)N[a]) * h[a];
        hmax = tmax_d(hmax, h[a]);
        pmax = tmax_d(pmax, fabs((double)pc[a]));
    }
    double gl = INFINITY, gh = -INFINITY, xl = INFINITY, xh = -INFINITY;
    for (int v = 0; v < 3; v++) {
        double gv = 0.0, mv = 0.0;
        for (int a = 0; a < 3; a++) {
            gv += (double)N[a] * t->v[3 * v + a];
            mv = tmax_d(mv, fabs((double)t->v[3 * v + a] - pc[a]));
        }
        gl = tmin_d(gl, gv);
        gh = tmax_d(gh, gv);
        M = tmax_d(M, mv + hmax);
    }
    for (int v = 0; v < 4; v++) {
        double xv = 0.0;
        for (int a = 0; a < 3; a++) {
            xv += (double)N[a] * sh->light_poly[3 * v + a];
            lmax = tmax_d(lmax, fabs(sh->light_poly[3 * v + a]));
        }
        xl = tmin_d(xl, xv);
        xh = tmax_d(xh, xv);
    }
    const double S = 2.0 * (lmax + pmax + hmax), E = 1.01 * 16.0 * 0x1p-24 * (M + S) * n1;
    const double al = a0 - ah, au = a0 + ah;
    const double D = tmax_d(xh, au) - tmin_d(xl, al);
    const double nearm = 2.0 * (double)sh->ctx->near * D + E, farm = 2.0 * (1.0 - (double)sh->ctx->far) * D + E;
    if (au < gl && gh < xl) return gl - au >= nearm && xl - gh >= farm;   /* receivers, plane, light in order */
    if (xh < gl && gh < al) return al - gh >= nearm && gl - xh >= farm;   /* and in reverse */
    return 0;
}
