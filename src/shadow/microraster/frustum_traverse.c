/* The run-time choice among the frustum traversal's instances, under an explicit ISA cap. */
#include "frustum_traverse.h"

ms_frustum_trace_fn ms_frustum_trace_isa(int k, ms_isa isa)
{
    static const ms_frustum_trace_fn table[][3] = {
        [MS_ISA_SCALAR] = MS_PERK_TABLE(ms_frustum_trace, scalar),
        [MS_ISA_AVX2] = MS_PERK_TABLE(ms_frustum_trace, avx2),
        [MS_ISA_AVX512] = MS_PERK_TABLE(ms_frustum_trace, avx512),
    };
    const int w = ms_k_index(k);
    if (w < 0 || isa < MS_ISA_SCALAR || isa > MS_ISA_AVX512 || ms_cpu_isa() < isa) return NULL;
    return table[isa][w];
}

ms_frustum_trace_fn ms_frustum_trace_select(int k, ms_isa cap, ms_isa *chosen)
{
    /* Every level has an instance, so the capped level is the one. */
    const ms_isa isa = ms_isa_select(cap, MS_ISA_ALL);
    const ms_frustum_trace_fn fn = ms_frustum_trace_isa(k, isa);
    if (fn && chosen) *chosen = isa;
    return fn;
}
