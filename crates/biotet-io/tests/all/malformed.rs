//! Malformed input: every reader, fed truncated, mutated and garbage data, returns an error (or
//! a mesh) but never panics; error messages name the file, the place and the reason.

use crate::common::{Rng, box_surface, cube6, tri_grid};
use crate::tet::{self, F};
use biotet_io::{TetgenOptions, VtuEncoding, gmsh, medit, obj, off, ply, stl, tetgen, vtu};

type Parser = Box<dyn Fn(&[u8]) -> bool>;

/// (name, a valid file, a parser returning whether it succeeded, whether every strict prefix
/// must fail)
fn cases() -> Vec<(String, Vec<u8>, Parser, bool)> {
    let s = box_surface(1, 1.0);
    let t = cube6();
    let tri = tri_grid(2, 0.1);
    let mut v: Vec<(String, Vec<u8>, Parser, bool)> = Vec::new();
    let mut b = Vec::new();
    stl::write_binary(&mut b, &s, "x").unwrap();
    v.push((
        "stl binary".into(),
        b,
        Box::new(|d| stl::parse(d, "x.stl").is_ok()),
        true,
    ));
    let mut b = Vec::new();
    stl::write_ascii(&mut b, &s, "x").unwrap();
    v.push((
        "stl ascii".into(),
        b,
        Box::new(|d| stl::parse(d, "x.stl").is_ok()),
        false,
    ));
    let mut b = Vec::new();
    obj::write(&mut b, &s, "x").unwrap();
    v.push((
        "obj".into(),
        b,
        Box::new(|d| obj::parse(d, "x.obj").is_ok()),
        false,
    ));
    let mut b = Vec::new();
    off::write(&mut b, &s, "x").unwrap();
    v.push((
        "off".into(),
        b,
        Box::new(|d| off::parse(d, "x.off").is_ok()),
        false,
    ));
    let mut b = Vec::new();
    ply::write_binary(&mut b, &s, "x").unwrap();
    v.push((
        "ply binary".into(),
        b,
        Box::new(|d| ply::parse(d, "x.ply").is_ok()),
        true,
    ));
    let mut b = Vec::new();
    ply::write_ascii(&mut b, &s, "x").unwrap();
    v.push((
        "ply ascii".into(),
        b,
        Box::new(|d| ply::parse(d, "x.ply").is_ok()),
        false,
    ));
    let mut b = Vec::new();
    medit::write_surface(&mut b, &s, "x").unwrap();
    v.push((
        "medit surface".into(),
        b,
        Box::new(|d| medit::parse_surface(d, "x.mesh").is_ok()),
        false,
    ));
    let mut b = Vec::new();
    medit::write_tri(&mut b, &tri, "x").unwrap();
    v.push((
        "medit 2d".into(),
        b,
        Box::new(|d| medit::parse_tri(d, "x.mesh").is_ok()),
        false,
    ));
    for f in tet::ALL {
        let files = tet::write(f, &t);
        match f {
            F::TetGen(_) => {
                let (node, ele) = (files[0].clone(), files[1].clone());
                let e2 = ele.clone();
                v.push((
                    format!("{f:?} node"),
                    node.clone(),
                    Box::new(move |d| tetgen::parse_tet(d, &e2, "x").is_ok()),
                    false,
                ));
                v.push((
                    format!("{f:?} ele"),
                    ele,
                    Box::new(move |d| tetgen::parse_tet(&node, d, "x").is_ok()),
                    false,
                ));
            }
            _ => {
                let strict = matches!(f, F::GmshBinary);
                v.push((
                    format!("{f:?}"),
                    files[0].clone(),
                    Box::new(move |d| tet::read(f, &[d.to_vec()]).is_ok()),
                    strict,
                ));
            }
        }
    }
    let (mut a, mut b) = (Vec::new(), Vec::new());
    tetgen::write_tri(&mut a, &mut b, &tri, "x", TetgenOptions::default()).unwrap();
    let b2 = b.clone();
    v.push((
        "triangle node".into(),
        a.clone(),
        Box::new(move |d| tetgen::parse_tri(d, &b2, "x").is_ok()),
        false,
    ));
    v.push((
        "triangle ele".into(),
        b,
        Box::new(move |d| tetgen::parse_tri(&a, d, "x").is_ok()),
        false,
    ));
    let g22 = b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 2 1 1 1 2 3 4\n$EndElements\n".to_vec();
    v.push((
        "gmsh 2.2".into(),
        g22,
        Box::new(|d| gmsh::parse_tet(d, "x.msh").is_ok()),
        false,
    ));
    v
}

fn cuts(len: usize) -> Vec<usize> {
    if len <= 3000 {
        (0..len).collect()
    } else {
        let mut c: Vec<usize> = (0..300).map(|i| i * len / 300).collect();
        c.extend(len.saturating_sub(100)..len);
        c
    }
}

#[test]
fn valid_inputs_parse() {
    for (name, data, parse, _) in cases() {
        assert!(parse(&data), "{name}");
    }
}

#[test]
fn truncated_inputs_never_panic() {
    for (name, data, parse, strict) in cases() {
        for cut in cuts(data.len()) {
            let ok = parse(&data[..cut]);
            if strict && !(cut + 1 == data.len() && data[cut] == b'\n') {
                // Binary formats: any strict prefix that cuts into the data is an error.
                assert!(!ok, "{name}: prefix of {cut}/{} bytes parsed", data.len());
            }
        }
    }
}

#[test]
fn mutated_inputs_never_panic() {
    let mut rng = Rng(42);
    let alphabet = b"0123456789-+.eE \n\t#$/_<>\"=nainfNAN";
    for (_, data, parse, _) in cases() {
        for k in 0..400 {
            let mut d = data.clone();
            let n = 1 + (rng.next_u64() % 4) as usize;
            for _ in 0..n {
                let i = (rng.next_u64() as usize) % d.len();
                d[i] = if k % 2 == 0 {
                    rng.next_u64() as u8
                } else {
                    alphabet[(rng.next_u64() as usize) % alphabet.len()]
                };
            }
            if k % 7 == 0 {
                let i = (rng.next_u64() as usize) % d.len();
                d.remove(i);
            }
            let _ = parse(&d);
        }
    }
}

#[test]
fn garbage_inputs_never_panic() {
    let mut rng = Rng(7);
    let mut inputs: Vec<Vec<u8>> = vec![
        vec![],
        b"\n".to_vec(),
        b"solid".to_vec(),
        b"ply\n".to_vec(),
        b"$MeshFormat".to_vec(),
    ];
    for len in [1, 3, 10, 83, 84, 100, 134, 1000, 20000] {
        inputs.push((0..len).map(|_| rng.next_u64() as u8).collect());
        inputs.push(
            (0..len)
                .map(|_| b"0123456789 \n-."[(rng.next_u64() % 14) as usize])
                .collect(),
        );
    }
    // Headers announcing absurd counts.
    inputs.push(b"OFF\n999999999999999 3 0\n0 0 0\n".to_vec());
    inputs.push(
        b"MeshVersionFormatted 2\nDimension 3\nVertices\n99999999999999999\n0 0 0 0\n".to_vec(),
    );
    inputs.push(b"MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 0 0 0\nTetrahedra 18446744073709551615\n1 1 1 1 1\n".to_vec());
    inputs.push(b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 99999999999999 1 1\n2 1 0 9999999999999\n".to_vec());
    let mut bin = b"$MeshFormat\n4.1 1 8\n".to_vec();
    bin.extend_from_slice(&1i32.to_le_bytes());
    bin.extend_from_slice(b"\n$EndMeshFormat\n$Nodes\n");
    bin.extend_from_slice(&[0xff; 64]);
    inputs.push(bin);
    inputs.push(b"ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n".to_vec());
    inputs.push(b"ply\nformat binary_little_endian 1.0\nelement nothing 4000000000\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n".to_vec());
    inputs.push(b"4000000000 3 0 0\n1 0 0 0\n".to_vec());
    // Counts at the integer limits (overflow checks).
    inputs.push(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n18446744073709551615 0 1 2\n".to_vec());
    inputs.push(b"4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n".to_vec());
    inputs.push(b"1 4 18446744073709551615\n1 1 2 3 4 1\n".to_vec());
    inputs.push(b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n1\n1 4 18446744073709551615 1 1 1 1\n$EndElements\n".to_vec());
    inputs.push(
        b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n18446744073709551615 0 0 0\n".to_vec(),
    );
    inputs.push(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n0 0 0\n4294967295 0 0 0\n".to_vec());
    let mut stl = vec![b' '; 80];
    stl.extend_from_slice(&u32::MAX.to_le_bytes());
    inputs.push(stl);
    inputs.push(br#"<VTKFile type="UnstructuredGrid" header_type="UInt64" compressor="vtkZLibDataCompressor"><UnstructuredGrid><Piece NumberOfPoints="99999999999" NumberOfCells="99999999999"><Points><DataArray type="Float64" NumberOfComponents="3" format="binary">AAAAAAAAAAA=</DataArray></Points></Piece></UnstructuredGrid></VTKFile>"#.to_vec());
    inputs.push(br#"<VTKFile type="UnstructuredGrid"><UnstructuredGrid><Piece NumberOfPoints="1" NumberOfCells="1"><Points><DataArray type="Float64" NumberOfComponents="3" format="appended" offset="999999999999"/></Points></Piece></UnstructuredGrid><AppendedData encoding="raw">_</AppendedData></VTKFile>"#.to_vec());
    for d in &inputs {
        let _ = stl::parse(d, "g");
        let _ = obj::parse(d, "g");
        let _ = off::parse(d, "g");
        let _ = ply::parse(d, "g");
        let _ = medit::parse_surface(d, "g");
        let _ = medit::parse_tet(d, "g");
        let _ = medit::parse_tri(d, "g");
        let _ = gmsh::parse_tet(d, "g");
        let _ = vtu::parse_tet(d, "g");
        let _ = tetgen::parse_tet(d, d, "g");
        let _ = tetgen::parse_tet(b"4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", d, "g");
        let _ = tetgen::parse_tri(d, d, "g");
        let _ = medit::peek_kind(&d[..], "g");
        let _ = tetgen::peek_dim(&d[..], "g");
    }
}

#[test]
fn vtu_raw_truncated_in_data_is_an_error() {
    let d = tet::write(F::Vtu(VtuEncoding::Raw), &cube6()).remove(0);
    let tag = d.windows(13).position(|w| w == b"<AppendedData").unwrap();
    let us = tag + d[tag..].iter().position(|&c| c == b'_').unwrap();
    // The reader needs every array up to `region` (the quality arrays after it are not read).
    let text = String::from_utf8_lossy(&d).into_owned();
    let key = "Name=\"min_dihedral_deg\" format=\"appended\" offset=\"";
    let at = text.find(key).unwrap() + key.len();
    let off: usize = text[at..].split('"').next().unwrap().parse().unwrap();
    for cut in us..us + 1 + off {
        assert!(vtu::parse_tet(&d[..cut], "x.vtu").is_err(), "cut {cut}");
    }
}

fn err(r: Result<impl std::fmt::Debug, biotet_io::Error>) -> String {
    r.expect_err("should fail").to_string()
}

#[test]
fn messages_name_file_place_and_reason() {
    let e = err(off::parse(
        b"OFF\n3 1 0\n0 0 0\n1 0 0\n1 2\n3 0 1 2\n",
        "x.off",
    ));
    assert_eq!(e, "x.off: line 5: expected 3 coordinates, got 2");
    let e = err(off::parse(
        b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 12\n",
        "x.off",
    ));
    assert_eq!(
        e,
        "x.off: line 6: vertex index 12 out of range (3 vertices)"
    );
    let e = err(off::parse(
        b"OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n",
        "x.off",
    ));
    assert_eq!(e, "x.off: line 4: non-finite coordinate 'nan'");
    let e = err(obj::parse(
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n",
        "brain.obj",
    ));
    assert_eq!(
        e,
        "brain.obj: line 4: vertex index 99 out of range (3 vertices)"
    );
    let e = err(obj::parse(b"v 0 0 0\nf 1 -5 1\n", "r.obj"));
    assert!(
        e.starts_with("r.obj: line 2: relative vertex index -5"),
        "{e}"
    );
    let e = err(obj::parse(b"v 0 0 inf\n", "i.obj"));
    assert_eq!(e, "i.obj: line 1: non-finite coordinate 'inf'");
    // Binary STL: truncated, non-finite.
    let mut b = Vec::new();
    stl::write_binary(&mut b, &box_surface(1, 1.0), "x").unwrap();
    let e = err(stl::parse(&b[..b.len() - 10], "brain.stl"));
    assert!(e.starts_with("brain.stl: truncated file: header announces 12 triangles (684 bytes), file has 674 bytes"), "{e}");
    b[84 + 50 * 3 + 12..84 + 50 * 3 + 16].copy_from_slice(&f32::NAN.to_le_bytes());
    let e = err(stl::parse(&b, "n.stl"));
    assert!(
        e.starts_with("n.stl: triangle 3: non-finite coordinate"),
        "{e}"
    );
    let e = err(stl::parse(b"solid x\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n", "q.stl"));
    assert_eq!(e, "q.stl: line 7: facet with 2 vertices, expected 3");
    // Medit.
    let e = err(medit::parse_tet(b"MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 0 0 0\nTetrahedra\n1\n1 1 1 2 3\nEnd\n", "m.mesh"));
    assert_eq!(
        e,
        "m.mesh: line 8: vertex index 2 out of range (1 vertices)"
    );
    let e = err(medit::parse_tet(b"MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\nTetrahedra\n1\n1 2 3 4 -1\nEnd\n", "m.mesh"));
    assert_eq!(
        e,
        "m.mesh: line 11: region label -1 is not in 0..=2147483647"
    );
    // Gmsh.
    let g = b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n1\n1 4 0 1 2 3 99\n$EndElements\n";
    let e = err(gmsh::parse_tet(g, "g.msh"));
    assert_eq!(e, "g.msh: tet 0: node tag 2 not in $Nodes (element tag 1)");
    let e = err(gmsh::parse_tet(b"$MeshFormat\n2.2 1 8\n", "b.msh"));
    assert!(e.contains("Gmsh 2.2 binary files are not supported"), "{e}");
    // TetGen.
    let e = err(tetgen::parse_tet(
        b"4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n",
        b"1 4 1\n1 1 2 3 5 1\n",
        "t",
    ));
    assert_eq!(
        e,
        "t.ele: line 2: point index 5 out of range (4 points numbered from 1)"
    );
    let e = err(tetgen::parse_tet(
        b"2 3 0 0\n0 0 0 0\n2 1 0 0\n",
        b"0 4 0\n",
        "t",
    ));
    assert_eq!(
        e,
        "t.node: line 3: point index 2 out of sequence (expected 1)"
    );
    let e = err(tetgen::parse_tet(b"1 3 0 0\n1 0 0\n", b"0 4 0\n", "t"));
    assert_eq!(e, "t.node: line 2: expected 3 coordinates, got 2");
    // PLY.
    let e = err(ply::parse(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n3 0 0 7\n", "p.ply"));
    assert_eq!(
        e,
        "p.ply: line 11: vertex index 7 out of range (1 vertices)"
    );
    // VTU.
    let e = err(vtu::parse_tet(
        br#"<VTKFile type="PolyData"></VTKFile>"#,
        "p.vtu",
    ));
    assert_eq!(
        e,
        "p.vtu: line 1: VTK file type 'PolyData': only UnstructuredGrid (.vtu) is read"
    );
    // Writers reject bad meshes.
    let mut m = cube6();
    m.points[3][1] = f64::NAN;
    let e = err(medit::write_tet(Vec::new(), &m, "w.mesh"));
    assert!(
        e.starts_with("w.mesh: cannot write: point 3 has a non-finite coordinate"),
        "{e}"
    );
}
