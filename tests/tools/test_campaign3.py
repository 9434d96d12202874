# SPDX-License-Identifier: MIT
"""Outputs and environment under attack: the third campaign's findings.

Usage: test_campaign3.py BUMPGRAD_EXE [CASE ...]

Cases (all by default): obj_full, jpg_full, links, modes, env, sweep, long_names.
Each one failed before its fix (docs/RELIABILITY.md, "Third campaign"):
- obj_full: an .obj on a full disk (RLIMIT_FSIZE, SIGXFSZ ignored) replaced the
  old file with a truncated one and exited 0;
- jpg_full: libjpeg's exit(1) on a full disk left temporaries and no message;
- links: a planted link in a sticky folder to a FIFO or a device was written
  through (or blocked for ever); a FIFO of another user there too;
- modes: a replaced 0600/0755 output came back 0644;
- env: bad BUMPGRAD_* values were ignored or switched the cap off, a FIFO as
  BUMPGRAD_IO_MODULE hung;
- sweep: nested and short-form temporaries of a killed run were never removed;
- long_names: a legal 240-character output name failed;
- textures_under: BUMPGRAD_TEXTURES_UNDER=DIR refuses a material texture
  that resolves outside DIR ("../", absolute, a link), and keeps the ones inside;
- udim_race: two runs writing one UDIM set (and its .glb) at once could leave
  a mix of both, each exiting 0 (the renames are now made under one lock).
"""
import os
import resource
import signal
import stat
import subprocess
import sys
import tempfile

EXE = os.path.abspath(sys.argv[1])
CASES = sys.argv[2:] or ["obj_full", "jpg_full", "links", "modes", "env", "sweep", "long_names",
                         "udim_race", "textures_under"]
FAILURES = []
TAG = ".tmp-bumpgrad-"
# Under AddressSanitizer a child that runs out of its address space can hang
# in ASan's own report (its symbolizer lock) until BUMPGRAD_CHILD_TIMEOUT: the
# too-small BUMPGRAD_MESH_MAX_MB case is then checked for no hang only.
with open(EXE, "rb") as _f:
    ASAN = b"__asan_init" in _f.read()
ROUNDS = int(os.environ.get("C3_ROUNDS", "4"))


def check(cond, what):
    print(("ok: " if cond else "FAIL: ") + what)
    if not cond:
        FAILURES.append(what)


def run(args, cwd, limit=None, env=None, timeout=120):
    def pre():
        if limit is not None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    e = dict(os.environ, BUMPGRAD_NO_PROGRESS="1")
    e.update(env or {})
    try:
        return subprocess.run([EXE, "-q"] + args, preexec_fn=pre, cwd=cwd, env=e,
                              capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return subprocess.CompletedProcess(args, -999, "", "TIMED OUT")


def temps(d):
    return sorted(f for f in os.listdir(d) if TAG in f)


def write_obj(path, n):
    """A UV sphere with n x n quads (as triangles), positions, normals and UVs."""
    import math
    lines = []
    for i in range(n + 1):
        for j in range(n + 1):
            th, ph = math.pi * i / n, 2 * math.pi * j / n
            x, y, z = math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)
            lines.append(f"v {x:.6f} {y:.6f} {z:.6f}")
            lines.append(f"vn {x:.6f} {y:.6f} {z:.6f}")
            lines.append(f"vt {j / n:.6f} {i / n:.6f}")
    for i in range(n):
        for j in range(n):
            a, b = i * (n + 1) + j + 1, i * (n + 1) + j + 2
            c, d = a + n + 1, b + n + 1
            lines.append(f"f {a}/{a}/{a} {c}/{c}/{c} {b}/{b}/{b}")
            lines.append(f"f {b}/{b}/{b} {c}/{c}/{c} {d}/{d}/{d}")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def dead_pid():
    p = subprocess.Popen(["true"])
    p.wait()
    return p.pid


def full_disk(d, name, small, big, out, limit, words):
    r = run(small, d)
    check(r.returncode == 0, f"{name}: the small output is written ({r.stderr.strip()})")
    before = open(os.path.join(d, out), "rb").read()
    r = run(big, d, limit=limit)
    check(r.returncode != 0, f"{name}: a write past the limit fails (exit {r.returncode})")
    check(any(w in r.stderr for w in words) and out in r.stderr,
          f"{name}: a message names the output ({r.stderr.strip()[-200:]!r})")
    check(open(os.path.join(d, out), "rb").read() == before, f"{name}: the old output is kept")
    check(temps(d) == [], f"{name}: no temporary left ({temps(d)})")


def case_obj_full(d):
    write_obj(os.path.join(d, "small.obj"), 6)
    write_obj(os.path.join(d, "big.obj"), 60)
    full_disk(d, "mesh obj", ["mesh", "small.obj", "out.obj"], ["mesh", "big.obj", "out.obj"],
              "out.obj", 40960, ["cannot write", "failed"])


def case_jpg_full(d):
    full_disk(d, "render jpg", ["render", "--size", "8x8", "-o", "o.jpg"],
              ["render", "--size", "1024x1024", "-o", "o.jpg"], "o.jpg", 4096,
              ["cannot write", "failed"])
    # A bake's tile: the image writer is handed a temporary, and makes its own
    # nested one; neither is left, and the message names the user's file.
    write_obj(os.path.join(d, "m.obj"), 4)
    full_disk(d, "bake jpg", ["mesh", "m.obj", "--bake-normal-map", "n.jpg", "--size", "8"],
              ["mesh", "m.obj", "--bake-normal-map", "n.jpg", "--size", "1024"], "n.jpg", 4096,
              ["cannot write", "failed"])


def case_links(d):
    shared = os.path.join(d, "shared")
    os.mkdir(shared)
    os.chmod(shared, 0o1777)
    with open(os.path.join(d, "in.csv"), "w") as f:
        f.write("x,y,z\n1,2,3\n")
    fifo = os.path.join(shared, "fifo")
    os.mkfifo(fifo)
    evalo = ["eval", "--function", "noise", "-i", "in.csv", "-o"]
    # A link to a FIFO in a sticky folder: refused at once, never opened.
    os.symlink(fifo, os.path.join(shared, "out.csv"))
    r = run(evalo + ["shared/out.csv"], d, timeout=20)
    check(r.returncode not in (0, -999), f"link to a FIFO in a sticky folder: refused, no hang "
          f"(exit {r.returncode})")
    check("shared/out.csv" in r.stderr and "link" in r.stderr,
          f"... with a message naming it ({r.stderr.strip()!r})")
    check(os.path.islink(os.path.join(shared, "out.csv")), "... and the link is left alone")
    # A link to a device there: refused too (the data would go to the device).
    os.symlink("/dev/null", os.path.join(shared, "dev.csv"))
    r = run(evalo + ["shared/dev.csv"], d, timeout=20)
    check(r.returncode != 0 and "link" in r.stderr,
          f"link to a device in a sticky folder: refused ({r.returncode}, {r.stderr.strip()!r})")
    # The mesh PLY writer follows the same rule.
    write_obj(os.path.join(d, "m.obj"), 4)
    os.symlink(fifo, os.path.join(shared, "m.ply"))
    r = run(["mesh", "m.obj", "shared/m.ply"], d, timeout=20)
    check(r.returncode not in (0, -999), f"mesh PLY through a planted link: refused ({r.returncode})")
    # A link to a regular file is replaced, never written through.
    victim = os.path.join(d, "victim.csv")
    with open(victim, "w") as f:
        f.write("precious\n")
    os.symlink(victim, os.path.join(shared, "reg.csv"))
    r = run(evalo + ["shared/reg.csv"], d)
    check(r.returncode == 0 and open(victim).read() == "precious\n" and
          not os.path.islink(os.path.join(shared, "reg.csv")),
          "a link to a regular file is replaced by the output, its target untouched")
    # A FIFO of another user planted directly in a sticky folder (needs root to make).
    if os.geteuid() == 0:
        other = os.path.join(shared, "other.csv")
        os.mkfifo(other)
        os.chown(other, 65534, 65534)
        r = run(evalo + ["shared/other.csv"], d, timeout=20)
        check(r.returncode not in (0, -999) and "another user" in r.stderr,
              f"another user's FIFO in a sticky folder: refused ({r.returncode}, {r.stderr.strip()!r})")
    # What users name on purpose still works: /dev/null directly, /dev/stdout
    # (a link outside any sticky folder).
    r = run(evalo + ["/dev/null"], d)
    check(r.returncode == 0, f"-o /dev/null still works ({r.stderr.strip()!r})")
    r = run(evalo + ["/dev/stdout"], d)
    check(r.returncode == 0 and r.stdout.startswith("x,y,z"), f"-o /dev/stdout still works "
          f"({r.stderr.strip()!r})")
    check(stat.S_ISFIFO(os.stat(fifo).st_mode), "the FIFO is still a FIFO")


def case_modes(d):
    with open(os.path.join(d, "in.csv"), "w") as f:
        f.write("x,y,z\n1,2,3\n")
    write_obj(os.path.join(d, "m.obj"), 4)
    jobs = [("o.csv", ["eval", "--function", "noise", "-i", "in.csv", "-o", "o.csv"], 0o600),
            ("o.png", ["render", "--size", "8x8", "-o", "o.png"], 0o755),
            ("o.obj", ["mesh", "m.obj", "o.obj"], 0o600),
            ("o.ply", ["mesh", "m.obj", "o.ply"], 0o640)]
    for out, args, mode in jobs:
        r = run(args, d)
        check(r.returncode == 0, f"{out}: first write ({r.stderr.strip()!r})")
        os.chmod(os.path.join(d, out), mode)
        r = run(args, d)
        got = stat.S_IMODE(os.stat(os.path.join(d, out)).st_mode)
        check(r.returncode == 0 and got == mode, f"{out}: a replaced {oct(mode)} file keeps its mode "
              f"(now {oct(got)})")
    old = os.umask(0o027)
    try:
        r = run(jobs[0][1][:-1] + ["new.csv"], d)
    finally:
        os.umask(old)
    got = stat.S_IMODE(os.stat(os.path.join(d, "new.csv")).st_mode)
    check(got == 0o640, f"a new file gets 0666 & ~umask (umask 027: {oct(got)})")


def case_env(d):
    write_obj(os.path.join(d, "m.obj"), 4)
    render = ["render", "--size", "8x8", "-o", "o.png"]
    for var, value, args in [("BUMPGRAD_MAX_MB", "-1", render),
                             ("BUMPGRAD_MAX_MB", "abc", render),
                             ("BUMPGRAD_MAX_MB", "1e3", render),
                             ("BUMPGRAD_MAX_MB", str(2 ** 44), render),
                             ("BUMPGRAD_MAX_MB", " 12", render),
                             ("BUMPGRAD_MESH_MAX_MB", "1", ["mesh", "m.obj", "o.ply"]),
                             ("BUMPGRAD_MESH_MAX_MB", "-1", ["mesh", "m.obj", "o.ply"]),
                             ("BUMPGRAD_MESH_MAX_MB", str(2 ** 44), ["mesh", "m.obj", "o.ply"]),
                             ("BUMPGRAD_VDB_MAX_MB", "x", render),
                             ("BUMPGRAD_CHILD_TIMEOUT", "0", render),
                             ("BUMPGRAD_CHILD_TIMEOUT", "5s", render)]:
        if ASAN and var == "BUMPGRAD_MESH_MAX_MB" and value == "1":
            r = run(args, d, env={var: value, "BUMPGRAD_CHILD_TIMEOUT": "5"}, timeout=60)
            check(r.returncode != 0 and "not a readable" not in r.stderr,
                  f"{var}={value!r} under ASan: fails, not blaming the file ({r.returncode})")
            continue
        r = run(args, d, env={var: value}, timeout=60)
        check(r.returncode == 2 and var in r.stderr and "not a readable" not in r.stderr,
              f"{var}={value!r}: exit 2 naming the variable ({r.returncode}, {r.stderr.strip()!r})")
    for var, value, args in [("BUMPGRAD_MAX_MB", "0", render), ("BUMPGRAD_MAX_MB", "64", render),
                             ("BUMPGRAD_MESH_MAX_MB", "0", ["mesh", "m.obj", "o.ply"]),
                             ("BUMPGRAD_MESH_MAX_MB", "512", ["mesh", "m.obj", "o.ply"])]:
        r = run(args, d, env={var: value})
        check(r.returncode == 0, f"{var}={value}: accepted ({r.stderr.strip()!r})")
    fifo = os.path.join(d, "module.fifo")
    os.mkfifo(fifo)
    r = run(render, d, env={"BUMPGRAD_IO_MODULE": fifo}, timeout=20)
    check(r.returncode == 2 and "BUMPGRAD_IO_MODULE" in r.stderr,
          f"BUMPGRAD_IO_MODULE=a FIFO: no hang, exit 2 naming it ({r.returncode}, {r.stderr.strip()!r})")


def case_sweep(d):
    pid = dead_pid()
    stale = ["..o.jpg%s%d-abcdef.jpg%s%d-ghijkl.jpg" % (TAG, pid, TAG, pid),   # nested
             ".o.jpg%s%d-mnopqr.jpg" % (TAG, pid),                              # plain
             "%s%d-stuvwx.jpg" % (TAG, pid)]                                     # short form
    kept = [".other.jpg%s%d-abcdef.jpg" % (TAG, pid),                           # another target
            "..o.jpg%s%d-abcdef.jpg%s%d-ghijkl.jpg" % (TAG, os.getpid(), TAG, os.getpid())]
    for n in stale + kept:
        open(os.path.join(d, n), "w").close()
    r = run(["render", "--size", "8x8", "-o", "o.jpg"], d)
    check(r.returncode == 0, f"render o.jpg ({r.stderr.strip()!r})")
    now = set(os.listdir(d))
    for n in stale:
        check(n not in now, f"a dead run's temporary is removed: {n}")
    for n in kept:
        check(n in now, f"kept (another target, or a live run): {n}")


def case_long_names(d):
    with open(os.path.join(d, "in.csv"), "w") as f:
        f.write("x,y,z\n1,2,3\n")
    for ext, args in [(".csv", ["eval", "--function", "noise", "-i", "in.csv", "-o"]),
                      (".png", ["render", "--size", "8x8", "-o"])]:
        name = "n" * (240 - len(ext)) + ext
        for attempt in ("new", "replaced"):
            r = run(args + [name], d)
            check(r.returncode == 0 and os.path.isfile(os.path.join(d, name)),
                  f"a 240-character {ext} name ({attempt}): written ({r.stderr.strip()[-120:]!r})")
        check(temps(d) == [], f"... no temporary left ({temps(d)})")
    name = "n" * 251 + ".csv"
    r = run(["eval", "--function", "noise", "-i", "in.csv", "-o", name], d)
    check(r.returncode == 0, f"a 255-character name (the longest legal one): written "
          f"({r.stderr.strip()[-120:]!r})")


def write_tiles(path, tiles):
    """`tiles` unit quads, one inside each UDIM tile (1001 + u + 10 v)."""
    lines, faces = [], []
    for t in range(tiles):
        u, v = t % 10, t // 10
        base = 4 * t
        for k, (x, y) in enumerate([(0, 0), (1, 0), (1, 1), (0, 1)]):
            lines += [f"v {u + x} {v + y} 0", f"vt {u + 0.01 + 0.98 * x:.4f} {v + 0.01 + 0.98 * y:.4f}",
                      "vn 0 0 1"]
        a, b, c, e = base + 1, base + 2, base + 3, base + 4
        faces += [f"f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}", f"f {a}/{a}/{a} {c}/{c}/{c} {e}/{e}/{e}"]
    with open(path, "w") as f:
        f.write("\n".join(lines + faces) + "\n")


def case_udim_race(d):
    import fcntl
    import time
    tiles = 10
    write_tiles(os.path.join(d, "tiles.obj"), tiles)
    names = [f"t.{1001 + i % 10 + 10 * (i // 10)}.png" for i in range(tiles)] + ["o.glb"]
    def args(amp):
        return ["mesh", "tiles.obj", "o.glb", "--bake-normal-map", "t.<UDIM>.png", "--size", "16",
                "--padding", "0", "--amplitude", amp, "--octaves", "1"]
    def snapshot():
        return [open(os.path.join(d, n), "rb").read() for n in names]
    solo = {}
    for amp in ("0.1", "-0.3"):
        r = run(args(amp), d)
        check(r.returncode == 0, f"solo run, amplitude {amp} ({r.stderr.strip()!r})")
        solo[amp] = snapshot()
    check(all(x != y for x, y in zip(*solo.values())),
          "the two runs write different bytes to every file of the set")
    env = dict(os.environ, BUMPGRAD_NO_PROGRESS="1")
    # Deterministic: while another holder has the folder's lock, a run makes
    # its temporaries but renames nothing; it completes once the lock is free.
    fd = os.open(d, os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)
    p = subprocess.Popen([EXE, "-q"] + args("0.1"), cwd=d, env=env, stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE)
    for _ in range(400):
        if p.poll() is not None or len(temps(d)) >= tiles + 1:
            break
        time.sleep(0.05)
    time.sleep(0.3)
    check(p.poll() is None, "a run waits for the set's lock before renaming")
    check(snapshot() == solo["-0.3"], "... and meanwhile the old set is whole")
    fcntl.flock(fd, fcntl.LOCK_UN)
    os.close(fd)
    rc = p.wait(timeout=120)
    check(rc == 0 and snapshot() == solo["0.1"], f"... then puts its whole set in place (exit {rc})")
    # And a few rounds of two runs at once (the campaign saw 1 mix in 12).
    mixed = 0
    for _ in range(ROUNDS):
        ps = [subprocess.Popen([EXE, "-q"] + args(amp), cwd=d, env=env, stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE) for amp in ("0.1", "-0.3")]
        rcs = [q.wait(timeout=120) for q in ps]
        check(rcs == [0, 0], f"both concurrent runs succeed ({rcs})")
        got = snapshot()
        if got != solo["0.1"] and got != solo["-0.3"]:
            mixed += 1
    check(mixed == 0, f"every set is one run's, never a mix ({mixed} of {ROUNDS} rounds mixed)")
    check(temps(d) == [], f"no temporary left ({temps(d)})")

def case_textures_under(d):
    secret, meshes = os.path.join(d, "secret"), os.path.join(d, "meshes")
    os.makedirs(secret)
    os.makedirs(os.path.join(meshes, "m"))
    def ppm(path, rgb):
        with open(path, "wb") as f:
            f.write(b"P6 8 8 255\n" + bytes(rgb) * 64)
    ppm(os.path.join(secret, "s.ppm"), (230, 20, 20))
    ppm(os.path.join(meshes, "m", "ok.ppm"), (20, 230, 20))
    os.symlink(os.path.join(secret, "s.ppm"), os.path.join(meshes, "m", "link.ppm"))
    def quad(tex):
        with open(os.path.join(meshes, "m", "q.mtl"), "w") as f:
            f.write("newmtl a\nKd 1 1 1\nmap_Kd %s\n" % tex)
        with open(os.path.join(meshes, "m", "q.obj"), "w") as f:
            f.write("mtllib q.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\n"
                    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl a\nf 1/1/1 2/2/1 3/3/1 4/4/1\n")
    render = ["render", "--mesh", "meshes/m/q.obj", "--method", "none", "--size", "16x16",
              "-o", "o.png"]
    confined = {"BUMPGRAD_TEXTURES_UNDER": meshes}
    for tex, what in [("../../secret/s.ppm", "a ../ path"),
                      (os.path.join(secret, "s.ppm"), "an absolute path"),
                      ("link.ppm", "a link inside that points outside")]:
        quad(tex)
        r = run(render, d)
        check(r.returncode == 0, f"{what}: read without the variable, as renderers do ({r.stderr.strip()!r})")
        r = run(render, d, env=confined)
        check(r.returncode == 2 and "BUMPGRAD_TEXTURES_UNDER" in r.stderr and "s.ppm" in r.stderr,
              f"{what}: refused under BUMPGRAD_TEXTURES_UNDER ({r.returncode}, {r.stderr.strip()!r})")
    quad("ok.ppm")
    r = run(render, d, env=confined)
    check(r.returncode == 0, f"a texture inside the folder is used ({r.stderr.strip()!r})")
    r = run(render, d, env={"BUMPGRAD_TEXTURES_UNDER": os.path.join(d, "nosuch")})
    check(r.returncode == 2 and "BUMPGRAD_TEXTURES_UNDER" in r.stderr,
          f"BUMPGRAD_TEXTURES_UNDER naming no folder: exit 2 ({r.stderr.strip()!r})")


for case in CASES:
    print(f"== {case}")
    with tempfile.TemporaryDirectory() as d:
        globals()["case_" + case](d)

if FAILURES:
    print(f"{len(FAILURES)} failure(s)")
    sys.exit(1)
