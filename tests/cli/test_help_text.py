# SPDX-License-Identifier: MIT
"""`bumpgrad --help` tells the truth about the program it describes:
  - every exit status a command's own --help documents is in the main help,
    and `render --fail-above` really exits 3 (with the tools);
  - the render summary names the last --preset that `render --help` accepts;
  - every BUMPGRAD_* environment variable the sources read is in the main help;
  - no help text calls a paper or article "the seed".

Usage: test_help_text.py BUMPGRAD_EXE SOURCE_ROOT TOOLS(true|false)
"""
import os
import re
import subprocess
import sys
import tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import QUIET, check, finish  # noqa: E402

EXE = os.path.abspath(sys.argv[1])
SRC = os.path.abspath(sys.argv[2])
TOOLS = sys.argv[3] == "true"
QUIET[0] = True  # failures only


def run(args, cwd=None):
    env = dict(os.environ)
    env.pop("BUMPGRAD_ISA", None)
    env["BUMPGRAD_NO_PROGRESS"] = "1"
    p = subprocess.run([EXE] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                       timeout=60, cwd=cwd)
    return p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")


def exit_codes(text):
    """The statuses of the help's 'Exit status:' paragraph: {code: description}."""
    m = re.search(r"Exit status:(.*?)(?:\n\s*\n|\Z)", text, re.S)
    if not m:
        return None
    para = " ".join(m.group(1).split())
    return {int(c): d.strip() for c, d in re.findall(r"\b(\d+) ([^,.;]+)", para)}


rc, main_help, err = run(["--help"])
check(rc == 0 and main_help.startswith("Usage: bumpgrad"), "bumpgrad --help: rc %d, %r" % (rc, err))
commands = re.findall(r"^  ([a-z]+) {2,}\S", main_help.split("Commands:\n", 1)[-1].split("\n\n")[0],
                      re.M)
check(len(commands) >= 5, "commands listed in --help: %r" % commands)
main_codes = exit_codes(main_help) or {}
check({0, 1, 2} <= set(main_codes), "main help's exit statuses: %r" % main_codes)

# 1. Exit statuses: the union of the commands' own lists is in the main help.
for cmd in commands:
    rc, text, err = run([cmd, "--help"])
    check(rc == 0, "%s --help exits 0 (rc %d, %r)" % (cmd, rc, err[:200]))
    for code, what in (exit_codes(text) or {}).items():
        check(code in main_codes,
              "exit status %d of `%s` (%s) missing from bumpgrad --help" % (code, cmd, what))
    check(not re.search(r"\bthe seed\b|\bseed's\b|\bseed method\b|\bseed =", text),
          "%s --help speaks of 'seed' (cite the paper or article instead)" % cmd)
check(not re.search(r"\bseed\b", main_help), "bumpgrad --help speaks of 'seed'")
check(3 in main_codes and "fail-above" in main_codes.get(3, ""),
      "bumpgrad --help explains exit status 3 (--fail-above): %r" % main_codes.get(3))

# 2. The presets: the render summary names the last one render accepts (render is
# built with the tools only).
if TOOLS:
    rc, render_help, _ = run(["render", "--help"])
    m = re.search(r"--preset ([a-z0-9|]+)", render_help)
    if check(m is not None, "render --help shows --preset's choices"):
        presets = m.group(1).split("|")
        check(presets[-1] == "fig4" or len(presets) >= 4, "render presets: %r" % presets)
        summary = next((ln for ln in main_help.splitlines() if ln.startswith("  render ")), "")
        last = re.sub(r"\D", "", presets[-1])
        check(re.search(r"fig1\.\.(fig)?%s\b" % last, summary) is not None,
              "bumpgrad --help's render line names presets up to %s: %r" % (presets[-1], summary))

# 3. Environment variables: every one the sources read.
names = set()
for root, _, files in os.walk(os.path.join(SRC, "src")):
    for f in files:
        if f.endswith((".c", ".cc", ".h")):
            with open(os.path.join(root, f), encoding="utf-8", errors="replace") as fp:
                names.update(re.findall(r'"(BUMPGRAD_[A-Z0-9_]+)"', fp.read()))
check({"BUMPGRAD_ISA", "BUMPGRAD_MAX_MB"} <= names, "env vars found in src/: %r" % sorted(names))
env_section = main_help.split("Environment:", 1)[-1]
for name in sorted(names):
    check(re.search(r"\b%s\b" % name, env_section) is not None,
          "%s (read in src/) missing from bumpgrad --help's Environment" % name)

# 4. The documented exit status 3 is the real one.
if TOOLS:
    with tempfile.TemporaryDirectory() as d:
        rc, _, err = run(["render", "--size", "48x48", "--compare", "surfgrad,additive",
                          "--fail-above", "0", "-q", "-o", "cmp.png"], cwd=d)
        check(rc == 3 and "fail-above" in err, "render --fail-above 0: rc %d, %r" % (rc, err))
        check(os.path.getsize(os.path.join(d, "cmp.png")) > 0, "--fail-above still writes the image")
        rc, _, err = run(["render", "--size", "48x48", "--compare", "surfgrad,additive",
                          "--fail-above", "90", "-q", "-o", "cmp.png"], cwd=d)
        check(rc == 0, "render --fail-above 90: rc %d, %r" % (rc, err))

sys.exit(finish("help text"))
