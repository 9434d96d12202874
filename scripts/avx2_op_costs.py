#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Cost on this CPU of the AVX2 instructions the noise kernels use: the
reciprocal throughput of each (12 independent chains), of pairs (do two kinds
share execution pipes?), and the latency of a few (one dependent chain), in
core cycles. The clock is calibrated by a chain of vpaddb (1 cycle latency on
every x86 core with AVX2), so TSC ticks convert to cycles without knowing the
frequency. Builds a small C program with `cc` in a temporary directory.

  taskset -c 1 scripts/avx2_op_costs.py

CHANGELOG.md ("AVX2 against FastNoise2: what binds") reads its output.
"""
import os
import subprocess
import sys
import tempfile

R = 'ymm%d'
# Throughput tests: each operand template writes and reads {r}.
SINGLE = {
    'vpaddb': 'vpaddb %%ymm14, {r}, {r}',
    'vpand': 'vpand %%ymm14, {r}, {r}',
    'vpshufb': 'vpshufb %%ymm14, {r}, {r}',
    'vpermps': 'vpermps {r}, %%ymm14, {r}',
    'vpslld': 'vpslld $1, {r}, {r}',
    'vpblendvb': 'vpblendvb %%ymm15, %%ymm14, {r}, {r}',
    'vblendvps': 'vblendvps %%ymm15, %%ymm14, {r}, {r}',
    'vmulps': 'vmulps %%ymm14, {r}, {r}',
    'vaddps': 'vaddps %%ymm14, {r}, {r}',
}
PAIRS = [('vpshufb', 'vpblendvb'), ('vpshufb', 'vpslld'), ('vpshufb', 'vpermps'),
         ('vpshufb', 'vmulps'), ('vpshufb', 'vaddps'), ('vpblendvb', 'vblendvps'),
         ('vpblendvb', 'vmulps'), ('vblendvps', 'vmulps'), ('vmulps', 'vaddps')]
LAT = {
    'vpaddb': 'vpaddb %%ymm14, %%ymm0, %%ymm0',
    'vpshufb': 'vpshufb %%ymm14, %%ymm0, %%ymm0',
    'vpblendvb': 'vpblendvb %%ymm15, %%ymm14, %%ymm0, %%ymm0',
    'vpermps': 'vpermps %%ymm0, %%ymm14, %%ymm0',
    'vmulps': 'vmulps %%ymm14, %%ymm0, %%ymm0',
    # the gather's index is its own previous result masked to 0 by vpand
    # (1 cycle, subtracted below)
    'vpgatherdd': 'vpcmpeqd %%ymm13, %%ymm13, %%ymm13\\n\\tvpgatherdd %%ymm13, (%%rsi,%%ymm0,4), %%ymm1'
                  '\\n\\tvpand %%ymm15, %%ymm1, %%ymm0',
}


def tput_body(ops):
    body = []
    for rep in range(4):
        for k in range(12):
            body.append(ops[(rep * 12 + k) % len(ops)].replace('{r}', '%%' + R % k))
    return body


def main():
    tests = []  # (kind, name, asm lines, ops per iteration)
    for n, op in SINGLE.items():
        tests.append(('tput', n, tput_body([op]), 48))
    for a, b in PAIRS:
        tests.append(('tput', a + '+' + b, tput_body([SINGLE[a], SINGLE[b]]), 48))
    tests.append(('tput', 'vpgatherdd', ['vpcmpeqd %%ymm13, %%ymm13, %%ymm13\\n\\t'
                                         'vpgatherdd %%ymm13, (%%rsi,%%ymm12,4), %%' + R % k
                                         for k in range(12)], 12))
    for n, op in LAT.items():
        # vpand with zero keeps the chain across iterations (no zero idiom)
        # and the gather's index at 0: 16 ops and one 1-cycle vpand a round
        tests.append(('lat', n, ['vpand %%ymm15, %%ymm0, %%ymm0'] + [op] * 16, 1))
    src = ['#include <stdio.h>', '#include <stdint.h>', '#include <x86intrin.h>',
           'static int tab[256];']
    clob = ','.join('"xmm%d"' % k for k in range(16))
    for i, (_, _, body, n) in enumerate(tests):
        src.append('static double t%d(long it) { uint64_t a = __rdtsc(); for (long j = 0; j < it; j++) '
                   '__asm__ volatile("%s" :: "S"(tab) : "memory", %s); '
                   'return (double)(__rdtsc() - a) / ((double)it * %d); }'
                   % (i, '\\n\\t'.join(body), clob, n))
    src.append('static double best(double (*f)(long)) { double b = 1e30; for (int r = 0; r < 9; r++) '
               '{ double t = f(100000); if (t < b) b = t; } return b; }')
    src.append('int main(void) {')
    src.append('__asm__ volatile("vpxor %%ymm12,%%ymm12,%%ymm12\\n\\tvpxor %%ymm14,%%ymm14,%%ymm14\\n\\t'
               'vpxor %%ymm15,%%ymm15,%%ymm15" ::: "xmm12","xmm14","xmm15");')
    cal = [i for i, t in enumerate(tests) if t[0] == 'lat' and t[1] == 'vpaddb'][0]
    src.append('double cyc = best(t%d) / 17;' % cal)
    src.append('printf("TSC ticks per core cycle (vpaddb chain): %.3f\\n", cyc);')
    for i, (kind, name, _, _) in enumerate(tests):
        if kind == 'tput':
            src.append('printf("throughput %%-22s %%.2f cycles/op\\n", "%s", best(t%d) / cyc);' % (name, i))
        else:
            adj = ' - 1' if name == 'vpgatherdd' else ''
            src.append('printf("latency    %%-22s %%.2f cycles\\n", "%s", (best(t%d) / cyc - 1) / 16%s);'
                       % (name, i, adj))
    src.append('return 0; }')
    with tempfile.TemporaryDirectory() as d:
        c, exe = os.path.join(d, 'ops.c'), os.path.join(d, 'ops')
        with open(c, 'w') as f:
            f.write('\n'.join(src) + '\n')
        subprocess.run([os.environ.get('CC', 'cc'), '-O1', '-mavx2', c, '-o', exe], check=True)
        sys.exit(subprocess.run([exe]).returncode)


if __name__ == '__main__':
    main()
