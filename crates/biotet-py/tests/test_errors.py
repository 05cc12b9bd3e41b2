"""Bad input: the CLI's messages as Python exceptions, never a crash."""

import numpy as np
import pytest

import biotet
from conftest import SHAPES, cube, run_cli


def test_open_surface_is_invalid_naming_triangles():
    with pytest.raises(biotet.InvalidSurfaceError) as e:
        biotet.mesh_file(SHAPES / "invalid_open_box.off")
    assert isinstance(e.value, ValueError)
    assert "invalid_open_box.off" in str(e.value) and "closed" in str(e.value)
    assert e.value.triangles and all(isinstance(t, int) for t in e.value.triangles)


def test_hole_and_crossing_cubes():
    p, t = cube()
    cases = {
        "closed": (p, t[:-1]),
    }
    q, u = cube((0.5, 0.25, 0.25), 0.5)
    q = q * [2.0, 1.0, 1.0] - [0.5, 0, 0]
    cases["intersect"] = (np.vstack([p, q]), np.vstack([t, u + 8]))
    for word, (pp, tt) in cases.items():
        with pytest.raises(biotet.InvalidSurfaceError) as e:
            biotet.mesh(pp, tt)
        assert word in str(e.value).lower(), str(e.value)
        assert "triangle" in str(e.value)
        assert e.value.triangles, word
        assert max(e.value.triangles) < len(tt)


def test_crossing_triangles_are_untangled_by_the_surface_stage():
    # A flat ellipsoid whose top pole is pushed through its bottom: refused with the way out,
    # meshed with a surface tolerance (the points moved at most a quarter of it). Two cubes
    # pushed deep into one another stay refused, saying so.
    rings, seg = 8, 16  # a UV sphere: poles 0 and 1, rings of `seg` points between
    th = np.pi * np.arange(1, rings) / rings
    ph = 2 * np.pi * np.arange(seg) / seg
    ring = np.stack([np.outer(np.sin(th), np.cos(ph)), np.outer(np.sin(th), np.sin(ph)),
                     np.outer(np.cos(th), np.ones(seg))], axis=-1).reshape(-1, 3)
    p = np.vstack([[0, 0, 1], [0, 0, -1], ring]) * [2.0, 2.0, 0.3]
    at = lambda r, k: 2 + r * seg + k % seg  # noqa: E731
    t = [[0, at(0, k), at(0, k + 1)] for k in range(seg)]
    t += [[1, at(rings - 2, k + 1), at(rings - 2, k)] for k in range(seg)]
    for r in range(rings - 2):
        for k in range(seg):
            t += [[at(r, k), at(r + 1, k), at(r + 1, k + 1)], [at(r, k), at(r + 1, k + 1), at(r, k + 1)]]
    t = np.array(t)
    p[0, 2] = -0.35  # the north pole pushed through the bottom
    with pytest.raises(biotet.InvalidSurfaceError) as err:
        biotet.mesh(p, t)
    assert "surface_tolerance=D" in str(err.value), str(err.value)
    m = biotet.mesh(p, t, surface_tolerance=0.5)
    u = m.report["surface"]["untangled"]
    assert u["pairs"] > 0 and 0 < u["max_move"] <= 0.125, u
    assert biotet.check(m)["valid"]
    q, v = cube((0.5, 0.25, 0.25), 0.5)
    c, ct = cube()
    with pytest.raises(biotet.InvalidSurfaceError) as err:
        biotet.mesh(np.vstack([c, q * [2.0, 1.0, 1.0] - [0.5, 0, 0]]), np.vstack([ct, v + 8]),
                    surface_tolerance=0.05)
    assert "self-intersection" in str(err.value), str(err.value)
    assert "surface_tolerance=D" not in str(err.value), str(err.value)


def test_a_turned_triangle_is_turned_back():
    # Orientation means nothing before the nesting gives the regions: the triangle turned
    # against its neighbours is turned back (as `biotet mesh` does, with a note), not refused.
    p, t = cube()
    turned = np.vstack([t[:3], t[3:4, [0, 2, 1]], t[4:]])
    m = biotet.mesh(p, turned, size=0.5)
    assert biotet.check(m, (p, turned))["valid"]


def test_degenerate_triangle_names_it():
    p, t = cube()
    p = np.vstack([p, p[0]])
    t = np.vstack([t, [[0, 1, 8]]])
    with pytest.raises(biotet.InvalidSurfaceError):
        biotet.mesh(p, t)


def test_missing_and_garbage_files(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        biotet.mesh_file(tmp_path / "nope.stl")
    assert isinstance(e.value, biotet.BiotetFileError)
    assert "nope.stl" in str(e.value)
    g = tmp_path / "garbage.msh"
    g.write_text("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1")
    with pytest.raises(OSError) as e:
        biotet.read(g)
    assert "garbage.msh" in str(e.value)
    bad = tmp_path / "bad.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n")
    with pytest.raises(biotet.BiotetFileError) as e:
        biotet.mesh_file(bad)
    assert "bad.off" in str(e.value)
    with pytest.raises(biotet.BiotetFileError) as e:
        biotet.read(tmp_path / "x.unknown")
    assert "extension" in str(e.value)


@pytest.mark.parametrize(
    "points, faces, msg",
    [
        (np.zeros((4, 2)), [[0, 1, 2]], "shape"),
        (np.zeros((4, 3)), [[0, 1, 9]], "outside"),
        (np.zeros((4, 3)), [[0, 1, -1]], "outside"),
        (np.zeros((4, 3)), [[0.5, 1, 2]], "integers"),
        (np.zeros((4, 3)), np.zeros((0, 3), int), "empty"),
        (np.full((4, 3), np.nan), [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]], "finite"),
    ],
)
def test_bad_arrays_raise_value_errors(points, faces, msg):
    with pytest.raises(ValueError) as e:
        biotet.mesh(points, faces)
    assert msg in str(e.value).lower()


# A tet mesh with a non-finite point: quality() left its tets out of the minimum, improve() and
# smooth() gave back a mesh with NaN points and no error (until session 33); the CLI's readers
# refuse such a file.
@pytest.mark.parametrize("call", ["quality", "improve", "smooth", "check", "write"])
def test_a_tet_mesh_with_a_non_finite_point_is_a_value_error(call, tmp_path):
    m = biotet.mesh(*cube())
    points = m.points.copy()
    points[3, 1] = np.nan
    bad = biotet.TetMesh(points, m.tets, m.labels)
    args = {"write": (tmp_path / "bad.vtu", bad)}.get(call, (bad,))
    with pytest.raises(ValueError) as e:
        getattr(biotet, call)(*args)
    assert "point 3" in str(e.value) and "finite" in str(e.value)
    assert not (tmp_path / "bad.vtu").exists()


def test_bad_options_raise_value_errors():
    p, t = cube()
    with pytest.raises(ValueError):
        biotet.mesh(p, t, zone="round")
    with pytest.raises(ValueError):
        biotet.mesh(p, t, size=-1.0)
    with pytest.raises(ValueError):
        biotet.mesh_file(SHAPES / "tm_box.off", labels={"other.off": [1]})


# Each a ValueError naming the option (a MeshingError, or an OverflowError naming no option,
# until session 32; a size for a region the surface lacks was ignored), and the surface stage's
# prefix said once.
@pytest.mark.parametrize("kwargs, name", [
    ({"surface_tolerance": 0}, "tolerance"),
    ({"surface_tolerance": float("nan")}, "surface_tolerance"),
    ({"surface_tolerance": 0.1, "surface_feature_angle": -5.0}, "feature angle"),
    ({"resolution": 0}, "resolution"),
    ({"resolution": float("inf")}, "resolution"),
    ({"max_voxels": -1}, "max_voxels"),
    ({"surface_rounds": -1}, "surface_rounds"),
    ({"labels": [-3]}, "labels"),
    ({"labels": [2**40]}, "labels"),
    ({"labels": [1.7]}, "labels"),
    ({"region_sizes": {5: 0.1}}, "region_sizes"),
])
def test_out_of_range_options_are_value_errors_naming_them(kwargs, name):
    p, t = cube()
    with pytest.raises(ValueError) as e:
        biotet.mesh(p, t, **kwargs)
    assert name in str(e.value), str(e.value)
    assert str(e.value).count("surface stage") <= 1, str(e.value)


def test_write_nothing_on_a_failed_write(tmp_path):
    p, t = cube()
    m = biotet.mesh(p, t)
    with pytest.raises(OSError):
        m.write(tmp_path / "no" / "such" / "dir.vtu")
    with pytest.raises(biotet.BiotetFileError):
        m.write(tmp_path / "out.unknown")
    assert not any(tmp_path.iterdir())


def bad_cubes():
    """The CLI's bad surfaces (a hole, a crossing cube) and a degenerate triangle, as (points,
    triangles)."""
    p, t = cube()
    q, u = cube((0.5, 0.25, 0.25), 0.5)
    q = q * [2.0, 1.0, 1.0] - [0.5, 0, 0]
    return {
        "closed": (p, t[:-1]),
        "intersect": (np.vstack([p, q]), np.vstack([t, u + 8])),
        "degenerate": (np.vstack([p, p[0] * 0.5 + p[1] * 0.5]),
                       np.vstack([t[:4], [[0, 8, 1]], t[4:]])),
    }


@pytest.mark.parametrize("case", ["closed", "intersect", "degenerate"])
def test_invalid_surfaces_raise_the_cli_message(cli, tmp_path, case):
    p, t = bad_cubes()[case]
    path = tmp_path / f"{case}.off"
    path.write_text(
        f"OFF\n{len(p)} {len(t)} 0\n"
        + "".join(" ".join(repr(float(x)) for x in q) + "\n" for q in p)
        + "".join(f"3 {a} {b} {c}\n" for a, b, c in t)
    )
    r = run_cli(cli, "mesh", path, "--quiet")
    assert r.returncode != 0, r.stderr
    want = r.stderr.strip().removeprefix("error: ")
    with pytest.raises(biotet.InvalidSurfaceError) as e:
        biotet.mesh_file(path)
    assert str(e.value) == want
    if case != "degenerate":  # refused while assembling the shells: no triangle named
        assert e.value.triangles and max(e.value.triangles) < len(t)
    with pytest.raises(biotet.InvalidSurfaceError) as e2:
        biotet.mesh(p, t, name=str(path))
    assert str(e2.value) == want and e2.value.triangles == e.value.triangles
