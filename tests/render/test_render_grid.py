# SPDX-License-Identifier: MIT
"""`render --height-grid`: what the grid reached is reported. A band of
voxels around a sphere of radius 0.8 misses the unit sphere the render hits,
so every hit point gets height 0: the report says so (a `grid` line with
zero_height = points, and a warning) and the header names the grid, not the
default turbulence. A band around radius 1 bumps the sphere: most hits see a
non-zero height and there is no warning. --json carries the same counts.
usage: test_render_grid.py BUMPGRAD"""
import json
import os
import re
import sys
import tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish, run  # noqa: E402

EXE = os.path.abspath(sys.argv[1])


def bake(tmp, radius):
    path = os.path.join(tmp, "band%g.vdb" % radius)
    rc, _, err = run(EXE, ["volume", "--function", "fbm", "--octaves", "3", "--amplitude", "0.1",
                           "--frequency", "4", "--bbox", "-1.2,-1.2,-1.2,1.2,1.2,1.2",
                           "--voxel-size", "0.04", "--band-sphere", "0,0,0,%g,0.12" % radius,
                           "--output", path])
    check(rc == 0, "volume bake of a band at radius %g: exit 0 (%d %s)" % (radius, rc, err))
    return path


def grid_line(out):
    m = re.search(r"^grid points=(\d+) in_active_box=(\d+) zero_height=(\d+) active_box=(\S+)$",
                  out, re.M)
    return tuple(int(m.group(k)) for k in (1, 2, 3)) if m else None


def render(path, tmp, extra=()):
    return run(EXE, ["render", "--height-grid", path, "--size", "48x48", "--output",
                     os.path.join(tmp, "g.png")] + list(extra), env={"BUMPGRAD_NO_PROGRESS": "1"})


with tempfile.TemporaryDirectory(prefix="render-grid-") as tmp:
    miss = bake(tmp, 0.8)
    rc, out, err = render(miss, tmp)
    check(rc == 0, "a grid that misses the surface still renders: exit 0 (%d %s)" % (rc, err))
    head = out.splitlines()[0] if out else ""
    check("height-grid=" + miss in head and "function=" not in head,
          "the header names the grid, not a function: %r" % head)
    g = grid_line(out)
    check(g is not None and g[0] > 500 and g[2] == g[0],
          "the grid line counts every hit at height 0: %r" % (g,))
    check("warning" in err and "is 0 at all" in err and miss in err,
          "a warning names the grid that bumped nothing: %r" % err)

    hit = bake(tmp, 1.0)
    rc, out, err = render(hit, tmp)
    g = grid_line(out)
    check(rc == 0 and g is not None and g[0] > 500 and g[1] == g[0] and g[2] < g[0] // 10,
          "a band around the surface: every hit in the box, few at height 0: %r" % (g,))
    check("warning" not in err, "no warning when the grid bumps the surface: %r" % err)

    rc, out, err = render(miss, tmp, ["--json"])
    try:
        j = json.loads(out)
    except ValueError:
        j = {}
    check(rc == 0 and j.get("grid_points", 0) > 500 and j.get("grid_zero") == j["grid_points"]
          and len(j.get("grid_active_box", [])) == 6,
          "--json: grid_points, grid_zero, grid_active_box: %r" % {k: j.get(k) for k in (
              "grid_points", "in_grid", "grid_zero")})
    check("is 0 at all" in err, "--json still warns on stderr")

    rc, out, err = render(os.path.join(tmp, "missing.vdb"), tmp)
    check(rc == 2 and "missing.vdb" in err and out == "",
          "a missing grid: exit 2 naming it, nothing on stdout (%d %r)" % (rc, err))

sys.exit(finish("render_grid"))
