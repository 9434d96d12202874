# SPDX-License-Identifier: MIT
"""README.md's examples do what README.md says they do:
  - the ```c block compiles against the public headers with -std=c11 -Wall
    -Wextra -Werror, links with nothing but -lbumpgrad, and prints the output
    quoted after it;
  - the ```python block runs against the build tree's package (skipped when the
    package was not built) and prints Perlin's reference value.

Usage: readme_examples.py README.md SOURCE_ROOT BUILD_ROOT CC
"""
import os
import re
import subprocess
import sys
import tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import QUIET, check, finish  # noqa: E402

readme, src, build, cc = sys.argv[1:5]
text = open(readme, encoding="utf-8").read()
QUIET[0] = True  # failures only


def block(lang):
    m = re.search(r"```%s\n(.*?)```" % lang, text, re.S)
    return m.group(1) if m else None


with tempfile.TemporaryDirectory() as d:
    code = block("c")
    if check(code is not None, "README.md has a ```c block"):
        lines = code.strip("\n").split("\n")
        check(len(lines) <= 12, "the C example is short (%d lines)" % len(lines))
        c_file, exe = os.path.join(d, "app.c"), os.path.join(d, "app")
        with open(c_file, "w") as f:
            f.write(code)
        p = subprocess.run([cc, "-std=c11", "-Wall", "-Wextra", "-Werror", "-I" + os.path.join(src, "include"),
                            c_file, "-L" + build, "-lbumpgrad", "-Wl,-rpath," + build, "-o", exe],
                           capture_output=True, text=True)
        if check(p.returncode == 0, "the C example compiles: %s" % p.stderr[-2000:]):
            out = subprocess.run([exe], capture_output=True, text=True).stdout.strip()
            # The README quotes the output in a `...` span after "prints", maybe across lines.
            m = re.search(r"prints `([^`]*)`", text)
            quoted = " ".join(m.group(1).split()) if m else None
            print("C example printed: %s" % out)
            check(quoted is not None and " ".join(out.split()) == quoted,
                  "README quotes the C example's output: %r, it printed %r" % (quoted, out))

    py = block("python")
    pydir = os.path.join(build, "python")
    if check(py is not None, "README.md has a ```python block"):
        if os.path.isdir(os.path.join(pydir, "bumpgrad")):
            env = dict(os.environ, PYTHONPATH=pydir)
            p = subprocess.run(["/usr/bin/python3", "-c", py], capture_output=True, text=True, env=env,
                               timeout=120)
            print("Python example printed: %s" % p.stdout.strip())
            check(p.returncode == 0 and "0.13691995878400012" in p.stdout,
                  "the Python example runs and prints Perlin's value: %r %r" % (p.stdout, p.stderr[-1000:]))
        else:
            print("Python example: skipped (no bumpgrad package in %s)" % pydir)

sys.exit(finish("README examples"))
