/* SPDX-License-Identifier: MIT */
/* The private C extension under the `bumpgrad` Python package (python/bumpgrad/
 * __init__.py is the public face). It only calls: the Python layer checks shapes
 * and dtypes, and hands over 1-D C-contiguous float32 or float64 buffers of equal
 * length (numpy arrays, through the buffer protocol). Each call releases the GIL
 * around the C library and converts a bg_status into bumpgrad.Error.
 *
 * Why a C extension rather than ctypes or cffi: the measured per-call overhead
 * (docs/PYTHON.md) is 2.7 us against 19 us (ctypes) and 13 us (cffi ABI) for a
 * one-point call, and the framework's single-point functions (tangent- and
 * object-space normals, triplanar, the double entry points) need a C loop anyway
 * to be usable on arrays. The extension links the shared libbumpgrad and finds
 * it through an $ORIGIN-relative rpath (python/meson.build).
 *
 * Loops over the single-point functions give the same bits as the C API called
 * point by point; the float batch calls are used where the library has them
 * (same bits as the single-point functions, noise.h). */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <string.h>

#include "bumpgrad.h"

static PyObject *error_type; /* bumpgrad.Error, set by _set_error_type */

/* Raise bumpgrad.Error(status, text). */
static PyObject *raise_status(bg_status s, const char *what)
{
    PyObject *type = error_type ? error_type : PyExc_RuntimeError;
    PyObject *args = Py_BuildValue("(iss)", (int)s, bg_status_string(s), what ? what : "");
    if (args) {
        PyErr_SetObject(type, args);
        Py_DECREF(args);
    }
    return NULL;
}

/* ---- buffers ---------------------------------------------------------------- */

#define MAXBUF 16
typedef struct bufs {
    Py_buffer b[MAXBUF];
    int count;
} bufs;

static void release(bufs *B)
{
    for (int i = 0; i < B->count; i++)
        PyBuffer_Release(&B->b[i]);
    B->count = 0;
}

/* A 1-D C-contiguous buffer of `fmt` ('f' or 'd') and length n (n < 0: take its
 * length into *n). None gives NULL when `optional`. Returns the data pointer or
 * NULL with an exception set (or NULL and no exception for an optional None). */
static void *get(bufs *B, PyObject *o, char fmt, Py_ssize_t *n, int writable, int optional)
{
    if (o == Py_None && optional)
        return NULL;
    if (B->count >= MAXBUF) {
        PyErr_SetString(PyExc_RuntimeError, "bumpgrad: too many buffers");
        return NULL;
    }
    Py_buffer *b = &B->b[B->count];
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(o, b, flags) != 0)
        return NULL;
    B->count++;
    const size_t item = fmt == 'd' ? sizeof(double) : sizeof(float);
    if (b->ndim > 1 || !b->format || strlen(b->format) != 1 || b->format[0] != fmt ||
        (size_t)b->itemsize != item) {
        PyErr_Format(PyExc_TypeError, "bumpgrad: internal: expected a 1-D %s buffer",
                     fmt == 'd' ? "float64" : "float32");
        return NULL;
    }
    Py_ssize_t len = b->len / b->itemsize;
    if (*n < 0)
        *n = len;
    else if (len != *n) {
        PyErr_SetString(PyExc_ValueError, "bumpgrad: internal: buffer lengths differ");
        return NULL;
    }
    return b->buf;
}

/* The end of every batch call: the buffers released; None, or NULL (!ok) with
 * the Python error already set. */
static PyObject *done(bufs *B, int ok)
{
    release(B);
    if (!ok)
        return NULL;
    Py_RETURN_NONE;
}

/* Fetch k required buffers into ptrs. */
static int getn(bufs *B, PyObject **objs, void **ptrs, int k, char fmt, Py_ssize_t *n,
                int writable)
{
    for (int i = 0; i < k; i++) {
        ptrs[i] = get(B, objs[i], fmt, n, writable, 0);
        if (!ptrs[i])
            return 0;
    }
    return 1;
}

/* The buffers of a batch call, in argument order: k inputs, one optional output
 * (None gives NULL) and nout outputs, all of one length *n. 0 with the Python
 * error set. */
static int get_batch(bufs *B, PyObject **objs, int k, char fmt, Py_ssize_t *n, void **in,
                     void **opt, void **out, int nout)
{
    if (!getn(B, objs, in, k, fmt, n, 0))
        return 0;
    *opt = get(B, objs[k], fmt, n, 1, 1);
    if (PyErr_Occurred())
        return 0;
    return getn(B, objs + k + 1, out, nout, fmt, n, 1);
}

static int parse_fractal(int function, int octaves, float lacunarity, float gain, bg_fractal *f)
{
    f->function = (bg_function)function;
    f->octaves = octaves;
    f->lacunarity = lacunarity;
    f->gain = gain;
    bg_status s = bg_fractal_validate(f);
    if (s != BG_OK) {
        raise_status(s, "fractal parameters (octaves 1..32, lacunarity finite and > 0, gain finite)");
        return 0;
    }
    return 1;
}

/* ---- noise and fractals ---------------------------------------------------------- */

/* fractal(double, function, octaves, lacunarity, gain, mode, step, x, y, z,
 *         value|None, gx|None, gy, gz)   mode 0: value only, 1: analytic, 2: central */
static PyObject *py_fractal(PyObject *self, PyObject *args)
{
    (void)self;
    int dbl, function, octaves, mode;
    float lac, gain;
    double step;
    PyObject *o[7];
    if (!PyArg_ParseTuple(args, "piiffidOOOOOOO", &dbl, &function, &octaves, &lac, &gain, &mode,
                          &step, &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &o[6]))
        return NULL;
    bg_fractal f;
    if (!parse_fractal(function, octaves, lac, gain, &f))
        return NULL;
    if (mode == 2 && !(step > 0.0 && step < 1e30))
        return raise_status(BG_ERR_INVALID_ARGUMENT, "central-difference step must be > 0");
    const char fmt = dbl ? 'd' : 'f';
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    void *p[3], *v = NULL, *g[3] = {NULL, NULL, NULL};
    if (!get_batch(&B, o, 3, fmt, &n, p, &v, g, mode != 0 ? 3 : 0))
        goto fail;
    const size_t N = (size_t)n;
    Py_BEGIN_ALLOW_THREADS
    if (!dbl) {
        const float *x = p[0], *y = p[1], *z = p[2];
        if (mode == 0 && function == BG_FUNC_NOISE)
            bg_noise3_batch(x, y, z, N, v);
        else if (mode == 0)
            bg_fractal3_batch(&f, x, y, z, N, v);
        else if (mode == 1 && function == BG_FUNC_NOISE)
            bg_noise3_grad_batch(x, y, z, N, v, g[0], g[1], g[2]);
        else if (mode == 1)
            bg_fractal3_grad_batch(&f, x, y, z, N, v, g[0], g[1], g[2]);
        else
            bg_fractal3_grad_central_batch(&f, (float)step, x, y, z, N, v, g[0], g[1], g[2]);
    } else {
        const double *x = p[0], *y = p[1], *z = p[2];
        double *val = v, *gx = g[0], *gy = g[1], *gz = g[2];
        for (size_t i = 0; i < N; i++) {
            bg_dvec3 d;
            double r;
            if (mode == 0) {
                r = function == BG_FUNC_NOISE ? bg_noise3d(x[i], y[i], z[i])
                                              : bg_fractal3d(&f, x[i], y[i], z[i]);
            } else {
                if (mode == 1)
                    r = function == BG_FUNC_NOISE ? bg_noise3d_grad(x[i], y[i], z[i], &d)
                                                  : bg_fractal3d_grad(&f, x[i], y[i], z[i], &d);
                else
                    r = bg_fractal3d_grad_central(&f, step, x[i], y[i], z[i], &d);
                gx[i] = d.x;
                gy[i] = d.y;
                gz[i] = d.z;
            }
            if (val)
                val[i] = r;
        }
    }
    Py_END_ALLOW_THREADS
    return done(&B, 1);
fail:
    return done(&B, 0);
}

/* footprint(function, octaves, lacunarity, gain, fp, x, y, z, value|None, gx, gy, gz) float32 */
static PyObject *py_footprint(PyObject *self, PyObject *args)
{
    (void)self;
    int function, octaves;
    float lac, gain;
    PyObject *o[8];
    if (!PyArg_ParseTuple(args, "iiffOOOOOOOO", &function, &octaves, &lac, &gain, &o[0], &o[1],
                          &o[2], &o[3], &o[4], &o[5], &o[6], &o[7]))
        return NULL;
    bg_fractal f;
    if (!parse_fractal(function, octaves, lac, gain, &f))
        return NULL;
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    void *p[4], *v = NULL, *g[3];
    if (!get_batch(&B, o, 4, 'f', &n, p, &v, g, 3))
        goto fail;
    Py_BEGIN_ALLOW_THREADS
    bg_fractal3_grad_footprint_batch(&f, p[0], p[1], p[2], p[3], (size_t)n, v, g[0], g[1], g[2]);
    Py_END_ALLOW_THREADS
    return done(&B, 1);
fail:
    return done(&B, 0);
}

/* octaves(kind, footprint, out, lacunarity, octave|max_octaves): kind 0 bg_octave_weight,
 * 1 bg_octaves_for_footprint (float32) */
static PyObject *py_octaves(PyObject *self, PyObject *args)
{
    (void)self;
    int kind, k;
    float lac;
    PyObject *o[2];
    if (!PyArg_ParseTuple(args, "iOOfi", &kind, &o[0], &o[1], &lac, &k))
        return NULL;
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    const float *fp = get(&B, o[0], 'f', &n, 0, 0);
    float *out = fp ? get(&B, o[1], 'f', &n, 1, 0) : NULL;
    if (!out) {
        return done(&B, 0);
    }
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < n; i++)
        out[i] = kind == 0 ? bg_octave_weight(fp[i], lac, k) : bg_octaves_for_footprint(fp[i], k);
    Py_END_ALLOW_THREADS
    return done(&B, 1);
}

/* ---- surface gradient and perturbation ------------------------------------------------ */

#define V3(a, i) {(a)[0][i], (a)[1][i], (a)[2][i]}
#define PUT3(a, i, r) ((a)[0][i] = (r).x, (a)[1][i] = (r).y, (a)[2][i] = (r).z)

/* vec(op, double, a3..., out3): two-vector operations
 *   op 0: surface gradient (n, g); 1..3: perturb method op-1 (n, g);
 *   4: from_tangent_normal (t, b, m) [three inputs]; 5: from_perturbed_normal (n, m);
 *   6: resolve (n, s) */
static PyObject *py_vec(PyObject *self, PyObject *args)
{
    (void)self;
    int op, dbl;
    PyObject *o[12];
    if (!PyArg_ParseTuple(args, "ipOOOOOOOOOOOO", &op, &dbl, &o[0], &o[1], &o[2], &o[3], &o[4],
                          &o[5], &o[6], &o[7], &o[8], &o[9], &o[10], &o[11]))
        return NULL;
    const int nin = op == 4 ? 9 : 6;
    if (op < 0 || op > 6)
        return raise_status(BG_ERR_INVALID_ARGUMENT, "operation");
    const char fmt = dbl ? 'd' : 'f';
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    void *in[9], *out[3];
    if (!getn(&B, o, in, nin, fmt, &n, 0) || !getn(&B, o + 9, out, 3, fmt, &n, 1)) {
        return done(&B, 0);
    }
    const size_t N = (size_t)n;
    Py_BEGIN_ALLOW_THREADS
    if (!dbl) {
        float *a[3] = {in[0], in[1], in[2]}, *b[3] = {in[3], in[4], in[5]};
        float *c[3] = {in[6], in[7], in[8]}, *r[3] = {out[0], out[1], out[2]};
        if (op >= 1 && op <= 3)
            bg_perturb_batch((bg_perturb_method)(op - 1), a[0], a[1], a[2], b[0], b[1], b[2], N,
                             r[0], r[1], r[2]);
        else if (op == 6)
            bg_resolve_normal_batch(a[0], a[1], a[2], b[0], b[1], b[2], N, r[0], r[1], r[2]);
        else
            for (size_t i = 0; i < N; i++) {
                bg_vec3 A = V3(a, i), Bv = V3(b, i), R;
                if (op == 0)
                    R = bg_surface_gradient(A, Bv);
                else if (op == 4) {
                    bg_vec3 C = V3(c, i);
                    R = bg_surfgrad_from_tangent_normal(A, Bv, C);
                } else
                    R = bg_surfgrad_from_perturbed_normal(A, Bv);
                PUT3(r, i, R);
            }
    } else {
        double *a[3] = {in[0], in[1], in[2]}, *b[3] = {in[3], in[4], in[5]};
        double *c[3] = {in[6], in[7], in[8]}, *r[3] = {out[0], out[1], out[2]};
        for (size_t i = 0; i < N; i++) {
            bg_dvec3 A = V3(a, i), Bv = V3(b, i), R;
            if (op == 0)
                R = bg_surface_gradientd(A, Bv);
            else if (op <= 3)
                R = bg_perturbd((bg_perturb_method)(op - 1), A, Bv);
            else if (op == 4) {
                bg_dvec3 C = V3(c, i);
                R = bg_surfgrad_from_tangent_normald(A, Bv, C);
            } else if (op == 5)
                R = bg_surfgrad_from_perturbed_normald(A, Bv);
            else
                R = bg_resolve_normald(A, &Bv, NULL, 1);
            PUT3(r, i, R);
        }
    }
    Py_END_ALLOW_THREADS
    return done(&B, 1);
}

/* accumulate(weight, gx, gy, gz, ax, ay, az): a += weight * g, float32 */
static PyObject *py_accumulate(PyObject *self, PyObject *args)
{
    (void)self;
    float w;
    PyObject *o[6];
    if (!PyArg_ParseTuple(args, "fOOOOOO", &w, &o[0], &o[1], &o[2], &o[3], &o[4], &o[5]))
        return NULL;
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    void *g[3], *a[3];
    if (!getn(&B, o, g, 3, 'f', &n, 0) || !getn(&B, o + 3, a, 3, 'f', &n, 1)) {
        return done(&B, 0);
    }
    Py_BEGIN_ALLOW_THREADS
    bg_surfgrad_accumulate_batch(w, g[0], g[1], g[2], (size_t)n, a[0], a[1], a[2]);
    Py_END_ALLOW_THREADS
    return done(&B, 1);
}

/* triplanar(double, k, nx, ny, nz, d_yz.x, .y, d_xz.x, .y, d_xy.x, .y, ox, oy, oz)
 * With the six derivative arguments None: the weights. */
static PyObject *py_triplanar(PyObject *self, PyObject *args)
{
    (void)self;
    int dbl;
    double k;
    PyObject *o[12];
    if (!PyArg_ParseTuple(args, "pdOOOOOOOOOOOO", &dbl, &k, &o[0], &o[1], &o[2], &o[3], &o[4],
                          &o[5], &o[6], &o[7], &o[8], &o[9], &o[10], &o[11]))
        return NULL;
    const char fmt = dbl ? 'd' : 'f';
    const int weights_only = o[3] == Py_None;
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    void *nn[3], *d[6] = {NULL}, *r[3];
    if (!getn(&B, o, nn, 3, fmt, &n, 0) || (!weights_only && !getn(&B, o + 3, d, 6, fmt, &n, 0)) ||
        !getn(&B, o + 9, r, 3, fmt, &n, 1)) {
        return done(&B, 0);
    }
    const size_t N = (size_t)n;
    Py_BEGIN_ALLOW_THREADS
    if (!dbl) {
        float *a[3] = {nn[0], nn[1], nn[2]}, *q[6], *out[3] = {r[0], r[1], r[2]};
        memcpy(q, d, sizeof q);
        for (size_t i = 0; i < N; i++) {
            bg_vec3 A = V3(a, i), R;
            if (weights_only)
                R = bg_triplanar_weights(A, (float)k);
            else {
                bg_vec2 yz = {q[0][i], q[1][i]}, xz = {q[2][i], q[3][i]}, xy = {q[4][i], q[5][i]};
                R = bg_surfgrad_triplanar(A, (float)k, yz, xz, xy);
            }
            PUT3(out, i, R);
        }
    } else {
        double *a[3] = {nn[0], nn[1], nn[2]}, *q[6], *out[3] = {r[0], r[1], r[2]};
        memcpy(q, d, sizeof q);
        for (size_t i = 0; i < N; i++) {
            bg_dvec3 A = V3(a, i), R;
            if (weights_only)
                R = bg_triplanar_weightsd(A, k);
            else {
                bg_dvec2 yz = {q[0][i], q[1][i]}, xz = {q[2][i], q[3][i]}, xy = {q[4][i], q[5][i]};
                R = bg_surfgrad_triplanard(A, k, yz, xz, xy);
            }
            PUT3(out, i, R);
        }
    }
    Py_END_ALLOW_THREADS
    return done(&B, 1);
}

/* perturb_height(function, octaves, lacunarity, gain, amplitude, frequency, gradient, step,
 *                method, px, py, pz, nx, ny, nz, height|None, ox, oy, oz, footprint|None) */
static PyObject *py_perturb_height(PyObject *self, PyObject *args)
{
    (void)self;
    int function, octaves, gradient, method;
    float lac, gain, amp, freq, step;
    PyObject *o[11];
    if (!PyArg_ParseTuple(args, "iiffffifiOOOOOOOOOOO", &function, &octaves, &lac, &gain, &amp,
                          &freq, &gradient, &step, &method, &o[0], &o[1], &o[2], &o[3], &o[4],
                          &o[5], &o[6], &o[7], &o[8], &o[9], &o[10]))
        return NULL;
    bg_height h = bg_height_default();
    h.fractal.function = (bg_function)function;
    h.fractal.octaves = octaves;
    h.fractal.lacunarity = lac;
    h.fractal.gain = gain;
    h.amplitude = amp;
    h.frequency = freq;
    h.gradient = (bg_gradient_mode)gradient;
    h.step = step;
    bg_status s = bg_height_validate(&h);
    if (s != BG_OK)
        return raise_status(s, "height parameters");
    if (method < 0 || method > 2)
        return raise_status(BG_ERR_INVALID_ARGUMENT, "perturbation method");
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    void *in[6], *hv = NULL, *out[3], *fp;
    if (!get_batch(&B, o, 6, 'f', &n, in, &hv, out, 3))
        goto fail;
    fp = get(&B, o[10], 'f', &n, 0, 1);
    if (PyErr_Occurred())
        goto fail;
    Py_BEGIN_ALLOW_THREADS
    if (fp)
        bg_perturb_height_footprint_batch(&h, (bg_perturb_method)method, fp, in[0], in[1], in[2],
                                          in[3], in[4], in[5], (size_t)n, hv, out[0], out[1],
                                          out[2]);
    else
        bg_perturb_height_batch(&h, (bg_perturb_method)method, in[0], in[1], in[2], in[3], in[4],
                                in[5], (size_t)n, hv, out[0], out[1], out[2]);
    Py_END_ALLOW_THREADS
    return done(&B, 1);
fail:
    return done(&B, 0);
}

/* ---- ISA and version --------------------------------------------------------------------- */

static PyObject *py_isa(PyObject *self, PyObject *args)
{
    (void)self;
    const char *what, *name = NULL;
    if (!PyArg_ParseTuple(args, "s|z", &what, &name))
        return NULL;
    if (strcmp(what, "best") == 0)
        return PyUnicode_FromString(bg_isa_name(bg_isa_best()));
    if (strcmp(what, "active") == 0)
        return PyUnicode_FromString(bg_isa_name(bg_isa_active()));
    if (strcmp(what, "force") == 0 && name) {
        bg_isa isa;
        bg_status s = bg_isa_parse(name, &isa);
        if (s == BG_OK)
            s = bg_isa_force(isa);
        if (s != BG_OK)
            return raise_status(s, name);
        Py_RETURN_NONE;
    }
    return raise_status(BG_ERR_INVALID_ARGUMENT, what);
}

static PyObject *py_version(PyObject *self, PyObject *args)
{
    (void)self;
    (void)args;
    return PyUnicode_FromString(bg_version_string());
}

static PyObject *py_status_string(PyObject *self, PyObject *args)
{
    (void)self;
    int s;
    if (!PyArg_ParseTuple(args, "i", &s))
        return NULL;
    return PyUnicode_FromString(bg_status_string((bg_status)s));
}

static PyObject *py_set_error_type(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *t;
    if (!PyArg_ParseTuple(args, "O", &t))
        return NULL;
    Py_XDECREF(error_type);
    Py_INCREF(t);
    error_type = t;
    Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"fractal", py_fractal, METH_VARARGS, NULL},
    {"footprint", py_footprint, METH_VARARGS, NULL},
    {"octaves", py_octaves, METH_VARARGS, NULL},
    {"vec", py_vec, METH_VARARGS, NULL},
    {"accumulate", py_accumulate, METH_VARARGS, NULL},
    {"triplanar", py_triplanar, METH_VARARGS, NULL},
    {"perturb_height", py_perturb_height, METH_VARARGS, NULL},
    {"isa", py_isa, METH_VARARGS, NULL},
    {"version", py_version, METH_NOARGS, NULL},
    {"status_string", py_status_string, METH_VARARGS, NULL},
    {"_set_error_type", py_set_error_type, METH_VARARGS, NULL},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_bumpgrad",
    "Private calls into libbumpgrad; use the bumpgrad package.", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__bumpgrad(void)
{
    return PyModule_Create(&module);
}
