# SPDX-License-Identifier: MIT
"""Big jobs as pure functions of (parameters, piece), through the command:
`bumpgrad volume --brick I/N` + `--merge` equals the single-run volume, and
`bumpgrad mesh --bake-normal-map n.<UDIM>.exr --tile T` equals tile T of the
full UDIM bake. Usage: test_pieces.py BUMPGRAD"""
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish, run  # noqa: E402

EXE = sys.argv[1]
UUID = slice(21, 57)  # the file's UUID (bytes 22..57): the only bytes two writes differ in


def vdb_same(a, b):
    """Same file but for its UUID: every grid, voxel, tile and metadata item."""
    x, y = open(a, "rb").read(), open(b, "rb").read()
    if len(x) != len(y) or len(x) < 57:
        return False
    return x[:UUID.start] == y[:UUID.start] and x[UUID.stop:] == y[UUID.stop:]


def volume_bricks(tmp):
    for name, extra, n in [("box", ["--voxel-size", "0.05"], 3),
                           ("band", ["--voxel-size", "0.04", "--band-sphere", "0,0,0,0.7,0.1"], 8),
                           ("many", ["--voxel-size", "0.1"], 7)]:
        d = os.path.join(tmp, name)
        os.mkdir(d)
        args = ["volume", "--quiet", "--function", "fbm", "--octaves", "3"] + extra
        whole = os.path.join(d, "whole.vdb")
        rc, _, err = run(EXE, args + ["-o", whole])
        check(rc == 0, "%s: the whole volume (%s)" % (name, err.strip()))
        bricks = []
        for i in range(n):
            b = os.path.join(d, "b%d.vdb" % i)
            rc, _, err = run(EXE, args + ["--brick", "%d/%d" % (i, n), "-o", b])
            check(rc == 0, "%s: brick %d/%d (%s)" % (name, i, n, err.strip()))
            bricks.append(b)
        merged = os.path.join(d, "merged.vdb")
        rc, out, err = run(EXE, ["volume", "--merge", merged] + bricks[::-1])
        check(rc == 0 and "%d bricks merged" % n in out, "%s: --merge (%s)" % (name, err.strip()))
        check(vdb_same(whole, merged),
              "%s: %d merged bricks = the single-run volume, byte for byte but the UUID" % (name, n))
        check(sorted(os.listdir(d)) == sorted(["whole.vdb", "merged.vdb"] +
                                              ["b%d.vdb" % i for i in range(n)]),
              "%s: no temporary left" % name)
    d = os.path.join(tmp, "box")
    # 13 leaf slabs in 3 bricks: dropping one brick gives another volume.
    part = os.path.join(d, "part.vdb")
    run(EXE, ["volume", "--merge", part, os.path.join(d, "b0.vdb"), os.path.join(d, "b1.vdb")])
    check(os.path.exists(part) and not vdb_same(part, os.path.join(d, "whole.vdb")),
          "two of three bricks differ from the whole (the comparison can fail)")
    rc, _, err = run(EXE, ["volume", "--merge", os.path.join(d, "x.vdb"),
                           os.path.join(d, "b0.vdb"), os.path.join(d, "b0.vdb")])
    check(rc != 0 and "overlap" in err and not os.path.exists(os.path.join(d, "x.vdb")),
          "a brick given twice: refused, no output (%s)" % err.strip())
    other = os.path.join(d, "other.vdb")
    run(EXE, ["volume", "--quiet", "--voxel-size", "0.05", "--brick", "1/3", "-o", other])
    rc, _, err = run(EXE, ["volume", "--merge", os.path.join(d, "x.vdb"),
                           os.path.join(d, "b0.vdb"), other])
    check(rc != 0 and "other height parameters" in err and other in err,
          "bricks of other parameters: refused naming the file (%s)" % err.strip())
    bad = os.path.join(d, "bad.vdb")
    with open(bad, "wb") as f:
        f.write(open(os.path.join(d, "b1.vdb"), "rb").read()[:300])
    rc, _, err = run(EXE, ["volume", "--merge", os.path.join(d, "x.vdb"),
                           os.path.join(d, "b0.vdb"), bad])
    check(rc != 0 and bad in err and not os.path.exists(os.path.join(d, "x.vdb")),
          "a truncated brick: refused naming it, no output (%s)" % err.strip())
    for arg in ["3/3", "1/0", "x/2", "-1/2", "1"]:
        rc, _, err = run(EXE, ["volume", "--brick", arg, "-o", os.path.join(d, "y.vdb")])
        check(rc == 2 and "--brick" in err, "--brick %s: usage error (%s)" % (arg, err.strip()))


def udim_obj(path, tiles):
    """One tilted quad per UDIM tile (u_tile, v_tile), UVs covering the tile."""
    v, vt, f = [], [], []
    for k, (a, b) in enumerate(tiles):
        for j in range(3):
            for i in range(3):
                s, t = i / 2, j / 2
                v.append((s + 1.5 * k, t, 0.3 + 0.2 * s - 0.1 * k * t))
                vt.append((a + s, b + t))
        base = 9 * k + 1
        for j in range(2):
            for i in range(2):
                q = base + 3 * j + i
                f += [(q, q + 1, q + 4), (q, q + 4, q + 3)]
    with open(path, "w") as fh:
        fh.writelines("v %r %r %r\n" % p for p in v)
        fh.writelines("vt %r %r\n" % p for p in vt)
        fh.writelines("f %d/%d %d/%d %d/%d\n" % (a, a, b, b, c, c) for a, b, c in f)


def udim_tiles(tmp):
    import bumpgrad
    src = os.path.join(tmp, "tiles.obj")
    udim_obj(src, [(0, 0), (1, 0), (0, 1)])  # 1001, 1002, 1011
    full, one = os.path.join(tmp, "full"), os.path.join(tmp, "one")
    os.mkdir(full)
    os.mkdir(one)
    args = ["mesh", src, "--quiet", "--size", "32x16", "--bake-depth", "float",
            "--function", "fbm", "--octaves", "5", "--frequency", "6"]
    rc, _, err = run(EXE, args + ["--bake-normal-map", os.path.join(full, "n.<UDIM>.exr")])
    check(rc == 0 and sorted(os.listdir(full)) == ["n.1001.exr", "n.1002.exr", "n.1011.exr"],
          "the full UDIM bake: three tiles (%s)" % err.strip())
    for t in (1001, 1002, 1011):
        rc, _, err = run(EXE, args + ["--bake-normal-map", os.path.join(one, "n.<UDIM>.exr"),
                                      "--tile", str(t)])
        name = "n.%d.exr" % t
        check(rc == 0 and name in os.listdir(one), "--tile %d writes %s (%s)" % (t, name, err.strip()))
        a = bumpgrad.read_image(os.path.join(full, name))
        b = bumpgrad.read_image(os.path.join(one, name))
        check(a.shape == b.shape and a.tobytes() == b.tobytes() and np.ptp(a) > 0,
              "--tile %d = tile %d of the full bake, texel for texel" % (t, t))
    check(sorted(os.listdir(one)) == ["n.1001.exr", "n.1002.exr", "n.1011.exr"],
          "one file per --tile run, nothing else")
    rc, _, err = run(EXE, args + ["--bake-normal-map", os.path.join(one, "n.<UDIM>.exr"),
                                  "--tile", "1003"])
    check(rc == 2 and "--tile 1003" in err and "1001, 1002, 1011" in err
          and "n.1003.exr" not in os.listdir(one), "--tile of an untouched tile: refused (%s)"
          % err.strip())
    rc, _, err = run(EXE, args + ["--bake-normal-map", os.path.join(one, "n.exr"), "--tile",
                                  "1001"])
    check(rc == 2 and "<UDIM>" in err, "--tile without <UDIM>: refused (%s)" % err.strip())
    # The same through Python: bake_normal_map(tile=) and its argument checks.
    arr = bumpgrad.bake_normal_map(src, (32, 16), udim=True, tile=1011, function="fbm",
                                   octaves=5, frequency=6.0, padding=16)
    ref = bumpgrad.read_image(os.path.join(full, "n.1011.exr"))
    check(list(arr) == [1011] and arr[1011].tobytes() == ref.tobytes(),
          "bake_normal_map(tile=1011) = the CLI's full bake's tile 1011")
    for bad, kind in [(999, ValueError), (1011.0, TypeError)]:
        try:
            bumpgrad.bake_normal_map(src, 8, udim=True, tile=bad)
            got = None
        except Exception as e:  # noqa: BLE001
            got = e
        check(isinstance(got, kind) and "tile" in str(got), "tile=%r: %r" % (bad, got))


def python_bricks(tmp):
    import bumpgrad
    box = (-0.5, -0.5, -0.5, 0.5, 0.5, 0.5)
    one = os.path.join(tmp, "one.vdb")
    bumpgrad.volume(box, 0.05, one, function="fbm")
    parts = [os.path.join(tmp, "p%d.vdb" % i) for i in range(3)]
    for i, b in enumerate(parts):
        bumpgrad.volume(box, 0.05, b, function="fbm", brick=(i, 3))
    merged = os.path.join(tmp, "merged.vdb")
    bumpgrad.merge_volumes(merged, parts)
    check(vdb_same(one, merged), "volume(brick=) + merge_volumes = volume(), byte for byte")
    for kw, kind in [(dict(brick=(3, 3)), ValueError), (dict(brick=3), TypeError)]:
        try:
            bumpgrad.volume(box, 0.05, os.path.join(tmp, "x.vdb"), **kw)
            got = None
        except Exception as e:  # noqa: BLE001
            got = e
        check(isinstance(got, kind) and "brick" in str(got), "%r: %r" % (kw, got))
    try:
        bumpgrad.merge_volumes(os.path.join(tmp, "x.vdb"), [parts[0], parts[0]])
        got = None
    except Exception as e:  # noqa: BLE001
        got = e
    check(isinstance(got, bumpgrad.Error) and "overlap" in str(got)
          and not os.path.exists(os.path.join(tmp, "x.vdb")),
          "merge_volumes of a brick twice: bumpgrad.Error (%s)" % got)


def row_ranges(tmp):
    rng = np.random.default_rng(5)
    pts = os.path.join(tmp, "p.npy")
    np.save(pts, rng.uniform(-30, 30, (10007, 3)))
    pn = os.path.join(tmp, "pn.npy")
    n = rng.normal(size=(10007, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    np.save(pn, np.concatenate([rng.uniform(-30, 30, (10007, 3)), n], axis=1).astype(np.float32))
    for cmd, src, extra in [("eval", pts, ["--precision", "double", "--gradient", "analytic"]),
                            ("eval", pts, []), ("perturb", pn, ["--octaves", "4"])]:
        whole = os.path.join(tmp, "whole.npy")
        rc, _, err = run(EXE, [cmd, "--quiet", "-i", src, "-o", whole] + extra)
        check(rc == 0, "%s: the whole table (%s)" % (cmd, err.strip()))
        parts = []
        for k, r in enumerate([":3000", "3000:3000", "3000:7001", "7001:"]):
            out = os.path.join(tmp, "part%d.npy" % k)
            rc, _, err = run(EXE, [cmd, "--quiet", "-i", src, "-o", out, "--rows", r] + extra)
            check(rc == 0, "%s --rows %s (%s)" % (cmd, r, err.strip()))
            parts.append(np.load(out))
        w = np.load(whole)
        cat = np.concatenate(parts)
        check(cat.dtype == w.dtype and cat.tobytes() == w.tobytes() and len(parts[1]) == 0,
              "%s %s: four row ranges concatenated = the whole run, bit for bit" % (cmd, extra))
    for r, want in [("5:3", "--rows"), ("0:10008", "10007 rows"), ("x:1", "--rows"),
                    ("-1:3", "--rows"), ("3", "--rows")]:
        rc, _, err = run(EXE, ["eval", "-i", pts, "-o", os.path.join(tmp, "bad.npy"), "--rows", r])
        check(rc == 2 and want in err and not os.path.exists(os.path.join(tmp, "bad.npy")),
              "--rows %s: refused (%s)" % (r, err.strip()))
    csv = os.path.join(tmp, "p.csv")
    with open(csv, "w") as f:
        f.write("x,y,z\n1,2,3\n")
    rc, _, err = run(EXE, ["eval", "-i", csv, "-o", os.path.join(tmp, "o.csv"), "--rows", "0:1"])
    check(rc == 2 and ".npy" in err, "--rows on a CSV input: refused (%s)" % err.strip())


with tempfile.TemporaryDirectory() as tmp:
    row_ranges(tmp)
with tempfile.TemporaryDirectory() as tmp:
    volume_bricks(tmp)
    udim_tiles(tmp)
with tempfile.TemporaryDirectory() as tmp:
    python_bricks(tmp)
sys.exit(finish("distributed_pieces"))
