# SPDX-License-Identifier: MIT
"""Tests of `bumpgrad mesh` on real meshes (Debian's assimp-testmodels) and on
small meshes written here.

usage: test_mesh.py GROUP BUMPGRAD MESH_ORACLE MODELS_DIR
GROUP: vertex | recompute | degenerate | errors | bake | formats | udim

Every expected value is computed here, independently of the command: input
meshes are parsed by the PLY/OBJ/STL readers below, vertex normals by numpy,
and the bumped normals by `mesh_oracle`, which calls only the library's public
single-point API (bg_height_eval + bg_perturb). Exit 77 (skip) when the models
are missing.
"""
import json
import os
import re
import stat
import struct
import subprocess
import sys
import tempfile

import numpy as np
from mesh_util import grid_triangles, read_image  # noqa: E402  (and tests/ on the path)
from harness import FAILURES, check  # noqa: E402

GROUP, BUMPGRAD, ORACLE, MODELS = sys.argv[1:5]

# One height field for all checks: non-default in every parameter, so that an
# option the command dropped on the way would show.
HEIGHT = ["--function", "fbm", "--octaves", "4", "--lacunarity", "2.1", "--gain", "0.55",
          "--amplitude", "0.35", "--frequency", "3.7"]


def run(args, expect=None):
    # The oracle evaluates the height at single points of the file's positions:
    # compare with the unfiltered one-sample bake in the file's units (the
    # defaults, --units model, --filter footprint and the default samples, are checked by
    # test_mesh_scale.py and test_mesh_aa.py).
    args = list(args) + ["--units", "file"]
    if "--bake-normal-map" in args:
        args += ["--filter", "none", "--samples", "1"]
    p = subprocess.run([BUMPGRAD, "mesh"] + args, capture_output=True, text=True)
    if expect is not None and p.returncode != expect:
        print(p.stdout, p.stderr)
    return p


# ---- readers (independent of the command's writer) ----

PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
             "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
             "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4", "double": "f8",
             "float64": "f8"}


def read_ply(path):
    """Vertex properties (dict of float64 arrays), faces (list of index tuples),
    header comments. Scalar vertex properties, one list property per face."""
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert header[0] == "ply", path
    fmt = header[1].split()[1]
    elements, comments = [], []
    for line in header[2:]:
        w = line.split()
        if w[0] == "comment":
            comments.append(line[8:])
        elif w[0] == "element":
            elements.append([w[1], int(w[2]), []])
        elif w[0] == "property":
            elements[-1][2].append(w[1:])
    body = data[end:]
    verts, faces = {}, []
    if fmt == "ascii":
        tokens = body.split()
        pos = 0
        for name, count, props in elements:
            if name == "vertex":
                k = len(props)
                arr = np.array([float(t) for t in tokens[pos:pos + k * count]]).reshape(count, k)
                pos += k * count
                for j, p in enumerate(props):
                    # Round to the declared type, as a binary file would hold it.
                    verts[p[-1]] = arr[:, j].astype(PLY_TYPES[p[0]]).astype(np.float64)
            else:
                for _ in range(count):
                    n = int(tokens[pos])
                    faces.append(tuple(int(t) for t in tokens[pos + 1:pos + 1 + n]))
                    pos += 1 + n
    else:
        assert fmt == "binary_little_endian", fmt
        pos = 0
        for name, count, props in elements:
            if name == "vertex":
                dt = np.dtype([(p[-1], "<" + PLY_TYPES[p[0]]) for p in props])
                arr = np.frombuffer(body, dt, count, pos)
                pos += dt.itemsize * count
                for p in props:
                    verts[p[-1]] = arr[p[-1]].astype(np.float64)
            else:
                (_, ct, it, _), = props
                cs, isz = np.dtype(PLY_TYPES[ct]).itemsize, np.dtype(PLY_TYPES[it]).itemsize
                for _ in range(count):
                    n = int(np.frombuffer(body, "<" + PLY_TYPES[ct], 1, pos)[0])
                    pos += cs
                    faces.append(tuple(int(x) for x in np.frombuffer(body, "<" + PLY_TYPES[it], n, pos)))
                    pos += n * isz
        assert pos == len(body), (path, pos, len(body))
    return verts, faces, comments


def write_ply_ascii(path, pos, faces, normals=None, uv=None):
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\n" % len(pos))
        f.write("property float x\nproperty float y\nproperty float z\n")
        if normals is not None:
            f.write("property float nx\nproperty float ny\nproperty float nz\n")
        if uv is not None:
            f.write("property float s\nproperty float t\n")
        f.write("element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(faces))
        for i in range(len(pos)):
            row = list(pos[i]) + (list(normals[i]) if normals is not None else []) + \
                (list(uv[i]) if uv is not None else [])
            f.write(" ".join("%.9g" % v for v in row) + "\n")
        for t in faces:
            f.write("%d %s\n" % (len(t), " ".join(str(i) for i in t)))


def oracle_perturb(tmp, p, n, method="surfgrad"):
    """Height and bumped normal per row from bg_height_eval + bg_perturb."""
    rows = np.hstack([p, n]).astype(np.float32)
    fin, fout = os.path.join(tmp, "oracle_in.f32"), os.path.join(tmp, "oracle_out.f32")
    rows.tofile(fin)
    subprocess.run([ORACLE, "perturb", fin, fout, str(len(rows)), "--method", method] + HEIGHT,
                   check=True)
    out = np.fromfile(fout, np.float32).reshape(-1, 4)
    return out[:, 0].astype(np.float64), out[:, 1:].astype(np.float64)


def angle_weighted_normals(P, F):
    """Angle-weighted vertex normals written from the definition (arccos of the
    normalized edge dot products), float64; zero vector where none."""
    F = np.asarray(F, np.int64).reshape(-1, 3)
    p0, p1, p2 = P[F[:, 0]], P[F[:, 1]], P[F[:, 2]]
    c = np.cross(p1 - p0, p2 - p0)
    with np.errstate(invalid="ignore", divide="ignore"):
        ln = np.linalg.norm(c, axis=1)
        ok = np.isfinite(ln) & (ln > 0) & (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & \
            (F[:, 0] != F[:, 2])
        fn = c[ok] / ln[ok, None]
        acc = np.zeros_like(P)
        for k, (a, b, d) in enumerate(((0, 1, 2), (1, 2, 0), (2, 0, 1))):
            ea = P[F[ok, b]] - P[F[ok, a]]
            eb = P[F[ok, d]] - P[F[ok, a]]
            cosang = np.sum(ea * eb, 1) / (np.linalg.norm(ea, axis=1) * np.linalg.norm(eb, axis=1))
            ang = np.arccos(np.clip(cosang, -1, 1))
            np.add.at(acc, F[ok, a], ang[:, None] * fn)
        ln = np.linalg.norm(acc, axis=1)
        good = np.isfinite(ln) & (ln > 0)
        out = np.zeros_like(P)
        out[good] = acc[good] / ln[good, None]
    return out


def stack(v, *names):
    return np.stack([v[n] for n in names], 1)


def vec_angle_deg(a, b):
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, 1)))


# ---- groups ----

def group_vertex(tmp):
    """Wuson.ply: normals and UVs in the file, vertices kept one for one."""
    src = os.path.join(MODELS, "PLY", "Wuson.ply")
    vin, fin, _ = read_ply(src)
    out1, out2, outa = (os.path.join(tmp, n) for n in ("w1.ply", "w2.ply", "wa.ply"))
    p = run([src, out1, "--compare", "--threads", "1"] + HEIGHT, 0)
    check(p.returncode == 0, "mesh Wuson.ply exits 0")
    run([src, out2, "--compare", "--threads", "2", "--quiet"] + HEIGHT, 0)
    run([src, outa, "--compare", "--ascii", "--quiet"] + HEIGHT, 0)
    check(open(out1, "rb").read() == open(out2, "rb").read(),
          "1 and 2 threads write byte-identical files")
    v, f, comments = read_ply(out1)
    va, fa, _ = read_ply(outa)
    check(all(np.array_equal(v[k], va[k], equal_nan=True) for k in v) and f == fa,
          "ASCII and binary outputs hold the same values")
    n = len(vin["x"])
    check(len(v["x"]) == n, "every vertex kept (%d of %d)" % (len(v["x"]), n))
    check(f == fin, "every face kept, same indices and order (%d faces)" % len(f))
    P = stack(v, "x", "y", "z")
    # assimp's ASCII number parser (fast_atof) is not correctly rounded: it may
    # land one float ulp away from strtod's value, so "unchanged" means <= 1 ulp.
    Pin = stack(vin, "x", "y", "z")
    ulp = np.spacing(np.abs(Pin).astype(np.float32)).astype(np.float64)
    check(np.all(np.abs(P - Pin) <= ulp), "positions unchanged (to 1 ulp of assimp's parser)")
    check(np.array_equal(v["s"], vin["s"]) and np.array_equal(v["t"], vin["t"]), "UVs kept as s,t")
    on = stack(vin, "nx", "ny", "nz")
    on = on / np.linalg.norm(on, axis=1)[:, None]
    O = stack(v, "ox", "oy", "oz")
    check(np.max(np.abs(O - on)) < 1e-6, "ox,oy,oz = the file's normal, normalized")
    N = stack(v, "nx", "ny", "nz")
    check(np.max(np.abs(np.linalg.norm(N, axis=1) - 1)) < 1e-5, "perturbed normals are unit")
    h, ns = oracle_perturb(tmp, P, O, "surfgrad")
    _, na = oracle_perturb(tmp, P, O, "additive")
    err = np.max(np.abs(N - ns))
    check(err < 2e-6, "normals agree with bg_height_eval + bg_perturb_normal (max err %.2g)" % err)
    check(np.max(np.abs(v["height"] - h)) < 1e-6, "heights agree with bg_height_eval")
    cmp_ref = vec_angle_deg(ns, na)
    check(np.max(np.abs(v["compare_deg"] - cmp_ref)) < 1e-3,
          "compare_deg = angle(surfgrad, additive) (max %.2f deg)" % cmp_ref.max())
    check(np.max(vec_angle_deg(O, N)) > 1.0, "the normals are actually perturbed")
    check(any("method=surfgrad" in c and "octaves=4" in c for c in comments),
          "header comment records the parameters")
    inward_add = int(np.sum(np.sum(na * O, 1) <= 0))
    inward_surf = int(np.sum(np.sum(ns * O, 1) <= 0))
    check(inward_surf == 0 and inward_add > 0,
          "surfgrad never inward, additive inward at %d vertices" % inward_add)
    check("surfgrad 0 " in p.stdout and ("additive %d " % inward_add) in p.stdout,
          "summary prints the inward counts")
    check("%d vertices, %d triangles" % (n, len(fin)) in p.stdout, "summary prints the counts")
    # assimp reads the output back (its PLY loader, not ours).
    a = subprocess.run(["assimp", "info", out1], capture_output=True, text=True)
    check(a.returncode == 0 and "Faces:              %d" % len(fin) in a.stdout,
          "assimp info reads the output PLY")
    # --method additive writes the additive normals.
    outb = os.path.join(tmp, "wb.ply")
    run([src, outb, "--method", "additive", "--quiet"] + HEIGHT, 0)
    vb, _, _ = read_ply(outb)
    check(np.max(np.abs(stack(vb, "nx", "ny", "nz") - na)) < 2e-6, "--method additive")
    check("compare_deg" not in vb, "no compare_deg without --compare")


def obj_triangle_count(path):
    n = 0
    for line in open(path, errors="replace"):
        w = line.split()
        if w and w[0] == "f":
            n += len(w) - 3
    return n


def group_recompute(tmp):
    # STL: no vertex normals (facet normals are dropped), vertices merged.
    src = os.path.join(MODELS, "STL", "Wuson.stl")
    raw = open(src, "rb").read()
    ntri = struct.unpack_from("<I", raw, 80)[0]
    tris = np.frombuffer(raw, np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]),
                         ntri, 84)["v"]
    out = os.path.join(tmp, "stl.ply")
    p = run([src, out] + HEIGHT, 0)
    check(p.returncode == 0 and "angle-weighted" in p.stdout, "STL: normals computed")
    v, f, _ = read_ply(out)
    P = stack(v, "x", "y", "z")
    uniq = np.unique(tris.reshape(-1, 3), axis=0)
    check(len(P) == len(uniq), "STL: identical vertices merged (%d unique positions)" % len(uniq))
    check(len(f) == ntri, "STL: every triangle kept")
    def canon(t):
        t = [tuple(x) for x in t]
        k = t.index(min(t))
        return tuple(t[k:] + t[:k])
    ref = sorted(canon(t) for t in tris.astype(np.float64))
    got = sorted(canon(P[list(t)]) for t in f)
    check(ref == got, "STL: triangles and winding as in the file")
    ref_n = angle_weighted_normals(P, f)
    O = stack(v, "ox", "oy", "oz")
    check(np.max(np.abs(O - ref_n)) < 1e-5,
          "angle-weighted normals match numpy (max err %.2g)" % np.max(np.abs(O - ref_n)))
    h, ns = oracle_perturb(tmp, P, O)
    check(np.max(np.abs(stack(v, "nx", "ny", "nz") - ns)) < 2e-6, "STL: perturbed normals agree")

    # --recompute-normals on a file that has normals.
    src = os.path.join(MODELS, "PLY", "Wuson.ply")
    out = os.path.join(tmp, "re.ply")
    run([src, out, "--recompute-normals", "--quiet"] + HEIGHT, 0)
    v, f, _ = read_ply(out)
    P = stack(v, "x", "y", "z")
    ref_n = angle_weighted_normals(P, f)
    O = stack(v, "ox", "oy", "oz")
    check(len(P) == 11184 and np.max(np.abs(O - ref_n)) < 1e-5, "--recompute-normals")

    # OBJ with 19 meshes: flattened into one list.
    src = os.path.join(MODELS, "OBJ", "spider.obj")
    out = os.path.join(tmp, "spider.ply")
    p = run([src, out, "--quiet"] + HEIGHT, 0)
    v, f, _ = read_ply(out)
    check(len(f) == obj_triangle_count(src), "OBJ: all meshes' triangles (%d)" % len(f))
    N = stack(v, "nx", "ny", "nz")
    ln = np.linalg.norm(N, axis=1)
    check(np.all((np.abs(ln - 1) < 1e-5) | (ln == 0)), "OBJ: unit normals or the 0 sentinel")


def group_degenerate(tmp):
    """NaN position, zero-area, repeated-index triangles, an unreferenced vertex."""
    V = np.array([[0.1, 0.2, 0.3], [1.1, 0.2, 0.3], [0.1, 1.2, 0.3], [1.1, 1.2, 0.3],
                  [np.nan, 0.2, 0.3], [2, 0, 0], [3, 0, 0], [4, 0, 0], [5, 5, 5], [6, 6, 6]],
                 np.float32)
    F = [(0, 1, 2), (1, 3, 2), (1, 4, 3), (5, 6, 7), (0, 9, 9)]
    src = os.path.join(tmp, "degen.ply")
    hdr = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
           "property float y\nproperty float z\nelement face %d\n"
           "property list uchar int vertex_indices\nend_header\n" % (len(V), len(F))).encode()
    open(src, "wb").write(hdr + V.astype("<f4").tobytes() +
                          b"".join(struct.pack("<Biii", 3, *t) for t in F))
    out = os.path.join(tmp, "degen_out.ply")
    p = run([src, out, "--compare"] + HEIGHT, 0)
    check(p.returncode == 0, "degenerate mesh: exit 0")
    check("3 unusable triangles" in p.stdout and "1 vertices with NaN/Inf position" in p.stdout,
          "degenerate mesh: summary reports 3 unusable triangles and 1 NaN vertex")
    v, f, _ = read_ply(out)
    check(len(v["x"]) == len(V) and f == F, "degenerate mesh: all vertices and faces kept")
    O, N = stack(v, "ox", "oy", "oz"), stack(v, "nx", "ny", "nz")
    check(np.allclose(O[:4], [0, 0, 1], atol=1e-7), "good vertices: normal +z")
    check(np.all(O[4:] == 0) and np.all(N[4:] == 0),
          "NaN, zero-area-only, repeated-index-only and unreferenced vertices: (0,0,0) sentinel")
    check(np.isnan(v["height"][4]) and np.all(np.isfinite(np.delete(v["height"], 4))),
          "height NaN only at the NaN vertex")
    check(np.all(np.isnan(v["compare_deg"][4:])), "compare_deg NaN where there is no normal")
    _, ns = oracle_perturb(tmp, stack(v, "x", "y", "z")[:4], O[:4])
    check(np.max(np.abs(N[:4] - ns)) < 2e-6, "good vertices: perturbed as the oracle says")
    check(np.all(np.isfinite(N)), "no NaN normal in the output")

    # A NaN vertex in a joined (OBJ) mesh: assimp's joining took it as equal to
    # its finite neighbours and one vertex came out; all three must stay.
    for order in ([0, 1, 2], [1, 2, 0]):
        pts = [("nan", 0, 0), (1, 0, 0), (0, 1, 0)]
        src = os.path.join(tmp, "nan_first.obj")
        with open(src, "w") as fh:
            fh.write("".join("v %s %s %s\n" % pts[i] for i in order) + "f 1 2 3\n")
        out = os.path.join(tmp, "nan_obj_out.ply")
        for join in ("auto", "always"):
            p = run([src, out, "--join", join], 0)
            v, f, _ = read_ply(out)
            P = stack(v, "x", "y", "z")
            check(p.returncode == 0 and len(P) == 3 and f == [(0, 1, 2)] and
                  np.sum(np.isnan(P[:, 0])) == 1 and np.sum(np.all(P == [1, 0, 0], axis=1)) == 1,
                  "OBJ with a NaN vertex (order %s, --join %s): all 3 vertices kept" % (order, join))


def listing(d):
    return sorted(os.listdir(d))


def group_errors(tmp):
    d = os.path.join(tmp, "out")
    os.mkdir(d)
    old = os.path.join(d, "old.ply")
    open(old, "w").write("OLD CONTENT\n")
    wuson = os.path.join(MODELS, "PLY", "Wuson.ply")

    def untouched(what):
        check(open(old).read() == "OLD CONTENT\n", what + ": old output untouched")
        check(listing(d) == ["old.ply"], what + ": no temporary file left (%s)" % listing(d))

    missing = os.path.join(tmp, "no_such_mesh.obj")
    p = run([missing, old])
    check(p.returncode == 2 and missing in p.stderr and "No such file" in p.stderr,
          "missing file: exit 2 naming the file")
    untouched("missing file")

    garbage = os.path.join(tmp, "garbage.ply")
    open(garbage, "wb").write(bytes(range(256)) * 40)
    p = run([garbage, old])
    check(p.returncode == 2 and garbage in p.stderr, "corrupt PLY: exit 2 naming the file")
    untouched("corrupt PLY")

    trunc = os.path.join(tmp, "trunc.ply")
    open(trunc, "wb").write(open(wuson, "rb").read()[:3000])
    p = run([trunc, old])
    check(p.returncode == 2 and trunc in p.stderr, "truncated PLY: exit 2 naming the file")
    untouched("truncated PLY")

    # assimp's own regression file: a header claiming 3.5e9 vertices. Without
    # the importer's memory cap this swaps for minutes instead of failing.
    oom = os.path.join(MODELS, "invalid", "OutOfMemory.off")
    if os.path.exists(oom):
        try:
            p = subprocess.run([BUMPGRAD, "mesh", oom, old], capture_output=True, text=True,
                               timeout=60)
            check(p.returncode == 2 and oom in p.stderr, "absurd vertex count: exit 2 naming the file")
        except subprocess.TimeoutExpired:
            check(False, "absurd vertex count: no answer within 60 s")
        untouched("absurd vertex count")

    empty = os.path.join(tmp, "empty.obj")
    open(empty, "w").close()
    p = run([empty, old])
    check(p.returncode == 2 and empty in p.stderr, "empty file: exit 2 naming the file")
    untouched("empty file")

    points = os.path.join(MODELS, "PLY", "points.ply")
    p = run([points, old])
    check(p.returncode == 2 and points in p.stderr, "point cloud (no triangles): exit 2")
    untouched("point cloud")

    p = run([tmp, old])
    check(p.returncode == 2 and "directory" in p.stderr, "directory as input: exit 2")

    p = run([wuson, os.path.join(tmp, "no_dir", "out.ply")])
    check(p.returncode == 1 and "no_dir" in p.stderr, "unwritable output: exit 1 naming it")
    p = run([wuson, d])
    check(p.returncode == 1, "output is a directory: exit 1")
    untouched("unwritable output")

    off = os.path.join(MODELS, "OFF", "Wuson.off")
    p = run([off, old, "--bake-normal-map", os.path.join(d, "n.png"), "--size", "16"])
    check(p.returncode == 2 and "texture coordinates" in p.stderr and off in p.stderr,
          "bake without UVs: exit 2 with a clear message")
    untouched("bake without UVs")
    p = run([off, os.path.join(tmp, "off.ply"), "--quiet"])
    check(p.returncode == 0, "the same mesh without the bake works (vertex mode)")

    # A FIFO (like /dev/null) is written directly: renaming a temporary file
    # over it would replace the node with a regular file.
    fifo = os.path.join(tmp, "fifo.ply")
    os.mkfifo(fifo)
    sink = os.path.join(tmp, "from_fifo.ply")
    with open(sink, "wb") as f:
        reader = subprocess.Popen(["cat", fifo], stdout=f)
        p = run([wuson, fifo, "--quiet"])
        reader.wait(timeout=60)
    data = open(sink, "rb").read()
    check(p.returncode == 0 and data.startswith(b"ply\n") and
          stat.S_ISFIFO(os.stat(fifo).st_mode), "output to a FIFO: written through, node kept")
    p = run([wuson, "--bake-normal-map", fifo, "--size", "8"])
    check(p.returncode == 2 and stat.S_ISFIFO(os.stat(fifo).st_mode),
          "normal map onto a FIFO: refused, node kept")

    # The map cannot be written: the PLY must not be replaced either.
    p = run([wuson, old, "--bake-normal-map", os.path.join(tmp, "no_dir", "n.png"), "--size", "8"])
    check(p.returncode == 1, "unwritable normal map: exit 1")
    untouched("unwritable normal map")

    for args, what in (([wuson], "no output"), ([wuson, old, "--size", "8"], "--size without bake"),
                       ([wuson, old, "--method", "nope"], "bad --method"),
                       ([wuson, old, "--octaves", "0"], "bad --octaves"),
                       ([wuson, "--bake-normal-map", "x.png"], "bake without --size"),
                       ([wuson, old, "--bake-normal-map", "x.png", "--size", "0"], "--size 0"),
                       ([wuson, old, "--frobnicate"], "unknown option")):
        p = run(args)
        check(p.returncode == 2 and "error" in p.stderr, "usage error exits 2: " + what)
    untouched("usage errors")

    # One path for OUT.ply and the map (the PLY silently replaced the map, exit
    # 0), a PLY over a non-PLY input (the source mesh replaced), and a map name
    # without an image format (exit 1 before): usage errors that write nothing.
    box = os.path.join(tmp, "box_copy.obj")
    box_bytes = open(os.path.join(MODELS, "OBJ", "box.obj"), "rb").read()
    open(box, "wb").write(box_bytes)
    uv_ply = os.path.join(tmp, "uv.ply")
    check(run([wuson, uv_ply, "--quiet"]).returncode == 0, "PLY with UVs for the bake checks")
    both = os.path.join(d, "both.png")
    for args, what in (([wuson, both, "--bake-normal-map", both, "--size", "8"], "map = OUT.ply"),
                       ([box, box], "OUT.ply = the OBJ input"),
                       ([wuson, old, "--bake-normal-map", os.path.join(d, "n.txt"), "--size", "8"],
                        "map without an image format")):
        p = run(args)
        check(p.returncode == 2 and "error" in p.stderr, "usage error exits 2: " + what)
        untouched(what)
    check(open(box, "rb").read() == box_bytes, "the OBJ input is left as it was")
    p = run([uv_ply, uv_ply, "--quiet"])
    check(p.returncode == 0, "a PLY input may be its own output (in place)")


def bake_plane(tmp, mapping, space):
    """A flat 4x4-cell grid z = 0.3 over [0,1]^2 with a known UV layout; every
    texel centre is inside the layout, so every texel can be checked."""
    n = 4
    g = np.linspace(0, 1, n + 1)
    X, Y = np.meshgrid(g, g)
    x, y = X.ravel(), Y.ravel()
    pos = np.stack([x, y, np.full_like(x, 0.3)], 1)
    nrm = np.tile([0.0, 0.0, 1.0], (len(x), 1))
    if mapping == "identity":
        uv = np.stack([x, y], 1)
    elif mapping == "rotate":
        uv = np.stack([y, 1 - x], 1)
    else:  # mirror: u runs along -x, an orientation-reversing layout
        uv = np.stack([1 - x, y], 1)
    faces = grid_triangles(n, n)
    src = os.path.join(tmp, "plane_%s.ply" % mapping)
    write_ply_ascii(src, pos, faces, nrm, uv)
    img = os.path.join(tmp, "plane_%s_%s.exr" % (mapping, space))
    W, H = 24, 16
    p = run([src, "--bake-normal-map", img, "--size", "%dx%d" % (W, H), "--space", space,
             "--bake-depth", "float", "--padding", "0"] + HEIGHT, 0)
    pix = read_image(ORACLE, tmp, img)
    # Texel centre -> (u, v) -> position on the plane.
    u = (np.arange(W) + 0.5) / W
    v = 1 - (np.arange(H) + 0.5) / H
    U, V = np.meshgrid(u, v)
    U, V = U.ravel(), V.ravel()
    if mapping == "identity":
        px, py, T, B = U, V, [1, 0, 0], [0, 1, 0]
    elif mapping == "rotate":
        px, py, T, B = 1 - V, U, [0, 1, 0], [-1, 0, 0]
    else:
        px, py, T, B = 1 - U, V, [-1, 0, 0], [0, 1, 0]
    P = np.stack([px, py, np.full_like(px, 0.3)], 1)
    _, ns = oracle_perturb(tmp, P, np.tile([0.0, 0.0, 1.0], (len(P), 1)))
    if space == "tangent":
        m = np.stack([ns @ np.array(T, float), ns @ np.array(B, float), ns[:, 2]], 1)
    else:
        m = ns
    want = (0.5 * m + 0.5).reshape(H, W, 3)
    err = np.max(np.abs(pix - want))
    check(p.returncode == 0 and pix.shape == (H, W, 3) and err < 2e-5,
          "bake plane, %s UVs, %s space: every texel = 0.5 n' + 0.5 (max err %.2g)"
          % (mapping, space, err))
    return pix


def group_bake(tmp):
    for mapping in ("identity", "rotate", "mirror"):
        t = bake_plane(tmp, mapping, "tangent")
        if mapping == "identity":
            o = bake_plane(tmp, mapping, "object")
            check(np.max(np.abs(t - o)) < 1e-6, "identity layout: tangent map = object map")

    # A curved patch (a quarter cylinder): the tangent map, decoded the way a
    # mikkTSpace renderer does (interpolated, unnormalized t and n, b = sign *
    # cross(n, t), normalize(m.x t + m.y b + m.z n)), gives back the bumped
    # normal at the interpolated position.
    nt, nz = 8, 4
    th = np.linspace(0, np.pi / 2, nt + 1)
    zz = np.linspace(0, 1, nz + 1)
    TH, ZZ = np.meshgrid(th, zz)
    th_v, z_v = TH.ravel(), ZZ.ravel()
    pos = np.stack([np.cos(th_v), np.sin(th_v), z_v], 1)
    nrm = np.stack([np.cos(th_v), np.sin(th_v), 0 * z_v], 1)
    tan = np.stack([-np.sin(th_v), np.cos(th_v), 0 * z_v], 1)
    uv = np.stack([th_v / (np.pi / 2), z_v], 1)
    faces = grid_triangles(nt, nz)
    src = os.path.join(tmp, "cyl.ply")
    write_ply_ascii(src, pos.astype(np.float32), faces, nrm.astype(np.float32),
                    uv.astype(np.float32))
    W = H = 32
    img = os.path.join(tmp, "cyl.exr")
    run([src, "--bake-normal-map", img, "--size", str(W), "--bake-depth", "float", "--quiet"] +
        HEIGHT, 0)
    m = read_image(ORACLE, tmp, img).reshape(-1, 3) * 2 - 1
    u = (np.arange(W) + 0.5) / W
    v = 1 - (np.arange(H) + 0.5) / H
    U, V = (a.ravel() for a in np.meshgrid(u, v))
    # Barycentrics of each texel centre in the grid cell's two triangles.
    ci, cj = np.minimum((U * nt).astype(int), nt - 1), np.minimum((V * nz).astype(int), nz - 1)
    s, t = U * nt - ci, V * nz - cj
    a = cj * (nt + 1) + ci
    b, c, d = a + 1, a + nt + 2, a + nt + 1
    low = s >= t
    wa = np.where(low, 1 - s, 1 - t)
    w1 = np.where(low, s - t, s)
    w2 = np.where(low, t, t - s)
    i1, i2 = np.where(low, b, c), np.where(low, c, d)
    P32, N32, T32 = (x.astype(np.float32).astype(np.float64) for x in (pos, nrm, tan))
    def interp(A):
        return wa[:, None] * A[a] + w1[:, None] * A[i1] + w2[:, None] * A[i2]
    P, vN, vT = interp(P32), interp(N32), interp(T32)
    vB = np.cross(vN, vT)
    dec = m[:, :1] * vT + m[:, 1:2] * vB + m[:, 2:] * vN
    dec /= np.linalg.norm(dec, axis=1)[:, None]
    _, ns = oracle_perturb(tmp, P, vN)
    err = np.max(vec_angle_deg(dec, ns))  # atan2: arccos cannot resolve 1e-4 deg
    check(err < 0.005, "cylinder: mikkTSpace-style decoding of the tangent map gives n' "
          "(max %.2g deg)" % err)

    # A real mesh with UVs: PNG of the right size, read by OpenImageIO's iinfo.
    src = os.path.join(MODELS, "PLY", "Wuson.ply")
    png = os.path.join(tmp, "wuson_n.png")
    ply = os.path.join(tmp, "wuson_n.ply")
    p = run([src, ply, "--bake-normal-map", png, "--size", "128x64", "--padding", "2"] + HEIGHT, 0)
    check(p.returncode == 0 and os.path.exists(ply), "Wuson bake + PLY: exit 0, both written")
    info = subprocess.run(["iinfo", png], capture_output=True, text=True).stdout
    check(re.search(r"128 x +64, 3 channel, uint8 png", info) is not None,
          "iinfo: 128 x 64, 3 channels (%s)" % info.strip())
    pix = read_image(ORACLE, tmp, png)
    bg = np.all(np.abs(pix - [0.5, 0.5, 1.0]) < 1 / 255, axis=2)
    cov = 1 - bg.mean()
    check(0.05 < cov < 0.95, "Wuson: a part of the map is baked (%.0f%%)" % (100 * cov))
    mm = pix[~bg] * 2 - 1
    check(np.all(np.abs(np.linalg.norm(mm, axis=1) - 1) < 0.02), "Wuson: texels decode to unit vectors")
    check(np.mean(mm[:, 2] > 0) > 0.99, "Wuson: tangent-space texels point out (z > 0)")
    check(listing(tmp).count("wuson_n.png") == 1 and not any(".tmp" in f for f in listing(tmp)),
          "no temporary files left")


def group_formats(tmp):
    """OUT by extension: glb/gltf with tangents that read back, obj, refusal."""
    wuson = os.path.join(MODELS, "PLY", "Wuson.ply")
    bad = os.path.join(tmp, "out.xyz")
    p = run(["--quiet", wuson, bad])
    check(p.returncode == 2 and "cannot write a mesh in this format" in p.stderr
          and not os.path.exists(bad), "unknown OUT extension refused, nothing written")
    for ext in ("glb", "gltf"):
        out = os.path.join(tmp, "w." + ext)
        p = run([wuson, out])
        check(p.returncode == 0 and "glTF 2.0" in p.stdout, ext + ": written")
        dump = os.path.join(tmp, "w_%s.assxml" % ext)
        a = subprocess.run(["assimp", "dump", out, dump], capture_output=True, text=True)
        txt = open(dump).read() if os.path.exists(dump) else ""
        check(a.returncode == 0 and "<Tangents num=" in txt and "<Bitangents num=" in txt,
              ext + ": assimp reads TANGENT back")
    with open(os.path.join(tmp, "w.glb"), "rb") as f:
        data = f.read()
    check(data[:4] == b"glTF" and int.from_bytes(data[8:12], "little") == len(data),
          "glb header: magic and total length")
    jlen = int.from_bytes(data[12:16], "little")
    doc = json.loads(data[20:20 + jlen])
    att = doc["meshes"][0]["primitives"][0]["attributes"]
    tacc = doc["accessors"][att["TANGENT"]]
    check(tacc["type"] == "VEC4" and "NORMAL" in att and "TEXCOORD_0" in att,
          "glb: TANGENT is VEC4, NORMAL and TEXCOORD_0 present")
    obj = os.path.join(tmp, "w.obj")
    p = run(["--quiet", wuson, obj])
    a = subprocess.run(["assimp", "info", obj], capture_output=True, text=True)
    check(p.returncode == 0 and "Faces:              3732" in a.stdout, "obj: written, 3732 faces")
    # --tangents file on our own glb gives the mikkTSpace bake (same normals,
    # same welded frames), --tangents file on a PLY is refused
    glb = os.path.join(tmp, "w.glb")
    m1, m2 = os.path.join(tmp, "m1.exr"), os.path.join(tmp, "m2.exr")
    p1 = run(["--quiet", "--bake-normal-map", m1, "--bake-depth", "float",
              "--size", "64", glb])
    p2 = run(["--quiet", "--tangents", "file", "--bake-normal-map", m2,
              "--bake-depth", "float", "--size", "64", glb])
    if p1.returncode == 0 and p2.returncode == 0:
        d = np.abs(read_image(ORACLE, tmp, m1) - read_image(ORACLE, tmp, m2)).max()
        check(d < 1e-4, "--tangents file = mikktspace on our glb (max %.2g)" % d)
    else:
        check(False, "--tangents bakes ran")
    p = run(["--quiet", "--tangents", "file", "--bake-normal-map", m2,
             "--size", "64", wuson])
    check(p.returncode == 2 and "has no tangents" in p.stderr, "--tangents file without tangents: exit 2")
    # --normal-map-y -y negates the green channel only
    p = run(["--quiet", "--normal-map-y", "-y", "--bake-normal-map", m2,
             "--bake-depth", "float", "--size", "64", glb])
    a, b = read_image(ORACLE, tmp, m1), read_image(ORACLE, tmp, m2)
    check(p.returncode == 0 and np.abs(a[..., 0] - b[..., 0]).max() == 0
          and np.abs((2 * a[..., 1] - 1) + (2 * b[..., 1] - 1)).max() < 1e-6,
          "--normal-map-y -y flips green only")


def udim_mesh(path, tiles, shift=(0, 0)):
    """One 2x2-cell grid patch per (u_tile, v_tile), each on its own tilted
    plane, UVs = tile + [0,1]^2 - shift (multiples of 1/2: exact floats, so the
    shift is exact)."""
    pos, nrm, uv, faces = [], [], [], []
    for k, (a, b) in enumerate(tiles):
        base = len(pos)
        for j in range(3):
            for i in range(3):
                s, t = i / 2, j / 2
                pos.append([s + 1.5 * k, t, 0.3 + 0.2 * s - 0.1 * k * t])
                nrm.append([-0.2, 0.1 * k, 1.0])
                uv.append([a + s - shift[0], b + t - shift[1]])
        for j in range(2):
            for i in range(2):
                q = base + j * 3 + i
                faces += [(q, q + 1, q + 4), (q, q + 4, q + 3)]
    write_ply_ascii(path, np.array(pos), faces, np.array(nrm), np.array(uv))


def group_udim(tmp):
    tiles = [(0, 0), (1, 0), (0, 1)]  # 1001, 1002, 1011
    src = os.path.join(tmp, "tiles.ply")
    udim_mesh(src, tiles)
    out = os.path.join(tmp, "out")
    os.mkdir(out)
    size = ["--size", "16x8", "--space", "object", "--bake-depth", "float"] + HEIGHT
    p = run([src, os.path.join(out, "bumped.glb"), "--quiet", "--bake-normal-map",
             os.path.join(out, "n.<UDIM>.exr")] + size, 0)
    names = sorted(os.listdir(out))
    check(p.returncode == 0 and names == ["bumped.glb", "n.1001.exr", "n.1002.exr", "n.1011.exr"],
          "<UDIM>: one map per tile 1001 + u + 10 v, nothing else left (%s)" % names)
    # Each tile = the single-tile bake of the mesh with the tile's UVs moved
    # to the unit square (the other patches fall outside and are clipped).
    seen = []
    for a, b in tiles:
        shifted = os.path.join(tmp, "shift_%d%d.ply" % (a, b))
        udim_mesh(shifted, tiles, (a, b))
        single = os.path.join(tmp, "single_%d%d.exr" % (a, b))
        q = run([shifted, "--quiet", "--bake-normal-map", single] + size, 0)
        got = read_image(ORACLE, tmp, os.path.join(out, "n.%d.exr" % (1001 + a + 10 * b)))
        want = read_image(ORACLE, tmp, single)
        flat = np.all(np.abs(want - 0.5) < 1e-12, axis=2)
        check(q.returncode == 0 and got.shape == want.shape == (8, 16, 3)
              and np.array_equal(got, want) and flat.sum() < flat.size // 2,
              "tile %d = single-tile bake of the shifted UVs, texel for texel (%d of %d texels "
              "baked)" % (1001 + a + 10 * b, flat.size - flat.sum(), flat.size))
        seen.append(got)
    check(not any(np.array_equal(seen[i], seen[j]) for i in range(3) for j in range(i)),
          "the three tiles hold different patches")
    # The command line's view of the tiles: --json lists them, the summary
    # names them, --progress on a pipe reports the bake in texels.
    p = run([src, "--json", "--bake-normal-map", os.path.join(out, "j.<UDIM>.png"),
             "--size", "16x8"], 0)
    doc = json.loads(p.stdout) if p.returncode == 0 else {}
    check(doc.get("bake", {}).get("tiles") == [1001, 1002, 1011],
          "--json: bake.tiles lists the UDIM tiles written (%s)" % doc.get("bake"))
    p = run([src, "--progress", "--bake-normal-map", os.path.join(out, "t.<UDIM>.png"),
             "--size", "16x8"], 0)
    check(p.returncode == 0 and "3 tiles written: 1001, 1002, 1011" in p.stdout,
          "the summary names the tiles written")
    check(re.search(r"^bake: .*texels", p.stderr, re.M) is not None
          and "bake: done, %d texels" % (3 * 16 * 8) in p.stderr,
          "--progress on a pipe: bake progress lines in texels (%r)" % p.stderr[-300:])
    one = os.path.join(tmp, "one.ply")
    udim_mesh(one, [(0, 0)])
    d1 = os.path.join(tmp, "one")
    os.mkdir(d1)
    p = run([one, "--quiet", "--bake-normal-map", os.path.join(d1, "m_<UDIM>.png"),
             "--size", "8"], 0)
    check(p.returncode == 0 and os.listdir(d1) == ["m_1001.png"],
          "<UDIM> on a single-tile mesh writes one tile")
    # A failure after the tiles were baked (OUT.ply cannot be opened) leaves
    # none of them and keeps an old tile as it was.
    d2 = os.path.join(tmp, "fail")
    os.mkdir(d2)
    old = os.path.join(d2, "n.1002.exr")
    open(old, "wb").write(b"old tile")
    p = run([src, os.path.join(tmp, "no_such_dir", "out.ply"), "--quiet", "--bake-normal-map",
             os.path.join(d2, "n.<UDIM>.exr")] + size)
    check(p.returncode == 1 and os.listdir(d2) == ["n.1002.exr"]
          and open(old, "rb").read() == b"old tile",
          "a failed run writes no tile and leaves the old ones (%s)" % os.listdir(d2))
    # More tiles than the cap: refused before baking (exit 2), nothing written.
    big = os.path.join(tmp, "big.ply")
    write_ply_ascii(big, np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float), [(0, 1, 2)],
                    np.array([[0, 0, 1]] * 3, float),
                    np.array([[0.5, 0.5], [9.5, 0.5], [0.5, 10.5]]))
    d3 = os.path.join(tmp, "big")
    os.mkdir(d3)
    p = run([big, "--quiet", "--bake-normal-map", os.path.join(d3, "n.<UDIM>.png"),
             "--size", "4"])
    check(p.returncode == 2 and "110 UDIM tiles" in p.stderr and os.listdir(d3) == [],
          "more than 100 tiles refused, exit 2, nothing written: " + p.stderr.strip())
    # The memory cap applies per tile, before any allocation of the bake.
    env = dict(os.environ, BUMPGRAD_MAX_MB="1")
    p = subprocess.run([BUMPGRAD, "mesh", src, "--quiet", "--bake-normal-map",
                        os.path.join(d3, "c.<UDIM>.png"), "--size", "256"], capture_output=True,
                       text=True, env=env)
    check(p.returncode == 2 and "over the cap of 1 MiB" in p.stderr and os.listdir(d3) == [],
          "a tile over BUMPGRAD_MAX_MB refused, exit 2: " + p.stderr.strip())


def main():
    if not os.path.isdir(os.path.join(MODELS, "PLY")):
        print("skip: %s not found (Debian package assimp-testmodels)" % MODELS)
        return 77
    with tempfile.TemporaryDirectory(prefix="mesh-%s-" % GROUP, dir=os.getcwd()) as tmp:
        {"vertex": group_vertex, "recompute": group_recompute, "degenerate": group_degenerate,
         "errors": group_errors, "bake": group_bake, "formats": group_formats,
         "udim": group_udim}[GROUP](tmp)
    print("%d failure(s)" % len(FAILURES))
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
