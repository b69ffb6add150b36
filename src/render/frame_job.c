/* A frame tile by tile (ms_frame_job, microshadow.h): the set-up, the tiled primary and shadow phases and
 * the frame-global finish that ms_render runs in one go, split so that a driver can render any tiles in
 * any number of calls (the CLI's MPI mode hands tiles out to processes) and still get ms_render's image bit
 * for bit. Why that holds: a pixel's hit point, surface, samples and V/S/S_spec for every light depend only
 * on the pixel, the seed and the scene (the block methods group 4x4 pixel blocks, which never straddle a
 * 16x16 tile; a sphere light is answered one query at a time); what depends on the whole frame (the
 * interleaved pattern's filter, which reads neighbours across tiles, the exposure's 99th percentile, the
 * shading's hit points) runs in finish over the whole frame. Frame-level methods (visibility_all) get the
 * receivers of one call at once, which is exact only for methods whose answer does not depend on the other
 * receivers (method.h, split_exact); the others only render whole frames. Each light has its own method
 * state for the job's life (set-ups such as hpc's light hierarchy and the frusta are per light), so that
 * any call can render any tile for every light. */
#include "microshadow.h"
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

#define TILE MS_TILE_SIZE

struct ms_frame_job {
    ms_scene soup;                /* a procedural scene materialised for a method that does not stream */
    int own_soup;
    const ms_scene *scene;
    const ms_shadow_method *sm;
    const ms_primary_method *pm;
    ms_render_ctx ctx;            /* ctx.light: light 0; each light's pass uses a copy with its light */
    const ms_light *lights;
    size_t nlights;
    ms_light *placed_lights;      /* the lights with their suns placed for the scene (sun_place.h); NULL: none */
    ms_bvh bvh;
    struct ms_alpha *alpha;       /* alpha-tested triangles (NULL: none), ctx.alpha */
    void *pstate;
    void **sstate;                /* per light */
    void **own_sstate;            /* per light whose occluders merge coplanar faces: the method over the scene's
                                   * own triangles, for the receivers on merged faces (merged_last) */
    void **axis_sstate;           /* per light and axis (3 per light), for a method with MS_OCC_MERGE_EXACT: the
                                   * method over the light's set exact for that axis (occluders.h, for_axis) */
    void **interior_sstate;       /* per light with interior boxes, for a method with MS_OCC_INTERIOR_PASS: the
                                   * method over the boxes' triangles, run before the scene's */
    ms_occluders *occ;            /* per light: its occluders (sm->occluders, occluder_what), else NULL */
    ms_render_options opt;
    int W, H, tx, ty, ntiles, samples, spp, threads, rendered_any, streamed;
    /* The rows the planes (hits, surf, the frame's) hold: y_base .. y_base + rows_held; the whole frame, or
     * a band of band_rows at most when the outputs are streamed (frame_stream.c). */
    int y_base, rows_held, band_rows;
    /* Streamed: rows 0 .. rendered_to are rendered, 0 .. emitted_to handed out. With the interleaved filter
     * (band_filter) a band is handed out once two rows of the next are rendered: the planes then hold a window
     * of 2 band_rows + 2 rows from y_base, and the filtered band goes to band_vis, band_shadow, band_spec. */
    int rendered_to, emitted_to, band_filter;
    float *band_vis, *band_shadow, *band_spec;
    int aa_s, aa_split;           /* anti-aliasing: W, H are s times the output's; frame_aa.c resolves them */
    ms_hit *hits;
    ms_surface *surf;             /* per pixel, only for scenes with materials or normals (shade.h) */
    uint8_t *traced;              /* per tile: primary hits (and surfaces) are in hits (and surf) */
    ms_frame frame;
    double t_start;
    long done, total;             /* progress: tiles over the primary phase and every light's shadow phase */
    long reported;                /* the largest `done` handed to the progress callback */
    int cancelled;                /* the callback asked to stop: the remaining tiles are skipped */
};

/* CPU seconds of all the process's threads: on a shared machine, where wall time depends on the
 * neighbours, the figure to compare methods by. */
static double process_cpu_s(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts)) return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* One tile done. The callback runs on whichever thread finished a tile, one thread at a time and with
 * fractions that only grow (a late smaller count is dropped): reporting from thread 0 alone, as before,
 * said nothing at all when the other threads took every tile (a small frame), and missed the final 1. */
static void progress_tick(ms_frame_job *j)
{
    long d;
#pragma omp atomic capture
    d = ++j->done;
    if (!j->opt.progress) return;
#pragma omp critical(ms_frame_progress)
    if (d > j->reported && !j->cancelled) {
        j->reported = d;
        if (j->opt.progress(j->opt.progress_user, (double)d / (double)j->total)) {
#pragma omp atomic write
            j->cancelled = 1;
        }
    }
}

/* 1 once the progress callback cancelled the frame: a tile not begun is skipped. */
static int cancelled(ms_frame_job *j)
{
    int c;
#pragma omp atomic read
    c = j->cancelled;
    return c;
}

void ms_frame_job_free(ms_frame_job *j)
{
    if (!j) return;
    for (size_t l = 0; j->sstate && l < j->nlights; l++)
        if (j->sstate[l]) j->sm->destroy(j->sstate[l]);
    free(j->sstate);
    for (size_t l = 0; j->own_sstate && l < j->nlights; l++)
        if (j->own_sstate[l]) j->sm->destroy(j->own_sstate[l]);
    free(j->own_sstate);
    for (size_t l = 0; j->axis_sstate && l < 3 * j->nlights; l++)
        if (j->axis_sstate[l]) j->sm->destroy(j->axis_sstate[l]);
    free(j->axis_sstate);
    for (size_t l = 0; j->interior_sstate && l < j->nlights; l++)
        if (j->interior_sstate[l]) j->sm->destroy(j->interior_sstate[l]);
    free(j->interior_sstate);
    if (j->pm && j->pstate) j->pm->destroy(j->pstate);
    for (size_t l = 0; j->occ && l < j->nlights; l++) ms_occluders_free(&j->occ[l]);
    free(j->occ);
    free(j->placed_lights);
    ms_bvh_free(&j->bvh);
    ms_alpha_free(j->alpha);
    free(j->hits);
    free(j->surf);
    free(j->traced);
    free(j->band_vis);
    free(j->band_shadow);
    free(j->band_spec);
    ms_frame_free(&j->frame);
    if (j->own_soup) free(j->soup.tri);
    free(j);
}

/* What the lights' occluder sets hold for method sm under the options (MS_OCC_*; 0: the scene's BVH). */
static int occluder_what(const ms_shadow_method *sm, const ms_render_options *opt)
{
    const int cull = opt->closed_cull == MS_CLOSED_CULL_ON ||
                     (opt->closed_cull == MS_CLOSED_CULL_DEFAULT && (sm->occluders & MS_OCC_CULL_BY_DEFAULT));
    return sm->occluders & (cull ? ~0 : ~MS_OCC_CULL) & (opt->no_interior ? ~(MS_OCC_INTERIOR | MS_OCC_INTERIOR_PASS) : ~0) &
           (opt->no_merge ? ~MS_OCC_MERGE : ~0);
}

/* Light l's context: the frame's, with its light and, when the method takes them, its occluders. */
static void light_ctx(const ms_frame_job *j, size_t l, ms_render_ctx *c)
{
    *c = j->ctx;
    c->light = j->lights[l];
    if (j->occ && j->occ[l].active) {
        c->bvh = &j->occ[l].bvh;
        c->alpha = j->occ[l].alpha;
        c->prim_map = j->occ[l].prim_map;
        c->prim_merged = j->occ[l].prim_merged;
    }
    if (j->occ && j->occ[l].interior.n_tris) c->interior = &j->occ[l].interior;
}

/* Light l's context over the scene's own triangles (its interior boxes kept: they are exact for any
 * receiver), for the receivers on merged faces. */
static void light_own_ctx(const ms_frame_job *j, size_t l, ms_render_ctx *c)
{
    light_ctx(j, l, c);
    c->bvh = &j->bvh;
    c->alpha = j->alpha;
    c->prim_map = NULL;
    c->prim_merged = NULL;
}

/* Light l's context over its set exact for segments sheared along axis a (occluders.h, for_axis). */
static void light_axis_ctx(const ms_frame_job *j, size_t l, int a, ms_render_ctx *c)
{
    const ms_occluders *s = j->occ[l].for_axis[a];
    light_ctx(j, l, c);
    c->bvh = &s->bvh;
    c->alpha = s->alpha;
    c->prim_map = s->prim_map;
    c->prim_merged = NULL;
}

/* Light l's split of the samples among its exact sets (exact_split.h): the axes its merge is not exact for,
 * each with the state over its set exact for it, or over the scene's own triangles. axes 0: no split (a
 * method that need not equal raytrace, or nothing merged). */
static void light_split(const ms_frame_job *j, size_t l, ms_exact_split *sp)
{
    memset(sp, 0, sizeof *sp);
    if (!(j->sm->occluders & MS_OCC_MERGE_EXACT) || !j->occ || !j->occ[l].active) return;
    sp->axes = j->occ[l].merged_axes;
    for (int a = 0; a < 3; a++) {
        if (!(sp->axes >> a & 1u)) continue;
        ms_render_ctx c;
        if (j->occ[l].for_axis[a]) light_axis_ctx(j, l, a, &c);
        else light_own_ctx(j, l, &c);
        sp->state[a] = j->occ[l].for_axis[a] ? j->axis_sstate[3 * l + (size_t)a] : j->own_sstate[l];
        sp->bvh[a] = c.bvh;
        sp->alpha[a] = c.alpha;
        sp->prim_map[a] = c.prim_map;
    }
}

/* Light l's context over its interior boxes alone, for a method that takes them as occluders of its own
 * (MS_OCC_INTERIOR_PASS): no receiver lies on them, none is alpha-tested. */
static void light_interior_ctx(const ms_frame_job *j, size_t l, ms_render_ctx *c)
{
    light_ctx(j, l, c);
    c->bvh = c->interior;
    c->interior = NULL;
    c->alpha = NULL;
    c->prim_map = NULL;
    c->prim_merged = NULL;
}

/* Every light's occluders (occluders.h) with what the method takes and the options allow: the scene's
 * closed components and interior boxes once, then per light; sums into the stats. 0, or -1 when out of
 * memory. */
static int occluders_build(ms_frame_job *j, int what, ms_stats *st)
{
    ms_closed closed;
    ms_interior interior = { 0 };
    if (ms_closed_find(j->scene->tri, j->scene->n_tris, &closed)) return -1;
    int rc = 0;
    if (closed.n_cycles || (what & MS_OCC_MERGE)) {
        const double eps = ms_interior_clearance(&j->bvh, j->lights, j->nlights);
        if ((what & MS_OCC_INTERIOR) && closed.n_cycles)
            rc = ms_interior_find(j->scene->tri, j->scene->n_tris, &closed, MS_INTERIOR_RES, MS_INTERIOR_MIN_TRIS, eps, j->threads, &interior);
        j->occ = rc ? NULL : calloc(j->nlights, sizeof *j->occ);
        rc = j->occ ? 0 : -1;
        for (size_t l = 0; l < j->nlights && !rc; l++) {
            rc = ms_occluders_build(&j->occ[l], j->scene, &j->bvh, &closed, &interior, eps, j->alpha, &j->lights[l], what, j->threads);
            st->occluders_culled += j->occ[l].culled;
            st->interior_boxes += j->occ[l].interior_boxes;
            st->occluders_merged += j->occ[l].merged;
        }
    }
    ms_interior_free(&interior);
    ms_closed_free(&closed);
    return rc;
}

/* stream: MS_STREAM_OFF (the whole frame), MS_STREAM_ON (bands), or MS_STREAM_AUTO (bands when only they fit the
 * budget). */
static ms_status job_create(const ms_scene *scene, const ms_render_options *opt, int stream, ms_frame_job **out, char *err,
                      size_t errlen)
{
    *out = NULL;
    const double t_start = omp_get_wtime();
    const char *method = opt->method ? opt->method : MS_DEFAULT_METHOD;   /* zeroed options: defaults */
    const int auto_pick = strcmp(method, MS_AUTO_METHOD) == 0;
    if (auto_pick) method = ms_auto_method(opt->pattern);
    const ms_shadow_method *sm = ms_find_shadow_method(method);
    if (!sm) {
        if (ms_method_available(method) < 0) snprintf(err, errlen, "method '%s' is not compiled into this build", method);
        else snprintf(err, errlen, "unknown method '%s'", method);
        return MS_ERR_METHOD;
    }
    if (opt->shading != MS_SHADING_STANDARD && opt->shading != MS_SHADING_DIFFUSE) {
        snprintf(err, errlen, "shading %d is not MS_SHADING_STANDARD (0) or MS_SHADING_DIFFUSE (1)", (int)opt->shading);
        return MS_ERR_INVALID;
    }
    ms_frame_job *j = calloc(1, sizeof *j);
    if (!j) { snprintf(err, errlen, "out of memory"); return MS_ERR_NO_MEMORY; }
    j->t_start = t_start;
    j->opt = *opt;
    j->sm = sm;
    j->threads = opt->threads > 0 ? opt->threads : omp_get_num_procs();
    /* The primary: the option's, else the shadow method's pairing ("depth" for a streamed scene). */
    const int procedural = scene->procedural.type != MS_PROCEDURAL_NONE;
    const char *pname = opt->primary ? opt->primary : procedural && sm->streams ? "depth" : sm->primary;
    const ms_primary_method *pm = ms_find_primary_method(pname);
    if (!pm) {
        if (strcmp(pname, "embree") == 0) snprintf(err, errlen, "primary method 'embree' is not compiled into this build");
        else snprintf(err, errlen, "unknown primary method '%s' (bvh, embree, depth, 3dr-bb, 3dr-bin, 3dr-fc, 3dr-fs, 3dr-full)", pname);
        free(j);
        return MS_ERR_METHOD;
    }
    if (strcmp(pm->name, "depth") == 0 && !(procedural && sm->streams)) {
        snprintf(err, errlen, "primary method 'depth' needs a procedural scene and a streaming shadow method (e.g. hpc)");
        free(j);
        return MS_ERR_INVALID;
    }
    /* A procedural scene: streamed when the shadow method and the primary can (no BVH), else materialised
     * (below, once the options are checked and the budget allows it). */
    const int streamed = procedural && sm->streams && pm->streams;
    j->streamed = streamed;
    j->scene = scene;
    j->lights = ms_scene_lights(scene, &j->nlights);
    ms_status rc = MS_ERR_INVALID;
    const int samples = opt->samples > 0 ? opt->samples : scene->samples;
    /* Anti-aliasing: K primary samples per pixel as the pixels of an s-times larger frame (s = sqrt K), which
     * every primary and shadow method renders as it renders any frame; finish resolves it (frame_aa.c). */
    const int aa = opt->aa > 0 ? opt->aa : scene->aa > 0 ? scene->aa : 1;
    int aa_s = 1;
    while (aa_s * aa_s < aa) aa_s++;
    if (opt->aa < 0 || aa_s * aa_s != aa || aa_s > 4) { snprintf(err, errlen, "aa must be 1, 4, 9 or 16 (got %d)", opt->aa < 0 ? opt->aa : aa); goto fail; }
    const int aa_split = opt->aa_split && aa > 1;
    /* Split: each of the K hits gets N/K of the pixel's samples (its own pattern, seeded by its sub-pixel). */
    const int hit_samples = aa_split ? samples / aa : samples;
    if (aa_split && (samples % aa || !ms_pattern_samples_per_pixel(opt->pattern, hit_samples))) {
        snprintf(err, errlen, "aa_split: %d samples over %d primary samples leave %d each, not a sample count of the %s pattern",
                 samples, aa, samples / aa, ms_pattern_name(opt->pattern));
        goto fail;
    }
    if ((unsigned)opt->pattern > MS_PATTERN_INTERLEAVED) { snprintf(err, errlen, "unknown pattern %d", (int)opt->pattern); goto fail; }
    if ((unsigned)opt->traversal > MS_TRAVERSAL_PIXEL) { snprintf(err, errlen, "unknown traversal %d", (int)opt->traversal); goto fail; }
    if ((unsigned)opt->closed_cull > MS_CLOSED_CULL_OFF) { snprintf(err, errlen, "unknown closed_cull %d", (int)opt->closed_cull); goto fail; }
    /* Samples per pixel: N, or N/16 for interleaved; always a multiple of 16 (full ray packets). */
    const int spp = ms_pattern_samples_per_pixel(opt->pattern, hit_samples);
    if (!spp) {
        snprintf(err, errlen, "samples must be %s with the %s pattern (got %d)",
                 opt->pattern == MS_PATTERN_STRATIFIED ? "16, 64, 256, 1024 or 4096" : "256, 1024 or 4096",
                 ms_pattern_name(opt->pattern), samples);
        goto fail;
    }
    if (sm->needs_grid && opt->pattern != MS_PATTERN_GRID) {
        snprintf(err, errlen, "method '%s' needs --pattern grid", sm->name);
        goto fail;
    }
    const int W_out = opt->width > 0 ? opt->width : scene->camera.width;
    const int H_out = opt->height > 0 ? opt->height : scene->camera.height;
    /* The output's size; the s-times larger frame the methods render may exceed it (streamed, it is held a band
     * at a time, and the memory budget decides either way). */
    if (W_out < 1 || H_out < 1 || W_out > MS_MAX_IMAGE_SIZE || H_out > MS_MAX_IMAGE_SIZE) {
        snprintf(err, errlen, "width and height must be in [1, %d]", MS_MAX_IMAGE_SIZE);
        goto fail;
    }
    const int W = W_out * aa_s, H = H_out * aa_s;
    /* The memory budget, before anything proportional to the frame or the scene is allocated. */
    {
        ms_frame_shape fs;
        memset(&fs, 0, sizeof fs);
        fs.W = W;
        fs.H = H;
        fs.nl = j->nlights;
        fs.n_tris = scene->n_tris;
        fs.materialise = procedural && !streamed;
        fs.bvh = !streamed;
        fs.surf = !streamed && (scene->tri_material || scene->tri_normal);
        fs.mask_words = (spp + 63) / 64;
        fs.npk = spp / 16;
        fs.whole_frame = sm->visibility_all != NULL;
        fs.scanline_slots = strcmp(sm->name, "hpc-scanline") == 0;
        fs.shallow_per_light = (sm->needs_grid && opt->traversal != MS_TRAVERSAL_PIXEL) || strcmp(sm->name, "mft") == 0;
        fs.hpc_order = sm->visibility_all != NULL && !streamed;
        fs.embree = strcmp(sm->name, "embree") == 0 || strcmp(pm->name, "embree") == 0;
        fs.primary_depth = strcmp(pm->name, "depth") == 0;
        fs.primary_3dr = strncmp(pm->name, "3dr", 3) == 0;
        fs.primary_3dr_setups = fs.primary_3dr && !streamed;
        fs.filter = opt->pattern == MS_PATTERN_INTERLEAVED && !opt->no_filter;
        for (size_t l = 0; l < j->nlights; l++) fs.textured |= j->lights[l].texture != NULL;
        fs.threads = j->threads;
        fs.occluders = occluder_what(sm, opt) != 0;
        fs.exact_sets = (occluder_what(sm, opt) & (MS_OCC_MERGE | MS_OCC_MERGE_EXACT)) == (MS_OCC_MERGE | MS_OCC_MERGE_EXACT);
        /* Streamed outputs: bands of whole tile rows, by default about 512 tiles (and 16 per thread): a parallel
         * region per band and light costs a barrier, which on a loaded machine means waiting for a time slice
         * (bands of 128 tiles at 2048 wide took twice as long as the whole frame with the load at 11 on 2
         * cores); fewer rows when the budget needs. Not for frame-level methods (their receivers are the
         * whole frame). */
        const int tiles_x = (W + TILE - 1) / TILE, want = 16 * j->threads > 512 ? 16 * j->threads : 512;
        /* Anti-aliased, a band holds whole blocks of output rows (frame_stream.c resolves each band; the EXR
         * writer takes 16-row blocks): its rows of the s-times larger frame are a multiple of s tiles. */
        const int unit = aa_s * TILE;
        fs.aa_s = aa_s;
        const int streamable = !sm->visibility_all;
        if (opt->stream_rows < 0 || opt->stream_rows % unit) {
            snprintf(err, errlen, "stream_rows %d is not a multiple of %d%s", opt->stream_rows, unit, aa_s > 1 ? " (with anti-aliasing: the tile times its scale)" : "");
            goto fail;
        }
        const int unit_tiles = tiles_x * aa_s;   /* the tiles of one band unit */
        fs.stream_rows = !streamable ? 0 : opt->stream_rows ? opt->stream_rows : unit * ((want + unit_tiles - 1) / unit_tiles);
        const uint64_t budget = ms_memory_budget(opt->max_memory);
        if (stream == MS_STREAM_ON && !streamable) {
            snprintf(err, errlen, "streamed outputs: the method takes the whole frame at once (its receivers are all of the frame's pixels)");
            goto fail;
        }
        /* AUTO streams only when that fits where the whole frame does not: else the whole frame's refusal names
         * what would fit (--stream among it, with its need). */
        if (stream == MS_STREAM_ON || (stream == MS_STREAM_AUTO && streamable && ms_frame_need(&fs, NULL) > budget)) {
            ms_frame_shape t = fs;
            t.band_rows = opt->stream_rows ? opt->stream_rows : ms_frame_band_rows(&fs, fs.stream_rows, budget);
            if (stream == MS_STREAM_ON || ms_frame_need(&t, NULL) <= budget) {
                fs = t;
                j->band_rows = fs.band_rows < H ? fs.band_rows : H;
            }
        }
        if (ms_frame_budget_check(&fs, budget, err, errlen)) {
            if (auto_pick && fs.materialise && opt->pattern == MS_PATTERN_GRID && !opt->primary) {
                /* "auto": a procedural scene that does not fit materialised is streamed by hpc. */
                ms_frame_job_free(j);
                ms_render_options streamed_opt = *opt;
                streamed_opt.method = "hpc";
                return job_create(scene, &streamed_opt, stream, out, err, errlen);
            }
            rc = MS_ERR_BUDGET;
            goto fail;
        }
        j->frame.stats.memory_need = ms_frame_need(&fs, NULL);
        j->frame.stats.memory_budget = budget;
    }
    if (procedural && !streamed) {
        if (ms_scene_materialise(scene, j->threads, &j->soup, err, errlen)) goto fail;
        j->own_soup = 1;
        scene = &j->soup;
        j->scene = scene;
        j->lights = ms_scene_lights(scene, &j->nlights);
        j->t_start = omp_get_wtime();   /* the generation counts as loading (soup.load_s) */
    }
    ms_render_ctx *ctx = &j->ctx;
    ms_render_ctx_init(ctx, scene, streamed ? NULL : &j->bvh, &j->lights[0], opt->pattern, ms_samples_to_k(hit_samples),
                       opt->seed, j->threads);
    if (ms_camera_basis_init(&ctx->cam, &scene->camera, W, H)) {
        snprintf(err, errlen, "camera is degenerate (eye = target, up parallel to the view, or a field of view, extent or type out of range)");
        goto fail;
    }
    if (!streamed && ms_bvh_build(&j->bvh, scene->tri, scene->n_tris, j->threads)) { snprintf(err, errlen, "BVH build failed: out of memory"); rc = MS_ERR_NO_MEMORY; goto fail; }
    {   /* suns placed for the scene's box before anything uses the lights' geometry */
        int oom;
        j->placed_lights = ms_lights_placed(j->lights, j->nlights, scene, streamed ? NULL : &j->bvh, &oom);
        if (oom) { snprintf(err, errlen, "out of memory for the lights"); rc = MS_ERR_NO_MEMORY; goto fail; }
        if (j->placed_lights) { j->lights = j->placed_lights; ctx->light = j->lights[0]; }
    }
    if (!streamed && ms_alpha_build(scene, &j->bvh, &j->alpha)) { snprintf(err, errlen, "out of memory for the alpha-tested triangles"); rc = MS_ERR_NO_MEMORY; goto fail; }
    ctx->alpha = j->alpha;
    ctx->isa_cap = opt->isa;
    ctx->no_occlusion_cull = opt->no_occlusion_cull;
    ctx->no_child_order = opt->no_child_order;
    ctx->traversal = opt->traversal;
    ctx->frustum_shrink = opt->frustum_shrink;
    ctx->embree_mode = opt->embree_mode;
    ctx->embree_filter = opt->embree_filter;
    ctx->consistent_primary = opt->consistent_primary;
    j->W = W;
    j->H = H;
    j->samples = samples;
    j->spp = spp;
    j->aa_s = aa_s;
    j->aa_split = aa_split;
    j->tx = (W + TILE - 1) / TILE;
    j->ty = (H + TILE - 1) / TILE;
    j->ntiles = j->tx * j->ty;
    j->total = (long)(1 + j->nlights) * j->ntiles;

    j->band_filter = j->band_rows && opt->pattern == MS_PATTERN_INTERLEAVED && !opt->no_filter;
    j->rows_held = !j->band_rows ? H : j->band_filter ? (2 * j->band_rows + 2 < H ? 2 * j->band_rows + 2 : H) : j->band_rows;
    const size_t npix = (size_t)W * j->rows_held, nl = j->nlights;
    if (j->band_filter) {
        const size_t nb = nl * (size_t)W * (size_t)j->band_rows;
        j->band_vis = malloc(nb * sizeof(float));
        j->band_shadow = malloc(nb * sizeof(float));
        j->band_spec = malloc(nb * sizeof(float));
        if (!j->band_vis || !j->band_shadow || !j->band_spec) { snprintf(err, errlen, "out of memory for a %dx%d band", W, j->band_rows); rc = MS_ERR_NO_MEMORY; goto fail; }
    }
    j->hits = malloc(npix * sizeof *j->hits);
    j->traced = calloc((size_t)j->ntiles, 1);
    j->sstate = calloc(nl, sizeof *j->sstate);
    j->own_sstate = calloc(nl, sizeof *j->own_sstate);
    j->axis_sstate = calloc(3 * nl, sizeof *j->axis_sstate);
    j->interior_sstate = calloc(nl, sizeof *j->interior_sstate);
    ms_frame *f = &j->frame;
    f->vis = calloc(nl * npix, sizeof(float));   /* zero until rendered: a finish without tiles reads them */
    f->shadow = calloc(nl * npix, sizeof(float));
    f->shadow_spec = calloc(nl * npix, sizeof(float));
    f->front = calloc(nl * npix, sizeof *f->front);
    f->rgb = malloc(npix * 3 * sizeof(float));
    f->n_lights = (int)nl;
    if (!j->hits || !j->traced || !j->sstate || !j->own_sstate || !j->axis_sstate || !j->interior_sstate || !f->vis || !f->shadow || !f->shadow_spec || !f->front || !f->rgb) {
        snprintf(err, errlen, "out of memory for a %dx%d frame", W, H);
        rc = MS_ERR_NO_MEMORY;
        goto fail;
    }
    /* The surfaces (material, shading normal) of the hits: S_spec needs them with the masks. */
    if (!streamed && (scene->tri_material || scene->tri_normal)) {
        j->surf = malloc(npix * sizeof *j->surf);
        if (!j->surf) { snprintf(err, errlen, "out of memory for the surfaces of a %dx%d frame", W, H); rc = MS_ERR_NO_MEMORY; goto fail; }
    }
    f->width = W;
    f->height = j->rows_held;
    /* The primary's create is timed as primary visibility: the rasterizing primaries (3dr-*, depth) do
     * their whole pass there. */
    const double t_primary = omp_get_wtime();
    void *pstate = NULL;
    if (pm->create(ctx, &pstate, err, errlen)) goto fail;
    j->pm = pm;
    j->pstate = pstate;
    f->stats.primary_s = omp_get_wtime() - t_primary;
    const double t_setup = omp_get_wtime();
    const int occ_what = occluder_what(sm, opt);
    if (occ_what && !streamed && occluders_build(j, occ_what, &f->stats)) {
        snprintf(err, errlen, "out of memory for the lights' occluders");
        rc = MS_ERR_NO_MEMORY;
        goto fail;
    }
    for (size_t l = 0; l < nl; l++) {
        ms_render_ctx lc;
        light_ctx(j, l, &lc);
        if (sm->create(&lc, &j->sstate[l], err, errlen)) { j->sstate[l] = NULL; rc = MS_ERR_METHOD; goto fail; }
        if (lc.prim_merged) {
            light_own_ctx(j, l, &lc);
            if (sm->create(&lc, &j->own_sstate[l], err, errlen)) { j->own_sstate[l] = NULL; rc = MS_ERR_METHOD; goto fail; }
        }
        for (int a = 0; a < 3 && (sm->occluders & MS_OCC_MERGE_EXACT) && j->occ && j->occ[l].active; a++) {
            if (!j->occ[l].for_axis[a]) continue;
            light_axis_ctx(j, l, a, &lc);
            void **st = &j->axis_sstate[3 * l + (size_t)a];
            if (sm->create(&lc, st, err, errlen)) { *st = NULL; rc = MS_ERR_METHOD; goto fail; }
        }
        light_ctx(j, l, &lc);
        if ((sm->occluders & MS_OCC_INTERIOR_PASS) && lc.interior) {
            light_interior_ctx(j, l, &lc);
            if (sm->create(&lc, &j->interior_sstate[l], err, errlen)) { j->interior_sstate[l] = NULL; rc = MS_ERR_METHOD; goto fail; }
        }
    }
    ms_stats *st = &f->stats;
    st->setup_s = omp_get_wtime() - t_setup;
    st->build_s = j->bvh.build_s;
    /* The last light's state speaks for the stats (isa_used, counters_used), as the counters sum over lights. */
    void *const last = j->sstate[nl - 1];
    const char *const *cnames = sm->counter_names;
    st->n_counters = sm->n_counters;
    if (sm->counters_used) {
        const int n = sm->counters_used(last, &cnames);
        if (n >= 0) st->n_counters = n;
        else cnames = sm->counter_names;
    }
    for (int c = 0; c < st->n_counters; c++) st->counter_name[c] = cnames[c];
    *out = j;
    return 0;
fail:
    ms_frame_job_free(j);
    return rc;
}

ms_status ms_frame_job_create_abi(const ms_abi *abi, const ms_scene *scene, const ms_render_options *opt,
                                  ms_frame_job **out, char *err, size_t errlen)
{
    *out = NULL;
    const ms_status st = ms_abi_check(abi, "ms_frame_job_create", err, errlen);
    if (st) return st;
    return job_create(scene, opt, MS_STREAM_OFF, out, err, errlen);
}

int ms_frame_job_create_stream(const ms_scene *scene, const ms_render_options *opt, int stream, ms_frame_job **out,
                               int *band_rows, char *err, size_t errlen)
{
    const int rc = job_create(scene, opt, stream, out, err, errlen);
    *band_rows = rc ? 0 : (*out)->band_rows;
    return rc;
}

int ms_frame_job_tiles(const ms_frame_job *j, int *tiles_x, int *tiles_y)
{
    if (tiles_x) *tiles_x = j->tx;
    if (tiles_y) *tiles_y = j->ty;
    return j->ntiles;
}

int ms_frame_job_splittable(const ms_frame_job *j)
{
    return !j->sm->visibility_all || j->sm->split_exact;
}

ms_frame *ms_frame_job_frame(ms_frame_job *j) { return &j->frame; }

static void tile_rect(const ms_frame_job *j, int t, int *x0, int *y0, int *x1, int *y1)
{
    *x0 = (t % j->tx) * TILE;
    *y0 = (t / j->tx) * TILE;
    *x1 = *x0 + TILE < j->W ? *x0 + TILE : j->W;
    *y1 = *y0 + TILE < j->H ? *y0 + TILE : j->H;
}

/* Primary hits of tiles[0..n) (tiles == NULL: 0..n-1) into j->hits. */
static void trace_tiles(ms_frame_job *j, const int *tiles, int n, int tick)
{
#pragma omp parallel for schedule(dynamic, 1) num_threads(j->threads)
    for (int i = 0; i < n; i++) {
        if (tick && cancelled(j)) continue;
        const int t = tiles ? tiles[i] : i;
        int x0, y0, x1, y1;
        tile_rect(j, t, &x0, &y0, &x1, &y1);
        ms_hit tile[TILE * TILE];
        j->pm->trace(j->pstate, &j->ctx, x0, y0, x1, y1, tile);
        for (int y = y0; y < y1; y++)
            memcpy(&j->hits[(size_t)(y - j->y_base) * j->W + x0], &tile[(y - y0) * (x1 - x0)], (size_t)(x1 - x0) * sizeof *tile);
        j->traced[t] = 1;
        if (tick) progress_tick(j);
    }
}

/* The surfaces of the hits of tiles[0..n) (tiles == NULL: 0..n-1), when the scene has any. */
static void surface_tiles(ms_frame_job *j, const int *tiles, int n)
{
    if (!j->surf) return;
#pragma omp parallel for schedule(dynamic, 1) num_threads(j->threads)
    for (int i = 0; i < n; i++) {
        int x0, y0, x1, y1;
        tile_rect(j, tiles ? tiles[i] : i, &x0, &y0, &x1, &y1);
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) {
                const size_t p = (size_t)(y - j->y_base) * j->W + x;
                float viewer[3];   /* the eye, or up the pixel's own ray for an orthographic camera */
                ms_camera_viewer(&j->ctx.cam, j->hits[p].p, viewer);
                ms_surface_at(j->scene, &j->bvh, &j->hits[p], viewer, j->opt.shading, &j->surf[p]);
            }
    }
}

/* Sums of the shadow passes of one call. */
typedef struct pass_sums {
    uint64_t counters[MS_MAX_COUNTERS];
    uint64_t visible, penumbra, segments, on_merged;
    double resolve_thread_s;
} pass_sums;

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

/* The shadow phase of light l over tiles[0..n) (tiles == NULL: 0..n-1; whole: the frame's first and only
 * call): front masks, the method's visible masks, V, S and S_spec into light l's planes, over 16x16 tiles
 * (or the method's frame-level entry). Adds to p. 0, or -1 out of memory or when the method fails. */
static int shadow_pass(ms_frame_job *j, size_t l, const int *tiles, int n, int whole, pass_sums *p)
{
    const ms_shadow_method *sm = j->sm;
    void *const sstate = j->sstate[l];
    void *const own_state = j->own_sstate[l];
    void *const interior_state = j->interior_sstate[l];
    ms_render_ctx ictx;
    if (interior_state) light_interior_ctx(j, l, &ictx);
    ms_render_ctx lctx;
    light_ctx(j, l, &lctx);
    const ms_render_ctx ctx = lctx;
    const int W = j->W;
    const size_t npix = (size_t)W * j->rows_held, mw = (size_t)ctx.mask_words;
    ms_frame *const out = &j->frame;
    float *const vis = out->vis + l * npix, *const shadow = out->shadow + l * npix;
    float *const spec = out->shadow_spec + l * npix;   /* S_spec (shade.h) where surf has a specular lobe, else S */
    uint16_t *const fr = out->front + l * npix;
    const ms_surface *const surf = j->surf;
    const ms_hit *const hits = j->hits;
    uint64_t visible = 0, penumbra = 0, segments = 0, on_merged = 0;
    double resolve_thread_s = 0.0;
    int failed = 0;
    const int stratified = ctx.pattern != MS_PATTERN_GRID;   /* sample points listed (not the grid) */
    /* A sphere or a sun: each receiver has its own light, the shape's outline seen from it (a per-query light
     * frame: ms_light_sphere_outline, ms_light_sun_outline). A method that declares .outlines (the
     * micro-rasterization methods) takes the tile's queries together, with ctx.outline_per_query, and sets
     * each query's light itself (ms_ctx_for_query), keeping its 4x4 blocks. Any other is called one query
     * at a time with a context whose light is that outline, so every method answers on the same
     * per-receiver samples as raytrace, whatever it sets up per frame (mft re-derives its light frame per
     * call; hpc sets up its light per call, so an outlined light costs it a pass over every triangle per
     * receiver); frame-level entries are not used. */
    const ms_light_shape_ops *shape = ms_light_shape_of(ctx.light.shape);
    const int outlined = shape && shape->outline;   /* a per-receiver light: the shape's outline (light_shape.h) */
    const int batched = outlined && sm->outlines;    /* ... which the method takes a tile at a time */
    ms_render_ctx bctx = ctx;   /* the batch's context: each query's light its outline */
    bctx.outline_per_query = 1;
    const int shadow_tiles = sm->visibility_all && !outlined ? 0 : n;   /* a frame-level method: shadow_frame.c */
    /* The samples of the axes the merged set is not exact for go to the sets that are (exact_split.h); not for
     * a batch of outlined lights (the micro-rasterization methods, which do not equal raytrace anyway). */
    ms_exact_split split;
    light_split(j, l, &split);
    if (batched) split.axes = 0;
#pragma omp parallel num_threads(j->threads)
    {
        uint64_t local[MS_MAX_COUNTERS] = { 0 };
        uint64_t local_visible = 0, local_penumbra = 0, local_segments = 0, local_on_merged = 0;
        double local_resolve = 0.0;
        /* Per thread: the tile's front and visible masks, and the stratified pattern's points. */
        uint64_t *front = aligned_alloc(64, TILE * TILE * mw * sizeof *front);
        uint64_t *vmask = aligned_alloc(64, TILE * TILE * mw * sizeof *vmask);
        /* The samples the interior boxes leave (MS_OCC_INTERIOR_PASS). */
        uint64_t *imask = interior_state ? aligned_alloc(64, TILE * TILE * mw * sizeof *imask) : NULL;
        float *pts = stratified ? malloc((size_t)ctx.samples * 3 * sizeof *pts) : NULL;
        /* merged_last's scratch: the frame's one light (an outlined light's samples are the query's own) */
        float *mpts = ctx.prim_merged && !outlined ? malloc((size_t)ctx.samples * 3 * sizeof *mpts) : NULL;
        float hull[8][3], hull_box[6];
        const int n_hull = ms_light_hull(&ctx.light, hull, hull_box);
        int ok = front && vmask && (pts || !stratified) && (imask || !interior_state) && (mpts || !ctx.prim_merged || outlined);
#pragma omp for schedule(dynamic, 1)
        for (int ti = 0; ti < shadow_tiles; ti++) {
            if (cancelled(j)) continue;
            int x0, y0, x1, y1;
            tile_rect(j, tiles ? tiles[ti] : ti, &x0, &y0, &x1, &y1);
            ms_shadow_query q[TILE * TILE];
            size_t where[TILE * TILE];
            ms_render_ctx qc = ctx;   /* the query's context: the frame's, or with a sphere's outline disk */
            int nq = 0;
            for (int y = y0; y < y1 && ok; y++)
                for (int x = x0; x < x1; x++) {
                    size_t i = (size_t)(y - j->y_base) * W + x;
                    const ms_hit *h = &hits[i];
                    if (h->prim == UINT32_MAX) { vis[i] = shadow[i] = spec[i] = -1.0f; fr[i] = 0; continue; }
                    ms_query_from_hit(&q[nq], h, (uint32_t)x, (uint32_t)y);
                    q[nq].prim = ms_ctx_skip_prim(&ctx, h->prim);
                    if (outlined && shape->outline(&ctx.light, q[nq].p, &qc.light)) {
                        vis[i] = shadow[i] = spec[i] = 0.0f;   /* inside the sphere: no sample counts */
                        fr[i] = 0;
                        local_visible++;
                        continue;
                    }
                    if (pts) ms_pattern_points(ctx.pattern, &qc.light, ctx.k, q[nq].px, q[nq].py, ctx.seed, pts);
                    const int nf = ms_front_mask(&qc, &q[nq], pts, front + (size_t)nq * mw);
                    fr[i] = (uint16_t)nf;
                    local_segments += (uint64_t)nf;
                    where[nq++] = i;
                }
            const int nm = ctx.prim_merged && ok ? merged_last(&ctx, &j->bvh, hits, (const float (*)[3])hull, n_hull, q, where, front, mw, nq, mpts) : nq;
            uint32_t scene_prim[TILE * TILE];   /* the receivers' hit triangles, for the exact split */
            for (int i = 0; i < nm && split.axes; i++) scene_prim[i] = hits[where[i]].prim;
            if (!outlined && interior_state && nm && ok) {
                /* The interior boxes first (no receiver on them: no prim to skip), then the triangles
                 * with the samples they left. */
                uint32_t prim[TILE * TILE];
                for (int i = 0; i < nm; i++) { prim[i] = q[i].prim; q[i].prim = UINT32_MAX; }
                if (sm->visibility(interior_state, &ictx, q, nm, front, imask, local)) ok = 0;
                for (int i = 0; i < nm; i++) q[i].prim = prim[i];
                if (ok && visibility_of(sm, sstate, &ctx, &split, q, scene_prim, nm, imask, vmask, local)) ok = 0;
            } else if (!outlined || batched) {
                if (nm && ok && visibility_of(sm, sstate, batched ? &bctx : &ctx, &split, q, scene_prim, nm, front, vmask, local)) ok = 0;
            } else
                for (int i = 0; i < nm && ok; i++) {
                    shape->outline(&ctx.light, q[i].p, &qc.light);
                    if (visibility_of(sm, sstate, &qc, &split, &q[i], scene_prim + i, 1, front + (size_t)i * mw, vmask + (size_t)i * mw, local)) ok = 0;
                }
            /* Receivers on merged faces that the merge could answer otherwise: the same method over the
             * scene's own triangles (was: the reference tracer, 19% of the grid of bars' shadow time). */
            if (nm < nq && ok) {
                ms_render_ctx rc;
                light_own_ctx(j, l, &rc);
                for (int i = nm; i < nq; i++) q[i].prim = hits[where[i]].prim;   /* the receivers' own prims */
                rc.outline_per_query = batched;
                if (!outlined || batched) {
                    if (sm->visibility(own_state, &rc, q + nm, nq - nm, front + (size_t)nm * mw, vmask + (size_t)nm * mw, local)) ok = 0;
                } else
                    for (int i = nm; i < nq && ok; i++) {
                        ms_render_ctx qrc = rc;
                        shape->outline(&ctx.light, q[i].p, &qrc.light);
                        if (sm->visibility(own_state, &qrc, &q[i], 1, front + (size_t)i * mw, vmask + (size_t)i * mw, local)) ok = 0;
                    }
                local_on_merged += (uint64_t)(nq - nm);
            }
            const double tr = omp_get_wtime();
            for (int i = 0; i < nq && ok; i++) {
                if (outlined) shape->outline(&ctx.light, q[i].p, &qc.light);
                if (pts) ms_pattern_points(ctx.pattern, &qc.light, ctx.k, q[i].px, q[i].py, ctx.seed, pts);
                local_penumbra += (uint64_t)ms_resolve_vs(&qc, &q[i], pts, front + (size_t)i * mw,
                                                          vmask + (size_t)i * mw, &vis[where[i]],
                                                          &shadow[where[i]]);
                spec[where[i]] = surf && surf[where[i]].specular
                    ? ms_resolve_spec(&qc, &q[i], pts, front + (size_t)i * mw, vmask + (size_t)i * mw, &surf[where[i]])
                    : shadow[where[i]];
            }
            local_resolve += omp_get_wtime() - tr;
            local_visible += (uint64_t)nq;
            progress_tick(j);
        }
        free(front);
        free(vmask);
        free(imask);
        free(pts);
        free(mpts);
#pragma omp critical(ms_counters)
        {
            for (int c = 0; c < MS_MAX_COUNTERS; c++) p->counters[c] += local[c];
            visible += local_visible;
            penumbra += local_penumbra;
            segments += local_segments;
            on_merged += local_on_merged;
            resolve_thread_s += local_resolve;
            failed |= !ok;
        }
    }
    if (sm->visibility_all && !outlined && !failed) {
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
        light_own_ctx(j, l, &own_ctx);
        if (!failed)
            failed = ms_shadow_frame_whole(sm, sstate, &ctx, &split, own_state, &own_ctx, hits, surf, W, j->H, pixels, np, vis,
                                           shadow, spec, fr, p->counters, &visible, &penumbra, &segments, &on_merged,
                                           &resolve_thread_s) != 0;
        free(pixels);
    }
    p->visible += visible;
    p->penumbra += penumbra;
    p->segments += segments;
    p->on_merged += on_merged;
    p->resolve_thread_s += resolve_thread_s;
    return failed ? -1 : 0;
}

ms_status ms_frame_job_render(ms_frame_job *j, const int *tiles, int n, char *err, size_t errlen)
{
    const ms_shadow_method *sm = j->sm;
    const int whole = !tiles && n == j->ntiles && !j->rendered_any;
    if (!tiles && n != j->ntiles) { snprintf(err, errlen, "ms_frame_job_render: tiles is NULL but n is not the frame's %d tiles", j->ntiles); return MS_ERR_INVALID; }
    for (int i = 0; tiles && i < n; i++)
        if (tiles[i] < 0 || tiles[i] >= j->ntiles) { snprintf(err, errlen, "ms_frame_job_render: tile %d is not in [0, %d)", tiles[i], j->ntiles); return MS_ERR_INVALID; }
    if (!whole && !ms_frame_job_splittable(j)) {
        snprintf(err, errlen, "method '%s' renders only whole frames (the receivers its hierarchy rasterizes triangles for, "
                 "and so its rounding at their edges, depend on all of the frame's pixels)", sm->name);
        return MS_ERR_INVALID;
    }
    j->rendered_any = 1;
    ms_stats *st = &j->frame.stats;
    const double t0 = omp_get_wtime();
    trace_tiles(j, tiles, n, 1);
    if (cancelled(j)) { snprintf(err, errlen, "cancelled by the progress callback"); return MS_ERR_CANCELLED; }
    const double t1 = omp_get_wtime();
    const double c1 = process_cpu_s();

    /* The surfaces are timed with the shadow phase (a lookup per pixel, far below the shadow cost). Each
     * light in turn, with its own state and planes; the hits and surfaces are shared. */
    surface_tiles(j, tiles, n);
    pass_sums p;
    memset(&p, 0, sizeof p);
    int failed = 0;
    for (size_t l = 0; l < j->nlights && !failed && !cancelled(j); l++) failed = shadow_pass(j, l, tiles, n, whole, &p) != 0;
    if (cancelled(j)) { snprintf(err, errlen, "cancelled by the progress callback"); return MS_ERR_CANCELLED; }
    if (failed) {
        snprintf(err, errlen, "out of memory in the shadow phase of method '%s'", sm->name);
        return MS_ERR_NO_MEMORY;
    }
    st->primary_s += t1 - t0;
    st->shadow_s += omp_get_wtime() - t1;
    st->shadow_cpu_s += process_cpu_s() - c1;
    for (int c = 0; c < MS_MAX_COUNTERS; c++) st->counter[c] += p.counters[c];
    st->visible_pixels += p.visible / j->nlights;   /* every light's pass counts each visible pixel once */
    st->penumbra_pixels += p.penumbra;
    st->receivers_on_merged += p.on_merged;
    st->shadow_rays += p.segments;
    st->shadow_factor_s += p.resolve_thread_s;
    return 0;
}

/* The frame's stats once every tile is rendered (finish, or a streamed frame's last band). */
static void job_stats(ms_frame_job *j, ms_stats *st)
{
    const size_t nl = j->nlights;
    st->triangles = j->scene->n_tris;
    st->load_s = j->scene->load_s;
    st->samples = j->samples;
    st->samples_per_pixel = j->spp * (j->aa_split ? j->aa_s * j->aa_s : 1);
    st->threads = j->threads;
    st->width = j->W;
    st->height = j->H;
    st->method = j->sm->name;
    st->primary = j->pm->name;
    if (j->pm->counters) {
        uint64_t c[3];
        j->pm->counters(j->pstate, c);
        st->primary_setups = c[0];
        st->primary_edge_evals = c[1];
        st->primary_nodes = c[2];
    }
    ms_isa kisa = MS_ISA_AUTO, tisa = MS_ISA_AUTO;
    if (j->sm->isa_used) j->sm->isa_used(j->sstate[nl - 1], &kisa, &tisa);
    st->kernel_isa = kisa == MS_ISA_AUTO ? "none" : ms_isa_name(kisa);
    st->traversal_isa = tisa == MS_ISA_AUTO ? "none" : ms_isa_name(tisa);
    st->pattern = ms_pattern_name(j->opt.pattern);
    st->shadow_factor_s /= j->threads;   /* thread-seconds to seconds */
    st->total_s = omp_get_wtime() - j->t_start + j->scene->load_s;
}

ms_status ms_frame_job_finish(ms_frame_job *j, ms_frame *out, char *err, size_t errlen)
{
    if (j->band_rows) { snprintf(err, errlen, "ms_frame_job_finish: a streamed job's frame is written band by band"); return MS_ERR_INVALID; }
    memset(out, 0, sizeof *out);
    ms_frame *f = &j->frame;
    ms_stats *st = &f->stats;
    const int W = j->W, H = j->H;
    const size_t npix = (size_t)W * H, nl = j->nlights;
    /* Hit points (and surfaces) of the tiles other jobs rendered: the filter and the shading need them all. */
    int *missing = malloc((size_t)j->ntiles * sizeof *missing), nm = 0;
    if (!missing) { snprintf(err, errlen, "out of memory for a %dx%d frame", W, H); return MS_ERR_NO_MEMORY; }
    for (int t = 0; t < j->ntiles; t++)
        if (!j->traced[t]) missing[nm++] = t;
    const double tp = omp_get_wtime();
    if (nm) {
        trace_tiles(j, missing, nm, 0);
        surface_tiles(j, missing, nm);
    }
    free(missing);
    st->primary_s += omp_get_wtime() - tp;
    /* The interleaved pattern's filter belongs to its shadow cost (timed in shadow_s and on its own). */
    if (j->ctx.pattern == MS_PATTERN_INTERLEAVED && !j->opt.no_filter) {
        const double tf = omp_get_wtime(), cf = process_cpu_s();
        /* S_spec through the same filter, with the same raw V deciding the neighbours (one pass for both). */
        int ferr = 0;
        for (size_t l = 0; l < nl && !ferr; l++)
            ferr = ms_interleave_filter(W, H, j->hits, f->front + l * npix, f->vis + l * npix, f->shadow + l * npix,
                                        j->surf ? f->shadow_spec + l * npix : NULL, j->threads);
        if (ferr) {
            snprintf(err, errlen, "out of memory for the interleaved filter of a %dx%d frame", W, H);
            return MS_ERR_NO_MEMORY;
        }
        st->filter_s = omp_get_wtime() - tf;
        st->shadow_s += st->filter_s;
        st->shadow_cpu_s += process_cpu_s() - cf;
    }
    if (ms_frame_shade(j->scene, &j->ctx, j->lights, nl, j->hits, j->surf, j->threads, 0, f, NULL)) {
        snprintf(err, errlen, "out of memory for the textured lights of a %dx%d frame", W, H);
        return MS_ERR_NO_MEMORY;
    }
    if (j->aa_s > 1 && ms_frame_aa_resolve(f, j->aa_s, j->aa_split ? j->aa_s * j->aa_s : 1)) {
        snprintf(err, errlen, "out of memory resolving the anti-aliased %dx%d frame", W / j->aa_s, H / j->aa_s);
        return MS_ERR_NO_MEMORY;
    }

    job_stats(j, st);
    *out = *f;
    memset(f, 0, sizeof *f);
    return 0;
}

int ms_frame_job_band_render(ms_frame_job *j, int y0, int rows, char *err, size_t errlen)
{
    if (!j->band_rows || y0 != j->rendered_to || y0 % TILE || rows < 1 || rows > j->band_rows || (rows % TILE && y0 + rows != j->H) ||
        y0 + rows > j->H) {
        snprintf(err, errlen, "ms_frame_job_band_render: rows %d..%d are not the next band of whole tile rows", y0, y0 + rows);
        return -1;
    }
    /* Without the filter the planes hold this band alone (light l's plane at l * W * rows, as in a frame of that
     * height); with it they keep the window from y_base (shifted in ms_frame_job_band_take). */
    if (!j->band_filter) {
        j->y_base = y0;
        j->rows_held = rows;
    }
    const int ty0 = y0 / TILE, ty1 = (y0 + rows + TILE - 1) / TILE, n = (ty1 - ty0) * j->tx;
    int *tiles = malloc((size_t)n * sizeof *tiles);
    if (!tiles) { snprintf(err, errlen, "out of memory"); return -1; }
    for (int i = 0; i < n; i++) tiles[i] = ty0 * j->tx + i;
    const int rc = ms_frame_job_render(j, tiles, n, err, errlen);
    free(tiles);
    if (!rc) j->rendered_to = y0 + rows;
    return rc;
}

/* Moves rows from .. rendered_to of every plane of the window to its start. */
static void window_shift(ms_frame_job *j, int from)
{
    const size_t W = (size_t)j->W, cap = W * (size_t)j->rows_held, off = (size_t)(from - j->y_base) * W;
    const size_t keep = (size_t)(j->rendered_to - from) * W;
    memmove(j->hits, j->hits + off, keep * sizeof *j->hits);
    if (j->surf) memmove(j->surf, j->surf + off, keep * sizeof *j->surf);
    ms_frame *f = &j->frame;
    for (size_t l = 0; l < j->nlights; l++) {
        memmove(f->vis + l * cap, f->vis + l * cap + off, keep * sizeof *f->vis);
        memmove(f->shadow + l * cap, f->shadow + l * cap + off, keep * sizeof *f->shadow);
        memmove(f->shadow_spec + l * cap, f->shadow_spec + l * cap + off, keep * sizeof *f->shadow_spec);
        memmove(f->front + l * cap, f->front + l * cap + off, keep * sizeof *f->front);
    }
    j->y_base = from;
}

int ms_frame_job_band_take(ms_frame_job *j, ms_frame *band, int *y0, float *lum, char *err, size_t errlen)
{
    const int a = j->emitted_to, W = j->W;
    int b = j->band_filter ? a + j->band_rows : j->rendered_to;
    if (b > j->H) b = j->H;
    /* The filter reads two rows below the band: ready once they are rendered (or the frame ends there). */
    if (a >= j->rendered_to || (j->band_filter && j->rendered_to < (b + 2 < j->H ? b + 2 : j->H))) return 0;
    ms_frame *f = &j->frame, bf = *f;
    bf.height = b - a;
    const size_t off = (size_t)(a - j->y_base) * (size_t)W;
    if (j->band_filter) {
        const size_t cap = (size_t)W * (size_t)j->rows_held, bn = (size_t)W * (size_t)(b - a);
        const double tf = omp_get_wtime();
        for (size_t l = 0; l < j->nlights; l++)
            if (ms_interleave_filter_rows(W, j->H, j->hits, f->front + l * cap, f->vis + l * cap, f->shadow + l * cap,
                                          f->shadow_spec + l * cap, j->y_base, j->rows_held, a, b, j->band_vis + l * bn,
                                          j->band_shadow + l * bn, j->band_spec + l * bn, j->threads)) {
                snprintf(err, errlen, "out of memory for the interleaved filter of a %d-pixel-wide band", W);
                return -1;
            }
        const double dt = omp_get_wtime() - tf;
        f->stats.filter_s += dt;
        f->stats.shadow_s += dt;
        bf.vis = j->band_vis;
        bf.shadow = j->band_shadow;
        bf.shadow_spec = j->band_spec;
        bf.front = NULL;   /* not handed out: the window's */
    }
    if (ms_frame_shade(j->scene, &j->ctx, j->lights, j->nlights, j->hits + off, j->surf ? j->surf + off : NULL, j->threads, a,
                       &bf, lum)) {
        snprintf(err, errlen, "out of memory for the textured lights of a %dx%d band", W, b - a);
        return -1;
    }
    j->emitted_to = b;
    if (j->band_filter && b < j->H) window_shift(j, b - 2);   /* the next band's filter reads rows b - 2, b - 1 */
    if (b == j->H) job_stats(j, &f->stats);
    bf.stats = f->stats;
    *band = bf;
    *y0 = a;
    return 1;
}

void ms_frame_job_size(const ms_frame_job *j, int *W, int *H)
{
    *W = j->W;
    *H = j->H;
}

void ms_frame_job_aa(const ms_frame_job *j, int *s, int *front_scale)
{
    *s = j->aa_s;
    *front_scale = j->aa_split ? j->aa_s * j->aa_s : 1;
}
