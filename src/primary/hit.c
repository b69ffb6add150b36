/* The hit finishing every primary method shares, so that all agree on the receiver (primary.h). */
#include "primary.h"
#include "core/vec.h"

void ms_hit_finish(const ms_render_ctx *ctx, const float o[3], const float d[3], float t, uint32_t prim,
                   ms_hit *h)
{
    ms_hit_finish_tri(ctx->bvh->tri + 9 * (size_t)prim, o, d, t, prim, h);
}

void ms_hit_finish_tri(const float *tri, const float o[3], const float d[3], float t, uint32_t prim, ms_hit *h)
{
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
