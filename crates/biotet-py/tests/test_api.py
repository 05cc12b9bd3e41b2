"""The package's surface: docstrings everywhere, a stub for every native function, nothing
printed, progress through the ``biotet`` logger."""

import ast
import inspect
import logging
from pathlib import Path

import biotet
from biotet import _core
import pytest

from conftest import SHAPES, cube


def test_every_public_name_has_a_docstring():
    for name in biotet.__all__:
        if name == "__version__":
            continue
        obj = getattr(biotet, name)
        assert inspect.getdoc(obj), name
        if inspect.isclass(obj):
            for m, f in vars(obj).items():
                if callable(f) and not m.startswith("_"):
                    assert inspect.getdoc(f), f"{name}.{m}"


def test_every_native_function_has_a_docstring_and_a_stub():
    stub = Path(_core.__file__).with_name("_core.pyi")
    tree = ast.parse(stub.read_text())
    stubbed = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    native = {n for n, f in vars(_core).items() if callable(f) and not n.startswith("_")}
    native.discard("CoreError")
    assert native, "no native functions found"
    assert native == stubbed, (native - stubbed, stubbed - native)
    for n in native:
        assert getattr(_core, n).__doc__, n
    assert (stub.parent / "py.typed").is_file()


def test_nothing_printed_and_progress_logged(capfd, caplog):
    p, t = cube(side=2.0)
    with caplog.at_level(logging.INFO, logger="biotet"):
        biotet.mesh(p, t, size=0.6)
    out, err = capfd.readouterr()
    assert out == "" and err == ""
    stages = [r.getMessage() for r in caplog.records if r.name == "biotet"]
    assert stages and any("smooth" in s.lower() for s in stages), stages
    caplog.clear()
    biotet.mesh(p, t, size=0.6)  # the logger below INFO: nothing logged
    assert not [r for r in caplog.records if r.name == "biotet"]


def test_meshes_and_surfaces_compare_as_plain_bools():
    # Until session 33, `a == b` raised numpy's "truth value of an array is ambiguous".
    a = biotet.mesh(*cube())
    b = biotet.mesh(*cube())
    assert a == b and not (a != b)
    moved = biotet.TetMesh(a.points + 1.0, a.tets, a.labels)
    assert a != moved
    assert a != biotet.TetMesh(a.points, a.tets[:1], a.labels[:1])
    assert a != "a mesh"
    s = biotet.read_surface(SHAPES / "tm_box.off")
    assert s == biotet.read_surface(SHAPES / "tm_box.off")
    assert s != biotet.Surface(s.points * 2, s.triangles, s.sides)
    with pytest.raises(TypeError):
        hash(a)


def test_mesh_file_with_no_file_is_a_value_error():
    with pytest.raises(ValueError, match="at least one file"):
        biotet.mesh_file([])
