"""Round trips through meshio, and pyvista / dolfinx when installed."""

import numpy as np
import pytest

import biotet
from conftest import SHAPES


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


def test_dolfinx_mesh(torus):
    dolfinx = pytest.importorskip("dolfinx")
    from mpi4py import MPI
    import basix.ufl
    import ufl

    domain = ufl.Mesh(basix.ufl.element("Lagrange", "tetrahedron", 1, shape=(3,)))
    mesh = dolfinx.mesh.create_mesh(MPI.COMM_WORLD, torus.tets.astype(np.int64), domain, torus.points)
    assert mesh.topology.index_map(3).size_global == torus.n_tets
