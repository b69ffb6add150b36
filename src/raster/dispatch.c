/* Kernel tables and the run-time choice of the SIMD variant. */
#include <stddef.h>
#include <string.h>
#include "raster_internal.h"

static int width_index(int k) { return k == 16 ? 0 : k == 32 ? 1 : k == 64 ? 2 : -1; }

static ms_raster_fn scalar_fn(ms_kernel_id id, int k)
{
    static const ms_raster_fn table[MS_KERNEL_COUNT][3] = {
        [MS_KERNEL_SCANLINE] = { ms_scanline_16, ms_scanline_32, ms_scanline_64 },
        [MS_KERNEL_BOUNDS] = { ms_bounds_16, ms_bounds_32, ms_bounds_64 },
        [MS_KERNEL_HIERARCHICAL] = { ms_hier_16, ms_hier_32, ms_hier_64 },
    };
    const int w = width_index(k);
    if (w < 0 || (int)id < 0 || id >= MS_KERNEL_COUNT) return NULL;
    return table[id][w];
}

ms_raster_fn ms_raster_kernel_scalar(ms_kernel_id id, int k) { return scalar_fn(id, k); }

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
/* LZCNT (CPUID 0x80000001 ECX bit 5, "ABM"): clang 14 does not know __builtin_cpu_supports("lzcnt"). */
static int have_lzcnt(void)
{
    unsigned a, b, c, d;
    return __get_cpuid(0x80000001u, &a, &b, &c, &d) && (c & (1u << 5));
}
static int have_avx512(void)
{
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
           __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq");
}
/* Everything the *_avx2.c files are compiled for (CMakeLists.txt), since the compiler may use any of it. */
static int have_avx2(void)
{
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
           __builtin_cpu_supports("bmi2") && __builtin_cpu_supports("popcnt") && have_lzcnt();
}
#else
static int have_avx512(void) { return 0; }
static int have_avx2(void) { return 0; }
#endif

ms_raster_fn ms_raster_kernel_isa(ms_kernel_id id, int k, const char *isa)
{
    const int w = width_index(k);
    if (isa == NULL || w < 0) return NULL;
    if (strcmp(isa, "scalar") == 0) return scalar_fn(id, k);
    /* Only Scanline has SIMD variants: it is the kernel the renderer uses; Bounds and Hierarchical are
     * the paper's baselines and stay scalar so that the comparison is like for like. */
    if (id != MS_KERNEL_SCANLINE) return NULL;
    static const ms_raster_fn avx512[3] = { ms_scanline_16_avx512, ms_scanline_32_avx512, ms_scanline_64_avx512 };
    static const ms_raster_fn avx2[3] = { ms_scanline_16_avx2, ms_scanline_32_avx2, ms_scanline_64_avx2 };
    if (strcmp(isa, "avx512") == 0) return have_avx512() ? avx512[w] : NULL;
    if (strcmp(isa, "avx2") == 0) return have_avx2() ? avx2[w] : NULL;
    return NULL;
}

const char *ms_raster_isa(void) { return have_avx512() ? "avx512" : have_avx2() ? "avx2" : "scalar"; }

ms_raster_fn ms_raster_kernel(ms_kernel_id id, int k)
{
    if (id == MS_KERNEL_SCANLINE) return ms_raster_kernel_isa(id, k, ms_raster_isa());
    return scalar_fn(id, k);
}
