//! Tet mesh formats: round trips between every pair of formats, orientation repair, details.

use crate::common::{assert_same_tet, cube6, grid, moderate};
use biotet::TetMesh;
use biotet_io::{TetRead, TetgenOptions, VtuEncoding, gmsh, medit, tetgen, vtu};

/// Every tet writer variant, in memory.
#[derive(Debug, Clone, Copy)]
pub enum F {
    Vtu(VtuEncoding),
    Medit,
    Gmsh,
    GmshBinary,
    TetGen(bool),
}

pub const ALL: [F; 10] = [
    F::Vtu(VtuEncoding::Raw),
    F::Vtu(VtuEncoding::RawZlib),
    F::Vtu(VtuEncoding::Base64),
    F::Vtu(VtuEncoding::Base64Zlib),
    F::Vtu(VtuEncoding::Ascii),
    F::Medit,
    F::Gmsh,
    F::GmshBinary,
    F::TetGen(false),
    F::TetGen(true),
];

/// The file(s) of `m` in format `f`: one buffer, or node/ele/face for TetGen.
pub fn write(f: F, m: &TetMesh) -> Vec<Vec<u8>> {
    let mut a = Vec::new();
    match f {
        F::Vtu(e) => vtu::write_tet_with(&mut a, m, "m.vtu", e).unwrap(),
        F::Medit => medit::write_tet(&mut a, m, "m.mesh").unwrap(),
        F::Gmsh => gmsh::write_tet(&mut a, m, "m.msh").unwrap(),
        F::GmshBinary => gmsh::write_tet_binary(&mut a, m, "m.msh").unwrap(),
        F::TetGen(zero_based) => {
            let (mut b, mut c) = (Vec::new(), Vec::new());
            tetgen::write_tet(
                &mut a,
                &mut b,
                Some(&mut c),
                m,
                "m",
                TetgenOptions { zero_based },
            )
            .unwrap();
            return vec![a, b, c];
        }
    }
    vec![a]
}

pub fn read(f: F, files: &[Vec<u8>]) -> biotet_io::Result<TetRead> {
    match f {
        F::Vtu(_) => vtu::parse_tet(&files[0], "m.vtu"),
        F::Medit => medit::parse_tet(&files[0], "m.mesh"),
        F::Gmsh | F::GmshBinary => gmsh::parse_tet(&files[0], "m.msh"),
        F::TetGen(_) => tetgen::parse_tet(&files[0], &files[1], "m"),
    }
}

fn roundtrip_all_pairs(m: &TetMesh, name: &str) {
    for a in ALL {
        let ra = read(a, &write(a, m)).unwrap_or_else(|e| panic!("{name}: read {a:?}: {e}"));
        assert_eq!(ra.flipped, 0, "{name}: {a:?}");
        assert_eq!(ra.skipped_elements, 0);
        assert_same_tet(m, &ra.mesh, &format!("{name}: {a:?}"));
        for b in ALL {
            let rb =
                read(b, &write(b, &ra.mesh)).unwrap_or_else(|e| panic!("{name}: read {b:?}: {e}"));
            assert_same_tet(m, &rb.mesh, &format!("{name}: {a:?} -> {b:?}"));
            assert_eq!(
                rb.mesh.neighbors, m.neighbors,
                "{name}: {a:?} -> {b:?}: adjacency"
            );
        }
    }
}

#[test]
fn generator_is_positive() {
    let m = moderate();
    assert_eq!(m.tets.len(), 6000);
    let mut tets = m.tets.clone();
    for t in &mut tets {
        let c = [0, 1, 2, 3].map(|i| m.points[t[i] as usize]);
        assert_eq!(
            biotet::geom::predicates::orient3d(c[0], c[1], c[2], c[3]),
            biotet::geom::predicates::Sign::Positive
        );
    }
    assert_eq!(m.regions(), vec![1, 2, 3]);
}

#[test]
fn all_pairs_cube6() {
    roundtrip_all_pairs(&cube6(), "cube6");
}

#[test]
fn all_pairs_moderate() {
    roundtrip_all_pairs(&moderate(), "moderate");
}

#[test]
fn label_zero_and_large_labels_survive() {
    let mut m = grid(2, 0.5, 0.0, 0, |_| 0);
    for (t, l) in m.labels.iter_mut().enumerate() {
        *l = [0, 7, 1_000_000][t % 3];
    }
    for f in ALL {
        let r = read(f, &write(f, &m)).unwrap();
        assert_same_tet(&m, &r.mesh, &format!("{f:?}"));
    }
}

#[test]
fn empty_mesh_round_trips() {
    let m = TetMesh::new(vec![], vec![], vec![]);
    for f in ALL {
        let r = read(f, &write(f, &m)).unwrap_or_else(|e| panic!("{f:?}: {e}"));
        assert_eq!(r.mesh.tets.len(), 0);
        assert_eq!(r.mesh.points.len(), 0);
    }
}

#[test]
fn orphan_points_round_trip() {
    let mut m = cube6();
    m.points.push([9.0, 9.0, 9.0]);
    let m = TetMesh::new(m.points, m.tets, m.labels);
    for f in ALL {
        let r = read(f, &write(f, &m)).unwrap();
        assert_same_tet(&m, &r.mesh, &format!("{f:?}"));
    }
}

#[test]
fn negative_convention_is_flipped_and_mixed_orientation_kept_in_every_format() {
    let m = moderate();
    // A file written with the other convention: every tet negative.
    let mut other = m.clone();
    for t in other.tets.iter_mut() {
        t.swap(0, 1);
    }
    // A file with some inverted tets: they must reach the checker as they are.
    let mut mixed = m.clone();
    for t in mixed.tets.iter_mut().step_by(3) {
        t.swap(0, 1);
    }
    for f in ALL {
        let r = read(f, &write(f, &other)).unwrap();
        assert_eq!(r.flipped, m.tets.len(), "{f:?}");
        assert_eq!(r.degenerate, 0);
        // Fixed orientation: the same tets as the positive original, up to even permutation.
        assert_same_tet(&m, &r.mesh, &format!("{f:?}"));
        let r = read(f, &write(f, &mixed)).unwrap();
        assert_eq!(r.flipped, 0, "{f:?}");
        assert_same_tet(&mixed, &r.mesh, &format!("{f:?}"));
        let report = biotet::check::check(&r.mesh, None);
        assert_eq!(report.n_nonpositive, m.tets.len().div_ceil(3), "{f:?}");
    }
}

#[test]
fn degenerate_tets_are_counted() {
    let pts = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let m = TetMesh::new(pts, vec![[0, 1, 2, 4], [0, 1, 2, 3]], vec![1, 1]);
    let r = read(F::Medit, &write(F::Medit, &m)).unwrap();
    assert_eq!(r.degenerate, 1);
    assert_eq!(r.flipped, 0);
}

#[test]
fn vtu_has_quality_arrays_and_region() {
    let m = cube6();
    let text = String::from_utf8_lossy(&write(F::Vtu(VtuEncoding::Ascii), &m)[0]).into_owned();
    for name in [
        "region",
        "min_dihedral_deg",
        "min_solid_angle_sr",
        "q",
        "connectivity",
        "offsets",
        "types",
    ] {
        assert!(text.contains(&format!("Name=\"{name}\"")), "{name}");
    }
    assert!(text.contains("type=\"Int32\" Name=\"region\""));
    assert!(text.contains("type=\"Float64\" Name=\"q\""));
    // The q of a Kuhn tet of the unit cube, as TetMeasures computes it.
    let q = biotet::quality::tet::TetMeasures::of(&m.corners(0)).q;
    let mut b = ryu::Buffer::new();
    assert!(text.contains(b.format(q)), "q value {q} present");
}

#[test]
fn vtu_reads_other_label_names_and_cell_types() {
    // Hand-written ASCII VTU: one tet (reversed), one hexahedron (skipped), one triangle
    // (ignored), labels in "CellEntityIds", Float32 points, Int64 connectivity.
    let vtu = r#"<?xml version="1.0"?>
<!-- written by hand -->
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="9" NumberOfCells="3">
      <PointData></PointData>
      <Points>
        <DataArray type="Float32" NumberOfComponents="3" format="ascii">
          0 0 0  1 0 0  0 1 0  0 0 1
          0 0 2  1 0 2  1 1 2  0 1 2  0.5 0.5 3
        </DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="ascii">1 0 2 3  4 5 6 7 4 5 6 7  0 1 2</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">4 12 15</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">10 12 5</DataArray>
      </Cells>
      <CellData>
        <DataArray type="Float64" Name="whatever" format="ascii">0.5 0.5 0.5</DataArray>
        <DataArray type="Int32" Name="CellEntityIds" format="ascii">4 5 6</DataArray>
      </CellData>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"#;
    let r = vtu::parse_tet(vtu.as_bytes(), "hand.vtu").unwrap();
    assert_eq!(r.mesh.tets.len(), 1);
    assert_eq!(r.mesh.labels, vec![4]);
    assert_eq!(r.flipped, 1);
    assert_eq!(r.skipped_elements, 1);
    assert_eq!(r.mesh.points.len(), 9);
}

#[test]
fn vtu_big_endian_uint32_headers_and_appended_base64() {
    // Build a VTU by hand in the VTK 0.1 style: UInt32 headers, big endian, appended base64
    // with header and data encoded separately.
    let m = cube6();
    let enc = |bytes: Vec<u8>| {
        let mut h = (bytes.len() as u32).to_be_bytes().to_vec();
        let mut out = b64(&h);
        h.clear();
        out.push_str(&b64(&bytes));
        out
    };
    let pts: Vec<u8> = m
        .points
        .iter()
        .flatten()
        .flat_map(|x| x.to_be_bytes())
        .collect();
    let conn: Vec<u8> = m
        .tets
        .iter()
        .flatten()
        .flat_map(|&v| (v as i32).to_be_bytes())
        .collect();
    let offs: Vec<u8> = (1..=6i32).flat_map(|i| (4 * i).to_be_bytes()).collect();
    let types = vec![10u8; 6];
    let labs: Vec<u8> = m
        .labels
        .iter()
        .flat_map(|&l| (l as u16).to_be_bytes())
        .collect();
    let blocks = [enc(pts), enc(conn), enc(offs), enc(types), enc(labs)];
    let mut off = vec![0];
    for b in &blocks {
        off.push(off.last().unwrap() + b.len());
    }
    let vtu = format!(
        r#"<VTKFile type="UnstructuredGrid" version="0.1" byte_order="BigEndian">
<UnstructuredGrid><Piece NumberOfPoints="8" NumberOfCells="6">
<Points><DataArray type="Float64" NumberOfComponents="3" format="appended" offset="{}"/></Points>
<Cells>
<DataArray type="Int32" Name="connectivity" format="appended" offset="{}"/>
<DataArray type="Int32" Name="offsets" format="appended" offset="{}"/>
<DataArray type="UInt8" Name="types" format="appended" offset="{}"/>
</Cells>
<CellData><DataArray type="UInt16" Name="material" format="appended" offset="{}"/></CellData>
</Piece></UnstructuredGrid>
<AppendedData encoding="base64">
_{}
</AppendedData></VTKFile>"#,
        off[0],
        off[1],
        off[2],
        off[3],
        off[4],
        blocks.concat()
    );
    let r = vtu::parse_tet(vtu.as_bytes(), "be.vtu").unwrap();
    assert_same_tet(&m, &r.mesh, "big endian appended base64");
}

/// Standard base64 for the tests (independent of the crate's).
pub fn b64(data: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let v = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(v >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[test]
fn gmsh_22_ascii() {
    // Gmsh 2.2 with physical names, a triangle (ignored), a prism (skipped), sparse node tags,
    // elements out of order.
    let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n3 5 \"region_9\"\n3 6 \"white matter\"\n$EndPhysicalNames\n\
$Nodes\n5\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n50 1 1 1\n$EndNodes\n\
$Elements\n5\n7 4 2 6 1 10 20 30 40\n3 4 2 5 1 20 30 40 50\n4 2 2 1 1 10 20 30\n5 6 2 1 1 10 20 30 40 50 10\n6 4 0 10 30 20 40\n$EndElements\n";
    let r = gmsh::parse_tet(msh.as_bytes(), "old.msh").unwrap();
    assert_eq!(r.mesh.points.len(), 5);
    assert_eq!(r.mesh.tets.len(), 3);
    // Order by element tag: 3, 6, 7.
    assert_eq!(r.mesh.labels, vec![9, 1, 6]);
    assert_eq!(r.skipped_elements, 1);
    // Element 6 (10 30 20 40) is negative while the others are positive: an inverted element,
    // kept as it is for the checker rather than silently repaired.
    assert_eq!(r.flipped, 0);
    assert_eq!(biotet::check::check(&r.mesh, None).n_nonpositive, 1);
}

#[test]
fn gmsh_41_written_structure() {
    let m = moderate();
    let text = String::from_utf8(write(F::Gmsh, &m)[0].clone()).unwrap();
    assert!(text.starts_with("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n"));
    for name in [
        "\"region_1\"",
        "\"region_2\"",
        "\"region_3\"",
        "\"boundary_1_0\"",
        "\"boundary_2_0\"",
        "\"interface_1_2\"",
        "\"interface_1_3\"",
        "\"interface_2_3\"",
    ] {
        assert!(text.contains(name), "{name}");
    }
    // Entities: 0 points, 0 curves, 5 surfaces, 3 volumes.
    assert!(text.contains("$Entities\n0 0 5 3\n"));
    let nodes_hdr = text
        .split("$Nodes\n")
        .nth(1)
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .to_string();
    let f: Vec<usize> = nodes_hdr.split(' ').map(|x| x.parse().unwrap()).collect();
    assert_eq!(f[1], m.points.len());
    assert_eq!((f[2], f[3]), (1, m.points.len()));
}

#[test]
fn medit_triangles_are_boundary_and_interfaces() {
    let m = cube6();
    let text = String::from_utf8(write(F::Medit, &m)[0].clone()).unwrap();
    let tri = text.split("Triangles\n").nth(1).unwrap();
    let n: usize = tri.lines().next().unwrap().parse().unwrap();
    // 12 boundary triangles of the cube + interface faces between tets 0..3 and 3..6.
    let boundary = m.boundary_faces().count();
    assert_eq!(boundary, 12);
    let interfaces = (0..6)
        .flat_map(|t| (0..4).map(move |f| (t, f)))
        .filter(|&(t, f)| {
            let o = m.neighbors[t][f];
            o != biotet::NO_NEIGHBOR && m.labels[o as usize] > m.labels[t]
        })
        .count();
    assert!(interfaces > 0);
    assert_eq!(n, boundary + interfaces);
}

#[test]
fn tetgen_reads_quadratic_and_comments() {
    let node = "# comment\n5 3 1 1\n0 0 0 0 7 1\n1 1 0 0 7 1 # trailing\n2 0 1 0 7 1\n3 0 0 1 7 1\n4 1 1 1 7 0\n";
    let ele = "2 10 2\n\
0 0 1 2 3 0 0 0 0 0 0 4 9\n\
1 1 3 2 4 1 1 1 1 1 1 5.0 9\n";
    let r = tetgen::parse_tet(node.as_bytes(), ele.as_bytes(), "q").unwrap();
    assert_eq!(r.mesh.labels, vec![4, 5]);
    assert_eq!(r.mesh.tets[0], [0, 1, 2, 3]);
}

#[test]
fn paths_round_trip_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let m = moderate();
    for name in [
        "a.vtu", "a.mesh", "a.msh", "a.node", "b.ele", "c.1.node", "UP.VTU",
    ] {
        let p = dir.path().join(name);
        let written = biotet_io::write_tet_mesh(&p, &m).unwrap();
        let r = biotet_io::read_tet_mesh(&p).unwrap();
        assert_same_tet(&m, &r.mesh, name);
        for w in written {
            assert!(w.exists(), "{}", w.display());
        }
    }
    // Read TetGen by the .ele path too.
    let r = biotet_io::read_tet_mesh(&dir.path().join("a.ele")).unwrap();
    assert_same_tet(&m, &r.mesh, "a.ele");
    // Gmsh binary by explicit format, read back by extension.
    let p = dir.path().join("bin.msh");
    biotet_io::write_tet_mesh_as(&p, &m, biotet_io::TetFormat::GmshBinary).unwrap();
    assert_same_tet(&m, &biotet_io::read_tet_mesh(&p).unwrap().mesh, "bin.msh");
}
