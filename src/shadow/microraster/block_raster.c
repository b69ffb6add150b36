/* The run-time choice among the block traversal's instances, under an explicit ISA cap. */
#include "block_raster.h"

ms_block_raster_fn ms_block_raster_isa(int k, ms_isa isa)
{
    static const ms_block_raster_fn table[][3] = {
        [MS_ISA_SCALAR] = MS_PERK_TABLE(ms_block_raster, scalar),
        [MS_ISA_AVX2] = MS_PERK_TABLE(ms_block_raster, avx2),
        [MS_ISA_AVX512] = MS_PERK_TABLE(ms_block_raster, avx512),
    };
    const int w = ms_k_index(k);
    if (w < 0 || isa < MS_ISA_SCALAR || isa > MS_ISA_AVX512 || ms_cpu_isa() < isa) return NULL;
    return table[isa][w];
}

ms_block_raster_fn ms_block_raster_select(int k, ms_isa cap, ms_isa *chosen)
{
    const ms_isa isa = ms_isa_select(cap, MS_ISA_ALL);
    const ms_block_raster_fn fn = ms_block_raster_isa(k, isa);
    if (fn && chosen) *chosen = isa;
    return fn;
}
