/* Method "raytrace": the reference. One any-hit shadow segment per light sample in front of the
 * receiver's plane through our BVH, from the hit point to the sample, occluding for parameters in [near, far] and never by
 * the hit triangle. The k*k rays of a pixel share their origin and point at one small light, so they
 * are traced as 16-ray packets: a node is visited when any live ray of the packet enters it, and each
 * triangle is tested against the packet's rays that are still unoccluded. The lane loops are plain C
 * that the compiler vectorises (AVX-512 in -march=native builds, SSE2 otherwise). */
#include "method.h"
#include "../core/pattern.h"
#include "../core/vec.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LANES 16

enum { C_PACKETS, C_NODE_VISITS, C_TRI_TESTS };

typedef struct packet {
    float o[3];
    float d[3][LANES], inv[3][LANES];
    float tmin, tmax;
    int live[LANES];        /* 1 while the ray is unoccluded */
} packet;

static int any_live(const int *live)
{
    int a = 0;
    for (int l = 0; l < LANES; l++) a |= live[l];
    return a;
}

/* 1 if any live ray of the packet enters the node within [tmin, tmax]. */
static int packet_enters(const packet *pk, const ms_bvh_node *n)
{
    float lo[3], hi[3];
    for (int a = 0; a < 3; a++) { lo[a] = n->bmin[a] - pk->o[a]; hi[a] = n->bmax[a] - pk->o[a]; }
    int hit = 0;
    for (int l = 0; l < LANES; l++) {
        float t0 = pk->tmin, t1 = pk->tmax;
        for (int a = 0; a < 3; a++) {
            float x = lo[a] * pk->inv[a][l], y = hi[a] * pk->inv[a][l];
            /* Plain compares (fminf/fmaxf are calls without -ffast-math); a NaN from 0*inf, the origin
             * on a slab plane of an axis-parallel ray, leaves t0/t1 unchanged. */
            float mn = x < y ? x : y, mx = x < y ? y : x;
            t0 = mn > t0 ? mn : t0;
            t1 = mx < t1 ? mx : t1;
        }
        /* Exit widened by 2*gamma(3) as in ms_bvh_occluded: rounding never culls a box that a ray
         * through a vertex or along an edge really touches. */
        hit |= (t0 <= t1 * (1.0f + 2.0f * 3.5762786e-07f)) & pk->live[l];
    }
    return hit;
}

/* Moller-Trumbore against every live lane; clears the lanes the triangle blocks. */
static void packet_triangle(packet *pk, const float *tri)
{
    float e1[3], e2[3], s[3], q[3];
    v3_sub(e1, tri + 3, tri);
    v3_sub(e2, tri + 6, tri);
    if (ms_triangle_degenerate(e1, e2)) return;
    v3_sub(s, pk->o, tri);
    v3_cross(q, s, e1);            /* shared by all lanes: the origin is common */
    float sq = v3_dot(e2, q);
    for (int l = 0; l < LANES; l++) {
        float d0 = pk->d[0][l], d1 = pk->d[1][l], d2 = pk->d[2][l];
        float p0 = d1 * e2[2] - d2 * e2[1], p1 = d2 * e2[0] - d0 * e2[2], p2 = d0 * e2[1] - d1 * e2[0];
        float det = e1[0] * p0 + e1[1] * p1 + e1[2] * p2;
        float inv = 1.0f / det;
        float u = (s[0] * p0 + s[1] * p1 + s[2] * p2) * inv;
        float v = (d0 * q[0] + d1 * q[1] + d2 * q[2]) * inv;
        float t = sq * inv;
        int hit = (det != 0.0f) & (u >= 0.0f) & (u <= 1.0f) & (v >= 0.0f) & (u + v <= 1.0f) &
                  (t >= pk->tmin) & (t <= pk->tmax);
        pk->live[l] &= !hit;
    }
}

static void trace_packet(const ms_bvh *b, packet *pk, uint32_t skip, uint64_t *cnt)
{
    uint32_t stack[MS_BVH_STACK];
    int sp = 0;
    stack[sp++] = 0;
    cnt[C_PACKETS]++;
    while (sp) {
        const ms_bvh_node *n = &b->nodes[stack[--sp]];
        cnt[C_NODE_VISITS]++;
        if (!packet_enters(pk, n)) continue;
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                if (i == skip) continue;
                cnt[C_TRI_TESTS]++;
                packet_triangle(pk, b->tri + 9 * (size_t)i);
            }
            if (!any_live(pk->live)) return;
        } else {
            stack[sp++] = n->first + 1;
            stack[sp++] = n->first;
        }
    }
}

static int rt_create(const ms_render_ctx *ctx, void **state, char *err, size_t errlen)
{
    (void)ctx; (void)err; (void)errlen;
    *state = NULL;
    return 0;
}

int ms_raytrace_visible_samples(const ms_render_ctx *ctx, const ms_shadow_query *q, float *pts,
                                const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    const int ns = ctx->samples;
    ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, q->px, q->py, ctx->seed, pts);
    memset(vis, 0, (size_t)ctx->mask_words * sizeof *vis);
    int visible = 0;
    for (int base = 0; base < ns; base += LANES) {
        /* Samples behind the receiver's plane are not traced (LANES divides 64: one word holds them). */
        const uint64_t lanes = front[base >> 6] >> (base & 63) & ((UINT64_C(1) << LANES) - 1);
        if (!lanes) continue;
        packet pk;
        for (int a = 0; a < 3; a++) pk.o[a] = q->p[a];
        pk.tmin = ctx->near;
        pk.tmax = ctx->far;
        for (int l = 0; l < LANES; l++) {
            for (int a = 0; a < 3; a++) {
                pk.d[a][l] = pts[3 * (base + l) + a] - pk.o[a];
                pk.inv[a][l] = 1.0f / pk.d[a][l];
            }
            pk.live[l] = (int)(lanes >> l & 1u);
        }
        trace_packet(ctx->bvh, &pk, q->prim, cnt);
        uint64_t bits = 0;
        for (int l = 0; l < LANES; l++) bits |= (uint64_t)(pk.live[l] != 0) << l;
        vis[base >> 6] |= bits << (base & 63);
        visible += __builtin_popcountll(bits);
    }
    return visible;
}

static int rt_visibility(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, int nq,
                         const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    (void)state;
    float *pts = malloc((size_t)ctx->samples * 3 * sizeof(float));
    if (!pts) return -1;
    const size_t mw = (size_t)ctx->mask_words;
    for (int qi = 0; qi < nq; qi++)
        ms_raytrace_visible_samples(ctx, &q[qi], pts, front + qi * mw, vis + qi * mw, cnt);
    free(pts);
    return 0;
}

static void rt_destroy(void *state) { (void)state; }

const ms_shadow_method ms_shadow_raytrace = {
    .name = "raytrace",
    .primary = "bvh",
    .needs_grid = 0,
    .n_counters = 3,
    .counter_names = { "packets", "packet_node_visits", "packet_triangle_tests" },
    .create = rt_create,
    .visibility = rt_visibility,
    .destroy = rt_destroy,
};
