/* Primary method "bvh": camera rays through our BVH, with the watertight ray/triangle test
 * (ray_triangle.h), or with ctx->consistent_primary the 3D edge-function test of the 3D rasterizers
 * (edge3d.h: Dachsbacher et al.'s transfer of rasterization consistency to ray casting): the closest hit,
 * ties in t to the smaller triangle id, so it agrees with every "3dr-*" primary bit for bit. */
#include "primary.h"
#include "visibility/alpha.h"
#include "edge3d.h"
#include "accel/ray_triangle.h"
#include "core/vec.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct bvh_primary_state {
    ms_e3_cam cam;
    uint64_t S, E, N;    /* summed by the tiles (atomically) */
} bvh_primary_state;

static int bvh_primary_create(const ms_render_ctx *ctx, void **state, char *err, size_t errlen)
{
    (void)err; (void)errlen;
    bvh_primary_state *s = calloc(1, sizeof *s);
    if (!s) { snprintf(err, errlen, "out of memory"); return -1; }
    ms_e3_cam_init(&s->cam, &ctx->cam);
    *state = s;
    return 0;
}

/* The consistent closest hit: a stack traversal with the watertight test's conservative boxes (their
 * margin, ms_wt_box_origins, is far above the double rounding of the edge functions), leaves decided by
 * ms_e3_hit; a node is skipped only when its box starts beyond the best t, so an equal t of a smaller id
 * is still found. Triangles are set up per ray (S counts them). */
static uint32_t consistent_closest(const bvh_primary_state *s, const ms_bvh *b, const ms_alpha *a, const float o[3],
                                   const float d[3], float *tbest, uint64_t c[3])
{
    const float *q = ms_e3_q(&s->cam, o, d);
    float olo[3], ohi[3], inv[3];
    ms_wt_box_origins(b->nodes[0].bmin, b->nodes[0].bmax, o, olo, ohi);
    for (int a = 0; a < 3; a++) inv[a] = 1.0f / d[a];
    uint32_t best = UINT32_MAX, stack[MS_BVH_STACK];
    float bt = INFINITY;
    int sp = 0;
    stack[sp++] = 0;
    while (sp) {
        const ms_bvh_node *n = &b->nodes[stack[--sp]];
        c[2]++;
        float tn = 0.0f, tf = INFINITY;
        for (int a = 0; a < 3; a++) {
            float lo = (n->bmin[a] - olo[a]) * inv[a], hi = (n->bmax[a] - ohi[a]) * inv[a];
            if (inv[a] < 0.0f) { lo = (n->bmax[a] - ohi[a]) * inv[a]; hi = (n->bmin[a] - olo[a]) * inv[a]; }
            if (lo != lo) lo = -INFINITY;   /* 0 * inf: the ray lies in the slab's plane */
            if (hi != hi) hi = INFINITY;
            tn = lo > tn ? lo : tn;
            tf = hi < tf ? hi : tf;
        }
        if (!(tn <= tf * MS_WT_FAR_SCALE) || tn > bt) continue;
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                ms_e3_tri T;
                ms_e3_setup(&s->cam, b->tri + 9 * (size_t)i, &T);
                c[0]++;
                c[1] += 3;
                float t;
                if (!ms_e3_hit(&T, o, d, q, &t)) continue;
                if (t > bt || (t == bt && i > best)) continue;
                if (!ms_e3_accept(a, i, o, d)) continue;   /* a cut-out's hole: the ray goes on */
                bt = t;
                best = i;
            }
            continue;
        }
        if (sp + 2 > MS_BVH_STACK) continue;   /* cannot happen: the build caps the depth */
        stack[sp++] = n->first + 1;
        stack[sp++] = n->first;
    }
    *tbest = bt;
    return best;
}

static void bvh_primary_trace(void *state, const ms_render_ctx *ctx, int x0, int y0, int x1, int y1,
                              ms_hit *out)
{
    bvh_primary_state *s = state;
    uint64_t c[3] = { 0, 0, 0 };
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            ms_ray r;
            ms_ray_hit hit;
            ms_hit *h = out++;
            if (ms_camera_ray(&ctx->cam, x, y, r.o, r.d)) { h->prim = UINT32_MAX; continue; }
            if (ctx->consistent_primary) {
                float t;
                const uint32_t p = consistent_closest(s, ctx->bvh, ctx->alpha, r.o, r.d, &t, c);
                if (p != UINT32_MAX) ms_hit_finish(ctx, r.o, r.d, t, p, h);
                else h->prim = UINT32_MAX;
                continue;
            }
            r.tmin = 0.0f;
            r.tmax = INFINITY;
            /* Alpha-tested triangles: only where opaque (alpha.h), so a ray goes on through a cut-out's holes. */
            const int found = ctx->alpha ? ms_bvh_closest_filter(ctx->bvh, &r, &hit, ms_alpha_ray_filter, ctx->alpha)
                                         : ms_bvh_closest(ctx->bvh, &r, &hit);
            if (found) ms_hit_finish(ctx, r.o, r.d, hit.t, hit.prim, h);
            else h->prim = UINT32_MAX;
        }
    if (ctx->consistent_primary) {
#pragma omp atomic
        s->S += c[0];
#pragma omp atomic
        s->E += c[1];
#pragma omp atomic
        s->N += c[2];
    }
}

static void bvh_primary_destroy(void *state) { free(state); }

static void bvh_primary_counters(const void *state, uint64_t c[3])
{
    const bvh_primary_state *s = state;
    c[0] = s->S; c[1] = s->E; c[2] = s->N;
}

const ms_primary_method ms_primary_bvh = {
    .name = "bvh",
    .create = bvh_primary_create,
    .trace = bvh_primary_trace,
    .destroy = bvh_primary_destroy,
    .counters = bvh_primary_counters,
};
