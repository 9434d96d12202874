#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Parallel efficiency of bumpgrad.dask on this machine: a 3-tile UDIM bake and
an 8-brick volume on a LocalCluster of 1 and of 2 worker processes (one thread
each), interleaved, medians of --runs; and the scheduling overhead per task
(no-op tasks). Prints the load average before and after: on a shared machine
the figures are only as good as it was quiet.

    python3 bench.py [--size 1024] [--voxel-size 0.01] [--runs 3]"""
import argparse
import os
import statistics
import sys
import tempfile
import time

from distributed import Client, LocalCluster

import bumpgrad.dask as bgd

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from udim import three_tile_mesh  # noqa: E402

BOX = (-1, -1, -1, 1, 1, 1)


def noop(x):
    return x


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--voxel-size", type=float, default=0.01)
    ap.add_argument("--runs", type=int, default=3)
    a = ap.parse_args()
    print("load average before: %.2f %.2f %.2f" % os.getloadavg())
    times = {(job, w): [] for job in ("udim", "volume", "noop") for w in (1, 2)}
    with tempfile.TemporaryDirectory() as tmp:
        mesh = os.path.join(tmp, "tiles.obj")
        tiles = three_tile_mesh(mesh)
        clusters = {w: LocalCluster(n_workers=w, threads_per_worker=1, processes=True,
                                    dashboard_address=None) for w in (1, 2)}
        clients = {w: Client(c) for w, c in clusters.items()}
        try:
            for r in range(a.runs):
                for w in (1, 2):
                    c = clients[w]
                    t0 = time.perf_counter()
                    bgd.bake_udim(mesh, a.size, os.path.join(tmp, f"n{r}{w}.<UDIM>.exr"),
                                  tiles=tiles, client=c, function="fbm", octaves=6,
                                  frequency=8.0, amplitude=0.05, depth="float")
                    times["udim", w].append(time.perf_counter() - t0)
                    t0 = time.perf_counter()
                    bgd.volume(BOX, a.voxel_size, os.path.join(tmp, f"v{r}{w}.vdb"), bricks=8,
                               client=c, function="fbm", octaves=6)
                    times["volume", w].append(time.perf_counter() - t0)
                    t0 = time.perf_counter()
                    c.gather(c.map(noop, range(r * 1000, (r + 1) * 1000), pure=False))
                    times["noop", w].append((time.perf_counter() - t0) / 1000)
        finally:
            for c in clients.values():
                c.close()
            for c in clusters.values():
                c.close()
    print("load average after: %.2f %.2f %.2f" % os.getloadavg())
    for job, what in (("udim", f"3 tiles of {a.size}^2"),
                      ("volume", f"8 bricks, voxel {a.voxel_size} over [-1,1]^3")):
        t1, t2 = statistics.median(times[job, 1]), statistics.median(times[job, 2])
        print(f"{what}: 1 worker {t1:.2f} s, 2 workers {t2:.2f} s, "
              f"efficiency {t1 / (2 * t2):.0%} (runs: {[round(t, 2) for t in times[job, 1]]} / "
              f"{[round(t, 2) for t in times[job, 2]]})")
    for w in (1, 2):
        print(f"scheduling overhead, no-op tasks, {w} worker(s): "
              f"{statistics.median(times['noop', w]) * 1e3:.2f} ms per task")


if __name__ == "__main__":
    main()
