/* Portable instances of the frustum traversal, and the run-time choice among the instances. */
#include "frustum_traverse.h"
#include <stdlib.h>
#include <string.h>

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
void ms_frustum_trace_k16_avx512(const ms_bvh *, const ms_raster_frame *, ms_raster_fn, uint32_t, void *, uint64_t *, int);
void ms_frustum_trace_k32_avx512(const ms_bvh *, const ms_raster_frame *, ms_raster_fn, uint32_t, void *, uint64_t *, int);
void ms_frustum_trace_k64_avx512(const ms_bvh *, const ms_raster_frame *, ms_raster_fn, uint32_t, void *, uint64_t *, int);

enum { ISA_SCALAR, ISA_AVX2, ISA_AVX512 };

static int cpu_isa(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
        __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("fma"))
        return ISA_AVX512;
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return ISA_AVX2;
#endif
    return ISA_SCALAR;
}

/* The best ISA this CPU runs; MS_FORCE_SCALAR=1 forces scalar, MS_TRAVERSE_ISA=scalar|avx2|avx512 caps
 * it (to compare the instances in one process; a level the CPU lacks is never chosen). */
static int pick_isa(int scalar_only)
{
    if (scalar_only) return ISA_SCALAR;
    const char *e = getenv("MS_FORCE_SCALAR");
    if (e && e[0] == '1') return ISA_SCALAR;
    int isa = cpu_isa();
    const char *cap = getenv("MS_TRAVERSE_ISA");
    if (cap && strcmp(cap, "scalar") == 0) isa = ISA_SCALAR;
    else if (cap && strcmp(cap, "avx2") == 0 && isa > ISA_AVX2) isa = ISA_AVX2;
    return isa;
}

const char *ms_frustum_trace_isa(int scalar_only)
{
    static const char *const names[] = { "scalar", "avx2", "avx512" };
    return names[pick_isa(scalar_only)];
}

ms_frustum_trace_fn ms_frustum_trace_select(int k, int scalar_only)
{
    static const ms_frustum_trace_fn table[3][3] = {
        [ISA_SCALAR] = { ms_frustum_trace_k16_scalar, ms_frustum_trace_k32_scalar, ms_frustum_trace_k64_scalar },
        [ISA_AVX2] = { ms_frustum_trace_k16_avx2, ms_frustum_trace_k32_avx2, ms_frustum_trace_k64_avx2 },
        [ISA_AVX512] = { ms_frustum_trace_k16_avx512, ms_frustum_trace_k32_avx512, ms_frustum_trace_k64_avx512 },
    };
    const int w = k == 16 ? 0 : k == 32 ? 1 : k == 64 ? 2 : -1;
    return w < 0 ? NULL : table[pick_isa(scalar_only)][w];
}
