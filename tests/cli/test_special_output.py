# SPDX-License-Identifier: MIT
"""An output path that is a FIFO (or a device such as /dev/null) is written in
place, never replaced by a renamed temporary file (which, as root, would turn
/dev/null into a regular file)."""
import atexit, os, shutil, stat, subprocess, sys, tempfile, threading
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish  # noqa: E402

exe = sys.argv[1]
tmp = tempfile.mkdtemp(prefix="bg-fifo-")
atexit.register(shutil.rmtree, tmp, True)
inp = os.path.join(tmp, "in.csv")
with open(inp, "w") as f:
    f.write("x,y,z\n3.14,42,7\n")
fifo = os.path.join(tmp, "out.fifo")
os.mkfifo(fifo)
got = []
reader = threading.Thread(target=lambda: got.append(open(fifo).read()), daemon=True)
reader.start()
r = subprocess.run([exe, "eval", "--function", "noise", "--precision", "double",
                    "--input", inp, "--output", fifo], capture_output=True, text=True, timeout=60)
reader.join(timeout=60)
check(r.returncode == 0, "eval to a FIFO exits 0 (%s)" % r.stderr.strip())
check(stat.S_ISFIFO(os.stat(fifo).st_mode), "the FIFO is still a FIFO")
check(bool(got) and "0.13691995878400012" in got[0], "the reader received the rows")
check(sorted(os.listdir(tmp)) == ["in.csv", "out.fifo"], "no temporary files left: %s" % os.listdir(tmp))
r = subprocess.run([exe, "eval", "--function", "noise", "--input", inp, "--output", tmp],
                   capture_output=True, text=True)
check(r.returncode != 0 and tmp in r.stderr, "a folder as output is refused with its name")
sys.exit(finish("special_output"))
