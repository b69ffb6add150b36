/* What an alpha-tested triangle costs the micro-rasterizer (src/visibility/alpha.c, ms_alpha_raster), in TSC cycles:
 * for every (visible point, alpha-tested triangle) pair of a frame whose triangle covers some of the point's
 * visible samples, the Scanline kernel alone into the point's buffer (what an opaque triangle costs) against
 * ms_alpha_raster (the kernel into a scratch buffer, the merge, one alpha lookup per covered visible sample);
 * and the alpha lookup itself (ms_alpha_segment_occludes) per call.
 *
 *   bench_alpha SCENE.json [--size N] [--k 16|32|64]
 *
 * Each call is timed alone between fenced rdtsc (about 50 cycles of fence on this machine, in both columns);
 * the figures are medians over the pairs. The scene should have alpha-tested materials (e.g. the one of
 * scripts/make_foliage_scene.py). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <x86intrin.h>
#include "microshadow.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include "raster/raster.h"
#include "light/pattern.h"
#include "core/vec.h"

static inline uint64_t tsc(void)
{
    _mm_lfence();
    const uint64_t t = __rdtsc();
    _mm_lfence();
    return t;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}
static uint64_t median(uint64_t *v, size_t n)
{
    if (!n) return 0;
    qsort(v, n, sizeof *v, cmp_u64);
    return v[n / 2];
}

int main(int argc, char **argv)
{
    const char *path = NULL;
    int size = 96, k = 32;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc) size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--k") && i + 1 < argc) k = atoi(argv[++i]);
        else path = argv[i];
    }
    if (!path || (k != 16 && k != 32 && k != 64) || size < 1) {
        fprintf(stderr, "usage: bench_alpha SCENE.json [--size N] [--k 16|32|64]\n");
        return 2;
    }
    ms_scene sc;
    char err[512];
    if (ms_scene_load(path, &sc, err, sizeof err)) { fprintf(stderr, "%s\n", err); return 2; }
    ms_bvh bvh;
    ms_alpha *alpha = NULL;
    if (ms_bvh_build(&bvh, sc.tri, sc.n_tris, 0) || ms_alpha_build(&sc, &bvh, &alpha)) { fprintf(stderr, "out of memory\n"); return 1; }
    if (!alpha) { fprintf(stderr, "%s: no alpha-tested triangles\n", path); return 2; }
    ms_render_ctx ctx;
    ms_render_ctx_init(&ctx, &sc, &bvh, sc.n_lights ? &sc.lights[0] : &sc.light, MS_PATTERN_GRID, k, 0, 1);
    if (ms_camera_basis_init(&ctx.cam, &sc.camera, size, size)) { fprintf(stderr, "bad camera\n"); return 2; }
    ctx.alpha = alpha;
    ms_isa isa;
    const ms_raster_fn kernel = ms_raster_kernel(MS_KERNEL_SCANLINE, k, MS_ISA_AUTO, &isa);
    const ms_primary_method *pm = ms_find_primary_method("bvh");
    void *ps = NULL;
    ms_hit *hits = malloc((size_t)size * size * sizeof *hits);
    if (!hits || pm->create(&ctx, &ps, err, sizeof err)) return 1;
    pm->trace(ps, &ctx, 0, 0, size, size, hits);
    pm->destroy(ps);

    const size_t mw = (size_t)ctx.mask_words, cap = 1u << 22;
    uint64_t *c_kernel = malloc(cap * sizeof *c_kernel), *c_alpha = malloc(cap * sizeof *c_alpha);
    if (!c_kernel || !c_alpha) return 1;
    size_t n = 0;
    uint64_t lookups = 0;
    _Alignas(64) uint64_t front[64], buf[64];
    for (int p = 0; p < size * size && n < cap; p++) {
        const ms_hit *h = &hits[p];
        if (h->prim == UINT32_MAX) continue;
        ms_shadow_query q = { { h->p[0], h->p[1], h->p[2] }, { h->n[0], h->n[1], h->n[2] }, h->prim, (uint32_t)(p % size),
                              (uint32_t)(p / size) };
        ms_front_mask(&ctx, &q, NULL, front);
        ms_grid g;
        ms_grid_for_pixel(&ctx.light, k, q.px, q.py, ctx.seed, &g);
        ms_raster_frame f;
        if (ms_raster_frame_init(&f, q.p, &g, ctx.near, ctx.far, 0)) continue;
        const ms_alpha_pixel ap = { &ctx, &q };
        for (uint32_t t = 0; t < bvh.n_tris && n < cap; t++) {
            if (!alpha->flag[t] || t == q.prim) continue;
            const float *tri = bvh.tri + 9 * (size_t)t;
            memcpy(buf, front, mw * sizeof *buf);
            uint64_t t0 = tsc();
            kernel(&f, tri, buf);
            uint64_t t1 = tsc();
            int covered = 0;
            for (size_t w = 0; w < mw; w++) covered += __builtin_popcountll(front[w] & ~buf[w]);
            if (!covered) continue;   /* only pairs where the triangle meets visible samples */
            c_kernel[n] = t1 - t0;
            memcpy(buf, front, mw * sizeof *buf);
            t0 = tsc();
            ms_alpha_raster(&ap, &f, kernel, tri, t, buf);
            t1 = tsc();
            c_alpha[n++] = t1 - t0;
            lookups += (uint64_t)covered;
        }
    }
    /* The lookup alone: segments from the pairs' points to light samples through the alpha-tested triangles'
     * centroids' neighbourhood (any segment: the cost does not depend on the answer). */
    const int reps = 200000;
    uint64_t *c_look = malloc((size_t)reps * sizeof *c_look);
    if (!c_look) return 1;
    uint32_t t = 0;
    volatile int sink = 0;
    for (int r = 0; r < reps; r++) {
        while (!alpha->flag[t]) t = (t + 1) % bvh.n_tris;
        const float *v = bvh.tri + 9 * (size_t)t;
        const float P[3] = { v[0] * 0.3f + v[3] * 0.3f + v[6] * 0.4f, v[1] * 0.3f + v[4] * 0.3f + v[7] * 0.4f - 1.0f,
                             v[2] * 0.3f + v[5] * 0.3f + v[8] * 0.4f };
        const float L[3] = { P[0] + 0.01f * (float)(r % 17), P[1] + 2.0f, P[2] - 0.01f * (float)(r % 13) };
        const uint64_t t0 = tsc();
        sink += ms_alpha_segment_occludes(alpha, t, P, L);
        c_look[r] = tsc() - t0;
        t = (t + 1) % bvh.n_tris;
    }
    (void)sink;
    double mk = 0, ma = 0;
    for (size_t i = 0; i < n; i++) { mk += (double)c_kernel[i]; ma += (double)c_alpha[i]; }
    printf("%s, %dx%d, k = %d, Scanline %s: %zu (point, alpha-tested triangle) pairs meeting visible samples, "
           "%.1f covered visible samples each\n", path, size, size, k, ms_isa_name(isa), n, n ? (double)lookups / n : 0.0);
    printf("  kernel alone (an opaque triangle): median %llu cycles, mean %.0f\n", (unsigned long long)median(c_kernel, n),
           n ? mk / n : 0.0);
    printf("  ms_alpha_raster:                   median %llu cycles, mean %.0f\n", (unsigned long long)median(c_alpha, n),
           n ? ma / n : 0.0);
    printf("  one alpha lookup (ms_alpha_segment_occludes, fenced): median %llu cycles\n",
           (unsigned long long)median(c_look, (size_t)reps));
    free(c_look);
    free(c_kernel);
    free(c_alpha);
    free(hits);
    ms_alpha_free(alpha);
    ms_bvh_free(&bvh);
    ms_scene_free(&sc);
    return 0;
}
