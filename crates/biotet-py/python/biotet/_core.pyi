"""Type stubs of the native module (biotet._core); use the functions of ``biotet`` instead."""

from typing import Any, Callable, Sequence, TypedDict

import numpy as np
import numpy.typing as npt

__version__: str

class CoreError(Exception):
    """A failure inside biotet: args are (kind, message, triangles)."""

_Ints = npt.NDArray[np.int32] | npt.NDArray[np.int64]
_MeshOut = tuple[npt.NDArray[np.float64], npt.NDArray[np.int32], npt.NDArray[np.int32], str]

class _SizeField(TypedDict):
    path: str | None
    array: str | None
    values: npt.NDArray[np.float64] | None
    affine: Sequence[Sequence[float]] | None

class _ImageOptions(TypedDict):
    keep: Sequence[int] | None
    merge: Sequence[tuple[Sequence[int], int]]
    outside: int
    min_component_voxels: int

class _MeshOptions(TypedDict):
    size: float | None
    grading: float
    min_size: float | None
    max_size: float | None
    region_sizes: Sequence[tuple[int, float]]
    resolution: float
    zone: str
    max_voxels: int
    steiner: bool
    stages: tuple[bool, bool, bool, bool]
    surface_tolerance: float | None
    exact_surface: bool
    surface_feature_angle: float
    surface_rounds: int
    adaptive_size: bool
    size_field: _SizeField | None

def mesh_arrays(
    points: npt.NDArray[np.float64],
    triangles: _Ints,
    shell_labels: Sequence[int] | None,
    side_labels: _Ints | None,
    name: str,
    options: _MeshOptions,
    threads: int | None,
    progress: Callable[[str], Any] | None,
) -> _MeshOut: ...
def mesh_image(
    labels: npt.NDArray[np.uint32],
    affine: Sequence[Sequence[float]],
    name: str,
    image: _ImageOptions,
    options: _MeshOptions,
    threads: int | None,
    progress: Callable[[str], Any] | None,
) -> _MeshOut: ...
def surface_image(
    labels: npt.NDArray[np.uint32],
    affine: Sequence[Sequence[float]],
    name: str,
    image: _ImageOptions,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32], npt.NDArray[np.int32]]: ...
def surface_image_file(
    path: str, image: _ImageOptions
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32], npt.NDArray[np.int32]]: ...
def mesh_files(
    paths: Sequence[str],
    labels: Sequence[Sequence[int] | None],
    image: _ImageOptions,
    options: _MeshOptions,
    threads: int | None,
    progress: Callable[[str], Any] | None,
) -> _MeshOut: ...
def check(
    points: npt.NDArray[np.float64],
    tets: _Ints,
    labels: _Ints,
    surface_points: npt.NDArray[np.float64] | None = None,
    surface_triangles: _Ints | None = None,
    shell_labels: Sequence[int] | None = None,
    side_labels: _Ints | None = None,
    threads: int | None = None,
) -> str: ...
def quality(
    points: npt.NDArray[np.float64],
    tets: _Ints,
    labels: _Ints,
    threads: int | None = None,
) -> str: ...
def delaunay(points: npt.NDArray[np.float64], threads: int | None = None) -> _MeshOut: ...
def recover_surface(
    points: npt.NDArray[np.float64],
    tets: _Ints,
    labels: _Ints,
    surface_points: npt.NDArray[np.float64],
    surface_triangles: _Ints,
    steiner: bool = True,
    keep_outside: bool = False,
    threads: int | None = None,
) -> _MeshOut: ...
def improve_mesh(
    points: npt.NDArray[np.float64],
    tets: _Ints,
    labels: _Ints,
    threshold: float | None = None,
    metric: str = "dihedral",
    threads: int | None = None,
) -> _MeshOut: ...
def smooth_mesh(
    points: npt.NDArray[np.float64],
    tets: _Ints,
    labels: _Ints,
    surface_points: npt.NDArray[np.float64] | None = None,
    surface_triangles: _Ints | None = None,
    slide: bool = False,
    max_sweeps: int | None = None,
    feature_angle: float = 45.0,
    threads: int | None = None,
) -> _MeshOut: ...
def read_tet_mesh(path: str) -> _MeshOut: ...
def mesh_kind(path: str) -> str: ...
def read_surface(
    path: str,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32], npt.NDArray[np.int32]]: ...
def write_tet_mesh(
    path: str,
    points: npt.NDArray[np.float64],
    tets: _Ints,
    labels: _Ints,
) -> list[str]: ...
