/* Hierarchical penumbra casting against ray tracing as the output resolution grows (Laine & Aila 2005,
 * Table 2 and its claim that the advantage grows with resolution): for each scene and resolution, the
 * shadow seconds of raytrace, hpc, hpc-scanline and scanline in one run (same binary, samples, threads),
 * the ratio raytrace / hpc, agreement with raytrace (pixels whose V differs), and hpc's own figures:
 * triangles cast, sample tests, peak masks (sum over chunks) and their memory, full-umbra points, rebuilds.
 * Prints Markdown.
 *
 * usage: bench_hpc [--samples N] [--sizes 512,1024,2048] [--threads T] SCENE.json|builtin ... */
#include "microshadow.h"
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const methods[] = { "raytrace", "hpc", "hpc-scanline", "scanline" };
#define NM 4

static int counter(const ms_frame *f, const char *name, uint64_t *v)
{
    for (int c = 0; c < f->stats.n_counters; c++)
        if (strcmp(f->stats.counter_name[c], name) == 0) { *v = f->stats.counter[c]; return 1; }
    return 0;
}

int main(int argc, char **argv)
{
    int samples = 256, threads = 0, sizes[8] = { 512, 1024, 2048 }, nsizes = 3;
    int first = 1;
    for (; first < argc && argv[first][0] == '-'; first += 2) {
        if (first + 1 >= argc) { fprintf(stderr, "bench_hpc: %s needs a value\n", argv[first]); return 2; }
        if (!strcmp(argv[first], "--samples")) samples = atoi(argv[first + 1]);
        else if (!strcmp(argv[first], "--threads")) threads = atoi(argv[first + 1]);
        else if (!strcmp(argv[first], "--sizes")) {
            nsizes = 0;
            for (char *t = strtok(argv[first + 1], ","); t && nsizes < 8; t = strtok(NULL, ",")) sizes[nsizes++] = atoi(t);
        } else { fprintf(stderr, "bench_hpc: unknown option %s\n", argv[first]); return 2; }
    }
    if (first >= argc) { fprintf(stderr, "usage: bench_hpc [--samples N] [--sizes a,b,c] [--threads T] SCENE.json|builtin ...\n"); return 2; }
    printf("| scene | size | raytrace s | hpc s | hpc-scanline s | scanline s | raytrace/hpc | raytrace/hpc-scanline "
           "| scanline/hpc | hpc px != raytrace | hpc-scanline px != raytrace | triangles | sample tests | peak masks (MB) "
           "| full-umbra points | rebuilds |\n");
    printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int a = first; a < argc; a++) {
        ms_scene sc;
        char err[1024];
        if (!strcmp(argv[a], "builtin")) ms_scene_default(&sc);
        else if (ms_scene_load(argv[a], &sc, err, sizeof err)) { fprintf(stderr, "bench_hpc: %s\n", err); return 2; }
        const char *label = strrchr(argv[a], '/') ? strrchr(argv[a], '/') + 1 : argv[a];
        for (int s = 0; s < nsizes; s++) {
            ms_frame f[NM];
            for (int m = 0; m < NM; m++) {
                ms_render_options o;
                ms_render_options_default(&o);
                o.method = methods[m];
                o.samples = samples;
                o.width = o.height = sizes[s];
                o.threads = threads;
                if (ms_render(&sc, &o, &f[m], err, sizeof err)) { fprintf(stderr, "bench_hpc: %s: %s\n", methods[m], err); return 1; }
                fprintf(stderr, "%s %d %s: %.3f s\n", label, sizes[s], methods[m], f[m].stats.shadow_s);
            }
            long diff[NM] = { 0 };
            const size_t np = (size_t)sizes[s] * sizes[s];
            for (int m = 1; m < NM; m++)
                for (size_t i = 0; i < np; i++) diff[m] += f[m].vis[i] != f[0].vis[i];
            uint64_t tris = 0, tests = 0, peak = 0, umbra = 0, rebuilds = 0;
            counter(&f[1], "triangles", &tris);
            counter(&f[1], "sample_tests", &tests);
            counter(&f[1], "masks_peak_sum_over_chunks", &peak);
            counter(&f[1], "full_umbra_points", &umbra);
            counter(&f[1], "rebuilds", &rebuilds);
            /* a pool slot (hpc.c): mask bytes + packet shear axes, rounded up to 64 bytes */
            const double slot = (double)((samples / 8 + samples / 16 + 63) / 64 * 64);
            printf("| %s | %d | %.3f | %.3f | %.3f | %.3f | %.2f | %.2f | %.2f | %ld | %ld | %llu | %llu | %.1f | %llu | %llu |\n",
                   label, sizes[s], f[0].stats.shadow_s, f[1].stats.shadow_s, f[2].stats.shadow_s, f[3].stats.shadow_s,
                   f[0].stats.shadow_s / f[1].stats.shadow_s, f[0].stats.shadow_s / f[2].stats.shadow_s,
                   f[3].stats.shadow_s / f[1].stats.shadow_s, diff[1], diff[2], (unsigned long long)tris,
                   (unsigned long long)tests, (double)peak * slot / 1048576.0, (unsigned long long)umbra,
                   (unsigned long long)rebuilds);
            fflush(stdout);
            for (int m = 0; m < NM; m++) ms_frame_free(&f[m]);
        }
        ms_scene_free(&sc);
    }
    return 0;
}
