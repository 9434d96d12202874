/* SPDX-License-Identifier: MIT */
/* The tools as Python calls (tools builds only; included by _bumpgrad.c):
 * bgt_mesh_run through its face (mesh/mesh.h) and bg_image_read. The
 * Python layer (__init__.py) checks the arguments and turns results into
 * arrays. Tool errors raise bumpgrad.Error(status, text, message). */
#include <stdatomic.h>

#include "bumpgrad/image.h"
#include "bumpgrad/volume.h"
#include "common/tool.h"
#include "height_source.h"
#include "bake/heightmap.h"
#include "bake/volume.h"
#include "mesh/mesh.h"
#include "render/render.h"

static PyObject *raise_tool(bg_status s, const bgt_err *e)
{
    PyObject *type = error_type ? error_type : PyExc_RuntimeError;
    PyObject *args = Py_BuildValue("(iss)", (int)s, bg_status_string(s), e->msg);
    if (args) {
        PyErr_SetObject(type, args);
        Py_DECREF(args);
    }
    return NULL;
}

/* Progress to a Python callable progress(done, total), from the tool's
 * workers: at most about 100 calls per run, each with the GIL taken. An
 * exception in the callback stops further calls and is raised after the run. */
typedef struct py_progress {
    PyObject *cb;
    size_t total;
    atomic_size_t next; /* the next `done` worth a call */
    atomic_int failed;
    PyObject *exc;      /* the callback's exception (type, value, traceback) */
    PyObject *exc_value, *exc_tb;
} py_progress;

/* The height parameters of a tool call, as the CLI's height options give them. */
static void height_from_args(bgt_height *h, int function, int octaves, float lac, float gain,
                             float amp, float freq, int gradient, float step, bg_domain dom)
{
    bgt_height_init(h);
    h->h.fractal.function = (bg_function)function;
    h->h.fractal.octaves = octaves;
    h->h.fractal.lacunarity = lac;
    h->h.fractal.gain = gain;
    h->h.amplitude = amp;
    h->h.frequency = freq;
    h->h.gradient = (bg_gradient_mode)gradient;
    h->h.step = step;
    h->h.domain = dom;
}

/* After a tool run: the progress callback's exception, else the tool's error
 * (bumpgrad.Error), is set and 1 returned; 0 when the run succeeded. */
static int tool_failed(py_progress *pp, bg_status s, const bgt_err *e)
{
    if (pp->exc) {
        PyErr_Restore(pp->exc, pp->exc_value, pp->exc_tb);
        return 1;
    }
    if (s != BG_OK) {
        raise_tool(s, e);
        return 1;
    }
    return 0;
}

static void progress_call(py_progress *p, size_t done)
{
    PyGILState_STATE g = PyGILState_Ensure();
    if (!atomic_load(&p->failed)) {
        PyObject *r = PyObject_CallFunction(p->cb, "nn", (Py_ssize_t)done, (Py_ssize_t)p->total);
        if (!r) {
            atomic_store(&p->failed, 1);
            PyErr_Fetch(&p->exc, &p->exc_value, &p->exc_tb);
        }
        Py_XDECREF(r);
    }
    PyGILState_Release(g);
}

static void progress_begin(void *ctx, const char *label, size_t total)
{
    (void)label;
    py_progress *p = ctx;
    p->total = total;
    atomic_store(&p->next, 0);
    progress_call(p, 0);
    atomic_store(&p->next, total / 100 + 1);
}

static void progress_update(void *ctx, size_t done)
{
    py_progress *p = ctx;
    size_t want = atomic_load(&p->next);
    if (done < want || atomic_load(&p->failed))
        return;
    if (!atomic_compare_exchange_strong(&p->next, &want, done + p->total / 100 + 1))
        return; /* another worker reports this step */
    progress_call(p, done);
}

static void progress_end(void *ctx)
{
    py_progress *p = ctx;
    progress_call(p, p->total);
}

/* The tool calls: the options, the result (none for heightmap) and the error
 * of bgt_<tool>_run. */
typedef bg_status (*tool_run)(const void *opts, void *result, bgt_err *e);
static bg_status run_heightmap(const void *o, void *r, bgt_err *e)
{
    (void)r;
    return bgt_heightmap_run(o, e);
}

/* read_image and write_image: the I/O module (bgt_io_ready), then the shim. */
typedef struct image_io {
    const char *path;
    bg_image *img;
    bg_pixel_type type; /* write only */
    int srgb;           /* write only */
} image_io;

static bg_status run_read_image(const void *o, void *r, bgt_err *e)
{
    const image_io *io = o;
    (void)r;
    bg_status s = bgt_io_ready(e);
    return s != BG_OK ? s : bg_image_read(io->path, io->img, e->msg, sizeof e->msg);
}

static bg_status run_write_image(const void *o, void *r, bgt_err *e)
{
    const image_io *io = o;
    (void)r;
    bg_status s = bgt_io_ready(e);
    return s != BG_OK ? s
                      : bg_image_write(io->path, io->img, io->type, io->srgb, e->msg,
                                       sizeof e->msg);
}
static bg_status run_mesh(const void *o, void *r, bgt_err *e) { return bgt_mesh_run(o, r, e); }
static bg_status run_volume(const void *o, void *r, bgt_err *e) { return bgt_volume_run(o, r, e); }
static bg_status run_render(const void *o, void *r, bgt_err *e) { return bgt_render_run(o, r, e); }

/* One tool call from Python: *progress (the options' progress field; NULL
 * for a tool without one) drives `cb` unless it is None, the tool runs
 * without the GIL, then tool_failed. 0 on success; -1 with the exception set. */
static int call_tool(tool_run run, const void *opts, void *result, PyObject *cb,
                     const bgt_progress **progress)
{
    py_progress pp = {.cb = cb};
    bgt_progress sink = {progress_begin, progress_update, progress_end, &pp};
    if (progress && cb != Py_None)
        *progress = &sink;
    bgt_err e;
    bgt_err_clear(&e);
    bg_status s;
    Py_BEGIN_ALLOW_THREADS
    s = run(opts, result, &e);
    Py_END_ALLOW_THREADS
    if (progress)
        *progress = NULL; /* the sink lives only for this call */
    return tool_failed(&pp, s, &e) ? -1 : 0;
}

/* mesh_bake(input, path, width, height, function, octaves, lacunarity, gain, amplitude,
 *           frequency, gradient, step, method, space, padding, tangents, green_down,
 *           recompute_normals, depth, threads, progress|None, (px, py, pz), seed
 *           [, only_tile, samples, filter, units]) (0 each: the defaults)
 * -> (covered, padded, skipped, islands, [udim tiles]) */
static PyObject *py_mesh_bake(PyObject *self, PyObject *args)
{
    (void)self;
    const char *input, *path;
    int width, height, function, octaves, gradient, method, space, padding, tangents, green_down;
    int recompute, depth, threads;
    float lac, gain, amp, freq, step;
    PyObject *cb;
    int only_tile = 0, samples = 0, filter = 0, units = 0;
    bg_domain dom = {{0, 0, 0}, 0};
    if (!PyArg_ParseTuple(args, "ssiiiifffffiiiiiiiiiO(iii)I|iiii", &input, &path, &width, &height,
                          &function, &octaves, &lac, &gain, &amp, &freq, &step, &gradient,
                          &method, &space, &padding, &tangents, &green_down, &recompute, &depth,
                          &threads, &cb, &dom.period[0], &dom.period[1], &dom.period[2],
                          &dom.seed, &only_tile, &samples, &filter, &units))
        return NULL;
    bgt_height h;
    height_from_args(&h, function, octaves, lac, gain, amp, freq, gradient, step, dom);
    bgt_mesh_opts o;
    memset(&o, 0, sizeof o);
    o.input = input;
    o.bake_path = path;
    o.height = &h;
    o.method = (bg_perturb_method)method;
    o.threads = threads;
    o.join = BG_MESH_JOIN_AUTO;
    o.recompute_normals = recompute;
    o.bake.width = width;
    o.bake.height = height;
    o.bake.space = (mesh_bake_space)space;
    o.bake.padding = padding;
    o.bake.tangents = (mesh_tangent_source)tangents;
    o.bake.green_down = green_down;
    o.bake.only_tile = only_tile;
    o.bake.samples = samples;
    o.bake.filter = (mesh_bake_filter)filter;
    o.units = units;
    o.bake_depth = depth;
    bgt_mesh_result r;
    if (call_tool(run_mesh, &o, &r, cb, &o.progress))
        return NULL;
    PyObject *tiles = PyList_New((Py_ssize_t)r.bake.tiles);
    if (!tiles)
        return NULL;
    for (size_t i = 0; i < r.bake.tiles; i++)
        PyList_SET_ITEM(tiles, (Py_ssize_t)i, PyLong_FromLong(r.bake.tile_udim[i]));
    return Py_BuildValue("(nnnnN)", (Py_ssize_t)r.bake.covered, (Py_ssize_t)r.bake.padded,
                         (Py_ssize_t)r.bake.skipped, (Py_ssize_t)r.bake.islands, tiles);
}

/* read_image(path) -> float32 array (height, width, channels), as the file holds it
 * (8/16-bit integers mapped to [0, 1]). */
static PyObject *py_read_image(PyObject *self, PyObject *args)
{
    (void)self;
    const char *path;
    if (!PyArg_ParseTuple(args, "s", &path))
        return NULL;
    bg_image img;
    memset(&img, 0, sizeof img);
    image_io io = {.path = path, .img = &img};
    if (call_tool(run_read_image, &io, NULL, Py_None, NULL))
        return NULL;
    npy_intp dims[3] = {img.height, img.width, img.channels};
    PyObject *a = PyArray_SimpleNew(3, dims, NPY_FLOAT32);
    if (a)
        memcpy(PyArray_DATA((PyArrayObject *)a), img.pixels,
               (size_t)img.width * (size_t)img.height * (size_t)img.channels * sizeof(float));
    bg_image_free(&img);
    return a;
}

/* write_image(path, array float32 (h, w, c) C-contiguous, pixel type, srgb) */
static PyObject *py_write_image(PyObject *self, PyObject *args)
{
    (void)self;
    const char *path;
    PyObject *o;
    int type, srgb;
    if (!PyArg_ParseTuple(args, "sOii", &path, &o, &type, &srgb))
        return NULL;
    if (!PyArray_Check(o) || PyArray_TYPE((PyArrayObject *)o) != NPY_FLOAT32 ||
        PyArray_NDIM((PyArrayObject *)o) != 3 || !PyArray_ISCARRAY_RO((PyArrayObject *)o)) {
        PyErr_SetString(PyExc_TypeError, "bumpgrad: internal: write_image needs a C-contiguous "
                                         "float32 (h, w, c) array");
        return NULL;
    }
    PyArrayObject *a = (PyArrayObject *)o;
    bg_image img = {.width = (int)PyArray_DIM(a, 1), .height = (int)PyArray_DIM(a, 0),
                    .channels = (int)PyArray_DIM(a, 2), .pixels = PyArray_DATA(a)};
    image_io io = {.path = path, .img = &img, .type = (bg_pixel_type)type, .srgb = srgb};
    if (call_tool(run_write_image, &io, NULL, Py_None, NULL))
        return NULL;
    Py_RETURN_NONE;
}

/* heightmap(input, output, gray, strength, wrap, y_down, to_derivative, bits) */
static PyObject *py_heightmap(PyObject *self, PyObject *args)
{
    (void)self;
    bgt_heightmap_opts o;
    memset(&o, 0, sizeof o);
    int gray;
    if (!PyArg_ParseTuple(args, "ssifiiii", &o.input, &o.output, &gray, &o.strength, &o.wrap,
                          &o.y_down, &o.to_derivative, &o.bits))
        return NULL;
    o.gray = (bgt_gray)gray;
    if (call_tool(run_heightmap, &o, NULL, Py_None, NULL))
        return NULL;
    Py_RETURN_NONE;
}

/* volume_bake(output, x0, y0, z0, x1, y1, z1, voxel, band (cx, cy, cz, r, w) | None, function,
 *             octaves, lacunarity, gain, amplitude, frequency, step, gradient, threads,
 *             progress|None, (px, py, pz), seed) -> (voxels, (lo), (hi)) */
static PyObject *py_volume_bake(PyObject *self, PyObject *args)
{
    (void)self;
    bgt_volume_opts o;
    memset(&o, 0, sizeof o);
    PyObject *band, *cb;
    int function, octaves, gradient;
    float lac, gain, amp, freq, step;
    bg_domain dom = {{0, 0, 0}, 0};
    if (!PyArg_ParseTuple(args, "sdddddddOiifffffiiO(iii)I|ii", &o.output, &o.bbox[0], &o.bbox[1],
                          &o.bbox[2], &o.bbox[3], &o.bbox[4], &o.bbox[5], &o.voxel, &band,
                          &function, &octaves, &lac, &gain, &amp, &freq, &step, &gradient,
                          &o.threads, &cb, &dom.period[0], &dom.period[1], &dom.period[2],
                          &dom.seed, &o.brick, &o.bricks))
        return NULL;
    if (band != Py_None) {
        if (!PyArg_ParseTuple(band, "ddddd", &o.band[0], &o.band[1], &o.band[2], &o.band[3],
                              &o.band[4]))
            return NULL;
        o.have_band = 1;
    }
    bgt_height h;
    height_from_args(&h, function, octaves, lac, gain, amp, freq, gradient, step, dom);
    o.height = &h;
    bgt_volume_result r;
    if (call_tool(run_volume, &o, &r, cb, &o.progress))
        return NULL;
    return Py_BuildValue("(K(LLL)(LLL))", (unsigned long long)r.voxels, r.lo[0], r.lo[1], r.lo[2],
                         r.hi[0], r.hi[1], r.hi[2]);
}

/* vdb_merge(output, [brick paths]): bg_vdb_merge (volume --merge). */
static PyObject *py_vdb_merge(PyObject *self, PyObject *args)
{
    (void)self;
    const char *output;
    PyObject *list;
    if (!PyArg_ParseTuple(args, "sO!", &output, &PyList_Type, &list))
        return NULL;
    Py_ssize_t n = PyList_GET_SIZE(list);
    const char **paths = PyMem_Calloc(n ? (size_t)n : 1, sizeof *paths);
    if (!paths)
        return PyErr_NoMemory();
    for (Py_ssize_t i = 0; i < n; i++) {
        paths[i] = PyUnicode_AsUTF8(PyList_GET_ITEM(list, i));
        if (!paths[i]) {
            PyMem_Free(paths);
            return NULL;
        }
    }
    char msg[1024];
    bg_status s;
    Py_BEGIN_ALLOW_THREADS
    s = bg_vdb_merge(paths, (size_t)n, output, msg, sizeof msg);
    Py_END_ALLOW_THREADS
    PyMem_Free(paths);
    if (s != BG_OK) {
        bgt_err e;
        bgt_fail(&e, s, "%s", msg);
        return raise_tool(s, &e);
    }
    Py_RETURN_NONE;
}

/* The tools' height source (height_source.h) on SoA points, over threads. */
static void height_field_range(const job *j, size_t b, size_t e)
{
    bgt_height_gradient(j->aux[0], (float *)j->in[0] + b, (float *)j->in[1] + b,
                        (float *)j->in[2] + b, e - b, (float *)j->out[0] + b,
                        (float *)j->out[1] + b, (float *)j->out[2] + b, (float *)j->out[3] + b);
}

/* height_field(function, octaves, lacunarity, gain, amplitude, frequency, step, gradient,
 *              threads, x, y, z, height, gx, gy, gz, (px, py, pz), seed):
 * bgt_height_gradient, the function `bumpgrad volume` bakes (the fractal height; no grid). */
static PyObject *py_height_field(PyObject *self, PyObject *args)
{
    (void)self;
    int function, octaves, gradient, threads;
    float lac, gain, amp, freq, step;
    PyObject *o[7];
    bg_domain dom = {{0, 0, 0}, 0};
    if (!PyArg_ParseTuple(args, "iifffffiiOOOOOOO(iii)I", &function, &octaves, &lac, &gain, &amp,
                          &freq, &step, &gradient, &threads, &o[0], &o[1], &o[2], &o[3], &o[4],
                          &o[5], &o[6], &dom.period[0], &dom.period[1], &dom.period[2],
                          &dom.seed))
        return NULL;
    bgt_height h;
    height_from_args(&h, function, octaves, lac, gain, amp, freq, gradient, step, dom);
    bgt_err e;
    bgt_err_clear(&e);
    bg_status s = bgt_height_open(&h, &e);
    if (s != BG_OK)
        return raise_tool(s, &e);
    job j = {.run = height_field_range};
    j.aux[0] = &h;
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    PyObject *r = NULL;
    if (getn(&B, o, j.in, 3, 'f', &n, 0, 0) && getn(&B, o + 3, j.out, 4, 'f', &n, 1, 0))
        r = finish(&B, &j, n, threads);
    else
        release(&B);
    bgt_height_close(&h);
    return r;
}

/* vdb_sample(path, grid|None, x, y, z, height) float32: bg_vdb_height_sample_batch. */
static PyObject *py_vdb_sample(PyObject *self, PyObject *args)
{
    (void)self;
    const char *path, *grid;
    PyObject *o[4];
    if (!PyArg_ParseTuple(args, "szOOOO", &path, &grid, &o[0], &o[1], &o[2], &o[3]))
        return NULL;
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    void *in[3], *out[1];
    if (!getn(&B, o, in, 3, 'f', &n, 0, 0) || !getn(&B, o + 3, out, 1, 'f', &n, 1, 0)) {
        release(&B);
        return NULL;
    }
    bgt_err e;
    bgt_err_clear(&e);
    bg_status s;
    Py_BEGIN_ALLOW_THREADS
    bg_vdb_height *v = NULL;
    s = bgt_io_ready(&e);
    if (s == BG_OK)
        s = bg_vdb_height_open(path, grid, &v, e.msg, sizeof e.msg);
    if (s == BG_OK) {
        bg_vdb_height_sample_batch(v, in[0], in[1], in[2], (size_t)n, out[0], NULL, NULL, NULL);
        bg_vdb_height_close(v);
    }
    Py_END_ALLOW_THREADS
    release(&B);
    if (s != BG_OK)
        return raise_tool(s, &e);
    Py_RETURN_NONE;
}

/* render(output, scene, mesh|None, width, height, ss, method, function, octaves, lacunarity,
 *        gain, amplitude, frequency, step, gradient, (px, py, pz), seed, threads,
 *        progress|None) -> (out_width, out_height, tracer, triangles):
 * bgt_render_run writing `output` (a float file for the array form). */
static PyObject *py_render(PyObject *self, PyObject *args)
{
    (void)self;
    const char *output, *scene, *mesh, *method;
    int width, height, ss, function, octaves, gradient, threads;
    float lac, gain, amp, freq, step;
    int period[3];
    unsigned int seed;
    PyObject *cb;
    if (!PyArg_ParseTuple(args, "ssziiisiifffffi(iii)IiO", &output, &scene, &mesh, &width,
                          &height, &ss, &method, &function, &octaves, &lac, &gain, &amp, &freq,
                          &step, &gradient, &period[0], &period[1], &period[2], &seed, &threads,
                          &cb))
        return NULL;
    render_opts o;
    render_opts_default(&o);
    render_shape shape;
    if (render_shape_parse(scene, &shape) != 0) {
        PyErr_Format(PyExc_ValueError, "scene must be 'sphere', 'blob' or 'torus', got '%s'",
                     scene);
        return NULL;
    }
    render_method m;
    if (render_method_parse(method, &m) != 0) {
        PyObject *names = PyList_New(0);
        for (int i = 0; names && i < RENDER_METHOD_COUNT; i++) {
            PyObject *n = PyUnicode_FromString(render_method_name((render_method)i));
            if (!n || PyList_Append(names, n) < 0) {
                Py_XDECREF(n);
                Py_CLEAR(names);
            }
            Py_XDECREF(n);
        }
        if (names) {
            PyErr_Format(PyExc_ValueError, "method must be one of %R, got '%s'", names, method);
            Py_DECREF(names);
        }
        return NULL;
    }
    o.shape = shape;
    o.mesh_path = mesh;
    o.width = width;
    o.height = height;
    o.ss = ss;
    o.nmethods = 1;
    o.methods[0] = m;
    o.output = output;
    o.threads = threads;
    bg_domain dom = {{period[0], period[1], period[2]}, seed};
    height_from_args(&o.h, function, octaves, lac, gain, amp, freq, gradient, step, dom);
    render_result r;
    memset(&r, 0, sizeof r);
    if (call_tool(run_render, &o, &r, cb, &o.progress))
        return NULL;
    return Py_BuildValue("(iisn)", r.out_width, r.out_height, r.tracer ? r.tracer : "",
                         (Py_ssize_t)r.triangles);
}

#define TOOLS_PY_METHODS                                                                          \
    {"mesh_bake", py_mesh_bake, METH_VARARGS, NULL},                                              \
        {"read_image", py_read_image, METH_VARARGS, NULL},                                        \
        {"write_image", py_write_image, METH_VARARGS, NULL},                                      \
        {"heightmap", py_heightmap, METH_VARARGS, NULL},                                          \
        {"volume_bake", py_volume_bake, METH_VARARGS, NULL},                                      \
        {"vdb_merge", py_vdb_merge, METH_VARARGS, NULL},                                          \
        {"vdb_sample", py_vdb_sample, METH_VARARGS, NULL},                                        \
        {"height_field", py_height_field, METH_VARARGS, NULL},                                    \
        {"render", py_render, METH_VARARGS, NULL},
