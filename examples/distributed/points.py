#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Noise, fBm and perturbed normals of a point set on a Dask cluster.

    python3 points.py [--points N] [--chunk C] [--scheduler ADDRESS] [--check]

Without --scheduler it starts a LocalCluster of 2 worker processes. With
--check it computes the same arrays in this process with bumpgrad and exits 1
on any differing bit."""
import argparse
import sys
import time

import dask.array as da
import numpy as np
from distributed import Client, LocalCluster

import bumpgrad
import bumpgrad.dask as bgd


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--chunk", type=int, default=125_000)
    ap.add_argument("--scheduler", help="address of a running Dask scheduler")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes")
    ap.add_argument("--check", action="store_true", help="compare with one process, bit for bit")
    a = ap.parse_args()
    with (Client(a.scheduler) if a.scheduler else
          Client(LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                              dashboard_address=None))) as client:
        rng = np.random.default_rng(7)
        p = rng.uniform(-100, 100, (a.points, 3))
        n = rng.normal(size=(a.points, 3))
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        dp = da.from_array(p, chunks=(a.chunk, 3))
        dn = da.from_array(n, chunks=(a.chunk, 3))
        t0 = time.perf_counter()
        noise = bgd.noise3(dp)
        value, grad = bgd.fractal3(dp, "fbm", 6, gradient="analytic")
        normal = bgd.perturb(dn, grad)
        noise, value, grad, normal = client.compute([noise, value, grad, normal], sync=True)
        dt = time.perf_counter() - t0
        print(f"{a.points} points in {len(dp.chunks[0])} blocks on "
              f"{len(client.scheduler_info()['workers'])} workers: {dt:.2f} s")
        if not a.check:
            return 0
        v1, g1 = bumpgrad.fractal3(p, "fbm", 6, gradient="analytic")
        ref = [bumpgrad.noise3(p), v1, g1, bumpgrad.perturb(n, g1)]
        bad = 0
        for name, x, y in zip(["noise3", "fractal3", "gradient", "perturb"],
                              [noise, value, grad, normal], ref):
            diff = int(np.count_nonzero(x.view(np.uint64) != y.view(np.uint64)))
            print(f"check {name}: {diff} values differ in their bits")
            bad += diff
        return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
