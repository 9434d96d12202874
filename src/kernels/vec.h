/* SPDX-License-Identifier: MIT */
/* Selects the vector vocabulary for this compilation of a template (meson passes
 * -DBG_VEC_<ISA> together with that ISA's compiler flags). */
#if defined(BG_VEC_AVX512)
#include "vec_avx512.h"
#elif defined(BG_VEC_AVX2)
#include "vec_avx2.h"
#elif defined(BG_VEC_SSE2)
#include "vec_sse2.h"
#elif defined(BG_VEC_NEON)
#include "vec_neon.h"
#else
#include "vec_c.h"
#endif

#define BG_CAT2(a, b) a##b
#define BG_CAT(a, b) BG_CAT2(a, b)
/* Kernel names: bg_<kernel>_<isa>, scalar _c (docs/DESIGN.md, rule 5). */
#define KFN(name) BG_CAT(BG_CAT(bg_, name), BG_CAT(_, BG_ISA_SUFFIX))
/* The one-lane single-point functions this table calls (its noise3_point,
 * its batch tails): bg_<kernel>_c, or bg_<kernel>_c_avx2 where the build has
 * that compile and this ISA implies AVX2 (kernels.h). */
#if defined(BG_HAVE_C_AVX2) && (defined(BG_VEC_AVX2) || defined(BG_VEC_AVX512))
#define PFN(name) BG_CAT(BG_CAT(bg_, name), _c_avx2)
#else
#define PFN(name) BG_CAT(BG_CAT(bg_, name), _c)
#endif
