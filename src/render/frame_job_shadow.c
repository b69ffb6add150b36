/* A frame job's shadow phase for one light (frame_job.h): per tile the queries and their front masks, the
 * method's visible masks (on the sets exact for each sample when the light's merge asks), V, S and S_spec; or
 * the method's frame-level entry. */

#include "frame_job.h"
#include "core/abi.h"
#include "light/pattern.h"
#include "light/light_shape.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include "visibility/occluders.h"
#include "frame_shade.h"
#include "shadow_frame.h"
#include "exact_split.h"
#include "shade.h"
#include "render_materialise.h"
#include "interleave_filter.h"
#include "budget.h"
#include "frame_stream.h"
#include "frame_aa.h"
#include "sun_place.h"
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Moves the queries whose receiver lies on a merged coplanar face (ctx->prim_merged; their prims in the
 * scene's BVH b: hits[where[i]].prim) where the merged faces could answer otherwise than the scene's own
 * triangles (ms_merged_receiver_ok: a grazing segment meeting its own plane beyond the near range; for the light
 * as a whole, then, with pts (3 * ctx->samples floats of scratch; NULL: not), for the receiver's own samples in
 * front) after the others, with their front masks and pixels (ms_queries_move_last); returns how many come
 * first. */
static int merged_last(const ms_render_ctx *ctx, const ms_bvh *b, const ms_hit *hits, const float (*hull)[3], int n_hull,
                       ms_shadow_query *q, size_t *where, uint64_t *front, size_t mw, int nq, float *pts)
{
    uint8_t last[TILE * TILE];
    for (int i = 0; i < nq; i++) {
        const uint32_t own = hits[where[i]].prim;
        const float *tri = b->tri + 9 * (size_t)own;
        last[i] = ctx->prim_merged[own] && !ms_merged_receiver_ok(tri, q[i].p, hull, n_hull);
        if (last[i] && pts) {
            ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, q[i].px, q[i].py, ctx->seed, pts);
            last[i] = !ms_merged_receiver_ok_samples(tri, q[i].p, pts, front + (size_t)i * mw, ctx->samples);
        }
    }
    return (int)ms_queries_move_last(q, where, front, mw, (size_t)nq, last);
}

/* The method's visible masks for a tile's queries (method.h, visibility), each sample on a set exact for it
 * when the light's merge asks for the split (exact_split.h). */
static int visibility_of(const ms_shadow_method *sm, void *state, const ms_render_ctx *ctx, const ms_exact_split *split,
                         const ms_shadow_query *q, const uint32_t *scene_prim, int n, const uint64_t *front, uint64_t *vis,
                         uint64_t *counters)
{
    if (!split->axes) return sm->visibility(state, ctx, q, n, front, vis, counters);
    return ms_exact_split_visibility(sm, state, ctx, split, q, scene_prim, (size_t)n, front, vis, 0, 1, counters);
}

/* A shadow pass's constants: light l's states, contexts, exact split and planes (fj_shadow_pass). */
typedef struct pass_ctx {
    ms_frame_job *j;
    size_t l;
    const ms_shadow_method *sm;
    void *sstate, *own_state, *interior_state;
    ms_render_ctx ictx;           /* over the interior boxes (interior_state) */
    ms_render_ctx ctx;            /* light l's */
    ms_render_ctx bctx;           /* the batch's context: each query's light its outline */
    ms_exact_split split;
    const ms_light_shape_ops *shape;
    int outlined, batched, stratified, W;
    size_t mw;
    float *vis, *shadow, *spec;   /* light l's planes; spec: S_spec (shade.h) where surf has a specular lobe, else S */
    uint16_t *fr;
    const ms_surface *surf;
    const ms_hit *hits;
} pass_ctx;

/* A thread's scratch and sums over the tiles it takes. */
typedef struct pass_thread {
    uint64_t local[MS_MAX_COUNTERS];
    uint64_t visible, penumbra, segments, on_merged;
    double resolve;
    uint64_t *front, *vmask;      /* the tile's front and visible masks */
    uint64_t *imask;              /* the samples the interior boxes leave (MS_OCC_INTERIOR_PASS) */
    float *pts;                   /* the stratified pattern's points */
    float *mpts;                  /* merged_last's scratch: the frame's one light (an outlined light's samples are
                                   * the query's own) */
    float hull[8][3], hull_box[6];
    int n_hull, ok;
} pass_thread;

/* The tile's queries (its pixels with a hit), with their front masks; pixels without a hit, or inside a
 * sphere, get their V and S here. Returns how many. */
static int tile_queries(const pass_ctx *P, pass_thread *T, int x0, int y0, int x1, int y1, ms_render_ctx *qc,
                        ms_shadow_query *q, size_t *where)
{
    const ms_frame_job *j = P->j;
    const ms_render_ctx *ctx = &P->ctx;
    const size_t mw = P->mw;
    float *const vis = P->vis, *const shadow = P->shadow, *const spec = P->spec;
    int nq = 0;
    for (int y = y0; y < y1 && T->ok; y++)
        for (int x = x0; x < x1; x++) {
            size_t i = (size_t)(y - j->y_base) * P->W + x;
            const ms_hit *h = &P->hits[i];
            if (h->prim == UINT32_MAX) { vis[i] = shadow[i] = spec[i] = -1.0f; P->fr[i] = 0; continue; }
            ms_query_from_hit(&q[nq], h, (uint32_t)x, (uint32_t)y);
            q[nq].prim = ms_ctx_skip_prim(ctx, h->prim);
            if (P->outlined && P->shape->outline(&ctx->light, q[nq].p, &qc->light)) {
                vis[i] = shadow[i] = spec[i] = 0.0f;   /* inside the sphere: no sample counts */
                P->fr[i] = 0;
                T->visible++;
                continue;
            }
            if (T->pts) ms_pattern_points(ctx->pattern, &qc->light, ctx->k, q[nq].px, q[nq].py, ctx->seed, T->pts);
            const int nf = ms_front_mask(qc, &q[nq], T->pts, T->front + (size_t)nq * mw);
            P->fr[i] = (uint16_t)nf;
            T->segments += (uint64_t)nf;
            where[nq++] = i;
        }
    return nq;
}

/* The method's visible masks of the tile's first nm queries (the interior boxes first when the method takes
 * them), then of the receivers on merged faces the merge could answer otherwise (nm .. nq). */
static void tile_visibility(const pass_ctx *P, pass_thread *T, ms_render_ctx *qc, ms_shadow_query *q, const size_t *where,
                            int nq, int nm)
{
    const ms_shadow_method *sm = P->sm;
    const ms_render_ctx *ctx = &P->ctx;
    const size_t mw = P->mw;
    uint64_t *const front = T->front, *const vmask = T->vmask, *const local = T->local;
    uint32_t scene_prim[TILE * TILE];   /* the receivers' hit triangles, for the exact split */
    for (int i = 0; i < nm && P->split.axes; i++) scene_prim[i] = P->hits[where[i]].prim;
    if (!P->outlined && P->interior_state && nm && T->ok) {
        /* The interior boxes first (no receiver on them: no prim to skip), then the triangles
         * with the samples they left. */
        uint32_t prim[TILE * TILE];
        for (int i = 0; i < nm; i++) { prim[i] = q[i].prim; q[i].prim = UINT32_MAX; }
        if (sm->visibility(P->interior_state, &P->ictx, q, nm, front, T->imask, local)) T->ok = 0;
        for (int i = 0; i < nm; i++) q[i].prim = prim[i];
        if (T->ok && visibility_of(sm, P->sstate, ctx, &P->split, q, scene_prim, nm, T->imask, vmask, local)) T->ok = 0;
    } else if (!P->outlined || P->batched) {
        if (nm && T->ok && visibility_of(sm, P->sstate, P->batched ? &P->bctx : ctx, &P->split, q, scene_prim, nm, front, vmask, local)) T->ok = 0;
    } else
        for (int i = 0; i < nm && T->ok; i++) {
            P->shape->outline(&ctx->light, q[i].p, &qc->light);
            if (visibility_of(sm, P->sstate, qc, &P->split, &q[i], scene_prim + i, 1, front + (size_t)i * mw, vmask + (size_t)i * mw, local)) T->ok = 0;
        }
    /* Receivers on merged faces that the merge could answer otherwise: the same method over the
     * scene's own triangles (was: the reference tracer, 19% of the grid of bars' shadow time). */
    if (nm < nq && T->ok) {
        ms_render_ctx rc;
        fj_light_own_ctx(P->j, P->l, &rc);
        for (int i = nm; i < nq; i++) q[i].prim = P->hits[where[i]].prim;   /* the receivers' own prims */
        rc.outline_per_query = P->batched;
        if (!P->outlined || P->batched) {
            if (sm->visibility(P->own_state, &rc, q + nm, nq - nm, front + (size_t)nm * mw, vmask + (size_t)nm * mw, local)) T->ok = 0;
        } else
            for (int i = nm; i < nq && T->ok; i++) {
                ms_render_ctx qrc = rc;
                P->shape->outline(&ctx->light, q[i].p, &qrc.light);
                if (sm->visibility(P->own_state, &qrc, &q[i], 1, front + (size_t)i * mw, vmask + (size_t)i * mw, local)) T->ok = 0;
            }
        T->on_merged += (uint64_t)(nq - nm);
    }
}

/* V, S and S_spec of the tile's queries from their front and visible masks. */
static void tile_resolve(const pass_ctx *P, pass_thread *T, ms_render_ctx *qc, const ms_shadow_query *q,
                         const size_t *where, int nq)
{
    const ms_render_ctx *ctx = &P->ctx;
    const size_t mw = P->mw;
    const ms_surface *const surf = P->surf;
    float *const shadow = P->shadow, *const spec = P->spec;
    const double tr = omp_get_wtime();
    for (int i = 0; i < nq && T->ok; i++) {
        if (P->outlined) P->shape->outline(&ctx->light, q[i].p, &qc->light);
        if (T->pts) ms_pattern_points(ctx->pattern, &qc->light, ctx->k, q[i].px, q[i].py, ctx->seed, T->pts);
        T->penumbra += (uint64_t)ms_resolve_vs(qc, &q[i], T->pts, T->front + (size_t)i * mw,
                                               T->vmask + (size_t)i * mw, &P->vis[where[i]],
                                               &shadow[where[i]]);
        spec[where[i]] = surf && surf[where[i]].specular
            ? ms_resolve_spec(qc, &q[i], T->pts, T->front + (size_t)i * mw, T->vmask + (size_t)i * mw, &surf[where[i]])
            : shadow[where[i]];
    }
    T->resolve += omp_get_wtime() - tr;
    T->visible += (uint64_t)nq;
}

/* One tile of the pass: queries and front masks, the method's visible masks, V, S and S_spec. */
static void pass_tile(const pass_ctx *P, pass_thread *T, int t)
{
    const ms_render_ctx *ctx = &P->ctx;
    int x0, y0, x1, y1;
    tile_rect(P->j, t, &x0, &y0, &x1, &y1);
    ms_shadow_query q[TILE * TILE];
    size_t where[TILE * TILE];
    ms_render_ctx qc = *ctx;   /* the query's context: the frame's, or with a sphere's outline disk */
    const int nq = tile_queries(P, T, x0, y0, x1, y1, &qc, q, where);
    const int nm = ctx->prim_merged && T->ok ? merged_last(ctx, &P->j->bvh, P->hits, (const float (*)[3])T->hull, T->n_hull, q, where, T->front, P->mw, nq, T->mpts) : nq;
    tile_visibility(P, T, &qc, q, where, nq, nm);
    tile_resolve(P, T, &qc, q, where, nq);
    fj_progress_tick(P->j);
}

/* A frame-level method (visibility_all; shadow_frame.c): the receivers of the listed tiles (whole: the frame's)
 * at once. 0, or -1 out of memory or when the method fails. */
static int pass_frame_level(const pass_ctx *P, const int *tiles, int n, int whole, pass_sums *p, uint64_t *visible,
                            uint64_t *penumbra, uint64_t *segments, uint64_t *on_merged, double *resolve_thread_s)
{
    ms_frame_job *j = P->j;
    const int W = P->W;
    int failed = 0;
    size_t *pixels = NULL, np = 0;
    if (!whole) {   /* the listed tiles' pixels, tile after tile */
        pixels = malloc((size_t)n * TILE * TILE * sizeof *pixels);
        failed = !pixels;
        for (int ti = 0; ti < n && pixels; ti++) {
            int x0, y0, x1, y1;
            tile_rect(j, tiles ? tiles[ti] : ti, &x0, &y0, &x1, &y1);
            for (int y = y0; y < y1; y++)
                for (int x = x0; x < x1; x++) pixels[np++] = (size_t)y * W + x;
        }
    }
    ms_render_ctx own_ctx;
    fj_light_own_ctx(j, P->l, &own_ctx);
    if (!failed)
        failed = ms_shadow_frame_whole(P->sm, P->sstate, &P->ctx, &P->split, P->own_state, &own_ctx, P->hits, P->surf, W,
                                       j->H, pixels, np, P->vis, P->shadow, P->spec, P->fr, p->counters, visible, penumbra,
                                       segments, on_merged, resolve_thread_s) != 0;
    free(pixels);
    return failed ? -1 : 0;
}

/* Light l's constants for its pass. */
static void pass_setup(ms_frame_job *j, size_t l, pass_ctx *P)
{
    P->j = j;
    P->l = l;
    P->sm = j->sm;
    P->sstate = j->sstate[l];
    P->own_state = j->own_sstate[l];
    P->interior_state = j->interior_sstate[l];
    if (P->interior_state) fj_light_interior_ctx(j, l, &P->ictx);
    fj_light_ctx(j, l, &P->ctx);
    const ms_render_ctx *ctx = &P->ctx;
    P->W = j->W;
    const size_t npix = (size_t)P->W * j->rows_held;
    P->mw = (size_t)ctx->mask_words;
    ms_frame *const out = &j->frame;
    P->vis = out->vis + l * npix;
    P->shadow = out->shadow + l * npix;
    P->spec = out->shadow_spec + l * npix;
    P->fr = out->front + l * npix;
    P->surf = j->surf;
    P->hits = j->hits;
    P->stratified = ctx->pattern != MS_PATTERN_GRID;   /* sample points listed (not the grid) */
    /* A sphere or a sun: each receiver has its own light, the shape's outline seen from it (a per-query light
     * frame: ms_light_sphere_outline, ms_light_sun_outline). A method that declares .outlines (the
     * micro-rasterization methods) takes the tile's queries together, with ctx.outline_per_query, and sets
     * each query's light itself (ms_ctx_for_query), keeping its 4x4 blocks. Any other is called one query
     * at a time with a context whose light is that outline, so every method answers on the same
     * per-receiver samples as raytrace, whatever it sets up per frame (mft re-derives its light frame per
     * call; hpc sets up its light per call, so an outlined light costs it a pass over every triangle per
     * receiver); frame-level entries are not used. */
    P->shape = ms_light_shape_of(ctx->light.shape);
    P->outlined = P->shape && P->shape->outline;   /* a per-receiver light: the shape's outline (light_shape.h) */
    P->batched = P->outlined && P->sm->outlines;    /* ... which the method takes a tile at a time */
    P->bctx = *ctx;
    P->bctx.outline_per_query = 1;
    /* The samples of the axes the merged set is not exact for go to the sets that are (exact_split.h); not for
     * a batch of outlined lights (the micro-rasterization methods, which do not equal raytrace anyway). */
    fj_light_split(j, l, &P->split);
    if (P->batched) P->split.axes = 0;
}

int fj_shadow_pass(ms_frame_job *j, size_t l, const int *tiles, int n, int whole, pass_sums *p)
{
    pass_ctx P;
    pass_setup(j, l, &P);
    const ms_render_ctx ctx = P.ctx;
    const size_t mw = P.mw;
    uint64_t visible = 0, penumbra = 0, segments = 0, on_merged = 0;
    double resolve_thread_s = 0.0;
    int failed = 0;
    const int shadow_tiles = P.sm->visibility_all && !P.outlined ? 0 : n;   /* a frame-level method: shadow_frame.c */
#pragma omp parallel num_threads(j->threads)
    {
        pass_thread T;
        memset(T.local, 0, sizeof T.local);
        T.visible = T.penumbra = T.segments = T.on_merged = 0;
        T.resolve = 0.0;
        /* Per thread: the tile's front and visible masks, and the stratified pattern's points. */
        T.front = aligned_alloc(64, TILE * TILE * mw * sizeof *T.front);
        T.vmask = aligned_alloc(64, TILE * TILE * mw * sizeof *T.vmask);
        T.imask = P.interior_state ? aligned_alloc(64, TILE * TILE * mw * sizeof *T.imask) : NULL;
        T.pts = P.stratified ? malloc((size_t)ctx.samples * 3 * sizeof *T.pts) : NULL;
        T.mpts = ctx.prim_merged && !P.outlined ? malloc((size_t)ctx.samples * 3 * sizeof *T.mpts) : NULL;
        T.n_hull = ms_light_hull(&ctx.light, T.hull, T.hull_box);
        T.ok = T.front && T.vmask && (T.pts || !P.stratified) && (T.imask || !P.interior_state) &&
               (T.mpts || !ctx.prim_merged || P.outlined);
#pragma omp for schedule(dynamic, 1)
        for (int ti = 0; ti < shadow_tiles; ti++) {
            if (fj_cancelled(j)) continue;
            pass_tile(&P, &T, tiles ? tiles[ti] : ti);
        }
        free(T.front);
        free(T.vmask);
        free(T.imask);
        free(T.pts);
        free(T.mpts);
#pragma omp critical(ms_counters)
        {
            for (int c = 0; c < MS_MAX_COUNTERS; c++) p->counters[c] += T.local[c];
            visible += T.visible;
            penumbra += T.penumbra;
            segments += T.segments;
            on_merged += T.on_merged;
            resolve_thread_s += T.resolve;
            failed |= !T.ok;
        }
    }
    if (P.sm->visibility_all && !P.outlined && !failed)
        failed = pass_frame_level(&P, tiles, n, whole, p, &visible, &penumbra, &segments, &on_merged, &resolve_thread_s) != 0;
    p->visible += visible;
    p->penumbra += penumbra;
    p->segments += segments;
    p->on_merged += on_merged;
    p->resolve_thread_s += resolve_thread_s;
    return failed ? -1 : 0;
}
