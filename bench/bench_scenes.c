/* The scene benchmark: shadow seconds of every method on every scene, same samples, same threads, same
 * binary, in one run; with the ratio of each method to scanline and to embree, a check that each agrees
 * with raytrace (pixels whose V differs at all, and by more than one sample of the pixel's front count),
 * and for scanline the cost of the shadow factor S (shadow_factor_s / shadow_s) and how far S is from V
 * (mean |S - V| over visible pixels, share of pixels with |S - V| > 0.1). Prints Markdown.
 *
 * Then the time-to-quality table (issue 12): per scene a 4096-sample reference (grid pattern; embree when
 * compiled in, else raytrace: the two agree sample for sample), and for each configuration of
 * quality_cfgs the mean absolute error of V and S against it and its shadow seconds, so that one reads
 * off who reaches a given error first. --quality-only runs only this table and, with --out, replaces only
 * its section of the file (between the markers below; appended when absent). */
#include "microshadow.h"
#include <dirent.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAX_SCENES 32
#define MAX_METHODS 12
#define QUALITY_BEGIN "<!-- time-to-quality: begin (bench_scenes --quality-only rewrites this section) -->"
#define QUALITY_END "<!-- time-to-quality: end -->"

/* The configurations of the time-to-quality table, in the order printed. Methods not compiled in are
 * skipped with a note. */
typedef struct quality_cfg {
    const char *method;
    ms_pattern pattern;
    int samples;                  /* N; the interleaved pattern traces N/16 per pixel */
    int no_filter;                /* interleaved: raw V and S */
    const char *note;
} quality_cfg;
static const quality_cfg quality_cfgs[] = {
    { "mft", MS_PATTERN_INTERLEAVED, 256, 0, "the paper's mode" },
    { "raytrace", MS_PATTERN_INTERLEAVED, 256, 0, "the same samples and filter as mft" },
    { "raytrace", MS_PATTERN_INTERLEAVED, 256, 1, "raw (--no-filter): what the filter buys" },
    { "scanline", MS_PATTERN_GRID, 256, 0, "" },
    { "scanline", MS_PATTERN_GRID, 1024, 0, "" },
    { "embree", MS_PATTERN_GRID, 256, 0, "" },
    { "embree", MS_PATTERN_GRID, 1024, 0, "" },
    { "raytrace", MS_PATTERN_STRATIFIED, 16, 0, "as many rays as interleaved 256" },
    { "raytrace", MS_PATTERN_STRATIFIED, 64, 0, "" },
    { "raytrace", MS_PATTERN_STRATIFIED, 256, 0, "" },
};
#define N_QUALITY (sizeof quality_cfgs / sizeof *quality_cfgs)

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

static int render_frame(const ms_scene *sc, const char *method, ms_pattern pat, int samples, int no_filter, int size,
                        int threads, ms_frame *f, const char *scene_path)
{
    ms_render_options opt;
    ms_render_options_default(&opt);
    opt.method = method;
    opt.pattern = pat;
    opt.samples = samples;
    opt.no_filter = no_filter;
    opt.width = opt.height = size;
    opt.threads = threads;
    char err[1024];
    if (ms_render(sc, &opt, f, err, sizeof err)) { fprintf(stderr, "%s: %s\n", scene_path, err); return -1; }
    return 0;
}

/* The time-to-quality table for every scene into out (Markdown, between the section markers). */
static void quality_table(FILE *out, char **scenes, int n_scenes, int size, int threads, const char *date,
                          const char *cmd)
{
    const char *ref_method = ms_method_available("embree") == 1 ? "embree" : "raytrace";
    fprintf(out, "%s\n\n### Time to quality\n\nMean absolute error of V and S against a 4096-sample `%s` frame "
            "(grid pattern), and shadow seconds (the interleaved filter included), %dx%d, seed 0, threads %s, "
            "measured %s by `%s`. Rays per pixel: N, or N/16 for the interleaved "
            "pattern (then filtered over 4x4 pixels).\n\n"
            "| scene | method | pattern | N | rays per pixel | MAE V | MAE S | shadow s | note |\n"
            "|---|---|---|---|---|---|---|---|---|\n",
            QUALITY_BEGIN, ref_method, size, size, threads ? "as given" : "= all cores", date, cmd);
    fflush(out);
    for (int s = 0; s < n_scenes; s++) {
        ms_scene sc;
        char err[1024];
        if (ms_scene_load(scenes[s], &sc, err, sizeof err)) { fprintf(stderr, "%s\n", err); continue; }
        ms_frame ref;
        if (render_frame(&sc, ref_method, MS_PATTERN_GRID, 4096, 0, size, threads, &ref, scenes[s])) { ms_scene_free(&sc); continue; }
        fprintf(stderr, "  %s reference %s 4096: shadow %.3f s\n", base_name(scenes[s]), ref_method, ref.stats.shadow_s);
        for (size_t c = 0; c < N_QUALITY; c++) {
            const quality_cfg *q = &quality_cfgs[c];
            if (ms_method_available(q->method) != 1) {
                fprintf(stderr, "bench_scenes: method %s is not available in this build, skipped\n", q->method);
                continue;
            }
            ms_frame f;
            if (render_frame(&sc, q->method, q->pattern, q->samples, q->no_filter, size, threads, &f, scenes[s])) continue;
            /* over the pixels both frames see (embree's primary rays may pick another triangle at an edge) */
            double ev = 0.0, es = 0.0;
            size_t n = 0;
            for (size_t i = 0; i < (size_t)size * size; i++) {
                if (ref.vis[i] < 0.0f || f.vis[i] < 0.0f) continue;
                ev += fabs((double)f.vis[i] - ref.vis[i]);
                es += fabs((double)f.shadow[i] - ref.shadow[i]);
                n++;
            }
            if (n) { ev /= (double)n; es /= (double)n; }
            const char *raw = q->no_filter ? " raw" : "";
            fprintf(stderr, "  %s %s %s%s %d: MAE V %.5f, shadow %.3f s\n", base_name(scenes[s]), q->method,
                    ms_pattern_name(q->pattern), raw, q->samples, ev, f.stats.shadow_s);
            fprintf(out, "| %s | %s | %s%s | %d | %d | %.5f | %.5f | %.3f | %s |\n", base_name(scenes[s]), q->method,
                    ms_pattern_name(q->pattern), raw, q->samples, f.stats.samples_per_pixel, ev, es, f.stats.shadow_s,
                    q->note);
            fflush(out);
            ms_frame_free(&f);
        }
        ms_frame_free(&ref);
        ms_scene_free(&sc);
    }
    fprintf(out, "\n%s\n", QUALITY_END);
}

/* Replaces the time-to-quality section of the file at path by section (appends it when the file has
 * none), through a temporary file renamed into place. */
static int splice_section(const char *path, const char *section)
{
    char *old = NULL;
    size_t len = 0;
    FILE *f = fopen(path, "rb");
    if (f) {
        fseek(f, 0, SEEK_END);
        long n = ftell(f);
        fseek(f, 0, SEEK_SET);
        old = calloc((size_t)(n > 0 ? n : 0) + 1, 1);
        if (!old || (n > 0 && fread(old, 1, (size_t)n, f) != (size_t)n)) { fclose(f); free(old); return -1; }
        len = (size_t)n;
        fclose(f);
    }
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *o = fopen(tmp, "wb");
    if (!o) { free(old); return -1; }
    const char *b = old ? strstr(old, QUALITY_BEGIN) : NULL, *e = b ? strstr(b, QUALITY_END) : NULL;
    if (b && e) {
        e += strlen(QUALITY_END);
        if (*e == '\n') e++;
        fwrite(old, 1, (size_t)(b - old), o);
        fputs(section, o);
        fputs(e, o);
    } else {
        if (old) fwrite(old, 1, len, o);
        if (len && old[len - 1] != '\n') fputc('\n', o);
        fputs("\n", o);
        fputs(section, o);
    }
    free(old);
    if (fclose(o) || rename(tmp, path)) { remove(tmp); return -1; }
    return 0;
}

int main(int argc, char **argv)
{
    const char *dir = "../shared/scenes", *out_md = NULL;
    int samples[4] = { 1024 }, n_samples = 1, size = 1024, threads = 0;
    /* A method may name a variant after a colon: scanline:pixel (the per-pixel traversal), scanline:fs
     * (block traversal with frustum shrinking), embree:packet16, embree:packet8 and embree:stream (its ways
     * of being handed rays; the "/ embree" ratios are against the fastest of the embree variants run).
     * Plain names run the defaults. */
    const char *methods[MAX_METHODS] = { "raytrace", "embree:packet16", "embree:packet8", "embree:stream", "mft",
                                         "bounds", "hierarchical", "scanline:pixel", "scanline" };
    int n_methods = 9, quality_only = 0, no_quality = 0, repeat = 1;
    ms_pattern pattern = MS_PATTERN_GRID;   /* --pattern: the main table's samples (interleaved: filtered, as rendered) */
    const char *pattern_name = "grid";
    /* The command line as given, for the header (strtok below cuts the lists). */
    char cmdline[1024] = "";
    for (int i = 1; i < argc; i++) {
        strncat(cmdline, " ", sizeof cmdline - strlen(cmdline) - 1);
        strncat(cmdline, argv[i], sizeof cmdline - strlen(cmdline) - 1);
    }
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--scenes") && i + 1 < argc) dir = argv[++i];
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc) threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) out_md = argv[++i];
        else if (!strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = atoi(argv[++i]) < 1 ? 1 : atoi(argv[i]);
        else if (!strcmp(argv[i], "--quality-only")) quality_only = 1;
        else if (!strcmp(argv[i], "--no-quality")) no_quality = 1;
        else if (!strcmp(argv[i], "--pattern") && i + 1 < argc) {
            const char *pn = argv[++i];
            if (!strcmp(pn, "grid")) pattern = MS_PATTERN_GRID;
            else if (!strcmp(pn, "interleaved")) pattern = MS_PATTERN_INTERLEAVED;
            else if (!strcmp(pn, "stratified")) pattern = MS_PATTERN_STRATIFIED;
            else { fprintf(stderr, "bench_scenes: unknown pattern %s\n", pn); return 2; }
            pattern_name = pn;
        }
        else if (!strcmp(argv[i], "--samples") && i + 1 < argc) {
            n_samples = 0;
            for (char *t = strtok(argv[++i], ","); t && n_samples < 4; t = strtok(NULL, ",")) samples[n_samples++] = atoi(t);
        } else if (!strcmp(argv[i], "--methods") && i + 1 < argc) {
            n_methods = 0;
            for (char *t = strtok(argv[++i], ","); t && n_methods < MAX_METHODS; t = strtok(NULL, ",")) methods[n_methods++] = t;
        } else {
            fprintf(stderr, "usage: bench_scenes [--scenes DIR] [--samples 256,1024,4096] [--size S] [--threads T] "
                            "[--methods raytrace,embree:packet16,embree:packet8,embree:stream,mft,bounds,hierarchical,scanline:pixel,scanline] "
                            "[--pattern grid|interleaved|stratified] [--repeat N] [--quality-only | --no-quality] "
                            "[--out FILE.md]\n");
            return 2;
        }
    }
    /* Methods not compiled in are dropped with a note rather than failing the run. */
    int m_ok = 0;
    for (int m = 0; m < n_methods; m++) {
        char base[64];
        snprintf(base, sizeof base, "%s", methods[m]);
        base[strcspn(base, ":")] = 0;
        if (ms_method_available(base) == 1) methods[m_ok++] = methods[m];
        else fprintf(stderr, "bench_scenes: method %s is not available in this build, skipped\n", methods[m]);
    }
    n_methods = m_ok;
    char *scenes[MAX_SCENES];
    int n_scenes = find_scenes(dir, scenes);
    if (!n_scenes) { fprintf(stderr, "bench_scenes: no scenes under %s\n", dir); return 2; }

    time_t now = time(NULL);
    char date[64];
    strftime(date, sizeof date, "%Y-%m-%d", gmtime(&now));
    char cmd[1100];
    snprintf(cmd, sizeof cmd, "build/bench_scenes%s", cmdline);
    /* Built in memory (progress on stderr), then printed and written; with --quality-only the file keeps
     * everything outside the section. */
    char *sec = NULL;
    size_t sec_len = 0;
    if (quality_only) {
        FILE *mem = open_memstream(&sec, &sec_len);
        if (!mem) { fprintf(stderr, "bench_scenes: out of memory\n"); return 1; }
        quality_table(mem, scenes, n_scenes, size, threads, date, cmd);
        fclose(mem);
        fputs(sec, stdout);
        int rc = 0;
        if (out_md && splice_section(out_md, sec)) { fprintf(stderr, "bench_scenes: cannot write %s\n", out_md); rc = 1; }
        free(sec);
        for (int s = 0; s < n_scenes; s++) free(scenes[s]);
        return rc;
    }
    FILE *md = out_md ? fopen(out_md, "w") : NULL;
    FILE *outs[2] = { stdout, md };
    for (int o = 0; o < 2; o++) {
        if (!outs[o]) continue;
        fprintf(outs[o], "Shadow seconds per method (primary visibility, shading and BVH build excluded; the fastest of %d "
                "frames), %dx%d, %s pattern, seed 0, threads %s, measured %s by `build/bench_scenes",
                repeat, size, size, pattern_name, threads ? "as given" : "= all cores", date);
        fprintf(outs[o], "%s`. What the figures mean and how they moved: the lab notebook, "
                "docs/notebook/README.md (by hand; this file is regenerated).\n\n", cmdline);
    }
    double log_scan[MAX_METHODS] = { 0 }, log_emb[MAX_METHODS] = { 0 };
    int n_scan[MAX_METHODS] = { 0 }, n_emb[MAX_METHODS] = { 0 }, n_lines = 0;
    char *counter_lines[MAX_METHODS * MAX_SCENES];
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
            ms_stats stats[MAX_METHODS];
            memset(stats, 0, sizeof stats);
            float *vis[MAX_METHODS] = { 0 };
            uint16_t *front[MAX_METHODS] = { 0 };
            int ref = -1, scan = -1, emb = -1;
            for (int m = 0; m < n_methods; m++) {
                ms_render_options opt;
                ms_render_options_default(&opt);
                char base[64];
                snprintf(base, sizeof base, "%s", methods[m]);
                const char *variant = strchr(methods[m], ':');
                base[strcspn(base, ":")] = 0;
                opt.method = base;
                if (variant && !strcmp(variant + 1, "pixel")) opt.traversal = MS_TRAVERSAL_PIXEL;
                if (variant && !strcmp(variant + 1, "fs")) opt.frustum_shrink = 1;
                if (variant && !strcmp(variant + 1, "packet16")) opt.embree_mode = MS_EMBREE_PACKET16;
                if (variant && !strcmp(variant + 1, "stream")) opt.embree_mode = MS_EMBREE_STREAM;
                if (variant && !strcmp(variant + 1, "packet8")) opt.embree_mode = MS_EMBREE_PACKET8;
                opt.samples = N;
                opt.pattern = pattern;
                opt.width = opt.height = size;
                opt.threads = threads;
                ms_frame f;
                secs[m] = NAN;
                if (ms_render(&sc, &opt, &f, err, sizeof err)) { fprintf(stderr, "%s: %s\n", scenes[s], err); continue; }
                /* --repeat: the fastest of N frames (short frames move by 10% from run to run); the last frame's
                 * images and counters, which every frame repeats */
                double best = f.stats.shadow_s;
                for (int r = 1; r < repeat; r++) {
                    ms_frame_free(&f);
                    memset(&f, 0, sizeof f);
                    if (ms_render(&sc, &opt, &f, err, sizeof err)) { fprintf(stderr, "%s: %s\n", scenes[s], err); break; }
                    best = f.stats.shadow_s < best ? f.stats.shadow_s : best;
                }
                if (!f.vis) continue;
                f.stats.shadow_s = best;
                secs[m] = f.stats.shadow_s;
                stats[m] = f.stats;
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
                /* "/ embree" is against Embree at its best: the fastest of the embree variants measured */
                if (!strncmp(methods[m], "embree", 6) && (emb < 0 || isnan(secs[emb]) || secs[m] < secs[emb])) emb = m;
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
                for (int m = 0; m < n_methods; m++) fprintf(outs[o], " %.4f |", secs[m]);
                for (int m = 0; m < n_methods; m++) fprintf(outs[o], scan >= 0 ? " %.2f |" : " - |", scan >= 0 ? secs[m] / secs[scan] : 0.0);
                for (int m = 0; m < n_methods; m++) fprintf(outs[o], emb >= 0 ? " %.2f |" : " - |", emb >= 0 ? secs[m] / secs[emb] : 0.0);
                fprintf(outs[o], " %s | %.1f%% | %.4f | %.2f%% |\n", agree, 100.0 * s_cost, mean_sv, 100.0 * big_sv);
                fflush(outs[o]);
            }
            for (int m = 0; m < n_methods; m++) {
                if (isnan(secs[m])) continue;
                if (scan >= 0 && !isnan(secs[scan])) { log_scan[m] += log(secs[m] / secs[scan]); n_scan[m]++; }
                if (emb >= 0 && !isnan(secs[emb])) { log_emb[m] += log(secs[m] / secs[emb]); n_emb[m]++; }
                /* the counters, for the table after this sample count */
                char *line = counter_lines[n_lines] = malloc(4096);
                if (!line) continue;
                int len = snprintf(line, 4096, "| %s | %s |", base_name(scenes[s]), methods[m]);
                for (int c = 0; c < stats[m].n_counters && len < 4000; c++)
                    len += snprintf(line + len, (size_t)(4096 - len), " %s %.3gM;", stats[m].counter_name[c],
                                    (double)stats[m].counter[c] * 1e-6);
                snprintf(line + len, (size_t)(4096 - len), " |\n");
                n_lines++;
            }
            for (int m = 0; m < n_methods; m++) { free(vis[m]); free(front[m]); }
            ms_scene_free(&sc);
        }
        for (int o = 0; o < 2; o++) {
            if (!outs[o]) continue;
            fprintf(outs[o], "| geometric mean | |");
            for (int m = 0; m < n_methods; m++) fprintf(outs[o], " |");
            for (int m = 0; m < n_methods; m++) fprintf(outs[o], n_scan[m] ? " %.2f |" : " - |", n_scan[m] ? exp(log_scan[m] / n_scan[m]) : 0.0);
            for (int m = 0; m < n_methods; m++) fprintf(outs[o], n_emb[m] ? " %.2f |" : " - |", n_emb[m] ? exp(log_emb[m] / n_emb[m]) : 0.0);
            fprintf(outs[o], " | | | |\n");
            /* Counters per method (the paper's Table 1: for the block traversals aabb_tests are 16-wide
             * node tests, tris_accessed the triangles of visited leaves, tri_pixel_tests the triangle-frustum
             * pairs after the leaf's culling, triangles_rasterized / the ray tests what reached the kernel). */
            fprintf(outs[o], "\nCounters, %d samples (M = millions; per method, see docs/design.md):\n\n| scene | method | counters |\n|---|---|---|\n", N);
            for (int l = 0; l < n_lines; l++) fputs(counter_lines[l], outs[o]);
            fflush(outs[o]);
        }
        for (int l = 0; l < n_lines; l++) free(counter_lines[l]);
        n_lines = 0;
        memset(log_scan, 0, sizeof log_scan); memset(log_emb, 0, sizeof log_emb);
        memset(n_scan, 0, sizeof n_scan); memset(n_emb, 0, sizeof n_emb);
    }
    FILE *mem = no_quality ? NULL : open_memstream(&sec, &sec_len);
    if (mem) {
        quality_table(mem, scenes, n_scenes, size, threads, date, cmd);
        fclose(mem);
        for (int o = 0; o < 2; o++)
            if (outs[o]) fprintf(outs[o], "\n%s", sec);
        free(sec);
    }
    if (md) fclose(md);
    for (int s = 0; s < n_scenes; s++) free(scenes[s]);
    return 0;
}
