# SPDX-License-Identifier: MIT
"""bumpgrad on Dask: point sets, UDIM bakes and volumes split into tasks
(docs/DISTRIBUTED.md).

Every bumpgrad result is bit-identical for any ISA and any thread count, so a
block of points, a UDIM tile or a volume brick computed on any worker equals
the same piece of a single-process run, and the pieces meet without a seam.

* noise3, fractal3, perturb, perturb_height: dask arrays in, dask arrays out
  (``map_blocks`` over the kernels; points (..., 3) with the last axis in one
  chunk). Lazy, as every dask array: ``.compute()`` on any scheduler.
* bake_udim(mesh, size, path, tiles=..., client=): one task per UDIM tile.
* volume(bbox, voxel_size, path, bricks=N, client=): one task per brick, then
  one merge task (OpenVDB's tree merge).

``client=None`` uses Dask's default scheduler (threads, or the
``distributed.Client`` made most recently); a ``distributed.Client`` (a
LocalCluster, dask-jobqueue's SLURMCluster, a Kubernetes cluster) runs the tasks
on its workers. The file tasks write through the tools' safe writer (a
temporary renamed into place), so a task that dies or is run twice never leaves
a half-written tile or brick under its final name; files must be on a file
system every worker and the caller see.

>>> import numpy, dask.array as da, bumpgrad, bumpgrad.dask
>>> p = da.from_array(numpy.array([[3.14, 42, 7]] * 4), chunks=(2, 3))
>>> print(repr(bumpgrad.dask.noise3(p).compute()[0]))
0.13691995878400012
"""
import os as _os
import tempfile as _tempfile

import dask as _dask
import dask.array as _da
import numpy as _np

import bumpgrad as _bg

__all__ = ["noise3", "fractal3", "perturb", "perturb_height", "bake_udim", "volume"]


def _points(p, name):
    """p as a dask array (..., 3) whose last axis is one chunk."""
    p = _da.asarray(p)
    if p.ndim < 1 or p.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., 3), got {p.shape}")
    if len(p.chunks[-1]) != 1:
        p = p.rechunk({p.ndim - 1: 3})
    return p


def _dtype(p, dtype):
    if dtype is not None:
        return _np.dtype(dtype)
    return _np.dtype(_np.float64) if p.dtype == _np.float64 else _np.dtype(_np.float32)


def _own(b):
    """A block as the kernels take it: C-contiguous, aligned and writeable (a
    block a worker received may be a read-only view of a network buffer)."""
    return _np.require(b, requirements="CAW")


def _value_and_gradient(p, gradient, dtype, fn):
    """map_blocks of fn(block) -> value or (value, gradient), as one (..., 1|4)
    array split afterwards (map_blocks returns one array per block)."""
    dt = _dtype(p, dtype)
    if gradient is None:
        return p.map_blocks(lambda b: fn(_own(b)), drop_axis=p.ndim - 1, dtype=dt)

    def block(b):
        v, g = fn(_own(b))
        return _np.concatenate([v[..., None], g], axis=-1)

    both = p.map_blocks(block, chunks=p.chunks[:-1] + ((4,),), dtype=dt)
    return both[..., 0], both[..., 1:]


def noise3(p, gradient=None, *, dtype=None, threads=1):
    """bumpgrad.noise3 on a dask array of points (..., 3): a lazy dask array of
    values (...), or (values, gradients (..., 3)) with gradient='analytic' or
    'central'. threads= is per task (1: Dask runs the tasks in parallel).
    Bit-identical to bumpgrad.noise3 on the whole array."""
    p = _points(p, "p")
    return _value_and_gradient(p, gradient, dtype, lambda b: _bg.noise3(
        b, gradient, dtype=dtype, threads=threads))


def fractal3(p, function="fbm", octaves=_bg.DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5,
             gradient=None, step=_bg.DEFAULT_CENTRAL_STEP, *, dtype=None, threads=1):
    """bumpgrad.fractal3 on a dask array of points (..., 3); arguments as
    bumpgrad.fractal3, results as noise3 here."""
    p = _points(p, "p")
    # Check the arguments once, here, not in every task.
    _bg.fractal3(_np.zeros((1, 3), p.dtype), function, octaves, lacunarity, gain, gradient,
                 step, dtype=dtype, threads=1)
    return _value_and_gradient(p, gradient, dtype, lambda b: _bg.fractal3(
        b, function, octaves, lacunarity, gain, gradient, step, dtype=dtype, threads=threads))


def perturb(n, g, method="surfgrad", *, dtype=None, threads=1):
    """bumpgrad.perturb on dask arrays (..., 3) of unit normals and volume
    gradients (the same chunks along the leading axes): a lazy (..., 3)."""
    n, g = _points(n, "n"), _points(g, "g")
    if n.shape != g.shape:
        raise ValueError(f"n and g must have one shape, got {n.shape} and {g.shape}")
    g = g.rechunk(n.chunks)
    dt = _dtype(n, dtype) if dtype is not None or n.dtype == g.dtype else _np.dtype(_np.float64)
    return _da.map_blocks(lambda a, b: _bg.perturb(_own(a), _own(b), method, dtype=dtype, threads=threads),
                          n, g, dtype=dt)


def perturb_height(p, n, *, threads=1, **kw):
    """bumpgrad.perturb_height (float32) on dask arrays (..., 3) of points and
    unit normals: lazy (height (...), normal (..., 3)), as bumpgrad.perturb_height
    (scalar keywords only: amplitude, frequency and footprint per point are
    not split here)."""
    p, n = _points(p, "p"), _points(n, "n")
    if p.shape != n.shape:
        raise ValueError(f"p and n must have one shape, got {p.shape} and {n.shape}")
    n = n.rechunk(p.chunks)
    _bg.perturb_height(_np.zeros((1, 3), _np.float32), _np.array([[0, 0, 1]], _np.float32),
                       threads=1, **kw)

    def block(a, b):
        h, nn = _bg.perturb_height(_own(a), _own(b), threads=threads, **kw)
        return _np.concatenate([h[..., None], nn], axis=-1)

    both = _da.map_blocks(block, p, n, chunks=p.chunks[:-1] + ((4,),), dtype=_np.float32)
    return both[..., 0], both[..., 1:]


def _run(tasks, client):
    """Compute a list of delayed tasks on client (or Dask's default scheduler)."""
    if client is None:
        return list(_dask.compute(*tasks))
    futures = client.compute(tasks)
    try:
        return client.gather(futures)
    except BaseException:
        # The first failure fails the job: stop the tasks still running, so
        # that none writes into a folder the caller is about to remove.
        client.cancel(futures)
        raise


def _bake_tile(mesh, size, path, tile, threads, kw):
    if path is None:
        return _bg.bake_normal_map(mesh, size, None, udim=True, tile=tile, threads=threads,
                                   **kw)[tile]
    _bg.bake_normal_map(mesh, size, path, tile=tile, threads=threads, **kw)
    return tile


def bake_udim(mesh, size, path=None, *, tiles, client=None, threads=1, **kw):
    """The UDIM bake of `mesh`, one task per tile: each task is
    bumpgrad.bake_normal_map(mesh, size, path, tile=t, **kw), texel for texel
    the tile of the single-process bake.

    tiles   the UDIM numbers to bake (the tiles the mesh's UVs touch: a tile
            they do not touch fails the job with the tool's message).
    path    a file name holding <UDIM> (each task writes its tile through a
            temporary renamed into place; returns the tiles written), or None
            (returns {tile: float32 array}, as bake_normal_map(udim=True)).
    client  a distributed.Client, or None for Dask's default scheduler.
    threads per task (default 1: one core per task).
    """
    if path is not None and "<UDIM>" not in _os.fsdecode(path):
        raise ValueError(f"path must hold <UDIM> (one file per tile), got {path!r}")
    tiles = [int(t) for t in tiles]
    if not tiles:
        raise ValueError("tiles must name at least one UDIM tile")
    mesh = _os.fsdecode(mesh)
    task = _dask.delayed(_bake_tile, pure=True)
    res = _run([task(mesh, size, path, t, threads, kw, dask_key_name=f"bumpgrad-tile-{t}-"
                     + _dask.base.tokenize(mesh, size, path, t, kw)) for t in tiles], client)
    return res if path is not None else dict(zip(tiles, res))


def _bake_brick(bbox, voxel_size, brick_path, i, n, threads, kw):
    _bg.volume(bbox, voxel_size, brick_path, brick=(i, n), threads=threads, **kw)
    return brick_path


def _merge(path, bricks):
    _bg.merge_volumes(path, bricks)
    for b in bricks:
        _os.unlink(b)
    return path


def volume(bbox, voxel_size, path, *, bricks, client=None, threads=1, **kw):
    """bumpgrad.volume(bbox, voxel_size, path, **kw) as `bricks` tasks, one
    brick each (bumpgrad.volume(..., brick=(i, bricks))), written next to
    `path`, then one task merging them into `path` (bumpgrad.merge_volumes)
    and removing the bricks. The file equals the single-run volume voxel for
    voxel. `path` must be on a file system the workers share. Returns path."""
    path = _os.path.abspath(_os.fsdecode(path))
    bricks = int(bricks)
    if not 1 <= bricks <= 1000000:
        raise ValueError(f"bricks must be in 1..1000000, got {bricks}")
    folder = _os.path.dirname(path)
    tag = _dask.base.tokenize(bbox, voxel_size, path, bricks, kw)
    parts = _tempfile.mkdtemp(prefix=f".{_os.path.basename(path)}.bricks-", dir=folder)
    try:
        brick = _dask.delayed(_bake_brick, pure=True)
        files = [brick(tuple(bbox), voxel_size, _os.path.join(parts, f"brick{i}.vdb"), i, bricks,
                       threads, kw, dask_key_name=f"bumpgrad-brick-{i}-{tag}")
                 for i in range(bricks)]
        merged = _dask.delayed(_merge, pure=True)(path, files,
                                                  dask_key_name=f"bumpgrad-merge-{tag}")
        return _run([merged], client)[0]
    finally:
        # Bricks (and a killed writer's temporaries) go; a failure to remove
        # them must not hide the job's own error.
        try:
            for f in _os.listdir(parts):
                _os.unlink(_os.path.join(parts, f))
            _os.rmdir(parts)
        except OSError:
            pass
