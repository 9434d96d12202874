# SPDX-License-Identifier: MIT
"""Tests of `bumpgrad render` (the paper's scenes, Mikkelsen 2010 Figures 1-3).

Usage: test_render.py BUMPGRAD_EXE {presets|inward|density|none|determinism|badargs|closeup}

Checks are properties, not numbers saved from an earlier run: image sizes follow
from --size and the documented panel layout and are read back with OpenImageIO's
`iinfo`; surfgrad (eq. 4) can never point inward while Perlin's additive method
does on Figure 2's scene; Listing 1's error against surfgrad must fall as the
pixel density rises (section 6); the same sample grid reached two ways (a larger
image, or supersampling) must give the same statistics; `none` must equal the
shading of an unbumped surface; bad arguments fail with exit 2 (usage) or 1
(I/O) and leave an existing output alone.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from harness import check, finish, run as harness_run, two_quads  # noqa: E402

EXE = os.path.abspath(sys.argv[1])


def run(args, cwd):
    return harness_run(EXE, ["render"] + args, cwd=cwd)


def stats(out, kind="stats"):
    """{method: {key: float}} from the `stats method=M key=value ...` lines."""
    res = {}
    for line in out.splitlines():
        if not line.startswith(kind + " "):
            continue
        kv = dict(f.split("=", 1) for f in line.split()[1:])
        key = kv.pop("method")
        if kind == "sweep":
            key = (key, float(kv["density"]))
        res[key] = {k: (float(v) if re.fullmatch(r"[-+0-9.eE]+", v) else v) for k, v in kv.items()}
    return res


def iinfo_size(path):
    p = subprocess.run(["iinfo", path], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    m = re.search(r":\s*(\d+)\s*x\s*(\d+)", p.stdout)
    return (int(m.group(1)), int(m.group(2))) if p.returncode == 0 and m else None


def panel_size(w, h, columns, rows):
    """The layout of render_image.c's compose_panel without the parameter stamp:
    4-px padding, a label strip of font height + 6 above every image (font 8 px
    below 128 px wide), a colour bar of 8 px, 4 px of ticks, a row of tick
    values and a caption row at the bottom."""
    font = 16 if w >= 256 else 10 if w >= 128 else 8
    lab, pad = font + 6, 4
    return columns * (w + pad) + pad, rows * (lab + h + pad) + pad + 12 + 2 * lab + 2


def panel_ok(size, w, h, columns, rows):
    """The panel's size: panel_size plus 1 to 4 stamp lines (font 8 or 12, + 4 px)."""
    if size is None:
        return False
    pw, ph = panel_size(w, h, columns, rows)
    line = (12 if w >= 256 else 8) + 4
    extra = size[1] - ph
    return size[0] == pw and extra % line == 0 and 1 <= extra // line <= 4


def t_presets(tmp):
    for preset, rows in (("fig1", 2), ("fig2", 2), ("fig3", 3)):
        out = os.path.join(tmp, preset + ".png")
        rc, so, se = run(["--preset", preset, "--size", "64x64", "--output", out], tmp)
        check(rc == 0, f"{preset}: exit 0 (got {rc}: {se.strip()})")
        check(panel_ok(iinfo_size(out), 64, 64, 2, rows),
              f"{preset}: iinfo reads a {panel_size(64, 64, 2, rows)} PNG + stamp lines (got {iinfo_size(out)})")
    # A single method writes exactly --size; EXR is float.
    out = os.path.join(tmp, "one.exr")
    rc, so, se = run(["--method", "surfgrad", "--size", "48x32", "--output", out], tmp)
    check(rc == 0 and iinfo_size(out) == (48, 32), f"single EXR is 48x32 (got {iinfo_size(out)})")
    info = subprocess.run(["iinfo", out], stdout=subprocess.PIPE, text=True).stdout
    check("float" in info, "EXR output stores float pixels")
    out = os.path.join(tmp, "blob.png")
    rc, so, se = run(["--scene", "torus", "--grid", "20", "--method", "listing1", "--size", "40x30",
                      "--output", out], tmp)
    check(rc == 0 and iinfo_size(out) == (40, 30), "isosurface (torus) render is 40x30")


def t_inward(tmp):
    out = os.path.join(tmp, "fig2.png")
    rc, so, se = run(["--preset", "fig2", "--size", "64x64", "--output", out], tmp)
    s = stats(so)
    check(rc == 0 and "additive" in s and "surfgrad" in s, "fig2 prints stats for both methods")
    # Eq. 4 keeps n' on the outer side: dot(n', n) = 1 / |n - grad_S h| > 0.
    check(s["surfgrad"]["inward"] == 0.0, "surfgrad never points inward on fig2")
    # Section 5: additive overstates gradients below the tangent plane "up to
    # pointing inward"; on this scene a visible part of the sphere does
    # (about 2.6% of the samples at every size we measured; 1% is the bar).
    check(s["additive"]["inward"] > 0.01, f"additive points inward on > 1% (got {s['additive']['inward']})")
    check(s["additive"]["mean_deg"] > 5.0, "additive departs from surfgrad by > 5 degrees on average")
    # surfgrad is never inward on any scene/method mix either.
    rc, so, se = run(["--scene", "blob", "--grid", "16", "--function", "noise", "--amplitude", "0.6",
                      "--compare", "surfgrad,surfgrad-central,additive", "--size", "48x48",
                      "--output", os.path.join(tmp, "b.png")], tmp)
    s = stats(so)
    check(rc == 0 and s["surfgrad"]["inward"] == 0 and s["surfgrad-central"]["inward"] == 0,
          "surfgrad and surfgrad-central never inward on a steep blob")
    check(s["surfgrad-central"]["mean_deg"] < 0.5, "central differences stay close to analytic")


def t_density(tmp):
    # Smooth noise: Listing 1's forward differences are first order, so every
    # doubling of the density should roughly halve the mean error.
    rc, so, se = run(["--function", "noise", "--frequency", "3", "--amplitude", "0.1",
                      "--compare", "listing1,listing1-coarse,flat", "--size", "64x64", "--sweep",
                      "--output", os.path.join(tmp, "d.png")], tmp)
    s = stats(so, "sweep")
    check(rc == 0, "sweep runs")
    for m in ("listing1", "listing1-coarse", "flat"):
        e = [s[(m, d)]["mean_deg"] for d in (0.5, 1.0, 2.0, 4.0)]
        check(all(a > b for a, b in zip(e, e[1:])), f"{m}: error falls with density {e}")
        check(e[3] < 0.5 * e[1], f"{m}: 4x density at least halves the error {e[1]} -> {e[3]}")
    # The same sample grid two ways: a 2x larger image equals 2x2 supersampling.
    rc, so, se = run(["--function", "noise", "--frequency", "3", "--amplitude", "0.1",
                      "--method", "listing1", "--size", "32x32", "--spp", "4", "--output",
                      os.path.join(tmp, "e.png")], tmp)
    keys = ("mean_deg", "p99_deg", "max_deg", "inward", "hits")
    a = [s[("listing1", 1.0)][k] for k in keys]
    b = [stats(so)["listing1"][k] for k in keys]
    check(rc == 0 and a == b, f"64x64 spp 1 and 32x32 spp 4 give the same Listing 1 statistics {a} {b}")
    # Figure 3's scene (6-octave turbulence): listing1 departs at low density.
    rc, so, se = run(["--preset", "fig3", "--size", "96x96", "--output", os.path.join(tmp, "f3.png")], tmp)
    s = stats(so, "sweep")
    lo, hi = s[("listing1", 0.25)]["mean_deg"], s[("listing1", 4.0)]["mean_deg"]
    check(rc == 0 and hi < lo, f"fig3: listing1 error at 4x density below 1/4x ({hi} < {lo})")


def t_none(tmp):
    # `none` shades the interpolated normal; surfgrad with a zero amplitude
    # perturbs by nothing, so both images must agree (to float rounding of the
    # renormalization) and the angle between them must vanish.
    a, b = os.path.join(tmp, "none.exr"), os.path.join(tmp, "flat.exr")
    rc1, so, _ = run(["--method", "none", "--size", "48x48", "--output", a], tmp)
    rc2, _, _ = run(["--method", "surfgrad", "--amplitude", "0", "--size", "48x48", "--output", b], tmp)
    check(rc1 == 0 and rc2 == 0, "none and zero-amplitude renders run")
    d = subprocess.run(["idiff", "-fail", "1e-5", "-failpercent", "0", a, b], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, text=True)
    check(d.returncode == 0, f"none == unbumped shading (idiff: {d.stdout.strip().splitlines()[-1:]})")
    s = stats(so)
    check(s["none"]["mean_deg"] > 1.0, "none differs from the bumped surfgrad (default amplitude)")
    rc, so, _ = run(["--compare", "none,surfgrad", "--amplitude", "0", "--size", "32x32", "--output",
                     os.path.join(tmp, "z.png")], tmp)
    check(stats(so)["none"]["max_deg"] < 0.01, "zero amplitude: none and surfgrad agree")


def t_determinism(tmp):
    outs = []
    for th in ("1", "2"):
        o = os.path.join(tmp, f"d{th}.exr")
        rc, so, _ = run(["--preset", "fig1", "--size", "40x40", "--spp", "4", "--threads", th,
                         "--output", o], tmp)
        check(rc == 0, f"--threads {th} runs")
        outs.append([l for l in so.splitlines() if l.startswith("stats")])
    check(outs[0] == outs[1], "1 and 2 threads print identical statistics")
    # The files differ only in their DateTime metadata: compare the pixels exactly.
    d = subprocess.run(["idiff", "-fail", "0", "-failpercent", "0", os.path.join(tmp, "d1.exr"),
                        os.path.join(tmp, "d2.exr")], stdout=subprocess.PIPE, text=True)
    check(d.returncode == 0, "1 and 2 threads give identical pixels")


def t_closeup(tmp):
    # --closeup 1 magnifies a crop as large as the image: it must be the image
    # itself (the crop once started left of the buffer and read outside it).
    p, m = os.path.join(tmp, "p.exr"), os.path.join(tmp, "m.exr")
    rc1, _, e1 = run(["--compare", "surfgrad,listing1", "--closeup", "1", "--size", "64x64",
                      "--output", p], tmp)
    rc2, _, e2 = run(["--method", "surfgrad", "--size", "64x64", "--output", m], tmp)
    check(rc1 == 0 and rc2 == 0, f"--closeup 1 panel renders ({e1.strip()} {e2.strip()})")
    # Layout at W = 64: label font 8, pad 4, label row 14, cell 64 + 4: the
    # close-up of column (a) starts at x = 4, y = 4 + (14 + 64 + 4) + 14.
    c = os.path.join(tmp, "c.exr")
    subprocess.run([os.environ.get("OIIOTOOL", "oiiotool"), p, "--cut", "64x64+4+100", "-o", c],
                   check=True)
    d = subprocess.run(["idiff", "-fail", "0", "-failpercent", "0", c, m], stdout=subprocess.PIPE,
                       text=True)
    check(d.returncode == 0, "the x1 close-up equals the render itself")


def t_json(tmp):
    # --json: one object that a JSON parser accepts, with the same statistics
    # as the text lines; --fail-above: exit 3 past the threshold, idiff-style;
    # any format OpenImageIO writes, with a sensible bit depth.
    import json
    args = ["--compare", "surfgrad,listing1", "--size", "48x48"]
    rc, so, _ = run(args + ["--output", os.path.join(tmp, "a.png")], tmp)
    rc2, sj, _ = run(args + ["--json", "--output", os.path.join(tmp, "b.png")], tmp)
    check(rc == 0 and rc2 == 0, "render with and without --json")
    try:
        doc = json.loads(sj)
    except ValueError as e:
        doc = {}
        check(False, f"--json output parses ({e}: {sj[:200]!r})")
    text = stats(so)
    check(abs(doc.get("methods", {}).get("listing1", {}).get("mean_deg", -1) -
              text["listing1"]["mean_deg"]) < 1e-4, "JSON and text statistics agree")
    check(doc.get("parameters", {}).get("height", {}) != {}, "JSON carries the parameters")
    mean = text["listing1"]["mean_deg"]
    rc, _, se = run(args + [f"--fail-above={mean / 2}", "--output", os.path.join(tmp, "c.png")], tmp)
    check(rc == 3 and "FAIL" in se, f"--fail-above below the mean error: exit 3 (got {rc})")
    rc, _, _ = run(args + ["--fail-above", str(mean * 2), "--output", os.path.join(tmp, "d.png")], tmp)
    check(rc == 0, "--fail-above over the mean error: exit 0")
    for ext, want in (("tif", "float"), ("jpg", "uint8"), ("hdr", "float"), ("ppm", "uint8")):
        out = os.path.join(tmp, "x." + ext)
        rc, _, se = run(["--size", "24x24", "--output", out], tmp)
        info = subprocess.run(["iinfo", out], capture_output=True, text=True).stdout
        check(rc == 0 and want in info, f".{ext} output written as {want} ({se.strip()} {info.strip()})")


def t_badargs(tmp):
    old = os.path.join(tmp, "old.png")
    with open(old, "wb") as f:
        f.write(b"previous contents")
    cases = [
        (["--method", "bogus"], 2, "unknown method"),
        (["--compare", "surfgrad,nope"], 2, "unknown method"),
        (["--size", "64x"], 2, "--size"),
        (["--size", "0x10"], 2, "--size"),
        (["--spp", "3"], 2, "--spp"),
        (["--scene", "cube"], 2, "--scene"),
        (["--preset", "fig9"], 2, "--preset"),
        (["--frequency", "-1"], 2, "--frequency"),
        (["--bogus-option", "1"], 2, "unknown option"),
    ]
    for args, code, msg in cases:
        small = [] if "--size" in args else ["--size", "16x16"]
        rc, so, se = run(args + small + ["--output", old], tmp)
        check(rc == code and msg in se, f"{args}: exit {code} naming '{msg}' (got {rc}: {se.strip()})")
        check(open(old, "rb").read() == b"previous contents", f"{args}: old output untouched")
    rc, so, se = run(["--size", "16x16", "--output", os.path.join(tmp, "x.gif")], tmp)
    check(rc == 2 and ".png or .exr" in se, f"unsupported extension: exit 2 (got {rc})")
    rc, so, se = run(["--size", "16x16"], tmp)
    check(rc == 2 and "--output" in se, "missing --output: exit 2")
    # Unwritable: the parent is a regular file (works even for root).
    rc, so, se = run(["--size", "16x16", "--output", os.path.join(old, "x.png")], tmp)
    check(rc == 1 and "cannot write" in se, f"unwritable folder: exit 1 (got {rc}: {se.strip()})")
    # The target is a directory: the write itself fails, nothing is replaced.
    d = os.path.join(tmp, "dir.png")
    os.mkdir(d)
    rc, so, se = run(["--size", "16x16", "--output", d], tmp)
    check(rc == 1 and os.path.isdir(d), f"output path is a folder: exit 1, folder kept (got {rc})")
    left = [f for f in os.listdir(tmp) if ".tmp" in f]
    check(not left, f"no temporary files left behind ({left})")


SPIDER = "/usr/share/assimp/models/OBJ/spider.obj"


def write_plane(tmp, uvs=True):
    """A 2x2 plane in z = 0 as an OBJ, with or without texture coordinates, and
    a smooth 64x64 height texture (a product of sines) as a PGM."""
    import math
    W = 64
    with open(os.path.join(tmp, "h.pgm"), "wb") as f:
        f.write(b"P5 %d %d 255\n" % (W, W))
        f.write(bytes(int(127.5 + 127 * math.sin(2 * math.pi * 2 * (i + .5) / W) *
                          math.cos(2 * math.pi * (j + .5) / W)) for j in range(W) for i in range(W)))
    name = "plane.obj" if uvs else "plane_nouv.obj"
    with open(os.path.join(tmp, name), "w") as f:
        f.write("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\n")
        if uvs:
            f.write("vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n")
        else:
            f.write("f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n")
    return os.path.join(tmp, name), os.path.join(tmp, "h.pgm")


def t_mesh(tmp):
    """The issue's command: assimp-testmodels' spider with its texture gives a
    labelled 2-column panel, and the texture methods are close to eq. 3 where
    the texture is smooth and magnified (a plane with a sine height)."""
    if not os.path.exists(SPIDER):
        print("SKIP: assimp-testmodels not installed")
        sys.exit(77)
    out = os.path.join(tmp, "cmp.png")
    rc, so, se = run(["--mesh", SPIDER, "--compare", "normalmap,listing1-heightmap", "--size",
                      "96x96", "--output", out], tmp)
    check(rc == 0, f"spider: exit 0 (got {rc}: {se.strip()})")
    check(panel_ok(iinfo_size(out), 96, 96, 2, 2), f"spider: a 2-column panel ({iinfo_size(out)})")
    st = stats(so)
    check(set(st) == {"normalmap", "listing1-heightmap"}, f"spider: stats of both methods ({so})")
    check(all(v["hits"] > 500 for v in st.values()), "spider: the mesh fills the automatic framing")
    check("wal67ar_small.jpg" in so, "spider: the texture named by its material is used")
    plane, hgt = write_plane(tmp)
    rc, so, se = run(["--mesh", plane, "--height-map", hgt, "--view", "0.3,0.2,1",
                      "--tex-amplitude", "0.02", "--size", "128x128", "--compare",
                      "none,normalmap,listing1-heightmap,listing1-heightmap-central,detail,"
                      "surfgrad-heightmap", "--amplitude", "0.0005", "--output", out], tmp)
    check(rc == 0, f"plane: exit 0 (got {rc}: {se.strip()})")
    st = stats(so)
    if check(len(st) == 6, "plane: six stats lines"):
        check(st["none"]["mean_deg"] > 1.0, f"plane: the height visibly bumps ({st['none']})")
        check(st["surfgrad-heightmap"]["max_deg"] == 0, "plane: the reference is surfgrad-heightmap")
        # A smooth texture magnified ~2x: forward taps are first order, central second
        # order, the baked normal map is exact up to the bake's differences.
        for m, bound in (("listing1-heightmap", 0.5), ("listing1-heightmap-central", 0.2),
                         ("normalmap", 0.2)):
            check(st[m]["mean_deg"] < bound,
                  f"plane: {m} within {bound} deg of eq. 3 ({st[m]['mean_deg']})")
        check(st["listing1-heightmap-central"]["mean_deg"] < st["listing1-heightmap"]["mean_deg"],
              "plane: central taps beat forward taps")
        check(st["detail"]["mean_deg"] > st["listing1-heightmap"]["mean_deg"],
              "plane: the detail turbulence adds to the texture's bumps")


def t_mesherrors(tmp):
    """Absent or corrupt meshes and textures, and a mesh without UVs for a UV
    method, fail with exit 2 and a message naming the file; no output appears."""
    plane, hgt = write_plane(tmp)
    nouv, _ = write_plane(tmp, uvs=False)
    bad = os.path.join(tmp, "bad.png")
    with open(bad, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n this is not a png")
    badmesh = os.path.join(tmp, "bad.obj")
    with open(badmesh, "w") as f:
        f.write("this is not an obj file\n")
    missing = os.path.join(tmp, "missing.obj")
    out = os.path.join(tmp, "o.png")
    cases = [
        (["--mesh", missing], missing),
        (["--mesh", badmesh], badmesh),
        (["--mesh", plane, "--height-map", bad, "--method", "listing1-heightmap"], bad),
        (["--mesh", plane, "--height-map", os.path.join(tmp, "nope.png"), "--method",
          "surfgrad-heightmap"], "nope.png"),
        (["--mesh", plane, "--height-map", hgt, "--normal-map", bad, "--method", "normalmap"], bad),
        (["--mesh", nouv, "--height-map", hgt, "--method", "normalmap"], nouv),
        (["--mesh", nouv, "--height-map", hgt, "--method", "listing1-heightmap"], nouv),
        (["--mesh", plane, "--method", "listing1-heightmap"], plane),  # no texture at all
        (["--method", "normalmap"], "--mesh"),
    ]
    for args, name in cases:
        rc, so, se = run(args + ["--size", "16x16", "--output", out], tmp)
        check(rc == 2 and name in se and not os.path.exists(out),
              f"{' '.join(os.path.basename(a) for a in args)}: exit 2 naming {os.path.basename(name)} "
              f"(got {rc}: {se.strip()})")
    # The procedural methods need no UVs.
    rc, so, se = run(["--mesh", nouv, "--compare", "none,surfgrad,listing1", "--size", "32x32",
                      "--output", out], tmp)
    check(rc == 0, f"a mesh without UVs renders the procedural methods (got {rc}: {se.strip()})")


def t_tracers(tmp):
    """Embree and the renderer's own BVH agree on the paper's isosurface scenes:
    the same samples hit, and every statistic within 0.01 degree (the two
    intersectors round barycentrics differently, which Listing 1's quad
    differences amplify on a few samples)."""
    if "without Embree" in run(["--scene", "blob", "--tracer", "embree", "--size", "8x8",
                                "--output", os.path.join(tmp, "x.png")], tmp)[2]:
        print("SKIP: built without Embree")
        sys.exit(77)
    scenes = [["--preset", "fig1", "--size", "128x128"],
                  ["--scene", "torus", "--compare", "none,surfgrad,listing1,flat,additive",
                   "--size", "128x128"]]
    if os.path.exists(SPIDER):  # a user's mesh, textured methods included
        scenes.append(["--mesh", SPIDER, "--compare", "none,normalmap,listing1-heightmap,detail",
                       "--size", "96x96"])
    for scene in scenes:
        res = {}
        for tr in ("bvh", "embree"):
            rc, so, se = run(scene + ["--tracer", tr, "--output", os.path.join(tmp, tr + ".png")], tmp)
            check(rc == 0 and f"tracer={tr}" in so, f"{scene[1]} {tr}: exit 0 (got {rc}: {se.strip()})")
            res[tr] = stats(so)
        a, b = res["bvh"], res["embree"]
        check(a.keys() == b.keys() and len(a) >= 2, f"{scene[1]}: same methods")
        for m in a:
            check(a[m]["hits"] == b[m]["hits"], f"{scene[1]} {m}: same hits ({a[m]['hits']} {b[m]['hits']})")
            for k in ("mean_deg", "p99_deg"):
                check(abs(a[m][k] - b[m][k]) <= 0.01,
                      f"{scene[1]} {m} {k}: bvh {a[m][k]} vs embree {b[m][k]} within 0.01")


def t_fig4(tmp):
    if not os.path.exists(SPIDER):
        print("SKIP: assimp-testmodels not installed")
        sys.exit(77)
    out = os.path.join(tmp, "fig4.png")
    rc, so, se = run(["--preset", "fig4", "--size", "96x96", "--output", out], tmp)
    check(rc == 0, f"fig4: exit 0 (got {rc}: {se.strip()})")
    panels = [l for l in so.splitlines() if l.startswith("stats panel=")]
    check(len(panels) == 6, f"fig4: six panels ({len(panels)})")
    st = {l.split()[1]: dict(f.split("=", 1) for f in l.split()[2:]) for l in panels}
    if len(st) == 6:
        check(float(st["panel=c"]["mean_deg"]) > 0.5, "fig4: the height texture bumps the model")
        check(st["panel=a"]["mean_deg"] == st["panel=d"]["mean_deg"],
              "fig4: (d) is (a) with albedo: the same normals")
        check(int(st["panel=e"]["hits"]) > int(st["panel=a"]["hits"]),
              "fig4: the close-up (e) is filled by the model")
        check(float(st["panel=f"]["mean_deg"]) > float(st["panel=e"]["mean_deg"]),
              "fig4: the detail turbulence (f) adds to (e)")
    size = iinfo_size(out)
    check(size is not None and size[0] == 3 * (96 + 4) + 4, f"fig4: three columns ({size})")


def t_bakedmap(tmp):
    """A tangent-space normal map baked by `bumpgrad mesh --bake-normal-map` from
    a solid height renders (`--method normalmap`, mikkTSpace frames) as the same
    height rendered procedurally (surfgrad, eq. 2 and 4, the reference of a
    job with a normal map and no height texture). The mesh's jittered UVs make
    per-triangle dP/du turn between neighbours, so frames averaged any other
    way than mikkTSpace's decode the map away from the bake: the renderer's
    former per-vertex UV tangents (area-weighted dP/ds, normalized after
    interpolation) give mean 0.099, p99 0.32 deg here; mikkTSpace 0.009, 0.056."""
    mesh = os.path.join(tmp, "wavy.obj")
    here = os.path.dirname(os.path.abspath(__file__))
    subprocess.run([sys.executable, os.path.join(here, "make_wavy_obj.py"), mesh], check=True)
    height = ["--function", "noise", "--frequency", "4", "--amplitude", "0.08"]
    nm = os.path.join(tmp, "nm.exr")
    p = subprocess.run([EXE, "mesh", mesh, "--bake-normal-map", nm, "--size", "512",
                        "--bake-depth", "float", "--quiet"] + height,
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=120)
    if not check(p.returncode == 0, f"bake: exit 0 (got {p.returncode}: {p.stderr.strip()})"):
        return
    out = os.path.join(tmp, "nm.png")
    rc, so, se = run(["--mesh", mesh, "--normal-map", nm, "--compare", "normalmap,none",
                      "--view", "0.2,0.3,1", "--size", "128x128", "--output", out] + height, tmp)
    check(rc == 0, f"render: exit 0 (got {rc}: {se.strip()})")
    st = stats(so)
    if not check(set(st) == {"normalmap", "none"}, f"stats of both methods ({so})"):
        return
    check(st["none"]["mean_deg"] > 3.0, f"the height visibly bumps the mesh ({st['none']})")
    # Float map, 512 texels over the patch: what remains is the bilinear filter
    # of the map between texel centres. The bounds sit 3x above what mikkTSpace
    # frames give and 3x below what the former UV tangents gave.
    check(st["normalmap"]["mean_deg"] < 0.03 and st["normalmap"]["p99_deg"] < 0.15,
          f"the baked map renders as baked: mean < 0.03, p99 < 0.15 deg ({st['normalmap']})")


def read_ppm(path):
    """(width, height, bytes) of a binary PPM (P6, maxval 255)."""
    with open(path, "rb") as f:
        data = f.read()
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos)
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    assert fields[0] == b"P6" and fields[3] == b"255"
    return int(fields[1]), int(fields[2]), data[pos + 1:]


def t_materials(tmp):
    """Each triangle takes its own material's textures: an OBJ whose left quad
    uses a red and whose right quad uses a blue albedo renders red on the left
    and blue on the right; --albedo overrides both; the spider's legs, abdomen
    and eyes use their own materials' images."""
    def ppm(name, rgb):
        with open(os.path.join(tmp, name), "wb") as f:
            f.write(b"P6 8 8 255\n" + bytes(rgb) * 64)
    ppm("red.ppm", (230, 20, 20))
    ppm("blue.ppm", (20, 20, 230))
    ppm("green.ppm", (20, 230, 20))
    # the blue (right) face first in the file, so file order is what is checked
    mesh = two_quads(tmp, "red.ppm", "blue.ppm", names=("red", "blue"), right_first=True)
    out = os.path.join(tmp, "two.ppm")

    def sides(extra):
        rc, so, se = run(["--mesh", mesh, "--method", "none", "--view", "0,0,1", "--size",
                          "64x64", "--output", out] + extra, tmp)
        check(rc == 0, f"two materials: exit 0 (got {rc}: {se.strip()})")
        w, h, px = read_ppm(out)
        def at(x, y):
            i = (y * w + x) * 3
            return tuple(px[i:i + 3])
        return so, at(w // 4, h // 2), at(3 * w // 4, h // 2)

    so, left, right = sides([])
    check("red.ppm" in so and "blue.ppm" in so, f"both materials' textures are loaded ({so})")
    check(left[0] > 2 * left[2] and left[0] > 2 * left[1], f"the left quad is red {left}")
    check(right[2] > 2 * right[0] and right[2] > 2 * right[1], f"the right quad is blue {right}")
    so, left, right = sides(["--albedo", os.path.join(tmp, "green.ppm")])
    check(all(c[1] > 2 * c[0] and c[1] > 2 * c[2] for c in (left, right)),
          f"--albedo overrides every material: both green {left} {right}")
    if os.path.exists(SPIDER):
        rc, so, se = run(["--mesh", SPIDER, "--compare", "none,listing1-heightmap", "--size",
                          "48x48", "--output", os.path.join(tmp, "sp.png")], tmp)
        check(rc == 0, f"spider: exit 0 (got {rc}: {se.strip()})")
        for img in ("wal67ar_small.jpg", "SpiderTex.jpg", "drkwood2.jpg", "engineflare1.jpg"):
            check(img in so, f"spider: its material's {img} is used")
    t_materials_collada(tmp)
    t_materials_embedded(tmp)


BOX_GLB = "/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb"


def t_materials_embedded(tmp):
    """A texture embedded in the file (glb, "*0") is skipped and said so: the
    textures line counts it, and a texture method then fails with exit 2
    saying why there is no height texture."""
    if not os.path.exists(BOX_GLB):
        print("skip: assimp-testmodels' BoxTextured.glb not installed")
        return
    out = os.path.join(tmp, "glb.png")
    rc, so, se = run(["--mesh", BOX_GLB, "--method", "none", "--size", "16x16", "--output", out],
                     tmp)
    check(rc == 0 and "(embedded textures skipped: 1)" in so,
          f"glb: the embedded texture is counted as skipped (rc {rc}: {so.strip()} {se.strip()})")
    rc, so, se = run(["--mesh", BOX_GLB, "--method", "listing1-heightmap", "--size", "16x16",
                      "--output", out], tmp)
    check(rc == 2 and "embedded in the file are not extracted" in se,
          f"glb: a texture method says the embedded texture is not used (rc {rc}: {se.strip()})")


KWX_DAE = "/usr/share/assimp/models/Collada/kwxport_test_vcolors.dae"


def t_materials_collada(tmp):
    """The loader's per-triangle materials for a format other than OBJ
    (bg_mesh.material/materials from assimp's aiMesh::mMaterialIndex, not the
    renderer's own OBJ reader): assimp-testmodels' Collada cube has three
    textured materials, "top" (../X/top.tga) on its +y faces, "bottom"
    (../X/bottom.tga) on its -y faces and "side" (../X/updown.tga) on the
    others. The real file renders with all three sets; a copy next to solid
    red/blue/green stand-ins for those textures shows each face takes its own
    material's: red seen from above, blue from below, green from the side."""
    if not os.path.exists(KWX_DAE):
        print("skip: assimp-testmodels' Collada cube not installed")
        return
    rc, so, se = run(["--mesh", KWX_DAE, "--compare", "none,listing1-heightmap", "--size",
                      "48x48", "--output", os.path.join(tmp, "kwx.png")], tmp)
    check(rc == 0, f"collada: exit 0 (got {rc}: {se.strip()})")
    for name, img in (("bottom", "bottom.tga"), ("side", "updown.tga"), ("top", "top.tga")):
        check(re.search(r"\[%s\] albedo=%s " % (name, re.escape(img)), so) is not None,
              f"collada: material [{name}] loads its own {img} ({so.strip()})")
    # the copy: model in tmp/c/, its textures in tmp/X/ as the file names them
    os.makedirs(os.path.join(tmp, "c"), exist_ok=True)
    os.makedirs(os.path.join(tmp, "X"), exist_ok=True)
    mesh = os.path.join(tmp, "c", "cube.dae")
    shutil.copyfile(KWX_DAE, mesh)

    def tga(name, rgb):  # uncompressed 24-bit TGA, 8x8, one colour
        hdr = bytes([0, 0, 2] + [0] * 9 + [8, 0, 8, 0, 24, 0])
        with open(os.path.join(tmp, "X", name), "wb") as f:
            f.write(hdr + bytes((rgb[2], rgb[1], rgb[0])) * 64)
    tga("top.tga", (230, 20, 20))
    tga("bottom.tga", (20, 20, 230))
    tga("updown.tga", (20, 230, 20))
    out = os.path.join(tmp, "cube.ppm")
    for view, chan, what in (("0.2,1,0.2", 0, "red from above (top)"),
                             ("0.2,-1,0.2", 2, "blue from below (bottom)"),
                             ("1,0.2,0.2", 1, "green from the side (side)")):
        light = ",".join(str(5 * float(c)) for c in view.split(","))
        rc, so, se = run(["--mesh", mesh, "--method", "none", "--view", view, "--light", light,
                          "--size", "32x32", "--output", out], tmp)
        if not check(rc == 0, f"collada copy, view {view}: exit 0 (got {rc}: {se.strip()})"):
            continue
        w, h, px = read_ppm(out)
        i = (h // 2 * w + w // 2) * 3
        c = tuple(px[i:i + 3])
        check(all(c[chan] > 2 * c[k] for k in range(3) if k != chan),
              f"collada copy: the centre pixel is {what}: {c}")


TESTS = {"presets": t_presets, "inward": t_inward, "density": t_density, "none": t_none,
         "determinism": t_determinism, "badargs": t_badargs, "closeup": t_closeup,
         "mesh": t_mesh, "mesherrors": t_mesherrors, "tracers": t_tracers, "fig4": t_fig4,
         "json": t_json, "bakedmap": t_bakedmap,
         "materials": t_materials}

if __name__ == "__main__":
    if shutil.which("iinfo") is None or shutil.which("idiff") is None:
        print("SKIP: OpenImageIO's iinfo/idiff not found")
        sys.exit(77)
    with tempfile.TemporaryDirectory() as tmp:
        TESTS[sys.argv[2]](tmp)
    sys.exit(finish("render " + sys.argv[2]))
