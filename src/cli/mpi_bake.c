/* One lightmap over MPI ranks (mpi_run.h, docs/mpi.md): every rank lays the lightmap out (UVs, texel
 * points) and builds its own acceleration structure, the ranks take chunks of texel rows under the chosen
 * schedule, rank 0 gathers the other ranks' rows (V, S, front) and the sums of their stats and finishes the
 * lightmap (irradiance, exposure, dilation), which makes it ms_bake's bit for bit (microshadow.h). */
#include "mpi_run.h"
#include <limits.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct bake_work { const ms_accel *accel; const ms_bake_options *opt; ms_lightmap *lm; } bake_work;

static int bake_chunk(void *user, int first, int count, char *err, size_t errlen)
{
    bake_work *w = user;
    return ms_bake_rows(w->accel, w->opt, w->lm, first, first + count, err, errlen) != MS_OK ? -1 : 0;
}

static uint64_t fingerprint(const ms_scene *scene, const ms_lightmap *lm, const ms_bake_options *o)
{
    const size_t nt = (size_t)lm->frame.width * lm->frame.height;
    uint64_t h = ms_mpi_hash(0, &nt, sizeof nt);
    h = ms_mpi_hash_lights(h, scene);   /* every light's planes are baked and gathered */
    /* the texels' points decide the answer: word by word */
    const uint32_t *w = (const uint32_t *)lm->position;
    for (size_t i = 0; i < 3 * nt; i++) h = (h ^ w[i]) * 1099511628211ull;
    for (size_t i = 0; i < nt; i++) h = (h ^ lm->triangle[i]) * 1099511628211ull;
    const char *m = o->points.method ? o->points.method : MS_DEFAULT_METHOD;
    h = ms_mpi_hash(h, m, strlen(m));
    const int v[] = { (int)o->points.pattern, o->points.samples, (int)o->points.seed, o->dilate };
    return ms_mpi_hash(h, v, sizeof v);
}

int ms_mpi_bake(const ms_scene *scene, const char *what, const ms_bake_options *opt, ms_mpi_schedule sched,
                int chunk, ms_lightmap *out, char *err, size_t errlen)
{
    const int rank = ms_mpi_rank(), size = ms_mpi_size();
    ms_accel *accel = NULL;
    ms_status st = ms_bake_layout(scene, opt, out, err, errlen);
    if (!st) st = ms_accel_build(scene, opt->points.threads, &accel, err, errlen);
    if (st) fprintf(stderr, "microshadow bake: %s: %s\n", what, err);
    if (ms_mpi_agree(st != MS_OK)) {
        ms_accel_free(accel);
        ms_lightmap_free(out);
        return -1;
    }
    if (!ms_mpi_same(fingerprint(scene, out, opt))) {
        if (rank == 0) fprintf(stderr, "microshadow bake: the MPI ranks were given different scenes or options\n");
        ms_mpi_agree(rank == 0);
        ms_accel_free(accel);
        ms_lightmap_free(out);
        return -1;
    }
    /* Zero texels: the stats' names and set-up, whichever rows this rank gets (maybe none). */
    if (ms_bake_rows(accel, opt, out, 0, 0, err, errlen)) fprintf(stderr, "microshadow bake: %s: %s\n", what, err);
    const int rows = out->frame.height, W = out->frame.width;
    const size_t nl = out->frame.n_lights > 1 ? (size_t)out->frame.n_lights : 1, np = (size_t)rows * W;
    if ((double)rows * 2.0 * (double)W * (double)nl > (double)INT_MAX) {
        /* MPI counts are ints; every rank sees the same sizes, so every rank stops here alike */
        snprintf(err, errlen, "a %dx%d lightmap of %zu lights is too large for one MPI gather", W, rows, nl);
        fprintf(stderr, "microshadow bake: %s: %s\n", what, err);
        ms_mpi_agree(1);
        ms_accel_free(accel);
        ms_lightmap_free(out);
        return -1;
    }
    const double t0 = MPI_Wtime();
    unsigned char *done = malloc((size_t)rows);
    if (!done) ms_mpi_fatal("out of memory");   /* a few kilobytes: no way to go on in step */
    bake_work w = { accel, opt, out };
    ms_mpi_report rep;
    memset(&rep, 0, sizeof rep);
    const int bad = ms_mpi_distribute(sched, rows, chunk, bake_chunk, &w, done, &rep, err, errlen) != 0;

    /* Rank 0 gathers the other ranks' rows: per row, every light's V and S (2 W nl floats) and front (W nl). */
    ms_frame *f = &out->frame;
    const size_t rw = 2 * (size_t)W * nl, fw = (size_t)W * nl;   /* floats and fronts per gathered row */
    int mine = 0;
    for (int y = 0; rank > 0 && y < rows; y++) mine += done[y];
    int *ids = malloc(((size_t)mine + 1) * sizeof *ids);
    float *vs = malloc(((size_t)mine + 1) * rw * sizeof *vs);
    uint16_t *fr = malloc(((size_t)mine + 1) * fw * sizeof *fr);
    if (!ids || !vs || !fr) ms_mpi_fatal("out of memory gathering the ranks' results");
    for (int y = 0, k = 0; rank > 0 && k < mine; y++) {
        if (!done[y]) continue;
        ids[k] = y;
        for (size_t l = 0; l < nl; l++) {
            memcpy(vs + (size_t)k * rw + 2 * l * W, f->vis + l * np + (size_t)y * W, (size_t)W * sizeof *vs);
            memcpy(vs + (size_t)k * rw + (2 * l + 1) * W, f->shadow + l * np + (size_t)y * W, (size_t)W * sizeof *vs);
            memcpy(fr + (size_t)k * fw + l * W, f->front + l * np + (size_t)y * W, (size_t)W * sizeof *fr);
        }
        k++;
    }
    int *counts = NULL, *displ = NULL, *c2 = NULL, *d2 = NULL, *c1 = NULL, *d1 = NULL, total = 0;
    if (rank == 0) {
        counts = calloc((size_t)size, sizeof *counts);
        displ = calloc((size_t)size, sizeof *displ);
        c2 = calloc((size_t)size, sizeof *c2);
        d2 = calloc((size_t)size, sizeof *d2);
        c1 = calloc((size_t)size, sizeof *c1);
        d1 = calloc((size_t)size, sizeof *d1);
        if (!counts || !displ || !c2 || !d2 || !c1 || !d1) ms_mpi_fatal("out of memory gathering the ranks' results");
    }
    MPI_Gather(&mine, 1, MPI_INT, counts, 1, MPI_INT, 0, MPI_COMM_WORLD);
    for (int r = 0; rank == 0 && r < size; r++) {
        displ[r] = total;
        c2[r] = counts[r] * (int)rw;
        d2[r] = total * (int)rw;
        c1[r] = counts[r] * (int)fw;
        d1[r] = total * (int)fw;
        total += counts[r];
    }
    int *all_ids = rank == 0 ? malloc(((size_t)total + 1) * sizeof *all_ids) : NULL;
    float *all_vs = rank == 0 ? malloc(((size_t)total + 1) * rw * sizeof *all_vs) : NULL;
    uint16_t *all_fr = rank == 0 ? malloc(((size_t)total + 1) * fw * sizeof *all_fr) : NULL;
    if (rank == 0 && (!all_ids || !all_vs || !all_fr)) ms_mpi_fatal("out of memory gathering the ranks' results");
    MPI_Gatherv(ids, mine, MPI_INT, all_ids, counts, displ, MPI_INT, 0, MPI_COMM_WORLD);
    MPI_Gatherv(vs, mine * (int)rw, MPI_FLOAT, all_vs, c2, d2, MPI_FLOAT, 0, MPI_COMM_WORLD);
    MPI_Gatherv(fr, mine * (int)fw, MPI_UINT16_T, all_fr, c1, d1, MPI_UINT16_T, 0, MPI_COMM_WORLD);
    for (int k = 0; rank == 0 && k < total; k++) {
        const int y = all_ids[k];
        for (size_t l = 0; l < nl; l++) {
            memcpy(f->vis + l * np + (size_t)y * W, all_vs + (size_t)k * rw + 2 * l * W, (size_t)W * sizeof *all_vs);
            memcpy(f->shadow + l * np + (size_t)y * W, all_vs + (size_t)k * rw + (2 * l + 1) * W, (size_t)W * sizeof *all_vs);
            memcpy(f->front + l * np + (size_t)y * W, all_fr + (size_t)k * fw + l * W, (size_t)W * sizeof *all_fr);
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
    free(ids);
    free(vs);
    free(fr);
    free(done);

    ms_stats *s = &f->stats;
    uint64_t sums[MS_MAX_COUNTERS + 3], totals[MS_MAX_COUNTERS + 3];
    memcpy(sums, s->counter, sizeof s->counter);
    sums[MS_MAX_COUNTERS] = s->visible_pixels;
    sums[MS_MAX_COUNTERS + 1] = s->penumbra_pixels;
    sums[MS_MAX_COUNTERS + 2] = s->shadow_rays;
    double resolve = s->shadow_factor_s, resolve_total = 0.0;
    MPI_Reduce(sums, totals, MS_MAX_COUNTERS + 3, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
    MPI_Reduce(&resolve, &resolve_total, 1, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
    if (bad) fprintf(stderr, "microshadow bake: %s: %s\n", what, err);
    ms_accel_free(accel);
    if (ms_mpi_agree(bad)) {
        ms_lightmap_free(out);
        ms_mpi_report_free(&rep);
        return -1;
    }
    if (rank != 0) {
        ms_lightmap_free(out);
        ms_mpi_report_free(&rep);
        return 0;
    }
    memcpy(s->counter, totals, sizeof s->counter);
    s->visible_pixels = totals[MS_MAX_COUNTERS];
    s->penumbra_pixels = totals[MS_MAX_COUNTERS + 1];
    s->shadow_rays = totals[MS_MAX_COUNTERS + 2];
    s->shadow_factor_s = resolve_total;
    s->shadow_s = MPI_Wtime() - t0;   /* the distributed phase, until rank 0 has every row */
    rep.distribute_s = s->shadow_s;
    rep.threads = s->threads;
    st = ms_bake_finish(scene, opt, out, err, errlen);
    ms_mpi_report_free(&ms_mpi_last_report);
    ms_mpi_last_report = rep;
    if (st) {
        fprintf(stderr, "microshadow bake: %s: %s\n", what, err);
        ms_lightmap_free(out);
        return -1;
    }
    return 0;
}
