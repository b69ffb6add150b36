/* A frame job's set-up (ms_frame_job_create, frame_job.h): the methods, the options checked, the memory budget
 * (and the bands when streamed), the scene, context and BVH, the frame's planes, the lights' occluders and every
 * state of the shadow method; and its free. */

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

/* Every light's occluders (occluders.h) with what the method takes and the options allow: the scene's
 * closed components and interior boxes once, then per light; sums into the stats. 0, or -1 when out of
 * memory. */
static int occluders_build(ms_frame_job *j, int what, ms_stats *st)
{
    ms_closed closed;
    ms_interior interior = { 0 };
    if (ms_closed_find(j->scene->tri, j->scene->n_tris, &closed)) return -1;
    int rc = 0;
    if (ms_closed_groups(&closed) || (what & MS_OCC_MERGE)) {
        const double eps = ms_interior_clearance(&j->bvh, j->lights, j->nlights);
        if ((what & MS_OCC_INTERIOR) && ms_closed_groups(&closed))
            rc = ms_interior_find(j->scene->tri, j->scene->n_tris, &closed, ms_interior_res(what), MS_INTERIOR_MIN_TRIS, eps, j->threads, &interior);
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

/* The shadow method and the primary the options name (the primary: the option's, else the shadow method's
 * pairing, "depth" for a streamed scene). MS_OK, or a status with its line in err. */
static ms_status job_methods(const ms_scene *scene, const ms_render_options *opt, const ms_shadow_method **sm_out,
                             const ms_primary_method **pm_out, int *auto_pick, char *err, size_t errlen)
{
    const char *method = opt->method ? opt->method : MS_DEFAULT_METHOD;   /* zeroed options: defaults */
    *auto_pick = strcmp(method, MS_AUTO_METHOD) == 0;
    if (*auto_pick) method = ms_auto_method(opt->pattern);
    const ms_shadow_method *sm = ms_find_shadow_method(method);
    if (!sm) {
        if (ms_method_available(method) < 0) snprintf(err, errlen, "method '%s' is not compiled into this build", method);
        else snprintf(err, errlen, "unknown method '%s'", method);
        return MS_ERR_METHOD;
    }
    const int procedural = scene->procedural.type != MS_PROCEDURAL_NONE;
    const char *pname = opt->primary ? opt->primary : procedural && sm->streams ? "depth" : sm->primary;
    const ms_primary_method *pm = ms_find_primary_method(pname);
    if (!pm) {
        if (strcmp(pname, "embree") == 0) snprintf(err, errlen, "primary method 'embree' is not compiled into this build");
        else snprintf(err, errlen, "unknown primary method '%s' (bvh, embree, depth, 3dr-bb, 3dr-bin, 3dr-fc, 3dr-fs, 3dr-full)", pname);
        return MS_ERR_METHOD;
    }
    if (strcmp(pm->name, "depth") == 0 && !(procedural && sm->streams)) {
        snprintf(err, errlen, "primary method 'depth' needs a procedural scene and a streaming shadow method (e.g. hpc)");
        return MS_ERR_INVALID;
    }
    *sm_out = sm;
    *pm_out = pm;
    return MS_OK;
}

/* The frame's sizes and samples from the options and the scene. */
typedef struct job_dims {
    int samples, aa, aa_s, aa_split, hit_samples, spp, W, H;
} job_dims;

/* The options' samples, anti-aliasing, pattern and size checked (0, else -1 with err). */
static int job_dims_of(const ms_scene *scene, const ms_render_options *opt, const ms_shadow_method *sm, job_dims *d,
                       char *err, size_t errlen)
{
    const int samples = d->samples = opt->samples > 0 ? opt->samples : scene->samples;
    /* Anti-aliasing: K primary samples per pixel as the pixels of an s-times larger frame (s = sqrt K), which
     * every primary and shadow method renders as it renders any frame; finish resolves it (frame_aa.c). */
    const int aa = d->aa = opt->aa > 0 ? opt->aa : scene->aa > 0 ? scene->aa : 1;
    int aa_s = 1;
    while (aa_s * aa_s < aa) aa_s++;
    d->aa_s = aa_s;
    if (opt->aa < 0 || aa_s * aa_s != aa || aa_s > 4) { snprintf(err, errlen, "aa must be 1, 4, 9 or 16 (got %d)", opt->aa < 0 ? opt->aa : aa); return -1; }
    const int aa_split = d->aa_split = opt->aa_split && aa > 1;
    /* Split: each of the K hits gets N/K of the pixel's samples (its own pattern, seeded by its sub-pixel). */
    const int hit_samples = d->hit_samples = aa_split ? samples / aa : samples;
    if (aa_split && (samples % aa || !ms_pattern_samples_per_pixel(opt->pattern, hit_samples))) {
        snprintf(err, errlen, "aa_split: %d samples over %d primary samples leave %d each, not a sample count of the %s pattern",
                 samples, aa, samples / aa, ms_pattern_name(opt->pattern));
        return -1;
    }
    if ((unsigned)opt->pattern > MS_PATTERN_INTERLEAVED) { snprintf(err, errlen, "unknown pattern %d", (int)opt->pattern); return -1; }
    if ((unsigned)opt->traversal > MS_TRAVERSAL_PIXEL) { snprintf(err, errlen, "unknown traversal %d", (int)opt->traversal); return -1; }
    if ((unsigned)opt->closed_cull > MS_CLOSED_CULL_OFF) { snprintf(err, errlen, "unknown closed_cull %d", (int)opt->closed_cull); return -1; }
    /* Samples per pixel: N, or N/16 for interleaved; always a multiple of 16 (full ray packets). */
    const int spp = d->spp = ms_pattern_samples_per_pixel(opt->pattern, hit_samples);
    if (!spp) {
        snprintf(err, errlen, "samples must be %s with the %s pattern (got %d)",
                 opt->pattern == MS_PATTERN_STRATIFIED ? "16, 64, 256, 1024 or 4096" : "256, 1024 or 4096",
                 ms_pattern_name(opt->pattern), samples);
        return -1;
    }
    if (sm->needs_grid && opt->pattern != MS_PATTERN_GRID) {
        snprintf(err, errlen, "method '%s' needs --pattern grid", sm->name);
        return -1;
    }
    const int W_out = opt->width > 0 ? opt->width : scene->camera.width;
    const int H_out = opt->height > 0 ? opt->height : scene->camera.height;
    /* The output's size; the s-times larger frame the methods render may exceed it (streamed, it is held a band
     * at a time, and the memory budget decides either way). */
    if (W_out < 1 || H_out < 1 || W_out > MS_MAX_IMAGE_SIZE || H_out > MS_MAX_IMAGE_SIZE) {
        snprintf(err, errlen, "width and height must be in [1, %d]", MS_MAX_IMAGE_SIZE);
        return -1;
    }
    d->W = W_out * aa_s;
    d->H = H_out * aa_s;
    return 0;
}

/* The memory budget, before anything proportional to the frame or the scene is allocated: the frame's shape,
 * streamed in bands when asked or (MS_STREAM_AUTO) when only that fits (j->band_rows). MS_OK; MS_ERR_INVALID or
 * MS_ERR_BUDGET with err; or, for "auto" (auto_pick) on a procedural scene that does not fit materialised,
 * *retry_hpc set: streamed by hpc instead. */
static ms_status job_budget(ms_frame_job *j, const ms_scene *scene, const ms_render_options *opt, int stream,
                            const ms_primary_method *pm, const job_dims *d, int auto_pick, int *retry_hpc, char *err,
                            size_t errlen)
{
    const ms_shadow_method *sm = j->sm;
    const int procedural = scene->procedural.type != MS_PROCEDURAL_NONE, streamed = j->streamed;
    const int W = d->W, H = d->H, aa_s = d->aa_s, spp = d->spp;
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
        return MS_ERR_INVALID;
    }
    const int unit_tiles = tiles_x * aa_s;   /* the tiles of one band unit */
    fs.stream_rows = !streamable ? 0 : opt->stream_rows ? opt->stream_rows : unit * ((want + unit_tiles - 1) / unit_tiles);
    const uint64_t budget = ms_memory_budget(opt->max_memory);
    if (stream == MS_STREAM_ON && !streamable) {
        snprintf(err, errlen, "streamed outputs: the method takes the whole frame at once (its receivers are all of the frame's pixels)");
        return MS_ERR_INVALID;
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
            *retry_hpc = 1;
            return MS_OK;
        }
        return MS_ERR_BUDGET;
    }
    j->frame.stats.memory_need = ms_frame_need(&fs, NULL);
    j->frame.stats.memory_budget = budget;
    return MS_OK;
}

/* The scene (a procedural one materialised unless streamed), the render context, the camera, the BVH, the suns
 * placed, the alpha-tested triangles. MS_OK, or a status with err. */
static ms_status job_scene(ms_frame_job *j, const ms_render_options *opt, const job_dims *d, char *err, size_t errlen)
{
    const ms_scene *scene = j->scene;
    const int streamed = j->streamed;
    if (scene->procedural.type != MS_PROCEDURAL_NONE && !streamed) {
        if (ms_scene_materialise(scene, j->threads, &j->soup, err, errlen)) return MS_ERR_INVALID;
        j->own_soup = 1;
        scene = &j->soup;
        j->scene = scene;
        j->lights = ms_scene_lights(scene, &j->nlights);
        j->t_start = omp_get_wtime();   /* the generation counts as loading (soup.load_s) */
    }
    ms_render_ctx *ctx = &j->ctx;
    ms_render_ctx_init(ctx, scene, streamed ? NULL : &j->bvh, &j->lights[0], opt->pattern, ms_samples_to_k(d->hit_samples),
                       opt->seed, j->threads);
    if (ms_camera_basis_init(&ctx->cam, &scene->camera, d->W, d->H)) {
        snprintf(err, errlen, "camera is degenerate (eye = target, up parallel to the view, or a field of view, extent or type out of range)");
        return MS_ERR_INVALID;
    }
    if (!streamed && ms_bvh_build(&j->bvh, scene->tri, scene->n_tris, j->threads)) { snprintf(err, errlen, "BVH build failed: out of memory"); return MS_ERR_NO_MEMORY; }
    {   /* suns placed for the scene's box before anything uses the lights' geometry */
        int oom;
        j->placed_lights = ms_lights_placed(j->lights, j->nlights, scene, streamed ? NULL : &j->bvh, &oom);
        if (oom) { snprintf(err, errlen, "out of memory for the lights"); return MS_ERR_NO_MEMORY; }
        if (j->placed_lights) { j->lights = j->placed_lights; ctx->light = j->lights[0]; }
    }
    if (!streamed && ms_alpha_build(scene, &j->bvh, &j->alpha)) { snprintf(err, errlen, "out of memory for the alpha-tested triangles"); return MS_ERR_NO_MEMORY; }
    ctx->alpha = j->alpha;
    ctx->isa_cap = opt->isa;
    ctx->traversal = opt->traversal;
    ctx->frustum_shrink = opt->frustum_shrink;
    ctx->embree_mode = opt->embree_mode;
    ctx->embree_filter = opt->embree_filter;
    ctx->consistent_primary = opt->consistent_primary;
    return MS_OK;
}

/* The frame's planes (the whole frame's rows, or a band's window) and the per-light state arrays. MS_OK, or
 * MS_ERR_NO_MEMORY with err. */
static ms_status job_planes(ms_frame_job *j, const ms_render_options *opt, const job_dims *d, char *err, size_t errlen)
{
    const int W = d->W, H = d->H;
    j->W = W;
    j->H = H;
    j->samples = d->samples;
    j->spp = d->spp;
    j->aa_s = d->aa_s;
    j->aa_split = d->aa_split;
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
        if (!j->band_vis || !j->band_shadow || !j->band_spec) { snprintf(err, errlen, "out of memory for a %dx%d band", W, j->band_rows); return MS_ERR_NO_MEMORY; }
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
        return MS_ERR_NO_MEMORY;
    }
    /* The surfaces (material, shading normal) of the hits: S_spec needs them with the masks. */
    if (!j->streamed && (j->scene->tri_material || j->scene->tri_normal)) {
        j->surf = malloc(npix * sizeof *j->surf);
        if (!j->surf) { snprintf(err, errlen, "out of memory for the surfaces of a %dx%d frame", W, H); return MS_ERR_NO_MEMORY; }
    }
    f->width = W;
    f->height = j->rows_held;
    return MS_OK;
}

/* Each light's shadow method states: over its occluders, over the scene's own triangles (merged faces), over its
 * sets exact per axis, over its interior boxes. MS_OK, or a status with err. */
static ms_status job_light_states(ms_frame_job *j, char *err, size_t errlen)
{
    const ms_shadow_method *sm = j->sm;
    for (size_t l = 0; l < j->nlights; l++) {
        ms_render_ctx lc;
        fj_light_ctx(j, l, &lc);
        if (sm->create(&lc, &j->sstate[l], err, errlen)) { j->sstate[l] = NULL; return MS_ERR_METHOD; }
        if (lc.prim_merged) {
            fj_light_own_ctx(j, l, &lc);
            if (sm->create(&lc, &j->own_sstate[l], err, errlen)) { j->own_sstate[l] = NULL; return MS_ERR_METHOD; }
        }
        for (int a = 0; a < 3 && (sm->occluders & MS_OCC_MERGE_EXACT) && j->occ && j->occ[l].active; a++) {
            if (!j->occ[l].for_axis[a]) continue;
            fj_light_axis_ctx(j, l, a, &lc);
            void **st = &j->axis_sstate[3 * l + (size_t)a];
            if (sm->create(&lc, st, err, errlen)) { *st = NULL; return MS_ERR_METHOD; }
        }
        fj_light_ctx(j, l, &lc);
        if ((sm->occluders & MS_OCC_INTERIOR_PASS) && lc.interior) {
            fj_light_interior_ctx(j, l, &lc);
            if (sm->create(&lc, &j->interior_sstate[l], err, errlen)) { j->interior_sstate[l] = NULL; return MS_ERR_METHOD; }
        }
    }
    return MS_OK;
}

/* The primary's state, the lights' occluders and the shadow method's states; the set-up's stats and the
 * counters' names. MS_OK, or a status with err. */
static ms_status job_states(ms_frame_job *j, const ms_render_options *opt, const ms_primary_method *pm, char *err,
                            size_t errlen)
{
    const ms_shadow_method *sm = j->sm;
    ms_frame *f = &j->frame;
    const size_t nl = j->nlights;
    /* The primary's create is timed as primary visibility: the rasterizing primaries (3dr-*, depth) do
     * their whole pass there. */
    const double t_primary = omp_get_wtime();
    void *pstate = NULL;
    if (pm->create(&j->ctx, &pstate, err, errlen)) return MS_ERR_INVALID;
    j->pm = pm;
    j->pstate = pstate;
    f->stats.primary_s = omp_get_wtime() - t_primary;
    const double t_setup = omp_get_wtime();
    int occ_what = occluder_what(sm, opt);
    if ((occ_what & MS_OCC_INTERIOR) && sm->interior_silhouettes && sm->interior_silhouettes(&j->ctx))
        occ_what |= MS_OCC_INTERIOR_SILHOUETTE;   /* the boxes on the finer grid */
    if (occ_what && !j->streamed && occluders_build(j, occ_what, &f->stats)) {
        snprintf(err, errlen, "out of memory for the lights' occluders");
        return MS_ERR_NO_MEMORY;
    }
    const ms_status rc = job_light_states(j, err, errlen);
    if (rc) return rc;
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
    return MS_OK;
}

/* stream: MS_STREAM_OFF (the whole frame), MS_STREAM_ON (bands), or MS_STREAM_AUTO (bands when only they fit the
 * budget). */
static ms_status job_create(const ms_scene *scene, const ms_render_options *opt, int stream, ms_frame_job **out, char *err,
                      size_t errlen)
{
    *out = NULL;
    const double t_start = omp_get_wtime();
    const ms_shadow_method *sm = NULL;
    const ms_primary_method *pm = NULL;
    int auto_pick = 0;
    ms_status rc = job_methods(scene, opt, &sm, &pm, &auto_pick, err, errlen);
    if (rc) return rc;
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
    /* A procedural scene: streamed when the shadow method and the primary can (no BVH), else materialised
     * (job_scene, once the options are checked and the budget allows it). */
    j->streamed = scene->procedural.type != MS_PROCEDURAL_NONE && sm->streams && pm->streams;
    j->scene = scene;
    j->lights = ms_scene_lights(scene, &j->nlights);
    job_dims d;
    int retry_hpc = 0;
    if (job_dims_of(scene, opt, sm, &d, err, errlen)) { rc = MS_ERR_INVALID; goto fail; }
    if ((rc = job_budget(j, scene, opt, stream, pm, &d, auto_pick, &retry_hpc, err, errlen))) goto fail;
    if (retry_hpc) {
        ms_frame_job_free(j);
        ms_render_options streamed_opt = *opt;
        streamed_opt.method = "hpc";
        return job_create(scene, &streamed_opt, stream, out, err, errlen);
    }
    if ((rc = job_scene(j, opt, &d, err, errlen)) || (rc = job_planes(j, opt, &d, err, errlen)) ||
        (rc = job_states(j, opt, pm, err, errlen)))
        goto fail;
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
    ms_render_options own;
    opt = ms_abi_options(opt, MS_ABI_SIZE(abi, render_options), &own, sizeof own);
    return job_create(scene, opt, MS_STREAM_OFF, out, err, errlen);
}

int ms_frame_job_create_stream(const ms_scene *scene, const ms_render_options *opt, int stream, ms_frame_job **out,
                               int *band_rows, char *err, size_t errlen)
{
    const int rc = job_create(scene, opt, stream, out, err, errlen);
    *band_rows = rc ? 0 : (*out)->band_rows;
    return rc;
}
