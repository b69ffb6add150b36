/* Primary method "bvh": camera rays through our BVH; and the hit finishing every primary method shares. */
#include "method.h"
#include "alpha.h"
#include "../core/vec.h"
#include <math.h>

void ms_hit_finish(const ms_render_ctx *ctx, const float o[3], const float d[3], float t, uint32_t prim,
                   ms_hit *h)
{
    const float *tri = ctx->bvh->tri + 9 * (size_t)prim;
    float e1[3], e2[3], n[3];
    v3_sub(e1, tri + 3, tri);
    v3_sub(e2, tri + 6, tri);
    v3_cross(n, e1, e2);
    v3_normalize(n, n);
    if (v3_dot(n, d) > 0.0f) v3_scale(n, n, -1.0f);
    /* Not lifted off the surface: rounding may leave p on either side of its triangle's plane, and V does
     * not depend on which (segments to samples behind the plane are not drawn; occluders closer than the
     * near parameter are ignored). */
    v3_madd(h->p, o, d, t);
    h->n[0] = n[0]; h->n[1] = n[1]; h->n[2] = n[2];
    h->prim = prim;
}

static int bvh_primary_create(const ms_render_ctx *ctx, void **state, char *err, size_t errlen)
{
    (void)ctx; (void)err; (void)errlen;
    *state = NULL;
    return 0;
}

static void bvh_primary_trace(void *state, const ms_render_ctx *ctx, int x0, int y0, int x1, int y1,
                              ms_hit *out)
{
    (void)state;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            ms_ray r;
            ms_ray_hit hit;
            ms_hit *h = out++;
            if (ms_camera_ray(&ctx->cam, x, y, r.o, r.d)) { h->prim = UINT32_MAX; continue; }
            r.tmin = 0.0f;
            r.tmax = INFINITY;
            /* Alpha-tested triangles: only where opaque (alpha.h), so a ray goes on through a cut-out's holes. */
            const int found = ctx->alpha ? ms_bvh_closest_filter(ctx->bvh, &r, &hit, ms_alpha_ray_filter, ctx->alpha)
                                         : ms_bvh_closest(ctx->bvh, &r, &hit);
            if (found) ms_hit_finish(ctx, r.o, r.d, hit.t, hit.prim, h);
            else h->prim = UINT32_MAX;
        }
}

static void bvh_primary_destroy(void *state) { (void)state; }

const ms_primary_method ms_primary_bvh = {
    .name = "bvh",
    .create = bvh_primary_create,
    .trace = bvh_primary_trace,
    .destroy = bvh_primary_destroy,
};
