/* The scene's local frame (docs/design.md, "The scene's frame"). A loaded scene keeps its positions - the
 * triangles, the camera's eye and target, the lights' corners and centres - relative to an origin chosen
 * from the geometry's bounds, subtracted in double before anything is rounded to float; ms_scene.origin
 * says where it is (world = local + origin). Every method then works on coordinates of the size of the
 * scene, not of its distance from the world's origin: a float has the same absolute precision, and every
 * conservative bound derived from the coordinates (ray_triangle.h, the traversals) stays as tight, 100 km
 * out as at home. This file is the only place that chooses or applies it. */
#include "scene_internal.h"
#include <math.h>

/* The origin: per axis, the centre c of the bounds rounded to a multiple of s, the smallest power of two
 * not below the half-extent e (the largest over the axes); zero on an axis where |c| <= s, i.e. where the
 * scene already lies about the origin (centring would win at most two bits, and every scene that does not
 * lie far out keeps its floats bit for bit). Then every local coordinate is below 4e in magnitude
 * (|x| <= |c| + e <= 2s, or |x - o| <= e + s/2), whatever the distance. A multiple of a power of two
 * >= the spacing of the floats near the scene makes world -> local exact for float positions near the
 * geometry (ms_visibility_points) and local -> world exact in double. */
void ms_scene_frame_origin(const double *tri_d, size_t n, double origin[3])
{
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (size_t i = 0; i < 9 * n; i++) {
        lo[i % 3] = fmin(lo[i % 3], tri_d[i]);
        hi[i % 3] = fmax(hi[i % 3], tri_d[i]);
    }
    origin[0] = origin[1] = origin[2] = 0.0;
    double e = 0.0;
    for (int a = 0; a < 3; a++) e = fmax(e, 0.5 * (hi[a] - lo[a]));
    if (!(e > 0.0) || !isfinite(e)) return;   /* no triangles, or all on one point: nothing to centre */
    int ex;
    frexp(e, &ex);                                   /* e in [2^(ex-1), 2^ex) */
    const double s = ldexp(1.0, ex - 1) == e ? e : ldexp(1.0, ex);
    for (int a = 0; a < 3; a++) {
        const double c = 0.5 * (lo[a] + hi[a]);
        if (fabs(c) > s) origin[a] = s * nearbyint(c / s);
    }
}

void ms_scene_frame_apply(float *tri, const double *tri_d, size_t n, const double origin[3])
{
    if (origin[0] == 0.0 && origin[1] == 0.0 && origin[2] == 0.0) return;   /* tri as loaded */
    for (size_t i = 0; i < 9 * n; i++) tri[i] = (float)(tri_d[i] - origin[i % 3]);
}

void ms_scene_frame_point(const double p[3], const double origin[3], float out[3])
{
    for (int a = 0; a < 3; a++) out[a] = (float)(p[a] - origin[a]);
}
