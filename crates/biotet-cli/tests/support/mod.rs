//! Helpers shared by the CLI test binaries: run `biotet`, read its JSON, name repository files.
#![allow(dead_code)] // each test binary uses its own subset

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Run the `biotet` binary with `args`.
pub fn biotet(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_biotet"))
        .args(args)
        .output()
        .expect("the biotet binary runs")
}

/// A path as `&str` for an argument list.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// The JSON object a successful run printed.
pub fn json_of(out: &Output) -> Value {
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object on stdout")
}

/// A run's standard error.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `s` as a triangle soup: each triangle on three points of its own (as a PLY or OBJ exporter
/// that does not merge points writes it).
pub fn soup(s: &biotet::SurfaceMesh) -> biotet::SurfaceMesh {
    let mut soup = biotet::SurfaceMesh::default();
    for (t, side) in s.triangles.iter().zip(&s.sides) {
        let base = soup.points.len() as u32;
        soup.points.extend(t.map(|v| s.points[v as usize]));
        soup.triangles.push([base, base + 1, base + 2]);
        soup.sides.push(*side);
    }
    soup
}
