"""Shared fixtures: the repository's data and the CLI binary to compare with."""

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT / "tests" / "data"
SHAPES = DATA / "shapes"
IMAGES = ROOT / "crates" / "biotet-io" / "tests" / "data"


def cube(origin=(0.0, 0.0, 0.0), side=1.0):
    """A closed outward cube of 12 triangles (points, triangles)."""
    o = np.asarray(origin, float)
    p = np.array([[(i >> 0) & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], float) * side + o
    t = np.array([
        [0, 2, 1], [1, 2, 3],  # z = 0
        [4, 5, 6], [5, 7, 6],  # z = 1
        [0, 1, 4], [1, 5, 4],  # y = 0
        [2, 6, 3], [3, 6, 7],  # y = 1
        [0, 4, 2], [2, 4, 6],  # x = 0
        [1, 3, 5], [3, 7, 5],  # x = 1
    ])
    return p, t


@pytest.fixture(scope="session")
def cli():
    """The biotet CLI: $BIOTET_CLI, else the workspace's release or debug build (built by the
    test command before pytest runs)."""
    env = os.environ.get("BIOTET_CLI")
    candidates = [Path(env)] if env else [ROOT / "target" / k / "biotet" for k in ("release", "debug")]
    for c in candidates:
        if c.is_file():
            return c
    found = shutil.which("biotet")
    if found:
        return Path(found)
    pytest.fail("no biotet CLI binary: build it (cargo build -p biotet-cli) or set BIOTET_CLI")


def run_cli(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)


def nested_balls(n=20, inner=4.5, outer=8.5, values=(30, 7)):
    """A label volume of two nested balls: ``values[0]`` inside radius ``inner`` (voxels),
    ``values[1]`` out to ``outer``, 0 outside; uint16, Fortran-ordered as nibabel gives."""
    i, j, k = np.meshgrid(*[np.arange(n)] * 3, indexing="ij")
    c = (n - 1) / 2
    r = np.sqrt((i - c) ** 2 + (j - c) ** 2 + (k - c + 0.7) ** 2)
    lab = np.zeros((n, n, n), np.uint16, order="F")
    lab[r < outer] = values[1]
    lab[r < inner] = values[0]
    return lab


def write_nrrd(path, labels, spacing, origin):
    """A raw RAS NRRD of a label volume (``labels[i, j, k]`` at ``origin + spacing * ijk``)."""
    a = np.asarray(labels)
    fmt = lambda v: "(" + ",".join(repr(float(x)) for x in v) + ")"
    dirs = " ".join(fmt(np.eye(3)[c] * spacing[c]) for c in range(3))
    header = (
        "NRRD0004\ntype: uint16\ndimension: 3\nspace: right-anterior-superior\n"
        f"sizes: {a.shape[0]} {a.shape[1]} {a.shape[2]}\nspace directions: {dirs}\n"
        f"kinds: domain domain domain\nendian: little\nencoding: raw\n"
        f"space origin: {fmt(origin)}\n\n"
    )
    path.write_bytes(header.encode() + a.astype("<u2").ravel(order="F").tobytes())


def write_vti(path, values, spacing, origin):
    """An ASCII VTK image of a scalar grid (``values[i, j, k]`` at ``origin + spacing * ijk``)."""
    v = np.asarray(values, float)
    e = " ".join(f"0 {d - 1}" for d in v.shape)
    data = " ".join(repr(float(x)) for x in v.ravel(order="F"))
    path.write_text(
        '<?xml version="1.0"?>\n<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian">\n'
        f'<ImageData WholeExtent="{e}" Origin="{" ".join(map(repr, map(float, origin)))}" '
        f'Spacing="{" ".join(map(repr, map(float, spacing)))}">\n<Piece Extent="{e}">\n'
        '<PointData Scalars="size">\n'
        f'<DataArray type="Float64" Name="size" format="ascii">{data}</DataArray>\n'
        "</PointData>\n</Piece>\n</ImageData>\n</VTKFile>\n"
    )
