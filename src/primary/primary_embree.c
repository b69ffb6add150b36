/* Primary method "embree": camera rays as 16-ray packets over 4x4 pixel blocks through the Embree scene
 * the shadow method "embree" also uses (visibility/embree_scene.h). Alpha-tested triangles: the shared
 * context filter, for primary rays the ray's own line decides (alpha.h). */
#include "primary.h"
#include "visibility/embree_scene.h"
#include "accel/ray_triangle.h"
#include <math.h>

/* The hit parameter of ray (o, d) on the plane of tri, by the very operations of the watertight test
 * (ms_wt_hit_t: so bit for bit the t the BVH primary finds on that triangle), without its inside
 * test: Embree may report a triangle at an edge that our test would just miss. Embree's own t if the
 * triangle is edge-on. */
static float eb_plane_t(const float tri[9], const float n[3], const float o[3], const float d[3], float t_embree)
{
    ms_wt_ray w;
    ms_wt_eval e;
    ms_wt_prepare(&w, o, d);
    ms_wt_evaluate(&w, tri, &e);
    if (e.det == 0.0f) return t_embree;
    float t = ms_wt_hit_t(&w, tri, n, &e);
    return isfinite(t) && t > 0.0f ? t : t_embree;
}

static void eb_primary_trace(void *state, const ms_render_ctx *ctx, int x0, int y0, int x1, int y1, ms_hit *out)
{
    ms_embree_scene *s = state;
    const int tw = x1 - x0;
    unsigned mx = ms_embree_enter();
    /* Alpha-tested triangles: the context filter lets camera rays through their transparent texels. */
    ms_embree_ictx ec = { .skip = UINT32_MAX, .alpha = ctx->alpha, .primary = 1 };
    struct RTCIntersectContext *const icp = &ec.c;
    rtcInitIntersectContext(icp);
    icp->flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    if (ctx->alpha) icp->filter = ms_embree_context_filter;
    struct RTCRayHit16 rh __attribute__((aligned(64)));
    int valid[16] __attribute__((aligned(64)));
    int inside[16];   /* the pixel is in the tile (it may still have no ray: outside a fisheye's circle) */
    for (int by = y0; by < y1; by += 4)
        for (int bx = x0; bx < x1; bx += 4) {
            for (int l = 0; l < 16; l++) {
                int x = bx + (l & 3), y = by + (l >> 2);
                float o[3] = { ctx->cam.eye[0], ctx->cam.eye[1], ctx->cam.eye[2] }, d[3] = { 0.0f, 0.0f, 1.0f };
                inside[l] = x < x1 && y < y1;
                valid[l] = inside[l] ? -1 : 0;
                if (valid[l] && ms_camera_ray(&ctx->cam, x, y, o, d)) valid[l] = 0;
                rh.ray.org_x[l] = o[0]; rh.ray.org_y[l] = o[1]; rh.ray.org_z[l] = o[2];
                rh.ray.dir_x[l] = d[0]; rh.ray.dir_y[l] = d[1]; rh.ray.dir_z[l] = d[2];
                rh.ray.tnear[l] = 0.0f;
                rh.ray.tfar[l] = INFINITY;
                rh.ray.time[l] = 0.0f;
                rh.ray.mask[l] = 0xFFFFFFFFu;
                rh.ray.id[l] = (unsigned)l;
                rh.ray.flags[l] = 0;
                rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
                rh.hit.primID[l] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect16(valid, s->scene, icp, &rh);
            for (int l = 0; l < 16; l++) {
                if (!inside[l]) continue;
                int x = bx + (l & 3), y = by + (l >> 2);
                ms_hit *h = &out[(y - y0) * tw + (x - x0)];
                if (!valid[l] || rh.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID) { h->prim = UINT32_MAX; continue; }
                const float o[3] = { rh.ray.org_x[l], rh.ray.org_y[l], rh.ray.org_z[l] };
                const float d[3] = { rh.ray.dir_x[l], rh.ray.dir_y[l], rh.ray.dir_z[l] };
                uint32_t prim = rh.hit.primID[l];
                /* Embree decides which triangle is seen; the hit parameter on it is recomputed by the
                 * shared triangle test, so that a pixel that sees the same triangle gets the very same
                 * point C as with the BVH primary (Embree's t differs by up to tens of ulps). */
                ms_hit_finish(ctx, o, d, eb_plane_t(ctx->bvh->tri + 9 * (size_t)prim, ctx->bvh->tri_n + 3 * (size_t)prim, o, d, rh.ray.tfar[l]), prim, h);
            }
        }
    ms_embree_leave(mx);
}

const ms_primary_method ms_primary_embree = {
    .name = "embree",
    .create = ms_embree_scene_acquire,
    .trace = eb_primary_trace,
    .destroy = ms_embree_scene_release,
};
