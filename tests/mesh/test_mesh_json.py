# SPDX-License-Identifier: MIT
"""`bumpgrad mesh --json`: one JSON object that a parser accepts, agreeing with
the text summary. Usage: test_mesh_json.py BUMPGRAD_EXE MODELS_DIR"""
import json
import os
import re
import subprocess
import sys
import tempfile

exe, models = sys.argv[1], sys.argv[2]
wuson = os.path.join(models, "PLY", "Wuson.ply")
if not os.path.exists(wuson):
    print("SKIP: assimp-testmodels' Wuson.ply not found")
    sys.exit(77)
with tempfile.TemporaryDirectory() as d:
    args = [exe, "mesh", "--compare", "--amplitude", "0.02", wuson, os.path.join(d, "w.ply"),
            "--bake-normal-map", os.path.join(d, 'n "q".png'), "--size", "64"]
    text = subprocess.run(args, capture_output=True, text=True)
    js = subprocess.run(args + ["--json"], capture_output=True, text=True)
    ok = text.returncode == 0 and js.returncode == 0
    doc = json.loads(js.stdout) if ok else {}
    m = re.search(r"(\d+) vertices, (\d+) triangles", text.stdout)
    checks = [
        (ok, "both runs succeed"),
        (m and doc.get("vertices") == int(m.group(1)) and doc.get("triangles") == int(m.group(2)),
         "counts agree with the text summary"),
        (doc.get("bake", {}).get("path", "").endswith('n "q".png'), "strings are escaped"),
        (doc.get("inward_fraction_surfgrad") == 0, "surfgrad never inward"),
        ("height" in doc.get("parameters", {}), "parameters included"),
    ]
    bad = [w for c, w in checks if not c]
    for c, w in checks:
        print(("ok: " if c else "FAIL: ") + w)
    sys.exit(1 if bad else 0)
