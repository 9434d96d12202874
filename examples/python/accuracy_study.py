# SPDX-License-Identifier: MIT
"""How accurate is a noise gradient? A worked study for notebook users
(docs/PYTHON.md): bumpgrad's analytic gradient (dnoise, from the same pass as
the value) against central differences of step h, each in float32 and in
float64, all measured against an independent numpy float64 reference of
Perlin's algorithm (examples/perlin_ref.py). The points are rounded to float32
first, so every method sees the same points.

Central differences trade truncation error (about h^2) against rounding error
(about eps |p| / h). For points up to 100 in float32 the best step is about
1e-3 (noise) to 1e-4 (fBm), and even there the error is about 100 to 400
times the analytic gradient's. Below the float spacing of the points
(x + h == x - h) the central gradient is 0. The plot shows the median and the
largest error over the points for each step.

usage: PYTHONPATH=BUILD/python:examples python3 examples/python/accuracy_study.py [N] [RNG_STATE] [OUT.png]
(with an installed package only the examples folder is needed on PYTHONPATH,
for perlin_ref). Needs matplotlib (Debian: python3-matplotlib).
"""
import os
import sys

import numpy as np

import bumpgrad
import perlin_ref


def errors(g, ref):
    """Per point, the largest component error."""
    return np.max(np.abs(np.asarray(g, np.float64) - ref), axis=-1)


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 20000
    # The state of numpy's random-number generator that draws the points.
    rng_state = int(sys.argv[2]) if len(sys.argv) > 2 else 2026
    out = sys.argv[3] if len(sys.argv) > 3 else "python_accuracy_study.png"
    rng = np.random.default_rng(rng_state)
    p32 = rng.uniform(-100.0, 100.0, (n, 3)).astype(np.float32)
    p64 = p32.astype(np.float64)
    steps = np.logspace(-7, -0.5, 27)
    functions = ("noise", "fbm")
    rows = {}
    for function in functions:
        _, rg, _ = perlin_ref.fractal(p64[:, 0], p64[:, 1], p64[:, 2], function)
        ref = np.stack(rg, -1)
        res = {}
        for dt in (np.float32, np.float64):
            name = np.dtype(dt).name
            _, ga = bumpgrad.fractal3(p64, function, gradient="analytic", dtype=dt)
            e = errors(ga, ref)
            res[("analytic", name)] = (np.median(e), e.max())
            med, mx = [], []
            for h in steps:
                _, gc = bumpgrad.fractal3(p64, function, gradient="central", step=float(h), dtype=dt)
                e = errors(gc, ref)
                med.append(np.median(e))
                mx.append(e.max())
            res[("central", name)] = (np.array(med), np.array(mx))
        rows[function] = res
    # The table.
    print(f"bumpgrad {bumpgrad.__version__}, ISA {bumpgrad.isa_active()}, {n} points in "
          f"[-100, 100]^3 (float32), random state {rng_state}; gradient error (largest component), "
          "median / max")
    print(f"{'function':9s} {'method':28s} {'float32':>21s} {'float64':>21s}")
    for function, res in rows.items():
        a32, a64 = res[("analytic", "float32")], res[("analytic", "float64")]
        print(f"{function:9s} {'analytic':28s} {a32[0]:9.2e} / {a32[1]:9.2e} "
              f"{a64[0]:9.2e} / {a64[1]:9.2e}")
        for dtn in ("float32", "float64"):
            med, mx = res[("central", dtn)]
            i = int(np.argmin(med))
            print(f"{function:9s} {'central, best h for ' + dtn + f' ({steps[i]:.1e})':28s} "
                  + (f"{med[i]:9.2e} / {mx[i]:9.2e} {'':21s}" if dtn == "float32"
                     else f"{'':21s} {med[i]:9.2e} / {mx[i]:9.2e}"))
    # The plot.
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(functions), figsize=(11, 4.6), sharey=True)
    colors = {"float32": "tab:orange", "float64": "tab:blue"}
    for ax, function in zip(axes, functions):
        res = rows[function]
        for dtn in ("float32", "float64"):
            med, mx = res[("central", dtn)]
            ax.loglog(steps, med, "-o", ms=3, color=colors[dtn], label=f"central, {dtn}: median")
            ax.loglog(steps, mx, "--", color=colors[dtn], alpha=0.6, label=f"central, {dtn}: max")
            am, ax_ = res[("analytic", dtn)]
            ax.axhline(max(am, 1e-18), color=colors[dtn], lw=2, ls=":",
                       label=f"analytic, {dtn}: median")
        ax.set_title(f"{function} ({'one octave' if function == 'noise' else '6 octaves'})")
        ax.set_xlabel("central-difference step h (noise-space units)")
        ax.grid(True, which="major", alpha=0.3)
    axes[0].set_ylabel("gradient error vs float64 reference")
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle(f"bumpgrad gradients: analytic vs central differences, float32 vs float64 "
                 f"({n} points)", fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"wrote {os.path.abspath(out)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
