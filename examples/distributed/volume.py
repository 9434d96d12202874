#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A VDB height volume on a Dask cluster: one task per brick, then the merge.

    python3 volume.py [--bricks N] [--voxel-size S] [--out FILE.vdb]
                      [--scheduler ADDRESS] [--check]

Without --scheduler it starts a LocalCluster of 2 worker processes. With
--check it bakes the same volume in this process and exits 1 unless the files
are the same bytes (but the UUID every VDB file gets): every grid, voxel and
metadata item."""
import argparse
import os
import sys
import tempfile
import time

from distributed import Client, LocalCluster

import bumpgrad
import bumpgrad.dask as bgd

BOX = (-1, -1, -1, 1, 1, 1)


def same_vdb(a, b):
    x, y = open(a, "rb").read(), open(b, "rb").read()
    # bytes 21..56: the file's UUID, new on every write
    return len(x) == len(y) and x[:21] == y[:21] and x[57:] == y[57:]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bricks", type=int, default=8)
    ap.add_argument("--voxel-size", type=float, default=0.02)
    ap.add_argument("--out", help="the merged FILE.vdb (default: in a temporary folder)")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes")
    ap.add_argument("--threads", type=int, default=1, help="threads per task")
    ap.add_argument("--check", action="store_true", help="compare with one process, bit for bit")
    a = ap.parse_args()
    kw = dict(function="fbm", octaves=6)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.abspath(a.out or os.path.join(tmp, "volume.vdb"))
        with (Client(a.scheduler) if a.scheduler else
              Client(LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                                  dashboard_address=None))) as client:
            t0 = time.perf_counter()
            bgd.volume(BOX, a.voxel_size, out, bricks=a.bricks, client=client,
                       threads=a.threads, **kw)
            dt = time.perf_counter() - t0
        print(f"{a.bricks} bricks baked and merged in {dt:.2f} s -> {out}")
        if not a.check:
            return 0
        one = os.path.join(tmp, "one.vdb")
        bumpgrad.volume(BOX, a.voxel_size, one, **kw)
        same = same_vdb(out, one)
        print("check: the merged bricks %s the single-process volume" %
              ("equal" if same else "DIFFER FROM"))
        return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
