# SPDX-License-Identifier: MIT
"""Temporaries of the safe file writer (src/tools/common/safe_file.c).

Usage: test_temps.py BUMPGRAD_EXE

- SIGTERM and SIGINT during a run remove its temporary and keep the old output;
- SIGKILL leaves the temporary (nothing can catch it), and the next run that
  writes the same target in the same folder removes it, while a temporary of a
  process that is still alive is left alone.
"""
import os
import signal
import subprocess
import sys
import tempfile
import time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish  # noqa: E402

EXE = os.path.abspath(sys.argv[1])


def temps(d):
    return sorted(f for f in os.listdir(d) if ".tmp-bumpgrad-" in f)


def start_eval(d, out):
    """eval reading a pipe that we keep open: the run stays in its loop with
    its temporary output created, until we signal it."""
    p = subprocess.Popen([EXE, "eval", "--function", "noise", "--input", "-", "--output", out],
                         stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         env=dict(os.environ, BUMPGRAD_NO_PROGRESS="1"))
    p.stdin.write(b"x,y,z\n" + b"0.5,0.25,0.125\n" * 20000)
    p.stdin.flush()
    for _ in range(200):
        if temps(d):
            break
        time.sleep(0.02)
    return p


with tempfile.TemporaryDirectory() as d:
    out = os.path.join(d, "out.csv")
    with open(out, "w") as f:
        f.write("old\n")
    for sig in (signal.SIGTERM, signal.SIGINT):
        p = start_eval(d, out)
        check(len(temps(d)) == 1, f"{sig.name}: the run has a temporary ({temps(d)})")
        p.send_signal(sig)
        p.communicate(timeout=30)
        check(p.returncode != 0, f"{sig.name}: non-zero exit ({p.returncode})")
        check(temps(d) == [], f"{sig.name}: temporary removed ({temps(d)})")
        check(open(out).read() == "old\n", f"{sig.name}: old output kept")

    p = start_eval(d, out)
    p.kill()
    p.communicate(timeout=30)
    left = temps(d)
    check(len(left) == 1 and f"-{p.pid}-" in left[0],
          f"SIGKILL leaves the temporary, named with its pid ({left})")
    check(open(out).read() == "old\n", "SIGKILL: old output kept")
    # A temporary of a live process (our own pid) for the same target: kept.
    live = os.path.join(d, ".out.csv.tmp-bumpgrad-%d-abcdef.csv" % os.getpid())
    open(live, "w").close()
    # A stale temporary of another target: not ours to remove.
    other = os.path.join(d, ".other.csv.tmp-bumpgrad-%d-abcdef.csv" % (left and int(left[0].split("-")[2]) or 1))
    open(other, "w").close()
    inp = os.path.join(d, "in.csv")
    with open(inp, "w") as f:
        f.write("x,y,z\n3.14,42,7\n")
    r = subprocess.run([EXE, "eval", "--function", "noise", "-i", inp, "-o", out],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    check(r.returncode == 0 and open(out).read().startswith("x,y,z,value"), "the next run works")
    now = temps(d)
    check(left[0] not in now, f"the next run removed the dead run's temporary ({now})")
    check(os.path.basename(live) in now, "a live process's temporary is kept")
    check(os.path.basename(other) in now, "another target's temporary is kept")

sys.exit(finish("temps"))
