# SPDX-License-Identifier: MIT
"""Images on "-": `render -o -` and `heightmap - -` stream through OpenImageIO's
memory I/O (bg_image_write_as / bg_image_read_as), the report moves to stderr,
a closed pipe is a clean exit 1, and the refusals (--json with -o -, --bits
float with a PNG stream, a --format against the extension, a format the
stream cannot carry) are exit 2 naming the reason; heightmap's --format and
--input-format pick the formats on "-"; `mesh --bake-normal-map -` streams
the map. The PNGs are decoded here with zlib, independently of the command.
usage: test_image_stream.py BUMPGRAD"""
import os
import struct
import subprocess
import sys
import tempfile
import zlib
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish, run as harness_run  # noqa: E402

EXE = sys.argv[1]


def run(args, stdin=None):
    rc, out, err = harness_run(EXE, args, stdin, {"BUMPGRAD_NO_PROGRESS": "1"}, text=False)
    return rc, out, err.decode(errors="replace")


def png_decode(data):
    """(width, height, channels, bit depth, raw scanline bytes) of a PNG, or None."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    pos, ihdr, idat = 8, None, b""
    while pos + 8 <= len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBB", body[:10])
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
        pos += 12 + n
    if not ihdr:
        return None
    w, h, depth, ctype = ihdr
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(ctype, 0)
    return w, h, channels, depth, zlib.decompress(idat)


def decodes(png, w, h):
    d = png_decode(png)
    if not d:
        return False
    dw, dh, ch, depth, raw = d
    return (dw, dh) == (w, h) and ch > 0 and len(raw) == h * (1 + w * ch * depth // 8)


# render -o - --format png: a complete PNG of the asked size on stdout, the
# report lines on stderr.
rc, out, err = run(["render", "--size", "16x12", "-o", "-", "--format", "png"])
check(rc == 0 and decodes(out, 16, 12),
      "render -o - --format png: a 16x12 PNG on stdout (rc %d, %r)" % (rc, out[:24]))
check("wrote - 16x12" in err and "stats " in err, "the report goes to stderr: %r" % err)
rc, out2, err = run(["render", "--size", "16x12", "-o", "-"])
check(rc == 0 and out2 == out, "-o - without --format is the same PNG")
rc, out, err = run(["render", "--size", "16x12", "-o", "-", "--format", "exr"])
check(rc == 0 and out[:4] == b"\x76\x2f\x31\x01", "-o - --format exr: OpenEXR magic: %r" % out[:4])
rc, out, err = run(["render", "--size", "16x12", "-o", "-", "--format", ".EXR"])
check(rc == 0 and out[:4] == b"\x76\x2f\x31\x01",
      "--format .EXR (a dot, upper case) is --format exr (rc %d, %r)" % (rc, err))
# A file output still reports on stdout and the extension decides.
with tempfile.TemporaryDirectory() as d:
    f = os.path.join(d, "r.png")
    rc, out, err = run(["render", "--size", "8x8", "-o", f])
    check(rc == 0 and b"wrote " + f.encode() in out, "a file output reports on stdout")
    rc, out, err = run(["render", "--size", "8x8", "-o", f, "--format", "exr"])
    check(rc == 2 and "--format exr disagrees" in err, "--format against the extension: %r" % err)
rc, out, err = run(["render", "--size", "8x8", "-o", "-", "--format", "sgi2"])
check(rc == 2 and "--format" in err and out == b"", "an unknown --format: exit 2: %r" % err)
rc, out, err = run(["render", "--size", "8x8", "-o", "-", "--json"])
check(rc == 2 and "--json" in err and out == b"", "--json with -o - refused, exit 2: %r" % err)

# A reader that closes the pipe early: exit 1 with a message, no signal death.
p = subprocess.run(["bash", "-c", '"$0" render --size 512x512 -o - --format exr 2>"$1" | '
                    'head -c 10 >/dev/null; echo "${PIPESTATUS[0]}"', EXE, os.devnull],
                   capture_output=True, text=True, timeout=120,
                   env=dict(os.environ, BUMPGRAD_NO_PROGRESS="1"))
check(p.stdout.strip() == "1", "render -o - | head -c 10: exit 1 (got %r)" % p.stdout.strip())
p = subprocess.run(["bash", "-c", '{ "$0" render --size 512x512 -o - --format exr | '
                    'head -c 10 >/dev/null; } 2>&1', EXE], capture_output=True, text=True,
                   timeout=120, env=dict(os.environ, BUMPGRAD_NO_PROGRESS="1"))
check("Broken pipe" in p.stdout and "error" in p.stdout,
      "the closed pipe is named: %r" % p.stdout.strip()[-200:])

# heightmap - -: a PNG on stdin to a PNG of the same size on stdout.
rc, src, err = run(["render", "--size", "24x20", "-o", "-"])
rc, out, err = run(["heightmap", "-", "-", "--strength", "2"], src)
check(rc == 0 and decodes(out, 24, 20), "heightmap - -: a 24x20 PNG in, a 24x20 PNG out (rc %d, %r)"
      % (rc, err))
with tempfile.TemporaryDirectory() as d:
    f = os.path.join(d, "in.png")
    open(f, "wb").write(src)
    ref = os.path.join(d, "ref.png")
    rc2, _, _ = run(["heightmap", f, ref, "--strength", "2"])
    check(rc == 0 and rc2 == 0 and png_decode(open(ref, "rb").read())[4] == png_decode(out)[4],
          "heightmap - - gives the same pixels as with files")
rc, out, err = run(["heightmap", "--bits", "16", "-", "-"], src)
d = png_decode(out) if rc == 0 else None
check(d is not None and d[3] == 16 and decodes(out, 24, 20), "heightmap --bits 16 -: a 16-bit PNG")
rc, out, err = run(["heightmap", "--bits", "float", "-", "-"], src)
check(rc == 2 and "float" in err and out == b"",
      "--bits float with OUT - (a PNG) refused, exit 2: %r" % err)
rc, out, err = run(["heightmap", "--json", "-", "-"], src)
check(rc == 2 and "--json" in err and out == b"", "heightmap --json with OUT - refused: %r" % err)
rc, out, err = run(["heightmap", "-", "-"], b"not an image")
check(rc == 2 and out == b"" and "error" in err, "garbage on stdin: exit 2: %r" % err)
check("--input-format" in err, "garbage on stdin: the message says how to name its format: %r" % err)

# heightmap --format: the format of OUT "-" (render --format's rule: a file's
# extension decides, a --format against it is refused); --input-format: IN's.
rc, out, err = run(["heightmap", "-", "-", "--format", "png", "--strength", "2"], src)
rc2, out2, _ = run(["heightmap", "-", "-", "--strength", "2"], src)
check(rc == 0 and rc2 == 0 and out == out2 and decodes(out, 24, 20),
      "heightmap --format png -: the same bytes as without --format (rc %d, %r)" % (rc, err))
rc, out, err = run(["heightmap", "-", "-", "--format", "exr", "--bits", "float"], src)
check(rc == 0 and out[:4] == b"\x76\x2f\x31\x01",
      "heightmap --format exr --bits float -: OpenEXR on stdout (rc %d, %r, %r)" % (rc, out[:4], err))
rc, out, err = run(["heightmap", "-", "-", "--format", "tif", "--to-derivative"], src)
check(rc == 0 and out[:4] == b"II*\x00",
      "heightmap --to-derivative --format tif -: a float TIFF on stdout (rc %d, %r, %r)"
      % (rc, out[:4], err))
rc, out, err = run(["heightmap", "-", "-", "--format", "jpg", "--bits", "16"], src)
check(rc == 2 and out == b"" and "jpg" in err and "16-bit" in err,
      "heightmap --format jpg --bits 16 -: refused naming the format, exit 2: %r" % err)
rc, out, err = run(["heightmap", "-", "-", "--format", "sgi"], src)
check(rc == 2 and out == b"" and "sgi" in err,
      "heightmap --format sgi - (not streamable): refused by name, exit 2: %r" % err)
rc, out, err = run(["heightmap", "-", "-", "--format", "nosuch"], src)
check(rc == 2 and out == b"" and "--format" in err and "nosuch" in err,
      "heightmap --format nosuch: exit 2 naming the option: %r" % err)
rc, out, err = run(["heightmap", "-", "-", "--input-format", "exr"], src)
check(rc == 2 and out == b"" and "exr" in err,
      "heightmap --input-format exr with a PNG on stdin: exit 2 naming the format: %r" % err)
with tempfile.TemporaryDirectory() as d:
    f = os.path.join(d, "in.png")
    open(f, "wb").write(src)
    o = os.path.join(d, "o.png")
    rc, out, err = run(["heightmap", f, o, "--format", "exr"])
    check(rc == 2 and "disagrees" in err and not os.path.exists(o),
          "heightmap --format exr with OUT o.png: refused, no file: %r" % err)
    rc, out, err = run(["heightmap", f, o, "--format", "PNG", "--strength", "2"])
    check(rc == 0 and png_decode(open(o, "rb").read())[4] == png_decode(out2)[4],
          "heightmap --format PNG with OUT o.png: agrees with the extension, same pixels")
    # A TGA on stdin named by --input-format gives the pixels of the file.
    t = os.path.join(d, "in.tga")
    rc, _, err = run(["heightmap", f, t, "--bits", "8", "--strength", "0"])
    tga = open(t, "rb").read() if rc == 0 else b""
    rc, out, err = run(["heightmap", "-", "-", "--input-format", "tga", "--strength", "2"], tga)
    rc2, _, _ = run(["heightmap", t, o, "--strength", "2"])
    check(rc == 0 and rc2 == 0 and png_decode(out)[4] == png_decode(open(o, "rb").read())[4],
          "heightmap --input-format tga - gives the pixels of the TGA file (rc %d, %r)" % (rc, err))

# mesh --bake-normal-map -: the map on stdout (--format, PNG by default), the
# same bytes as the map file; the summary on stderr; refusals before the mesh
# is opened: both outputs on "-", --json, a --format against a file's name.
with tempfile.TemporaryDirectory() as d:
    plane = os.path.join(d, "plane.obj")
    with open(plane, "w") as f:
        f.write("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nvt 0 0\nvt 1 0\n"
                "vt 1 1\nvt 0 1\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n")
    bake = ["mesh", plane, "--size", "16x12", "--amplitude", "0.05", "--frequency", "3"]
    rc, out, err = run(bake + ["--bake-normal-map", "-"])
    check(rc == 0 and decodes(out, 16, 12) and "bake: - 16x12" in err,
          "mesh --bake-normal-map -: a 16x12 PNG on stdout, the summary on stderr (rc %d, %r)"
          % (rc, err[-200:]))
    f = os.path.join(d, "map.png")
    rc2, out2, _ = run(bake + ["--bake-normal-map", f])
    check(rc2 == 0 and os.path.exists(f) and open(f, "rb").read() == out and b"bake: " in out2,
          "mesh --bake-normal-map -: the same bytes as the map file")
    rc, out, err = run(bake + ["--bake-normal-map", "-", "--format", "exr"])
    check(rc == 0 and out[:4] == b"\x76\x2f\x31\x01",
          "mesh --bake-normal-map - --format exr: OpenEXR on stdout (rc %d, %r)" % (rc, err[-200:]))
    ply = os.path.join(d, "o.ply")
    rc, out, err = run(bake + [ply, "--bake-normal-map", "-"])
    check(rc == 0 and decodes(out, 16, 12) and os.path.exists(ply),
          "mesh OUT.ply --bake-normal-map -: the PLY file and the map on stdout (rc %d)" % rc)
    rc, out, err = run(bake + ["--bake-normal-map", "-", "--format", "sgi"])
    check(rc == 2 and out == b"" and "sgi" in err,
          "mesh --bake-normal-map - --format sgi: refused by name, nothing on stdout: %r" % err)
rc, out, err = run(["mesh", "no_such.ply", "-", "--bake-normal-map", "-", "--size", "8"])
check(rc == 2 and "both" in err and out == b"",
      "mesh - --bake-normal-map -: two streams on stdout refused, exit 2: %r" % err)
rc, out, err = run(["mesh", "no_such.ply", "--bake-normal-map", "-", "--size", "8", "--json"])
check(rc == 2 and "--json" in err and out == b"",
      "mesh --json --bake-normal-map -: refused, exit 2: %r" % err)
rc, out, err = run(["mesh", "no_such.ply", "--bake-normal-map", "m.png", "--size", "8",
                    "--format", "exr"])
check(rc == 2 and "disagrees" in err and out == b"",
      "mesh --format exr with --bake-normal-map m.png: refused, exit 2: %r" % err)

sys.exit(finish("cli_image_stream"))
