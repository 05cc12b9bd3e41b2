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
        "--exact-surface",
        "-o",
        s(&out),
        "--json",
    ]);
    assert!(r.status.success(), "{}", stderr(&r));
    let j = json_of(&r);
    let rows = j["image_regions"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    // The voxel faces kept: each region's mesh volume is its voxel volume, at distance 0.
    assert!(j.get("surface").is_none());
    for row in rows {
        let e = row["relative_error"].as_f64().unwrap();
        assert!(e.abs() < 1e-9, "{row}");
        assert_eq!(row["hausdorff_in_to_out"].as_f64(), Some(0.0), "{row}");
    }
    // An oblique image is meshed in its axis-aligned frame, so flat voxel faces stay flat and
    // no flat tet fills a rounding fold.
    assert!(j["image"]["frame_to_world"].is_array());
    let min = j["quality"]["min_dihedral_deg"].as_f64().unwrap();
    assert!(min > 5.0, "min dihedral {min}");
    let c = biotet(&["check", s(&out), "--json"]);
    assert!(c.status.success(), "{}", stderr(&c));
    // Text output names the regions.
    let t = biotet(&[
        "mesh",
        s(&fixture("label_ascii.vti")),
        "--size",
        "1.0",
        "--exact-surface",
    ]);
    assert!(t.status.success(), "{}", stderr(&t));
    let text = String::from_utf8_lossy(&t.stdout);
    assert!(
        text.contains("voxel volume") && text.contains("mesh volume"),
        "{text}"
    );
}

#[test]
fn an_image_is_meshed_through_the_surface_stage_by_default() {
    // The anisotropic fixture (voxels 1.1 × 0.95 × 1.2, labels 1, 2, 17, 41): by default the
    // voxel faces are remeshed within half the smallest spacing, and every region reports its
    // distance to its voxel boundary within that, in image labels.
    let dir = tempfile::tempdir().unwrap();
    let (out, surf) = (dir.path().join("m.vtu"), dir.path().join("s.vtu"));
    let image = fixture("label_lps_gzip.nrrd");
    let r = biotet(&[
        "mesh",
        s(&image),
        "-o",
        s(&out),
        "--surface-output",
        s(&surf),
        "--json",
    ]);
    assert!(r.status.success(), "{}", stderr(&r));
    let j = json_of(&r);
    let d = j["image"]["default_surface_tolerance"].as_f64().unwrap();
    let spacing: Vec<f64> = j["image"]["spacing"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(
        d,
        0.5 * spacing.iter().copied().fold(f64::INFINITY, f64::min)
    );
    assert_eq!(j["surface"]["tolerance"].as_f64(), Some(d));
    let sheets = j["surface"]["sheets"].as_array().unwrap();
    let labels: Vec<u64> = j["image_regions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["label"].as_u64().unwrap())
        .collect();
    assert_eq!(labels, vec![1, 2, 17, 41]);
    // The report's sheets name the image's labels, not the mesher's renumbered ones.
    for sh in sheets {
        for l in sh["sides"].as_array().unwrap() {
            let l = l.as_u64().unwrap();
            assert!(l == 0 || labels.contains(&l), "{sh}");
        }
    }
    let mut moved = false;
    for row in j["image_regions"].as_array().unwrap() {
        let (a, b) = (
            row["hausdorff_in_to_out"].as_f64().unwrap(),
            row["hausdorff_out_to_in"].as_f64().unwrap(),
        );
        assert!(a <= d && b <= d, "{row}");
        moved |= a > 0.0;
        let e = row["relative_error"].as_f64().unwrap();
        assert!(e.abs() < 0.2, "{row}");
        // No region pinched off or lost: as many pieces in the mesh as in the image.
        assert_eq!(row["components"], row["components_voxels"], "{row}");
        assert!(row["components"].as_u64().unwrap() >= 1, "{row}");
    }
    assert!(moved, "the stage moved no region's boundary");
    // The mesh keeps the improved surface it wrote, with the image's labels.
    let c = biotet(&["check", s(&out), "--surface", s(&surf), "--json"]);
    assert!(c.status.success(), "{}", stderr(&c));
    // --exact-surface and --surface-tolerance cannot both be given.
    let both = biotet(&[
        "mesh",
        s(&image),
        "--exact-surface",
        "--surface-tolerance",
        "0.3",
    ]);
    assert!(!both.status.success());
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
