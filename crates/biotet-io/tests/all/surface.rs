//! Surface formats: round trips, STL welding and detection, format details.

use crate::common::{assert_same_surface, assert_same_surface_geometry, box_surface};
use biotet::SurfaceMesh;
use biotet_io::{SurfaceRead, medit, obj, off, ply, stl};

#[derive(Debug, Clone, Copy)]
enum F {
    StlBinary,
    StlAscii,
    Obj,
    Off,
    PlyBinary,
    PlyAscii,
    Medit,
}

const ALL: [F; 7] = [
    F::StlBinary,
    F::StlAscii,
    F::Obj,
    F::Off,
    F::PlyBinary,
    F::PlyAscii,
    F::Medit,
];

fn write(f: F, m: &SurfaceMesh) -> Vec<u8> {
    let mut b = Vec::new();
    match f {
        F::StlBinary => stl::write_binary(&mut b, m, "s.stl"),
        F::StlAscii => stl::write_ascii(&mut b, m, "s.stl"),
        F::Obj => obj::write(&mut b, m, "s.obj"),
        F::Off => off::write(&mut b, m, "s.off"),
        F::PlyBinary => ply::write_binary(&mut b, m, "s.ply"),
        F::PlyAscii => ply::write_ascii(&mut b, m, "s.ply"),
        F::Medit => medit::write_surface(&mut b, m, "s.mesh"),
    }
    .unwrap();
    b
}

fn read(f: F, d: &[u8]) -> SurfaceRead {
    match f {
        F::StlBinary | F::StlAscii => stl::parse(d, "s.stl"),
        F::Obj => obj::parse(d, "s.obj"),
        F::Off => off::parse(d, "s.off"),
        F::PlyBinary | F::PlyAscii => ply::parse(d, "s.ply"),
        F::Medit => medit::parse_surface(d, "s.mesh"),
    }
    .unwrap_or_else(|e| panic!("{f:?}: {e}"))
}

fn is_stl(f: F) -> bool {
    matches!(f, F::StlBinary | F::StlAscii)
}

#[test]
fn all_pairs_round_trip() {
    let m = box_surface(3, 0.25);
    assert_eq!(m.triangles.len(), 6 * 9 * 2);
    for a in ALL {
        let ra = read(a, &write(a, &m));
        assert_eq!(ra.mesh.sides, vec![[1, 0]; m.triangles.len()]);
        if is_stl(a) {
            // STL renumbers points in first-use order; geometry per triangle must match.
            assert_same_surface_geometry(&m, &ra.mesh, &format!("{a:?}"));
            assert_eq!(ra.welded, 3 * m.triangles.len() - m.points.len(), "{a:?}");
            assert_eq!(ra.mesh.points.len(), m.points.len());
        } else {
            assert_same_surface(&m, &ra.mesh, &format!("{a:?}"));
            assert_eq!(ra.welded, 0);
        }
        for b in ALL {
            let rb = read(b, &write(b, &ra.mesh));
            if is_stl(a) || is_stl(b) {
                assert_same_surface_geometry(&m, &rb.mesh, &format!("{a:?} -> {b:?}"));
            } else {
                assert_same_surface(&m, &rb.mesh, &format!("{a:?} -> {b:?}"));
            }
            assert_eq!(rb.mesh.points.len(), m.points.len());
        }
    }
}

#[test]
fn text_formats_keep_f64_exactly() {
    let mut m = box_surface(2, 0.5);
    for (i, p) in m.points.iter_mut().enumerate() {
        p[0] += 1e-13 * i as f64 + 0.1;
        p[1] *= std::f64::consts::PI;
        p[2] = p[2] * 1e-300 + 1e-310; // subnormal-ish and tiny numbers
    }
    for f in [
        F::StlAscii,
        F::Obj,
        F::Off,
        F::PlyAscii,
        F::PlyBinary,
        F::Medit,
    ] {
        let r = read(f, &write(f, &m));
        if is_stl(f) {
            assert_same_surface_geometry(&m, &r.mesh, &format!("{f:?}"));
        } else {
            assert_eq!(r.mesh.points, m.points, "{f:?}");
        }
    }
}

#[test]
fn binary_stl_with_solid_header_is_binary() {
    let m = box_surface(1, 1.0);
    let mut b = write(F::StlBinary, &m);
    b[..80].fill(b' ');
    b[..21].copy_from_slice(b"solid exported_by_cad");
    assert!(stl::is_binary(&b));
    let r = stl::parse(&b, "cad.stl").unwrap();
    assert_eq!(r.mesh.triangles.len(), 12);
    assert_eq!(r.mesh.points.len(), 8);
    assert_eq!(r.welded, 36 - 8);
}

#[test]
fn ascii_stl_multiple_solids_and_case() {
    let s = "solid a\nFACET NORMAL 0 0 0\nOUTER LOOP\nVERTEX 0 0 0\nVERTEX 1 0 0\nVERTEX 0 1 0\nENDLOOP\nENDFACET\nendsolid a\n\
solid b\nfacet normal nan nan nan\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\nendsolid\n";
    let r = stl::parse(s.as_bytes(), "two.stl").unwrap();
    assert_eq!(r.mesh.triangles.len(), 2);
    assert_eq!(r.mesh.points.len(), 4);
    assert_eq!(r.welded, 2);
}

#[test]
fn obj_forms_polygons_negative_indices() {
    let s = "# cube-ish\nmtllib x.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0 1.0\nv 0 1 0 0.5 0.5 0.5\nvt 0 0\nvn 0 0 1\n\
g top\nusemtl red\ns off\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -4//1 -2//1 -1//1\nf 1/1 2/1 3/1\nv 0 0 1\nf 1 2 5\n";
    let r = obj::parse(s.as_bytes(), "x.obj").unwrap();
    assert_eq!(r.mesh.points.len(), 5);
    assert_eq!(
        r.mesh.triangles,
        vec![[0, 1, 2], [0, 2, 3], [0, 2, 3], [0, 1, 2], [0, 1, 4]]
    );
    assert_eq!(r.polygons_split, 1);
}

#[test]
fn off_variants() {
    let s = "COFF # coloured\n# a comment line\n\n4 2 0\n0 0 0 255 0 0 255\n1 0 0 255 0 0 255\n1 1 0 0 0 0 255\n0 1 0 1 1 1 1\n4 0 1 2 3 200 100 0\n3 0 2 1\n";
    let r = off::parse(s.as_bytes(), "c.off").unwrap();
    assert_eq!(r.mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 1]]);
    assert_eq!(r.polygons_split, 1);
    let s = "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(
        off::parse(s.as_bytes(), "d.off")
            .unwrap()
            .mesh
            .triangles
            .len(),
        1
    );
}

#[test]
fn ply_big_endian_mixed_types_refs_and_extra_elements() {
    let mut b = b"ply\nformat binary_big_endian 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\nproperty double y\nproperty short z\nproperty uchar red\nelement face 2\nproperty uchar flags\nproperty list uint short vertex_index\nproperty int label\nelement edge 1\nproperty int vertex1\nproperty list uchar int others\nend_header\n".to_vec();
    let verts = [
        (0.0f32, 0.0f64, 0i16),
        (1.0, 0.0, 0),
        (1.0, 1.0, 0),
        (0.0, 1.0, 2),
    ];
    for (x, y, z) in verts {
        b.extend_from_slice(&x.to_be_bytes());
        b.extend_from_slice(&y.to_be_bytes());
        b.extend_from_slice(&z.to_be_bytes());
        b.push(200);
    }
    // Face 0: quad with label 7; face 1: triangle with label -3.
    b.push(1);
    b.extend_from_slice(&4u32.to_be_bytes());
    for v in [0i16, 1, 2, 3] {
        b.extend_from_slice(&v.to_be_bytes());
    }
    b.extend_from_slice(&7i32.to_be_bytes());
    b.push(0);
    b.extend_from_slice(&3u32.to_be_bytes());
    for v in [0i16, 2, 1] {
        b.extend_from_slice(&v.to_be_bytes());
    }
    b.extend_from_slice(&(-3i32).to_be_bytes());
    b.extend_from_slice(&5i32.to_be_bytes());
    b.push(2);
    b.extend_from_slice(&1i32.to_be_bytes());
    b.extend_from_slice(&2i32.to_be_bytes());
    let r = ply::parse(&b, "be.ply").unwrap();
    assert_eq!(r.mesh.points[3], [0.0, 1.0, 2.0]);
    assert_eq!(r.mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 1]]);
    assert_eq!(r.triangle_refs, Some(vec![7, 7, -3]));
    assert_eq!(r.polygons_split, 1);
}

#[test]
fn ply_ascii_by_hand() {
    let s = "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty double x\r\nproperty double y\r\nproperty double z\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n";
    let r = ply::parse(s.as_bytes(), "a.ply").unwrap();
    assert_eq!(r.mesh.triangles, vec![[0, 1, 2]]);
    assert_eq!(r.triangle_refs, None);
}

#[test]
fn medit_surface_refs_and_skipped_sections() {
    let s = "MeshVersionFormatted 1\n\nDimension\n3\n\nVertices\n4\n0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\n\
Edges\n1\n1 2 0\nCorners\n2\n1 2\nTriangles 2\n1 3 2 5\n1 2 4 -6\nNormals\n1\n0 0 1\nEnd\n";
    let r = medit::parse_surface(s.as_bytes(), "s.mesh").unwrap();
    assert_eq!(r.mesh.triangles, vec![[0, 2, 1], [0, 1, 3]]);
    assert_eq!(r.triangle_refs, Some(vec![5, -6]));
    // Written refs: the back side label, or explicit refs.
    let mut b = Vec::new();
    medit::write_surface_with_refs(&mut b, &r.mesh, Some(&[5, -6]), "o.mesh").unwrap();
    assert_eq!(
        medit::parse_surface(&b, "o.mesh").unwrap().triangle_refs,
        Some(vec![5, -6])
    );
}

#[test]
fn paths_round_trip_and_uppercase() {
    let dir = tempfile::tempdir().unwrap();
    let m = box_surface(2, 0.5);
    for name in [
        "s.stl", "s.obj", "s.off", "s.ply", "s.mesh", "S.STL", "S.Ply",
    ] {
        let p = dir.path().join(name);
        biotet_io::write_surface(&p, &m).unwrap();
        let r = biotet_io::read_surface(&p).unwrap();
        assert_same_surface_geometry(&m, &r.mesh, name);
    }
    for f in [
        biotet_io::SurfaceFormat::StlAscii,
        biotet_io::SurfaceFormat::PlyAscii,
    ] {
        let p = dir.path().join("t.stl");
        biotet_io::write_surface_as(&p, &m, f).unwrap();
        let r = biotet_io::read_surface_as(&p, f).unwrap();
        assert_same_surface_geometry(&m, &r.mesh, &format!("{f:?}"));
    }
}

/// Two triangles back to back on a tetrahedron's faces, labelled: region 2 inside a tet whose
/// outer faces face region 0, with one face an interface to region 5.
fn labelled_tet() -> SurfaceMesh {
    SurfaceMesh {
        points: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        sides: vec![[2, 0], [2, 0], [2, 5], [2, 0]],
    }
}

#[test]
fn side_labels_round_trip_through_ply_vtu_and_medit() {
    let m = labelled_tet();
    let dir = tempfile::tempdir().unwrap();
    for name in ["s.ply", "s.vtu", "s.mesh"] {
        let p = dir.path().join(name);
        biotet_io::write_surface(&p, &m).unwrap();
        let r = biotet_io::read_surface(&p).unwrap();
        assert_eq!(r.mesh.triangles, m.triangles, "{name}");
        // Medit writes each triangle with the region behind it (interfaces twice): an outer
        // triangle's front is left to the geometry.
        let want: Vec<[u32; 2]> = if name.ends_with(".mesh") {
            let g = biotet::mesh::side_labels::FROM_GEOMETRY;
            m.sides
                .iter()
                .map(|s| if s[1] == 0 { [s[0], g] } else { *s })
                .collect()
        } else {
            m.sides.clone()
        };
        assert_eq!(r.side_labels.as_ref(), Some(&want), "{name}");
        assert_eq!(
            biotet_io::mesh_kind(&p).unwrap(),
            biotet_io::MeshKind::Surface,
            "{name}"
        );
    }
    let mut b = Vec::new();
    ply::write_ascii(&mut b, &m, "a.ply").unwrap();
    assert_eq!(
        ply::parse(&b, "a.ply").unwrap().side_labels,
        Some(m.sides.clone())
    );
    // An unlabelled surface writes no labels and reads none.
    let plain = SurfaceMesh::closed(m.points.clone(), m.triangles.clone(), 1);
    let mut b = Vec::new();
    ply::write_binary(&mut b, &plain, "p.ply").unwrap();
    assert_eq!(ply::parse(&b, "p.ply").unwrap().side_labels, None);
}

#[test]
fn medit_refs_name_the_region_behind_and_a_second_copy_the_front() {
    use biotet::mesh::side_labels::FROM_GEOMETRY;
    let head = "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\nTriangles\n";
    // Once each: fronts from the geometry.
    let once = format!("{head}4\n1 3 2 2\n1 2 4 2\n1 4 3 2\n2 3 4 7\nEnd\n");
    let r = medit::parse_surface(once.as_bytes(), "a.mesh").unwrap();
    assert_eq!(r.side_labels.unwrap()[3], [7, FROM_GEOMETRY]);
    // The shared face twice, reversed: merged, both sides given.
    let twice = format!("{head}5\n1 3 2 2\n1 2 4 2\n1 4 3 2\n2 3 4 2\n2 4 3 5\nEnd\n");
    let r = medit::parse_surface(twice.as_bytes(), "b.mesh").unwrap();
    assert_eq!(r.mesh.triangles.len(), 4);
    assert_eq!(r.side_labels.unwrap()[3], [2, 5]);
    // A copy with the same orientation, or the same ref, is an error naming line and triangle.
    let same = format!("{head}5\n1 3 2 2\n1 2 4 2\n1 4 3 2\n2 3 4 2\n3 4 2 5\nEnd\n");
    let e = medit::parse_surface(same.as_bytes(), "c.mesh")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("c.mesh")
            && e.contains("triangle 4: repeats triangle 3 with the same orientation"),
        "{e}"
    );
    // Refs all equal carry no regions.
    let plain = format!("{head}4\n1 3 2 1\n1 2 4 1\n1 4 3 1\n2 3 4 1\nEnd\n");
    assert_eq!(
        medit::parse_surface(plain.as_bytes(), "d.mesh")
            .unwrap()
            .side_labels,
        None
    );
}

#[test]
fn vtu_side_labels_from_surface_nets_names_and_errors() {
    let m = labelled_tet();
    let mut b = Vec::new();
    biotet_io::vtu::write_surface(&mut b, &m, "s.vtu").unwrap();
    // VTK's SurfaceNets name for the same two-component array.
    let at = b.windows(12).position(|w| w == b"Name=\"sides\"").unwrap();
    let mut text = b[..at].to_vec();
    text.extend_from_slice(b"Name=\"BoundaryLabels\"");
    text.extend_from_slice(&b[at + 12..]);
    let r = biotet_io::vtu::parse_surface(&text, "n.vtu").unwrap();
    assert_eq!(r.side_labels, Some(m.sides.clone()));
    // A tet mesh is not a surface.
    let tet = biotet::TetMesh::new(m.points.clone(), vec![[0, 1, 2, 3]], vec![1]);
    let mut b = Vec::new();
    biotet_io::vtu::write_tet(&mut b, &tet, "t.vtu").unwrap();
    let e = biotet_io::vtu::parse_surface(&b, "t.vtu")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("t.vtu") && e.contains("cell 0") && e.contains("tet mesh"),
        "{e}"
    );
    assert_eq!(
        biotet_io::vtu::peek_kind(&b, "t.vtu").unwrap(),
        biotet_io::MeshKind::Tetrahedra
    );
}

#[test]
fn a_surface_without_labels_is_written_without_them() {
    // `sides` empty: the VTK formats write no `sides` array (read back: no side labels, every
    // triangle [1, 0]), PLY no label properties; with labels, they travel.
    let mut m = box_surface(2, 1.0);
    let labelled = m.clone();
    m.sides.clear();
    let dir = tempfile::tempdir().unwrap();
    for ext in ["vtu", "vtp", "vtk", "ply", "mesh", "off"] {
        let p = dir.path().join(format!("s.{ext}"));
        biotet_io::write_surface(&p, &m).unwrap();
        let r = biotet_io::read_surface(&p).unwrap();
        assert_eq!(r.side_labels, None, "{ext}");
        assert_same_surface(&r.mesh, &labelled, ext);
        if ext != "off" {
            let mut two = labelled.clone();
            two.sides[0] = [2, 1];
            biotet_io::write_surface(&p, &two).unwrap();
            let r = biotet_io::read_surface(&p).unwrap();
            let got = r.side_labels.expect(ext);
            assert_eq!(got[0][0], 2, "{ext}");
        }
    }
}

#[test]
fn medit_regions_on_their_own_copies_of_the_points_pair_their_interface() {
    // Two tets sharing the face (0,0,0) (1,0,0) (0,1,0): region 1 above it, region 2 below,
    // each written as its own outward boundary on its own four points (as a file concatenating
    // per-region exports has it). The shared face is one triangle with sides [1, 2] (or [2, 1]).
    let text = "MeshVersionFormatted 2\nDimension 3\nVertices\n8\n\
        0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n\
        0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 -1 0\n\
        Triangles\n8\n\
        1 3 2 1\n1 2 4 1\n1 4 3 1\n2 3 4 1\n\
        5 6 7 2\n5 8 6 2\n5 7 8 2\n6 8 7 2\nEnd\n";
    let r = medit::parse_surface(text.as_bytes(), "two.mesh").unwrap();
    assert_eq!(r.mesh.triangles.len(), 7);
    let sides = r.side_labels.unwrap();
    let shared: Vec<&[u32; 2]> = sides
        .iter()
        .filter(|s| !s.contains(&biotet::mesh::side_labels::FROM_GEOMETRY))
        .collect();
    assert_eq!(shared.len(), 1, "{sides:?}");
    let mut pair = *shared[0];
    pair.sort_unstable();
    assert_eq!(pair, [1, 2]);
}
