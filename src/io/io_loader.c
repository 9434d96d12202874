/* SPDX-License-Identifier: MIT */
/* The public functions of the I/O shim (image.h, volume.h, mesh.h) as small
 * forwarders into the module that holds the C++ code (libbumpgrad_io_module.so),
 * loaded with dlopen on first use. Built twice from this file: the installed
 * shared libbumpgrad-io.so (bumpgrad-io.pc, CMake bumpgrad::bumpgrad-io) and the
 * static libbumpgrad_io.a that the command and the tests link.
 *
 * Why: Debian's OpenImageIO pulls in about 260 shared libraries (OpenCV,
 * ffmpeg, DCMTK, ...). Linked directly, loading and relocating them cost every
 * `bumpgrad` run about 70 ms and 120 MB of resident memory (42 MB anonymous),
 * even `bumpgrad eval`, which never touches a file format. Behind dlopen only
 * the commands that read or write images, volumes or meshes pay for it.
 *
 * Where the module is looked up (include/bumpgrad/io.h): $BUMPGRAD_IO_MODULE if
 * set; else relative to the object holding this code, found with dladdr (the
 * shared library, or the program for the static copy): paths relative to it
 * only, so a moved prefix and the build tree both work. Nothing here prints. */
#define _GNU_SOURCE /* dladdr1, realpath and dlopen under -std=c11 */
#include <dlfcn.h>
#include <limits.h>
#include <link.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bumpgrad/image.h"
#include "bumpgrad/io.h"
#include "bumpgrad/mesh.h"
#include "bumpgrad/volume.h"
#include "io_paths.h" /* relative paths only: BG_IO_MODULE_NAME, BG_IO_BINDIR_TO_LIBDIR, BG_IO_BUILD_SUBDIR */
#include "io_host.h"
#include "common/env.h"
#include "common/safe_file.h"
#include <sys/stat.h>

static void *module;
static char load_error[3072];
static pthread_once_t load_once = PTHREAD_ONCE_INIT;
/* Any object of this file: dladdr on its address names the file that holds the code. */
static const char anchor = 0;

/* Append `src` to the string in dst (size bytes), truncating silently. Plain
 * copies rather than snprintf: gcc's -Wformat-truncation flags every %s of a
 * PATH_MAX buffer, and truncation is the intended behaviour here. */
static void append(char *dst, size_t size, const char *src)
{
    size_t used = strnlen(dst, size);
    while (*src && used + 1 < size)
        dst[used++] = *src++;
    if (used < size)
        dst[used] = '\0';
}

/* Append a part to load_error, "; "-separated. */
static void note(const char *a, const char *b)
{
    if (load_error[0])
        append(load_error, sizeof load_error, "; ");
    append(load_error, sizeof load_error, a);
    if (b)
        append(load_error, sizeof load_error, b);
}

/* ---- the host services lent to the module (io_host.h) ----------------------
 * The one copy of the safe writer, the cap and the variables in this process
 * (src/tools/common, linked into this loader), with bgt_err turned into the
 * module's err/errlen buffers. */
static void copy_err(const bgt_err *e, char *err, size_t errlen)
{
    if (err && errlen) {
        err[0] = '\0';
        append(err, errlen, e->msg);
    }
}

static char *host_temp_path(const char *path, char *err, size_t errlen)
{
    bgt_err e;
    bgt_err_clear(&e);
    char *t = bgt_safe_temp_path(path, &e);
    if (!t)
        copy_err(&e, err, errlen);
    return t;
}

/* A host call's status, its message copied to the module's buffer on failure. */
static int host_result(bg_status s, const bgt_err *e, char *err, size_t errlen)
{
    if (s != BG_OK)
        copy_err(e, err, errlen);
    return s;
}

static int host_commit_path(const char *tmp, const char *path, char *err, size_t errlen)
{
    bgt_err e;
    bgt_err_clear(&e);
    return host_result(bgt_safe_commit_path(tmp, path, &e), &e, err, errlen);
}

static int host_check_alloc(double bytes, const char *what, char *err, size_t errlen)
{
    bgt_err e;
    bgt_err_clear(&e);
    return host_result(bgt_check_alloc(bytes, what, &e), &e, err, errlen);
}

static int host_env_uint(const char *name, unsigned long long *out, char *err, size_t errlen)
{
    bgt_err e;
    bgt_err_clear(&e);
    return host_result(bgt_env_uint(name, out, &e), &e, err, errlen);
}

static const bg_io_host host_services = {
    BG_IO_HOST_VERSION, host_temp_path, host_commit_path, bgt_safe_discard_path, free,
    host_check_alloc, bgt_memory_cap, host_env_uint,
};

/* dlopen `path` (if only_if_present, only when the file exists); 1 when loaded.
 * A missing file is only noted by the caller's list of searched places, a
 * present but unloadable one with dlerror (that is the message a user needs:
 * e.g. a missing OpenImageIO). */
static int try_open(const char *path, int only_if_present)
{
    if (only_if_present && access(path, F_OK) != 0)
        return 0;
    /* RTLD_LOCAL: the module's OpenImageIO/OpenVDB/assimp symbols stay out of
     * the program's namespace. RTLD_NOW: a broken module fails here, at one
     * place with one message, not at some later call. */
    module = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (module) {
        bg_io_attach_fn attach;
        void *sym = dlsym(module, BG_IO_ATTACH_SYMBOL);
        memcpy(&attach, &sym, sizeof attach);
        if (sym && attach(&host_services) == 0)
            return 1;
        dlclose(module);
        module = NULL;
        note(path, ": an I/O module from another build (its host interface differs)");
        return 0;
    }
    const char *e = dlerror();
    note(e ? e : path, NULL);
    return 0;
}

/* dst = a/b/c (c may be empty: then a/b), truncated to size. */
static void join3(char *dst, size_t size, const char *a, const char *b, const char *c)
{
    if (!size)
        return;
    dst[0] = '\0';
    append(dst, size, a);
    append(dst, size, "/");
    append(dst, size, b);
    if (*c) {
        append(dst, size, "/");
        append(dst, size, c);
    }
}

/* Folder of the file (shared library or program) that holds this code, in
 * `dir` (PATH_MAX bytes); 0 if it cannot be found. */
static int self_dir(char *dir)
{
    Dl_info info;
    struct link_map *map = NULL;
    char path[PATH_MAX];
    path[0] = '\0';
    if (dladdr1(&anchor, &info, (void **)&map, RTLD_DL_LINKMAP) && map && map->l_name &&
        map->l_name[0]) {
        /* A shared library: l_name is the path it was loaded from. */
        if (!realpath(map->l_name, path)) {
            path[0] = '\0';
            append(path, sizeof path, map->l_name);
        }
    } else {
        /* The main program (its link map has an empty name). */
        ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
        path[n > 0 ? n : 0] = '\0';
    }
    char *slash = strrchr(path, '/');
    if (!slash)
        return 0;
    *slash = '\0';
    dir[0] = '\0';
    append(dir, PATH_MAX, path[0] ? path : "/");
    return 1;
}

static void load_module(void)
{
    const char *env = getenv("BUMPGRAD_IO_MODULE");
    if (env && *env) {
        /* dlopen would block for ever on a FIFO and fail obscurely on a folder. */
        struct stat st;
        if (stat(env, &st) != 0 || !S_ISREG(st.st_mode)) {
            note(env, stat(env, &st) != 0 ? ": no such file" : ": not a regular file");
            note("the path came from $BUMPGRAD_IO_MODULE", NULL);
            return;
        }
        if (!try_open(env, 0))
            note("the path came from $BUMPGRAD_IO_MODULE", NULL);
        return;
    }
    char dir[PATH_MAX], cand[PATH_MAX + 256], searched[2048] = "";
    if (!self_dir(dir)) {
        note("cannot tell where the running library or program is", NULL);
        return;
    }
    /* 1: shared library installed in LIBDIR; 2: shared library in the build
     * tree, next to the module; 3: a program installed in BINDIR. */
    const char *const rel[] = {"bumpgrad", ".", BG_IO_BINDIR_TO_LIBDIR "/bumpgrad"};
    for (size_t i = 0; i < sizeof rel / sizeof rel[0]; i++) {
        join3(cand, sizeof cand, dir, rel[i], BG_IO_MODULE_NAME);
        if (try_open(cand, 1))
            return;
        if (searched[0])
            append(searched, sizeof searched, ", ");
        join3(searched + strlen(searched), sizeof searched - strlen(searched), dir, rel[i], "");
    }
    /* 4: a program in the build tree (src/cli/, tests/x/, ...): the build
     * root's BG_IO_BUILD_SUBDIR is in the program's folder or a parent. */
    char up[PATH_MAX];
    up[0] = '\0';
    append(up, sizeof up, dir);
    for (int level = 0; level < 4 && up[0]; level++) {
        join3(cand, sizeof cand, up, BG_IO_BUILD_SUBDIR, BG_IO_MODULE_NAME);
        if (try_open(cand, 1))
            return;
        char *slash = strrchr(up, '/');
        if (!slash)
            break;
        *slash = '\0';
    }
    append(searched, sizeof searched, ", and " BG_IO_BUILD_SUBDIR " in ");
    append(searched, sizeof searched, dir);
    append(searched, sizeof searched, " and its parents");
    note(BG_IO_MODULE_NAME " not found in ", searched);
}

static int ensure_loaded(void)
{
    pthread_once(&load_once, load_module);
    return module != NULL;
}

bg_status bg_io_available(char *err, size_t errlen)
{
    if (ensure_loaded())
        return BG_OK;
    const char *env = getenv("BUMPGRAD_IO_MODULE");
    if (err && errlen)
        snprintf(err, errlen, "the I/O module (OpenImageIO, OpenVDB, assimp) cannot be loaded: %s%s",
                 load_error, env && *env ? "" : " (set BUMPGRAD_IO_MODULE to its path)");
    return BG_ERR_IO;
}

/* Address of `name` in the module, loading it first if `load` is set; NULL if
 * it cannot be had. Only the loading thread writes load_error (inside
 * pthread_once), so a failed dlsym is reported by name, not through it. */
static void *lookup(const char *name, int load)
{
    if (load ? !ensure_loaded() : !module)
        return NULL;
    return dlsym(module, name);
}

static bg_status unavailable(const char *name, char *err, size_t errlen)
{
    if (!module)
        return bg_io_available(err, errlen);
    if (err && errlen)
        snprintf(err, errlen, "the I/O module lacks %s (a module from another version?)", name);
    return BG_ERR_IO;
}

/* A function pointer from dlsym's void *: memcpy, since ISO C has no cast
 * between object and function pointers. */
#define GET(fp, name, load)                       \
    do {                                          \
        void *p_ = lookup(name, load);            \
        fp = NULL;                                \
        if (p_)                                   \
            memcpy(&fp, &p_, sizeof fp);          \
    } while (0)

/* The release calls (free, close) of an object the module made: without the
 * module loaded no such object can exist, so there is nothing to do. */
#define FORWARD_RELEASE(name, type)                \
    void name(type *obj)                           \
    {                                              \
        void (*f)(type *);                         \
        GET(f, #name, 0);                          \
        if (f)                                     \
            f(obj);                                \
    }

/* ---- images: allocation needs no module ---------------------------------- */

bg_status bg_image_read(const char *path, bg_image *out, char *err, size_t errlen)
{
    bg_status (*f)(const char *, bg_image *, char *, size_t);
    GET(f, "bg_image_read", 1);
    return f ? f(path, out, err, errlen) : unavailable("bg_image_read", err, errlen);
}

bg_status bg_image_write(const char *path, const bg_image *img, bg_pixel_type type, int srgb,
                         char *err, size_t errlen)
{
    bg_status (*f)(const char *, const bg_image *, bg_pixel_type, int, char *, size_t);
    GET(f, "bg_image_write", 1);
    return f ? f(path, img, type, srgb, err, errlen) : unavailable("bg_image_write", err, errlen);
}

bg_status bg_image_read_as(const char *path, const char *format, bg_image *out, char *err,
                           size_t errlen)
{
    bg_status (*f)(const char *, const char *, bg_image *, char *, size_t);
    GET(f, "bg_image_read_as", 1);
    return f ? f(path, format, out, err, errlen) : unavailable("bg_image_read_as", err, errlen);
}

bg_status bg_image_write_as(const char *path, const char *format, const bg_image *img,
                            bg_pixel_type type, int srgb, char *err, size_t errlen)
{
    bg_status (*f)(const char *, const char *, const bg_image *, bg_pixel_type, int, char *,
                   size_t);
    GET(f, "bg_image_write_as", 1);
    return f ? f(path, format, img, type, srgb, err, errlen)
             : unavailable("bg_image_write_as", err, errlen);
}

bg_status bg_image_draw_text(bg_image *img, int x, int y, const char *text, const float rgb[3],
                             int size, char *err, size_t errlen)
{
    bg_status (*f)(bg_image *, int, int, const char *, const float *, int, char *, size_t);
    GET(f, "bg_image_draw_text", 1);
    return f ? f(img, x, y, text, rgb, size, err, errlen) : unavailable("bg_image_draw_text", err, errlen);
}

/* ---- volumes -------------------------------------------------------------- */

bg_status bg_vdb_writer_create(double voxel_size, const double origin[3], const char *height_name,
                               const char *gradient_name, bg_vdb_writer **out)
{
    bg_status (*f)(double, const double *, const char *, const char *, bg_vdb_writer **);
    GET(f, "bg_vdb_writer_create", 1);
    /* No error buffer in this call: the reason is bg_io_available's message. */
    if (!f) {
        if (out)
            *out = NULL;
        return BG_ERR_IO;
    }
    return f(voxel_size, origin, height_name, gradient_name, out);
}

/* The calls below take an object the module made, so it is loaded already. */
bg_status bg_vdb_writer_add(bg_vdb_writer *w, const int32_t *i, const int32_t *j, const int32_t *k,
                            size_t n, const float *height, const float *gx, const float *gy,
                            const float *gz)
{
    bg_status (*f)(bg_vdb_writer *, const int32_t *, const int32_t *, const int32_t *, size_t,
                   const float *, const float *, const float *, const float *);
    GET(f, "bg_vdb_writer_add", 0);
    return f ? f(w, i, j, k, n, height, gx, gy, gz) : BG_ERR_NULL_POINTER;
}

bg_status bg_vdb_writer_set_meta(bg_vdb_writer *w, const char *key, const char *value)
{
    bg_status (*f)(bg_vdb_writer *, const char *, const char *);
    GET(f, "bg_vdb_writer_set_meta", 0);
    return f ? f(w, key, value) : BG_ERR_NULL_POINTER;
}

uint64_t bg_vdb_writer_voxel_count(const bg_vdb_writer *w)
{
    uint64_t (*f)(const bg_vdb_writer *);
    GET(f, "bg_vdb_writer_voxel_count", 0);
    return f ? f(w) : 0;
}

bg_status bg_vdb_writer_write(const bg_vdb_writer *w, const char *path, char *err, size_t errlen)
{
    bg_status (*f)(const bg_vdb_writer *, const char *, char *, size_t);
    GET(f, "bg_vdb_writer_write", 1);
    return f ? f(w, path, err, errlen) : unavailable("bg_vdb_writer_write", err, errlen);
}

FORWARD_RELEASE(bg_vdb_writer_free, bg_vdb_writer)

bg_status bg_vdb_merge(const char *const *inputs, size_t n, const char *output, char *err,
                       size_t errlen)
{
    bg_status (*f)(const char *const *, size_t, const char *, char *, size_t);
    GET(f, "bg_vdb_merge", 1);
    return f ? f(inputs, n, output, err, errlen) : unavailable("bg_vdb_merge", err, errlen);
}

bg_status bg_vdb_height_open(const char *path, const char *grid_name, bg_vdb_height **out,
                             char *err, size_t errlen)
{
    bg_status (*f)(const char *, const char *, bg_vdb_height **, char *, size_t);
    GET(f, "bg_vdb_height_open", 1);
    if (!f && out)
        *out = NULL;
    return f ? f(path, grid_name, out, err, errlen) : unavailable("bg_vdb_height_open", err, errlen);
}

FORWARD_RELEASE(bg_vdb_height_close, bg_vdb_height)

void bg_vdb_height_get_info(const bg_vdb_height *h, bg_vdb_height_info *info)
{
    void (*f)(const bg_vdb_height *, bg_vdb_height_info *);
    GET(f, "bg_vdb_height_get_info", 0);
    if (f)
        f(h, info);
}

void bg_vdb_height_sample_batch(const bg_vdb_height *h, const float *px, const float *py,
                                const float *pz, size_t n, float *height, float *gx, float *gy,
                                float *gz)
{
    void (*f)(const bg_vdb_height *, const float *, const float *, const float *, size_t, float *,
              float *, float *, float *);
    GET(f, "bg_vdb_height_sample_batch", 0);
    if (f)
        f(h, px, py, pz, n, height, gx, gy, gz);
}

/* ---- meshes --------------------------------------------------------------- */

bg_status bg_mesh_load(const char *path, bg_mesh *out, char *err, size_t errlen)
{
    bg_status (*f)(const char *, bg_mesh *, char *, size_t);
    GET(f, "bg_mesh_load", 1);
    return f ? f(path, out, err, errlen) : unavailable("bg_mesh_load", err, errlen);
}

bg_status bg_mesh_load_ex(const char *path, unsigned flags, bg_mesh *out, char *err,
                          size_t errlen)
{
    bg_status (*f)(const char *, unsigned, bg_mesh *, char *, size_t);
    GET(f, "bg_mesh_load_ex", 1);
    return f ? f(path, flags, out, err, errlen) : unavailable("bg_mesh_load_ex", err, errlen);
}

bg_status bg_mesh_export(const char *path, const char *format_id, const bg_mesh *mesh, char *err,
                         size_t errlen)
{
    bg_status (*f)(const char *, const char *, const bg_mesh *, char *, size_t);
    GET(f, "bg_mesh_export", 1);
    return f ? f(path, format_id, mesh, err, errlen) : unavailable("bg_mesh_export", err, errlen);
}

FORWARD_RELEASE(bg_mesh_free, bg_mesh)
