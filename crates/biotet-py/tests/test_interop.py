"""Round trips through meshio, and pyvista / dolfinx when installed."""

import numpy as np
import pytest

import biotet
from conftest import SHAPES, cube, run_cli


@pytest.fixture(scope="module")
def torus():
    return biotet.mesh_file(SHAPES / "tm_torus.off")


def test_meshio_roundtrip(tmp_path, torus):
    meshio = pytest.importorskip("meshio")
    m = torus.to_meshio()
    path = tmp_path / "t.vtu"
    meshio.write(path, m)
    back = biotet.read(path)
    np.testing.assert_array_equal(back.points, torus.points)
    np.testing.assert_array_equal(back.tets, torus.tets)
    r = meshio.read(path)
    np.testing.assert_array_equal(r.cell_data["region"][0], torus.labels)


def test_pyvista_grid(torus):
    pv = pytest.importorskip("pyvista")
    g = torus.to_pyvista()
    assert g.n_cells == torus.n_tets and g.n_points == torus.n_points
    assert np.array_equal(np.asarray(g.cell_data["region"]), torus.labels)
    assert g.volume == pytest.approx(biotet.quality(torus)["volume"])


def test_dolfinx_mesh_with_the_labels_as_meshtags():
    """A two-region mesh into dolfinx (when installed): the cell labels as meshtags, each
    region's volume integrated by dolfinx equal to biotet's."""
    dolfinx = pytest.importorskip("dolfinx")
    from mpi4py import MPI
    import basix.ufl
    import dolfinx.fem
    import ufl

    p1, t1 = cube((0, 0, 0), 4.0)
    p2, t2 = cube((1, 1, 1), 2.0)
    m = biotet.mesh(np.vstack([p1, p2]), np.vstack([t1, t2 + 8]), labels=[7, 3], size=0.8)
    domain = ufl.Mesh(basix.ufl.element("Lagrange", "tetrahedron", 1, shape=(3,)))
    mesh = dolfinx.mesh.create_mesh(MPI.COMM_WORLD, m.tets.astype(np.int64), domain, m.points)
    assert mesh.topology.index_map(3).size_global == m.n_tets
    # dolfinx reorders cells: take each local cell's label through its original index.
    n_local = mesh.topology.index_map(3).size_local
    original = np.asarray(mesh.topology.original_cell_index)[:n_local]
    cells = np.arange(n_local, dtype=np.int32)
    tags = dolfinx.mesh.meshtags(mesh, 3, cells, m.labels[original].astype(np.int32))
    dx = ufl.Measure("dx", domain=mesh, subdomain_data=tags)
    one = dolfinx.fem.Constant(mesh, 1.0)
    want = {r["label"]: r["volume"] for r in biotet.quality(m)["regions"]}
    for label in (3, 7):
        got = MPI.COMM_WORLD.allreduce(
            dolfinx.fem.assemble_scalar(dolfinx.fem.form(one * dx(label))), op=MPI.SUM
        )
        assert got == pytest.approx(want[label], rel=1e-12)
    assert want[3] == pytest.approx(8.0) and want[7] == pytest.approx(56.0)


def test_surfaces_pyvista_writes_mesh(tmp_path, cli):
    """A sphere PyVista writes as VTP or legacy VTK (binary and ASCII, polygons and triangle
    strips) meshes with every triangle kept, and the VTP and VTK biotet writes read back in
    PyVista with their sides."""
    pv = pytest.importorskip("pyvista")
    sphere = pv.Sphere(theta_resolution=24, phi_resolution=12)
    strips = sphere.strip()
    assert strips.n_strips > 0
    for name, mesh, binary in [
        ("polys.vtp", sphere, True),
        ("polys_ascii.vtp", sphere, False),
        ("strips.vtp", strips, True),
        ("polys.vtk", sphere, True),
        ("polys_ascii.vtk", sphere, False),
        ("strips.vtk", strips, True),
    ]:
        path = tmp_path / name
        mesh.save(path, binary=binary)
        s = biotet.read(path)
        assert isinstance(s, biotet.Surface), name
        assert len(s.triangles) == sphere.n_cells, name
        # VTK's ASCII writers keep six digits of a float32; binary files are exact.
        np.testing.assert_allclose(np.unique(s.points, axis=0),
                                   np.unique(np.asarray(sphere.points), axis=0),
                                   rtol=0 if binary else 1e-5, atol=0 if binary else 1e-6)
        m = biotet.mesh_file(path)
        c = biotet.check(m, s)
        assert c["valid"] and c["surface"]["n_missing"] == 0, (name, c)
    for ext in ("vtp", "vtk"):
        # Converted as it is: no labels (none were read); with --regions, its one region's.
        out = tmp_path / f"back.{ext}"
        r = run_cli(cli, "convert", tmp_path / "polys.vtp", "-o", out)
        assert r.returncode == 0, r.stderr
        back = pv.read(out)
        assert back.n_cells == sphere.n_cells, ext
        assert "sides" not in back.cell_data, ext
        r = run_cli(cli, "convert", tmp_path / "polys.vtp", "--regions", "-o", out)
        assert r.returncode == 0, r.stderr
        back = pv.read(out)
        sides = np.asarray(back.cell_data["sides"])
        assert np.array_equal(sides, np.tile([1, 0], (back.n_cells, 1))), ext


def test_a_tet_mesh_through_legacy_vtk(tmp_path, torus):
    """A tet mesh biotet writes as legacy VTK reads in PyVista with its regions, and one PyVista
    writes (binary and ASCII) reads back in biotet with the same tets and labels."""
    pv = pytest.importorskip("pyvista")
    path = tmp_path / "t.vtk"
    torus.write(path)
    g = pv.read(path)
    assert g.n_cells == torus.n_tets
    assert np.array_equal(np.asarray(g.cell_data["region"]), torus.labels)
    for binary in (True, False):
        back_path = tmp_path / f"pv_{binary}.vtk"
        torus.to_pyvista().save(back_path, binary=binary)
        back = biotet.read(back_path)
        # VTK's ASCII writer keeps eleven digits of a double; its binary files are exact.
        np.testing.assert_allclose(back.points, torus.points, rtol=0 if binary else 1e-9,
                                   atol=0 if binary else 1e-10)
        np.testing.assert_array_equal(back.tets, torus.tets)
        np.testing.assert_array_equal(back.labels, torus.labels)
