# SPDX-License-Identifier: MIT
"""Images on "-": bg_image_write_as / bg_image_read_as on standard output and
input, and the heightmap tool from stdin to stdout (docs/IO.md, "Images on -").

Usage: test_image_stream.py TEST_IMAGE_STREAM_EXE

The PNG bytes are decoded here with zlib (our own few lines, not OpenImageIO),
so the check of what went to stdout does not trust the code that wrote it.
"""
import os
import pty
import resource
import signal
import struct
import subprocess
import sys
import tempfile
import zlib

import numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import PASSED, check, clean_env, finish  # noqa: E402

EXE = os.path.abspath(sys.argv[1])


def run(args, stdin=b"", env=None):
    return subprocess.run([EXE] + args, input=stdin, env=clean_env(env), capture_output=True,
                          timeout=120)


def pattern(w, h, c=3):
    y, x, ch = np.meshgrid(np.arange(h), np.arange(w), np.arange(c), indexing="ij")
    return ((7 * x + 13 * y + 5 * ch) % 256).astype(np.uint8)


def decode_png(data):
    """8-bit gray/RGB/RGBA, non-interlaced PNG -> (h, w, c) uint8."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "PNG signature"
    pos, idat, ihdr = 8, b"", None
    while pos < len(data):
        n, typ = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        crc, = struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])
        assert zlib.crc32(typ + body) & 0xffffffff == crc, "chunk CRC"
        if typ == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif typ == b"IDAT":
            idat += body
        pos += 12 + n
        if typ == b"IEND":
            break
    w, h, depth, ctype, _, _, interlace = ihdr
    assert depth == 8 and interlace == 0, "8-bit non-interlaced"
    c = {0: 1, 2: 3, 4: 2, 6: 4}[ctype]
    raw = zlib.decompress(idat)
    stride = w * c
    out = np.zeros((h, stride), np.int32)
    prev = np.zeros(stride, np.int32)
    for r in range(h):
        f = raw[r * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, r * (stride + 1) + 1).astype(np.int32)
        cur = np.zeros(stride, np.int32)
        for i in range(stride):
            a = cur[i - c] if i >= c else 0
            b = prev[i]
            d = prev[i - c] if i >= c else 0
            if f == 0:
                p = 0
            elif f == 1:
                p = a
            elif f == 2:
                p = b
            elif f == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - d), abs(a - d), abs(a + b - 2 * d)
                p = a if pa <= pb and pa <= pc else (b if pb <= pc else d)
            cur[i] = (line[i] + p) & 255
        out[r] = cur
        prev = cur
    return out.reshape(h, w, c).astype(np.uint8)


def encode_png_gray(img):
    """(h, w) uint8 -> PNG bytes, filter 0."""
    def chunk(t, b):
        return struct.pack(">I", len(b)) + t + b + struct.pack(">I", zlib.crc32(t + b) & 0xffffffff)
    h, w = img.shape
    raw = b"".join(b"\0" + img[r].tobytes() for r in range(h))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def read_back(data, fmt="auto"):
    r = run(["read", fmt], stdin=data)
    if r.returncode != 0:
        return r, None
    v = [int(t) for t in r.stdout.split()]
    return r, (v[0], v[1], v[2], np.array(v[3:], np.int64))


# 1. PNG on stdout: signature, size and every byte, decoded independently.
r = run(["write", "png", "16", "8"])
ok = r.returncode == 0 and r.stdout[:8] == b"\x89PNG\r\n\x1a\n"
check(ok, "write png to stdout: exit 0 and PNG signature (%d, %r)" % (r.returncode, r.stderr))
if ok:
    img = decode_png(r.stdout)
    check(img.shape == (8, 16, 3) and np.array_equal(img, pattern(16, 8)),
          "the PNG on stdout decodes (zlib, here) to the written 16x8 RGB pattern")
png16x8 = r.stdout

# 2. No format given: PNG.
r = run(["write", "default", "4", "4"])
check(r.returncode == 0 and r.stdout[:8] == b"\x89PNG\r\n\x1a\n",
      "no format with \"-\": PNG (%r)" % r.stderr)

# 3. Round trips through the stream reader, format found from the content.
magic = {"png": b"\x89PNG", "exr": b"\x76\x2f\x31\x01", "tif": (b"II*\0", b"MM\0*"),
         "ppm": b"P6", "bmp": b"BM", "jpg": b"\xff\xd8\xff", "tga": None, "hdr": b"#?"}
for fmt, m in magic.items():
    r = run(["write", fmt, "16", "8"])
    ms = m if isinstance(m, tuple) else (m,)
    good = r.returncode == 0 and (m is None or any(r.stdout.startswith(x) for x in ms))
    check(good, "write %s to stdout: exit 0, magic (%d bytes, %r)" % (fmt, len(r.stdout),
                                                                         r.stderr[-200:]))
    if not good:
        continue
    rb, got = read_back(r.stdout)
    check(got is not None and got[:3] == (16, 8, 3),
          "%s read back from stdin by its content: 16x8x3 (%r)" % (fmt, rb.stderr[-200:]))
    if got is None:
        continue
    diff = np.abs(got[3] - pattern(16, 8).reshape(-1).astype(np.int64)).max()
    # jpg is lossy; hdr keeps 8 bits of mantissa shared by the pixel's channels.
    tol = {"jpg": 40, "hdr": 2, "exr": 0}.get(fmt, 0)
    check(diff <= tol, "%s read back equals the pattern within %d/255 (max %d)" % (fmt, tol, diff))

# 4. A named reader that does not match the content, junk, empty input.
r = run(["read", "bmp"], stdin=png16x8)
check(r.returncode == 2 and b"bmp" in r.stderr and b"<stdin>" in r.stderr,
      "PNG bytes read as bmp: exit 2 naming the format (%r)" % r.stderr)
r = run(["read", "auto"], stdin=b"not an image at all\n" * 10)
check(r.returncode == 2 and b"<stdin>" in r.stderr, "junk on stdin: exit 2 (%r)" % r.stderr)
r = run(["read", "auto"], stdin=b"")
check(r.returncode == 2 and b"empty" in r.stderr, "empty stdin: exit 2 (%r)" % r.stderr)
r = run(["read", "nosuchformat"], stdin=png16x8)
check(r.returncode == 2 and b"unknown image format" in r.stderr,
      "unknown format name: exit 2 (%r)" % r.stderr)

# 5. Formats OpenImageIO 2.4 cannot stream: a clear refusal naming them, nothing written.
for fmt in ("sgi", "fits", "rla"):
    r = run(["write", fmt, "4", "4"])
    check(r.returncode == 2 and r.stdout == b"" and b"stream" in r.stderr and
          fmt.encode() in r.stderr.lower(),
          "write %s to stdout refused, named, nothing on stdout (%r)" % (fmt, r.stderr))
r = run(["read", "fits"], stdin=png16x8)
check(r.returncode == 2 and b"fits" in r.stderr and b"stream" in r.stderr,
      "read fits from stdin refused, named (%r)" % r.stderr)

# 6. The reader goes away: EPIPE is an error (exit 1), not a death by SIGPIPE.
sh = "'%s' write png 1024 1024 random | head -c 10 > /dev/null; echo ${PIPESTATUS[0]}" % EXE
p = subprocess.run(["bash", "-c", sh], capture_output=True, text=True, timeout=120)
check(p.stdout.strip() == "1" and "Broken pipe" in p.stderr,
      "| head -c 10: exit 1 with the EPIPE message, no signal (%r %r)" % (p.stdout, p.stderr))

# 7. Standard output a regular file, and that file on a full disk (RLIMIT_FSIZE).
with tempfile.TemporaryDirectory() as d:
    path = os.path.join(d, "o.png")
    with open(path, "wb") as f:
        r = subprocess.run([EXE, "write", "png", "16", "8"], stdout=f, stderr=subprocess.PIPE,
                           timeout=120)
    with open(path, "rb") as f:
        check(r.returncode == 0 and f.read() == png16x8, "stdout a regular file: the same bytes")

    def small():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
    with open(path, "wb") as f:
        p = subprocess.run([EXE, "write", "png", "512", "512", "random"], stdout=f,
                           stderr=subprocess.PIPE, preexec_fn=small, timeout=120)
    check(p.returncode == 1 and b"<stdout>" in p.stderr,
          "full disk under stdout: exit 1 naming <stdout> (%d %r)" % (p.returncode, p.stderr))

# 8. A terminal as stdout is refused before anything is written.
master, slave = pty.openpty()
p = subprocess.run([EXE, "write", "png", "4", "4"], stdout=slave, stderr=subprocess.PIPE,
                   timeout=60)
os.close(slave)
os.set_blocking(master, False)
try:
    leaked = os.read(master, 100)
except (BlockingIOError, OSError):
    leaked = b""
os.close(master)
check(p.returncode == 2 and b"terminal" in p.stderr and b"PNG" not in leaked,
      "stdout a terminal: exit 2, no bytes (%r)" % p.stderr)

# 9. stdin larger than the allocation cap: refused at the cap.
big = run(["write", "png", "1024", "1024", "random"]).stdout
check(len(big) > 2 << 20, "a random 1024x1024 PNG is over 2 MiB (%d bytes)" % len(big))
r = run(["read", "auto"], stdin=big, env={"BUMPGRAD_MAX_MB": "1"})
check(r.returncode == 2 and b"<stdin>" in r.stderr and b"BUMPGRAD_MAX_MB" in r.stderr,
      "stdin over BUMPGRAD_MAX_MB=1: exit 2 naming the cap (%r)" % r.stderr)
r = run(["read", "auto"], stdin=big, env={"BUMPGRAD_MAX_MB": "64"})
check(r.returncode == 0 and r.stdout.startswith(b"1024 1024 3 "),
      "the same stdin under a 64 MiB cap reads (%r)" % r.stderr[-200:])

# 10. heightmap - -: a gray PNG on stdin, the normal map on stdout, against numpy.
h, w = 6, 9
gray = ((np.arange(h)[:, None] * 37 + np.arange(w)[None, :] * 11) % 256).astype(np.uint8)
r = run(["heightmap"], stdin=encode_png_gray(gray))
check(r.returncode == 0 and r.stdout[:8] == b"\x89PNG\r\n\x1a\n",
      "heightmap - -: exit 0, PNG on stdout (%r)" % r.stderr)
if r.returncode == 0:
    got = decode_png(r.stdout).astype(np.float64)
    H = gray.astype(np.float64) / 255.0
    xs, ys = np.arange(w), np.arange(h)
    a = H[:, np.minimum(xs + 1, w - 1)] - H[:, np.maximum(xs - 1, 0)]
    b = H[np.maximum(ys - 1, 0), :] - H[np.minimum(ys + 1, h - 1), :]
    n = np.stack([-a, -b, np.ones_like(a)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    want = np.round(255.0 * (0.5 * n + 0.5))
    check(got.shape == (h, w, 3) and np.abs(got - want).max() <= 1,
          "heightmap from stdin: s x t normals within 1/255 (max %s)"
          % (np.abs(got - want).max() if got.shape == want.shape else got.shape))
r = run(["heightmap"], stdin=b"")
check(r.returncode == 2 and r.stdout == b"", "heightmap with empty stdin: exit 2, no output")

check(PASSED[0] > 0, "some checks ran")
sys.exit(finish("tools_image_stream"))
