/* Methods "hpc" and "hpc-scanline" (hpc.c): hierarchical penumbra casting over the whole frame at once,
 * through the method interface's frame-level entry (visibility_all, method.h). The triangles are those of
 * ctx->bvh, read in coarse area order (hpc_sort.c) from its leaf-order triangle array, each named by its
 * leaf index (the prim id); the BVH's hierarchy is not used for shadows. With the light's occluders
 * (MS_OCC_CULL, on by default: visibility/occluders.h, docs/culling.md) ctx->bvh holds the scene's
 * triangles less those of closed components that face away from the whole light, which provably decide no
 * segment (same V and S); the driver names a receiver's own triangle in that set (ms_ctx_skip_prim). The
 * paper has no such cull; on closed bars it removes nearly half the triangles and a third of the time. hpc also takes the occluders' merge of coplanar rectangles (MS_OCC_MERGE,
 * accel/coplanar.h: the same points; with MS_OCC_MERGE_EXACT each sample on a set that decides it as the pieces
 * do, render/exact_split.c), as the micro-raster methods
 * and mft do: the bars' faces, 32 segments each, become one rectangle, and the cost per pair, which bounds
 * hpc, is paid 30 times less often. The receivers on
 * merged faces that the merge could answer otherwise are answered over the scene's own triangles by a second
 * call (shadow_frame.c); hpc-scanline keeps the triangles as they are. A procedural scene is streamed:
 * generated batch by batch, its primary hits from the depth pass (primary_depth.c), no BVH at all, no cull.
 * The per-tile entry runs the same algorithm over the tile's points, for callers that drive methods per tile. */
#include "hpc.h"
#include "visibility/receiver.h"
#include "visibility/occluders.h"
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct hpc_state {
    int scanline;
    ms_raster_fn raster;
    ms_isa kernel_isa;
    ms_isa cast_isa;      /* the engine's instance (hpc.c) */
    uint32_t *order;      /* ctx->bvh's triangles (leaf order) in area order */
    double sort_s;        /* the coarse sort of the scene's triangles, done once in create */
} hpc_state;

typedef struct soup_source {
    const ms_render_ctx *ctx;
    const hpc_state *s;
    size_t pos;
    double sort_s;        /* procedural: the batches' sorts */
} soup_source;

static int soup_rewind(void *user) { ((soup_source *)user)->pos = 0; return 0; }

/* A procedural scene, generated batch by batch (in parallel) and bucketed by area within each batch: the
 * paper buckets the whole stream out of core into files; a batch is all we hold. ids: the triangle index,
 * as the depth pass names hits. */
static size_t procedural_next(void *user, float *tri, uint32_t *ids, size_t max)
{
    soup_source *src = user;
    const ms_scene *sc = src->ctx->scene;
    const size_t n = sc->n_tris - src->pos < max ? sc->n_tris - src->pos : max;
    if (!n) return 0;
    float *raw = malloc(n * 9 * sizeof *raw);
    if (!raw) return (size_t)-1;
    const int threads = src->ctx->threads > 0 ? src->ctx->threads : 1;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t c = 0; c < n; c += 1024) ms_procedural_triangles(sc, src->pos + c, n - c < 1024 ? n - c : 1024, raw + 9 * c);
    const double t0 = omp_get_wtime();
    uint32_t *order = ms_hpc_area_order(raw, n);
    if (order && MS_HOOK(ms_hpc_switches & MS_HPC_OFF_SORT))
        for (size_t i = 0; i < n; i++) order[i] = (uint32_t)i;
    src->sort_s += omp_get_wtime() - t0;
    if (!order) { free(raw); return (size_t)-1; }
    for (size_t i = 0; i < n; i++) {
        memcpy(tri + 9 * i, raw + 9 * (size_t)order[i], 9 * sizeof *tri);
        ids[i] = (uint32_t)(src->pos + order[i]);
    }
    free(order);
    free(raw);
    src->pos += n;
    return n;
}

static size_t soup_next(void *user, float *tri, uint32_t *ids, size_t max)
{
    soup_source *src = user;
    const ms_bvh *b = src->ctx->bvh;
    size_t n = 0;
    for (; n < max && src->pos < b->n_tris; n++, src->pos++) {
        const uint32_t i = src->s->order[src->pos];
        memcpy(tri + 9 * n, b->tri + 9 * (size_t)i, 9 * sizeof *tri);
        ids[n] = i;
    }
    return n;
}

static int hpc_create_common(const ms_render_ctx *ctx, void **state, char *err, size_t errlen, int scanline)
{
    hpc_state *s = calloc(1, sizeof *s);
    if (!s) { snprintf(err, errlen, "out of memory"); return -1; }
    s->scanline = scanline;
    if (!ms_hpc_cast_select(ctx->isa_cap, &s->cast_isa)) s->cast_isa = MS_ISA_AUTO;
    if (scanline && !(s->raster = ms_raster_kernel(MS_KERNEL_SCANLINE, ctx->k, ctx->isa_cap, &s->kernel_isa))) {
        free(s);
        snprintf(err, errlen, "no Scanline kernel for %d samples", ctx->samples);
        return -1;
    }
    if (ctx->scene->procedural.type != MS_PROCEDURAL_NONE) { *state = s; return 0; }   /* streamed */
    const size_t n = ctx->bvh->n_tris;
    const double t0 = omp_get_wtime();
    s->order = ms_hpc_area_order(ctx->bvh->tri, n);
    if (s->order && MS_HOOK(ms_hpc_switches & MS_HPC_OFF_SORT))   /* measuring: the scene's own order */
        for (size_t i = 0; i < n; i++) s->order[i] = (uint32_t)i;
    s->sort_s = omp_get_wtime() - t0;
    if (!s->order) {
        free(s);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    *state = s;
    return 0;
}

static int hpc_create(const ms_render_ctx *c, void **s, char *e, size_t n) { return hpc_create_common(c, s, e, n, 0); }
static int hpcs_create(const ms_render_ctx *c, void **s, char *e, size_t n) { return hpc_create_common(c, s, e, n, 1); }

static int hpc_cast_all(const hpc_state *s, const ms_render_ctx *ctx, const ms_shadow_query *q, size_t n,
                        const uint64_t *front, uint64_t *vis, uint64_t *counters, double *sort_s)
{
    soup_source ss = { ctx, s, 0, 0.0 };
    const int streamed = ctx->scene->procedural.type != MS_PROCEDURAL_NONE;
    const hpc_source src = { &ss, soup_rewind, streamed ? procedural_next : soup_next, streamed ? 0 : ctx->bvh->n_tris };
    const int rc = ms_hpc_cast(ctx, s->scanline, s->raster, q, n, front, vis, &src, counters);
    *sort_s = ss.sort_s;
    return rc;
}

/* The frame: the sort counter holds create's sort of the scene, or the streamed batches' sorts. */
static int hpc_all(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, size_t n, const uint64_t *front,
                   uint64_t *vis, uint64_t *counters)
{
    const hpc_state *s = state;
    double sort_s;
    const int rc = hpc_cast_all(s, ctx, q, n, front, vis, counters, &sort_s);
    counters[HPC_COUNTER_SORT_US] += (uint64_t)((s->sort_s + sort_s) * 1e6);
    return rc;
}

static int hpc_tile(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, int n, const uint64_t *front,
                    uint64_t *vis, uint64_t *counters)
{
    ms_render_ctx one = *ctx;
    one.threads = 1;      /* called from the renderer's threads */
    double sort_s;
    return hpc_cast_all(state, &one, q, (size_t)n, front, vis, counters, &sort_s);
}

static void hpc_destroy(void *state)
{
    hpc_state *s = state;
    if (!s) return;
    free(s->order);
    free(s);
}

static void hpc_isa_used(const void *state, ms_isa *kernel, ms_isa *traversal)
{
    const hpc_state *s = state;
    *kernel = s->scanline ? s->kernel_isa : s->cast_isa;
    *traversal = s->cast_isa;
}

#define HPC_COUNTER_NAMES                                                                              \
    { "triangles", "triangle_chunk_passes", "node_visits", "nodes_outside_vl", "umbra_node_skips",     \
      "plane_tests", "group_volume_sets_built", "point_tests", "group_point_tests", "sample_tests",     \
      "samples_blocked", "masks_allocated", "masks_peak_sum_over_chunks", "rebuilds",                  \
      "full_umbra_points", "raster_calls", "sort_us", "build_us", "rebuild_thread_us", "cast_us",      \
      "sample_bytes", "hierarchy_bytes", "mask_bytes", "pairs_in_vl",  \
      "pairs_footprint", "leaf_culls", "leaf_culls_blocked", "rect_pairs", "samples_sure",          \
      "leaf_lane_tests", "samples_t_sure" }

const ms_shadow_method ms_shadow_hpc = {
    .name = "hpc", .primary = "bvh", .needs_grid = 1, .streams = 1,
    .occluders = MS_OCC_CULL | MS_OCC_CULL_BY_DEFAULT | MS_OCC_MERGE | MS_OCC_MERGE_EXACT,
    .n_counters = HPC_N_COUNTERS,
    .counter_names = HPC_COUNTER_NAMES,
    .create = hpc_create, .visibility = hpc_tile, .visibility_all = hpc_all, .split_exact = 1, .destroy = hpc_destroy,
    .isa_used = hpc_isa_used,
};

const ms_shadow_method ms_shadow_hpc_scanline = {
    .name = "hpc-scanline", .primary = "bvh", .needs_grid = 1, .streams = 1,
    .occluders = MS_OCC_CULL | MS_OCC_CULL_BY_DEFAULT, .n_counters = HPC_N_COUNTERS,
    .counter_names = HPC_COUNTER_NAMES,
    .create = hpcs_create, .visibility = hpc_tile, .visibility_all = hpc_all, .destroy = hpc_destroy,
    .isa_used = hpc_isa_used,
};
