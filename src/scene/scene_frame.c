/* The scene's local frame (docs/design.md, "The scene's frame"). A loaded scene keeps its positions - the
 * triangles, the camera's eye and target, the lights' corners and centres - relative to an origin chosen
 * from the geometry's bounds, subtracted in double before anything is rounded to float; ms_scene.origin
 * says where it is (world = local + origin). Every method then works on coordinates of the size of the
 * scene, not of its distance from the world's origin: a float has the same absolute precision, and every
 * conservative bound derived from the coordinates (ray_triangle.h, the traversals) stays as tight, 100 km
 * out as at home. This file is the only place that chooses or applies it. */
#include "microshadow.h"
#include "scene_internal.h"
#include <math.h>
#include <stdlib.h>

/* The origin: per axis, the centre c of the bounds rounded to a multiple of s, the smallest power of two
 * not below the half-extent e (the largest over the axes); zero on an axis where |c| <= 2 s, i.e. where
 * the scene lies within 2 of its sizes of the origin: there centring would win at most 2 bits, while a
 * scene placed about the origin keeps its world coordinates (and its floats bit for bit). Beyond that the
 * scene is centred, so that the bounds derived from coordinates (ray_triangle.h; hpc's slacks and culling
 * margins, the most sensitive: they grow with the largest coordinate, and a scene left 10 of its sizes out
 * gets margins 10 times its own) stay those of a scene at home. Every local coordinate is below 6e in magnitude
 * (|x| <= |c| + e <= 3s, or |x - o| <= e + s/2), whatever the distance. A multiple of a power of two >= the
 * spacing of the floats near the scene makes world -> local exact for float positions near the geometry
 * (ms_visibility_points) and local -> world exact in double. */
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
        if (fabs(c) > 2.0 * s) origin[a] = s * nearbyint(c / s);
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

/* ms_scene_localize: the same frame for a scene built in world floats (microshadow.h). */
static void shift3(ms_vec3 *v, const double d[3])
{
    v->x = (float)((double)v->x + d[0]);
    v->y = (float)((double)v->y + d[1]);
    v->z = (float)((double)v->z + d[2]);
}

ms_status ms_scene_localize(ms_scene *s)
{
    if (!s || !s->tri || !s->n_tris) return MS_OK;   /* procedural scenes are generated about the origin */
    const size_t n = 9 * s->n_tris;
    double *w = malloc(n * sizeof *w);
    if (!w) return MS_ERR_NO_MEMORY;
    for (size_t i = 0; i < n; i++) w[i] = (double)s->tri[i] + s->origin[i % 3];
    double o[3];
    ms_scene_frame_origin(w, s->n_tris, o);
    const double d[3] = { s->origin[0] - o[0], s->origin[1] - o[1], s->origin[2] - o[2] };
    if (d[0] != 0.0 || d[1] != 0.0 || d[2] != 0.0) {
        /* exact for the triangles: a float minus a multiple of a power of two above its spacing */
        for (size_t i = 0; i < n; i++) s->tri[i] = (float)(w[i] - o[i % 3]);
        shift3(&s->camera.eye, d);
        shift3(&s->camera.target, d);
        ms_light *l = s->n_lights && s->lights ? s->lights : &s->light;
        const size_t nl = s->n_lights && s->lights ? s->n_lights : 1;
        for (size_t i = 0; i < nl; i++) {
            if (l[i].shape != MS_LIGHT_SUN) shift3(&l[i].corner, d);   /* a sun's square is a direction's */
            if (l[i].shape == MS_LIGHT_SPHERE) shift3(&l[i].center, d);
        }
        if (s->n_lights && s->lights) s->light = s->lights[0];
        for (int a = 0; a < 3; a++) s->origin[a] = o[a];
    }
    free(w);
    return MS_OK;
}
