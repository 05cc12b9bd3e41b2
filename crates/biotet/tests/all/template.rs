//! Node deployment (chapter 2): the exact inside test, the template, the deployed nodes and the
//! pipeline's output.

use crate::common::{cube_surface, load_stl, octahedron, point_triangle_distance};
use biotet::SurfaceMesh;
use biotet::check::check;
use biotet::mesh::inside::{Location, RegionLocator};
use biotet::pipeline::{PipelineOptions, mesh_surface};
use biotet::quality::tet::volume;
use biotet::sizing::Sizing;
use biotet::template::voxels::Template;
use biotet::template::{DeployOptions, Zone, classify::classify, deploy};

/// Dyadic coordinates from -1.5 to 1.5 by 0.25: they hit vertices, edges and faces exactly.
fn dyadic() -> Vec<f64> {
    (-6..=6).map(|i| i as f64 * 0.25).collect()
}

#[test]
fn inside_cube_with_rays_through_vertices_and_edges() {
    // [0,1]^3: queries with y, z in {0, 0.5, 1} send rays through vertices, along edges and
    // across the diagonals of the triangulated faces.
    let s = cube_surface([0.0; 3], 1.0);
    let loc = RegionLocator::new(&s);
    let (mut inside, mut on) = (0, 0);
    for &x in &dyadic() {
        for &y in &dyadic() {
            for &z in &dyadic() {
                let p = [x, y, z];
                let strictly = p.iter().all(|&c| c > 0.0 && c < 1.0);
                let closed = p.iter().all(|&c| (0.0..=1.0).contains(&c));
                let expect = if strictly {
                    Location::Region(1)
                } else if closed {
                    Location::OnSurface
                } else {
                    Location::Region(0)
                };
                assert_eq!(loc.locate(p), expect, "{p:?}");
                inside += usize::from(strictly);
                on += usize::from(closed && !strictly);
            }
        }
    }
    assert_eq!(inside, 27);
    assert_eq!(on, 125 - 27);
}

#[test]
fn inside_octahedron_with_rays_through_vertices_and_edges() {
    let s = octahedron(1.0);
    let loc = RegionLocator::new(&s);
    for &x in &dyadic() {
        for &y in &dyadic() {
            for &z in &dyadic() {
                let p = [x, y, z];
                let l1 = x.abs() + y.abs() + z.abs(); // exact for these dyadic values
                let expect = if l1 < 1.0 {
                    Location::Region(1)
                } else if l1 == 1.0 {
                    Location::OnSurface
                } else {
                    Location::Region(0)
                };
                assert_eq!(loc.locate(p), expect, "{p:?}");
            }
        }
    }
}

#[test]
fn inside_nested_shells_gives_regions() {
    // An outer cube [0,4]^3 (region 1) around an inner cube [1,3]^3 (region 2).
    let mut s = cube_surface([0.0; 3], 4.0);
    let inner = cube_surface([1.0; 3], 2.0);
    let base = s.points.len() as u32;
    s.points.extend(&inner.points);
    s.triangles
        .extend(inner.triangles.iter().map(|t| t.map(|v| v + base)));
    s.sides.extend(inner.triangles.iter().map(|_| [2, 1]));
    let loc = RegionLocator::new(&s);
    for i in -1..=9 {
        for j in -1..=9 {
            for k in -1..=9 {
                let p = [i, j, k].map(|c| c as f64 * 0.5);
                let inside = |lo: f64, hi: f64| p.iter().all(|&c| c > lo && c < hi);
                let closed = |lo: f64, hi: f64| p.iter().all(|&c| c >= lo && c <= hi);
                let expect = if inside(1.0, 3.0) {
                    Location::Region(2)
                } else if closed(1.0, 3.0) || (closed(0.0, 4.0) && !inside(0.0, 4.0)) {
                    Location::OnSurface
                } else if inside(0.0, 4.0) {
                    Location::Region(1)
                } else {
                    Location::Region(0)
                };
                assert_eq!(loc.locate(p), expect, "{p:?}");
            }
        }
    }
}

/// The template's row classification agrees with the point locator voxel by voxel.
fn classification_agrees(s: &SurfaceMesh, dx: f64, origin: [f64; 3], n: [usize; 3], step: usize) {
    let mut t = Template::new(n, origin, dx);
    let c = classify(&mut t, s);
    let loc = RegionLocator::new(s);
    let mut on = 0;
    for idx in (0..t.cells.len()).step_by(step) {
        let p = t.point(t.ijk(idx));
        match loc.locate(p) {
            Location::OnSurface => {
                on += 1;
                assert_eq!(t.state(idx), biotet::template::voxels::BUFFER, "{p:?}");
            }
            Location::Region(r) => assert_eq!(t.region(idx), r, "{p:?}"),
        }
    }
    if step == 1 {
        assert_eq!(on, c.on_surface);
    }
}

#[test]
fn template_classification_is_exact_on_degenerate_grids() {
    // Voxel centres on the cube's vertices, edges and face diagonals.
    classification_agrees(&cube_surface([0.0; 3], 1.0), 0.25, [-0.5; 3], [9, 9, 9], 1);
    classification_agrees(&octahedron(1.0), 0.25, [-1.5; 3], [13, 13, 13], 1);
    classification_agrees(&octahedron(1.0), 0.125, [-1.25; 3], [21, 21, 21], 1);
}

#[test]
fn template_classification_matches_on_the_brain() {
    let s = load_stl("brain_20k.stl");
    let dx = 1.7;
    let n = [90, 110, 95];
    classification_agrees(&s, dx, [-75.0, -110.0, -74.0], n, 7);
}

/// Nearest other node of each interior node, brute force on a small set.
fn nearest(points: &[[f64; 3]], from: usize) -> Vec<f64> {
    (from..points.len())
        .map(|i| {
            points
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(_, q)| biotet::geom::vec3::norm(biotet::geom::vec3::sub(points[i], *q)))
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}

/// Deploy at uniform size `h` and check spacing and clearance; returns (min, max) nearest
/// distance over h and the smallest clearance to the surface over h.
fn spacing_and_clearance(s: &SurfaceMesh, h: f64, zone: Zone) -> (f64, f64, f64) {
    let sizing = Sizing::uniform(h).unwrap();
    let opts = DeployOptions {
        zone,
        ..DeployOptions::default()
    };
    let d = deploy(s, &sizing, &opts).unwrap();
    assert!(d.stats.interior_nodes > 50, "{:?}", d.stats);
    assert_eq!(d.points.len(), d.n_surface + d.stats.interior_nodes);
    let loc = RegionLocator::new(s);
    for p in &d.points[d.n_surface..] {
        assert_eq!(
            loc.locate(*p),
            Location::Region(1),
            "interior node outside: {p:?}"
        );
    }
    // Interior nodes among themselves: at least h apart (the zone is every voxel closer than
    // h), and each has a neighbour (interior or surface) closer than 2h.
    let interior = &d.points[d.n_surface..];
    let nn_interior = nearest(interior, 0);
    let nn_all = nearest(&d.points, d.n_surface);
    let lo = nn_interior.iter().copied().fold(f64::INFINITY, f64::min) / h;
    let hi = nn_all.iter().copied().fold(0.0, f64::max) / h;
    let clearance = interior
        .iter()
        .map(|p| {
            (0..s.triangles.len())
                .map(|t| point_triangle_distance(*p, s.corners(t)))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(f64::INFINITY, f64::min)
        / h;
    (lo, hi, clearance)
}

#[test]
fn sphere_and_cube_spacing_and_clearance() {
    // A sphere whose triangles match the size, and a cube of 12 triangles far larger than the
    // size (every one sealed by a prism).
    let sphere = SurfaceMesh::icosphere(10.0, 3); // edges about 1.9
    let cube = cube_surface([0.0; 3], 12.0);
    for zone in [Zone::Euclidean, Zone::Box] {
        for (s, h) in [(&sphere, 2.0), (&cube, 1.5)] {
            let (lo, hi, clearance) = spacing_and_clearance(s, h, zone);
            eprintln!(
                "{zone:?} h={h}: nearest interior ≥ {lo:.3}h, nearest node ≤ {hi:.3}h, clearance ≥ {clearance:.3}h"
            );
            // Stated band: nearest interior neighbour at least h (the zone is every voxel closer
            // than h; 1e-9 for the float voxel coordinates), nearest node within 1.5h (an
            // unclaimed voxel would have become a node: 2h is the bound in theory, 1.12h the
            // measured value); no interior node within 0.75h of the surface (√(2/3)h = 0.82h is
            // the prism height, and a surface node's zone is centred on its nearest voxel, up
            // to √3/2·dx off; measured 0.84h).
            assert!(lo >= 1.0 - 1e-9, "{zone:?} h={h}: nearest interior {lo}·h");
            assert!(hi <= 1.5, "{zone:?} h={h}: nearest node {hi}·h");
            assert!(clearance >= 0.75, "{zone:?} h={h}: clearance {clearance}·h");
        }
    }
}

#[test]
fn deployment_is_deterministic_and_template_is_two_bytes_per_voxel() {
    let s = SurfaceMesh::icosphere(10.0, 2);
    let sizing = Sizing::uniform(1.5).unwrap();
    let a = deploy(&s, &sizing, &DeployOptions::default()).unwrap();
    let b = deploy(&s, &sizing, &DeployOptions::default()).unwrap();
    assert_eq!(a.points, b.points);
    let st = &a.stats;
    assert_eq!(st.voxels, st.dims[0] * st.dims[1] * st.dims[2]);
    assert_eq!(st.bytes, 2 * st.voxels);
    assert!((st.dx - 0.75).abs() < 1e-15);
    // Too fine a template is refused with a clear error, not attempted.
    let tiny = Sizing::uniform(1e-4).unwrap();
    let e = deploy(&s, &tiny, &DeployOptions::default()).unwrap_err();
    assert!(e.to_string().contains("voxels"), "{e}");
}

#[test]
fn pipeline_on_the_brain_keeps_the_inside() {
    let s = load_stl("brain_20k.stl");
    let sizing = crate::common::default_sizing(&s);
    let (mesh, report) =
        mesh_surface(&s, &sizing, &PipelineOptions::deploy_only(), &mut |_| {}).unwrap();
    let c = check(&mesh, None);
    assert!(
        c.n_nonpositive == 0 && c.n_overshared_faces == 0 && c.n_adjacency_errors == 0,
        "{c:?}"
    );
    assert!(c.n_unused_points == 0 && c.n_duplicate_points == 0, "{c:?}");
    // Surface points come first, unchanged.
    assert_eq!(&mesh.points[..s.points.len()], &s.points[..]);
    assert!(mesh.labels.iter().all(|&l| l == 1));
    assert!(report.n_interior_nodes > 1000);
    assert_eq!(report.n_tets, mesh.tets.len());
    // The count of missing triangles agrees with the checker's.
    let cs = check(&mesh, Some(&s));
    let conf = cs.surface.expect("surface conformity");
    assert_eq!(
        conf.n_missing + conf.n_points_missing,
        report.missing_triangles
    );
    // Before recovery the kept volume approximates the enclosed one.
    let v: f64 = (0..mesh.tets.len()).map(|t| volume(&mesh.corners(t))).sum();
    let enclosed = 1_659_213.0;
    assert!((v - enclosed).abs() / enclosed < 0.02, "volume {v}");
}

/// The smallest sphere through a triangle's corners (centre in its plane), and its radius.
fn circumsphere(p: [[f64; 3]; 3]) -> ([f64; 3], f64) {
    use biotet::geom::vec3::{add, cross, dot, norm, scale, sub};
    let (a, b) = (sub(p[1], p[0]), sub(p[2], p[0]));
    let n = cross(a, b);
    let r = scale(
        add(scale(cross(b, n), dot(a, a)), scale(cross(n, a), dot(b, b))),
        0.5 / dot(n, n),
    );
    (add(p[0], r), norm(r))
}

#[test]
fn size_finer_than_the_surface_keeps_nodes_out_of_triangle_circumspheres() {
    // Triangles of edge about 3.9 at size 1: each is sealed, and no interior node may sit in
    // its smallest circumsphere (else the triangle is not Delaunay and recovery must dig). A
    // node set outside every such sphere still fills the ball (the spheres reach only about
    // 2.3 inward).
    let s = SurfaceMesh::icosphere(10.0, 2);
    let d = deploy(
        &s,
        &Sizing::uniform(1.0).unwrap(),
        &DeployOptions::default(),
    )
    .unwrap();
    assert!(
        d.stats.sealed_triangles == s.triangles.len(),
        "{:?}",
        d.stats
    );
    assert!(d.stats.interior_nodes > 1000, "{:?}", d.stats);
    for t in 0..s.triangles.len() {
        let (c, r) = circumsphere(s.corners(t));
        for p in &d.points[d.n_surface..] {
            let dist = biotet::geom::vec3::norm(biotet::geom::vec3::sub(*p, c));
            assert!(
                dist >= r,
                "node {p:?} inside the circumsphere of triangle {t}"
            );
        }
    }
    // So the Delaunay tetrahedralization already has every triangle, and the pipeline's mesh is
    // valid with no Steiner point.
    let sizing = Sizing::uniform(1.0).unwrap();
    let (_, before) =
        mesh_surface(&s, &sizing, &PipelineOptions::deploy_only(), &mut |_| {}).unwrap();
    let (mesh, report) =
        mesh_surface(&s, &sizing, &PipelineOptions::default(), &mut |_| {}).unwrap();
    eprintln!("missing before recovery: {}", before.missing_triangles);
    assert_eq!(before.missing_triangles, 0);
    let c = check(&mesh, Some(&s));
    assert!(c.valid, "{:?}", c.problems);
    assert_eq!(report.recover.as_ref().unwrap().steiner_points, 0);
}

#[test]
fn a_cube_at_a_size_far_finer_than_its_faces_meshes() {
    // Twelve triangles of circumradius 0.71 over interior nodes 0.1 apart: each face is a
    // Delaunay face only through a sphere bulging less than the nodes' clearance, centred far
    // outside (it failed with all 12 triangles missing when the enclosing corners stood a
    // quarter extent out).
    let s = crate::common::cube_surface([0.0; 3], 1.0);
    for h in [0.2, 0.1] {
        let (mesh, report) = mesh_surface(
            &s,
            Sizing::uniform(h).unwrap(),
            &PipelineOptions::default(),
            &mut |_| {},
        )
        .unwrap();
        assert_eq!(report.missing_triangles, 0, "h = {h}");
        let c = check(&mesh, Some(&s));
        assert!(c.valid, "h = {h}: {:?}", c.problems);
        let v: f64 = (0..mesh.tets.len()).map(|t| volume(&mesh.corners(t))).sum();
        assert!((v - 1.0).abs() < 1e-12, "h = {h}: volume {v}");
        assert!(
            mesh.tets.len() > (0.5 / (h * h * h)) as usize,
            "h = {h}: {} tets",
            mesh.tets.len()
        );
    }
}
