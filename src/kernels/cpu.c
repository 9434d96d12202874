/* SPDX-License-Identifier: MIT */
/* CPU feature detection with cpuid + xgetbv, once (docs/DESIGN.md, rule 4). A level counts
 * only if the OS saves its register state (XCR0), not just if cpuid lists it. */
#include "cpu.h"

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#include <stdatomic.h>

/* Internal feature bits above the bg_isa levels. */
#define CPU_BIT_VBMI 16

static unsigned long long xgetbv0(void)
{
    unsigned eax, edx;
    __asm__ volatile("xgetbv" : "=a"(eax), "=d"(edx) : "c"(0));
    return ((unsigned long long)edx << 32) | eax;
}

static int detect(void)
{
    unsigned a, b, c, d;
    int mask = 1 << BG_ISA_SCALAR;
    if (!__get_cpuid(1, &a, &b, &c, &d))
        return mask;
    if (d & (1u << 26))
        mask |= 1 << BG_ISA_SSE2;
    int osxsave = (c & (1u << 27)) != 0, avx = (c & (1u << 28)) != 0;
    if (!osxsave || !avx)
        return mask;
    unsigned long long xcr0 = xgetbv0();
    if ((xcr0 & 0x6) != 0x6)
        return mask;
    unsigned a7, b7, c7, d7;
    if (!__get_cpuid_count(7, 0, &a7, &b7, &c7, &d7))
        return mask;
    if (b7 & (1u << 5))
        mask |= 1 << BG_ISA_AVX2;
    /* AVX-512 level: F, DQ, BW, VL; opmask and ZMM state enabled in XCR0. */
    unsigned need = (1u << 16) | (1u << 17) | (1u << 30) | (1u << 31);
    if ((mask & (1 << BG_ISA_AVX2)) && (b7 & need) == need && (xcr0 & 0xE6) == 0xE6) {
        mask |= 1 << BG_ISA_AVX512;
        if (c7 & (1u << 1)) /* AVX512_VBMI */
            mask |= 1 << CPU_BIT_VBMI;
    }
    return mask;
}

static int cpu_mask(void)
{
    static atomic_int cached = -1;
    int m = atomic_load(&cached);
    if (m < 0) {
        m = detect();
        atomic_store(&cached, m);
    }
    return m;
}

int bg_cpu_has(bg_isa isa)
{
    return (cpu_mask() >> isa) & 1;
}

int bg_cpu_has_avx512vbmi(void)
{
    return (cpu_mask() >> CPU_BIT_VBMI) & 1;
}

#elif defined(__aarch64__)
int bg_cpu_has(bg_isa isa)
{
    return isa == BG_ISA_SCALAR || isa == BG_ISA_NEON; /* NEON is mandatory on AArch64 */
}
int bg_cpu_has_avx512vbmi(void)
{
    return 0;
}
#else
int bg_cpu_has(bg_isa isa)
{
    return isa == BG_ISA_SCALAR;
}
int bg_cpu_has_avx512vbmi(void)
{
    return 0;
}
#endif
