# SPDX-License-Identifier: MIT
"""Material textures named by paths of another machine (`render --mesh`):
a Windows path (C:\\Users\\me\\proj\\tex\\red.ppm), a foreign absolute path
(/home/other/tex/blue.ppm) and a relative one with backslashes
(..\\tex\\green.ppm) are found by their base name next to the mesh, in its
textures/ or tex/ subfolder (mesh_texture_find, docs/MESH.md "Material
textures"); a miss is exit 2 naming the material, the path as written and
every place tried; a texture error names its real origin (the option, or
"material N 'NAME' of MESH"), not always --albedo. assimp-testmodels'
spider.fbx, whose materials name D:\\projects\\...\\drkwood2.jpg, renders
from a copy with its images in textures/.
usage: test_texture_paths.py BUMPGRAD"""
import os
import re
import shutil
import sys
import tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish, run as harness_run, two_quads  # noqa: E402

EXE = os.path.abspath(sys.argv[1])


def run(args, cwd):
    return harness_run(EXE, ["render"] + args, env={"BUMPGRAD_NO_PROGRESS": "1"}, cwd=cwd)


def ppm(path, rgb):
    with open(path, "wb") as f:
        f.write(b"P6 8 8 255\n" + bytes(rgb) * 64)


def read_ppm(path):
    """(width, height, bytes) of the binary PPM (P6 W H 255) the render writes."""
    data = open(path, "rb").read()
    fields = data.split(maxsplit=4)
    assert fields[0] == b"P6" and fields[3] == b"255", fields[:4]
    w, h = int(fields[1]), int(fields[2])
    return w, h, data[len(data) - w * h * 3:]


def sides(mesh, tmp, what):
    """Render `mesh` flat (--method none) and return (stdout, stderr, left, right pixel)."""
    out = os.path.join(tmp, "o.ppm")
    if os.path.exists(out):
        os.remove(out)
    rc, so, se = run(["--mesh", mesh, "--method", "none", "--view", "0,0,1", "--size", "64x64",
                      "--output", out], tmp)
    if not check(rc == 0, f"{what}: exit 0 (got {rc}: {se.strip()})"):
        return so, se, None, None
    w, h, px = read_ppm(out)
    at = lambda x, y: tuple(px[(y * w + x) * 3:(y * w + x) * 3 + 3])
    return so, se, at(w // 4, h // 2), at(3 * w // 4, h // 2)


def is_colour(c, k):
    return c is not None and all(c[k] > 2 * c[j] for j in range(3) if j != k)


def t_foreign(tmp):
    d = os.path.join(tmp, "m")
    os.makedirs(os.path.join(d, "textures"))
    os.makedirs(os.path.join(d, "tex"))
    ppm(os.path.join(d, "textures", "red.ppm"), (230, 20, 20))
    ppm(os.path.join(d, "blue.ppm"), (20, 20, 230))
    mesh = two_quads(d, r"C:\Users\me\proj\tex\red.ppm", "/home/other/tex/blue.ppm")
    so, se, left, right = sides(mesh, tmp, "a Windows and a foreign absolute path")
    check(is_colour(left, 0), f"C:\\Users\\me\\proj\\tex\\red.ppm found in textures/: red {left}")
    check(is_colour(right, 2), f"/home/other/tex/blue.ppm found next to the mesh: blue {right}")
    check("[left] albedo=red.ppm" in so and "[right] albedo=blue.ppm" in so,
          f"the report names the files found ({so.strip()})")
    # The mesh folder first: a red.ppm next to the mesh wins over textures/.
    ppm(os.path.join(d, "red.ppm"), (20, 230, 20))
    so, se, left, right = sides(mesh, tmp, "the order")
    check(is_colour(left, 1), f"the mesh's folder comes before textures/: green {left}")
    # ..\tex\green.ppm: as written (outside the mesh folder, the file's own
    # relative path) when it exists, else tex/green.ppm inside.
    d2 = os.path.join(tmp, "n")
    mesh2 = two_quads(d2, r"..\tex\green.ppm", r"..\tex\green.ppm")
    os.makedirs(os.path.join(d2, "tex"))
    ppm(os.path.join(d2, "tex", "green.ppm"), (20, 230, 20))
    so, se, left, right = sides(mesh2, tmp, r"..\tex\green.ppm in n/tex/")
    check(is_colour(left, 1) and is_colour(right, 1),
          f"..\\tex\\green.ppm found in the mesh's tex/: {left} {right}")
    os.makedirs(os.path.join(tmp, "tex"))
    ppm(os.path.join(tmp, "tex", "green.ppm"), (230, 20, 20))
    so, se, left, right = sides(mesh2, tmp, r"..\tex\green.ppm as written")
    check(is_colour(left, 0) and is_colour(right, 0),
          f"..\\tex\\green.ppm as written comes first: red {left} {right}")


def t_missing(tmp):
    d = os.path.join(tmp, "m")
    os.makedirs(d)
    ppm(os.path.join(tmp, "gone.ppm"), (230, 20, 20))  # outside the mesh folder: not looked at
    ppm(os.path.join(d, "blue.ppm"), (20, 20, 230))
    mesh = two_quads(d, r"C:\Users\me\gone.ppm", "blue.ppm")
    out = os.path.join(tmp, "o.png")
    rc, so, se = run(["--mesh", mesh, "--method", "none", "--size", "16x16", "--output", out], tmp)
    check(rc == 2 and not os.path.exists(out), f"a missing texture: exit 2, no image (got {rc})")
    m = re.search(r"material (\d+) 'left' of (\S+): diffuse texture \"(.*?)\" not found; "
                  r"tried (.*)", se)
    if check(m is not None, f"the error names the material and the path: {se.strip()}"):
        check(m.group(2) == mesh, f"... of the mesh file {m.group(2)}")
        check(m.group(3) == "C:/Users/me/gone.ppm",
              f"... the path as written, backslashes as '/' (the loader's): {m.group(3)}")
        tried = m.group(4).strip().split(", ")
        want = [d + "/gone.ppm", d + "/textures/gone.ppm", d + "/tex/gone.ppm"]
        check(tried == want, f"... every place tried, in order: {tried}")
        check(all(t.startswith(d + "/") for t in tried), "... none outside the mesh's folder")
    check("--albedo" not in se, f"the error does not blame --albedo: {se.strip()}")


def t_labels(tmp):
    d = os.path.join(tmp, "m")
    os.makedirs(d)
    with open(os.path.join(d, "bad.ppm"), "wb") as f:
        f.write(b"P6 8 8 255\nshort")
    ppm(os.path.join(d, "blue.ppm"), (20, 20, 230))
    mesh = two_quads(d, "bad.ppm", "blue.ppm")
    out = os.path.join(tmp, "o.png")
    rc, so, se = run(["--mesh", mesh, "--method", "none", "--size", "16x16", "--output", out], tmp)
    check(rc == 2 and re.search(r"material \d+ 'left' of %s, diffuse texture \"%s\"" %
                                (re.escape(mesh), re.escape(os.path.join(d, "bad.ppm"))), se)
          is not None and "--albedo" not in se,
          f"an unreadable material texture is labelled by its material: {se.strip()}")
    # The height from the material's diffuse (gray of albedo) is the same texture.
    rc, so, se = run(["--mesh", mesh, "--method", "listing1-heightmap", "--no-albedo",
                      "--size", "16x16", "--output", out], tmp)
    check(rc == 2 and re.search(r"material \d+ 'left' of .*, diffuse texture", se) is not None,
          f"... also when read as the height: {se.strip()}")
    rc, so, se = run(["--mesh", mesh, "--albedo", os.path.join(d, "bad.ppm"), "--method", "none",
                      "--size", "16x16", "--output", out], tmp)
    check(rc == 2 and se.count("--albedo \"") == 1 and "material" not in se,
          f"a bad --albedo file is labelled --albedo: {se.strip()}")
    good = two_quads(os.path.join(tmp, "g"), os.path.join(d, "blue.ppm"), "../m/blue.ppm")
    rc, so, se = run(["--mesh", good, "--height-map", os.path.join(d, "bad.ppm"), "--method",
                      "listing1-heightmap", "--size", "16x16", "--output", out], tmp)
    check(rc == 2 and "--height-map \"" in se and "material" not in se,
          f"a bad --height-map is labelled so: {se.strip()}")


SPIDER_FBX = "/usr/share/assimp/models/FBX/spider.fbx"
SPIDER_JPG = ["drkwood2.jpg", "engineflare1.jpg", "SpiderTex.jpg", "wal67ar_small.jpg"]


def t_spider(tmp):
    if not os.path.exists(SPIDER_FBX):
        print("skip: assimp-testmodels' spider.fbx not installed")
        return
    d = os.path.join(tmp, "s")
    os.makedirs(os.path.join(d, "textures"))
    shutil.copyfile(SPIDER_FBX, os.path.join(d, "spider.fbx"))
    for j in SPIDER_JPG:
        shutil.copyfile(os.path.join("/usr/share/assimp/models/OBJ", j),
                        os.path.join(d, "textures", j))
    out = os.path.join(tmp, "sp.png")
    rc, so, se = run(["--mesh", os.path.join(d, "spider.fbx"), "--compare",
                      "none,listing1-heightmap", "--size", "48x48", "--output", out], tmp)
    check(rc == 0, f"spider.fbx (D:\\projects\\... textures) renders from a copy (got {rc}: "
          f"{se.strip()})")
    for j in SPIDER_JPG:
        check(j in so, f"spider.fbx: {j} found in textures/")


TESTS = {"foreign": t_foreign, "missing": t_missing, "labels": t_labels, "spider": t_spider}

if __name__ == "__main__":
    for name, t in TESTS.items():
        with tempfile.TemporaryDirectory() as tmp:
            t(os.path.realpath(tmp))
    sys.exit(finish("texture_paths"))
