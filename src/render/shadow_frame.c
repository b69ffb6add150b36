/* The whole-frame shadow phase (shadow_frame.h): the same front masks and the same V/S resolution as the
 * tiled phase of frame_job.c, around one call of the method's frame-level entry. */
#include "shadow_frame.h"
#include "primary/primary.h"
#include "light/pattern.h"
#include "visibility/receiver.h"
#include "visibility/occluders.h"
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* 1 when the receiver of hit h may have to be answered over the scene's own triangles (own_ctx): it lies on a
 * merged coplanar face where the light as a whole does not rule out that the merge answers otherwise
 * (ms_merged_receiver_ok); its own samples decide (ms_merged_receiver_ok_samples, below). */
static int on_merged_face(const ms_render_ctx *ctx, const ms_render_ctx *own_ctx, const ms_hit *h,
                          const float (*hull)[3], int n_hull)
{
    return own_ctx && ctx->prim_merged && ctx->prim_merged[h->prim] &&
           !ms_merged_receiver_ok(own_ctx->bvh->tri + 9 * (size_t)h->prim, h->p, hull, n_hull);
}

size_t ms_queries_move_last(ms_shadow_query *q, size_t *where, uint64_t *front, size_t mw, size_t n, const uint8_t *last)
{
    /* Position i still holds query i when it is read: only positions up to i are written before. */
    size_t w = 0;
    for (size_t i = 0; i < n; i++) {
        if (last[i]) continue;
        if (w != i) {
            const ms_shadow_query tq = q[w]; q[w] = q[i]; q[i] = tq;
            const size_t tw = where[w]; where[w] = where[i]; where[i] = tw;
            for (size_t k = 0; k < mw; k++) {
                const uint64_t tf = front[w * mw + k];
                front[w * mw + k] = front[i * mw + k];
                front[i * mw + k] = tf;
            }
        }
        w++;
    }
    return w;
}

int ms_shadow_frame_whole(const ms_shadow_method *sm, void *sstate, const ms_render_ctx *ctx, const ms_exact_split *split, void *own_state,
                          const ms_render_ctx *own_ctx, const ms_hit *hits,
                          const ms_surface *surf, int W, int H, const size_t *pixels, size_t npixels, float *vis_out, float *shadow_out, float *spec_out,
                          uint16_t *front_out, uint64_t *counters, uint64_t *visible, uint64_t *penumbra,
                          uint64_t *segments, uint64_t *on_merged, double *resolve_thread_s)
{
    const size_t npix = pixels ? npixels : (size_t)W * H, mw = (size_t)ctx->mask_words;
    (void)H;
    const int stratified = ctx->pattern != MS_PATTERN_GRID;
    size_t n = 0;
    for (size_t j = 0; j < npix; j++) n += hits[pixels ? pixels[j] : j].prim != UINT32_MAX;
    ms_shadow_query *q = malloc((n ? n : 1) * sizeof *q);
    size_t *where = malloc((n ? n : 1) * sizeof *where);
    uint64_t *front = malloc((n ? n : 1) * mw * sizeof *front);
    uint64_t *vis = malloc((n ? n : 1) * mw * sizeof *vis);
    uint8_t *own = own_state ? malloc(n ? n : 1) : NULL;   /* 1: answered over the scene's own triangles */
    int rc = -1;
    if (!q || !where || !front || !vis || (own_state && !own)) goto done;
    float hull[8][3], hull_box[6];
    const int n_hull = own_state ? ms_light_hull(&ctx->light, hull, hull_box) : 0;
    if (!own_state) own_ctx = NULL;
    n = 0;
    for (size_t j = 0; j < npix; j++) {
        const size_t i = pixels ? pixels[j] : j;
        const ms_hit *h = &hits[i];
        if (h->prim == UINT32_MAX) { vis_out[i] = shadow_out[i] = spec_out[i] = -1.0f; front_out[i] = 0; continue; }
        if (own) own[n] = (uint8_t)on_merged_face(ctx, own_ctx, h, (const float (*)[3])hull, n_hull);
        ms_query_from_hit(&q[n], h, (uint32_t)(i % (size_t)W), (uint32_t)(i / (size_t)W));
        q[n].prim = ms_ctx_skip_prim(ctx, h->prim);
        where[n++] = i;
    }
    int failed = 0;
    uint64_t seg = 0;
#pragma omp parallel num_threads(ctx->threads) reduction(+ : seg) reduction(| : failed)
    {
        const int need_pts = stratified || own;
        float *pts = need_pts ? malloc((size_t)ctx->samples * 3 * sizeof *pts) : NULL;
        failed |= need_pts && !pts;
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            if (failed) continue;
            if (stratified || (own && own[i])) ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, q[i].px, q[i].py, ctx->seed, pts);
            const int nf = ms_front_mask(ctx, &q[i], stratified ? pts : NULL, front + i * mw);
            front_out[where[i]] = (uint16_t)nf;
            seg += (uint64_t)nf;
            /* the receiver's own samples in front may rule the difference out after all */
            if (own && own[i] && ms_merged_receiver_ok_samples(own_ctx->bvh->tri + 9 * (size_t)hits[where[i]].prim, q[i].p, pts,
                                                                front + i * mw, ctx->samples))
                own[i] = 0;
        }
        free(pts);
    }
    if (failed) goto done;
    /* The receivers the merged faces answer first (in their order), then those on merged faces that go to the
     * scene's own triangles (own_state), named there by their own prims. */
    const size_t n_main = own ? ms_queries_move_last(q, where, front, mw, n, own) : n;
    for (size_t i = n_main; i < n; i++) q[i].prim = hits[where[i]].prim;
    if (split->axes) {   /* each sample on a set exact for its segment's shear axis (exact_split.h) */
        uint32_t *prim = malloc((n_main ? n_main : 1) * sizeof *prim);
        if (!prim) goto done;
        for (size_t i = 0; i < n_main; i++) prim[i] = hits[where[i]].prim;
        const int r = ms_exact_split_visibility(sm, sstate, ctx, split, q, prim, n_main, front, vis, 1, ctx->threads, counters);
        free(prim);
        if (r) goto done;
    } else if (sm->visibility_all(sstate, ctx, q, n_main, front, vis, counters))
        goto done;
    if (n > n_main && sm->visibility_all(own_state, own_ctx, q + n_main, n - n_main, front + n_main * mw,
                                         vis + n_main * mw, counters))
        goto done;
    const double tr = omp_get_wtime();
    uint64_t pen = 0;
#pragma omp parallel num_threads(ctx->threads) reduction(+ : pen) reduction(| : failed)
    {
        float *pts = stratified ? malloc((size_t)ctx->samples * 3 * sizeof *pts) : NULL;
        failed |= stratified && !pts;
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            if (failed) continue;
            if (pts) ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, q[i].px, q[i].py, ctx->seed, pts);
            pen += (uint64_t)ms_resolve_vs(ctx, &q[i], pts, front + i * mw, vis + i * mw, &vis_out[where[i]],
                                           &shadow_out[where[i]]);
            spec_out[where[i]] = surf && surf[where[i]].specular
                ? ms_resolve_spec(ctx, &q[i], pts, front + i * mw, vis + i * mw, &surf[where[i]])
                : shadow_out[where[i]];
        }
        free(pts);
    }
    if (failed) goto done;
    *resolve_thread_s += (omp_get_wtime() - tr) * ctx->threads;   /* thread-seconds, as render.c sums them */
    *visible += n;
    *penumbra += pen;
    *segments += seg;
    *on_merged += n - n_main;
    rc = 0;
done:
    free(q);
    free(where);
    free(front);
    free(vis);
    free(own);
    return rc;
}
