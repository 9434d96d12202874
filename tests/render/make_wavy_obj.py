# SPDX-License-Identifier: MIT
"""Write a wavy height-field patch as an OBJ with normals and jittered UVs, for
the test that a normal map baked by `bumpgrad mesh` renders as baked
(tests/render/test_render.py, t_bakedmap).

usage: make_wavy_obj.py OUT.obj [N]

N x N quads (default 6, coarse: the frames then vary most inside a triangle) on z = 0.25 sin(2.3 x) cos(1.7 y) + 0.1 x y, split
along alternating diagonals, scaled so that the bounding-box centre is the
origin and the farthest vertex is at distance 1 (what `render --mesh` does, so
the solid height sees the same points in both tools). The UVs are the grid
position plus a deterministic jitter of 0.35 cell: the UV chart is not a
smooth map of the surface, so per-triangle dP/du turns from one triangle to
the next and the tangent frame depends on how it is averaged at a vertex
(mikkTSpace: corner angles, per fan) - a renderer with other tangents decodes
the map wrongly. The jitter keeps every triangle's UV orientation, so the map
has no overlaps.
"""
import math
import sys


def main():
    out = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 6
    pts, uvs, nrm = [], [], []
    for j in range(n + 1):
        for i in range(n + 1):
            x, y = -1 + 2 * i / n, -1 + 2 * j / n
            z = 0.25 * math.sin(2.3 * x) * math.cos(1.7 * y) + 0.1 * x * y
            dzx = 0.25 * 2.3 * math.cos(2.3 * x) * math.cos(1.7 * y) + 0.1 * y
            dzy = -0.25 * 1.7 * math.sin(2.3 * x) * math.sin(1.7 * y) + 0.1 * x
            ln = math.sqrt(dzx * dzx + dzy * dzy + 1)
            pts.append((x, y, z))
            nrm.append((-dzx / ln, -dzy / ln, 1 / ln))
            # a hash in [-1, 1) per vertex, the same on every platform
            h1 = ((i * 73856093) ^ (j * 19349663)) % 1000 / 500.0 - 1
            h2 = ((i * 83492791) ^ (j * 2654435761)) % 1000 / 500.0 - 1
            interior = 0 < i < n and 0 < j < n
            ju = 0.35 * h1 / n if interior else 0.0
            jv = 0.35 * h2 / n if interior else 0.0
            uvs.append((0.02 + 0.96 * (i / n + ju), 0.02 + 0.96 * (j / n + jv)))
    lo = [min(p[a] for p in pts) for a in range(3)]
    hi = [max(p[a] for p in pts) for a in range(3)]
    c = [(lo[a] + hi[a]) / 2 for a in range(3)]
    r = max(math.dist(p, c) for p in pts)
    with open(out, "w") as f:
        for p in pts:
            f.write("v %.9g %.9g %.9g\n" % tuple((p[a] - c[a]) / r for a in range(3)))
        for q in nrm:
            f.write("vn %.9g %.9g %.9g\n" % q)
        for t in uvs:
            f.write("vt %.9g %.9g\n" % t)
        for j in range(n):
            for i in range(n):
                a, b = j * (n + 1) + i + 1, j * (n + 1) + i + 2
                c_, d = a + n + 1, b + n + 1
                tris = [(a, b, d), (a, d, c_)] if (i + j) % 2 == 0 else [(a, b, c_), (b, d, c_)]
                for t in tris:
                    f.write("f " + " ".join("%d/%d/%d" % (k, k, k) for k in t) + "\n")


if __name__ == "__main__":
    main()
