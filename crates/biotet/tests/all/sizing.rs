//! Sizing functions: the surface-derived graded field, clamps and region overrides.

use crate::common::octahedron;
use biotet::sizing::{SizeSpec, Sizing, SizingOptions};

#[test]
fn surface_field_is_the_graded_cone_minimum() {
    let s = octahedron(10.0);
    let mut o = SizingOptions::new(SizeSpec::FromSurface { grading: 0.5 });
    o.min_size = Some(1.0);
    let z = Sizing::new(&s, o).unwrap();
    // Every edge is √200 ≈ 14.1, but each node faces the opposite one 20 away (less than twice
    // that): the size is capped at half the thickness, 10 (see `sizing::thickness`).
    let h = 10.0;
    assert!((z.at([10.0, 0.0, 0.0], 1) - h).abs() < 1e-12);
    // At the centre every node is 10 away: h + 0.5 * 10.
    assert!((z.at([0.0, 0.0, 0.0], 1) - (h + 5.0)).abs() < 1e-12);
    assert!((z.min_size() - h).abs() < 1e-12);
}

#[test]
fn clamps_and_region_overrides() {
    let s = octahedron(10.0);
    let mut o = SizingOptions::new(SizeSpec::FromSurface { grading: 1.0 });
    o.max_size = Some(15.0);
    o.region_sizes = vec![(2, 3.0)];
    let z = Sizing::new(&s, o).unwrap();
    assert_eq!(z.at([0.0, 0.0, 0.0], 1), 15.0);
    assert_eq!(z.at([0.0, 0.0, 0.0], 2), 3.0);
    assert_eq!(z.min_size(), 3.0);
    assert!(Sizing::uniform(0.0).is_err());
    assert!(Sizing::uniform(f64::NAN).is_err());
    assert_eq!(Sizing::uniform(2.0).unwrap().at([1e9, 0.0, 0.0], 0), 2.0);
}

/// A torus whose tube is a tenth as wide as its ring (trimesh's `torus(1, 0.05, 64, 12)`): the
/// mean edge length at its nodes (0.075) is wider than half the tube, the template's sealing
/// zones filled the whole cross-section, and every tet spanned the tube from wall to wall (441
/// under 10°, the flattest 2e-15°). Capped by the thickness, the sizes leave room for nodes on
/// the tube's axis.
#[test]
fn a_thin_tube_gets_interior_nodes_and_no_flat_tets() {
    use biotet::mesh::surface::SurfaceMesh;
    use biotet::pipeline::{PipelineOptions, mesh_surface};
    use biotet::quality::tet::min_dihedral_deg;
    let (major, minor, nu, nv) = (1.0f64, 0.05f64, 64u32, 12u32);
    let mut points = Vec::new();
    for i in 0..nu {
        let u = 2.0 * std::f64::consts::PI * f64::from(i) / f64::from(nu);
        for j in 0..nv {
            let v = 2.0 * std::f64::consts::PI * f64::from(j) / f64::from(nv);
            let r = major + minor * v.cos();
            points.push([r * u.cos(), r * u.sin(), minor * v.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % nu) * nv + (j % nv);
    let mut triangles = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    let mut s = SurfaceMesh::closed(points, triangles, 1);
    let v = biotet::mesh::validate::validate_surface(&mut s, &Default::default());
    assert!(!v.expect("a valid torus").flipped_inward);
    let sizing = crate::common::default_sizing(&s);
    // At a node: at most half the tube's width (the wall facing it is a diameter away).
    assert!(sizing.at(s.points[0], 1) <= minor * 1.001);
    let (m, report) = mesh_surface(&s, &sizing, &PipelineOptions::default(), &mut |_| {}).unwrap();
    assert!(report.n_interior_nodes > 0, "no node inside the tube");
    assert!(biotet::check::check(&m, Some(&s)).valid);
    let worst = m
        .tets
        .iter()
        .map(|t| min_dihedral_deg(&t.map(|v| m.points[v as usize])))
        .fold(f64::INFINITY, f64::min);
    assert!(worst >= 10.0, "smallest dihedral angle {worst}°");
}

/// `--size H` coarser than a CAD part's triangles (gmsh's component8, 13,296 triangles, at a
/// fifth of its diagonal): as a uniform size it placed no interior node, sliver removal and
/// polishing then worked 7 s on the flat tets left and 635 stayed under 10°. Capped near the
/// surface by the surface's own edges and graded up to H, the part meshes as its default size
/// does; an H at or under the median surface size is exactly uniform.
#[test]
fn a_size_coarser_than_the_surface_grades_up_from_it() {
    use biotet::pipeline::{PipelineOptions, mesh_surface};
    use biotet::quality::tet::min_dihedral_deg;
    let s = crate::common::load_shape("cad_component8.off");
    let h = 11.75;
    let z = Sizing::new(
        &s,
        SizingOptions::new(SizeSpec::UpTo {
            size: h,
            grading: 0.3,
        }),
    )
    .unwrap();
    let node = s.points[s.triangles[0][0] as usize];
    assert!(z.at(node, 1) < 2.0, "{} at a surface node", z.at(node, 1));
    assert!(z.at(node, 1) <= z.at([1e6, 1e6, 1e6], 1));
    assert_eq!(z.at([1e6, 1e6, 1e6], 1), h);
    let (m, report) = mesh_surface(&s, &z, &PipelineOptions::default(), &mut |_| {}).unwrap();
    assert!(report.n_interior_nodes > 0);
    assert!(biotet::check::check(&m, Some(&s)).valid);
    let under_10 = m
        .tets
        .iter()
        .filter(|t| min_dihedral_deg(&t.map(|v| m.points[v as usize])) < 10.0)
        .count();
    assert!(under_10 <= 100, "{under_10} tets under 10°");
    // Finer than the surface: uniform.
    let fine = Sizing::new(
        &s,
        SizingOptions::new(SizeSpec::UpTo {
            size: 0.2,
            grading: 0.3,
        }),
    );
    for p in [node, [0.0; 3], [1e6, 1e6, 1e6]] {
        assert_eq!(fine.as_ref().unwrap().at(p, 1), 0.2);
    }
}
