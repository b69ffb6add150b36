/* The one CPU probe, and the compile-time rules of the ISA layer.
 *
 * Every source is portable (compiled with no instruction-set flags) unless its name ends in _avx2.c or
 * _avx512.c: CMake compiles those with exactly the flags ms_cpu_isa() checks for (CMakeLists.txt) and
 * defines MS_TARGET_AVX2 or MS_TARGET_AVX512 on them. ISA-specific code is selected by these macros,
 * never by __AVX2__ & co., which a global -march=native would define on the portable files too: the
 * "scalar" path would then run AVX2 code and the portable build would not be what the tests exercise. */
#ifndef MS_CPU_H
#define MS_CPU_H
#include "microshadow.h"

#if defined(MS_TARGET_AVX2) && defined(MS_TARGET_AVX512)
#error "a source targets one ISA"
#elif defined(MS_TARGET_AVX512)
#if !(defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512VL__) && defined(__AVX512DQ__) && \
      defined(__AVX2__) && defined(__FMA__) && defined(__BMI2__) && defined(__LZCNT__))
#error "an _avx512.c file must be compiled with the AVX-512 flags of CMakeLists.txt"
#endif
#elif defined(MS_TARGET_AVX2)
#if !(defined(__AVX2__) && defined(__FMA__) && defined(__BMI__) && defined(__BMI2__) && defined(__LZCNT__))
#error "an _avx2.c file must be compiled with the AVX2 flags of CMakeLists.txt"
#endif
#if defined(__AVX512F__)
#error "an _avx2.c file must not be compiled for AVX-512 (the CPU probe would not have checked it)"
#endif
#elif defined(__AVX__) || defined(__AVX2__) || defined(__FMA__) || defined(__AVX512F__) || defined(__BMI__) || \
    defined(__BMI2__) || defined(__LZCNT__)
#error "portable source compiled with instruction-set flags (-march=native?): only *_avx2.c / *_avx512.c may be"
#endif

/* The best ISA level this CPU and OS run (see cpu.c for the flags checked); MS_ISA_SCALAR off x86. */
ms_isa ms_cpu_isa(void);
/* The level to run under a cap: the CPU's best, or the cap when it is lower (MS_ISA_AUTO: no cap). */
ms_isa ms_isa_capped(ms_isa cap);

/* The one ISA selector every dispatcher uses (kernels, traversals, packet tracers, weights). A family has
 * instances at the levels of `have` (bit 1 << level; MS_ISA_ALL: every level, as every family has today).
 * The level run is the capped one (ms_isa_capped: the caller's cap, the CPU probe); the documented
 * fallback when the family has no instance there is downward, to the next lower level that has one,
 * never above the cap or the probe. MS_ISA_AUTO when no level at or below has one: the dispatcher then
 * returns NULL and leaves its *chosen untouched. */
#define MS_ISA_ALL ((1u << MS_ISA_SCALAR) | (1u << MS_ISA_AVX2) | (1u << MS_ISA_AVX512))
static inline ms_isa ms_isa_select(ms_isa cap, unsigned have)
{
    /* Inline: the S weights and the mask popcount select per receiver. */
    for (ms_isa isa = ms_isa_capped(cap); isa >= MS_ISA_SCALAR; isa = (ms_isa)(isa - 1))
        if (have >> isa & 1u) return isa;
    return MS_ISA_AUTO;
}

#endif
