# SPDX-License-Identifier: MIT
# Type stubs of bumpgrad.dask (dask.py documents every function).
import os
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union

import dask.array

_Array = dask.array.Array
_Path = Union[str, "os.PathLike[str]"]
_Gradient = Optional[Literal["analytic", "central"]]

def noise3(p: Any, gradient: _Gradient = ..., *, dtype: Any = ...,
           threads: int = ...) -> Union[_Array, Tuple[_Array, _Array]]: ...
def fractal3(p: Any, function: Literal["noise", "fbm", "turbulence"] = ..., octaves: int = ...,
             lacunarity: float = ..., gain: float = ..., gradient: _Gradient = ...,
             step: float = ..., *, dtype: Any = ...,
             threads: int = ...) -> Union[_Array, Tuple[_Array, _Array]]: ...
def perturb(n: Any, g: Any, method: Literal["surfgrad", "additive", "additive-perlin"] = ..., *,
            dtype: Any = ..., threads: int = ...) -> _Array: ...
def perturb_height(p: Any, n: Any, *, threads: int = ..., **kw: Any) -> Tuple[_Array, _Array]: ...
def bake_udim(mesh: _Path, size: Union[int, Tuple[int, int]], path: Optional[_Path] = ..., *,
              tiles: Sequence[int], client: Any = ..., threads: int = ...,
              **kw: Any) -> Union[List[int], Dict[int, Any]]: ...
def volume(bbox: Sequence[float], voxel_size: float, path: _Path, *, bricks: int,
           client: Any = ..., threads: int = ..., **kw: Any) -> str: ...
