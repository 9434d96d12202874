# SPDX-License-Identifier: MIT
"""Write a cube-sphere (a cube's six faces, each a K x K grid, projected onto
the unit sphere) as an OBJ with clean UVs: each face is one UV island in a
3 x 2 atlas, with a gutter of 1/32 of a cell around it. For the anti-aliasing
checks of the bake (test_mesh_aa.py, docs/MESH.md).

usage: make_cubesphere.py OUT.obj [K] [SCALE]
"""
import sys

import numpy as np


def cubesphere(k=24, scale=1.0):
    pos, uv, faces = [], [], []
    axes = [(0, 1, 2, 1), (0, 1, 2, -1), (1, 2, 0, 1), (1, 2, 0, -1), (2, 0, 1, 1), (2, 0, 1, -1)]
    g = np.linspace(-1.0, 1.0, k + 1)
    gut = 1.0 / 32.0
    for f, (a, b, c, s) in enumerate(axes):
        A, B = np.meshgrid(g, g, indexing="ij")
        p = np.zeros(A.shape + (3,))
        p[..., a], p[..., b], p[..., c] = A * s, B, s
        p /= np.linalg.norm(p, axis=-1, keepdims=True)
        cu, cv = f % 3, f // 3
        u = (cu + gut + (A + 1) / 2 * (1 - 2 * gut)) / 3.0
        v = (cv + gut + (B + 1) / 2 * (1 - 2 * gut)) / 2.0
        base = len(pos) and sum(len(x) for x in pos)
        pos.append((p * scale).reshape(-1, 3))
        uv.append(np.stack([u, v], -1).reshape(-1, 2))
        idx = np.arange((k + 1) * (k + 1)).reshape(k + 1, k + 1) + base
        for i in range(k):
            for j in range(k):
                q = [idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]]
                # counter-clockwise seen from outside
                tri = [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
                n = p[i, j]
                e = np.cross(p[i + 1, j] - p[i, j], p[i + 1, j + 1] - p[i, j])
                if np.dot(e, n) < 0:
                    tri = [(t[0], t[2], t[1]) for t in tri]
                faces.extend(tri)
    return np.concatenate(pos), np.concatenate(uv), np.array(faces)


def write_obj(path, pos, uv, faces):
    with open(path, "w") as f:
        for p in pos:
            f.write("v %.9g %.9g %.9g\n" % tuple(p))
        for t in uv:
            f.write("vt %.9g %.9g\n" % tuple(t))
        for t in faces + 1:
            f.write("f %d/%d %d/%d %d/%d\n" % (t[0], t[0], t[1], t[1], t[2], t[2]))


if __name__ == "__main__":
    k = int(sys.argv[2]) if len(sys.argv) > 2 else 24
    scale = float(sys.argv[3]) if len(sys.argv) > 3 else 1.0
    write_obj(sys.argv[1], *cubesphere(k, scale))
