/* Kernel tables and the run-time choice of the variant, under an explicit ISA cap (core/cpu.h). */
#include <stddef.h>
#include "raster_internal.h"

ms_raster_fn ms_raster_kernel_isa(ms_kernel_id id, int k, ms_isa isa)
{
    /* Scanline: the SIMD kernel (scanline_simd_impl.h) for AVX2 and AVX-512. Bounds and Hierarchical, the
     * paper's baselines: the same C compiled for each ISA (bit for bit the same buffers). */
    static const ms_raster_fn table[MS_ISA_AVX512 + 1][MS_KERNEL_COUNT][3] = {
        [MS_ISA_SCALAR] = { [MS_KERNEL_SCANLINE] = MS_PERK_TABLE(ms_scanline, scalar),
                            [MS_KERNEL_BOUNDS] = MS_PERK_TABLE(ms_bounds, scalar),
                            [MS_KERNEL_HIERARCHICAL] = MS_PERK_TABLE(ms_hier, scalar) },
        [MS_ISA_AVX2] = { [MS_KERNEL_SCANLINE] = MS_PERK_TABLE(ms_scanline, avx2),
                          [MS_KERNEL_BOUNDS] = MS_PERK_TABLE(ms_bounds, avx2),
                          [MS_KERNEL_HIERARCHICAL] = MS_PERK_TABLE(ms_hier, avx2) },
        [MS_ISA_AVX512] = { [MS_KERNEL_SCANLINE] = MS_PERK_TABLE(ms_scanline, avx512),
                            [MS_KERNEL_BOUNDS] = MS_PERK_TABLE(ms_bounds, avx512),
                            [MS_KERNEL_HIERARCHICAL] = MS_PERK_TABLE(ms_hier, avx512) },
    };
    const int w = ms_k_index(k);
    if (w < 0 || (int)id < 0 || id >= MS_KERNEL_COUNT || isa < MS_ISA_SCALAR || isa > MS_ISA_AVX512) return NULL;
    /* A variant runs only where the probe grants its ISA. */
    if (isa > MS_ISA_SCALAR && ms_cpu_isa() < isa) return NULL;
    return table[isa][id][w];
}

ms_raster_fn ms_raster_kernel(ms_kernel_id id, int k, ms_isa cap, ms_isa *chosen)
{
    unsigned have = 0;   /* the levels with a variant (today every kernel has all) */
    for (ms_isa isa = MS_ISA_SCALAR; isa <= MS_ISA_AVX512; isa = (ms_isa)(isa + 1))
        if (ms_raster_kernel_isa(id, k, isa)) have |= 1u << isa;
    const ms_isa isa = ms_isa_select(cap, have);
    if (isa == MS_ISA_AUTO) return NULL;
    if (chosen) *chosen = isa;
    return ms_raster_kernel_isa(id, k, isa);
}

ms_scan_rows_fn ms_raster_rows(ms_raster_fn kernel, int k, int edges)
{
    static const ms_raster_fn kernels[2][3] = { MS_PERK_TABLE(ms_scanline, avx2), MS_PERK_TABLE(ms_scanline, avx512) };
    static const ms_scan_rows_fn rows3[2][3] = { MS_PERK_TABLE(ms_scanline_rows3, avx2), MS_PERK_TABLE(ms_scanline_rows3, avx512) };
    static const ms_scan_rows_fn rows5[2][3] = { MS_PERK_TABLE(ms_scanline_rows5, avx2), MS_PERK_TABLE(ms_scanline_rows5, avx512) };
    const int w = ms_k_index(k);
    if (w < 0 || !kernel || (edges != 3 && edges != 5)) return NULL;
    for (int i = 0; i < 2; i++)
        if (kernel == kernels[i][w]) return edges == 3 ? rows3[i][w] : rows5[i][w];
    return NULL;
}
