/* Methods "scanline", "bounds", "hierarchical": soft shadows by micro-rasterization (Woop 2010,
 * sec. 6). For every visible point C the frustum spanned by C and the light finds the triangles between
 * them, each of which is rasterized into the pixel's k x k occlusion buffer with the method's kernel
 * (src/raster); the buffer starts as the pixel's front mask (the receiver's horizon rasterized by the
 * Scanline row loop, receiver.c) and what is left is the visible mask. The pixel's 3x3 light-space
 * transform is set up once and shared by all its triangles. Two traversals give the same buffers: by
 * default the frusta of a 4x4 pixel block together through the shallow BVH (Benthin & Wald 2009,
 * block_raster_impl.h), or each pixel's alone through the deep BVH (Woop's, frustum_traverse_impl.h;
 * ms_render_options.traversal).
 *
 * Departure from the paper: a point that sees the light nearly edge-on (closer to the light's plane than
 * 1e-3 of its distance to the light) makes the light-space transform near-singular (light-space
 * coordinates of 1e6 were seen on Sponza). The kernels' edge equations no longer depend on it (they are
 * world cross products carried by M^T, raster_internal.h), but the traversal's node projections and the
 * kernels' boxes do. Such points are answered by the reference per-sample tracer instead, on the same
 * samples; they are counted (pixels_traced_edge_on) and are few: the light barely reaches them.
 *
 * Before the triangles, a light's interior boxes (ctx->interior, visibility/occluders.h, docs/culling.md):
 * virtual occluders inside closed surfaces, which empty most umbra buffers in a few kernel calls; the
 * triangles themselves come from the light's occluder set (the cull of closed parts without boxes, merged
 * coplanar rectangles), all with the same V and S.
 *
 * The render context's switches (visibility/context.h) cap the kernels' and the traversal's instruction set and
 * switch off the coverage test and the near-first child order; the library reads no environment. */
#include "shadow/method.h"
#include "visibility/occluders.h"
#include "shadow/raytrace/raytrace.h"
#include "frustum_traverse.h"
#include "block_raster.h"
#include "block_group.h"
#include "raster/raster_internal.h"   /* ms_raster_rows */
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include <math.h>
#include <omp.h>
#include "core/vec.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EDGE_ON 1e-3f

/* Largest leaf of the shallow BVH of the block traversal (accel/bvh.h). On dense meshes 16 halves the node
 * tests of 8 for 1.3x the triangle tests, and is faster; 12 and 24 were slower (the lab notebook,
 * docs/notebook/2026-11-25-dense-meshes.md and 2026-11-29-penumbra-cost.md). */
#define MR_SHALLOW_LEAF 16
/* Largest leaf of the interior boxes' shallow BVH with the silhouette pass: a box costs a pixel more than a
 * triangle, so the node tests cull them in smaller groups (the sweep: docs/notebook/2026-11-30-box-silhouettes.md). */
#define MR_BOX_LEAF 4

typedef struct mr_state {
    ms_raster_fn raster;
    ms_frustum_trace_fn trace;
    ms_block_raster_fn block;       /* NULL: per-pixel traversal */
    ms_bvh_shallow shallow;
    ms_bvh_shallow interior_shallow;  /* over ctx->interior, or ctx->interior_box_bvh with box_pass (n_nodes 0: none) */
    int box_pass;                   /* the block traversal rasterizes each interior box's silhouette (block_box_impl.h):
                                     * the kernel's row loop for five edges exists (the SIMD Scanline) */
    int flags, block_flags;
    ms_isa kernel_isa, trace_isa; /* what ran, for ms_stats */
} mr_state;

static const char *const block_counter_names[] = {
    "blocks", "aabb_tests", "leaves", "tris_accessed", "blocks_early_out", "leaf_pixels_culled", "tri_pixel_tests",
    "culled_depth", "culled_rect", "culled_corner_rays", "culled_coverage", "triangles_rasterized",
    "pixels_early_out", "rect_shrinks", "shared_setups", "shared_setups_clipped", "node_pixels_culled", "pixels_traced_edge_on", "interior_rasterized", "interior_pixels_emptied",
    "pixels_lit", "pixels_umbra", "pixels_penumbra", "pixels_facing_away", "tests_lit", "tests_umbra", "tests_penumbra",
    "rasterized_lit", "rasterized_umbra", "rasterized_penumbra", "lit_ns", "umbra_ns", "penumbra_ns"
};
/* The interior boxes' pass adds to every counter above (its work is work) and to its own two. */
/* Then where the time goes, by the class of each pixel's answer (lit: every front sample visible; umbra:
 * none; penumbra: some; facing away: no front sample, decided before any traversal): the pixels, their
 * (triangle, pixel) tests and rasterizations (interior boxes included), and the nanoseconds of their blocks'
 * traversals, each block's shared among its pixels in proportion to 1 + tests + rasterizations. */
enum { MR_BLOCK_EDGE_ON = MS_BR_COUNTERS, MR_INTERIOR_RASTERIZED, MR_INTERIOR_EMPTIED, MR_PIXELS_CLASS,
       MR_FACING_AWAY = MR_PIXELS_CLASS + 3, MR_TESTS_CLASS, MR_RAST_CLASS = MR_TESTS_CLASS + 3,
       MR_NS_CLASS = MR_RAST_CLASS + 3, MR_BLOCK_COUNTERS = MR_NS_CLASS + 3 };
_Static_assert(MR_BLOCK_COUNTERS <= MS_MAX_COUNTERS, "counters");

static int mr_create_kernel(ms_kernel_id id, const ms_render_ctx *ctx, void **state, char *err, size_t errlen)
{
    mr_state *s = calloc(1, sizeof *s);
    if (!s) { snprintf(err, errlen, "out of memory"); return -1; }
    s->raster = ms_raster_kernel(id, ctx->k, ctx->isa_cap, &s->kernel_isa);
    if (ctx->traversal == MS_TRAVERSAL_PIXEL) s->trace = ms_frustum_trace_select(ctx->k, ctx->isa_cap, &s->trace_isa);
    else s->block = ms_block_raster_select(ctx->k, ctx->isa_cap, &s->trace_isa);
    if (!s->raster || !(s->trace || s->block)) {
        free(s);
        snprintf(err, errlen, "no %s kernel for %d samples", ms_kernel_name(id), ctx->samples);
        return -1;
    }
    s->flags = (ctx->no_occlusion_cull ? 0 : MS_FT_CULL_OCCLUDED) | (ctx->no_child_order ? 0 : MS_FT_ORDER_CHILDREN);
    s->block_flags = (ctx->no_child_order ? 0 : MS_BR_ORDER) | (ctx->frustum_shrink ? MS_BR_FRUSTUM_SHRINK : 0);
    s->box_pass = s->block && ctx->interior_box_bvh && ms_raster_rows(s->raster, ctx->k, 5);   /* as mr_silhouettes */
    if (s->block && (ms_bvh_shallow_build(&s->shallow, ctx->bvh, MR_SHALLOW_LEAF) ||
                     (ctx->interior && ms_bvh_shallow_build(&s->interior_shallow, s->box_pass ? ctx->interior_box_bvh : ctx->interior,
                                                            s->box_pass ? MR_BOX_LEAF : MR_SHALLOW_LEAF)))) {
        ms_bvh_shallow_free(&s->shallow);
        free(s);
        snprintf(err, errlen, "out of memory for the shallow BVH");
        return -1;
    }
    *state = s;
    return 0;
}

/* Whether the block traversal rasterizes the interior boxes as silhouettes (block_box_impl.h): it borrows the
 * SIMD Scanline kernel's row loop, which the portable kernel lacks; the per-pixel traversal takes triangles. */
static int mr_silhouettes(const ms_render_ctx *ctx)
{
    return ctx->traversal != MS_TRAVERSAL_PIXEL &&
           ms_raster_rows(ms_raster_kernel(MS_KERNEL_SCANLINE, ctx->k, ctx->isa_cap, NULL), ctx->k, 5) != NULL;
}

static int mr_create_scanline(const ms_render_ctx *c, void **s, char *e, size_t n) { return mr_create_kernel(MS_KERNEL_SCANLINE, c, s, e, n); }
static int mr_create_bounds(const ms_render_ctx *c, void **s, char *e, size_t n) { return mr_create_kernel(MS_KERNEL_BOUNDS, c, s, e, n); }
static int mr_create_hier(const ms_render_ctx *c, void **s, char *e, size_t n) { return mr_create_kernel(MS_KERNEL_HIERARCHICAL, c, s, e, n); }

/* Starts query q's buffer as its front mask (the horizon is already rasterized, so samples behind count
 * as neither visible nor occluded and the all-zero early-out means "every front sample occluded") and
 * sets up its frame. Returns 1 when the frame is to be traversed, 0 when the buffer is final: no front
 * sample, or an edge-on point, traced per sample (counted in *edge_on), or -1 when out of memory. */
static int mr_start(const ms_render_ctx *ctx, const ms_shadow_query *q, const uint64_t *fm, uint64_t *buf,
                    ms_raster_frame *f, ms_alpha_pixel *ap, float **pts, uint64_t *edge_on)
{
    const size_t mw = (size_t)ctx->mask_words;
    memcpy(buf, fm, mw * sizeof *buf);
    if (ms_mask_count(fm, (int)mw) == 0) return 0;
    ms_grid g;
    ms_grid_for_pixel(&ctx->light, ctx->k, q->px, q->py, ctx->seed, &g);
    float n[3], rel[3];
    v3_cross(n, g.ds, g.dt);
    v3_sub(rel, g.p0, q->p);
    float h = fabsf(v3_dot(n, rel)), d = v3_len(n) * v3_len(rel);
    if (!(h > EDGE_ON * d) || ms_raster_frame_init(f, q->p, &g, ctx->near, ctx->far, 0) != 0) {
        uint64_t rt_counters[MS_MAX_COUNTERS] = { 0 };
        if (!*pts && !(*pts = malloc((size_t)ctx->samples * 3 * sizeof(float)))) return -1;
        ms_raytrace_visible_samples(ctx, q, *pts, fm, buf, rt_counters);
        ++*edge_on;
        return 0;
    }
    /* Alpha-tested triangles need the query to find their samples (alpha.h); opaque scenes: NULL. */
    ap->ctx = ctx;
    ap->q = q;
    f->alpha = ctx->alpha ? ap : NULL;
    return 1;
}

static int mr_visibility_pixel(const mr_state *s, const ms_render_ctx *ctx, const ms_shadow_query *q, int nq,
                               const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    const size_t mw = (size_t)ctx->mask_words;
    float *pts = NULL;
    for (int qi = 0; qi < nq; qi++) {
        ms_raster_frame f;
        ms_alpha_pixel ap;
        uint64_t *buf = vis + qi * mw;   /* the k x k occlusion buffer itself (receiver.h) */
        ms_render_ctx own;   /* an outlined light: the query's own (ms_ctx_for_query) */
        const int go = mr_start(ms_ctx_for_query(ctx, &q[qi], &own), &q[qi], front + qi * mw, buf, &f, &ap, &pts,
                                &cnt[MS_FT_TRACED_EDGE_ON]);
        if (go < 0) { free(pts); return -1; }
        if (!go) continue;
        cnt[MS_FT_FRUSTA]++;
        if (ctx->interior) {
            /* The interior boxes first (opaque, nobody's own triangle); then what they left. */
            const void *alpha = f.alpha;
            f.alpha = NULL;
            s->trace(ctx->interior, &f, s->raster, UINT32_MAX, buf, cnt, s->flags);
            f.alpha = alpha;
            if (ms_mask_count((const uint64_t *)buf, (int)mw) == 0) continue;
        }
        s->trace(ctx->bvh, &f, s->raster, q[qi].prim, buf, cnt, s->flags);
    }
    free(pts);
    return 0;
}

/* The block's pass over the interior boxes (occluders.h): the same traversal over their BVH, with no
 * receiver's triangle to skip and no alpha test; the pixels it empties leave the block. */
static void interior_pass(const mr_state *s, const ms_render_ctx *ctx, ms_block_input *in, int *orig, size_t mw,
                          uint64_t *cnt, ms_block_leaf_cache *box_cache)
{
    ms_block_input vin = *in;
    vin.cache = box_cache;   /* its own: the scene's cache holds leaves of the scene's BVH */
    vin.box = s->box_pass ? ctx->interior_box : NULL;
    const void *alpha[MS_BLOCK_LANES];
    for (int l = 0; l < in->n; l++) {
        vin.skip[l] = UINT32_MAX;
        alpha[l] = in->frame[l]->alpha;
        ((ms_raster_frame *)in->frame[l])->alpha = NULL;
    }
    const uint64_t before = cnt[MS_BR_RASTERIZED];
    s->block(&vin, s->box_pass ? ctx->interior_box_bvh : ctx->interior, &s->interior_shallow, s->raster, ctx->near, ctx->far, cnt, s->block_flags);
    cnt[MR_INTERIOR_RASTERIZED] += cnt[MS_BR_RASTERIZED] - before;
    int n = 0;
    for (int l = 0; l < in->n; l++) {
        ((ms_raster_frame *)in->frame[l])->alpha = alpha[l];
        if (ms_mask_count((const uint64_t *)in->buf[l], (int)mw) == 0) { cnt[MR_INTERIOR_EMPTIED]++; continue; }
        in->frame[n] = in->frame[l];
        in->buf[n] = in->buf[l];
        in->skip[n] = in->skip[l];
        orig[n] = orig[l];
        n++;
    }
    in->n = n;
}

/* The pixel-class counters of one block's `n` lanes (MR_PIXELS_CLASS): each lane's class from its front mask and
 * its final buffer, its work, and its share of the block's seconds. */
static void count_classes(uint64_t *cnt, int n, const uint64_t *const *front, uint64_t *const *buf, const uint32_t *tests,
                          const uint32_t *rast, double seconds, size_t mw)
{
    double weight[MS_BLOCK_LANES], total = 0.0;
    for (int l = 0; l < n; l++) total += weight[l] = 1.0 + tests[l] + rast[l];
    for (int l = 0; l < n; l++) {
        const int v = ms_mask_count(buf[l], (int)mw), f = ms_mask_count(front[l], (int)mw);
        const int c = v == f ? 0 : v == 0 ? 1 : 2;
        cnt[MR_PIXELS_CLASS + c]++;
        cnt[MR_TESTS_CLASS + c] += tests[l];
        cnt[MR_RAST_CLASS + c] += rast[l];
        cnt[MR_NS_CLASS + c] += (uint64_t)(seconds * 1e9 * weight[l] / total + 0.5);
    }
}

/* The queries grouped by 4x4 pixel block (at most 16 to a group), or 16 consecutive ones when they come
 * in proximity order (the points API), each group traversed together.
 * An outlined light (the sun, the sphere: ctx->outline_per_query): each lane's frame is set up from its
 * query's own light (ms_ctx_for_query, the context the one-query path gets), and nothing in the traversal
 * mixes lanes: each lane's frustum is its own frame's (block_raster_impl.h, br_corner_dirs), so the node
 * and leaf tests bound that lane's segments alone, every cull is conservative for that lane's kernel, and
 * its buffer is its front mask less the union of the kernel's coverage of the triangles its frustum
 * reaches, in whatever order: the same buffer as a block of one. */
static int mr_visibility_block(const mr_state *s, const ms_render_ctx *ctx, const ms_shadow_query *q, int nq,
                               const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    const size_t mw = (size_t)ctx->mask_words;
    float *pts = NULL;
    int *order = malloc((size_t)nq * sizeof *order);
    if (!order) return -1;
    ms_block_order(ctx, q, nq, order);
    /* One leaf cache per tree: the scene's, and the interior boxes' (an umbra pixel rasterizes the boxes until its
     * buffer is empty, and the previous block's best boxes empty it with fewer). */
    ms_block_leaf_cache cache = { 0 }, box_cache = { 0 };
    cache.pre_bits = calloc(((size_t)s->shallow.n_nodes + 63) / 64, sizeof *cache.pre_bits);
    box_cache.pre_bits = calloc(((size_t)s->interior_shallow.n_nodes + 63) / 64 + 1, sizeof *box_cache.pre_bits);
    if (!cache.pre_bits || !box_cache.pre_bits) { free(cache.pre_bits); free(box_cache.pre_bits); free(order); return -1; }
    int rc = 0;
    for (int g = 0; g < nq && !rc;) {
        ms_block_input in;
        ms_raster_frame frames[MS_BLOCK_LANES];
        ms_alpha_pixel aps[MS_BLOCK_LANES];
        ms_render_ctx own[MS_BLOCK_LANES];   /* an outlined light: the lanes' own contexts (aps[] point at them) */
        /* Per lane of the block as formed (orig: a lane's index there after the interior pass compacts). */
        const uint64_t *lane_front[MS_BLOCK_LANES];
        uint32_t tests[MS_BLOCK_LANES] = { 0 }, rast[MS_BLOCK_LANES] = { 0 };
        uint32_t all_tests[MS_BLOCK_LANES] = { 0 }, all_rast[MS_BLOCK_LANES] = { 0 };
        uint64_t *lane_buf[MS_BLOCK_LANES];
        int orig[MS_BLOCK_LANES];
        in.n = 0;
        in.cache = &cache;
        in.box = NULL;
        in.lane_tests = tests;
        in.lane_rast = rast;
        const int end = ms_block_group_end(ctx, q, order, nq, g);
        for (int e = g; e < end; e++) {
            const int i = order[e];
            uint64_t *buf = vis + (size_t)i * mw;
            const int go = mr_start(ms_ctx_for_query(ctx, &q[i], &own[in.n]), &q[i], front + (size_t)i * mw, buf,
                                    &frames[in.n], &aps[in.n], &pts, &cnt[MR_BLOCK_EDGE_ON]);
            if (go < 0) { rc = -1; break; }
            if (!go) {
                cnt[MR_FACING_AWAY] += ms_mask_count(front + (size_t)i * mw, (int)mw) == 0;
                continue;
            }
            in.frame[in.n] = &frames[in.n];
            in.buf[in.n] = buf;
            in.skip[in.n] = q[i].prim;
            lane_front[in.n] = front + (size_t)i * mw;
            lane_buf[in.n] = buf;
            orig[in.n] = in.n;
            in.n++;
        }
        const int formed = in.n;
        const double t0 = formed ? omp_get_wtime() : 0.0;
        if (!rc && in.n && ctx->interior) {
            interior_pass(s, ctx, &in, orig, mw, cnt, &box_cache);   /* lanes counted as formed, then compacted */
            for (int l = 0; l < formed; l++) {
                all_tests[l] = tests[l];
                all_rast[l] = rast[l];
                tests[l] = rast[l] = 0;
            }
        }
        if (!rc && in.n) {
            s->block(&in, ctx->bvh, &s->shallow, s->raster, ctx->near, ctx->far, cnt, s->block_flags);
            for (int l = 0; l < in.n; l++) {
                all_tests[orig[l]] += tests[l];
                all_rast[orig[l]] += rast[l];
            }
        }
        if (!rc && formed) count_classes(cnt, formed, lane_front, lane_buf, all_tests, all_rast, omp_get_wtime() - t0, mw);
        g = end;
    }
    free(order);
    free(pts);
    free(cache.pre_bits);
    free(box_cache.pre_bits);
    return rc;
}

static int mr_visibility(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, int nq,
                         const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    const mr_state *s = state;
    return s->block ? mr_visibility_block(s, ctx, q, nq, front, vis, cnt)
                    : mr_visibility_pixel(s, ctx, q, nq, front, vis, cnt);
}

static int mr_counters_used(const void *state, const char *const **names)
{
    const mr_state *s = state;
    if (!s->block) return -1;
    *names = block_counter_names;
    return MR_BLOCK_COUNTERS;
}

static void mr_destroy(void *state)
{
    mr_state *s = state;
    ms_bvh_shallow_free(&s->shallow);
    ms_bvh_shallow_free(&s->interior_shallow);
    free(s);
}

static void mr_isa_used(const void *state, ms_isa *kernel, ms_isa *traversal)
{
    const mr_state *s = state;
    *kernel = s->kernel_isa;
    *traversal = s->trace_isa;
}

#define MICRORASTER_METHOD(ident, mname, create_fn, silhouettes_fn)                                   \
    const ms_shadow_method ident = {                                                                  \
        .name = mname, .primary = "bvh", .needs_grid = 1, .n_counters = MS_FT_COUNTERS,               \
        .occluders = MS_OCC_CULL | MS_OCC_CULL_BY_DEFAULT | MS_OCC_INTERIOR | MS_OCC_MERGE,            \
        .interior_silhouettes = silhouettes_fn,                                                       \
        .counter_names = { "frusta", "nodes_visited", "nodes_culled_frustum", "nodes_culled_occluded", \
                           "triangles_rasterized", "pixels_early_out", "pixels_traced_edge_on" },    \
        .create = create_fn, .visibility = mr_visibility, .destroy = mr_destroy, .isa_used = mr_isa_used, \
        .counters_used = mr_counters_used, .outlines = 1 }

/* Scanline's block traversal rasterizes the interior boxes as silhouettes (mr_silhouettes); the baselines' kernels
 * take them as triangles. */
MICRORASTER_METHOD(ms_shadow_scanline, "scanline", mr_create_scanline, mr_silhouettes);
MICRORASTER_METHOD(ms_shadow_bounds, "bounds", mr_create_bounds, NULL);
MICRORASTER_METHOD(ms_shadow_hierarchical, "hierarchical", mr_create_hier, NULL);
