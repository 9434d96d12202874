#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Turns `bumpgrad bench --json` output into the Markdown tables and the
target verdicts of docs/PERFORMANCE.md, so that a re-measurement on a quiet
machine updates the document without hand-copying numbers.

usage: scripts/bench_report.py bench.json [--command "the command that made it"]
"""
import json
import sys

OURS = ["noise3", "noise3_grad", "fbm3_grad", "turbulence3_grad", "turbulence3_grad_central",
        "perturb_surfgrad", "perturb_additive", "perturb_height"]
ISA_ORDER = ["scalar", "sse2", "avx2", "avx512", "neon"]
# Rows that call the public per-point and grid functions (one ISA: the active
# one), with the stb_perlin operation each is set against.
PUBLIC_PEER_OP = {"noise3_point": "value", "noise3_grad_point": "grad_central",
                  "fbm3_point": "fbm", "fbm3_grad_point": "fbm",
                  "noise3_grid": "value", "fbm3_grid": "fbm", "fbm3_grad_grid": "fbm"}
PUBLIC = list(PUBLIC_PEER_OP)
# Kernels whose cost is arithmetic and gathers, not memory traffic: the thread
# scaling target is judged on these (perturb_* stream 36 bytes per sample and
# measure the memory system at two threads, reported but not judged).
COMPUTE_BOUND = ["noise3", "noise3_grad", "fbm3_grad", "turbulence3_grad",
                 "turbulence3_grad_central", "perturb_height"]


def fmt(v, digits=1):
    return "-" if v is None else ("%.*f" % (digits, v))


def main():
    args = sys.argv[1:]
    command = None
    if "--command" in args:
        k = args.index("--command")
        command = args[k + 1]
        del args[k:k + 2]
    rows = json.load(open(args[0]))
    by = {(r["kernel"], r["isa"], r["threads"]): r for r in rows}
    isas = [i for i in ISA_ORDER if any(r["isa"] == i for r in rows)]
    nthr = sorted({r["threads"] for r in rows if not r["kernel"].startswith("peer:")})
    many = nthr[-1] if nthr else 1
    out = []
    samples = rows[0]["samples"] if rows else 0
    runs = rows[0]["runs"] if rows else 0
    out.append("%d samples per run, median of %d runs; M samples/s, "
               "`median (min-max)`." % (samples, runs))
    shares = sorted(r["cpu_share"] for r in rows if r.get("cpu_share"))
    if shares:
        # Below about 0.9 the machine was shared and the medians are low.
        out.append("CPU share (CPU time / (wall time x threads)) over the rows: median %.2f, "
                   "min %.2f; 1.00 means the run had its cores to itself." % (
                       shares[len(shares) // 2], shares[0]))
    out.append("")

    for t in nthr:
        out.append("**%d thread%s**" % (t, "" if t == 1 else "s"))
        out.append("")
        out.append("| kernel | " + " | ".join(isas) + " | best / scalar |")
        out.append("|---|" + "---:|" * len(isas) + "---:|")
        for k in OURS:
            cells, best, scal = [], None, None
            for i in isas:
                r = by.get((k, i, t))
                if r is None:
                    cells.append("-")
                    continue
                cells.append("%s (%s-%s)" % (fmt(r["msamples_per_s"]), fmt(r["min"]), fmt(r["max"])))
                if i == "scalar":
                    scal = r["msamples_per_s"]
                if best is None or r["msamples_per_s"] > best:
                    best = r["msamples_per_s"]
            if all(c == "-" for c in cells):
                continue
            ratio = "%.1fx" % (best / scal) if best and scal else "-"
            out.append("| `%s` | %s | %s |" % (k, " | ".join(cells), ratio))
        out.append("")

    peers = [r for r in rows if r["kernel"].startswith("peer:")]
    if peers:
        out.append("**Peers (one thread, the build's default target)**")
        out.append("")
        out.append("| peer | value | fbm | grad_central |")
        out.append("|---|---:|---:|---:|")
        libs = []
        for r in peers:
            lib = r["kernel"].split(":")[1]
            if lib not in libs:
                libs.append(lib)
        for lib in libs:
            cells = []
            for op in ["value", "fbm", "grad_central"]:
                r = by.get(("peer:%s:%s" % (lib, op), "baseline", 1))
                cells.append("-" if r is None else "%s (%s-%s)" % (
                    fmt(r["msamples_per_s"], 2), fmt(r["min"], 2), fmt(r["max"], 2)))
            out.append("| %s | %s |" % (lib, " | ".join(cells)))
        out.append("")

    def fastest(kernel, threads=1):
        best = None
        for i in isas:
            r = by.get((kernel, i, threads))
            if r and (best is None or r["msamples_per_s"] > best["msamples_per_s"]):
                best = r
        return best

    # Ratios to the best comparable peer (one thread, our fastest ISA).
    comparable = {"noise3": "value", "noise3_grad": "grad_central", "fbm3_grad": "fbm",
                  "turbulence3_grad": "fbm"}
    if peers:
        out.append("**Ours (fastest ISA, one thread) over the fastest peer of the comparable "
                   "operation**")
        out.append("")
        out.append("| kernel | ours | peer operation | fastest peer | ratio | vs stb_perlin |")
        out.append("|---|---:|---|---|---:|---:|")
        for k, op in comparable.items():
            r = fastest(k)
            cands = [p for p in peers if p["kernel"].endswith(":" + op)]
            if not r or not cands:
                continue
            bp = max(cands, key=lambda p: p["msamples_per_s"])
            stb = by.get(("peer:stb_perlin:%s" % op, "baseline", 1))
            out.append("| `%s` (%s) | %s | %s | %s %s | %.2fx | %s |" % (
                k, r["isa"], fmt(r["msamples_per_s"]), op, bp["kernel"].split(":")[1],
                fmt(bp["msamples_per_s"], 2), r["msamples_per_s"] / bp["msamples_per_s"],
                "%.2fx" % (r["msamples_per_s"] / stb["msamples_per_s"]) if stb else "-"))
        out.append("")

    # Rows through the public API (per-point and grid calls): one ISA, the
    # active one; set against stb_perlin per point by CPU time, the figure a
    # loaded machine does not inflate (cpu_ns_per_sample).
    public = [r for r in rows if r["threads"] == 1 and r["kernel"] in PUBLIC]
    if public:
        out.append("**Per-point and grid calls (public API, active ISA, one thread)**")
        out.append("")
        out.append("| kernel | isa | M/s | CPU ns/sample | instructions/sample | stb_perlin "
                   "operation | CPU time / stb_perlin's |")
        out.append("|---|---|---:|---:|---:|---|---:|")
        for r in sorted(public, key=lambda r: PUBLIC.index(r["kernel"])):
            op = PUBLIC_PEER_OP[r["kernel"]]
            stb = by.get(("peer:stb_perlin:%s" % op, "baseline", 1))
            ratio = "-"
            if stb and stb.get("cpu_ns_per_sample") and r.get("cpu_ns_per_sample"):
                ratio = "%.2fx" % (r["cpu_ns_per_sample"] / stb["cpu_ns_per_sample"])
            ic = r.get("instructions_per_sample")
            out.append("| `%s` | %s | %s | %s | %s | %s | %s |" % (
                r["kernel"], r["isa"], fmt(r["msamples_per_s"], 2),
                fmt(r.get("cpu_ns_per_sample")), "-" if ic is None else "%g" % ic, op, ratio))
        out.append("")

    # Targets of the issue.
    out.append("**Targets** (one thread at the fastest ISA unless said otherwise)")
    out.append("")
    out.append("| target | measured | verdict |")
    out.append("|---|---|---|")

    def verdict(ok):
        return "met" if ok else "**not met**"

    n3, g3, tg = fastest("noise3"), fastest("noise3_grad"), fastest("turbulence3_grad")
    if n3:
        out.append("| noise3 value >= 400 M/s | %s M/s (%s) | %s |" % (
            fmt(n3["msamples_per_s"]), n3["isa"], verdict(n3["msamples_per_s"] >= 400)))
    if g3:
        out.append("| noise3 value+gradient >= 250 M/s | %s M/s (%s) | %s |" % (
            fmt(g3["msamples_per_s"]), g3["isa"], verdict(g3["msamples_per_s"] >= 250)))
        same = by.get(("noise3", g3["isa"], 1))
        if same:
            cost = same["msamples_per_s"] / g3["msamples_per_s"]
            out.append("| value+gradient costs <= 1.7x value | %.2fx (%s) | %s |" % (
                cost, g3["isa"], verdict(cost <= 1.7)))
    if tg:
        out.append("| 6-octave turbulence + analytic gradient >= 40 M/s | %s M/s (%s) | %s |" % (
            fmt(tg["msamples_per_s"]), tg["isa"], verdict(tg["msamples_per_s"] >= 40)))
    if n3:
        sc = by.get(("noise3", "scalar", 1))
        if sc:
            sp = n3["msamples_per_s"] / sc["msamples_per_s"]
            others = []
            for k in OURS:
                b, s = fastest(k), by.get((k, "scalar", 1))
                if b and s and k != "noise3":
                    others.append("%s %.1fx" % (k, b["msamples_per_s"] / s["msamples_per_s"]))
            out.append("| best ISA >= 10x our scalar (noise3) | %.1fx (%s); %s | %s |" % (
                sp, n3["isa"], ", ".join(others), verdict(sp >= 10)))
        stb = by.get(("peer:stb_perlin:value", "baseline", 1))
        if stb:
            r8 = n3["msamples_per_s"] / stb["msamples_per_s"]
            # Per CPU-second as well: if one side ran while another job held its
            # core, rate / cpu_share is the better estimate of its own speed.
            note = ""
            if n3.get("cpu_share") and stb.get("cpu_share"):
                note = "; per CPU-second %.1fx (cpu %.0f%% vs %.0f%%)" % (
                    r8 * stb["cpu_share"] / n3["cpu_share"], 100 * n3["cpu_share"],
                    100 * stb["cpu_share"])
            out.append("| >= 8x stb_perlin (noise3 vs stb_perlin_noise3) | %.1fx%s | %s |" % (
                r8, note, verdict(r8 >= 8)))
    if many > 1:
        # A two-thread row that got well under its cores (cpu_share < 0.9) says
        # nothing about scaling: another job held a core. Such rows make the
        # verdict inconclusive unless a row that did get its cores already fails.
        scal, fails, shared = [], 0, 0
        for k in COMPUTE_BOUND:
            b = fastest(k)
            m = by.get((k, b["isa"], many)) if b else None
            if not m:
                continue
            s = m["msamples_per_s"] / b["msamples_per_s"]
            share = m.get("cpu_share") or 0.0
            quiet = share >= 0.9
            scal.append("%s %.2fx (cpu %.0f%%)" % (k, s, 100 * share))
            fails += quiet and s < 1.85
            shared += not quiet
        if scal:
            v = "**not met**" if fails else ("inconclusive: cores shared" if shared else "met")
            out.append("| %d threads scale >= 1.85x (every compute-bound kernel, its fastest "
                       "ISA) | %s | %s |" % (many, ", ".join(scal), v))
    out.append("")
    if command:
        out.append("Command: `%s`" % command)
        out.append("")
    print("\n".join(out))


if __name__ == "__main__":
    main()
