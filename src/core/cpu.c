/* The one CPU probe (cpu.h). cpuid and xgetbv directly rather than __builtin_cpu_supports: clang 14 does
 * not know "lzcnt" there, and neither builtin checks that the OS saves the AVX / AVX-512 registers. */
#include "cpu.h"
#include <string.h>
#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>

/* XCR0 (the register state the OS saves), read with the instruction itself: _xgetbv would need -mxsave
 * on this portable file. Call only when CPUID.1:ECX.OSXSAVE is set. */
static unsigned long long xcr0(void)
{
    unsigned lo, hi;
    __asm__ volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(0));
    return (unsigned long long)hi << 32 | lo;
}

static ms_isa probe(void)
{
    unsigned a, b, c, d;
    if (__get_cpuid_max(0, NULL) < 7 || !__get_cpuid(1, &a, &b, &c, &d)) return MS_ISA_SCALAR;
    const unsigned c1 = c;
    /* leaf 1 ECX: SSE3 0, SSSE3 9, FMA 12, SSE4.1 19, SSE4.2 20, POPCNT 23, OSXSAVE 27, AVX 28 (-mavx2
     * implies the SSE levels, so they are checked too) */
    const unsigned need1 = 1u << 0 | 1u << 9 | 1u << 12 | 1u << 19 | 1u << 20 | 1u << 23 | 1u << 27 | 1u << 28;
    if ((c1 & need1) != need1) return MS_ISA_SCALAR;
    /* XCR0: SSE (bit 1) and AVX (bit 2) state; opmask, ZMM0-15 upper halves, ZMM16-31 (bits 5-7) */
    const unsigned long long x = xcr0();
    if ((x & 0x6) != 0x6) return MS_ISA_SCALAR;
    __cpuid_count(7, 0, a, b, c, d);
    const unsigned b7 = b;
    /* leaf 7 EBX: BMI1 3, AVX2 5, BMI2 8 */
    const unsigned need7 = 1u << 3 | 1u << 5 | 1u << 8;
    if ((b7 & need7) != need7) return MS_ISA_SCALAR;
    /* leaf 0x80000001 ECX bit 5: LZCNT (ABM) */
    if (!__get_cpuid(0x80000001u, &a, &b, &c, &d) || !(c & 1u << 5)) return MS_ISA_SCALAR;
    /* leaf 7 EBX: AVX512F 16, AVX512DQ 17, AVX512BW 30, AVX512VL 31 */
    const unsigned need512 = 1u << 16 | 1u << 17 | 1u << 30 | 1u << 31;
    if ((b7 & need512) == need512 && (x & 0xE0) == 0xE0) return MS_ISA_AVX512;
    return MS_ISA_AVX2;
}
#else
static ms_isa probe(void) { return MS_ISA_SCALAR; }
#endif

/* Probed once: cpuid traps to the hypervisor in a VM, and the per-sample tracer's fallback asks per pixel.
 * Racing first calls store the same value. */
ms_isa ms_cpu_isa(void)
{
    static int cached;   /* 0: not probed yet (MS_ISA_AUTO is never a probe's answer) */
    int c = __atomic_load_n(&cached, __ATOMIC_RELAXED);
    if (!c) {
        c = (int)probe();
        __atomic_store_n(&cached, c, __ATOMIC_RELAXED);
    }
    return (ms_isa)c;
}

ms_isa ms_isa_capped(ms_isa cap)
{
    const ms_isa best = ms_cpu_isa();
    return cap == MS_ISA_AUTO || cap > best ? best : cap;
}

const char *ms_isa_name(ms_isa isa)
{
    switch (isa) {
    case MS_ISA_AUTO: return "auto";
    case MS_ISA_SCALAR: return "scalar";
    case MS_ISA_AVX2: return "avx2";
    case MS_ISA_AVX512: return "avx512";
    default: return "unknown";
    }
}

ms_status ms_isa_from_name(const char *name, ms_isa *out)
{
    static const ms_isa all[] = { MS_ISA_AUTO, MS_ISA_SCALAR, MS_ISA_AVX2, MS_ISA_AVX512 };
    for (size_t i = 0; name && i < sizeof all / sizeof all[0]; i++)
        if (strcmp(name, ms_isa_name(all[i])) == 0) { *out = all[i]; return MS_OK; }
    return MS_ERR_INVALID;
}
