"""Meshing from numpy and from files, compared with the CLI and checked."""

import json

import numpy as np
import pytest

import biotet
from conftest import DATA, SHAPES, cube, run_cli


@pytest.fixture(scope="module")
def brain():
    return biotet.read_surface(DATA / "brain_20k.stl")


@pytest.fixture(scope="module")
def brain_mesh(brain):
    return biotet.mesh(brain.points, brain.triangles, threads=2)


def test_brain_from_numpy_is_valid_and_keeps_every_triangle(brain, brain_mesh):
    m = brain_mesh
    assert m.points.dtype == np.float64 and m.points.shape[1] == 3
    assert m.tets.dtype == np.int32 and m.tets.shape[1] == 4
    assert m.labels.shape == (m.n_tets,) and set(np.unique(m.labels)) == {1}
    # The input points come first, unchanged.
    assert np.array_equal(m.points[: len(brain.points)], brain.points)
    c = biotet.check(m, brain)
    assert c["valid"], c["problems"]
    assert c["surface"]["n_missing"] == 0
    r = m.report
    assert r["pipeline"]["missing_triangles"] == 0
    assert r["n_surface_triangles"] == len(brain.triangles)
    q = biotet.quality(m)
    assert q["n_tets"] == m.n_tets and q["n_inverted"] == 0
    assert q["min_dihedral_deg"] == pytest.approx(r["quality"]["min_dihedral_deg"])


def test_thread_count_does_not_change_the_mesh(brain, brain_mesh):
    one = biotet.mesh(brain.points, brain.triangles, threads=1)
    assert np.array_equal(one.points, brain_mesh.points)
    assert np.array_equal(one.tets, brain_mesh.tets)
    assert np.array_equal(one.labels, brain_mesh.labels)


@pytest.mark.parametrize(
    "shape", ["tm_box.off", "gen_schonhardt.off", "tm_annulus.off", "cad_coarse_block.off"]
)
def test_mesh_file_writes_the_same_bytes_as_the_cli(cli, tmp_path, shape):
    src = SHAPES / shape
    out_cli = tmp_path / "cli.vtu"
    out_py = tmp_path / "py.vtu"
    r = run_cli(cli, "mesh", src, "-o", out_cli, "--quiet")
    assert r.returncode == 0, r.stderr
    m = biotet.mesh_file(src)
    assert m.write(out_py) == [str(out_py)]
    assert out_py.read_bytes() == out_cli.read_bytes()
    assert biotet.check(m, biotet.read_surface(src))["valid"]


def test_mesh_from_arrays_matches_mesh_file(brain_mesh):
    m = biotet.mesh_file(DATA / "brain_20k.stl", threads=1)
    assert np.array_equal(m.tets, brain_mesh.tets)
    assert np.array_equal(m.points, brain_mesh.points)


def test_report_matches_the_cli_json(cli, tmp_path):
    src = SHAPES / "tm_box.off"
    r = run_cli(cli, "mesh", src, "--json", "-o", tmp_path / "x.vtu")
    assert r.returncode == 0, r.stderr
    want = json.loads(r.stdout)
    got = biotet.mesh_file(src).report
    assert got["quality"] == want["quality"]
    assert got["forcing"] == want["forcing"]
    assert got["pipeline"]["recover"]["steiner_points"] == want["pipeline"]["recover"]["steiner_points"]


def test_two_nested_shells_make_two_regions_with_labels():
    p1, t1 = cube((0, 0, 0), 4.0)
    p2, t2 = cube((1, 1, 1), 2.0)
    p = np.vstack([p1, p2])
    t = np.vstack([t1, t2 + len(p1)])
    m = biotet.mesh(p, t, labels=[7, 3], size=0.7)
    # Shells are labelled in order of first triangle: the outer cube 7, the inner 3.
    assert set(np.unique(m.labels)) == {3, 7}
    c = biotet.check(m, (p, t), labels=[7, 3])
    assert c["valid"], c["problems"]
    # The same surface with other labels does not match the mesh.
    assert not biotet.check(m, (p, t))["valid"]
    vol = {r["label"]: r["volume"] for r in biotet.quality(m)["regions"]}
    assert vol[3] == pytest.approx(8.0)
    assert vol[7] == pytest.approx(64.0 - 8.0)


def test_uniform_size_gives_more_tets_and_stays_valid():
    p, t = cube(side=3.0)
    coarse = biotet.mesh(p, t)
    fine = biotet.mesh(p, t, size=0.5)
    assert fine.n_tets > 10 * coarse.n_tets
    assert biotet.check(fine, (p, t))["valid"]


def test_progress_callable_sees_the_stages():
    seen = []
    p, t = cube(side=2.0)
    biotet.mesh(p, t, size=0.5, progress=seen.append)
    assert any("recover" in s or "Delaunay" in s or "delaunay" in s for s in seen), seen


def test_progress_callable_sees_the_surface_stage_steps():
    # Each step of the stage is a progress point (Ctrl-C stops the call at the next one); the
    # stage was one point, so a long run could not be stopped for minutes.
    seen = []
    p, t = cube(side=2.0)
    biotet.mesh(p, t, surface_tolerance=0.05, progress=seen.append)
    steps = [s for s in seen if s.startswith("improving the surface: ")]
    assert any("round" in s for s in steps) and any("measuring" in s for s in steps), seen


def test_labels_beyond_the_template_are_renumbered_and_put_back():
    # An extracted segmentation keeps its values (FreeSurfer's 2035): mesh() took at most 8191,
    # as mesh_image() did not.
    p, t = cube()
    m = biotet.mesh(p, t, labels=[9000])
    assert set(np.unique(m.labels)) == {9000}
    assert biotet.check(m, (p, t), labels=[9000])["valid"]


def test_delaunay_recover_improve_smooth_chain():
    src = SHAPES / "cad_as1_nut_default.off"
    s = biotet.read_surface(src)
    dt = biotet.delaunay(s.points)
    assert biotet.check(dt)["valid"]
    rec = biotet.recover(dt, s)
    c = biotet.check(rec, s)
    assert c["valid"] and c["surface"]["n_missing"] == 0, c["problems"]
    imp = biotet.improve(rec)
    assert biotet.check(imp, s)["valid"]
    assert imp.report["n_bad_after"] <= imp.report["n_bad_before"]
    sm = biotet.smooth(imp)
    assert biotet.check(sm, s)["valid"]
    assert sm.report["min_solid_angle_after_sr"] >= sm.report["min_solid_angle_before_sr"]


def test_read_write_roundtrip(tmp_path, brain_mesh):
    for ext in ("vtu", "mesh", "msh"):
        path = tmp_path / f"m.{ext}"
        biotet.write(path, brain_mesh)
        back = biotet.read(path)
        assert isinstance(back, biotet.TetMesh)
        assert back.n_tets == brain_mesh.n_tets
        assert np.array_equal(back.labels, brain_mesh.labels)
        np.testing.assert_array_equal(back.points, brain_mesh.points)
    s = biotet.read(SHAPES / "tm_box.off")
    assert isinstance(s, biotet.Surface) and s.triangles.shape == (12, 3)


def test_surface_tolerance_moves_the_surface_within_the_bound(brain):
    m = biotet.mesh(brain.points, brain.triangles, surface_tolerance=0.5)
    s = m.report["surface"]
    assert s["hausdorff_in_to_out"] <= 0.5 and s["hausdorff_out_to_in"] <= 0.5
    assert m.report["quality"]["n_dihedral_lt_10"] < 100
    assert biotet.check(m)["valid"]


def test_surface_stage_options_write_the_cli_bytes(cli, tmp_path):
    src = SHAPES / "tm_torus.off"
    s = biotet.read_surface(src)
    d = 0.01 * float(np.linalg.norm(np.ptp(s.points, axis=0)))
    out = tmp_path / "cli.vtu"
    r = run_cli(cli, "mesh", src, "-o", out, "--quiet", "--surface-tolerance", repr(d),
                "--feature-angle", "20", "--surface-rounds", "3")
    assert r.returncode == 0, r.stderr
    m = biotet.mesh_file(src, surface_tolerance=d, surface_feature_angle=20.0, surface_rounds=3)
    mine = tmp_path / "py.vtu"
    m.write(mine)
    assert mine.read_bytes() == out.read_bytes()
    assert m.report["surface"]["hausdorff_in_to_out"] <= d
    # The options reach the stage: its default rounds give another surface.
    other = biotet.mesh_file(src, surface_tolerance=d, surface_feature_angle=20.0)
    assert other.points.shape != m.points.shape or not np.array_equal(other.points, m.points)
