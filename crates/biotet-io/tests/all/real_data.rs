//! The real surfaces in tests/data.

use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data")
        .join(name)
}

#[test]
fn brain_20k_stl() {
    let r = biotet_io::read_surface(&data("brain_20k.stl")).unwrap();
    assert_eq!(r.mesh.triangles.len(), 19_648);
    assert_eq!(r.mesh.points.len(), 9_770);
    assert_eq!(r.welded, 3 * 19_648 - 9_770);
    assert_eq!(r.mesh.sides, vec![[1, 0]; 19_648]);
    // Closed: every edge in exactly two triangles.
    let mut edges: Vec<(u32, u32)> = r
        .mesh
        .triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable();
    for w in edges.chunks(2) {
        assert_eq!(w[0], w[1]);
    }
}

#[test]
fn nested_and_wm_stl() {
    let r = biotet_io::read_surface(&data("wm_20k.stl")).unwrap();
    assert_eq!(
        (r.mesh.points.len(), r.mesh.triangles.len()),
        (14_726, 29_576)
    );
    let r = biotet_io::read_surface(&data("nested_brain_wm_20k.stl")).unwrap();
    assert_eq!(
        (r.mesh.points.len(), r.mesh.triangles.len()),
        (24_496, 49_224)
    );
}

#[test]
fn brain_through_every_surface_format() {
    let dir = tempfile::tempdir().unwrap();
    let m = biotet_io::read_surface(&data("brain_20k.stl"))
        .unwrap()
        .mesh;
    for name in ["b.stl", "b.obj", "b.off", "b.ply", "b.mesh"] {
        let p = dir.path().join(name);
        biotet_io::write_surface(&p, &m).unwrap();
        let r = biotet_io::read_surface(&p).unwrap();
        assert_eq!(r.mesh.points, m.points, "{name}");
        assert_eq!(r.mesh.triangles, m.triangles, "{name}");
    }
}
