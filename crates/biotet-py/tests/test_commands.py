"""delaunay, recover, improve and smooth beside the CLI's commands on the same input: the same
bytes."""

import numpy as np
import pytest

import biotet
from conftest import SHAPES, run_cli


def cli_ok(cli, *args):
    r = run_cli(cli, *args, "--quiet")
    assert r.returncode == 0, r.stderr


def same_bytes(m, path, tmp_path):
    mine = tmp_path / ("py_" + path.name)
    m.write(mine)
    return mine.read_bytes() == path.read_bytes()


@pytest.mark.parametrize("shape", ["cad_as1_nut_default.off", "gen_schonhardt.off"])
def test_each_stage_writes_the_cli_bytes(cli, tmp_path, shape):
    src = SHAPES / shape
    s = biotet.read_surface(src)
    pts = tmp_path / "points.txt"
    pts.write_text("".join(" ".join(repr(float(x)) for x in p) + "\n" for p in s.points))

    dt = tmp_path / "dt.vtu"
    cli_ok(cli, "delaunay", pts, "-o", dt)
    py_dt = biotet.delaunay(s.points)
    assert same_bytes(py_dt, dt, tmp_path)

    rec = tmp_path / "rec.vtu"
    cli_ok(cli, "recover", dt, "-s", src, "-o", rec)
    py_rec = biotet.recover(biotet.read(dt), s)
    assert same_bytes(py_rec, rec, tmp_path)
    assert biotet.check(py_rec, s)["valid"]

    imp = tmp_path / "imp.vtu"
    cli_ok(cli, "improve", rec, "-o", imp)
    py_imp = biotet.improve(py_rec)
    assert same_bytes(py_imp, imp, tmp_path)
    imp_q = tmp_path / "imp_q.vtu"
    cli_ok(cli, "improve", rec, "-o", imp_q, "--metric", "q")
    assert same_bytes(biotet.improve(py_rec, metric="q"), imp_q, tmp_path)

    sm = tmp_path / "sm.vtu"
    cli_ok(cli, "smooth", imp, "-o", sm)
    py_sm = biotet.smooth(py_imp)
    assert same_bytes(py_sm, sm, tmp_path)
    slide = tmp_path / "slide.vtu"
    cli_ok(cli, "smooth", imp, "-o", slide, "--boundary", "slide", "-s", src,
           "--feature-angle", "30", "--max-sweeps", "4")
    py_slide = biotet.smooth(py_imp, s, slide=True, feature_angle=30.0, max_sweeps=4)
    assert same_bytes(py_slide, slide, tmp_path)
    assert biotet.check(py_slide)["valid"]


def test_int32_and_int64_arrays_give_the_same_answers():
    s = biotet.read_surface(SHAPES / "tm_box.off")
    m = biotet.mesh(s.points, s.triangles)
    assert m.tets.dtype == np.int32
    wide = biotet.TetMesh(m.points, m.tets.astype(np.int64), m.labels.astype(np.int64))
    assert biotet.quality(wide) == biotet.quality(m)
    assert biotet.check(wide, s) == biotet.check(m, s)
    narrow = biotet.TetMesh(m.points, m.tets.astype(np.uint16), m.labels.astype(np.uint8))
    assert biotet.quality(narrow) == biotet.quality(m)


def test_bad_stage_options():
    s = biotet.read_surface(SHAPES / "tm_box.off")
    m = biotet.mesh(s.points, s.triangles)
    with pytest.raises(ValueError, match="threshold -1"):
        biotet.improve(m, threshold=-1.0)
    with pytest.raises(ValueError, match="metric"):
        biotet.improve(m, metric="volume")
    with pytest.raises(ValueError, match="feature_angle 200"):
        biotet.smooth(m, feature_angle=200.0)
    with pytest.raises(ValueError, match="integers"):
        biotet.quality(biotet.TetMesh(m.points, m.tets, m.labels.astype(float)))


def test_tets_stored_the_other_way_round_are_turned_as_the_readers_do():
    # Another tool's convention: every tet negative. The file readers turn them all; arrays
    # handed to check, improve and smooth are turned the same way (before, improve and smooth
    # returned them unchanged and check called the result invalid).
    s = biotet.read_surface(SHAPES / "cad_as1_nut_default.off")
    m = biotet.mesh(s.points, s.triangles)
    other = biotet.TetMesh(m.points, m.tets[:, [1, 0, 2, 3]], m.labels)
    assert biotet.check(other, s)["valid"]
    for out in (biotet.improve(other), biotet.smooth(other)):
        assert biotet.check(out, s)["valid"]
        assert out.n_tets == m.n_tets
