/* SPDX-License-Identifier: MIT */
/* The peers built into this binary (bench.h: bgt_bench_peers_builtin). */
#include <string.h>

#include "bench/peers.h"

size_t bgt_bench_peers_builtin(bgt_bench_peer *out, size_t cap, const char **missing)
{
    size_t n = 0;
#if BGT_HAVE_PEER_STB
    n += bench_peers_stb(out + n, cap - n);
#endif
#if BGT_HAVE_PEER_CXX
    n += bench_peers_cxx(out + n, cap - n);
#endif
    static const char *const why[3] = {" stb_perlin (libstb-dev)", " libnoise (libnoise-dev, C++)",
                                       " glm (libglm-dev, C++)"};
    static char note[160];
    note[0] = '\0';
    for (size_t k = 0; k < 3; k++) {
        int have = 0;
        for (size_t i = 0; i < n; i++)
            have |= strcmp(out[i].library, bgt_bench_peer_libraries[k]) == 0;
        if (!have)
            strcat(note, why[k]);
    }
    if (missing)
        *missing = note[0] ? note : NULL;
    return n;
}
