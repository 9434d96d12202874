# SPDX-License-Identifier: MIT
"""The meshes of the high-poly to low-poly tests and measurements, with their
exact answers.

LOW is a coarse latitude-longitude unit sphere with UVs (the seam split, a
fan of pole triangles each with its own pole vertex) and unit normals.
HIGH is a finely tessellated sphere displaced by a known smooth function:
the point of direction d (unit) is r(d) d with r(d) = 1 + A g(d), and its
vertex normals are exact, from the gradient of F(P) = |P| - 1 - A g(P / |P|):
grad F = d - (A / |P|) (grad g - d (d . grad g)).

usage: make_highpoly.py OUTDIR [--low N_LON N_LAT] [--high N_LON N_LAT]
                        [--amplitude A] [--frequency K]
writes OUTDIR/low.obj, high.ply (binary, positions and normals, no UVs),
cage.obj (LOW's triangles, its vertices at 1.2 p + CAGE_SHIFT: the cage's
rays are not LOW's normals), high_split.obj (HIGH as two
objects, the northern and the southern half). The defaults (16 x 8 and
256 x 128) are the tests'; `--low 100 51 --high 500 1001` gives the
10,000-triangle LOW and the 1,000,000-triangle HIGH of docs/PERFORMANCE.md;
scripts/demo uses `--amplitude 0.05 --frequency 3` (g(K d): ripples).
"""
import os
import sys

import numpy as np

A = 0.08  # the displacement's amplitude
K = 1.0   # and its frequency: g(K d)
CAGE_SCALE = 1.2
CAGE_SHIFT = np.array([0.04, -0.03, 0.02])


def g(d):
    x, y, z = K * d[..., 0], K * d[..., 1], K * d[..., 2]
    return 0.6 * np.sin(3 * x + 1) * np.cos(2 * y) + 0.4 * np.sin(4 * z + 0.5 * x)


def grad_g(d):
    x, y, z = K * d[..., 0], K * d[..., 1], K * d[..., 2]
    gx = 1.8 * np.cos(3 * x + 1) * np.cos(2 * y) + 0.2 * np.cos(4 * z + 0.5 * x)
    gy = -1.2 * np.sin(3 * x + 1) * np.sin(2 * y)
    gz = 1.6 * np.cos(4 * z + 0.5 * x)
    return K * np.stack([gx, gy, gz], -1)


def surface_F(p):
    """F(P) = |P| - 1 - A g(P / |P|): < 0 inside HIGH, > 0 outside."""
    r = np.linalg.norm(p, axis=-1)
    return r - 1.0 - A * g(p / r[..., None])


def analytic_normal(p):
    """The unit normal of HIGH's exact surface at (or through) the points p."""
    r = np.linalg.norm(p, axis=-1)
    d = p / r[..., None]
    gg = grad_g(d)
    tang = gg - d * np.sum(d * gg, -1)[..., None]
    n = d - (A / r)[..., None] * tang
    return n / np.linalg.norm(n, axis=-1)[..., None]


def ray_hit(o, u, tmax, iters=60):
    """Per ray (origin o, unit direction u): the t in [-tmax, tmax] of the
    exact surface's crossing nearest to t = 0 (bisection on each side), NaN
    when there is none. Scans in 64 steps per side for the first sign change.
    tmax: a number or one per ray."""
    n = len(o)
    best = np.full(n, np.nan)
    tm = np.broadcast_to(np.asarray(tmax, float), (n,))
    for sign in (1.0, -1.0):
        ts = tm[:, None] * np.linspace(0.0, 1.0, 65)[None, :]
        f = np.stack([surface_F(o + sign * ts[:, i, None] * u) for i in range(65)], 1)
        ch = np.signbit(f[:, :-1]) != np.signbit(f[:, 1:])
        has = ch.any(1)
        k = np.argmax(ch, 1)
        lo, hi = ts[np.arange(n), k], ts[np.arange(n), k + 1]
        flo = f[np.arange(n), k]
        for _ in range(iters):
            mid = 0.5 * (lo + hi)
            fm = surface_F(o + sign * mid[:, None] * u)
            same = np.signbit(fm) == np.signbit(flo)
            lo = np.where(same, mid, lo)
            flo = np.where(same, fm, flo)
            hi = np.where(same, hi, mid)
        t = sign * 0.5 * (lo + hi)
        take = has & (np.isnan(best) | (np.abs(t) < np.abs(best)))
        best = np.where(take, t, best)
    return best


def uv_sphere(n_lon, n_lat, radius=1.0):
    """Positions, unit normals, UVs and triangles (counter-clockwise from
    outside) of a latitude-longitude sphere: n_lat bands, n_lon + 1 vertices
    per interior parallel (the seam split), one pole vertex per pole triangle."""
    pos, uv, faces = [], [], []
    lat = np.linspace(0, np.pi, n_lat + 1)
    for i in range(1, n_lat):
        for j in range(n_lon + 1):
            phi = 2 * np.pi * j / n_lon
            pos.append([np.sin(lat[i]) * np.cos(phi), np.sin(lat[i]) * np.sin(phi), np.cos(lat[i])])
            uv.append([j / n_lon, 1 - lat[i] / np.pi])

    def ring(i, j):  # interior parallel i (1..n_lat-1), column j
        return (i - 1) * (n_lon + 1) + j

    for i in range(1, n_lat - 1):
        for j in range(n_lon):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            faces += [[a, c, d], [a, d, b]]
    for j in range(n_lon):
        top = len(pos)
        pos.append([0, 0, 1])
        uv.append([(j + 0.5) / n_lon, 1.0])
        faces.append([top, ring(1, j), ring(1, j + 1)])
        bot = len(pos)
        pos.append([0, 0, -1])
        uv.append([(j + 0.5) / n_lon, 0.0])
        faces.append([bot, ring(n_lat - 1, j + 1), ring(n_lat - 1, j)])
    pos = np.array(pos) * radius
    nrm = pos / np.linalg.norm(pos, axis=1)[:, None]
    return pos, nrm, np.array(uv), np.array(faces)


def displaced_sphere(n_lon, n_lat):
    """HIGH: a latitude-longitude sphere (seam welded, one vertex per pole)
    displaced by r(d) = 1 + A g(d), with the exact normals."""
    lat = np.linspace(0, np.pi, n_lat + 1)[1:-1]
    lon = np.arange(n_lon) * (2 * np.pi / n_lon)
    LAT, LON = np.meshgrid(lat, lon, indexing="ij")
    d = np.stack([np.sin(LAT) * np.cos(LON), np.sin(LAT) * np.sin(LON), np.cos(LAT)], -1)
    d = np.concatenate([[[0, 0, 1]], d.reshape(-1, 3), [[0, 0, -1]]])
    pos = d * (1 + A * g(d))[:, None]
    nrm = analytic_normal(pos)
    rows = n_lat - 1
    idx = 1 + np.arange(rows * n_lon).reshape(rows, n_lon)
    a, b = idx[:-1], np.roll(idx[:-1], -1, 1)
    c, e = idx[1:], np.roll(idx[1:], -1, 1)
    quads = np.concatenate([np.stack([a, c, e], -1).reshape(-1, 3),
                            np.stack([a, e, b], -1).reshape(-1, 3)])
    top = np.stack([np.zeros(n_lon, int), idx[0], np.roll(idx[0], -1)], -1)
    last = len(pos) - 1
    bot = np.stack([np.full(n_lon, last), np.roll(idx[-1], -1), idx[-1]], -1)
    return pos, nrm, np.concatenate([top, quads, bot])


def write_obj(path, pos, nrm, uv, faces, objects=None):
    """OBJ with v, vt (if uv), vn; `objects`: a list of (name, face indices)
    written as separate `o` blocks (assimp reads each as a mesh)."""
    with open(path, "w") as f:
        f.write("".join("v %.9g %.9g %.9g\n" % tuple(p) for p in pos))
        if uv is not None:
            f.write("".join("vt %.9g %.9g\n" % tuple(t) for t in uv))
        f.write("".join("vn %.9g %.9g %.9g\n" % tuple(n) for n in nrm))
        for name, sel in objects or [(None, np.arange(len(faces)))]:
            if name:
                f.write("o %s\n" % name)
            for t in faces[sel] + 1:
                if uv is not None:
                    f.write("f %d/%d/%d %d/%d/%d %d/%d/%d\n" % (t[0], t[0], t[0], t[1], t[1], t[1],
                                                               t[2], t[2], t[2]))
                else:
                    f.write("f %d//%d %d//%d %d//%d\n" % (t[0], t[0], t[1], t[1], t[2], t[2]))


def write_ply(path, pos, nrm, faces):
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                 "property float x\nproperty float y\nproperty float z\n"
                 "property float nx\nproperty float ny\nproperty float nz\n"
                 "element face %d\nproperty list uchar int vertex_indices\nend_header\n"
                 % (len(pos), len(faces))).encode())
        f.write(np.hstack([pos, nrm]).astype("<f4").tobytes())
        rec = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
        rec["n"] = 3
        rec["i"] = faces
        f.write(rec.tobytes())


def main(argv):
    out = argv[0]
    low, high = (16, 8), (256, 128)
    a = argv[1:]
    for k, opt in enumerate(a):
        if opt == "--low":
            low = (int(a[k + 1]), int(a[k + 2]))
        if opt == "--high":
            high = (int(a[k + 1]), int(a[k + 2]))
        if opt == "--amplitude":
            globals()["A"] = float(a[k + 1])
        if opt == "--frequency":
            globals()["K"] = float(a[k + 1])
    os.makedirs(out, exist_ok=True)
    pos, nrm, uv, faces = uv_sphere(*low)
    write_obj(os.path.join(out, "low.obj"), pos, nrm, uv, faces)
    write_obj(os.path.join(out, "cage.obj"), CAGE_SCALE * pos + CAGE_SHIFT, nrm, uv, faces)
    hp, hn, hf = displaced_sphere(*high)
    write_ply(os.path.join(out, "high.ply"), hp, hn, hf)
    north = np.nonzero(hp[hf].mean(1)[:, 2] >= 0)[0]
    south = np.nonzero(hp[hf].mean(1)[:, 2] < 0)[0]
    write_obj(os.path.join(out, "high_split.obj"), hp, hn, None, hf,
              [("north", north), ("south", south)])


if __name__ == "__main__":
    main(sys.argv[1:])
