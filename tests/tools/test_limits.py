# SPDX-License-Identifier: MIT
"""Nothing hung, nothing unbounded (issue 13): every input-driven allocation is
checked against the one cap (BUMPGRAD_MAX_MB, default 4096) before it happens,
child processes time out (BUMPGRAD_CHILD_TIMEOUT) and die with their parent,
FIFO inputs are refused instead of blocking, and OpenVDB's refusal of a tiny
voxel is not reported as "out of memory".

Usage: test_limits.py BUMPGRAD_EXE
"""
import os
import signal
import struct
import subprocess
import sys
import tempfile
import time

EXE = os.path.abspath(sys.argv[1])
FAILURES = []


def check(cond, what):
    print(("ok: " if cond else "FAIL: ") + what)
    if not cond:
        FAILURES.append(what)


def run(args, cwd, timeout=120, **env):
    e = dict(os.environ, BUMPGRAD_NO_PROGRESS="1", **env)
    t0 = time.monotonic()
    r = subprocess.run([EXE] + args, cwd=cwd, env=e, capture_output=True, text=True, timeout=timeout)
    return r.returncode, r.stderr, time.monotonic() - t0


def peak_rss_mb(args, cwd):
    """Run and return (rc, stderr, peak RSS of the process in MiB)."""
    p = subprocess.Popen([EXE] + args, cwd=cwd, stderr=subprocess.PIPE, text=True,
                         env=dict(os.environ, BUMPGRAD_NO_PROGRESS="1"))
    _, status, ru = os.wait4(p.pid, 0)
    err = p.stderr.read()
    return os.waitstatus_to_exitcode(status), err, ru.ru_maxrss / 1024.0


with tempfile.TemporaryDirectory() as d:
    # A tiny TGA that declares 28018 x 65535 pixels (22 GB as floats): refused
    # from its header, in little memory.
    tga = struct.pack("<BBBHHBHHHHBB", 0, 0, 2, 0, 0, 0, 0, 0, 28018, 65535, 24, 0) + b"\0" * 400
    with open(os.path.join(d, "huge.tga"), "wb") as f:
        f.write(tga)
    rc, err, rss = peak_rss_mb(["heightmap", "huge.tga", "n.png"], d)
    check(rc == 2 and "cap" in err, f"declared 28018x65535 image refused (rc {rc}: {err.strip()})")
    check(rss < 1024, f"... without allocating it (peak RSS {rss:.0f} MiB)")

    rc, err, _ = run(["render", "--size", "16384x16384", "--spp", "256", "-o", "x.png"], d)
    check(rc == 2 and "cap" in err, f"a 16384^2 x 256 spp render is refused up front ({err.strip()})")
    rc, err, _ = run(["render", "--size", "512x512", "-o", "x.png"], d, BUMPGRAD_MAX_MB="1")
    check(rc == 2 and "BUMPGRAD_MAX_MB" in err, "the cap is BUMPGRAD_MAX_MB's")
    rc, err, _ = run(["render", "--size", "64x64", "-o", "x.png"], d)
    check(rc == 0, "... and the default lets a normal render through")

    # One voxel thick: 5e7 voxels under the voxel limit, but ~6.5 GB of leaves.
    rc, err, _ = run(["volume", "--function", "noise", "--bbox", "0,0,0,70.7,70.7,0",
                      "--voxel-size", "0.01", "-o", "v.vdb"], d)
    check(rc == 2 and "cap" in err, f"a one-voxel-thick box is judged by its leaves ({err.strip()})")
    rc, err, _ = run(["volume", "--function", "noise", "--bbox", "0,0,0,0.0001,0.0001,0.0001",
                      "--voxel-size", "1e-5", "-o", "v.vdb"], d)
    check(rc == 2 and "out of memory" not in err and "voxel" in err,
          f"OpenVDB's refusal of a tiny voxel is named as such ({err.strip()})")

    # A PLY header without end_header: assimp loops forever in the import child.
    with open(os.path.join(d, "h.ply"), "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n")
    rc, err, dt = run(["mesh", "h.ply", "o.ply"], d, timeout=60, BUMPGRAD_CHILD_TIMEOUT="2")
    check(rc == 2 and "took more than 2 s" in err and dt < 30,
          f"a hanging import is stopped after the time-out ({dt:.1f} s, {err.strip()})")
    # The parent killed while the child hangs: the child must not outlive it.
    p = subprocess.Popen([EXE, "mesh", "h.ply", "o.ply"], cwd=d, stderr=subprocess.DEVNULL)
    kids = []
    for _ in range(300):  # the module loads first: wait for the import child
        kids = subprocess.run(["pgrep", "-P", str(p.pid)], capture_output=True,
                              text=True).stdout.split()
        if kids:
            break
        time.sleep(0.1)
    time.sleep(0.5)
    p.kill()
    p.wait()
    time.sleep(1.0)
    alive = [k for k in kids if os.path.exists(f"/proc/{k}") and
             open(f"/proc/{k}/stat").read().split()[2] != "Z"]
    check(kids and not alive, f"the import child dies with its parent (children {kids}, alive {alive})")

    # FIFOs as inputs: refused at once, never a blocked open.
    for cmd, name in (("heightmap", "f.png"), ("mesh", "f.obj")):
        os.mkfifo(os.path.join(d, name))
        rc, err, dt = run([cmd, name, "out.png" if cmd == "heightmap" else "out.ply"], d, timeout=30)
        check(rc != 0 and "regular file" in err and dt < 20, f"{cmd} refuses a FIFO input ({err.strip()})")

if FAILURES:
    print(f"{len(FAILURES)} failure(s)")
    sys.exit(1)
