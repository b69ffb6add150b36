/* Single-ray traversal of the BVH: closest hit (nearer child first) and any hit (stops at the first),
 * with the watertight triangle test and the box test widened to match it (ray_triangle.h). */
#include "bvh.h"
#include "ray_triangle.h"
#include "core/vec.h"
#include <math.h>

int ms_intersect_triangle(const float tri[9], const float o[3], const float d[3], float tmin, float tmax,
                          float *t, float *u, float *v)
{
    ms_wt_ray w;
    float n[3];
    ms_wt_prepare(&w, o, d);
    ms_wt_normal(tri, n);
    return ms_wt_intersect(&w, tri, n, tmin, tmax, t, u, v);
}

typedef struct ray_pre { float o_lo[3], o_hi[3], inv[3]; ms_wt_ray wt; } ray_pre;

static void ray_prepare(ray_pre *rp, const ms_bvh *b, const ms_ray *r)
{
    for (int a = 0; a < 3; a++) rp->inv[a] = 1.0f / r->d[a];   /* +-inf for axis-parallel rays; the slab test copes */
    ms_wt_prepare(&rp->wt, r->o, r->d);
    ms_wt_box_origins(b->nodes[0].bmin, b->nodes[0].bmax, r->o, rp->o_lo, rp->o_hi);
}

/* Slab test on the box widened to match the watertight triangle test (ms_wt_box_origins); returns
 * the entry distance or +inf when the box is missed within [tmin, tmax]. */
static inline float box_enter(const ms_bvh_node *n, const ray_pre *rp, float tmin, float tmax)
{
    float lo[3], hi[3];
    for (int a = 0; a < 3; a++) { lo[a] = n->bmin[a] - rp->o_lo[a]; hi[a] = n->bmax[a] - rp->o_hi[a]; }
    float t0 = tmin, t1 = tmax;
    for (int a = 0; a < 3; a++) {
        float x = lo[a] * rp->inv[a], y = hi[a] * rp->inv[a];
        /* NaN (0 * inf: origin on the slab plane of an axis-parallel ray) must not cull: treat as inside. */
        if (x > y) { float s = x; x = y; y = s; }
        t0 = x > t0 ? x : t0;
        t1 = y < t1 ? y : t1;
    }
    /* Exit widened by Ize's bound (ray_triangle.h) for the rounding of the slabs themselves. */
    return t0 <= t1 * MS_WT_FAR_SCALE ? t0 : INFINITY;
}

/* Closest hit; accept NULL or a filter of the hits. Inlined into both entry points, so that the unfiltered one
 * compiles to the traversal it always was (the filter test folds away). */
static inline __attribute__((always_inline)) int closest(const ms_bvh *b, const ms_ray *r, ms_ray_hit *hit,
                                                         ms_bvh_hit_filter accept, const void *user)
{
    ray_pre rp;
    ray_prepare(&rp, b, r);
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
                if (ms_wt_intersect(&rp.wt, b->tri + 9 * (size_t)i, b->tri_n + 3 * (size_t)i, r->tmin, best, &t, &u, &v) &&
                    (!accept || accept(user, i, r))) {
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

int ms_bvh_closest(const ms_bvh *b, const ms_ray *r, ms_ray_hit *hit) { return closest(b, r, hit, NULL, NULL); }

int ms_bvh_closest_filter(const ms_bvh *b, const ms_ray *r, ms_ray_hit *hit, ms_bvh_hit_filter accept, const void *user)
{
    return closest(b, r, hit, accept, user);
}

int ms_bvh_occluded(const ms_bvh *b, const ms_ray *r, uint32_t skip_prim)
{
    ray_pre rp;
    ray_prepare(&rp, b, r);
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
                    ms_wt_intersect(&rp.wt, b->tri + 9 * (size_t)i, b->tri_n + 3 * (size_t)i, r->tmin, r->tmax, &t, &u, &v))
                    return 1;
            }
        } else {
            stack[sp++] = n->first + 1;
            stack[sp++] = n->first;
        }
    }
    return 0;
}
