/* SPDX-License-Identifier: MIT */
#ifndef BUMPGRAD_CPU_H
#define BUMPGRAD_CPU_H
#include "bumpgrad/common.h"
/* 1 if the CPU (and the OS, for the register state) supports every feature the
 * kernels of `isa` are compiled with. Detected once, thread-safe. */
int bg_cpu_has(bg_isa isa);
/* 1 if the AVX-512 level is usable and the CPU also has AVX512_VBMI (vpermi2b),
 * which the avx512vbmi variant of the AVX-512 kernels needs. */
int bg_cpu_has_avx512vbmi(void);
#endif
