/* Methods "scanline", "bounds", "hierarchical": soft shadows by micro-rasterization (Woop 2010,
 * sec. 6). For every visible point C the frustum spanned by C and the light is traversed through the
 * BVH (frustum_traverse_impl.h); every triangle of a surviving leaf is rasterized into the pixel's
 * k x k occlusion buffer with the method's kernel (src/raster), which starts as the pixel's front mask
 * (the receiver's horizon rasterized by the Scanline row loop, receiver.c); what is left is the visible
 * mask. The pixel's 3x3 light-space transform is set up once and shared by all its triangles.
 *
 * Departure from the paper: a point that sees the light nearly edge-on (closer to the light's plane than
 * 1e-3 of its distance to the light) makes the light-space transform near-singular (light-space
 * coordinates of 1e6 were seen on Sponza). The kernels' edge equations no longer depend on it (they are
 * world cross products carried by M^T, raster_internal.h), but the traversal's node projections and the
 * kernels' boxes do. Such points are answered by the reference per-sample tracer instead, on the same
 * samples; they are counted (pixels_traced_edge_on) and are few: the light barely reaches them.
 *
 * The render context's switches (method.h) cap the kernels' and the traversal's instruction set and
 * switch off the coverage test and the near-first child order; the library reads no environment. */
#include "method.h"
#include "frustum_traverse.h"
#include "receiver.h"
#include <math.h>
#include "../core/vec.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EDGE_ON 1e-3f

typedef struct mr_state {
    ms_raster_fn raster;
    ms_frustum_trace_fn trace;
    int flags;
    ms_isa kernel_isa, trace_isa; /* what ran, for ms_stats */
} mr_state;

static int mr_create_kernel(ms_kernel_id id, const ms_render_ctx *ctx, void **state, char *err, size_t errlen)
{
    mr_state *s = calloc(1, sizeof *s);
    if (!s) { snprintf(err, errlen, "out of memory"); return -1; }
    s->raster = ms_raster_kernel(id, ctx->k, ctx->isa_cap, &s->kernel_isa);
    s->trace = ms_frustum_trace_select(ctx->k, ctx->isa_cap, &s->trace_isa);
    if (!s->raster || !s->trace) {
        free(s);
        snprintf(err, errlen, "no %s kernel for %d samples", ms_kernel_name(id), ctx->samples);
        return -1;
    }
    s->flags = (ctx->no_occlusion_cull ? 0 : MS_FT_CULL_OCCLUDED) | (ctx->no_child_order ? 0 : MS_FT_ORDER_CHILDREN);
    *state = s;
    return 0;
}

static int mr_create_scanline(const ms_render_ctx *c, void **s, char *e, size_t n) { return mr_create_kernel(MS_KERNEL_SCANLINE, c, s, e, n); }
static int mr_create_bounds(const ms_render_ctx *c, void **s, char *e, size_t n) { return mr_create_kernel(MS_KERNEL_BOUNDS, c, s, e, n); }
static int mr_create_hier(const ms_render_ctx *c, void **s, char *e, size_t n) { return mr_create_kernel(MS_KERNEL_HIERARCHICAL, c, s, e, n); }

static int mr_visibility(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, int nq,
                         const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    const mr_state *s = state;
    const size_t mw = (size_t)ctx->mask_words;
    float *pts = NULL;
    for (int qi = 0; qi < nq; qi++) {
        const uint64_t *fm = front + qi * mw;
        uint64_t *buf = vis + qi * mw;   /* the k x k occlusion buffer itself (receiver.h) */
        /* The horizon is already rasterized: the buffer starts as the front mask, so samples behind count
         * as neither visible nor occluded and the all-zero early-out means "every front sample occluded". */
        memcpy(buf, fm, mw * sizeof *buf);
        if (ms_mask_count(fm, (int)mw) == 0) continue;
        ms_grid g;
        ms_raster_frame f;
        ms_grid_for_pixel(&ctx->light, ctx->k, q[qi].px, q[qi].py, ctx->seed, &g);
        float n[3], rel[3];
        v3_cross(n, g.ds, g.dt);
        v3_sub(rel, g.p0, q[qi].p);
        float h = fabsf(v3_dot(n, rel)), d = v3_len(n) * v3_len(rel);
        if (!(h > EDGE_ON * d) || ms_raster_frame_init(&f, q[qi].p, &g, ctx->near, ctx->far, 0) != 0) {
            uint64_t rt_counters[MS_MAX_COUNTERS] = { 0 };
            if (!pts && !(pts = malloc((size_t)ctx->samples * 3 * sizeof(float)))) return -1;
            ms_raytrace_visible_samples(ctx, &q[qi], pts, fm, buf, rt_counters);
            cnt[MS_FT_TRACED_EDGE_ON]++;
            continue;
        }
        cnt[MS_FT_FRUSTA]++;
        s->trace(ctx->bvh, &f, s->raster, q[qi].prim, buf, cnt, s->flags);
    }
    free(pts);
    return 0;
}

static void mr_destroy(void *state) { free(state); }

static void mr_isa_used(const void *state, ms_isa *kernel, ms_isa *traversal)
{
    const mr_state *s = state;
    *kernel = s->kernel_isa;
    *traversal = s->trace_isa;
}

#define MICRORASTER_METHOD(ident, mname, create_fn)                                                   \
    const ms_shadow_method ident = {                                                                  \
        .name = mname, .primary = "bvh", .needs_grid = 1, .n_counters = MS_FT_COUNTERS,               \
        .counter_names = { "frusta", "nodes_visited", "nodes_culled_frustum", "nodes_culled_occluded", \
                           "triangles_rasterized", "pixels_early_out", "pixels_traced_edge_on" },    \
        .create = create_fn, .visibility = mr_visibility, .destroy = mr_destroy, .isa_used = mr_isa_used }

MICRORASTER_METHOD(ms_shadow_scanline, "scanline", mr_create_scanline);
MICRORASTER_METHOD(ms_shadow_bounds, "bounds", mr_create_bounds);
MICRORASTER_METHOD(ms_shadow_hierarchical, "hierarchical", mr_create_hier);
