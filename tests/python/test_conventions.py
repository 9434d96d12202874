# SPDX-License-Identifier: MIT
"""numpy conventions of the bumpgrad package (docs/PYTHON.md): broadcasting,
out=, dtype=, threads= (the same bits for any thread count), the deprecated
float64 names, noise3's C fast path against the general path, and Ctrl-C
between blocks of a long call.

usage: test_conventions.py [sigint]
"""
import os
import signal
import sys
import warnings

import numpy as np

import bumpgrad
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import QUIET, check, finish  # noqa: E402
QUIET[0] = True  # failures only, as before



def same(a, b):
    """Bit-identical arrays (NaNs included), or tuples of them."""
    if isinstance(a, tuple):
        return isinstance(b, tuple) and len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and np.array_equal(
        np.ascontiguousarray(a).view(np.uint8), np.ascontiguousarray(b).view(np.uint8))


rng = np.random.default_rng(11)
P64 = rng.uniform(-20, 20, (200, 3))
P32 = P64.astype(np.float32)
N64 = rng.normal(size=(200, 3))
N64 /= np.linalg.norm(N64, axis=1, keepdims=True)
N32 = N64.astype(np.float32)


def test_broadcasting():
    up = np.float32([0, 0, 1])
    h, n = bumpgrad.perturb_height(P32, up)
    h2, n2 = bumpgrad.perturb_height(P32, np.tile(up, (200, 1)))
    check(same(h, h2) and same(n, n2), "perturb_height: n (3,) against p (N, 3)")
    # Per-point amplitudes: each point as if called with its own scalar.
    amp = rng.uniform(0.0, 0.3, 200).astype(np.float32)
    amp[50:120] = 0.1  # a run of equal values is one batch call
    ha, na = bumpgrad.perturb_height(P32, up, amplitude=amp)
    for i in (0, 7, 60, 199):
        hi, ni = bumpgrad.perturb_height(P32[i:i + 1], up, amplitude=float(amp[i]))
        check(same(ha[i:i + 1], hi) and same(na[i:i + 1], ni), f"per-point amplitude at {i}")
    hu, nu = bumpgrad.perturb_height(P32, up, amplitude=np.full(200, 0.1, np.float32))
    check(same(hu, h) and same(nu, n), "uniform amplitude array == scalar")
    fr = np.float32([0.5, 1.0, 2.0])[:, None]            # (3, 1) against (N,) -> (3, N)
    hf, nf = bumpgrad.perturb_height(P32, up, frequency=fr)
    check(hf.shape == (3, 200) and nf.shape == (3, 200, 3), f"frequency broadcast {hf.shape}")
    h1, _ = bumpgrad.perturb_height(P32, up, frequency=2.0)
    check(same(hf[2], h1), "per-row frequency == scalar frequency")
    # Points (N, 1, 3) against normals (M, 3): an (N, M) grid.
    g = bumpgrad.perturb(N64[:5, None, :], P64[:7] * 0.01)
    check(g.shape == (5, 7, 3), f"perturb grid shape {g.shape}")
    check(same(g[3, 4], bumpgrad.perturb(N64[3], P64[4] * 0.01)), "grid element")
    # Tuples broadcast too: a scalar z.
    v = bumpgrad.noise3((P64[:, 0], P64[:, 1], 0.5))
    w = bumpgrad.noise3(np.stack([P64[:, 0], P64[:, 1], np.full(200, 0.5)], -1))
    check(same(v, w), "tuple with a scalar component")
    # Footprints broadcast; resolve_normal takes (3,) normals and (N, 3) gradients.
    fv, fg = bumpgrad.fractal3_footprint(P32, np.float32(0.01))
    fv2, fg2 = bumpgrad.fractal3_footprint(P32, np.full(200, 0.01, np.float32))
    check(same(fv, fv2) and same(fg, fg2), "scalar footprint")
    r = bumpgrad.resolve_normal(up, 0.1 * P32)
    check(r.shape == (200, 3) and same(r, bumpgrad.resolve_normal(np.tile(up, (200, 1)), 0.1 * P32)),
          "resolve_normal broadcast")
    t = bumpgrad.surfgrad_triplanar(N64, 4.0, [0.1, 0.2], [0.3, 0.4], [0.5, 0.6])
    check(t.shape == (200, 3), "triplanar derivative (2,) against normals (N, 3)")


def test_dtype():
    v = bumpgrad.noise3(P64)
    check(v.dtype == np.float64, "float64 input -> float64")
    check(bumpgrad.noise3(P32).dtype == np.float32, "float32 input -> float32")
    check(bumpgrad.noise3(P32, dtype=np.float64).dtype == np.float64, "dtype= widens")
    check(same(bumpgrad.noise3(P64, dtype="float32"), bumpgrad.noise3(P32)), "dtype= rounds")
    check(bumpgrad.perturb(N32, P64).dtype == np.float64, "any float64 input -> float64")
    check(bumpgrad.noise3([[0.5, 0.5, 0.5]]).dtype == np.float64, "lists are float64")
    check(bumpgrad.perturb_height(P64, N64)[0].dtype == np.float32, "float32-only functions")
    # The deprecated names warn and equal dtype=float64.
    for old, new in ((lambda: bumpgrad.noise3d(P32), lambda: bumpgrad.noise3(P32, dtype=np.float64)),
                     (lambda: bumpgrad.fbm3d(P32, gradient="analytic"),
                      lambda: bumpgrad.fbm3(P32, gradient="analytic", dtype=np.float64)),
                     (lambda: bumpgrad.perturbd(N32, P32), lambda: bumpgrad.perturb(N32, P32, dtype="f8"))):
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            a = old()
        check(any(issubclass(x.category, DeprecationWarning) for x in w), "no DeprecationWarning")
        check(same(a, new()), "deprecated alias differs")
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        a = bumpgrad.noise3(P32, grad=True)
    check(any(issubclass(x.category, DeprecationWarning) for x in w) and
          same(a, bumpgrad.noise3(P32, "analytic")), "noise3(grad=True)")
    # One gradient option everywhere: 'central' works for noise3 too.
    v, g = bumpgrad.noise3(P64, "central")
    v2, g2 = bumpgrad.fractal3(P64, "noise", gradient="central")
    check(same(v, v2) and same(g, g2), "noise3 central == fractal3('noise') central")


def test_out():
    out = np.empty(200, np.float32)
    r = bumpgrad.noise3(P32, out=out)
    check(r is out and same(out, bumpgrad.noise3(P32)), "out= scalar result")
    strided = np.empty((200, 2), np.float64)[:, 1]
    r = bumpgrad.fbm3(P64, out=strided)
    check(r is strided and same(np.ascontiguousarray(strided), bumpgrad.fbm3(P64)), "strided out")
    vo, go = np.empty(200), np.empty((200, 3))
    v, g = bumpgrad.fbm3(P64, gradient="analytic", out=(vo, go))
    want = bumpgrad.fbm3(P64, gradient="analytic")
    check(v is vo and g is go and same((vo, go), want), "out=(value, gradient)")
    v, g = bumpgrad.fbm3(P64, gradient="analytic", out=(None, go))
    check(g is go and same(v, want[0]), "out=(None, gradient)")
    no = np.empty((200, 3), np.float32)
    r = bumpgrad.perturb(N32, 0.1 * P32, out=no)
    check(r is no and same(no, bumpgrad.perturb(N32, 0.1 * P32)), "vector out (N, 3)")
    rows = tuple(np.empty(200, np.float32) for _ in range(3))
    r = bumpgrad.perturb(tuple(N32.T.copy()), tuple((0.1 * P32).T.copy()), out=rows)
    check(r is rows and same(np.stack(rows, -1), no), "vector out as three arrays")
    ho, nno = np.empty(200, np.float32), np.empty((200, 3), np.float32)
    r = bumpgrad.perturb_height(P32, N32, out=(ho, nno))
    check(same(r, bumpgrad.perturb_height(P32, N32)) and r[0] is ho, "perturb_height out")
    wo = np.empty(3, np.float32)
    check(bumpgrad.octave_weight([0.0, 0.1, 0.5], out=wo) is wo, "octave_weight out")
    r = bumpgrad.resolve_normal(N64, 0.1 * P64, out=np.empty((200, 3)))
    check(same(r, bumpgrad.resolve_normal(N64, 0.1 * P64)), "resolve_normal out")
    r = bumpgrad.triplanar_weights(N64, out=np.empty((200, 3)))
    check(same(r, bumpgrad.triplanar_weights(N64)), "triplanar out")


def test_threads():
    block = bumpgrad._c.BLOCK
    n = 3 * block + 1234   # several blocks and a partial one
    p = np.random.default_rng(3).uniform(-50, 50, (n, 3))
    q = p.astype(np.float32)
    nn = np.tile(np.float32([0, 0, 1]), (n, 1))
    calls = [
        ("noise3 f32", lambda t: bumpgrad.noise3(q, "analytic", threads=t)),
        ("noise3 f64", lambda t: bumpgrad.noise3(p, "analytic", threads=t)),
        ("fbm3 central", lambda t: bumpgrad.fbm3(q, gradient="central", octaves=3, threads=t)),
        ("turbulence3 f64", lambda t: bumpgrad.turbulence3(p, octaves=3, threads=t)),
        ("footprint", lambda t: bumpgrad.fractal3_footprint(q, 0.01, threads=t)),
        ("perturb_height", lambda t: bumpgrad.perturb_height(q, nn, threads=t)),
        ("perturb", lambda t: bumpgrad.perturb(nn, 0.1 * q, threads=t)),
        ("resolve", lambda t: bumpgrad.resolve_normal(nn, 0.1 * q, 0.2 * q, threads=t)),
        ("triplanar", lambda t: bumpgrad.surfgrad_triplanar(p, 4.0, p[:, :2], p[:, 1:], p[:, ::2],
                                                            threads=t)),
    ]
    for name, call in calls:
        one = call(1)
        for t in (2, 3, 7):
            check(same(call(t), one), f"{name}: threads={t} differs from threads=1")
    # An interleaved (N, 3) array is split into x, y, z per block in C: the same
    # bits as three arrays, over several blocks, in both precisions.
    for arr in (p, q):
        soa = tuple(np.ascontiguousarray(arr[:, i]) for i in range(3))
        a, b = bumpgrad.noise3(arr, "analytic", threads=2), bumpgrad.noise3(soa, "analytic", threads=2)
        check(same(a[0], b[0]) and same(a[1], np.stack(b[1], -1)), f"(N, 3) vs SoA {arr.dtype}")
    # The default (all cores) too, and one block per point count around a block edge.
    for m in (block - 1, block, block + 1):
        check(same(bumpgrad.noise3(q[:m]), bumpgrad.noise3(q[:m], threads=1)), f"n={m}")
    print(f"threads: {len(calls)} calls bit-identical for 1, 2, 3, 7 threads over {n} points")


def test_fast_path():
    # noise3 on a small plain array runs in C; the same call through the
    # general path (a keyword sends it there) gives the same bits and shapes.
    for p in (P32[:1], P32[:17], P64[:5], P64[0], P32[3], P64[:12].reshape(3, 4, 3)):
        a = bumpgrad.noise3(p)
        b = bumpgrad.noise3(p, threads=1)
        check(same(a, b) and type(a) is type(b), f"fast path {p.shape} {p.dtype}: {a!r} {b!r}")
    check(bumpgrad.noise3(P64[0]) == bumpgrad.noise3(P64[:1])[0], "single point scalar")


def test_sigint():
    """A real SIGINT during a long call: KeyboardInterrupt between blocks, the
    unfinished blocks never written (not an exception after the whole call).

    The test installs Python's own SIGINT handler for its duration: a process
    started in the background by a non-interactive shell inherits SIGINT
    ignored, and Python then keeps it ignored (no KeyboardInterrupt at all).
    The SIGINT is sent by a SIGALRM handler, which Python runs in the main
    thread between two blocks, so no helper thread has to win the GIL while
    the call runs."""
    n = 256 * bumpgrad._c.BLOCK   # seconds of work on one core
    p = np.random.default_rng(1).uniform(-50, 50, (n, 3)).astype(np.float32)
    out = (np.full(n, np.nan, np.float32), None)
    old_int = signal.signal(signal.SIGINT, signal.default_int_handler)
    old = signal.signal(signal.SIGALRM, lambda s, f: os.kill(os.getpid(), signal.SIGINT))
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.1)
        bumpgrad.fbm3(p, octaves=32, gradient="central", threads=1, out=out)
        interrupted = False
    except KeyboardInterrupt:
        interrupted = True
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
        signal.signal(signal.SIGINT, old_int)
    done = int(np.count_nonzero(~np.isnan(out[0])))
    check(interrupted, "no KeyboardInterrupt")
    check(0 < done < n, f"{done} of {n} values written: the call was not stopped between blocks")
    print(f"sigint: KeyboardInterrupt after {done} of {n} points ({done // bumpgrad._c.BLOCK} blocks)")


def test_stubs():
    """Every public name has a type stub, and the stub file parses."""
    import ast
    path = os.path.join(os.path.dirname(bumpgrad.__file__), "__init__.pyi")
    with open(path) as f:
        tree = ast.parse(f.read())
    stubbed = {n.name for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    stubbed |= {t.id for n in ast.walk(tree) if isinstance(n, ast.AnnAssign) for t in [n.target]}
    missing = [n for n in bumpgrad.__all__ if n not in stubbed]
    check(not missing, f"no stub for {missing}")


def main():
    if sys.argv[1:] == ["sigint"]:
        test_sigint()
    else:
        test_broadcasting()
        test_dtype()
        test_out()
        test_threads()
        test_fast_path()
        test_stubs()
    return finish('conventions')


if __name__ == "__main__":
    sys.exit(main())
