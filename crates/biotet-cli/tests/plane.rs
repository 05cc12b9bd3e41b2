//! `biotet` on 2D inputs: PSLGs meshed, segments recovered, meshes smoothed and checked, outputs
//! in every 2D format, byte-identical across runs; bad input gets an error naming file and line.

mod support;
use serde_json::Value;
use support::*;

/// A 10 × 10 square (unit segments) with a square hole, a triangular region 2 inside and an open
/// polyline.
fn holey_poly() -> String {
    let mut pts: Vec<[f64; 2]> = Vec::new();
    let mut segs: Vec<[usize; 2]> = Vec::new();
    for k in 0..40 {
        let t = k as f64;
        pts.push(match k / 10 {
            0 => [t, 0.0],
            1 => [10.0, t - 10.0],
            2 => [30.0 - t, 10.0],
            _ => [0.0, 40.0 - t],
        });
        segs.push([k, (k + 1) % 40]);
    }
    let mut ring = |p: &[[f64; 2]], closed: bool| {
        let b = pts.len();
        pts.extend_from_slice(p);
        let n = p.len();
        for i in 0..if closed { n } else { n - 1 } {
            segs.push([b + i, b + (i + 1) % n]);
        }
    };
    ring(&[[6.0, 6.0], [8.0, 6.0], [8.0, 8.0], [6.0, 8.0]], true);
    ring(&[[1.0, 1.0], [3.0, 1.5], [2.0, 3.0]], true);
    ring(&[[6.0, 2.0], [7.0, 2.5], [8.0, 3.0]], false);
    let mut t = format!("# holey test domain\n{} 2 0 0\n", pts.len());
    for (i, p) in pts.iter().enumerate() {
        t += &format!("{} {} {}\n", i + 1, p[0], p[1]);
    }
    t += &format!("{} 0\n", segs.len());
    for (i, q) in segs.iter().enumerate() {
        t += &format!("{} {} {}\n", i + 1, q[0] + 1, q[1] + 1);
    }
    t += "1\n1 7 7\n2\n1 5 9 1\n2 2 2 2\n";
    t
}

#[test]
fn mesh_check_smooth_a_polygon_with_a_hole_and_internal_boundaries() {
    let d = tempfile::tempdir().unwrap();
    let poly = d.path().join("holey.poly");
    std::fs::write(&poly, holey_poly()).unwrap();
    let out = d.path().join("holey.mesh");
    let j = json_of(&biotet(&[
        "mesh",
        s(&poly),
        "--size",
        "0.5",
        "-o",
        s(&out),
        "--json",
    ]));
    assert_eq!(j["check"]["valid"], true, "{j}");
    let sides: Vec<Value> = j["check"]["pslg"]["sides"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["labels"].clone())
        .collect();
    assert_eq!(
        sides,
        vec![
            serde_json::json!([0, 1]),
            serde_json::json!([1, 1]),
            serde_json::json!([1, 2])
        ]
    );
    assert_eq!(
        j["check"]["pslg"]["n_found"],
        j["check"]["pslg"]["n_segments"]
    );
    // The checker agrees from the files, and the run is byte-identical.
    let c = biotet(&["check", s(&out), "--surface", s(&poly)]);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stdout));
    let again = d.path().join("again.mesh");
    assert!(
        biotet(&["mesh", s(&poly), "--size", "0.5", "-o", s(&again), "-q"])
            .status
            .success()
    );
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
    // Every 2D output format.
    for name in ["holey.vtu", "holey.msh", "holey.node"] {
        let o = d.path().join(name);
        let r = biotet(&["mesh", s(&poly), "--size", "0.5", "-o", s(&o), "-q"]);
        assert!(r.status.success(), "{name}");
        assert!(std::fs::metadata(&o).unwrap().len() > 1000, "{name}");
    }
    assert!(d.path().join("holey.ele").exists());
    let c = biotet(&[
        "check",
        s(&d.path().join("holey.node")),
        "--surface",
        s(&poly),
        "-q",
    ]);
    assert!(c.status.success());
    // Smoothing with sliding boundary keeps the mesh valid and every segment (the PSLG's points
    // are held or slide along straight boundary lines; the checker matches segments by
    // coordinates, so check without the PSLG after sliding).
    let sm = d.path().join("smooth.mesh");
    let j = json_of(&biotet(&[
        "smooth",
        s(&out),
        "--surface",
        s(&poly),
        "--boundary",
        "slide",
        "-o",
        s(&sm),
        "--json",
    ]));
    assert!(j["smooth"]["n_sliding"].as_u64().unwrap() > 0, "{j}");
    assert!(
        j["after"]["min_angle_deg"].as_f64().unwrap()
            >= j["before"]["min_angle_deg"].as_f64().unwrap()
    );
    assert!(biotet(&["check", s(&sm), "-q"]).status.success());
    let q = json_of(&biotet(&["quality", s(&sm), "--json"]));
    assert_eq!(q["min_angle_deg"], j["after"]["min_angle_deg"]);
}

/// A 2 × 1 rectangle split by the diagonal (0,0)–(2,1) as a 2D Medit mesh; the PSLG asks for the
/// other diagonal (2,0)–(0,1), which is missing.
const RECT_MESH: &str = "MeshVersionFormatted 2\nDimension 2\nVertices\n4\n0 0 0\n2 0 0\n2 1 0\n0 1 0\nTriangles\n2\n1 2 3 1\n1 3 4 1\nEnd\n";

#[test]
fn recover_makes_a_missing_segment_an_edge() {
    let d = tempfile::tempdir().unwrap();
    let m = d.path().join("rect.mesh");
    std::fs::write(&m, RECT_MESH).unwrap();
    let poly = d.path().join("rect.poly");
    std::fs::write(
        &poly,
        "4 2 0 0\n1 0 0\n2 2 0\n3 2 1\n4 0 1\n5 0\n1 1 2\n2 2 3\n3 3 4\n4 4 1\n5 2 4\n0\n",
    )
    .unwrap();
    let c = biotet(&["check", s(&m), "--surface", s(&poly), "-q"]);
    assert_eq!(c.status.code(), Some(1), "the diagonal is missing");
    let out = d.path().join("out.mesh");
    let j = json_of(&biotet(&[
        "recover",
        s(&m),
        "--surface",
        s(&poly),
        "-o",
        s(&out),
        "--json",
    ]));
    assert_eq!(j["recover"]["n_recovered"], 1, "{j}");
    assert_eq!(j["recover"]["n_present"], 4);
    let c = biotet(&["check", s(&out), "--surface", s(&poly)]);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stdout));
}

#[test]
fn bad_2d_input_names_file_and_line() {
    let d = tempfile::tempdir().unwrap();
    let poly = d.path().join("bad.poly");
    std::fs::write(
        &poly,
        "3 2 0 0\n1 0 0\n2 1 0\n3 0 1\n3 0\n1 1 2\n2 2 9\n3 3 1\n0\n",
    )
    .unwrap();
    let out = biotet(&["mesh", s(&poly)]);
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("bad.poly: line 7") && e.contains("point index 9"),
        "{e}"
    );
    // Crossing segments: the PSLG is refused, naming both.
    std::fs::write(
        &poly,
        "4 2 0 0\n1 0 0\n2 1 0\n3 1 1\n4 0 1\n6 0\n1 1 2\n2 2 3\n3 3 4\n4 4 1\n5 1 3\n6 2 4\n0\n",
    )
    .unwrap();
    let out = biotet(&["mesh", s(&poly)]);
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("segments 4 and 5 cross"), "{e}");
}
