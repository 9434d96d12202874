# SPDX-License-Identifier: MIT
"""Tests of the bumpgrad Python package (docs/PYTHON.md), run by meson with
PYTHONPATH pointing at BUILD/python.

usage: test_bumpgrad.py reference|bounds|cli|badinput|api [BUMPGRAD_EXE] [VERSION]
"""
import os
import sys
import tempfile

import numpy as np

import bumpgrad
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import QUIET, check, eval_points, finish  # noqa: E402
QUIET[0] = True  # failures only, as before
import perlin_ref as ref  # examples/perlin_ref.py



def points(n, seed, scale=100.0, dtype=np.float64):
    """Random points in [-scale, scale]^3 plus near-lattice, lattice, negative and
    large ones, as an (n, 3) array."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(-scale, scale, (n, 3))
    k = n // 8
    p[:k] = np.round(p[:k]) + rng.uniform(-1e-6, 1e-6, (k, 3))   # near lattice
    p[k:2 * k] = np.round(p[k:2 * k])                               # on the lattice
    p[2 * k:3 * k] *= 100.0                                         # to 1e4
    return p.astype(dtype)


# ---- reference: Perlin's reference point ---------------------------------------------

def test_reference():
    want = 0.13691995878400012          # Perlin's Java ImprovedNoise.noise(3.14, 42, 7)
    got = bumpgrad.noise3(np.array([[3.14, 42, 7]]), dtype=np.float64)
    check(got.shape == (1,) and got.dtype == np.float64, f"shape/dtype {got.shape} {got.dtype}")
    check(got[0] == want, f"noise3d(3.14, 42, 7) = {got[0]!r}, want {want!r}")
    one = bumpgrad.noise3(np.array([3.14, 42, 7]), dtype=np.float64)
    check(np.ndim(one) == 0 and float(one) == want, f"single point gave {one!r}")
    check(float(ref.noise(3.14, 42, 7)) == want, "the numpy reference misses the point")
    v, g = bumpgrad.noise3(np.array([3.14, 42, 7]), "analytic", dtype=np.float64)
    check(v == want and g.shape == (3,), f"value with gradient {v!r} {g.shape}")
    print(f"noise3d(3.14, 42, 7) = {got[0]!r} (Perlin: {want!r})")


# ---- bounds against the numpy double reference ---------------------------------------------

def test_bounds():
    p = points(4000, 1)
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    # float64 noise equals Perlin's lerp chain bit for bit (noise.h).
    v = bumpgrad.noise3(p, dtype=np.float64)
    check(np.array_equal(v, ref.noise(x, y, z)), "noise3d differs from the reference bits: max "
          f"{np.max(np.abs(v - ref.noise(x, y, z)))}")
    for function in ("noise", "fbm", "turbulence"):
        p32 = p.astype(np.float32)
        x32, y32, z32 = (p32[:, i].astype(np.float64) for i in range(3))
        rv, rg, minabs = ref.fractal(x32, y32, z32, function)
        # Turbulence has a crease where an octave crosses 0: its gradient jumps.
        keep = minabs > 1e-4 if function == "turbulence" else np.ones(len(p), bool)
        rg = np.stack(rg, -1)
        # float32: the documented bounds (noise.h: value 1e-5, gradient 5e-5).
        fv, fg = bumpgrad.fractal3(p32, function, gradient="analytic")
        ev = np.max(np.abs(fv - rv))
        eg = np.max(np.abs(fg - rg)[keep])
        check(fv.dtype == np.float32 and fg.dtype == np.float32, "float32 results")
        check(ev <= 1e-5, f"{function} float32 value error {ev:.3g} > 1e-5")
        check(eg <= 5e-5, f"{function} float32 gradient error {eg:.3g} > 5e-5")
        # float64 analytic: a few 1e-15 (ACCURACY.md); checked at 1e-12.
        dv, dg = bumpgrad.fractal3(p32.astype(np.float64), function, gradient="analytic")
        edv = np.max(np.abs(dv - rv))
        edg = np.max(np.abs(dg - rg)[keep])
        check(edv <= 1e-12 and edg <= 1e-12, f"{function} float64 errors {edv:.3g} {edg:.3g}")
        # central differences, float64 with a small step: truncation error ~h^2.
        _, cg = bumpgrad.fractal3(p32.astype(np.float64), function, gradient="central", step=1e-5)
        ecg = np.max(np.abs(cg - rg)[keep & (minabs > 1e-3)])
        check(ecg <= 2e-3, f"{function} float64 central gradient error {ecg:.3g}")
        print(f"{function:10s} float32 value {ev:.3g} gradient {eg:.3g}; float64 value {edv:.3g} "
              f"gradient {edg:.3g}; central(1e-5) {ecg:.3g} over {int(keep.sum())} points")
    # A bound that can fail: the float32 kernel is NOT within 1e-9 of the reference.
    check(np.max(np.abs(bumpgrad.noise3(p.astype(np.float32)) -
                        ref.noise(*(p.astype(np.float32).astype(np.float64).T)))) > 1e-9,
          "float32 noise suspiciously exact: is noise3 calling the double path?")


# ---- bit identity with `bumpgrad eval` -------------------------------------------------------

def run_eval(exe, pts, precision, function, gradient, tmp):
    return eval_points(exe, pts, precision, ["--function", function, "--gradient", gradient], tmp)


def test_cli(exe):
    p64 = points(600, 2, scale=50.0)
    with tempfile.TemporaryDirectory() as tmp:
        for precision, dtype in (("float", np.float32), ("double", np.float64)):
            p = p64.astype(dtype)
            for function in ("noise", "fbm", "turbulence"):
                for gradient in ("analytic", "central"):
                    cv, cg = run_eval(exe, p, precision, function, gradient, tmp)
                    v, g = bumpgrad.fractal3(p, function, gradient=gradient, dtype=dtype)
                    bits = lambda a: np.ascontiguousarray(a).view(np.uint8)  # noqa: E731
                    same = (np.array_equal(bits(v), bits(cv)) and
                            np.array_equal(bits(g), bits(cg)))
                    check(same, f"{precision} {function} {gradient}: differs from bumpgrad eval "
                          f"(max value diff {np.max(np.abs(v - cv)):.3g})")
                    print(f"{precision:6s} {function:10s} {gradient:8s}: "
                          f"{'bit-identical' if same else 'DIFFERENT'} over {len(p)} points")
        # The named wrappers are the same calls.
        p = p64.astype(np.float32)
        v, g = bumpgrad.noise3(p, "analytic")
        cv, cg = run_eval(exe, p, "float", "noise", "analytic", tmp)
        check(np.array_equal(v, cv) and np.array_equal(g, cg), "noise3 differs from eval")


# ---- bad input -----------------------------------------------------------------------------

def raises(exc, fn, *a, **k):
    try:
        fn(*a, **k)
    except exc as e:
        return e
    check(False, f"{fn.__name__}{a!r:.60} did not raise {exc.__name__}")
    return None


def test_badinput():
    good = np.zeros((4, 3))
    # Shapes.
    raises(ValueError, bumpgrad.noise3, np.zeros((4, 2)))
    raises(ValueError, bumpgrad.noise3, np.zeros(()))
    raises(ValueError, bumpgrad.noise3, np.zeros((3, 4)))
    raises(ValueError, bumpgrad.noise3, (np.zeros(4), np.zeros(4)))
    raises(ValueError, bumpgrad.noise3, [[1.0, 2.0]])
    raises(ValueError, bumpgrad.noise3, (np.zeros(4), np.zeros(4), np.zeros(5)))
    raises(ValueError, bumpgrad.perturb, good, np.zeros((5, 3)))
    raises(ValueError, bumpgrad.surfgrad_triplanar, good, 4.0, np.zeros((4, 3)), good, good)
    # dtypes: integers, booleans, complex and objects raise TypeError.
    for bad in (np.zeros((4, 3), np.int32), np.zeros((4, 3), np.int64), np.zeros((4, 3), bool),
                np.zeros((4, 3), np.complex128), np.zeros((4, 3), object), [[1, 2, 3]]):
        e = raises(TypeError, bumpgrad.noise3, bad, dtype=np.float64)
        check(e is None or "floating-point" in str(e), f"message: {e}")
        raises(TypeError, bumpgrad.perturb, bad, good)
    raises(TypeError, bumpgrad.fbm3, (np.zeros(2), np.zeros(2, np.int16), np.zeros(2)))
    # Conversions: float16/32 widen exactly to float64; dtype=float32 rounds
    # float64 input (the caller asked for float32).
    q = points(50, 3)
    check(np.array_equal(bumpgrad.noise3(q.astype(np.float32), dtype=np.float64),
                         bumpgrad.noise3(q.astype(np.float32).astype(np.float64))), "f32->f64")
    check(np.array_equal(bumpgrad.noise3(q, dtype=np.float32),
                         bumpgrad.noise3(q.astype(np.float32))), "f64->f32")
    check(bumpgrad.noise3(q.astype(np.float16)).dtype == np.float32, "f16 -> float32 result")
    # Parameter errors name the argument and the rule.
    for call, kw, want in (
            (bumpgrad.fbm3, dict(octaves=0), "octaves must be in 1..32, got 0"),
            (bumpgrad.fbm3, dict(octaves=33), "octaves must be in 1..32, got 33"),
            (bumpgrad.turbulence3, dict(lacunarity=0.0), "lacunarity must be > 0, got 0.0"),
            (bumpgrad.fbm3, dict(gain=float("nan")), "gain must be finite, got nan"),
            (bumpgrad.fbm3, dict(gradient="central", step=0.0), "step must be > 0, got 0.0"),
            (bumpgrad.perturb_height, dict(n=good + [0, 0, 1], amplitude=float("nan")),
             "amplitude must be finite, got nan"),
            (bumpgrad.perturb_height, dict(n=good + [0, 0, 1], amplitude=[0.1, 0.2, np.inf, 0]),
             "amplitude must be finite, got inf"),
            (bumpgrad.perturb, dict(g=good, method="sideways"), "method must be one of"),
            (bumpgrad.fractal3, dict(function="perlin"), "function must be one of"),
            (bumpgrad.fractal3, dict(gradient="forward"), "gradient must be one of"),
            (bumpgrad.noise3, dict(threads=0), "threads must be in 1..1024, got 0"),
            (bumpgrad.noise3, dict(dtype=np.int32), "dtype must be float32 or float64"),
            (bumpgrad.perturb_height, dict(n=good, gradient=None), "gradient must be"),
            (bumpgrad.perturb_height, dict(n=good, dtype=np.float64), "float32 only")):
        e = raises(ValueError, call, good, **kw)
        check(e is None or want in str(e), f"{call.__name__}{kw}: message {e!r} lacks {want!r}")
    # Integer parameters refuse non-integers (2.9 is not silently 2).
    for call, kw in ((bumpgrad.fbm3, dict(octaves=2.9)), (bumpgrad.fbm3, dict(octaves=3.0)),
                     (bumpgrad.fbm3, dict(octaves=True)), (bumpgrad.noise3, dict(threads=1.5)),
                     (bumpgrad.octaves_for_footprint, dict(max_octaves="6"))):
        arg = good if call is not bumpgrad.octaves_for_footprint else np.zeros(4)
        e = raises(TypeError, call, arg, **kw)
        name = next(iter(kw))
        check(e is None or f"{name} must be an integer" in str(e), f"message {e!r}")
    check(bumpgrad.fbm3(good, octaves=np.int64(3)).shape == (4,), "numpy integers are integers")
    # Library errors that are not argument errors raise bumpgrad.Error with the status text.
    e = raises(bumpgrad.Error, bumpgrad.isa_force, "no-such-isa")
    check(e is not None and e.text == bumpgrad._c.status_string(e.status) and e.text in str(e),
          f"status text: {e!r}")
    # out= of the wrong shape, dtype or a read-only one.
    raises(ValueError, bumpgrad.noise3, good, out=np.empty(3))
    raises(ValueError, bumpgrad.noise3, good, out=np.empty(4, np.float32))
    ro = np.empty(4)
    ro.flags.writeable = False
    raises(ValueError, bumpgrad.noise3, good, out=ro)
    raises(ValueError, bumpgrad.noise3, good, "analytic", out=np.empty(4))
    # NaN policy: the C library's, nothing raises.
    nanp = np.array([[np.nan, 1.0, 2.0], [np.inf, 0.5, 0.5], [0.3, 0.4, 0.5]])
    for dt in (np.float32, np.float64):
        v, g = bumpgrad.noise3(nanp, "analytic", dtype=dt)
        check(np.isnan(v[:2]).all() and np.isnan(g[:2]).all() and np.isfinite(v[2]),
              f"{dt}: NaN/Inf point gives NaN value and gradient, others finite")
    n = np.array([[0, 0, 2.0], [np.nan, 0, 1], [0, 0, 0]])
    g = np.array([[np.nan, 0, 0], [0.1, 0, 0], [0.1, 0, 0]])
    for dt in (np.float32, np.float64):
        r = bumpgrad.perturb(n, g, dtype=dt)
        check(np.array_equal(r[0], [0, 0, 1]), f"{dt}: NaN g gives the unit n: {r[0]}")
        check(np.array_equal(r[1:], np.zeros((2, 3))), f"{dt}: bad n gives 0: {r[1:]}")
    # Empty batches are fine.
    check(bumpgrad.noise3(np.zeros((0, 3))).shape == (0,), "empty batch")
    check(bumpgrad.fbm3(np.zeros((0, 3)), gradient="analytic")[1].shape == (0, 3), "empty grad")


# ---- API: layouts, strides, copies, docs, version, ISA ---------------------------------------

def test_api(version):
    check(bumpgrad.__version__ == version, f"__version__ {bumpgrad.__version__} != {version}")
    doc = bumpgrad.noise3.__doc__ or ""
    check("Perlin" in doc and "float32" in doc, "noise3 has a docstring")
    import io
    import contextlib
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        help(bumpgrad.noise3)
    check("grad" in buf.getvalue(), "help(bumpgrad.noise3)")
    import doctest
    # Without the tools, the examples that run a tool (they return arrays) are
    # skipped; those that show the tool's Error still run.
    tool_examples = {"bumpgrad.heightmap", "bumpgrad.volume", "bumpgrad.render"}
    runner = doctest.DocTestRunner()
    for t in doctest.DocTestFinder().find(bumpgrad):
        if bumpgrad.HAVE_TOOLS or t.name not in tool_examples:
            runner.run(t)
    res = runner.summarize(verbose=False)
    check(res.failed == 0 and res.attempted > 0, f"doctests: {res}")
    for name in bumpgrad.__all__:
        obj = getattr(bumpgrad, name)
        if callable(obj) and not isinstance(obj, type):
            check(bool(obj.__doc__), f"{name} lacks a docstring")
    # Layouts agree: (N, 3), three arrays, strided views, (..., 3) batches.
    p = points(257, 4).astype(np.float32)
    v, g = bumpgrad.fbm3(p, gradient="analytic")
    soa = np.ascontiguousarray(p.T)
    v2, (gx, gy, gz) = bumpgrad.fbm3((soa[0], soa[1], soa[2]), gradient="analytic")
    check(np.array_equal(v, v2) and np.array_equal(g, np.stack([gx, gy, gz], -1)), "SoA == AoS")
    big = np.zeros((257, 7), np.float32)
    big[:, 1:7:2] = p
    v3, g3 = bumpgrad.fbm3(big[:, 1:7:2], gradient="analytic")
    check(np.array_equal(v, v3) and np.array_equal(g, g3), "strided columns")
    v4 = bumpgrad.fbm3(p[::-1])
    check(np.array_equal(v[::-1], v4), "negative strides")
    v5, g5 = bumpgrad.fbm3(p[:256].reshape(4, 8, 8, 3), gradient="analytic")
    check(v5.shape == (4, 8, 8) and g5.shape == (4, 8, 8, 3) and
          np.array_equal(v5.reshape(-1), v[:256]), "(..., 3) batches")
    # Copy-free: contiguous SoA components of the right dtype reach C as they are.
    comps, shape, _ = bumpgrad._split((soa[0], soa[1], soa[2]), "p")
    flat = [bumpgrad._flat(c, shape, np.dtype(np.float32)) for c in comps]
    check(all(np.shares_memory(c, s) for c, s in zip(flat, soa)), "SoA input copied")
    comps, shape, _ = bumpgrad._split(p.astype(np.float64), "p")
    flat = [bumpgrad._flat(c, shape, np.dtype(np.float32)) for c in comps]
    check(all(c.dtype == np.float32 and c.flags.c_contiguous for c in flat), "converted")
    check(gx.base is not None and gx.base is gy.base, "three-array results: rows of one block")
    # The single-point C API through the loops: triplanar and tangent normals agree
    # between float and double to float rounding, and between layouts exactly.
    rng = np.random.default_rng(5)
    n = rng.normal(size=(100, 3))
    d = [rng.normal(size=(100, 2)) for _ in range(3)]
    t32 = bumpgrad.surfgrad_triplanar(n, 4.0, *d, dtype=np.float32)
    t64 = bumpgrad.surfgrad_triplanar(n, 4.0, *d)
    check(np.max(np.abs(t32 - t64)) < 1e-5, "triplanar float vs double")
    w = bumpgrad.triplanar_weights(n, 4.0)
    check(np.allclose(w.sum(-1), 1.0, atol=1e-12), "triplanar weights sum to 1")
    # Resolve: the unit n with no influence, and linear in the influences.
    un = n / np.linalg.norm(n, axis=1, keepdims=True)
    check(np.allclose(bumpgrad.resolve_normal(n), un, atol=1e-15), "resolve with nothing")
    sg = bumpgrad.surface_gradient(n, rng.normal(size=(100, 3)))
    r2 = bumpgrad.resolve_normal(n, sg, sg, weights=[0.25, 0.75])
    check(np.allclose(r2, bumpgrad.resolve_normal(n, sg), atol=1e-12), "resolve weights")
    check(np.max(np.abs(bumpgrad.resolve_normal(n, sg, sg, weights=[0.25, 0.75],
                                                dtype=np.float32) - r2)) < 1e-5,
          "resolve float vs double")
    # The surfgrad perturbation equals the resolve of the surface gradient (eq. 4).
    gg = rng.normal(size=(100, 3))
    check(np.allclose(bumpgrad.perturb(un, gg),
                      bumpgrad.resolve_normal(un, bumpgrad.surface_gradient(un, gg)),
                      atol=1e-12), "perturb == resolve(surface_gradient)")
    # Object-space normal round trip: normalize(n - g(m)) == normalize(m) for m.n > 0.
    m = un + 0.3 * rng.normal(size=(100, 3))
    m[np.sum(m * un, 1) <= 0.1] = un[np.sum(m * un, 1) <= 0.1]
    back = bumpgrad.resolve_normal(un, bumpgrad.surfgrad_from_perturbed_normal(un, m))
    check(np.allclose(back, m / np.linalg.norm(m, axis=1, keepdims=True), atol=1e-9),
          "object-space round trip")
    # Fused height -> normal equals perturbing with the height gradient.
    P = points(64, 6, scale=4.0).astype(np.float32)
    N = np.tile(np.float32([0, 0, 1]), (64, 1))
    h, nn = bumpgrad.perturb_height(P, N, amplitude=0.1, frequency=1.0)
    hv, hg = bumpgrad.turbulence3(P, gradient="analytic")
    check(np.allclose(h, 0.1 * hv, atol=1e-6), "fused height")
    check(np.allclose(nn, bumpgrad.perturb(N, 0.1 * hg), atol=1e-5), "fused normal")
    h0, n0 = bumpgrad.perturb_height(P, N, footprint=0.0)
    check(np.array_equal(h0, h) and np.array_equal(n0, nn), "footprint 0 == unfiltered")
    fv, fg = bumpgrad.fractal3_footprint(P, 0.0, "turbulence")
    check(np.array_equal(fv, hv) and np.array_equal(fg, hg), "fractal footprint 0")
    check(np.array_equal(bumpgrad.octaves_for_footprint(np.float32([0.0, 0.5, 1.0]), 6),
                         np.float32([6, 0, 0])), "octaves_for_footprint")
    # ISA: every level gives the same bits.
    best = bumpgrad.isa_best()
    base = bumpgrad.fbm3(p)
    for isa in ("scalar", "sse2", "avx2", "avx512", "neon"):
        try:
            bumpgrad.isa_force(isa)
        except bumpgrad.Error:
            continue
        check(bumpgrad.isa_active() == isa, f"isa_force({isa})")
        check(np.array_equal(bumpgrad.fbm3(p), base), f"{isa} differs")
    bumpgrad.isa_force(best)
    print(f"api: ISA best {best}, version {bumpgrad.__version__}")


def main():
    mode = sys.argv[1]
    if mode == "reference":
        test_reference()
    elif mode == "bounds":
        test_bounds()
    elif mode == "cli":
        test_cli(sys.argv[2])
    elif mode == "badinput":
        test_badinput()
    elif mode == "api":
        test_api(sys.argv[2])
    else:
        print("unknown mode", mode)
        return 2
    return finish(mode)


if __name__ == "__main__":
    sys.exit(main())
