"""Every Python block of the README and of docs/ runs as written (from a scratch directory that
sees the repository's tests/ and examples/), so the documentation cannot drift from the package."""

import os
import re

import pytest

from conftest import ROOT

DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
# Blocks that need a machine we do not have in CI: a Slurm cluster.
NEEDS_CLUSTER = ("SLURMCluster",)


def python_blocks():
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"^```python\n(.*?)^```", text, re.S | re.M):
            line = text[: m.start()].count("\n") + 1
            yield pytest.param(m.group(1), id=f"{path.name}:{line}")


BLOCKS = list(python_blocks())


def test_the_docs_have_python_blocks():
    assert len(BLOCKS) >= 2


@pytest.mark.parametrize("code", BLOCKS)
def test_python_block_runs(code, tmp_path, monkeypatch):
    if any(k in code for k in NEEDS_CLUSTER):
        pytest.skip("needs a Slurm cluster (dask-jobqueue)")
    for d in ("tests", "examples"):
        os.symlink(ROOT / d, tmp_path / d)
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "<docs>", "exec"), {"__name__": "__docs__"})


def cohort_lines():
    """The `python examples/cohort_dask.py` lines of the docs' sh blocks (the Rust docs test runs
    every other sh line; these need Dask, which the Python suite has)."""
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"^```sh\n(.*?)^```", text, re.S | re.M):
            first = text[: m.start()].count("\n") + 2
            for k, line in enumerate(m.group(1).splitlines()):
                if line.startswith("python examples/cohort_dask.py"):
                    yield pytest.param(line.split(" #")[0], id=f"{path.name}:{first + k}")


COHORT_LINES = list(cohort_lines())


def test_the_docs_have_cohort_lines():
    assert len(COHORT_LINES) >= 3


def write_ascii_stl(path, points, triangles):
    with open(path, "w") as f:
        f.write("solid s\n")
        for t in triangles:
            f.write(" facet normal 0 0 0\n  outer loop\n")
            for i in t:
                f.write("   vertex {:.17g} {:.17g} {:.17g}\n".format(*points[i]))
            f.write("  endloop\n endfacet\n")
        f.write("endsolid s\n")


def nested_balls(r):
    """A 28³ int16 label image: a ball of label 41 inside a shell of label 2, a 3-voxel island of
    label 2 outside (merged away by --min-component-voxels 20) and a slab of label 3 (dropped
    by --keep-labels 2,41)."""
    import numpy as np

    i, j, k = np.indices((28, 28, 28)) - 13.5
    d = np.sqrt(i**2 + j**2 + k**2)
    labels = np.where(d < r / 2, 41, np.where(d < r, 2, 0)).astype(np.int16)
    labels[26, 26, 24:27] = 2
    labels[:, :, 0:2] = 3
    return labels


def write_nifti_gz(path, labels, spacing=(0.9, 0.9, 0.9)):
    """A gzipped NIfTI-1 file (int16, no sform or qform: pixdim gives the geometry)."""
    import gzip
    import struct

    import numpy as np

    hdr = bytearray(348)
    struct.pack_into("<i", hdr, 0, 348)
    struct.pack_into("<8h", hdr, 40, 3, *labels.shape, 1, 1, 1, 1)
    struct.pack_into("<hh", hdr, 70, 4, 16)  # datatype int16, bitpix
    struct.pack_into("<8f", hdr, 76, 1.0, *spacing, 1.0, 1.0, 1.0, 1.0)
    struct.pack_into("<f", hdr, 108, 352.0)  # vox_offset
    struct.pack_into("<f", hdr, 112, 1.0)  # scl_slope
    hdr[344:348] = b"n+1\0"
    data = np.asarray(labels, "<i2").tobytes(order="F")  # i fastest
    with gzip.open(path, "wb") as f:
        f.write(bytes(hdr) + b"\0\0\0\0" + data)


@pytest.mark.parametrize("line", COHORT_LINES)
def test_cohort_line_runs(line, tmp_path):
    """Each documented cohort command runs as written on two small subjects of the kind it names
    (surfaces in subjects/, label images in seg/); `tcp://HOST:8786` is a scheduler this test
    starts. Every mesh it writes passes `biotet check`."""
    import shlex
    import subprocess
    import sys

    import biotet

    pytest.importorskip("dask.distributed")
    from conftest import SHAPES, cube

    (tmp_path / "subjects").mkdir()
    (tmp_path / "seg").mkdir()
    os.symlink(ROOT / "examples", tmp_path / "examples")
    s = biotet.read_surface(SHAPES / "tm_capsule.off")
    write_ascii_stl(tmp_path / "subjects" / "a.stl", s.points, s.triangles)
    write_ascii_stl(tmp_path / "subjects" / "b.stl", *cube(side=2.0))
    for k, r in ((1, 9.0), (2, 10.5)):
        write_nifti_gz(tmp_path / "seg" / f"sub{k}.nii.gz", nested_balls(r))
    cluster = None
    if "HOST" in line:
        from dask.distributed import LocalCluster

        cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None)
        line = line.replace("tcp://HOST:8786", cluster.scheduler_address)
    try:
        args = shlex.split(line)
        pattern = args[2]
        subjects = sorted(tmp_path.glob(pattern))
        assert subjects, pattern
        args = [sys.executable, args[1], *map(str, subjects), *args[3:]]
        r = subprocess.run(args, cwd=tmp_path, capture_output=True, text=True, timeout=600)
    finally:
        if cluster is not None:
            cluster.close()
    assert r.returncode == 0, r.stdout + r.stderr
    assert f"{len(subjects)} of {len(subjects)} subjects meshed" in r.stdout, r.stdout
    for x in subjects:
        stem = x.name.split(".")[0]
        m = biotet.read(tmp_path / "meshes" / f"{stem}.vtu")
        assert biotet.check(m)["valid"]
        if "--keep-labels 2,41" in line:
            assert set(m.labels.tolist()) == {2, 41}
