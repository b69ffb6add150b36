/* Kernel tables and the run-time choice of the variant, under an explicit ISA cap (core/cpu.h). */
#include <stddef.h>
#include "raster_internal.h"

ms_raster_fn ms_raster_kernel_isa(ms_kernel_id id, int k, ms_isa isa)
{
    static const ms_raster_fn scalar[MS_KERNEL_COUNT][3] = {
        [MS_KERNEL_SCANLINE] = MS_PERK_TABLE(ms_scanline, scalar),
        [MS_KERNEL_BOUNDS] = MS_PERK_TABLE(ms_bounds, scalar),
        [MS_KERNEL_HIERARCHICAL] = MS_PERK_TABLE(ms_hier, scalar),
    };
    static const ms_raster_fn avx2[3] = MS_PERK_TABLE(ms_scanline, avx2);
    static const ms_raster_fn avx512[3] = MS_PERK_TABLE(ms_scanline, avx512);
    const int w = ms_k_index(k);
    if (w < 0 || (int)id < 0 || id >= MS_KERNEL_COUNT) return NULL;
    if (isa == MS_ISA_SCALAR) return scalar[id][w];
    /* Only Scanline has SIMD variants; a variant runs only where the probe grants its ISA. */
    if (id != MS_KERNEL_SCANLINE || (isa != MS_ISA_AVX2 && isa != MS_ISA_AVX512) || ms_cpu_isa() < isa) return NULL;
    return isa == MS_ISA_AVX512 ? avx512[w] : avx2[w];
}

ms_raster_fn ms_raster_kernel(ms_kernel_id id, int k, ms_isa cap, ms_isa *chosen)
{
    /* From the capped level down to scalar, the first variant the kernel has. */
    for (ms_isa isa = ms_isa_capped(cap); isa >= MS_ISA_SCALAR; isa = (ms_isa)(isa - 1)) {
        const ms_raster_fn fn = ms_raster_kernel_isa(id, k, isa);
        if (fn) {
            if (chosen) *chosen = isa;
            return fn;
        }
    }
    return NULL;
}
