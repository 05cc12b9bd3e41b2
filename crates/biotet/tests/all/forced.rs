//! Forced tets: poor because the input surface makes them so.

use crate::common::{cube_surface, cube6, load_stl, tetgen_brain};
use biotet::SurfaceMesh;
use biotet::TetMesh;
use biotet::quality::forced::{Placement, classify, face_forces, placement_quality, summarise};

#[test]
fn a_good_cube_has_no_forced_tets() {
    let m = cube6();
    let s = cube_surface([0.0; 3], 1.0);
    let f = classify(&m, &s, 10.0);
    assert!(f.forced.iter().all(|&x| !x));
    // Every Kuhn tet of the cube has a boundary face.
    assert!(f.placement.iter().all(|&p| p == Placement::Face));
    let sum = summarise(&m, &f, 10.0);
    assert_eq!(sum.n_face, 6);
    assert_eq!(sum.n_unforced_dihedral_lt_10, 0);
}

#[test]
fn a_needle_triangle_and_a_sharp_fold_force_their_tets() {
    // One tet whose face 0-1-2 has a 2.9° angle at vertex 2, and the surface is the tet itself.
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 10.0, 0.0],
        [0.5, 0.3, 1.0],
    ];
    let mut tets = vec![[0u32, 1, 2, 3]];
    crate::common::orient_all(&p, &mut tets);
    let m = TetMesh::new(p.clone(), tets.clone(), vec![1]);
    let faces: Vec<[u32; 3]> = (0..4).map(|f| m.face(0, f)).collect();
    let s = SurfaceMesh::closed(p, faces, 1);
    let f = classify(&m, &s, 10.0);
    assert_eq!(f.forced, vec![true]);
    assert_eq!(f.placement, vec![Placement::Face]);
    // With a threshold below the needle's angle, nothing is forced by the triangle, and the fold
    // angles at the tet's edges (its own dihedral angles) are all above 2°.
    let f = classify(&m, &s, 2.0);
    assert_eq!(f.forced, vec![false]);
}

/// A needle forces its tet below the threshold, not flat: on a cube whose bottom holds a 2.3°
/// needle, a tet on the needle is forced, the same tet squashed to 1e-9 of its height (angles
/// near 1e-7°) is not.
#[test]
fn a_tet_far_flatter_than_its_needle_is_not_forced() {
    let mut p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 0.02, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    p.extend([
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [0.0, 1.0, 1.0],
        [1.0, 1.0, 1.0],
    ]);
    // Bottom (needle 0-1-2 and its fan), top, then the four sides; outward.
    let faces: Vec<[u32; 3]> = vec![
        [0, 2, 1],
        [0, 3, 2],
        [2, 4, 1],
        [2, 3, 4],
        [5, 6, 8],
        [5, 8, 7],
        [0, 1, 6],
        [0, 6, 5],
        [1, 4, 8],
        [1, 8, 6],
        [4, 3, 7],
        [4, 7, 8],
        [3, 0, 5],
        [3, 5, 7],
    ];
    let s = SurfaceMesh::closed(p.clone(), faces, 1);
    for (h, forced) in [(0.5, true), (1e-9, false)] {
        let mut q = p.clone();
        q.push([0.5, 0.01, h]);
        let mut tets = vec![[0u32, 1, 2, 9]];
        crate::common::orient_all(&q, &mut tets);
        let m = TetMesh::new(q, tets, vec![1]);
        assert_eq!(classify(&m, &s, 10.0).forced, vec![forced], "height {h}");
    }
    assert!(face_forces(2.9, 0.01, 10.0) && !face_forces(2.9, 0.001, 10.0));
}

#[test]
fn the_tetgen_brain_mesh_has_forced_tets_from_marching_cubes() {
    let m = tetgen_brain();
    let s = load_stl("brain_20k.stl");
    let f = classify(&m, &s, 10.0);
    let sum = summarise(&m, &f, 10.0);
    // About 9% of brain_20k's triangles have an angle under 10° (tests/data/README): TetGen keeps
    // them all as faces, so their tets are forced.
    assert!(sum.n_forced > 1000, "{sum:?}");
    assert_eq!(sum.n_face + sum.n_vertex + sum.n_interior, m.tets.len());
    assert!(sum.n_forced_dihedral_lt_10 > 0);
    // Forced tets are a minority of the poor ones: TetGen leaves unforced slivers too.
    assert!(sum.n_unforced_dihedral_lt_10 > 0, "{sum:?}");
    assert!(sum.n_forced < sum.n_face + sum.n_vertex, "{sum:?}");
    // The per-placement quality adds up to the summary.
    let pq = placement_quality(&m, &f);
    let classes = [&pq.face, &pq.vertex, &pq.interior];
    assert_eq!(
        [pq.face.n_tets, pq.vertex.n_tets, pq.interior.n_tets],
        [sum.n_face, sum.n_vertex, sum.n_interior]
    );
    assert_eq!(
        classes.iter().map(|c| c.n_forced).sum::<usize>(),
        sum.n_forced
    );
    assert_eq!(
        classes.map(|c| c.n_dihedral_lt_10),
        sum.dihedral_lt_10_by_placement
    );
    // What bounds the unforced tets under 10°: mostly a poor input triangle next to them.
    assert_eq!(
        sum.unforced_lt_10_by_cause.iter().sum::<usize>(),
        sum.n_unforced_dihedral_lt_10
    );
    assert!(sum.unforced_lt_10_by_cause[0] > 0, "{sum:?}");
    // Recomputed from the surface alone: a tet of the first cause has, opposite its smallest
    // dihedral angle, an edge of an input triangle with an angle under 10°.
    let key = |p: [f64; 3]| p.map(f64::to_bits);
    let mut poor_edges = std::collections::HashSet::new();
    for t in &s.triangles {
        let c = t.map(|v| s.points[v as usize]);
        if biotet::quality::tri::min_angle_3d_deg(&c) < 10.0 {
            for k in 0..3 {
                let (a, b) = (key(c[k]), key(c[(k + 1) % 3]));
                poor_edges.insert((a.min(b), a.max(b)));
            }
        }
    }
    let mut first = 0;
    for (t, tet) in m.tets.iter().enumerate() {
        let a = biotet::quality::tet::dihedral_angles(&m.corners(t));
        let e = (0..6).min_by(|&i, &j| a[i].total_cmp(&a[j])).unwrap();
        if f.forced[t] || a[e].to_degrees() >= 10.0 || f.cause(*tet, e) != 0 {
            continue;
        }
        let [i, j] = biotet::mesh::tet::TET_EDGES[5 - e];
        let (p, q) = (
            key(m.points[tet[i] as usize]),
            key(m.points[tet[j] as usize]),
        );
        assert!(poor_edges.contains(&(p.min(q), p.max(q))), "tet {t}");
        first += 1;
    }
    assert_eq!(first, sum.unforced_lt_10_by_cause[0]);
    // Forced tets touch the surface; every class of this mesh is populated and measured.
    assert_eq!(pq.interior.n_forced, 0);
    for c in classes {
        let q = c.mean_q.unwrap();
        assert!(q > 0.0 && q <= 1.0, "{c:?}");
        assert!(c.min_dihedral_deg.unwrap() <= c.max_dihedral_deg.unwrap());
    }
}
