/* SPDX-License-Identifier: MIT */
/* The private C extension under the `bumpgrad` Python package (python/bumpgrad/
 * __init__.py is the public face). The Python layer checks arguments,
 * broadcasts and converts; it hands over 1-D C-contiguous float32 or float64
 * buffers of one length, and this file calls the library on them, split into
 * blocks of BLOCK points over `threads` threads (run_blocks). Each point is
 * computed on its own, so the result has the same bits for any thread count.
 * The GIL is released while the blocks run; the calling thread takes it back
 * after each of its blocks to run Python's signal handlers (a Ctrl-C stops the
 * call between blocks with KeyboardInterrupt).
 *
 * One exception to "Python checks first": noise3 itself is the C function
 * py_noise3 (METH_FASTCALL), so that a call on a small (..., 3) float32 or
 * float64 array costs well under a microsecond. Anything else it is given
 * (keywords, lists, tuples, large arrays) goes to the Python implementation
 * registered by __init__.py, unchanged.
 *
 * Why a C extension rather than ctypes or cffi: the measured per-call overhead
 * (docs/PYTHON.md). libbumpgrad and the tools library are linked statically
 * (python/bumpgrad/meson.build), so the installed package carries them. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "bumpgrad.h"

static PyObject *error_type;    /* bumpgrad.Error, set by _set_error_type */
static PyObject *noise3_slow;   /* the Python implementation of noise3 */
#define NMETHODS 24
static PyMethodDef methods[NMETHODS]; /* methods[0] is noise3 */

/* Parameter errors the Python layer did not catch (e.g. an octave scale that
 * overflows) are ValueErrors; everything else is bumpgrad.Error(status, text, what). */
static PyObject *raise_status(bg_status s, const char *what)
{
    if (s == BG_ERR_INVALID_ARGUMENT || s == BG_ERR_OVERFLOW) {
        PyErr_Format(PyExc_ValueError, "%s: %s", what ? what : "argument", bg_status_string(s));
        return NULL;
    }
    PyObject *type = error_type ? error_type : PyExc_RuntimeError;
    PyObject *args = Py_BuildValue("(iss)", (int)s, bg_status_string(s), what ? what : "");
    if (args) {
        PyErr_SetObject(type, args);
        Py_DECREF(args);
    }
    return NULL;
}

/* ---- buffers ---------------------------------------------------------------- */

#define MAXBUF 24
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
    /* A zero-length buffer may have no storage; the library reads nothing then. */
    return b->buf ? b->buf : (void *)b;
}

/* Fetch k buffers into ptrs (optional: None gives NULL). 0 with the error set. */
static int getn(bufs *B, PyObject **objs, void **ptrs, int k, char fmt, Py_ssize_t *n,
                int writable, int optional)
{
    for (int i = 0; i < k; i++) {
        ptrs[i] = get(B, objs[i], fmt, n, writable, optional);
        if (!ptrs[i] && PyErr_Occurred())
            return 0;
    }
    return 1;
}

/* ---- jobs: one call split into blocks over threads ---------------------------- */

/* Points per block: small enough that a Ctrl-C is honoured within a fraction of
 * a second even for 32-octave central differences, large enough that the SIMD
 * batches and the GIL round trip per block cost nothing measurable. */
#define BLOCK 16384

typedef struct job job;
typedef void (*range_fn)(const job *j, size_t b, size_t e);
struct job {
    range_fn run;
    int dbl, mode, function, op, method, weights_only, kind, ival;
    bg_fractal f;
    bg_domain d; /* fractal: the tileable, seeded domain (used when dom) */
    int dom;
    bg_height h;
    double step, k;
    float w, lac;
    void *in[9];
    void *out[4];
    void *aux[3]; /* footprint, per-point amplitude, per-point frequency */
    /* shared state of run_blocks */
    size_t n, nblocks;
    atomic_size_t next;
    atomic_int stop;
    atomic_int oom; /* a block could not get its scratch memory */
};

static void run_some(job *j)
{
    while (!atomic_load(&j->stop)) {
        size_t b = atomic_fetch_add(&j->next, 1);
        if (b >= j->nblocks)
            break;
        size_t e = (b + 1) * BLOCK < j->n ? (b + 1) * BLOCK : j->n;
        j->run(j, b * BLOCK, e);
    }
}

static void *worker(void *arg)
{
    run_some(arg);
    return NULL;
}

/* Run j over [0, n) with up to `threads` threads (the caller's included), GIL
 * released. 0, or -1 with the Python error set (KeyboardInterrupt or whatever a
 * signal handler raised): the call stopped between blocks. */
static int run_blocks(job *j, size_t n, int threads)
{
    if (n == 0)
        return 0;
    j->n = n;
    j->nblocks = (n + BLOCK - 1) / BLOCK;
    atomic_init(&j->next, 0);
    atomic_init(&j->stop, 0);
    if (threads < 1)
        threads = 1;
    if ((size_t)threads > j->nblocks)
        threads = (int)j->nblocks;
    if (j->nblocks == 1) {
        Py_BEGIN_ALLOW_THREADS
        j->run(j, 0, n);
        Py_END_ALLOW_THREADS
        return 0;
    }
    enum { MAXT = 256 };
    pthread_t tid[MAXT];
    int started = 0, interrupted = 0;
    if (threads > MAXT)
        threads = MAXT;
    Py_BEGIN_ALLOW_THREADS
    for (int t = 1; t < threads; t++) {
        if (pthread_create(&tid[started], NULL, worker, j) != 0)
            break; /* fewer threads; the blocks still all run */
        started++;
    }
    for (;;) {
        if (atomic_load(&j->stop))
            break;
        size_t b = atomic_fetch_add(&j->next, 1);
        if (b >= j->nblocks)
            break;
        size_t e = (b + 1) * BLOCK < n ? (b + 1) * BLOCK : n;
        j->run(j, b * BLOCK, e);
        /* Python's own SIGINT handler only sets a flag; its Python-level handler
         * (KeyboardInterrupt) runs here, with the GIL, between blocks. */
        Py_BLOCK_THREADS
        if (PyErr_CheckSignals() != 0) {
            interrupted = 1;
            atomic_store(&j->stop, 1);
        }
        Py_UNBLOCK_THREADS
    }
    for (int t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    Py_END_ALLOW_THREADS
    return interrupted ? -1 : 0;
}

/* The result of a batch call: None, or NULL with the error set. */
static PyObject *finish(bufs *B, job *j, Py_ssize_t n, int threads)
{
    int r = run_blocks(j, (size_t)n, threads);
    release(B);
    if (r != 0)
        return NULL;
    Py_RETURN_NONE;
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

#define OFF(p, T, b) ((p) ? (T *)(p) + (b) : NULL)

static void fractal_range_soa(const job *j, size_t b, size_t e);

/* Points given as one interleaved (N, 3) array (job.kind = 1, in[0]): each
 * block is split into x, y, z here, on the worker's thread, then computed as
 * SoA. The same bits as SoA input: only the layout of the input differs. */
static void fractal_range(const job *j, size_t b, size_t e)
{
    if (!j->kind) {
        fractal_range_soa(j, b, e);
        return;
    }
    const size_t N = e - b, item = j->dbl ? sizeof(double) : sizeof(float);
    char *buf = malloc(3 * N * item);
    if (!buf) {
        /* No memory for the block's copy: NaN results rather than a crash
         * (the caller's arrays are fine; this needs 3 * 16384 * 8 bytes). */
        atomic_store((atomic_int *)&j->oom, 1);
        return;
    }
    job k;
    memcpy(&k, j, sizeof k);
    k.kind = 0;
    k.in[0] = buf;
    k.in[1] = buf + N * item;
    k.in[2] = buf + 2 * N * item;
    /* The outputs shifted so that index 0 is point b: the SoA code then runs on [0, N). */
    for (int i = 0; i < 4; i++)
        if (k.out[i])
            k.out[i] = (char *)k.out[i] + b * item;
    if (j->dbl) {
        const double *p = (const double *)j->in[0] + 3 * b;
        double *x = (double *)buf, *y = x + N, *z = y + N;
        for (size_t i = 0; i < N; i++) {
            x[i] = p[3 * i];
            y[i] = p[3 * i + 1];
            z[i] = p[3 * i + 2];
        }
    } else {
        const float *p = (const float *)j->in[0] + 3 * b;
        float *x = (float *)buf, *y = x + N, *z = y + N;
        for (size_t i = 0; i < N; i++) {
            x[i] = p[3 * i];
            y[i] = p[3 * i + 1];
            z[i] = p[3 * i + 2];
        }
    }
    fractal_range_soa(&k, 0, N);
    free(buf);
}

static void fractal_range_soa(const job *j, size_t b, size_t e)
{
    const size_t N = e - b;
    const int mode = j->mode, function = j->function;
    if (!j->dbl) {
        const float *x = OFF(j->in[0], const float, b), *y = OFF(j->in[1], const float, b),
                    *z = OFF(j->in[2], const float, b);
        float *v = OFF(j->out[0], float, b), *gx = OFF(j->out[1], float, b),
              *gy = OFF(j->out[2], float, b), *gz = OFF(j->out[3], float, b);
        if (j->dom) { /* periodic noise (no seed): bg_pnoise3; else the domain fractal */
            const int pn = function == BG_FUNC_NOISE && j->d.seed == 0;
            if (mode == 0 && pn)
                bg_pnoise3_batch(j->d.period, x, y, z, N, v);
            else if (mode == 0)
                bg_fractal3_domain_batch(&j->f, &j->d, x, y, z, N, v);
            else if (mode == 1 && pn)
                bg_pnoise3_grad_batch(j->d.period, x, y, z, N, v, gx, gy, gz);
            else if (mode == 1)
                bg_fractal3_domain_grad_batch(&j->f, &j->d, x, y, z, N, v, gx, gy, gz);
            else
                bg_fractal3_domain_grad_central_batch(&j->f, &j->d, (float)j->step, x, y, z, N, v,
                                                      gx, gy, gz);
            return;
        }
        if (mode == 0 && function == BG_FUNC_NOISE)
            bg_noise3_batch(x, y, z, N, v);
        else if (mode == 0)
            bg_fractal3_batch(&j->f, x, y, z, N, v);
        else if (mode == 1 && function == BG_FUNC_NOISE)
            bg_noise3_grad_batch(x, y, z, N, v, gx, gy, gz);
        else if (mode == 1)
            bg_fractal3_grad_batch(&j->f, x, y, z, N, v, gx, gy, gz);
        else
            bg_fractal3_grad_central_batch(&j->f, (float)j->step, x, y, z, N, v, gx, gy, gz);
        return;
    }
    const double *x = j->in[0], *y = j->in[1], *z = j->in[2];
    double *val = j->out[0], *gx = j->out[1], *gy = j->out[2], *gz = j->out[3];
    for (size_t i = b; i < e; i++) {
        bg_dvec3 d;
        double r;
        if (j->dom) { /* mode 0 or 1: py_fractal refuses central differences here */
            const int pn = function == BG_FUNC_NOISE && j->d.seed == 0;
            if (mode == 0)
                r = pn ? bg_pnoise3d(x[i], y[i], z[i], j->d.period)
                       : bg_fractal3d_domain(&j->f, &j->d, x[i], y[i], z[i]);
            else {
                r = pn ? bg_pnoise3d_grad(x[i], y[i], z[i], j->d.period, &d)
                       : bg_fractal3d_domain_grad(&j->f, &j->d, x[i], y[i], z[i], &d);
                gx[i] = d.x;
                gy[i] = d.y;
                gz[i] = d.z;
            }
        } else if (mode == 0) {
            r = function == BG_FUNC_NOISE ? bg_noise3d(x[i], y[i], z[i])
                                          : bg_fractal3d(&j->f, x[i], y[i], z[i]);
        } else {
            if (mode == 1)
                r = function == BG_FUNC_NOISE ? bg_noise3d_grad(x[i], y[i], z[i], &d)
                                              : bg_fractal3d_grad(&j->f, x[i], y[i], z[i], &d);
            else
                r = bg_fractal3d_grad_central(&j->f, j->step, x[i], y[i], z[i], &d);
            gx[i] = d.x;
            gy[i] = d.y;
            gz[i] = d.z;
        }
        if (val)
            val[i] = r;
    }
}

/* fractal(double, function, octaves, lacunarity, gain, mode, step, threads, x, y, z,
 *         value|None, gx|None, gy, gz, (px, py, pz), seed)
 * mode 0: value only, 1: analytic, 2: central; a nonzero period or seed: the
 * domain calls of noise.h (bg_pnoise3* for noise without a seed). */
static PyObject *py_fractal(PyObject *self, PyObject *args)
{
    (void)self;
    int dbl, function, octaves, mode, threads;
    float lac, gain;
    double step;
    PyObject *o[7];
    bg_domain dom = {{0, 0, 0}, 0};
    if (!PyArg_ParseTuple(args, "piiffidiOOOOOOO(iii)I", &dbl, &function, &octaves, &lac, &gain,
                          &mode, &step, &threads, &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &o[6],
                          &dom.period[0], &dom.period[1], &dom.period[2], &dom.seed))
        return NULL;
    job j = {.run = fractal_range, .dbl = dbl, .mode = mode, .function = function, .step = step};
    j.d = dom;
    j.dom = dom.period[0] || dom.period[1] || dom.period[2] || dom.seed;
    if (function == BG_FUNC_NOISE && mode != 2) {
        j.f.function = BG_FUNC_NOISE; /* octaves etc. unused, but valid for a domain */
        j.f.octaves = 1;
        j.f.lacunarity = 2.0f;
        j.f.gain = 0.5f;
    } else if (!parse_fractal(function, octaves, lac, gain, &j.f))
        return NULL;
    if (j.dom && bg_domain_validate(&j.f, &j.d) != BG_OK)
        return raise_status(BG_ERR_INVALID_ARGUMENT,
                            "period (each 0..256, an integer lacunarity, and the finest octave's "
                            "period P * lacunarity^(octaves-1) at most 2^24)");
    if (j.dom && dbl && mode == 2)
        return raise_status(BG_ERR_INVALID_ARGUMENT,
                            "period/seed with gradient='central' in float64 (only the analytic "
                            "gradient over a domain in double)");
    if (mode == 2 && !(step > 0.0 && step < 1e30))
        return raise_status(BG_ERR_INVALID_ARGUMENT, "step (must be finite and > 0)");
    const char fmt = dbl ? 'd' : 'f';
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    if (o[1] == Py_None) { /* x is an interleaved (N, 3) buffer */
        Py_ssize_t n3 = -1;
        if (!getn(&B, o, j.in, 1, fmt, &n3, 0, 0)) {
            release(&B);
            return NULL;
        }
        if (n3 % 3 != 0) {
            release(&B);
            PyErr_SetString(PyExc_ValueError, "bumpgrad: internal: interleaved points not 3N long");
            return NULL;
        }
        n = n3 / 3;
        j.kind = 1;
    } else if (!getn(&B, o, j.in, 3, fmt, &n, 0, 0)) {
        release(&B);
        return NULL;
    }
    if (!getn(&B, o + 3, j.out, 1, fmt, &n, 1, 1) ||
        (mode != 0 && !getn(&B, o + 4, j.out + 1, 3, fmt, &n, 1, 0))) {
        release(&B);
        return NULL;
    }
    atomic_init(&j.oom, 0);
    PyObject *r = finish(&B, &j, n, threads);
    if (r && atomic_load(&j.oom)) {
        Py_DECREF(r);
        return PyErr_NoMemory();
    }
    return r;
}

static void footprint_range(const job *j, size_t b, size_t e)
{
    bg_fractal3_grad_footprint_batch(&j->f, OFF(j->aux[0], const float, b),
                                     OFF(j->in[0], const float, b), OFF(j->in[1], const float, b),
                                     OFF(j->in[2], const float, b), e - b,
                                     OFF(j->out[0], float, b), OFF(j->out[1], float, b),
                                     OFF(j->out[2], float, b), OFF(j->out[3], float, b));
}

/* footprint(function, octaves, lacunarity, gain, threads, fp, x, y, z, value|None, gx, gy, gz) */
static PyObject *py_footprint(PyObject *self, PyObject *args)
{
    (void)self;
    int function, octaves, threads;
    float lac, gain;
    PyObject *o[8];
    if (!PyArg_ParseTuple(args, "iiffiOOOOOOOO", &function, &octaves, &lac, &gain, &threads,
                          &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &o[6], &o[7]))
        return NULL;
    job j = {.run = footprint_range};
    if (!parse_fractal(function, octaves, lac, gain, &j.f))
        return NULL;
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    if (!getn(&B, o, j.aux, 1, 'f', &n, 0, 0) || !getn(&B, o + 1, j.in, 3, 'f', &n, 0, 0) ||
        !getn(&B, o + 4, j.out, 1, 'f', &n, 1, 1) || !getn(&B, o + 5, j.out + 1, 3, 'f', &n, 1, 0)) {
        release(&B);
        return NULL;
    }
    return finish(&B, &j, n, threads);
}

static void octaves_range(const job *j, size_t b, size_t e)
{
    const float *fp = j->in[0];
    float *out = j->out[0];
    for (size_t i = b; i < e; i++)
        out[i] = j->kind == 0 ? bg_octave_weight(fp[i], j->lac, j->ival)
                              : bg_octaves_for_footprint(fp[i], j->ival);
}

/* octaves(kind, footprint, out, lacunarity, octave|max_octaves, threads): kind 0
 * bg_octave_weight, 1 bg_octaves_for_footprint (float32) */
static PyObject *py_octaves(PyObject *self, PyObject *args)
{
    (void)self;
    int kind, k, threads;
    float lac;
    PyObject *o[2];
    if (!PyArg_ParseTuple(args, "iOOfii", &kind, &o[0], &o[1], &lac, &k, &threads))
        return NULL;
    job j = {.run = octaves_range, .kind = kind, .lac = lac, .ival = k};
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    if (!getn(&B, o, j.in, 1, 'f', &n, 0, 0) || !getn(&B, o + 1, j.out, 1, 'f', &n, 1, 0)) {
        release(&B);
        return NULL;
    }
    return finish(&B, &j, n, threads);
}

/* ---- surface gradient and perturbation ------------------------------------------------ */

#define V3(a, i) {(a)[0][i], (a)[1][i], (a)[2][i]}
#define PUT3(a, i, r) ((a)[0][i] = (r).x, (a)[1][i] = (r).y, (a)[2][i] = (r).z)

static void vec_range(const job *j, size_t b, size_t e)
{
    const int op = j->op;
    if (!j->dbl) {
        float *a[3] = {j->in[0], j->in[1], j->in[2]}, *bb[3] = {j->in[3], j->in[4], j->in[5]};
        float *c[3] = {j->in[6], j->in[7], j->in[8]}, *r[3] = {j->out[0], j->out[1], j->out[2]};
        if (op >= 1 && op <= 3)
            bg_perturb_batch((bg_perturb_method)(op - 1), a[0] + b, a[1] + b, a[2] + b, bb[0] + b,
                             bb[1] + b, bb[2] + b, e - b, r[0] + b, r[1] + b, r[2] + b);
        else if (op == 6)
            bg_resolve_normal_batch(a[0] + b, a[1] + b, a[2] + b, bb[0] + b, bb[1] + b, bb[2] + b,
                                    e - b, r[0] + b, r[1] + b, r[2] + b);
        else
            for (size_t i = b; i < e; i++) {
                bg_vec3 A = V3(a, i), Bv = V3(bb, i), R;
                if (op == 0)
                    R = bg_surface_gradient(A, Bv);
                else if (op == 4) {
                    bg_vec3 C = V3(c, i);
                    R = bg_surfgrad_from_tangent_normal(A, Bv, C);
                } else
                    R = bg_surfgrad_from_perturbed_normal(A, Bv);
                PUT3(r, i, R);
            }
        return;
    }
    double *a[3] = {j->in[0], j->in[1], j->in[2]}, *bb[3] = {j->in[3], j->in[4], j->in[5]};
    double *c[3] = {j->in[6], j->in[7], j->in[8]}, *r[3] = {j->out[0], j->out[1], j->out[2]};
    for (size_t i = b; i < e; i++) {
        bg_dvec3 A = V3(a, i), Bv = V3(bb, i), R;
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

/* vec(op, double, threads, a3..., out3): two-vector operations
 *   op 0: surface gradient (n, g); 1..3: perturb method op-1 (n, g);
 *   4: from_tangent_normal (t, b, m) [three inputs]; 5: from_perturbed_normal (n, m);
 *   6: resolve (n, s) */
static PyObject *py_vec(PyObject *self, PyObject *args)
{
    (void)self;
    int op, dbl, threads;
    PyObject *o[12];
    if (!PyArg_ParseTuple(args, "ipiOOOOOOOOOOOO", &op, &dbl, &threads, &o[0], &o[1], &o[2],
                          &o[3], &o[4], &o[5], &o[6], &o[7], &o[8], &o[9], &o[10], &o[11]))
        return NULL;
    if (op < 0 || op > 6)
        return raise_status(BG_ERR_INVALID_ARGUMENT, "operation");
    const int nin = op == 4 ? 9 : 6;
    job j = {.run = vec_range, .op = op, .dbl = dbl};
    const char fmt = dbl ? 'd' : 'f';
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    if (!getn(&B, o, j.in, nin, fmt, &n, 0, 0) || !getn(&B, o + 9, j.out, 3, fmt, &n, 1, 0)) {
        release(&B);
        return NULL;
    }
    return finish(&B, &j, n, threads);
}

static void accumulate_range(const job *j, size_t b, size_t e)
{
    bg_surfgrad_accumulate_batch(j->w, (float *)j->in[0] + b, (float *)j->in[1] + b,
                                 (float *)j->in[2] + b, e - b, (float *)j->out[0] + b,
                                 (float *)j->out[1] + b, (float *)j->out[2] + b);
}

/* accumulate(weight, threads, gx, gy, gz, ax, ay, az): a += weight * g, float32 */
static PyObject *py_accumulate(PyObject *self, PyObject *args)
{
    (void)self;
    float w;
    int threads;
    PyObject *o[6];
    if (!PyArg_ParseTuple(args, "fiOOOOOO", &w, &threads, &o[0], &o[1], &o[2], &o[3], &o[4],
                          &o[5]))
        return NULL;
    job j = {.run = accumulate_range, .w = w};
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    if (!getn(&B, o, j.in, 3, 'f', &n, 0, 0) || !getn(&B, o + 3, j.out, 3, 'f', &n, 1, 0)) {
        release(&B);
        return NULL;
    }
    return finish(&B, &j, n, threads);
}

static void triplanar_range(const job *j, size_t b, size_t e)
{
    if (!j->dbl) {
        float *a[3] = {j->in[0], j->in[1], j->in[2]}, *q[6], *out[3] = {j->out[0], j->out[1], j->out[2]};
        memcpy(q, j->in + 3, sizeof q);
        for (size_t i = b; i < e; i++) {
            bg_vec3 A = V3(a, i), R;
            if (j->weights_only)
                R = bg_triplanar_weights(A, (float)j->k);
            else {
                bg_vec2 yz = {q[0][i], q[1][i]}, xz = {q[2][i], q[3][i]}, xy = {q[4][i], q[5][i]};
                R = bg_surfgrad_triplanar(A, (float)j->k, yz, xz, xy);
            }
            PUT3(out, i, R);
        }
        return;
    }
    double *a[3] = {j->in[0], j->in[1], j->in[2]}, *q[6], *out[3] = {j->out[0], j->out[1], j->out[2]};
    memcpy(q, j->in + 3, sizeof q);
    for (size_t i = b; i < e; i++) {
        bg_dvec3 A = V3(a, i), R;
        if (j->weights_only)
            R = bg_triplanar_weightsd(A, j->k);
        else {
            bg_dvec2 yz = {q[0][i], q[1][i]}, xz = {q[2][i], q[3][i]}, xy = {q[4][i], q[5][i]};
            R = bg_surfgrad_triplanard(A, j->k, yz, xz, xy);
        }
        PUT3(out, i, R);
    }
}

/* triplanar(double, k, threads, nx, ny, nz, d_yz.x, .y, d_xz.x, .y, d_xy.x, .y, ox, oy, oz)
 * With the six derivative arguments None: the weights. */
static PyObject *py_triplanar(PyObject *self, PyObject *args)
{
    (void)self;
    int dbl, threads;
    double k;
    PyObject *o[12];
    if (!PyArg_ParseTuple(args, "pdiOOOOOOOOOOOO", &dbl, &k, &threads, &o[0], &o[1], &o[2],
                          &o[3], &o[4], &o[5], &o[6], &o[7], &o[8], &o[9], &o[10], &o[11]))
        return NULL;
    const char fmt = dbl ? 'd' : 'f';
    job j = {.run = triplanar_range, .dbl = dbl, .k = k, .weights_only = o[3] == Py_None};
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    if (!getn(&B, o, j.in, 3, fmt, &n, 0, 0) ||
        (!j.weights_only && !getn(&B, o + 3, j.in + 3, 6, fmt, &n, 0, 0)) ||
        !getn(&B, o + 9, j.out, 3, fmt, &n, 1, 0)) {
        release(&B);
        return NULL;
    }
    return finish(&B, &j, n, threads);
}

/* One batch call per run of points with the same amplitude and frequency (both
 * are per-point arrays or NULL): a uniform array is one call, so a per-point
 * parameter gives the same bits as the scalar one. */
static void height_range(const job *j, size_t b, size_t e)
{
    const float *amp = j->aux[1], *freq = j->aux[2];
    size_t s = b;
    while (s < e) {
        bg_height h = j->h;
        size_t t = s + 1;
        if (amp || freq) {
            if (amp)
                h.amplitude = amp[s];
            if (freq)
                h.frequency = freq[s];
            while (t < e && (!amp || memcmp(&amp[t], &amp[s], sizeof(float)) == 0) &&
                   (!freq || memcmp(&freq[t], &freq[s], sizeof(float)) == 0))
                t++;
        } else
            t = e;
        const size_t N = t - s;
        float *const *in = (float *const *)j->in;
        if (j->aux[0])
            bg_perturb_height_footprint_batch(&h, (bg_perturb_method)j->method,
                                              (const float *)j->aux[0] + s, in[0] + s, in[1] + s,
                                              in[2] + s, in[3] + s, in[4] + s, in[5] + s, N,
                                              OFF(j->out[3], float, s), (float *)j->out[0] + s,
                                              (float *)j->out[1] + s, (float *)j->out[2] + s);
        else
            bg_perturb_height_batch(&h, (bg_perturb_method)j->method, in[0] + s, in[1] + s,
                                    in[2] + s, in[3] + s, in[4] + s, in[5] + s, N,
                                    OFF(j->out[3], float, s), (float *)j->out[0] + s,
                                    (float *)j->out[1] + s, (float *)j->out[2] + s);
        s = t;
    }
}

/* perturb_height(function, octaves, lacunarity, gain, amplitude, frequency, gradient, step,
 *                method, threads, px, py, pz, nx, ny, nz, height|None, ox, oy, oz,
 *                footprint|None, amplitude[]|None, frequency[]|None, (px, py, pz), seed)
 * The per-point arrays, when given, replace the scalar; the scalars are checked
 * (bg_height_validate) and the Python layer checks the arrays are finite. */
static PyObject *py_perturb_height(PyObject *self, PyObject *args)
{
    (void)self;
    int function, octaves, gradient, method, threads;
    float lac, gain, amp, freq, step;
    PyObject *o[13];
    bg_domain dom = {{0, 0, 0}, 0};
    if (!PyArg_ParseTuple(args, "iiffffifiiOOOOOOOOOOOOO(iii)I", &function, &octaves, &lac, &gain,
                          &amp, &freq, &gradient, &step, &method, &threads, &o[0], &o[1], &o[2],
                          &o[3], &o[4], &o[5], &o[6], &o[7], &o[8], &o[9], &o[10], &o[11], &o[12],
                          &dom.period[0], &dom.period[1], &dom.period[2], &dom.seed))
        return NULL;
    job j = {.run = height_range, .method = method};
    j.h = bg_height_default();
    j.h.fractal.function = (bg_function)function;
    j.h.fractal.octaves = octaves;
    j.h.fractal.lacunarity = lac;
    j.h.fractal.gain = gain;
    j.h.amplitude = amp;
    j.h.frequency = freq;
    j.h.gradient = (bg_gradient_mode)gradient;
    j.h.step = step;
    j.h.domain = dom;
    bg_status s = bg_height_validate(&j.h);
    if (s != BG_OK)
        return raise_status(s, "height parameters");
    if (method < 0 || method > 2)
        return raise_status(BG_ERR_INVALID_ARGUMENT, "method");
    bufs B = {.count = 0};
    Py_ssize_t n = -1;
    if (!getn(&B, o, j.in, 6, 'f', &n, 0, 0) || !getn(&B, o + 6, j.out + 3, 1, 'f', &n, 1, 1) ||
        !getn(&B, o + 7, j.out, 3, 'f', &n, 1, 0) || !getn(&B, o + 10, j.aux, 3, 'f', &n, 0, 1)) {
        release(&B);
        return NULL;
    }
    if (j.aux[1] || j.aux[2]) {
        /* The overflow checks of bg_height_validate for each distinct value
         * would cost a pass per point; the scalar call validated the extremes
         * the Python layer passed (largest |amplitude|, |frequency|). */
    }
    return finish(&B, &j, n, threads);
}

/* ---- noise3: the fast path ------------------------------------------------------------ */

/* Up to this many points the fast path converts on the stack and calls the
 * library on one thread; larger calls go to the Python implementation, which
 * splits them over threads. */
#define FAST_MAX 1024

static PyObject *py_noise3(PyObject *self, PyObject *const *args, Py_ssize_t nargs,
                           PyObject *kwnames)
{
    (void)self;
    if (nargs != 1 || kwnames || !PyArray_CheckExact(args[0]))
        goto slow;
    PyArrayObject *a = (PyArrayObject *)args[0];
    const int type = PyArray_TYPE(a), nd = PyArray_NDIM(a);
    if ((type != NPY_FLOAT32 && type != NPY_FLOAT64) || nd < 1 || nd > 8 ||
        PyArray_DIM(a, nd - 1) != 3 || !PyArray_ISCARRAY_RO(a) || !PyArray_ISNOTSWAPPED(a))
        goto slow;
    const npy_intp n = PyArray_SIZE(a) / 3;
    if (n > FAST_MAX)
        goto slow;
    PyObject *res;
    if (nd == 1) {
        /* One point: a numpy scalar (PyArray_Scalar does not take the descr's reference). */
        PyArray_Descr *d = PyArray_DescrFromType(type);
        if (type == NPY_FLOAT32) {
            const float *p = PyArray_DATA(a);
            float v;
            bg_noise3_batch(&p[0], &p[1], &p[2], 1, &v);
            res = PyArray_Scalar(&v, d, NULL);
        } else {
            const double *p = PyArray_DATA(a);
            double v = bg_noise3d(p[0], p[1], p[2]);
            res = PyArray_Scalar(&v, d, NULL);
        }
        Py_DECREF(d);
        return res;
    }
    res = PyArray_SimpleNew(nd - 1, PyArray_DIMS(a), type);
    if (!res)
        return NULL;
    if (type == NPY_FLOAT32) {
        const float *p = PyArray_DATA(a);
        float x[FAST_MAX], y[FAST_MAX], z[FAST_MAX];
        for (npy_intp i = 0; i < n; i++) {
            x[i] = p[3 * i];
            y[i] = p[3 * i + 1];
            z[i] = p[3 * i + 2];
        }
        bg_noise3_batch(x, y, z, (size_t)n, PyArray_DATA((PyArrayObject *)res));
    } else {
        const double *p = PyArray_DATA(a);
        double *v = PyArray_DATA((PyArrayObject *)res);
        for (npy_intp i = 0; i < n; i++)
            v[i] = bg_noise3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
    }
    return res;
slow:
    if (!noise3_slow) {
        PyErr_SetString(PyExc_RuntimeError, "bumpgrad: the package was not initialized");
        return NULL;
    }
    return PyObject_Vectorcall(noise3_slow, args, (size_t)nargs, kwnames);
}

/* ---- ISA, version, set-up ------------------------------------------------------------------ */

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
        if (s != BG_OK) {
            PyObject *type = error_type ? error_type : PyExc_RuntimeError;
            PyObject *a = Py_BuildValue("(iss)", (int)s, bg_status_string(s), name);
            if (a) {
                PyErr_SetObject(type, a);
                Py_DECREF(a);
            }
            return NULL;
        }
        Py_RETURN_NONE;
    }
    PyErr_Format(PyExc_ValueError, "bumpgrad: unknown ISA query %s", what);
    return NULL;
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

static PyObject *py_set_hooks(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *t, *slow;
    const char *doc;
    if (!PyArg_ParseTuple(args, "OOs", &t, &slow, &doc))
        return NULL;
    /* noise3's docstring (with its text signature) is written once, in __init__.py. */
    static char *noise3_doc;
    if (!noise3_doc && (noise3_doc = strdup(doc)) != NULL)
        methods[0].ml_doc = noise3_doc;
    Py_XDECREF(error_type);
    Py_XDECREF(noise3_slow);
    Py_INCREF(t);
    Py_INCREF(slow);
    error_type = t;
    noise3_slow = slow;
    Py_RETURN_NONE;
}

#ifdef BGPY_TOOLS
#include "tools_py.h"
#endif

static PyMethodDef methods[NMETHODS] = {
    {"noise3", (PyCFunction)(void (*)(void))py_noise3, METH_FASTCALL | METH_KEYWORDS, NULL},
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
    {"_set_hooks", py_set_hooks, METH_VARARGS, NULL},
#ifdef BGPY_TOOLS
    TOOLS_PY_METHODS
#endif
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_bumpgrad",
    "Private calls into libbumpgrad; use the bumpgrad package.", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__bumpgrad(void)
{
    import_array();
    PyObject *m = PyModule_Create(&module);
    if (!m)
        return NULL;
#ifdef BGPY_TOOLS
    PyModule_AddIntConstant(m, "HAVE_TOOLS", 1);
    PyModule_AddIntConstant(m, "MESH_MAX_UDIM_TILES", MESH_UDIM_MAX_TILES);
#else
    PyModule_AddIntConstant(m, "HAVE_TOOLS", 0);
#endif
    PyModule_AddIntConstant(m, "BLOCK", BLOCK);
    return m;
}
