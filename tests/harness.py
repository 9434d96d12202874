# SPDX-License-Identifier: MIT
"""The one harness of the Python tests: checks that print and count, the
bumpgrad command run with a clean environment, and the exit status.

A test in tests/AREA/ starts with

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    from harness import FAILURES, check, finish, run

and ends with `sys.exit(finish("name"))`.
"""
import os
import subprocess

FAILURES = []   # what failed, in order
PASSED = [0]    # how many checks passed
QUIET = [False]  # True: print failures only


def check(cond, what):
    """One check: prints "ok: WHAT" or "FAIL: WHAT" and counts; returns cond."""
    if cond:
        PASSED[0] += 1
        if not QUIET[0]:
            print("ok:", what, flush=True)
    else:
        FAILURES.append(what)
        print("FAIL:", what, flush=True)
    return cond


def clean_env(extra=None):
    """os.environ without BUMPGRAD_ISA (a forced ISA must not leak into a test
    that does not ask for one), plus EXTRA's entries."""
    env = dict(os.environ)
    env.pop("BUMPGRAD_ISA", None)
    env.update(extra or {})
    return env


def run(exe, args, stdin=None, env=None, cwd=None, timeout=120, preexec_fn=None, text=True,
        stdout=subprocess.PIPE):
    """Runs [exe] + args with clean_env(env); stdin as bytes or str. Returns
    (returncode, stdout, stderr), decoded unless text is False; stdout may
    name a file object instead of the pipe (stdout is then "")."""
    if isinstance(stdin, str):
        stdin = stdin.encode()
    p = subprocess.run([exe] + list(args), input=stdin, stdout=stdout, stderr=subprocess.PIPE,
                       env=clean_env(env), cwd=cwd, timeout=timeout, preexec_fn=preexec_fn)
    out = p.stdout if p.stdout is not None else b""
    if not text:
        return p.returncode, out, p.stderr
    return (p.returncode, out.decode(errors="replace"),
            p.stderr.decode(errors="replace"))


def eval_points(exe, pts, precision, args, tmp):
    """`bumpgrad eval` over the points PTS (N x 3) in PRECISION ("float" or
    "double"), one thread, with the extra ARGS, through CSV files in TMP,
    the coordinates written to read back exactly (%.9g, %.17g). Returns the
    value column and the N x 3 gradient, float32 for "float"."""
    import numpy as np
    fmt = "%.9g" if precision == "float" else "%.17g"
    inp = os.path.join(tmp, "in.csv")
    out = os.path.join(tmp, "out.csv")
    with open(inp, "w") as f:
        f.write("x,y,z\n")
        for q in pts:
            f.write(",".join(fmt % c for c in q) + "\n")
    subprocess.run([exe, "eval", "--precision", precision, "--threads", "1", "-i", inp, "-o", out]
                   + list(args), check=True)
    t = np.loadtxt(out, delimiter=",", skiprows=1, dtype=np.float64)
    if precision == "float":
        t = t.astype(np.float32)
    return t[:, 3], t[:, 4:7]


def two_quads(d, left, right, names=("left", "right"), right_first=False):
    """A mesh fixture for the material tests: d/two.obj, two unit quads side
    by side facing +z, the left one in material names[0] (map_Kd `left`), the
    right one in names[1] (map_Kd `right`), paths written as given; with
    right_first, the right face comes first in the file. Returns the path."""
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "two.mtl"), "w") as f:
        f.write("newmtl %s\nKd 1 1 1\nmap_Kd %s\nnewmtl %s\nKd 1 1 1\nmap_Kd %s\n"
                % (names[0], left, names[1], right))
    faces = ["usemtl %s\nf 1/1/1 2/2/1 3/3/1 4/4/1\n" % names[0],
             "usemtl %s\nf 2/1/1 5/2/1 6/3/1 3/4/1\n" % names[1]]
    if right_first:
        faces.reverse()
    mesh = os.path.join(d, "two.obj")
    with open(mesh, "w") as f:
        f.write("mtllib two.mtl\nv -1 -0.5 0\nv 0 -0.5 0\nv 0 0.5 0\nv -1 0.5 0\nv 1 -0.5 0\n"
                "v 1 0.5 0\nvn 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n" + "".join(faces))
    return mesh


def ppm_header(data):
    """(width, height, maxval, offset of the pixels) of a binary PPM (P6) in
    DATA, comments in the header skipped."""
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    assert fields[0] == b"P6", fields
    return int(fields[1]), int(fields[2]), int(fields[3]), pos + 1


def finish(name):
    """The verdict line; the exit status for sys.exit."""
    if FAILURES:
        print("%s: %d check(s) FAILED (%d passed)" % (name, len(FAILURES), PASSED[0]), flush=True)
        return 1
    print("%s: all %d checks passed" % (name, PASSED[0]), flush=True)
    return 0
