/* Portable instances of the frustum traversal, and the run-time choice among the instances. */
#include "frustum_traverse.h"
#include <stdlib.h>

#define TRAV_K 16
#define TRAV_ROW_T uint16_t
#define TRAV_FN ms_frustum_trace_k16_scalar
#include "frustum_traverse_impl.h"
#define TRAV_K 32
#define TRAV_ROW_T uint32_t
#define TRAV_FN ms_frustum_trace_k32_scalar
#include "frustum_traverse_impl.h"
#define TRAV_K 64
#define TRAV_ROW_T uint64_t
#define TRAV_FN ms_frustum_trace_k64_scalar
#include "frustum_traverse_impl.h"

void ms_frustum_trace_k16_avx2(const ms_bvh *, const ms_raster_frame *, ms_raster_fn, uint32_t, void *, uint64_t *, int);
void ms_frustum_trace_k32_avx2(const ms_bvh *, const ms_raster_frame *, ms_raster_fn, uint32_t, void *, uint64_t *, int);
void ms_frustum_trace_k64_avx2(const ms_bvh *, const ms_raster_frame *, ms_raster_fn, uint32_t, void *, uint64_t *, int);

static int use_avx2(int scalar_only)
{
    if (scalar_only) return 0;
    const char *e = getenv("MS_FORCE_SCALAR");
    if (e && e[0] == '1') return 0;
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}

const char *ms_frustum_trace_isa(int scalar_only) { return use_avx2(scalar_only) ? "avx2" : "scalar"; }

ms_frustum_trace_fn ms_frustum_trace_select(int k, int scalar_only)
{
    int v = use_avx2(scalar_only);
    switch (k) {
    case 16: return v ? ms_frustum_trace_k16_avx2 : ms_frustum_trace_k16_scalar;
    case 32: return v ? ms_frustum_trace_k32_avx2 : ms_frustum_trace_k32_scalar;
    case 64: return v ? ms_frustum_trace_k64_avx2 : ms_frustum_trace_k64_scalar;
    default: return NULL;
    }
}
