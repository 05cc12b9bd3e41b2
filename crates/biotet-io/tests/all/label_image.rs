//! Label image readers: the same volume written by nibabel, pynrrd and SimpleITK (and a `.vti`
//! by hand) in every format reads to the same labels and the same RAS affine (nibabel's for
//! NIfTI and MGH); garbage, truncations and byte flips of every file give errors, never panics.

use std::path::{Path, PathBuf};

use biotet::image::LabelImage;
use biotet_io::image::{self, ImageFormat};

use crate::common::Rng;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

const FILES: [&str; 8] = [
    "label_nifti1_int16.nii.gz",
    "label_nifti2_float32_qform.nii",
    "label_uint8.mgz",
    "label_lps_gzip.nrrd",
    "label_ras_detached.nhdr",
    "label_uint8.mha",
    "label_int32.mhd",
    "label_ascii.vti",
];

struct Expected {
    affine: [f64; 12],
    per_file: Vec<(String, [f64; 12])>,
    labels: Vec<u32>,
}

fn expected() -> Expected {
    let text = std::fs::read_to_string(data("label_expected.txt")).unwrap();
    let mut e = Expected {
        affine: [0.0; 12],
        per_file: Vec::new(),
        labels: Vec::new(),
    };
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let (key, rest) = line.split_once(' ').unwrap();
        let nums = || -> [f64; 12] {
            let v: Vec<f64> = rest.split(' ').map(|t| t.parse().unwrap()).collect();
            v.try_into().unwrap()
        };
        match key {
            "affine" => e.affine = nums(),
            "labels" => e.labels = rest.split(' ').map(|t| t.parse().unwrap()).collect(),
            f => e.per_file.push((f.to_string(), nums())),
        }
    }
    e
}

fn assert_affine(img: &LabelImage, a: &[f64; 12], tol: f64, what: &str) {
    for r in 0..3 {
        for c in 0..4 {
            let (x, y) = (img.voxel_to_world[r][c], a[4 * r + c]);
            assert!(
                (x - y).abs() <= tol * (1.0 + y.abs()),
                "{what}: row {r} col {c}: {x} vs {y}\n{:?}",
                img.voxel_to_world
            );
        }
    }
    assert_eq!(img.voxel_to_world[3], [0.0, 0.0, 0.0, 1.0]);
}

#[test]
fn every_format_reads_the_same_volume() {
    let e = expected();
    for f in FILES {
        let img = image::read_label_image(&data(f)).unwrap_or_else(|err| panic!("{f}: {err}"));
        assert_eq!(img.dims, [5, 4, 3], "{f}");
        assert_eq!(img.labels, e.labels, "{f}");
        // float32 headers (NIfTI-1, MGH) keep about 7 digits.
        assert_affine(&img, &e.affine, 1e-6, f);
    }
}

#[test]
fn nifti_and_mgh_match_nibabel() {
    let e = expected();
    assert_eq!(e.per_file.len(), 3);
    for (f, a) in &e.per_file {
        let img = image::read_label_image(&data(f)).unwrap();
        // nibabel computes MGH's vox2ras in float32 arithmetic, we in f64.
        let tol = if f.ends_with(".mgz") { 1e-6 } else { 1e-12 };
        assert_affine(&img, a, tol, f);
    }
}

#[test]
fn fractional_labels_are_refused() {
    let err = image::read_label_image(&data("label_fractional.nii"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("2.5") && err.contains("whole numbers"),
        "{err}"
    );
}

#[test]
fn formats_by_extension() {
    for (n, f) in [
        ("a.nii.gz", ImageFormat::Nifti),
        ("A.NII", ImageFormat::Nifti),
        ("aseg.mgz", ImageFormat::Mgh),
        ("x.nhdr", ImageFormat::Nrrd),
        ("x.mhd", ImageFormat::MetaImage),
        ("x.vti", ImageFormat::Vti),
    ] {
        assert_eq!(ImageFormat::detect(Path::new(n)), Some(f), "{n}");
    }
    assert!(!image::is_label_image(Path::new("brain.stl")));
}

fn parse(f: &str, bytes: &[u8]) -> biotet_io::Result<LabelImage> {
    let dir = data("");
    match ImageFormat::detect(Path::new(f)).unwrap() {
        ImageFormat::Nifti => image::nifti::parse(bytes, f),
        ImageFormat::Mgh => image::mgh::parse(bytes, f),
        ImageFormat::Nrrd => image::nrrd::parse(bytes, f, Some(&dir)),
        ImageFormat::MetaImage => image::metaimage::parse(bytes, f, Some(&dir)),
        ImageFormat::Vti => image::vti::parse(bytes, f),
    }
}

/// A label the written formats cannot hold (VTU's Int32): refused where it is read, naming the
/// voxel, not after meshing by the writer.
#[test]
fn labels_past_int32_are_refused() {
    let mut bytes =
        b"NRRD0004\ntype: uint32\ndimension: 3\nsizes: 2 1 1\nencoding: raw\nendian: little\n\n"
            .to_vec();
    for v in [1u32, 3_000_000_000] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let err = parse("big.nrrd", &bytes).unwrap_err().to_string();
    assert!(
        err.contains("voxel 1 holds 3000000000") && err.contains("2147483647"),
        "{err}"
    );
    let n = bytes.len();
    bytes[n - 4..].copy_from_slice(&2_147_483_647u32.to_le_bytes());
    assert_eq!(parse("big.nrrd", &bytes).unwrap().labels[1], 2_147_483_647);
}

/// Random bytes, every truncation, and random byte flips of every fixture: an error or an
/// image, never a panic (a flipped byte may still give a valid image).
#[test]
fn fuzz_readers_never_panic() {
    let mut rng = Rng(21);
    for f in FILES {
        let good = std::fs::read(data(f)).unwrap();
        for len in 0..good.len() {
            let _ = parse(f, &good[..len]);
        }
        for _ in 0..300 {
            let mut b = good.clone();
            let flips = 1 + rng.next_u64() % 4;
            for _ in 0..flips {
                let at = (rng.next_u64() % b.len() as u64) as usize;
                b[at] = rng.next_u64() as u8;
            }
            let _ = parse(f, &b);
        }
        for _ in 0..50 {
            let n = (rng.next_u64() % 2000) as usize;
            let b: Vec<u8> = (0..n).map(|_| rng.next_u64() as u8).collect();
            let _ = parse(f, &b);
            // Random bytes after the file's first line (its magic).
            let first = good
                .iter()
                .position(|&c| c == b'\n')
                .unwrap_or(4)
                .min(good.len());
            let mut m = good[..first].to_vec();
            m.extend(b);
            let _ = parse(f, &m);
        }
    }
}

/// Headers announcing huge images are refused before allocation.
#[test]
fn huge_headers_are_refused() {
    let h = b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 100000 100000 100000\nencoding: raw\n\n";
    let e = image::nrrd::parse(h, "huge.nrrd", None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("supported"), "{e}");
    let h = b"ObjectType = Image\nNDims = 3\nDimSize = 100000 100000 100000\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n";
    let e = image::metaimage::parse(h, "huge.mha", None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("supported"), "{e}");
}
