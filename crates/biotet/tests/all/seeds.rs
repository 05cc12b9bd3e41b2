//! Interior seeds in sections too thin for the template's nodes (`biotet::seeds`).

use biotet::check::check;
use biotet::mesh::surface::SurfaceMesh;
use biotet::mesh::tet::{TetMesh, face_adjacency};
use biotet::mesh::validate::{ValidateOptions, validate_surface};
use biotet::pipeline::{MeshReport, PipelineOptions, mesh_surface};
use biotet::quality::tet::min_dihedral_deg_by_chord;

fn shape(name: &str) -> SurfaceMesh {
    let mut s = crate::common::load_shape(name);
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    s
}

fn mesh(s: &SurfaceMesh, opts: &PipelineOptions) -> (TetMesh, MeshReport) {
    let sizing = crate::common::default_sizing(s);
    mesh_surface(s, &sizing, opts, &mut |_| {}).expect("meshes")
}

fn under_10(m: &TetMesh) -> usize {
    (0..m.tets.len())
        .filter(|&t| min_dihedral_deg_by_chord(&m.corners(t)) < 10.0)
        .count()
}

/// trimesh's square-section ring tube (200 segments 0.031 long, 0.014 across; no interior node
/// fits): without seeds the pipeline leaves flat caps on its planar side faces and over a
/// hundred tets under 10°; with a seed at the circumcentre of each segment's tets (TetGen `q`'s
/// point) none, every triangle kept.
#[test]
fn seeds_leave_no_tet_under_10_degrees_in_a_square_section_ring_tube() {
    let s = shape("tm_square_torus.off");
    let without = PipelineOptions {
        seeds: false,
        ..PipelineOptions::default()
    };
    let (m0, r0) = mesh(&s, &without);
    assert_eq!(r0.seeds, 0);
    assert!(
        under_10(&m0) > 100,
        "{} tets under 10° without seeds",
        under_10(&m0)
    );
    let (m, r) = mesh(&s, &PipelineOptions::default());
    assert!(r.seeds >= 150, "{} seeds for 200 segments", r.seeds);
    assert_eq!(under_10(&m), 0);
    assert_eq!(r.missing_triangles, 0);
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
}

/// trimesh's triangular-section ring tube (200 twisted prisms, none with a tetrahedralization of
/// its six corners): most segments' poor tets are flat on a planar side quad, with no
/// circumsphere to hold a neighbour's circumcentre, so the seed's cavity must take the poor tets
/// beside it or its cone replaces only good tets and is refused (141 seeds and 68 tets under 10°
/// before that; 191 and 14 now; TetGen `pq1.2Y` 0).
#[test]
fn seed_cavities_take_the_flat_tets_beside_them_in_a_triangular_ring_tube() {
    let s = shape("tm_tri_torus.off");
    let (m, r) = mesh(&s, &PipelineOptions::default());
    assert!(r.seeds >= 180, "{} seeds for 200 segments", r.seeds);
    assert!(under_10(&m) < 30, "{} tets under 10°", under_10(&m));
    assert_eq!(r.missing_triangles, 0);
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
}

/// Each seed's cone replaces its cavity in place, the adjacency kept without a rebuild: on the
/// ring tube (cones larger than their cavities) and on the hull of random points (no interior
/// node anywhere, cavities of half the mesh, cones with fewer tets than their cavities, whose
/// slots are removed) the mesh right after the seeds is valid, keeps the surface and its
/// adjacency is what it is recomputed to be.
#[test]
fn seed_cones_keep_the_mesh_and_its_adjacency() {
    let seeds_only = PipelineOptions {
        improve: None,
        smooth: None,
        polish: None,
        ..PipelineOptions::default()
    };
    for name in [
        "tm_square_torus.off",
        "tm_tri_torus.off",
        "tm_hull_random200.off",
    ] {
        let s = shape(name);
        let (m, r) = mesh(&s, &seeds_only);
        assert!(r.seeds > 0, "{name}: no seed");
        let (nb, over) = face_adjacency(&m.tets);
        assert_eq!(over, 0, "{name}");
        assert!(nb == m.neighbors, "{name}: adjacency not kept");
        let c = check(&m, Some(&s));
        assert!(c.valid, "{name}: {c}");
    }
}

/// A cube whose faces are fans of long thin triangles: a point inside cones to those triangles
/// no better than the tets there (3.6°–7.3° against 4.8°), so no seed is placed and the mesh is
/// the one without seeds.
#[test]
fn no_seed_where_its_cone_is_no_better() {
    let s = shape("gen_cube_fans.off");
    let (m, r) = mesh(&s, &PipelineOptions::default());
    assert_eq!(r.seeds, 0);
    let (m0, _) = mesh(
        &s,
        &PipelineOptions {
            seeds: false,
            ..PipelineOptions::default()
        },
    );
    assert_eq!(m, m0);
}

/// A solid of revolution whose profile zigzags between radii 1 and 1.3 every 0.2 (64 sections,
/// as trimesh's `creation.revolve` makes it): thin fins of triangular section around a core.
/// Each side quad is a planar isosceles trapezoid, so the Delaunay puts flat tets (volume 1e-19,
/// 0° and 180°) on the quads whose surface diagonal is not its own, in fins too thin for the
/// template's nodes.
fn revolved_zigzag() -> SurfaceMesh {
    let sections = 64;
    let profile: Vec<(f64, f64)> = (0..21)
        .map(|i| (1.0 + 0.3 * (i % 2) as f64, 0.2 * i as f64))
        .collect();
    let mut points = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 4.0]];
    for &(r, z) in &profile {
        for k in 0..sections {
            let a = std::f64::consts::TAU * k as f64 / sections as f64;
            points.push([r * a.cos(), r * a.sin(), z]);
        }
    }
    let at = |i: usize, k: usize| (2 + i * sections + k % sections) as u32;
    let mut tris = Vec::new();
    let last = profile.len() - 1;
    for k in 0..sections {
        tris.push([0, at(0, k + 1), at(0, k)]);
        tris.push([1, at(last, k), at(last, k + 1)]);
        for i in 0..last {
            tris.push([at(i, k), at(i, k + 1), at(i + 1, k + 1)]);
            tris.push([at(i, k), at(i + 1, k + 1), at(i + 1, k)]);
        }
    }
    let mut s = SurfaceMesh::closed(points, tris, 1);
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    s
}

/// The flat tets of the revolved zigzag's fins: a seed's cone there was refused at 5°–9.8°
/// (under the 10° floor) and the 0° tets stayed (seven seeds, 363 tets under 10° unforced, as
/// trimesh's copy gave). A cavity holding a flat tet takes a cone down to 5°: a hundred seeds,
/// no flat tet left.
#[test]
fn seeds_replace_the_flat_tets_of_a_revolved_zigzag() {
    let s = revolved_zigzag();
    let (m, r) = mesh(&s, &PipelineOptions::default());
    assert!(r.seeds >= 50, "{} seeds", r.seeds);
    let worst = (0..m.tets.len())
        .map(|t| min_dihedral_deg_by_chord(&m.corners(t)))
        .fold(180.0, f64::min);
    assert!(worst > 0.5, "a tet at {worst}°");
    assert!(under_10(&m) < 250, "{} tets under 10°", under_10(&m));
    assert_eq!(r.missing_triangles, 0);
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
}
