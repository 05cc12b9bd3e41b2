//! Path-based entry points: extension dispatch, kind detection, TetGen naming.

use crate::common::{box_surface, cube6, tri_grid};
use biotet_io::{MeshKind, mesh_kind, tetgen};
use std::path::{Path, PathBuf};

#[test]
fn kinds_by_extension_and_content() {
    let dir = tempfile::tempdir().unwrap();
    for (n, k) in [
        ("a.stl", MeshKind::Surface),
        ("a.OBJ", MeshKind::Surface),
        ("a.off", MeshKind::Surface),
        ("a.ply", MeshKind::Surface),
        ("a.vtu", MeshKind::Tetrahedra),
        ("a.vtp", MeshKind::Surface),
        ("a.vtk", MeshKind::Tetrahedra),
        ("a.MSH", MeshKind::Tetrahedra),
    ] {
        assert_eq!(mesh_kind(Path::new(n)).unwrap(), k, "{n}");
    }
    let tet = dir.path().join("tet.mesh");
    biotet_io::write_tet_mesh(&tet, &cube6()).unwrap();
    let surf = dir.path().join("surf.mesh");
    biotet_io::write_surface(&surf, &box_surface(1, 1.0)).unwrap();
    let tri = dir.path().join("tri.mesh");
    biotet_io::write_tri_mesh(&tri, &tri_grid(2, 0.0)).unwrap();
    let tg = dir.path().join("tg.ele");
    biotet_io::write_tet_mesh(&tg, &cube6()).unwrap();
    assert_eq!(mesh_kind(&tet).unwrap(), MeshKind::Tetrahedra);
    assert_eq!(mesh_kind(&surf).unwrap(), MeshKind::Surface);
    // Legacy VTK holds either: the cells tell.
    let (tet_vtk, surf_vtk) = (dir.path().join("tet.vtk"), dir.path().join("surf.vtk"));
    biotet_io::write_tet_mesh(&tet_vtk, &cube6()).unwrap();
    biotet_io::write_surface(&surf_vtk, &box_surface(1, 1.0)).unwrap();
    assert_eq!(mesh_kind(&tet_vtk).unwrap(), MeshKind::Tetrahedra);
    assert_eq!(mesh_kind(&surf_vtk).unwrap(), MeshKind::Surface);
    assert_eq!(mesh_kind(&tri).unwrap(), MeshKind::Triangles2d);
    assert_eq!(mesh_kind(&tg).unwrap(), MeshKind::Tetrahedra);
    assert_eq!(
        mesh_kind(&dir.path().join("tg.node")).unwrap(),
        MeshKind::Tetrahedra
    );
    // A FreeSurfer surface is known by its first bytes, whatever its name (`lh.pial`), or by
    // `.surf`; a file of another kind under such a name is not taken for one.
    let gii = dir.path().join("sub-01_hemi-L_pial.surf.gii");
    biotet_io::write_surface(&gii, &box_surface(1, 1.0)).unwrap();
    assert_eq!(mesh_kind(&gii).unwrap(), MeshKind::Surface);
    assert_eq!(
        biotet_io::read_surface(&gii).unwrap().mesh.points,
        box_surface(1, 1.0).points
    );
    for name in ["lh.pial", "rh.white.preaparc", "s.surf"] {
        let p = dir.path().join(name);
        let mut bytes = Vec::new();
        biotet_io::freesurfer::write(&mut bytes, &box_surface(1, 1.0), name).unwrap();
        std::fs::write(&p, bytes).unwrap();
        assert_eq!(mesh_kind(&p).unwrap(), MeshKind::Surface, "{name}");
        let r = biotet_io::read_surface(&p).unwrap();
        assert_eq!(r.mesh.triangles, box_surface(1, 1.0).triangles, "{name}");
    }
    let curv = dir.path().join("lh.thickness");
    std::fs::write(&curv, b"\xff\xff\xff\0\0\0\x01").unwrap();
    assert!(mesh_kind(&curv).is_err());
    let named = dir.path().join("thickness.surf");
    std::fs::write(&named, b"\xff\xff\xff\0\0\0\x01").unwrap();
    let e = biotet_io::read_surface(&named).unwrap_err().to_string();
    assert!(e.contains("curvature"), "{e}");
    let text = dir.path().join("notes.pial");
    std::fs::write(&text, b"not a surface").unwrap();
    assert!(mesh_kind(&text).is_err());
    // A tet .mesh read as a surface gives its boundary triangles.
    let r = biotet_io::read_surface(&tet).unwrap();
    assert!(r.mesh.triangles.len() >= 12);
}

#[test]
fn unknown_extensions_list_the_supported_ones() {
    let e = biotet_io::read_surface(Path::new("foo.xyz"))
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "foo.xyz: unknown surface file extension; supported: .stl, .obj, .off, .ply, .mesh, .vtu, \
         .vtp, .vtk, .gii, .surf or a FreeSurfer surface (lh.pial)"
    );
    let e = biotet_io::write_tet_mesh(Path::new("foo"), &cube6())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(
            "unknown tet mesh file extension; supported: .vtu, .vtk, .mesh, .msh, .node/.ele (TetGen)"
        ),
        "{e}"
    );
    let e = mesh_kind(Path::new("x.stp")).unwrap_err().to_string();
    assert!(e.contains("supported: .stl"), "{e}");
    let e = biotet_io::read_tet_mesh(Path::new("/nonexistent/x.vtu"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("/nonexistent/x.vtu: "), "{e}");
}

#[test]
fn tetgen_naming_rule() {
    let f = tetgen::files(Path::new("out"));
    assert_eq!(f.node, PathBuf::from("out.node"));
    assert_eq!(f.face, PathBuf::from("out.face"));
    let f = tetgen::files(Path::new("dir/brain.1.ele"));
    assert_eq!(f.base, PathBuf::from("dir/brain.1"));
    assert_eq!(f.node, PathBuf::from("dir/brain.1.node"));
    let f = tetgen::files(Path::new("A.NODE"));
    assert_eq!(f.ele, PathBuf::from("A.ele"));
    let f = tetgen::files(Path::new("mesh.1"));
    assert_eq!(f.ele, PathBuf::from("mesh.1.ele"));

    let dir = tempfile::tempdir().unwrap();
    let written = biotet_io::write_tet_mesh_as(
        &dir.path().join("out.1"),
        &cube6(),
        biotet_io::TetFormat::TetGen,
    )
    .unwrap();
    let names: Vec<String> = written
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["out.1.node", "out.1.ele", "out.1.face"]);
    let r = biotet_io::read_tet_mesh(&dir.path().join("out.1.node")).unwrap();
    assert_eq!(r.mesh.tets.len(), 6);
}

#[test]
fn stream_apis_work_with_readers_and_writers() {
    let m = cube6();
    let mut buf = std::io::Cursor::new(Vec::new());
    biotet_io::vtu::write_tet(&mut buf, &m, "m.vtu").unwrap();
    buf.set_position(0);
    let r = biotet_io::vtu::read_tet(&mut buf, "m.vtu").unwrap();
    assert_eq!(r.mesh.tets.len(), 6);
    let mut out = Vec::new();
    biotet_io::stl::write_ascii(&mut out, &box_surface(1, 1.0), "s").unwrap();
    assert_eq!(
        biotet_io::stl::read(&out[..], "s")
            .unwrap()
            .mesh
            .triangles
            .len(),
        12
    );
}
