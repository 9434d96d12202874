#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""`bumpgrad bench` on the option table (src/cli/args.h): generated --help,
--opt=value, range errors naming the option (exit 2), and exactly the rows
asked for. Never a timing check."""
import json
import subprocess
import sys
import os
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import QUIET, check, finish  # noqa: E402

QUIET[0] = True

KERNELS = ["noise3", "noise3_grad", "fbm3_grad", "turbulence3_grad", "turbulence3_grad_central",
           "perturb_surfgrad", "perturb_additive", "perturb_height", "fbm3",
           "noise3_point", "noise3_grad_point", "fbm3_point", "fbm3_grad_point",
           "noise3_batch1_point", "noise3_n1", "noise3_n4", "noise3_n8", "noise3_n16", "noise3_n64", "noise3_n256",
           "noise3_grid", "fbm3_grid", "fbm3_grad_grid", "stream3"]


def run(exe, args):
    p = subprocess.run([exe, "bench"] + args, capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def main():
    exe = sys.argv[1]
    rc, out, err = run(exe, ["--help"])
    check(rc == 0 and out.startswith("Usage: bumpgrad bench "), "--help: usage line (%d)" % rc)
    flat = " ".join(out.split())
    for k in KERNELS + ["--json", "--threads", "--isa", "--samples", "--runs", "--kernels",
                        "--icount", "--quick"]:
        check(k in flat, "--help names %s" % k)
    rc, out, err = run(exe, ["--samples=2048", "--runs=1", "--threads=1", "--isa=scalar",
                             "--kernels=noise3,fbm3_point", "--json"])
    check(rc == 0, "--opt=value forms run (%d %r)" % (rc, err))
    if rc == 0:
        rows = json.loads(out)
        got = sorted((r["kernel"], r["isa"], r["threads"], r["samples"], r["runs"]) for r in rows)
        check(got == [("fbm3_point", "scalar", 1, 2048, 1), ("noise3", "scalar", 1, 2048, 1)],
              "exactly the rows asked for: %r" % (got,))
    # --isa also moves the public-call rows (per-point, grid) to that ISA.
    rc, out, err = run(exe, ["--samples=3000", "--runs=1", "--threads=1", "--isa=scalar",
                             "--kernels=noise3_grid,fbm3_grad_grid,noise3_grad_point", "--json"])
    check(rc == 0, "grid rows run (%d %r)" % (rc, err))
    if rc == 0:
        got = sorted((r["kernel"], r["isa"], r["samples"]) for r in json.loads(out))
        check(got == [("fbm3_grad_grid", "scalar", 3000), ("noise3_grad_point", "scalar", 3000),
                      ("noise3_grid", "scalar", 3000)], "grid rows at --isa: %r" % (got,))
    for args, needle in ((["--runs", "0"], "--runs"), (["--samples=0"], "--samples"),
                         (["--threads", "x"], "--threads"), (["--isa", "bogus"], "--isa"),
                         (["--kernels", "nope"], "--kernels"),
                         (["--frobnicate"], "--frobnicate"), (["--samples"], "--samples")):
        rc, out, err = run(exe, args)
        check(rc == 2 and needle in err and out == "",
              "%s: exit 2 naming %s (%d %r)" % (" ".join(args), needle, rc, err.strip()))
    # A flag with a value: main.c splits --x=v of commands not in its table of
    # converted ones ("unexpected argument"), the table parser says "takes no value".
    rc, out, err = run(exe, ["--json=1"])
    check(rc == 2 and out == "" and ("takes no value" in err or 'argument "1"' in err),
          "--json=1: exit 2 (%d %r)" % (rc, err.strip()))
    rc, out, err = run(exe, ["--icount", "/nonexistent/icount.txt", "--samples", "64", "--runs",
                             "1", "--threads", "1", "--kernels", "noise3", "--isa", "scalar"])
    check(rc == 1 and "--icount" in err, "unreadable --icount: exit 1 (%d %r)" % (rc, err))
    sys.exit(finish("bench-cli"))


if __name__ == "__main__":
    main()
