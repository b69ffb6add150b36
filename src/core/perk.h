/* The one idiom for instantiating code per buffer width k (16, 32, 64) and per ISA.
 *
 * A source defines MS_PERK_IMPL as the path of its *_impl.h from src/ (e.g. "raster/scanline_impl.h":
 * the include is resolved from core/, so a bare name would not be found; tests/check_layers.sh does not
 * see this computed include, and it is no dependency of core on the caller's folder but a call-back,
 * like a template's) and includes "core/perk_each.h", which
 * includes the impl once per k with MS_K (16, 32, 64) and MS_WORD (uint16_t, uint32_t, uint64_t, the
 * scanline word) defined. Inside, MS_KFN(base) names the instance base_<k>_<isa>, the ISA taken from the
 * file's MS_TARGET_* macro (cpu.h): ms_scanline_32_avx2, ms_frustum_trace_64_scalar, ... K-dependent
 * code is either preprocessed on MS_K or written for a constant k that the compiler propagates.
 * Dispatchers list the instances with MS_PERK_TABLE(base, isa) and index it with ms_k_index(k). */
#ifndef MS_PERK_H
#define MS_PERK_H
#include "cpu.h"

#define MS_CAT_(a, b) a##b
#define MS_CAT(a, b) MS_CAT_(a, b)

#if defined(MS_TARGET_AVX512)
#define MS_ISA_SUFFIX avx512
#elif defined(MS_TARGET_AVX2)
#define MS_ISA_SUFFIX avx2
#else
#define MS_ISA_SUFFIX scalar
#endif

#define MS_KFN(base) MS_CAT(MS_CAT(MS_CAT(base, _), MS_K), MS_CAT(_, MS_ISA_SUFFIX))
#define MS_PERK_TABLE(base, isa) { base##_16_##isa, base##_32_##isa, base##_64_##isa }
/* Declares the three instances of base for isa; params in parentheses. */
#define MS_PERK_DECLARE(ret, base, isa, params) ret base##_16_##isa params; ret base##_32_##isa params; ret base##_64_##isa params

/* 0, 1, 2 for k = 16, 32, 64; -1 otherwise. */
static inline int ms_k_index(int k) { return k == 16 ? 0 : k == 32 ? 1 : k == 64 ? 2 : -1; }

#endif
