# SPDX-License-Identifier: MIT
"""period= and seed= (noise.h's bg_domain) from Python: f(p + P e_i) == f(p)
bit for bit for noise3, fbm3, turbulence3 and perturb_height (float32 and
float64, value and gradient); seed=0 is the plain call; different seeds
differ; the values equal `bumpgrad eval --period ... --seed ...`; bad
arguments name themselves.

usage: test_domain_py.py BUMPGRAD_EXE
"""
import os
import sys
import tempfile

import numpy as np

import bumpgrad

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import FAILURES, QUIET, check, eval_points, finish  # noqa: E402
QUIET[0] = True  # failures only


def bits(a):
    a = np.ascontiguousarray(a)
    return a.view(np.uint32 if a.dtype == np.float32 else np.uint64)


def same(a, b):
    if isinstance(a, tuple):
        return all(same(x, y) for x, y in zip(a, b))
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(bits(a), bits(b))


def grid_points(n, dtype, rng):
    """Points on a 2^-10 grid in [-20, 20): p + P e_i is exact in float."""
    return (rng.integers(-20 * 1024, 20 * 1024, (n, 3)) / 1024.0).astype(dtype)


def shifted(p, axis, P):
    q = p.copy()
    q[:, axis] += P
    return q


def test_periodic(rng):
    period = (3, 8, 0)
    calls = [
        ("noise3", lambda p, **k: bumpgrad.noise3(p, **k), {}),
        ("noise3 analytic", lambda p, **k: bumpgrad.noise3(p, "analytic", **k), {}),
        ("fbm3", lambda p, **k: bumpgrad.fbm3(p, 5, **k), {"seed": 11}),
        ("fbm3 analytic", lambda p, **k: bumpgrad.fbm3(p, 5, gradient="analytic", **k),
         {"seed": 11}),
        ("turbulence3 analytic",
         lambda p, **k: bumpgrad.turbulence3(p, 4, 3.0, 0.4, gradient="analytic", **k),
         {"seed": 5}),
    ]
    for dtype in (np.float32, np.float64):
        p = grid_points(500, dtype, rng)
        for name, f, kw in calls:
            a = f(p, period=period, **kw)
            for axis, P in enumerate(period):
                if P:
                    check(same(a, f(shifted(p, axis, P), period=period, **kw)),
                          f"{name} {np.dtype(dtype).name}: not periodic along axis {axis}")
            # Not periodic along the untiled axis (0) nor without period=.
            check(not same(a, f(shifted(p, 2, 3), period=period, **kw)),
                  f"{name}: periodic along an untiled axis")
            check(not same(a, f(shifted(p, 0, 3), **kw)), f"{name}: periodic with no period=")
    # Central differences: the value repeats bit for bit; the gradient samples
    # p +- h, which rounds differently at p + P, so it repeats to rounding.
    p = grid_points(500, np.float32, rng)
    v, g = bumpgrad.turbulence3(p, gradient="central", period=period, seed=9)
    v2, g2 = bumpgrad.turbulence3(shifted(p, 1, 8), gradient="central", period=period, seed=9)
    check(same(v, v2) and np.allclose(g, g2, rtol=0, atol=0.05),
          f"turbulence3 central: not periodic (gradient {np.max(np.abs(g - g2)):.3g})")
    # perturb_height: periods in noise space (frequency * p).
    n = np.array([0.0, 0.6, 0.8], np.float32)
    for grad in ("analytic", "central"):
        kw = dict(function="fbm", frequency=2.0, gradient=grad, period=(4, 4, 4), seed=3)
        h, m = bumpgrad.perturb_height(p, n, **kw)
        for axis in range(3):
            h2, m2 = bumpgrad.perturb_height(shifted(p, axis, 2), n, **kw)
            ok = same(h, h2) and (same(m, m2) if grad == "analytic" else
                                  np.allclose(m, m2, rtol=0, atol=2e-2))
            check(ok, f"perturb_height {grad}: not periodic along axis {axis}")
    # Period 256 on every axis is Perlin's own lattice.
    check(same(bumpgrad.noise3(p, period=256), bumpgrad.noise3(p)), "period 256 differs")


def test_seed(rng):
    p = grid_points(300, np.float32, rng)
    n = np.array([0.0, 0.0, 1.0], np.float32)
    for name, f in (("noise3", lambda **k: bumpgrad.noise3(p, "analytic", **k)),
                    ("fbm3", lambda **k: bumpgrad.fbm3(p, gradient="analytic", **k)),
                    ("fbm3 float64", lambda **k: bumpgrad.fbm3(p, dtype=np.float64, **k)),
                    ("turbulence3", lambda **k: bumpgrad.turbulence3(p, **k)),
                    ("perturb_height", lambda **k: bumpgrad.perturb_height(p, n, **k))):
        check(same(f(seed=0), f()), f"{name}: seed=0 differs from no seed")
        check(not same(f(seed=1), f(seed=2)), f"{name}: seeds 1 and 2 give the same values")
        check(same(f(seed=7), f(seed=7, threads=3)), f"{name}: seed 7 differs across threads")


def run_eval(exe, pts, precision, function, extra, tmp):
    return eval_points(exe, pts, precision, ["--function", function] + extra, tmp)


def test_cli(exe, rng):
    compared = 0
    p64 = rng.uniform(-30, 30, (200, 3))
    cases = [("noise", {"period": (5, 7, 2)}, ["--period", "5,7,2"]),
             ("noise", {"period": (5, 7, 2), "seed": 4}, ["--period", "5,7,2", "--seed", "4"]),
             ("fbm", {"period": (8, 8, 0), "seed": 3}, ["--period", "8,8,0", "--seed", "3"]),
             ("turbulence", {"seed": 123456789}, ["--seed", "123456789"]),
             ("fbm", {"period": 16, "octaves": 3, "lacunarity": 3.0},
              ["--period", "16", "--octaves", "3", "--lacunarity", "3"])]
    with tempfile.TemporaryDirectory() as tmp:
        for precision, dtype in (("float", np.float32), ("double", np.float64)):
            p = p64.astype(dtype)
            for function, kw, extra in cases:
                for grad in (["analytic", "central"] if precision == "float" else ["analytic"]):
                    cv, cg = run_eval(exe, p, precision, function, extra + ["--gradient", grad],
                                      tmp)
                    v, g = bumpgrad.fractal3(p, function, gradient=grad, dtype=dtype, **kw)
                    compared += 1
                    check(same(v, cv) and same(g, cg),
                          f"{precision} {function} {grad} {extra}: differs from bumpgrad eval "
                          f"(max value diff {np.max(np.abs(v - cv)):.3g})")
            # noise3(period=) (bg_pnoise3 batch) equals eval's domain noise.
            cv, cg = run_eval(exe, p, precision, "noise", ["--period", "5,7,2"], tmp)
            v, g = bumpgrad.noise3(p, "analytic", period=(5, 7, 2))
            check(same(v, cv) and same(g, cg), f"{precision} noise3(period=) differs from eval")
            compared += 1
    print(f"bumpgrad eval: {compared} runs, each bit-identical over {len(p64)} points"
          if not FAILURES else f"bumpgrad eval: {compared} runs compared")


def test_errors():
    p = [[0.5, 0.25, 0.125]]
    for kw, exc, word in [({"period": (4, 4)}, ValueError, "period"),
                          ({"period": (4, 4, 257)}, ValueError, "period[2]"),
                          ({"period": (4, -1, 4)}, ValueError, "period[1]"),
                          ({"period": (4.0, 4, 4)}, TypeError, "period[0]"),
                          ({"period": "444"}, TypeError, "period"),
                          ({"period": 4, "lacunarity": 2.5}, ValueError, "lacunarity"),
                          ({"period": 256, "octaves": 20}, ValueError, "2^24"),
                          ({"seed": -1}, ValueError, "seed"),
                          ({"seed": 2 ** 32}, ValueError, "seed"),
                          ({"seed": 1.5}, TypeError, "seed")]:
        for name, f in (("fbm3", bumpgrad.fbm3),
                        ("perturb_height", lambda q, **k: bumpgrad.perturb_height(
                            q, [0.0, 0.0, 1.0], **k))):
            try:
                f(p, **kw)
                check(False, f"{name}({kw}) did not raise")
            except exc as e:
                check(word in str(e), f"{name}({kw}): message does not name {word}: {e}")
    try:
        bumpgrad.fbm3(p, gradient="central", period=4, dtype=np.float64)
        check(False, "float64 central over a domain did not raise")
    except ValueError as e:
        check("central" in str(e), f"float64 central over a domain: {e}")


def main():
    rng = np.random.default_rng(2026)
    test_periodic(rng)
    test_seed(rng)
    test_cli(sys.argv[1], rng)
    test_errors()
    return finish("domain")


if __name__ == "__main__":
    sys.exit(main())
