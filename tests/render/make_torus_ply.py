#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Write a torus of 2*N*N triangles with texture coordinates as a binary PLY
(for `bumpgrad render --mesh`'s scale measurement in docs/FIGURES.md):
    make_torus_ply.py N OUT.ply      (N = 708: 1,002,528 triangles)
Vertices carry position, normal and (s, t) = (i / N, j / N) on the seam-free
(N+1) x (N+1) grid; written to OUT.ply.tmp and renamed when complete."""
import os
import sys

import numpy as np

n = int(sys.argv[1])
out = sys.argv[2]
R, r = 1.0, 0.4
i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
a, b = 2 * np.pi * i / n, 2 * np.pi * j / n
nx, ny, nz = np.cos(a) * np.cos(b), np.sin(a) * np.cos(b), np.sin(b)
px, py, pz = (R + r * np.cos(b)) * np.cos(a), (R + r * np.cos(b)) * np.sin(a), r * np.sin(b)
vert = np.zeros((n + 1) * (n + 1), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"),
                                          ("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4"),
                                          ("s", "<f4"), ("t", "<f4")])
for k, v in zip(("x", "y", "z", "nx", "ny", "nz"), (px, py, pz, nx, ny, nz)):
    vert[k] = v.ravel()
vert["s"], vert["t"] = (i / n * 8).ravel(), (j / n * 2).ravel()
idx = (i * (n + 1) + j)[:n, :n].ravel()
v00, v10, v01, v11 = idx, idx + (n + 1), idx + 1, idx + n + 2
faces = np.zeros(2 * n * n, dtype=[("c", "u1"), ("i", "<i4", 3)])
faces["c"] = 3
faces["i"][0::2] = np.stack([v00, v10, v11], 1)
faces["i"][1::2] = np.stack([v00, v11, v01], 1)
tmp = out + ".tmp"
with open(tmp, "wb") as f:
    f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % len(vert)).encode())
    for k in ("x", "y", "z", "nx", "ny", "nz", "s", "t"):
        f.write(("property float %s\n" % k).encode())
    f.write(("element face %d\nproperty list uchar int vertex_indices\nend_header\n"
             % len(faces)).encode())
    f.write(vert.tobytes())
    f.write(faces.tobytes())
    f.flush()
    os.fsync(f.fileno())
os.rename(tmp, out)
print("wrote %s: %d vertices, %d triangles" % (out, len(vert), len(faces)))
