# SPDX-License-Identifier: MIT
"""Runs `bumpgrad accuracy` / `bumpgrad stability` into a temporary folder and
checks the facts they are meant to show, with thresholds measured on this
project's sweeps (docs/STABILITY.md, docs/ACCURACY.md). Timing columns are
never asserted: speed claims come from the benchmark."""
import csv, json, os, shutil, subprocess, sys, tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish  # noqa: E402

exe, which = sys.argv[1], sys.argv[2]


def png_ok(path):
    return os.path.exists(path) and open(path, "rb").read(8) == b"\x89PNG\r\n\x1a\n"


tmp = tempfile.mkdtemp(prefix="bg-study-")
have_gnuplot = shutil.which("gnuplot") is not None
try:
    if which == "accuracy":
        out = os.path.join(tmp, "acc")
        args = [exe, "accuracy", "--out", out, "--samples", "8192", "--runs", "1"]
        if not have_gnuplot:
            args.append("--no-chart")
        r = subprocess.run(args, capture_output=True, text=True)
        check(r.returncode == 0, "accuracy exits 0 (stderr: %s)" % r.stderr.strip()[-300:])
        rows = list(csv.DictReader(open(os.path.join(out, "accuracy.csv"))))
        check(list(rows[0].keys()) == ["method", "param", "precision", "ns_per_sample",
                                       "err_mean_deg", "err_p99_deg", "err_max_deg"], "CSV header")
        methods = {(r["method"], r["precision"]) for r in rows}
        for m in [("analytic", "float32"), ("analytic", "float64"), ("central", "float32"),
                  ("central", "float64"), ("forward", "float32"), ("listing1", "float32"),
                  ("truncated", "float32")]:
            check(m in methods, "method %s %s present" % m)
        num = lambda r, k: float(r[k])
        ana = [r for r in rows if r["method"] == "analytic" and r["precision"] == "float32"][0]
        c32 = [r for r in rows if r["method"] == "central" and r["precision"] == "float32"]
        best_c = min(c32, key=lambda r: num(r, "err_mean_deg"))
        check(num(ana, "err_mean_deg") < num(best_c, "err_mean_deg") / 10,
              "analytic float32 mean error %.3g deg is 10x below the best float32 central (%.3g at h=%s)"
              % (num(ana, "err_mean_deg"), num(best_c, "err_mean_deg"), best_c["param"]))
        check(num(ana, "err_max_deg") < 1e-3, "analytic float32 max error %.3g deg < 1e-3" % num(ana, "err_max_deg"))
        l1 = sorted([r for r in rows if r["method"] == "listing1"], key=lambda r: float(r["param"]))
        errs = [num(r, "err_mean_deg") for r in l1]
        check(all(a > b for a, b in zip(errs, errs[1:])),
              "Listing 1 error falls as pixel density grows: %s" % errs)
        tr = sorted([r for r in rows if r["method"] == "truncated"], key=lambda r: int(r["param"]))
        terrs = [num(r, "err_mean_deg") for r in tr]
        check(all(a > b for a, b in zip(terrs, terrs[1:])), "fewer octaves, more error: %s" % terrs)
        for r in rows:
            for k in ["ns_per_sample", "err_mean_deg", "err_p99_deg", "err_max_deg"]:
                v = num(r, k)
                if not (v == v and v >= 0):
                    check(False, "finite non-negative %s in row %s" % (k, r))
        if have_gnuplot:
            check(png_ok(os.path.join(out, "accuracy.png")), "accuracy.png written")
            check(os.path.getsize(os.path.join(out, "accuracy.svg")) > 1000, "accuracy.svg written")
        # Bad argument: exit 2, message names it, nothing created.
        r = subprocess.run([exe, "accuracy", "--samples", "abc", "--out", os.path.join(tmp, "x")],
                           capture_output=True, text=True)
        check(r.returncode == 2 and "--samples" in r.stderr, "bad --samples -> exit 2 naming the option")
        # The most octaves allowed: one truncated row per octave below 32 (the row
        # table held 64 rows and overflowed the stack from --octaves 23 on).
        out32 = os.path.join(tmp, "acc32")
        r = subprocess.run([exe, "accuracy", "--out", out32, "--samples", "4", "--runs", "1",
                            "--no-chart", "--octaves", "32"], capture_output=True, text=True)
        rows32 = list(csv.DictReader(open(os.path.join(out32, "accuracy.csv")))) if r.returncode == 0 else []
        check(r.returncode == 0 and sum(x["method"] == "truncated" for x in rows32) == 31,
              "--octaves 32: exit 0 and 31 truncated rows (rc %d %s)" % (r.returncode, r.stderr.strip()[-200:]))
    else:
        out = os.path.join(tmp, "stab")
        args = [exe, "stability", "--out", out, "--samples", "8000"]
        if not have_gnuplot:
            args.append("--no-chart")
        r = subprocess.run(args, capture_output=True, text=True)
        check(r.returncode == 0, "stability exits 0 (stderr: %s)" % r.stderr.strip()[-300:])
        s = json.load(open(os.path.join(out, "summary.json")))
        check(s["inward_surfgrad_max"] == 0, "surfgrad never inward for unit n, finite g (amplitudes 0.1..10)")
        check(s["inward_additive_at_amplitude_1"] >= 0.05,
              "additive inward on >= 5%% of samples at amplitude 1 (measured %.1f%%)"
              % (100 * s["inward_additive_at_amplitude_1"]))
        check(1e-4 <= s["central_f32_best_step"] <= 1e-2,
              "float32 central-difference optimum h = %.3g in [1e-4, 1e-2]" % s["central_f32_best_step"])
        check(s["double_exact_at_1e7"] == 1 and s["double_distinct_at_1e7"] == 1000,
              "double entry point exact and distinct (1000 of 1000) at 1e7")
        check(s["crease_near_mean_deg"] > 10 * s["crease_mid_mean_deg"],
              "turbulence: analytic/central disagree near creases (%.3g deg) far more than away (%.3g deg)"
              % (s["crease_near_mean_deg"], s["crease_mid_mean_deg"]))
        check(s["listing1_mean_deg_85"] > 2 * s["listing1_mean_deg_head_on"],
              "Listing 1 error grows at grazing angles (%.3g -> %.3g deg)"
              % (s["listing1_mean_deg_head_on"], s["listing1_mean_deg_85"]))
        # The one det = 0 rule (bg_listing1_normal): the normal is kept, so the
        # error is the bump's own angle, never the 180 deg of normalize(0).
        check(0 < s["listing1_mean_deg_det0"] < 90, "Listing 1 at det = 0 keeps the normal")
        md = open(os.path.join(out, "STABILITY.md")).read()
        for h in ["## 1.", "## 2.", "## 3.", "## 4.", "## 5.", "## 6."]:
            check(h in md, "report has section %s" % h)
        import re
        tables = [l for l in md.splitlines() if l.startswith("|")]
        check(not any(re.search(r"\b-?nan\b", c.strip().lower()) for l in tables for c in l.split("|")[3:]),
              "no NaN among the report's measured numbers")
        if have_gnuplot:
            for name in ["inward", "central_step", "large_coords", "creases", "listing1_grazing"]:
                check(png_ok(os.path.join(out, name + ".png")), name + ".png written")
finally:
    shutil.rmtree(tmp, ignore_errors=True)


sys.exit(finish("study " + which))
