# SPDX-License-Identifier: MIT
"""bumpgrad: procedural bump mapping on the CPU, from numpy.

Perlin's improved noise (2002) with its analytic gradient, fBm and turbulence,
Mikkelsen's surface gradient (2010, eq. 2) and perturbed normal (eq. 4,
Listing 3), the surface-gradient framework's batchable pieces, over the C
library libbumpgrad (include/bumpgrad/*.h documents every function).

Conventions shared by every function (docs/PYTHON.md):

* Points and vectors are numpy arrays (or nested lists) of shape (..., 3),
  or a tuple of three arrays (x, y, z). Every array argument broadcasts
  against the others as in numpy: points (N, 3) with one normal (3,),
  per-point amplitudes (N,) with a scalar, and so on.
* ``dtype=`` chooses the precision, float32 (the SIMD kernels) or float64
  (Perlin's reference bit for bit). The default is the inputs' float type:
  float64 if any array input is float64 (Python lists are), else float32.
  Integer, boolean, complex and object arrays raise TypeError.
* ``out=`` takes the result array(s), of the result's shape and dtype; the
  function writes them and returns them.
* ``threads=`` splits a large call into blocks over that many threads
  (default: the cores this process may use). The result has the same bits for
  any thread count. The GIL is released, and a Ctrl-C stops a long call
  between blocks with KeyboardInterrupt.
* ``gradient=`` is None (value only), 'analytic' or 'central' everywhere.
* Bad arguments raise ValueError or TypeError naming the argument and the rule
  (``ValueError: amplitude must be finite, got nan``). NaN and Inf inside
  point arrays follow the C library and never raise.
* Results are bit-identical to the C API and to ``bumpgrad eval``.

>>> import numpy, bumpgrad
>>> print(repr(bumpgrad.noise3(numpy.array([[3.14, 42, 7]]))[0]))
0.13691995878400012
"""
import math as _math
import operator as _operator
import os as _os
import warnings as _warnings

import numpy as _np

from . import _bumpgrad as _c

__all__ = [
    "Error", "__version__", "noise3", "fbm3", "turbulence3", "fractal3", "fractal3_footprint",
    "octave_weight", "octaves_for_footprint", "surface_gradient", "perturb", "perturb_height",
    "resolve_normal", "surfgrad_from_tangent_normal", "surfgrad_from_perturbed_normal",
    "triplanar_weights", "surfgrad_triplanar", "isa_best", "isa_active", "isa_force",
    "DEFAULT_OCTAVES", "DEFAULT_CENTRAL_STEP", "MAX_OCTAVES", "MAX_PERIOD", "HAVE_TOOLS",
    "bake_normal_map", "heightmap", "volume", "render", "merge_volumes", "read_image", "write_image",
    # deprecated float64 aliases (use dtype=numpy.float64)
    "noise3d", "fbm3d", "turbulence3d", "fractal3d", "surface_gradientd", "perturbd",
    "resolve_normald", "surfgrad_from_tangent_normald", "surfgrad_from_perturbed_normald",
    "triplanar_weightsd", "surfgrad_triplanard",
]

#: Version of the C library, "MAJOR.MINOR.PATCH" (the meson project version).
__version__ = _c.version()

DEFAULT_OCTAVES = 6         #: BG_DEFAULT_OCTAVES
MAX_OCTAVES = 32            #: BG_MAX_OCTAVES
MAX_PERIOD = 256            #: BG_MAX_PERIOD (noise.h): largest period= entry
#: BG_DEFAULT_CENTRAL_STEP, noise-space units: the C constant is the float 2e-4f,
#: so the double entry points (and `bumpgrad eval --precision double`) use that
#: float widened, 2.0000000949949026e-04, not the double 2e-4.
DEFAULT_CENTRAL_STEP = float(_np.float32(2e-4))
#: Whether this build has the tools (OpenImageIO, OpenVDB, assimp).
HAVE_TOOLS = bool(_c.HAVE_TOOLS)


class Error(Exception):
    """A libbumpgrad call failed for a reason other than a bad argument (an ISA
    this CPU lacks, a file that cannot be read, ...). ``status`` is the
    bg_status code, ``text`` the library's bg_status_string text, ``what``
    names the argument or file."""

    def __init__(self, status, text, what=""):
        super().__init__(status, text, what)
        self.status = status
        self.text = text
        self.what = what

    def __str__(self):
        return f"{self.text}: {self.what}" if self.what else self.text


_FUNCTIONS = {"noise": 0, "fbm": 1, "turbulence": 2}
_METHODS = {"surfgrad": 0, "additive": 1, "additive-perlin": 2}
_GRADIENTS = {None: 0, "analytic": 1, "central": 2}
_F32 = _np.dtype(_np.float32)
_F64 = _np.dtype(_np.float64)


def _cores():
    try:
        return max(1, len(_os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, _os.cpu_count() or 1)


_CORES = _cores()


# ---- argument checks -------------------------------------------------------------

def _int_arg(name, v, lo, hi):
    """An integer parameter: int or numpy integer (not bool, not float), lo..hi."""
    if isinstance(v, (bool, _np.bool_)):
        raise TypeError(f"{name} must be an integer, got {v!r}")
    try:
        i = _operator.index(v)
    except TypeError:
        raise TypeError(f"{name} must be an integer, got {v!r}") from None
    if not lo <= i <= hi:
        raise ValueError(f"{name} must be in {lo}..{hi}, got {i}")
    return i


def _float_arg(name, v, rule=None, f32=True):
    """A float parameter, finite (in float32 when the C API takes a float);
    rule 'positive': > 0, 'nonneg': >= 0."""
    if isinstance(v, (bool, _np.bool_)) or isinstance(v, (str, bytes)):
        raise TypeError(f"{name} must be a number, got {v!r}")
    try:
        f = float(v)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number, got {v!r}") from None
    if not _math.isfinite(f):
        raise ValueError(f"{name} must be finite, got {f}")
    if f32 and abs(f) > 3.4028234663852886e38:
        raise ValueError(f"{name} must be finite in float32, got {f}")
    if rule == "positive" and not f > 0:
        raise ValueError(f"{name} must be > 0, got {f}")
    if rule == "nonneg" and not f >= 0:
        raise ValueError(f"{name} must be >= 0, got {f}")
    return f


def _threads(threads):
    return _CORES if threads is None else _int_arg("threads", threads, 1, 1024)


def _choice(name, v, table):
    try:
        return table[v]
    except (KeyError, TypeError):
        raise ValueError(f"{name} must be one of {', '.join(repr(k) for k in table)}, "
                         f"got {v!r}") from None


def _gradient(gradient, allow_none=True):
    if isinstance(gradient, (bool, _np.bool_)):
        _warnings.warn("gradient=True/False is deprecated: use gradient='analytic' or None",
                       DeprecationWarning, stacklevel=4)
        gradient = "analytic" if gradient else None
    if gradient is None and not allow_none:
        raise ValueError("gradient must be 'analytic' or 'central', got None")
    return _choice("gradient", gradient, _GRADIENTS)


def _deprecated(old, new):
    _warnings.warn(f"bumpgrad.{old} is deprecated: use {new}", DeprecationWarning, stacklevel=3)


# ---- array plumbing -----------------------------------------------------------

def _asfloat(a, name):
    a = _np.asarray(a)
    if a.dtype.kind != "f":
        raise TypeError(f"{name} must be a floating-point array, not {a.dtype} "
                        "(convert explicitly, e.g. a.astype(numpy.float64))")
    return a


def _split(p, name, width=3):
    """(component arrays, batch shape, was_tuple) of a vector argument."""
    if isinstance(p, tuple):
        if len(p) != width:
            raise ValueError(f"{name} as separate arrays needs {width} of them, got {len(p)}")
        comps = [_asfloat(c, name) for c in p]
        try:
            shape = _np.broadcast_shapes(*(c.shape for c in comps))
        except ValueError:
            raise ValueError(f"the {width} arrays of {name} do not broadcast: "
                             f"{[c.shape for c in comps]}") from None
        return comps, shape, True
    a = _asfloat(p, name)
    if a.ndim == 0 or a.shape[-1] != width:
        raise ValueError(f"{name} must have shape (..., {width}) or be {width} arrays; "
                         f"got shape {a.shape}")
    return [a[..., i] for i in range(width)], a.shape[:-1], False


def _dtype(dtype, arrays, f32_only=None):
    """The computing dtype: dtype= if given, else float64 if any input is
    float64 (or wider), else float32. f32_only names a float32-only function."""
    if dtype is not None:
        try:
            d = _np.dtype(dtype)
        except TypeError:
            raise TypeError(f"dtype must be float32 or float64, got {dtype!r}") from None
        if d not in (_F32, _F64):
            raise ValueError(f"dtype must be float32 or float64, got {d}")
        if f32_only and d != _F32:
            raise ValueError(f"{f32_only} computes in float32 only: dtype must be float32, got {d}")
        return d
    if f32_only:
        return _F32
    return _F64 if any(a.dtype.itemsize >= 8 for a in arrays) else _F32


def _broadcast(names, shapes):
    try:
        return _np.broadcast_shapes(*shapes)
    except ValueError:
        raise ValueError("cannot broadcast " + ", ".join(
            f"{n} {s}" for n, s in zip(names, shapes)) + " together") from None


def _flat(a, shape, dtype):
    """a broadcast to `shape`, as a 1-D C-contiguous array of dtype (no copy
    when it already is one)."""
    if a.shape != shape:
        a = _np.broadcast_to(a, shape)
    return _np.ascontiguousarray(a, dtype=dtype).reshape(-1)


class _Out:
    """Where a result goes: a fresh array or the caller's out= (written in
    place when it is C-contiguous, else through a copy)."""

    def __init__(self, out, shape, dtype, name, vector, as_tuple):
        self.shape, self.dtype, self.vector, self.user = shape, dtype, vector, out
        n = _math.prod(shape)
        self.copy_back = False
        if out is None:
            self.as_tuple = as_tuple
            if vector:
                self.block = _np.empty((3, n), dtype)
                self.rows = [self.block[i] for i in range(3)]
            else:
                self.flat = _np.empty(n, dtype)
            return
        self.as_tuple = isinstance(out, tuple)
        want = shape + (3,) if vector and not self.as_tuple else shape
        arrays = list(out) if self.as_tuple else [out]
        if vector and self.as_tuple and len(arrays) != 3:
            raise ValueError(f"{name} as separate arrays needs 3 of them, got {len(arrays)}")
        for a in arrays:
            if not isinstance(a, _np.ndarray) or a.shape != want or a.dtype != dtype:
                got = (f"shape {a.shape} {a.dtype}" if isinstance(a, _np.ndarray)
                       else type(a).__name__)
                raise ValueError(f"{name} must be an array of shape {want} and dtype {dtype}, "
                                 f"got {got}")
            if not a.flags.writeable:
                raise ValueError(f"{name} is read-only")
        if vector and self.as_tuple and all(a.flags.c_contiguous for a in arrays):
            self.rows = [a.reshape(-1) for a in arrays]
        elif not vector and out.flags.c_contiguous:
            self.flat = out.reshape(-1)
        else:
            self.copy_back = True
            if vector:
                self.block = _np.empty((3, n), dtype)
                self.rows = [self.block[i] for i in range(3)]
            else:
                self.flat = _np.empty(n, dtype)

    def result(self):
        shape = self.shape
        if self.user is not None:
            if self.copy_back:
                if not self.vector:
                    self.user[...] = self.flat.reshape(shape)
                elif self.as_tuple:
                    for a, r in zip(self.user, self.rows):
                        a[...] = r.reshape(shape)
                else:
                    self.user[...] = _np.moveaxis(self.block.reshape((3,) + shape), 0, -1)
            return self.user
        if not self.vector:
            v = self.flat.reshape(shape)
            return v[()] if v.ndim == 0 else v
        if self.as_tuple:
            return tuple(r.reshape(shape) for r in self.rows)
        nd = len(shape)
        # A (..., 3) view of the (3, N) block the C calls wrote SoA.
        return self.block.reshape((3,) + shape).transpose(tuple(range(1, nd + 1)) + (0,))


def _out_pair(out, name="out"):
    if out is None:
        return None, None
    if not isinstance(out, tuple) or len(out) != 2:
        raise ValueError(f"{name} must be a pair (value_out, gradient_out) when a gradient is "
                         "returned; either may be None")
    return out


def _domain(period, seed):
    """period=, seed= as noise.h's bg_domain: ((px, py, pz), seed)."""
    if period is None:
        per = (0, 0, 0)
    else:
        if isinstance(period, (int, _np.integer)) and not isinstance(period, bool):
            period = (period,) * 3
        try:
            if isinstance(period, (str, bytes)):
                raise TypeError
            vals = list(period)
        except TypeError:
            raise TypeError(f"period must be None, an integer or 3 integers (x, y, z), "
                            f"got {period!r}") from None
        if len(vals) != 3:
            raise ValueError(f"period must be 3 integers (x, y, z), got {len(vals)}")
        per = tuple(_int_arg(f"period[{i}]", v, 0, MAX_PERIOD) for i, v in enumerate(vals))
    sd = _int_arg("seed", seed, 0, 0xFFFFFFFF)
    return per, sd


def _tool_height(function, gradient, octaves, lacunarity, gain, amplitude, frequency, step):
    """The height arguments of the tool calls (volume_bake, bake_normal_map,
    render), checked in this order: (function, gradient - 1, octaves,
    lacunarity, gain, amplitude, frequency, step)."""
    return (_choice("function", function, _FUNCTIONS),
            _gradient(gradient, allow_none=False) - 1,
            _int_arg("octaves", octaves, 1, MAX_OCTAVES),
            _float_arg("lacunarity", lacunarity, "positive"),
            _float_arg("gain", gain),
            _float_arg("amplitude", amplitude),
            _float_arg("frequency", frequency),
            _float_arg("step", step, "positive"))


def _progress_arg(progress):
    """A tool call's progress= : a callable or None."""
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be callable or None, got {progress!r}")


def _domain_fits(per, octaves, lacunarity):
    """bg_domain_validate's rules for a period, with the arguments named."""
    if not any(per):
        return
    if lacunarity != int(lacunarity):
        raise ValueError(f"period needs an integer lacunarity (octave i repeats after "
                         f"P * lacunarity^i lattice cells), got lacunarity={lacunarity}")
    if max(per) * lacunarity ** (octaves - 1) > 2 ** 24:
        raise ValueError(f"period: the finest octave's period P * lacunarity^(octaves-1) = "
                         f"{max(per)} * {lacunarity:g}^{octaves - 1} exceeds 2^24")


# ---- noise and fractals ----------------------------------------------------------

def _fractal(p, function, octaves, lacunarity, gain, gradient, step, dtype, out, threads,
             period=None, seed=0):
    fn = _choice("function", function, _FUNCTIONS)
    mode = _gradient(gradient)
    if fn != 0 or mode == 2:
        octaves = _int_arg("octaves", octaves, 1, MAX_OCTAVES)
        lacunarity = _float_arg("lacunarity", lacunarity, "positive")
        gain = _float_arg("gain", gain)
    step = _float_arg("step", step, "positive", f32=False) if mode == 2 else 0.0
    dom = _domain(period, seed)
    if fn != 0 or mode == 2:
        _domain_fits(dom[0], octaves, float(_np.float32(lacunarity)))
    nt = _threads(threads)
    comps, shape, tup = _split(p, "p")
    dt = _dtype(dtype, comps)
    a = None if tup else _np.asarray(p)
    if a is not None and a.flags.c_contiguous:
        # A C-contiguous (..., 3) array (checked by _split): C splits it into
        # x, y, z block by block, on the worker threads (no SoA copy here).
        x, y, z = _np.ascontiguousarray(a, dtype=dt).reshape(-1), None, None
    else:
        x, y, z = (_flat(c, shape, dt) for c in comps)
    if mode == 0:
        o = _Out(out, shape, dt, "out", False, tup)
        _c.fractal(dt is _F64, fn, int(octaves), float(lacunarity), float(gain), 0, float(step),
                   nt, x, y, z, o.flat, None, None, None, *dom)
        return o.result()
    vout, gout = _out_pair(out)
    vo = _Out(vout, shape, dt, "out[0]", False, tup)
    go = _Out(gout, shape, dt, "out[1]", True, tup)
    _c.fractal(dt is _F64, fn, int(octaves), float(lacunarity), float(gain), mode, float(step),
               nt, x, y, z, vo.flat, *go.rows, *dom)
    return vo.result(), go.result()


def fractal3(p, function="fbm", octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5,
             gradient=None, step=DEFAULT_CENTRAL_STEP, *, period=None, seed=0, dtype=None,
             out=None, threads=None):
    """Fractal value (and gradient): bg_fractal3_batch and friends, or the
    bg_fractal3d entry points in float64.

    p           points, (..., 3) or three arrays.
    function    'noise' (one octave), 'fbm' (sum gain^i noise(lacunarity^i p)) or
                'turbulence' (sum gain^i |noise(lacunarity^i p)|, Perlin 1985).
    octaves     integer 1..32; lacunarity finite > 0; gain finite.
    gradient    None: return the value only; 'analytic': (value, gradient) from the
                same pass (dnoise); 'central': central differences with `step`
                (noise-space units, finite > 0, 7 evaluations per point).
    period      None, an integer, or (px, py, pz): tile the noise (noise.h's
                bg_domain, the CLI's --period): each entry an integer 0..256,
                0 leaving that axis untiled, so that f(p + P e_i) == f(p). A
                period needs an integer lacunarity, and P * lacunarity^(octaves-1)
                at most 2^24.
    seed        integer 0..2^32-1 (--seed): 0 is Perlin's lattice (the same
                bits as no seed); another seed offsets each octave by a
                multiple of 1/256, a different pattern that keeps the tiling.
                In float64 a period or seed needs gradient None or 'analytic'.
    dtype, out, threads: see help(bumpgrad). out is (value_out, gradient_out)
                when a gradient is returned.
    Returns the value, shape p.shape[:-1] (a numpy scalar for one point), and the
    gradient shaped like p.

    >>> v, g = fractal3([[0.5, 0.25, 0.125]], "fbm", octaves=4, gradient="analytic")
    >>> v.shape, g.shape, v.dtype
    ((1,), (1, 3), dtype('float64'))
    """
    return _fractal(p, function, octaves, lacunarity, gain, gradient, step, dtype, out, threads,
                    period, seed)


def _noise3(p, gradient=None, *, period=None, seed=0, dtype=None, out=None, threads=None,
            grad=None):
    if grad is not None:
        _warnings.warn("noise3(grad=...) is deprecated: use gradient='analytic' or None",
                       DeprecationWarning, stacklevel=2)
        if gradient is None:
            gradient = "analytic" if grad else None
    return _fractal(p, "noise", 1, 2.0, 0.5, gradient, DEFAULT_CENTRAL_STEP, dtype, out, threads,
                    period, seed)


_NOISE3_DOC = """noise3($module, p, /, gradient=None, *, period=None, seed=0, dtype=None, out=None, threads=None)
--

Perlin's improved noise (2002), about [-1, 1]: bg_noise3_batch in float32,
bg_noise3d in float64 (Perlin's reference implementation bit for bit).

p         points: an array (or nested list) of shape (..., 3), or a tuple of
          three arrays (x, y, z).
gradient  None: return the values (shape p.shape[:-1]); 'analytic': return
          (values, gradients), the gradient (dnoise) from the same pass,
          shaped like p; 'central': central differences with the default step.
period    None, an integer or (px, py, pz), each 0..256 (0: that axis not
          tiled): periodic noise, bg_pnoise3_batch (bg_pnoise3d in float64),
          noise3(p + P e_i) == noise3(p). seed: as fractal3.
dtype, out, threads: see help(bumpgrad).
Float32 accuracy against the double reference: value error <= 1e-5,
gradient <= 5e-5 (noise.h). NaN or Inf in a point: NaN value and gradient.
A call on a C-contiguous (..., 3) float32 or float64 array of up to 1024
points with no keyword takes a fast path in C.

>>> import numpy
>>> print(repr(noise3(numpy.array([[3.14, 42, 7]]), dtype=numpy.float64)[0]))
0.13691995878400012
>>> bool(noise3([0.25, 0.625, 0.875], period=4) == noise3([4.25, 0.625, 0.875], period=4))
True
"""
_noise3.__name__ = _noise3.__qualname__ = "noise3"  # in its TypeErrors
_noise3.__doc__ = _NOISE3_DOC.split("--\n\n", 1)[1]
_c._set_hooks(Error, _noise3, _NOISE3_DOC)
#: The C function: its fast path handles plain (..., 3) arrays, the rest goes to _noise3.
noise3 = _c.noise3


def fbm3(p, octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5, gradient=None,
         step=DEFAULT_CENTRAL_STEP, *, period=None, seed=0, dtype=None, out=None, threads=None):
    """fBm: sum_i gain^i noise(lacunarity^i p). Arguments as fractal3 (period=
    and seed= tile and vary it).

    >>> float(fbm3([0.5, 0.25, 0.125], octaves=1)) == float(noise3([0.5, 0.25, 0.125]))
    True
    >>> a = fbm3([0.5, 0.25, 0.125], period=(8, 8, 0), seed=3)
    >>> bool(a == fbm3([8.5, 0.25, 0.125], period=(8, 8, 0), seed=3))
    True
    """
    return _fractal(p, "fbm", octaves, lacunarity, gain, gradient, step, dtype, out, threads,
                    period, seed)


def turbulence3(p, octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5, gradient=None,
                step=DEFAULT_CENTRAL_STEP, *, period=None, seed=0, dtype=None, out=None,
                threads=None):
    """Turbulence: sum_i gain^i |noise(lacunarity^i p)| (Perlin 1985). The
    analytic gradient takes sign(0) = +1 at zero crossings. Arguments as
    fractal3, period= and seed= included.

    >>> bool(turbulence3([[0.5, 0.25, 0.125]], octaves=3)[0] >= 0)
    True
    """
    return _fractal(p, "turbulence", octaves, lacunarity, gain, gradient, step, dtype, out,
                    threads, period, seed)


# ---- footprints ----------------------------------------------------------------

def fractal3_footprint(p, footprint, function="fbm", octaves=DEFAULT_OCTAVES, lacunarity=2.0,
                       gain=0.5, *, dtype=None, out=None, threads=None):
    """Fractal value and analytic gradient with per-point footprints, float32
    only (bg_fractal3_grad_footprint_batch): octave i is weighted by
    clamp(2 - 4 w lacunarity^i, 0, 1) for footprint w (noise space) and skipped
    where that is 0. footprint broadcasts against p's batch shape. Returns
    (value, gradient); out is (value_out, gradient_out).

    >>> v, g = fractal3_footprint([[0.5, 0.25, 0.125]], 0.0, octaves=2)
    >>> bool(v[0] == fbm3([[0.5, 0.25, 0.125]], octaves=2, dtype="float32")[0])
    True
    """
    fn = _choice("function", function, _FUNCTIONS)
    octaves = _int_arg("octaves", octaves, 1, MAX_OCTAVES)
    lacunarity = _float_arg("lacunarity", lacunarity, "positive")
    gain = _float_arg("gain", gain)
    nt = _threads(threads)
    dt = _dtype(dtype, [], "fractal3_footprint")
    comps, pshape, tup = _split(p, "p")
    fp = _asfloat(footprint, "footprint")
    shape = _broadcast(("p", "footprint"), (pshape, fp.shape))
    x, y, z = (_flat(c, shape, dt) for c in comps)
    vout, gout = _out_pair(out)
    vo = _Out(vout, shape, dt, "out[0]", False, tup)
    go = _Out(gout, shape, dt, "out[1]", True, tup)
    _c.footprint(fn, octaves, lacunarity, gain, nt, _flat(fp, shape, dt), x, y, z, vo.flat,
                 *go.rows)
    return vo.result(), go.result()


def _octaves(kind, footprint, lac, k, dtype, out, threads, name):
    nt = _threads(threads)
    dt = _dtype(dtype, [], name)
    fp = _asfloat(footprint, "footprint")
    o = _Out(out, fp.shape, dt, "out", False, False)
    _c.octaves(kind, _flat(fp, fp.shape, dt), o.flat, lac, k, nt)
    return o.result()


def octave_weight(footprint, lacunarity=2.0, octave=0, *, dtype=None, out=None, threads=None):
    """Weight c_i of octave `octave` (integer, 0-based) for footprints (array,
    noise space): bg_octave_weight, float32 only. NaN footprint: 1 (no filtering).

    >>> float(octave_weight(0.0)), float(octave_weight(0.5))
    (1.0, 0.0)
    """
    lac = _float_arg("lacunarity", lacunarity, "positive")
    k = _int_arg("octave", octave, 0, MAX_OCTAVES - 1)
    return _octaves(0, footprint, lac, k, dtype, out, threads, "octave_weight")


def octaves_for_footprint(footprint, max_octaves=DEFAULT_OCTAVES, *, dtype=None, out=None,
                          threads=None):
    """Effective octave count for lacunarity 2 (bg_octaves_for_footprint), float32
    only: max_octaves for a tiny footprint, about 2.5 for 1/16, 0 from 1/2 on.

    >>> octaves_for_footprint([0.0, 0.5], 6).tolist()
    [6.0, 0.0]
    """
    k = _int_arg("max_octaves", max_octaves, 1, MAX_OCTAVES)
    return _octaves(1, footprint, 2.0, k, dtype, out, threads, "octaves_for_footprint")


# ---- surface gradient and perturbation ---------------------------------------------

def _vec_op(op, names, arrays, dtype, out, threads):
    nt = _threads(threads)
    parts = [_split(a, n) for n, a in zip(names, arrays)]
    shape = _broadcast(names, [s for _, s, _ in parts])
    dt = _dtype(dtype, [c for cs, _, _ in parts for c in cs])
    comps = [_flat(c, shape, dt) for cs, _, _ in parts for c in cs]
    while len(comps) < 9:
        comps.append(comps[0])
    o = _Out(out, shape, dt, "out", True, parts[0][2])
    _c.vec(op, dt is _F64, nt, *comps, *o.rows)
    return o.result()


def surface_gradient(n, g, *, dtype=None, out=None, threads=None):
    """Surface gradient g - n (n.g) (Mikkelsen 2010, eq. 2): the volume gradient g
    projected onto the tangent plane of n (normalized first). Invalid n or
    non-finite g: (0, 0, 0). Vectors (..., 3) or three arrays each; they broadcast.

    >>> surface_gradient([0.0, 0.0, 1.0], [1.0, 2.0, 3.0]).tolist()
    [1.0, 2.0, 0.0]
    """
    return _vec_op(0, ("n", "g"), (n, g), dtype, out, threads)


def perturb(n, g, method="surfgrad", *, dtype=None, out=None, threads=None):
    """Perturbed normal from unit normal n and volume gradient g
    (bg_perturb_batch, bg_perturbd). method 'surfgrad': normalize(n - (g - n (n.g)))
    (eq. 4, Listing 3); 'additive': normalize(n - g); 'additive-perlin':
    normalize(n + g) (Perlin 1985's sign). Invalid n: (0, 0, 0); non-finite g:
    the unit n.

    >>> perturb([0.0, 0.0, 1.0], [0.0, 0.0, 5.0]).tolist()
    [0.0, 0.0, 1.0]
    """
    m = _choice("method", method, _METHODS)
    return _vec_op(1 + m, ("n", "g"), (n, g), dtype, out, threads)


def perturb_height(p, n, function="turbulence", octaves=DEFAULT_OCTAVES, lacunarity=2.0,
                   gain=0.5, amplitude=0.1, frequency=1.0, gradient="analytic",
                   step=DEFAULT_CENTRAL_STEP, method="surfgrad", footprint=None, *,
                   period=None, seed=0, dtype=None, out=None, threads=None):
    """The fused "height gradient -> perturbed normal" call, float32 only
    (bg_perturb_height_batch): h(p) = amplitude F(frequency p) with F the
    fractal, its gradient ('analytic', or 'central' with `step`), and the normal
    n perturbed with `method`. amplitude, frequency and footprint may be scalars
    or per-point arrays; every array broadcasts against p's and n's batch
    shapes. footprint (world units) selects bg_perturb_height_footprint_batch
    (always analytic). period= and seed= tile and vary the fractal as in
    fractal3 (bg_height.domain; periods in noise-space units, frequency * p).
    Defaults are bg_height_default(): 6-octave turbulence,
    amplitude 0.1, frequency 1. Returns (height, normal); out is
    (height_out, normal_out).

    >>> h, nn = perturb_height([[0.5, 0.25, 0.125]], [0.0, 0.0, 1.0], amplitude=0.0)
    >>> nn.tolist()
    [[0.0, 0.0, 1.0]]
    """
    fn = _choice("function", function, _FUNCTIONS)
    m = _choice("method", method, _METHODS)
    grad = _gradient(gradient, allow_none=False) - 1
    octaves = _int_arg("octaves", octaves, 1, MAX_OCTAVES)
    lacunarity = _float_arg("lacunarity", lacunarity, "positive")
    gain = _float_arg("gain", gain)
    step = _float_arg("step", step, "positive")
    dom = _domain(period, seed)
    _domain_fits(dom[0], octaves, float(_np.float32(lacunarity)))
    nt = _threads(threads)
    dt = _dtype(dtype, [], "perturb_height")
    pc, pshape, tup = _split(p, "p")
    nc, nshape, _ = _split(n, "n")
    extra, names, shapes = {}, ["p", "n"], [pshape, nshape]
    scal = {}
    for name, v in (("amplitude", amplitude), ("frequency", frequency)):
        if _np.ndim(v) == 0 and not isinstance(v, _np.ndarray):
            scal[name] = _float_arg(name, v)
            continue
        a = _asfloat(v, name).astype(_F32)
        bad = ~_np.isfinite(a)
        if bad.any():
            raise ValueError(f"{name} must be finite, got {a[bad].flat[0]}")
        extra[name] = a
        names.append(name)
        shapes.append(a.shape)
        # The C call validates the scalar: the largest magnitude stands for all.
        scal[name] = float(a.flat[_np.argmax(_np.abs(a))]) if a.size else 1.0
    if footprint is not None:
        extra["footprint"] = _asfloat(footprint, "footprint")
        names.append("footprint")
        shapes.append(extra["footprint"].shape)
    shape = _broadcast(names, shapes)
    px, py, pz = (_flat(c, shape, dt) for c in pc)
    nx, ny, nz = (_flat(c, shape, dt) for c in nc)
    fp, amp, freq = (_flat(extra[k], shape, dt) if k in extra else None
                     for k in ("footprint", "amplitude", "frequency"))
    hout, nout = _out_pair(out)
    ho = _Out(hout, shape, dt, "out[0]", False, tup)
    no = _Out(nout, shape, dt, "out[1]", True, tup)
    _c.perturb_height(fn, octaves, lacunarity, gain, scal["amplitude"], scal["frequency"], grad,
                      step, m, nt, px, py, pz, nx, ny, nz, ho.flat, *no.rows, fp, amp, freq,
                      *dom)
    return ho.result(), no.result()


# ---- the framework ------------------------------------------------------------------

def resolve_normal(n, *surfgrads, weights=None, dtype=None, out=None, threads=None):
    """The normal resolve n' = normalize(n - sum_i w_i g_i) (the framework's one
    resolve; each term is eq. 4 of Mikkelsen 2010). Each positional argument
    after n is one influence's surface gradient, (..., 3) or three arrays; all
    broadcast. weights: one float per influence (default all 1). In float32 each
    influence is added with bg_surfgrad_accumulate_batch (weight * g rounded, then
    added), then bg_resolve_normal_batch forms the normal; in float64 the
    weighted sum is formed in numpy in argument order, then bg_resolve_normald.
    Invalid n: (0, 0, 0); a NaN/Inf sum contributes nothing. With no influence:
    the unit n.

    >>> resolve_normal([0.0, 0.0, 2.0]).tolist()
    [0.0, 0.0, 1.0]
    """
    nt = _threads(threads)
    if weights is None:
        weights = [1.0] * len(surfgrads)
    weights = [_float_arg("weights", w) for w in _np.atleast_1d(_np.asarray(weights)).tolist()]
    if len(weights) != len(surfgrads):
        raise ValueError(f"weights needs one value per surface gradient: {len(surfgrads)} "
                         f"surface gradients, {len(weights)} weights")
    names = ["n"] + [f"surfgrads[{i}]" for i in range(len(surfgrads))]
    parts = [_split(a, nm) for nm, a in zip(names, (n,) + surfgrads)]
    shape = _broadcast(names, [s for _, s, _ in parts])
    dt = _dtype(dtype, [c for cs, _, _ in parts for c in cs])
    nx, ny, nz = (_flat(c, shape, dt) for c in parts[0][0])
    size = _math.prod(shape)
    acc = _np.zeros((3, size), dt)
    for (cs, _, _), w in zip(parts[1:], weights):
        g = [_flat(c, shape, dt) for c in cs]
        if dt == _F32:
            _c.accumulate(w, nt, *g, acc[0], acc[1], acc[2])
        else:
            acc += w * _np.stack(g)
    o = _Out(out, shape, dt, "out", True, parts[0][2])
    _c.vec(6, dt is _F64, nt, nx, ny, nz, acc[0], acc[1], acc[2], nx, ny, nz, *o.rows)
    return o.result()


def surfgrad_from_tangent_normal(t, b, m, *, dtype=None, out=None, threads=None):
    """Surface gradient -(m.x/m.z) t - (m.y/m.z) b of a tangent-space normal m in
    the frame (t, b) (bg_surfgrad_from_tangent_normal), with the framework's
    clamp: m.z replaced by max(|m.z|, max(|m.x|, |m.y|) / 128).

    >>> import numpy
    >>> g = surfgrad_from_tangent_normal([1.0, 0, 0], [0, 1.0, 0], [0.5, 0, 1.0])
    >>> bool(numpy.allclose(g, [-0.5, 0, 0]))
    True
    """
    return _vec_op(4, ("t", "b", "m"), (t, b, m), dtype, out, threads)


def surfgrad_from_perturbed_normal(n, m, *, dtype=None, out=None, threads=None):
    """Surface gradient of an object-space perturbed normal m relative to the
    base normal n (bg_surfgrad_from_perturbed_normal): -m_t / max(|k|, |m_t|/128)
    with k = m.n, m_t = m - k n.

    >>> import numpy
    >>> g = surfgrad_from_perturbed_normal([0, 0, 1.0], [0.5, 0, 1.0])
    >>> bool(numpy.allclose(g, [-0.5, 0, 0]))
    True
    """
    return _vec_op(5, ("n", "m"), (n, m), dtype, out, threads)


def _triplanar(n, k, ds, dtype, out, threads):
    k = _float_arg("k", k, "nonneg")
    nt = _threads(threads)
    names, parts = ["n"], [_split(n, "n")]
    if ds is not None:
        for name, d in zip(("d_yz", "d_xz", "d_xy"), ds):
            names.append(name)
            parts.append(_split(d, name, width=2))
    shape = _broadcast(names, [s for _, s, _ in parts])
    dt = _dtype(dtype, [c for cs, _, _ in parts for c in cs])
    comps = [_flat(c, shape, dt) for cs, _, _ in parts for c in cs]
    if ds is None:
        comps += [None] * 6
    o = _Out(out, shape, dt, "out", True, parts[0][2])
    _c.triplanar(dt is _F64, k, nt, *comps, *o.rows)
    return o.result()


def triplanar_weights(n, k=4.0, *, dtype=None, out=None, threads=None):
    """Triplanar blend weights |n_i|^k / sum_j |n_j|^k (bg_triplanar_weights);
    k finite >= 0. n invalid: (0, 0, 0).

    >>> triplanar_weights([0.0, 0.0, 1.0]).tolist()
    [0.0, 0.0, 1.0]
    """
    return _triplanar(n, k, None, dtype, out, threads)


def surfgrad_triplanar(n, k, d_yz, d_xz, d_xy, *, dtype=None, out=None, threads=None):
    """Triplanar surface gradient (bg_surfgrad_triplanar): the three planar height
    derivatives d_yz = (dh/dy, dh/dz), d_xz = (dh/dx, dh/dz), d_xy = (dh/dx, dh/dy),
    each (..., 2) or two arrays, blended with triplanar_weights(n, k) and
    projected (eq. 2). All arrays broadcast.

    >>> surfgrad_triplanar([0.0, 0.0, 1.0], 4.0, [0.0, 0.0], [0.0, 0.0], [1.0, 2.0]).tolist()
    [1.0, 2.0, 0.0]
    """
    return _triplanar(n, k, (d_yz, d_xz, d_xy), dtype, out, threads)


# ---- deprecated float64 aliases ---------------------------------------------------------

def noise3d(p, grad=False, **kw):
    """Deprecated: noise3(p, gradient='analytic' if grad else None, dtype=numpy.float64)."""
    _deprecated("noise3d", "noise3(p, dtype=numpy.float64)")
    return _noise3(p, "analytic" if grad else None, dtype=_F64, **kw)


def _alias(name, fn):
    def alias(*args, **kw):
        _deprecated(name + "d", f"{name}(..., dtype=numpy.float64)")
        return fn(*args, dtype=_F64, **kw)
    alias.__name__ = alias.__qualname__ = name + "d"
    alias.__doc__ = f"Deprecated: {name}(..., dtype=numpy.float64)."
    return alias


fractal3d = _alias("fractal3", fractal3)
fbm3d = _alias("fbm3", fbm3)
turbulence3d = _alias("turbulence3", turbulence3)
surface_gradientd = _alias("surface_gradient", surface_gradient)
perturbd = _alias("perturb", perturb)
resolve_normald = _alias("resolve_normal", resolve_normal)
surfgrad_from_tangent_normald = _alias("surfgrad_from_tangent_normal",
                                       surfgrad_from_tangent_normal)
surfgrad_from_perturbed_normald = _alias("surfgrad_from_perturbed_normal",
                                         surfgrad_from_perturbed_normal)
triplanar_weightsd = _alias("triplanar_weights", triplanar_weights)
surfgrad_triplanard = _alias("surfgrad_triplanar", surfgrad_triplanar)


# ---- the tools (builds with OpenImageIO, OpenVDB and assimp) ---------------------------------

_SPACES = {"tangent": 0, "object": 1}
_TANGENTS = {"mikktspace": 0, "file": 1}
_Y = {"+y": 0, "-y": 1}
_FILTERS = {"footprint": 0, "none": 1}
_UNITS = {"model": 0, "file": 1}
_DEPTHS = {None: -1, 8: 0, 16: 1, "half": 2, "float": 3}


def _need_tools(name):
    if not HAVE_TOOLS:
        raise Error(6, "not available", f"{name} needs a build with the tools "
                    "(OpenImageIO, OpenVDB, assimp)")


def read_image(path):
    """An image file as a float32 array of shape (height, width, channels), row 0
    at the top, as bg_image_read gives it (8- and 16-bit formats map to [0, 1]).
    Raises bumpgrad.Error naming the file when it cannot be read. Tools builds only.

    >>> read_image("/no/such/file.png")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bumpgrad.Error: ...
    """
    _need_tools("read_image")
    return _c.read_image(_os.fsdecode(path))


_BITS = {8: 0, 16: 1, "half": 2, "float": 3, 32: 3}


def write_image(path, image, bits=8, srgb=False):
    """Write an array (height, width) or (height, width, channels), row 0 at the
    top, to an image file (format from the extension) with bg_image_write:
    through a temporary file, renamed when complete. bits: 8, 16, 'half' or
    'float' (the file format must store it); srgb=True encodes linear values
    with the sRGB curve. Tools builds only.

    >>> write_image("/no/such/dir/x.png", [[0.5]])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bumpgrad.Error: ...
    """
    _need_tools("write_image")
    a = _asfloat(image, "image")
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3 or not 1 <= a.shape[2] <= 4 or a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError(f"image must have shape (height, width) or (height, width, 1..4), "
                         f"got {a.shape}")
    _c.write_image(_os.fsdecode(path), _np.ascontiguousarray(a, dtype=_F32),
                   _choice("bits", bits, _BITS), int(bool(srgb)))


_GRAYS = {"diffuse": 0, "rec709": 1}


def heightmap(image, path=None, *, strength=1.0, edge="clamp", normal_map_y="+y",
              gray="diffuse", to_derivative=False, bits=None):
    """The tool behind ``bumpgrad heightmap`` (bgt_heightmap_run): an image's
    gray level as a height H into a tangent-space normal map
    n = normalize(-S a, -S b, 1) with a = H[x+1,y] - H[x-1,y], b = H[x,y-1] - H[x,y+1]
    stored as 0.5 n + 0.5; or, with to_derivative=True, a normal map into the
    derivative map (dh/du, dh/dv, 0).

    image      an image file name, or an array (height, width[, channels]) of
               float values, row 0 at the top (written to a float TIFF first).
    path       None: return the result as a float32 array (height, width, 3),
               exactly as a float file from the command holds it; or a file name
               to write (format from the extension) and return None.
    strength   the slope factor S (finite; negative inverts the bumps).
    edge       'clamp' or 'wrap' (the neighbours beyond the border).
    normal_map_y '+y' (OpenGL) or '-y' (DirectX: --y-down).
    gray       'diffuse' or 'rec709' (--gray): the gray level of a colour image.
    bits       with path: 8, 16 or 'float' (None: 8, or float with to_derivative).
    Raises bumpgrad.Error with the tool's message (unreadable image, a NaN
    sample, ...). Tools builds only.

    >>> import numpy
    >>> m = heightmap(numpy.zeros((4, 5)))
    >>> m.shape, m[0, 0].tolist()
    ((4, 5, 3), [0.5, 0.5, 1.0])
    """
    _need_tools("heightmap")
    strength = _float_arg("strength", strength)
    wrap = _choice("edge", edge, {"clamp": 0, "wrap": 1})
    y_down = _choice("normal_map_y", normal_map_y, _Y)
    if isinstance(gray, str) and gray == "seed":
        _warnings.warn("heightmap(gray='seed') is deprecated: use gray='diffuse' (the CLI's "
                       "--gray diffuse)", DeprecationWarning, stacklevel=2)
        gray = "diffuse"
    g = _choice("gray", gray, _GRAYS)
    nbits = _choice("bits", bits, {None: 0, 8: 8, 16: 16, "float": 32, 32: 32})
    if not isinstance(to_derivative, (bool, _np.bool_)):
        raise TypeError(f"to_derivative must be True or False, got {to_derivative!r}")
    import tempfile
    with tempfile.TemporaryDirectory(prefix="bumpgrad-heightmap-") as tmp:
        if isinstance(image, (str, bytes, _os.PathLike)):
            src = _os.fsdecode(image)
        else:
            src = _os.path.join(tmp, "in.tif")
            write_image(src, image, bits="float")
        if path is not None:
            _c.heightmap(src, _os.fsdecode(path), g, strength, wrap, y_down,
                         int(bool(to_derivative)), nbits)
            return None
        if bits is not None:
            raise ValueError("bits is for path=: the array is always float32")
        out = _os.path.join(tmp, "out.tif")
        _c.heightmap(src, out, g, strength, wrap, y_down, int(bool(to_derivative)), 32)
        return read_image(out)


def volume(bbox, voxel_size, path=None, *, band_sphere=None, function="turbulence",
           octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5, amplitude=0.1, frequency=1.0,
           gradient="analytic", step=DEFAULT_CENTRAL_STEP, period=None, seed=0, threads=None,
           progress=None,
           brick=None):
    """The tool behind ``bumpgrad volume`` (bgt_volume_run): the height field
    h(p) = amplitude F(frequency p) baked at the voxel centres S (i, j, k) inside
    the box, for any sub-box (docs/IO.md describes the file).

    bbox       (x0, y0, z0, x1, y1, z1): the voxels whose centre is inside.
    voxel_size S, finite > 0.
    path       a .vdb file name: write the FloatGrid "height" and the Vec3SGrid
               "gradient" (temporary file, renamed when complete) and return
               (active voxels, index lo (i, j, k), index hi). None: return
               (heights, gradients, lo): float32 arrays indexed
               [i - lo[0], j - lo[1], k - lo[2]] (gradients with a last axis of 3)
               holding the values the file holds. The tool runs first (into a
               temporary file: its checks and caps decide the box), then the
               tools' height source (bgt_height_gradient) is evaluated at the
               tool's voxel centres (float)(S * i), as the bake does. A dense box
               only: band_sphere needs a path.
    band_sphere (cx, cy, cz, r, w): only the voxels with | |p - c| - r | <= w.
    function ... step, period, seed: the height field, as perturb_height; threads, progress
               (progress(done, total) in rows of voxels) as bake_normal_map.
    brick      None, or (i, n) with path=: write only brick i (0 <= i < n) of n,
               as ``bumpgrad volume --brick i/n``; merge_volumes joins them.
    Raises bumpgrad.Error with the tool's message. Tools builds only.

    >>> h, g, lo = volume((0, 0, 0, 1, 1, 1), 0.5, amplitude=0.0)
    >>> h.shape, g.shape, lo, float(abs(h).max())
    ((3, 3, 3), (3, 3, 3, 3), (0, 0, 0), 0.0)
    """
    _need_tools("volume")
    try:
        box = [_float_arg(f"bbox[{i}]", v, f32=False) for i, v in enumerate(bbox)]
    except TypeError:
        raise TypeError(f"bbox must be 6 numbers (x0, y0, z0, x1, y1, z1), got {bbox!r}") from None
    if len(box) != 6:
        raise ValueError(f"bbox must be 6 numbers (x0, y0, z0, x1, y1, z1), got {len(box)}")
    voxel = _float_arg("voxel_size", voxel_size, "positive", f32=False)
    band = None
    if band_sphere is not None:
        band = tuple(_float_arg(f"band_sphere[{i}]", v, f32=False) for i, v in enumerate(band_sphere))
        if len(band) != 5:
            raise ValueError(f"band_sphere must be 5 numbers (cx, cy, cz, r, w), got {len(band)}")
        if path is None:
            raise ValueError("band_sphere needs path=: the array form is for dense boxes")
    fn, grad, octaves, lacunarity, gain, amplitude, frequency, step = _tool_height(
        function, gradient, octaves, lacunarity, gain, amplitude, frequency, step)
    dom = _domain(period, seed)
    _domain_fits(dom[0], octaves, float(_np.float32(lacunarity)))
    nt = _threads(threads)
    _progress_arg(progress)

    bi, bn = 0, 0
    if brick is not None:
        if path is None:
            raise ValueError("brick needs path=: a brick is a file to merge")
        try:
            bi, bn = brick
        except (TypeError, ValueError):
            raise TypeError(f"brick must be (i, n), got {brick!r}") from None
        bn = _int_arg("brick[1]", bn, 1, 1000000)
        bi = _int_arg("brick[0]", bi, 0, bn - 1)

    def run(target):
        return _c.volume_bake(target, *box, voxel, band, fn, octaves, lacunarity, gain,
                              amplitude, frequency, step, grad, nt, progress, *dom, bi, bn)

    if path is not None:
        return run(_os.fsdecode(path))
    import tempfile
    with tempfile.TemporaryDirectory(prefix="bumpgrad-volume-") as tmp:
        target = _os.path.join(tmp, "volume.vdb")
        _, lo, hi = run(target)
    axes = [_np.arange(a, b + 1, dtype=_np.int64) for a, b in zip(lo, hi)]
    ii, jj, kk = _np.meshgrid(*axes, indexing="ij")
    # The tool's voxel centres: (float)(S * i) (src/tools/bake/volume.c).
    pts = [(voxel * a).astype(_F32).reshape(-1) for a in (ii, jj, kk)]
    heights = _np.empty(ii.size, _F32)
    grads = _np.empty((3, ii.size), _F32)
    _c.height_field(fn, octaves, lacunarity, gain, amplitude, frequency, step, grad, nt, *pts,
                    heights, grads[0], grads[1], grads[2], *dom)
    return (heights.reshape(ii.shape), _np.moveaxis(grads.reshape((3,) + ii.shape), 0, -1),
            tuple(lo))


def merge_volumes(path, bricks):
    """Merge the brick files of one volume (volume(..., brick=(i, n)) or
    ``bumpgrad volume --brick I/N``) into the VDB file `path`, as ``bumpgrad
    volume --merge``: OpenVDB's tree merge, the bricks checked to hold the same
    grids, voxel size and height parameters and no common voxel; the result is
    the single-run volume voxel for voxel. Written through a temporary file.
    Raises bumpgrad.Error naming the bad brick. Tools builds only.

    >>> merge_volumes("/tmp/out.vdb", ["/no/such/brick.vdb"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bumpgrad.Error: ...
    """
    _need_tools("merge_volumes")
    files = [_os.fsdecode(b) for b in bricks]
    if not files:
        raise ValueError("bricks must name at least one file")
    _c.vdb_merge(_os.fsdecode(path), files)
    return None


def bake_normal_map(mesh_path, size, path=None, *, function="turbulence",
                    octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5, amplitude=0.1,
                    frequency=1.0, gradient="analytic", step=DEFAULT_CENTRAL_STEP,
                    method="surfgrad", space="tangent", padding=16, tangents="mikktspace",
                    normal_map_y="+y", recompute_normals=False, depth=None, udim=False,
                    period=None, seed=0, threads=None, progress=None, tile=None,
                    samples=None, filter="footprint", units="model"):
    """Bake the normal map of a mesh bumped by a solid height field: the tool
    behind ``bumpgrad mesh --bake-normal-map`` (bgt_mesh_run), with the CLI's
    options as keyword arguments (docs/MESH.md).

    mesh_path  any mesh assimp reads, with UV set 0.
    size       texels: N or (width, height), per UDIM tile.
    path       None: return the map as a float32 array (height, width, 3) holding
               the encoded normal 0.5 m + 0.5 exactly as a float file from the
               CLI holds it; with udim=True a dict {udim: array} of the tiles.
               A file name: write the map (format from the extension, one file per
               tile when it holds <UDIM>) and return the list of UDIM tiles written.
    function, octaves, lacunarity, gain, amplitude, frequency, gradient, step,
    method, period, seed: the height field and perturbation, as perturb_height.
    space      'tangent' (mikkTSpace frame) or 'object'; tangents 'mikktspace' or
               'file'; normal_map_y '+y' (OpenGL, glTF) or '-y' (DirectX).
    padding    dilate into empty texels this many times (integer >= 0; 16, as the CLI).
    samples    None: the default anti-aliasing (2 x 2 points per texel, 7 where an
               octave is finer than 4 texels); N (1..16): N x N points per texel
               (``--samples``; docs/MESH.md, "Anti-aliasing").
    filter     'footprint' (octaves finer than a texel fade out) or 'none'
               (every octave at each point), as ``--filter``.
    units      'model' (frequency and amplitude per model radius) or 'file' (the
               file's own units), as ``--units``.
    depth      None (the tool's default for the file type), 8, 16, 'half' or 'float'.
    threads    worker threads (default: all cores).
    tile       None, or one UDIM number (1001..1999) with udim=True or a path
               holding <UDIM>: bake that tile alone, texel for texel the full
               bake's tile (``bumpgrad mesh --tile``; one job per tile).
    progress   None, or a callable progress(done, total) called with texel
               counts about 100 times during the bake (from the bake's threads).
    Raises bumpgrad.Error with the tool's message (missing mesh, no UVs, a map
    too large for BUMPGRAD_MAX_MB, ...). Tools builds only (bumpgrad.HAVE_TOOLS).

    >>> bake_normal_map("/no/such/mesh.obj", 16)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bumpgrad.Error: ...
    """
    _need_tools("bake_normal_map")
    if isinstance(size, tuple) and len(size) == 2:
        w = _int_arg("size[0]", size[0], 1, 1 << 16)
        h = _int_arg("size[1]", size[1], 1, 1 << 16)
    else:
        w = h = _int_arg("size", size, 1, 1 << 16)
    fn, grad, octaves, lacunarity, gain, amplitude, frequency, step = _tool_height(
        function, gradient, octaves, lacunarity, gain, amplitude, frequency, step)
    m = _choice("method", method, _METHODS)
    sp = _choice("space", space, _SPACES)
    tg = _choice("tangents", tangents, _TANGENTS)
    gy = _choice("normal_map_y", normal_map_y, _Y)
    padding = _int_arg("padding", padding, 0, 4096)
    ns = 0 if samples is None else _int_arg("samples", samples, 1, 16)
    flt = _choice("filter", filter, _FILTERS)
    un = _choice("units", units, _UNITS)
    dp = _choice("depth", depth, _DEPTHS)
    dom = _domain(period, seed)
    _domain_fits(dom[0], octaves, float(_np.float32(lacunarity)))
    nt = _threads(threads)
    _progress_arg(progress)
    mesh_path = _os.fsdecode(mesh_path)
    if not isinstance(recompute_normals, (bool, _np.bool_)):
        raise TypeError(f"recompute_normals must be True or False, got {recompute_normals!r}")

    only = 0 if tile is None else _int_arg("tile", tile, 1001, 1999)

    def run(target, depth_code):
        return _c.mesh_bake(mesh_path, target, w, h, fn, octaves, lacunarity, gain, amplitude,
                            frequency, step, grad, m, sp, padding, tg, gy,
                            int(bool(recompute_normals)), depth_code, nt, progress, *dom, only,
                            ns, flt, un)

    if path is not None:
        return run(_os.fsdecode(path), dp)[4]
    import tempfile
    with tempfile.TemporaryDirectory(prefix="bumpgrad-bake-") as tmp:
        target = _os.path.join(tmp, "map<UDIM>.tif" if udim else "map.tif")
        tiles = run(target, _DEPTHS["float"])[4]
        if not udim:
            return read_image(target)
        return {t: read_image(_os.path.join(tmp, f"map{t:04d}.tif")) for t in tiles}


def render(scene="sphere", *, mesh=None, size=384, method="surfgrad", spp=1,
           function="turbulence", octaves=DEFAULT_OCTAVES, lacunarity=2.0, gain=0.5,
           amplitude=0.06, frequency=1.0, gradient="analytic", step=DEFAULT_CENTRAL_STEP,
           period=None, seed=0, threads=None, progress=None):
    """Ray-cast a bumped scene: the tool behind ``bumpgrad render``
    (bgt_render_run, docs/FIGURES.md), with its options as keyword arguments.
    The tool writes files only, so the image is written to a float TIFF in a
    private temporary folder and read back with read_image: the array holds
    exactly what ``bumpgrad render -o FILE.tif`` (or .exr) writes with the
    same options.

    scene      'sphere', 'blob' or 'torus' (--scene); ignored with mesh=.
    mesh       None, or any mesh file assimp reads (--mesh).
    size       pixels: N or (width, height) (--size).
    method     the normal perturbation (--method): 'surfgrad', 'surfgrad-central',
               'listing1', 'listing1-coarse', 'additive', 'flat', 'none', ...
    spp        samples per pixel, a square 1..256 (--spp).
    function ... step: the height field, as perturb_height (the CLI's height
               options; the default amplitude 0.06 is the renderer's).
    period, seed: the tileable, seeded noise domain, as fbm3 (--period, --seed).
    threads    worker threads (default: all cores); progress as bake_normal_map.
    Returns a float32 array (height, width, channels), row 0 at the top.
    Raises bumpgrad.Error with the tool's message. Tools builds only.

    >>> img = render(size=(32, 24), amplitude=0.0)
    >>> img.shape[:2], img.dtype
    ((24, 32), dtype('float32'))
    """
    _need_tools("render")
    if isinstance(size, tuple) and len(size) == 2:
        w = _int_arg("size[0]", size[0], 1, 1 << 16)
        h = _int_arg("size[1]", size[1], 1, 1 << 16)
    else:
        w = h = _int_arg("size", size, 1, 1 << 16)
    n = _int_arg("spp", spp, 1, 256)
    ss = int(round(_math.sqrt(n)))
    if ss * ss != n:
        raise ValueError(f"spp must be a square (1, 4, 9, 16, ...), got {n}")
    if not isinstance(scene, str):
        raise TypeError(f"scene must be a string, got {scene!r}")
    if not isinstance(method, str):
        raise TypeError(f"method must be a string, got {method!r}")
    fn, grad, octaves, lacunarity, gain, amplitude, frequency, step = _tool_height(
        function, gradient, octaves, lacunarity, gain, amplitude, frequency, step)
    per, sd = _domain(period, seed)
    _domain_fits(per, octaves, float(_np.float32(lacunarity)))
    nt = _threads(threads)
    _progress_arg(progress)
    mesh = None if mesh is None else _os.fsdecode(mesh)
    import tempfile
    with tempfile.TemporaryDirectory(prefix="bumpgrad-render-") as tmp:
        target = _os.path.join(tmp, "render.tif")
        _c.render(target, scene, mesh, w, h, ss, method, fn, octaves, lacunarity, gain,
                  amplitude, frequency, step, grad, per, sd, nt, progress)
        return read_image(target)


# ---- ISA ------------------------------------------------------------------------------

def isa_best():
    """Highest kernel ISA this CPU and build support: 'scalar', 'sse2', 'avx2',
    'avx512' or 'neon'.

    >>> isa_best() in ("scalar", "sse2", "avx2", "avx512", "neon")
    True
    """
    return _c.isa("best")


def isa_active():
    """ISA the batch calls use now (first call reads $BUMPGRAD_ISA).

    >>> isa_active() in ("scalar", "sse2", "avx2", "avx512", "neon")
    True
    """
    return _c.isa("active")


def isa_force(name):
    """Force the batch kernels down to ISA `name` (bg_isa_force; every ISA gives the
    same bits). Raises bumpgrad.Error for an unknown name or one above isa_best().
    Not thread-safe against concurrent calls: call it before starting work.

    >>> isa_force(isa_best())
    """
    _c.isa("force", str(name))
