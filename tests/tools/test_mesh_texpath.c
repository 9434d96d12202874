/* SPDX-License-Identifier: MIT */
/* mesh_texture_find (src/tools/mesh/mesh_texpath.h): material texture paths
 * written on another machine are looked for, in the documented order, by
 * their base name in the mesh's folder, then in its textures/ and tex/
 * subfolders, never outside it; a miss names the material, the path as
 * written and every place tried. The material paths are given as bg_mesh_load
 * forms them (the mesh folder, absolute, before a relative path; backslashes
 * as '/'), so this needs no mesh file or I/O module.
 * usage: test_mesh_texpath BUILDDIR */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "mesh/mesh_texpath.h"
#include "scratch.h"

static void touch(const char *path)
{
    FILE *f = fopen(path, "w");
    if (f)
        fclose(f);
    CHECK(f != NULL, "cannot create %s", path);
}

/* find `written` (relative: behind the mesh folder, as the loader does) for
 * dir/m/mesh.obj; expect the file `want` (a path under dir, NULL: not found). */
static void expect(const char *written, const char *want, const char *what)
{
    char mesh[4200], path[8400], wantp[4200];
    snprintf(mesh, sizeof mesh, "%s/m/mesh.obj", dir);
    if (written[0] == '/')
        snprintf(path, sizeof path, "%s", written);
    else
        snprintf(path, sizeof path, "%s/m/%s", dir, written);
    bgt_err e = {BG_OK, ""};
    char *got = mesh_texture_find(mesh, 3, "wood", "diffuse", path, &e);
    if (want) {
        snprintf(wantp, sizeof wantp, "%s/%s", dir, want);
        CHECK(got && strcmp(got, wantp) == 0, "%s: %s -> %s, expected %s (%s)", what, written,
              got ? got : "NULL", wantp, e.msg);
    } else {
        CHECK(!got && e.status == BG_ERR_FORMAT, "%s: %s -> %s, expected not found", what,
              written, got ? got : "NULL");
    }
    free(got);
}

int main(int argc, char **argv)
{
    (void)temp_leftovers; /* scratch.h's, for the writers' tests */
    if (argc < 2 || !scratch_create(argv[1], "test_mesh_texpath", "find"))
        return 1;
    char sub[4200];
    const char *subs[] = {"m", "m/textures", "m/tex", "m/deep", "other"};
    for (size_t i = 0; i < sizeof subs / sizeof subs[0]; i++) {
        snprintf(sub, sizeof sub, "%s/%s", dir, subs[i]);
        CHECK(mkdir(sub, 0777) == 0, "mkdir %s", sub);
    }
    touch(path_in("m/a.png"));          /* next to the mesh */
    touch(path_in("m/textures/a.png")); /* also in textures/: the folder wins */
    touch(path_in("m/textures/b.png")); /* only in textures/ */
    touch(path_in("m/tex/b.png"));      /* and in tex/: textures/ wins */
    touch(path_in("m/tex/c.png"));      /* only in tex/ */
    touch(path_in("m/deep/d.png"));     /* the path as written */
    touch(path_in("m/d.png"));          /* its base name, not used while it exists */
    touch(path_in("other/e.png"));      /* outside the mesh's folder: never found */
    touch(path_in("e.png"));            /* the mesh folder's parent: never found */
    CHECK(mkdir(path_in("m/f.png"), 0777) == 0, "mkdir f.png"); /* a folder is no texture */
    touch(path_in("m/tex/f.png"));

    /* 1. the path as written, when it exists (returned as it is) */
    expect("deep/d.png", "m/deep/d.png", "as written (relative)");
    expect("../other/e.png", "m/../other/e.png",
           "as written, relative with ..: the file's own path");
    char abs[4200];
    snprintf(abs, sizeof abs, "%s/other/e.png", dir);
    expect(abs, "other/e.png", "as written (absolute)");
    /* 2-4. Windows drive paths (backslashes already '/'), foreign absolute paths */
    expect("C:/Users/me/proj/tex/a.png", "m/a.png", "drive path: base name in the folder");
    expect("C:/Users/me/proj/b.png", "m/textures/b.png", "drive path: textures/ before tex/");
    expect("D:c.png", "m/tex/c.png", "drive-relative path: tex/");
    expect("/home/other/tex/a.png", "m/a.png", "foreign absolute path: base name");
    expect("/home/other/c.png", "m/tex/c.png", "foreign absolute path: tex/");
    expect("../tex/b.png", "m/textures/b.png", "missing ../tex/b.png: base name inside");
    expect("x/f.png", "m/tex/f.png", "a folder of that name is not a texture");
    /* never outside the mesh's folder tree */
    expect("C:/proj/e.png", NULL, "e.png is only outside the mesh folder");
    expect("C:/proj/..", NULL, "a base name of .. is not tried");

    /* The miss: the material, the path as written and every place, in order. */
    char mesh[4200], path[8400], want[20000];
    snprintf(mesh, sizeof mesh, "%s/m/mesh.obj", dir);
    snprintf(path, sizeof path, "%s/m/C:/Users/me/g.png", dir);
    bgt_err e = {BG_OK, ""};
    char *got = mesh_texture_find(mesh, 3, "wood", "diffuse", path, &e);
    snprintf(want, sizeof want,
             "material 3 'wood' of %s: diffuse texture \"C:/Users/me/g.png\" not found; tried "
             "%s/m/g.png, %s/m/textures/g.png, %s/m/tex/g.png",
             mesh, dir, dir, dir);
    CHECK(!got && e.status == BG_ERR_FORMAT && strcmp(e.msg, want) == 0,
          "the miss message:\n    got  %s\n    want %s", e.msg, want);
    free(got);
    snprintf(path, sizeof path, "/nowhere/h.png");
    got = mesh_texture_find(mesh, 0, "", "height", path, &e);
    snprintf(want, sizeof want,
             "material 0 '' of %s: height texture \"/nowhere/h.png\" not found; tried "
             "/nowhere/h.png, %s/m/h.png, %s/m/textures/h.png, %s/m/tex/h.png",
             mesh, dir, dir, dir);
    CHECK(!got && strcmp(e.msg, want) == 0, "an absolute miss lists it first:\n    got  %s\n"
          "    want %s", e.msg, want);
    free(got);
    /* A relative mesh path: the loader puts the current folder before it. */
    char cwd[4096];
    if (getcwd(cwd, sizeof cwd) && chdir(dir) == 0) {
        snprintf(path, sizeof path, "%s/m/C:/x/a.png", dir);
        got = mesh_texture_find("m/mesh.obj", 1, "w", "diffuse", path, &e);
        snprintf(want, sizeof want, "%s/m/a.png", dir);
        CHECK(got && strcmp(got, want) == 0, "relative mesh path: %s (%s)", got ? got : "NULL",
              e.msg);
        free(got);
        CHECK(chdir(cwd) == 0, "chdir back");
    }
    char origin[64];
    CHECK(strcmp(mesh_texture_origin(origin, sizeof origin, "a.obj", 2, "x"),
                 "material 2 'x' of a.obj") == 0, "origin label: %s", origin);

    return scratch_finish("test_mesh_texpath");
}
