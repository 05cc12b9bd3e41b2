//! The validity checker finds each kind of defect, and only those.

use crate::common::{cube_points, cube_surface, cube6, cube6_tets, orient_all, two_cubes};
use biotet::check::check;
use biotet::{NO_NEIGHBOR, SurfaceMesh, TetMesh};

#[test]
fn cube_is_valid_and_has_its_surface() {
    let m = cube6();
    let r = check(&m, Some(&cube_surface([0.0; 3], 1.0)));
    assert!(r.valid, "{r}");
    assert_eq!(r.n_boundary_faces, 12);
    let s = r.surface.unwrap();
    assert_eq!((s.n_triangles, s.n_found), (12, 12));
}

#[test]
fn flipped_tet_is_not_positive() {
    let mut m = cube6();
    m.tets[2].swap(0, 1);
    m.rebuild_neighbors();
    let r = check(&m, None);
    assert!(!r.valid);
    assert_eq!(r.n_nonpositive, 1, "{r}");
    // Its faces now have the same orientation as its neighbours' view of them.
    assert!(r.n_misoriented_faces >= 1, "{r}");
}

#[test]
fn flat_tet_is_not_positive() {
    let pts = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    let m = TetMesh::new(pts, vec![[0, 1, 2, 3]], vec![1]);
    let r = check(&m, None);
    assert_eq!(r.n_nonpositive, 1);
    assert!(!r.valid);
}

#[test]
fn missing_tet_loses_surface_triangles() {
    let mut m = cube6();
    m.tets.remove(0);
    m.labels.remove(0);
    m.rebuild_neighbors();
    let r = check(&m, Some(&cube_surface([0.0; 3], 1.0)));
    // The mesh itself is still a valid (non-convex) mesh...
    assert_eq!(
        r.n_nonpositive + r.n_overshared_faces + r.n_adjacency_errors,
        0
    );
    // ...but two cube triangles are gone and two inner faces became boundary.
    let s = r.surface.as_ref().unwrap();
    assert_eq!(s.n_missing, 2, "{r}");
    assert_eq!(s.n_extra_boundary_faces, 2, "{r}");
    assert!(!r.valid);
}

#[test]
fn triangle_off_the_mesh_points_is_reported() {
    let m = cube6();
    let s = cube_surface([0.0, 0.0, 0.5], 1.0);
    let r = check(&m, Some(&s));
    assert!(!r.valid);
    assert!(r.surface.unwrap().n_points_missing > 0);
}

#[test]
fn overshared_face_is_reported() {
    let mut m = cube6();
    let t = m.tets[0];
    // A second copy of tet 0: each of its faces is now in too many tets or misoriented.
    m.tets.push(t);
    m.labels.push(1);
    m.rebuild_neighbors();
    let r = check(&m, None);
    assert!(!r.valid);
    assert!(r.n_overshared_faces >= 1, "{r}");
}

#[test]
fn stale_adjacency_is_reported() {
    let mut m = cube6();
    let f = (0..4).find(|&f| m.neighbors[0][f] != NO_NEIGHBOR).unwrap();
    m.neighbors[0][f] = NO_NEIGHBOR;
    let r = check(&m, None);
    assert_eq!(r.n_adjacency_errors, 1, "{r}");
    assert!(!r.valid);
}

#[test]
fn unused_and_duplicate_points_are_reported() {
    let mut m = cube6();
    m.points.push([5.0, 5.0, 5.0]);
    m.points.push([1.0, 1.0, 1.0]);
    let r = check(&m, None);
    assert_eq!(r.n_unused_points, 2, "{r}");
    assert_eq!(r.n_duplicate_points, 1, "{r}");
    assert!(!r.valid);
}

#[test]
fn out_of_range_index_does_not_panic() {
    let mut m = cube6();
    m.tets[3][1] = 99;
    let r = check(&m, None);
    assert_eq!(r.n_bad_tets, 1);
    assert!(!r.valid);
}

#[test]
fn two_regions_with_their_interface() {
    let m = two_cubes();
    // Surface: the outer boundary of both cubes and the interface x = 1 between 1 and 2.
    let left = cube_surface([0.0; 3], 1.0);
    let right = cube_surface([1.0, 0.0, 0.0], 1.0);
    let mut s = SurfaceMesh::default();
    for (cube, label, x_shared) in [(&left, 1u32, 1.0), (&right, 2u32, 1.0)] {
        let mut part = cube.clone();
        for t in 0..part.triangles.len() {
            let on_shared = part.corners(t).iter().all(|p| p[0] == x_shared);
            part.sides[t] = [label, 0];
            if on_shared {
                // Keep the interface once, from the left cube: back = 1, front = 2.
                part.sides[t] = if label == 1 {
                    [1, 2]
                } else {
                    [u32::MAX, u32::MAX]
                };
            }
        }
        let keep: Vec<usize> = (0..part.triangles.len())
            .filter(|&t| part.sides[t][0] != u32::MAX)
            .collect();
        part.triangles = keep.iter().map(|&t| part.triangles[t]).collect();
        part.sides = keep.iter().map(|&t| part.sides[t]).collect();
        s.append(&part);
    }
    let r = check(&m, Some(&s));
    assert!(r.valid, "{r}");
    let sc = r.surface.unwrap();
    assert_eq!(sc.n_triangles, 22);
    let pairs: Vec<([u32; 2], usize)> = sc.interfaces.iter().map(|i| (i.labels, i.found)).collect();
    assert_eq!(pairs, vec![([0, 1], 10), ([0, 2], 10), ([1, 2], 2)]);

    // Swapping the labels of the two cubes contradicts the interface's sides.
    let mut swapped = m.clone();
    for l in &mut swapped.labels {
        *l = 3 - *l;
    }
    let r = check(&swapped, Some(&s));
    assert!(!r.valid);
    assert!(r.surface.unwrap().n_label_mismatch > 0);
}

#[test]
fn scaled_and_shifted_cube_stays_valid() {
    // The same fixture from 1e-9 to 1e9: exact predicates do not care about scale.
    for &s in &[1e-9, 1e-3, 1.0, 1e3, 1e9] {
        let pts = cube_points([s * 0.1, -s, 3.0 * s], s);
        let mut m = cube6();
        m.points = pts.clone();
        let r = check(&m, Some(&cube_surface([s * 0.1, -s, 3.0 * s], s)));
        assert!(r.valid, "scale {s}: {r}");
    }
}

/// A positively oriented tet with corners `o + s·(unit tet corners)`.
fn tet_at(o: [f64; 3], s: f64) -> Vec<[f64; 3]> {
    vec![
        o,
        [o[0] + s, o[1], o[2]],
        [o[0], o[1] + s, o[2]],
        [o[0], o[1], o[2] + s],
    ]
}

#[test]
fn overlapping_tets_without_a_shared_face_are_invalid() {
    // Every tet positive, no face shared at all: only the boundary shows the overlap.
    let mut pts = tet_at([0.0; 3], 1.0);
    pts.extend(tet_at([0.2, 0.2, 0.2], 1.0));
    let m = TetMesh::new(pts, vec![[0, 1, 2, 3], [4, 5, 6, 7]], vec![1, 1]);
    let r = check(&m, None);
    assert_eq!(
        r.n_nonpositive + r.n_overshared_faces + r.n_misoriented_faces,
        0
    );
    assert!(!r.valid, "{r}");
    assert!(
        r.boundary_problem.as_deref().unwrap().contains("intersect"),
        "{r}"
    );
}

#[test]
fn tet_nested_inside_another_is_invalid() {
    // The small tet's boundary lies inside the big one's without crossing it: its shell is
    // outward where a cavity would have to face inward.
    let mut pts = tet_at([0.0; 3], 4.0);
    pts.extend(tet_at([0.5, 0.5, 0.5], 1.0));
    let m = TetMesh::new(pts, vec![[0, 1, 2, 3], [4, 5, 6, 7]], vec![1, 1]);
    let r = check(&m, None);
    assert!(!r.valid, "{r}");
    assert!(r.boundary_problem.is_some(), "{r}");
}

#[test]
fn separate_tets_are_valid() {
    let mut pts = tet_at([0.0; 3], 1.0);
    pts.extend(tet_at([3.0, 0.0, 0.0], 1.0));
    let m = TetMesh::new(pts, vec![[0, 1, 2, 3], [4, 5, 6, 7]], vec![1, 1]);
    let r = check(&m, None);
    assert!(r.valid, "{r}");
}

#[test]
fn empty_mesh_is_invalid() {
    let r = check(&TetMesh::default(), None);
    assert!(!r.valid);
    assert!(r.problems.iter().any(|p| p.contains("no tets")));
}

#[test]
fn wrong_labels_are_not_counted_as_extra_boundary_faces() {
    // Two cubes labelled 1 and 2 checked against a surface that says both are region 1 with an
    // interface [1, 2] where there is none in the surface: only labels disagree.
    let m = two_cubes();
    let mut s = cube_surface([0.0; 3], 1.0);
    s.append(&cube_surface([1.0, 0.0, 0.0], 1.0));
    // Keep only the outer triangles (drop the two copies of the shared face x = 1).
    let keep: Vec<usize> = (0..s.triangles.len())
        .filter(|&t| !s.corners(t).iter().all(|p| p[0] == 1.0))
        .collect();
    s.triangles = keep.iter().map(|&t| s.triangles[t]).collect();
    s.sides = keep.iter().map(|_| [1, 0]).collect();
    let r = check(&m, Some(&s));
    let sc = r.surface.as_ref().unwrap();
    assert!(!r.valid);
    assert_eq!(sc.n_extra_boundary_faces, 0, "{r}");
    // The right cube's 10 outer triangles have label 2 behind them, not 1.
    assert_eq!(sc.n_label_mismatch, 10, "{r}");
}

#[test]
fn coordinates_outside_the_exact_range_are_reported() {
    // At 1e-200 the orientation determinants underflow: no sign can be trusted, so the checker
    // says so instead of reporting wrong orientations.
    let mut m = cube6();
    for p in &mut m.points {
        *p = p.map(|c| c * 1e-200);
    }
    let r = check(&m, None);
    assert!(!r.valid);
    assert_eq!(r.n_nonfinite_points, 7, "{r}"); // every corner but the origin
}

/// Unit cubes of 6 tets each at `origins`, with labels, sharing the points they have in common.
fn cubes(origins: &[[f64; 3]], labels: &[u32]) -> TetMesh {
    let mut pts: Vec<[f64; 3]> = Vec::new();
    let mut tets = Vec::new();
    let mut tet_labels = Vec::new();
    for (o, &l) in origins.iter().zip(labels) {
        let map: Vec<u32> = cube_points(*o, 1.0)
            .into_iter()
            .map(|p| match pts.iter().position(|q| *q == p) {
                Some(i) => i as u32,
                None => {
                    pts.push(p);
                    pts.len() as u32 - 1
                }
            })
            .collect();
        for t in cube6_tets(0) {
            tets.push(t.map(|v| map[v as usize]));
            tet_labels.push(l);
        }
    }
    orient_all(&pts, &mut tets);
    TetMesh::new(pts, tets, tet_labels)
}

#[test]
fn regions_touching_along_an_edge_or_at_a_vertex_are_valid() {
    // Cubes [0,1]^3 and [1,2]x[1,2]x[0,1] share the edge (1,1,0)-(1,1,1); [1,2]^3 shares only
    // the vertex (1,1,1). The boundary is not a manifold there, but its sheets belong to
    // different regions.
    for (b, touching) in [([1.0, 1.0, 0.0], 2), ([1.0, 1.0, 1.0], 1)] {
        let m = cubes(&[[0.0; 3], b], &[1, 2]);
        let r = check(&m, None);
        assert!(r.valid, "{b:?}: {r}");
        assert_eq!(r.n_boundary_faces, 24, "{r}");
        assert_eq!(r.n_touching_vertices, touching, "{b:?}: {r}");
        assert!(r.to_string().contains("different regions touch"), "{r}");
        // With its surface: both cubes' boundaries, each region's own.
        let mut s = cube_surface([0.0; 3], 1.0);
        let mut sb = cube_surface(b, 1.0);
        sb.sides = vec![[2, 0]; 12];
        s.append(&sb);
        s.weld_exact();
        let r = check(&m, Some(&s));
        assert!(r.valid, "{b:?}: {r}");
        let sc = r.surface.as_ref().unwrap();
        let found: Vec<_> = sc
            .interfaces
            .iter()
            .map(|i| (i.labels, i.expected, i.found))
            .collect();
        assert_eq!(found, vec![([0, 1], 12, 12), ([0, 2], 12, 12)], "{r}");
    }
}

#[test]
fn a_region_pinched_at_an_edge_or_a_vertex_is_invalid() {
    // The same cubes as one region: the region is pinched, and the message names the edge or
    // the vertex by its coordinates.
    for (b, words) in [
        (
            [1.0, 1.0, 0.0],
            ["non-manifold edges", "(1, 1, 0)–(1, 1, 1) in 4 triangles"],
        ),
        (
            [1.0, 1.0, 1.0],
            ["non-manifold vertices", "vertex 7 (1, 1, 1)"],
        ),
    ] {
        let m = cubes(&[[0.0; 3], b], &[1, 1]);
        let r = check(&m, None);
        assert!(!r.valid, "{b:?}: {r}");
        let p = r.boundary_problem.as_deref().unwrap();
        for w in words {
            assert!(p.contains(w), "{b:?}: {p}");
        }
    }
}

#[test]
fn touching_is_judged_per_region_not_per_piece() {
    // A (region 1) and B (region 2) share the face x = 1; C touches B alone along the edge
    // (2,1,0)-(2,1,1). Region 1 in two pieces (A, C) touching region 2 is fine; C in region 2
    // pinches region 2 at that edge.
    let origins = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 1.0, 0.0]];
    let r = check(&cubes(&origins, &[1, 2, 1]), None);
    assert!(r.valid, "{r}");
    assert_eq!(r.n_touching_vertices, 2, "{r}");
    let r = check(&cubes(&origins, &[1, 2, 2]), None);
    assert!(!r.valid, "{r}");
    let p = r.boundary_problem.as_deref().unwrap();
    assert!(
        p.contains("non-manifold edges") && p.contains("(2, 1, 0)–(2, 1, 1)"),
        "{p}"
    );
}

#[test]
fn region_components_count_face_connected_tets_of_one_label() {
    // Four tets around the edge 0–1, each sharing a face with the next (an open fan): labels 1,
    // 1, 2, 1. Label 1 is then two pieces (the 2 cuts the fan), label 2 one; without the stored
    // adjacency the count is the same.
    let points = vec![
        [0.0, 0.0, -1.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.9, -0.4, 0.0],
    ];
    let tets = vec![[0, 1, 2, 3], [0, 1, 3, 4], [0, 1, 4, 5], [0, 1, 5, 6]];
    let mut m = TetMesh::new(points, tets, vec![1, 1, 2, 1]);
    let shared = m
        .neighbors
        .iter()
        .flatten()
        .filter(|&&n| n != NO_NEIGHBOR)
        .count();
    assert_eq!(shared, 6, "three shared faces, each seen from both tets");
    assert_eq!(m.region_components(), vec![(1, 2), (2, 1)]);
    m.labels = vec![1, 1, 1, 1];
    assert_eq!(m.region_components(), vec![(1, 1)]);
    m.neighbors.clear();
    m.labels = vec![1, 2, 1, 2];
    assert_eq!(m.region_components(), vec![(1, 2), (2, 2)]);
}
