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


def run_cohort(inputs, out, workers):
    return subprocess.run(
        [sys.executable, str(ROOT / "examples" / "cohort_dask.py"), *map(str, inputs),
         "-o", str(out), "--workers", str(workers)],
        capture_output=True, text=True, timeout=600,
    )


def test_cohort_example_meshes_each_subject_and_reports_failures(tmp_path):
    inputs = [SHAPES / "tm_box.off", IMAGES / "label_uint8.mha", SHAPES / "invalid_open_box.off"]
    out = tmp_path / "out"
    r = run_cohort(inputs, out, workers=2)
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


def test_subjects_with_the_same_file_name_get_their_own_outputs(tmp_path):
    # s1/brain.stl and s2/brain.stl (the usual layout: one folder a subject), and box.off beside
    # box.stl: before, the later task overwrote the earlier one's mesh and both rows named it.
    box = (SHAPES / "tm_box.off").read_text()
    for d in ("s1", "s2"):
        (tmp_path / d).mkdir()
        (tmp_path / d / "box.off").write_text(box)
    (tmp_path / "box.off").write_text(box)
    inputs = [tmp_path / "s1" / "box.off", tmp_path / "s2" / "box.off", tmp_path / "box.off"]
    out = tmp_path / "out"
    r = run_cohort(inputs, out, workers=1)
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(open(out / "summary.csv")))
    assert [row["subject"] for row in rows] == ["s1_box", "s2_box", f"{tmp_path.name}_box"]
    assert len({row["mesh"] for row in rows}) == 3
    for row in rows:
        assert biotet.check(biotet.read(row["mesh"]))["valid"]
