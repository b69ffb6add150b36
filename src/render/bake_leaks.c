/* Texels inside geometry (microshadow/bake.h, "Lightmap baking"; docs/baking.md, "Quality").
 *
 * A texel's centre may land where another object stands on or cuts through the receiver (the floor under a
 * box's side, a wall running into another): evaluated there it is in full shadow, and bilinear filtering
 * carries that black out past the object's edge - a dark line along every contact, the leak bakers know.
 * As the established bakers do (Bakery's and Unity's "backface" test, Lightmass's texel validity), each
 * texel casts rays along its surface, in 8 directions of the receiver's tangent plane, as far as the
 * texel's own footprint reaches (0.75 of its world size, so every point its bilinear footprint may blend
 * is covered): when the nearest hit of a ray is the back of a triangle (the ray leaves a solid: for a closed
 * mesh the side its signed volume says is inside, whichever way its winding turns - the built-in scene's
 * boxes are wound inward; for an open surface the side its winding declares the back),
 * the texel's point is inside that object, and it is moved to the nearest such exit, just past the face
 * (1% of the texel's size along the face's normal). The texel keeps its triangle as receiver; the point
 * stays in its plane (the rays run in it, started a hair above it so that coplanar neighbours are never
 * hit). A texel no ray leads out of within its footprint lies deep inside and is left alone: no lookup
 * on a visible surface reaches it. */
#include "bake_leaks.h"
#include "accel/bvh.h"
#include "accel/closed.h"
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* World length of one texel on each triangle (isotropic: the square root of the area ratio). */
static float texel_world_size(const float *t, const float *u, int width, int height)
{
    const double e1[3] = { t[3] - t[0], t[4] - t[1], t[5] - t[2] }, e2[3] = { t[6] - t[0], t[7] - t[1], t[8] - t[2] };
    const double c[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
    const double wa = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    const double ua = fabs(((double)u[2] - u[0]) * ((double)u[5] - u[1]) - ((double)u[3] - u[1]) * ((double)u[4] - u[0])) * width * height;
    return ua > 0.0 ? (float)sqrt(wa / ua) : 0.0f;
}

int ms_bake_fix_leaks(const ms_scene *sc, int size, int height, const float *uv, const uint32_t *texel_tri, float *position,
                      const float *normal, int threads, size_t *moved, char *err, size_t errlen)
{
    *moved = 0;
    if (!sc->n_tris) return 0;
    ms_bvh bvh;
    if (ms_bvh_build(&bvh, sc->tri, sc->n_tris, threads)) { snprintf(err, errlen, "out of memory for the texels' BVH"); return -1; }
    /* Which side of a face is out: a closed component's own orientation (its signed volume), whatever way its
     * winding turns; an open surface's winding, as the asset declares its front. */
    ms_closed closed;
    if (ms_closed_find(sc->tri, sc->n_tris, &closed)) {
        ms_bvh_free(&bvh);
        snprintf(err, errlen, "out of memory for the texels' leak test");
        return -1;
    }
    const size_t np = (size_t)size * height;
    size_t count = 0;
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads > 0 ? threads : omp_get_num_procs()) reduction(+ : count)
    for (size_t i = 0; i < np; i++) {
        const uint32_t t = texel_tri[i];
        if (t == MS_NO_TRIANGLE) continue;
        /* a receiver wound into its own solid faces the inside: nothing there to move it out to */
        if (closed.component[t] != MS_OPEN_COMPONENT && closed.outward[closed.component[t]] < 0) continue;
        const float r = 0.75f * texel_world_size(sc->tri + 9 * t, uv + 6 * t, size, height);
        if (!(r > 0.0f) || !isfinite(r)) continue;
        const float *p = position + 3 * i, *n = normal + 3 * i;
        /* a tangent frame of the receiver */
        float a[3] = { 0, 0, 0 }, tu[3], tv[3];
        a[fabsf(n[0]) < 0.57f ? 0 : fabsf(n[1]) < 0.57f ? 1 : 2] = 1.0f;
        tu[0] = n[1] * a[2] - n[2] * a[1];
        tu[1] = n[2] * a[0] - n[0] * a[2];
        tu[2] = n[0] * a[1] - n[1] * a[0];
        const float lu = sqrtf(tu[0] * tu[0] + tu[1] * tu[1] + tu[2] * tu[2]);
        for (int d = 0; d < 3; d++) tu[d] /= lu;
        tv[0] = n[1] * tu[2] - n[2] * tu[1];
        tv[1] = n[2] * tu[0] - n[0] * tu[2];
        tv[2] = n[0] * tu[1] - n[1] * tu[0];
        /* a hair above the plane: coplanar triangles (the receiver's neighbours) are never hit, and rounding
         * does not put the origin behind the receiver */
        const float lift = 1e-3f * r;
        ms_ray ray;
        for (int d = 0; d < 3; d++) ray.o[d] = p[d] + lift * n[d];
        float best = INFINITY, to[3] = { 0, 0, 0 };
        for (int k = 0; k < 8; k++) {
            const float ang = (float)k * (float)(M_PI / 4.0), cs = cosf(ang), sn = sinf(ang);
            for (int d = 0; d < 3; d++) ray.d[d] = cs * tu[d] + sn * tv[d];
            ray.tmin = 0.0f;
            ray.tmax = r;
            ms_ray_hit h;
            if (!ms_bvh_closest(&bvh, &ray, &h) || h.t >= best) continue;
            const float *q = bvh.tri + 9 * (size_t)h.prim;
            const float e1[3] = { q[3] - q[0], q[4] - q[1], q[5] - q[2] }, e2[3] = { q[6] - q[0], q[7] - q[1], q[8] - q[2] };
            float nh[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
            const float ln = sqrtf(nh[0] * nh[0] + nh[1] * nh[1] + nh[2] * nh[2]);
            if (!(ln > 0.0f)) continue;
            const uint32_t src = bvh.tri_source[h.prim], comp = closed.component[src];
            const float out = comp == MS_OPEN_COMPONENT ? 1.0f : (float)closed.outward[comp];
            for (int d = 0; d < 3; d++) nh[d] *= out / ln;
            const float facing = nh[0] * ray.d[0] + nh[1] * ray.d[1] + nh[2] * ray.d[2];
            if (facing <= 0.0f) continue;   /* the front of a face: the texel is outside it */
            best = h.t;
            /* just past the face, pushed along its normal (out of the object), kept above the receiver */
            for (int d = 0; d < 3; d++) to[d] = ray.o[d] + h.t * ray.d[d] + 0.01f * r * nh[d];
        }
        if (best < INFINITY) {
            /* back into the receiver's plane, the lift kept: the push may have a component along n */
            const float off = (to[0] - p[0]) * n[0] + (to[1] - p[1]) * n[1] + (to[2] - p[2]) * n[2];
            for (int d = 0; d < 3; d++) position[3 * i + d] = to[d] - (off - lift) * n[d];
            count++;
        }
    }
    ms_bvh_free(&bvh);
    ms_closed_free(&closed);
    *moved = count;
    return 0;
}
