#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Static size of a kernel's main loop: the largest backward-jump loop of a
function in `objdump -d` of its object (valgrind cannot count AVX-512, so this
is the instruction count used for the AVX-512 kernels in docs/KERNELS.md).

  scripts/kernel_loop_size.py build-simd/src/kernels/libbg_kernels_avx512vbmi.a.p/bump_tmpl.c.o \
      bg_noise3_avx512vbmi
  OBJDUMP=aarch64-linux-gnu-objdump scripts/kernel_loop_size.py <neon object> bg_noise3_neon
"""
import re
import subprocess
import sys


def main():
    obj, fn = sys.argv[1], sys.argv[2]
    out = subprocess.run([__import__('os').environ.get('OBJDUMP', 'objdump'), '-d', '--no-show-raw-insn', obj], capture_output=True,
                         text=True, check=True).stdout
    m = re.search(r'<%s>:\n(.*?)\n\n' % re.escape(fn), out, re.S)
    if not m:
        sys.exit('%s not found in %s' % (fn, obj))
    ins = []
    for line in m.group(1).splitlines():
        mm = re.match(r'\s*([0-9a-f]+):\s+(\S+)\s*(.*)', line)
        if mm:
            ins.append((int(mm.group(1), 16), mm.group(2), mm.group(3)))
    addrs = [a for a, _, _ in ins]
    best = []
    # x86 jumps (j*), AArch64 branches (b, b.<cond>, cbz/cbnz, tbz/tbnz).
    branch = re.compile(r'^(j\w+|b|b\.\w+|cbn?z|tbn?z)$')
    for i, (a, op, arg) in enumerate(ins):
        t = re.search(r'(?:^|[\s,])([0-9a-f]+) <', arg)
        if branch.match(op) and t:
            ta = int(t.group(1), 16)
            if ta <= a and ta in addrs:
                body = ins[addrs.index(ta):i + 1]
                if len(body) > len(best):
                    best = body
    ops = {}
    for _, op, _ in best:
        ops[op] = ops.get(op, 0) + 1
    print('%s: loop body %d instructions' % (fn, len(best)))
    print(' '.join('%s:%d' % kv for kv in sorted(ops.items(), key=lambda kv: -kv[1])[:20]))


if __name__ == '__main__':
    main()
