# SPDX-License-Identifier: MIT
"""The glTF that `bumpgrad mesh IN OUT.glb|.gltf --bake-normal-map ...` writes
keeps the source's structure: one glTF mesh and one root node per node of the
source that holds triangles (an instanced node once per instance), named
after it, with the source's mesh name, its triangle count, and its
triangles in the source's order with the node's world transform baked into
the vertices (the nodes have none). Checked against the source itself, read
with our own reader (gltf_read.py: json + numpy): glTF2 ClearCoatTest (24
nodes in a hierarchy, instanced meshes), spider.obj (19 groups, read from the
OBJ text) and a glTF of our own (a mirrored instance, a mesh of two
primitives, a name that needs JSON escaping); a name that is not UTF-8; and
the cap of 65536 parts (one more: one mesh, said in the summary). Every file written also passes
a structural check of the kind a strict importer (Blender's) makes: indices,
accessor and buffer view bounds, POSITION min/max, unit NORMAL and TANGENT.

usage: test_mesh_gltf_nodes.py BUMPGRAD MODELS_DIR
Exit 77 (skip) when the models are missing."""
import base64
import json
import os
import struct
import sys
import tempfile

import numpy as np

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
import mesh_util  # noqa: E402,F401  (puts tests/ on the path)
from harness import check, finish, run  # noqa: E402
from gltf_read import COMPONENTS, DTYPES, Gltf  # noqa: E402

BUMPGRAD, MODELS = sys.argv[1:3]


def mesh(args):
    rc, out, err = run(BUMPGRAD, ["mesh"] + args)
    if rc != 0:
        print(out, err)
    return rc, out


def node_matrix(n):
    """A glTF node's local transform (4x4)."""
    if "matrix" in n:
        return np.array(n["matrix"], np.float64).reshape(4, 4).T
    x, y, z, w = n.get("rotation", [0, 0, 0, 1])
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.eye(4)
    m[:3, :3] = r * np.array(n.get("scale", [1, 1, 1]))
    m[:3, 3] = n.get("translation", [0, 0, 0])
    return m


def source_parts(g):
    """Per node of a glTF source holding a mesh, depth first in the order of
    the scene: (node name, mesh name, triangle corners (T, 3, 3) in model
    space with the winding kept, as the loader flips it under a mirror)."""
    js = g.json
    out = []

    def visit(i, parent):
        n = js["nodes"][i]
        w = parent @ node_matrix(n)
        if "mesh" in n:
            corners = []
            for p in js["meshes"][n["mesh"]]["primitives"]:
                P = g.accessor(p["attributes"]["POSITION"]).astype(np.float64)
                t = g.accessor(p["indices"]).reshape(-1, 3).astype(np.int64)
                if np.linalg.det(w[:3, :3]) < 0:
                    t = t[:, ::-1]
                corners.append(P[t] @ w[:3, :3].T + w[:3, 3])
            out.append((n.get("name", ""), js["meshes"][n["mesh"]].get("name", ""),
                        np.concatenate(corners)))
        for c in n.get("children", []):
            visit(c, w)

    for i in js["scenes"][js.get("scene", 0)]["nodes"]:
        visit(i, np.eye(4))
    return out


def written_parts(g):
    """Per node of a file we wrote: (node name, mesh name, corners (T, 3, 3),
    primitive count)."""
    out = []
    for n in g.json["nodes"]:
        m = g.json["meshes"][n["mesh"]]
        corners = []
        for p in m["primitives"]:
            P = g.accessor(p["attributes"]["POSITION"]).astype(np.float64)
            corners.append(P[g.accessor(p["indices"]).reshape(-1, 3).astype(np.int64)])
        out.append((n.get("name"), m.get("name", ""), np.concatenate(corners),
                    len(m["primitives"])))
    return out


def structure_problems(path):
    """What a strict importer would refuse in the file at `path` (a list of
    strings, empty when none)."""
    bad = []
    data = open(path, "rb").read()
    if data[:4] == b"glTF":
        version, total = struct.unpack("<II", data[4:12])
        n0, k0 = struct.unpack("<I4s", data[12:20])
        n1, k1 = struct.unpack("<I4s", data[20 + n0:28 + n0])
        if (version, total, k0, k1) != (2, len(data), b"JSON", b"BIN\0") or n0 % 4 or n1 % 4 \
                or 28 + n0 + n1 != total:
            bad.append("glb header or chunks")
    g = Gltf(path)
    js = g.json
    if js["asset"]["version"] != "2.0":
        bad.append("asset.version")
    nodes, meshes, acc, views = js["nodes"], js["meshes"], js["accessors"], js["bufferViews"]
    roots = js["scenes"][js["scene"]]["nodes"]
    if sorted(roots) != list(range(len(nodes))):
        bad.append("every node is a root node, once")
    if sorted(n["mesh"] for n in nodes) != list(range(len(meshes))):
        bad.append("every mesh is used by one node")
    for i, n in enumerate(nodes):
        if any(k in n for k in ("matrix", "translation", "rotation", "scale", "children")):
            bad.append("node %d has a transform or children" % i)
        if not isinstance(n.get("name"), str) or not n["name"]:
            bad.append("node %d has no name" % i)
    for i, v in enumerate(views):
        blen = js["buffers"][v["buffer"]]["byteLength"]
        if v.get("byteOffset", 0) % 4 or v.get("byteOffset", 0) + v["byteLength"] > blen:
            bad.append("bufferView %d out of its buffer" % i)
    for i, b in enumerate(js["buffers"]):
        if g.buffers[i] is None or len(g.buffers[i]) < b["byteLength"]:
            bad.append("buffer %d shorter than its byteLength" % i)
    for i, a in enumerate(acc):
        size = np.dtype(DTYPES[a["componentType"]]).itemsize
        end = a.get("byteOffset", 0) + a["count"] * COMPONENTS[a["type"]] * size
        if a["count"] < 1 or a.get("byteOffset", 0) % size or \
                end > views[a["bufferView"]]["byteLength"]:
            bad.append("accessor %d out of its bufferView" % i)
    if bad:
        return bad
    for mi, m in enumerate(meshes):
        for p in m["primitives"]:
            at = p["attributes"]
            counts = {acc[k]["count"] for k in at.values()}
            P = g.accessor(at["POSITION"])
            ia = acc[p["indices"]]
            idx = g.accessor(p["indices"])
            if len(counts) != 1 or ia["type"] != "SCALAR" or ia["componentType"] != 5125 or \
                    ia["count"] % 3 or idx.max() >= len(P) or p.get("mode", 4) != 4:
                bad.append("mesh %d: attribute counts or indices" % mi)
            pa = acc[at["POSITION"]]
            # the bounds as float32 (JSON holds 9 significant digits of them)
            if "min" not in pa or "max" not in pa or \
                    np.any(np.float32(pa["min"]) != P.min(axis=0)) or \
                    np.any(np.float32(pa["max"]) != P.max(axis=0)):
                bad.append("mesh %d: POSITION min/max are not the data's" % mi)
            nrm = np.linalg.norm(g.accessor(at["NORMAL"]), axis=1)
            if np.abs(nrm - 1).max() > 1e-3:
                bad.append("mesh %d: NORMAL not unit" % mi)
            if "TANGENT" in at:
                t = g.accessor(at["TANGENT"])
                if np.abs(np.linalg.norm(t[:, :3], axis=1) - 1).max() > 1e-3 or \
                        not np.all(np.abs(t[:, 3]) == 1):
                    bad.append("mesh %d: TANGENT xyz not unit or w not +-1" % mi)
            if p.get("material", 0) >= max(1, len(js.get("materials", []))):
                bad.append("mesh %d: material index" % mi)
    for m in js.get("materials", []):
        for key in ("normalTexture",):
            if key in m and m[key]["index"] >= len(js.get("textures", [])):
                bad.append("material texture index")
    for t in js.get("textures", []):
        if t["source"] >= len(js.get("images", [])):
            bad.append("texture source index")
    return bad


def same_geometry(src, out, scale):
    """The corners of every part agree (relative to the model's scale)."""
    return max(np.abs(s[2] - o[2]).max() if s[2].shape == o[2].shape else np.inf
               for s, o in zip(src, out)) <= 1e-5 * scale


def own_gltf(path):
    """A glTF2 of our own: mesh "Quad" (a unit quad with UVs) under a node
    that mirrors it (scale -1 in x) inside a translated and scaled parent,
    again under a plain node (an instance), and mesh "Twin" of two primitives
    (materials A and B) under a node whose name needs escaping."""
    pos = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
    nrm = np.tile(np.array([0, 0, 1], np.float32), (4, 1))
    uv = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
    idx = np.array([0, 1, 2, 0, 2, 3], np.uint32)
    pos2 = pos * [0.5, 1, 1] + [2, 0, 0]
    blob = b"".join(a.tobytes() for a in (pos, nrm, uv, idx, pos2))
    views = [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in
             ((0, 48), (48, 48), (96, 32), (128, 24), (152, 48))]
    accs = [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5125, "count": 6, "type": "SCALAR"},
            {"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [2, 0, 0], "max": [2.5, 1, 0]}]
    quad = {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3}
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 3, 4]}],
        "nodes": [
            {"name": "Parent", "children": [1, 2], "translation": [1, 2, 3],
             "scale": [2, 2, 2]},
            {"name": "Mirrored", "mesh": 0, "scale": [-1, 1, 1]},
            {"name": "Twin \"node\" \\ \u00fc", "mesh": 1, "translation": [0, 0, 1]},
            {"name": "Plain", "mesh": 0, "rotation": [0, 0, 0.7071068, 0.7071068]},
            {"name": "Only lines", "mesh": 2},
        ],
        "meshes": [
            {"name": "Quad", "primitives": [dict(quad, material=0)]},
            {"name": "Twin", "primitives": [dict(quad, material=0),
                                            {"attributes": {"POSITION": 4, "NORMAL": 1,
                                                            "TEXCOORD_0": 2},
                                             "indices": 3, "material": 1}]},
            {"name": "Lines", "primitives": [dict(quad, mode=1)]},
        ],
        "materials": [{"name": "A", "pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1]}},
                      {"name": "B", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 1, 1]}}],
        "accessors": accs,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64,"
                     + base64.b64encode(blob).decode()}],
    }
    with open(path, "w") as f:
        json.dump(doc, f)


def many_nodes(path, n):
    """A glTF2 of n nodes n0, n1, ... each using one triangle, side by side."""
    blob = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32).tobytes() + \
        np.array([0, 1, 2], np.uint32).tobytes()
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(range(n))}],
           "nodes": [{"name": "n%d" % i, "mesh": 0, "translation": [i * 1e-3, 0, 0]}
                     for i in range(n)],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                          "min": [0, 0, 0], "max": [1, 1, 0]},
                         {"bufferView": 1, "componentType": 5125, "count": 3,
                          "type": "SCALAR"}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                           {"buffer": 0, "byteOffset": 36, "byteLength": 12}],
           "buffers": [{"byteLength": 48, "uri": "data:application/octet-stream;base64,"
                        + base64.b64encode(blob).decode()}]}
    with open(path, "w") as f:
        json.dump(doc, f)


def obj_groups(path):
    """The groups of an OBJ file in order with their triangle counts (a face
    of n corners is n - 2 triangles; lines are not triangles)."""
    groups = []
    for line in open(path, errors="replace"):
        w = line.split()
        if not w:
            continue
        if w[0] in ("g", "o"):
            groups.append([" ".join(w[1:]), 0])
        elif w[0] == "f" and len(w) >= 4:
            groups[-1][1] += len(w) - 3
    return [g for g in groups if g[1]]


def main():
    cc = os.path.join(MODELS, "glTF2", "ClearCoat-glTF", "ClearCoatTest.gltf")
    spider = os.path.join(MODELS, "OBJ", "spider.obj")
    if not (os.path.exists(cc) and os.path.exists(spider)):
        print("models missing: skipped")
        return 77
    with tempfile.TemporaryDirectory() as tmp:
        # 1. glTF2 source: ClearCoatTest, a two-level hierarchy with translations,
        #    meshes 0, 1 and 2 each used by two nodes
        src = source_parts(Gltf(cc))
        scale = max(np.abs(s[2]).max() for s in src)
        for join in ("auto", "always", "never"):
            out = os.path.join(tmp, "cc-%s.glb" % join)
            rc, text = mesh([cc, out, "--bake-normal-map", os.path.join(tmp, "cc.png"),
                             "--size", "64", "--join", join])
            if not check(rc == 0, "ClearCoatTest --join %s: baked into a .glb" % join):
                continue
            got = written_parts(Gltf(out))
            check([o[0] for o in got] == [s[0] for s in src],
                  "ClearCoatTest --join %s: the %d node names, in order (%s ...)"
                  % (join, len(src), [o[0] for o in got][:4]))
            check([o[1] for o in got] == [s[1] for s in src],
                  "ClearCoatTest --join %s: each mesh has its source mesh's name" % join)
            check([len(o[2]) for o in got] == [len(s[2]) for s in src],
                  "ClearCoatTest --join %s: triangles per mesh match the source (%s ...)"
                  % (join, [len(o[2]) for o in got][:4]))
            check(same_geometry(src, got, scale),
                  "ClearCoatTest --join %s: each mesh's triangles are the source's, in "
                  "order, in model space (node transforms applied)" % join)
            bad = structure_problems(out)
            check(not bad, "ClearCoatTest --join %s: the glb passes the structural check %s"
                  % (join, bad))
            check("glTF: original normals, %d meshes," % len(src) in text,
                  "ClearCoatTest --join %s: the summary counts %d meshes" % (join, len(src)))

        # 2. OBJ: one node per group (lines-only parts of a group are dropped)
        out = os.path.join(tmp, "spider.gltf")
        rc, _ = mesh([spider, out, "--bake-normal-map", os.path.join(tmp, "s.png"),
                      "--size", "64"])
        if check(rc == 0, "spider.obj: baked into a .gltf"):
            groups = obj_groups(spider)
            got = written_parts(Gltf(out))
            check([(o[0], len(o[2])) for o in got] == [tuple(g) for g in groups],
                  "spider.obj: the %d groups of the OBJ are the nodes, with their triangle "
                  "counts (%s ...)" % (len(groups), [(o[0], len(o[2])) for o in got][:3]))
            check(sum(o[3] for o in got) > len(got) - 1,
                  "spider.obj: every mesh has its primitives")
            bad = structure_problems(out)
            check(not bad, "spider.obj: the .gltf passes the structural check %s" % bad)

        # 3. our own glTF: a mirrored instance, a two-primitive mesh, escaping
        own = os.path.join(tmp, "own.gltf")
        own_gltf(own)
        src = source_parts(Gltf(own))
        src = [s for s in src if s[0] != "Only lines"]
        for ext in ("glb", "gltf"):
            out = os.path.join(tmp, "own-out." + ext)
            rc, _ = mesh([own, out, "--bake-normal-map", os.path.join(tmp, "own.png"),
                          "--size", "32"])
            if not check(rc == 0, "own glTF: baked into a .%s" % ext):
                continue
            g = Gltf(out)
            got = written_parts(g)
            check([o[0] for o in got] == ["Mirrored", "Twin \"node\" \\ \u00fc", "Plain"],
                  ".%s: node names kept, escaped in the JSON and read back (%s); the node "
                  "with only lines has none" % (ext, [o[0] for o in got]))
            check([o[1] for o in got] == ["Quad", "Twin", "Quad"] and
                  [o[3] for o in got] == [1, 2, 1],
                  ".%s: mesh names (the two-primitive mesh is one mesh of two primitives)"
                  % ext)
            check(same_geometry(src, got, 4.0),
                  ".%s: the triangles carry their nodes' world transforms (the mirrored one "
                  "with its winding turned back)" % ext)
            mats = [[p.get("material") for p in m["primitives"]] for m in g.json["meshes"]]
            names = [m.get("name") for m in g.json["materials"]]
            check([[names[i] for i in m] for m in mats] == [["A"], ["A", "B"], ["A"]],
                  ".%s: each primitive keeps its material (%s)" % (ext, mats))
            P, tris = [], []
            for p in g.json["meshes"][0]["primitives"]:
                P = g.accessor(p["attributes"]["POSITION"]).astype(np.float64)
                N = g.accessor(p["attributes"]["NORMAL"]).astype(np.float64)
                tris = g.accessor(p["indices"]).reshape(-1, 3)
            face = np.cross(P[tris[:, 1]] - P[tris[:, 0]], P[tris[:, 2]] - P[tris[:, 0]])
            check(np.all(np.einsum("ka,ka->k", face, N[tris[:, 0]]) > 0),
                  ".%s: the mirrored quad's winding agrees with its NORMAL" % ext)
            bad = structure_problems(out)
            check(not bad, ".%s: passes the structural check %s" % (ext, bad))

        # 4. a group name that is not UTF-8 (Latin-1) becomes U+FFFD: valid JSON
        obj = os.path.join(tmp, "latin1.obj")
        with open(obj, "wb") as f:
            f.write(b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                    b"g Kopf\xfc\nf 1/1 2/2 3/3\ng Fu\xc3\x9f\nf 1/1 3/3 4/4\n")
        out = os.path.join(tmp, "latin1.glb")
        rc, _ = mesh([obj, out, "--bake-normal-map", os.path.join(tmp, "l.png"), "--size", "16"])
        try:
            names = [n.get("name") for n in Gltf(out).json["nodes"]] if rc == 0 else None
        except (UnicodeDecodeError, ValueError) as err:
            names = str(err)
        check(names == ["Kopf\ufffd", "Fu\u00df"],
              "a Latin-1 group name is written as U+FFFD, a UTF-8 one as it is (%s)" % names)

        # 5. the cap: 65536 nodes with triangles are kept, one more and the
        #    glTF is one mesh, which the summary says
        for n in (65536, 65537):
            src = os.path.join(tmp, "many%d.gltf" % n)
            many_nodes(src, n)
            out = os.path.join(tmp, "many%d.glb" % n)
            rc, text = mesh([src, out])
            nodes = Gltf(out).json["nodes"] if rc == 0 else []
            if n == 65536:
                check(len(nodes) == n and nodes[-1]["name"] == "n65535" and
                      "65536 meshes, " in text, "%d nodes: %d meshes and nodes" % (n, len(nodes)))
            else:
                check(len(nodes) == 1 and "1 mesh (the scene has more than 65536 nodes with "
                      "triangles: merged into one)" in text,
                      "%d nodes: one mesh, and the summary says why" % n)
    return finish("mesh_gltf_nodes")


if __name__ == "__main__":
    sys.exit(main())
