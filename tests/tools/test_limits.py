# SPDX-License-Identifier: MIT
"""Nothing hung, nothing unbounded (issue 13): every input-driven allocation is
checked against the one cap (BUMPGRAD_MAX_MB, default 4096) before it happens,
child processes time out (BUMPGRAD_CHILD_TIMEOUT) and die with their parent,
FIFO inputs are refused instead of blocking, and OpenVDB's refusal of a tiny
voxel is not reported as "out of memory".

Usage: test_limits.py BUMPGRAD_EXE
"""
import os
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish  # noqa: E402

EXE = os.path.abspath(sys.argv[1])


def run(args, cwd, timeout=120, **env):
    e = dict(os.environ, BUMPGRAD_NO_PROGRESS="1", **env)
    t0 = time.monotonic()
    r = subprocess.run([EXE] + args, cwd=cwd, env=e, capture_output=True, text=True, timeout=timeout)
    return r.returncode, r.stderr, time.monotonic() - t0


def peak_rss_mb(args, cwd, **env):
    """Run and return (rc, stderr, peak RSS in MiB of the process or of a child
    it waited for: the VDB probe and the mesh import count)."""
    p = subprocess.Popen([EXE] + args, cwd=cwd, stderr=subprocess.PIPE, text=True,
                         env=dict(os.environ, BUMPGRAD_NO_PROGRESS="1", **env))
    _, status, ru = os.wait4(p.pid, 0)
    err = p.stderr.read()
    return os.waitstatus_to_exitcode(status), err, ru.ru_maxrss / 1024.0


REGRESS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "fuzz", "regress")


def tiled_tiff(w, h, tile):
    """A w x h RGB uint8 TIFF (deflate) declaring tile x tile tiles, with the
    data of a w x h tile: OpenImageIO sizes its tile buffers by the tags."""
    data = zlib.compress(b"\x80" * (w * h * 3))
    n = 12
    bps_off = 8 + 2 + 12 * n + 4
    data_off = bps_off + 6
    tags = [(256, 3, 1, w), (257, 3, 1, h), (258, 3, 3, bps_off), (259, 3, 1, 8),
            (262, 3, 1, 2), (277, 3, 1, 3), (284, 3, 1, 1), (322, 4, 1, tile),
            (323, 4, 1, tile), (324, 4, 1, data_off), (325, 4, 1, len(data)), (339, 3, 1, 1)]
    out = b"II*\x00" + struct.pack("<IH", 8, n)
    for tag, typ, cnt, val in tags:
        out += struct.pack("<HHIHH" if typ == 3 and cnt == 1 else "<HHII", tag, typ, cnt,
                           *((val, 0) if typ == 3 and cnt == 1 else (val,)))
    return out + struct.pack("<I3H", 0, 8, 8, 8) + data


def fuzz_input(target, name):
    """A regression input of tests/fuzz/regress without the harness's selector byte."""
    with open(os.path.join(REGRESS, target, name), "rb") as f:
        return f.read()[1:]


with tempfile.TemporaryDirectory() as d:
    # A tiny TGA that declares 28018 x 65535 pixels (22 GB as floats): refused
    # from its header, in little memory.
    tga = struct.pack("<BBBHHBHHHHBB", 0, 0, 2, 0, 0, 0, 0, 0, 28018, 65535, 24, 0) + b"\0" * 400
    with open(os.path.join(d, "huge.tga"), "wb") as f:
        f.write(tga)
    rc, err, rss = peak_rss_mb(["heightmap", "huge.tga", "n.png"], d)
    check(rc == 2 and "cap" in err, f"declared 28018x65535 image refused (rc {rc}: {err.strip()})")
    check(rss < 1024, f"... without allocating it (peak RSS {rss:.0f} MiB)")

    # A 4x4 TIFF declaring 8192 x 8192 tiles: OpenImageIO reads a row of tiles
    # at their declared size (1.1 GB here; 15.8 GB with 32768 x 32768 tiles,
    # tests/fuzz/regress/image). The cap counts the tiles, not just the image.
    with open(os.path.join(d, "tiles.tif"), "wb") as f:
        f.write(tiled_tiff(4, 4, 8192))
    rc, err, rss = peak_rss_mb(["heightmap", "tiles.tif", "n.png"], d, BUMPGRAD_MAX_MB="64")
    check(rc == 2 and "tiles.tif" in err and "8192x8192 tiles" in err and "cap" in err,
          f"a 4x4 image in 8192x8192 tiles is refused by its tiles (rc {rc}: {err.strip()})")
    check(rss < 512, f"... without allocating them (peak RSS {rss:.0f} MiB)")
    with open(os.path.join(d, "small_tiles.tif"), "wb") as f:
        f.write(tiled_tiff(4, 4, 16))
    rc, err, _ = run(["heightmap", "small_tiles.tif", "n.png"], d, BUMPGRAD_MAX_MB="64")
    check(rc != 0 and "cap" not in err,
          f"... while 16x16 tiles pass the cap (to the decoder's own error: {err.strip()})")

    # An RLE8 BMP declaring 32768 x 32768 pixels: OpenImageIO's BMP reader
    # decodes RLE data into a zeroed width x height buffer inside open() (1 GB
    # here), before any spec can be checked, so the header is checked first.
    pal = b"\0" * 1024
    rle = b"\x00\x01"  # end of bitmap
    off = 14 + 40 + len(pal)
    bmp = (b"BM" + struct.pack("<IHHI", off + len(rle), 0, 0, off)
           + struct.pack("<IiiHHIIiiII", 40, 32768, 32768, 1, 8, 1, len(rle), 2835, 2835, 256, 0)
           + pal + rle)
    with open(os.path.join(d, "rle.bmp"), "wb") as f:
        f.write(bmp)
    rc, err, rss = peak_rss_mb(["heightmap", "rle.bmp", "n.png"], d, BUMPGRAD_MAX_MB="64")
    check(rc == 2 and "rle.bmp" in err and "RLE8 BMP" in err and "cap" in err,
          f"a 32768^2 RLE8 BMP is refused before OpenImageIO decodes it (rc {rc}: {err.strip()})")
    check(rss < 512, f"... without allocating its buffer (peak RSS {rss:.0f} MiB)")
    bmp16 = bmp[:28] + struct.pack("<H", 16) + bmp[30:]
    with open(os.path.join(d, "rle16.bmp"), "wb") as f:
        f.write(bmp16)
    rc, err, _ = run(["heightmap", "rle16.bmp", "n.png"], d)
    check(rc == 2 and "RLE8 compression with 16 bits per pixel" in err,
          f"RLE8 with 16 bits per pixel (OpenImageIO 2.4 segfaults) is refused ({err.strip()})")

    rc, err, _ = run(["render", "--size", "16384x16384", "--spp", "256", "-o", "x.png"], d)
    check(rc == 2 and "cap" in err, f"a 16384^2 x 256 spp render is refused up front ({err.strip()})")
    rc, err, _ = run(["render", "--size", "512x512", "-o", "x.png"], d, BUMPGRAD_MAX_MB="1")
    check(rc == 2 and "BUMPGRAD_MAX_MB" in err, "the cap is BUMPGRAD_MAX_MB's")
    rc, err, _ = run(["render", "--size", "64x64", "-o", "x.png"], d)
    check(rc == 0, "... and the default lets a normal render through")

    # One voxel thick: 5e7 voxels under the voxel limit, but ~6.5 GB of leaves.
    rc, err, _ = run(["volume", "--function", "noise", "--bbox", "0,0,0,70.7,70.7,0",
                      "--voxel-size", "0.01", "-o", "v.vdb"], d)
    check(rc == 2 and "cap" in err, f"a one-voxel-thick box is judged by its leaves ({err.strip()})")
    rc, err, _ = run(["volume", "--function", "noise", "--bbox", "0,0,0,0.0001,0.0001,0.0001",
                      "--voxel-size", "1e-5", "-o", "v.vdb"], d)
    check(rc == 2 and "out of memory" not in err and "voxel" in err,
          f"OpenVDB's refusal of a tiny voxel is named as such ({err.strip()})")

    # VDB files: OpenVDB allocates whatever a length field says before reading
    # (a 20 KB file cost 1.8 GB and 9 s, probe child and parent). The layout
    # before the trees is checked first, and the grids' file_mem_bytes against
    # the cap.
    with open(os.path.join(d, "pts.csv"), "w") as f:
        f.write("x,y,z,nx,ny,nz\n0.1,0.1,0.1,0,0,1\n")
    with open(os.path.join(d, "meta.vdb"), "wb") as f:
        f.write(fuzz_input("vdb", "vdb-meta-string-1.7GB"))
    rc, err, rss = peak_rss_mb(["perturb", "--height-grid", "meta.vdb", "-i", "pts.csv",
                                "-o", "o.csv"], d)
    check(rc == 2 and "meta.vdb" in err and "1701667182 bytes runs past the end" in err,
          f"a VDB metadata length past the end of the file is refused ({err.strip()})")
    check(rss < 512, f"... without allocating it (peak RSS {rss:.0f} MiB, probe child included)")
    rc, err, _ = run(["volume", "--function", "noise", "--bbox", "0,0,0,4,4,4",
                      "--voxel-size", "0.0625", "-o", "v64.vdb"], d)
    check(rc == 0, f"a 64^3 volume bakes ({err.strip()})")
    rc, err, _ = run(["perturb", "--height-grid", "v64.vdb", "-i", "pts.csv", "-o", "o.csv"], d,
                     BUMPGRAD_MAX_MB="2")
    check(rc == 2 and "file_mem_bytes" in err and "BUMPGRAD_MAX_MB" in err,
          f"... its 7 MiB of grids are refused under BUMPGRAD_MAX_MB=2 ({err.strip()})")
    rc, err, _ = run(["perturb", "--height-grid", "v64.vdb", "-i", "pts.csv", "-o", "o.csv"], d)
    check(rc == 0, f"... and read under the default cap ({err.strip()})")
    # The probe child's own cap (BUMPGRAD_VDB_MAX_MB=1: 1 MiB over its mappings):
    # reading fails in the child, and the parent must then refuse the file,
    # never read it in-process without that cap.
    os.remove(os.path.join(d, "o.csv"))
    rc, err, _ = run(["perturb", "--height-grid", "v64.vdb", "-i", "pts.csv", "-o", "o.csv"], d,
                     BUMPGRAD_VDB_MAX_MB="1")
    check(rc == 2 and "v64.vdb" in err and "BUMPGRAD_VDB_MAX_MB" in err
          and not os.path.exists(os.path.join(d, "o.csv")),
          f"a probe child stopped by its memory cap fails the command ({err.strip()})")

    # A corrupt VDB is read by OpenVDB once, in the probe child, whose message
    # comes back: the parent does not open the file again after reaping it
    # (a tree that asks for 1.9 GB before failing cost that twice).
    strace = shutil.which("strace")
    if strace:
        trace = os.path.join(d, "strace.log")
        r = subprocess.run([strace, "-f", "-e", "trace=openat,wait4", "-o", trace, EXE,
                            "perturb", "--height-grid", "v64.vdb:nosuch", "-i", "pts.csv",
                            "-o", "o.csv"], cwd=d, capture_output=True, text=True,
                           env=dict(os.environ, BUMPGRAD_NO_PROGRESS="1"))
        lines = open(trace).read().splitlines()
        # strace -f splits a blocking call into "wait4(... <unfinished ...>" and
        # "<... wait4 resumed> ...": the status is on whichever line ends it.
        reaped = [i for i, l in enumerate(lines) if "wait4" in l and "WEXITSTATUS(s) == 3" in l]
        parent = lines[reaped[0]].split()[0] if reaped else None
        again = [l for l in lines[reaped[0] + 1:] if l.split()[0] == parent
                 and 'v64.vdb"' in l] if reaped else []
        check(r.returncode == 2 and "no grid named 'nosuch'" in r.stderr and reaped and not again,
              f"a VDB the probe child refused is not read again in the parent "
              f"(rc {r.returncode}, child reaped: {bool(reaped)}, reopened: {again})")
    else:
        print("skip: strace not found (the VDB read-once check)")

    # The probe child's time-out (BUMPGRAD_CHILD_TIMEOUT, then the parent's 1 s
    # of grace and SIGKILL). No valid file is slow enough to read on every
    # machine, so the child is held from outside: strace delays the return of
    # its alarm() call (the alarm is already armed then; only the children of
    # the I/O shim call alarm) by 3 s, three times the 1 s time-out, so the
    # child is past its time-out on any machine, fast or loaded. A parent that
    # took a killed child for a good probe would read the file and exit 0.
    delay_ok = strace and subprocess.run(
        [strace, "-qq", "-o", os.devnull, "-e", "trace=alarm", "-e",
         "inject=alarm:delay_exit=1", "true"], capture_output=True).returncode == 0
    if delay_ok:
        if os.path.exists(os.path.join(d, "o.csv")):
            os.remove(os.path.join(d, "o.csv"))
        t0 = time.monotonic()
        r = subprocess.run([strace, "-qq", "-f", "-o", os.devnull, "-e", "trace=alarm", "-e",
                            "inject=alarm:delay_exit=3000000", EXE, "perturb", "--height-grid",
                            "v64.vdb", "-i", "pts.csv", "-o", "o.csv"], cwd=d,
                           capture_output=True, text=True, timeout=60,
                           env=dict(os.environ, BUMPGRAD_NO_PROGRESS="1",
                                    BUMPGRAD_CHILD_TIMEOUT="1"))
        dt = time.monotonic() - t0
        check(r.returncode == 2 and "'v64.vdb': reading the VDB file took over 1 s" in r.stderr
              and not os.path.exists(os.path.join(d, "o.csv")),
              f"a probe child past BUMPGRAD_CHILD_TIMEOUT=1 fails the command, nothing written "
              f"(rc {r.returncode}, {dt:.1f} s, {r.stderr.strip()})")
    else:
        print("skip: strace with syscall delay injection not usable (the VDB probe time-out)")

    # A PLY header without end_header: assimp loops forever in the import child.
    with open(os.path.join(d, "h.ply"), "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n")
    rc, err, dt = run(["mesh", "h.ply", "o.ply"], d, timeout=60, BUMPGRAD_CHILD_TIMEOUT="2")
    check(rc == 2 and "took more than 2 s" in err and dt < 30,
          f"a hanging import is stopped after the time-out ({dt:.1f} s, {err.strip()})")
    # The parent killed while the child hangs: the child must not outlive it.
    p = subprocess.Popen([EXE, "mesh", "h.ply", "o.ply"], cwd=d, stderr=subprocess.DEVNULL)
    kids = []
    for _ in range(300):  # the module loads first: wait for the import child
        kids = subprocess.run(["pgrep", "-P", str(p.pid)], capture_output=True,
                              text=True).stdout.split()
        if kids:
            break
        time.sleep(0.1)
    time.sleep(0.5)
    p.kill()
    p.wait()
    time.sleep(1.0)
    alive = [k for k in kids if os.path.exists(f"/proc/{k}") and
             open(f"/proc/{k}/stat").read().split()[2] != "Z"]
    check(kids and not alive, f"the import child dies with its parent (children {kids}, alive {alive})")

    # FIFOs as inputs: refused at once, never a blocked open.
    for cmd, name in (("heightmap", "f.png"), ("mesh", "f.obj")):
        os.mkfifo(os.path.join(d, name))
        rc, err, dt = run([cmd, name, "out.png" if cmd == "heightmap" else "out.ply"], d, timeout=30)
        check(rc != 0 and "regular file" in err and dt < 20, f"{cmd} refuses a FIFO input ({err.strip()})")

sys.exit(finish("limits"))
