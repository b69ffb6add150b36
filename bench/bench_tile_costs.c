/* How unevenly a frame's cost spreads over its 16x16 tiles (docs/mpi.md: the frame the MPI schedules are
 * measured on): every tile rendered alone through ms_frame_job_render on one thread and timed; prints the
 * distribution of the tiles' seconds and the share of the frame's time in its most expensive tenth.
 *
 * usage: bench_tile_costs SCENE.json|builtin [W H SAMPLES [METHOD]] */
#include "microshadow.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    if (argc < 2) { fprintf(stderr, "usage: bench_tile_costs SCENE.json|builtin [W H SAMPLES [METHOD]]\n"); return 2; }
    char err[1024];
    ms_scene sc;
    if (strcmp(argv[1], "builtin") ? ms_scene_load(argv[1], &sc, err, sizeof err) : ms_scene_default(&sc)) {
        fprintf(stderr, "bench_tile_costs: %s\n", err);
        return 2;
    }
    ms_render_options o;
    ms_render_options_default(&o);
    o.width = argc > 2 ? atoi(argv[2]) : 512;
    o.height = argc > 3 ? atoi(argv[3]) : 512;
    o.samples = argc > 4 ? atoi(argv[4]) : 1024;
    if (argc > 5) o.method = argv[5];
    o.threads = 1;
    ms_frame_job *job;
    if (ms_frame_job_create(&sc, &o, &job, err, sizeof err)) { fprintf(stderr, "bench_tile_costs: %s\n", err); return 2; }
    const int n = ms_frame_job_tiles(job, NULL, NULL);
    double *t = malloc((size_t)n * sizeof *t), sum = 0.0;
    if (!t) return 1;
    for (int i = 0; i < n; i++) {
        const double t0 = now();
        if (ms_frame_job_render(job, &i, 1, err, sizeof err)) { fprintf(stderr, "bench_tile_costs: %s\n", err); return 2; }
        t[i] = now() - t0;
        sum += t[i];
    }
    qsort(t, (size_t)n, sizeof *t, cmp_double);
    double top = 0.0;
    for (int i = n - n / 10; i < n; i++) top += t[i];
    printf("%s, %dx%d, %d samples, method %s: %d tiles, %.3f s in all\n", argv[1], o.width, o.height, o.samples,
           o.method, n, sum);
    printf("tile ms: min %.3f, median %.3f, p90 %.3f, p99 %.3f, max %.3f (max / median %.0f); the costliest tenth of "
           "the tiles holds %.0f%% of the time\n", 1e3 * t[0], 1e3 * t[n / 2], 1e3 * t[n * 9 / 10], 1e3 * t[n * 99 / 100],
           1e3 * t[n - 1], t[n / 2] > 0 ? t[n - 1] / t[n / 2] : 0.0, 100.0 * top / sum);
    free(t);
    ms_frame_job_free(job);
    ms_scene_free(&sc);
    return 0;
}
