"""The Dask cohort example on three small subjects (a surface, a label image, an invalid
surface) with a 2-process LocalCluster."""

import csv
import json
import subprocess
import sys

import pytest

import biotet
from conftest import IMAGES, ROOT, SHAPES

pytest.importorskip("dask.distributed")


def test_cohort_example_meshes_each_subject_and_reports_failures(tmp_path):
    inputs = [SHAPES / "tm_box.off", IMAGES / "label_uint8.mha", SHAPES / "invalid_open_box.off"]
    out = tmp_path / "out"
    r = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "cohort_dask.py"), *map(str, inputs),
         "-o", str(out), "--workers", "2"],
        capture_output=True, text=True, timeout=600,
    )
    # One subject is invalid: exit 1, the others meshed.
    assert r.returncode == 1, r.stderr
    assert "2 of 3 subjects meshed" in r.stdout
    rows = {row["subject"]: row for row in csv.DictReader(open(out / "summary.csv"))}
    assert set(rows) == {"tm_box", "label_uint8", "invalid_open_box"}
    assert rows["invalid_open_box"]["status"] == "failed"
    assert "closed" in rows["invalid_open_box"]["error"]
    for name in ("tm_box", "label_uint8"):
        row = rows[name]
        assert row["status"] == "ok"
        m = biotet.read(out / f"{name}.vtu")
        assert m.n_tets == int(row["tets"])
        assert biotet.check(m)["valid"]
        assert (out / f"{name}.json").is_file()
    assert biotet.check(biotet.read(out / "tm_box.vtu"), biotet.read_surface(SHAPES / "tm_box.off"))["valid"]
    # The image's regions keep its labels; their boundaries moved, within half the smallest
    # voxel spacing of the voxel faces (the surface stage's default), so their volumes moved a
    # little (a few voxels each in this 5 × 4 × 3 image: several percent).
    image = biotet.read(out / "label_uint8.vtu")
    assert set(image.labels.tolist()) == {1, 2, 17, 41}
    report = json.loads((out / "label_uint8.json").read_text())
    d = report["image"]["default_surface_tolerance"]
    assert 0.0 < float(rows["label_uint8"]["max_region_distance"]) <= d
    assert 0.0 < float(rows["label_uint8"]["max_region_volume_error"]) < 0.2
    assert rows["tm_box"]["max_region_volume_error"] == ""
    assert rows["tm_box"]["max_region_distance"] == ""
    assert not (out / "invalid_open_box.vtu").exists()
