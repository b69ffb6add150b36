/* Visibility at caller-given points (microshadow/points.h, "Visibility at any points"): the driver ms_render
 * is for frames, without the camera. Points are grouped by proximity (30-bit Morton codes of their
 * positions in the points' bounding box) into batches of BATCH, and each batch goes through the shadow
 * method interface exactly as a frame tile does in frame_job.c: front masks (receiver.c), the method's
 * visible masks, V and S from ms_resolve_vs. A point's sample pattern is keyed like a pixel, so the same
 * receiver with the same key gets the same V and S as in a frame (test_points checks it bit for bit). */
#include "microshadow.h"
#include "core/abi.h"
#include "points.h"
#include "budget.h"
#include "light/pattern.h"
#include "light/light_shape.h"
#include "shadow/method.h"
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include "visibility/occluders.h"
#include "sun_place.h"
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BATCH 256              /* points per visibility call: a frame tile's 16 x 16 */

struct ms_accel {
    ms_bvh bvh;
    struct ms_alpha *alpha;    /* alpha-tested triangles, own copies of what they need (NULL: none) */
    uint32_t *leaf_of;         /* scene triangle index -> BVH leaf-order prim id */
    ms_scene view;             /* the scene's counts, light = lights[0] (tri = NULL: the BVH holds the triangles) */
    ms_light *lights;          /* copies of the scene's lights, each with its own texels */
    size_t n_lights;
    int threads;
    /* The scene's closed surfaces and their interior boxes (occluders.h), found once: each call keeps those
     * its light allows, for the methods that take them; the culled sets below are built from them. */
    ms_closed closed;
    ms_interior interior;
    double interior_eps;
    /* Per light of the scene, its occluders with the closed-component cull and the interior boxes (occluders.h),
     * built by the first call that needs them (accel_culled) and kept: frames cull by default for the methods
     * that gain (ms_shadow_method.occluders), and a bake calls once per light and row range. 0: not built; 1:
     * built; -1: out of memory when tried (the call goes without). */
    ms_occluders *culled;
    int8_t *culled_state;
};

const char *ms_status_name(ms_status s)
{
    switch (s) {
    case MS_OK: return "ok";
    case MS_ERR_INVALID: return "invalid argument";
    case MS_ERR_NO_MEMORY: return "out of memory";
    case MS_ERR_CANCELLED: return "cancelled";
    case MS_ERR_METHOD: return "method";
    case MS_ERR_IO: return "i/o";
    case MS_ERR_BUDGET: return "over the memory budget";
    }
    return "unknown status";
}

ms_status ms_accel_build_abi(const ms_abi *abi, const ms_scene *scene, int threads, ms_accel **out, char *err,
                             size_t errlen)
{
    const ms_status ast = ms_abi_check(abi, "ms_accel_build", err, errlen);
    if (ast) return ast;
    if (!out) { snprintf(err, errlen, "ms_accel_build: out is NULL"); return MS_ERR_INVALID; }
    *out = NULL;
    if (!scene) { snprintf(err, errlen, "ms_accel_build: no scene"); return MS_ERR_INVALID; }
    if (!scene->tri && scene->n_tris) {
        snprintf(err, errlen, "ms_accel_build: a procedural scene has no triangles in memory (only the streaming methods render it)");
        return MS_ERR_INVALID;
    }
    if (scene->n_tris >= UINT32_MAX) { snprintf(err, errlen, "ms_accel_build: more than 2^32-2 triangles"); return MS_ERR_INVALID; }
    {   /* No options here: the default budget (ms_memory_budget). */
        const uint64_t need = ms_accel_need(scene->n_tris), budget = ms_memory_budget(0);
        if (need > budget) {
            char nb[32], bb[32];
            ms_bytes_text(need, nb, sizeof nb);
            ms_bytes_text(budget, bb, sizeof bb);
            snprintf(err, errlen, "the acceleration structure over %zu triangles needs about %s but the default memory budget is %s (%d%% of "
                     "physical memory)", scene->n_tris, nb, bb, MS_MEMORY_DEFAULT_PERCENT);
            return MS_ERR_BUDGET;
        }
    }
    ms_accel *a = calloc(1, sizeof *a);
    if (!a) { snprintf(err, errlen, "out of memory"); return MS_ERR_NO_MEMORY; }
    a->threads = threads > 0 ? threads : omp_get_num_procs();
    if (ms_bvh_build(&a->bvh, scene->tri, scene->n_tris, a->threads)) {
        free(a);
        snprintf(err, errlen, "BVH build failed: out of memory");
        return MS_ERR_NO_MEMORY;
    }
    if (ms_alpha_build(scene, &a->bvh, &a->alpha)) { ms_accel_free(a); snprintf(err, errlen, "out of memory"); return MS_ERR_NO_MEMORY; }
    a->leaf_of = malloc((scene->n_tris ? scene->n_tris : 1) * sizeof *a->leaf_of);
    if (!a->leaf_of) { ms_accel_free(a); snprintf(err, errlen, "out of memory"); return MS_ERR_NO_MEMORY; }
    for (uint32_t i = 0; i < a->bvh.n_tris; i++) a->leaf_of[a->bvh.tri_source[i]] = i;
    a->view = *scene;
    a->view.tri = NULL;
    a->view.lights = NULL;   /* the caller's array: the accel keeps its own copies in a->lights */
    a->view.n_lights = 0;
    /* Every light of the scene, with its own copy of any texels: the scene may be freed before the accel. */
    size_t nl;
    const ms_light *src = ms_scene_lights(scene, &nl);
    a->lights = calloc(nl, sizeof *a->lights);
    if (!a->lights) { ms_accel_free(a); snprintf(err, errlen, "out of memory"); return MS_ERR_NO_MEMORY; }
    a->n_lights = nl;
    a->culled = calloc(nl ? nl : 1, sizeof *a->culled);
    a->culled_state = calloc(nl ? nl : 1, sizeof *a->culled_state);
    if (!a->culled || !a->culled_state) { ms_accel_free(a); snprintf(err, errlen, "out of memory"); return MS_ERR_NO_MEMORY; }
    for (size_t l = 0; l < nl; l++) {
        a->lights[l] = src[l];
        a->lights[l].texture = NULL;
        if (!src[l].texture) continue;
        const size_t nt = (size_t)src[l].texture_width * (size_t)src[l].texture_height * 3;
        float *t = malloc(nt * sizeof *t);
        if (!t) { ms_accel_free(a); snprintf(err, errlen, "out of memory"); return MS_ERR_NO_MEMORY; }
        memcpy(t, src[l].texture, nt * sizeof *t);
        a->lights[l].texture = t;
    }
    float sbox[6];
    ms_scene_tri_box(scene, &a->bvh, sbox);
    for (size_t l = 0; l < nl; l++) ms_light_sun_place(&a->lights[l], sbox);   /* the interior clearance's lights */
    a->view.light = a->lights[0];
    if (scene->n_tris && (ms_closed_find(scene->tri, scene->n_tris, &a->closed) ||
                          ms_interior_find(scene->tri, scene->n_tris, &a->closed, MS_INTERIOR_RES_SILHOUETTE, MS_INTERIOR_MIN_TRIS,
                                           a->interior_eps = ms_interior_clearance(&a->bvh, a->lights, a->n_lights),
                                           a->threads, &a->interior))) {
        ms_accel_free(a);
        snprintf(err, errlen, "out of memory");
        return MS_ERR_NO_MEMORY;
    }
    *out = a;
    return MS_OK;
}

void ms_accel_free(ms_accel *a)
{
    if (!a) return;
    ms_bvh_free(&a->bvh);
    ms_alpha_free(a->alpha);
    free(a->leaf_of);
    ms_closed_free(&a->closed);
    ms_interior_free(&a->interior);
    for (size_t l = 0; a->culled && a->culled_state && l < a->n_lights; l++)
        if (a->culled_state[l] == 1) ms_occluders_free(&a->culled[l]);
    free(a->culled);
    free(a->culled_state);
    for (size_t l = 0; a->lights && l < a->n_lights; l++) free((void *)a->lights[l].texture);
    free(a->lights);
    free(a);
}

size_t ms_accel_triangles(const ms_accel *a) { return a ? a->view.n_tris : 0; }

const ms_light *ms_accel_lights(const ms_accel *a, size_t *n)
{
    *n = a ? a->n_lights : 0;
    return a ? a->lights : NULL;
}

/* Spreads the low 10 bits of x to every third bit. */
static uint32_t spread3(uint32_t x)
{
    x &= 0x3ff;
    x = (x | (x << 16)) & 0x030000ff;
    x = (x | (x << 8)) & 0x0300f00f;
    x = (x | (x << 4)) & 0x030c30c3;
    x = (x | (x << 2)) & 0x09249249;
    return x;
}

typedef struct morton_item { uint32_t code; size_t index; } morton_item;

static int cmp_morton(const void *a, const void *b)
{
    const morton_item *x = a, *y = b;
    if (x->code != y->code) return x->code < y->code ? -1 : 1;
    return (x->index > y->index) - (x->index < y->index);
}

static int finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

/* Checks the arguments that do not need the method; MS_OK or MS_ERR_INVALID with a message. */
static ms_status check_points(const ms_accel *a, const ms_points *pts, char *err, size_t errlen)
{
    if (!pts || (pts->n && (!pts->position || !pts->normal))) {
        snprintf(err, errlen, "ms_visibility_points: positions and normals are required");
        return MS_ERR_INVALID;
    }
    for (size_t i = 0; i < pts->n; i++) {
        const float *p = pts->position + 3 * i, *n = pts->normal + 3 * i;
        if (!finite3(p)) { snprintf(err, errlen, "point %zu: position is NaN or infinite", i); return MS_ERR_INVALID; }
        if (!finite3(n) || !(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0.0f)) {
            snprintf(err, errlen, "point %zu: normal is zero, NaN or infinite", i);
            return MS_ERR_INVALID;
        }
        if (pts->triangle && pts->triangle[i] != MS_NO_TRIANGLE && pts->triangle[i] >= a->view.n_tris) {
            snprintf(err, errlen, "point %zu: triangle %u is not in the scene (%zu triangles)", i,
                     pts->triangle[i], a->view.n_tris);
            return MS_ERR_INVALID;
        }
    }
    return MS_OK;
}

/* The shadow query of point i: unit normal, leaf-order prim, pattern key. */
static void make_query(const ms_accel *a, const ms_points *pts, size_t i, ms_shadow_query *q)
{
    const float *p = pts->position + 3 * i, *n = pts->normal + 3 * i;
    const float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int c = 0; c < 3; c++) { q->p[c] = p[c]; q->n[c] = n[c] / len; }
    const uint32_t t = pts->triangle ? pts->triangle[i] : MS_NO_TRIANGLE;
    q->prim = t == MS_NO_TRIANGLE ? UINT32_MAX : a->leaf_of[t];
    if (pts->key) { q->px = pts->key[2 * i]; q->py = pts->key[2 * i + 1]; }
    else { q->px = (uint32_t)i; q->py = (uint32_t)((uint64_t)i >> 32); }
}

void ms_accel_origin(const ms_accel *a, double origin[3])
{
    for (int c = 0; c < 3; c++) origin[c] = a ? a->view.origin[c] : 0.0;
}

ms_status ms_visibility_points_abi(const ms_abi *abi, const ms_accel *a, const ms_light *light, const ms_points *pts,
                                   const ms_points_options *opt, float *vis, float *shadow, uint16_t *front_out,
                                   ms_stats *stats, char *err, size_t errlen)
{
    const ms_status ast = ms_abi_check(abi, "ms_visibility_points", err, errlen);
    if (ast) return ast;
    ms_points_options own;
    opt = ms_abi_options(opt, MS_ABI_SIZE(abi, points_options), &own, sizeof own);
    /* World positions into the scene's frame (scene_frame.c): subtracted in double, which is exact for points
     * near the geometry (the origin is a multiple of a power of two above the floats' spacing there). */
    if (!a || !pts || !pts->position || !pts->n ||
        (a->view.origin[0] == 0.0 && a->view.origin[1] == 0.0 && a->view.origin[2] == 0.0))
        return ms_visibility_points_local(a, light, pts, opt, vis, shadow, front_out, stats, err, errlen);
    if (stats) memset(stats, 0, sizeof *stats);
    float *local = malloc(pts->n * 3 * sizeof *local);
    if (!local) { snprintf(err, errlen, "out of memory for %zu points", pts->n); return MS_ERR_NO_MEMORY; }
    for (size_t i = 0; i < 3 * pts->n; i++) local[i] = (float)((double)pts->position[i] - a->view.origin[i % 3]);
    ms_points lp = *pts;
    lp.position = local;
    const ms_status st = ms_visibility_points_local(a, light, &lp, opt, vis, shadow, front_out, stats, err, errlen);
    free(local);
    return st;
}

/* The method of the options (MS_AUTO_METHOD resolved), and the buffer side k of their samples, checked against
 * the pattern (points take the grid and stratified patterns at 256, 1024 or 4096 samples). */
static ms_status points_method(const ms_points_options *opt, const ms_shadow_method **sm_out, int *k_out, char *err,
                               size_t errlen)
{
    const char *method = opt->method ? opt->method : MS_DEFAULT_METHOD;
    if (strcmp(method, MS_AUTO_METHOD) == 0) method = ms_auto_method(opt->pattern);
    const ms_shadow_method *sm = ms_find_shadow_method(method);
    if (!sm) {
        if (ms_method_available(method) < 0) snprintf(err, errlen, "method '%s' is not compiled into this build", method);
        else snprintf(err, errlen, "unknown method '%s'", method);
        return MS_ERR_METHOD;
    }
    const int samples = opt->samples > 0 ? opt->samples : MS_SAMPLES_DEFAULT;
    /* 256, 1024 or 4096 for either pattern here (16 and 64 are for frames of stratified ray tracing) */
    const int k = ms_pattern_samples_per_pixel(MS_PATTERN_GRID, samples) ? ms_samples_to_k(samples) : 0;
    if (!k) { snprintf(err, errlen, "samples must be 256, 1024 or 4096 (got %d)", samples); return MS_ERR_INVALID; }
    if (opt->pattern == MS_PATTERN_INTERLEAVED) {
        snprintf(err, errlen, "the interleaved pattern needs pixels (4x4 blocks): frames only, not points");
        return MS_ERR_INVALID;
    }
    if (opt->pattern != MS_PATTERN_GRID && opt->pattern != MS_PATTERN_STRATIFIED) {
        snprintf(err, errlen, "unknown pattern %d", (int)opt->pattern);
        return MS_ERR_INVALID;
    }
    if (sm->needs_grid && opt->pattern != MS_PATTERN_GRID) {
        snprintf(err, errlen, "method '%s' needs the grid pattern", sm->name);
        return MS_ERR_INVALID;
    }
    *sm_out = sm;
    *k_out = k;
    return MS_OK;
}

/* The points in proximity order: Morton codes in their bounding box, ties by index (a total order). A malloc'ed
 * array of pts->n, NULL when out of memory. */
static morton_item *proximity_order(const ms_points *pts)
{
    const size_t n = pts->n;
    morton_item *order = malloc((n ? n : 1) * sizeof *order);
    if (!order) return NULL;
    float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            const float v = pts->position[3 * i + c];
            lo[c] = v < lo[c] ? v : lo[c];
            hi[c] = v > hi[c] ? v : hi[c];
        }
    for (size_t i = 0; i < n; i++) {
        uint32_t cell[3];
        for (int c = 0; c < 3; c++) {
            const double ext = (double)hi[c] - (double)lo[c];
            const double u = ext > 0.0 ? ((double)pts->position[3 * i + c] - (double)lo[c]) / ext : 0.0;
            cell[c] = (uint32_t)fmin(u * 1024.0, 1023.0);
        }
        order[i].code = spread3(cell[0]) | spread3(cell[1]) << 1 | spread3(cell[2]) << 2;
        order[i].index = i;
    }
    qsort(order, n, sizeof *order, cmp_morton);
    return order;
}

/* What every batch of one call shares, read-only while the batches run. */
typedef struct points_run {
    const ms_accel *a;
    const ms_points *pts;
    const morton_item *order;
    const ms_shadow_method *sm;
    void *sstate;
    const ms_render_ctx *ctx, *bctx;   /* the call's context; the batch's when each query has its own outline */
    void *istate;                      /* a method that does not rasterize the interior boxes itself (MS_OCC_INTERIOR_PASS):
                                        * its state over the boxes, run first as frames do (frame_job_shadow.c); NULL: none */
    const ms_render_ctx *ictx;
    const ms_light_shape_ops *shape;
    int outlined, batched;             /* a per-receiver light (the shape's outline); the method takes it by batch */
    size_t mw;
    float *vis, *shadow;
    uint16_t *front_out;
} points_run;

/* The points [i0, i1) of the proximity order, as a frame tile (frame_job.c): their queries and front masks, the
 * method's visible masks, V and S. A sphere or a sun: each point has its own light, the shape's outline seen
 * from it, and the method takes the batch with each point's outline (.outlines) or is called one point at a
 * time with it, exactly as frames do; a point inside a sphere has no sample in front (V = S = 0). Scratch: fm,
 * vm, im (BATCH masks each; im only with r->istate), spts (a pixel's samples, stratified patterns only), q
 * (BATCH queries). Adds to the thread's counters, segments, penumbra points and resolve seconds. 0, or -1 when
 * the method failed. */
static int points_batch(const points_run *r, size_t i0, size_t i1, uint64_t *fm, uint64_t *vm, uint64_t *im, float *spts,
                        ms_shadow_query *q, uint64_t *counters, uint64_t *segments, uint64_t *penumbra, double *resolve_s)
{
    const int m = (int)(i1 - i0);
    ms_render_ctx qc = *r->ctx;
    int nq = 0;
    size_t where[BATCH];
    for (int j = 0; j < m; j++) {
        const size_t i = r->order[i0 + j].index;
        make_query(r->a, r->pts, i, &q[nq]);
        q[nq].prim = ms_ctx_skip_prim(r->ctx, q[nq].prim);   /* its own triangle in the occluders' numbering */
        if (r->outlined && r->shape->outline(&r->ctx->light, q[nq].p, &qc.light)) {
            if (r->front_out) r->front_out[i] = 0;
            if (r->vis) r->vis[i] = 0.0f;
            if (r->shadow) r->shadow[i] = 0.0f;
            continue;
        }
        if (spts) ms_pattern_points(r->ctx->pattern, &qc.light, r->ctx->k, q[nq].px, q[nq].py, r->ctx->seed, spts);
        const int nf = ms_front_mask(&qc, &q[nq], spts, fm + (size_t)nq * r->mw);
        if (r->front_out) r->front_out[i] = (uint16_t)nf;
        *segments += (uint64_t)nf;
        where[nq++] = i;
    }
    int vfail = 0;
    if (r->istate && nq) {
        /* The interior boxes first (no receiver on them: no prim to skip), then the triangles with the samples
         * they left. */
        uint32_t prim[BATCH];
        for (int j = 0; j < nq; j++) { prim[j] = q[j].prim; q[j].prim = UINT32_MAX; }
        vfail = r->sm->visibility(r->istate, r->ictx, q, nq, fm, im, counters);
        for (int j = 0; j < nq; j++) q[j].prim = prim[j];
        vfail = vfail || r->sm->visibility(r->sstate, r->ctx, q, nq, im, vm, counters);
    } else if (!r->outlined || r->batched)
        vfail = nq && r->sm->visibility(r->sstate, r->batched ? r->bctx : r->ctx, q, nq, fm, vm, counters);
    else
        for (int j = 0; j < nq && !vfail; j++) {
            r->shape->outline(&r->ctx->light, q[j].p, &qc.light);
            vfail = r->sm->visibility(r->sstate, &qc, &q[j], 1, fm + (size_t)j * r->mw, vm + (size_t)j * r->mw, counters);
        }
    if (vfail) return -1;
    const double tr = omp_get_wtime();
    for (int j = 0; j < nq; j++) {
        const size_t i = where[j];
        float v, s;
        if (r->outlined) r->shape->outline(&r->ctx->light, q[j].p, &qc.light);
        if (spts) ms_pattern_points(r->ctx->pattern, &qc.light, r->ctx->k, q[j].px, q[j].py, r->ctx->seed, spts);
        *penumbra += (uint64_t)ms_resolve_vs(&qc, &q[j], spts, fm + (size_t)j * r->mw, vm + (size_t)j * r->mw, &v, &s);
        if (r->vis) r->vis[i] = v;
        if (r->shadow) r->shadow[i] = s;
    }
    *resolve_s += omp_get_wtime() - tr;
    return 0;
}

/* What the batches of a call add up: the method's counters, penumbra points, segments, resolve thread-seconds,
 * and whether the progress callback cancelled. */
typedef struct points_sums {
    uint64_t *counters;
    uint64_t penumbra, segments;
    double resolve_thread_s;
    int cancelled;
} points_sums;

/* Every batch of the n points of run on `threads` threads (OpenMP, dynamic: costs vary), with the progress
 * callback of opt after each; sums into *sums. 0, or 1 when out of memory or the method failed. */
static int points_batches(const points_run *run, size_t n, int threads, const ms_points_options *opt, points_sums *sums)
{
    const ms_render_ctx *ctx = run->ctx;
    const long nbatch = (long)((n + BATCH - 1) / BATCH);
    const size_t mw = run->mw;
    const int stratified = ctx->pattern != MS_PATTERN_GRID;
    long done = 0;
    int failed = 0, cancelled = 0;
#pragma omp parallel num_threads(threads)
    {
        uint64_t local[MS_MAX_COUNTERS] = { 0 };
        uint64_t local_penumbra = 0, local_segments = 0;
        double local_resolve = 0.0;
        uint64_t *fm = aligned_alloc(64, BATCH * mw * sizeof *fm);
        uint64_t *vm = aligned_alloc(64, BATCH * mw * sizeof *vm);
        uint64_t *im = run->istate ? aligned_alloc(64, BATCH * mw * sizeof *im) : NULL;
        float *spts = stratified ? malloc((size_t)ctx->samples * 3 * sizeof *spts) : NULL;
        ms_shadow_query *q = malloc(BATCH * sizeof *q);
        int ok = fm && vm && q && (spts || !stratified) && (im || !run->istate);
        if (!ok) {
#pragma omp atomic write
            failed = 1;
        }
#pragma omp for schedule(dynamic, 1)
        for (long b = 0; b < nbatch; b++) {
            int stop;
#pragma omp atomic read
            stop = cancelled;
            if (!ok || stop) continue;
            const size_t i0 = (size_t)b * BATCH, i1 = i0 + BATCH < n ? i0 + BATCH : n;
            if (points_batch(run, i0, i1, fm, vm, im, spts, q, local, &local_segments, &local_penumbra, &local_resolve)) {
                ok = 0;
#pragma omp atomic write
                failed = 1;
                continue;
            }
            if (opt->progress) {
                /* One caller at a time; its answer stops the remaining batches. */
#pragma omp critical(ms_points_progress)
                {
                    done++;
                    if (!cancelled && opt->progress(opt->progress_user, (double)done / (double)nbatch)) {
#pragma omp atomic write
                        cancelled = 1;
                    }
                }
            }
        }
        free(fm);
        free(vm);
        free(im);
        free(spts);
        free(q);
#pragma omp critical(ms_points_counters)
        {
            for (int c = 0; c < MS_MAX_COUNTERS; c++) sums->counters[c] += local[c];
            sums->penumbra += local_penumbra;
            sums->segments += local_segments;
            sums->resolve_thread_s += local_resolve;
        }
    }
    sums->cancelled = cancelled;
    return failed;
}

/* What a call measured: the timings and the counters summed over the threads. */
typedef struct points_tally {
    double setup_s, shadow_s, resolve_thread_s, t_start;
    uint64_t interior_boxes, occluders_culled, penumbra, segments;
    const uint64_t *counters;
    ms_isa kisa, tisa;
} points_tally;

/* The stats of a call: the accel's, the method's, and what it measured. */
static void points_stats(const ms_accel *a, const ms_shadow_method *sm, const ms_render_ctx *ctx, size_t n, int threads,
                         uint64_t budget, const points_tally *t, ms_stats *stats)
{
    const int stratified = ctx->pattern != MS_PATTERN_GRID;
    const size_t mw = (size_t)ctx->mask_words;
    stats->triangles = a->view.n_tris;
    stats->build_s = a->bvh.build_s;
    stats->setup_s = t->setup_s;
    stats->shadow_s = t->shadow_s;
    stats->interior_boxes = t->interior_boxes;
    stats->occluders_culled = t->occluders_culled;
    stats->samples = ctx->samples;
    stats->samples_per_pixel = ctx->samples;   /* every point gets all N (no interleaving here) */
    stats->threads = threads;
    stats->method = sm->name;
    stats->pattern = stratified ? "stratified" : "grid";
    stats->kernel_isa = t->kisa == MS_ISA_AUTO ? "none" : ms_isa_name(t->kisa);
    stats->traversal_isa = t->tisa == MS_ISA_AUTO ? "none" : ms_isa_name(t->tisa);
    stats->visible_pixels = n;
    stats->penumbra_pixels = t->penumbra;
    stats->shadow_rays = t->segments;
    stats->shadow_factor_s = t->resolve_thread_s / threads;
    stats->n_counters = sm->n_counters;
    for (int c = 0; c < sm->n_counters; c++) { stats->counter_name[c] = sm->counter_names[c]; stats->counter[c] = t->counters[c]; }
    stats->memory_need = ms_points_need(n, a->view.n_tris, sm->visibility_all != NULL, (int)mw, threads, NULL);
    stats->memory_budget = budget;
    stats->total_s = omp_get_wtime() - t->t_start;
}

/* A NaN or infinite V or S (geometry the form-factor weights overflow on) is an error naming the point. */
static ms_status points_finite(size_t n, const float *vis, const float *shadow, char *err, size_t errlen)
{
    for (size_t i = 0; i < n; i++)
        if ((vis && !isfinite(vis[i])) || (shadow && !isfinite(shadow[i]))) {
            snprintf(err, errlen, "point %zu: %s is %s (a NaN or infinite result is an error)", i,
                     vis && !isfinite(vis[i]) ? "V" : "S", isnan(vis && !isfinite(vis[i]) ? vis[i] : shadow[i]) ? "NaN" : "infinite");
            return MS_ERR_INVALID;
        }
    return MS_OK;
}

/* The light a call answers for: light, or the accel's scene's first (NULL), checked; a sun placed for the
 * accel's scene as frames place it (sun_place.h), whatever distance the caller's holds. */
static ms_status points_light(const ms_accel *a, const ms_light *light, ms_light *placed, char *err, size_t errlen)
{
    if (!light) light = &a->view.light;
    if (!ms_light_shape_of(light->shape)) { snprintf(err, errlen, "unknown light shape %d", (int)light->shape); return MS_ERR_INVALID; }
    if (!ms_light_finite(light)) { snprintf(err, errlen, "light has a NaN or infinite value, or zero area (a sphere: radius not > 0)"); return MS_ERR_INVALID; }
    *placed = *light;
    float sbox[6];
    ms_scene_tri_box(&a->view, &a->bvh, sbox);
    ms_light_sun_place(placed, sbox);
    return MS_OK;
}

/* The interior boxes of the accel's closed surfaces that the light allows (occluders.h) into occ, and ctx's
 * interior fields pointing at them where there are any (ms_occluders_ctx: occ holds nothing else, so the scene's
 * BVH stays). 0, or -1 when out of memory. */
static int points_interior(const ms_accel *a, const ms_scene *view, const ms_light *light, int threads, ms_occluders *occ,
                           ms_render_ctx *ctx)
{
    if (ms_occluders_build(occ, view, &a->bvh, &a->closed, &a->interior, a->interior_eps, a->alpha, light, MS_OCC_INTERIOR,
                           threads))
        return -1;
    ms_occluders_ctx(occ, ctx);
    return 0;
}

/* The accel's triangles in scene order (it keeps them in the BVH's leaf order): a malloc'ed copy, NULL when out
 * of memory. */
static float *scene_order_tris(const ms_accel *a)
{
    float *tri = calloc(a->view.n_tris * 9, sizeof *tri);
    if (!tri) return NULL;
    for (uint32_t i = 0; i < a->bvh.n_tris; i++)
        memcpy(tri + 9 * (size_t)a->bvh.tri_source[i], a->bvh.tri + 9 * (size_t)i, 9 * sizeof *tri);
    return tri;
}

/* The accel's light that `light` (placed) is, by its geometry (shape, corner, edges, centre, radius: what its
 * occluders depend on); -1 when none is. */
static long accel_light_index(const ms_accel *a, const ms_light *light)
{
    for (size_t l = 0; l < a->n_lights; l++) {
        const ms_light *m = &a->lights[l];
        if (m->shape == light->shape && m->radius == light->radius &&
            !memcmp(&m->corner, &light->corner, sizeof m->corner) && !memcmp(&m->edge_s, &light->edge_s, sizeof m->edge_s) &&
            !memcmp(&m->edge_t, &light->edge_t, sizeof m->edge_t) && !memcmp(&m->center, &light->center, sizeof m->center))
            return (long)l;
    }
    return -1;
}

/* Light l's occluders with the closed-component cull and the interior boxes, as frames build them
 * (frame_job_create.c), made on first use and kept in the accel: NULL when building it would take the sets the
 * accel holds and the call's own need (call_need) past the budget, or when out of memory (the call then goes
 * without: the same answer). The accel is shared by the caller's threads: one builds, under the lock, and the
 * rest wait. */
static const ms_occluders *accel_culled(const ms_accel *ac, size_t l, int threads, uint64_t call_need, uint64_t budget)
{
    ms_accel *a = (ms_accel *)ac;   /* the cache only: built once, then read */
    const ms_occluders *o = NULL;
#pragma omp critical(ms_accel_culled)
    {
        size_t held = 0;
        for (size_t i = 0; i < a->n_lights; i++) held += a->culled_state[i] == 1;
        if (!a->culled_state[l] && call_need + ms_culled_sets_need(a->view.n_tris, held, 1) <= budget) {
            ms_scene view = a->view;
            float *tri = a->view.n_tris ? scene_order_tris(a) : NULL;
            view.tri = tri;
            a->culled_state[l] = (a->view.n_tris && !tri) ||
                                 ms_occluders_build(&a->culled[l], &view, &a->bvh, &a->closed, &a->interior, a->interior_eps,
                                                    a->alpha, &a->lights[l], MS_OCC_CULL | MS_OCC_INTERIOR, threads)
                                 ? -1 : 1;
            free(tri);
        }
        if (a->culled_state[l] == 1) o = &a->culled[l];
    }
    return o;
}

ms_status ms_visibility_points_local(const ms_accel *a, const ms_light *light, const ms_points *pts,
                                     const ms_points_options *opt_in, float *vis, float *shadow, uint16_t *front_out,
                                     ms_stats *stats, char *err, size_t errlen)
{
    const double t_start = omp_get_wtime();
    ms_points_options zero;
    memset(&zero, 0, sizeof zero);
    const ms_points_options *opt = opt_in ? opt_in : &zero;
    if (stats) memset(stats, 0, sizeof *stats);
    if (!a) { snprintf(err, errlen, "ms_visibility_points: no accel"); return MS_ERR_INVALID; }
    ms_light placed;
    ms_status st = points_light(a, light, &placed, err, errlen);
    if (st) return st;
    light = &placed;
    st = check_points(a, pts, err, errlen);
    if (st) return st;
    const ms_shadow_method *sm;
    int k;
    st = points_method(opt, &sm, &k, err, errlen);
    if (st) return st;
    const int threads = opt->threads > 0 ? opt->threads : omp_get_num_procs();
    const uint64_t budget = ms_memory_budget(opt->max_memory);
    if (ms_points_budget_check(pts->n, a->view.n_tris, sm->visibility_all != NULL, (k * k + 63) / 64, threads, budget, err,
                               errlen))
        return MS_ERR_BUDGET;

    /* The hpc methods (those with a frame-level entry) read the scene's triangles in scene order
     * (hpc_method.c), which the accel keeps only in the BVH's leaf order: a scene-order copy for this call. */
    ms_scene view = a->view;
    float *scene_tri = NULL;
    if (sm->visibility_all && a->view.n_tris) {
        if (!(scene_tri = scene_order_tris(a))) {
            snprintf(err, errlen, "out of memory for the triangles of method '%s'", sm->name);
            return MS_ERR_NO_MEMORY;
        }
        view.tri = scene_tri;
    }
    ms_render_ctx ctx;   /* the frames' context (ms_render_ctx_init), so points answer as frames do */
    ms_render_ctx_init(&ctx, &view, &a->bvh, light, opt->pattern, k, opt->seed, threads);
    ctx.alpha = a->alpha;
    ctx.isa_cap = opt->isa;
    ctx.embree_mode = opt->embree_mode;
    ctx.embree_filter = opt->embree_filter;
    ctx.queries_in_order = 1;   /* Morton order: block methods group consecutive points */
    const ms_light_shape_ops *shape = ms_light_shape_of(light->shape);
    const int outlined = shape && shape->outline;   /* a per-receiver light: the shape's outline (light_shape.h) */
    const int batched = outlined && sm->outlines;    /* ... which the method takes a batch at a time (frame_job.c) */
    ms_render_ctx bctx;   /* the batch's context then: each query's light its outline (ms_ctx_for_query) */

    const size_t n = pts->n;
    morton_item *order = proximity_order(pts);
    if (!order) { free(scene_tri); snprintf(err, errlen, "out of memory for %zu points", n); return MS_ERR_NO_MEMORY; }

    void *sstate = NULL;
    const double t_setup = omp_get_wtime();
    ms_occluders occ = { 0 };
    /* The occluders frames use by default: for a method that culls closed meshes by default and takes the
     * interior boxes (and the queries one batch at a time), a light of the scene gets the accel's culled set
     * with its boxes; otherwise the scene's triangles, with the interior boxes this light allows. */
    const long li = (sm->occluders & MS_OCC_CULL_BY_DEFAULT) && (sm->occluders & MS_OCC_INTERIOR) && !sm->visibility_all &&
                    ms_closed_groups(&a->closed) ? accel_light_index(a, light) : -1;
    const uint64_t call_need = ms_points_need(pts->n, a->view.n_tris, sm->visibility_all != NULL, (k * k + 63) / 64, threads, NULL);
    const ms_occluders *culled = li >= 0 ? accel_culled(a, (size_t)li, threads, call_need, budget) : NULL;
    uint64_t occ_boxes = 0, occ_culled = 0;
    if (culled) {
        ms_occluders_ctx(culled, &ctx);
        occ_boxes = culled->interior_boxes;
        occ_culled = culled->culled;
    } else if ((sm->occluders & MS_OCC_INTERIOR) && a->interior.n_boxes && points_interior(a, &view, light, threads, &occ, &ctx)) {
        free(order);
        free(scene_tri);
        snprintf(err, errlen, "out of memory for the interior boxes");
        return MS_ERR_NO_MEMORY;
    } else {
        occ_boxes = occ.interior_boxes;
    }
    if (sm->create(&ctx, &sstate, err, errlen)) { ms_occluders_free(&occ); free(order); free(scene_tri); return MS_ERR_METHOD; }
    bctx = ctx;
    bctx.outline_per_query = 1;
    /* A method that leaves the interior boxes to the driver gets them in a pass of their own, as in frames
     * (frame_job_create.c: not for a per-receiver light). */
    void *istate = NULL;
    ms_render_ctx ictx;
    ms_ctx_interior_pass(&ctx, &ictx);
    if ((sm->occluders & MS_OCC_INTERIOR_PASS) && ctx.interior && !outlined) {
        if (sm->create(&ictx, &istate, err, errlen)) {
            sm->destroy(sstate);
            ms_occluders_free(&occ);
            free(order);
            free(scene_tri);
            return MS_ERR_METHOD;
        }
    }
    const double setup_s = omp_get_wtime() - t_setup;

    const size_t mw = (size_t)ctx.mask_words;
    uint64_t counters[MS_MAX_COUNTERS] = { 0 };
    points_sums sums = { counters, 0, 0, 0.0, 0 };
    const points_run run = { a, pts, order, sm, sstate, &ctx, &bctx, istate, &ictx, shape, outlined, batched, mw, vis, shadow,
                             front_out };
    const double t0 = omp_get_wtime();
    const int failed = points_batches(&run, n, threads, opt, &sums);
    const uint64_t penumbra = sums.penumbra, segments = sums.segments;
    const double resolve_thread_s = sums.resolve_thread_s;
    const int cancelled = sums.cancelled;
    const double t1 = omp_get_wtime();
    free(order);
    ms_isa kisa = MS_ISA_AUTO, tisa = MS_ISA_AUTO;
    if (sm->isa_used) sm->isa_used(sstate, &kisa, &tisa);
    sm->destroy(sstate);
    if (istate) sm->destroy(istate);
    ms_occluders_free(&occ);
    free(scene_tri);
    if (failed) { snprintf(err, errlen, "out of memory in the shadow phase of method '%s'", sm->name); return MS_ERR_NO_MEMORY; }
    if (cancelled) { snprintf(err, errlen, "cancelled by the progress callback"); return MS_ERR_CANCELLED; }
    st = points_finite(n, vis, shadow, err, errlen);
    if (st) return st;
    if (stats) {
        const points_tally t = { setup_s, t1 - t0, resolve_thread_s, t_start, occ_boxes, occ_culled, penumbra, segments, counters,
                                 kisa, tisa };
        points_stats(a, sm, &ctx, n, threads, budget, &t, stats);
    }
    return MS_OK;
}
