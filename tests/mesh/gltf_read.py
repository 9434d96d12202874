# SPDX-License-Identifier: MIT
"""A small glTF 2.0 reader of our own (json + numpy), for checking what
`bumpgrad mesh` writes as a glTF viewer reads it: .glb (JSON and BIN chunks)
or .gltf (a base64 data URI or a file beside it), accessors of float32 and
uint32 (tightly packed), materials and images (bytes embedded in a bufferView
or a relative URI resolved against the file's folder)."""
import base64
import json
import os
import struct
import urllib.parse

import numpy as np

COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
DTYPES = {5126: "<f4", 5125: "<u4", 5123: "<u2", 5121: "u1"}


class Gltf:
    def __init__(self, path):
        self.path = path
        data = open(path, "rb").read()
        self.bin = None
        if data[:4] == b"glTF":
            version, total = struct.unpack("<II", data[4:12])
            assert version == 2 and total == len(data), "bad .glb header"
            off = 12
            while off < total:
                n, kind = struct.unpack("<I4s", data[off:off + 8])
                chunk = data[off + 8:off + 8 + n]
                if kind == b"JSON":
                    self.json = json.loads(chunk.decode("utf-8"))
                elif kind == b"BIN\0":
                    self.bin = chunk
                off += 8 + n
        else:
            self.json = json.loads(data.decode("utf-8"))
        self.buffers = []
        for i, b in enumerate(self.json.get("buffers", [])):
            uri = b.get("uri")
            if uri is None:
                self.buffers.append(self.bin)
            elif uri.startswith("data:"):
                self.buffers.append(base64.b64decode(uri.split(",", 1)[1]))
            else:
                self.buffers.append(open(self.resolve(uri), "rb").read())

    def resolve(self, uri):
        return os.path.join(os.path.dirname(os.path.abspath(self.path)),
                            urllib.parse.unquote(uri))

    def view(self, i):
        v = self.json["bufferViews"][i]
        o = v.get("byteOffset", 0)
        return self.buffers[v["buffer"]][o:o + v["byteLength"]]

    def accessor(self, i):
        a = self.json["accessors"][i]
        k = COMPONENTS[a["type"]]
        dt = np.dtype(DTYPES[a["componentType"]])
        raw = self.view(a["bufferView"])
        o = a.get("byteOffset", 0)
        arr = np.frombuffer(raw[o:o + a["count"] * k * dt.itemsize], dt)
        return arr.reshape(a["count"], k) if k > 1 else arr

    def image_bytes(self, i):
        im = self.json["images"][i]
        if "bufferView" in im:
            return bytes(self.view(im["bufferView"])), im.get("mimeType")
        return open(self.resolve(im["uri"]), "rb").read(), None

    def primitives(self):
        """(attributes dict of arrays, triangles (n, 3), material index) per primitive,
        in file order."""
        for mesh in self.json["meshes"]:
            for p in mesh["primitives"]:
                assert p.get("mode", 4) == 4
                attrs = {k: self.accessor(v) for k, v in p["attributes"].items()}
                tris = self.accessor(p["indices"]).reshape(-1, 3)
                yield attrs, tris, p.get("material")

    def merged(self):
        """Every primitive in one triangle list, as a viewer draws the scene
        (our files' nodes have no transform): the attributes of the meshes
        concatenated (primitives sharing their accessors share the vertices),
        the triangles (n, 3) into them and each triangle's material."""
        for node in self.json.get("nodes", []):
            assert not any(k in node for k in ("matrix", "translation", "rotation", "scale"))
        base, parts, tris, mats, n = {}, [], [], [], 0
        for attrs_ix, p in ((tuple(sorted(p["attributes"].items())), p)
                            for mesh in self.json["meshes"] for p in mesh["primitives"]):
            assert p.get("mode", 4) == 4
            if attrs_ix not in base:
                attrs = {k: self.accessor(v) for k, v in attrs_ix}
                base[attrs_ix] = n
                parts.append(attrs)
                n += len(attrs["POSITION"])
            t = self.accessor(p["indices"]).reshape(-1, 3).astype(np.int64)
            tris.append(t + base[attrs_ix])
            mats.append(np.full(len(t), -1 if p.get("material") is None else p["material"]))
        attrs = {k: np.concatenate([a[k] for a in parts]) for k in parts[0]}
        return attrs, np.concatenate(tris), np.concatenate(mats)
