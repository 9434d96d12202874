# SPDX-License-Identifier: MIT
"""The one option parser (src/cli/args.c) and what main.c does around it:
--opt=value, `--`, global options anywhere, the messages, the generated help,
completions and man pages, and --progress on a pipe.

Usage: test_args.py BUMPGRAD_EXE {syntax|csv|json|npy|help|generated|progress|tools|render_mesh}
"""
import os
import shutil
import subprocess
import sys
import tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import QUIET, check, finish, run as harness_run  # noqa: E402

EXE = os.path.abspath(sys.argv[1])
QUIET[0] = True


def run(args, stdin=None, env_extra=None, cwd=None):
    return harness_run(EXE, args, stdin, env_extra, cwd)

PTS = b"x,y,z\n0.5,1.25,2\n3.5,-1,0.125\n"


def syntax():
    ref = run(["eval", "--function", "fbm", "--octaves", "3", "-i", "-", "-o", "-"], PTS)
    check(ref[0] == 0 and ref[1].count("\n") == 3, "eval reference run: %r" % (ref,))
    for args in (["--function=fbm", "--octaves=3", "-i", "-", "-o", "-"],
                 ["--function=fbm", "--octaves", "3", "--input=-", "--output=-"],
                 ["--function", "fbm", "--octaves=3", "-i-", "-o-"],
                 ["-q", "--function=fbm", "--isa=scalar", "--octaves=3", "-i", "-", "-o", "-"],
                 ["--function=fbm", "-v", "--octaves=3", "-i", "-", "-o", "-", "--quiet"]):
        rc, out, err = run(["eval"] + args, PTS)
        check(rc == 0 and out == ref[1], "eval %s equals the --opt value run (%d %r)"
              % (args, rc, err))
    # --isa after the command is the global option: a bad level is refused by main.
    rc, out, err = run(["eval", "-i", "-", "-o", "-", "--isa", "nosuchisa"], PTS)
    check(rc == 2 and "unknown ISA level" in err, "--isa after the command: %d %r" % (rc, err))
    rc, out, err = run(["eval", "-i", "-", "-o", "-", "--bogus=1"], PTS)
    check(rc == 2 and 'unknown option "--bogus" (see bumpgrad eval --help)' in err,
          "unknown --bogus=1: %d %r" % (rc, err))
    rc, out, err = run(["perturb", "-i", "-", "-o"])
    check(rc == 2 and "-o needs a value" in err, "missing value: %d %r" % (rc, err))
    rc, out, err = run(["eval", "--allow-nonfinite=1", "-i", "-", "-o", "-"], PTS)
    check(rc == 2 and "takes no value" in err, "flag with a value: %d %r" % (rc, err))
    rc, out, err = run(["eval", "-i", "-", "-o", "-", "--", "--function"], PTS)
    check(rc == 2 and 'unexpected argument "--function"' in err, "-- ends options: %d %r" % (rc, err))
    rc, out, err = run(["eval", "--function=fbmx", "-i", "-", "-o", "-"], PTS)
    check(rc == 2 and '--function: expected noise, fbm or turbulence, got "fbmx"' in err,
          "bad choice: %d %r" % (rc, err))
    rc, out, err = run(["eval", "-o", "-"], PTS)
    check(rc == 2 and "--input is required" in err, "required: %d %r" % (rc, err))
    # A command not yet on the table parser gets --name=value split by main.c.
    # (bench exists in every build; render and mesh only with the tools.)
    rc, out, err = run(["bench", "--bogus-option=1"])
    check(rc == 2 and "--bogus-option" in err and "=1" not in err,
          "bench --x=1 split before dispatch: %d %r" % (rc, err))


def help_():
    rc, out, err = run(["accuracy", "--help"])
    check(rc == 0 and out.startswith("Usage: bumpgrad accuracy "), "accuracy --help usage line")
    amp = [ln for ln in out.splitlines() if ln.strip().startswith("--amplitude")]
    frq = [ln for ln in out.splitlines() if ln.strip().startswith("--frequency")]
    check(len(amp) == 1 and "(default 0.05)" in amp[0], "accuracy: one amplitude default 0.05: %r"
          % amp)
    check(len(frq) == 1 and "(default 4)" in frq[0], "accuracy: one frequency default 4: %r" % frq)
    check("default 0.1)" not in out, "accuracy --help shows no second amplitude default")
    rc, out, _ = run(["perturb", "--help"])
    amp = [ln for ln in out.splitlines() if ln.strip().startswith("--amplitude")]
    check(len(amp) == 1 and "(default 0.1)" in amp[0], "perturb amplitude default 0.1: %r" % amp)
    for c in ["eval", "perturb", "accuracy", "stability"]:
        rc, out, err = run([c, "--help"])
        check(rc == 0 and out.startswith("Usage: bumpgrad %s" % c), "%s --help: Usage:" % c)
        rc2, out2, _ = run(["help", c])
        check(rc2 == 0 and out2 == out, "help %s equals %s --help" % (c, c))


def generated():
    rc, bash, err = run(["completion", "bash"])
    check(rc == 0 and "complete -o filenames -F _bumpgrad bumpgrad" in bash, "bash completion")
    rc, out, err = run(["--help"])
    cmds = [ln.split()[0] for ln in out.split("Commands:\n")[1].split("\n\n")[0].splitlines()]
    for c in cmds:
        check((" %s" % c) in bash, "bash completion names %s" % c)
    for o in ("--lacunarity", "--height-grid", "--allow-nonfinite", "--no-chart"):
        check(o in bash, "bash completion has %s" % o)
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "bumpgrad")
        with open(path, "w") as f:
            f.write(bash)
        p = subprocess.run(["bash", "-n", path], capture_output=True)
        check(p.returncode == 0, "bash -n accepts the completion: %r" % p.stderr)
        # Drive the function as bash would.
        script = ("source %s; COMP_WORDS=(bumpgrad -q perturb --method ''); COMP_CWORD=4; "
                  "_bumpgrad; echo \"${COMPREPLY[@]}\"" % path)
        p = subprocess.run(["bash", "-c", script], capture_output=True, text=True)
        check(p.stdout.split() == ["surfgrad", "additive", "additive-perlin"],
              "bash completes --method values: %r" % p.stdout)
    rc, zsh, err = run(["completion", "zsh"])
    check(rc == 0 and zsh.startswith("#compdef bumpgrad") and "--octaves=" in zsh, "zsh completion")
    if shutil.which("zsh"):
        p = subprocess.run(["zsh", "-n"], input=zsh, capture_output=True, text=True)
        check(p.returncode == 0, "zsh -n: %r" % p.stderr)
    rc, out, err = run(["completion", "fish"])
    check(rc == 2, "completion fish refused")
    pages = [[]] + [[c] for c in ["eval", "perturb", "accuracy", "stability"]]
    for page in pages:
        rc, man, err = run(["man"] + page)
        check(rc == 0 and man.startswith(".TH BUMPGRAD"), "man %s" % page)
        if shutil.which("groff"):
            p = subprocess.run(["groff", "-man", "-Tutf8", "-ww", "-z"], input=man,
                               capture_output=True, text=True)
            check(p.returncode == 0 and p.stderr == "", "groff -ww on man %s: %r" % (page, p.stderr))
    rc, out, err = run(["man", "nosuchcommand"])
    check(rc == 2, "man of an unknown command refused")


def progress():
    # 100k rows: several blocks; --progress forces the lines onto a pipe.
    rows = b"".join(b"%d.25,%d.5,0.75\n" % (i % 997, i % 13) for i in range(100000))
    with tempfile.TemporaryDirectory() as d:
        inp = os.path.join(d, "p.csv")
        with open(inp, "wb") as f:
            f.write(b"x,y,z\n" + rows)
        outp = os.path.join(d, "o.csv")
        rc, out, err = run(["eval", "--progress", "-i", inp, "-o", outp],
                           env_extra={"BUMPGRAD_NO_PROGRESS": "1"})
        check(rc == 0, "eval --progress: %d %r" % (rc, err))
        lines = [ln for ln in err.splitlines() if ln.startswith("eval:")]
        check(lines and "\r" not in err, "progress lines on a pipe, no carriage return: %r" % err)
        check(any("rows/s" in ln and "100000 rows" in ln for ln in lines),
              "final progress line counts rows with a unit: %r" % lines)
        rc, out, err = run(["eval", "-i", inp, "-o", outp])
        check(rc == 0 and err == "", "no progress on a pipe by default: %r" % err)
        rc, out, err = run(["eval", "--progress", "-q", "-i", inp, "-o", outp])
        check(rc == 0 and err == "", "--quiet wins over --progress: %r" % err)
        rc, out, err = run(["-v", "eval", "-i", inp, "-o", outp])
        check(rc == 0 and "rows/s" in err, "-v gives the final rate: %r" % err)


def tools():
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "v.vdb")
        rc, so, err = run(["volume", "--voxel-size=0.1", "--output=" + out])
        check(rc == 0 and "9261 active voxels" in so, "volume default box -1..1 at 0.1: %d %r %r"
              % (rc, so, err))
        rc, so, err = run(["volume", "--voxel-size", "0.1", "--band-sphere", "5,5,5,0.1,0.01",
                           "-o", out])
        check(rc == 0 and "warning" in err and "no voxel" in err, "volume empty band warns: %r" % err)
        rc, so, err = run(["-q", "volume", "--voxel-size", "0.1", "-o", out])
        check(rc == 0 and so == "" and err == "", "volume -q prints nothing: %r %r" % (so, err))
        rc, so, err = run(["volume", "-o", "-"])
        check(rc == 2 and "stream" in err, "volume -o - refused: %r" % err)
        rc, so, err = run(["heightmap", "-", os.path.join(d, "n.png")], b"not an image")
        check(rc == 2 and "not supported" not in err and "error" in err,
              "heightmap - reads stdin (garbage there is bad input): %r" % err)
        rc, so, err = run(["volume", "--json", "--voxel-size", "0.25", "--band-sphere",
                           "0,0,0,0.5,0.25", "--function=fbm", "-o", out])
        j = json_check(so, "volume --json")
        check(rc == 0 and j.get("active_voxels", 0) > 0 and
              j.get("parameters", {}).get("height", {}).get("function") == "fbm",
              "volume json: %r" % j)
        # --height-grid that no point reaches: a warning with the count.
        rc, so, err = run(["perturb", "--height-grid", out, "-i", "-", "-o", "-"],
                          b"x,y,z,nx,ny,nz\n10,10,10,0,0,1\n11,10,10,0,0,1\n")
        check(rc == 0 and "warning" in err and "none of the 2 points" in err,
              "perturb --height-grid missing every point warns: %r" % err)
        rc, so, err = run(["perturb", "--height-grid", out, "-i", "-", "-o", "-"],
                          b"x,y,z,nx,ny,nz\n0.5,0,0,1,0,0\n11,10,10,0,0,1\n")
        check(rc == 0 and "warning" not in err, "a point in the grid: no warning: %r" % err)
        hm_in = os.path.join(d, "h.png")
        with open(hm_in, "wb") as f:
            # 2x2 8-bit gray PNG
            import struct
            import zlib
            def chunk(t, data):
                c = struct.pack(">I", len(data)) + t + data
                return c + struct.pack(">I", zlib.crc32(t + data) & 0xffffffff)
            raw = b"\x00\x00\x80\x00\xff\x40"
            f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 0, 0, 0, 0))
                    + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
        rc, so, err = run(["heightmap", hm_in, os.path.join(d, "n.png"), "--json", "--strength=2"])
        j = json_check(so, "heightmap --json")
        check(rc == 0 and j.get("parameters", {}).get("strength") == 2, "heightmap json: %r %r"
              % (j, err))
        rc, so, err = run(["volume", "--help"])
        check("(default -1,-1,-1,1,1,1)" in so and "(default 0.02)" in so,
              "volume --help says its default box and voxel size")


def csv():
    plain = b"x,y,z\n0.5,1.25,2\n3.5,-1,0.125\n"
    rc, ref, err = run(["eval", "--function", "fbm", "-i", "-", "-o", "-"], plain)
    check(rc == 0, "plain eval: %r" % err)
    ref_rows = [ln.split(",") for ln in ref.splitlines()[1:]]
    mapped = (b'"ID", "Z" ,Y,x,Extra,note\n'
              b'p1,2,1.25,0.5,abc,"a,""b"""\n'
              b'p2,0.125,-1,3.5,,\n')
    for prec in ("float", "double"):
        rc, refp, _ = run(["eval", "--precision", prec, "-i", "-", "-o", "-"], plain)
        rc, out, err = run(["eval", "--precision", prec, "-i", "-", "-o", "-"], mapped)
        lines = out.splitlines()
        check(rc == 0 and lines[0] == '"ID",x,y,z,value,dx,dy,dz,Extra,note',
              "mapped header (%s): %r %r" % (prec, lines[:1], err))
        want = [r.split(",") for r in refp.splitlines()[1:]]
        got = [ln.split(",") for ln in lines[1:]]
        check(len(got) == 2 and got[0][1:8] == want[0] and got[1][1:8] == want[1],
              "mapped columns give the values of the plain table (%s): %r" % (prec, got))
        check(lines[1].startswith("p1,") and lines[1].endswith(',abc,"a,""b"""') and
              lines[2].startswith("p2,") and lines[2].endswith(",,"),
              "id first and extra columns passed through unchanged: %r" % lines[1:])
    rc, out, err = run(["eval", "--function", "fbm", "-i", "-", "-o", "-"],
                       b"X,Y,Z\n0.5,1.25,2\n3.5,-1,0.125\n")
    check(rc == 0 and out == ref, "X,Y,Z equals x,y,z")
    rc, out, err = run(["perturb", "-i", "-", "-o", "-"],
                       b"nz,ny,nx,z,y,x,id\n1,0,0,0.1,0.2,0.3,a\n")
    rc2, out2, _ = run(["perturb", "-i", "-", "-o", "-"], b"x,y,z,nx,ny,nz\n0.3,0.2,0.1,0,0,1\n")
    check(rc == 0 and out.splitlines()[1] == "a," + out2.splitlines()[1],
          "perturb with columns in any order and an id: %r %r" % (out, err))
    for data, loc, part in ((b"x,y\n1,2\n", "<stdin>:1:4:", 'no column "z"'),
                            (b"x,y,z,x\n1,2,3,4\n", "<stdin>:1:7:", "twice"),
                            (b"a,x,y,z\nq,1,2\n", "<stdin>:2:6:", "expected 4 fields, got 3"),
                            (b"a,x,y,z\nq,1,2,3,4\n", "<stdin>:2:9:", "expected 4 fields, got 5"),
                            (b"a,x,y,z\nq,1,2x,3\n", "<stdin>:2:5:", '"2x"'),
                            (b'"x",y,"q\n1,2,3\n', "<stdin>:1:", "header")):
        rc, out, err = run(["eval", "-i", "-", "-o", "-"], data)
        check(rc == 2 and loc in err and part in err, "bad mapped input %r: %d %r" % (data, rc, err))
        check("\\x22" not in err, "a quote shows as a quote: %r" % err)


def json_check(text, what):
    p = subprocess.run(["/usr/bin/python3", "-m", "json.tool"], input=text, capture_output=True,
                       text=True)
    check(p.returncode == 0, "%s: python3 -m json.tool accepts it: %r" % (what, p.stderr))
    import json
    try:
        return json.loads(text)
    except ValueError:
        return {}


def json_():
    with tempfile.TemporaryDirectory() as d:
        # A file name that needs escaping: quote, backslash, tab, newline.
        inp = os.path.join(d, 'in "q" \\ \t\n.csv')
        with open(inp, "wb") as f:
            f.write(b"id,x,y,z,nx,ny,nz\n1,0.3,0.2,0.1,0,0,1\n2,1,2,3,0,1,0\n3,0,0,0,0,0,0\n")
        outp = os.path.join(d, "o.csv")
        rc, out, err = run(["perturb", "--json", "--method=additive", "--amplitude=2",
                            "-i", inp, "-o", outp])
        check(rc == 0, "perturb --json: %d %r" % (rc, err))
        j = json_check(out, "perturb --json")
        with open(outp) as f:
            inward = sum(ln.rstrip().endswith(",1") for ln in f.readlines()[1:])
        check(j.get("rows") == 3 and j.get("inward") == inward and j.get("command") == "perturb",
              "perturb json counts: %r (inward in the table: %d)" % (j, inward))
        par = j.get("parameters", {})
        check(par.get("input") == inp and par.get("method") == "additive" and
              par.get("height", {}).get("amplitude") == 2 and "isa" in j,
              "perturb json parameters (escaped file name read back): %r" % par)
        with open(inp, "wb") as f:
            f.write(b"x,y,z\n1,2,3\n4,5,6\n")
        rc, out, err = run(["eval", "--json", "--precision=double", "-i", inp, "-o", outp])
        j = json_check(out, "eval --json")
        check(rc == 0 and j.get("rows") == 2 and
              j.get("parameters", {}).get("precision") == "double", "eval json: %r" % j)
        rc, out, err = run(["eval", "--json", "-i", inp, "-o", "-"])
        check(rc == 2 and "--json" in err, "eval --json -o - refused: %r" % err)


def npy():
    import numpy as np
    rng = np.random.default_rng(12)
    with tempfile.TemporaryDirectory() as d:
        a32 = rng.uniform(-8, 8, size=(9000, 3)).astype(np.float32)
        a64 = rng.uniform(-8, 8, size=(9000, 3))
        np.save(os.path.join(d, "a32.npy"), a32)
        np.save(os.path.join(d, "a64.npy"), a64)
        for name, arr, prec, fmt in (("a32", a32, "float", "%.9g"), ("a64", a64, "double", "%.17g"),
                                     ("a32", a32, "double", "%.17g")):
            csvp = os.path.join(d, name + ".csv")
            with open(csvp, "w") as f:
                f.write("x,y,z\n")
                np.savetxt(f, arr, fmt=fmt, delimiter=",")
            outn, outc = os.path.join(d, "o.NPY"), os.path.join(d, "o.csv")
            rc1, _, e1 = run(["eval", "--precision", prec, "--function=turbulence", "-i",
                              os.path.join(d, name + ".npy"), "-o", outn])
            rc2, _, e2 = run(["eval", "--precision", prec, "--function=turbulence", "-i", csvp,
                              "-o", outc])
            check(rc1 == 0 and rc2 == 0, "eval .npy (%s, %s): %r %r" % (name, prec, e1, e2))
            o = np.load(outn)
            c = np.loadtxt(outc, delimiter=",", skiprows=1)
            dt = np.float64 if prec == "double" else np.float32
            check(o.dtype == dt and o.shape == (len(arr), 7), "npy output %s %s" % (o.dtype, o.shape))
            check(np.array_equal(o, c.astype(dt)), "npy output equals the CSV output (%s, %s)"
                  % (name, prec))
        n = np.concatenate([a32, np.tile(np.float32([0, 0, 1]), (len(a32), 1))], axis=1)
        np.save(os.path.join(d, "n.npy"), n)
        rc, _, err = run(["perturb", "--method", "additive", "--amplitude", "3", "-i",
                          os.path.join(d, "n.npy"), "-o", os.path.join(d, "p.npy")])
        p = np.load(os.path.join(d, "p.npy"))
        check(rc == 0 and p.shape == (len(n), 11) and np.array_equal(p[:, :6], n) and
              set(np.unique(p[:, 10])) <= {0.0, 1.0}, "perturb .npy: %r %s" % (err, p.shape))
        cases = [("be.npy", a32.astype(">f4"), "byte 20:", "dtype"),
                 ("two.npy", a32[:, :2].copy(), "byte", "expected 3 columns"),
                 ("fortran.npy", np.asfortranarray(a32), "byte", "Fortran"),
                 ("int.npy", np.zeros((4, 3), np.int32), "byte", "dtype")]
        nan = a32.copy()
        nan[5, 2] = np.nan
        cases.append(("nan.npy", nan, "byte %d:" % (128 + (5 * 3 + 2) * 4), "non-finite"))
        for fname, arr, where, part in cases:
            path = os.path.join(d, fname)
            np.save(path, arr)
            rc, _, err = run(["eval", "-i", path, "-o", os.path.join(d, "x.npy")])
            check(rc == 2 and (path + ": " + where) in err and part in err,
                  "bad .npy %s: %d %r" % (fname, rc, err))
        with open(os.path.join(d, "a32.npy"), "rb") as f:
            data = f.read()
        for cut, what in ((len(data) - 6, "truncated"), (5, "magic")):
            path = os.path.join(d, "cut.npy")
            with open(path, "wb") as f:
                f.write(data[:cut])
            rc, _, err = run(["eval", "-i", path, "-o", os.path.join(d, "x.npy")])
            check(rc == 2 and path + ": byte" in err and what in err, "cut .npy: %r" % err)
        check(not os.path.exists(os.path.join(d, "x.npy")), "no output after bad .npy input")


QUAD_OBJ = (b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
            b"vn 0 0 1\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n")


def render_mesh():
    """render and mesh on the table parser: --opt=value, `--`, short forms, the
    generated help with its defaults, completions and man pages."""
    with tempfile.TemporaryDirectory() as d:
        a, b = os.path.join(d, "a.png"), os.path.join(d, "b.png")
        rc1, o1, e1 = run(["render", "--size", "16x16", "--method", "additive", "--light",
                           "-3,2,1", "--output", a])
        rc2, o2, e2 = run(["render", "--size=16x16", "--method=additive", "--light=-3,2,1",
                           "-o" + b])
        check(rc1 == 0 and rc2 == 0 and o1.replace(a, "X") == o2.replace(b, "X") and
              open(a, "rb").read() == open(b, "rb").read(),
              "render --opt=value equals --opt value: %r %r %r %r" % (o1, o2, e1, e2))
        rc, o, e = run(["render", "--size=16x16", "-o", a, "--", "--sweep"])
        check(rc == 2 and 'unexpected argument "--sweep"' in e, "render: -- ends options: %r" % e)
        rc, o, e = run(["render", "--size=16x16", "-o", a, "--scene=cube"])
        check(rc == 2 and '--scene: expected sphere, blob or torus, got "cube"' in e,
              "render --scene=cube: %r" % e)
        rc, o, e = run(["render", "--size", "16x16", "--zoom=0", "-o", a])
        check(rc == 2 and '--zoom: must be > 0, got "0"' in e, "render --zoom=0: %r" % e)
        rc, o, e = run(["render", "--size=16x16"])
        check(rc == 2 and "--output FILE is required" in e, "render without --output: %r" % e)
        # The preset is applied first wherever it stands; options override it.
        rc1, o1, _ = run(["render", "--size=16x16", "--preset=fig2", "-o", a])
        rc2, o2, _ = run(["render", "--preset", "fig2", "--size", "16x16", "-o", a])
        rc3, o3, _ = run(["render", "--preset", "fig2", "--size", "16x16", "--amplitude=0.1",
                          "-o", a])
        rc4, o4, _ = run(["render", "--amplitude=0.1", "--size", "16x16", "--preset", "fig2",
                          "-o", a])
        check(rc1 == 0 and o1 == o2 and "amplitude=0.4" in o1 and "amplitude=0.1" in o3 and
              o4 == o3, "render --preset anywhere, options before or after override it: %r %r %r"
              % (o1, o3, o4))

        # An input whose name starts with "-", given after `--` (relative to d).
        quad = "-quad.obj"
        with open(os.path.join(d, quad), "wb") as f:
            f.write(QUAD_OBJ)
        p1, p2 = os.path.join(d, "1.ply"), os.path.join(d, "2.ply")

        def summary(text, path):  # the timings differ from run to run
            return [ln.replace(path, "X") for ln in text.splitlines() if not ln.startswith("time:")]
        rc1, o1, e1 = run(["mesh", "--compare", "--amplitude", "0.5", "--join", "never", "--",
                           quad, p1], cwd=d)
        rc2, o2, e2 = run(["mesh", "--compare", "--amplitude=0.5", "--join=never", "--", quad,
                           p2], cwd=d)
        check(rc1 == 0 and rc2 == 0 and summary(o1, p1) == summary(o2, p2) and
              "6 vertices" in o1 and open(p1, "rb").read() == open(p2, "rb").read(),
              "mesh --opt=value and -- before an input named -quad.obj: %r %r" % (o1, e1))
        rc, o, e = run(["mesh", quad, p1], cwd=d)
        check(rc == 2 and 'unknown option "-quad.obj"' in e,
              "mesh without --: -quad.obj is an option: %r" % e)
        quad = os.path.join(d, quad)
        n1 = os.path.join(d, "n.png")
        rc, o, e = run(["mesh", "--bake-normal-map=" + n1, "--size=8x4", "--normal-map-y=-y",
                        "--padding=1", "--", quad])
        check(rc == 0 and "bake: %s 8x4 tangent space" % n1 in o and "green -y" in o,
              "mesh bake options as --opt=value: %r %r" % (o, e))
        rc, o, e = run(["-q", "mesh", "--", quad, p1])
        rc2, o2, e2 = run(["mesh", "--quiet", "--", quad, p1])
        check(rc == 0 and rc2 == 0 and o == "" and o2 == "" and e == "" and e2 == "",
              "mesh -q and --quiet print nothing: %r %r" % (o, o2))
        rc, o, e = run(["mesh", "--join=sometimes", "--", quad, p1])
        check(rc == 2 and '--join: expected auto, always or never, got "sometimes"' in e,
              "mesh --join=sometimes: %r" % e)
        rc, o, e = run(["mesh", "--", quad, p1, p2])
        check(rc == 2 and "unexpected argument" in e, "mesh: a third positional: %r" % e)

    for c, shorts, defaults in (("render", ["-o, --output"], ["(default 384x384)", "(default 48)",
                                                              "(default surfgrad)",
                                                              "(default -5,4,3)",
                                                              "(default 0.06)"]),
                                ("mesh", [], ["(default 16)", "(default tangent)",
                                              "(default mikktspace)", "(default +y)",
                                              "(default 0.1)"])):
        rc, out, err = run([c, "--help"])
        check(rc == 0 and out.startswith("Usage: bumpgrad %s [options] " % c), "%s --help: usage" % c)
        check("usage:" not in out, "%s --help: one usage style" % c)
        for s in shorts:
            check(s in out, "%s --help lists the short form %s" % (c, s))
        for dflt in defaults:
            check(dflt in out, "%s --help shows %s" % (c, dflt))
        amp = [ln for ln in out.splitlines() if ln.strip().startswith("--amplitude")]
        check(len(amp) == 1, "%s --help: one --amplitude line: %r" % (c, amp))
        rc2, out2, _ = run(["help", c])
        check(rc2 == 0 and out2 == out, "help %s equals %s --help" % (c, c))
        rc, man, err = run(["man", c])
        check(rc == 0 and man.startswith(".TH BUMPGRAD-%s 1" % c), "man %s: %r" % (c, err))
        if shutil.which("groff"):
            p = subprocess.run(["groff", "-man", "-Tutf8", "-ww", "-z"], input=man,
                               capture_output=True, text=True)
            check(p.returncode == 0 and p.stderr == "", "groff -ww on man %s: %r" % (c, p.stderr))

    rc, bash, err = run(["completion", "bash"])
    for c, opts in (("render", ["--tex-amplitude", "--fail-above", "--preset", "-o"]),
                    ("mesh", ["--bake-normal-map", "--normal-map-y", "--recompute-normals"])):
        block = bash.split("\n    %s)\n" % c)
        check(len(block) == 2, "bash completion has a %s entry" % c)
        if len(block) == 2:
            section = block[1].split("fi;;")[0]
            words = section.split('compgen -W "$globals --help')[-1].split('"')[0].split()
            for o in opts + ["--amplitude", "--height-grid"]:
                check(o in words, "bash completion of %s offers %s: %r" % (c, o, words))
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "bumpgrad")
        with open(path, "w") as f:
            f.write(bash)
        for words, want in ((["render", "--scene", "''"], ["sphere", "blob", "torus"]),
                            (["render", "--preset", "''"], ["fig1", "fig2", "fig3", "fig4"]),
                            (["mesh", "--join", "''"], ["auto", "always", "never"]),
                            (["mesh", "--bake-depth", "''"], ["8", "16", "half", "float"])):
            script = ("source %s; COMP_WORDS=(bumpgrad %s); COMP_CWORD=%d; _bumpgrad; "
                      "echo \"${COMPREPLY[@]}\"" % (path, " ".join(words), len(words)))
            p = subprocess.run(["bash", "-c", script], capture_output=True, text=True)
            check(p.stdout.split() == want, "bash completes %s: %r" % (words[:2], p.stdout))
    rc, zsh, err = run(["completion", "zsh"])
    for c, o in (("render", "--heat-max="), ("mesh", "--bake-depth=")):
        check(("\n    %s)\n" % c) in zsh and o in zsh.split("\n    %s)\n" % c)[-1].split(";;")[0],
              "zsh completion of %s offers %s" % (c, o))


{"syntax": syntax, "csv": csv, "json": json_, "npy": npy, "help": help_, "generated": generated, "progress": progress,
 "tools": tools, "render_mesh": render_mesh}[sys.argv[2]]()
sys.exit(finish("cli_args " + sys.argv[2]))
