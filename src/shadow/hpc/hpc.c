/* The choice of the penumbra casting engine's instance (hpc_impl.h) under the context's ISA cap. */
#include "hpc.h"

#ifdef MS_TEST_HOOKS
int ms_hpc_switches;
#endif

ms_hpc_cast_fn ms_hpc_cast_isa(ms_isa isa)
{
    static const ms_hpc_cast_fn table[] = {
        [MS_ISA_SCALAR] = ms_hpc_cast_scalar,
        [MS_ISA_AVX2] = ms_hpc_cast_avx2,
        [MS_ISA_AVX512] = ms_hpc_cast_avx512,
    };
    if (isa < MS_ISA_SCALAR || isa > MS_ISA_AVX512 || ms_cpu_isa() < isa) return NULL;
    return table[isa];
}

ms_hpc_cast_fn ms_hpc_cast_select(ms_isa cap, ms_isa *chosen)
{
    const ms_isa isa = ms_isa_select(cap, MS_ISA_ALL);
    const ms_hpc_cast_fn fn = isa == MS_ISA_AUTO ? NULL : ms_hpc_cast_isa(isa);
    if (fn && chosen) *chosen = isa;
    return fn;
}

int ms_hpc_cast(const ms_render_ctx *ctx, int scanline, ms_raster_fn raster, const ms_shadow_query *q, size_t n,
                const uint64_t *front, uint64_t *vis, const hpc_source *src, uint64_t *counters)
{
    const ms_hpc_cast_fn fn = ms_hpc_cast_select(ctx->isa_cap, NULL);
    return fn ? fn(ctx, scanline, raster, q, n, front, vis, src, counters) : -1;
}
