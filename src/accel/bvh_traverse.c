/* Single-ray traversal of the BVH: closest hit (nearer child first) and any hit (stops at the first). */
#include "bvh.h"
#include "../core/vec.h"
#include <math.h>

int ms_intersect_triangle(const float tri[9], const float o[3], const float d[3], float tmin, float tmax,
                          float *t, float *u, float *v)
{
    float e1[3], e2[3], p[3], s[3], q[3];
    v3_sub(e1, tri + 3, tri);
    v3_sub(e2, tri + 6, tri);
    if (ms_triangle_degenerate(e1, e2)) return 0;
    v3_cross(p, d, e2);
    float det = v3_dot(e1, p);
    if (det == 0.0f) return 0;            /* ray parallel to the plane: two-sided, no culling */
    float inv = 1.0f / det;
    v3_sub(s, o, tri);
    float uu = v3_dot(s, p) * inv;
    if (!(uu >= 0.0f && uu <= 1.0f)) return 0;
    v3_cross(q, s, e1);
    float vv = v3_dot(d, q) * inv;
    if (!(vv >= 0.0f && uu + vv <= 1.0f)) return 0;
    float tt = v3_dot(e2, q) * inv;
    if (!(tt >= tmin && tt <= tmax)) return 0;
    *t = tt; *u = uu; *v = vv;
    return 1;
}

typedef struct ray_pre { float o[3], inv[3]; } ray_pre;

static void ray_prepare(ray_pre *rp, const ms_ray *r)
{
    for (int a = 0; a < 3; a++) {
        rp->o[a] = r->o[a];
        rp->inv[a] = 1.0f / r->d[a];     /* +-inf for axis-parallel rays; the slab test copes */
    }
}

/* Slab test; returns the entry distance or +inf when the box is missed within [tmin, tmax]. */
static inline float box_enter(const ms_bvh_node *n, const ray_pre *rp, float tmin, float tmax)
{
    float t0 = tmin, t1 = tmax;
    for (int a = 0; a < 3; a++) {
        float lo = (n->bmin[a] - rp->o[a]) * rp->inv[a];
        float hi = (n->bmax[a] - rp->o[a]) * rp->inv[a];
        /* NaN (0 * inf: origin on the slab plane of an axis-parallel ray) must not cull: treat as inside. */
        if (lo > hi) { float x = lo; lo = hi; hi = x; }
        t0 = lo > t0 ? lo : t0;
        t1 = hi < t1 ? hi : t1;
    }
    /* Conservative: the exit distance is widened by 2*gamma(3) (Ize, "Robust BVH ray traversal", 2013)
     * so that rounding in the slabs never culls a box that a ray through a vertex or along an edge of
     * one of its triangles really touches, where ms_intersect_triangle reports a hit. */
    return t0 <= t1 * (1.0f + 2.0f * 3.5762786e-07f) ? t0 : INFINITY;
}

int ms_bvh_closest(const ms_bvh *b, const ms_ray *r, ms_ray_hit *hit)
{
    ray_pre rp;
    ray_prepare(&rp, r);
    float best = r->tmax;
    hit->prim = UINT32_MAX;
    hit->t = INFINITY;
    uint32_t stack[MS_BVH_STACK];
    int sp = 0;
    if (box_enter(&b->nodes[0], &rp, r->tmin, best) == INFINITY) return 0;
    uint32_t ni = 0;
    for (;;) {
        const ms_bvh_node *n = &b->nodes[ni];
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                float t, u, v;
                if (ms_intersect_triangle(b->tri + 9 * (size_t)i, r->o, r->d, r->tmin, best, &t, &u, &v)) {
                    best = t; hit->t = t; hit->u = u; hit->v = v; hit->prim = i;
                }
            }
        } else {
            uint32_t l = n->first, rr = l + 1;
            float tl = box_enter(&b->nodes[l], &rp, r->tmin, best);
            float tr = box_enter(&b->nodes[rr], &rp, r->tmin, best);
            if (tl != INFINITY && tr != INFINITY) {
                if (tr < tl) { uint32_t x = l; l = rr; rr = x; }
                stack[sp++] = rr;
                ni = l;
                continue;
            }
            if (tl != INFINITY) { ni = l; continue; }
            if (tr != INFINITY) { ni = rr; continue; }
        }
        /* Pop, skipping nodes that the current best hit has made too far. */
        for (;;) {
            if (sp == 0) return hit->prim != UINT32_MAX;
            ni = stack[--sp];
            if (box_enter(&b->nodes[ni], &rp, r->tmin, best) != INFINITY) break;
        }
    }
}

int ms_bvh_occluded(const ms_bvh *b, const ms_ray *r, uint32_t skip_prim)
{
    ray_pre rp;
    ray_prepare(&rp, r);
    uint32_t stack[MS_BVH_STACK];
    int sp = 0;
    stack[sp++] = 0;
    while (sp) {
        const ms_bvh_node *n = &b->nodes[stack[--sp]];
        if (box_enter(n, &rp, r->tmin, r->tmax) == INFINITY) continue;
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                float t, u, v;
                if (i != skip_prim &&
                    ms_intersect_triangle(b->tri + 9 * (size_t)i, r->o, r->d, r->tmin, r->tmax, &t, &u, &v))
                    return 1;
            }
        } else {
            stack[sp++] = n->first + 1;
            stack[sp++] = n->first;
        }
    }
    return 0;
}
