//! Atomic writes: complete files or nothing.

use crate::common::cube6;
use biotet_io::atomic::write_atomic_many;
use std::io::Write;

fn entries(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn success_leaves_only_the_target() {
    let dir = tempfile::tempdir().unwrap();
    biotet_io::write_tet_mesh(&dir.path().join("m.vtu"), &cube6()).unwrap();
    assert_eq!(entries(dir.path()), vec!["m.vtu"]);
    let files = biotet_io::write_tet_mesh_as(
        &dir.path().join("t"),
        &cube6(),
        biotet_io::TetFormat::TetGen,
    )
    .unwrap();
    assert_eq!(files.len(), 3);
    assert_eq!(
        entries(dir.path()),
        vec!["m.vtu", "t.ele", "t.face", "t.node"]
    );
}

#[test]
fn failure_leaves_nothing_and_keeps_old_files() {
    let dir = tempfile::tempdir().unwrap();
    let mut bad = cube6();
    bad.points[0][0] = f64::INFINITY;
    for name in ["a.vtu", "a.mesh", "a.msh", "a.node"] {
        assert!(biotet_io::write_tet_mesh(&dir.path().join(name), &bad).is_err());
    }
    assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
    // An existing file survives a failed overwrite unchanged.
    let p = dir.path().join("keep.mesh");
    biotet_io::write_tet_mesh(&p, &cube6()).unwrap();
    let before = std::fs::read(&p).unwrap();
    assert!(biotet_io::write_tet_mesh(&p, &bad).is_err());
    assert_eq!(std::fs::read(&p).unwrap(), before);
    assert_eq!(entries(dir.path()), vec!["keep.mesh"]);
}

#[test]
fn multi_file_error_after_partial_writes_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let paths = vec![dir.path().join("x.node"), dir.path().join("x.ele")];
    let r = write_atomic_many(&paths, |ws| {
        ws[0].write_all(b"lots of data").unwrap();
        ws[1].write_all(b"more").unwrap();
        Err(biotet_io::Error::Format {
            file: "x".into(),
            msg: "failed late".into(),
        })
    });
    assert!(r.is_err());
    assert!(entries(dir.path()).is_empty());
}

#[test]
fn missing_directory_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("no/such/dir/m.vtu");
    let e = biotet_io::write_tet_mesh(&p, &cube6())
        .unwrap_err()
        .to_string();
    assert!(e.contains("m.vtu"), "{e}");
}

#[cfg(unix)]
#[test]
fn permissions_like_a_normal_file() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("ref");
    std::fs::File::create(&reference).unwrap();
    let p = dir.path().join("m.stl");
    biotet_io::write_surface(&p, &crate::common::box_surface(1, 1.0)).unwrap();
    let mode = |p: &std::path::Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode(&p), mode(&reference));
}
