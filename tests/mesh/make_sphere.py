# SPDX-License-Identifier: MIT
"""Write a latitude-longitude unit sphere as a binary little-endian PLY, for the
scale measurements of docs/MESH.md (not a test).

usage: make_sphere.py OUT.ply [N_LON [N_LAT]] [--normals] [--uv]

N_LON meridians and N_LAT parallels give N_LON * (N_LAT - 1) + 2 vertices and
2 * N_LON * (N_LAT - 1) triangles; the defaults 1000 x 1001 give 1,000,002
vertices and 1,998,000 triangles. Positions only unless --normals / --uv (the
UVs are the longitude/latitude fractions; the seam is not split, so the bake
would see one stretched column of triangles there).
"""
import sys

import numpy as np


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    normals, uv = "--normals" in sys.argv, "--uv" in sys.argv
    out = args[0]
    n_lon = int(args[1]) if len(args) > 1 else 1000
    n_lat = int(args[2]) if len(args) > 2 else 1001
    lat = np.linspace(0, np.pi, n_lat + 1)[1:-1]           # interior parallels
    lon = np.arange(n_lon) * (2 * np.pi / n_lon)
    LAT, LON = np.meshgrid(lat, lon, indexing="ij")
    ring = np.stack([np.sin(LAT) * np.cos(LON), np.sin(LAT) * np.sin(LON), np.cos(LAT)], -1)
    pos = np.concatenate([[[0, 0, 1]], ring.reshape(-1, 3), [[0, 0, -1]]]).astype(np.float32)
    nv = len(pos)
    cols = [pos]
    names = ["x", "y", "z"]
    if normals:
        cols.append(pos)
        names += ["nx", "ny", "nz"]
    if uv:
        u = np.concatenate([[0.5], (LON / (2 * np.pi)).ravel(), [0.5]])
        v = np.concatenate([[1.0], (1 - LAT / np.pi).ravel(), [0.0]])
        cols.append(np.stack([u, v], 1).astype(np.float32))
        names += ["s", "t"]
    verts = np.hstack(cols).astype("<f4")

    rings = n_lat - 1
    idx = 1 + np.arange(rings * n_lon).reshape(rings, n_lon)
    nxt = np.roll(idx, -1, axis=1)
    # Counter-clockwise seen from outside, so the winding agrees with +radius.
    top = np.stack([np.zeros(n_lon, int), idx[0], nxt[0]], 1)
    a, b, c, d = idx[:-1], idx[1:], nxt[1:], nxt[:-1]
    quads = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                            np.stack([a, c, d], -1).reshape(-1, 3)])
    bot = np.stack([np.full(n_lon, nv - 1), nxt[-1], idx[-1]], 1)
    tris = np.concatenate([top, quads, bot])
    faces = np.zeros(len(tris), dtype=[("n", "u1"), ("i", "<u4", 3)])
    faces["n"] = 3
    faces["i"] = tris

    with open(out, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\n")
        f.write(b"element vertex %d\n" % nv)
        for n in names:
            f.write(b"property float %s\n" % n.encode())
        f.write(b"element face %d\nproperty list uchar uint vertex_indices\nend_header\n" % len(tris))
        f.write(verts.tobytes())
        f.write(faces.tobytes())
    print("%s: %d vertices, %d triangles" % (out, nv, len(tris)))


if __name__ == "__main__":
    main()
