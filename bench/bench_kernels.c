/* Reproduces Woop 2010, Figure 2 on this machine: cycles per triangle (rdtsc, the median over the
 * triangles of a bin) against the number of samples the triangle occludes, for the Scanline, Bounds and
 * Hierarchical kernels on the 32x32 buffer (or --k 16/64), the SIMD Scanline variant the CPU dispatches
 * to (scanline_simd) and, when that is AVX-512 and the CPU has AVX2+FMA, the AVX2 variant
 * (scanline_avx2), which is what CPUs without AVX-512 run. "scanline" is the portable scalar kernel (the
 * fallback, compiled for baseline x86-64); Bounds and Hierarchical are the ones the renderer dispatches
 * to: their C compiled for the CPU's ISA.
 *
 *   bench_kernels [--csv] [--n TRIANGLES] [--k 16|32|64] [--seed S] [--passes P]
 *
 * Triangles: random shape, orientation and size, vertices at random depths between C and the light,
 * centred on the light (their projections fall on it). The triangles of a bin are shuffled and timed in
 * batches of 32 consecutive calls (fenced rdtsc around the batch): one fenced call alone measures its
 * latency plus ~50 cycles of fence, not its cost in a stream, and this machine's TSC ticks in steps of 26.
 * A triangle's cycles are its batch's mean; the figure is the median over all batches of the bin and
 * over P passes (reshuffled each time). --csv prints
 * kernel,samples,cycles rows: per kernel and bin, the bin's median occluded-sample count and median
 * cycles. The text report adds the fitted Scanline setup cost and cost per iterated scanline, as the
 * paper does, and the figures for the project's targets. Cycles are TSC cycles. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <x86intrin.h>
#include "raster/raster.h"
#include "raster/raster_internal.h"

typedef struct kernel_entry {
    const char *name;
    ms_raster_fn fn;
} kernel_entry;

static uint64_t g_rng = 12345;
static double unit(void)
{
    uint64_t z = (g_rng += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}
static uint32_t median_u32(uint32_t *v, size_t n)
{
    if (n == 0) return 0;
    qsort(v, n, sizeof *v, cmp_u32);
    return v[n / 2];
}

static inline uint64_t tsc_begin(void)
{
    _mm_lfence();
    uint64_t t = __rdtsc();
    _mm_lfence();
    return t;
}
static inline uint64_t tsc_end(void)
{
    unsigned aux;
    uint64_t t = __rdtscp(&aux);
    _mm_lfence();
    return t;
}


/* Sample-count bins: two per octave, 1 .. k*k. */
static int bin_of(int count) { return count <= 0 ? -1 : (int)floor(2.0 * log2((double)count) + 1e-9); }

int main(int argc, char **argv)
{
    int csv = 0, k = 32, passes = 3;
    long n = 200000;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--csv")) csv = 1;
        else if (!strcmp(argv[i], "--n") && i + 1 < argc) n = atol(argv[++i]);
        else if (!strcmp(argv[i], "--k") && i + 1 < argc) k = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--seed") && i + 1 < argc) g_rng = strtoull(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--passes") && i + 1 < argc) passes = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: %s [--csv] [--n TRIANGLES] [--k 16|32|64] [--seed S] [--passes P]\n", argv[0]);
            return 2;
        }
    }
    if (ms_raster_kernel(MS_KERNEL_SCANLINE, k, MS_ISA_AUTO, NULL) == NULL || n < 100 || passes < 1) {
        fprintf(stderr, "bench_kernels: bad --k, --n or --passes\n");
        return 2;
    }

    /* A unit light at z = 0 seen from C one unit below its centre, with the renderer's rotated and
     * shifted grid. */
    ms_light light;
    memset(&light, 0, sizeof light);
    light.corner = (ms_vec3){ 0, 0, 0 };
    light.edge_s = (ms_vec3){ 1, 0, 0 };
    light.edge_t = (ms_vec3){ 0, 1, 0 };
    ms_grid g;
    ms_grid_for_pixel(&light, k, 17, 23, 1, &g);
    const float c[3] = { 0.5f, 0.5f, -1.0f };
    ms_raster_frame f;
    if (ms_raster_frame_init(&f, c, &g, 1e-4f, 1.0f, 0) != 0) return 1;
    double M[3][3];
    for (int r = 0; r < 3; r++) { M[r][0] = g.ds[r]; M[r][1] = g.dt[r]; M[r][2] = (double)g.p0[r] - c[r]; }

    ms_isa simd_isa = MS_ISA_AUTO;
    kernel_entry kernels[5] = {
        { "scanline", ms_raster_kernel_isa(MS_KERNEL_SCANLINE, k, MS_ISA_SCALAR) },
        { "bounds", ms_raster_kernel(MS_KERNEL_BOUNDS, k, MS_ISA_AUTO, NULL) },
        { "hierarchical", ms_raster_kernel(MS_KERNEL_HIERARCHICAL, k, MS_ISA_AUTO, NULL) },
        { "scanline_simd", ms_raster_kernel(MS_KERNEL_SCANLINE, k, MS_ISA_AUTO, &simd_isa) },
    };
    int nk = 4;
    /* A column of its own only when it is not already scanline_simd (a CPU without AVX-512). */
    const ms_raster_fn avx2 = ms_raster_kernel_isa(MS_KERNEL_SCANLINE, k, MS_ISA_AVX2);
    const int i_avx2 = avx2 != NULL && avx2 != kernels[3].fn ? nk : -1;
    if (i_avx2 >= 0) kernels[nk++] = (kernel_entry){ "scanline_avx2", avx2 };

    /* Triangles: centre on the light, size log-uniform from a third of a sample to 1.5 lights, vertices
     * in random directions at random depths. Kept only when they occlude something. */
    float *tris = malloc(sizeof(float) * 9 * (size_t)n);
    int *count = malloc(sizeof(int) * (size_t)n), *rows = malloc(sizeof(int) * (size_t)n);
    uint32_t *cyc = malloc(sizeof(uint32_t) * (size_t)n * (size_t)nk);
    long *order = malloc(sizeof(long) * (size_t)n);
    uint32_t *tmp = malloc(sizeof(uint32_t) * (size_t)n);
    if (!tris || !count || !rows || !cyc || !order || !tmp) return 1;
    uint64_t buf[64];
    for (long t = 0; t < n;) {
        double cx = unit() * k, cy = unit() * k, size = exp(log(0.3) + unit() * (log(1.5 * k) - log(0.3)));
        float *tri = tris + 9 * t;
        for (int v = 0; v < 3; v++) {
            double a = unit() * 2 * M_PI, r = size * sqrt(unit()), z = 0.1 + 0.8 * unit();
            double lv[3] = { (cx + r * cos(a)) * z, (cy + r * sin(a)) * z, z };
            for (int i = 0; i < 3; i++) tri[3 * v + i] = (float)(c[i] + M[i][0] * lv[0] + M[i][1] * lv[1] + M[i][2] * lv[2]);
        }
        ms_buffer_fill_visible(buf, k);
        kernels[1].fn(&f, tri, buf);
        count[t] = k * k - ms_buffer_visible_count(buf, k);
        if (count[t] == 0) continue;
        rows[t] = ms_scanline_rows(&f, tri);
        order[t] = t;
        t++;
    }

    /* Each triangle's cycles: the mean of its batch of BATCH consecutive calls in a shuffled stream of
     * triangles of its own bin (or row count), the least over the passes. */
    enum { BATCH = 32 };
    for (long i = 0; i < (long)n * nk; i++) cyc[i] = UINT32_MAX;
    for (int p = 0; p < passes; p++) {
        for (long t = n - 1; t > 0; t--) {
            long j = (long)(unit() * (double)(t + 1));
            long x = order[t]; order[t] = order[j]; order[j] = x;
        }
        /* Stable regroup by bin, keeping the shuffled order inside each bin. */
        long w = 0;
        for (int b = -1; b <= bin_of(k * k); b++)
            for (long i = 0; i < n; i++)
                if (bin_of(count[order[i]]) == b) tmp[w++] = (uint32_t)order[i];
        for (int kk = 0; kk < nk; kk++) {
            ms_raster_fn fn = kernels[kk].fn;
            for (long i0 = 0; i0 < n; i0 += BATCH) {
                long i1 = i0 + BATCH < n ? i0 + BATCH : n;
                /* The batch's triangles side by side and in cache, as a renderer's leaf would hand them
                 * over: the kernels are timed, not the memory system. */
                float batch[9 * BATCH];
                for (long i = i0; i < i1; i++) memcpy(batch + 9 * (i - i0), tris + 9 * (size_t)tmp[i], 9 * sizeof(float));
                ms_buffer_fill_visible(buf, k);
                uint64_t t0 = tsc_begin();
                for (long i = i0; i < i1; i++) fn(&f, batch + 9 * (i - i0), buf);
                uint64_t dt = tsc_end() - t0;
                uint32_t v = (uint32_t)((dt + (uint64_t)(i1 - i0) / 2) / (uint64_t)(i1 - i0));
                for (long i = i0; i < i1; i++)
                    if (v < cyc[(size_t)tmp[i] * nk + kk]) cyc[(size_t)tmp[i] * nk + kk] = v;
            }
        }
    }
    const uint32_t overhead = 0;

    /* Per bin: median count and median cycles of each kernel. */
    const int nbins = bin_of(k * k) + 1;
    if (!csv) {
        printf("bench_kernels: k=%d, %ld triangles, %d passes, SIMD variant %s, TSC cycles (batches of %d)\n", k, n,
               passes, ms_isa_name(simd_isa), (int)BATCH);
        (void)overhead;
        printf("%-12s %8s", "samples", "tris");
        for (int kk = 0; kk < nk; kk++) printf(" %14s", kernels[kk].name);
        printf("\n");
    } else {
        printf("kernel,samples,cycles\n");
    }
    for (int kk = 0; kk < nk; kk++) {
        for (int b = 0; b < nbins; b++) {
            size_t m = 0;
            for (long t = 0; t < n; t++)
                if (bin_of(count[t]) == b) tmp[m++] = (uint32_t)count[t];
            if (m < 20) continue;
            uint32_t med_count = median_u32(tmp, m);
            m = 0;
            for (long t = 0; t < n; t++)
                if (bin_of(count[t]) == b) tmp[m++] = cyc[(size_t)t * nk + kk];
            uint32_t med = median_u32(tmp, m);
            if (csv) printf("%s,%u,%u\n", kernels[kk].name, med_count, med);
        }
    }
    if (csv) return 0;
    for (int b = 0; b < nbins; b++) {
        size_t m = 0;
        for (long t = 0; t < n; t++)
            if (bin_of(count[t]) == b) tmp[m++] = (uint32_t)count[t];
        if (m < 20) continue;
        size_t tris_in_bin = m;
        uint32_t med_count = median_u32(tmp, m);
        printf("%-12u %8zu", med_count, tris_in_bin);
        for (int kk = 0; kk < nk; kk++) {
            m = 0;
            for (long t = 0; t < n; t++)
                if (bin_of(count[t]) == b) tmp[m++] = cyc[(size_t)t * nk + kk];
            printf(" %14u", median_u32(tmp, m));
        }
        printf("\n");
    }

    /* Targets: ~400 samples (380..420) and 1-sample triangles. */
    uint32_t at400[8], at1[8];
    size_t m400 = 0, m1 = 0;
    for (int kk = 0; kk < nk; kk++) {
        size_t m = 0;
        for (long t = 0; t < n; t++)
            if (count[t] >= 380 && count[t] <= 420) tmp[m++] = cyc[(size_t)t * nk + kk];
        m400 = m;
        at400[kk] = median_u32(tmp, m);
        m = 0;
        for (long t = 0; t < n; t++)
            if (count[t] == 1) tmp[m++] = cyc[(size_t)t * nk + kk];
        m1 = m;
        at1[kk] = median_u32(tmp, m);
    }
    printf("\n~400 samples (380..420, %zu triangles):", m400);
    for (int kk = 0; kk < nk; kk++) printf("%s %s %u", kk ? "," : "", kernels[kk].name, at400[kk]);
    printf(" cycles\n  hierarchical / scanline = %.1fx (paper 17x), hierarchical / scanline_simd = %.1fx",
           (double)at400[2] / at400[0], (double)at400[2] / at400[3]);
    if (i_avx2 >= 0)
        printf(", hierarchical / scanline_avx2 = %.1fx, scanline / scanline_avx2 = %.1fx", (double)at400[2] / at400[i_avx2],
               (double)at400[0] / at400[i_avx2]);
    printf("\n1-sample triangles (%zu):", m1);
    for (int kk = 0; kk < nk; kk++) printf("%s %s %u", kk ? "," : "", kernels[kk].name, at1[kk]);
    printf(" cycles\n  scanline / bounds = %.2fx (paper 1.36x), scanline_simd / bounds = %.2fx", (double)at1[0] / at1[1],
           (double)at1[3] / at1[1]);
    if (i_avx2 >= 0)
        printf(", scanline_avx2 / bounds = %.2fx, scanline / scanline_avx2 = %.2fx", (double)at1[i_avx2] / at1[1],
               (double)at1[0] / at1[i_avx2]);
    printf("\n");

    /* Cost model cycles = setup + per_row * rows for the scalar Scanline kernel, fitted by least squares
     * on the median cycles of each iterated-row count (weighted by the number of triangles). The same
     * fit for the SIMD variants, whose cost grows per group of 16 (AVX-512) or 8 (AVX2) rows instead. */
    for (int kk = 0; kk < nk; kk++) {
        if (kk == 1 || kk == 2) continue; /* Bounds and Hierarchical do not iterate scanlines */
        double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
        for (int r = 1; r <= k; r++) {
            size_t m = 0;
            for (long t = 0; t < n; t++)
                if (rows[t] == r) tmp[m++] = cyc[(size_t)t * nk + kk];
            if (m < 20) continue;
            double y = median_u32(tmp, m), w = (double)m;
            sw += w; sx += w * r; sy += w * y; sxx += w * r * r; sxy += w * r * y;
        }
        double slope = (sw * sxy - sx * sy) / (sw * sxx - sx * sx), icpt = (sy - slope * sx) / sw;
        printf("%s fit: setup %.1f cycles + %.2f cycles per iterated scanline (paper: 193 + 17.2)\n",
               kernels[kk].name, icpt, slope);
    }
    free(tris); free(count); free(rows); free(cyc); free(order); free(tmp);
    return 0;
}
