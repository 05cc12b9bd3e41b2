//! 2D triangle meshes: Medit `Dimension 2` and Triangle `.node`/`.ele`.

use crate::common::{assert_same_tri, tri_grid};
use biotet::TriMesh;
use biotet_io::{TetgenOptions, TriRead, medit, tetgen};

#[derive(Debug, Clone, Copy)]
enum F {
    Medit,
    Triangle(bool),
}

const ALL: [F; 3] = [F::Medit, F::Triangle(false), F::Triangle(true)];

fn write(f: F, m: &TriMesh) -> Vec<Vec<u8>> {
    let mut a = Vec::new();
    match f {
        F::Medit => medit::write_tri(&mut a, m, "t.mesh").unwrap(),
        F::Triangle(zero_based) => {
            let mut b = Vec::new();
            tetgen::write_tri(&mut a, &mut b, m, "t", TetgenOptions { zero_based }).unwrap();
            return vec![a, b];
        }
    }
    vec![a]
}

fn read(f: F, d: &[Vec<u8>]) -> TriRead {
    match f {
        F::Medit => medit::parse_tri(&d[0], "t.mesh"),
        F::Triangle(_) => tetgen::parse_tri(&d[0], &d[1], "t"),
    }
    .unwrap_or_else(|e| panic!("{f:?}: {e}"))
}

#[test]
fn all_pairs_round_trip() {
    let m = tri_grid(12, 0.2);
    for a in ALL {
        let ra = read(a, &write(a, &m));
        assert_eq!(ra.flipped, 0);
        assert_same_tri(&m, &ra.mesh, &format!("{a:?}"));
        for b in ALL {
            let rb = read(b, &write(b, &ra.mesh));
            assert_same_tri(&m, &rb.mesh, &format!("{a:?} -> {b:?}"));
            assert_eq!(rb.mesh.neighbors, m.neighbors);
        }
    }
}

#[test]
fn clockwise_meshes_are_flipped_and_mixed_ones_kept() {
    let m = tri_grid(4, 0.0);
    let mut cw = m.clone();
    for t in cw.triangles.iter_mut() {
        t.swap(0, 1);
    }
    let mut mixed = m.clone();
    for t in mixed.triangles.iter_mut().step_by(2) {
        t.swap(0, 1);
    }
    for f in ALL {
        let r = read(f, &write(f, &cw));
        assert_eq!(r.flipped, m.triangles.len(), "{f:?}");
        assert_same_tri(&m, &r.mesh, &format!("{f:?}"));
        let r = read(f, &write(f, &mixed));
        assert_eq!(r.flipped, 0, "{f:?}");
        assert_same_tri(&mixed, &r.mesh, &format!("{f:?}"));
    }
}

#[test]
fn paths_and_kind_detection() {
    let dir = tempfile::tempdir().unwrap();
    let m = tri_grid(5, 0.1);
    for name in ["t.mesh", "u.node", "v.ele"] {
        let p = dir.path().join(name);
        biotet_io::write_tri_mesh(&p, &m).unwrap();
        assert_eq!(
            biotet_io::mesh_kind(&p).unwrap(),
            biotet_io::MeshKind::Triangles2d,
            "{name}"
        );
        let r = biotet_io::read_tri_mesh(&p).unwrap();
        assert_same_tri(&m, &r.mesh, name);
        // TriRead derefs to the mesh.
        assert_eq!(r.points.len(), m.points.len());
    }
    assert!(dir.path().join("v.node").exists());
    // A 2D file read as a tet mesh, and vice versa, is a clear error.
    let e = biotet_io::read_tet_mesh(&dir.path().join("t.mesh"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("2D mesh"), "{e}");
    let e = biotet_io::read_tet_mesh(&dir.path().join("u.node"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("dimension 2, expected 3"), "{e}");
}
