# SPDX-License-Identifier: MIT
"""The I/O module compiles none of the process-wide machinery.

Usage: test_one_registry.py MODULE.so

The safe writer's registry of temporaries, its signal handlers, the memory cap
and the BUMPGRAD_* reader live once per process (src/tools/common, linked by
the program or libbumpgrad-io.so) and are lent to the module when it is
loaded (src/io/io_host.h). Before, the module compiled safe_file.c and tool.c
too: two registries, two chained signal handlers, two reads of the cap.
"""
import subprocess
import sys

syms = subprocess.run(["nm", sys.argv[1]], capture_output=True, text=True, check=True).stdout
own = [line.split()[-1] for line in syms.splitlines()
       if any(k in line.split()[-1] for k in ("bgt_", "live_temps", "remove_stale_temps"))]
attach = any(line.split()[-1] == "bg_io_module_attach" for line in syms.splitlines())
print(("ok: " if not own else "FAIL: ") + f"no tools/common code in the module ({own[:5]})")
print(("ok: " if attach else "FAIL: ") + "the module takes its host services (bg_io_module_attach)")
sys.exit(0 if attach and not own else 1)
