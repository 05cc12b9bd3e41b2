//! PSLG readers (`.poly`, `.node`/`.edge`, 2D Medit with `Edges`) and the 2D VTU / Gmsh writers.

use biotet::TriMesh;
use biotet_io::poly::{parse_node_edge, parse_poly, write_poly};

const POLY: &str = "# a unit square with a hole and a region
# points numbered from 0, with one attribute and a marker
8 2 1 1
0 0 0 7 1
1 4 0 7 1
2 4 4 7 1
3 0 4 7 1
4 1 1 0 2
5 3 1 0 2
6 3 3 0 2
7 1 3 0 2
8 1
0 0 1 5
1 1 2 5
2 2 3 5
3 3 0 5
4 4 5 -2
5 5 6 -2
6 6 7 -2
7 7 4 -2
1
0 2 2
1
0 0.5 0.5 3 0.1
";

#[test]
fn poly_with_hole_and_region_reads_and_round_trips() {
    let r = parse_poly(POLY.as_bytes(), "sq.poly", None).unwrap();
    let g = &r.pslg;
    assert_eq!(g.points.len(), 8);
    assert_eq!(g.segments[4], [4, 5]);
    assert_eq!(g.segment_markers[4], -2);
    assert_eq!(g.holes, vec![[2.0, 2.0]]);
    assert_eq!(g.regions.len(), 1);
    assert_eq!(g.regions[0].label, 3);
    assert_eq!(g.validate(), Ok(()));
    let mut out = Vec::new();
    write_poly(&mut out, g, "x.poly").unwrap();
    let again = parse_poly(&out, "x.poly", None).unwrap();
    assert_eq!(&again.pslg, g);
}

#[test]
fn poly_errors_name_file_and_line() {
    let bad = POLY.replace("6 6 7 -2", "6 6 17 -2");
    let e = parse_poly(bad.as_bytes(), "sq.poly", None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("sq.poly: line 19") && e.contains("point index 17"),
        "{e}"
    );
    let e = parse_poly(b"4 3 0 0\n", "d.poly", None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("d.poly: line 1") && e.contains("dimension 3"),
        "{e}"
    );
    let e = parse_poly(b"0 2 0 0\n0 0\n", "n.poly", None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no .node file"), "{e}");
    let bad = POLY.replace("0 0.5 0.5 3 0.1", "0 0.5 0.5 0 0.1");
    let e = parse_poly(bad.as_bytes(), "sq.poly", None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("region label 0"), "{e}");
}

#[test]
fn node_edge_and_medit_edges_read_as_pslgs() {
    let node = "4 2 0 0\n1 0 0\n2 1 0\n3 1 1\n4 0 1\n";
    let edge = "4 1\n1 1 2 3\n2 2 3 3\n3 3 4 3\n4 4 1 3\n";
    let r = parse_node_edge(node.as_bytes(), "s.node", edge.as_bytes(), "s.edge").unwrap();
    assert_eq!(r.pslg.segments, vec![[0, 1], [1, 2], [2, 3], [3, 0]]);
    assert_eq!(r.pslg.segment_markers, vec![3; 4]);
    let medit = "MeshVersionFormatted 2\nDimension 2\nVertices\n4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\nEdges\n4\n1 2 5\n2 3 5\n3 4 5\n4 1 5\nEnd\n";
    let m = biotet_io::medit::parse_pslg(medit.as_bytes(), "s.mesh").unwrap();
    assert_eq!(m.pslg.points, r.pslg.points);
    assert_eq!(m.pslg.segments, r.pslg.segments);
    // A file on disk is recognised as a PSLG.
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("s.mesh");
    std::fs::write(&p, medit).unwrap();
    assert!(biotet_io::is_pslg(&p).unwrap());
    assert_eq!(biotet_io::read_pslg(&p).unwrap().pslg, m.pslg);
}

#[test]
fn two_d_vtu_and_msh_are_written_deterministically() {
    let m = TriMesh::new(
        vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        vec![[0, 1, 2], [0, 2, 3]],
        vec![1, 2],
    );
    let d = tempfile::tempdir().unwrap();
    for name in ["a.vtu", "a.msh"] {
        let p = d.path().join(name);
        biotet_io::write_tri_mesh(&p, &m).unwrap();
        let first = std::fs::read(&p).unwrap();
        biotet_io::write_tri_mesh(&p, &m).unwrap();
        assert_eq!(first, std::fs::read(&p).unwrap(), "{name}");
        let text = String::from_utf8(first).unwrap();
        if name.ends_with(".msh") {
            assert!(text.contains("\"interface_1_2\"") && text.contains("\"boundary_1_0\""));
            assert!(
                text.contains("$Elements\n7\n"),
                "4 boundary edges, 1 interface, 2 triangles: {text}"
            );
        } else {
            assert!(text.contains("NumberOfCells=\"2\"") && text.contains("Name=\"region\""));
        }
        assert!(biotet_io::read_tri_mesh(&p).is_err(), "written only");
    }
}
