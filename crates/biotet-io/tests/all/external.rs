//! Files written by VTK and Gmsh (see tests/data/README.md).

use crate::common::{assert_same_tet, grid};
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

#[test]
fn vtk_written_vtu_files() {
    let m = grid(1, 1.0, 0.02, 1, |p| if p[0] < 0.8 { 1 } else { 2 });
    for name in [
        "vtk_inline_base64_zlib.vtu",
        "vtk_appended_base64_uint32.vtu",
        "vtk_appended_raw_bigendian_zlib.vtu",
        "vtk_ascii.vtu",
    ] {
        let r = biotet_io::read_tet_mesh(&data(name)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(r.flipped, 0);
        if name == "vtk_ascii.vtu" {
            // VTK's ASCII output prints fewer digits: not exact.
            assert_eq!(r.mesh.tets, m.tets);
            assert_eq!(r.mesh.labels, m.labels);
        } else {
            assert_same_tet(&m, &r.mesh, name);
        }
    }
}

#[test]
fn gmsh_written_files() {
    for name in [
        "gmsh_two_boxes_41.msh",
        "gmsh_two_boxes_41_binary.msh",
        "gmsh_two_boxes_22.msh",
        "gmsh_two_boxes.mesh",
    ] {
        let r = biotet_io::read_tet_mesh(&data(name)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(r.mesh.points.len(), 78, "{name}");
        assert_eq!(r.mesh.tets.len(), 200, "{name}");
        assert_eq!(r.flipped, 0, "{name}");
        assert_eq!(r.mesh.clone().rebuild_neighbors(), 0, "{name}: conforming");
        let regions = r.mesh.regions();
        if name.ends_with(".msh") {
            // Physical "region_4" (tag 11) gives label 4; "right" (tag 12) its tag.
            assert_eq!(regions, vec![4, 12], "{name}");
        } else {
            assert_eq!(regions.len(), 2, "{name}");
        }
    }
    // The Gmsh encodings give the same mesh (Gmsh's ASCII prints 16 digits: not exact).
    let a = biotet_io::read_tet_mesh(&data("gmsh_two_boxes_41_binary.msh")).unwrap();
    for name in ["gmsh_two_boxes_41.msh", "gmsh_two_boxes_22.msh"] {
        let b = biotet_io::read_tet_mesh(&data(name)).unwrap();
        assert_eq!(a.mesh.tets, b.mesh.tets, "{name}");
        assert_eq!(a.mesh.labels, b.mesh.labels, "{name}");
        for (p, q) in a.mesh.points.iter().zip(&b.mesh.points) {
            assert!(
                (0..3).all(|k| (p[k] - q[k]).abs() < 1e-14),
                "{name}: {p:?} vs {q:?}"
            );
        }
    }
}
