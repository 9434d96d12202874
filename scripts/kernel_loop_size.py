#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Static size of a kernel's main loop: the largest backward-jump loop of a
function in `objdump -d` of its object (valgrind cannot count AVX-512, so this
is the instruction count used for the AVX-512 kernels in docs/KERNELS.md).

  scripts/kernel_loop_size.py build-simd/src/kernels/libbg_kernels_avx512vbmi.a.p/bump_tmpl.c.o \
      bg_noise3_avx512vbmi
  OBJDUMP=aarch64-linux-gnu-objdump scripts/kernel_loop_size.py <neon object> bg_noise3_neon
  scripts/kernel_loop_size.py --all OBJ FN   every backward-jump loop, innermost
      (smallest) first, with its address range: a software-pipelined kernel's
      steady-state loop is a small one inside larger prologue/tail loops.
"""
import re
import subprocess
import sys


def main():
    show_all = sys.argv[1] == '--all'
    obj, fn = sys.argv[1 + show_all], sys.argv[2 + show_all]
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
    best, loops = [], []
    # x86 jumps (j*), AArch64 branches (b, b.<cond>, cbz/cbnz, tbz/tbnz).
    branch = re.compile(r'^(j\w+|b|b\.\w+|cbn?z|tbn?z)$')
    for i, (a, op, arg) in enumerate(ins):
        t = re.search(r'(?:^|[\s,])([0-9a-f]+) <', arg)
        if branch.match(op) and t:
            ta = int(t.group(1), 16)
            if ta <= a and ta in addrs:
                body = ins[addrs.index(ta):i + 1]
                loops.append(body)
                if len(body) > len(best):
                    best = body
    for body in sorted(loops, key=len) if show_all else [best]:
        ops = {}
        for _, op, _ in body:
            ops[op] = ops.get(op, 0) + 1
        where = ' (%x-%x)' % (body[0][0], body[-1][0]) if show_all and body else ''
        print('%s: loop body %d instructions%s' % (fn, len(body), where))
        print(' '.join('%s:%d' % kv for kv in sorted(ops.items(), key=lambda kv: -kv[1])[:20 if not show_all else 40]))


if __name__ == '__main__':
    main()
