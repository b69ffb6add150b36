/* Methods "scanline", "bounds", "hierarchical": soft shadows by micro-rasterization (Woop 2010,
 * sec. 6). For every visible point C the frustum spanned by C and the light is traversed through the
 * BVH; every triangle of a surviving leaf is rasterized into the pixel's k x k occlusion buffer with
 * the method's kernel; V is the fraction of samples left visible.
 *
 * The traversal works in the pixel's light-index space (the kernel's frame: C at the origin, sample
 * (i,j) at (i,j,1)), where the frustum is simply 0 <= x <= (k-1)z, 0 <= y <= (k-1)z, near <= z <= far.
 * A node's 8 corners are transformed once (a base corner plus the three transformed edges) and serve
 * three tests:
 *   - frustum: the box is outside one of those half-spaces (the paper culls against frustum planes
 *     in world space; these are the same planes, written where they are axis-aligned);
 *   - coverage: the box lies in front of C, so its projection is the hull of its projected corners;
 *     if that hull holds no sample, or only samples already occluded (rows tested against the buffer),
 *     nothing below can change V;
 *   - order: the nearer child (smaller z, larger projection) is visited first, so big occluders
 *     fill the buffer early and the coverage test and the umbra early-out fire sooner.
 * The pixel stops as soon as the buffer is all zero (umbra). */
#include "method.h"
#include "../raster/raster.h"
#include "../core/vec.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { C_FRUSTA, C_NODES_VISITED, C_NODES_CULLED_FRUSTUM, C_NODES_CULLED_OCCLUDED, C_TRIANGLES, C_EARLY_OUT,
       C_COUNT };

/* Slack, in sample units per unit depth, for rounding at the frustum sides. */
#define SIDE_SLACK 0.01f

typedef struct mr_state {
    ms_kernel_id kernel;
    ms_raster_fn fn;
    int cull_occluded;      /* coverage test on, default; off to measure what it buys */
    int order_children;
} mr_state;

typedef struct node_view {
    int outside;            /* culled by the frustum */
    int in_front;           /* every corner has z > 0: projected bounds valid */
    float zmin;
    float x0, x1, y0, y1;   /* projected bounds in sample units (valid when in_front) */
} node_view;

static void view_node(const ms_raster_frame *f, const ms_bvh_node *n, node_view *v)
{
    float rel[3], e[3];
    for (int a = 0; a < 3; a++) { rel[a] = n->bmin[a] - f->c[a]; e[a] = n->bmax[a] - n->bmin[a]; }
    float base[3], col[3][3];
    for (int r = 0; r < 3; r++) {
        base[r] = f->m[r][0] * rel[0] + f->m[r][1] * rel[1] + f->m[r][2] * rel[2];
        for (int a = 0; a < 3; a++) col[a][r] = f->m[r][a] * e[a];
    }
    float xs[8], ys[8], zs[8];
    for (int c = 0; c < 8; c++) {
        float p[3] = { base[0], base[1], base[2] };
        for (int a = 0; a < 3; a++)
            if (c >> a & 1) { p[0] += col[a][0]; p[1] += col[a][1]; p[2] += col[a][2]; }
        xs[c] = p[0]; ys[c] = p[1]; zs[c] = p[2];
    }
    const float hi = (float)(f->k - 1) + SIDE_SLACK;
    int out_xl = 1, out_xh = 1, out_yl = 1, out_yh = 1, out_near = 1, out_far = 1, front = 1;
    float zmin = INFINITY;
    for (int c = 0; c < 8; c++) {
        float z = zs[c];
        out_xl &= xs[c] < -SIDE_SLACK * fabsf(z);
        out_xh &= xs[c] > hi * z + SIDE_SLACK * fabsf(z);
        out_yl &= ys[c] < -SIDE_SLACK * fabsf(z);
        out_yh &= ys[c] > hi * z + SIDE_SLACK * fabsf(z);
        out_near &= z < f->near;
        out_far &= z > f->far;
        front &= z > 0.0f;
        zmin = ms_minf(zmin, z);
    }
    v->outside = out_xl | out_xh | out_yl | out_yh | out_near | out_far;
    v->in_front = front;
    v->zmin = zmin;
    if (front && !v->outside) {
        float x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
        for (int c = 0; c < 8; c++) {
            float iz = 1.0f / zs[c];
            float px = xs[c] * iz, py = ys[c] * iz;
            x0 = ms_minf(x0, px); x1 = ms_maxf(x1, px);
            y0 = ms_minf(y0, py); y1 = ms_maxf(y1, py);
        }
        v->x0 = x0; v->x1 = x1; v->y0 = y0; v->y1 = y1;
    }
}

static inline uint64_t buffer_row(const void *buf, int k, int j)
{
    switch (k) {
    case 16: return ((const uint16_t *)buf)[j];
    case 32: return ((const uint32_t *)buf)[j];
    default: return ((const uint64_t *)buf)[j];
    }
}

/* 1 if some still-visible sample lies in the node's projected bounds (with a one-sample margin
 * against rounding in the projection). */
static int covers_live_sample(const node_view *v, const void *buf, int k)
{
    if (!v->in_front) return 1;
    float fx0 = ceilf(v->x0 - 0.01f), fx1 = floorf(v->x1 + 0.01f);
    float fy0 = ceilf(v->y0 - 0.01f), fy1 = floorf(v->y1 + 0.01f);
    float kmax = (float)(k - 1);
    if (fx0 > kmax || fy0 > kmax || fx1 < 0.0f || fy1 < 0.0f || fx0 > fx1 || fy0 > fy1) return 0;
    int i0 = fx0 < 0.0f ? 0 : (int)fx0, i1 = fx1 > kmax ? k - 1 : (int)fx1;
    int j0 = fy0 < 0.0f ? 0 : (int)fy0, j1 = fy1 > kmax ? k - 1 : (int)fy1;
    /* Bits i0..i1, built without shifting by the word size. */
    uint64_t mask = (~0ull >> (63 - (i1 - i0))) << i0;
    for (int j = j0; j <= j1; j++)
        if (buffer_row(buf, k, j) & mask) return 1;
    return 0;
}

static int mr_create_kernel(ms_kernel_id id, const ms_render_ctx *ctx, void **state, char *err, size_t errlen)
{
    mr_state *s = calloc(1, sizeof *s);
    if (!s) { snprintf(err, errlen, "out of memory"); return -1; }
    s->kernel = id;
    s->fn = ms_raster_kernel(id, ctx->k);
    if (!s->fn) { free(s); snprintf(err, errlen, "no %s kernel for %d samples", ms_kernel_name(id), ctx->samples); return -1; }
    const char *e = getenv("MS_MICRORASTER_NO_OCCLUSION_CULL");
    s->cull_occluded = !(e && e[0] == '1');
    e = getenv("MS_MICRORASTER_NO_ORDER");
    s->order_children = !(e && e[0] == '1');
    *state = s;
    return 0;
}

static int mr_create_scanline(const ms_render_ctx *c, void **s, char *e, size_t n) { return mr_create_kernel(MS_KERNEL_SCANLINE, c, s, e, n); }
static int mr_create_bounds(const ms_render_ctx *c, void **s, char *e, size_t n) { return mr_create_kernel(MS_KERNEL_BOUNDS, c, s, e, n); }
static int mr_create_hier(const ms_render_ctx *c, void **s, char *e, size_t n) { return mr_create_kernel(MS_KERNEL_HIERARCHICAL, c, s, e, n); }

/* Traverses one pixel's frustum; returns with buf holding the visible samples. */
static void trace_frustum(const mr_state *s, const ms_bvh *b, const ms_raster_frame *f, uint32_t skip, void *buf,
                          uint64_t *cnt)
{
    uint32_t stack[MS_BVH_STACK];
    int sp = 0;
    node_view v;
    view_node(f, &b->nodes[0], &v);
    cnt[C_NODES_VISITED]++;
    if (v.outside) { cnt[C_NODES_CULLED_FRUSTUM]++; return; }
    uint32_t ni = 0;
    for (;;) {
        const ms_bvh_node *n = &b->nodes[ni];
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                if (i == skip) continue;
                s->fn(f, b->tri + 9 * (size_t)i, buf);
                cnt[C_TRIANGLES]++;
            }
            if (ms_buffer_all_occluded(buf, f->k)) { cnt[C_EARLY_OUT]++; return; }
        } else {
            uint32_t c[2] = { n->first, n->first + 1 };
            node_view cv[2];
            int keep[2];
            for (int i = 0; i < 2; i++) {
                view_node(f, &b->nodes[c[i]], &cv[i]);
                cnt[C_NODES_VISITED]++;
                keep[i] = !cv[i].outside;
                if (!keep[i]) { cnt[C_NODES_CULLED_FRUSTUM]++; continue; }
                if (s->cull_occluded && !covers_live_sample(&cv[i], buf, f->k)) {
                    keep[i] = 0;
                    cnt[C_NODES_CULLED_OCCLUDED]++;
                }
            }
            if (keep[0] && keep[1]) {
                int first = s->order_children && cv[1].zmin < cv[0].zmin;
                stack[sp++] = c[!first];
                ni = c[first];
                continue;
            }
            if (keep[0]) { ni = c[0]; continue; }
            if (keep[1]) { ni = c[1]; continue; }
        }
        if (sp == 0) return;
        ni = stack[--sp];
        /* The buffer has changed since this node was pushed: it may be fully occluded by now. */
        if (s->cull_occluded) {
            view_node(f, &b->nodes[ni], &v);
            while (!covers_live_sample(&v, buf, f->k)) {
                cnt[C_NODES_CULLED_OCCLUDED]++;
                if (sp == 0) return;
                ni = stack[--sp];
                view_node(f, &b->nodes[ni], &v);
            }
        }
    }
}

static void mr_visibility(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, int nq, float *vis,
                          uint64_t *cnt)
{
    const mr_state *s = state;
    _Alignas(64) uint64_t buf[64];
    for (int qi = 0; qi < nq; qi++) {
        ms_grid g;
        ms_raster_frame f;
        ms_grid_for_pixel(&ctx->light, ctx->k, q[qi].px, q[qi].py, ctx->seed, &g);
        ms_buffer_fill_visible(buf, ctx->k);
        cnt[C_FRUSTA]++;
        if (ms_raster_frame_init(&f, q[qi].p, &g, ctx->near, ctx->far, 0) == 0)
            trace_frustum(s, ctx->bvh, &f, q[qi].prim, buf, cnt);
        vis[qi] = (float)ms_buffer_visible_count(buf, ctx->k) / (float)ctx->samples;
    }
}

static void mr_destroy(void *state) { free(state); }

#define MICRORASTER_METHOD(ident, mname, create_fn)                                                         \
    const ms_shadow_method ident = {                                                                        \
        .name = mname, .primary = "bvh", .needs_grid = 1, .n_counters = C_COUNT,                            \
        .counter_names = { "frusta", "nodes_visited", "nodes_culled_frustum", "nodes_culled_occluded",     \
                           "triangles_rasterized", "pixels_early_out" },                                   \
        .create = create_fn, .visibility = mr_visibility, .destroy = mr_destroy }

MICRORASTER_METHOD(ms_shadow_scanline, "scanline", mr_create_scanline);
MICRORASTER_METHOD(ms_shadow_bounds, "bounds", mr_create_bounds);
MICRORASTER_METHOD(ms_shadow_hierarchical, "hierarchical", mr_create_hier);
