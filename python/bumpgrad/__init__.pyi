# SPDX-License-Identifier: MIT
# Type stubs of the bumpgrad package (python/bumpgrad/__init__.py documents each call).
import os
from typing import Any, Callable, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str
DEFAULT_OCTAVES: int
MAX_OCTAVES: int
MAX_PERIOD: int
DEFAULT_CENTRAL_STEP: float
HAVE_TOOLS: bool

_Array = npt.NDArray[np.floating[Any]]
_Points = Union[npt.ArrayLike, Tuple[npt.ArrayLike, npt.ArrayLike, npt.ArrayLike]]
_Pairs = Union[npt.ArrayLike, Tuple[npt.ArrayLike, npt.ArrayLike]]
_DType = Union[None, str, type, np.dtype[Any]]
_Function = Literal["noise", "fbm", "turbulence"]
_Gradient = Optional[Literal["analytic", "central"]]
_Method = Literal["surfgrad", "additive", "additive-perlin"]
_Vec = Union[_Array, Tuple[_Array, _Array, _Array]]
_Scalar = Union[_Array, np.floating[Any]]
_Period = Union[None, int, Tuple[int, int, int]]

class Error(Exception):
    status: int
    text: str
    what: str
    def __init__(self, status: int, text: str, what: str = ...) -> None: ...

@overload
def noise3(p: _Points, gradient: None = ..., *, period: _Period = ..., seed: int = ...,
           dtype: _DType = ..., out: Optional[_Array] = ...,
           threads: Optional[int] = ...) -> _Scalar: ...
@overload
def noise3(p: _Points, gradient: Literal["analytic", "central"], *, period: _Period = ...,
           seed: int = ..., dtype: _DType = ...,
           out: Optional[Tuple[Optional[_Array], Optional[_Vec]]] = ...,
           threads: Optional[int] = ...) -> Tuple[_Scalar, _Vec]: ...
@overload
def fractal3(p: _Points, function: _Function = ..., octaves: int = ..., lacunarity: float = ...,
             gain: float = ..., gradient: None = ..., step: float = ..., *,
             period: _Period = ..., seed: int = ..., dtype: _DType = ...,
             out: Optional[_Array] = ..., threads: Optional[int] = ...) -> _Scalar: ...
@overload
def fractal3(p: _Points, function: _Function, octaves: int, lacunarity: float, gain: float,
             gradient: Literal["analytic", "central"], step: float = ..., *,
             period: _Period = ..., seed: int = ..., dtype: _DType = ...,
             out: Optional[Tuple[Optional[_Array], Optional[_Vec]]] = ...,
             threads: Optional[int] = ...) -> Tuple[_Scalar, _Vec]: ...
@overload
def fractal3(p: _Points, function: _Function = ..., octaves: int = ..., lacunarity: float = ...,
             gain: float = ..., *, gradient: Literal["analytic", "central"], step: float = ...,
             period: _Period = ..., seed: int = ..., dtype: _DType = ...,
             out: Optional[Tuple[Optional[_Array], Optional[_Vec]]] = ...,
             threads: Optional[int] = ...) -> Tuple[_Scalar, _Vec]: ...
def fbm3(p: _Points, octaves: int = ..., lacunarity: float = ..., gain: float = ...,
         gradient: _Gradient = ..., step: float = ..., *, period: _Period = ...,
         seed: int = ..., dtype: _DType = ..., out: Any = ...,
         threads: Optional[int] = ...) -> Any: ...
def turbulence3(p: _Points, octaves: int = ..., lacunarity: float = ..., gain: float = ...,
                gradient: _Gradient = ..., step: float = ..., *, period: _Period = ...,
                seed: int = ..., dtype: _DType = ...,
                out: Any = ..., threads: Optional[int] = ...) -> Any: ...
def fractal3_footprint(p: _Points, footprint: npt.ArrayLike, function: _Function = ...,
                       octaves: int = ..., lacunarity: float = ..., gain: float = ..., *,
                       dtype: _DType = ..., out: Optional[Tuple[Optional[_Array], Optional[_Vec]]] = ...,
                       threads: Optional[int] = ...) -> Tuple[_Scalar, _Vec]: ...
def octave_weight(footprint: npt.ArrayLike, lacunarity: float = ..., octave: int = ..., *,
                  dtype: _DType = ..., out: Optional[_Array] = ...,
                  threads: Optional[int] = ...) -> _Scalar: ...
def octaves_for_footprint(footprint: npt.ArrayLike, max_octaves: int = ..., *, dtype: _DType = ...,
                          out: Optional[_Array] = ..., threads: Optional[int] = ...) -> _Scalar: ...
def surface_gradient(n: _Points, g: _Points, *, dtype: _DType = ..., out: Optional[_Vec] = ...,
                     threads: Optional[int] = ...) -> _Vec: ...
def perturb(n: _Points, g: _Points, method: _Method = ..., *, dtype: _DType = ...,
            out: Optional[_Vec] = ..., threads: Optional[int] = ...) -> _Vec: ...
def perturb_height(p: _Points, n: _Points, function: _Function = ..., octaves: int = ...,
                   lacunarity: float = ..., gain: float = ..., amplitude: npt.ArrayLike = ...,
                   frequency: npt.ArrayLike = ..., gradient: Literal["analytic", "central"] = ...,
                   step: float = ..., method: _Method = ...,
                   footprint: Optional[npt.ArrayLike] = ..., *, period: _Period = ...,
                   seed: int = ..., dtype: _DType = ...,
                   out: Optional[Tuple[Optional[_Array], Optional[_Vec]]] = ...,
                   threads: Optional[int] = ...) -> Tuple[_Scalar, _Vec]: ...
def resolve_normal(n: _Points, *surfgrads: _Points, weights: Optional[Sequence[float]] = ...,
                   dtype: _DType = ..., out: Optional[_Vec] = ...,
                   threads: Optional[int] = ...) -> _Vec: ...
def surfgrad_from_tangent_normal(t: _Points, b: _Points, m: _Points, *, dtype: _DType = ...,
                                 out: Optional[_Vec] = ..., threads: Optional[int] = ...) -> _Vec: ...
def surfgrad_from_perturbed_normal(n: _Points, m: _Points, *, dtype: _DType = ...,
                                   out: Optional[_Vec] = ..., threads: Optional[int] = ...) -> _Vec: ...
def triplanar_weights(n: _Points, k: float = ..., *, dtype: _DType = ..., out: Optional[_Vec] = ...,
                      threads: Optional[int] = ...) -> _Vec: ...
def surfgrad_triplanar(n: _Points, k: float, d_yz: _Pairs, d_xz: _Pairs, d_xy: _Pairs, *,
                       dtype: _DType = ..., out: Optional[_Vec] = ...,
                       threads: Optional[int] = ...) -> _Vec: ...
def isa_best() -> str: ...
def isa_active() -> str: ...
def isa_force(name: str) -> None: ...

# Deprecated float64 names: the functions above with dtype=numpy.float64.
def noise3d(p: _Points, grad: bool = ..., **kw: Any) -> Any: ...
def fractal3d(*args: Any, **kw: Any) -> Any: ...
def fbm3d(*args: Any, **kw: Any) -> Any: ...
def turbulence3d(*args: Any, **kw: Any) -> Any: ...
def surface_gradientd(*args: Any, **kw: Any) -> _Vec: ...
def perturbd(*args: Any, **kw: Any) -> _Vec: ...
def resolve_normald(*args: Any, **kw: Any) -> _Vec: ...
def surfgrad_from_tangent_normald(*args: Any, **kw: Any) -> _Vec: ...
def surfgrad_from_perturbed_normald(*args: Any, **kw: Any) -> _Vec: ...
def triplanar_weightsd(*args: Any, **kw: Any) -> _Vec: ...
def surfgrad_triplanard(*args: Any, **kw: Any) -> _Vec: ...

# The tools (HAVE_TOOLS builds; otherwise they raise Error).
def read_image(path: Union[str, "os.PathLike[str]"]) -> npt.NDArray[np.float32]: ...
def bake_normal_map(mesh_path: Union[str, "os.PathLike[str]"], size: Union[int, Tuple[int, int]],
                    path: Optional[Union[str, "os.PathLike[str]"]] = ..., *,
                    function: _Function = ..., octaves: int = ..., lacunarity: float = ...,
                    gain: float = ..., amplitude: float = ..., frequency: float = ...,
                    gradient: Literal["analytic", "central"] = ..., step: float = ...,
                    method: _Method = ..., space: Literal["tangent", "object"] = ...,
                    padding: int = ..., tangents: Literal["mikktspace", "file"] = ...,
                    normal_map_y: Literal["+y", "-y"] = ..., recompute_normals: bool = ...,
                    depth: Union[None, int, str] = ..., udim: bool = ...,
                    period: _Period = ..., seed: int = ..., threads: Optional[int] = ...,
                    progress: Optional[Callable[[int, int], Any]] = ...,
                    tile: Optional[int] = ...) -> Any: ...
def write_image(path: Union[str, "os.PathLike[str]"], image: npt.ArrayLike,
                bits: Union[int, str] = ..., srgb: bool = ...) -> None: ...
def heightmap(image: Union[str, "os.PathLike[str]", npt.ArrayLike],
              path: Optional[Union[str, "os.PathLike[str]"]] = ..., *, strength: float = ...,
              edge: Literal["clamp", "wrap"] = ..., normal_map_y: Literal["+y", "-y"] = ...,
              gray: Literal["diffuse", "rec709"] = ..., to_derivative: bool = ...,
              bits: Union[None, int, str] = ...) -> Optional[npt.NDArray[np.float32]]: ...
def volume(bbox: Sequence[float], voxel_size: float,
           path: Optional[Union[str, "os.PathLike[str]"]] = ..., *,
           band_sphere: Optional[Sequence[float]] = ..., function: _Function = ...,
           octaves: int = ..., lacunarity: float = ..., gain: float = ...,
           amplitude: float = ..., frequency: float = ...,
           gradient: Literal["analytic", "central"] = ..., step: float = ...,
           period: _Period = ..., seed: int = ..., threads: Optional[int] = ...,
           progress: Optional[Callable[[int, int], Any]] = ...,
           brick: Optional[Tuple[int, int]] = ...) -> Any: ...
def merge_volumes(path: Union[str, "os.PathLike[str]"],
                  bricks: Sequence[Union[str, "os.PathLike[str]"]]) -> None: ...
def render(scene: Literal["sphere", "blob", "torus"] = ..., *,
           mesh: Optional[Union[str, "os.PathLike[str]"]] = ...,
           size: Union[int, Tuple[int, int]] = ..., method: str = ..., spp: int = ...,
           function: _Function = ..., octaves: int = ..., lacunarity: float = ...,
           gain: float = ..., amplitude: float = ..., frequency: float = ...,
           gradient: Literal["analytic", "central"] = ..., step: float = ...,
           period: _Period = ..., seed: int = ..., threads: Optional[int] = ...,
           progress: Optional[Callable[[int, int], Any]] = ...) -> npt.NDArray[np.float32]: ...
