# SPDX-License-Identifier: MIT
"""A write that runs out of space never replaces the old output and never exits 0.

Usage: test_fullwrite.py BUMPGRAD_EXE

The child runs under a small RLIMIT_FSIZE with SIGXFSZ ignored, so its writes
fail with EFBIG exactly as they would with ENOSPC on a full disk (no mount
needed). Before the fix, PNG (libpng) and VDB (OpenVDB's io::File) outputs
exited 0 and left a truncated file under the real name.
"""
import os
import resource
import signal
import subprocess
import sys
import tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish  # noqa: E402

EXE = os.path.abspath(sys.argv[1])


def run(args, limit=None, cwd=None):
    def pre():
        if limit is not None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    env = dict(os.environ, BUMPGRAD_NO_PROGRESS="1")
    return subprocess.run([EXE] + args, preexec_fn=pre, cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=300)


with tempfile.TemporaryDirectory() as d:
    cases = [
        ("render png", ["render", "--size", "8x8", "-o", "o.png"],
         ["render", "--size", "512x512", "-o", "o.png"], "o.png", 4096),
        ("render exr", ["render", "--size", "8x8", "-o", "o.exr"],
         ["render", "--size", "512x512", "-o", "o.exr"], "o.exr", 4096),
        ("volume vdb", ["volume", "--function", "noise", "--bbox", "-1,-1,-1,1,1,1", "--voxel-size",
                        "0.5", "-o", "b.vdb"],
         ["volume", "--function", "fbm", "--octaves", "2", "--bbox", "-1,-1,-1,1,1,1",
          "--voxel-size", "0.05", "-o", "b.vdb"], "b.vdb", 40000),
        ("eval csv", ["eval", "--function", "noise", "-i", "in.csv", "-o", "o.csv"],
         ["eval", "--function", "noise", "-i", "big.csv", "-o", "o.csv"], "o.csv", 4096),
    ]
    with open(os.path.join(d, "in.csv"), "w") as f:
        f.write("x,y,z\n1,2,3\n")
    with open(os.path.join(d, "big.csv"), "w") as f:
        f.write("x,y,z\n" + "0.5,0.25,0.125\n" * 5000)
    for name, small, big, out, limit in cases:
        r = run(small, cwd=d)
        check(r.returncode == 0, f"{name}: the small output is written ({r.stderr.strip()})")
        before = open(os.path.join(d, out), "rb").read()
        r = run(big, limit=limit, cwd=d)
        check(r.returncode != 0, f"{name}: a write past the limit fails (exit {r.returncode})")
        check("cannot write" in r.stderr or "failed" in r.stderr,
              f"{name}: the message says so ({r.stderr.strip()[-160:]})")
        check(open(os.path.join(d, out), "rb").read() == before, f"{name}: the old output is kept")
        left = [f for f in os.listdir(d) if ".tmp" in f]
        check(not left, f"{name}: no temporary left ({left})")

sys.exit(finish("fullwrite"))
