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
    BG_ERR_FORMAT = 6            /**< file contents are malformed (tools only) */
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

/** Highest ISA level this CPU and build support. Thread-safe. */
BG_API bg_isa bg_isa_best(void);

/** ISA level the batch calls currently use. The first call reads the
 *  BUMPGRAD_ISA environment variable (see bg_isa_force). Thread-safe. */
BG_API bg_isa bg_isa_active(void);

/** Force the batch kernels down to `isa` (for tests and users, as dav1d's cpu
 *  mask). Returns BG_ERR_UNSUPPORTED_ISA if `isa` is above bg_isa_best().
 *  Not thread-safe against concurrent batch calls: call it before starting work. */
BG_API bg_status bg_isa_force(bg_isa isa);

#ifdef __cplusplus
}
#endif

#endif /* BUMPGRAD_COMMON_H */
