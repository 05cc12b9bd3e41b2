//! `--max-memory`: work estimated above the limit is refused before it starts, with a message
//! naming the input and the option; work under it runs as before.

mod support;
use support::*;

fn code_and_message(args: &[&str]) -> (Option<i32>, String) {
    let o = biotet(args);
    (o.status.code(), stderr(&o))
}

#[test]
fn meshing_estimated_above_the_limit_is_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.vtu");
    let box_ = root().join("tests/data/shapes/tm_box.off");
    // Size 0.01 in a unit cube: about a million nodes, some 800 MiB.
    let (code, msg) = code_and_message(&[
        "mesh",
        s(&box_),
        "--size",
        "0.01",
        "--max-memory",
        "64M",
        "-o",
        s(&out),
    ]);
    assert_eq!(code, Some(2), "{msg}");
    assert!(
        msg.contains("tm_box.off") && msg.contains("--max-memory"),
        "{msg}"
    );
    assert_eq!(msg.trim_end().lines().count(), 1, "{msg}");
    assert!(!out.exists());
    // Size 0.2 fits.
    let o = biotet(&[
        "mesh",
        s(&box_),
        "--size",
        "0.2",
        "--max-memory",
        "64M",
        "-o",
        s(&out),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let c = biotet(&["check", s(&out), "--quiet"]);
    assert!(c.status.success(), "{}", stderr(&c));
}

#[test]
fn delaunay_and_images_above_the_limit_are_refused() {
    let (code, msg) = code_and_message(&[
        "delaunay",
        s(&root().join("examples/brain_tetgen.node")),
        "--max-memory",
        "1M",
    ]);
    assert_eq!(code, Some(2), "{msg}");
    assert!(
        msg.contains("brain_tetgen.node") && msg.contains("--max-memory"),
        "{msg}"
    );

    // A NIfTI header announcing 1024×1024×64 voxels (the data need not be there: the
    // announcement alone is refused).
    let dir = tempfile::tempdir().unwrap();
    let nii = dir.path().join("big.nii");
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    for (i, d) in [3u16, 1024, 1024, 64, 1, 1, 1, 1].iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&2i16.to_le_bytes()); // uint8
    h[72..74].copy_from_slice(&8i16.to_le_bytes());
    for i in 0..4 {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&1f32.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[344..348].copy_from_slice(b"n+1\0");
    std::fs::write(&nii, h).unwrap();
    let out = dir.path().join("s.vtu");
    let (code, msg) =
        code_and_message(&["surface", s(&nii), "-o", s(&out), "--max-memory", "256M"]);
    assert_eq!(code, Some(2), "{msg}");
    assert!(
        msg.contains("big.nii") && msg.contains("--max-memory"),
        "{msg}"
    );
    assert!(!out.exists());
}

#[test]
fn bad_limits_are_refused() {
    for v in ["12Q", "0", "1.5.2G", "lots"] {
        let (code, msg) = code_and_message(&["validate", "x.stl", "--max-memory", v]);
        assert_eq!(code, Some(2), "{v}: {msg}");
        assert!(msg.contains("--max-memory"), "{v}: {msg}");
    }
}

/// The surface stage at a fine edge length (a label image's default, or `--surface-tolerance`
/// with `--size`) grew past 2 GB under `--max-memory 300M` and ran on (an image of 30³ 1 mm
/// voxels at `--size 0.02`): refused before the work, naming the stage and the option.
#[test]
fn a_surface_stage_estimated_above_the_limit_is_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.vtu");
    let box_ = root().join("tests/data/shapes/tm_box.off");
    for args in [
        vec![
            "mesh",
            s(&box_),
            "--surface-tolerance",
            "0.01",
            "--size",
            "0.001",
        ],
        vec![
            "surface",
            "improve",
            s(&box_),
            "--tolerance",
            "0.01",
            "--edge-length",
            "0.001",
        ],
    ] {
        let mut args = args;
        args.extend(["--max-memory", "64M", "-o", s(&out)]);
        let (code, msg) = code_and_message(&args);
        assert_eq!(code, Some(2), "{msg}");
        assert!(
            msg.contains("tm_box.off")
                && msg.contains("surface stage")
                && msg.contains("--max-memory"),
            "{msg}"
        );
        assert_eq!(msg.trim_end().lines().count(), 1, "{msg}");
        assert!(!out.exists());
    }
}
