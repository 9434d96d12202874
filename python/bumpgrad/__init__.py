# SPDX-License-Identifier: MIT
"""bumpgrad: procedural bump mapping on the CPU, from numpy.

Perlin's improved noise (2002) with its analytic gradient, fBm and turbulence,
Mikkelsen's surface gradient (2010, eq. 2) and perturbed normal (eq. 4,
Listing 3), the surface-gradient framework's batchable pieces, over the C
library libbumpgrad (include/bumpgrad/*.h documents every function).

Conventions shared by every function (docs/PYTHON.md):

* Points and vectors are numpy arrays (or nested lists) of shape (..., 3),
  or a tuple of three arrays (x, y, z) of one common shape: a tuple always
  means separate components, a list is read as one array. Any strides.
* Precision is chosen by the name: ``noise3``, ``fbm3``, ... compute in
  float32 (the SIMD kernels), ``noise3d``, ``fbm3d``, ... in float64 (the
  double entry points, ``noise3d`` is Perlin's reference bit for bit).
  Floating-point input of any precision is converted to the function's
  precision (rounded to nearest for float64 input to a float32 function: you
  asked for float32); integer, boolean, complex and object arrays raise
  TypeError, since silently treating 3 as 3.0 hides lattice-point mistakes.
* Results are numpy arrays of the function's precision, shaped like the
  input: a value per point has the input's shape without the last axis, a
  vector result has shape (..., 3) for (..., 3) input and is a tuple of three
  arrays for three-array input. Three contiguous arrays of the function's
  dtype are passed to C without any copy, and vector results are always
  written in place (a (..., 3) result is a view of one (3, ...) block).
* NaN and Inf follow the C library: noise of a NaN point is NaN; normal
  functions return the (0, 0, 0) "no normal" sentinel or the unit normal as
  surfgrad.h and framework.h document. Nothing raises for NaN.
* The GIL is released during every C call, so threads calling bumpgrad run
  in parallel.
* Errors of the library (bad octaves, an ISA this CPU lacks) raise
  bumpgrad.Error, whose message is the library's bg_status_string text.
* Float results are bit-identical to the C API and to ``bumpgrad eval``.
"""
import math as _math

import numpy as _np

# The extension finds libbumpgrad through an rpath relative to its own file
# ($ORIGIN): the build tree's library, or LIBDIR of the prefix it is installed in.
from . import _bumpgrad as _c

__all__ = [
    "Error", "__version__", "noise3", "noise3d", "fbm3", "fbm3d", "turbulence3", "turbulence3d",
    "fractal3", "fractal3d", "fractal3_footprint", "octave_weight", "octaves_for_footprint",
    "surface_gradient", "surface_gradientd", "perturb", "perturbd", "perturb_height",
    "resolve_normal", "resolve_normald", "surfgrad_from_tangent_normal",
    "surfgrad_from_tangent_normald", "surfgrad_from_perturbed_normal",
    "surfgrad_from_perturbed_normald", "triplanar_weights", "triplanar_weightsd",
    "surfgrad_triplanar", "surfgrad_triplanard", "isa_best", "isa_active", "isa_force",
    "DEFAULT_OCTAVES", "DEFAULT_CENTRAL_STEP", "MAX_OCTAVES",
]

#: Version of the C library, "MAJOR.MINOR.PATCH" (the meson project version).
__version__ = _c.version()

DEFAULT_OCTAVES = 6         #: BG_DEFAULT_OCTAVES
MAX_OCTAVES = 32            #: BG_MAX_OCTAVES
#: BG_DEFAULT_CENTRAL_STEP, noise-space units: the C constant is the float 2e-4f,
#: so the double entry points (and `bumpgrad eval --precision double`) use that
#: float widened, 2.0000000949949026e-04, not the double 2e-4.
DEFAULT_CENTRAL_STEP = float(_np.float32(2e-4))


class Error(Exception):
    """A libbumpgrad call failed. ``status`` is the bg_status code, ``text``
    the library's bg_status_string text, ``what`` names the argument."""

    def __init__(self, status, text, what=""):
        super().__init__(status, text, what)
        self.status = status
        self.text = text
        self.what = what

    def __str__(self):
        return f"{self.text}: {self.what}" if self.what else self.text


_c._set_error_type(Error)

_FUNCTIONS = {"noise": 0, "fbm": 1, "turbulence": 2}
_METHODS = {"surfgrad": 0, "additive": 1, "additive-perlin": 2}
_GRADIENT_MODES = {None: 0, False: 0, "analytic": 1, True: 1, "central": 2}
_F32 = _np.dtype(_np.float32)
_F64 = _np.dtype(_np.float64)


# ---- array plumbing -----------------------------------------------------------

def _convert(a, dtype, name):
    a = _np.asarray(a)
    if a.dtype.kind != "f":
        raise TypeError(f"bumpgrad: {name} must be a floating-point array, not {a.dtype} "
                        "(convert explicitly, e.g. a.astype(numpy.float64))")
    return a


def _vectors(p, dtype, name, width=3):
    """(components as contiguous 1-D arrays of dtype, batch shape, was_tuple)."""
    if isinstance(p, tuple):
        if len(p) != width:
            raise ValueError(f"bumpgrad: {name} as separate arrays needs {width} of them, "
                             f"got {len(p)}")
        comps = [_convert(c, dtype, name) for c in p]
        shape = comps[0].shape
        for c in comps[1:]:
            if c.shape != shape:
                raise ValueError(f"bumpgrad: the {width} arrays of {name} differ in shape: "
                                 f"{[c.shape for c in comps]}")
        tup = True
    else:
        a = _convert(p, dtype, name)
        if a.ndim == 0 or a.shape[-1] != width:
            raise ValueError(f"bumpgrad: {name} must have shape (..., {width}) or be "
                             f"{width} arrays; got shape {a.shape}")
        shape = a.shape[:-1]
        comps = [a[..., i] for i in range(width)]
        tup = False
    # ravel of a contiguous array is a view; astype(copy=False) keeps the same
    # array when the dtype already matches: contiguous SoA input is not copied.
    flat = [_np.ascontiguousarray(c.astype(dtype, copy=False)).reshape(-1) for c in comps]
    return flat, shape, tup


def _scalars(a, dtype, name, shape=None):
    a = _convert(a, dtype, name)
    if shape is not None and a.shape != shape:
        a = _np.broadcast_to(a, shape)
    return _np.ascontiguousarray(a.astype(dtype, copy=False)).reshape(-1), a.shape


def _same_shape(shape_a, shape_b, what):
    if shape_a != shape_b:
        raise ValueError(f"bumpgrad: {what} have different shapes: {shape_a} and {shape_b}")


def _vec_out(shape, dtype, as_tuple):
    """Output block (3, N) and what to return: three arrays or a (..., 3) view."""
    shape = tuple(shape)
    block = _np.empty((3, _math.prod(shape)), dtype)
    if as_tuple:
        ret = tuple(block[i].reshape(shape) for i in range(3))
    else:
        # A (..., 3) view of the (3, N) block: the C calls write SoA in place.
        # (transpose, not numpy.moveaxis: a third of the per-call time for 1 point.)
        nd = len(shape)
        ret = block.reshape((3,) + shape).transpose(tuple(range(1, nd + 1)) + (0,))
    return block, ret


def _scalar_result(v, shape):
    v = v.reshape(shape)
    return v[()] if v.ndim == 0 else v


def _method(method):
    try:
        return _METHODS[method]
    except KeyError:
        raise ValueError(f"bumpgrad: method must be one of {sorted(_METHODS)}, "
                         f"not {method!r}") from None


# ---- noise and fractals ----------------------------------------------------------

def _fractal(p, dtype, function, octaves, lacunarity, gain, gradient, step):
    if function not in _FUNCTIONS:
        raise ValueError(f"bumpgrad: function must be one of {sorted(_FUNCTIONS)}")
    mode = _GRADIENT_MODES.get(gradient)
    if mode is None:
        raise ValueError("bumpgrad: gradient must be None, 'analytic' or 'central'")
    (x, y, z), shape, tup = _vectors(p, dtype, "p")
    value = _np.empty(x.shape, dtype)
    if mode == 0:
        _c.fractal(dtype is _F64, _FUNCTIONS[function], int(octaves), float(lacunarity),
                   float(gain), 0, float(step), x, y, z, value, None, None, None)
        return _scalar_result(value, shape)
    block, grad = _vec_out(shape, dtype, tup)
    _c.fractal(dtype is _F64, _FUNCTIONS[function], int(octaves), float(lacunarity),
               float(gain), mode, float(step), x, y, z, value, block[0], block[1], block[2])
    return _scalar_result(value, shape), grad


def fractal3(p, function="fbm", octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5,
             gradient=None, step=DEFAULT_CENTRAL_STEP):
    """Fractal value (and gradient) in float32: bg_fractal3_batch and friends.

    p           points, (..., 3) or three arrays.
    function    'noise' (one octave), 'fbm' (sum gain^i noise(lacunarity^i p)) or
                'turbulence' (sum gain^i |noise(lacunarity^i p)|, Perlin 1985).
    octaves     1..32; lacunarity finite > 0; gain finite.
    gradient    None: return the value only; 'analytic': (value, gradient) from the
                same pass (dnoise); 'central': central differences with `step`
                (noise-space units, 7 evaluations per point).
    Returns value of shape p.shape[:-1] (a numpy scalar for one point), and the
    gradient shaped like p. Raises bumpgrad.Error for parameters out of range.
    """
    return _fractal(p, _F32, function, octaves, lacunarity, gain, gradient, step)


def fractal3d(p, function="fbm", octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5,
              gradient=None, step=DEFAULT_CENTRAL_STEP):
    """fractal3 in float64 (bg_fractal3d, bg_fractal3d_grad, bg_fractal3d_grad_central).
    lacunarity and gain are float parameters of the C API (widened exactly)."""
    return _fractal(p, _F64, function, octaves, lacunarity, gain, gradient, step)


def noise3(p, grad=False):
    """Perlin's improved noise (2002) in float32, about [-1, 1].

    p     points: an array (or nested list) of shape (..., 3), or a tuple of
          three arrays (x, y, z) of one shape.
    grad  False: return the values (shape p.shape[:-1]); True: return
          (values, gradients), the analytic gradient (dnoise) from the same pass,
          shaped like p.
    Float accuracy against the double reference: value error <= 1e-5, gradient
    <= 5e-5 (noise.h). Same bits as bg_noise3 / bg_noise3_batch and bumpgrad eval.
    NaN or Inf in a point: NaN value and gradient.

    >>> float(noise3d([3.14, 42.0, 7.0]))
    0.13691995878400012
    """
    return _fractal(p, _F32, "noise", 1, 2.0, 0.5, "analytic" if grad else None, 0.0)


def noise3d(p, grad=False):
    """Perlin's improved noise in float64; equals Perlin's reference
    implementation exactly (noise3d([3.14, 42, 7]) == 0.13691995878400012).
    Arguments and results as noise3."""
    return _fractal(p, _F64, "noise", 1, 2.0, 0.5, "analytic" if grad else None, 0.0)


def fbm3(p, octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5, gradient=None,
         step=DEFAULT_CENTRAL_STEP):
    """fBm in float32: sum_i gain^i noise(lacunarity^i p). See fractal3."""
    return fractal3(p, "fbm", octaves, lacunarity, gain, gradient, step)


def fbm3d(p, octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5, gradient=None,
          step=DEFAULT_CENTRAL_STEP):
    """fBm in float64. See fractal3d."""
    return fractal3d(p, "fbm", octaves, lacunarity, gain, gradient, step)


def turbulence3(p, octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5, gradient=None,
                step=DEFAULT_CENTRAL_STEP):
    """Turbulence in float32: sum_i gain^i |noise(lacunarity^i p)| (Perlin 1985).
    The analytic gradient takes sign(0) = +1 at zero crossings. See fractal3."""
    return fractal3(p, "turbulence", octaves, lacunarity, gain, gradient, step)


def turbulence3d(p, octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5, gradient=None,
                 step=DEFAULT_CENTRAL_STEP):
    """Turbulence in float64. See fractal3d."""
    return fractal3d(p, "turbulence", octaves, lacunarity, gain, gradient, step)


# ---- footprints ----------------------------------------------------------------

def fractal3_footprint(p, footprint, function="fbm", octaves=DEFAULT_OCTAVES, lacunarity=2.0,
                       gain=0.5):
    """Fractal value and analytic gradient with per-point footprints (float32,
    bg_fractal3_grad_footprint_batch): octave i is weighted by
    clamp(2 - 4 w lacunarity^i, 0, 1) for footprint w (noise space) and skipped
    where that is 0. footprint broadcasts to p's batch shape. Returns
    (value, gradient)."""
    (x, y, z), shape, tup = _vectors(p, _F32, "p")
    fp, _ = _scalars(footprint, _F32, "footprint", shape)
    value = _np.empty(x.shape, _F32)
    block, grad = _vec_out(shape, _F32, tup)
    _c.footprint(_FUNCTIONS[function], int(octaves), float(lacunarity), float(gain), fp, x, y, z,
                 value, block[0], block[1], block[2])
    return _scalar_result(value, shape), grad


def octave_weight(footprint, lacunarity=2.0, octave=0):
    """Weight c_i of octave `octave` (0-based) for footprints (array, noise space):
    bg_octave_weight. NaN footprint: 1 (no filtering)."""
    fp, shape = _scalars(footprint, _F32, "footprint")
    out = _np.empty(fp.shape, _F32)
    _c.octaves(0, fp, out, float(lacunarity), int(octave))
    return _scalar_result(out, shape)


def octaves_for_footprint(footprint, max_octaves=DEFAULT_OCTAVES):
    """Effective octave count for lacunarity 2 (bg_octaves_for_footprint): e.g. 6 for
    a tiny footprint, about 2.5 for 1/16, 0 from 1/2 on."""
    fp, shape = _scalars(footprint, _F32, "footprint")
    out = _np.empty(fp.shape, _F32)
    _c.octaves(1, fp, out, 2.0, int(max_octaves))
    return _scalar_result(out, shape)


# ---- surface gradient and perturbation ---------------------------------------------

def _vec_op(op, dtype, names, arrays):
    comps, shape, tup = [], None, None
    for name, a in zip(names, arrays):
        c, s, t = _vectors(a, dtype, name)
        if shape is None:
            shape, tup = s, t
        _same_shape(shape, s, " and ".join(names))
        comps += c
    while len(comps) < 9:
        comps += [comps[0]]
    block, ret = _vec_out(shape, dtype, tup)
    _c.vec(op, dtype is _F64, *comps, block[0], block[1], block[2])
    return ret


def surface_gradient(n, g):
    """Surface gradient g - n (n.g) (Mikkelsen 2010, eq. 2), float32: the volume
    gradient g projected onto the tangent plane of n (normalized first). Invalid
    n or non-finite g: (0, 0, 0). Vectors (..., 3) or three arrays each."""
    return _vec_op(0, _F32, ("n", "g"), (n, g))


def surface_gradientd(n, g):
    """surface_gradient in float64 (bg_surface_gradientd)."""
    return _vec_op(0, _F64, ("n", "g"), (n, g))


def perturb(n, g, method="surfgrad"):
    """Perturbed normal from unit normal n and volume gradient g, float32
    (bg_perturb_batch). method 'surfgrad': normalize(n - (g - n (n.g))) (eq. 4,
    Listing 3); 'additive': normalize(n - g); 'additive-perlin': normalize(n + g)
    (Perlin 1985's sign). Invalid n: (0, 0, 0); non-finite g: the unit n."""
    return _vec_op(1 + _method(method), _F32, ("n", "g"), (n, g))


def perturbd(n, g, method="surfgrad"):
    """perturb in float64 (bg_perturbd)."""
    return _vec_op(1 + _method(method), _F64, ("n", "g"), (n, g))


def perturb_height(p, n, function="turbulence", octaves=DEFAULT_OCTAVES, lacunarity=2.0,
                   gain=0.5, amplitude=0.1, frequency=1.0, gradient="analytic", step=0.0,
                   method="surfgrad", footprint=None):
    """The fused "height gradient -> perturbed normal" call, float32
    (bg_perturb_height_batch): h(p) = amplitude F(frequency p) with F the fractal,
    its gradient (gradient 'analytic' or 'central' with `step`, 0 meaning
    DEFAULT_CENTRAL_STEP), and the normal n perturbed with `method`.
    footprint (world units, broadcast to the batch shape) selects
    bg_perturb_height_footprint_batch (always analytic). Defaults are
    bg_height_default(): 6-octave turbulence, amplitude 0.1, frequency 1.
    Returns (height, normal)."""
    (px, py, pz), shape, tup = _vectors(p, _F32, "p")
    (nx, ny, nz), nshape, _ = _vectors(n, _F32, "n")
    _same_shape(shape, nshape, "p and n")
    grad = {"analytic": 0, "central": 1}.get(gradient)
    if grad is None:
        raise ValueError("bumpgrad: gradient must be 'analytic' or 'central'")
    fp = None
    if footprint is not None:
        fp, _ = _scalars(footprint, _F32, "footprint", shape)
    height = _np.empty(px.shape, _F32)
    block, ret = _vec_out(shape, _F32, tup)
    _c.perturb_height(_FUNCTIONS[function], int(octaves), float(lacunarity), float(gain),
                      float(amplitude), float(frequency), grad, float(step), _method(method),
                      px, py, pz, nx, ny, nz, height, block[0], block[1], block[2], fp)
    return _scalar_result(height, shape), ret


# ---- the framework ------------------------------------------------------------------

def _resolve(n, surfgrads, weights, dtype):
    if weights is None:
        weights = [1.0] * len(surfgrads)
    weights = [float(w) for w in _np.atleast_1d(_np.asarray(weights, dtype=_F64))]
    if len(weights) != len(surfgrads):
        raise ValueError(f"bumpgrad: {len(surfgrads)} surface gradients but "
                         f"{len(weights)} weights")
    (nx, ny, nz), shape, tup = _vectors(n, dtype, "n")
    grads = []
    for g in surfgrads:
        c, s, _ = _vectors(g, dtype, "surface gradient")
        _same_shape(shape, s, "n and a surface gradient")
        grads.append(c)
    if dtype == _F32:
        acc = _np.zeros((3, nx.size), dtype)
        for c, w in zip(grads, weights):
            _c.accumulate(w, c[0], c[1], c[2], acc[0], acc[1], acc[2])
    else:
        acc = _np.zeros((3, nx.size), dtype)
        for c, w in zip(grads, weights):
            acc += w * _np.stack(c)
    block, ret = _vec_out(shape, dtype, tup)
    _c.vec(6, dtype is _F64, nx, ny, nz, acc[0], acc[1], acc[2], nx, ny, nz,
           block[0], block[1], block[2])
    return ret


def resolve_normal(n, *surfgrads, weights=None):
    """The normal resolve n' = normalize(n - sum_i w_i g_i) (the framework's one
    resolve; each term is eq. 4 of Mikkelsen 2010), float32. Each positional
    argument after n is one influence's surface gradient, (..., 3) or three arrays;
    weights: one float per influence (default all 1). Each influence is added with
    bg_surfgrad_accumulate_batch (weight * g rounded, then added), then
    bg_resolve_normal_batch forms the normal. Invalid n: (0, 0, 0); a NaN/Inf sum
    contributes nothing. With no influence: the unit n."""
    return _resolve(n, surfgrads, weights, _F32)


def resolve_normald(n, *surfgrads, weights=None):
    """resolve_normal in float64: the weighted sum in numpy (w * g, then added in
    argument order), then bg_resolve_normald with that one influence."""
    return _resolve(n, surfgrads, weights, _F64)


def surfgrad_from_tangent_normal(t, b, m):
    """Surface gradient -(m.x/m.z) t - (m.y/m.z) b of a tangent-space normal m in the
    frame (t, b), float32 (bg_surfgrad_from_tangent_normal), with the framework's
    clamp: m.z replaced by max(|m.z|, max(|m.x|, |m.y|) / 128)."""
    return _vec_op(4, _F32, ("t", "b", "m"), (t, b, m))


def surfgrad_from_tangent_normald(t, b, m):
    """surfgrad_from_tangent_normal in float64."""
    return _vec_op(4, _F64, ("t", "b", "m"), (t, b, m))


def surfgrad_from_perturbed_normal(n, m):
    """Surface gradient of an object-space perturbed normal m relative to the base
    normal n, float32 (bg_surfgrad_from_perturbed_normal): -m_t / max(|k|, |m_t|/128)
    with k = m.n, m_t = m - k n."""
    return _vec_op(5, _F32, ("n", "m"), (n, m))


def surfgrad_from_perturbed_normald(n, m):
    """surfgrad_from_perturbed_normal in float64."""
    return _vec_op(5, _F64, ("n", "m"), (n, m))


def _triplanar(n, k, d_yz, d_xz, d_xy, dtype):
    (nx, ny, nz), shape, tup = _vectors(n, dtype, "n")
    ds = []
    if d_yz is not None:
        for name, d in (("d_yz", d_yz), ("d_xz", d_xz), ("d_xy", d_xy)):
            c, s, _ = _vectors(d, dtype, name, width=2)
            _same_shape(shape, s, "n and " + name)
            ds += c
    else:
        ds = [None] * 6
    block, ret = _vec_out(shape, dtype, tup)
    _c.triplanar(dtype is _F64, float(k), nx, ny, nz, *ds, block[0], block[1], block[2])
    return ret


def triplanar_weights(n, k=4.0):
    """Triplanar blend weights |n_i|^k / sum_j |n_j|^k, float32
    (bg_triplanar_weights). n invalid or k negative: (0, 0, 0)."""
    return _triplanar(n, k, None, None, None, _F32)


def triplanar_weightsd(n, k=4.0):
    """triplanar_weights in float64."""
    return _triplanar(n, k, None, None, None, _F64)


def surfgrad_triplanar(n, k, d_yz, d_xz, d_xy):
    """Triplanar surface gradient, float32 (bg_surfgrad_triplanar): the three planar
    height derivatives d_yz = (dh/dy, dh/dz), d_xz = (dh/dx, dh/dz),
    d_xy = (dh/dx, dh/dy), each (..., 2) or two arrays, blended with
    triplanar_weights(n, k) and projected (eq. 2)."""
    return _triplanar(n, k, d_yz, d_xz, d_xy, _F32)


def surfgrad_triplanard(n, k, d_yz, d_xz, d_xy):
    """surfgrad_triplanar in float64."""
    return _triplanar(n, k, d_yz, d_xz, d_xy, _F64)


# ---- ISA ------------------------------------------------------------------------------

def isa_best():
    """Highest kernel ISA this CPU and build support: 'scalar', 'sse2', 'avx2',
    'avx512' or 'neon'."""
    return _c.isa("best")


def isa_active():
    """ISA the batch calls use now (first call reads $BUMPGRAD_ISA)."""
    return _c.isa("active")


def isa_force(name):
    """Force the batch kernels down to ISA `name` (bg_isa_force; every ISA gives the
    same bits). Raises bumpgrad.Error for an unknown name or one above isa_best().
    Not thread-safe against concurrent calls: call it before starting work."""
    _c.isa("force", str(name))
