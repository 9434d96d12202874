/* SPDX-License-Identifier: MIT */
/**
 * @file common.h
 * @brief Shared types of bumpgrad: vectors, status codes, visibility, version, ISA control.
 */
#ifndef BUMPGRAD_COMMON_H
#define BUMPGRAD_COMMON_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(BG_BUILDING_LIBRARY) && (defined(__GNUC__) || defined(__clang__))
#define BG_API __attribute__((visibility("default")))
#else
#define BG_API
#endif

#define BG_VERSION_MAJOR 0
#define BG_VERSION_MINOR 1
#define BG_VERSION_PATCH 0

/** A 3-vector of floats (plain value type, no alignment requirement). */
typedef struct bg_vec3 {
    float x, y, z;
} bg_vec3;

/** A 3-vector of doubles, for the double-precision entry points. */
typedef struct bg_dvec3 {
    double x, y, z;
} bg_dvec3;

/** Result of every fallible call. BG_OK is zero. */
typedef enum bg_status {
    BG_OK = 0,
    BG_ERR_INVALID_ARGUMENT = 1, /**< a parameter is out of its documented range */
    BG_ERR_NULL_POINTER = 2,     /**< a required pointer was NULL */
    BG_ERR_UNSUPPORTED_ISA = 3,  /**< the requested ISA is above what this CPU has */
    BG_ERR_OUT_OF_MEMORY = 4,
    BG_ERR_IO = 5,               /**< file could not be read or written (tools only) */
    BG_ERR_FORMAT = 6,           /**< file contents are malformed (tools only) */
    BG_ERR_OVERFLOW = 7          /**< parameters whose octave scaling overflows float
                                      (bg_fractal_validate, bg_height_validate) */
} bg_status;

/** Human-readable text for a status code; never NULL, static storage. */
BG_API const char *bg_status_string(bg_status s);

/** Library version as "MAJOR.MINOR.PATCH"; static storage. */
BG_API const char *bg_version_string(void);

/** Instruction-set levels of the kernels, lowest first. */
typedef enum bg_isa {
    BG_ISA_SCALAR = 0,
    BG_ISA_SSE2 = 1,
    BG_ISA_AVX2 = 2,
    BG_ISA_AVX512 = 3,
    BG_ISA_NEON = 4,
    BG_ISA_COUNT = 5
} bg_isa;

/** Name of an ISA level ("scalar", "sse2", "avx2", "avx512", "neon"). */
BG_API const char *bg_isa_name(bg_isa isa);

/** Parse an ISA name; returns BG_ERR_INVALID_ARGUMENT for an unknown name. */
BG_API bg_status bg_isa_parse(const char *name, bg_isa *out);

/** Highest ISA level this CPU and build support. Thread-safe, including the
 *  first call (CPU detection is lazy and atomic). */
BG_API bg_isa bg_isa_best(void);

/** 1 if the batch calls can run at `isa` here, else 0: it is built into this
 *  library and this CPU and OS can run it. This is the one rule the library
 *  applies (bg_isa_force, BUMPGRAD_ISA): scalar always; on x86 every level of
 *  the chain sse2 < avx2 < avx512 up to bg_isa_best(); on AArch64 neon. A value
 *  outside the enum gives 0. Thread-safe. */
BG_API int bg_isa_supported(bg_isa isa);

/** ISA level the batch calls currently use. The first call (of this or of any
 *  batch call) reads the BUMPGRAD_ISA environment variable: a supported level
 *  name selects that level, anything else (unknown name, unsupported level) is
 *  ignored there and the best level is used; bg_isa_env_status() reports it.
 *  Thread-safe, including concurrent first calls; a bg_isa_force() that
 *  happened before is never overridden by the lazy initialisation. */
BG_API bg_isa bg_isa_active(void);

/** Force the batch kernels down to `isa` (for tests and users, as dav1d's cpu
 *  mask). Returns BG_ERR_INVALID_ARGUMENT for a value outside the enum and
 *  BG_ERR_UNSUPPORTED_ISA if bg_isa_supported(isa) is 0 (nothing changes then).
 *  Not thread-safe against concurrent batch calls: call it before starting work. */
BG_API bg_status bg_isa_force(bg_isa isa);

/** Check the BUMPGRAD_ISA environment variable as it is now (the library reads
 *  it once, at the first bg_isa_active() or batch call, and silently ignores a
 *  bad value; this is how a program reports one). The library never prints: a
 *  message goes to `msg`.
 *  @return BG_OK if the variable is unset, empty or names a supported level
 *          (`msg` is then ""); BG_ERR_INVALID_ARGUMENT for an unknown name, with
 *          `msg` = `BUMPGRAD_ISA: unknown ISA level "NAME" (this CPU has: LIST)`;
 *          BG_ERR_UNSUPPORTED_ISA for a level bg_isa_supported() refuses, with
 *          `msg` = `BUMPGRAD_ISA: ISA level "NAME" is not available here (this CPU
 *          has: LIST)`. LIST is the supported names, lowest first, ", "-separated.
 *  @param msg receives a NUL-terminated message, truncated to `msglen` bytes;
 *         may be NULL when `msglen` is 0.
 *  Thread-safe as long as no thread changes the environment meanwhile. */
BG_API bg_status bg_isa_env_status(char *msg, size_t msglen);

#ifdef __cplusplus
}
#endif

#endif /* BUMPGRAD_COMMON_H */
