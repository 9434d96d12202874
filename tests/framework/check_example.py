#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The usage example of docs/FRAMEWORK.md must be the code test_fw_example.c
compiles: compares the doc's C block under "## Usage" with the region between the
test's begin/end markers, line for line (trailing blanks ignored)."""
import re
import sys

doc_path, test_path = sys.argv[1], sys.argv[2]
doc = open(doc_path, encoding="utf-8").read()
test = open(test_path, encoding="utf-8").read()
usage = doc.split("\n## Usage", 1)
if len(usage) != 2:
    sys.exit("docs: no '## Usage' section")
m = re.search(r"```c\n(.*?)```", usage[1], re.S)
if not m:
    sys.exit("docs: no C block in '## Usage'")
t = re.search(r"/\* ---- begin docs/FRAMEWORK.md example ---- \*/\n(.*?)/\* ---- end docs/FRAMEWORK.md example ---- \*/",
              test, re.S)
if not t:
    sys.exit("test: markers not found")
a = [l.rstrip() for l in m.group(1).strip("\n").split("\n")]
b = [l.rstrip() for l in t.group(1).strip("\n").split("\n")]
if a != b:
    for i, (x, y) in enumerate(zip(a + [""] * len(b), b + [""] * len(a))):
        if x != y:
            sys.exit("line %d differs:\n  doc:  %s\n  test: %s" % (i + 1, x, y))
print("docs/FRAMEWORK.md example matches test_fw_example.c (%d lines)" % len(a))
