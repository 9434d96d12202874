# SPDX-License-Identifier: MIT
"""What the mesh tests share: an image read back through mesh_oracle, a grid's
triangles, and the texel centres one UV triangle covers by the bake's rule. Importing it also
puts tests/ on the path, for the harness (tests/harness.py)."""
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def read_image(oracle, tmp, path):
    """The image at PATH as an (h, w, c) float64 array, read by `MESH_ORACLE
    image` (OpenImageIO, as the command reads it) through a file in TMP."""
    fout = os.path.join(tmp, "image.f32")
    subprocess.run([oracle, "image", path, fout], check=True)
    raw = np.fromfile(fout, np.uint8)
    w, h, c = np.frombuffer(raw[:12].tobytes(), np.int32)
    return np.frombuffer(raw[12:].tobytes(), np.float32).reshape(h, w, c).astype(np.float64)


def grid_triangles(nu, nv):
    """The triangles of a grid of (nv + 1) rows of (nu + 1) vertices, row by
    row: two per cell, (a, b, c) and (a, c, d) with a, b, c, d the cell's
    corners counter-clockwise from its first vertex."""
    faces = []
    for j in range(nv):
        for i in range(nu):
            a, b = j * (nu + 1) + i, j * (nu + 1) + i + 1
            c, d = (j + 1) * (nu + 1) + i + 1, (j + 1) * (nu + 1) + i
            faces += [(a, b, c), (a, c, d)]
    return faces


def texel_cover(x, y, w, h):
    """The texel centres of a W x H image inside the triangle whose corners
    are at x, y (in texels, three each): (rows, cols, weights), weights the
    (k, 3) barycentric weights of the k centres; None for a triangle of zero
    or non-finite area or one that holds no centre."""
    area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0])
    if area == 0 or not np.isfinite(area):
        return None
    xs = np.arange(max(np.ceil(x.min() - 0.5), 0), min(np.floor(x.max() - 0.5), w - 1) + 1)
    ys = np.arange(max(np.ceil(y.min() - 0.5), 0), min(np.floor(y.max() - 0.5), h - 1) + 1)
    if not len(xs) or not len(ys):
        return None
    cx, cy = np.meshgrid(xs + 0.5, ys + 0.5)
    l0 = ((x[2] - x[1]) * (cy - y[1]) - (y[2] - y[1]) * (cx - x[1])) / area
    l1 = ((x[0] - x[2]) * (cy - y[2]) - (y[0] - y[2]) * (cx - x[2])) / area
    l2 = 1 - l0 - l1
    inside = (l0 >= 0) & (l1 >= 0) & (l2 >= 0)
    rows = (cy[inside] - 0.5).astype(np.int64)
    cols = (cx[inside] - 0.5).astype(np.int64)
    return rows, cols, np.stack([l0[inside], l1[inside], l2[inside]], 1)
