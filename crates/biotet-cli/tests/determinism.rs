//! Determinism across the whole CLI: every command (`view` included) gives byte-identical output files, and the
//! same stdout less its times and memory figures, with `--threads` 1, 2 and 4 and on a second
//! run with 2. Every tet mesh written is also checked.

mod support;
use serde_json::Value;
use std::path::{Path, PathBuf};
use support::*;

/// What one run produced: its output files' bytes and its stdout less the measures that vary.
#[derive(Debug, PartialEq)]
struct Run {
    files: Vec<(String, Vec<u8>)>,
    stdout: Value,
}

/// Drop the keys that measure the run (times, memory) rather than describe the result.
fn without_measures(v: &mut Value) {
    match v {
        Value::Object(m) => {
            m.retain(|k, _| {
                !k.split('_')
                    .any(|w| ["ms", "seconds", "second", "rss", "memory"].contains(&w))
            });
            m.values_mut().for_each(without_measures);
        }
        Value::Array(a) => a.iter_mut().for_each(without_measures),
        _ => {}
    }
}

/// Where two JSON values first differ, as a path.
fn first_difference(a: &Value, b: &Value, at: String) -> Option<String> {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            if x.len() != y.len() {
                return Some(format!("{at} (keys)"));
            }
            x.iter()
                .find_map(|(k, v)| first_difference(v, y.get(k)?, format!("{at}.{k}")))
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .find_map(|(i, (v, w))| first_difference(v, w, format!("{at}[{i}]"))),
        _ => (a != b).then(|| format!("{at}: {a} vs {b}")),
    }
}

/// Run `args` (with `{out}` standing for a fresh directory) with `threads`; the output files
/// are those the run created in the directory.
fn run(args: &[String], threads: usize, dir: &Path) -> Run {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).unwrap();
    let args: Vec<String> = args
        .iter()
        .map(|a| a.replace("{out}", s(dir)))
        .chain(["--json".into(), "--threads".into(), threads.to_string()])
        .collect();
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = biotet(&refs);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut stdout: Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    without_measures(&mut stdout);
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            // Paths in the output name the run's directory: the same for every run.
            (name, std::fs::read(&p).unwrap())
        })
        .collect();
    files.sort();
    Run { files, stdout }
}

/// The command's outputs agree for 1, 2, 4 threads and a second run; the tet meshes among them
/// pass `check`. Returns the output directory of the last run.
fn deterministic(name: &str, args: &[&str], base: &Path) -> PathBuf {
    let args: Vec<String> = args.iter().map(|a| a.to_string()).collect();
    let dir = base.join(name);
    let first = run(&args, 1, &dir);
    for threads in [2, 4, 2] {
        let again = run(&args, threads, &dir);
        if let Some(path) = first_difference(&first.stdout, &again.stdout, String::new()) {
            panic!("{name}: stdout differs at {threads} threads, at {path}");
        }
        let names: Vec<&String> = first.files.iter().map(|f| &f.0).collect();
        let again_names: Vec<&String> = again.files.iter().map(|f| &f.0).collect();
        assert_eq!(
            names, again_names,
            "{name}: other files at {threads} threads"
        );
        for (a, b) in first.files.iter().zip(&again.files) {
            assert!(a.1 == b.1, "{name}: {} differs at {threads} threads", a.0);
        }
    }
    for (f, _) in &first.files {
        if f.ends_with(".vtu") && !f.starts_with("surface") || f.ends_with(".msh") {
            let c = biotet(&["check", s(&dir.join(f)), "--quiet"]);
            assert!(c.status.success(), "{name}: {f}: {}", stderr(&c));
        }
    }
    dir
}

#[test]
fn every_command_is_deterministic() {
    let tmp = tempfile::tempdir().unwrap();
    let base = tmp.path();
    let shapes = root().join("tests/data/shapes");
    let torus = shapes.join("tm_torus.off");
    let torus = s(&torus);
    let data = root().join("crates/biotet-io/tests/data");

    let m = deterministic(
        "mesh",
        &["mesh", torus, "-o", "{out}/m.vtu", "--svg", "{out}/m.svg"],
        base,
    );
    let mesh = m.join("m.vtu");
    let mesh = s(&mesh);
    deterministic(
        "mesh_sized",
        &["mesh", torus, "--size", "0.25", "-o", "{out}/m.msh"],
        base,
    );
    deterministic(
        "mesh_2d",
        &[
            "mesh",
            s(&root().join("examples/plane/holey.poly")),
            "-o",
            "{out}/p.mesh",
        ],
        base,
    );
    let image = data.join("label_uint8.mgz");
    deterministic(
        "mesh_image",
        &["mesh", s(&image), "-o", "{out}/i.vtu"],
        base,
    );
    deterministic(
        "surface",
        &["surface", s(&image), "-o", "{out}/surface.vtu"],
        base,
    );
    deterministic(
        "surface_improve",
        &[
            "surface",
            "improve",
            torus,
            "--tolerance",
            "0.02",
            "-o",
            "{out}/surface.ply",
        ],
        base,
    );
    deterministic("validate", &["validate", torus], base);

    // A point cloud: the torus's points and a pseudo-random cloud.
    let xyz = base.join("cloud.xyz");
    let mut text = String::new();
    let mut x: u64 = 1;
    for _ in 0..3000 {
        let mut c = [0.0; 3];
        for v in &mut c {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            *v = (x >> 40) as f64 / (1u64 << 24) as f64;
        }
        text.push_str(&format!("{} {} {}\n", c[0], c[1], c[2]));
    }
    std::fs::write(&xyz, text).unwrap();
    deterministic(
        "delaunay",
        &["delaunay", s(&xyz), "-o", "{out}/d.vtu"],
        base,
    );

    // Recovery: the Delaunay of the torus's points, with the torus.
    let pts = base.join("torus.xyz");
    let surf = biotet_io::read_surface(Path::new(torus)).unwrap();
    let text: String = surf
        .points
        .iter()
        .map(|p| format!("{} {} {}\n", p[0], p[1], p[2]))
        .collect();
    std::fs::write(&pts, text).unwrap();
    let dt = base.join("torus_dt.vtu");
    let o = biotet(&["delaunay", s(&pts), "-o", s(&dt), "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    deterministic(
        "recover",
        &["recover", s(&dt), "--surface", torus, "-o", "{out}/r.vtu"],
        base,
    );

    deterministic("smooth", &["smooth", mesh, "-o", "{out}/s.vtu"], base);
    deterministic("improve", &["improve", mesh, "-o", "{out}/i.vtu"], base);
    deterministic(
        "remesh",
        &[
            "remesh",
            mesh,
            "--sphere",
            "2,0,0,0.5",
            "--size",
            "0.2",
            "-o",
            "{out}/r.vtu",
        ],
        base,
    );
    deterministic("convert", &["convert", mesh, "-o", "{out}/c.msh"], base);
    deterministic("quality", &["quality", mesh, "--svg", "{out}/q.svg"], base);
    deterministic("check", &["check", mesh, "--surface", torus], base);
    deterministic(
        "view",
        &["view", mesh, "--surface", torus, "-o", "{out}/v.svg"],
        base,
    );
    deterministic(
        "view_png",
        &["view", mesh, "--view", "iso", "-o", "{out}/v.png"],
        base,
    );
}
