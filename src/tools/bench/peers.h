/* SPDX-License-Identifier: MIT */
/* Between peers.c and the peer wrappers, each built only if its library was
 * found at configure time (bench/meson.build defines BGT_HAVE_PEER_STB and
 * BGT_HAVE_PEER_CXX); the C++ one sits behind extern "C". */
#ifndef BUMPGRAD_TOOLS_BENCH_PEERS_H
#define BUMPGRAD_TOOLS_BENCH_PEERS_H

#include <stddef.h>
#include "bench/bench.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Each returns the number of entries written to `out` (at most `cap`). */
size_t bench_peers_stb(bgt_bench_peer *out, size_t cap); /* peer_stb.c */
size_t bench_peers_cxx(bgt_bench_peer *out, size_t cap); /* peers_cxx.cc */

#ifdef __cplusplus
}
#endif

#endif
