# SPDX-License-Identifier: MIT
"""The tools as Python functions (docs/PYTHON.md): bake_normal_map returns the
same texels as `bumpgrad mesh --bake-normal-map` writes to a float file, for
several option sets, UDIM tiles and path= output; progress and errors; and
heightmap() the same as `bumpgrad heightmap`.

usage: test_tools.py BUMPGRAD_EXE
"""
import math
import os
import subprocess
import sys
import tempfile
import warnings

import numpy as np

import bumpgrad
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import QUIET, check, finish  # noqa: E402
QUIET[0] = True  # failures only, as before



def bits(a):
    return np.ascontiguousarray(a).view(np.uint32)


def write_sphere(path, rings=12, segments=24, u_tiles=1):
    """A UV sphere as OBJ with normals and UVs; u_tiles > 1 spreads U over
    that many UDIM tiles (1001, 1002, ...)."""
    lines = []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(segments + 1):
            ph = 2 * math.pi * j / segments
            x, y, z = math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)
            lines.append(f"v {x:.6f} {y:.6f} {z:.6f}")
            lines.append(f"vn {x:.6f} {y:.6f} {z:.6f}")
            lines.append(f"vt {u_tiles * j / segments * 0.999:.6f} {1 - i / rings:.6f}")
    w = segments + 1
    for i in range(rings):
        for j in range(segments):
            a, b, c, d = i * w + j + 1, i * w + j + 2, (i + 1) * w + j + 2, (i + 1) * w + j + 1
            lines.append(f"f {a}/{a}/{a} {d}/{d}/{d} {c}/{c}/{c}")
            lines.append(f"f {a}/{a}/{a} {c}/{c}/{c} {b}/{b}/{b}")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def cli_bake(exe, mesh, out, size, extra):
    subprocess.run([exe, "-q", "mesh", mesh, "--bake-normal-map", out, "--bake-depth", "float",
                    "--size", str(size)] + extra, check=True)


def main():
    exe = sys.argv[1]
    if not bumpgrad.HAVE_TOOLS:
        print("tools: this build has no tools; bake_normal_map raises")
        try:
            bumpgrad.bake_normal_map("x.obj", 8)
            check(False, "bake_normal_map without the tools did not raise")
        except bumpgrad.Error:
            pass
        return finish("tools")
    with tempfile.TemporaryDirectory() as tmp:
        mesh = os.path.join(tmp, "sphere.obj")
        write_sphere(mesh)
        cases = [
            ({}, []),
            (dict(function="fbm", octaves=4, frequency=3.0, amplitude=0.05),
             ["--function", "fbm", "--octaves", "4", "--frequency", "3", "--amplitude", "0.05"]),
            (dict(space="object", padding=0, gradient="central"),
             ["--space", "object", "--padding", "0", "--gradient", "central"]),
            (dict(normal_map_y="-y", method="additive", threads=1),
             ["--normal-map-y", "-y", "--method", "additive", "--threads", "1"]),
            (dict(function="fbm", frequency=4.0, period=(4, 4, 2), seed=5),
             ["--function", "fbm", "--frequency", "4", "--period", "4,4,2", "--seed", "5"]),
            (dict(samples=1, filter="none"), ["--samples", "1", "--filter", "none"]),
            (dict(samples=3, units="file", frequency=2.0),
             ["--samples", "3", "--units", "file", "--frequency", "2"]),
        ]
        for kw, args in cases:
            out = os.path.join(tmp, "cli.tif")
            cli_bake(exe, mesh, out, 48, args)
            want = bumpgrad.read_image(out)
            got = bumpgrad.bake_normal_map(mesh, 48, **kw)
            check(got.shape == (48, 48, 3) and got.dtype == np.float32, f"{kw}: {got.shape}")
            check(np.array_equal(bits(got), bits(want)), f"{kw}: texels differ from the CLI's")
            print(f"bake {kw or 'defaults'}: {'same texels as the CLI' if np.array_equal(bits(got), bits(want)) else 'DIFFERENT'}")
        # The thread count does not change the texels.
        check(np.array_equal(bits(bumpgrad.bake_normal_map(mesh, 40, threads=1)),
                             bits(bumpgrad.bake_normal_map(mesh, 40, threads=3))), "threads")
        # (width, height) and path=: the file equals the CLI's file.
        p = os.path.join(tmp, "py.tif")
        tiles = bumpgrad.bake_normal_map(mesh, (40, 24), p, depth="float")
        cli_bake(exe, mesh, os.path.join(tmp, "cli2.tif"), "40x24", [])
        check(tiles == [1001], f"path= returns the tiles written: {tiles}")
        check(np.array_equal(bits(bumpgrad.read_image(p)),
                             bits(bumpgrad.read_image(os.path.join(tmp, "cli2.tif")))),
              "path= file differs from the CLI's")
        # UDIM tiles: a dict of arrays, tile for tile the CLI's.
        udim_mesh = os.path.join(tmp, "udim.obj")
        write_sphere(udim_mesh, u_tiles=2)
        maps = bumpgrad.bake_normal_map(udim_mesh, 32, udim=True)
        cli_bake(exe, udim_mesh, os.path.join(tmp, "t.<UDIM>.tif"), 32, [])
        check(sorted(maps) == [1001, 1002], f"UDIM tiles {sorted(maps)}")
        for t, a in maps.items():
            want = bumpgrad.read_image(os.path.join(tmp, f"t.{t}.tif"))
            check(np.array_equal(bits(a), bits(want)), f"UDIM tile {t} differs")
        # Progress: (0, total) first, (total, total) last, never decreasing.
        calls = []
        bumpgrad.bake_normal_map(mesh, 128, progress=lambda d, t: calls.append((d, t)))
        done = [d for d, _ in calls]
        check(len(calls) >= 2 and calls[0][0] == 0 and calls[-1][0] == calls[-1][1] > 0 and
              done == sorted(done), f"progress calls {calls[:3]} ... {calls[-2:]}")
        print(f"progress: {len(calls)} calls for {calls[-1][1]} texels")

        def boom(d, t):
            raise RuntimeError("stop here")
        try:
            bumpgrad.bake_normal_map(mesh, 64, progress=boom)
            check(False, "an exception in progress was lost")
        except RuntimeError as e:
            check("stop here" in str(e), f"progress exception: {e}")
        # heightmap: the same texels as `bumpgrad heightmap ... --bits float`.
        h = np.random.default_rng(4).uniform(0, 1, (24, 40)).astype(np.float32)
        png, ftif = os.path.join(tmp, "h.png"), os.path.join(tmp, "h.tif")
        bumpgrad.write_image(png, h, bits=8)
        bumpgrad.write_image(ftif, h, bits="float")
        check(np.array_equal(bits(bumpgrad.read_image(ftif)[:, :, 0]), bits(h)),
              "write_image/read_image float round trip")
        for src, kw, args in ((png, {}, []),
                              (png, dict(strength=2.0, edge="wrap", normal_map_y="-y"),
                               ["--strength", "2", "--edge", "wrap", "--y-down"]),
                              (ftif, dict(strength=0.5), ["--strength", "0.5"])):
            out = os.path.join(tmp, "hm.tif")
            subprocess.run([exe, "-q", "heightmap", src, out, "--bits", "float"] + args, check=True)
            want = bumpgrad.read_image(out)
            got = bumpgrad.heightmap(src, **kw)
            check(np.array_equal(bits(got), bits(want)), f"heightmap {kw}: differs from the CLI")
            if src == ftif:
                check(np.array_equal(bits(bumpgrad.heightmap(h, **kw)), bits(want)),
                      "heightmap of an array differs from the CLI on its float file")
        # gray= on a colour image, named as the CLI's --gray ('seed' is a deprecated alias).
        col = os.path.join(tmp, "col.tif")
        bumpgrad.write_image(col, np.random.default_rng(5).uniform(0, 1, (16, 20, 3)),
                             bits="float")
        for gray in ("diffuse", "rec709"):
            out = os.path.join(tmp, "hm.tif")
            subprocess.run([exe, "-q", "heightmap", col, out, "--bits", "float", "--gray", gray],
                           check=True)
            check(np.array_equal(bits(bumpgrad.heightmap(col, gray=gray)),
                                 bits(bumpgrad.read_image(out))),
                  f"heightmap gray={gray!r} differs from --gray {gray}")
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            old = bumpgrad.heightmap(col, gray="seed")
        check(any(issubclass(x.category, DeprecationWarning) for x in w) and
              np.array_equal(bits(old), bits(bumpgrad.heightmap(col))),
              "heightmap(gray='seed') does not warn or differs from the default 'diffuse'")
        nm = os.path.join(tmp, "nm.tif")
        bumpgrad.heightmap(png, nm, bits="float")
        d_cli = os.path.join(tmp, "d.tif")
        subprocess.run([exe, "-q", "heightmap", nm, d_cli, "--to-derivative"], check=True)
        check(np.array_equal(bits(bumpgrad.heightmap(nm, to_derivative=True)),
                             bits(bumpgrad.read_image(d_cli))), "to_derivative differs")
        print("heightmap: same texels as the CLI (png, float tif, array, to_derivative)")
        # volume: the heights of the tool's file at its voxel centres are the
        # library's heights there (perturb_height), bit for bit; path= writes
        # the file the command writes.
        for voxel, kw in ((0.125, dict(function="fbm", amplitude=0.3, frequency=2.0)),
                          (0.1, dict(octaves=3, gradient="central")),
                          (0.125, dict(function="fbm", frequency=2.0, period=8, seed=9))):
            box = (-0.7, -0.5, 0.0, 0.6, 0.45, 0.55)
            hv, gv, lo = bumpgrad.volume(box, voxel, **kw)
            ii, jj, kk = np.meshgrid(*[np.arange(a, a + n) for a, n in zip(lo, hv.shape)],
                                     indexing="ij")
            pts = np.stack([(voxel * a).astype(np.float32) for a in (ii, jj, kk)], -1)
            hh, _ = bumpgrad.perturb_height(pts, [0.0, 0.0, 1.0], **kw)
            check(np.array_equal(bits(hv), bits(hh)), f"volume {voxel} {kw}: heights differ")
            check(gv.shape == hv.shape + (3,) and np.isfinite(gv).all(), "volume gradients")
            if voxel == 0.125:
                # Dyadic voxel centres: the file read back at them gives the same heights.
                flat = [np.ascontiguousarray(pts[..., i]).reshape(-1) for i in range(3)]
                back = np.empty(hv.size, np.float32)
                vdb0 = os.path.join(tmp, "v0.vdb")
                bumpgrad.volume(box, voxel, vdb0, **kw)
                bumpgrad._c.vdb_sample(vdb0, "height", *flat, back)
                check(np.array_equal(bits(back), bits(hv.reshape(-1))), "array != file's heights")
            vdb = os.path.join(tmp, "v.vdb")
            r = bumpgrad.volume(box, voxel, vdb, **kw)
            check(r[0] == hv.size and r[1] == lo, f"volume path= result {r}")
            cli_vdb = os.path.join(tmp, "cli.vdb")
            args = ["--bbox", ",".join(repr(v) for v in box), "--voxel-size", repr(voxel)]
            for k, v in kw.items():
                args += ["--" + k, str(v)]
            subprocess.run([exe, "-q", "volume", "-o", cli_vdb] + args, check=True)
            flat = [np.ascontiguousarray(pts[..., i]).reshape(-1) for i in range(3)]
            a, b = (np.empty(hv.size, np.float32) for _ in range(2))
            bumpgrad._c.vdb_sample(vdb, "height", *flat, a)
            bumpgrad._c.vdb_sample(cli_vdb, "height", *flat, b)
            check(np.array_equal(bits(a), bits(b)), f"volume {voxel}: path= file differs from "
                  "bumpgrad volume's (sampled at the voxel centres)")
        n_band, _, _ = bumpgrad.volume((-1, -1, -1, 1, 1, 1), 0.1, os.path.join(tmp, "b.vdb"),
                                       band_sphere=(0, 0, 0, 0.8, 0.15))
        check(0 < n_band < 21 ** 3, f"band voxels {n_band}")
        print("volume: heights bit-identical to the library's, path= files equal to the CLI's")
        # Errors: the tool's message, as bumpgrad.Error.
        missing = os.path.join(tmp, "missing.obj")
        try:
            bumpgrad.bake_normal_map(missing, 16)
            check(False, "missing mesh did not raise")
        except bumpgrad.Error as e:
            check("missing.obj" in str(e), f"message names the file: {e}")
        no_uv = os.path.join(tmp, "no_uv.obj")
        with open(no_uv, "w") as f:
            f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
        try:
            bumpgrad.bake_normal_map(no_uv, 16)
            check(False, "a mesh without UVs did not raise")
        except bumpgrad.Error as e:
            print(f"no UVs: bumpgrad.Error: {e}")
        for kw in (dict(size=0), dict(size=2.5), dict(padding=-1), dict(space="uv"),
                   dict(samples=0), dict(samples=17), dict(filter="box"), dict(units="cm")):
            args = dict(size=16)
            args.update(kw)
            try:
                bumpgrad.bake_normal_map(mesh, **args)
                check(False, f"{kw} did not raise")
            except (ValueError, TypeError) as e:
                check(next(iter(kw)) in str(e), f"{kw}: {e}")
    return finish('tools')


if __name__ == "__main__":
    sys.exit(main())
