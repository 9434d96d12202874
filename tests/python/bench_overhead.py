# SPDX-License-Identifier: MIT
"""Per-call cost of the bumpgrad Python package for small arrays (docs/PYTHON.md):
best of 5 repeats of many calls, in microseconds per call, and the throughput
for a large array. A benchmark, not a test: it prints, it does not judge.

usage: PYTHONPATH=BUILD/python python3 bench_overhead.py
"""
import timeit

import numpy as np

import bumpgrad


def per_call(fn, number):
    return min(timeit.repeat(fn, number=number, repeat=5)) / number


def main():
    rng = np.random.default_rng(1)
    print(f"bumpgrad {bumpgrad.__version__}, ISA {bumpgrad.isa_active()}")
    for n in (1, 16, 256):
        p32 = rng.uniform(-10, 10, (n, 3)).astype(np.float32)
        soa = tuple(np.ascontiguousarray(p32[:, i]) for i in range(3))
        p64 = p32.astype(np.float64)
        nn = np.tile(np.float32([0, 0, 1]), (n, 1))
        cases = [
            ("noise3 (N,3) float32", lambda: bumpgrad.noise3(p32)),
            ("noise3 (N,3) float64", lambda: bumpgrad.noise3(p64)),
            ("noise3 three arrays float32", lambda: bumpgrad.noise3(soa)),
            ("noise3 (N,3) threads=1 (general)", lambda: bumpgrad.noise3(p32, threads=1)),
            ("noise3 analytic (N,3)", lambda: bumpgrad.noise3(p32, "analytic")),
            ("fbm3 analytic (N,3)", lambda: bumpgrad.fbm3(p32, gradient="analytic")),
            ("perturb_height (N,3)", lambda: bumpgrad.perturb_height(p32, nn)),
            ("perturb (N,3)", lambda: bumpgrad.perturb(nn, p32)),
        ]
        for name, fn in cases:
            t = per_call(fn, 20000 if n == 1 else 5000)
            print(f"N={n:4d}  {name:30s} {t * 1e6:8.2f} us/call")
    p = rng.uniform(-10, 10, (1 << 20, 3)).astype(np.float32)
    soa = tuple(np.ascontiguousarray(p[:, i]) for i in range(3))
    for threads in (1, None):
        tn = "all cores" if threads is None else f"{threads} thread"
        for name, fn in (
                ("noise3, 2^20 points (N,3)", lambda: bumpgrad.noise3(p, threads=threads)),
                ("noise3 analytic, 2^20 (N,3)",
                 lambda: bumpgrad.noise3(p, "analytic", threads=threads)),
                ("noise3 analytic, 2^20 SoA",
                 lambda: bumpgrad.noise3(soa, "analytic", threads=threads))):
            t = per_call(fn, 3)
            print(f"{name:30s} {tn:9s} {t * 1e9 / len(p):6.2f} ns/point "
                  f"({len(p) / t / 1e6:5.0f} M points/s)")


if __name__ == "__main__":
    main()
