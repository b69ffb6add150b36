/* One frame: BVH build, primary visibility, shadows, shading, each phase timed on its own and run
 * over 16x16 pixel tiles by OpenMP (dynamic scheduling: shadow cost varies wildly across a frame). */
#include "microshadow.h"
#include "../core/pattern.h"
#include "../shadow/method.h"
#include "../shadow/receiver.h"
#include "shadow_frame.h"
#include "shade.h"
#include "render_materialise.h"
#include "interleave_filter.h"
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define TILE 16
#define MS_NEAR 1e-4f        /* segment parameter: occluders closer than this to the receiver are ignored */
#define MS_FAR (1.0f - 1e-4f)/* ... and this close to the light plane (a light set into a ceiling) */

void ms_render_options_default(ms_render_options *o)
{
    memset(o, 0, sizeof *o);
    o->method = MS_DEFAULT_METHOD;
    o->pattern = MS_PATTERN_GRID;
    o->samples = 0;        /* the scene's */
}

void ms_frame_free(ms_frame *f)
{
    free(f->vis);
    free(f->shadow);
    free(f->shadow_spec);
    free(f->front);
    free(f->rgb);
    memset(f, 0, sizeof *f);
}

typedef struct progress {
    const ms_render_options *opt;
    long done, total;      /* tiles over both passes */
} progress;

static void progress_tick(progress *p)
{
    long d;
#pragma omp atomic capture
    d = ++p->done;
    if (p->opt->progress && omp_get_thread_num() == 0) p->opt->progress(p->opt->progress_user, (double)d / (double)p->total);
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* CPU seconds of all the process's threads: on a shared machine, where wall time depends on the
 * neighbours, the figure to compare methods by. */
static double process_cpu_s(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts)) return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The shadow phase for one light (ctx->light): front masks, the method's visible masks, V and S into
 * p's planes, over 16x16 tiles (or the method's frame-level entry). Adds to p's counters and totals.
 * 0, or -1 when out of memory. */
typedef struct shadow_pass_io {
    const ms_hit *hits;
    int W, H;
    float *vis, *shadow, *spec;   /* spec: S_spec (shade.h) where surf has a specular lobe, else S */
    uint16_t *front;
    const ms_surface *surf;       /* per pixel, or NULL (no materials or normals) */
    progress *prog;
    uint64_t counters[MS_MAX_COUNTERS];
    uint64_t visible, penumbra, segments;
    double resolve_thread_s;
} shadow_pass_io;

static int shadow_pass(const ms_shadow_method *sm, void *sstate, const ms_render_ctx *ctxp, int threads,
                       shadow_pass_io *p)
{
    const ms_render_ctx ctx = *ctxp;
    uint64_t visible = 0, penumbra = 0, segments = 0;
    double resolve_thread_s = 0.0;
    int failed = 0;
    const int W = p->W, H = p->H, tx = (W + TILE - 1) / TILE, ty = (H + TILE - 1) / TILE, ntiles = tx * ty;
    const size_t mw = (size_t)ctx.mask_words;
    const int stratified = ctx.pattern != MS_PATTERN_GRID;   /* sample points listed (not the grid) */
    /* A sphere light: each receiver has its own light, the sphere's outline disk seen from it (a per-query
     * light frame: ms_light_sphere_outline). The method is called one query at a time with a context whose
     * light is that disk, so every method answers on the same per-receiver samples as raytrace, whatever
     * it sets up per frame (mft re-derives its light frame per call; hpc sets up its light per call, so
     * a sphere costs it a pass over every triangle per receiver); frame-level entries are not used. The
     * price is the block traversal's coherence: groups of one. */
    const int sphere = ctx.light.shape == MS_LIGHT_SPHERE;
    const int shadow_tiles = sm->visibility_all && !sphere ? 0 : ntiles;   /* a frame-level method: shadow_frame.c */
    float *const vis = p->vis, *const shadow = p->shadow, *const spec = p->spec;
    const ms_surface *const surf = p->surf;
    uint16_t *const fr = p->front;
    const ms_hit *const hits = p->hits;
    progress *const prog = p->prog;
#pragma omp parallel num_threads(threads)
    {
        uint64_t local[MS_MAX_COUNTERS] = { 0 };
        uint64_t local_visible = 0, local_penumbra = 0, local_segments = 0;
        double local_resolve = 0.0;
        /* Per thread: the tile's front and visible masks, and the stratified pattern's points. */
        uint64_t *front = aligned_alloc(64, TILE * TILE * mw * sizeof *front);
        uint64_t *vmask = aligned_alloc(64, TILE * TILE * mw * sizeof *vmask);
        float *pts = stratified ? malloc((size_t)ctx.samples * 3 * sizeof *pts) : NULL;
        int ok = front && vmask && (pts || !stratified);
#pragma omp for schedule(dynamic, 1)
        for (int t = 0; t < shadow_tiles; t++) {
            int x0 = (t % tx) * TILE, y0 = (t / tx) * TILE;
            int x1 = x0 + TILE < W ? x0 + TILE : W, y1 = y0 + TILE < H ? y0 + TILE : H;
            ms_shadow_query q[TILE * TILE];
            size_t where[TILE * TILE];
            ms_render_ctx qc = ctx;   /* the query's context: the frame's, or with a sphere's outline disk */
            int n = 0;
            for (int y = y0; y < y1 && ok; y++)
                for (int x = x0; x < x1; x++) {
                    size_t i = (size_t)y * W + x;
                    const ms_hit *h = &hits[i];
                    if (h->prim == UINT32_MAX) { vis[i] = shadow[i] = spec[i] = -1.0f; fr[i] = 0; continue; }
                    memcpy(q[n].p, h->p, sizeof h->p);
                    memcpy(q[n].n, h->n, sizeof h->n);
                    q[n].prim = h->prim;
                    q[n].px = (uint32_t)x;
                    q[n].py = (uint32_t)y;
                    if (sphere && ms_light_sphere_outline(&ctx.light, q[n].p, &qc.light)) {
                        vis[i] = shadow[i] = spec[i] = 0.0f;   /* inside the sphere: no sample counts */
                        fr[i] = 0;
                        local_visible++;
                        continue;
                    }
                    if (pts) ms_pattern_points(ctx.pattern, &qc.light, ctx.k, q[n].px, q[n].py, ctx.seed, pts);
                    const int nf = ms_front_mask(&qc, &q[n], pts, front + (size_t)n * mw);
                    fr[i] = (uint16_t)nf;
                    local_segments += (uint64_t)nf;
                    where[n++] = i;
                }
            if (!sphere) {
                if (n && ok && sm->visibility(sstate, &ctx, q, n, front, vmask, local)) ok = 0;
            } else
                for (int i = 0; i < n && ok; i++) {
                    ms_light_sphere_outline(&ctx.light, q[i].p, &qc.light);
                    if (sm->visibility(sstate, &qc, &q[i], 1, front + (size_t)i * mw, vmask + (size_t)i * mw, local)) ok = 0;
                }
            const double tr = omp_get_wtime();
            for (int i = 0; i < n && ok; i++) {
                if (sphere) ms_light_sphere_outline(&ctx.light, q[i].p, &qc.light);
                if (pts) ms_pattern_points(ctx.pattern, &qc.light, ctx.k, q[i].px, q[i].py, ctx.seed, pts);
                local_penumbra += (uint64_t)ms_resolve_vs(&qc, &q[i], pts, front + (size_t)i * mw,
                                                          vmask + (size_t)i * mw, &vis[where[i]],
                                                          &shadow[where[i]]);
                spec[where[i]] = surf && surf[where[i]].specular
                    ? ms_resolve_spec(&qc, &q[i], pts, front + (size_t)i * mw, vmask + (size_t)i * mw, &surf[where[i]])
                    : shadow[where[i]];
            }
            local_resolve += omp_get_wtime() - tr;
            local_visible += (uint64_t)n;
            progress_tick(prog);
        }
        free(front);
        free(vmask);
        free(pts);
#pragma omp critical(ms_counters)
        {
            for (int c = 0; c < MS_MAX_COUNTERS; c++) p->counters[c] += local[c];
            visible += local_visible;
            penumbra += local_penumbra;
            segments += local_segments;
            resolve_thread_s += local_resolve;
            failed |= !ok;
        }
    }
    if (sm->visibility_all && !sphere && !failed)
        failed = ms_shadow_frame_whole(sm, sstate, &ctx, hits, surf, W, H, vis, shadow, spec, fr, p->counters, &visible, &penumbra,
                                       &segments, &resolve_thread_s) != 0;
    p->visible += visible;
    p->penumbra += penumbra;
    p->segments += segments;
    p->resolve_thread_s += resolve_thread_s;
    return failed ? -1 : 0;
}

/* Textured lights: per light and pixel the weighted mean texel colour (ms_light_texture_mean) that scales
 * its unshadowed irradiance, 3 floats each (NULL entries for untextured lights); *out NULL when no light
 * is textured. 0, or -1 out of memory. */
static int texture_means(const ms_render_ctx *ctx0, const ms_light *lights, size_t nlights, const ms_hit *hits, int W,
                         size_t npix, int threads, float **out)
{
    *out = NULL;
    size_t textured = 0;
    for (size_t l = 0; l < nlights; l++) textured += lights[l].texture != NULL;
    if (!textured) return 0;
    float *t = malloc(nlights * npix * 3 * sizeof *t);
    if (!t) return -1;
    for (size_t l = 0; l < nlights; l++) {
        if (!lights[l].texture) continue;
        ms_render_ctx ctx = *ctx0;
        ctx.light = lights[l];
        float *tl = t + l * npix * 3;
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
        for (size_t i = 0; i < npix; i++) {
            if (hits[i].prim == UINT32_MAX) continue;
            ms_shadow_query q;
            memcpy(q.p, hits[i].p, sizeof q.p);
            memcpy(q.n, hits[i].n, sizeof q.n);
            q.prim = hits[i].prim;
            q.px = (uint32_t)(i % (size_t)W);
            q.py = (uint32_t)(i / (size_t)W);
            ms_light_texture_mean(&ctx, &q, tl + 3 * i);
        }
    }
    *out = t;
    return 0;
}

int ms_render(const ms_scene *scene, const ms_render_options *opt, ms_frame *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    double t_start = omp_get_wtime();
    const char *method = opt->method ? opt->method : MS_DEFAULT_METHOD;   /* zeroed options: defaults */
    const ms_shadow_method *sm = ms_find_shadow_method(method);
    if (!sm) {
        if (ms_method_available(method) < 0) snprintf(err, errlen, "method '%s' is not compiled into this build", method);
        else snprintf(err, errlen, "unknown method '%s'", method);
        return -1;
    }
    /* A procedural scene: streamed by the methods that can (primary by a depth pass, no BVH), else
     * materialised (render_materialise.c). */
    const int streamed = scene->procedural.type != MS_PROCEDURAL_NONE;
    if (streamed && !sm->streams) return ms_render_materialised(scene, opt, out, err, errlen);
    const ms_primary_method *pm = ms_find_primary_method(streamed ? "depth" : sm->primary);
    if (!pm) { snprintf(err, errlen, "primary method '%s' is not compiled into this build", sm->primary); return -1; }
    int samples = opt->samples > 0 ? opt->samples : scene->samples;
    if ((unsigned)opt->pattern > MS_PATTERN_INTERLEAVED) { snprintf(err, errlen, "unknown pattern %d", (int)opt->pattern); return -1; }
    if ((unsigned)opt->traversal > MS_TRAVERSAL_PIXEL) { snprintf(err, errlen, "unknown traversal %d", (int)opt->traversal); return -1; }
    /* Samples per pixel: N, or N/16 for interleaved; always a multiple of 16 (full ray packets). */
    const int spp = ms_pattern_samples_per_pixel(opt->pattern, samples);
    if (!spp) {
        snprintf(err, errlen, "samples must be %s with the %s pattern (got %d)",
                 opt->pattern == MS_PATTERN_STRATIFIED ? "16, 64, 256, 1024 or 4096" : "256, 1024 or 4096",
                 ms_pattern_name(opt->pattern), samples);
        return -1;
    }
    int k = ms_samples_to_k(samples);
    if (sm->needs_grid && opt->pattern != MS_PATTERN_GRID) {
        snprintf(err, errlen, "method '%s' needs --pattern grid", sm->name);
        return -1;
    }
    int W = opt->width > 0 ? opt->width : scene->camera.width;
    int H = opt->height > 0 ? opt->height : scene->camera.height;
    if (W < 1 || H < 1 || W > MS_MAX_IMAGE_SIZE || H > MS_MAX_IMAGE_SIZE) {
        snprintf(err, errlen, "width and height must be in [1, %d]", MS_MAX_IMAGE_SIZE);
        return -1;
    }
    int threads = opt->threads > 0 ? opt->threads : omp_get_num_procs();

    size_t nlights;
    const ms_light *lights = ms_scene_lights(scene, &nlights);
    ms_render_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    if (ms_camera_basis_init(&ctx.cam, &scene->camera, W, H)) {
        snprintf(err, errlen, "camera is degenerate (eye = target, or up parallel to the view)");
        return -1;
    }
    ms_bvh bvh;
    memset(&bvh, 0, sizeof bvh);
    if (!streamed && ms_bvh_build(&bvh, scene->tri, scene->n_tris, threads)) { snprintf(err, errlen, "BVH build failed: out of memory"); return -1; }
    ctx.scene = scene;
    ctx.bvh = streamed ? NULL : &bvh;
    ctx.light = lights[0];
    ctx.pattern = opt->pattern;
    ctx.k = k;
    ctx.samples = spp;
    ctx.mask_words = (spp + 63) / 64;   /* bits past spp stay 0 */
    ctx.seed = opt->seed;
    ctx.near = MS_NEAR;
    ctx.far = MS_FAR;
    ctx.threads = threads;
    ctx.isa_cap = opt->isa;
    ctx.no_occlusion_cull = opt->no_occlusion_cull;
    ctx.no_child_order = opt->no_child_order;
    ctx.traversal = opt->traversal;
    ctx.frustum_shrink = opt->frustum_shrink;
    ctx.embree_mode = opt->embree_mode;
    ctx.embree_filter = opt->embree_filter;

    size_t npix = (size_t)W * H;
    ms_hit *hits = malloc(npix * sizeof *hits);
    out->vis = malloc(nlights * npix * sizeof(float));
    out->shadow = malloc(nlights * npix * sizeof(float));
    out->front = malloc(nlights * npix * sizeof *out->front);
    out->n_lights = (int)nlights;
    out->rgb = malloc(npix * 3 * sizeof(float));
    out->shadow_spec = malloc(nlights * npix * sizeof(float));
    ms_surface *surf = NULL;   /* per pixel, only for scenes with materials or normals (shade.h) */
    void *pstate = NULL, *sstate = NULL;
    int rc = -1;
    if (!hits || !out->vis || !out->shadow || !out->front || !out->rgb || !out->shadow_spec) { snprintf(err, errlen, "out of memory for a %dx%d frame", W, H); goto fail; }
    const double t_setup = omp_get_wtime();
    if (pm->create(&ctx, &pstate, err, errlen)) goto fail;
    if (sm->create(&ctx, &sstate, err, errlen)) { pm->destroy(pstate); goto fail; }
    const double setup_s = omp_get_wtime() - t_setup;

    int tx = (W + TILE - 1) / TILE, ty = (H + TILE - 1) / TILE, ntiles = tx * ty;
    progress prog = { opt, 0, (long)(1 + nlights) * ntiles };

    double t0 = omp_get_wtime();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int t = 0; t < ntiles; t++) {
        int x0 = (t % tx) * TILE, y0 = (t / tx) * TILE;
        int x1 = x0 + TILE < W ? x0 + TILE : W, y1 = y0 + TILE < H ? y0 + TILE : H;
        ms_hit tile[TILE * TILE];
        pm->trace(pstate, &ctx, x0, y0, x1, y1, tile);
        for (int y = y0; y < y1; y++)
            memcpy(&hits[(size_t)y * W + x0], &tile[(y - y0) * (x1 - x0)], (size_t)(x1 - x0) * sizeof *tile);
        progress_tick(&prog);
    }
    double t1 = omp_get_wtime();
    const double c1 = process_cpu_s();

    /* Each light in turn: its own method state (set-ups such as hpc's light hierarchy and the frusta are
     * per light), its own V, S and front planes; the primary hits are shared. */
    shadow_pass_io io;
    memset(&io, 0, sizeof io);
    io.hits = hits;
    io.W = W;
    io.H = H;
    io.prog = &prog;
    /* The surfaces (material, shading normal) of the hits: S_spec needs them with the masks. Timed with
     * the shadow phase (a lookup per pixel, far below the shadow cost). */
    if (!streamed && (scene->tri_material || scene->tri_normal)) {
        surf = malloc(npix * sizeof *surf);
        if (!surf) { snprintf(err, errlen, "out of memory for the surfaces of a %dx%d frame", W, H); sm->destroy(sstate); pm->destroy(pstate); goto fail; }
        const float eye[3] = { scene->camera.eye.x, scene->camera.eye.y, scene->camera.eye.z };
#pragma omp parallel for schedule(static) num_threads(threads)
        for (size_t i = 0; i < npix; i++) ms_surface_at(scene, &bvh, &hits[i], eye, &surf[i]);
    }
    io.surf = surf;
    int failed = 0;
    double setup_more_s = 0.0;
    for (size_t l = 0; l < nlights && !failed; l++) {
        ctx.light = lights[l];
        if (l > 0) {
            const double ts = omp_get_wtime();
            if (sm->create(&ctx, &sstate, err, errlen)) { sstate = NULL; pm->destroy(pstate); goto fail; }
            setup_more_s += omp_get_wtime() - ts;
        }
        io.vis = out->vis + l * npix;
        io.shadow = out->shadow + l * npix;
        io.front = out->front + l * npix;
        io.spec = out->shadow_spec + l * npix;
        failed = shadow_pass(sm, sstate, &ctx, threads, &io) != 0;
        if (l + 1 < nlights) {
            /* the last light's state stays for the stats (isa_used, counters_used) */
            sm->destroy(sstate);
            sstate = NULL;
        }
    }
    ctx.light = lights[0];
    uint64_t *const counters = io.counters;
    const uint64_t visible = io.visible / nlights, penumbra = io.penumbra, segments = io.segments;
    const double resolve_thread_s = io.resolve_thread_s;
    if (failed) {
        snprintf(err, errlen, "out of memory in the shadow phase of method '%s'", sm->name);
        if (sstate) sm->destroy(sstate);
        pm->destroy(pstate);
        goto fail;
    }
    /* The interleaved pattern's filter belongs to its shadow cost (timed in shadow_s and on its own). */
    double filter_s = 0.0;
    if (ctx.pattern == MS_PATTERN_INTERLEAVED && !opt->no_filter) {
        const double tf = omp_get_wtime();
        /* S_spec through the same filter, with the same raw V deciding the neighbours. */
        float *raw_vis = surf ? malloc(npix * sizeof *raw_vis) : NULL;
        int ferr = surf && !raw_vis;
        for (size_t l = 0; l < nlights && !ferr; l++) {
            if (raw_vis) memcpy(raw_vis, out->vis + l * npix, npix * sizeof *raw_vis);
            ferr = ms_interleave_filter(W, H, hits, out->front + l * npix, out->vis + l * npix, out->shadow + l * npix,
                                        threads) ||
                   (raw_vis && ms_interleave_filter(W, H, hits, out->front + l * npix, raw_vis, out->shadow_spec + l * npix,
                                                    threads));
        }
        free(raw_vis);
        if (ferr) {
            snprintf(err, errlen, "out of memory for the interleaved filter of a %dx%d frame", W, H);
            sm->destroy(sstate);
            pm->destroy(pstate);
            goto fail;
        }
        filter_s = omp_get_wtime() - tf;
    }
    double t2 = omp_get_wtime();
    const double c2 = process_cpu_s();

    /* Shading (shade.h): per light the exact unshadowed irradiance times S, plus the LTC specular times
     * S_spec (ratio estimators: exact where the light is wholly visible or hidden, converging as k grows);
     * the lights' radiance adds up. */
    float *lum = malloc(npix * sizeof(float));
    size_t nlum = 0;
    float *tex = NULL;   /* textured lights: the mean texel colour each pixel sees */
    if (texture_means(&ctx, lights, nlights, hits, W, npix, threads, &tex)) {
        snprintf(err, errlen, "out of memory for the textured lights of a %dx%d frame", W, H);
        free(lum);
        sm->destroy(sstate);
        pm->destroy(pstate);
        goto fail;
    }
    const float eye[3] = { scene->camera.eye.x, scene->camera.eye.y, scene->camera.eye.z };
    /* In parallel (a disk across the horizon costs a 256-gon per pixel): lum[i] per pixel, misses
     * dropped after. */
#pragma omp parallel for schedule(dynamic, 1024) num_threads(threads)
    for (size_t i = 0; i < npix; i++) {
        float *c = out->rgb + 3 * i;
        c[0] = c[1] = c[2] = 0.0f;
        if (lum) lum[i] = -1.0f;
        if (hits[i].prim == UINT32_MAX) continue;
        ms_surface grey;
        if (!surf) ms_surface_at(scene, NULL, &hits[i], eye, &grey);
        float y = 0.0f;
        for (size_t l = 0; l < nlights; l++) {
            ms_light L = lights[l];
            if (tex && L.texture) {   /* the texels this pixel sees scale the emission */
                const float *t = tex + 3 * (l * npix + i);
                L.emission.x *= t[0];
                L.emission.y *= t[1];
                L.emission.z *= t[2];
            }
            float rgb[3], u;
            ms_shade(&L, hits[i].p, surf ? &surf[i] : &grey, out->shadow[l * npix + i], out->shadow_spec[l * npix + i],
                     rgb, &u);
            c[0] += rgb[0];
            c[1] += rgb[1];
            c[2] += rgb[2];
            y += u;
        }
        if (lum) lum[i] = y;
    }
    free(tex);
    for (size_t i = 0; lum && i < npix; i++)
        if (hits[i].prim != UINT32_MAX) lum[nlum++] = lum[i];
    out->exposure = 1.0f;
    if (lum && nlum) {
        qsort(lum, nlum, sizeof *lum, cmp_float);
        float p99 = lum[(size_t)(0.99 * (double)(nlum - 1))];
        if (p99 > 0.0f) out->exposure = 1.0f / p99;
    }
    free(lum);

    out->width = W;
    out->height = H;
    ms_stats *st = &out->stats;
    st->triangles = scene->n_tris;
    st->load_s = scene->load_s;
    st->build_s = bvh.build_s;
    st->setup_s = setup_s + setup_more_s;
    st->primary_s = t1 - t0;
    st->shadow_s = t2 - t1;
    st->shadow_cpu_s = c2 - c1;
    st->samples = samples;
    st->samples_per_pixel = spp;
    st->threads = threads;
    st->width = W;
    st->height = H;
    st->method = sm->name;
    ms_isa kisa = MS_ISA_AUTO, tisa = MS_ISA_AUTO;
    if (sm->isa_used) sm->isa_used(sstate, &kisa, &tisa);
    st->kernel_isa = kisa == MS_ISA_AUTO ? "none" : ms_isa_name(kisa);
    st->traversal_isa = tisa == MS_ISA_AUTO ? "none" : ms_isa_name(tisa);
    st->pattern = ms_pattern_name(opt->pattern);
    st->visible_pixels = visible;
    st->penumbra_pixels = penumbra;
    st->shadow_factor_s = resolve_thread_s / threads;
    st->filter_s = filter_s;
    st->shadow_rays = segments;
    const char *const *cnames = sm->counter_names;
    st->n_counters = sm->n_counters;
    if (sm->counters_used) {
        const int n = sm->counters_used(sstate, &cnames);
        if (n >= 0) st->n_counters = n;
        else cnames = sm->counter_names;
    }
    for (int c = 0; c < st->n_counters; c++) { st->counter_name[c] = cnames[c]; st->counter[c] = counters[c]; }
    sm->destroy(sstate);
    pm->destroy(pstate);
    st->total_s = omp_get_wtime() - t_start + scene->load_s;
    rc = 0;
fail:
    free(surf);
    free(hits);
    ms_bvh_free(&bvh);
    if (rc) ms_frame_free(out);
    return rc;
}
