#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A UDIM normal-map bake on a Dask cluster, one task per tile.

    python3 udim.py [--mesh M.obj --tiles 1001,1002,...] [--size N] [--out DIR]
                    [--scheduler ADDRESS] [--check]

Without --mesh it writes a small three-tile mesh (tiles 1001, 1002, 1011).
Without --scheduler it starts a LocalCluster of 2 worker processes. With
--check it bakes the same tiles in this process in one bake and exits 1 on any
differing bit."""
import argparse
import os
import sys
import tempfile
import time

import numpy as np
from distributed import Client, LocalCluster

import bumpgrad
import bumpgrad.dask as bgd


def three_tile_mesh(path):
    """One bent quad per UDIM tile (u_tile, v_tile), its UVs covering the tile."""
    v, vt, f = [], [], []
    for k, (a, b) in enumerate([(0, 0), (1, 0), (0, 1)]):
        for j in range(5):
            for i in range(5):
                s, t = i / 4, j / 4
                v.append((s + 1.5 * k, t, 0.3 * s * s - 0.1 * k * t))
                vt.append((a + s, b + t))
        base = 25 * k + 1
        for j in range(4):
            for i in range(4):
                q = base + 5 * j + i
                f += [(q, q + 1, q + 6), (q, q + 6, q + 5)]
    with open(path, "w") as fh:
        fh.writelines("v %r %r %r\n" % p for p in v)
        fh.writelines("vt %r %r\n" % p for p in vt)
        fh.writelines("f %d/%d %d/%d %d/%d\n" % (a, a, b, b, c, c) for a, b, c in f)
    return [1001, 1002, 1011]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh")
    ap.add_argument("--tiles", help="UDIM tiles, comma-separated (with --mesh)")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--out", help="folder for n.<UDIM>.exr (default: a temporary one)")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes")
    ap.add_argument("--threads", type=int, default=1, help="threads per task")
    ap.add_argument("--check", action="store_true", help="compare with one process, bit for bit")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.abspath(a.out or tmp)
        mesh = a.mesh
        if mesh:
            tiles = [int(t) for t in a.tiles.split(",")]
        else:
            mesh = os.path.join(out, "tiles.obj")
            tiles = three_tile_mesh(mesh)
        kw = dict(function="fbm", octaves=6, frequency=8.0, amplitude=0.05, depth="float")
        with (Client(a.scheduler) if a.scheduler else
              Client(LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                                  dashboard_address=None))) as client:
            t0 = time.perf_counter()
            done = bgd.bake_udim(mesh, a.size, os.path.join(out, "n.<UDIM>.exr"), tiles=tiles,
                                 client=client, threads=a.threads, **kw)
            dt = time.perf_counter() - t0
        print(f"tiles {done} of {a.size}x{a.size} in {dt:.2f} s -> {out}/n.<UDIM>.exr")
        if not a.check:
            return 0
        one = bumpgrad.bake_normal_map(mesh, a.size, udim=True, **{k: v for k, v in kw.items()
                                                                   if k != "depth"})
        bad = 0
        for t in tiles:
            mine = bumpgrad.read_image(os.path.join(out, f"n.{t}.exr"))
            diff = int(np.count_nonzero(mine.view(np.uint32) != one[t].view(np.uint32)))
            print(f"check tile {t}: {diff} texel values differ in their bits")
            bad += diff
        if sorted(one) != sorted(tiles):
            print(f"check: the single bake has tiles {sorted(one)}, the tasks {sorted(tiles)}")
            bad += 1
        return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
