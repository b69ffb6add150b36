/* One frame over MPI ranks (mpi_run.h, docs/mpi.md): every rank sets up its own ms_frame_job (scene, BVH,
 * methods), the ranks take chunks of tiles under the chosen schedule, rank 0 gathers the other ranks' tiles
 * (every light's V, S, S_spec and front counts, unfiltered) and the sums of their stats into its job and
 * finishes the frame there, which makes it ms_render's frame bit for bit (microshadow/render.h, "A frame tile by
 * tile"). */
#include "mpi_run.h"
#include <mpi.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TP (MS_TILE_SIZE * MS_TILE_SIZE)

typedef struct frame_work { ms_frame_job *job; int *tiles; } frame_work;

static int render_chunk(void *user, int first, int count, char *err, size_t errlen)
{
    frame_work *w = user;
    for (int i = 0; i < count; i++) w->tiles[i] = first + i;
    return ms_frame_job_render(w->job, w->tiles, count, err, errlen);
}

_Static_assert(sizeof(ms_texture_sampling) == 4 * sizeof(int32_t) + 6 * sizeof(float),
               "ms_texture_sampling is hashed as bytes (in ms_material): no padding");
_Static_assert(sizeof(ms_material) == 11 * sizeof(float) + 13 * sizeof(int32_t) + 4 * sizeof(ms_texture_sampling),
               "ms_material is hashed as bytes: no padding");
_Static_assert(sizeof(ms_camera) == 3 * sizeof(ms_vec3) + 3 * sizeof(float) + 2 * sizeof(int) + sizeof(ms_camera_type),
               "ms_camera is hashed as bytes: no padding");

/* The scene and the options that decide the image, so that ranks can check they were given the same. */
static uint64_t fingerprint(const ms_scene *s, const ms_render_options *o)
{
    uint64_t h = ms_mpi_hash(0, &s->n_tris, sizeof s->n_tris);
    if (s->tri) {   /* word by word: cheap next to the BVH build */
        const uint32_t *w = (const uint32_t *)s->tri;
        for (size_t i = 0; i < s->n_tris * 9; i++) h = (h ^ w[i]) * 1099511628211ull;
    }
    h = ms_mpi_hash(h, &s->procedural, sizeof s->procedural);
    /* the whole camera: type, fov and ortho_height included */
    h = ms_mpi_hash(h, &s->camera, sizeof s->camera);
    h = ms_mpi_hash_lights(h, s);
    h = ms_mpi_hash(h, &s->samples, sizeof s->samples);
    /* The surfaces (materials, their textures and UVs, shading normals) decide S_spec and the shading. */
    const size_t counts[] = { s->n_materials, s->n_textures, s->tri_material != NULL, s->tri_normal != NULL };
    h = ms_mpi_hash(h, counts, sizeof counts);
    if (s->materials) h = ms_mpi_hash(h, s->materials, s->n_materials * sizeof *s->materials);   /* no padding */
    if (s->tri_material) h = ms_mpi_hash(h, s->tri_material, s->n_tris * sizeof *s->tri_material);
    if (s->tri_normal) h = ms_mpi_hash(h, s->tri_normal, s->n_tris * 9 * sizeof *s->tri_normal);
    if (s->tri_tangent) h = ms_mpi_hash(h, s->tri_tangent, s->n_tris * 12 * sizeof *s->tri_tangent);
    for (int u = 0; s->n_textures && u < MS_MAX_UV_SETS; u++)
        if (s->tri_uv[u]) h = ms_mpi_hash(h, s->tri_uv[u], s->n_tris * 6 * sizeof *s->tri_uv[u]);
    for (size_t t = 0; t < s->n_textures; t++) {
        const ms_texture *x = &s->textures[t];
        const int d[] = { x->width, x->height };
        h = ms_mpi_hash(h, d, sizeof d);
        if (x->rgba) h = ms_mpi_hash(h, x->rgba, (size_t)x->width * (size_t)x->height * 4);
    }
    const char *m = o->method ? o->method : MS_DEFAULT_METHOD;
    h = ms_mpi_hash(h, m, strlen(m));
    const int v[] = { (int)o->pattern, o->samples, o->width, o->height, (int)o->seed, (int)o->traversal,
                      o->frustum_shrink, o->no_filter, o->aa, o->aa_split, s->aa };
    return ms_mpi_hash(h, v, sizeof v);
}

/* The checks every rank makes together before the frame is distributed: the same scene and options on every rank,
 * a method whose frame can be split, a gather whose counts fit MPI's ints. 0, or -1 (agreed by all ranks). */
static int frame_checks(const ms_scene *scene, const char *what, const ms_render_options *opt, ms_frame_job *job)
{
    const int rank = ms_mpi_rank(), size = ms_mpi_size();
    /* Every rank must render the same frame: a rank given another scene or other options fails the run. */
    if (!ms_mpi_same(fingerprint(scene, opt))) {
        if (rank == 0) fprintf(stderr, "microshadow: the MPI ranks were given different scenes or options\n");
        ms_mpi_agree(rank == 0);
        return -1;
    }
    const int ntiles = ms_frame_job_tiles(job, NULL, NULL);
    if (size > 1 && !ms_frame_job_splittable(job)) {
        if (rank == 0)
            fprintf(stderr, "microshadow: method '%s' cannot be split over MPI ranks: its answer at a pixel depends on the "
                    "frame's other pixels (run it with one rank)\n", opt->method ? opt->method : MS_DEFAULT_METHOD);
        ms_mpi_agree(rank == 0);
        return -1;
    }
    /* MPI counts are ints: the gather's floats (3 per pixel and light, whole tiles) must fit one. */
    {
        size_t nl = 1;
        ms_scene_lights(scene, &nl);
        if (size > 1 && (size_t)ntiles * 3 * nl * TP > (size_t)INT_MAX) {
            if (rank == 0)
                fprintf(stderr, "microshadow: %s: a %d-tile frame with %zu lights is too large to gather over MPI ranks "
                        "(run it with one rank)\n", what, ntiles, nl);
            ms_mpi_agree(rank == 0);
            return -1;
        }
    }
    return 0;
}

/* Rank 0 gathers the other ranks' tiles into its frame f: each rank's tile ids (ids: mine of them), then per tile
 * and light V, S and S_spec (vs: FT floats a tile) and front counts (fr: UT a tile). Collective. */
static void gather_tiles(ms_frame *f, int tiles_x, size_t nl, size_t FT, size_t UT, int mine, const int *ids, const float *vs,
                         const uint16_t *fr)
{
    const int rank = ms_mpi_rank(), size = ms_mpi_size();
    const int W = f->width, H = f->height;
    const size_t npix = (size_t)W * H;
    int *counts = rank == 0 ? calloc((size_t)size, sizeof *counts) : NULL;
    int *displ = rank == 0 ? calloc((size_t)size, sizeof *displ) : NULL;
    int *c2 = rank == 0 ? calloc((size_t)size, sizeof *c2) : NULL;
    int *d2 = rank == 0 ? calloc((size_t)size, sizeof *d2) : NULL;
    int *c1 = rank == 0 ? calloc((size_t)size, sizeof *c1) : NULL;
    int *d1 = rank == 0 ? calloc((size_t)size, sizeof *d1) : NULL;
    MPI_Gather(&mine, 1, MPI_INT, counts, 1, MPI_INT, 0, MPI_COMM_WORLD);
    int total = 0;
    if (rank == 0) {
        if (!counts || !displ || !c2 || !d2 || !c1 || !d1) ms_mpi_fatal("out of memory gathering the ranks' results");
        for (int r = 0; r < size; r++) {
            displ[r] = total;
            c2[r] = (int)((size_t)counts[r] * FT);   /* < INT_MAX: checked before the distribution */
            d2[r] = (int)((size_t)total * FT);
            c1[r] = (int)((size_t)counts[r] * UT);
            d1[r] = (int)((size_t)total * UT);
            total += counts[r];
        }
    }
    int *all_ids = rank == 0 ? malloc(((size_t)total + 1) * sizeof *all_ids) : NULL;
    float *all_vs = rank == 0 ? malloc(((size_t)total + 1) * FT * sizeof *all_vs) : NULL;
    uint16_t *all_fr = rank == 0 ? malloc(((size_t)total + 1) * UT * sizeof *all_fr) : NULL;
    if (rank == 0 && (!all_ids || !all_vs || !all_fr)) ms_mpi_fatal("out of memory gathering the ranks' results");
    MPI_Gatherv(ids, mine, MPI_INT, all_ids, counts, displ, MPI_INT, 0, MPI_COMM_WORLD);
    MPI_Gatherv(vs, (int)((size_t)mine * FT), MPI_FLOAT, all_vs, c2, d2, MPI_FLOAT, 0, MPI_COMM_WORLD);
    MPI_Gatherv(fr, (int)((size_t)mine * UT), MPI_UINT16_T, all_fr, c1, d1, MPI_UINT16_T, 0, MPI_COMM_WORLD);
    for (int k = 0; rank == 0 && k < total; k++) {
        const int t = all_ids[k];
        const int x0 = (t % tiles_x) * MS_TILE_SIZE, y0 = (t / tiles_x) * MS_TILE_SIZE;
        for (size_t l = 0; l < nl; l++) {
            const float *v = all_vs + (size_t)k * FT + 3 * l * TP;
            const uint16_t *u = all_fr + (size_t)k * UT + l * TP;
            for (int p = 0; p < TP; p++) {
                const int x = x0 + p % MS_TILE_SIZE, y = y0 + p / MS_TILE_SIZE;
                if (x >= W || y >= H) continue;
                const size_t i = l * npix + (size_t)y * W + x;
                f->vis[i] = v[p];
                f->shadow[i] = v[TP + p];
                f->shadow_spec[i] = v[2 * TP + p];
                f->front[i] = u[p];
            }
        }
    }
    free(all_ids);
    free(all_vs);
    free(all_fr);
    free(counts);
    free(displ);
    free(c2);
    free(d2);
    free(c1);
    free(d1);
}

int ms_mpi_frame(const ms_scene *scene, const char *what, const ms_render_options *opt, ms_mpi_schedule sched,
                 int chunk, ms_frame *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    const int rank = ms_mpi_rank(), size = ms_mpi_size();
    ms_frame_job *job = NULL;
    const int failed = ms_frame_job_create(scene, opt, &job, err, errlen) != 0;
    if (failed) fprintf(stderr, "microshadow: %s: %s\n", what, err);
    if (ms_mpi_agree(failed)) return -1;
    if (frame_checks(scene, what, opt, job)) {
        ms_frame_job_free(job);
        return -1;
    }
    int tiles_x, tiles_y;
    const int ntiles = ms_frame_job_tiles(job, &tiles_x, &tiles_y);
    const double t0 = MPI_Wtime();
    unsigned char *done = malloc((size_t)ntiles);
    frame_work w = { job, malloc((size_t)chunk * sizeof(int)) };
    if (!done || !w.tiles) ms_mpi_fatal("out of memory");   /* a few kilobytes: no way to go on in step */
    int bad = 0;
    ms_mpi_report rep;
    memset(&rep, 0, sizeof rep);
    if (size == 1) {   /* one rank: the whole frame in one call, as ms_render (also for hpc-scanline) */
        if (!bad) bad = ms_frame_job_render(job, NULL, ntiles, err, errlen) != 0;
        rep.ranks = 1;
        rep.rank_chunks = calloc(1, sizeof(int));
        rep.rank_units = malloc(sizeof(int));
        rep.rank_busy_s = malloc(sizeof(double));
        rep.rank_wall_s = malloc(sizeof(double));
        if (rep.rank_chunks && rep.rank_units && rep.rank_busy_s && rep.rank_wall_s) {
            rep.rank_chunks[0] = 1;
            rep.rank_units[0] = ntiles;
            rep.rank_busy_s[0] = rep.rank_wall_s[0] = MPI_Wtime() - t0;
        } else ms_mpi_report_free(&rep);
    } else {
        /* Every rank enters the distribution (a rank out of memory takes its chunks without rendering). */
        bad = ms_mpi_distribute(sched, ntiles, chunk, render_chunk, &w, done, &rep, err, errlen) != 0;
    }

    /* Rank 0 gathers the other ranks' tiles: ids, then per light V, S and S_spec (3 x 256 floats a tile and
     * light) and front counts (256 a tile and light). */
    ms_frame *f = ms_frame_job_frame(job);
    const int W = f->width, H = f->height;
    const size_t nl = f->n_lights > 0 ? (size_t)f->n_lights : 1, npix = (size_t)W * H;
    const size_t FT = 3 * nl * TP, UT = nl * TP;   /* floats and front counts of one tile */
    int mine = 0;
    for (int t = 0; size > 1 && rank > 0 && t < ntiles; t++) mine += done[t];
    int *ids = malloc(((size_t)mine + 1) * sizeof *ids);
    float *vs = malloc(((size_t)mine + 1) * FT * sizeof *vs);
    uint16_t *fr = malloc(((size_t)mine + 1) * UT * sizeof *fr);
    if (!ids || !vs || !fr) ms_mpi_fatal("out of memory gathering the ranks' results");
    for (int t = 0, k = 0; size > 1 && rank > 0 && k < mine; t++) {
        if (!done[t]) continue;
        ids[k] = t;
        const int x0 = (t % tiles_x) * MS_TILE_SIZE, y0 = (t / tiles_x) * MS_TILE_SIZE;
        for (size_t l = 0; l < nl; l++) {
            float *v = vs + (size_t)k * FT + 3 * l * TP;
            uint16_t *u = fr + (size_t)k * UT + l * TP;
            for (int p = 0; p < TP; p++) {
                const int x = x0 + p % MS_TILE_SIZE, y = y0 + p / MS_TILE_SIZE;
                const int in = x < W && y < H;
                const size_t i = in ? l * npix + (size_t)y * W + x : 0;
                v[p] = in ? f->vis[i] : 0.0f;
                v[TP + p] = in ? f->shadow[i] : 0.0f;
                v[2 * TP + p] = in ? f->shadow_spec[i] : 0.0f;
                u[p] = in ? f->front[i] : 0;
            }
        }
        k++;
    }
    if (size > 1) gather_tiles(f, tiles_x, nl, FT, UT, mine, ids, vs, fr);
    free(ids);
    free(vs);
    free(fr);
    free(done);
    free(w.tiles);

    /* The sums of the ranks' counts into rank 0's frame. */
    ms_stats *st = &f->stats;
    uint64_t sums[MS_MAX_COUNTERS + 3], totals[MS_MAX_COUNTERS + 3];
    memcpy(sums, st->counter, sizeof st->counter);
    sums[MS_MAX_COUNTERS] = st->visible_pixels;
    sums[MS_MAX_COUNTERS + 1] = st->penumbra_pixels;
    sums[MS_MAX_COUNTERS + 2] = st->shadow_rays;
    double secs[2] = { st->shadow_factor_s, st->shadow_cpu_s }, secs_total[2] = { 0.0, 0.0 };
    MPI_Reduce(sums, totals, MS_MAX_COUNTERS + 3, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
    MPI_Reduce(secs, secs_total, 2, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
    if (bad) fprintf(stderr, "microshadow: %s: %s\n", what, err);
    if (ms_mpi_agree(bad)) {
        ms_frame_job_free(job);
        ms_mpi_report_free(&rep);
        return -1;
    }
    int rc = 0;
    if (rank == 0) {
        memcpy(st->counter, totals, sizeof st->counter);
        st->visible_pixels = totals[MS_MAX_COUNTERS];
        st->penumbra_pixels = totals[MS_MAX_COUNTERS + 1];
        st->shadow_rays = totals[MS_MAX_COUNTERS + 2];
        st->shadow_factor_s = secs_total[0];
        st->shadow_cpu_s = secs_total[1];   /* every rank's CPU seconds in its tiles (finish adds rank 0's filter) */
        /* Seconds under MPI: shadow_s is the distributed phase (every tile's primary and shadow rays, on all
         * ranks, until rank 0 has them all), primary_s what rank 0 then spends on the other tiles' hits. */
        st->primary_s = 0.0;
        st->shadow_s = MPI_Wtime() - t0;
        rep.distribute_s = st->shadow_s;
        rep.threads = opt->threads;
        rc = ms_frame_job_finish(job, out, err, errlen);
        if (rc) fprintf(stderr, "microshadow: %s: %s\n", what, err);
        ms_mpi_report_free(&ms_mpi_last_report);
        ms_mpi_last_report = rep;
        if (out->stats.threads) ms_mpi_last_report.threads = out->stats.threads;
    } else ms_mpi_report_free(&rep);
    ms_frame_job_free(job);
    return rc;
}
