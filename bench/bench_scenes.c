/* The scene benchmark: shadow seconds of every method on every scene, same samples, same threads, same
 * binary, in one run; with the ratio of each method to scanline and to embree, a check that each agrees
 * with raytrace (pixels whose V differs at all, and by more than one sample of the pixel's front count),
 * and for scanline the cost of the shadow factor S (shadow_factor_s / shadow_s) and how far S is from V
 * (mean |S - V| over visible pixels, share of pixels with |S - V| > 0.1). Prints Markdown. */
#include "microshadow.h"
#include <dirent.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAX_SCENES 32
#define MAX_METHODS 8

static int cmp_str(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

static int find_scenes(const char *dir, char **out)
{
    int n = 0;
    DIR *d = opendir(dir);
    if (!d) return 0;
    struct dirent *e;
    while ((e = readdir(d)) && n < MAX_SCENES) {
        if (e->d_name[0] == '.') continue;
        char sub[4096];
        snprintf(sub, sizeof sub, "%s/%s", dir, e->d_name);
        DIR *sd = opendir(sub);
        if (!sd) continue;
        struct dirent *f;
        while ((f = readdir(sd)) && n < MAX_SCENES) {
            size_t l = strlen(f->d_name);
            if (l > 5 && strcmp(f->d_name + l - 5, ".json") == 0) {
                char *p = malloc(strlen(sub) + l + 2);
                sprintf(p, "%s/%s", sub, f->d_name);
                out[n++] = p;
            }
        }
        closedir(sd);
    }
    closedir(d);
    qsort(out, (size_t)n, sizeof *out, cmp_str);
    return n;
}

static const char *base_name(const char *p)
{
    const char *s = strrchr(p, '/');
    return s ? s + 1 : p;
}

int main(int argc, char **argv)
{
    const char *dir = "../shared/scenes", *out_md = NULL;
    int samples[4] = { 1024 }, n_samples = 1, size = 1024, threads = 0;
    const char *methods[MAX_METHODS] = { "raytrace", "embree", "bounds", "hierarchical", "scanline", "mft" };
    int n_methods = 6;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--scenes") && i + 1 < argc) dir = argv[++i];
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc) threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) out_md = argv[++i];
        else if (!strcmp(argv[i], "--samples") && i + 1 < argc) {
            n_samples = 0;
            for (char *t = strtok(argv[++i], ","); t && n_samples < 4; t = strtok(NULL, ",")) samples[n_samples++] = atoi(t);
        } else if (!strcmp(argv[i], "--methods") && i + 1 < argc) {
            n_methods = 0;
            for (char *t = strtok(argv[++i], ","); t && n_methods < MAX_METHODS; t = strtok(NULL, ",")) methods[n_methods++] = t;
        } else {
            fprintf(stderr, "usage: bench_scenes [--scenes DIR] [--samples 256,1024,4096] [--size S] [--threads T] "
                            "[--methods raytrace,embree,bounds,hierarchical,scanline,mft] [--out FILE.md]\n");
            return 2;
        }
    }
    /* Methods not compiled in are dropped with a note rather than failing the run. */
    int m_ok = 0;
    for (int m = 0; m < n_methods; m++) {
        if (ms_method_available(methods[m]) == 1) methods[m_ok++] = methods[m];
        else fprintf(stderr, "bench_scenes: method %s is not available in this build, skipped\n", methods[m]);
    }
    n_methods = m_ok;
    char *scenes[MAX_SCENES];
    int n_scenes = find_scenes(dir, scenes);
    if (!n_scenes) { fprintf(stderr, "bench_scenes: no scenes under %s\n", dir); return 2; }

    FILE *md = out_md ? fopen(out_md, "w") : NULL;
    FILE *outs[2] = { stdout, md };
    time_t now = time(NULL);
    char date[64];
    strftime(date, sizeof date, "%Y-%m-%d", gmtime(&now));
    for (int o = 0; o < 2; o++) {
        if (!outs[o]) continue;
        fprintf(outs[o], "Shadow seconds per method (primary visibility, shading and BVH build excluded), %dx%d, "
                "grid pattern, seed 0, threads %s, measured %s by `build/bench_scenes",
                size, size, threads ? "as given" : "= all cores", date);
        for (int i = 1; i < argc; i++) fprintf(outs[o], " %s", argv[i]);
        fprintf(outs[o], "`.\n\n");
    }
    for (int si = 0; si < n_samples; si++) {
        int N = samples[si];
        for (int o = 0; o < 2; o++) {
            if (!outs[o]) continue;
            fprintf(outs[o], "\n### %d samples\n\n| scene | triangles |", N);
            for (int m = 0; m < n_methods; m++) fprintf(outs[o], " %s s |", methods[m]);
            for (int m = 0; m < n_methods; m++) fprintf(outs[o], " %s / scanline |", methods[m]);
            for (int m = 0; m < n_methods; m++) fprintf(outs[o], " %s / embree |", methods[m]);
            fprintf(outs[o], " pixels off raytrace (any / >1 sample) | S cost (scanline) | mean abs(S - V) | abs(S - V) > 0.1 |\n|---|---|");
            for (int m = 0; m < 3 * n_methods + 4; m++) fprintf(outs[o], "---|");
            fprintf(outs[o], "\n");
            if (outs[o] == stdout) fflush(stdout);
        }
        for (int s = 0; s < n_scenes; s++) {
            ms_scene sc;
            char err[1024];
            if (ms_scene_load(scenes[s], &sc, err, sizeof err)) { fprintf(stderr, "%s\n", err); continue; }
            double secs[MAX_METHODS], s_cost = NAN, mean_sv = NAN, big_sv = NAN;
            float *vis[MAX_METHODS] = { 0 };
            uint16_t *front[MAX_METHODS] = { 0 };
            int ref = -1, scan = -1, emb = -1;
            for (int m = 0; m < n_methods; m++) {
                ms_render_options opt;
                ms_render_options_default(&opt);
                opt.method = methods[m];
                opt.samples = N;
                opt.width = opt.height = size;
                opt.threads = threads;
                ms_frame f;
                secs[m] = NAN;
                if (ms_render(&sc, &opt, &f, err, sizeof err)) { fprintf(stderr, "%s: %s\n", scenes[s], err); continue; }
                secs[m] = f.stats.shadow_s;
                fprintf(stderr, "  %s %s %d: shadow %.3f s (%.1f M rays/s)\n", base_name(scenes[s]), methods[m], N,
                        f.stats.shadow_s, (double)f.stats.shadow_rays / f.stats.shadow_s * 1e-6);
                vis[m] = f.vis;
                front[m] = f.front;
                f.vis = NULL;
                f.front = NULL;
                if (!strcmp(methods[m], "scanline")) {
                    s_cost = f.stats.shadow_factor_s / f.stats.shadow_s;
                    double sum = 0.0;
                    size_t n = 0, big = 0;
                    for (size_t i = 0; i < (size_t)size * size; i++) {
                        if (vis[m][i] < 0.0f) continue;   /* f.vis moved to vis[m] above */
                        double d = fabs((double)f.shadow[i] - (double)vis[m][i]);
                        sum += d;
                        big += d > 0.1;
                        n++;
                    }
                    mean_sv = n ? sum / (double)n : 0.0;
                    big_sv = n ? (double)big / (double)n : 0.0;
                }
                ms_frame_free(&f);
                if (!strcmp(methods[m], "raytrace")) ref = m;
                if (!strcmp(methods[m], "scanline")) scan = m;
                if (!strcmp(methods[m], "embree")) emb = m;
            }
            char agree[512] = "";
            size_t npx = (size_t)size * size;
            for (int m = 0; m < n_methods; m++) {
                if (m == ref || ref < 0 || !vis[m] || !vis[ref]) continue;
                size_t any = 0, big = 0;
                for (size_t i = 0; i < npx; i++) {
                    /* in samples: V = visible / front, and the front masks are the same for the same hit point */
                    const double nf = front[m][i] > front[ref][i] ? front[m][i] : front[ref][i];
                    const double d = fabs((double)vis[m][i] - (double)vis[ref][i]) * (nf > 0 ? nf : N);
                    any += d > 1e-3;
                    big += d > 1.0 + 1e-3;
                }
                char part[96];
                snprintf(part, sizeof part, "%s%s %zu/%zu", agree[0] ? ", " : "", methods[m], any, big);
                strncat(agree, part, sizeof agree - strlen(agree) - 1);
            }
            for (int o = 0; o < 2; o++) {
                if (!outs[o]) continue;
                fprintf(outs[o], "| %s | %zu |", base_name(scenes[s]), sc.n_tris);
                for (int m = 0; m < n_methods; m++) fprintf(outs[o], " %.2f |", secs[m]);
                for (int m = 0; m < n_methods; m++) fprintf(outs[o], scan >= 0 ? " %.2f |" : " - |", scan >= 0 ? secs[m] / secs[scan] : 0.0);
                for (int m = 0; m < n_methods; m++) fprintf(outs[o], emb >= 0 ? " %.2f |" : " - |", emb >= 0 ? secs[m] / secs[emb] : 0.0);
                fprintf(outs[o], " %s | %.1f%% | %.4f | %.2f%% |\n", agree, 100.0 * s_cost, mean_sv, 100.0 * big_sv);
                fflush(outs[o]);
            }
            for (int m = 0; m < n_methods; m++) { free(vis[m]); free(front[m]); }
            ms_scene_free(&sc);
        }
    }
    if (md) fclose(md);
    for (int s = 0; s < n_scenes; s++) free(scenes[s]);
    return 0;
}
