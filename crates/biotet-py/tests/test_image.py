"""Label volumes: mesh_image from numpy and mesh_file on image files, compared with the CLI."""

import numpy as np
import pytest

import biotet
from conftest import DATA, IMAGES, cube, nested_balls, run_cli, write_nrrd, write_vti

SPACING = (0.8, 1.0, 1.2)
ORIGIN = (-5.0, 3.0, 7.0)


def cli_mesh(cli, tmp_path, src, *args):
    """The CLI's mesh of a file, as bytes."""
    out = tmp_path / "cli.vtu"
    r = run_cli(cli, "mesh", src, "-o", out, "--quiet", *args)
    assert r.returncode == 0, r.stderr
    return out.read_bytes()


def bytes_of(m, tmp_path, name="py.vtu"):
    path = tmp_path / name
    m.write(path)
    return path.read_bytes()


def test_nested_balls_keep_their_labels_and_voxel_volumes():
    lab = nested_balls()
    m = biotet.mesh_image(lab, spacing=SPACING, origin=ORIGIN, exact_surface=True)
    # The tets carry the image's own values, not 1, 2.
    assert set(np.unique(m.labels)) == {7, 30}
    assert m.points.dtype == np.float64 and m.tets.dtype == np.int32
    c = biotet.check(m)
    assert c["valid"], c["problems"]
    # The surface is the voxel faces, kept exactly: each region's mesh volume is its voxel
    # volume (relative 1e-9: only rounding).
    voxel = np.prod(SPACING)
    vol = {r["label"]: r["volume"] for r in biotet.quality(m)["regions"]}
    for label in (7, 30):
        want = np.count_nonzero(lab == label) * voxel
        assert vol[label] == pytest.approx(want, rel=1e-9), label
    rows = {r["label"]: r for r in m.report["image_regions"]}
    assert set(rows) == {7, 30}
    assert all(abs(r["relative_error"]) < 1e-9 for r in rows.values())
    assert m.report["image"]["dims"] == list(lab.shape)
    assert m.report["image"]["frame_to_world"] is None
    # Inside the box of the voxels, around the outer ball.
    lo = np.asarray(ORIGIN) - 0.5 * np.asarray(SPACING)
    hi = lo + np.asarray(SPACING) * lab.shape
    assert np.all(m.points >= lo - 1e-12) and np.all(m.points <= hi + 1e-12)


def test_by_default_the_voxel_faces_are_remeshed_within_half_a_voxel():
    lab = nested_balls()
    m = biotet.mesh_image(lab, spacing=SPACING, origin=ORIGIN)
    assert set(np.unique(m.labels)) == {7, 30}
    d = 0.5 * min(SPACING)
    assert m.report["surface"]["tolerance"] == d
    # Each region's boundary within d of its voxel boundary both ways (and moved: no longer the
    # staircase), its volume near its voxel volume; the sheets in the image's labels.
    rows = {r["label"]: r for r in m.report["image_regions"]}
    assert set(rows) == {7, 30}
    for r in rows.values():
        assert 0.0 < r["hausdorff_in_to_out"] <= d and 0.0 < r["hausdorff_out_to_in"] <= d, r
        assert abs(r["relative_error"]) < 0.05, r
        assert r["components"] == r["components_voxels"] == 1, r
    assert {tuple(sorted(x["sides"])) for x in m.report["surface"]["sheets"]} == {(0, 7), (7, 30)}
    c = biotet.check(m)
    assert c["valid"], c["problems"]
    assert biotet.quality(m)["min_dihedral_deg"] >= 10.0


def test_affine_spacing_and_dtypes_give_the_same_mesh():
    lab = nested_balls(n=14, inner=3, outer=5.5)
    a = biotet.mesh_image(lab, spacing=SPACING, origin=ORIGIN)
    aff = np.diag([*SPACING, 1.0])
    aff[:3, 3] = ORIGIN
    for variant in (
        dict(affine=aff),
        dict(affine=aff[:3]),
    ):
        b = biotet.mesh_image(lab, **variant)
        assert np.array_equal(a.points, b.points) and np.array_equal(a.tets, b.tets)
    spaced = np.zeros((2 * lab.shape[0],) + lab.shape[1:], lab.dtype)
    spaced[::2] = lab
    reversed_view = np.ascontiguousarray(lab[::-1])[::-1]  # negative strides, same values
    for data in (lab.astype(np.int64), lab.astype(np.float32), np.ascontiguousarray(lab),
                 spaced[::2], reversed_view, lab.astype(np.dtype(">u4"))):
        b = biotet.mesh_image(data, spacing=SPACING, origin=ORIGIN)
        assert np.array_equal(a.tets, b.tets) and np.array_equal(a.labels, b.labels)


@pytest.mark.parametrize(
    "options, args",
    [
        ({}, []),
        ({"merge": {30: 7}}, ["--merge", "30=7"]),
        ({"keep_labels": [30], "size": 1.5}, ["--labels", "30", "--size", "1.5"]),
        ({"min_component_voxels": 5, "region_sizes": {7: 2.0}},
         ["--min-component-voxels", "5", "--region-size", "7=2.0"]),
    ],
)
def test_mesh_image_and_mesh_file_write_the_cli_bytes(cli, tmp_path, options, args):
    lab = nested_balls()
    lab[1, 1, 1] = 30  # an island of one voxel
    src = tmp_path / "balls.nrrd"
    write_nrrd(src, lab, SPACING, ORIGIN)
    want = cli_mesh(cli, tmp_path, src, *args)
    got = biotet.mesh_image(lab, spacing=SPACING, origin=ORIGIN, **options)
    assert bytes_of(got, tmp_path, "a.vtu") == want
    assert bytes_of(biotet.mesh_file(src, **options), tmp_path, "b.vtu") == want
    assert biotet.check(got)["valid"]


@pytest.mark.parametrize(
    "name",
    [
        "label_nifti1_int16.nii.gz",
        "label_nifti2_float32_qform.nii",
        "label_uint8.mgz",
        "label_lps_gzip.nrrd",
        "label_ras_detached.nhdr",
        "label_uint8.mha",
        "label_int32.mhd",
        "label_ascii.vti",
    ],
)
def test_every_image_format_meshes_as_the_cli(cli, tmp_path, name):
    src = IMAGES / name
    want = cli_mesh(cli, tmp_path, src, "--size", "1.0")
    m = biotet.mesh_file(src, size=1.0)
    assert bytes_of(m, tmp_path) == want
    assert set(np.unique(m.labels)) == {1, 2, 17, 41}
    # These files hold a rotated affine: meshed in the image's frame, rotated after.
    assert m.report["image"]["frame_to_world"] is not None
    assert biotet.check(m)["valid"]


def expected_image():
    """The labels and affine every label_* fixture holds (label_expected.txt)."""
    rows = {}
    for line in (IMAGES / "label_expected.txt").read_text().splitlines():
        if line and not line.startswith("#"):
            key, *vals = line.split()
            rows[key] = vals
    affine = np.array([float(x) for x in rows["affine"]]).reshape(3, 4)
    labels = np.array([int(x) for x in rows["labels"]]).reshape((5, 4, 3), order="F")
    return labels, affine


def test_an_oblique_volume_from_numpy_is_the_cli_mesh_of_its_file(cli, tmp_path):
    labels, affine = expected_image()
    # The detached NRRD holds this affine in RAS with every digit.
    want = cli_mesh(cli, tmp_path, IMAGES / "label_ras_detached.nhdr", "--merge", "41=2")
    m = biotet.mesh_image(labels, affine=affine, merge={41: 2})
    assert bytes_of(m, tmp_path) == want
    assert set(np.unique(m.labels)) == {1, 2, 17}


def test_a_nifti_written_by_nibabel(cli, tmp_path):
    nib = pytest.importorskip("nibabel")
    lab = nested_balls(n=16, inner=3.5, outer=6.5)
    aff = np.array([[0.0, -0.9, 0.0, 10.0], [1.1, 0.0, 0.0, -4.0], [0.0, 0.0, 1.0, 2.0],
                    [0.0, 0.0, 0.0, 1.0]])
    src = tmp_path / "balls.nii.gz"
    nib.save(nib.Nifti1Image(lab, aff), src)
    img = nib.load(src)
    want = cli_mesh(cli, tmp_path, src)
    m = biotet.mesh_image(np.asanyarray(img.dataobj), affine=img.affine)
    assert bytes_of(m, tmp_path) == want


def test_size_fields_from_files_and_from_numpy_match_the_cli(cli, tmp_path):
    # A field finer towards +x over a cube, as a .vti file and as arrays.
    p, t = cube(side=3.0)
    surf = tmp_path / "cube.off"
    surf.write_text(
        "OFF\n8 12 0\n" + "".join(" ".join(repr(float(x)) for x in q) + "\n" for q in p)
        + "".join(f"3 {a} {b} {c}\n" for a, b, c in t)
    )
    g = np.meshgrid(*[np.arange(5)] * 3, indexing="ij")[0]
    values = 1.2 - 0.2 * g
    field = tmp_path / "size.vti"
    write_vti(field, values, (0.75, 0.75, 0.75), (0.0, 0.0, 0.0))
    want = cli_mesh(cli, tmp_path, surf, "--size-field", field)
    from_file = biotet.mesh(p, t, size_field=field, name=str(surf))
    assert bytes_of(from_file, tmp_path, "a.vtu") == want
    grid = biotet.SizeField(values, spacing=(0.75, 0.75, 0.75))
    assert bytes_of(biotet.mesh(p, t, size_field=grid), tmp_path, "b.vtu") == want
    assert bytes_of(biotet.mesh_file(surf, size_field=grid), tmp_path, "c.vtu") == want
    # Finer where the field is smaller: more tets than with its largest value everywhere.
    assert from_file.n_tets > biotet.mesh(p, t, size=1.2).n_tets


def test_a_size_field_on_the_image_grid(cli, tmp_path):
    lab = nested_balls(n=14, inner=3, outer=5.5)
    sizes = np.where(lab == 30, 0.6, 1.5)
    src = tmp_path / "balls.nrrd"
    write_nrrd(src, lab, SPACING, ORIGIN)
    field = tmp_path / "size.vti"
    # The image's voxel centres are its grid points.
    write_vti(field, sizes, SPACING, ORIGIN)
    want = cli_mesh(cli, tmp_path, src, "--size-field", field)
    m = biotet.mesh_image(lab, spacing=SPACING, origin=ORIGIN, size_field=sizes)
    assert bytes_of(m, tmp_path) == want
    assert biotet.check(m)["valid"]


def test_bad_label_volumes_and_options_raise_the_cli_messages(cli, tmp_path):
    lab = nested_balls(n=10, inner=2, outer=4)
    src = tmp_path / "balls.nrrd"
    write_nrrd(src, lab, SPACING, ORIGIN)
    cases = [
        (dict(outside=7), ["--outside", "7"]),
        (dict(keep_labels=[99]), ["--labels", "99"]),
    ]
    for options, args in cases:
        r = run_cli(cli, "mesh", src, "--quiet", *args)
        assert r.returncode != 0
        cli_message = r.stderr.strip().removeprefix("error: ")
        with pytest.raises(ValueError) as e:
            biotet.mesh_file(src, **options)
        assert str(e.value) == cli_message
        with pytest.raises(ValueError) as e:
            biotet.mesh_image(lab, name=str(src), **options)
        assert str(e.value) == cli_message
    with pytest.raises(ValueError, match="no region 5 in the image"):
        biotet.mesh_image(lab, region_sizes={5: 1.0})
    bad = lab.astype(np.int32)
    bad[3, 2, 1] = -1
    with pytest.raises(ValueError, match=r"voxel \(3, 2, 1\) holds -1"):
        biotet.mesh_image(bad)
    with pytest.raises(ValueError, match=r"voxel \(0, 0, 0\) holds 0.5"):
        biotet.mesh_image(np.full((2, 2, 2), 0.5))
    # Labels the written formats cannot hold (Int32): refused before meshing, not wrapped to
    # negative numbers or refused by the writer after it.
    big = lab.astype(np.uint32)
    big[big == big.max()] = 3_000_000_000
    with pytest.raises(ValueError, match=r"holds 3000000000, not a label \(an integer in 0..2\*\*31\)"):
        biotet.mesh_image(big)
    with pytest.raises(ValueError, match="3-D"):
        biotet.mesh_image(lab[0])
    with pytest.raises(ValueError, match="not a finite invertible"):
        biotet.mesh_image(lab, spacing=(1.0, 0.0, 1.0))
    with pytest.raises(ValueError, match="not both"):
        biotet.mesh_image(lab, spacing=(2.0, 2.0, 2.0), affine=np.eye(4))
    with pytest.raises(ValueError, match="sizes must be positive"):
        biotet.mesh_image(lab, size_field=np.zeros(lab.shape))
    # Arguments that are no labels or thread counts name themselves (they raised Python's
    # conversion errors: "can't convert negative int to unsigned").
    with pytest.raises(ValueError, match=r"keep_labels: -1 is not a label"):
        biotet.mesh_image(lab, keep_labels=[-1])
    with pytest.raises(ValueError, match=r"merge: 3000000000 is not a label"):
        biotet.mesh_image(lab, merge={7: 3_000_000_000})
    with pytest.raises(ValueError, match=r"threads must be None or a whole number >= 0, not -1"):
        biotet.mesh_image(lab, threads=-1)
    with pytest.raises(ValueError, match=r"must have its shape \(10, 10, 10\), not \(3, 3, 3\)"):
        biotet.mesh_image(lab, size_field=np.ones((3, 3, 3)))
    with pytest.raises(ValueError, match="size_field must be a file path"):
        biotet.mesh(*cube(), size_field=np.ones((2, 2, 2)))


def test_bad_image_files(cli, tmp_path):
    with pytest.raises(FileNotFoundError):
        biotet.mesh_file(tmp_path / "nope.nii.gz")
    src = IMAGES / "label_fractional.nii"
    r = run_cli(cli, "mesh", src, "--quiet")
    assert r.returncode != 0
    with pytest.raises(biotet.BiotetFileError) as e:
        biotet.mesh_file(src)
    assert str(e.value) == r.stderr.strip().removeprefix("error: ")
    with pytest.raises(FileNotFoundError) as e:
        biotet.mesh(*cube(), size_field=tmp_path / "none.vti")
    assert "none.vti" in str(e.value)


def test_the_report_is_the_cli_json(cli, tmp_path):
    import json

    src = IMAGES / "label_uint8.mha"
    r = run_cli(cli, "mesh", src, "--json", "--merge", "2,41=1", "-o", tmp_path / "m.vtu")
    assert r.returncode == 0, r.stderr
    want = json.loads(r.stdout)
    got = biotet.mesh_file(src, merge={2: 1, 41: 1}).report
    untimed = lambda d: {k: v for k, v in d.items() if not k.startswith("seconds")}
    assert untimed(got["image"]) == untimed(want["image"])
    assert got["image_regions"] == want["image_regions"]
    assert got["quality"] == want["quality"] and got["forcing"] == want["forcing"]
    assert [row["label"] for row in got["image_regions"]] == [1, 17]


def test_the_mesh_conforms_to_the_extracted_surface(cli, tmp_path):
    lab = nested_balls()
    s = biotet.surface_extract(lab, spacing=SPACING, origin=ORIGIN)
    assert set(np.unique(s.sides)) == {0, 7, 30}
    m = biotet.mesh_image(lab, spacing=SPACING, origin=ORIGIN, exact_surface=True)
    c = biotet.check(m, s)
    assert c["valid"] and c["surface"]["n_missing"] == 0, c["problems"]
    # Another image's surface does not fit this mesh.
    other = biotet.surface_extract(nested_balls(values=(30, 8)), spacing=SPACING, origin=ORIGIN)
    assert not biotet.check(m, other)["valid"]
    # An oblique file: the CLI's surface, point for point, and its mesh conforms to it.
    src = IMAGES / "label_uint8.mha"
    out = tmp_path / "s.ply"
    r = run_cli(cli, "surface", src, "-o", out, "--quiet")
    assert r.returncode == 0, r.stderr
    want = biotet.read_surface(out)
    got = biotet.surface_extract(src)
    np.testing.assert_array_equal(got.points, want.points)
    np.testing.assert_array_equal(got.triangles, want.triangles)
    np.testing.assert_array_equal(got.sides, want.sides)
    c = biotet.check(biotet.mesh_file(src, exact_surface=True), got)
    assert c["valid"] and c["surface"]["n_missing"] == 0, c["problems"]
    with pytest.raises(ValueError, match="own geometry"):
        biotet.surface_extract(src, spacing=(2.0, 2.0, 2.0))
    with pytest.raises(biotet.BiotetFileError, match="not a label image"):
        biotet.surface_extract(IMAGES / "vtk_ascii.vtu")


def test_voxels_six_times_longer_one_way_mesh_without_flat_tets():
    # A ball in 0.5 x 0.5 x 3 mm voxels (CT slices): the voxel faces are 6:1 rectangles and, until
    # the surface stage turned each sheet one way for such images, every staircase edge between
    # differently signed faces was a rim it kept: 6.7e-9° triangles, 3e-13° tets, 12 s.
    i, j, k = np.indices((24, 24, 8))
    lab = ((((i - 11.5) * 0.5) ** 2 + ((j - 11.5) * 0.5) ** 2 + ((k - 3.5) * 3) ** 2) < 25).astype(np.uint8)
    m = biotet.mesh_image(lab, spacing=(0.5, 0.5, 3.0))
    q = biotet.quality(m)
    assert q["min_dihedral_deg"] >= 10.0 and q["max_dihedral_deg"] <= 165.0, q
    assert biotet.check(m)["valid"]
    assert m.report["surface"]["n_rim_edges"] == 0


def test_thick_slices_at_the_border_make_no_flat_triangles():
    # Grey and white matter in 0.5 x 0.5 x 3 mm voxels where their interface meets the image's
    # border (tests/data/ridge_aniso_crop.nii.gz): the kept triple lines there are staircases of
    # 3 mm steps, and the stage's rounds split the triangles on them again every round, their far
    # corners closing in: 1e-6° triangles, 0.00° tets, 705 under 10°. Splits there stopped at 3°
    # (41 tets under 10°, 2.93°); now the long kept edges are cut to the target before the rounds,
    # their pieces kept: 28° triangles, every tet within 10°-165°.
    m = biotet.mesh_file(DATA / "ridge_aniso_crop.nii.gz")
    s = m.report["surface"]
    assert s["min_angle_out"] >= 20.0, s["min_angle_out"]
    q = biotet.quality(m)
    assert q["min_dihedral_deg"] >= 10.0 and q["max_dihedral_deg"] <= 165.0, q
    assert biotet.check(m)["valid"]
