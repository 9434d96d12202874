/* SPDX-License-Identifier: MIT */
/* The public functions of the I/O shim (image.h, volume.h, mesh.h) as small
 * forwarders into the module that holds the C++ code (libbumpgrad_io_module.so),
 * loaded with dlopen on first use.
 *
 * Why: Debian's OpenImageIO pulls in about 260 shared libraries (OpenCV,
 * ffmpeg, DCMTK, ...). Linked directly, loading and relocating them cost every
 * `bumpgrad` run about 70 ms and 120 MB of resident memory (42 MB anonymous),
 * even `bumpgrad eval`, which never touches a file format. Behind dlopen only
 * the commands that read or write images, volumes or meshes pay for it.
 *
 * Where the module is looked up: $BUMPGRAD_IO_MODULE if set; else, for a
 * program inside the build tree (the command, the tests), the module built
 * next to it; else the installed one (LIBDIR/bumpgrad). */
#define _GNU_SOURCE /* readlink and dlopen under -std=c11 */
#include <dlfcn.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bumpgrad/image.h"
#include "bumpgrad/mesh.h"
#include "bumpgrad/volume.h"
#include "io_paths.h"

static void *module;
static char load_error[2048];
static pthread_once_t load_once = PTHREAD_ONCE_INIT;

static int try_open(const char *path)
{
    /* RTLD_LOCAL: the module's OpenImageIO/OpenVDB/assimp symbols stay out of
     * the program's namespace. RTLD_NOW: a broken module fails here, at one
     * place with one message, not at some later call. */
    module = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (module)
        return 1;
    const char *e = dlerror();
    size_t used = strlen(load_error);
    snprintf(load_error + used, sizeof load_error - used, "%s%s", used ? "; " : "",
             e ? e : path);
    return 0;
}

static void load_module(void)
{
    const char *env = getenv("BUMPGRAD_IO_MODULE");
    if (env && *env) {
        try_open(env);
        return;
    }
    char exe[4096];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    exe[n > 0 ? n : 0] = '\0';
    const size_t root = strlen(BG_IO_BUILD_ROOT);
    const int in_build_tree = n > 0 && strncmp(exe, BG_IO_BUILD_ROOT, root) == 0 && exe[root] == '/';
    if (in_build_tree && try_open(BG_IO_BUILD_MODULE))
        return;
    try_open(BG_IO_INSTALLED_MODULE);
}

/* Address of `name` in the module, loading it first if `load` is set; NULL
 * (with the reason in load_error) if it cannot be had. */
static void *lookup(const char *name, int load)
{
    if (load)
        pthread_once(&load_once, load_module);
    else if (!module)
        return NULL;
    if (!module)
        return NULL;
    void *p = dlsym(module, name);
    if (!p) {
        const char *e = dlerror();
        snprintf(load_error, sizeof load_error, "%s", e ? e : name);
    }
    return p;
}

static bg_status unavailable(char *err, size_t errlen)
{
    if (err && errlen)
        snprintf(err, errlen, "the I/O module (OpenImageIO, OpenVDB, assimp) cannot be loaded: %s "
                 "(set BUMPGRAD_IO_MODULE to its path)", load_error);
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

/* ---- images: allocation needs no module ---------------------------------- */

bg_status bg_image_alloc(bg_image *img, int width, int height, int channels)
{
    if (!img)
        return BG_ERR_NULL_POINTER;
    img->width = img->height = img->channels = 0;
    img->pixels = NULL;
    if (width <= 0 || height <= 0 || channels <= 0 || channels > 64)
        return BG_ERR_INVALID_ARGUMENT;
    size_t n = (size_t)width;
    if (n > (size_t)-1 / (size_t)height)
        return BG_ERR_OUT_OF_MEMORY;
    n *= (size_t)height;
    if (n > (size_t)-1 / sizeof(float) / (size_t)channels)
        return BG_ERR_OUT_OF_MEMORY;
    img->pixels = calloc(n * (size_t)channels, sizeof(float));
    if (!img->pixels)
        return BG_ERR_OUT_OF_MEMORY;
    img->width = width;
    img->height = height;
    img->channels = channels;
    return BG_OK;
}

void bg_image_free(bg_image *img)
{
    if (!img)
        return;
    free(img->pixels); /* same libc allocator as the module's bg_image_alloc */
    img->pixels = NULL;
    img->width = img->height = img->channels = 0;
}

bg_status bg_image_read(const char *path, bg_image *out, char *err, size_t errlen)
{
    bg_status (*f)(const char *, bg_image *, char *, size_t);
    GET(f, "bg_image_read", 1);
    return f ? f(path, out, err, errlen) : unavailable(err, errlen);
}

bg_status bg_image_write(const char *path, const bg_image *img, bg_pixel_type type, int srgb,
                         char *err, size_t errlen)
{
    bg_status (*f)(const char *, const bg_image *, bg_pixel_type, int, char *, size_t);
    GET(f, "bg_image_write", 1);
    return f ? f(path, img, type, srgb, err, errlen) : unavailable(err, errlen);
}

bg_status bg_image_draw_text(bg_image *img, int x, int y, const char *text, const float rgb[3],
                             int size, char *err, size_t errlen)
{
    bg_status (*f)(bg_image *, int, int, const char *, const float *, int, char *, size_t);
    GET(f, "bg_image_draw_text", 1);
    return f ? f(img, x, y, text, rgb, size, err, errlen) : unavailable(err, errlen);
}

/* ---- volumes -------------------------------------------------------------- */

bg_status bg_vdb_writer_create(double voxel_size, const double origin[3], const char *height_name,
                               const char *gradient_name, bg_vdb_writer **out)
{
    bg_status (*f)(double, const double *, const char *, const char *, bg_vdb_writer **);
    GET(f, "bg_vdb_writer_create", 1);
    if (!f) {
        fprintf(stderr, "bumpgrad: %s\n", load_error);
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
    return f ? f(w, path, err, errlen) : unavailable(err, errlen);
}

void bg_vdb_writer_free(bg_vdb_writer *w)
{
    void (*f)(bg_vdb_writer *);
    GET(f, "bg_vdb_writer_free", 0);
    if (f)
        f(w);
}

bg_status bg_vdb_height_open(const char *path, const char *grid_name, bg_vdb_height **out,
                             char *err, size_t errlen)
{
    bg_status (*f)(const char *, const char *, bg_vdb_height **, char *, size_t);
    GET(f, "bg_vdb_height_open", 1);
    if (!f && out)
        *out = NULL;
    return f ? f(path, grid_name, out, err, errlen) : unavailable(err, errlen);
}

void bg_vdb_height_close(bg_vdb_height *h)
{
    void (*f)(bg_vdb_height *);
    GET(f, "bg_vdb_height_close", 0);
    if (f)
        f(h);
}

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
    return f ? f(path, out, err, errlen) : unavailable(err, errlen);
}

bg_status bg_mesh_load_ex(const char *path, unsigned flags, bg_mesh *out, char *err,
                          size_t errlen)
{
    bg_status (*f)(const char *, unsigned, bg_mesh *, char *, size_t);
    GET(f, "bg_mesh_load_ex", 1);
    return f ? f(path, flags, out, err, errlen) : unavailable(err, errlen);
}

bg_status bg_mesh_export(const char *path, const char *format_id, const bg_mesh *mesh, char *err,
                         size_t errlen)
{
    bg_status (*f)(const char *, const char *, const bg_mesh *, char *, size_t);
    GET(f, "bg_mesh_export", 1);
    return f ? f(path, format_id, mesh, err, errlen) : unavailable(err, errlen);
}

void bg_mesh_free(bg_mesh *mesh)
{
    /* Without the module loaded no mesh can have come from it: nothing to free. */
    void (*f)(bg_mesh *);
    GET(f, "bg_mesh_free", 0);
    if (f)
        f(mesh);
}
