# SPDX-License-Identifier: MIT
"""The glTF that `bumpgrad mesh IN out.glb --bake-normal-map n.exr` writes,
read as a glTF viewer reads it (gltf_read.py, our own json + numpy reader):
per texel the map is decoded in the file's own frame (the interpolated
NORMAL and TANGENT, b = w cross(n, t), n' = normalize(m.x t + m.y b + m.z n),
as mikkTSpace's pixel shader does) and must match the object-space bake of
the same mesh. On spider.obj (OBJ, six materials with JPEG textures) and
duck.dae (Collada, mirrored UVs). Also: the materials reference the map, the
source's materials and textures survive, a .gltf references the map beside
it, and --gltf-normals bumped writes no normalTexture.

usage: test_mesh_gltf.py BUMPGRAD MESH_ORACLE MODELS_DIR
Exit 77 (skip) when the models are missing."""
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
from mesh_util import read_image, texel_cover  # noqa: E402
from harness import FAILURES, check, finish  # noqa: E402
from gltf_read import Gltf  # noqa: E402

BUMPGRAD, ORACLE, MODELS = sys.argv[1:4]
N = 256


def run(args):
    p = subprocess.run([BUMPGRAD, "mesh"] + args, capture_output=True, text=True)
    if p.returncode != 0:
        print(p.stdout, p.stderr)
    return p


def rasterize(P, UV, tris, W, H, edge=1e-4):
    """Per texel the LAST triangle whose UV image holds its centre (the
    bake's rule), with its barycentric weights; texels within `edge` of that
    triangle's border are marked ambiguous. Triangles with zero 3D or UV area
    are skipped, as the bake skips them."""
    owner = np.full(H * W, -1, np.int64)
    wts = np.zeros((H * W, 3))
    near = np.zeros(H * W, bool)
    X = UV[:, 0].astype(np.float64) * W
    Y = UV[:, 1].astype(np.float64) * H  # glTF's v is down: row = v * H
    for t, (i0, i1, i2) in enumerate(tris):
        a = np.cross(P[i1] - P[i0], P[i2] - P[i0])
        if not np.any(a):
            continue
        x, y = X[[i0, i1, i2]], Y[[i0, i1, i2]]
        cover = texel_cover(x, y, W, H)
        if cover is None:
            continue
        rows, cols, lam = cover
        k = rows * W + cols
        owner[k] = t
        wts[k] = lam
        near[k] = lam.min(axis=1) < edge
    return owner, wts, near


def decode_in_file_frame(g, tmap, materials=None):
    """The map decoded per texel in the glTF's TANGENT frame (over the
    primitives whose material is in `materials`, default all); returns the
    unit vectors and a mask of the texels that are unambiguous."""
    attrs, tris, mats = g.merged()
    P, Nn, T, UV = attrs["POSITION"], attrs["NORMAL"], attrs["TANGENT"], attrs["TEXCOORD_0"]
    if materials is not None:
        tris = tris[np.isin(mats, list(materials))]
    H, W, _ = tmap.shape
    owner, w, near = rasterize(P.astype(np.float64), UV, tris, W, H)
    ok = (owner >= 0) & ~near
    tri = tris[owner[ok]]
    ww = w[ok]
    n = np.einsum("kc,kca->ka", ww, Nn[tri].astype(np.float64))
    t = np.einsum("kc,kca->ka", ww, T[tri][:, :, :3].astype(np.float64))
    s = np.einsum("kc,kc->k", ww, T[tri][:, :, 3].astype(np.float64))
    b = s[:, None] * np.cross(n, t)
    m = 2.0 * tmap.reshape(-1, 3)[ok] - 1.0
    out = m[:, 0:1] * t + m[:, 1:2] * b + m[:, 2:3] * n
    out /= np.linalg.norm(out, axis=1, keepdims=True)
    return out, ok


def angles_deg(a, b):
    a = a / np.linalg.norm(a, axis=1, keepdims=True)
    b = b / np.linalg.norm(b, axis=1, keepdims=True)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1)))


def model(tmp, name, src):
    glb, nmap, omap = (os.path.join(tmp, name + s) for s in (".glb", "_n.exr", "_o.exr"))
    size = ["--size", str(N), "--bake-depth", "float"]
    p = run([src, glb, "--bake-normal-map", nmap] + size)
    check(p.returncode == 0, "%s: mesh IN out.glb --bake-normal-map n.exr" % name)
    p = run([src, "--bake-normal-map", omap, "--space", "object"] + size)
    check(p.returncode == 0, "%s: the object-space bake" % name)
    if FAILURES:
        return
    g = Gltf(glb)
    tmap, omap_img = read_image(ORACLE, tmp, nmap), read_image(ORACLE, tmp, omap)
    dec, ok = decode_in_file_frame(g, tmap)
    ref = 2.0 * omap_img.reshape(-1, 3)[ok] - 1.0
    a = angles_deg(dec, ref)
    mean, p99 = a.mean(), np.percentile(a, 99)
    print("%s: %d texels decoded in the file's TANGENT frame vs the object-space bake: "
          "mean %.5f deg, p99 %.5f deg, max %.3f deg" % (name, ok.sum(), mean, p99, a.max()))
    check(ok.sum() > 0.2 * N * N, "%s: most texels are decoded (%d)" % (name, ok.sum()))
    check(mean < 0.01 and p99 < 0.1, "%s: decoded map matches the object-space bake within "
          "0.01 deg mean, 0.1 deg p99 (%.5f, %.5f)" % (name, mean, p99))
    # the glb carries the ORIGINAL normals: NORMAL differs from the bumped ones
    mats = g.json.get("materials", [])
    prims = [m for _, _, m in g.primitives()]
    check(len(mats) > 0 and all(m is not None for m in prims),
          "%s: every primitive has a material (%d materials)" % (name, len(mats)))
    normal_tex = {m.get("normalTexture", {}).get("index") for m in mats}
    check(len(normal_tex) == 1 and None not in normal_tex,
          "%s: every material's normalTexture is the one map" % name)
    if normal_tex and None not in normal_tex:
        src_img = g.json["textures"][normal_tex.pop()]["source"]
        data, mime = g.image_bytes(src_img)
        png = os.path.join(tmp, name + "_embedded.png")
        open(png, "wb").write(data)
        emb = read_image(ORACLE, tmp, png)
        diff = np.abs(emb - np.clip(np.round(tmap * 255) / 255, 0, 1)).max()
        check(mime == "image/png" and data[:4] == b"\x89PNG" and diff <= 1.01 / 255,
              "%s: the embedded image is the map as an 8-bit PNG (max diff %.4f)" % (name, diff))
    return g


def udim(tmp):
    """A <UDIM> bake into a .glb: one material per tile, whose normalTexture is
    that tile's map, and UVs shifted into the tile; each tile decoded in the
    file's frame matches the object-space tile."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from make_cubesphere import cubesphere, write_obj
    pos, uv, faces = cubesphere(16)
    obj = os.path.join(tmp, "tiles.obj")
    write_obj(obj, pos, uv * [3, 2], faces)  # atlas cell (a, b) becomes tile (a, b)
    glb = os.path.join(tmp, "tiles.glb")
    size = ["--size", "128", "--bake-depth", "float"]
    p = run([obj, glb, "--bake-normal-map", os.path.join(tmp, "tn.<UDIM>.exr")] + size)
    q = run([obj, "--bake-normal-map", os.path.join(tmp, "to.<UDIM>.exr"), "--space", "object"]
            + size)
    check(p.returncode == 0 and q.returncode == 0, "UDIM: tangent and object bakes of six tiles")
    if p.returncode or q.returncode:
        return
    g = Gltf(glb)
    mats = g.json["materials"]
    check(len(mats) == 6 and all("normalTexture" in m for m in mats),
          "UDIM: six materials, each with a normalTexture (%s)" % [m.get("name") for m in mats])
    worst = (0.0, 0.0)
    for tile in (1001, 1002, 1003, 1011, 1012, 1013):
        sel = {i for i, m in enumerate(mats) if m.get("name", "").endswith(str(tile))}
        tmap = read_image(ORACLE, tmp, os.path.join(tmp, "tn.%d.exr" % tile))
        omap = read_image(ORACLE, tmp, os.path.join(tmp, "to.%d.exr" % tile))
        dec, ok = decode_in_file_frame(g, tmap, sel)
        a = angles_deg(dec, 2.0 * omap.reshape(-1, 3)[ok] - 1.0)
        if ok.sum() < 1000:
            worst = (99.0, 99.0)
        else:
            worst = (max(worst[0], a.mean()), max(worst[1], np.percentile(a, 99)))
    check(worst[0] < 0.01 and worst[1] < 0.1,
          "UDIM: every tile decoded in the file's frame matches its object-space tile (worst "
          "mean %.5f deg, p99 %.5f deg)" % worst)


def main():
    spider = os.path.join(MODELS, "OBJ", "spider.obj")
    duck = os.path.join(MODELS, "Collada", "duck.dae")
    if not (os.path.exists(spider) and os.path.exists(duck)):
        print("models missing: skipped")
        return 77
    with tempfile.TemporaryDirectory() as tmp:
        g = model(tmp, "spider", spider)
        if g is not None:
            names = [m.get("name") for m in g.json["materials"]]
            check(set(["Skin", "Brusttex", "HLeibTex", "BeinTex", "Augentex"]) <= set(names),
                  "spider: the source's material names survive (%s)" % names)
            with_tex = [m for m in g.json["materials"]
                        if "baseColorTexture" in m.get("pbrMetallicRoughness", {})]
            check(len(with_tex) == 5, "spider: five base colour textures kept (%d)" % len(with_tex))
            jpg = [g.image_bytes(g.json["textures"][m["pbrMetallicRoughness"]
                                                    ["baseColorTexture"]["index"]]["source"])
                   for m in with_tex]
            kd = {}
            name = None
            for line in open(os.path.join(MODELS, "OBJ", "spider.mtl")):
                w = line.split()
                if w[:1] == ["newmtl"]:
                    name = w[1]
                elif w[:1] == ["Kd"]:
                    kd[name] = [float(x) for x in w[1:4]]
            got = {m.get("name"): m["pbrMetallicRoughness"].get("baseColorFactor")
                   for m in g.json["materials"]}
            check(all(got.get(k) is not None and np.allclose(got[k][:3], v, atol=1e-6)
                      for k, v in kd.items()),
                  "spider: every material's Kd of spider.mtl is its baseColorFactor")
            orig = open(os.path.join(MODELS, "OBJ", "SpiderTex.jpg"), "rb").read()
            check(any(d == orig for d, _ in jpg), "spider: SpiderTex.jpg embedded byte for byte")
        model(tmp, "duck", duck)
        udim(tmp)
        # .gltf: the map referenced beside it; the source textures by relative paths
        sub = os.path.join(tmp, "out")
        os.mkdir(sub)
        p = run([spider, os.path.join(sub, "s.gltf"), "--bake-normal-map",
                 os.path.join(sub, "n.png"),
                 "--size", "64"])
        g = Gltf(os.path.join(sub, "s.gltf"))
        uris = [im.get("uri") for im in g.json["images"]]
        check(p.returncode == 0 and uris[0] == "n.png" and
              all(os.path.exists(g.resolve(u)) for u in uris if u),
              ".gltf: the map beside it as n.png, every image URI resolves (%s)" % uris)
        p = run([spider, os.path.join(tmp, "b.glb"), "--bake-normal-map",
                 os.path.join(tmp, "b.png"), "--size", "64", "--gltf-normals", "bumped"])
        g = Gltf(os.path.join(tmp, "b.glb"))
        check(p.returncode == 0 and not any("normalTexture" in m for m in g.json["materials"])
              and "no material uses the map" in p.stdout,
              "--gltf-normals bumped: no normalTexture, and the summary says why")
        # the normals: original with a map, bumped without
        p1 = run([spider, os.path.join(tmp, "plain.glb")])
        g1, g2 = Gltf(os.path.join(tmp, "plain.glb")), Gltf(os.path.join(tmp, "spider.glb"))
        n1 = next(g1.primitives())[0]["NORMAL"]
        n2 = next(g2.primitives())[0]["NORMAL"]
        check(p1.returncode == 0 and len(n1) == len(n2) and np.abs(n1 - n2).max() > 0.05,
              "without a map the glb carries the bumped normals, with one the original ones")
    return finish("mesh_gltf")


if __name__ == "__main__":
    sys.exit(main())
