# SPDX-License-Identifier: MIT
"""bumpgrad.render (docs/PYTHON.md): the array equals, bit for bit, the float
image `bumpgrad render` writes with the same options (TIFF and EXR), for a few
scenes, methods and height options (with period= and seed=); progress is
called; bad arguments raise errors that name them.

usage: test_render_py.py BUMPGRAD_EXE
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

import bumpgrad

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_tools import write_sphere  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import QUIET, check, finish  # noqa: E402
QUIET[0] = True  # failures only


def same(a, b):
    return a.shape == b.shape and np.array_equal(a.view(np.uint32), b.view(np.uint32))


def main():
    exe = sys.argv[1]
    if not bumpgrad.HAVE_TOOLS:
        try:
            bumpgrad.render(size=8)
            check(False, "render without tools did not raise")
        except bumpgrad.Error:
            pass
        print("render: this build has no tools; render raises")
        return finish("render")
    with tempfile.TemporaryDirectory(prefix="bumpgrad-test-render-") as tmp:
        mesh = os.path.join(tmp, "sphere.obj")
        write_sphere(mesh)
        cases = [
            ({"size": (40, 32)}, ["--size", "40x32"], "tif"),
            ({"scene": "torus", "size": 36, "method": "listing1", "function": "fbm",
              "octaves": 4, "amplitude": 0.05, "frequency": 3.0, "spp": 4},
             ["--scene", "torus", "--size", "36x36", "--method", "listing1", "--function", "fbm",
              "--octaves", "4", "--amplitude", "0.05", "--frequency", "3", "--spp", "4"], "exr"),
            ({"size": 32, "method": "surfgrad-central", "period": (4, 4, 2), "seed": 7,
              "frequency": 4.0},
             ["--size", "32x32", "--method", "surfgrad-central", "--period", "4,4,2", "--seed",
              "7", "--frequency", "4"], "tif"),
            ({"mesh": mesh, "size": 32, "amplitude": 0.03},
             ["--mesh", mesh, "--size", "32x32", "--amplitude", "0.03"], "tif"),
        ]
        for i, (kw, args, ext) in enumerate(cases):
            out = os.path.join(tmp, f"cli{i}.{ext}")
            subprocess.run([exe, "-q", "render", "-o", out] + args, check=True,
                           stdout=subprocess.DEVNULL)
            ref = bumpgrad.read_image(out)
            calls = []
            img = bumpgrad.render(**kw, threads=1 + i % 2,
                                  progress=lambda d, t: calls.append((d, t)))
            check(img.dtype == np.float32 and img.ndim == 3, f"case {i}: {img.dtype} {img.shape}")
            check(same(img, ref), f"case {i} {kw}: differs from `bumpgrad render {' '.join(args)}`"
                  f" ({img.shape} vs {ref.shape})")
            check(float(np.ptp(img)) > 0.1, f"case {i}: a flat image")
            check(len(calls) >= 2 and calls[-1][0] == calls[-1][1],
                  f"case {i}: progress {calls[-3:]}")
        # The seed changes the picture; period= and seed= match the CLI above.
        a = bumpgrad.render(size=24, seed=1)
        b = bumpgrad.render(size=24, seed=2)
        check(not same(a, b), "seed 1 and seed 2 render the same image")
    # Bad arguments: errors that name the argument or the file.
    for kw, exc, word in [({"method": "bogus"}, ValueError, "method"),
                          ({"scene": "cube"}, ValueError, "scene"),
                          ({"size": 0}, ValueError, "size"),
                          ({"spp": 3}, ValueError, "spp"),
                          ({"amplitude": float("nan")}, ValueError, "amplitude"),
                          ({"period": (4, 4, 300)}, ValueError, "period[2]"),
                          ({"mesh": "/no/such/mesh.obj", "size": 8}, bumpgrad.Error,
                           "/no/such/mesh.obj")]:
        try:
            bumpgrad.render(**kw)
            check(False, f"render({kw}) did not raise")
        except exc as e:
            check(word in str(e), f"render({kw}): message does not name {word}: {e}")
    return finish("render")


if __name__ == "__main__":
    sys.exit(main())
