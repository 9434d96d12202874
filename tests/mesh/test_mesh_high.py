# SPDX-License-Identifier: MIT
"""High-poly to low-poly bakes (`bumpgrad mesh LOW --from HIGH`) against exact
answers (make_highpoly.py): LOW a coarse UV sphere (16 x 8, 224 triangles),
HIGH a sphere displaced by a known smooth function (256 x 128, 65,024
triangles) with exact vertex normals.

Each texel's ray is recomputed here: LOW rasterized in UV space (texel centres,
barycentric weights, LOW's interpolated unit normal), the ray's crossing with
HIGH's EXACT surface found by bisection, and the exact normal there. The bake
(object space, one sample per texel, float EXR) must match it within the
tessellation's error: HIGH's facets and interpolated normals are not the
smooth surface. Measured on this pair at 128 x 128: 0.0034 / 0.0089 deg
mean / p99 (LOW's own normal is 4.8 deg off); the checks allow 0.02 / 0.05
deg (TOL_MEAN, TOL_P99: a wrong frame, a wrong hit or a texel shifted by
one is degrees off).

usage: test_mesh_high.py BUMPGRAD MESH_ORACLE [--measure]
--measure prints the figures of docs/MESH.md at 512 x 512 (no checks)."""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_highpoly as mk  # noqa: E402
from gltf_read import Gltf  # noqa: E402

BUMPGRAD, ORACLE = sys.argv[1:3]
MEASURE = "--measure" in sys.argv
FAILS = []
TOL_MEAN, TOL_P99 = 0.02, 0.05  # degrees: about 5x the tessellation's error measured here


def check(cond, what):
    print(("ok: " if cond else "FAIL: ") + what)
    if not cond:
        FAILS.append(what)


def read_image(tmp, path):
    fout = os.path.join(tmp, "image.f32")
    subprocess.run([ORACLE, "image", path, fout], check=True)
    raw = np.fromfile(fout, np.uint8)
    w, h, c = np.frombuffer(raw[:12].tobytes(), np.int32)
    return np.frombuffer(raw[12:].tobytes(), np.float32).reshape(h, w, c).astype(np.float64)


def run(args, expect=0):
    p = subprocess.run([BUMPGRAD, "mesh"] + args, capture_output=True, text=True)
    if p.returncode != expect:
        print(p.stdout, p.stderr)
    return p


def bake(tmp, low, extra, name="n.exr", n=128):
    out = os.path.join(tmp, name)
    args = [low, "--bake-normal-map", out, "--size", str(n), "--space", "object", "--padding",
            "0", "--bake-depth", "float", "--samples", "1", "--units", "file", "--json"] + extra
    p = run(args)
    check(p.returncode == 0, "bake %s exits 0" % " ".join(extra))
    return 2.0 * read_image(tmp, out) - 1.0, json.loads(p.stdout)


def raster(pos, nrm, uv, faces, n, unit=True):
    """Per texel centre of an n x n map: covered, LOW's point and unit normal
    (the bake's rule: centres on a shared edge go to the later triangle)."""
    tri = np.full((n, n), -1)
    P = np.zeros((n, n, 3))
    N = np.zeros((n, n, 3))
    for t, f in enumerate(faces):
        X = uv[f, 0] * n
        Y = (1.0 - uv[f, 1]) * n
        area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0])
        if area == 0:
            continue
        x0, x1 = max(int(np.ceil(X.min() - 0.5)), 0), min(int(np.floor(X.max() - 0.5)), n - 1)
        y0, y1 = max(int(np.ceil(Y.min() - 0.5)), 0), min(int(np.floor(Y.max() - 0.5)), n - 1)
        if x1 < x0 or y1 < y0:
            continue
        cy, cx = np.mgrid[y0:y1 + 1, x0:x1 + 1] + 0.5
        l0 = ((X[2] - X[1]) * (cy - Y[1]) - (Y[2] - Y[1]) * (cx - X[1])) / area
        l1 = ((X[0] - X[2]) * (cy - Y[2]) - (Y[0] - Y[2]) * (cx - X[2])) / area
        l2 = 1.0 - l0 - l1
        inside = (l0 >= 0) & (l1 >= 0) & (l2 >= 0)
        w = np.stack([l0, l1, l2], -1)[inside]
        ys, xs = (cy[inside] - 0.5).astype(int), (cx[inside] - 0.5).astype(int)
        tri[ys, xs] = t
        P[ys, xs] = w @ pos[f]
        N[ys, xs] = w @ nrm[f]
    if unit:
        N /= np.maximum(np.linalg.norm(N, axis=-1), 1e-300)[..., None]
    return tri >= 0, P, N


def angles(a, b):
    a = a / np.linalg.norm(a, axis=-1)[..., None]
    b = b / np.linalg.norm(b, axis=-1)[..., None]
    return np.degrees(np.arccos(np.clip(np.sum(a * b, -1), -1.0, 1.0)))


def stats(a):
    return a.mean(), np.percentile(a, 99), a.max()


def main():
    tmp = tempfile.mkdtemp(prefix="bg_high_")
    mk.main([tmp])
    low, high = os.path.join(tmp, "low.obj"), os.path.join(tmp, "high.ply")
    pos, nrm, uv, faces = mk.uv_sphere(16, 8)
    n = 512 if MEASURE else 128
    p = run([low, "--from", high, "--bake-normal-map", os.path.join(tmp, "probe.png"), "--size",
             "8"])
    if p.returncode != 0 and "without Embree" in p.stderr:
        print("skipped: this bumpgrad was built without Embree")
        sys.exit(77)
    cov, P, N = raster(pos, nrm, uv, faces, n)
    D = 0.2

    # 1. the analytic sphere: along LOW's normal, both ways
    got, js = bake(tmp, low, ["--from", high, "--ray-distance", str(D)], n=n)
    t = mk.ray_hit(P[cov], N[cov], D)
    ok = np.isfinite(t)
    hit = P[cov] + t[:, None] * N[cov]
    a = angles(got[cov][ok], mk.analytic_normal(hit[ok]))
    m, p99, mx = stats(a)
    print("analytic sphere (%d texels): %.4f / %.4f / %.4f deg mean / p99 / max" % (ok.sum(), m, p99, mx))
    if MEASURE:
        flat = angles(N[cov][ok], mk.analytic_normal(hit[ok]))
        print("LOW's own normal vs analytic: %.3f / %.3f deg mean / p99" % stats(flat)[:2])
    check(ok.all() and js["bake"]["miss_texels"] == 0, "every texel's ray crosses HIGH, none missed")
    check(m < TOL_MEAN and p99 < TOL_P99, "baked normal = analytic normal at the hit (%.4f / %.4f deg)" % (m, p99))
    flat = angles(N[cov][ok], mk.analytic_normal(hit[ok]))
    check(flat.mean() > 10 * m, "the check can fail: LOW's own normal is %.2f deg off" % flat.mean())
    if MEASURE:
        return
    # the height map: signed distance along the ray
    dm = os.path.join(tmp, "d.exr")
    bake(tmp, low, ["--from", high, "--ray-distance", str(D), "--bake-height-map", dm], "n2.exr")
    dist = read_image(tmp, dm)[..., 0][cov]
    err = np.abs(dist[ok] - t[ok])
    check(err.max() < 2e-3 and np.abs(dist).max() > 0.03,
          "height map = exact signed distance within the facets' sag (max err %.2g, |d| up to %.3f)"
          % (err.max(), np.abs(dist).max()))

    # 2. a cage: LOW's triangles at 1.2 p + a shift; rays from the cage's point
    # toward LOW's point and as far past it (the first hit from the cage)
    gc, _ = bake(tmp, low, ["--from", high, "--cage", os.path.join(tmp, "cage.obj")], "c.exr")
    c = mk.CAGE_SCALE * P[cov] + mk.CAGE_SHIFT
    L = np.linalg.norm(c - P[cov], axis=1)
    u = (c - P[cov]) / L[:, None]
    tc = mk.ray_hit(P[cov], u, L)
    okc = np.isfinite(tc)
    ac = angles(gc[cov][okc], mk.analytic_normal(P[cov][okc] + tc[okc, None] * u[okc]))
    check(okc.all() and ac.mean() < TOL_MEAN and np.percentile(ac, 99) < TOL_P99,
          "cage bake = analytic normal along the cage's rays (%d of %d texels cross HIGH; "
          "%.4f / %.4f deg)" % (okc.sum(), len(okc), ac.mean(), np.percentile(ac, 99)))
    check(angles(gc[cov], got[cov]).max() > 0.5, "the cage's rays are not LOW's normals")

    # 3. --ray-distance too short: missed texels keep LOW's normal, counted and mapped
    short = 0.005
    mm = os.path.join(tmp, "m.exr")
    gs, js = bake(tmp, low, ["--from", high, "--ray-distance", str(short), "--miss-map", mm], "s.exr")
    miss = read_image(tmp, mm)[..., 0][cov]
    expect_miss = ~(np.abs(t) <= short)
    b = js["bake"]
    check(b["miss_texels"] == int((miss == 1).sum()) and b["miss_texels"] > 100,
          "misses counted (%d texels) and in the miss map" % b["miss_texels"])
    agree = (miss == 1) == expect_miss
    check(agree.mean() > 0.99, "the missed texels are those whose exact hit is beyond %.3g (%.2f%%)"
          % (short, 100 * agree.mean()))
    lm = angles(gs[cov][miss == 1], N[cov][miss == 1])
    check(lm.max() < 1e-3, "a missed texel keeps LOW's own normal (max %.2g deg)" % lm.max())
    hm = (miss == 0) & ok
    ah = angles(gs[cov][hm], mk.analytic_normal((P[cov] + t[:, None] * N[cov])[hm]))
    check(ah.mean() < TOL_MEAN, "the texels that hit are still analytic (%.4f deg)" % ah.mean())
    p = run([low, "--from", high, "--ray-distance", "1e-5", "--bake-normal-map",
             os.path.join(tmp, "w.png"), "--size", "64", "--units", "file"])
    check(p.returncode == 0 and "every ray missed" in p.stderr, "a bake that misses warns")

    # 4. HIGH as two meshes (north and south objects of one OBJ)
    g2, j2 = bake(tmp, low, ["--from", os.path.join(tmp, "high_split.obj"), "--ray-distance", str(D)],
                  "two.exr")
    d2 = angles(g2[cov], got[cov])
    check(j2["bake"]["high_triangles"] == len(mk.displaced_sphere(256, 128)[2]),
          "both meshes' triangles are in the scene")
    check(d2.max() < 0.01, "two meshes bake as one (max %.2g deg)" % d2.max())

    # 5. procedural detail on top: the framework's resolve of the two surface gradients
    hopts = ["--function", "fbm", "--octaves", "3", "--frequency", "6", "--amplitude", "0.02"]
    gd, jd = bake(tmp, low, ["--from", high, "--ray-distance", str(D), "--filter", "none"] + hopts,
                  "det.exr")
    check(jd["bake"]["detail"], "a height option turns the detail on")
    hp = (P[cov] + dist[:, None] * N[cov]).astype(np.float32)  # HIGH's point, from the height map
    fin, fout = os.path.join(tmp, "p.f32"), os.path.join(tmp, "g.f32")
    hp.tofile(fin)
    subprocess.run([ORACLE, "gradient", fin, fout, str(len(hp))] + hopts, check=True)
    g = np.fromfile(fout, np.float32).reshape(-1, 4)[:, 1:].astype(np.float64)
    nl, mh = N[cov], got[cov] / np.linalg.norm(got[cov], axis=1)[:, None]
    k = np.sum(mh * nl, 1)
    mt = mh - k[:, None] * nl
    s1 = -mt / np.maximum(np.abs(k), np.linalg.norm(mt, axis=1) / 128)[:, None]  # sculpt
    s2 = g - nl * np.sum(nl * g, 1)[:, None]                                   # height
    ref = nl - s1 - s2
    ad = angles(gd[cov], ref)
    check(ad.max() < 0.02, "detail = resolve(n_low, sculpt + height surface gradients) (max %.2g deg)"
          % ad.max())
    check(angles(gd[cov], got[cov]).mean() > 1.0, "the detail changes the map (%.2f deg mean)"
          % angles(gd[cov], got[cov]).mean())

    # 6. the glb renders as baked: the tangent-space map decoded per texel in the
    # file's own NORMAL and TANGENT (as a viewer does) = the object-space bake
    glb, tm = os.path.join(tmp, "hp.glb"), os.path.join(tmp, "hp_t.exr")
    p = run([low, glb, "--from", high, "--ray-distance", str(D), "--bake-normal-map", tm,
             "--size", str(n), "--bake-depth", "float", "--samples", "1", "--padding", "0",
             "--units", "file"])
    gl = Gltf(glb)
    (attrs, tris, mat), = list(gl.primitives())
    check(mat is not None and "normalTexture" in gl.json["materials"][mat],
          "the glb's material uses the map as its normalTexture")
    Tf = attrs["TANGENT"].astype(np.float64)
    Nf = attrs["NORMAL"].astype(np.float64)
    uvf = attrs["TEXCOORD_0"].astype(np.float64) * [1, -1] + [0, 1]  # glTF's v is down
    # interpolated and NOT normalized, as a renderer does (mikkTSpace's rule)
    pf, tr = attrs["POSITION"].astype(np.float64), tris.astype(np.int64)
    cov2, _, Nn = raster(pf, Nf, uvf, tr, n, unit=False)
    _, _, Tt = raster(pf, Tf[:, :3], uvf, tr, n, unit=False)
    _, _, Ss = raster(pf, np.repeat(Tf[:, 3:], 3, 1), uvf, tr, n, unit=False)
    mt = 2.0 * read_image(tmp, tm) - 1.0
    b = np.sign(Ss[..., :1]) * np.cross(Nn, Tt)
    dec = mt[..., :1] * Tt + mt[..., 1:2] * b + mt[..., 2:3] * Nn
    both = cov2 & cov
    ag = angles(dec[both], got[both])
    check(p.returncode == 0 and ag.mean() < 0.01 and np.percentile(ag, 99) < 0.1,
          "glb + tangent map decoded in the file's frame = object-space bake (%.5f / %.5f deg)"
          % (ag.mean(), np.percentile(ag, 99)))

    # 7. tangent space with the defaults (samples, padding) and UDIM names, end to end
    out = os.path.join(tmp, "t.glb")
    p = run([low, out, "--from", high, "--bake-normal-map", os.path.join(tmp, "t.<UDIM>.png"),
             "--size", "64", "--samples", "4", "--bake-height-map", os.path.join(tmp, "t.<UDIM>.exr")])
    check(p.returncode == 0 and os.path.exists(os.path.join(tmp, "t.1001.png"))
          and os.path.exists(os.path.join(tmp, "t.1001.exr")) and os.path.exists(out),
          "tangent-space UDIM bake with --samples 4 writes the tiles and the glb")

    # 7b. --normal-map-y -y flips green, --bake-depth 16 is 16 bits, --threads
    # does not change a texel
    maps = {}
    for tag, extra in [("y", []), ("dx", ["--normal-map-y", "-y"]), ("t1", ["--threads", "1"])]:
        path = os.path.join(tmp, "g_%s.png" % tag)
        p = run([low, "--from", high, "--bake-normal-map", path, "--size", "64", "--bake-depth",
                 "16"] + extra)
        maps[tag] = read_image(tmp, path)
    gflip = np.abs(maps["dx"][..., 1] - (1.0 - maps["y"][..., 1])).max()
    rb = np.abs(maps["dx"][..., [0, 2]] - maps["y"][..., [0, 2]]).max()
    steps = len(np.unique(np.round(maps["y"][..., 0] * 65535)))
    check(gflip <= 1.01 / 65535 and rb == 0 and steps > 256,
          "--normal-map-y -y flips green only (max %.2g), 16-bit output (%d red levels)"
          % (gflip, steps))
    check(np.array_equal(maps["t1"], maps["y"]), "--threads 1 and the default bake the same map")

    # 8. bad input: clear errors, exit 2, nothing written
    pn = os.path.join(tmp, "nouv.obj")
    mk.write_obj(pn, pos, nrm, None, faces)
    empty = os.path.join(tmp, "empty.obj")
    with open(empty, "w") as f:
        f.write("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
    cp, cn, cu, cf = mk.uv_sphere(12, 6)
    other = os.path.join(tmp, "other_cage.obj")
    mk.write_obj(other, cp * 1.1, cn, cu, cf)
    bad_map = os.path.join(tmp, "bad.png")
    cases = [
        ([pn, "--from", high], "no texture coordinates", "LOW without UVs"),
        ([low, "--from", empty], "no usable triangle", "HIGH without a usable triangle"),
        ([low, "--from", os.path.join(tmp, "missing.ply")], "--from", "HIGH missing"),
        ([low, "--from", high, "--cage", other], "another topology", "a cage of another topology"),
        ([low, "--from", high, "--ray-distance", "0"], "--ray-distance", "distance 0"),
        ([low, "--from", high, "--ray-distance", "nan"], "--ray-distance", "distance NaN"),
        ([low, "--from", high, "--bake-height-map", os.path.join(tmp, "h.png")], "float image",
         "a height map that cannot hold signed values"),
        ([low, "--cage", other], "--from", "--cage without --from"),
    ]
    for args, msg, what in cases:
        p = run(args + ["--bake-normal-map", bad_map, "--size", "32"], expect=2)
        check(p.returncode == 2 and msg in p.stderr and not os.path.exists(bad_map),
              "%s: exit 2, '%s' in the message, no map" % (what, msg))
    if FAILS:
        print("%d FAILED" % len(FAILS))
        sys.exit(1)


if __name__ == "__main__":
    main()
