#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Print the ninja targets that the tests of the given suites need.

Usage: suite_targets.py BUILDDIR SUITE...

scripts/test builds only these in a sanitizer build of the tools, instead of
the whole project: the programs the tests run, their `depends`, and what a
test passes as an argument (bumpgrad_exe).
"""
import json
import os
import subprocess
import sys

build, suites = sys.argv[1], set(sys.argv[2:])


def introspect(what):
    out = subprocess.run(["meson", "introspect", "--" + what, build], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)


targets = introspect("targets")
by_id = {t["id"]: t for t in targets}
by_file = {f: t for t in targets for f in t["filename"]}
want = set()
for test in introspect("tests"):
    if not suites & {s.split(":")[-1] for s in test["suite"]}:
        continue
    for tid in test.get("depends", []):
        if tid in by_id:
            want.update(by_id[tid]["filename"])
    for word in test["cmd"]:
        if word in by_file:
            want.update(by_file[word]["filename"])
root = os.path.abspath(build)
print("\n".join(sorted(os.path.relpath(f, root) for f in want)))
