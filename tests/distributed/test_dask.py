# SPDX-License-Identifier: MIT
"""bumpgrad.dask on a real LocalCluster (2 worker processes): a worker killed
in the middle of a brick and the volume still identical, no half-written brick
under its final name, a task failing on bad input failing the job with the
tool's message (not a hang), and the default (non-distributed) scheduler.
Usage: test_dask.py"""
import glob
import os
import signal
import sys
import tempfile
import threading
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish  # noqa: E402

import dask  # noqa: E402
import dask.array as da  # noqa: E402
from distributed import Client, LocalCluster  # noqa: E402

import bumpgrad  # noqa: E402
import bumpgrad.dask as bgd  # noqa: E402

BOX = (-1, -1, -1, 1, 1, 1)
KW = dict(function="fbm", octaves=6)


def same_vdb(a, b):
    x, y = open(a, "rb").read(), open(b, "rb").read()
    return len(x) == len(y) and x[:21] == y[:21] and x[57:] == y[57:]


def in_thread(fn):
    """fn() in a thread: (thread, box) with box["result"] or box["error"]."""
    box = {}

    def body():
        try:
            box["result"] = fn()
        except Exception as e:  # noqa: BLE001 - handed to the checks
            box["error"] = e
    t = threading.Thread(target=body, daemon=True)
    t.start()
    return t, box


def kill_mid_brick(client, tmp):
    voxel = 0.01  # 201^3 voxels in 4 bricks: 2 M voxels, about a CPU second, per brick
    one = os.path.join(tmp, "one.vdb")
    bumpgrad.volume(BOX, voxel, one, **KW)
    out = os.path.join(tmp, "dist.vdb")
    t, box = in_thread(lambda: bgd.volume(BOX, voxel, out, bricks=4, client=client, **KW))
    victim = key = pid = None
    for _ in range(600):  # until a worker executes a brick (at most 60 s)
        state = client.run(lambda dask_worker: (os.getpid(), [
            str(ts.key) for ts in dask_worker.state.executing]))
        for w, (wpid, keys) in state.items():
            bricks = [k for k in keys if k.startswith("bumpgrad-brick-")]
            if bricks:
                victim, key, pid = w, bricks[0], wpid
                break
        if victim:
            break
        time.sleep(0.1)
    check(victim is not None, "a worker executes a brick task (%s)" % key)
    if victim is None:
        t.join(300)
        return
    time.sleep(0.1)  # into the brick's bake
    i = int(key.split("-")[2])
    folder = glob.glob(os.path.join(tmp, ".dist.vdb.bricks-*"))
    running = key in client.run(lambda dask_worker: [
        str(ts.key) for ts in dask_worker.state.executing], workers=[victim])[victim]
    os.kill(pid, signal.SIGKILL)
    check(running, "brick %d was still being baked when its worker was killed" % i)
    time.sleep(0.2)
    final = os.path.join(folder[0], "brick%d.vdb" % i) if folder else None
    check(final is not None and not os.path.exists(final),
          "the killed worker's brick %d is not under its final name" % i)
    t.join(300)
    check(not t.is_alive() and "error" not in box and box.get("result") == out,
          "the job finishes after the kill (%r)" % box.get("error"))
    story = client.run_on_scheduler(
        lambda dask_scheduler: [s[2] for s in dask_scheduler.story(key) if len(s) > 2])
    check(story.count("processing") >= 2,
          "the scheduler ran brick %d again (%d times processing)" % (i, story.count("processing")))
    check(os.path.exists(out) and same_vdb(out, one),
          "the volume after a worker was killed mid-brick = the single-process volume")
    check(sorted(os.listdir(tmp)) == ["dist.vdb", "one.vdb"],
          "no brick and no temporary left (%s)" % sorted(os.listdir(tmp)))


def bad_input(client, tmp):
    for what, fn, want in [
            ("a missing mesh", lambda: bgd.bake_udim(os.path.join(tmp, "none.obj"), 16,
                                                     tiles=[1001, 1002], client=client),
             "none.obj"),
            ("bricks of a box with no voxel centre",
             lambda: bgd.volume((0.01, 0, 0, 0.02, 1, 1), 0.5, os.path.join(tmp, "v.vdb"),
                                bricks=2, client=client),
             "no voxel centre")]:
        t, box = in_thread(fn)
        t.join(120)  # a guard against a hang, not a timing
        e = box.get("error")
        check(not t.is_alive() and isinstance(e, bumpgrad.Error) and want in str(e),
              "%s: the job fails with the tool's message (%s: %s)" % (what, type(e).__name__, e))
    check(not os.path.exists(os.path.join(tmp, "v.vdb"))
          and not glob.glob(os.path.join(tmp, ".v.vdb.bricks-*")), "nothing left of the failed job")


def arrays_back(client, tmp):
    """bake_udim without a path: the tiles come back as arrays, the bits of
    one bake_normal_map(udim=True)."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                    "examples", "distributed"))
    from udim import three_tile_mesh
    mesh = os.path.join(tmp, "tiles.obj")
    tiles = three_tile_mesh(mesh)
    got = bgd.bake_udim(mesh, 48, tiles=tiles, client=client, function="fbm", frequency=5.0)
    ref = bumpgrad.bake_normal_map(mesh, 48, udim=True, function="fbm", frequency=5.0)
    check(sorted(got) == sorted(ref) == tiles
          and all(got[t].tobytes() == ref[t].tobytes() for t in tiles),
          "bake_udim(path=None): the arrays of bake_normal_map(udim=True), bit for bit")


def default_scheduler():
    p = np.random.default_rng(3).uniform(-20, 20, (5001, 3)).astype(np.float32)
    dp = da.from_array(p, chunks=(700, 3))
    for sched in ("threads", "synchronous"):
        with dask.config.set(scheduler=sched):
            v, g = bgd.fractal3(dp, "turbulence", 5, gradient="central")
            v, g = dask.compute(v, g)
        V, G = bumpgrad.fractal3(p, "turbulence", 5, gradient="central")
        check(v.tobytes() == V.tobytes() and g.tobytes() == G.tobytes(),
              "fractal3 on dask's %s scheduler: the same bits as one call" % sched)


def main():
    default_scheduler()
    with tempfile.TemporaryDirectory() as tmp, \
            LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                         dashboard_address=None) as cluster, Client(cluster) as client:
        d1, d2 = os.path.join(tmp, "kill"), os.path.join(tmp, "bad")
        os.mkdir(d1)
        os.mkdir(d2)
        kill_mid_brick(client, d1)
        arrays_back(client, d2)
        bad_input(client, d2)
    return finish("distributed_dask")


if __name__ == "__main__":  # the workers (spawned processes) import this file too
    sys.exit(main())
