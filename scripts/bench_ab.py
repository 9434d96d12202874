#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Interleaved A/B timing of `bumpgrad bench` rows across builds.

    scripts/bench_ab.py [--rounds R] [--cpu N] [--] NAME=BUMPGRAD ... -- BENCH-ARGS...

Runs `taskset -c N BUMPGRAD bench --json --threads 1 BENCH-ARGS` for every
build in turn, R rounds (default 7), so that a change in the machine's load
hits every build alike, and prints per row and build the median over the rounds
of `cpu_ns_per_sample` (CPU time, the load-robust figure on a shared machine)
and of `ns_per_sample` (wall), with the ratio to the first build. Example (the
kernel change of docs/KERNELS.md item 5):

    scripts/bench_ab.py base=../base/build/src/cli/bumpgrad new=build/src/cli/bumpgrad \\
        -- --isa avx2 --runs 3 --kernels noise3,fbm3,peer:stb_perlin:value

A benchmark: it reports, never fails on slow numbers. Uses taskset when the
machine has it (util-linux).
"""
import json
import shutil
import statistics
import subprocess
import sys


def parse(argv):
    rounds, cpu, builds, rest = 7, "1", [], []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--rounds":
            rounds = int(argv[i + 1])
            i += 2
        elif a == "--cpu":
            cpu = argv[i + 1]
            i += 2
        elif a in ("-h", "--help"):
            print(__doc__.strip())
            sys.exit(0)
        elif a == "--":
            if builds:
                rest = argv[i + 1:]
                break
            i += 1
        elif "=" in a:
            name, path = a.split("=", 1)
            builds.append((name, path))
            i += 1
        else:
            sys.exit("bench_ab.py: argument %r: expected NAME=BUMPGRAD, --rounds R, --cpu N or --" % a)
    if not builds or rounds < 1:
        sys.exit("bench_ab.py: give at least one NAME=BUMPGRAD and R >= 1 (--help)")
    return rounds, cpu, builds, rest


def run(path, cpu, rest):
    cmd = [path, "bench", "--json", "--threads", "1"] + rest
    if shutil.which("taskset"):
        cmd = ["taskset", "-c", cpu] + cmd
    out = subprocess.run(cmd, check=True, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True).stdout
    return json.loads(out)


def main():
    rounds, cpu, builds, rest = parse(sys.argv[1:])
    rows = {}
    for r in range(rounds):
        for name, path in builds:
            for o in run(path, cpu, rest):
                rows.setdefault((o["kernel"], o["isa"]), {}).setdefault(name, []).append(o)
        print("round %d/%d done" % (r + 1, rounds), file=sys.stderr)
    first = builds[0][0]
    print("%-30s %-8s %-10s %12s %12s %8s" % ("kernel", "isa", "build", "cpu ns/smp", "wall ns/smp", "vs " + first))
    for (kernel, isa), per in sorted(rows.items()):
        base = None
        for name, _ in builds:
            if name not in per:
                continue
            c = statistics.median(o["cpu_ns_per_sample"] for o in per[name])
            w = statistics.median(o["ns_per_sample"] for o in per[name])
            base = c if name == first else base
            ratio = "%.3f" % (c / base) if base else "-"
            print("%-30s %-8s %-10s %12.3f %12.3f %8s" % (kernel, isa, name, c, w, ratio))


if __name__ == "__main__":
    main()
