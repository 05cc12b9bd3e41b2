//! `biotet surface improve` and `biotet mesh --surface-tolerance` end to end, on a
//! latitude–longitude sphere (needles at the poles): within the tolerance both ways, better
//! angles, and a mesh that `biotet check` accepts against the improved surface.

mod support;
use std::fmt::Write as _;
use std::path::Path;
use support::*;

/// A latitude–longitude sphere as OFF text.
fn uv_sphere_off(r: f64, nu: usize, nv: usize) -> String {
    let mut p = vec![[0.0, 0.0, r]];
    for i in 1..nv {
        let th = std::f64::consts::PI * i as f64 / nv as f64;
        for j in 0..nu {
            let ph = 2.0 * std::f64::consts::PI * j as f64 / nu as f64;
            p.push([
                r * th.sin() * ph.cos(),
                r * th.sin() * ph.sin(),
                r * th.cos(),
            ]);
        }
    }
    p.push([0.0, 0.0, -r]);
    let south = p.len() - 1;
    let ring = |i: usize, j: usize| 1 + (i - 1) * nu + j % nu;
    let mut t = Vec::new();
    for j in 0..nu {
        t.push([0, ring(1, j), ring(1, j + 1)]);
        t.push([south, ring(nv - 1, j + 1), ring(nv - 1, j)]);
    }
    for i in 1..nv - 1 {
        for j in 0..nu {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j),
                ring(i + 1, j + 1),
            );
            t.push([a, c, d]);
            t.push([a, d, b]);
        }
    }
    let mut s = format!("OFF\n{} {} 0\n", p.len(), t.len());
    for q in &p {
        writeln!(s, "{} {} {}", q[0], q[1], q[2]).unwrap();
    }
    for x in &t {
        writeln!(s, "3 {} {} {}", x[0], x[1], x[2]).unwrap();
    }
    s
}

fn write_sphere(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("sphere.off");
    std::fs::write(&path, uv_sphere_off(10.0, 24, 12)).unwrap();
    path
}

#[test]
fn surface_improve_keeps_the_tolerance_and_raises_the_angles() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_sphere(dir.path());
    let out = dir.path().join("improved.ply");
    let j = json_of(&biotet(&[
        "surface",
        "improve",
        s(&input),
        "--tolerance",
        "0.3",
        "-o",
        s(&out),
        "--json",
    ]));
    let r = &j["surface"];
    for key in [
        "hausdorff_in_to_out",
        "hausdorff_out_to_in",
        "hausdorff_bound",
        "hausdorff_bound_in_to_out",
        "hausdorff_bound_out_to_in",
        "regions",
        "min_angle_in",
        "min_angle_out",
        "min_fold_in",
        "min_fold_out",
        "triangles_in",
        "triangles_out",
        "seconds",
    ] {
        assert!(!r[key].is_null(), "{key} missing: {r}");
    }
    assert!(r["hausdorff_in_to_out"].as_f64().unwrap() <= 0.3);
    assert!(r["hausdorff_out_to_in"].as_f64().unwrap() <= 0.3);
    assert!(r["min_angle_out"].as_f64().unwrap() > r["min_angle_in"].as_f64().unwrap() + 10.0);
    // The written surface is valid.
    let v = biotet(&["validate", s(&out)]);
    assert!(v.status.success(), "{}", stderr(&v));
    // A hopeless option fails clearly.
    let bad = biotet(&["surface", "improve", s(&input), "--tolerance", "-1"]);
    assert!(!bad.status.success());
    assert!(stderr(&bad).contains("tolerance"), "{}", stderr(&bad));
}

#[test]
fn mesh_with_surface_tolerance_passes_check_against_the_improved_surface() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_sphere(dir.path());
    let surf = dir.path().join("improved.ply");
    let mesh = dir.path().join("m.vtu");
    let j = json_of(&biotet(&[
        "mesh",
        s(&input),
        "--surface-tolerance",
        "0.3",
        "--surface-output",
        s(&surf),
        "-o",
        s(&mesh),
        "--json",
    ]));
    assert!(j["surface"]["hausdorff_out_to_in"].as_f64().unwrap() <= 0.3);
    assert_eq!(j["pipeline"]["missing_triangles"].as_u64(), Some(0));
    let c = biotet(&["check", "--surface", s(&surf), s(&mesh)]);
    assert!(c.status.success(), "{}", stderr(&c));
    // `quality --distance` measures the mesh's surface against the input independently of the
    // stage: it moved (the poles' needles are gone), by no more than the tolerance; against the
    // improved surface it is zero (to rounding in the closest-point arithmetic).
    let q = json_of(&biotet(&[
        "quality",
        s(&mesh),
        "--surface",
        s(&input),
        "--distance",
        "--json",
    ]));
    let d = &q["surface_distance"];
    let (io, oi) = (
        d["in_to_out"].as_f64().unwrap(),
        d["out_to_in"].as_f64().unwrap(),
    );
    assert!(io > 0.01 && io <= 0.3 && oi > 0.01 && oi <= 0.3, "{d}");
    let same = json_of(&biotet(&[
        "quality",
        s(&mesh),
        "--surface",
        s(&surf),
        "--distance",
        "--json",
    ]));
    for side in ["in_to_out", "out_to_in"] {
        assert!(
            same["surface_distance"][side].as_f64().unwrap() < 1e-9,
            "{same}"
        );
    }
    // Without the option, no surface section.
    let plain = json_of(&biotet(&["mesh", s(&input), "--json"]));
    assert!(plain.get("surface").is_none());
}

#[test]
fn surface_improve_help_has_an_example() {
    let out = biotet(&["surface", "improve", "--help"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("--tolerance") && text.contains("Examples"),
        "{text}"
    );
    let out = biotet(&["mesh", "--help"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("--surface-tolerance"));
}

/// At a quarter millimetre both brain models must stay within the bound at a pinch of the input
/// (two sheets 0.04 mm apart near (38, −66, −16)). The nested model's last repair split the
/// nearest triangle and projected its midpoint, which landed on the other side of the pinch in
/// every repair, and the run failed at 0.263; a point is now moved onto the sample. On wm_20k a
/// fold opening there passed the guards' sparse samples and left 0.266 between them; a fold move
/// now checks its fan at dense samples.
#[test]
fn the_brain_models_stay_within_a_quarter_millimetre() {
    let dir = tempfile::tempdir().unwrap();
    for model in ["nested_brain_wm_20k.stl", "wm_20k.stl"] {
        let out = dir.path().join("out.vtu");
        let input = root().join("tests/data").join(model);
        let j = json_of(&biotet(&[
            "surface",
            "improve",
            s(&input),
            "--tolerance",
            "0.25",
            "-o",
            s(&out),
            "--json",
        ]));
        let r = &j["surface"];
        assert!(
            r["hausdorff_in_to_out"].as_f64().unwrap() <= 0.25,
            "{model}: {r}"
        );
        assert!(
            r["hausdorff_out_to_in"].as_f64().unwrap() <= 0.25,
            "{model}: {r}"
        );
        let v = biotet(&["validate", s(&out)]);
        assert!(v.status.success(), "{model}: {}", stderr(&v));
    }
}
