#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""`bumpgrad heightmap --generate` writes a map that tiles: laid next to itself,
the step across each edge (last column -> first column, last row -> first
row) is no larger than the steps between neighbours inside the map. The
control shows the measure can fail: the same pixel centres evaluated without
the period (`bumpgrad eval`) jump at the edge. Also: --volume and --eval accept
--period, and a period/seed mistake is a usage error (exit 2).

usage: test_tile.py BUMPGRAD"""
import os
import subprocess
import sys
import tempfile

import numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish, ppm_header  # noqa: E402

EXE = sys.argv[1]


def run(args, **kw):
    return subprocess.run([EXE] + args, capture_output=True, **kw)


def read_ppm16(data):
    """A binary P6 (maxval 255 or 65535) -> float array (H, W, 3) in [0, 1]."""
    w, h, m, pos = ppm_header(data)
    assert m in (255, 65535), m
    dt, size = (">u2", 6) if m == 65535 else ("u1", 3)
    return np.frombuffer(data[pos:pos + w * h * size], dtype=dt).reshape(h, w, 3) / float(m)


def edge_vs_inside(img):
    """(largest step across the wrapped edges, largest step between neighbours)."""
    dx = np.abs(np.diff(img, axis=1)).max()
    dy = np.abs(np.diff(img, axis=0)).max()
    ex = np.abs(img[:, 0] - img[:, -1]).max()
    ey = np.abs(img[0, :] - img[-1, :]).max()
    return max(ex, ey), max(dx, dy)


W, H, P = 160, 96, (5, 3)
for kind, extra in (("normal", ["--function", "fbm", "--amplitude", "0.05"]),
                    ("height", ["--function", "turbulence", "--seed", "7"]),
                    ("normal", ["--function", "noise", "--lacunarity", "3"])):
    r = run(["heightmap", "-", "--generate", f"{W}x{H}", "--period", f"{P[0]},{P[1]}",
             "--map", kind, "--format", "ppm"] + extra)
    check(r.returncode == 0, f"--generate {kind} {' '.join(extra)}: exit 0 "
          f"({r.stderr.decode().strip()})")
    if r.returncode:
        continue
    img = read_ppm16(r.stdout)
    check(img.shape == (H, W, 3), f"{kind}: {W}x{H} pixels")
    edge, inside = edge_vs_inside(img)
    check(edge <= inside, f"{kind} {' '.join(extra)}: edge step {edge:.4f} <= largest inside "
          f"step {inside:.4f} (tiles)")
    check(img.std() > 0.01, f"{kind}: the map is not flat (std {img.std():.4f})")

# Control: the same pixel centres (one period 5 x 3 at frequency 1) without
# --period: the value at the first and the last column of each row, against
# neighbours inside. Without the wrap the edge step is far larger.
with tempfile.TemporaryDirectory() as tmp:
    pts = os.path.join(tmp, "p.csv")
    ys = [(H - j - 0.5) * P[1] / H for j in range(H)]
    with open(pts, "w") as f:
        f.write("x,y,z\n")
        for y in ys:
            for x in ((W - 1.5) * P[0] / W, (W - 0.5) * P[0] / W, 0.5 * P[0] / W):
                f.write(f"{x!r},{y!r},0\n")
    for period, tiled in ((None, False), ("5,3", True)):
        args = ["eval", "-i", pts, "-o", "-", "--function", "fbm"]
        if period:
            args += ["--period", period]
        r = run(args)
        check(r.returncode == 0, f"eval {'--period ' + period if period else 'plain'}: exit 0")
        v = np.loadtxt(r.stdout.decode().splitlines()[1:], delimiter=",")[:, 3].reshape(-1, 3)
        inside, edge = np.abs(v[:, 1] - v[:, 0]).max(), np.abs(v[:, 2] - v[:, 1]).max()
        if tiled:
            check(edge < 3 * inside, f"eval --period: edge step {edge:.4f} like inside {inside:.4f}")
        else:
            check(edge > 3 * inside, f"control without --period: edge step {edge:.4f} > 3 x "
                  f"inside {inside:.4f}")

# Usage errors: exit 2 and a message naming the option.
for args, needle in ((["heightmap", "-", "--generate", "64", "--format", "ppm"], "--period"),
                     (["heightmap", "-", "--generate", "64", "--period", "4,4", "--lacunarity",
                       "2.5", "--function", "fbm", "--format", "ppm"], "lacunarity"),
                     (["heightmap", "-", "--generate", "0x5", "--period", "4"], "--generate"),
                     (["eval", "-i", "-", "-o", "-", "--period", "300"], "--period"),
                     (["eval", "-i", "-", "-o", "-", "--seed", "-1"], "--seed"),
                     (["heightmap", "a.png", "b.png", "--period", "4"], "--generate")):
    r = run(args, input=b"x,y,z\n1,2,3\n")
    err = r.stderr.decode()
    check(r.returncode == 2 and needle in err, f"{' '.join(args)}: exit 2 naming {needle} "
          f"(got {r.returncode}: {err.strip()[:120]})")

# --seed: 0 is the plain output byte for byte; another seed changes every row;
# perturb (the shared height options) follows the seed as eval does.
pts = "x,y,z\n" + "".join(f"{0.37 * i - 5},{0.11 * i},{1.3 - 0.07 * i}\n" for i in range(64))
outs = {}
for seed in (None, "0", "5", "6"):
    args = ["eval", "-i", "-", "-o", "-", "--function", "turbulence"]
    if seed is not None:
        args += ["--seed", seed]
    outs[seed] = run(args, input=pts.encode()).stdout
check(outs[None] == outs["0"] and len(outs[None]) > 100, "eval --seed 0 == no seed, byte for byte")
rows = lambda b: b.decode().splitlines()[1:]
check(all(a != b for a, b in zip(rows(outs[None]), rows(outs["5"]))), "--seed 5 changes every row")
check(sum(a != b for a, b in zip(rows(outs["5"]), rows(outs["6"]))) == 64, "seeds 5 and 6 differ")
pp = "x,y,z,nx,ny,nz\n" + "".join(f"{0.37 * i - 5},{0.11 * i},{1.3 - 0.07 * i},0,0,1\n"
                                   for i in range(64))
p0 = run(["perturb", "-i", "-", "-o", "-"], input=pp.encode()).stdout
p5 = run(["perturb", "-i", "-", "-o", "-", "--seed", "5"], input=pp.encode()).stdout
p00 = run(["perturb", "-i", "-", "-o", "-", "--seed", "0"], input=pp.encode()).stdout
check(p0 == p00 and p0 != p5 and len(p5) > 100, "perturb --seed: 0 is the default, 5 differs")

# volume takes the shared height options, --period and --seed among them.
r = run(["volume", "--help"])
check(b"--period" in r.stdout and b"--seed" in r.stdout, "volume --help lists --period, --seed")

sys.exit(finish("tile"))
