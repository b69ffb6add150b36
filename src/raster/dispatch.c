/* Kernel tables and the run-time choice of the SIMD variant. */
#include <stddef.h>
#include "raster_internal.h"

static ms_raster_fn scalar_fn(ms_kernel_id id, int k)
{
    static const ms_raster_fn table[MS_KERNEL_COUNT][3] = {
        [MS_KERNEL_SCANLINE] = { ms_scanline_16, ms_scanline_32, ms_scanline_64 },
        [MS_KERNEL_BOUNDS] = { ms_bounds_16, ms_bounds_32, ms_bounds_64 },
        [MS_KERNEL_HIERARCHICAL] = { ms_hier_16, ms_hier_32, ms_hier_64 },
    };
    const int w = k == 16 ? 0 : k == 32 ? 1 : k == 64 ? 2 : -1;
    if (w < 0 || (int)id < 0 || id >= MS_KERNEL_COUNT) return NULL;
    return table[id][w];
}

ms_raster_fn ms_raster_kernel_scalar(ms_kernel_id id, int k) { return scalar_fn(id, k); }

#if defined(__x86_64__) || defined(__i386__)
static int have_avx512(void)
{
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
           __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq");
}
#else
static int have_avx512(void) { return 0; }
#endif

ms_raster_fn ms_raster_kernel(ms_kernel_id id, int k)
{
    /* Only Scanline has a SIMD variant: it is the kernel the renderer uses; Bounds and Hierarchical are
     * the paper's baselines and stay scalar so that the comparison is like for like. */
    if (id == MS_KERNEL_SCANLINE && have_avx512()) {
        switch (k) {
        case 16: return ms_scanline_16_avx512;
        case 32: return ms_scanline_32_avx512;
        case 64: return ms_scanline_64_avx512;
        default: return NULL;
        }
    }
    return scalar_fn(id, k);
}

const char *ms_raster_isa(void) { return have_avx512() ? "avx512" : "scalar"; }
