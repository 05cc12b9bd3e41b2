"""biotet: tetrahedral meshes of anatomy from closed triangulated surfaces and label images.

Every input triangle is kept exactly (a label volume becomes such a surface, two triangles per
voxel face between labels), interior nodes are deployed on a template, boundary recovery and
sliver removal use the LAST RESORT search, and solid-angle smoothing finishes the mesh. numpy
arrays go in and out; the GIL is released while biotet computes, so threads and Dask workers
mesh in parallel.

>>> import biotet, numpy as np
>>> m = biotet.mesh_file("brain.stl")                    # doctest: +SKIP
>>> m.points.shape, m.tets.shape, m.report["quality"]["min_dihedral_deg"]  # doctest: +SKIP
>>> seg = biotet.mesh_image(labels, affine=img.affine)   # doctest: +SKIP

Functions mirror the command-line tool: :func:`mesh`, :func:`mesh_image`, :func:`mesh_file`,
:func:`surface_extract`, :func:`recover`, :func:`improve`, :func:`smooth`, :func:`check`,
:func:`quality`, :func:`delaunay`, :func:`read`, :func:`write`. Errors are
:class:`InvalidSurfaceError` (a ``ValueError``), :class:`MeshingError`, ``ValueError`` for bad
arguments, and ``OSError`` subclasses for files, with the CLI's messages. Progress goes to the
``biotet`` logger (level INFO) or to a ``progress`` callable; nothing is printed.
"""

from __future__ import annotations

import json
import math
import logging
import os
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Mapping, Sequence, Union

import numpy as np

from . import _core

__all__ = [
    "TetMesh",
    "Surface",
    "SizeField",
    "BiotetError",
    "InvalidSurfaceError",
    "MeshingError",
    "BiotetFileError",
    "mesh",
    "mesh_image",
    "mesh_file",
    "surface_extract",
    "recover",
    "improve",
    "smooth",
    "check",
    "quality",
    "delaunay",
    "read",
    "read_surface",
    "write",
    "__version__",
]

__version__: str = _core.__version__

logger = logging.getLogger("biotet")

PathLike = Union[str, "os.PathLike[str]"]


class BiotetError(Exception):
    """Base class of biotet's errors. ``triangles`` lists the offending input triangles (their
    indices in the given arrays or file) when the error names any."""

    def __init__(self, message: str, triangles: Sequence[int] = ()):
        super().__init__(message)
        self.triangles: list[int] = list(triangles)


class InvalidSurfaceError(BiotetError, ValueError):
    """The surface is not a valid closed surface (open, non-manifold, self-intersecting,
    degenerate, inconsistently oriented...): the message says which triangles and why, as
    ``biotet validate`` does."""


class MeshingError(BiotetError, RuntimeError):
    """Meshing could not finish on a valid input (or an internal error was caught)."""


class BiotetFileError(BiotetError, OSError):
    """A file could not be read or written: malformed, truncated, unknown format."""


class _NotFound(BiotetFileError, FileNotFoundError):
    pass


class _Permission(BiotetFileError, PermissionError):
    pass


_KINDS: dict[str, type[BiotetError]] = {
    "invalid_surface": InvalidSurfaceError,
    "meshing": MeshingError,
    "panic": MeshingError,
    "not_found": _NotFound,
    "permission": _Permission,
    "file": BiotetFileError,
}


def _call(fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
    """Call into the native module, turning its errors into biotet's exception classes."""
    try:
        return fn(*args, **kwargs)
    except _core.CoreError as e:
        kind, message, triangles = e.args
        if kind == "value":
            raise ValueError(message) from None
        raise _KINDS.get(kind, MeshingError)(message, triangles) from None


def _threads(threads: Any) -> int | None:
    """``threads`` as the native module takes it: None, or a whole number ≥ 0 (0: one a core)."""
    if threads is None:
        return None
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 0:
        raise ValueError(f"threads must be None or a whole number >= 0, not {threads!r}")
    return int(threads)


def _label(x: Any, what: str) -> int:
    """A region label given as an argument: a whole number in 0..2**31."""
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)) or not 0 <= x <= _LABEL_MAX:
        raise ValueError(f"{what}: {x!r} is not a label (an integer in 0..2**31)")
    return int(x)


def _positive(what: str, x: Any) -> None:
    """A positive finite number, or a ``ValueError`` naming ``what``."""
    ok = isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, bool)
    if not (ok and math.isfinite(x) and x > 0):
        raise ValueError(f"{what} must be a positive finite number, got {x!r}")


def _count(what: str, x: Any, least: int) -> None:
    """A whole number at least ``least`` (and under 2**63), or a ``ValueError`` naming it."""
    ok = isinstance(x, (int, np.integer)) and not isinstance(x, bool)
    if not (ok and least <= x < 2**63):
        raise ValueError(f"{what} must be a whole number of at least {least}, got {x!r}")


def _progress(progress: Callable[[str], Any] | None) -> Callable[[str], Any] | None:
    if progress is not None:
        return progress
    if logger.isEnabledFor(logging.INFO):
        return lambda stage: logger.info("%s", stage)
    return None


def _points(a: Any, what: str = "points") -> np.ndarray:
    """Points as float64 (n, 3), passed to biotet in place when they are float64 already."""
    p = np.asarray(a, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"{what} must have shape (n, 3), not {p.shape}")
    return p


_INDEX_TYPES = (np.dtype(np.int32), np.dtype(np.int64))


def _indices(a: Any, width: int, what: str) -> np.ndarray:
    """Index rows as int32 or int64 (n, width), passed in place when they are either (biotet
    returns int32); other integer types are converted once."""
    x = np.asarray(a)
    if x.size and not np.issubdtype(x.dtype, np.integer):
        raise ValueError(f"{what} must hold integers, not {x.dtype}")
    if x.dtype not in _INDEX_TYPES:
        x = x.astype(np.int64)
    if x.ndim != 2 or x.shape[1] != width:
        raise ValueError(f"{what} must have shape (n, {width}), not {x.shape}")
    return x


def _labels(a: Any, n: int) -> np.ndarray:
    """Labels as int32 or int64 (n,), passed in place when they are either."""
    x = np.asarray(a).reshape(-1)
    if x.size and not np.issubdtype(x.dtype, np.integer):
        raise ValueError(f"labels must hold integers, not {x.dtype}")
    if x.dtype not in _INDEX_TYPES:
        x = x.astype(np.int64)
    if x.shape[0] != n:
        raise ValueError(f"labels has {x.shape[0]} entries for {n} tets")
    return x


def _same_arrays(a: Any, b: Any, names: Sequence[str]) -> bool:
    """Whether ``a`` and ``b`` hold equal arrays under ``names`` (shapes and values)."""
    return all(np.array_equal(getattr(a, n), getattr(b, n)) for n in names)


@dataclass(eq=False)
class Surface:
    """A triangle surface: ``points`` (n×3 float64), ``triangles`` (m×3 int32) and ``sides``
    (m×2 int32: the region behind and in front of each triangle, ``[1, 0]`` for a plain closed
    surface)."""

    points: np.ndarray
    triangles: np.ndarray
    sides: np.ndarray

    def __eq__(self, other: object) -> Any:
        """Equal when the points, triangles and sides are (a plain ``bool``; numpy's
        elementwise ``==`` made the dataclass comparison raise)."""
        if not isinstance(other, Surface):
            return NotImplemented
        return _same_arrays(self, other, ("points", "triangles", "sides"))

    __hash__ = None  # type: ignore[assignment]


@dataclass(eq=False)
class TetMesh:
    """A tetrahedral mesh: ``points`` (n×3 float64), ``tets`` (m×4 int32, positively oriented),
    ``labels`` (m int32, the region of each tet) and ``report`` (the dict ``biotet mesh --json``
    prints: pipeline stages, quality, forcing; empty for meshes read from files)."""

    points: np.ndarray
    tets: np.ndarray
    labels: np.ndarray
    report: dict = field(default_factory=dict)

    def __eq__(self, other: object) -> Any:
        """Equal when the points, tets and labels are (the report, with its timings, is not
        compared)."""
        if not isinstance(other, TetMesh):
            return NotImplemented
        return _same_arrays(self, other, ("points", "tets", "labels"))

    __hash__ = None  # type: ignore[assignment]

    @property
    def n_points(self) -> int:
        """Number of points."""
        return int(self.points.shape[0])

    @property
    def n_tets(self) -> int:
        """Number of tets."""
        return int(self.tets.shape[0])

    def write(self, path: PathLike) -> list[str]:
        """Write the mesh (format from the extension: .vtu, .vtk, .mesh, .msh, .node/.ele); the file
        appears whole or not at all. Returns the paths written."""
        return write(path, self)

    def check(self, surface: Surface | tuple[Any, Any] | None = None,
              labels: Sequence[int] | None = None) -> dict:
        """The validity report of :func:`check`."""
        return check(self, surface, labels=labels)

    def quality(self) -> dict:
        """The quality report of :func:`quality`."""
        return quality(self)

    def to_meshio(self) -> Any:
        """A ``meshio.Mesh`` with the labels as cell data ``"region"`` (needs meshio)."""
        try:
            import meshio
        except ImportError as e:
            raise ImportError("to_meshio needs meshio: pip install meshio") from e
        return meshio.Mesh(
            self.points, [("tetra", self.tets)], cell_data={"region": [self.labels]}
        )

    def to_pyvista(self) -> Any:
        """A ``pyvista.UnstructuredGrid`` with the labels as cell data ``"region"`` (needs
        pyvista)."""
        try:
            import pyvista as pv
        except ImportError as e:
            raise ImportError("to_pyvista needs pyvista: pip install pyvista") from e
        n = self.n_tets
        cells = np.hstack([np.full((n, 1), 4, dtype=np.int64), self.tets.astype(np.int64)])
        grid = pv.UnstructuredGrid(
            cells.ravel(), np.full(n, pv.CellType.TETRA, dtype=np.uint8), self.points
        )
        grid.cell_data["region"] = self.labels
        return grid


def _tet(out: tuple, report: bool = True) -> TetMesh:
    points, tets, labels, text = out
    return TetMesh(points, tets, labels, json.loads(text) if report else {})


def _mesh_options(
    size: float | None,
    grading: float,
    min_size: float | None,
    max_size: float | None,
    region_sizes: Mapping[int, float] | None,
    resolution: float,
    zone: str,
    max_voxels: int,
    steiner: bool,
    stages: tuple[bool, bool, bool, bool],
    surface_tolerance: float | None,
    surface: tuple[float, int, bool],
    size_field: dict | None,
    exact_surface: bool = False,
) -> dict:
    """The options of ``mesh``, ``mesh_image`` and ``mesh_file`` as the native module reads
    them; a number out of its range is a ``ValueError`` naming it."""
    _positive("resolution", resolution)
    if surface_tolerance is not None:
        _positive("surface_tolerance", surface_tolerance)
    _count("max_voxels", max_voxels, 1)
    _count("surface_rounds", surface[1], 0)
    return dict(
        size=size,
        grading=grading,
        min_size=min_size,
        max_size=max_size,
        region_sizes=sorted((int(k), float(v)) for k, v in (region_sizes or {}).items()),
        resolution=resolution,
        zone=zone,
        max_voxels=max_voxels,
        steiner=steiner,
        stages=stages,
        surface_tolerance=surface_tolerance,
        exact_surface=bool(exact_surface),
        surface_feature_angle=float(surface[0]),
        surface_rounds=int(surface[1]),
        adaptive_size=bool(surface[2]),
        size_field=size_field,
    )


@dataclass
class SizeField:
    """A desired edge length sampled on a regular grid, as the CLI's ``--size-field`` reads
    from a .vti or NIfTI file: ``values[i, j, k]`` (positive) is the size at the grid point
    ``affine @ (i, j, k, 1)``, or at ``origin + spacing * (i, j, k)`` without an affine (the
    convention of :func:`mesh_image`). Interpolated trilinearly, clamped to the grid outside
    it."""

    values: Any
    spacing: Sequence[float] = (1.0, 1.0, 1.0)
    origin: Sequence[float] = (0.0, 0.0, 0.0)
    affine: Any = None


def _affine(spacing: Sequence[float], origin: Sequence[float], affine: Any,
            what: str) -> list[list[float]]:
    """A 4×4 voxel-to-world matrix from an affine (4×4, or its first 3 rows) or from a spacing
    and an origin."""
    if affine is not None:
        m = np.asarray(affine, dtype=np.float64)
        if m.shape == (3, 4):
            m = np.vstack([m, [0.0, 0.0, 0.0, 1.0]])
        if m.shape != (4, 4):
            raise ValueError(f"{what}: affine must have shape (4, 4) or (3, 4), not {m.shape}")
        if not np.array_equal(m[3], [0.0, 0.0, 0.0, 1.0]):
            raise ValueError(f"{what}: the affine's last row must be (0, 0, 0, 1), not {m[3]}")
        if tuple(map(float, spacing)) != (1.0, 1.0, 1.0) or tuple(map(float, origin)) != (
            0.0, 0.0, 0.0
        ):
            raise ValueError(f"{what}: give an affine or a spacing and an origin, not both")
        return m.tolist()
    sp = np.asarray(spacing, dtype=np.float64).reshape(-1)
    og = np.asarray(origin, dtype=np.float64).reshape(-1)
    if sp.shape != (3,) or og.shape != (3,):
        raise ValueError(f"{what}: spacing and origin must hold 3 numbers each")
    m = np.eye(4)
    m[:3, :3] = np.diag(sp)
    m[:3, 3] = og
    return m.tolist()


def _size_field(size_field: Any, array: str | None,
                image_affine: list[list[float]] | None = None,
                image_shape: tuple[int, ...] | None = None) -> dict | None:
    """The native module's form of ``size_field``: a path (with the .vti array name), a
    :class:`SizeField`, or (for :func:`mesh_image`) an array on the image's own grid."""
    if size_field is None:
        if array is not None:
            raise ValueError("size_field_array needs a size_field file")
        return None
    if isinstance(size_field, (str, os.PathLike)):
        return dict(path=os.fspath(size_field), array=array, values=None, affine=None)
    if array is not None:
        raise ValueError("size_field_array names an array of a .vti size_field file")
    if isinstance(size_field, SizeField):
        affine = _affine(size_field.spacing, size_field.origin, size_field.affine, "size_field")
        values = size_field.values
    elif image_affine is not None:
        affine, values = image_affine, size_field
    else:
        raise ValueError(
            "size_field must be a file path or a biotet.SizeField(values, spacing, origin, "
            "affine); a bare array is taken on the image's grid by mesh_image only"
        )
    v = np.asarray(values, dtype=np.float64)
    if v.ndim != 3:
        raise ValueError(f"size_field: values must be a 3-D array, not of shape {v.shape}")
    if not isinstance(size_field, SizeField) and image_shape is not None and v.shape != image_shape:
        # A bare array is read on the image's voxels: another shape would put its values
        # elsewhere (and leave most of the image outside the field).
        raise ValueError(
            f"size_field: an array on the image's grid must have its shape {image_shape}, "
            f"not {v.shape} (a biotet.SizeField places a grid of its own)"
        )
    return dict(path=None, array=None, values=v, affine=affine)


def _image_options(keep_labels: Iterable[int] | None, merge: Mapping[int, int] | None,
                   outside: int, min_component_voxels: int) -> dict:
    """The label options of an image (``--labels``, ``--merge``, ``--outside``,
    ``--min-component-voxels``) as the native module reads them."""
    if int(min_component_voxels) < 0:
        raise ValueError(f"min_component_voxels must be >= 0, not {min_component_voxels}")
    merge = {_label(a, "merge"): _label(b, "merge") for a, b in (merge or {}).items()}
    return dict(
        keep=None if keep_labels is None else sorted({_label(x, "keep_labels") for x in keep_labels}),
        merge=[([a], b) for a, b in sorted(merge.items())],
        outside=_label(outside, "outside"),
        min_component_voxels=int(min_component_voxels),
    )


_LABEL_MAX = 2**31 - 1


def _label_volume(labels: Any) -> np.ndarray:
    """A label volume as uint32 (no copy when it is one already), refusing values that are no
    labels (negative, fractional, too large) with the first such voxel, as the file readers
    do."""
    a = np.asarray(labels)
    if a.ndim != 3:
        raise ValueError(f"labels must be a 3-D array (i, j, k), not of shape {a.shape}")
    if a.dtype == np.bool_:
        return np.asarray(a, dtype=np.uint32)
    if np.issubdtype(a.dtype, np.integer):
        bad = (a < 0) | (a > _LABEL_MAX)
    elif np.issubdtype(a.dtype, np.floating):
        with np.errstate(invalid="ignore"):
            bad = ~np.isfinite(a) | (a != np.round(a)) | (a < 0) | (a > _LABEL_MAX)
    else:
        raise ValueError(f"labels must hold integers, not {a.dtype}")
    if bad.any():
        first = int(np.flatnonzero(bad.ravel(order="F"))[0])
        ijk = tuple(int(x) for x in np.unravel_index(first, a.shape, order="F"))
        raise ValueError(
            f"labels: voxel {ijk} holds {a[ijk]}, not a label (an integer in 0..2**31)"
        )
    return np.asarray(a, dtype=np.uint32)


def mesh(
    vertices: Any,
    faces: Any,
    *,
    labels: Sequence[int] | None = None,
    side_labels: Any = None,
    size: float | None = None,
    size_field: PathLike | SizeField | None = None,
    size_field_array: str | None = None,
    grading: float = 0.3,
    min_size: float | None = None,
    max_size: float | None = None,
    region_sizes: Mapping[int, float] | None = None,
    resolution: float = 2.0,
    zone: str = "euclidean",
    max_voxels: int = 1 << 31,
    steiner: bool = True,
    recover: bool = True,
    improve: bool = True,
    smooth: bool = True,
    polish: bool = True,
    surface_tolerance: float | None = None,
    surface_feature_angle: float = 30.0,
    surface_rounds: int = 4,
    adaptive_size: bool = False,
    threads: int | None = None,
    progress: Callable[[str], Any] | None = None,
    name: str = "arrays",
) -> TetMesh:
    """Mesh the volume inside closed surfaces given as arrays, as ``biotet mesh`` does.

    ``vertices`` (n×3) and ``faces`` (m×3 indices) hold one or more closed shells; each encloses
    a region, innermost first, labelled ``labels`` (one per shell, in order of first triangle)
    or 1, 2, ... by nesting. Or give ``side_labels`` (m×2: the region behind and in front of
    each triangle) for a multi-material surface.

    Sizes: ``size`` (as ``--size``: uniform where it is no coarser than the surface's median
    edge, else graded up to it from the surface's edges), else ``size_field`` (a .vti or NIfTI file, with
    ``size_field_array`` naming a .vti array, or a :class:`SizeField`; as ``--size-field``), else
    from the surface's own edges growing by ``grading`` per unit distance; all clamped to
    ``min_size``/``max_size``. ``region_sizes`` maps a region label to a uniform size inside it
    (``--region-size``). ``steiner=False`` forbids new interior points (recovery's,
    the seeds in thin sections, polishing's; ``--no-steiner``); ``recover``/``improve``/``smooth``/``polish`` switch stages off.
    ``surface_tolerance=D`` first remeshes the surface within a two-sided Hausdorff distance D
    (``--surface-tolerance D``; reported in ``report["surface"]``): fewer slivers, the surface
    no longer kept exactly; crossing triangles (a FreeSurfer surface's few) are untangled first,
    points moved at most D/4 (``report["surface"]["untangled"]``); ``surface_feature_angle``, ``surface_rounds`` and ``adaptive_size``
    are that stage's ``--feature-angle``, ``--surface-rounds`` and ``--adaptive-size``. ``threads``: worker threads (default one per core, at most four a core; the result does
    not depend on it). ``progress``: called with each stage's name (default: the ``biotet``
    logger at level INFO); an exception it raises stops the call and is raised in its place, as
    Ctrl-C's ``KeyboardInterrupt`` is.

    Raises :class:`InvalidSurfaceError` for an invalid surface, :class:`MeshingError` if
    meshing cannot finish, ``ValueError`` for bad arguments.
    """
    v = _points(vertices, "vertices")
    f = _indices(faces, 3, "faces")
    s = None if side_labels is None else _indices(side_labels, 2, "side_labels")
    shell = None if labels is None else [_label(x, "labels") for x in labels]
    o = _mesh_options(
        size, grading, min_size, max_size, region_sizes, resolution, zone, max_voxels,
        steiner, (recover, improve, smooth, polish), surface_tolerance,
        (surface_feature_angle, surface_rounds, adaptive_size),
        _size_field(size_field, size_field_array),
    )
    return _tet(_call(_core.mesh_arrays, v, f, shell, s, name, o, _threads(threads), _progress(progress)))


def mesh_image(
    labels: Any,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    affine: Any = None,
    *,
    keep_labels: Iterable[int] | None = None,
    merge: Mapping[int, int] | None = None,
    outside: int = 0,
    min_component_voxels: int = 0,
    size: float | None = None,
    size_field: Any = None,
    size_field_array: str | None = None,
    grading: float = 0.3,
    min_size: float | None = None,
    max_size: float | None = None,
    region_sizes: Mapping[int, float] | None = None,
    resolution: float = 2.0,
    zone: str = "euclidean",
    max_voxels: int = 1 << 31,
    steiner: bool = True,
    recover: bool = True,
    improve: bool = True,
    smooth: bool = True,
    polish: bool = True,
    surface_tolerance: float | None = None,
    exact_surface: bool = False,
    surface_feature_angle: float = 30.0,
    surface_rounds: int = 4,
    adaptive_size: bool = False,
    threads: int | None = None,
    progress: Callable[[str], Any] | None = None,
    name: str = "image",
) -> TetMesh:
    """Mesh the regions of a label volume (a segmentation), as ``biotet mesh IMAGE`` does.

    ``labels[i, j, k]`` (integers ≥ 0; integral floats are accepted) is the label of the voxel
    centred at ``origin + spacing * (i, j, k)``, or at ``affine @ (i, j, k, 1)`` when an
    ``affine`` (4×4 or 3×4, voxel to world, e.g. nibabel's ``img.affine``) is given. Each
    non-zero value is a region whose tets keep that value as their label; 0 is the outside.
    The surface is the voxel faces between labels (an oblique image is meshed in a frame
    rotated to world, a sheared one too: angles and distances are the world's), remeshed by the surface stage within half the
    smallest voxel spacing unless ``surface_tolerance`` says otherwise; ``exact_surface=True``
    keeps the voxel faces exactly instead (``--exact-surface``: each region's mesh volume is
    then its voxel volume, its boundary a staircase).

    The label options, as the CLI's: ``keep_labels`` (``--labels``: the others become outside),
    ``merge`` (``--merge``: a mapping from a label to the label it joins, applied first),
    ``outside`` (``--outside``: the value of the outside), ``min_component_voxels``
    (``--min-component-voxels``: smaller 6-connected islands join the label around them).

    Sizes: ``size`` (as ``--size``: uniform where it is no coarser than the surface's median
    edge, else graded up to it from the surface's edges), else ``size_field`` (a .vti or NIfTI file, with
    ``size_field_array`` naming a .vti array, or a :class:`SizeField`; as ``--size-field``), else
    from the surface's own edges growing by ``grading`` per unit distance; all clamped to
    ``min_size``/``max_size``. ``region_sizes`` maps a region label to a uniform size inside it
    (``--region-size``). ``steiner=False`` forbids new interior points (recovery's,
    the seeds in thin sections, polishing's; ``--no-steiner``); ``recover``/``improve``/``smooth``/``polish`` switch stages off.
    ``surface_tolerance=D`` first remeshes the surface within a two-sided Hausdorff distance D
    (``--surface-tolerance D``; reported in ``report["surface"]``): fewer slivers, the surface
    no longer kept exactly; ``surface_feature_angle``, ``surface_rounds`` and ``adaptive_size``
    are that stage's ``--feature-angle``, ``--surface-rounds`` and ``--adaptive-size``. ``threads``: worker threads (default one per core, at most four a core; the result does
    not depend on it). ``progress``: called with each stage's name (default: the ``biotet``
    logger at level INFO); an exception it raises stops the call and is raised in its place, as
    Ctrl-C's ``KeyboardInterrupt`` is. A bare array as ``size_field`` is taken on the image's own grid.

    ``report["image"]`` says what the extraction did and ``report["image_regions"]`` compares
    each region's mesh volume with its voxel volume. Raises ``ValueError`` for bad labels or
    options (with the CLI's messages), :class:`MeshingError` if meshing cannot finish.
    """
    vol = _label_volume(labels)
    m = _affine(spacing, origin, affine, "mesh_image")
    img = _image_options(keep_labels, merge, outside, min_component_voxels)
    o = _mesh_options(
        size, grading, min_size, max_size, region_sizes, resolution, zone, max_voxels,
        steiner, (recover, improve, smooth, polish), surface_tolerance,
        (surface_feature_angle, surface_rounds, adaptive_size),
        _size_field(size_field, size_field_array, m, vol.shape), exact_surface,
    )
    return _tet(_call(_core.mesh_image, vol, m, name, img, o, _threads(threads), _progress(progress)))


def mesh_file(
    paths: PathLike | Iterable[PathLike],
    *,
    labels: Mapping[str, Sequence[int]] | None = None,
    keep_labels: Iterable[int] | None = None,
    merge: Mapping[int, int] | None = None,
    outside: int = 0,
    min_component_voxels: int = 0,
    size: float | None = None,
    size_field: PathLike | SizeField | None = None,
    size_field_array: str | None = None,
    grading: float = 0.3,
    min_size: float | None = None,
    max_size: float | None = None,
    region_sizes: Mapping[int, float] | None = None,
    resolution: float = 2.0,
    zone: str = "euclidean",
    max_voxels: int = 1 << 31,
    steiner: bool = True,
    recover: bool = True,
    improve: bool = True,
    smooth: bool = True,
    polish: bool = True,
    surface_tolerance: float | None = None,
    exact_surface: bool = False,
    surface_feature_angle: float = 30.0,
    surface_rounds: int = 4,
    adaptive_size: bool = False,
    threads: int | None = None,
    progress: Callable[[str], Any] | None = None,
) -> TetMesh:
    """Mesh what files hold, exactly as ``biotet mesh FILE...`` does (the same tets, byte for
    byte, for the same options): the volume inside the closed surfaces of one or more surface
    files (STL, OBJ, OFF, PLY, Medit .mesh, VTU, VTP, legacy VTK), or the regions of one label
    image (.nii, .nii.gz, .mgh, .mgz, .nrrd, .nhdr, .mha, .mhd, .vti; world coordinates RAS+).

    ``labels`` maps a surface file (as given, or its name) to the labels of its shells, as
    ``--label FILE=N,...``. ``keep_labels``, ``merge``, ``outside`` and
    ``min_component_voxels`` apply to a label image, as in :func:`mesh_image` (its surface
    remeshed within half the smallest voxel spacing unless ``surface_tolerance`` is given or
    ``exact_surface=True``).

    Sizes: ``size`` (as ``--size``: uniform where it is no coarser than the surface's median
    edge, else graded up to it from the surface's edges), else ``size_field`` (a .vti or NIfTI file, with
    ``size_field_array`` naming a .vti array, or a :class:`SizeField`; as ``--size-field``), else
    from the surface's own edges growing by ``grading`` per unit distance; all clamped to
    ``min_size``/``max_size``. ``region_sizes`` maps a region label to a uniform size inside it
    (``--region-size``). ``steiner=False`` forbids new interior points (recovery's,
    the seeds in thin sections, polishing's; ``--no-steiner``); ``recover``/``improve``/``smooth``/``polish`` switch stages off.
    ``surface_tolerance=D`` first remeshes the surface within a two-sided Hausdorff distance D
    (``--surface-tolerance D``; reported in ``report["surface"]``): fewer slivers, the surface
    no longer kept exactly; ``surface_feature_angle``, ``surface_rounds`` and ``adaptive_size``
    are that stage's ``--feature-angle``, ``--surface-rounds`` and ``--adaptive-size``. ``threads``: worker threads (default one per core, at most four a core; the result does
    not depend on it). ``progress``: called with each stage's name (default: the ``biotet``
    logger at level INFO); an exception it raises stops the call and is raised in its place, as
    Ctrl-C's ``KeyboardInterrupt`` is.

    Raises ``FileNotFoundError``/:class:`BiotetFileError` (``OSError``) for unreadable files,
    and otherwise as :func:`mesh` and :func:`mesh_image`.
    """
    if isinstance(paths, (str, os.PathLike)):
        paths = [paths]
    ps = [os.fspath(p) for p in paths]
    if not ps:
        raise ValueError("mesh_file needs at least one file")
    per_file: list[list[int] | None] = [None] * len(ps)
    for key, ls in (labels or {}).items():
        hits = [i for i, p in enumerate(ps) if p == key or os.path.basename(p) == key]
        if not hits:
            raise ValueError(f"labels: {key} is not one of the input files")
        per_file[hits[0]] = [_label(x, "labels") for x in ls]
    img = _image_options(keep_labels, merge, outside, min_component_voxels)
    o = _mesh_options(
        size, grading, min_size, max_size, region_sizes, resolution, zone, max_voxels,
        steiner, (recover, improve, smooth, polish), surface_tolerance,
        (surface_feature_angle, surface_rounds, adaptive_size),
        _size_field(size_field, size_field_array), exact_surface,
    )
    return _tet(_call(_core.mesh_files, ps, per_file, img, o, _threads(threads), _progress(progress)))


def surface_extract(
    image: Any,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    affine: Any = None,
    *,
    keep_labels: Iterable[int] | None = None,
    merge: Mapping[int, int] | None = None,
    outside: int = 0,
    min_component_voxels: int = 0,
    name: str = "image",
) -> Surface:
    """The labelled surface of a label image, as ``biotet surface IMAGE -o OUT`` writes it: every
    voxel face between two labels (after the label options, as in :func:`mesh_image`) as two
    triangles whose ``sides`` are the labels behind and in front, each region closed and
    manifold, in world coordinates. ``image`` is a label image file or a numpy label volume
    with its ``spacing``/``origin`` or ``affine``. It is the surface :func:`mesh_image` and
    :func:`mesh_file` keep exactly, so ``check(mesh, surface)`` verifies that a mesh of the
    image conforms to it."""
    img = _image_options(keep_labels, merge, outside, min_component_voxels)
    if isinstance(image, (str, os.PathLike)):
        if (tuple(map(float, spacing)) != (1.0, 1.0, 1.0)
                or tuple(map(float, origin)) != (0.0, 0.0, 0.0) or affine is not None):
            raise ValueError("surface_extract: a file holds its own geometry; give no "
                             "spacing, origin or affine")
        return Surface(*_call(_core.surface_image_file, os.fspath(image), img))
    vol = _label_volume(image)
    m = _affine(spacing, origin, affine, "surface_extract")
    return Surface(*_call(_core.surface_image, vol, m, name, img))


def _surface_arrays(surface: Surface | tuple[Any, Any] | None) -> tuple[Any, Any]:
    if surface is None:
        return None, None
    if isinstance(surface, Surface):
        return _points(surface.points), _indices(surface.triangles, 3, "triangles")
    p, t = surface
    return _points(p), _indices(t, 3, "triangles")


def _side_labels(surface: Surface | tuple[Any, Any] | None) -> np.ndarray | None:
    """A surface's side labels when they say more than "region 1 inside, outside beyond"."""
    if isinstance(surface, Surface):
        s = np.asarray(surface.sides)
        if s.size and not (np.all(s[:, 0] == 1) and np.all(s[:, 1] == 0)):
            return _indices(s, 2, "sides")
    return None


def _mesh_arrays(m: TetMesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = _indices(m.tets, 4, "tets")
    return _points(m.points), t, _labels(m.labels, t.shape[0])


def check(mesh: TetMesh, surface: Surface | tuple[Any, Any] | None = None, *,
          labels: Sequence[int] | None = None, threads: int | None = None) -> dict:
    """Check a tet mesh as ``biotet check`` does: indices, strictly positive tets (exact),
    faces shared by at most two tets, adjacency, unused or duplicate points; and, with a
    ``surface`` (a :class:`Surface`, its side labels included, or ``(points, triangles)`` whose
    shells are labelled ``labels`` as in :func:`mesh`), that every surface triangle is a face
    of the mesh with the right regions on its sides. Returns the report; ``report["valid"]`` is
    the verdict."""
    sp, st = _surface_arrays(surface)
    shell = None if labels is None else [_label(x, "labels") for x in labels]
    return json.loads(_call(_core.check, *_mesh_arrays(mesh), sp, st, shell,
                            _side_labels(surface), threads=_threads(threads)))


def quality(mesh: TetMesh, *, threads: int | None = None) -> dict:
    """Quality measures of a tet mesh (``biotet quality --json``): dihedral angles, solid
    angles, q, radius ratio, histograms, per region."""
    return json.loads(_call(_core.quality, *_mesh_arrays(mesh), threads=_threads(threads)))


def delaunay(points: Any, *, threads: int | None = None) -> TetMesh:
    """The exact Delaunay tetrahedralization of a point cloud (degenerate inputs get a symbolic
    tie-break). Labels are 1."""
    return _tet(_call(_core.delaunay, _points(points), threads=_threads(threads)), report=False)


def recover(mesh: TetMesh, surface: Surface | tuple[Any, Any], *, steiner: bool = True,
            keep_outside: bool = False, threads: int | None = None) -> TetMesh:
    """Make every triangle of ``surface`` a face of ``mesh`` (LAST RESORT boundary recovery),
    never adding points on the surface; with ``steiner`` (the default) points strictly inside
    are added where no fill exists without them. The outside tets are removed unless
    ``keep_outside``. The report is the recovery's."""
    sp, st = _surface_arrays(surface)
    return _tet(_call(_core.recover_surface, *_mesh_arrays(mesh), sp, st, steiner=steiner,
                      keep_outside=keep_outside, threads=_threads(threads)))


def improve(mesh: TetMesh, *, threshold: float | None = None, metric: str = "dihedral",
            threads: int | None = None) -> TetMesh:
    """Remove slivers by refilling their cavities (LAST RESORT), as ``biotet improve``: tets
    whose smallest dihedral angle (``metric="dihedral"``, degrees, default threshold 10) or q
    (``metric="q"``, default threshold 0.2) is under ``threshold``. Points and surface are
    kept."""
    return _tet(_call(_core.improve_mesh, *_mesh_arrays(mesh), threshold=threshold,
                      metric=metric, threads=_threads(threads)))


def smooth(mesh: TetMesh, surface: Surface | tuple[Any, Any] | None = None, *,
           slide: bool = False, max_sweeps: int | None = None, feature_angle: float = 45.0,
           threads: int | None = None) -> TetMesh:
    """Raise the smallest solid angles by moving nodes, as ``biotet smooth``: the surface and
    interfaces fixed, or with ``slide=True`` sliding on ``surface`` (feature edges sharper than
    ``feature_angle`` degrees, and corners, stay). ``max_sweeps`` defaults to 10."""
    sp, st = _surface_arrays(surface)
    return _tet(_call(_core.smooth_mesh, *_mesh_arrays(mesh), sp, st, slide=slide,
                      max_sweeps=max_sweeps, feature_angle=feature_angle, threads=_threads(threads)))


_SURFACE_ONLY = (".stl", ".obj", ".off", ".ply", ".vtp")


def read(path: PathLike) -> TetMesh | Surface:
    """Read a mesh file: a :class:`TetMesh` when it holds tets (.vtu, .mesh, .msh,
    .node/.ele, .vtk), else a :class:`Surface` (STL, OBJ, OFF, PLY, VTP, or a .vtu/.vtk/.mesh
    of triangles)."""
    p = os.fspath(path)
    if p.lower().endswith(_SURFACE_ONLY):
        return read_surface(p)
    if p.lower().endswith(".vtk") and _call(_core.mesh_kind, p) == "surface":
        return read_surface(p)
    m = _tet(_call(_core.read_tet_mesh, p), report=False)
    if m.n_tets == 0 and p.lower().endswith((".vtu", ".mesh")):
        return read_surface(p)
    return m


def read_surface(path: PathLike) -> Surface:
    """Read a triangle surface file (STL, OBJ, OFF, PLY, Medit, VTU, VTP, legacy VTK) with its
    side labels."""
    return Surface(*_call(_core.read_surface, os.fspath(path)))


def write(path: PathLike, mesh: TetMesh) -> list[str]:
    """Write a tet mesh (format from the extension: .vtu, .vtk, .mesh, .msh, .node/.ele) through a
    temporary file renamed into place. Returns the paths written."""
    out = _call(_core.write_tet_mesh, os.fspath(path), *_mesh_arrays(mesh))
    return [os.fspath(p) for p in out]
