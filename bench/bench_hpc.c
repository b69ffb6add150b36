/* Hierarchical penumbra casting against ray tracing as the output resolution grows: the paper's Table 2
 * (Laine & Aila 2005) and its claim that the advantage grows with resolution. For each scene, light,
 * sample count and resolution, in one run (same binary, samples, threads): the shadow seconds of
 * raytrace and scanline; hpc's phases (coarse sort, receiver hierarchy build, cast; total = shadow
 * seconds + sort, which a scene's triangles pay in the method's set-up) and hpc-scanline's total; the
 * ratios; hpc's memory by kind as the paper's Table 2 counts it (the receiver points buffer; the
 * receiver hierarchy at its peak; the bit masks as allocated at the peak, with the per-point sample data
 * allocated beside each mask, hpc.c); agreement with raytrace (pixels whose V differs) and hpc's work counters. Prints Markdown.
 *
 * usage: bench_hpc [--samples 256,1024] [--sizes 512,1024,2048] [--light-scale 1,2] [--threads T]
 *                  [--no-reference] [--cpu] SCENE.json|builtin ...
 * --light-scale F: the light's edges times F about its centre (2: the paper's 4x light).
 * --no-reference: leave out raytrace and scanline (their columns read "-").
 * --cpu: the methods' totals in CPU seconds of all threads (ms_stats.shadow_cpu_s) instead of wall seconds,
 *        for a machine shared with other work; hpc's phase columns stay wall seconds.
 * --methods LIST: only these of raytrace, scanline, hpc, hpc-scanline (hpc always runs; absent columns "-").
 * --off LIST: hpc with parts turned off (ms_hpc_switches, src/shadow/hpc/hpc.h), to measure each alone:
 *        umbra (A), planesets (B), lazy (C), ondemand (D), sort, simdsamples, simdplanes, footprint (hpc's
 *        footprint test: the paper's group volumes instead), pairs (hpc's pairs of triangles sharing an edge:
 *        each triangle alone), leaffp (hpc's leaf footprint), leaffp-rule (the leaf footprint on every leaf),
 *        rect (hpc's rectangle pairs: each triangle of a pair with its own leaf footprint), sure (hpc's sure lanes:
 *        every candidate sample to the exact test), leaflanes (hpc's leaf lanes: each receiver of a leaf given
 *        its samples in turn), tsure (hpc's t_sure: the sure lanes' t range always tested). */
#include "microshadow.h"
#include "shadow/hpc/hpc.h"
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const methods[] = { "raytrace", "scanline", "hpc", "hpc-scanline" };
#define NM 4
enum { RT, SL, HPC, HPCS };

static uint64_t counter(const ms_frame *f, const char *name)
{
    uint64_t v = 0;
    ms_stats_counter(&f->stats, name, &v);
    return v;
}

static int parse_list(char *s, int *out, int cap)
{
    int n = 0;
    for (char *t = strtok(s, ","); t && n < cap; t = strtok(NULL, ",")) out[n++] = atoi(t);
    return n;
}

static int parse_flist(char *s, float *out, int cap)
{
    int n = 0;
    for (char *t = strtok(s, ","); t && n < cap; t = strtok(NULL, ",")) out[n++] = (float)atof(t);
    return n;
}

static void scale_light(ms_light *l, float f)
{
    const float c[3] = { l->corner.x + 0.5f * (l->edge_s.x + l->edge_t.x), l->corner.y + 0.5f * (l->edge_s.y + l->edge_t.y),
                         l->corner.z + 0.5f * (l->edge_s.z + l->edge_t.z) };
    l->edge_s.x *= f; l->edge_s.y *= f; l->edge_s.z *= f;
    l->edge_t.x *= f; l->edge_t.y *= f; l->edge_t.z *= f;
    l->corner.x = c[0] - 0.5f * (l->edge_s.x + l->edge_t.x);
    l->corner.y = c[1] - 0.5f * (l->edge_s.y + l->edge_t.y);
    l->corner.z = c[2] - 0.5f * (l->edge_s.z + l->edge_t.z);
}

/* The paper's "samples mem", the buffer of receiver points: each visible point's query (position, normal,
 * triangle, pixel) and its front and visible masks, which the renderer holds for the whole frame. */
static double points_mb(const ms_frame *f)
{
    const double mask = (double)((f->stats.samples_per_pixel + 63) / 64 * 8);
    /* 36 bytes: ms_shadow_query (src/shadow/method.h) */
    return (double)f->stats.visible_pixels * (36.0 + 2.0 * mask) / 1048576.0;
}

static int g_cpu;   /* --cpu: CPU seconds of all threads instead of wall seconds */

static double total_s(const ms_frame *f, int m)
{
    return (g_cpu ? f->stats.shadow_cpu_s : f->stats.shadow_s) + (m >= HPC ? (double)counter(f, "sort_us") * 1e-6 : 0.0);
}

int main(int argc, char **argv)
{
    int samples[4] = { 256 }, nsamples = 1, threads = 0, sizes[8] = { 512, 1024, 2048 }, nsizes = 3, reference = 1;
    float scales[4] = { 1.0f };
    int nscales = 1;
    int first = 1, run[NM] = { 1, 1, 1, 1 };
    for (; first < argc && argv[first][0] == '-'; first += 2) {
        if (!strcmp(argv[first], "--no-reference")) { reference = 0; first--; continue; }
        if (!strcmp(argv[first], "--cpu")) { g_cpu = 1; first--; continue; }
        if (first + 1 >= argc) { fprintf(stderr, "bench_hpc: %s needs a value\n", argv[first]); return 2; }
        if (!strcmp(argv[first], "--samples")) nsamples = parse_list(argv[first + 1], samples, 4);
        else if (!strcmp(argv[first], "--threads")) threads = atoi(argv[first + 1]);
        else if (!strcmp(argv[first], "--sizes")) nsizes = parse_list(argv[first + 1], sizes, 8);
        else if (!strcmp(argv[first], "--light-scale")) nscales = parse_flist(argv[first + 1], scales, 4);
        else if (!strcmp(argv[first], "--methods")) {
            for (int m = 0; m < NM; m++) run[m] = m == HPC;
            for (char *t = strtok(argv[first + 1], ","); t; t = strtok(NULL, ","))
                for (int m = 0; m < NM; m++) run[m] |= !strcmp(t, methods[m]);
        } else if (!strcmp(argv[first], "--off")) {
            static const char *const names[] = { "umbra", "planesets", "lazy", "ondemand", "sort", "simdsamples", "simdplanes", "footprint", "pairs", "leaffp", "leaffp-rule", "rect", "sure",
                                                 NULL, NULL, NULL, "leaflanes", "tsure" };   /* bits 13-15: faults, not parts */
            for (char *t = strtok(argv[first + 1], ","); t; t = strtok(NULL, ",")) {
                int found = 0;
                for (int b = 0; b < (int)(sizeof names / sizeof *names); b++)
                    if (names[b] && !strcmp(t, names[b])) { ms_hpc_switches |= 1 << b; found = 1; }
                if (!found) { fprintf(stderr, "bench_hpc: --off: unknown part %s\n", t); return 2; }
            }
        } else { fprintf(stderr, "bench_hpc: unknown option %s\n", argv[first]); return 2; }
    }
    if (first >= argc || !nsamples || !nsizes || !nscales) {
        fprintf(stderr, "usage: bench_hpc [--samples a,b] [--sizes a,b,c] [--light-scale 1,2] [--threads T] [--no-reference] [--cpu] SCENE.json|builtin ...\n");
        return 2;
    }
    printf("| scene | light | N | size | raytrace s | scanline s | hpc sort s | hpc build s | hpc cast s | hpc total s "
           "| hpc-scanline total s | raytrace/hpc | raytrace/hpc-scanline | scanline/hpc-scanline | hpc points MB "
           "| hpc hierarchy MB | hpc mask MB | hpc px != raytrace | hpc-scanline px != raytrace | triangles "
           "| pairs in V_L | pairs to footprint | leaf culls | leaf culls blocked | rect pairs | sample tests | samples blocked | full-umbra points | rebuilds |\n");
    printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int a = first; a < argc; a++) {
        ms_scene sc;
        char err[1024];
        if (!strcmp(argv[a], "builtin")) ms_scene_default(&sc);
        else if (ms_scene_load(argv[a], &sc, err, sizeof err)) { fprintf(stderr, "bench_hpc: %s\n", err); return 2; }
        const char *label = strrchr(argv[a], '/') ? strrchr(argv[a], '/') + 1 : argv[a];
        const ms_light light0 = sc.light;
        for (int li = 0; li < nscales; li++)
            for (int ni = 0; ni < nsamples; ni++)
                for (int s = 0; s < nsizes; s++) {
                    sc.light = light0;
                    scale_light(&sc.light, scales[li]);
                    ms_frame f[NM];
                    int have[NM] = { 0 };
                    for (int m = 0; m < NM; m++) {
                        if ((!reference && m < HPC) || !run[m]) continue;
                        ms_render_options o;
                        ms_render_options_default(&o);
                        o.method = methods[m];
                        o.samples = samples[ni];
                        o.width = o.height = sizes[s];
                        o.threads = threads;
                        if (ms_render(&sc, &o, &f[m], err, sizeof err)) {
                            fprintf(stderr, "bench_hpc: %s: %s\n", methods[m], err);
                            return 1;
                        }
                        have[m] = 1;
                        fprintf(stderr, "%s x%g %d %d %s: %.3f s\n", label, (double)(scales[li] * scales[li]), samples[ni],
                                sizes[s], methods[m], total_s(&f[m], m));
                    }
                    const size_t np = (size_t)sizes[s] * sizes[s];
                    char col[NM][32], ratio[3][32], diff[2][32];
                    for (int m = 0; m < NM; m++) snprintf(col[m], sizeof col[m], have[m] ? "%.3f" : "-", have[m] ? total_s(&f[m], m) : 0.0);
                    for (int r = 0; r < 3; r++) snprintf(ratio[r], sizeof ratio[r], "-");
                    for (int d = 0; d < 2; d++) snprintf(diff[d], sizeof diff[d], "-");
                    if (have[RT]) {
                        snprintf(ratio[0], sizeof ratio[0], "%.2f", total_s(&f[RT], RT) / total_s(&f[HPC], HPC));
                        if (have[HPCS]) snprintf(ratio[1], sizeof ratio[1], "%.2f", total_s(&f[RT], RT) / total_s(&f[HPCS], HPCS));
                        for (int d = 0; d < 2; d++) {
                            if (!have[HPC + d]) continue;
                            long c = 0;
                            for (size_t i = 0; i < np; i++) c += f[HPC + d].vis[i] != f[RT].vis[i];
                            snprintf(diff[d], sizeof diff[d], "%ld", c);
                        }
                    }
                    if (have[SL] && have[HPCS]) snprintf(ratio[2], sizeof ratio[2], "%.2f", total_s(&f[SL], SL) / total_s(&f[HPCS], HPCS));
                    const ms_frame *h = &f[HPC];
                    printf("| %s | x%g | %d | %d | %s | %s | %.3f | %.3f | %.3f | %s | %s | %s | %s | %s | %.1f | %.1f | %.1f | %s | %s "
                           "| %llu | %llu | %llu | %llu | %llu | %llu | %llu | %llu | %llu | %llu |\n",
                           label, (double)(scales[li] * scales[li]), samples[ni], sizes[s], col[RT], col[SL],
                           (double)counter(h, "sort_us") * 1e-6, (double)counter(h, "build_us") * 1e-6,
                           (double)counter(h, "cast_us") * 1e-6, col[HPC], col[HPCS], ratio[0], ratio[1], ratio[2],
                           points_mb(h), (double)counter(h, "hierarchy_bytes") / 1048576.0,
                           (double)(counter(h, "mask_bytes") + counter(h, "sample_bytes")) / 1048576.0, diff[0], diff[1],
                           (unsigned long long)counter(h, "triangles"), (unsigned long long)counter(h, "pairs_in_vl"),
                           (unsigned long long)counter(h, "pairs_footprint"), (unsigned long long)counter(h, "leaf_culls"),
                           (unsigned long long)counter(h, "leaf_culls_blocked"), (unsigned long long)counter(h, "rect_pairs"),
                           (unsigned long long)counter(h, "sample_tests"), (unsigned long long)counter(h, "samples_blocked"),
                           (unsigned long long)counter(h, "full_umbra_points"), (unsigned long long)counter(h, "rebuilds"));
                    fflush(stdout);
                    for (int m = 0; m < NM; m++)
                        if (have[m]) ms_frame_free(&f[m]);
                }
        ms_scene_free(&sc);
    }
    return 0;
}
