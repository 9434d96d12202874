# SPDX-License-Identifier: MIT
"""A numeric accuracy test of bumpgrad's float32 kernels from Python
(docs/PYTHON.md): the float32 noise, fBm and turbulence with their analytic
gradients against a numpy float64 reference of Perlin's published algorithm
(perlin_ref.py, next to this file), on random points.

usage: PYTHONPATH=BUILD/python:examples python3 examples/python_accuracy.py [N] [RNG_STATE]
Exits 1 if an error exceeds the bound noise.h documents (1e-5 value, 5e-5 gradient).
"""
import sys

import numpy as np

import bumpgrad
import perlin_ref


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 200000
    # The state of numpy's random-number generator that draws the points.
    rng_state = int(sys.argv[2]) if len(sys.argv) > 2 else 2026
    rng = np.random.default_rng(rng_state)
    # Points in [-100, 100]^3, rounded to float32 first: the reference sees the
    # very points the float32 kernel sees, so only the arithmetic differs.
    p = rng.uniform(-100.0, 100.0, (n, 3)).astype(np.float32)
    x, y, z = (p[:, i].astype(np.float64) for i in range(3))
    print(f"bumpgrad {bumpgrad.__version__}, ISA {bumpgrad.isa_active()}, {n} points in "
          f"[-100, 100]^3, random state {rng_state}")
    print(f"{'function':11s} {'max |value err|':>16s} {'mean':>10s} {'max |grad err|':>15s} "
          f"{'mean':>10s}  points")
    ok = True
    for function in ("noise", "fbm", "turbulence"):
        value, grad = bumpgrad.fractal3(p, function, gradient="analytic")
        rv, rg, minabs = perlin_ref.fractal(x, y, z, function)
        rg = np.stack(rg, axis=-1)
        # Turbulence |n| has a crease where an octave is 0; skip points within 1e-4.
        keep = minabs > 1e-4 if function == "turbulence" else np.ones(n, bool)
        ev = np.abs(value.astype(np.float64) - rv)
        eg = np.max(np.abs(grad.astype(np.float64) - rg), axis=1)[keep]
        print(f"{function:11s} {ev.max():16.3g} {ev.mean():10.3g} {eg.max():15.3g} "
              f"{eg.mean():10.3g}  {int(keep.sum())}")
        ok &= ev.max() <= 1e-5 and eg.max() <= 5e-5
    # float64 noise is Perlin's reference bit for bit.
    exact = np.array_equal(bumpgrad.noise3((x, y, z), dtype=np.float64), perlin_ref.noise(x, y, z))
    print(f"noise3 in float64 equals the numpy reference bit for bit: {exact}")
    ok &= exact
    print("within the documented bounds" if ok else "BOUND EXCEEDED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
