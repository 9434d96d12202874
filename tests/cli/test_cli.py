# SPDX-License-Identifier: MIT
"""Tests of the `bumpgrad` command (eval, perturb, global options).

Usage: test_cli.py BUMPGRAD_EXE {main|eval|perturb|badinput|stream}

References are independent of the C code: Perlin's improved noise is written
again below in plain Python (double arithmetic in the reference's operation
order), gradients are checked against central differences of that Python noise,
and perturbed normals are recomputed with numpy from the formula of Mikkelsen
(2010), eq. 2 and 4. Nothing here compares against output saved from bumpgrad.
"""
import math
import os
import random
import re
import subprocess
import sys
import tempfile

import numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import QUIET, check, clean_env, finish, run as harness_run  # noqa: E402

EXE = os.path.abspath(sys.argv[1])
QUIET[0] = True


def run(args, stdin=None, env=None, cwd=None, stdout=subprocess.PIPE):
    return harness_run(EXE, args, stdin, env, cwd, stdout=stdout)


def env_clean(**extra):
    return clean_env(extra)


# ---- independent reference: Perlin's improved noise (2002), in Python doubles ----
PERM = [151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30,
        69, 142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94,
        252, 219, 203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171,
        168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122, 60,
        211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1,
        216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86,
        164, 100, 109, 198, 173, 186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118,
        126, 255, 82, 85, 212, 207, 206, 59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170,
        213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39,
        253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218, 246, 97, 228, 251, 34,
        242, 193, 238, 210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49,
        192, 214, 31, 181, 199, 106, 157, 184, 84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254,
        138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78, 66, 215, 61, 156, 180]
assert sorted(PERM) == list(range(256))
P = PERM + PERM


def _fade(t):
    return t * t * t * (t * (t * 6 - 15) + 10)


def _lerp(t, a, b):
    return a + t * (b - a)


def _grad(h, x, y, z):
    h &= 15
    u = x if h < 8 else y
    v = y if h < 4 else (x if h in (12, 14) else z)
    return (u if (h & 1) == 0 else -u) + (v if (h & 2) == 0 else -v)


def ref_noise(x, y, z):
    fx, fy, fz = math.floor(x), math.floor(y), math.floor(z)
    X, Y, Z = int(fx) & 255, int(fy) & 255, int(fz) & 255
    x -= fx
    y -= fy
    z -= fz
    u, v, w = _fade(x), _fade(y), _fade(z)
    A = P[X] + Y
    AA = P[A] + Z
    AB = P[A + 1] + Z
    B = P[X + 1] + Y
    BA = P[B] + Z
    BB = P[B + 1] + Z
    return _lerp(w, _lerp(v, _lerp(u, _grad(P[AA], x, y, z), _grad(P[BA], x - 1, y, z)),
                          _lerp(u, _grad(P[AB], x, y - 1, z), _grad(P[BB], x - 1, y - 1, z))),
                 _lerp(v, _lerp(u, _grad(P[AA + 1], x, y, z - 1), _grad(P[BA + 1], x - 1, y, z - 1)),
                       _lerp(u, _grad(P[AB + 1], x, y - 1, z - 1),
                             _grad(P[BB + 1], x - 1, y - 1, z - 1))))


def ref_fractal(kind, x, y, z, octaves=6, lac=2.0, gain=0.5):
    if kind == "noise":
        return ref_noise(x, y, z)
    s, amp, freq = 0.0, 1.0, 1.0
    for _ in range(octaves):
        n = ref_noise(x * freq, y * freq, z * freq)
        s += amp * (abs(n) if kind == "turbulence" else n)
        amp *= gain
        freq *= lac
    return s


def ref_grad_fd(kind, x, y, z, h=1e-6):
    """Gradient of the Python reference by central differences (independent of
    the analytic derivative in the C kernels)."""
    return ((ref_fractal(kind, x + h, y, z) - ref_fractal(kind, x - h, y, z)) / (2 * h),
            (ref_fractal(kind, x, y + h, z) - ref_fractal(kind, x, y - h, z)) / (2 * h),
            (ref_fractal(kind, x, y, z + h) - ref_fractal(kind, x, y, z - h)) / (2 * h))


# ---- helpers ----
def parse_table(text, ncols):
    lines = text.splitlines()
    rows = [ln.split(",") for ln in lines[1:]]
    for r in rows:
        assert len(r) == ncols, r
    return lines[0], rows


def points_f32(n, seed, lo=-20.0, hi=20.0):
    rng = np.random.default_rng(seed)
    # Values that are exactly floats, printed to round-trip, so the float and
    # double runs evaluate the same points.
    return rng.uniform(lo, hi, size=(n, 3)).astype(np.float32)


def csv_of(header, rows, fmt="%.17g"):
    # 17 digits: the text reads back to the same float32 with strtof and to the
    # same (float32-valued) double with strtod.
    return header + "\n" + "".join(",".join(fmt % float(v) for v in r) + "\n" for r in rows)


def eval_table(args, text, ncols=7):
    rc, out, err = run(["eval"] + args + ["-i", "-", "-o", "-"], stdin=text.encode())
    if not check(rc == 0, "eval %s: exit %d: %s" % (args, rc, err.strip())):
        return None, None
    header, rows = parse_table(out, ncols)
    return header, rows


def numbers(rows, dtype):
    """Parse output text in the precision it was printed from (float32 text must
    be read with float32 rounding to recover the printed float)."""
    return np.array([[dtype(t) for t in r] for r in rows], dtype=dtype).astype(np.float64)


# ---- main: global options, help, version, ISA control ----
X86 = ["scalar", "sse2", "avx2", "avx512"]


def test_main():
    rc, out, err = run(["--version"])
    m = re.match(r"^bumpgrad (\d+\.\d+\.\d+) \(isa: (\w+), best: (\w+)\)\n$", out)
    check(rc == 0 and m, "--version format: %r" % out)
    if not m:
        return
    active, best = m.group(2), m.group(3)
    check(active == best, "--version without BUMPGRAD_ISA runs at the best level")
    if best == "neon":
        usable, unusable = ["scalar", "neon"], X86[1:]
    else:
        usable = X86[:X86.index(best) + 1]
        unusable = X86[X86.index(best) + 1:] + ["neon"]

    for isa in usable:
        rc, out, err = run(["--isa", isa, "--version"])
        check(rc == 0 and "(isa: %s, best: %s)" % (isa, best) in out, "--isa %s: %r %r" % (isa, out, err))
        rc, out, err = run(["--version"], env=env_clean(BUMPGRAD_ISA=isa))
        check(rc == 0 and "(isa: %s," % isa in out, "BUMPGRAD_ISA=%s: %r %r" % (isa, out, err))
    for isa in unusable + ["avx9", "SSE2", ""]:
        if isa == "":
            continue
        rc, out, err = run(["--isa", isa, "--version"])
        check(rc == 2 and "this CPU has: " + ", ".join(usable) in err,
              "--isa %s must fail with exit 2 naming the usable levels: %d %r" % (isa, rc, err))
        rc, out, err = run(["--version"], env=env_clean(BUMPGRAD_ISA=isa))
        check(rc == 2 and "BUMPGRAD_ISA" in err and "this CPU has" in err,
              "BUMPGRAD_ISA=%s must fail with exit 2: %d %r" % (isa, rc, err))
    rc, out, err = run(["--isa"])
    check(rc == 2, "--isa without a value: exit 2")

    # Every ISA gives the same bits (the contract of the kernels); through the CLI.
    pts = points_f32(300, 7)
    text = csv_of("x,y,z", pts)
    outs = set()
    for isa in usable:
        rc, out, err = run(["--isa", isa, "eval", "--function", "turbulence", "-i", "-", "-o", "-"],
                           stdin=text.encode())
        check(rc == 0, "--isa %s eval: %s" % (isa, err))
        outs.add(out)
    check(len(outs) == 1, "eval output differs between ISA levels %s" % usable)

    # Help: top level, every listed command, `help CMD`.
    rc, out, err = run(["--help"])
    check(rc == 0 and out.startswith("Usage: bumpgrad"), "--help")
    cmds = []
    if "Commands:\n" in out:
        for ln in out.split("Commands:\n", 1)[1].splitlines():
            m = re.match(r"^  (\S+)\s+\S", ln)
            if not m:
                break
            cmds.append(m.group(1))
    check("eval" in cmds and "perturb" in cmds, "--help lists eval and perturb: %s" % cmds)
    for c in cmds:
        rc, out, err = run([c, "--help"])
        check(rc == 0 and c in out and len(out) > 100, "%s --help: exit %d %r" % (c, rc, err))
        rc2, out2, err2 = run(["help", c])
        check(rc2 == 0 and out2 == out, "help %s equals %s --help" % (c, c))
    for c in ("eval", "perturb"):
        rc, out, err = run([c, "--help"])
        check("Example" in out, "%s --help has examples" % c)
    rc, out, err = run(["help"])
    check(rc == 0 and "Commands:" in out, "help without a command")
    rc, out, err = run(["evl"])
    check(rc == 2 and 'unknown command "evl"' in err and '"eval"' in err,
          "unknown command with suggestion: %d %r" % (rc, err))
    rc, out, err = run(["frobnicate"])
    check(rc == 2 and "unknown command" in err, "unknown command: %d %r" % (rc, err))
    rc, out, err = run(["help", "frobnicate"])
    check(rc == 2 and "unknown command" in err, "help of an unknown command")
    rc, out, err = run([])
    check(rc == 2 and "Usage" in err, "no command: exit 2 with usage on stderr")
    rc, out, err = run(["--bogus"])
    check(rc == 2, "unknown global option: exit 2")
    rc, out, err = run(["eval", "--bogus", "-i", "-", "-o", "-"])
    check(rc == 2 and "--bogus" in err, "unknown eval option: exit 2")
    for opt, val in (("--octaves", "0"), ("--octaves", "33"), ("--octaves", "3x"),
                     ("--lacunarity", "nan"), ("--lacunarity", "-1"), ("--gain", "inf"),
                     ("--gain", ""), ("--step", "-1"), ("--precision", "half"),
                     ("--function", "perlin"), ("--gradient", "forward")):
        rc, out, err = run(["eval", opt, val, "-i", "-", "-o", "-"], stdin=b"x,y,z\n1,2,3\n")
        check(rc == 2 and opt in err and out == "", "eval %s %r: exit 2 naming the option (%d %r)"
              % (opt, val, rc, err))
    for opt, val in (("--amplitude", "nan"), ("--frequency", "0"), ("--method", "normal"),
                     ("--threads", "-1")):
        rc, out, err = run(["perturb", opt, val, "-i", "-", "-o", "-"],
                           stdin=b"x,y,z,nx,ny,nz\n1,2,3,0,0,1\n")
        check(rc == 2 and opt in err, "perturb %s %r: exit 2 (%d %r)" % (opt, val, rc, err))
    rc, out, err = run(["perturb", "--height-grid", "h.vdb:height", "-i", "-", "-o", "-"],
                       stdin=b"x,y,z,nx,ny,nz\n1,2,3,0,0,1\n")
    check(rc == 2 and "--height-grid" in err, "--height-grid without VDB support: exit 2 (%r)" % err)


# ---- eval ----
def test_eval():
    # Perlin's published value, exactly.
    hdr, rows = eval_table(["--precision", "double"], "x,y,z\n3.14,42,7\n")
    if rows:
        check(hdr == "x,y,z,value,dx,dy,dz", "eval header: %r" % hdr)
        check(float(rows[0][3]) == 0.13691995878400012,
              "double noise(3.14,42,7) == 0.13691995878400012, got %s" % rows[0][3])
        check(float(rows[0][0]) == 3.14, "x echoed exactly in double")

    pts = points_f32(400, 1)
    text = csv_of("x,y,z", pts)
    # Double: bit-exact against the Python transliteration for noise; fractal
    # sums in the same order, to 1e-12; gradient against central differences.
    for kind in ("noise", "fbm", "turbulence"):
        hdr, rows = eval_table(["--precision", "double", "--function", kind], text)
        if not rows:
            continue
        vals = numbers(rows, np.float64)
        ref = np.array([ref_fractal(kind, *map(float, p)) for p in pts])
        check(np.array_equal(vals[:, :3], pts.astype(np.float64)), "%s: echoed coordinates" % kind)
        err = np.max(np.abs(vals[:, 3] - ref))
        if kind == "noise":
            check(err == 0.0, "double noise bit-exact vs Python reference (max diff %g)" % err)
        else:
            check(err <= 1e-12, "double %s vs Python reference: %g" % (kind, err))
        if kind != "turbulence":  # turbulence has creases where differences fail
            fd = np.array([ref_grad_fd(kind, *map(float, p)) for p in pts[:150]])
            gerr = np.max(np.abs(vals[:150, 4:7] - fd))
            check(gerr <= 1e-6, "double %s analytic gradient vs reference differences: %g" % (kind, gerr))

    # Float within the documented bounds of the double result.
    _, rf = eval_table(["--function", "noise"], text)
    _, rd = eval_table(["--function", "noise", "--precision", "double"], text)
    if rf and rd:
        f = numbers(rf, np.float32)
        d = numbers(rd, np.float64)
        check(np.max(np.abs(f[:, 3] - d[:, 3])) <= 1e-5, "float value within 1e-5 of double: %g"
              % np.max(np.abs(f[:, 3] - d[:, 3])))
        check(np.max(np.abs(f[:, 4:] - d[:, 4:])) <= 5e-5, "float gradient within 5e-5 of double: %g"
              % np.max(np.abs(f[:, 4:] - d[:, 4:])))

    # Central differences close to the analytic gradient (noise and fbm are smooth).
    # Tolerances sit ~3x above the errors measured with the default step
    # (BG_DEFAULT_CENTRAL_STEP, tuned for 6-octave sums in float) and with
    # explicit steps; a wrong divisor or a step not passed through is off by O(1).
    for kind, prec, extra, tol in (("noise", "float", [], 1e-2),
                                   ("noise", "float", ["--step", "2e-3"], 2e-3),
                                   ("noise", "double", [], 1e-5),
                                   ("fbm", "float", [], 1e-2),
                                   ("fbm", "double", [], 3e-3),
                                   ("fbm", "double", ["--step", "1e-5"], 1e-4)):
        _, ra = eval_table(["--function", kind, "--precision", prec] + extra, text)
        _, rc_ = eval_table(["--function", kind, "--precision", prec, "--gradient", "central"]
                            + extra, text)
        if ra and rc_:
            dt = np.float32 if prec == "float" else np.float64
            a = numbers(ra, dt)
            c = numbers(rc_, dt)
            check(np.array_equal(a[:, 3], c[:, 3]), "%s %s: central keeps the same value" % (kind, prec))
            e = np.max(np.abs(a[:, 4:] - c[:, 4:]))
            check(e <= tol, "%s %s central vs analytic gradient: %g > %g" % (kind, prec, e, tol))
    # A step that is far too big must show (the test of the test: central really
    # uses --step).
    _, ra = eval_table(["--function", "noise"], text)
    _, rc_ = eval_table(["--function", "noise", "--gradient", "central", "--step", "0.5"], text)
    if ra and rc_:
        a = numbers(ra, np.float32)
        c = numbers(rc_, np.float32)
        check(np.max(np.abs(a[:, 4:] - c[:, 4:])) > 0.05, "--step 0.5 changes the central gradient")

    # Round-trip formatting: every number re-formats to itself in its precision,
    # and the echoed input is the input value in that precision.
    tricky = ["0.1", "-0", "1e-40", "123456789.123", "3.4028234e38", "-2.5e-7", "7", "1e30",
              "0x1p-3", "  4.25 "]
    text2 = "x,y,z\n" + "".join("%s,%s,0.5\n" % (a, b) for a in tricky for b in ("0.3", "-1.75"))
    def num(s):
        s = s.strip()
        return float.fromhex(s) if "0x" in s else float(s)
    for prec, fmt, conv in (("float", "%.9g", lambda s: float(np.float32(num(s)))),
                            ("double", "%.17g", num)):
        _, rows = eval_table(["--precision", prec], text2)
        if not rows:
            continue
        ok = True
        for r in rows:
            for t in r:
                v = float(t)
                if prec == "float":
                    v = float(np.float32(t))
                ok &= (fmt % v) == t
        check(ok, "%s output re-formats to the same text (round trip)" % prec)
        xs = [conv(a) for a in tricky for _ in (0, 1)]
        check(len(rows) == len(xs) and all(conv(r[0]) == x for r, x in zip(rows, xs)),
              "%s: echoed x equals the parsed input" % prec)
        check(rows[2][0] == "-0", "%s: -0 keeps its sign: %r" % (prec, rows[2][0]))

    # CRLF, spaces, no final newline and trailing blank lines give the same result.
    clean = "x,y,z\n1.5,2.5,3.5\n-0.25,0.75,9\n"
    messy = "x , y,z\r\n 1.5,2.5 ,3.5\r\n-0.25,\t0.75,9\r\n\r\n\n"
    nofinal = "x,y,z\n1.5,2.5,3.5\n-0.25,0.75,9"
    bom = "\ufeffx,y,z\n1.5,2.5,3.5\n-0.25,0.75,9\n"
    r0 = run(["eval", "-i", "-", "-o", "-"], stdin=clean.encode())
    for name, t in (("crlf+spaces", messy), ("no final newline", nofinal), ("BOM", bom)):
        r1 = run(["eval", "-i", "-", "-o", "-"], stdin=t.encode())
        check(r1[0] == 0 and r1[1] == r0[1], "%s accepted with the same output (%r)" % (name, r1[2]))
    rc, out, err = run(["eval", "-i", "-", "-o", "-"], stdin=b"x,y,z\n")
    check(rc == 0 and out == "x,y,z,value,dx,dy,dz\n", "header-only input gives header-only output")
    rc, out, err = run(["eval", "--allow-nonfinite", "-i", "-", "-o", "-"], stdin=b"x,y,z\nnan,1,2\ninf,0,0\n")
    check(rc == 0 and out.count("nan") >= 6, "--allow-nonfinite: NaN results (%r)" % out)

    # Files and stdin/stdout give the same bytes; threads do not change results.
    with tempfile.TemporaryDirectory() as d:
        inp, outp = os.path.join(d, "in.csv"), os.path.join(d, "out.csv")
        big = csv_of("x,y,z", points_f32(20000, 3))
        with open(inp, "w") as fh:
            fh.write(big)
        rc, _, err = run(["eval", "--function", "fbm", "--threads", "1", "-i", inp, "-o", outp])
        check(rc == 0, "eval file to file: %s" % err)
        with open(outp) as fh:
            filed = fh.read()
        rc, piped, err = run(["eval", "--function", "fbm", "--threads", "2", "-i", "-", "-o", "-"],
                             stdin=big.encode())
        check(rc == 0 and piped == filed, "stdin/stdout and 2 threads give the same output as files")
        check(filed.count("\n") == 20001, "20000 rows out")
        check(sorted(os.listdir(d)) == ["in.csv", "out.csv"], "no temporary files left: %s" % os.listdir(d))
        # Output to a full device is an I/O failure (exit 1).
        if os.path.exists("/dev/full"):
            with open("/dev/full", "wb") as full:
                rc, _, err = run(["eval", "-i", inp, "-o", "-"], stdout=full)
            check(rc == 1 and "error" in err, "write error on stdout: exit 1 (%d %r)" % (rc, err))


# ---- perturb ----
def normalize(v):
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_perturb():
    rng = np.random.default_rng(5)
    n = 3000
    p = rng.uniform(-8, 8, size=(n, 3)).astype(np.float32)
    nrm = rng.normal(size=(n, 3)) * rng.uniform(0.1, 10, size=(n, 1))  # not unit length
    nrm = nrm.astype(np.float32)
    nrm[0] = 0  # the "no normal" sentinel
    nrm[1] = (0, 0, 3)
    table = np.hstack([p, nrm])
    text = csv_of("x,y,z,nx,ny,nz", table)

    amp, freq = np.float32(0.1), np.float32(2.0)
    # The height gradient from `eval`: g = (A f) F'(f p), with f p exact (f = 2).
    q = (p * freq).astype(np.float32)
    _, ev = eval_table(["--function", "turbulence"], csv_of("x,y,z", q))
    if not ev:
        return
    ev = numbers(ev, np.float32)
    af = np.float32(amp * freq)
    g = (af * ev[:, 4:7].astype(np.float32)).astype(np.float64)
    hval = (amp * ev[:, 3].astype(np.float32)).astype(np.float64)
    nn = np.zeros((n, 3))
    nn[1:] = normalize(nrm[1:].astype(np.float64))

    def perturb(method, extra=()):
        rc, out, err = run(["perturb", "--method", method, "--frequency", "2"] + list(extra)
                           + ["-i", "-", "-o", "-"], stdin=text.encode())
        if not check(rc == 0, "perturb %s: %d %s" % (method, rc, err)):
            return None
        hdr, rows = parse_table(out, 11)
        check(hdr == "x,y,z,nx,ny,nz,height,px,py,pz,inward", "perturb header %r" % hdr)
        return numbers(rows, np.float32)

    expect = {
        # eq. 2 and 4: n' = normalize(n - (g - n (n.g)))
        "surfgrad": lambda: n_ - (g - n_ * np.sum(n_ * g, axis=1, keepdims=True)),
        "additive": lambda: n_ - g,
        "additive-perlin": lambda: n_ + g,
    }
    for method in ("surfgrad", "additive", "additive-perlin"):
        for amp_arg in (None, "3"):
            extra = () if amp_arg is None else ("--amplitude", amp_arg)
            out = perturb(method, extra)
            if out is None:
                continue
            scale = 1.0 if amp_arg is None else float(np.float32(3) * freq) / float(af)
            g_saved = g
            g = g_saved * scale
            n_ = nn
            s = expect[method]()
            g = g_saved
            check(np.array_equal(out[:, :6], table.astype(np.float64)), "%s: input echoed" % method)
            if amp_arg is None:
                check(np.max(np.abs(out[:, 6] - hval)) <= 1e-6, "%s: height column = A F(f p)" % method)
            pn = out[:, 7:10]
            valid = np.arange(n) > 0
            lens = np.linalg.norm(pn, axis=1)
            check(np.all(np.abs(lens[valid] - 1) <= 1e-5), "%s: unit normals (max dev %g)"
                  % (method, np.max(np.abs(lens[valid] - 1))))
            check(np.all(pn[0] == 0) and out[0, 10] == 1, "%s: zero normal -> (0,0,0), inward 1" % method)
            slen = np.linalg.norm(s, axis=1)
            ok = valid & (slen > 0.1)  # well-conditioned rows of the normalization
            ref = s[ok] / slen[ok, None]
            err = np.max(np.abs(pn[ok] - ref))
            check(err <= 2e-5, "%s amp %s: normals vs numpy recomputation from eval's gradient: %g"
                  % (method, amp_arg, err))
            dots = np.sum(pn * nn, axis=1)
            flags = out[:, 10]
            clear = valid & (np.abs(dots) > 1e-4)
            check(np.array_equal(flags[clear] == 1, dots[clear] <= 0),
                  "%s: inward flags agree with dot(n', n) <= 0" % method)
            refdot = np.sum(ref * nn[ok], axis=1)
            sure = np.abs(refdot) > 1e-3
            check(np.array_equal(flags[ok][sure] == 1, refdot[sure] <= 0),
                  "%s: inward flags agree with the numpy recomputation" % method)
            if method == "surfgrad":
                check(np.all(flags[valid] == 0), "surfgrad never points inward (amp %s)" % amp_arg)
            elif amp_arg == "3":
                check(np.sum(flags[valid]) > 10, "%s with amplitude 3 points inward somewhere (%d rows)"
                      % (method, np.sum(flags[valid])))

    # Threads and the central-difference path.
    r1 = run(["perturb", "--threads", "1", "-i", "-", "-o", "-"], stdin=text.encode())
    r2 = run(["perturb", "--threads", "2", "-i", "-", "-o", "-"], stdin=text.encode())
    check(r1[0] == 0 and r1[1] == r2[1], "perturb output independent of --threads")
    # fbm: turbulence has creases where central differences legitimately differ.
    out_c = perturb("surfgrad", ("--function", "fbm", "--octaves", "3", "--gradient", "central"))
    out_a = perturb("surfgrad", ("--function", "fbm", "--octaves", "3"))
    if out_c is not None and out_a is not None:
        d = np.max(np.abs(out_c[1:, 7:10] - out_a[1:, 7:10]))
        check(0 < d <= 0.05, "central-difference normals close to analytic ones: %g" % d)


# ---- bad input ----
def test_badinput():
    sentinel = b"previous output, must survive\n"
    eval_cases = [
        # (name, input bytes, expected line, expected column, message part)
        ("empty", b"", 1, 1, "empty input"),
        ("wrong header", b"a,b,c\n1,2,3\n", 1, 1, "header"),
        ("missing header", b"1,2,3\n", 1, 1, "header"),
        # (Extra columns are passed through since issue 12; a missing one is an error
        # at the end of the header line.)
        ("header missing a column", b"x,y,w\n1,2,3\n", 1, 6, "header"),
        ("mapped row too short", b"id,x,y,z\n1,2,3\n", 2, 6, "expected 4 fields, got 3"),
        ("too few fields", b"x,y,z\n1,2,3\n1,2\n", 3, 4, "expected 3 fields, got 2"),
        ("too many fields", b"x,y,z\n1,2,3,4\n", 2, 7, "expected 3 fields, got 4"),
        ("not a number", b"x,y,z\n1,2,3\n0.5,abc,1\n", 3, 5, '"abc"'),
        ("trailing junk", b"x,y,z\n1,2,3x\n", 2, 5, '"3x"'),
        ("empty field", b"x,y,z\n1,,3\n", 2, 3, "expected a number"),
        ("nan", b"x,y,z\n1,2,nan\n", 2, 5, "non-finite"),
        ("inf", b"x,y,z\n-inf,2,3\n", 2, 1, "non-finite"),
        ("overflow", b"x,y,z\n1,1e999,3\n", 2, 3, "out of the range"),
        ("float overflow", b"x,y,z\n1,2,1e39\n", 2, 5, "float"),
        ("blank line inside", b"x,y,z\n1,2,3\n\n4,5,6\n", 3, 1, "blank line"),
        ("blank line after header", b"x,y,z\r\n  \r\n4,5,6\r\n", 2, 1, "blank line"),
        ("NUL byte", b"x,y,z\n1,2\x00,3\n", 2, 3, "expected a number"),
        # strtod skips these before a number; as after one, they are errors.
        ("leading vertical tab", b"x,y,z\n1,\x0b2,3\n", 2, 3, "expected a number"),
        ("leading form feed", b"x,y,z\n1,2,\x0c3\n", 2, 5, "expected a number"),
        ("leading carriage return", b"x,y,z\n\r1,2,3\n", 2, 1, "expected a number"),
        ("line over 65536 bytes", b"x,y,z\n1,2,3" + b" " * 65532 + b"\n", 2, 1,
         "longer than 65536 bytes"),
        ("late error", b"x,y,z\n" + b"0.5,0.25,0.125\n" * 20000 + b"1,x,3\n", 20002, 3, '"x"'),
    ]
    perturb_cases = [
        ("empty", b"", 1, 1, "empty input"),
        ("eval header", b"x,y,z\n1,2,3\n", 1, 6, "header"),
        ("five fields", b"x,y,z,nx,ny,nz\n1,2,3,0,0\n", 2, 10, "expected 6 fields, got 5"),
        ("bad normal", b"x,y,z,nx,ny,nz\n1,2,3,0,0,up\n", 2, 11, '"up"'),
        ("nan normal", b"x,y,z,nx,ny,nz\n1,2,3,0,NaN,1\n", 2, 9, "non-finite"),
        ("blank line", b"x,y,z,nx,ny,nz\n1,2,3,0,0,1\n\n1,2,3,0,0,1\n", 3, 1, "blank line"),
    ]
    with tempfile.TemporaryDirectory() as d:
        inp, outp = os.path.join(d, "in.csv"), os.path.join(d, "out.csv")
        for cmd, cases, extra in (("eval", eval_cases, []), ("perturb", perturb_cases, []),
                                  ("eval", eval_cases[9:12], ["--precision", "double"])):
            for name, data, line, col, part in cases:
                with open(inp, "wb") as fh:
                    fh.write(data)
                with open(outp, "wb") as fh:
                    fh.write(sentinel)
                rc, out, err = run([cmd] + extra + ["-i", inp, "-o", outp])
                loc = "%s:%d:%d:" % (inp, line, col)
                check(rc == 2, "%s %s: exit 2, got %d" % (cmd, name, rc))
                check(loc in err and part in err and "bumpgrad %s: error:" % cmd in err,
                      "%s %s: message with %s and %r, got %r" % (cmd, name, loc, part, err.strip()))
                with open(outp, "rb") as fh:
                    check(fh.read() == sentinel, "%s %s: existing output untouched" % (cmd, name))
                check(sorted(os.listdir(d)) == ["in.csv", "out.csv"],
                      "%s %s: no stray files: %s" % (cmd, name, os.listdir(d)))
                # The same through stdin: named <stdin>, nothing on stdout.
                rc, out, err = run([cmd] + extra + ["-i", "-", "-o", "-"], stdin=data)
                # (Rows before the error may already be on stdout: a stream cannot
                # be taken back; the exit status says the output is incomplete.)
                check(rc == 2 and "<stdin>:%d:%d:" % (line, col) in err,
                      "%s %s via stdin: %d %r" % (cmd, name, rc, err.strip()))
            # A new output file is not created on failure.
            newp = os.path.join(d, "new.csv")
            with open(inp, "wb") as fh:
                fh.write(cases[1][1])
            rc, _, _ = run([cmd] + extra + ["-i", inp, "-o", newp])
            check(rc == 2 and not os.path.exists(newp), "%s: no output created on bad input" % cmd)
        os.unlink(inp)
        # --allow-nonfinite accepts what the strict mode rejects (and only that).
        with open(inp, "wb") as fh:
            fh.write(b"x,y,z\n1,2,nan\n-inf,1,1\n")
        rc, _, err = run(["eval", "--allow-nonfinite", "-i", inp, "-o", outp])
        check(rc == 0, "--allow-nonfinite accepts nan/inf: %r" % err)
        with open(inp, "wb") as fh:
            fh.write(b"x,y,z\n1,2,1e999\n")
        rc, _, err = run(["eval", "--allow-nonfinite", "--precision", "double", "-i", inp, "-o", outp])
        check(rc == 2, "--allow-nonfinite still rejects an overflowing literal")
        os.unlink(outp)
        # Missing input: exit 2 naming the file; no output created.
        missing = os.path.join(d, "nosuch.csv")
        for cmd in ("eval", "perturb"):
            rc, _, err = run([cmd, "-i", missing, "-o", outp])
            check(rc == 2 and missing in err and not os.path.exists(outp),
                  "%s: missing input -> exit 2 naming it (%d %r)" % (cmd, rc, err))
            rc, _, err = run([cmd, "-i", d, "-o", outp])
            check(rc == 2 and not os.path.exists(outp), "%s: directory as input -> exit 2" % cmd)
            rc, _, err = run([cmd, "-o", outp])
            check(rc == 2 and "--input" in err, "%s: --input required" % cmd)
        # Unwritable output: I/O failure, exit 1, nothing created.
        with open(inp, "wb") as fh:
            fh.write(b"x,y,z,nx,ny,nz\n1,2,3,0,0,1\n")
        bad_out = os.path.join(d, "no-such-dir", "out.csv")
        rc, _, err = run(["perturb", "-i", inp, "-o", bad_out])
        check(rc == 1 and bad_out in err, "unwritable output -> exit 1 naming it (%d %r)" % (rc, err))
        rc, _, err = run(["perturb", "-i", inp, "-o", d])
        check(rc == 1 and sorted(os.listdir(d)) == ["in.csv"],
              "output path is a directory -> exit 1, no temp left (%d %r %s)" % (rc, err, os.listdir(d)))
        if os.geteuid() != 0:
            ro = os.path.join(d, "ro")
            os.mkdir(ro, 0o555)
            rc, _, err = run(["perturb", "-i", inp, "-o", os.path.join(ro, "o.csv")])
            check(rc == 1 and os.listdir(ro) == [], "read-only folder -> exit 1")
            os.chmod(ro, 0o755)
    # Text on a full stdout (summaries, stats, help) is a failure, not exit 0.
    if os.path.exists("/dev/full"):
        for args in (["eval", "--help"], ["--version"], ["--help"], ["help", "eval"], ["help"]):
            with open("/dev/full", "wb") as full:
                rc, _, err = run(args, stdout=full)
            check(rc == 1 and "standard output" in err,
                  "%s with stdout on /dev/full: exit 1 (%d %r)" % (" ".join(args), rc, err))
    # An empty output name is a usage error (it was exit 1, "writing  failed").
    for cmd, data in (("eval", b"x,y,z\n1,2,3\n"), ("perturb", b"x,y,z,nx,ny,nz\n1,2,3,0,0,1\n")):
        rc, out, err = run([cmd, "-i", "-", "-o", ""], stdin=data)
        check(rc == 2 and "output file name is empty" in err,
              "%s -o '': exit 2 with a message (%d %r)" % (cmd, rc, err.strip()))
    # bench --kernels: a list that selects nothing, or a misspelt peer operation,
    # is a usage error rather than an empty table with exit 0.
    for kern in ("", ",", "peer:glm:bar", "peer:libnoise:"):
        rc, out, err = run(["bench", "--kernels", kern, "--samples", "4", "--runs", "1",
                            "--threads", "1"])
        check(rc == 2 and "--kernels" in err and out == "",
              "bench --kernels %r: exit 2 naming the option (%d %r)" % (kern, rc, err.strip()))


# ---- streaming in constant memory ----
def test_line_limit():
    # A line of exactly the documented 65536 bytes is accepted, with "\n" or "\r\n".
    for nl in (b"\n", b"\r\n"):
        row = b"1,2,3" + b" " * (65536 - 5)
        rc, out, err = run(["eval", "--function", "noise", "-i", "-", "-o", "-"],
                           stdin=b"x,y,z" + nl + row + nl)
        check(rc == 0 and len(out.splitlines()) == 2,
              f"a 65536-byte line ending in {nl!r} is accepted (rc {rc}: {err.strip()})")


def test_stream():
    rows = 1_000_000
    with tempfile.TemporaryDirectory() as d:
        inp, outp = os.path.join(d, "in.csv"), os.path.join(d, "out.csv")
        with open(inp, "w") as fh:
            fh.write("x,y,z\n")
            line = "%.3f,0.5,%.2f\n"
            chunk = []
            for i in range(rows):
                chunk.append(line % (i * 0.001, (i % 1000) * 0.25))
                if len(chunk) == 100000:
                    fh.write("".join(chunk))
                    chunk = []
            fh.write("".join(chunk))
        # ru_maxrss survives fork and exec on Linux, so a child started directly
        # from this (numpy-sized) interpreter would report our own memory. A small
        # helper interpreter without numpy starts bumpgrad and reports the peak of
        # its children: max(helper at fork, bumpgrad).
        helper = ("import resource, subprocess, sys\n"
                  "r = subprocess.run(sys.argv[1:], stderr=subprocess.PIPE)\n"
                  "sys.stderr.write(r.stderr.decode(errors='replace'))\n"
                  "print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n")
        def peak(src):
            p = subprocess.run([sys.executable, "-S", "-c", helper, EXE, "eval", "--function",
                                "noise", "--threads", "1", "-i", src, "-o", outp],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env_clean(),
                               timeout=120)
            fields = p.stdout.split()
            rc, kb = (int(fields[0]), int(fields[1])) if len(fields) == 2 else (-1, 0)
            check(rc == 0, "eval of %s: exit %d %r" % (src, rc, p.stderr))
            return kb / 1024.0  # ru_maxrss is in kilobytes on Linux
        tiny = os.path.join(d, "tiny.csv")
        with open(tiny, "w") as fh:
            fh.write("x,y,z\n1,2,3\n")
        # The program's own footprint (its text and data: 26 MB in a -O0
        # ASan build, 7 MB in a release one) is measured on a one-row input and
        # taken off, so that the check is about the rows.
        base_mb = peak(tiny)
        os.remove(tiny)
        peak_mb = peak(inp)
        print("1M rows: peak RSS %.1f MB, one row: %.1f MB" % (peak_mb, base_mb))
        # Holding the rows would need >= 28 MB for the 7 float columns alone, plus
        # the text; a streaming run needs a few MB.
        check(0 < base_mb and peak_mb - base_mb < 12,
              "1M rows stream in constant memory: peak RSS %.1f MB, %.1f MB above one row's"
              % (peak_mb, peak_mb - base_mb))
        n = 0
        last = b""
        with open(outp, "rb") as fh:
            while True:
                b = fh.read(1 << 20)
                if not b:
                    break
                n += b.count(b"\n")
                last = (last + b)[-200:]
        check(n == rows + 1, "1M rows in, %d lines out" % n)
        lastrow = last.rstrip(b"\n").split(b"\n")[-1].split(b",")
        check(np.float32(lastrow[0].decode()) == np.float32("%.3f" % ((rows - 1) * 0.001)),
              "last row is the last input point")
        x, y, z = (float(np.float32(t)) for t in ("999.999", "0.5", "249.75"))
        check(abs(float(lastrow[3]) - ref_noise(x, y, z)) <= 1e-5, "last row value vs reference")
        check(sorted(os.listdir(d)) == ["in.csv", "out.csv"], "no temporary files left")


TESTS = {"main": test_main, "eval": test_eval, "perturb": test_perturb,
         "badinput": lambda: (test_badinput(), test_line_limit()), "stream": test_stream}

if __name__ == "__main__":
    TESTS[sys.argv[2]]()
    sys.exit(finish("cli " + sys.argv[2]))
