#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Checks the shape of `bumpgrad bench --json`, never its speed: the command
exits 0, prints one JSON array, and every record carries the documented keys
with sane types, for every kernel name. Timing thresholds would make the test
fail on a busy machine, which is what benchmark() numbers are for."""
import atexit
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

OURS = ["noise3", "noise3_grad", "fbm3_grad", "turbulence3_grad", "turbulence3_grad_central",
        "perturb_surfgrad", "perturb_additive", "perturb_height", "fbm3",
        "noise3_point", "noise3_grad_point", "fbm3_point", "fbm3_grad_point",
        "noise3_batch1_point", "noise3_n1", "noise3_n4", "noise3_n8", "noise3_n16", "noise3_n64", "noise3_n256",
        "noise3_grid", "fbm3_grid", "fbm3_grad_grid", "stream3",
        "pnoise3", "pnoise3_grad", "pfbm3", "pfbm3_grad", "fbm3_seed_grad", "pfbm3_grad_xy",
        "pfbm3_grad_p10", "fbm3_grad_l3", "pfbm3_grad_l3"]
# Per-point and grid rows call the public entry points, which run at the active
# ISA: one ISA for all of them (the highest one of the batch rows), one row per
# thread count.
POINT = {"noise3_point", "noise3_grad_point", "fbm3_point", "fbm3_grad_point", "noise3_batch1_point",
         "noise3_grid", "fbm3_grid", "fbm3_grad_grid", "stream3"}
PEER_LIBS = {"stb_perlin", "libnoise", "glm"}
PEER_OPS = {"value", "fbm", "grad_central"}
ISAS = {"scalar", "sse2", "avx2", "avx512", "neon", "baseline"}
NUMBERS = ["msamples_per_s", "ns_per_sample", "min", "max"]
OPTIONAL = ["cpu_share", "cpu_ns_per_sample", "speedup_vs_scalar", "thread_scaling", "vs_best_peer",
            "instructions_per_sample"]


def fail(msg):
    print("check_bench_json: " + msg, file=sys.stderr)
    sys.exit(1)


def main():
    exe = sys.argv[1]
    # --icount: a file in the format of scripts/kernel_icount.sh --bench; its
    # numbers must come back in instructions_per_sample of exactly those rows.
    # A per-point line for every ISA: only the active one's row exists.
    icount = {("noise3", "scalar"): 239.0}
    icount.update({("fbm3_point", isa): 1601.0 for isa in ["scalar", "sse2", "avx2", "avx512",
                                                           "neon"]})
    tmp = tempfile.mkdtemp()
    atexit.register(shutil.rmtree, tmp, True)
    path = os.path.join(tmp, "icount.txt")
    with open(path, "w") as f:
        for (k, isa), v in icount.items():
            f.write("%s %s %g\n" % (k, isa, v))
    args = [exe, "bench", "--quick", "--json", "--samples", "4096", "--runs", "1",
            "--icount", path]
    proc = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    sys.stderr.write(proc.stderr)
    if proc.returncode != 0:
        fail("exit status %d from %s" % (proc.returncode, " ".join(args)))
    try:
        rows = json.loads(proc.stdout)
    except ValueError as e:
        fail("stdout is not JSON: %s" % e)
    if not isinstance(rows, list) or not rows:
        fail("expected a non-empty JSON array")
    seen = set()
    point_isas = set()
    for r in rows:
        if not isinstance(r, dict):
            fail("record is not an object: %r" % (r,))
        for k in ["kernel", "isa", "threads", "samples", "runs"] + NUMBERS + OPTIONAL:
            if k not in r:
                fail("record %r lacks %r" % (r, k))
        name = r["kernel"]
        if name.startswith("peer:"):
            parts = name.split(":")
            if len(parts) != 3 or parts[1] not in PEER_LIBS or parts[2] not in PEER_OPS:
                fail("bad peer name %r" % name)
            if r["threads"] != 1:
                fail("peers run on one thread: %r" % (r,))
        elif name not in OURS:
            fail("unknown kernel %r" % name)
        elif name in POINT:
            point_isas.add(r["isa"])
        want = icount.get((name, r["isa"]))
        if want is not None and r["instructions_per_sample"] != want:
            fail("--icount value not in the row: %r" % (r,))
        if want is None and r["instructions_per_sample"] is not None:
            fail("instructions_per_sample set without --icount: %r" % (r,))
        if r["isa"] not in ISAS:
            fail("unknown isa %r" % r["isa"])
        if not isinstance(r["threads"], int) or r["threads"] < 1:
            fail("bad threads in %r" % (r,))
        if r["samples"] != 4096 or r["runs"] != 1:
            fail("samples/runs not as asked in %r" % (r,))
        for k in NUMBERS:
            v = r[k]
            if not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
                fail("%s is not a positive number in %r" % (k, r))
        if not r["min"] <= r["msamples_per_s"] <= r["max"]:
            fail("min <= median <= max fails in %r" % (r,))
        for k in OPTIONAL:
            v = r[k]
            if v is not None and (not isinstance(v, (int, float)) or not v > 0):
                fail("%s must be null or positive in %r" % (k, r))
        seen.add(name)
    missing = [k for k in OURS if k not in seen]
    if missing:
        fail("kernels missing from the output: %s" % ", ".join(missing))
    if not any(r["isa"] == "scalar" for r in rows):
        fail("no scalar rows")
    # No --isa: the active level, which is the highest ISA of the batch rows.
    order = ["scalar", "sse2", "avx2", "avx512", "neon"]
    top = max((r["isa"] for r in rows if r["isa"] in order and r["kernel"] not in POINT),
              key=order.index)
    if point_isas != {top}:
        fail("per-point and grid rows must run at the active ISA %s only, got %s"
             % (top, sorted(point_isas)))
    print("check_bench_json: %d records, all %d kernels" % (len(rows), len(OURS)))


if __name__ == "__main__":
    main()
