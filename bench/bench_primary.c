/* The primary methods against each other: the 3D rasterization continuum of Dachsbacher et al. ("3D
 * Rasterization - Unifying Rasterization and Ray Casting", Table 1) beside our BVH ray caster (watertight and --consistent) and Embree's. For each scene, camera
 * (the scene's pinhole, and a latlong panorama from the scene's eye, forward towards its target) and size:
 * per primary the seconds of its whole pass (create + trace of every 16x16 tile, as a frame does; Embree's
 * scene build is reported apart; wall ms and the process's CPU ms, the latter less disturbed by other work;
 * the CPU ms of Embree include its build), triangle set-ups S, edge-function evaluations E, BVH nodes N (where the
 * method counts them), E per pixel, pixels hit, and pixels whose hit triangle differs from bvh --consistent
 * (0 expected for every 3dr variant). Each primary runs `--reps` times, alternating; the run of least CPU time is kept.
 * Prints Markdown.
 *
 * usage: bench_primary [--sizes 1024,4096] [--cameras pinhole,latlong] [--threads T] [--reps R]
 *                      [--primaries 3dr-bb,...] SCENE.json|builtin ...
 *        bench_primary --end-to-end METHOD [--primaries P] [--sizes W] [--threads T] SCENE.json
 *   a whole frame (ms_render) as a latlong panorama of W x W/2 from the scene's eye with shadow method
 *   METHOD and primary P (default 3dr-bb): for a streamed procedural scene; run it under /usr/bin/time -v
 *   for the peak resident memory. METHOD "none": the streamed primary pass alone. */
#include "microshadow.h"
#include "accel/bvh.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct run { double s, cpu_s, build_s; uint64_t c[3]; long hit, differ; int has_c; } run;

/* CPU seconds of the process (all threads): the figure that a machine shared with other work disturbs least. */
static double cpu_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int run_primary(const char *name, int consistent, ms_render_ctx *ctx, const uint32_t *ref, uint32_t *prims, run *r)
{
    const ms_primary_method *pm = ms_find_primary_method(name);
    if (!pm) return -1;
    const int W = ctx->cam.width, H = ctx->cam.height;
    ctx->consistent_primary = consistent;
    char err[256];
    void *st = NULL;
    const double c0 = cpu_s();
    const double t0 = omp_get_wtime();
    if (pm->create(ctx, &st, err, sizeof err)) { fprintf(stderr, "bench_primary: %s: %s\n", name, err); return -1; }
    const double t1 = omp_get_wtime();
    const int tx = (W + 15) / 16, ty = (H + 15) / 16;
#pragma omp parallel for schedule(dynamic, 1) num_threads(ctx->threads)
    for (int t = 0; t < tx * ty; t++) {
        const int x0 = (t % tx) * 16, y0 = (t / tx) * 16;
        const int x1 = x0 + 16 < W ? x0 + 16 : W, y1 = y0 + 16 < H ? y0 + 16 : H;
        ms_hit tile[256];
        pm->trace(st, ctx, x0, y0, x1, y1, tile);
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) prims[(size_t)y * W + x] = tile[(y - y0) * (x1 - x0) + (x - x0)].prim;
    }
    const double t2 = omp_get_wtime();
    r->cpu_s = cpu_s() - c0;
    /* Embree builds its scene in create: a set-up, not the per-frame pass */
    const int is_embree = strcmp(name, "embree") == 0;
    r->build_s = is_embree ? t1 - t0 : 0.0;
    r->s = is_embree ? t2 - t1 : t2 - t0;
    r->has_c = pm->counters != NULL && (consistent || strcmp(name, "bvh") != 0);
    memset(r->c, 0, sizeof r->c);
    if (pm->counters) pm->counters(st, r->c);
    pm->destroy(st);
    ctx->consistent_primary = 0;
    r->hit = 0;
    r->differ = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        r->hit += prims[i] != UINT32_MAX;
        if (ref) r->differ += prims[i] != ref[i];
    }
    return 0;
}

static int parse_list(char *s, int *out, int cap)
{
    int n = 0;
    for (char *t = strtok(s, ","); t && n < cap; t = strtok(NULL, ",")) out[n++] = atoi(t);
    return n;
}

int main(int argc, char **argv)
{
    int sizes[8] = { 1024, 4096 }, nsizes = 2, threads = omp_get_num_procs(), reps = 1;
    int cams[2] = { 1, 1 };   /* pinhole, latlong */
    const char *prim_names[16] = { "3dr-bb", "3dr-bin", "3dr-fc", "3dr-fs", "3dr-full", "bvh", "bvh --consistent",
#ifdef MS_HAVE_EMBREE
                                   "embree",
#endif
    };
    int nprim = 7;
#ifdef MS_HAVE_EMBREE
    nprim = 8;
#endif
    int nprim_default = nprim;
    int first_scene = argc;
    const char *e2e = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--end-to-end") == 0 && i + 1 < argc) { e2e = argv[++i]; continue; }
        if (strcmp(argv[i], "--sizes") == 0 && i + 1 < argc) nsizes = parse_list(argv[++i], sizes, 8);
        else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) reps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--cameras") == 0 && i + 1 < argc) {
            const char *c = argv[++i];
            cams[0] = strstr(c, "pinhole") != NULL;
            cams[1] = strstr(c, "latlong") != NULL;
        } else if (strcmp(argv[i], "--primaries") == 0 && i + 1 < argc) {
            nprim = 0;
            for (char *t = strtok(argv[++i], ","); t && nprim < 16; t = strtok(NULL, ",")) prim_names[nprim++] = t;
        } else { first_scene = i; break; }
    }
    if (first_scene >= argc) {
        fprintf(stderr, "usage: bench_primary [--sizes 1024,4096] [--cameras pinhole,latlong] [--threads T] [--reps R] "
                        "[--primaries a,b] SCENE.json|builtin ...\n");
        return 2;
    }
    if (e2e) {
        ms_scene sc;
        char err[512];
        if (ms_scene_load(argv[first_scene], &sc, err, sizeof err)) { fprintf(stderr, "bench_primary: %s\n", err); return 2; }
        sc.camera.type = MS_CAMERA_LATLONG;
        if (strcmp(e2e, "none") == 0) {
            /* the primary pass alone, streamed as ms_render runs it for a streaming shadow method (no BVH) */
            const ms_primary_method *pm = ms_find_primary_method(nprim != nprim_default ? prim_names[0] : "3dr-bb");
            ms_render_ctx ctx;
            memset(&ctx, 0, sizeof ctx);
            if (!pm || !pm->streams || ms_camera_basis_init(&ctx.cam, &sc.camera, sizes[0], sizes[0] / 2)) {
                fprintf(stderr, "bench_primary: needs a streaming primary and a valid camera\n");
                return 2;
            }
            ctx.scene = &sc;
            ctx.threads = threads;
            void *st = NULL;
            const double t0 = omp_get_wtime(), c0 = cpu_s();
            if (pm->create(&ctx, &st, err, sizeof err)) { fprintf(stderr, "bench_primary: %s\n", err); return 1; }
            uint64_t c[3] = { 0, 0, 0 };
            if (pm->counters) pm->counters(st, c);
            printf("%s: %zu triangles streamed, latlong %dx%d, primary %s alone: %.1f s (CPU %.1f s), S %llu, E %llu\n",
                   argv[first_scene], sc.n_tris, sizes[0], sizes[0] / 2, pm->name, omp_get_wtime() - t0, cpu_s() - c0,
                   (unsigned long long)c[0], (unsigned long long)c[1]);
            pm->destroy(st);
            ms_scene_free(&sc);
            return 0;
        }
        ms_render_options o;
        ms_render_options_default(&o);
        o.method = e2e;
        o.primary = nprim != nprim_default ? prim_names[0] : "3dr-bb";
        o.width = sizes[0];
        o.height = sizes[0] / 2;
        o.threads = threads;
        ms_frame f;
        if (ms_render(&sc, &o, &f, err, sizeof err)) { fprintf(stderr, "bench_primary: %s\n", err); return 1; }
        const ms_stats *st = &f.stats;
        printf("%s: %zu triangles, latlong %dx%d, method %s, primary %s: primary %.1f s (S %llu, E %llu), shadow %.1f s, "
               "total %.1f s, %llu pixels hit\n", argv[first_scene], st->triangles, st->width, st->height, st->method,
               st->primary, st->primary_s, (unsigned long long)st->primary_setups, (unsigned long long)st->primary_edge_evals,
               st->shadow_s, st->total_s, (unsigned long long)st->visible_pixels);
        ms_frame_free(&f);
        ms_scene_free(&sc);
        return 0;
    }
    printf("threads %d, best of %d (alternating)\n\n", threads, reps);
    printf("| scene | T | camera | size | primary | ms | CPU ms | S | E | N | E/pixel | hit pixels | differ from bvh --consistent |\n");
    printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int a = first_scene; a < argc; a++) {
        ms_scene sc;
        char err[512];
        if (strcmp(argv[a], "builtin") == 0) ms_scene_default(&sc);
        else if (ms_scene_load(argv[a], &sc, err, sizeof err)) { fprintf(stderr, "bench_primary: %s\n", err); return 2; }
        ms_bvh bvh;
        if (ms_bvh_build(&bvh, sc.tri, sc.n_tris, threads)) { fprintf(stderr, "bench_primary: out of memory\n"); return 1; }
        const char *sname = strrchr(argv[a], '/') ? strrchr(argv[a], '/') + 1 : argv[a];
        for (int cam = 0; cam < 2; cam++) {
            if (!cams[cam]) continue;
            ms_camera c = sc.camera;
            if (cam == 1) c.type = MS_CAMERA_LATLONG;
            for (int z = 0; z < nsizes; z++) {
                const int W = sizes[z], H = sizes[z];
                ms_render_ctx ctx;
                memset(&ctx, 0, sizeof ctx);
                if (ms_camera_basis_init(&ctx.cam, &c, W, H)) { fprintf(stderr, "bench_primary: bad camera\n"); return 2; }
                ctx.scene = &sc;
                ctx.bvh = &bvh;
                ctx.threads = threads;
                uint32_t *ref = malloc((size_t)W * H * sizeof *ref), *prims = malloc((size_t)W * H * sizeof *prims);
                run best[16], r;
                if (!ref || !prims || run_primary("bvh", 1, &ctx, NULL, ref, &r)) return 1;
                for (int p = 0; p < nprim; p++) best[p].s = -1.0;
                for (int rep = 0; rep < reps; rep++)
                    for (int p = 0; p < nprim; p++) {
                        const int cons = strstr(prim_names[p], "--consistent") != NULL;
                        char nm[64];
                        snprintf(nm, sizeof nm, "%s", prim_names[p]);
                        char *sp = strchr(nm, ' ');
                        if (sp) *sp = 0;
                        if (run_primary(nm, cons, &ctx, ref, prims, &r)) continue;
                        if (best[p].s < 0.0 || r.cpu_s < best[p].cpu_s) best[p] = r;   /* the least disturbed run */
                    }
                for (int p = 0; p < nprim; p++) {
                    if (best[p].s < 0.0) continue;
                    const run *b = &best[p];
                    char S[32] = "-", E[32] = "-", N[32] = "-", EP[32] = "-";
                    if (b->has_c) {
                        snprintf(S, sizeof S, "%.0fk", b->c[0] / 1e3);
                        snprintf(E, sizeof E, "%.0fk", b->c[1] / 1e3);
                        snprintf(N, sizeof N, "%.0fk", b->c[2] / 1e3);
                        snprintf(EP, sizeof EP, "%.1f", (double)b->c[1] / ((double)W * H));
                    }
                    printf("| %s | %zu | %s | %d² | %s | %.0f | %.0f | %s | %s | %s | %s | %ld | %ld |\n", sname, sc.n_tris,
                           cam ? "latlong" : "pinhole", W, prim_names[p], b->s * 1e3, b->cpu_s * 1e3, S, E, N, EP, b->hit, b->differ);
                    if (b->build_s > 0.0) printf("|  |  |  |  | (embree scene build) | %.0f |  |  |  |  |  |  |  |\n", b->build_s * 1e3);
                }
                fflush(stdout);
                free(ref);
                free(prims);
            }
        }
        ms_bvh_free(&bvh);
        ms_scene_free(&sc);
    }
    return 0;
}
