//! The `biotet` binary end to end: real files in, exit codes, messages and outputs checked.

mod support;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use support::*;

fn example() -> PathBuf {
    root().join("examples/brain_tetgen.node")
}

fn brain_surface() -> PathBuf {
    root().join("tests/data/brain_20k.stl")
}

#[test]
fn help_everywhere() {
    for cmd in [
        vec!["--help"],
        vec!["quality", "--help"],
        vec!["check", "--help"],
        vec!["convert", "--help"],
        vec!["validate", "--help"],
        vec!["mesh", "--help"],
        vec!["delaunay", "--help"],
    ] {
        let out = biotet(&cmd);
        assert!(out.status.success(), "{cmd:?}");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("Usage"), "{cmd:?}: {text}");
        if cmd.len() > 1 {
            assert!(
                text.contains("--quiet") && text.contains("--json"),
                "{cmd:?}: {text}"
            );
        }
    }
}

/// Every JSON key docs/commands.md documents for `biotet quality --json`.
const QUALITY_KEYS: &[&str] = &[
    "n_points",
    "n_tets",
    "n_regions",
    "volume",
    "min_dihedral_deg",
    "max_dihedral_deg",
    "min_solid_angle_sr",
    "mean_q",
    "min_q",
    "n_dihedral_lt_5",
    "n_dihedral_lt_10",
    "n_dihedral_lt_20",
    "n_dihedral_gt_160",
    "n_dihedral_gt_170",
    "n_dihedral_gt_175",
];

#[test]
fn quality_of_the_bundled_example() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("q.svg");
    let out = biotet(&["quality", s(&example()), "--json", "--svg", s(&svg)]);
    let j = json_of(&out);
    for k in QUALITY_KEYS {
        assert!(j.get(k).is_some(), "missing key {k}");
    }
    // TetGen -pq1.4Y on brain_20k: 19,903 points and 95,654 tets (see examples/README.md).
    assert_eq!(j["n_points"], 19903);
    assert_eq!(j["n_tets"], 95654);
    // The surface was kept (-Y), so the marching-cubes slivers remain: the worst dihedral angle
    // is far below 1 degree while the bulk is fine.
    let min_d = j["min_dihedral_deg"].as_f64().unwrap();
    assert!(min_d > 0.0 && min_d < 1.0, "{min_d}");
    assert!(j["mean_q"].as_f64().unwrap() > 0.5);
    // The volume equals the surface's enclosed volume, 1,659,213 mm³ (tests/data/README.md).
    let v = j["volume"].as_f64().unwrap();
    assert!((v - 1_659_213.0).abs() < 1.0, "{v}");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.starts_with("<svg") || text.starts_with("<?xml"),
        "{}",
        &text[..100]
    );
    assert!(text.contains("</svg>"));
}

#[test]
fn quality_with_the_surface_splits_by_placement_and_counts_forced_tets() {
    let plain = json_of(&biotet(&["quality", s(&example()), "--json"]));
    let j = json_of(&biotet(&[
        "quality",
        s(&example()),
        "--surface",
        s(&brain_surface()),
        "--json",
    ]));
    // The report itself is unchanged; the split is added beside it.
    for k in QUALITY_KEYS {
        assert_eq!(j[k], plain[k], "{k}");
    }
    let place = &j["placement"];
    let count = |class: &str, key: &str| place[class][key].as_u64().unwrap();
    let classes = ["face", "vertex", "interior"];
    // Every tet is in one class, and each class's poor tets add up to the whole mesh's.
    for (key, total) in [
        ("n_tets", "n_tets"),
        ("n_dihedral_lt_5", "n_dihedral_lt_5"),
        ("n_dihedral_lt_10", "n_dihedral_lt_10"),
        ("n_dihedral_lt_20", "n_dihedral_lt_20"),
    ] {
        let sum: u64 = classes.iter().map(|c| count(c, key)).sum();
        assert_eq!(sum, j[total].as_u64().unwrap(), "{key}");
    }
    // TetGen -Y keeps all 19,648 input triangles as faces, each of one tet (the closed surface
    // bounds one side), a tet holding at most three of them.
    let face = count("face", "n_tets");
    assert!(face <= 19648 && 3 * face >= 19648, "{face}");
    // The marching-cubes triangles force poor tets, all of them on the surface.
    let forced = j["n_forced"].as_u64().unwrap();
    assert!(forced > 1000, "{forced}");
    assert_eq!(
        forced,
        classes.iter().map(|c| count(c, "n_forced")).sum::<u64>()
    );
    assert_eq!(count("interior", "n_forced"), 0);
    assert_eq!(j["forcing"]["n_forced"], j["n_forced"]);
    let unforced = j["n_unforced_dihedral_lt_10"].as_u64().unwrap();
    let lt10 = j["n_dihedral_lt_10"].as_u64().unwrap();
    assert!(unforced > 0 && unforced < lt10, "{unforced} of {lt10}");
    // The smallest dihedral angle of the mesh is the smallest of the classes'.
    let min_of = |c: &str| place[c]["min_dihedral_deg"].as_f64().unwrap();
    let m = classes
        .iter()
        .map(|c| min_of(c))
        .fold(f64::INFINITY, f64::min);
    assert_eq!(m, j["min_dihedral_deg"].as_f64().unwrap());
    // The text report says the same.
    let text = biotet(&["quality", s(&example()), "-s", s(&brain_surface())]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("by placement") && text.contains(&format!("{forced} tets")),
        "{text}"
    );
}

#[test]
fn the_bundled_example_passes_the_checker_with_its_surface() {
    let out = biotet(&[
        "check",
        s(&example()),
        "--surface",
        s(&brain_surface()),
        "--json",
    ]);
    let j = json_of(&out);
    assert_eq!(j["valid"], true);
    assert_eq!(j["surface"]["n_triangles"], 19648);
    assert_eq!(j["surface"]["n_found"], 19648);
}

#[test]
fn convert_round_trips_through_every_tet_format_byte_identically() {
    let dir = tempfile::tempdir().unwrap();
    let mut prev = example();
    for ext in ["vtu", "mesh", "msh", "ele", "vtu"] {
        let out_path = dir.path().join(format!("m_{ext}.{ext}"));
        let out = biotet(&["convert", s(&prev), "-o", s(&out_path), "--quiet"]);
        assert!(out.status.success(), "{ext}: {}", stderr(&out));
        assert!(out.stdout.is_empty(), "--quiet prints nothing");
        // Same input, same options: the same bytes.
        let again = dir.path().join(format!("again.{ext}"));
        let out = biotet(&["convert", s(&prev), "-o", s(&again), "--quiet"]);
        assert!(out.status.success());
        if ext != "ele" {
            assert_eq!(
                std::fs::read(&out_path).unwrap(),
                std::fs::read(&again).unwrap()
            );
        }
        let j = json_of(&biotet(&[
            "check",
            s(&out_path),
            "--surface",
            s(&brain_surface()),
            "--json",
        ]));
        assert_eq!(j["valid"], true, "{ext}");
        assert_eq!(j["n_tets"], 95654, "{ext}");
        prev = out_path;
    }
}

/// A unit cube as OFF text: 8 corners, 12 outward triangles; `edit` may change it.
fn cube_off(edit: impl FnOnce(&mut Vec<[usize; 3]>, &mut Vec<[f64; 3]>)) -> String {
    let mut pts: Vec<[f64; 3]> = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    let mut tris = vec![
        [0, 2, 3],
        [0, 3, 1],
        [4, 5, 7],
        [4, 7, 6],
        [0, 1, 5],
        [0, 5, 4],
        [2, 6, 7],
        [2, 7, 3],
        [0, 4, 6],
        [0, 6, 2],
        [1, 3, 7],
        [1, 7, 5],
    ];
    edit(&mut tris, &mut pts);
    let mut s = format!("OFF\n{} {} 0\n", pts.len(), tris.len());
    for p in &pts {
        s += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for t in &tris {
        s += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
    }
    s
}

fn validate_text(name: &str, text: &str) -> (Output, PathBuf, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join(name);
    std::fs::write(&p, text).unwrap();
    (biotet(&["validate", s(&p)]), p, dir)
}

#[test]
fn good_cube_validates() {
    let (out, _, _d) = validate_text("cube.off", &cube_off(|_, _| {}));
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn bad_surfaces_get_a_clear_error() {
    let hole = cube_off(|t, _| {
        t.pop();
    });
    // A second cube poking through the first one's face x = 1.
    let crossing = cube_off(|t, p| {
        let o = p.len();
        for i in 0..8 {
            let q = [
                0.5 + (i & 1) as f64,
                0.25 + 0.5 * ((i >> 1) & 1) as f64,
                0.25 + 0.5 * ((i >> 2) & 1) as f64,
            ];
            p.push(q);
        }
        let first: Vec<[usize; 3]> = t.clone();
        t.extend(first.iter().map(|f| f.map(|v| v + o)));
    });
    // (Two cubes sharing only an edge are valid: two regions, see
    // shells_touching_along_an_edge_or_at_a_vertex_are_two_regions; a triangle turned against
    // its neighbours is turned back, see inward_surface_is_flipped_and_the_user_told.)
    for (name, text, words) in [
        ("hole.off", hole, &["hole.off", "closed"][..]),
        ("crossing.off", crossing, &["crossing.off", "intersect"][..]),
    ] {
        let (out, _, _d) = validate_text(name, &text);
        assert_eq!(out.status.code(), Some(1), "{name} must be refused");
        let msg = stderr(&out);
        for w in words {
            assert!(
                msg.to_lowercase().contains(&w.to_lowercase()),
                "{name}: {msg}"
            );
        }
        assert!(!msg.contains("panicked"), "{msg}");
        // The message names a triangle with coordinates.
        assert!(
            msg.contains("triangle") && msg.contains('('),
            "{name}: {msg}"
        );
    }
}

#[test]
fn inward_surface_is_flipped_and_the_user_told() {
    let inward = cube_off(|t, _| {
        for f in t.iter_mut() {
            f.swap(1, 2);
        }
    });
    let (out, _, _d) = validate_text("inward.off", &inward);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("flipped"), "{}", stderr(&out));
    // One triangle, then half of them, turned against their neighbours (the orientation means
    // nothing before the nesting gives the regions): the minority turned back, the user told,
    // and the cube meshes with every triangle kept.
    for (name, turned, n) in [
        ("one.off", &[3usize][..], 1),
        ("half.off", &[0, 2, 4, 6, 8, 10], 6),
    ] {
        let text = cube_off(|t, _| {
            for &k in turned {
                t[k].swap(1, 2);
            }
        });
        let (out, p, d) = validate_text(name, &text);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        let want = format!("{n} of the 12 triangles of shell 0 were turned");
        assert!(stderr(&out).contains(&want), "{name}: {}", stderr(&out));
        let j = json_of(&biotet(&["validate", s(&p), "--json"]));
        assert_eq!(
            j["surfaces"][0]["shells"][0]["reoriented"], n,
            "{name}: {j}"
        );
        let o = d.path().join("out.vtu");
        let m = biotet(&["mesh", s(&p), "-o", s(&o), "-q"]);
        assert!(m.status.success(), "{name}: {}", stderr(&m));
        let c = biotet(&["check", s(&o), "--surface", s(&p), "-q"]);
        assert!(c.status.success(), "{name}: {}", stderr(&c));
    }
}

#[test]
fn missing_and_garbage_inputs_fail_cleanly_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("out.vtu");
    let missing = dir.path().join("nope.mesh");
    let garbage = dir.path().join("garbage.msh");
    std::fs::write(
        &garbage,
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1",
    )
    .unwrap();
    for input in [&missing, &garbage] {
        let out = biotet(&["convert", s(input), "-o", s(&out_path)]);
        // 2: the command could not run (1 is kept for "read and judged invalid").
        assert_eq!(out.status.code(), Some(2));
        let msg = stderr(&out);
        assert!(msg.starts_with("error: "), "{msg}");
        assert!(
            msg.contains(input.file_name().unwrap().to_str().unwrap()),
            "{msg}"
        );
        assert!(!msg.contains("panicked"), "{msg}");
        assert!(!out_path.exists());
    }
    // Nothing but the input is left in the folder: no temporary files either.
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1);
}

#[test]
fn check_fails_when_a_surface_triangle_is_missing() {
    // The example checked against the white-matter surface, which it does not contain.
    let out = biotet(&[
        "check",
        s(&example()),
        "--surface",
        s(&root().join("tests/data/wm_20k.stl")),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stdout).contains("INVALID"));
}

/// A file of triangles and no tets (a surface; a 2D mesh written as .vtu, which is written only)
/// is refused by name, not reported as an invalid mesh of no tets. Found by the docs test:
/// `biotet check holey_s.vtu` said "INVALID: 1901 points, 0 tets".
#[test]
fn check_refuses_a_file_of_triangles_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let smoothed = dir.path().join("holey_s.vtu");
    let poly = root().join("examples/plane/holey.poly");
    let mesh = dir.path().join("holey.mesh");
    assert!(
        biotet(&["mesh", s(&poly), "-o", s(&mesh), "-q"])
            .status
            .success()
    );
    let out = biotet(&[
        "smooth",
        s(&mesh),
        "--surface",
        s(&poly),
        "-o",
        s(&smoothed),
        "-q",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    for file in [smoothed, root().join("tests/data/shapes/tm_box.off")] {
        let out = biotet(&["check", s(&file)]);
        assert_eq!(out.status.code(), Some(2), "{}", file.display());
        let e = stderr(&out);
        assert_eq!(e.trim_end().lines().count(), 1, "{e}");
        assert!(e.contains(s(&file)) && e.contains("no tets"), "{e}");
    }
    // The 2D mesh as .mesh is checked as a 2D mesh.
    assert!(
        biotet(&["check", s(&mesh), "--surface", s(&poly)])
            .status
            .success()
    );
}

#[test]
fn json_errors_are_json_too() {
    let out = biotet(&["quality", "/nonexistent/m.vtu", "--json"]);
    assert_eq!(out.status.code(), Some(2));
    let j: Value = serde_json::from_slice(&out.stdout).expect("a JSON error object");
    assert!(j["error"].as_str().unwrap().contains("m.vtu"));
}

#[test]
fn a_closed_pipe_ends_quietly() {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_biotet"))
        .args(["quality", s(&example())])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read one byte and hang up, like `| head -c 1`.
    let mut first = [0u8; 1];
    child
        .stdout
        .as_mut()
        .unwrap()
        .read_exact(&mut first)
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn inverted_tets_in_a_file_reach_the_checker_and_the_report() {
    // Two tets over the triangle (0,1,2): apexes on opposite sides is a valid mesh; moving the
    // second apex to the same side as the first folds it (one tet inverted, overlapping).
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, apex: f64| {
        let p = dir.path().join(name);
        let text = format!(
            "MeshVersionFormatted 2\nDimension 3\nVertices\n5\n0 0 0 1\n1 0 0 1\n0 1 0 1\n\
             0 0 1 1\n0.2 0.2 {apex} 1\nTetrahedra\n2\n1 2 3 4 1\n1 3 2 5 1\nEnd\n"
        );
        std::fs::write(&p, text).unwrap();
        p
    };
    let good = write("good.mesh", -1.0);
    let folded = write("folded.mesh", 0.5);
    let j = json_of(&biotet(&["check", s(&good), "--json"]));
    assert_eq!(j["valid"], true);
    let out = biotet(&["check", s(&folded), "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let j: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["valid"], false);
    assert_eq!(j["n_nonpositive"], 1);
    let q = json_of(&biotet(&["quality", s(&folded), "--json"]));
    assert_eq!(q["n_inverted"], 1);
}

#[test]
fn quality_figures_of_a_cube_in_six_tets_through_the_cli() {
    // The Kuhn split of the unit cube: each tet has dihedral angles 45, 45, 60, 90, 90, 90
    // degrees, volume 1/6, edge lengths 1, 1, 1, sqrt2, sqrt2, sqrt3 so that
    // q = 12 (3/6)^(2/3) / 10 = 0.755953 (worked out in crates/biotet/tests/all/quality.rs).
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("cube.mesh");
    let mut text = String::from("MeshVersionFormatted 2\nDimension 3\nVertices\n8\n");
    for i in 0..8 {
        text += &format!("{} {} {} 0\n", i & 1, (i >> 1) & 1, (i >> 2) & 1);
    }
    text += "Tetrahedra\n6\n";
    // Axis orders; the odd permutations (xzy, yxz, zyx) get two vertices swapped so that every
    // tet is positively oriented.
    for (a, b, odd) in [
        (1, 2, false),
        (1, 4, true),
        (2, 1, true),
        (2, 4, false),
        (4, 1, false),
        (4, 2, true),
    ] {
        let (u, v) = (a + 1, a + b + 1);
        let (u, v) = if odd { (v, u) } else { (u, v) };
        text += &format!("1 {u} {v} 8 1\n");
    }
    text += "End\n";
    std::fs::write(&p, text).unwrap();
    let j = json_of(&biotet(&["quality", s(&p), "--json"]));
    assert_eq!(j["n_tets"], 6);
    let close = |k: &str, v: f64| {
        let got = j[k].as_f64().unwrap();
        assert!((got - v).abs() < 1e-9, "{k}: {got} vs {v}");
    };
    close("volume", 1.0);
    close("min_dihedral_deg", 45.0);
    close("max_dihedral_deg", 90.0);
    close("min_q", 0.755_952_629_936_923_9);
    close("mean_q", 0.755_952_629_936_923_9);
    close("min_solid_angle_sr", std::f64::consts::PI / 12.0);
    assert_eq!(j["n_dihedral_lt_20"], 0);
    assert_eq!(j["n_dihedral_gt_160"], 0);
}

#[test]
fn delaunay_of_a_lattice_is_valid_deterministic_and_reported() {
    // A 12×12×12 integer lattice: massively cospherical, decided by the symbolic perturbation.
    let dir = tempfile::tempdir().unwrap();
    let pts = dir.path().join("lattice.xyz");
    let mut text = String::from("# 12^3 lattice\n");
    for i in 0..12 {
        for j in 0..12 {
            for k in 0..12 {
                text += &format!("{i} {j} {k}\n");
            }
        }
    }
    std::fs::write(&pts, text).unwrap();
    let a = dir.path().join("a.vtu");
    let b = dir.path().join("b.vtu");
    let j = json_of(&biotet(&["delaunay", s(&pts), "-o", s(&a), "--json"]));
    for k in ["n_points", "n_tets", "seconds", "points_per_second"] {
        assert!(j.get(k).is_some(), "missing {k}");
    }
    assert_eq!(j["n_points"], 1728);
    assert!(j["seconds"].as_f64().unwrap() >= 0.0);
    let out = biotet(&["delaunay", s(&pts), "-o", s(&b), "--quiet"]);
    assert!(out.status.success());
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let c = json_of(&biotet(&["check", s(&a), "--json"]));
    assert_eq!(c["valid"], true);
    assert_eq!(c["n_points"], 1728);
    assert_eq!(c["n_tets"], j["n_tets"]);
    // The lattice's hull is the cube [0, 11]^3: volume 1331 (a float sum of 6655 tets).
    let q = json_of(&biotet(&["quality", s(&a), "--json"]));
    assert!((q["volume"].as_f64().unwrap() - 1331.0).abs() < 1e-6);
}

#[test]
fn delaunay_refuses_bad_point_files() {
    let dir = tempfile::tempdir().unwrap();
    for (name, text, words) in [
        ("short.xyz", "0 0 0\n1 0\n", &["short.xyz", "line 2"][..]),
        (
            "flat.xyz",
            "0 0 0\n1 0 0\n0 1 0\n1 1 0\n",
            &["flat.xyz", "coplanar"][..],
        ),
        (
            "nan.xyz",
            "0 0 0\n1 nan 0\n",
            &["nan.xyz", "non-finite"][..],
        ),
    ] {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        let out = biotet(&["delaunay", s(&p), "-o", s(&dir.path().join("o.vtu"))]);
        assert_eq!(out.status.code(), Some(2), "{name}");
        let msg = stderr(&out);
        for w in words {
            assert!(msg.contains(w), "{name}: {msg}");
        }
        assert!(!dir.path().join("o.vtu").exists());
    }
}

#[test]
fn mesh_the_bundled_example_and_report() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("brain.vtu");
    let j = json_of(&biotet(&["mesh", "-o", s(&out), "--json"]));
    let p = &j["pipeline"];
    assert!(p["n_tets"].as_u64().unwrap() > 50_000, "{p}");
    assert!(p["n_interior_nodes"].as_u64().unwrap() > 1_000, "{p}");
    assert_eq!(p["n_surface_points"], 9770);
    let t = &p["template"];
    assert_eq!(
        t["voxels"].as_u64(),
        Some(
            t["dims"]
                .as_array()
                .unwrap()
                .iter()
                .map(|d| d.as_u64().unwrap())
                .product()
        )
    );
    assert_eq!(t["bytes"].as_u64(), t["voxels"].as_u64().map(|v| 2 * v));
    assert!(p["missing_triangles"].is_u64());
    for k in ["deploy", "delaunay", "keep inside"] {
        assert!(
            p["stages"]
                .as_array()
                .unwrap()
                .iter()
                .any(|s| s["name"] == k),
            "{k}"
        );
    }
    assert_eq!(j["quality"]["n_tets"], p["n_tets"]);
    assert_eq!(j["quality"]["n_inverted"], 0);
    // The written mesh is valid (positive tets, conforming faces, adjacency, labels).
    let c = biotet(&["check", s(&out), "--json"]);
    let cj: Value = serde_json::from_slice(&c.stdout).unwrap();
    assert_eq!(cj["n_nonpositive"], 0, "{cj}");
    assert_eq!(cj["n_overshared_faces"], 0, "{cj}");
    assert_eq!(cj["n_adjacency_errors"], 0, "{cj}");
    // Same input and options, byte-identical output.
    let again = dir.path().join("again.vtu");
    let out2 = biotet(&["mesh", "-o", s(&again), "--quiet"]);
    assert!(out2.status.success());
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
}

#[test]
fn mesh_sizing_options() {
    let dir = tempfile::tempdir().unwrap();
    let brain = brain_surface();
    // Sizing only: the later stages have tests of their own.
    let n_tets = |args: &[&str]| {
        let mut a = vec![
            "mesh",
            s(&brain),
            "--json",
            "--no-recover",
            "--no-improve",
            "--no-smooth",
        ];
        a.extend_from_slice(args);
        json_of(&biotet(&a))["pipeline"]["n_tets"].as_u64().unwrap()
    };
    // Finer uniform sizes give more tets, about (4/3)^3 ≈ 2.4 times as many.
    let coarse = n_tets(&["--size", "4"]);
    let fine = n_tets(&["--size", "3"]);
    assert!(
        fine as f64 > 1.8 * coarse as f64 && (fine as f64) < 3.0 * coarse as f64,
        "{coarse} {fine}"
    );
    // A size field: 2 at the front half (y > 0), 4 behind, on a .vti grid.
    let (nx, ny, nz, o, sp) = (8, 10, 8, [-80.0, -115.0, -80.0], 25.0);
    let mut vals = Vec::new();
    for _k in 0..nz {
        for j in 0..ny {
            for _i in 0..nx {
                let y = o[1] + j as f64 * sp;
                vals.push(if y > 0.0 { "2" } else { "4" });
            }
        }
    }
    let vti = dir.path().join("size.vti");
    std::fs::write(
        &vti,
        format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n\
             <ImageData WholeExtent=\"0 {} 0 {} 0 {}\" Origin=\"{} {} {}\" Spacing=\"{sp} {sp} {sp}\">\n\
             <Piece Extent=\"0 {} 0 {} 0 {}\"><PointData Scalars=\"size\">\
             <DataArray type=\"Float64\" Name=\"size\" format=\"ascii\">{}</DataArray>\
             </PointData></Piece></ImageData></VTKFile>\n",
            nx - 1, ny - 1, nz - 1, o[0], o[1], o[2], nx - 1, ny - 1, nz - 1, vals.join(" ")
        ),
    )
    .unwrap();
    let field = n_tets(&["--size-field", s(&vti)]);
    assert!(
        field > coarse && field < n_tets(&["--size", "2"]),
        "{field}"
    );
    // Bad options are refused with the reason.
    for (args, needle) in [
        (vec!["--size", "0"], "size must be a positive"),
        (
            vec!["--size", "2", "--size-from-surface"],
            "cannot be used with",
        ),
        (vec!["--region-size", "x"], "LABEL=H"),
        (vec!["--size", "1e-4"], "voxels"),
        (vec!["--size-field", "/nonexistent/size.vti"], "size.vti"),
    ] {
        let mut a = vec!["mesh", s(&brain)];
        a.extend_from_slice(&args);
        let out = biotet(&a);
        assert!(!out.status.success(), "{args:?}");
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
    }
}

// ------------------------------------------------------------------------------------------------
// biotet smooth
// ------------------------------------------------------------------------------------------------

#[test]
fn smooth_fixed_keeps_the_surface_and_raises_the_low_end() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("smooth.vtu");
    let svg = dir.path().join("smooth.svg");
    let run = biotet(&[
        "smooth",
        s(&example()),
        "-o",
        s(&out),
        "--svg",
        s(&svg),
        "--json",
    ]);
    let j = json_of(&run);
    assert_eq!(j["boundary"], "fixed");
    assert_eq!(j["max_surface_distance"], 0.0);
    assert!(j["sweeps"].as_u64().unwrap() >= 1);
    assert!(j["nodes_moved"].as_u64().unwrap() > 1000);
    assert!(j["seconds_per_sweep"].as_f64().unwrap() > 0.0);
    let (qb, qa) = (&j["quality_before"], &j["quality_after"]);
    assert!(
        qa["min_solid_angle_sr"].as_f64().unwrap() >= qb["min_solid_angle_sr"].as_f64().unwrap()
    );
    assert!(qa["n_dihedral_lt_10"].as_u64().unwrap() < qb["n_dihedral_lt_10"].as_u64().unwrap());
    assert_eq!(qa["n_tets"], qb["n_tets"]);
    let share = &j["share_solid_below_0_2_sr"];
    assert!(share["after"].as_f64().unwrap() < share["before"].as_f64().unwrap());
    // The output is valid and still holds every input triangle exactly.
    let check = biotet(&["check", s(&out), "-s", s(&brain_surface()), "--quiet"]);
    assert!(check.status.success(), "{}", stderr(&check));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("<svg") && text.contains("before") && text.contains("after"));
    assert!(text.contains("0.2 sr"));
}

#[test]
fn smooth_slide_stays_on_the_surface_and_is_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.vtu"), dir.path().join("b.vtu"));
    for out in [&a, &b] {
        let run = biotet(&[
            "smooth",
            s(&example()),
            "--boundary",
            "slide",
            "--surface",
            s(&brain_surface()),
            "--max-sweeps",
            "2",
            "-o",
            s(out),
            "--json",
        ]);
        let j = json_of(&run);
        assert_eq!(j["boundary"], "slide");
        assert!(j["sweeps"].as_u64().unwrap() <= 2);
        let d = j["max_surface_distance"].as_f64().unwrap();
        assert!(d < 1e-12, "{d}");
        assert!(j["smooth"]["n_sliding_nodes"].as_u64().unwrap() > 1000);
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let check = biotet(&["check", s(&a), "--quiet"]);
    assert!(check.status.success(), "{}", stderr(&check));
}

#[test]
fn smooth_errors_name_the_file_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.vtu");
    let missing = dir.path().join("missing.vtu");
    let run = biotet(&["smooth", s(&missing), "-o", s(&out)]);
    assert_eq!(run.status.code(), Some(2));
    assert!(stderr(&run).contains("missing.vtu"), "{}", stderr(&run));
    assert!(!out.exists());
    let run = biotet(&[
        "smooth",
        s(&example()),
        "--feature-angle",
        "400",
        "-o",
        s(&out),
    ]);
    assert_eq!(run.status.code(), Some(2));
    assert!(stderr(&run).contains("--feature-angle"), "{}", stderr(&run));
    assert!(!out.exists());
    let help = biotet(&["smooth", "--help"]);
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(help.status.success() && text.contains("--boundary") && text.contains("--json"));
}

#[test]
fn recover_then_improve_a_mesh_made_without_them() {
    let dir = tempfile::tempdir().unwrap();
    let brain = brain_surface();
    let raw = dir.path().join("raw.vtu");
    let out = biotet(&[
        "mesh",
        s(&brain),
        "-o",
        s(&raw),
        "--no-recover",
        "--no-improve",
        "--no-smooth",
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    // Without recovery some triangles are missing: the checker says so.
    let c = biotet(&["check", s(&raw), "--surface", s(&brain), "--quiet"]);
    assert_eq!(c.status.code(), Some(1));
    let rec = dir.path().join("rec.vtu");
    let j = json_of(&biotet(&[
        "recover",
        s(&raw),
        "-s",
        s(&brain),
        "-o",
        s(&rec),
        "--json",
    ]));
    assert_eq!(j["complete"], true, "{j}");
    assert!(j["recover"]["missing_before"].as_u64().unwrap() > 100);
    assert_eq!(j["recover"]["missing_after"], 0);
    assert_eq!(j["recover"]["steiner_points"], 0);
    let c = biotet(&["check", s(&rec), "--surface", s(&brain), "--json"]);
    let cj: Value = serde_json::from_slice(&c.stdout).unwrap();
    assert_eq!(cj["valid"], true, "{cj}");
    let v = |path: &Path| {
        json_of(&biotet(&["quality", s(path), "--json"]))["volume"]
            .as_f64()
            .unwrap()
    };
    assert!((v(&rec) - 1_659_213.0).abs() < 1.0, "{}", v(&rec));
    // Sliver removal: fewer tets under 10°, the surface and the volume unchanged.
    let imp = dir.path().join("imp.vtu");
    let j = json_of(&biotet(&[
        "improve",
        s(&rec),
        "-s",
        s(&brain),
        "-o",
        s(&imp),
        "--json",
    ]));
    let (b, a) = (&j["slivers_before"]["lt_10"], &j["slivers_after"]["lt_10"]);
    assert!(a.as_u64().unwrap() * 2 < b.as_u64().unwrap(), "{b} → {a}");
    assert!(
        j["n_unforced_dihedral_lt_10"].as_u64().unwrap()
            < j["forcing_before"]["n_unforced_dihedral_lt_10"]
                .as_u64()
                .unwrap()
    );
    let c = biotet(&["check", s(&imp), "--surface", s(&brain), "--json"]);
    let cj: Value = serde_json::from_slice(&c.stdout).unwrap();
    assert_eq!(cj["valid"], true, "{cj}");
    assert!((v(&imp) - v(&rec)).abs() < 1e-6 * v(&rec));
    let q = json_of(&biotet(&["quality", s(&imp), "--json"]));
    assert_eq!(
        q["n_points"],
        json_of(&biotet(&["quality", s(&rec), "--json"]))["n_points"]
    );
}

#[test]
fn two_materials_check_and_open_in_meshio_with_their_labels() {
    let dir = tempfile::tempdir().unwrap();
    // A cube of side 4 around a cube of side 2: region 1 between them, region 2 inside.
    let scaled = |k: f64, o: f64| {
        cube_off(|_, pts| {
            for p in pts.iter_mut() {
                *p = p.map(|c| c * k + o);
            }
        })
    };
    let outer = dir.path().join("outer.off");
    let inner = dir.path().join("inner.off");
    std::fs::write(&outer, scaled(4.0, 0.0)).unwrap();
    std::fs::write(&inner, scaled(2.0, 1.0)).unwrap();
    let outs: Vec<PathBuf> = ["m.vtu", "m.mesh", "m.msh"]
        .iter()
        .map(|n| dir.path().join(n))
        .collect();
    let j = json_of(&biotet(&[
        "mesh",
        s(&outer),
        s(&inner),
        "--size",
        "0.7",
        "-o",
        s(&outs[0]),
        "--json",
    ]));
    let regions = j["quality"]["regions"].as_array().unwrap().clone();
    assert_eq!(regions.len(), 2);
    let v = |l: u64| {
        regions.iter().find(|r| r["label"] == l).unwrap()["volume"]
            .as_f64()
            .unwrap()
    };
    assert!(
        (v(1) - 56.0).abs() < 1e-9 && (v(2) - 8.0).abs() < 1e-9,
        "{regions:?}"
    );
    let c = biotet(&[
        "check",
        s(&outs[0]),
        "-s",
        s(&outer),
        "-s",
        s(&inner),
        "--json",
    ]);
    let cj: Value = serde_json::from_slice(&c.stdout).unwrap();
    assert_eq!(cj["valid"], true, "{cj}");
    for o in &outs[1..] {
        let out = biotet(&["convert", s(&outs[0]), "-o", s(o)]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    // meshio reads each with its labels (skipped where Python or meshio is absent).
    let probe = Command::new("python3")
        .args(["-c", "import meshio"])
        .output();
    if !probe.is_ok_and(|o| o.status.success()) {
        eprintln!("meshio not available: skipping the meshio part");
        return;
    }
    let script = r#"
import sys, meshio, numpy as np
m = meshio.read(sys.argv[1])
labels = set()
for name, data in m.cell_data.items():
    for block, cells in zip(data, m.cells):
        if cells.type == "tetra":
            labels |= set(int(x) for x in np.unique(block))
print(sorted(labels))
"#;
    for o in &outs {
        let r = Command::new("python3")
            .args(["-c", script, s(o)])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&r.stdout);
        assert!(
            r.status.success(),
            "{}: {}",
            o.display(),
            String::from_utf8_lossy(&r.stderr)
        );
        assert!(
            text.contains("1") && text.contains("2"),
            "{}: labels {text}",
            o.display()
        );
    }
}

/// Two unit cubes touching along x = 1 (regions 2 and 3) inside the box [-1, 3] x [-1, 2]²
/// (region 1), as one non-manifold surface with the labels of both sides of every triangle:
/// ASCII PLY with `label_back` and `label_front`. The shared square's edges are triple lines.
fn three_regions_ply() -> String {
    let mut pts: Vec<[f64; 3]> = Vec::new();
    let mut tris: Vec<([usize; 3], [u32; 2])> = Vec::new();
    let mut add_box = |lo: [f64; 3], hi: [f64; 3], sides: [u32; 2]| {
        for d in 0..3 {
            let (u, v) = ((d + 1) % 3, (d + 2) % 3);
            for (at, outward) in [(lo[d], false), (hi[d], true)] {
                let corner = |a: f64, b: f64| {
                    let mut p = [0.0; 3];
                    (p[d], p[u], p[v]) = (at, a, b);
                    p
                };
                let mut q = [
                    corner(lo[u], lo[v]),
                    corner(hi[u], lo[v]),
                    corner(hi[u], hi[v]),
                    corner(lo[u], hi[v]),
                ];
                if !outward {
                    q.reverse();
                }
                // Split along the diagonal through the smallest corner, so touching boxes agree.
                let k = (0..4)
                    .min_by(|&i, &j| q[i].partial_cmp(&q[j]).unwrap())
                    .unwrap();
                let id: Vec<usize> = (0..4)
                    .map(|i| {
                        let p = q[(k + i) % 4];
                        pts.iter().position(|x| *x == p).unwrap_or_else(|| {
                            pts.push(p);
                            pts.len() - 1
                        })
                    })
                    .collect();
                for t in [[id[0], id[1], id[2]], [id[0], id[2], id[3]]] {
                    let mut key = t;
                    key.sort_unstable();
                    let shared = tris.iter().position(|(x, _)| {
                        let mut k2 = *x;
                        k2.sort_unstable();
                        k2 == key
                    });
                    match shared {
                        // Given by the other cube: its front is this cube.
                        Some(i) => tris[i].1[1] = sides[0],
                        None => tris.push((t, sides)),
                    }
                }
            }
        }
    };
    add_box([0.0; 3], [1.0; 3], [2, 1]);
    add_box([1.0, 0.0, 0.0], [2.0, 1.0, 1.0], [3, 1]);
    add_box([-1.0; 3], [3.0, 2.0, 2.0], [1, 0]);
    let mut out = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nelement face {}\nproperty list uchar int vertex_indices\n\
         property int label_back\nproperty int label_front\nend_header\n",
        pts.len(),
        tris.len()
    );
    for p in &pts {
        out += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for (t, l) in &tris {
        out += &format!("3 {} {} {} {} {}\n", t[0], t[1], t[2], l[0], l[1]);
    }
    out
}

#[test]
fn a_labelled_non_manifold_surface_meshes_from_ply_vtu_and_medit() {
    let dir = tempfile::tempdir().unwrap();
    let ply = dir.path().join("three.ply");
    std::fs::write(&ply, three_regions_ply()).unwrap();
    // The same labelled surface as VTU (`sides`) and Medit (refs, interfaces twice).
    let vtu = dir.path().join("three.vtu");
    let medit = dir.path().join("three.mesh");
    for o in [&vtu, &medit] {
        let out = biotet(&["convert", s(&ply), "-o", s(o)]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let v = biotet(&["validate", s(&vtu), "--json"]);
    assert!(v.status.success(), "{}", stderr(&v));
    let mut tet_counts = Vec::new();
    for input in [&ply, &vtu, &medit] {
        let out = dir.path().join("m.vtu");
        let j = json_of(&biotet(&[
            "mesh",
            s(input),
            "--size",
            "0.5",
            "-o",
            s(&out),
            "--json",
        ]));
        assert_eq!(j["pipeline"]["missing_triangles"], 0, "{j}");
        let regions = j["quality"]["regions"].as_array().unwrap();
        let vol = |l: u64| {
            regions.iter().find(|r| r["label"] == l).unwrap()["volume"]
                .as_f64()
                .unwrap()
        };
        // Each region's volume is what its surface encloses.
        for (l, want) in [(1, 36.0 - 2.0), (2, 1.0), (3, 1.0)] {
            assert!((vol(l) - want).abs() < 1e-9 * 36.0, "{}: {regions:?}", l);
        }
        // Every interface triangle is a face between its two labels.
        let c = json_of(&biotet(&["check", s(&out), "-s", s(input), "--json"]));
        assert_eq!(c["valid"], true, "{c}");
        let interfaces = c["surface"]["interfaces"].as_array().unwrap();
        assert_eq!(interfaces.len(), 4, "{interfaces:?}"); // [0,1] [1,2] [1,3] [2,3]
        for i in interfaces {
            assert_eq!(i["found"], i["expected"], "{i}");
        }
        let i23 = interfaces
            .iter()
            .find(|i| i["labels"] == serde_json::json!([2, 3]));
        assert_eq!(i23.unwrap()["expected"], 2);
        for g in c["regions"].as_array().unwrap() {
            let (v, e) = (
                g["volume"].as_f64().unwrap(),
                g["enclosed_volume"].as_f64().unwrap(),
            );
            assert!((v - e).abs() < 1e-9 * 36.0, "{g}");
        }
        // `quality` reports the faces between each pair of regions.
        let q = json_of(&biotet(&["quality", s(&out), "--json"]));
        let qi = q["interfaces"].as_array().unwrap();
        let f23 = qi
            .iter()
            .find(|i| i["labels"] == serde_json::json!([2, 3]))
            .unwrap();
        assert!((f23["area"].as_f64().unwrap() - 1.0).abs() < 1e-12, "{f23}");
        tet_counts.push(j["pipeline"]["n_tets"].clone());
    }
    // The three files hold the same model: the same mesh.
    assert!(
        tet_counts.windows(2).all(|w| w[0] == w[1]),
        "{tet_counts:?}"
    );
}

#[test]
fn bad_side_labels_name_the_file_and_the_triangle() {
    let dir = tempfile::tempdir().unwrap();
    let good = three_regions_ply();
    let (head, body) = good.split_once("end_header\n").unwrap();
    let lines: Vec<&str> = body.lines().collect();
    let n_pts: usize = head
        .lines()
        .find_map(|l| l.strip_prefix("element vertex "))
        .unwrap()
        .parse()
        .unwrap();
    let write = |name: &str, faces: Vec<String>| {
        let p = dir.path().join(name);
        let text = format!(
            "{}end_header\n{}\n{}\n",
            head.replace(
                &format!("element face {}", lines.len() - n_pts),
                &format!("element face {}", faces.len())
            ),
            lines[..n_pts].join("\n"),
            faces.join("\n")
        );
        std::fs::write(&p, text).unwrap();
        p
    };
    let faces: Vec<String> = lines[n_pts..].iter().map(|l| l.to_string()).collect();
    let refused = |p: &Path, what: &str| {
        let out = biotet(&["mesh", s(p), "--size", "0.5"]);
        assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
        let e = stderr(&out);
        assert!(e.contains(s(p)) && e.contains(what), "{e}");
        e
    };
    // Inconsistent labels: a Medit file with each triangle once, ref = the region behind it,
    // where one triangle of cube 2 claims region 3.
    let k = faces.iter().position(|f| f.ends_with(" 2 1")).unwrap();
    let mut medit = format!("MeshVersionFormatted 2\nDimension 3\nVertices\n{n_pts}\n");
    for l in &lines[..n_pts] {
        medit += &format!("{l} 0\n");
    }
    medit += &format!("Triangles\n{}\n", faces.len());
    for (i, f) in faces.iter().enumerate() {
        let v: Vec<usize> = f.split(' ').map(|x| x.parse().unwrap()).collect();
        let back = if i == k { 3 } else { v[4] };
        medit += &format!("{} {} {} {back}\n", v[1] + 1, v[2] + 1, v[3] + 1);
    }
    medit += "End\n";
    let p = dir.path().join("labels.mesh");
    std::fs::write(&p, medit).unwrap();
    let e = refused(&p, "disagree with the geometry");
    assert!(
        e.contains(&format!("triangle {k}: its back side is labelled 3")),
        "{e}"
    );
    // An open region: a triangle of cube 3 removed.
    let k = faces.iter().position(|f| f.ends_with(" 3 1")).unwrap();
    let mut open = faces.clone();
    open.remove(k);
    refused(&write("open.ply", open), "not closed");
    // A crossing pair of shells: cube 2 moved half a unit into the box's corner region is not
    // possible without new points, so cross two boxes instead: the outer box and a box through
    // its wall (both labelled against the outside).
    let crossing = "ply\nformat ascii 1.0\nelement vertex 16\nproperty double x\n\
        property double y\nproperty double z\nelement face 24\n\
        property list uchar int vertex_indices\nproperty int label_back\n\
        property int label_front\nend_header\n";
    let mut text = crossing.to_string();
    let cube = |o: [f64; 3], k: f64| -> Vec<[f64; 3]> {
        (0..8)
            .map(|i| {
                [
                    o[0] + k * (i & 1) as f64,
                    o[1] + k * ((i >> 1) & 1) as f64,
                    o[2] + k * ((i >> 2) & 1) as f64,
                ]
            })
            .collect()
    };
    for p in cube([0.0; 3], 2.0).iter().chain(&cube([1.0; 3], 2.0)) {
        text += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    for (base, label) in [(0, 1), (8, 2)] {
        for q in quads {
            let q = q.map(|v| v + base);
            text += &format!("3 {} {} {} {label} 0\n", q[0], q[1], q[2]);
            text += &format!("3 {} {} {} {label} 0\n", q[0], q[2], q[3]);
        }
    }
    let p = dir.path().join("crossing.ply");
    std::fs::write(&p, text).unwrap();
    refused(&p, "intersect");
}

/// A unit cube whose face diagonals admit no tetrahedralization of its eight corners (trimesh's
/// `creation.box`, from the shape corpus): meshing it needs a Steiner point inside. No interior
/// node is deployed at the default size, so `--no-steiner` makes recovery fail.
fn twisted_cube_off() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/shapes/tm_box.off");
    std::fs::read_to_string(path).unwrap()
}

/// The Delaunay tetrahedralization of the twisted cube's corners (`corners.xyz` then `dt.vtu`
/// in `dir`), the mesh `recover` starts from.
fn twisted_cube_delaunay(dir: &Path) -> PathBuf {
    let points = dir.join("corners.xyz");
    std::fs::write(
        &points,
        (0..8)
            .map(|i| {
                let c = |b: i32| if b == 0 { "-0.5" } else { "0.5" };
                format!("{} {} {}\n", c(i >> 2), c((i >> 1) & 1), c(i & 1))
            })
            .collect::<String>(),
    )
    .unwrap();
    let dt = dir.join("dt.vtu");
    assert!(
        biotet(&["delaunay", s(&points), "-o", s(&dt), "-q"])
            .status
            .success()
    );
    dt
}

/// The files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_failed_mesh_creates_and_replaces_nothing_and_keeps_the_partial_mesh_on_request() {
    let dir = tempfile::tempdir().unwrap();
    let cube = dir.path().join("cube.off");
    std::fs::write(&cube, twisted_cube_off()).unwrap();
    let out = dir.path().join("cube.vtu");
    let svg = dir.path().join("cube.svg");
    let failed = dir.path().join("cube.failed.vtu");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "mesh",
            s(&cube),
            "--no-steiner",
            "-o",
            s(&out),
            "--svg",
            s(&svg),
        ];
        args.extend_from_slice(extra);
        biotet(&args)
    };
    // Nothing created: no output, no SVG, no partial mesh, no temporary file.
    let r = run(&[]);
    assert_eq!(r.status.code(), Some(1), "{}", stderr(&r));
    let e = stderr(&r);
    assert!(e.contains("could not be recovered"), "{e}");
    assert!(
        e.contains("was not written") || e.contains("were not written"),
        "{e}"
    );
    assert!(
        e.contains("--keep-failed") && e.contains("cube.failed.vtu"),
        "{e}"
    );
    assert!(e.contains("without --no-steiner"), "{e}");
    assert!(!e.contains("--allow-interior-steiner"), "{e}");
    assert_eq!(listing(dir.path()), ["cube.off"]);
    // Nothing replaced: files already there stay byte-identical, also with --quiet and --json.
    std::fs::write(&out, b"the previous mesh").unwrap();
    std::fs::write(&svg, b"the previous plot").unwrap();
    for extra in [&[][..], &["--quiet"], &["--json"]] {
        let r = run(extra);
        assert_eq!(r.status.code(), Some(1), "{extra:?}");
        assert!(stderr(&r).contains("was not written") || stderr(&r).contains("were not written"));
        assert_eq!(std::fs::read(&out).unwrap(), b"the previous mesh");
        assert_eq!(std::fs::read(&svg).unwrap(), b"the previous plot");
        assert_eq!(listing(dir.path()), ["cube.off", "cube.svg", "cube.vtu"]);
    }
    // --keep-failed: the partial mesh beside the output, named in the message and the JSON.
    let r = run(&["--keep-failed", "--json"]);
    assert_eq!(r.status.code(), Some(1));
    assert!(stderr(&r).contains(s(&failed)), "{}", stderr(&r));
    let j: Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(j["written"], serde_json::json!([s(&failed)]), "{j}");
    assert!(j["pipeline"]["missing_triangles"].as_u64().unwrap() > 0);
    assert_eq!(j["pipeline"]["recover"]["steiner_points"], 0);
    assert_eq!(std::fs::read(&out).unwrap(), b"the previous mesh");
    assert_eq!(std::fs::read(&svg).unwrap(), b"the previous plot");
    let c = biotet(&["check", s(&failed), "--surface", s(&cube), "--quiet"]);
    assert_eq!(c.status.code(), Some(1), "the partial mesh lacks triangles");
    // TetGen output: the three files of the base `cube_tg.failed`.
    let tg = dir.path().join("cube_tg.node");
    let r = biotet(&[
        "mesh",
        s(&cube),
        "--no-steiner",
        "-o",
        s(&tg),
        "--keep-failed",
        "--quiet",
    ]);
    assert_eq!(r.status.code(), Some(1));
    for ext in ["node", "ele", "face"] {
        let f = dir.path().join(format!("cube_tg.failed.{ext}"));
        assert!(f.exists(), "{}", f.display());
        assert!(stderr(&r).contains(s(&f)), "{}", stderr(&r));
        assert!(!dir.path().join(format!("cube_tg.{ext}")).exists());
    }
    // --keep-failed needs an output.
    let r = biotet(&["mesh", s(&cube), "--keep-failed"]);
    assert_eq!(r.status.code(), Some(2));
}

#[test]
fn a_failed_recover_creates_and_replaces_nothing_and_keeps_the_partial_mesh_on_request() {
    let dir = tempfile::tempdir().unwrap();
    let cube = dir.path().join("cube.off");
    std::fs::write(&cube, twisted_cube_off()).unwrap();
    let dt = twisted_cube_delaunay(dir.path());
    let out = dir.path().join("rec.vtu");
    let failed = dir.path().join("rec.failed.vtu");
    let recover = |extra: &[&str]| {
        let mut args = vec!["recover", s(&dt), "-s", s(&cube), "-o", s(&out)];
        args.extend_from_slice(extra);
        biotet(&args)
    };
    let r = recover(&["--no-steiner"]);
    assert_eq!(r.status.code(), Some(1), "{}", stderr(&r));
    let e = stderr(&r);
    assert!(
        e.contains("rec.vtu was not written") && e.contains("--keep-failed"),
        "{e}"
    );
    assert!(e.contains("without --no-steiner"), "{e}");
    assert!(!e.contains("--allow-interior-steiner"), "{e}");
    assert!(!out.exists() && !failed.exists());
    std::fs::write(&out, b"the previous mesh").unwrap();
    let r = recover(&["--no-steiner", "--quiet"]);
    assert_eq!(r.status.code(), Some(1));
    assert!(stderr(&r).contains("was not written"), "{}", stderr(&r));
    assert_eq!(std::fs::read(&out).unwrap(), b"the previous mesh");
    let r = recover(&["--no-steiner", "--keep-failed", "--json"]);
    assert_eq!(r.status.code(), Some(1));
    assert!(stderr(&r).contains(s(&failed)), "{}", stderr(&r));
    let j: Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(j["complete"], false);
    assert_eq!(j["written"], serde_json::json!([s(&failed)]), "{j}");
    assert_eq!(std::fs::read(&out).unwrap(), b"the previous mesh");
    assert!(failed.exists());
    assert_eq!(
        listing(dir.path()),
        [
            "corners.xyz",
            "cube.off",
            "dt.vtu",
            "rec.failed.vtu",
            "rec.vtu"
        ]
    );
}

#[test]
fn steiner_points_inside_mesh_the_twisted_cube_by_default() {
    let dir = tempfile::tempdir().unwrap();
    let cube = dir.path().join("cube.off");
    std::fs::write(&cube, twisted_cube_off()).unwrap();
    let out = dir.path().join("cube.vtu");
    let j = json_of(&biotet(&["mesh", s(&cube), "-o", s(&out), "--json"]));
    assert_eq!(j["pipeline"]["missing_triangles"], 0, "{j}");
    let n = j["pipeline"]["recover"]["steiner_points"].as_u64().unwrap();
    assert!(n >= 1, "{j}");
    assert_eq!(j["written"], serde_json::json!([s(&out)]));
    let c = biotet(&["check", s(&out), "--surface", s(&cube), "--quiet"]);
    assert!(c.status.success(), "{}", stderr(&c));
    // The text report says how many points were added, and where.
    let r = biotet(&["mesh", s(&cube)]);
    assert!(r.status.success(), "{}", stderr(&r));
    let text = String::from_utf8_lossy(&r.stdout);
    assert!(
        text.contains(&format!(
            "recover: {n} Steiner points added strictly inside (never on the surface)"
        )),
        "{text}"
    );
}

#[test]
fn allow_interior_steiner_is_still_accepted_and_the_default() {
    let dir = tempfile::tempdir().unwrap();
    let cube = dir.path().join("cube.off");
    std::fs::write(&cube, twisted_cube_off()).unwrap();
    let a = dir.path().join("a.vtu");
    let b = dir.path().join("b.vtu");
    let r = biotet(&["mesh", s(&cube), "-o", s(&a), "--quiet"]);
    assert!(r.status.success(), "{}", stderr(&r));
    let r = biotet(&[
        "mesh",
        s(&cube),
        "-o",
        s(&b),
        "--allow-interior-steiner",
        "--quiet",
    ]);
    assert!(r.status.success(), "{}", stderr(&r));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    // recover: the former opt-in gives the default's result.
    let dt = twisted_cube_delaunay(dir.path());
    let mut results = Vec::new();
    for extra in [&[][..], &["--allow-interior-steiner"]] {
        let rec = dir.path().join(format!("rec{}.vtu", results.len()));
        let mut args = vec!["recover", s(&dt), "-s", s(&cube), "-o", s(&rec), "--json"];
        args.extend_from_slice(extra);
        let j = json_of(&biotet(&args));
        assert_eq!(j["complete"], true, "{extra:?}: {j}");
        assert!(j["recover"]["steiner_points"].as_u64().unwrap() >= 1, "{j}");
        results.push(std::fs::read(&rec).unwrap());
    }
    assert_eq!(results[0], results[1]);
    // It contradicts --no-steiner.
    for cmd in [
        vec!["mesh", s(&cube), "--allow-interior-steiner", "--no-steiner"],
        vec![
            "recover",
            s(&dt),
            "-s",
            s(&cube),
            "-o",
            s(&a),
            "--allow-interior-steiner",
            "--no-steiner",
        ],
    ] {
        assert_eq!(biotet(&cmd).status.code(), Some(2), "{cmd:?}");
    }
}

#[test]
fn mesh_and_recover_help_end_with_examples_of_the_steiner_and_failure_flags() {
    for cmd in ["mesh", "recover"] {
        let out = biotet(&[cmd, "--help"]);
        assert!(out.status.success());
        let text = String::from_utf8_lossy(&out.stdout);
        let examples = text.find("Examples:").expect("examples");
        assert!(
            text[examples..].contains("--no-steiner --keep-failed"),
            "{text}"
        );
        assert!(text[examples..].contains(".failed.vtu"), "{text}");
        assert!(text[..examples].contains("--no-steiner"), "{text}");
        assert!(text[..examples].contains("--keep-failed"), "{text}");
        // The former opt-in is accepted but not shown.
        assert!(!text.contains("--allow-interior-steiner"), "{text}");
    }
}

/// Unit cubes at integer `cells` as one OFF surface: faces shared by two cubes removed, each
/// remaining square split along one diagonal (`other`: the other one, per cube).
fn cubes_off(cells: &[([i32; 3], bool)]) -> String {
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut squares: Vec<([[i32; 3]; 4], bool)> = Vec::new();
    for &(o, other) in cells {
        let c = |i: usize| {
            [
                o[0] + (i & 1) as i32,
                o[1] + ((i >> 1) & 1) as i32,
                o[2] + (i >> 2) as i32,
            ]
        };
        for q in quads {
            squares.push((q.map(c), other));
        }
    }
    let key = |q: &[[i32; 3]; 4]| {
        let mut k = *q;
        k.sort_unstable();
        k
    };
    let mut pts: Vec<[i32; 3]> = Vec::new();
    let mut tris: Vec<[usize; 3]> = Vec::new();
    for (q, other) in &squares {
        if squares.iter().filter(|(r, _)| key(r) == key(q)).count() > 1 {
            continue;
        }
        let id: Vec<usize> = (0..4)
            .map(|i| {
                let p = q[(i + *other as usize) % 4];
                pts.iter().position(|x| *x == p).unwrap_or_else(|| {
                    pts.push(p);
                    pts.len() - 1
                })
            })
            .collect();
        tris.push([id[0], id[1], id[2]]);
        tris.push([id[0], id[2], id[3]]);
    }
    let mut s = format!("OFF\n{} {} 0\n", pts.len(), tris.len());
    for p in &pts {
        s += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for t in &tris {
        s += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
    }
    s
}

#[test]
fn shells_touching_along_an_edge_or_at_a_vertex_are_two_regions() {
    // [0,1]^3 with [1,2]x[1,2]x[0,1] (sharing the edge (1,1,0)-(1,1,1)), or with [1,2]^3
    // (sharing the vertex (1,1,1)): validate accepts what mesh accepts, and says where the
    // shells touch; the mesh has two regions, each with its whole boundary, and passes check.
    let dir = tempfile::tempdir().unwrap();
    for (name, b, note, touching) in [
        (
            "edge.off",
            [1, 1, 0],
            [
                "shells touch along edge (",
                ") (1, 1, 0)–(1, 1, 1): kept as an edge shared by regions 1 and 2",
            ],
            2,
        ),
        (
            "vertex.off",
            [1, 1, 1],
            [
                "shells touch at vertex ",
                " (1, 1, 1): kept as a vertex shared by regions 1 and 2",
            ],
            1,
        ),
    ] {
        let off = dir.path().join(name);
        std::fs::write(&off, cubes_off(&[([0, 0, 0], false), (b, true)])).unwrap();
        let v = biotet(&["validate", s(&off)]);
        assert!(v.status.success(), "{name}: {}", stderr(&v));
        for w in note {
            assert!(stderr(&v).contains(w), "{name}: {}", stderr(&v));
        }
        let vtu = dir.path().join("out.vtu");
        let m = biotet(&["mesh", s(&off), "-o", s(&vtu)]);
        assert!(m.status.success(), "{name}: {}", stderr(&m));
        assert!(stderr(&m).contains(note[1]), "{name}: {}", stderr(&m));
        let c = json_of(&biotet(&["check", s(&vtu), "--surface", s(&off), "--json"]));
        assert_eq!(c["valid"], true, "{name}: {c}");
        assert_eq!(c["n_touching_vertices"], touching, "{name}: {c}");
        let regions: Vec<u64> = c["regions"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r["label"].as_u64().unwrap())
            .collect();
        assert_eq!(regions, vec![1, 2], "{name}: {c}");
        for i in c["surface"]["interfaces"].as_array().unwrap() {
            assert_eq!(
                (&i["expected"], &i["found"]),
                (&12.into(), &12.into()),
                "{c}"
            );
        }
        assert_eq!(c["surface"]["interfaces"].as_array().unwrap().len(), 2);
        // Converted without `--regions`, the surface carries no labels to the formats that
        // hold them (they used to declare both shells region 1, and the mesh was refused): the
        // same mesh, byte for byte.
        let want = std::fs::read(&vtu).unwrap();
        for ext in ["vtu", "vtp", "vtk", "ply", "mesh"] {
            let conv = dir.path().join(format!("conv.{ext}"));
            let c = biotet(&["convert", s(&off), "-o", s(&conv)]);
            assert!(c.status.success(), "{name} {ext}: {}", stderr(&c));
            let again = dir.path().join("again.vtu");
            let m = biotet(&["mesh", s(&conv), "-o", s(&again)]);
            assert!(m.status.success(), "{name} {ext}: {}", stderr(&m));
            assert!(
                std::fs::read(&again).unwrap() == want,
                "{name} {ext}: another mesh"
            );
        }
    }
}

#[test]
fn crossing_triangles_are_refused_with_the_way_out_and_untangled_by_the_surface_stage() {
    // A flat ellipsoid whose top pole is pushed down through its bottom: 18 pairs of crossing
    // triangles, as a FreeSurfer pial surface has a few. Refused, naming the option; meshed
    // with it, the points moved at most a quarter of the tolerance.
    let dir = tempfile::tempdir().unwrap();
    let mut e = biotet::SurfaceMesh::icosphere(1.0, 2);
    for p in &mut e.points {
        *p = [2.0 * p[0], 2.0 * p[1], 0.3 * p[2]];
    }
    let top = (0..e.points.len())
        .max_by(|&a, &b| e.points[a][2].total_cmp(&e.points[b][2]))
        .unwrap();
    e.points[top][2] = -0.35;
    let input = dir.path().join("dented.off");
    biotet_io::write_surface(&input, &e).unwrap();
    let out = dir.path().join("dented.vtu");
    for cmd in ["validate", "mesh"] {
        let r = biotet(&[cmd, s(&input), "-o", s(&out)][..if cmd == "mesh" { 4 } else { 2 }]);
        assert_eq!(r.status.code(), Some(1), "{cmd}");
        let err = stderr(&r);
        assert_eq!(err.trim_end().lines().count(), 1, "{cmd}: {err}");
        for w in ["dented.off", "self-intersection", "--surface-tolerance D"] {
            assert!(err.contains(w), "{cmd}: {w}: {err}");
        }
        assert!(!out.exists());
    }
    let r = biotet(&[
        "mesh",
        s(&input),
        "--surface-tolerance",
        "0.5",
        "-o",
        s(&out),
    ]);
    assert!(r.status.success(), "{}", stderr(&r));
    assert!(
        stderr(&r).contains("pairs of triangles cross"),
        "{}",
        stderr(&r)
    );
    let text = String::from_utf8_lossy(&r.stdout);
    assert!(text.contains("untangled first"), "{text}");
    let j = json_of(&biotet(&[
        "mesh",
        s(&input),
        "--surface-tolerance",
        "0.5",
        "-o",
        s(&out),
        "--json",
    ]));
    let u = &j["surface"]["untangled"];
    assert!(u["pairs"].as_u64().unwrap() > 0, "{u}");
    assert!(u["max_move"].as_f64().unwrap() <= 0.125, "{u}");
    assert!(
        j["surface"]["hausdorff_bound"].as_f64().unwrap() <= 0.5,
        "{j}"
    );
    let c = biotet(&["check", s(&out), "-q"]);
    assert!(c.status.success(), "{}", stderr(&c));
}

#[test]
fn freesurfer_and_gifti_surfaces_mesh() {
    // `lh.pial` as a subject's surf/ holds it: no format extension, known by its first bytes;
    // `convert` writes one as .surf.
    let dir = tempfile::tempdir().unwrap();
    let off = dir.path().join("e.off");
    std::fs::write(&off, ellipsoid_off([1.0, 2.0, 3.0], [1.0, 0.8, 0.6])).unwrap();
    let pial = dir.path().join("lh.pial");
    let mut bytes = Vec::new();
    let e = biotet_io::read_surface(&off).unwrap().mesh;
    biotet_io::freesurfer::write(&mut bytes, &e, "lh.pial").unwrap();
    std::fs::write(&pial, bytes).unwrap();
    let out = dir.path().join("lh.vtu");
    let j = json_of(&biotet(&["mesh", s(&pial), "-o", s(&out), "--json"]));
    assert_eq!(j["pipeline"]["missing_triangles"], 0, "{j}");
    let c = biotet(&["check", s(&out), "--surface", s(&pial), "-q"]);
    assert!(c.status.success(), "{}", stderr(&c));
    let surf = dir.path().join("back.surf");
    let c = biotet(&["convert", s(&off), "-o", s(&surf)]);
    assert!(c.status.success(), "{}", stderr(&c));
    let r = biotet_io::read_surface(&surf).unwrap().mesh;
    assert_eq!(r.triangles, e.triangles);
    // GIfTI, as fMRIPrep names it: meshed to the OFF's file byte for byte (float64 points).
    let gii = dir.path().join("sub-01_hemi-L_pial.surf.gii");
    let c = biotet(&["convert", s(&off), "-o", s(&gii)]);
    assert!(c.status.success(), "{}", stderr(&c));
    let (a, b) = (dir.path().join("a.vtu"), dir.path().join("b.vtu"));
    for (input, out) in [(&off, &a), (&gii, &b)] {
        let m = biotet(&["mesh", s(input), "-o", s(out), "--threads", "1", "-q"]);
        assert!(m.status.success(), "{}", stderr(&m));
    }
    assert!(std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap());
}

#[test]
fn a_surface_far_from_the_origin_meshes() {
    // An ellipsoid at (1e9, -2e9, 3e9) (survey or micrometre coordinates): the memory estimate
    // summed cones from the origin, whose terms cancelled to noise a million times the volume,
    // and refused it as needing petabytes. Meshed like the same ellipsoid at the origin.
    let dir = tempfile::tempdir().unwrap();
    let mut tets = Vec::new();
    for c in [[0.0; 3], [1e9, -2e9, 3e9]] {
        let input = dir.path().join("far.off");
        std::fs::write(&input, ellipsoid_off(c, [1.0, 0.8, 0.6])).unwrap();
        let out = dir.path().join("far.vtu");
        let j = json_of(&biotet(&["mesh", s(&input), "-o", s(&out), "--json"]));
        let c = biotet(&["check", s(&out), "--surface", s(&input), "-q"]);
        assert!(c.status.success(), "{}", stderr(&c));
        let v = j["quality"]["volume"].as_f64().unwrap();
        assert!(
            (v - 4.0 / 3.0 * std::f64::consts::PI * 0.48).abs() < 0.1,
            "{j}"
        );
        tets.push(j["pipeline"]["n_tets"].as_u64().unwrap());
    }
    // Rounding differs far away, so the meshes may too, but not by much.
    assert!(tets[1].abs_diff(tets[0]) * 5 < tets[0], "{tets:?}");
}

#[test]
fn solids_sharing_a_face_in_one_stl_are_two_regions() {
    // An assembly saved as one STL: [0,1]^3 and its mirror image [-1,0]x[0,1]^2, each with its
    // whole boundary, so the face x = 0 comes twice (opposite orientations, the same diagonal).
    // It was refused as overlapping triangles; it is two regions and one interface.
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let corner = |i: usize, sx: f64| [sx * (i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64];
    let mut stl = String::from("solid assembly\n");
    for sx in [1.0, -1.0] {
        for q in quads {
            for tri in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                // The mirror image turns orientation: its triangles are given reversed.
                let tri = if sx < 0.0 {
                    [tri[0], tri[2], tri[1]]
                } else {
                    tri
                };
                stl += "facet normal 0 0 0\nouter loop\n";
                for v in tri {
                    let p = corner(v, sx);
                    stl += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
                }
                stl += "endloop\nendfacet\n";
            }
        }
    }
    stl += "endsolid assembly\n";
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("assembly.stl");
    std::fs::write(&input, stl).unwrap();
    let v = biotet(&["validate", s(&input)]);
    assert!(v.status.success(), "{}", stderr(&v));
    assert!(
        stderr(&v).contains("2 triangles given twice"),
        "{}",
        stderr(&v)
    );
    let out = dir.path().join("assembly.vtu");
    let j = json_of(&biotet(&["mesh", s(&input), "-o", s(&out), "--json"]));
    assert_eq!(j["quality"]["n_regions"], 2, "{j}");
    assert_eq!(j["pipeline"]["missing_triangles"], 0, "{j}");
    let c = json_of(&biotet(&[
        "check",
        s(&out),
        "--surface",
        s(&input),
        "--json",
    ]));
    assert_eq!(c["valid"], true, "{c}");
    let inter: Vec<&Value> = c["surface"]["interfaces"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|i| {
            i["labels"]
                .as_array()
                .is_some_and(|l| !l.contains(&0.into()))
        })
        .collect();
    assert!(
        inter.iter().any(|i| i["expected"] == 2 && i["found"] == 2),
        "{c}"
    );
}

#[test]
fn a_region_pinched_at_an_edge_is_refused_naming_the_edge() {
    let dir = tempfile::tempdir().unwrap();
    // One shell: cubes [0,1]^3 and [1,2]x[1,2]x[0,1] joined above through [0,1]x[0,2]x[1,2]
    // and [1,2]^3, so one region pinched at the edge (1,1,0)-(1,1,1).
    let ring = dir.path().join("ring.off");
    let cells = [[0, 0, 0], [1, 1, 0], [0, 0, 1], [0, 1, 1], [1, 1, 1]];
    let cells: Vec<_> = cells.iter().map(|&c| (c, false)).collect();
    std::fs::write(&ring, cubes_off(&cells)).unwrap();
    // A bow-tie of two tets sharing the edge (0,0,0)-(0,0,1), labelled as one region.
    let bowtie = dir.path().join("bowtie.ply");
    let pts = ["0 0 0", "0 0 1", "1 0 0", "0 1 0", "-1 0 0", "0 -1 0"];
    let faces = [
        [0, 3, 2],
        [0, 2, 1],
        [0, 1, 3],
        [1, 2, 3],
        [0, 5, 4],
        [0, 4, 1],
        [0, 1, 5],
        [1, 4, 5],
    ];
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex 6\nproperty double x\nproperty double y\n\
         property double z\nelement face 8\nproperty list uchar int vertex_indices\n\
         property int label_back\nproperty int label_front\nend_header\n{}\n",
        pts.join("\n")
    );
    for f in faces {
        ply += &format!("3 {} {} {} 1 0\n", f[0], f[1], f[2]);
    }
    std::fs::write(&bowtie, ply).unwrap();
    for (f, edge) in [
        (&ring, "(1, 1, 0)–(1, 1, 1) in 4 triangles"),
        (&bowtie, "(0, 0, 0)–(0, 0, 1) in 4 triangles"),
    ] {
        let v = biotet(&["validate", s(f)]);
        assert_eq!(v.status.code(), Some(1), "{}", stderr(&v));
        let msg = stderr(&v);
        assert!(
            msg.contains("non-manifold edges") && msg.contains(edge) && msg.contains(s(f)),
            "{msg}"
        );
        let out = dir.path().join("out.vtu");
        let m = biotet(&["mesh", s(f), "-o", s(&out)]);
        assert_eq!(m.status.code(), Some(1), "{}", stderr(&m));
        assert!(stderr(&m).contains(edge), "{}", stderr(&m));
        assert!(!out.exists());
    }
}

/// trimesh's icosphere and its mesh (defaults) written into `dir`: (surface, mesh).
fn meshed_icosphere(dir: &Path) -> (PathBuf, PathBuf) {
    let surface = root().join("tests/data/shapes/tm_icosphere.off");
    let base = dir.join("base.vtu");
    let out = biotet(&["mesh", s(&surface), "-o", s(&base), "--quiet"]);
    assert!(out.status.success(), "{}", stderr(&out));
    (surface, base)
}

#[test]
fn remesh_replaces_a_zone_keeps_the_rest_and_refuses_a_missing_zone() {
    let dir = tempfile::tempdir().unwrap();
    let (surface, base) = meshed_icosphere(dir.path());
    let before = json_of(&biotet(&["quality", s(&base), "--json"]));
    // A ball and a box (negative coordinates without '=') at a finer size.
    for zone in [
        ["--sphere", "0.3,0,0,0.4"],
        ["--box", "-0.5,-0.5,-0.2,0.2,0.1,0.5"],
    ] {
        let new = dir.path().join("new.vtu");
        let out = biotet(&[
            "remesh",
            s(&base),
            zone[0],
            zone[1],
            "--size",
            "0.1",
            "-o",
            s(&new),
            "--json",
        ]);
        assert!(out.status.success(), "{zone:?}: {}", stderr(&out));
        let j = json_of(&out);
        let r = &j["remesh"];
        let kept = r["tets_kept"].as_u64().unwrap();
        let after = r["tets_after"].as_u64().unwrap();
        assert!(
            kept > 0 && after > r["tets_before"].as_u64().unwrap(),
            "{r}"
        );
        let v0 = before["volume"].as_f64().unwrap();
        let v1 = j["quality"]["volume"].as_f64().unwrap();
        assert!((v0 - v1).abs() < 1e-9 * v0, "{v0} vs {v1}");
        let check = biotet(&["check", s(&new), "-s", s(&surface)]);
        assert!(check.status.success(), "{zone:?}: {}", stderr(&check));
    }
    // A refill far too fine for --max-memory: refused before the work, nothing written.
    let big = dir.path().join("big.vtu");
    let out = biotet(&[
        "remesh",
        s(&base),
        "--sphere",
        "0.3,0,0,0.4",
        "--size",
        "0.0005",
        "--max-memory",
        "64M",
        "-o",
        s(&big),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--max-memory"), "{}", stderr(&out));
    assert!(!big.exists());
    // No zone, or a zone with no tet: an error naming the input, nothing written.
    let none = dir.path().join("none.vtu");
    for args in [vec![], vec!["--sphere", "10,10,10,1"]] {
        let mut a = vec!["remesh", s(&base), "-o", s(&none), "--size", "0.1"];
        a.extend(args);
        let out = biotet(&a);
        assert_eq!(out.status.code(), Some(2));
        assert!(stderr(&out).starts_with("error: "), "{}", stderr(&out));
        assert!(!none.exists());
    }
}

/// A .vti grid over [-1.5, 1.5]³ (7 points a side) whose value is `f(x)`.
fn size_vti(path: &std::path::Path, f: impl Fn(f64) -> f64) {
    let (n, o, sp) = (7, -1.5, 0.5);
    let mut vals = Vec::new();
    for _k in 0..n {
        for _j in 0..n {
            for i in 0..n {
                vals.push(f(o + i as f64 * sp).to_string());
            }
        }
    }
    std::fs::write(
        path,
        format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n\
             <ImageData WholeExtent=\"0 6 0 6 0 6\" Origin=\"{o} {o} {o}\" Spacing=\"{sp} {sp} {sp}\">\n\
             <Piece Extent=\"0 6 0 6 0 6\"><PointData Scalars=\"size\">\
             <DataArray type=\"Float64\" Name=\"size\" format=\"ascii\">{}</DataArray>\
             </PointData></Piece></ImageData></VTKFile>\n",
            vals.join(" ")
        ),
    )
    .unwrap();
}

#[test]
fn remesh_takes_a_size_field_and_allows_shell_changes() {
    let dir = tempfile::tempdir().unwrap();
    let (surface, base) = meshed_icosphere(dir.path());
    let added = |args: &[&str]| {
        let new = dir.path().join("new.vtu");
        let mut a = vec!["remesh", s(&base), "--region", "1", "-o", s(&new), "--json"];
        a.extend_from_slice(args);
        let out = biotet(&a);
        assert!(out.status.success(), "{args:?}: {}", stderr(&out));
        let check = biotet(&["check", s(&new), "-s", s(&surface)]);
        assert!(check.status.success(), "{args:?}: {}", stderr(&check));
        json_of(&out)["remesh"]["tets_after"].as_u64().unwrap()
    };
    // Fine (0.1) where x > 0, coarse (0.3) elsewhere: between the two uniform refills.
    let graded = dir.path().join("graded.vti");
    size_vti(&graded, |x| if x > 0.0 { 0.1 } else { 0.3 });
    let (fine, coarse) = (added(&["--size", "0.1"]), added(&["--size", "0.3"]));
    let field = added(&["--size-field", s(&graded)]);
    assert!(
        coarse < field && field < fine,
        "{coarse} < {field} < {fine}"
    );
    // --allow-shell-changes: the kept tets offered and replaced are in the JSON, the mesh valid.
    let new = dir.path().join("shell.vtu");
    let out = biotet(&[
        "remesh",
        s(&base),
        "--sphere",
        "0.3,0,0,0.4",
        "--size",
        "0.3",
        "--allow-shell-changes",
        "-o",
        s(&new),
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let j = json_of(&out);
    let c = &j["remesh"]["shell_changes"];
    let offered = c["kept_offered"].as_u64().unwrap();
    assert!(offered > 0, "{c}");
    assert!(c["kept_replaced"].as_array().unwrap().len() as u64 <= offered);
    let check = biotet(&["check", s(&new), "-s", s(&surface)]);
    assert!(check.status.success(), "{}", stderr(&check));
    // A field with a value at or below 0 is refused before any work, nothing written.
    let bad = dir.path().join("bad.vti");
    size_vti(&bad, |x| x);
    let none = dir.path().join("none.vtu");
    let out = biotet(&[
        "remesh",
        s(&base),
        "--region",
        "1",
        "--size-field",
        s(&bad),
        "-o",
        s(&none),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("bad.vti"), "{}", stderr(&out));
    assert!(!none.exists());
}

/// An ellipsoid (icosphere of two levels, radii `r`) centred at `c`, as OFF text.
fn ellipsoid_off(c: [f64; 3], r: [f64; 3]) -> String {
    let e = biotet::SurfaceMesh::icosphere(1.0, 2);
    let mut text = format!("OFF\n{} {} 0\n", e.points.len(), e.triangles.len());
    for p in &e.points {
        text += &format!(
            "{} {} {}\n",
            c[0] + r[0] * p[0],
            c[1] + r[1] * p[1],
            c[2] + r[2] * p[2]
        );
    }
    for t in &e.triangles {
        text += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
    }
    text
}

#[test]
fn remesh_insert_embeds_a_surface_and_refuses_one_crossing_the_boundary() {
    let dir = tempfile::tempdir().unwrap();
    let (surface, base) = meshed_icosphere(dir.path());
    let lesion = dir.path().join("lesion.off");
    std::fs::write(&lesion, ellipsoid_off([0.2, 0.1, 0.0], [0.35, 0.2, 0.25])).unwrap();
    let new = dir.path().join("new.vtu");
    let out = biotet(&[
        "remesh",
        s(&base),
        "--insert",
        s(&lesion),
        "--label",
        "5",
        "--size",
        "0.08",
        "-o",
        s(&new),
        "--json",
    ]);
    let j = json_of(&out);
    let r = &j["remesh"];
    assert!(r["tets_kept"].as_u64().unwrap() > 0, "{r}");
    let labels: Vec<u64> = j["quality"]["regions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["label"].as_u64().unwrap())
        .collect();
    assert_eq!(labels, [1, 5]);
    // Valid against the sphere and the lesion as a region 5 inside region 1.
    let lesion_name = lesion.file_name().unwrap().to_str().unwrap();
    let check = biotet(&[
        "check",
        s(&new),
        "-s",
        s(&surface),
        "-s",
        s(&lesion),
        "--label",
        "tm_icosphere.off=1",
        "--label",
        &format!("{lesion_name}=5"),
    ]);
    assert!(check.status.success(), "{}", stderr(&check));
    // The lesion as a triangle soup: welded (and said), the same mesh.
    let soup = dir.path().join("lesion_soup.ply");
    let read = biotet_io::read_surface(&lesion).unwrap().mesh;
    biotet_io::write_surface(&soup, &support::soup(&read)).unwrap();
    let again = dir.path().join("again.vtu");
    let out = biotet(&[
        "remesh",
        s(&base),
        "--insert",
        s(&soup),
        "--label",
        "5",
        "--size",
        "0.08",
        "-o",
        s(&again),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("duplicate vertices"),
        "{}",
        stderr(&out)
    );
    assert!(std::fs::read(&again).unwrap() == std::fs::read(&new).unwrap());

    // Across the outer boundary: refused on one line naming the triangle, the boundary and a
    // point; nothing written.
    let crossing = dir.path().join("crossing.off");
    std::fs::write(&crossing, ellipsoid_off([0.9, 0.0, 0.0], [0.3, 0.2, 0.2])).unwrap();
    let none = dir.path().join("none.vtu");
    let out = biotet(&[
        "remesh",
        s(&base),
        "--insert",
        s(&crossing),
        "--label",
        "5",
        "-o",
        s(&none),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    for part in [
        "error: ",
        "cannot insert",
        "triangle ",
        "outer boundary of region 1",
        "near (",
    ] {
        assert!(e.contains(part), "{part}: {e}");
    }
    assert!(!none.exists());
    // --label without --insert, and --insert without --label, are usage errors.
    let out = biotet(&["remesh", s(&base), "--insert", s(&lesion), "-o", s(&none)]);
    assert!(!out.status.success() && !none.exists());
    let help = biotet(&["remesh", "--help"]);
    assert!(String::from_utf8_lossy(&help.stdout).contains("--insert lesion.stl --label"));
}
