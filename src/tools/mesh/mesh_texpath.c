/* SPDX-License-Identifier: MIT */
/* Material textures written by another machine: the search of
 * mesh_texpath.h, after Blender's "find missing files" (by base name, in the
 * folder of the file that references it). */
#define _POSIX_C_SOURCE 200809L
#include "mesh/mesh_texpath.h"
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

const char *mesh_texture_origin(char *buf, size_t len, const char *mesh_path, size_t index,
                                const char *name)
{
    snprintf(buf, len, "material %zu '%s' of %s", index, name ? name : "", mesh_path);
    return buf;
}

/* The mesh's folder with a trailing '/' exactly as bg_mesh_load resolves
 * material paths against it (bg_mesh_material; src/io's mesh_folder): the
 * current directory prefixed to a relative mesh path. So the path as written
 * is the material path after this prefix. NULL: out of memory. */
static char *loader_folder(const char *mesh_path)
{
    const char *slash = strrchr(mesh_path, '/');
    size_t dl = slash ? (size_t)(slash - mesh_path) + 1 : 0;
    char cwd[4096];
    const int rel = mesh_path[0] != '/' && getcwd(cwd, sizeof cwd) != NULL;
    size_t cl = rel ? strlen(cwd) + 1 : 0;
    char *dir = malloc(cl + dl + 1);
    if (!dir)
        return NULL;
    if (rel)
        memcpy(dir, cwd, cl - 1), dir[cl - 1] = '/';
    memcpy(dir + cl, mesh_path, dl);
    dir[cl + dl] = '\0';
    return dir;
}

static int regular_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* "C:/..." or "C:" + more: a Windows drive path (the loader has turned its
 * backslashes into '/' and, as it is not absolute here, put DIR before it). */
static int drive_path(const char *w)
{
    return isalpha((unsigned char)w[0]) && w[1] == ':';
}

char *mesh_texture_find(const char *mesh_path, size_t index, const char *name, const char *kind,
                        const char *path, bgt_err *e)
{
    if (regular_file(path)) {
        char *same = strdup(path);
        if (!same)
            bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
        return same;
    }
    char *dir = loader_folder(mesh_path);
    if (!dir) {
        bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
        return NULL;
    }
    const size_t dl = strlen(dir);
    const char *written = strncmp(path, dir, dl) == 0 ? path + dl : path;
    const char *slash = strrchr(written, '/');
    const char *base = slash ? slash + 1 : written;
    if (drive_path(base))
        base += 2; /* "C:albedo.png": relative to the drive's current folder */
    const int base_ok = *base && strcmp(base, ".") != 0 && strcmp(base, "..") != 0;
    static const char *const sub[MESH_TEXTURE_PLACES - 1] = {"", "textures/", "tex/"};
    char *place[MESH_TEXTURE_PLACES] = {NULL};
    size_t n = 0;
    char *found = NULL;
    int oom = 0;
    if (!drive_path(written) && !(place[n++] = strdup(path)))
        oom = 1;
    for (size_t k = 0; base_ok && !oom && k < MESH_TEXTURE_PLACES - 1; k++) {
        size_t len = dl + strlen(sub[k]) + strlen(base) + 1;
        char *p = malloc(len);
        if (!p) {
            oom = 1;
            break;
        }
        snprintf(p, len, "%s%s%s", dir, sub[k], base);
        if (n && strcmp(p, place[0]) == 0) { /* the written path was DIR/BASE */
            free(p);
            continue;
        }
        place[n++] = p;
        if (regular_file(p)) {
            found = p;
            break;
        }
    }
    if (oom) {
        bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    } else if (!found) {
        char origin[512], tried[1024];
        size_t at = 0;
        tried[0] = '\0';
        for (size_t k = 0; k < n && at + 1 < sizeof tried; k++) {
            int w = snprintf(tried + at, sizeof tried - at, "%s%s", k ? ", " : "", place[k]);
            at = w < 0 ? at : at + (size_t)w;
        }
        bgt_fail(e, BG_ERR_FORMAT, "%s: %s texture \"%s\" not found; tried %s",
                 mesh_texture_origin(origin, sizeof origin, mesh_path, index, name), kind, written,
                 n ? tried : "nothing (no file name in it)");
    }
    for (size_t k = 0; k < n; k++)
        if (place[k] != found)
            free(place[k]);
    free(dir);
    return found;
}

char *mesh_udim_path(const char *pattern, int udim)
{
    size_t tok = strlen(MESH_UDIM_TOKEN);
    char *out = malloc(strlen(pattern) + 1); /* 4 digits replace 6 characters */
    if (!out)
        return NULL;
    char *o = out;
    for (const char *p = pattern; *p;) {
        if (strncmp(p, MESH_UDIM_TOKEN, tok) == 0) {
            o += sprintf(o, "%04d", udim);
            p += tok;
        } else {
            *o++ = *p++;
        }
    }
    *o = '\0';
    return out;
}
