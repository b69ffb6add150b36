/* AVX2 instances of the frustum traversal (compiled with -mavx2 -mfma, chosen at run time). */
#include "frustum_traverse.h"

#define TRAV_K 16
#define TRAV_ROW_T uint16_t
#define TRAV_FN ms_frustum_trace_k16_avx2
#include "frustum_traverse_impl.h"
#define TRAV_K 32
#define TRAV_ROW_T uint32_t
#define TRAV_FN ms_frustum_trace_k32_avx2
#include "frustum_traverse_impl.h"
#define TRAV_K 64
#define TRAV_ROW_T uint64_t
#define TRAV_FN ms_frustum_trace_k64_avx2
#include "frustum_traverse_impl.h"
