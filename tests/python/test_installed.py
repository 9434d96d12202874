# SPDX-License-Identifier: MIT
"""The package installed by pip (tests/python/pip_install.sh): it is imported
from the venv, not from a source or build tree, and carries what it loads.

usage: test_installed.py VENV
"""
import os
import subprocess
import sys

import bumpgrad
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import QUIET, check, finish  # noqa: E402
QUIET[0] = True  # failures only, as before

venv = os.path.realpath(sys.argv[1])
pkg = os.path.dirname(os.path.realpath(bumpgrad.__file__))


check(pkg.startswith(venv + os.sep), f"bumpgrad imported from {pkg}, not from the venv {venv}")
check(not os.environ.get("LD_LIBRARY_PATH"), "LD_LIBRARY_PATH is set")
files = os.listdir(pkg)
check("__init__.pyi" in files and "py.typed" in files, f"no type stubs in {files}")
ext = [f for f in files if f.startswith("_bumpgrad") and f.endswith(".so")]
check(len(ext) == 1, f"extension: {ext}")
# Nothing of ours is loaded from outside the package: ldd names no libbumpgrad.
ldd = subprocess.run(["ldd", os.path.join(pkg, ext[0])], capture_output=True, text=True).stdout
check("libbumpgrad" not in ldd, f"the extension links a libbumpgrad from outside:\n{ldd}")
if bumpgrad.HAVE_TOOLS:
    check(any(f.startswith("libbumpgrad_io_module") for f in files),
          f"a tools build without the I/O module in the package: {files}")
print(f"bumpgrad {bumpgrad.__version__} from {pkg}: {sorted(files)}")
sys.exit(finish("installed"))
