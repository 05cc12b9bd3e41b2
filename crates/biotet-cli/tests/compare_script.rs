//! Smoke test of `scripts/compare.py`, the comparison with TetGen, Gmsh, fTetWild and MMG: run on
//! a tiny sphere with the tools installed here, one repeat. Skipped where Python, numpy or meshio
//! is absent (the script's anchors need them); CI does not run the full comparison.

mod support;
use serde_json::Value;
use std::process::Command;
use support::*;

/// Whether `python3` can import numpy and meshio (the script's anchors need them); says so when
/// it cannot.
fn python_ready(test: &str) -> bool {
    let probe = Command::new("python3")
        .args(["-c", "import numpy, meshio"])
        .output();
    let ok = probe.is_ok_and(|o| o.status.success());
    if !ok {
        eprintln!("python3 with numpy and meshio not available: skipping {test}");
    }
    ok
}

/// `scripts/compare.py sphere.off ARGS --biotet <this build>` in a new directory holding an
/// icosahedron subdivided twice onto the sphere of radius 10 (320 triangles); the directory,
/// after the script succeeded.
fn compare_on_sphere(args: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let sphere = biotet::mesh::surface::SurfaceMesh::icosphere(10.0, 2);
    biotet_io::write_surface(&dir.path().join("sphere.off"), &sphere).unwrap();
    let out = Command::new("python3")
        .current_dir(dir.path())
        .arg(root().join("scripts/compare.py"))
        .arg("sphere.off")
        .args(args)
        .args(["--biotet", env!("CARGO_BIN_EXE_biotet")])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir
}

#[test]
fn compare_script_runs_every_installed_tool_on_a_small_sphere() {
    if !python_ready("the compare.py smoke test") {
        return;
    }
    let script = root().join("scripts/compare.py");
    let list = Command::new("python3")
        .arg(&script)
        .arg("--list-tools")
        .output()
        .unwrap();
    assert!(
        list.status.success(),
        "{}",
        String::from_utf8_lossy(&list.stderr)
    );
    let list: Value = serde_json::from_slice(&list.stdout).expect("--list-tools prints JSON");
    let installed: Vec<String> = list
        .as_object()
        .unwrap()
        .iter()
        .filter(|(_, why)| why.is_null())
        .map(|(k, _)| k.clone())
        .collect();
    assert!(installed.iter().any(|t| t == "biotet"), "{list}");

    let dir = compare_on_sphere(&["--repeat", "1", "--csv", "out.csv", "--markdown", "out.md"]);

    // One CSV row per installed tool.
    let csv = std::fs::read_to_string(dir.path().join("out.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let mut tools: Vec<&str> = rows.iter().map(|r| r[col("tool")]).collect();
    tools.sort_unstable();
    let mut installed: Vec<&str> = installed.iter().map(String::as_str).collect();
    installed.sort_unstable();
    assert_eq!(tools, installed, "{csv}");
    assert!(rows.iter().all(|r| r[col("surface")] == "sphere.off"));

    // biotet keeps every one of the 320 triangles and gives a valid mesh; so do the tools that
    // keep the surface, when they ran.
    let row = |tool: &str| rows.iter().find(|r| r[col("tool")] == tool);
    let b = row("biotet").unwrap();
    assert_eq!(b[col("status")], "ok", "{csv}");
    assert_eq!(b[col("missing")], "0", "{csv}");
    assert_eq!(b[col("valid")], "True", "{csv}");
    assert!(b[col("tets")].parse::<u64>().unwrap() > 0);
    let forced: u64 = b[col("forced")].parse().unwrap();
    let face_tets: u64 = b[col("face_tets")].parse().unwrap();
    // Each triangle is a face of one tet, a tet has at most three; the sphere forces nothing.
    assert!(3 * face_tets >= 320 && forced == 0, "{csv}");
    for tool in ["tetgen", "tetgen-O", "gmsh", "mmg"] {
        if let Some(r) = row(tool).filter(|r| r[col("status")] == "ok") {
            assert_eq!(r[col("missing")], "0", "{tool}: {csv}");
        }
    }
    let md = std::fs::read_to_string(dir.path().join("out.md")).unwrap();
    assert!(
        md.contains("| sphere.off | biotet mesh (defaults) |"),
        "{md}"
    );
}

#[test]
fn compare_script_tolerance_mode_measures_the_distance() {
    if !python_ready("the --tolerance smoke test") {
        return;
    }
    let dir = compare_on_sphere(&[
        "--tolerance",
        "0.5",
        "--tools",
        "biotet",
        "--json",
        "rows.json",
    ]);
    let rows: Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("rows.json")).unwrap()).unwrap();
    let b = &rows[0];
    assert_eq!(b["tool"], "biotet", "{rows}");
    assert_eq!(b["status"], "ok", "{rows}");
    // Measured by `biotet quality --distance`, independently of the stage: within D both ways.
    for key in ["h_in_out", "h_out_in"] {
        let h = b[key].as_f64().unwrap();
        assert!((0.0..=0.5).contains(&h), "{key} {h}: {rows}");
    }
    assert!(b["tets"].as_u64().unwrap() > 0);
}
