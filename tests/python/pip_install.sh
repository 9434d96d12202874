#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `pip install .` into a fresh venv (Debian's python3-mesonpy, offline), then the
# Python tests against the installed package, run from outside the source tree
# with no PYTHONPATH to the package (docs/PYTHON.md). Called by scripts/test.
# usage: tests/python/pip_install.sh WORKDIR [BUMPGRAD_EXE]   (WORKDIR keeps meson-python's
# build folder between runs, so a second run only recompiles what changed)
# Ends with "pip install tests: N passed, M failed".
set -uo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mkdir -p "$1" && cd "$1" && pwd)
exe=""
[ -n "${2:-}" ] && exe=$(cd "$(dirname "$2")" && pwd)/$(basename "$2")
venv=$work/venv
passed=0; failed=0
result() { # name, command...
  local name=$1; shift
  if "$@"; then echo "ok   $name"; passed=$((passed + 1)); else echo "FAIL $name"; failed=$((failed + 1)); fi
}
rm -rf "$venv"
/usr/bin/python3 -m venv --system-site-packages "$venv" || { echo "pip install tests: 0 passed, 1 failed"; exit 1; }
result pip_install "$venv/bin/pip" install --quiet --no-build-isolation --no-index --no-deps \
  --config-settings=builddir="$work/build" "$src"
# `pip wheel` from the same build folder: one wheel with the package in platlib.
check_wheel() {
  rm -rf "$work/wheel"
  "$venv/bin/pip" wheel --quiet --no-build-isolation --no-index --no-deps \
    --config-settings=builddir="$work/build" -w "$work/wheel" "$src" || return 1
  "$venv/bin/python" - "$work"/wheel/bumpgrad-*.whl <<'PY'
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
print("wheel:", sys.argv[1].rsplit("/", 1)[-1], sorted(n for n in names if n.startswith("bumpgrad/")))
assert any(n.startswith("bumpgrad/_bumpgrad") and n.endswith(".so") for n in names), names
assert "bumpgrad/__init__.py" in names and "bumpgrad/__init__.pyi" in names, names
PY
}
result pip_wheel check_wheel
run=$(mktemp -d)
trap 'rm -rf "$run"' EXIT
cd "$run"
check_value() {
  local got
  got=$("$venv/bin/python" -c 'import bumpgrad, numpy; print(repr(bumpgrad.noise3(numpy.array([[3.14, 42, 7]]), dtype=numpy.float64)[0]))') || return 1
  echo "noise3 at Perlin's point: $got"
  [ "$got" = "0.13691995878400012" ]
}
result perlin_point check_value
# perlin_ref.py (the numpy reference) is test data from examples/, not the package.
for t in "test_installed.py $venv" "test_bumpgrad.py reference" "test_bumpgrad.py bounds" \
         "test_bumpgrad.py badinput" "test_conventions.py" "test_conventions.py sigint"; do
  set -- $t
  result "$t" env PYTHONPATH="$src/examples" PYTHONDONTWRITEBYTECODE=1 \
    "$venv/bin/python" "$src/tests/python/$1" "${@:2}"
done
# bake_normal_map against the command's bake, when a built command is given.
if [ -n "$exe" ]; then
  result "test_tools.py" env PYTHONDONTWRITEBYTECODE=1 "$venv/bin/python" \
    "$src/tests/python/test_tools.py" "$exe"
  result "test_domain_py.py" env PYTHONDONTWRITEBYTECODE=1 "$venv/bin/python" \
    "$src/tests/python/test_domain_py.py" "$exe"
  result "test_render_py.py" env PYTHONDONTWRITEBYTECODE=1 "$venv/bin/python" \
    "$src/tests/python/test_render_py.py" "$exe"
fi
echo "pip install tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
