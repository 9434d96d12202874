#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Fail on any exported/global symbol of libbumpgrad that does not start with
bg_ (docs/DESIGN.md, rule 5): a stray helper would clash with user code at link time.

usage: check_symbols.py NM SHARED_LIB STATIC_LIB
Shared library: `nm -D --defined-only` (the dynamic symbol table, i.e. what the
visibility attributes export). Static library: `nm --defined-only -g` (every
global symbol of every object, hidden or not, since static linking sees them all).
"""
import subprocess
import sys


SANITIZER_PREFIXES = ("__odr_asan", "__asan", "__ubsan", "__tsan", "__msan", "__sanitizer",
                      "__sancov")


def symbols(nm, args, path):
    out = subprocess.run([nm] + args + [path], check=True, capture_output=True, text=True).stdout
    syms = []
    for line in out.splitlines():
        parts = line.split()
        # "<addr> <type> <name>"; archive member headers ("foo.o:") and blanks are skipped
        if len(parts) >= 3 and len(parts[1]) == 1:
            syms.append((parts[1], parts[2]))
    return syms


def main():
    if len(sys.argv) != 4:
        print(__doc__)
        return 2
    nm, shared, static = sys.argv[1:]
    bad = 0
    for label, args, path in (("shared", ["-D", "--defined-only"], shared),
                              ("static", ["--defined-only", "-g"], static)):
        syms = symbols(nm, args, path)
        # Instrumentation of a sanitizer build (b_sanitize) adds its own globals,
        # e.g. gcc's ASan ODR indicators "__odr_asan.bg_perm512": not our names.
        tooling = [n for t, n in syms if n.startswith(SANITIZER_PREFIXES)]
        offenders = [n for t, n in syms
                     if not n.startswith("bg_") and not n.startswith(SANITIZER_PREFIXES)]
        print(f"{label} {path}: {len(syms)} global symbols, {len(offenders)} without the bg_ "
              f"prefix ({len(tooling)} sanitizer symbols ignored)")
        for n in offenders:
            print(f"  FAIL: {n}")
        if not syms:
            print("  FAIL: no symbols found (wrong file?)")
            bad += 1
        bad += len(offenders)
    print("check_symbols: " + ("FAILED" if bad else "all symbols start with bg_"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
