/* SPDX-License-Identifier: MIT */
/* Runtime dispatch: detect the CPU once (cpu.c), fill the table scalar first and
 * upgrade level by level, stopping at the first missing feature (dav1d's
 * pal.h); BUMPGRAD_ISA or bg_isa_force() caps the level. */
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "kernels.h"
#include "cpu.h"
#include "kernels/bg_config.h"

#if BG_HAVE_SSE2
extern const bg_kernel_table bg_kernels_sse2;
#endif
#if BG_HAVE_AVX2
extern const bg_kernel_table bg_kernels_avx2;
#endif
#if BG_HAVE_AVX512
extern const bg_kernel_table bg_kernels_avx512;
#endif
#if BG_HAVE_AVX512VBMI
extern const bg_kernel_table bg_kernels_avx512vbmi;
#endif
#if BG_HAVE_NEON
extern const bg_kernel_table bg_kernels_neon;
#endif

static const bg_kernel_table *table_of(bg_isa isa)
{
    switch (isa) {
    case BG_ISA_SCALAR: return &bg_kernels_c;
#if BG_HAVE_SSE2
    case BG_ISA_SSE2: return &bg_kernels_sse2;
#endif
#if BG_HAVE_AVX2
    case BG_ISA_AVX2: return &bg_kernels_avx2;
#endif
#if BG_HAVE_AVX512VBMI
    /* Same bits as plain AVX-512, about 2x faster (docs/KERNELS.md). */
    case BG_ISA_AVX512:
        if (bg_cpu_has_avx512vbmi())
            return &bg_kernels_avx512vbmi;
        return &bg_kernels_avx512;
#elif BG_HAVE_AVX512
    case BG_ISA_AVX512: return &bg_kernels_avx512;
#endif
#if BG_HAVE_NEON
    case BG_ISA_NEON: return &bg_kernels_neon;
#endif
    default: return NULL;
    }
}

static const char *const isa_names[BG_ISA_COUNT] = {"scalar", "sse2", "avx2", "avx512", "neon"};

const char *bg_isa_name(bg_isa isa)
{
    return (unsigned)isa < BG_ISA_COUNT ? isa_names[isa] : "unknown";
}

bg_status bg_isa_parse(const char *name, bg_isa *out)
{
    if (!name || !out)
        return BG_ERR_NULL_POINTER;
    for (int i = 0; i < BG_ISA_COUNT; i++)
        if (strcmp(name, isa_names[i]) == 0) {
            *out = (bg_isa)i;
            return BG_OK;
        }
    if (strcmp(name, "c") == 0) {
        *out = BG_ISA_SCALAR;
        return BG_OK;
    }
    return BG_ERR_INVALID_ARGUMENT;
}

/* The ISA levels form a chain on each architecture; "supported" means both built
 * into this library and usable on this CPU (cpu.c checks OS support via xgetbv). */
static int isa_supported(bg_isa isa)
{
    return table_of(isa) != NULL && bg_cpu_has(isa);
}

bg_isa bg_isa_best(void)
{
    static atomic_int best = -1;
    int b = atomic_load(&best);
    if (b < 0) {
        b = BG_ISA_SCALAR;
#if BG_HAVE_NEON
        if (isa_supported(BG_ISA_NEON))
            b = BG_ISA_NEON;
#else
        for (int i = BG_ISA_SSE2; i <= BG_ISA_AVX512 && isa_supported((bg_isa)i); i++)
            b = i;
#endif
        atomic_store(&best, b);
    }
    return (bg_isa)b;
}

/* The library's one rule (common.h): scalar, the best level, or below the best
 * on the same x86 chain (NEON is its own chain). bg_isa_best() walks the chain
 * up to the first level that is not built or not usable, so every level this
 * accepts has a kernel table and runs on this CPU. */
static int isa_at_or_below(bg_isa want, bg_isa best)
{
    if (want == BG_ISA_SCALAR || want == best)
        return 1;
    if (want == BG_ISA_NEON || best == BG_ISA_NEON)
        return 0;
    return want <= best;
}

int bg_isa_supported(bg_isa isa)
{
    return (unsigned)isa < BG_ISA_COUNT && isa_at_or_below(isa, bg_isa_best());
}

/* The active table is the one piece of state: bg_isa_active() is its level.
 * One atomic pointer, so that a per-point call (bg_noise3) pays one load and
 * one test for its dispatch, and a level and its table can never disagree. */
_Atomic(const bg_kernel_table *) bg_active_table;

static const bg_kernel_table *first_table(void)
{
    bg_isa want, a = bg_isa_best();
    /* An unknown or unsupported BUMPGRAD_ISA is ignored here (the library
     * never prints); bg_isa_env_status() reports it. */
    const char *env = getenv("BUMPGRAD_ISA");
    if (env && *env && bg_isa_parse(env, &want) == BG_OK && bg_isa_supported(want))
        a = want;
    /* Concurrent first calls compute the same table; a bg_isa_force() that
     * got in first wins (a plain store here could undo it). */
    const bg_kernel_table *t = table_of(a), *expected = NULL;
    if (!atomic_compare_exchange_strong(&bg_active_table, &expected, t))
        t = expected;
    return t;
}

const bg_kernel_table *bg_kernels(void)
{
    const bg_kernel_table *t = atomic_load_explicit(&bg_active_table, memory_order_acquire);
    return t ? t : first_table();
}

bg_isa bg_isa_active(void) { return bg_kernels()->isa; }

bg_status bg_isa_force(bg_isa isa)
{
    if ((unsigned)isa >= BG_ISA_COUNT)
        return BG_ERR_INVALID_ARGUMENT;
    if (!bg_isa_supported(isa))
        return BG_ERR_UNSUPPORTED_ISA;
    atomic_store(&bg_active_table, table_of(isa));
    return BG_OK;
}

void bg_isa_list(char *buf, size_t len, int supported_only)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < BG_ISA_COUNT; i++) {
        if (supported_only && !bg_isa_supported((bg_isa)i))
            continue;
        int w = snprintf(buf + used, len - used, "%s%s", used ? ", " : "", isa_names[i]);
        if (w < 0 || (size_t)w >= len - used)
            return;
        used += (size_t)w;
    }
}

bg_status bg_isa_env_status(char *msg, size_t msglen)
{
    if (msg && msglen)
        msg[0] = '\0';
    else
        msg = NULL;
    const char *env = getenv("BUMPGRAD_ISA");
    if (!env || !*env)
        return BG_OK;
    bg_isa isa;
    char have[64];
    bg_isa_list(have, sizeof have, 1);
    if (bg_isa_parse(env, &isa) != BG_OK) {
        if (msg)
            snprintf(msg, msglen, "BUMPGRAD_ISA: unknown ISA level \"%s\" (this CPU has: %s)", env,
                     have);
        return BG_ERR_INVALID_ARGUMENT;
    }
    if (!bg_isa_supported(isa)) {
        if (msg)
            snprintf(msg, msglen,
                     "BUMPGRAD_ISA: ISA level \"%s\" is not available here (this CPU has: %s)",
                     env, have);
        return BG_ERR_UNSUPPORTED_ISA;
    }
    return BG_OK;
}

const bg_kernel_table *bg_kernels_for(bg_isa isa)
{
    return isa_supported(isa) ? table_of(isa) : NULL;
}

int bg_kernels_variants(bg_isa isa, const bg_kernel_table **out, int max)
{
    int n = 0;
    if (!isa_supported(isa))
        return 0;
#if BG_HAVE_AVX512VBMI
    if (isa == BG_ISA_AVX512) {
        if (bg_cpu_has_avx512vbmi() && n < max)
            out[n++] = &bg_kernels_avx512vbmi;
        if (n < max)
            out[n++] = &bg_kernels_avx512;
        return n;
    }
#endif
    if (n < max)
        out[n++] = table_of(isa);
    return n;
}
