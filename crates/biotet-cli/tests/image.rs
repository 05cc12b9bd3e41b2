//! Label images in: `biotet surface IMAGE` and `biotet mesh IMAGE`, on the small fixtures of
//! biotet-io (the same 5×4×3 volume in every format, rotated, anisotropic).

mod support;
use support::*;

fn fixture(name: &str) -> std::path::PathBuf {
    root().join("crates/biotet-io/tests/data").join(name)
}

#[test]
fn surface_extract_writes_a_labelled_surface_that_validates() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s.vtu");
    let r = biotet(&[
        "surface",
        s(&fixture("label_lps_gzip.nrrd")),
        "-o",
        s(&out),
        "--json",
    ]);
    assert!(r.status.success(), "{}", stderr(&r));
    let j = json_of(&r);
    let regions = j["image"]["regions"].as_array().unwrap();
    assert_eq!(
        regions
            .iter()
            .map(|r| r["label"].as_u64().unwrap())
            .collect::<Vec<_>>(),
        vec![1, 2, 17, 41]
    );
    let v = biotet(&["validate", s(&out), "--json"]);
    assert!(v.status.success(), "{}", stderr(&v));
    // The validated volume of each region is its voxel volume.
    let vj = json_of(&v);
    let rep = &vj["surfaces"][0]["report"]["regions"];
    for r in regions {
        let l = r["label"].as_u64().unwrap();
        let got = rep
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["label"].as_u64() == Some(l))
            .unwrap()["volume"]
            .as_f64()
            .unwrap();
        let want = r["voxel_volume"].as_f64().unwrap();
        assert!((got - want).abs() < 1e-9 * want, "{l}: {got} vs {want}");
    }
}

#[test]
fn mesh_an_image_with_label_options() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.vtu");
    let r = biotet(&[
        "mesh",
        s(&fixture("label_uint8.mha")),
        "--merge",
        "2,41=1",
        "--labels",
        "1,17",
        "--size",
        "1.0",
        "-o",
        s(&out),
        "--json",
    ]);
    assert!(r.status.success(), "{}", stderr(&r));
    let j = json_of(&r);
    let rows = j["image_regions"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for row in rows {
        let e = row["relative_error"].as_f64().unwrap();
        assert!(e.abs() < 1e-9, "{row}");
    }
    // An oblique image is meshed in its axis-aligned frame, so flat voxel faces stay flat and
    // no flat tet fills a rounding fold.
    assert!(j["image"]["frame_to_world"].is_array());
    let min = j["quality"]["min_dihedral_deg"].as_f64().unwrap();
    assert!(min > 5.0, "min dihedral {min}");
    let c = biotet(&["check", s(&out), "--json"]);
    assert!(c.status.success(), "{}", stderr(&c));
    // Text output names the regions.
    let t = biotet(&["mesh", s(&fixture("label_ascii.vti")), "--size", "1.0"]);
    assert!(t.status.success(), "{}", stderr(&t));
    let text = String::from_utf8_lossy(&t.stdout);
    assert!(
        text.contains("voxel volume") && text.contains("mesh volume"),
        "{text}"
    );
}

#[test]
fn bad_image_options_are_clear_errors() {
    let r = biotet(&["surface", s(&fixture("label_fractional.nii"))]);
    assert!(!r.status.success());
    assert!(stderr(&r).contains("whole numbers"), "{}", stderr(&r));
    let r = biotet(&["surface", s(&fixture("label_uint8.mgz")), "--merge", "2=x"]);
    assert!(!r.status.success());
    assert!(stderr(&r).contains("--merge"), "{}", stderr(&r));
}
