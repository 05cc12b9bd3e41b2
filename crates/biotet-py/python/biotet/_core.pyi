"""Type stubs of the native module (biotet._core); use the functions of ``biotet`` instead."""

from typing import Any, Callable, Sequence, TypedDict

import numpy as np
import numpy.typing as npt

__version__: str

class CoreError(Exception):
    """A failure inside biotet: args are (kind, message, triangles)."""

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
    size_field: _SizeField | None

def mesh_arrays(
    points: npt.NDArray[np.float64],
    triangles: npt.NDArray[np.int64],
    shell_labels: Sequence[int] | None,
    side_labels: npt.NDArray[np.int64] | None,
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
    tets: npt.NDArray[np.int64],
    labels: npt.NDArray[np.int64],
    surface_points: npt.NDArray[np.float64] | None = None,
    surface_triangles: npt.NDArray[np.int64] | None = None,
    shell_labels: Sequence[int] | None = None,
    side_labels: npt.NDArray[np.int64] | None = None,
    threads: int | None = None,
) -> str: ...
def quality(
    points: npt.NDArray[np.float64],
    tets: npt.NDArray[np.int64],
    labels: npt.NDArray[np.int64],
    threads: int | None = None,
) -> str: ...
def delaunay(points: npt.NDArray[np.float64], threads: int | None = None) -> _MeshOut: ...
def recover_surface(
    points: npt.NDArray[np.float64],
    tets: npt.NDArray[np.int64],
    labels: npt.NDArray[np.int64],
    surface_points: npt.NDArray[np.float64],
    surface_triangles: npt.NDArray[np.int64],
    steiner: bool = True,
    keep_outside: bool = False,
    threads: int | None = None,
) -> _MeshOut: ...
def improve_mesh(
    points: npt.NDArray[np.float64],
    tets: npt.NDArray[np.int64],
    labels: npt.NDArray[np.int64],
    threshold: float = 10.0,
    metric: str = "dihedral",
    threads: int | None = None,
) -> _MeshOut: ...
def smooth_mesh(
    points: npt.NDArray[np.float64],
    tets: npt.NDArray[np.int64],
    labels: npt.NDArray[np.int64],
    surface_points: npt.NDArray[np.float64] | None = None,
    surface_triangles: npt.NDArray[np.int64] | None = None,
    slide: bool = False,
    max_sweeps: int | None = None,
    threads: int | None = None,
) -> _MeshOut: ...
def read_tet_mesh(path: str) -> _MeshOut: ...
def read_surface(
    path: str,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32], npt.NDArray[np.int32]]: ...
def write_tet_mesh(
    path: str,
    points: npt.NDArray[np.float64],
    tets: npt.NDArray[np.int64],
    labels: npt.NDArray[np.int64],
) -> list[str]: ...
