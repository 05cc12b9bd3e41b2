//! Tests: validate.

use biotet::SurfaceMesh;
use biotet::geom::intersect::{TriTri, tri_tri};
use biotet::geom::predicates::{Sign, orient3d};
use biotet::mesh::validate::{SurfaceError, ValidateOptions, validate_surface};

fn opts() -> ValidateOptions {
    ValidateOptions::default()
}

/// Unit cube `[0,1]^3` scaled by `s` and shifted by `o`, outward, region `label`.
fn cube(o: [f64; 3], s: f64, label: u32) -> SurfaceMesh {
    let points: Vec<[f64; 3]> = (0..8)
        .map(|i| {
            [
                o[0] + s * (i & 1) as f64,
                o[1] + s * ((i >> 1) & 1) as f64,
                o[2] + s * ((i >> 2) & 1) as f64,
            ]
        })
        .collect();
    // Index = x + 2y + 4z; quads counter-clockwise seen from outside.
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let triangles = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    SurfaceMesh::closed(points, triangles, label)
}

/// The outward boundary of the tet `p`, region 1.
fn tet(p: [[f64; 3]; 4]) -> SurfaceMesh {
    let mut p = p;
    if orient3d(p[0], p[1], p[2], p[3]) == Sign::Negative {
        p.swap(0, 1);
    }
    SurfaceMesh::closed(
        p.to_vec(),
        vec![[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]],
        1,
    )
}

fn reversed(mut s: SurfaceMesh) -> SurfaceMesh {
    for t in &mut s.triangles {
        t.swap(1, 2);
    }
    s
}

#[test]
fn cube_is_valid() {
    let mut s = cube([0.0; 3], 1.0, 1);
    let before = s.clone();
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert_eq!(s, before);
    assert_eq!(r.n_triangles, 12);
    assert_eq!(r.n_used_points, 8);
    assert_eq!(r.n_edges, 18);
    assert_eq!(r.n_components, 1);
    assert_eq!(r.components[0].genus, Some(0));
    assert!(!r.flipped_inward);
    assert_eq!(r.regions.len(), 1);
    assert_eq!(r.regions[0].label, 1);
    assert!((r.regions[0].volume - 1.0).abs() < 1e-12);
    assert_eq!(r.regions[0].shells[0].depth, 0);
}

#[test]
fn hole() {
    let mut s = cube([0.0; 3], 1.0, 1);
    s.triangles.remove(3);
    s.sides.remove(3);
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    let SurfaceError::NotClosed { count, first, .. } = &e else {
        panic!("{e}")
    };
    assert_eq!(*count, 3);
    assert_eq!(first.len(), 3);
    let msg = e.to_string();
    assert!(
        msg.starts_with("not closed: 3 boundary edges (a hole); first: edge ("),
        "{msg}"
    );
    // The lowest-index triangle on a boundary edge is listed first, with its coordinates.
    assert!(
        msg.contains("of triangle 2 [(0, 0, 1), (1, 0, 1), (1, 1, 1)]"),
        "{msg}"
    );
    println!("{msg}");
}

#[test]
fn unwelded_surface_is_a_hole_with_a_hint() {
    let c = cube([0.0; 3], 1.0, 1);
    let mut s = SurfaceMesh::default();
    for (t, v) in c.triangles.iter().enumerate() {
        let n = s.points.len() as u32;
        s.points.extend(v.iter().map(|&i| c.points[i as usize]));
        s.triangles.push([n, n + 1, n + 2]);
        s.sides.push(c.sides[t]);
    }
    let e = validate_surface(&mut s.clone(), &opts()).unwrap_err();
    assert!(
        matches!(
            e,
            SurfaceError::NotClosed {
                count: 36,
                unwelded_points: 36,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("weld them first"));
    assert_eq!(s.weld_exact(), 28);
    validate_surface(&mut s, &opts()).unwrap();
}

#[test]
fn flipped_triangle() {
    let mut s = cube([0.0; 3], 1.0, 1);
    s.triangles[5].swap(0, 1);
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    let SurfaceError::Flipped {
        count,
        n_edges,
        to_flip,
        ..
    } = &e
    else {
        panic!("{e}")
    };
    assert_eq!((*count, *n_edges), (1, 3));
    assert_eq!(to_flip, &vec![5]);
    let msg = e.to_string();
    assert!(msg.contains("flip 1 triangle: triangle 5 ["), "{msg}");
    println!("{msg}");
    // Flipping what it says repairs the surface.
    s.triangles[5].swap(1, 2);
    validate_surface(&mut s, &opts()).unwrap();
}

#[test]
fn flipped_majority_reports_the_minority() {
    // 11 of 12 triangles reversed: the one left is the one to flip; the result is an inward
    // cube, which validation then turns outward.
    let mut s = reversed(cube([0.0; 3], 1.0, 1));
    s.triangles[0].swap(1, 2);
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    let SurfaceError::Flipped { to_flip, .. } = &e else {
        panic!("{e}")
    };
    assert_eq!(to_flip, &vec![0]);
    s.triangles[0].swap(1, 2);
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert!(r.flipped_inward);
    assert_eq!(s, cube([0.0; 3], 1.0, 1));
}

#[test]
fn interpenetrating_tets() {
    let a = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let b = a.map(|p| [p[0] + 0.25, p[1] + 0.2, p[2] + 0.15]);
    let mut s = tet(a);
    s.append(&tet(b));
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    let SurfaceError::SelfIntersection { count, first } = &e else {
        panic!("{e}")
    };
    assert!(*count >= 2, "{e}");
    // Lowest pairs first, pairs ordered.
    let pairs: Vec<(u32, u32)> = first.iter().map(|p| (p.0.index, p.1.index)).collect();
    let mut sorted = pairs.clone();
    sorted.sort_unstable();
    assert_eq!(pairs, sorted);
    assert!(pairs.iter().all(|&(i, j)| i < 4 && j >= 4));
    println!("{e}");
}

#[test]
fn surface_folding_through_itself() {
    // A cube whose top corner (1,1,1) is pushed down through the bottom face: still a closed,
    // consistently oriented manifold, but its triangles cross.
    let mut s = cube([0.0; 3], 1.0, 1);
    s.points[7] = [0.6, 0.7, -0.5];
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    assert!(matches!(e, SurfaceError::SelfIntersection { .. }), "{e}");
    // Without the self-intersection check it passes the other checks.
    let o = ValidateOptions {
        self_intersections: false,
        ..opts()
    };
    let r = validate_surface(&mut s, &o);
    assert!(
        r.is_ok() || matches!(r, Err(SurfaceError::LabelsContradictGeometry { .. })),
        "{r:?}"
    );
}

#[test]
fn touching_at_an_unwelded_corner_is_an_intersection() {
    let a = tet([
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ]);
    let b = tet([
        [0.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, -1.0],
    ]);
    let mut s = a.clone();
    s.append(&b);
    let e = validate_surface(&mut s.clone(), &opts()).unwrap_err();
    assert!(matches!(e, SurfaceError::SelfIntersection { .. }), "{e}");
    // Welded, the corner becomes a non-manifold vertex.
    s.weld_exact();
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    let SurfaceError::NonManifoldVertex { count, first } = &e else {
        panic!("{e}")
    };
    assert_eq!(*count, 1);
    assert_eq!(first[0].point, [0.0; 3]);
    assert_eq!(first[0].fans, 2);
    println!("{e}");
}

#[test]
fn non_manifold_edge() {
    let mut s = tet([
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ]);
    s.append(&tet([
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, -1.0],
    ]));
    s.weld_exact();
    assert_eq!(s.points.len(), 6);
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    let SurfaceError::NonManifoldEdge { count, first } = &e else {
        panic!("{e}")
    };
    assert_eq!(*count, 1);
    assert_eq!(first[0].n_triangles, 4);
    assert!(e.to_string().contains("in 4 triangles"), "{e}");
    println!("{e}");
}

#[test]
fn zero_area_triangles() {
    let mut s = cube([0.0; 3], 1.0, 1);
    s.points.push([0.5, 0.0, 0.0]);
    s.triangles.push([0, 8, 1]); // collinear corners
    s.triangles.push([2, 2, 3]); // repeated vertex
    s.sides.extend([[1, 0], [1, 0]]);
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    let SurfaceError::Degenerate { count, first } = &e else {
        panic!("{e}")
    };
    assert_eq!(*count, 2);
    assert_eq!(first[0].index, 12);
    assert!(
        e.to_string()
            .contains("triangle 12 [(0, 0, 0), (0.5, 0, 0), (1, 0, 0)]"),
        "{e}"
    );
    // Collinear up to the last bit is not degenerate: exact predicates see the difference
    // (the triangle then leaves holes, the next check).
    let mut s = cube([0.0; 3], 1.0, 1);
    s.points.push([0.1, 0.1, 0.1]);
    s.points.push([0.3, 0.3, 0.3f64.next_up()]);
    s.triangles.push([0, 8, 9]);
    s.sides.push([1, 0]);
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    assert!(matches!(e, SurfaceError::NotClosed { .. }), "{e}");
}

#[test]
fn duplicate_triangle() {
    let mut s = cube([0.0; 3], 1.0, 1);
    s.triangles.push(s.triangles[4]);
    let t = s.triangles[7];
    s.triangles.push([t[0], t[2], t[1]]); // reversed copy
    s.sides.extend([[1, 0], [1, 0]]);
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    let SurfaceError::Duplicate { count, first } = &e else {
        panic!("{e}")
    };
    assert_eq!(*count, 2);
    assert_eq!((first[0].0.index, first[0].1.index), (4, 12));
    assert_eq!((first[1].0.index, first[1].1.index), (7, 13));
    println!("{e}");
}

#[test]
fn bad_indices_coordinates_and_labels() {
    let mut s = cube([0.0; 3], 1.0, 1);
    s.triangles[2][1] = 99;
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    assert!(
        matches!(e, SurfaceError::IndexOutOfRange { count: 1, .. }),
        "{e}"
    );
    let mut s = cube([0.0; 3], 1.0, 1);
    s.points[3][2] = f64::NAN;
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    assert!(matches!(e, SurfaceError::NonFinite { count: 1, .. }), "{e}");
    let mut s = cube([0.0; 3], 1.0, 1);
    s.sides[0] = [1, 1];
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    assert!(
        matches!(e, SurfaceError::SameRegionBothSides { count: 1, .. }),
        "{e}"
    );
    let mut s = SurfaceMesh::default();
    assert_eq!(
        validate_surface(&mut s, &opts()).unwrap_err(),
        SurfaceError::Empty
    );
}

#[test]
fn inward_cube_is_flipped() {
    let mut s = reversed(cube([0.0; 3], 1.0, 1));
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert!(r.flipped_inward);
    assert_eq!(r.n_flipped_triangles, 12);
    assert!(r.components[0].flipped);
    assert!((r.regions[0].volume - 1.0).abs() < 1e-12);
    assert_eq!(s, cube([0.0; 3], 1.0, 1));
    // Now outward: nothing more to do.
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert!(!r.flipped_inward);
    // With fixing off, it is an error.
    let mut s = reversed(cube([0.0; 3], 1.0, 1));
    let o = ValidateOptions {
        fix_inward: false,
        ..opts()
    };
    let e = validate_surface(&mut s, &o).unwrap_err();
    assert!(matches!(e, SurfaceError::Inward { count: 1, .. }), "{e}");
    println!("{e}");
}

#[test]
fn shell_with_cavity() {
    // Outer cube outward, inner cube inward: region 1 is the hollow shell between them.
    let mut s = cube([0.0; 3], 4.0, 1);
    s.append(&reversed(cube([1.0; 3], 1.0, 1)));
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert!(!r.flipped_inward);
    assert_eq!(r.n_components, 2);
    let reg = &r.regions[0];
    assert_eq!(reg.shells.len(), 2);
    assert_eq!(reg.shells[0].depth, 0);
    assert_eq!(reg.shells[1].depth, 1);
    assert!((reg.volume - 63.0).abs() < 1e-9);
    // The whole thing inside out: both components reversed.
    let mut s2 = reversed(s.clone());
    let r = validate_surface(&mut s2, &opts()).unwrap();
    assert!(r.flipped_inward);
    assert_eq!(r.n_flipped_triangles, 24);
    assert_eq!(s2, s);
    // A separate body outside, inside out: only it is reversed.
    let mut s3 = s.clone();
    s3.append(&reversed(cube([10.0, 0.0, 0.0], 1.0, 1)));
    let r = validate_surface(&mut s3, &opts()).unwrap();
    assert!(r.flipped_inward);
    assert_eq!(r.n_flipped_triangles, 12);
    assert!((r.regions[0].volume - 64.0).abs() < 1e-9);
}

/// Nesting: a box with 27 cavities, an island inside one cavity (depth 2) and a cavity in the
/// island (depth 3), some written the wrong way round.
#[test]
fn nested_cavities_and_islands() {
    let mut good = cube([0.0; 3], 10.0, 1);
    for i in 0..27 {
        let o = [i % 3, (i / 3) % 3, i / 9].map(|k| 1.0 + 3.0 * k as f64);
        let side = if i == 13 { 2.5 } else { 1.5 };
        good.append(&reversed(cube(o, side, 1)));
    }
    // Island in the big middle cavity [4, 6.5]^3, and a cavity in the island.
    good.append(&cube([4.5; 3], 1.5, 1));
    good.append(&reversed(cube([5.0; 3], 0.5, 1)));
    let mut s = good.clone();
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert!(!r.flipped_inward);
    let reg = &r.regions[0];
    assert_eq!(reg.shells.len(), 30);
    let depths: Vec<usize> = reg.shells.iter().map(|sh| sh.depth).collect();
    assert_eq!(depths[0], 0);
    assert!(depths[1..28].iter().all(|&d| d == 1));
    assert_eq!((depths[28], depths[29]), (2, 3));
    let want = 1000.0 - 26.0 * 3.375 - 2.5f64.powi(3) + 3.375 - 0.125;
    assert!((reg.volume - want).abs() < 1e-9, "{} vs {want}", reg.volume);
    // Every shell written the wrong way round: all reversed back.
    let mut s = reversed(good.clone());
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert_eq!(r.n_flipped_triangles, good.triangles.len());
    assert_eq!(s, good);
    // Only the island and two cavities wrong: only those reversed.
    let mut s = good.clone();
    for t in (12..36).chain(12 * 28..12 * 29) {
        s.triangles[t].swap(1, 2);
    }
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert_eq!(r.n_flipped_triangles, 36);
    assert_eq!(s, good);
}

#[test]
fn two_materials() {
    // Nested: region 2 (inner cube, sides [2, 1]) inside region 1.
    let mut s = cube([0.0; 3], 4.0, 1);
    let mut inner = cube([1.0; 3], 1.0, 2);
    inner.sides.iter_mut().for_each(|sd| *sd = [2, 1]);
    s.append(&inner);
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert!(!r.flipped_inward);
    assert_eq!(r.regions.len(), 2);
    assert!((r.regions[0].volume - 63.0).abs() < 1e-9);
    assert!((r.regions[1].volume - 1.0).abs() < 1e-9);
    // The inner surface written inside out (labels kept): reversed.
    let mut s2 = cube([0.0; 3], 4.0, 1);
    s2.append(&reversed(inner.clone()));
    let r = validate_surface(&mut s2, &opts()).unwrap();
    assert!(r.flipped_inward);
    assert_eq!(s2, s);
    // The inner cube labelled as if region 1 were inside and region 2 around it: reversing it
    // is the same as swapping the labels back, so it is repaired too.
    let mut s3 = cube([0.0; 3], 4.0, 1);
    let mut swapped = inner.clone();
    swapped.sides.iter_mut().for_each(|sd| *sd = [1, 2]);
    s3.append(&swapped);
    let r = validate_surface(&mut s3, &opts()).unwrap();
    assert!(r.flipped_inward);
    assert!((r.regions[0].volume - 63.0).abs() < 1e-9);
    assert!((r.regions[1].volume - 1.0).abs() < 1e-9);

    // Side by side: cube A (region 1) and cube B (region 2) sharing the face x = 1.
    let a = cube([0.0; 3], 1.0, 1);
    let b = cube([1.0, 0.0, 0.0], 1.0, 2);
    let mut s = SurfaceMesh::default();
    // A's faces except x = 1 (quad 5 = triangles 10, 11).
    for t in 0..10 {
        push_tri(&mut s, &a, t, a.sides[t]);
    }
    // B's faces except x = 1 (its x = 0 face, quad 4 = triangles 8, 9).
    for t in (0..12).filter(|t| !(8..10).contains(t)) {
        push_tri(&mut s, &b, t, b.sides[t]);
    }
    // The interface: A's x = 1 face (normal +x, from region 1 into region 2).
    for t in 10..12 {
        push_tri(&mut s, &a, t, [1, 2]);
    }
    s.weld_exact();
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert_eq!(r.n_components, 1);
    assert_eq!(r.components[0].genus, None);
    assert_eq!(r.components[0].regions, vec![1, 2]);
    assert!((r.regions[0].volume - 1.0).abs() < 1e-12);
    assert!((r.regions[1].volume - 1.0).abs() < 1e-12);
    assert_eq!(r.regions[0].shells[0].genus, 0);
    // Both bodies inside out: reversed together (their shells share the interface).
    let mut s2 = reversed(s.clone());
    let r = validate_surface(&mut s2, &opts()).unwrap();
    assert!(r.flipped_inward);
    assert_eq!(s2, s);
    // A region-2 box around both: A|B sits inside region 2, so B's shell is a region-2 cavity
    // facing outward while A's region-1 shell is fine; no reversal fixes that.
    let mut s4 = s.clone();
    s4.append(&cube([-1.0; 3], 4.0, 2));
    let e = validate_surface(&mut s4, &opts()).unwrap_err();
    assert!(
        matches!(e, SurfaceError::LabelsContradictGeometry { count: 1, .. }),
        "{e}"
    );
    println!("{e}");
    // An interface triangle reversed (labels kept) is a flipped triangle for both regions.
    let last = s.triangles.len() - 1;
    s.triangles[last].swap(1, 2);
    let e = validate_surface(&mut s, &opts()).unwrap_err();
    let SurfaceError::Flipped { to_flip, .. } = &e else {
        panic!("{e}")
    };
    assert_eq!(to_flip, &vec![last as u32]);
    println!("{e}");
}

/// Two cubes of different regions touching along an edge only, one inside out: only that one
/// is reversed.
#[test]
fn different_regions_touching_along_an_edge() {
    let mut s = cube([0.0; 3], 1.0, 1);
    s.append(&reversed(cube([1.0, 1.0, 0.0], 1.0, 2)));
    s.weld_exact();
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert_eq!(r.n_components, 1);
    assert!(r.flipped_inward);
    assert_eq!(r.n_flipped_triangles, 12);
    assert!((r.regions[0].volume - 1.0).abs() < 1e-12);
    assert!((r.regions[1].volume - 1.0).abs() < 1e-12);
}

fn push_tri(s: &mut SurfaceMesh, from: &SurfaceMesh, t: usize, sides: [u32; 2]) {
    let n = s.points.len() as u32;
    s.points.extend(from.corners(t));
    s.triangles.push([n, n + 1, n + 2]);
    s.sides.push(sides);
}

/// The self-intersection search (BVH, parallel) finds exactly the pairs a brute-force loop over
/// all pairs finds, and reports the lowest ones. Many separate tets on a half-integer lattice:
/// crossings, touching corners, coplanar faces.
#[test]
fn self_intersections_match_brute_force() {
    let mut seed = 12345u64;
    let mut rnd = |n: u64| {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 33) % n
    };
    for round in 0..6 {
        let mut s = SurfaceMesh::default();
        while s.triangles.len() < 4 * 80 {
            let o = [0, 1, 2].map(|_| rnd(16) as f64 * 0.5);
            let p = [0, 1, 2, 3].map(|_| [0, 1, 2].map(|i| o[i] + rnd(4) as f64 * 0.5));
            if orient3d(p[0], p[1], p[2], p[3]) == Sign::Zero {
                continue;
            }
            s.append(&tet(p));
        }
        let mut brute = Vec::new();
        for i in 0..s.triangles.len() {
            for j in i + 1..s.triangles.len() {
                let (a, b) = (s.triangles[i], s.triangles[j]);
                let shared = a.iter().filter(|v| b.contains(v)).count();
                let bad = match tri_tri(&s.corners(i), &s.corners(j)) {
                    TriTri::Disjoint => false,
                    TriTri::SharedVertex { .. } => shared != 1,
                    TriTri::SharedEdge { .. } => shared != 2,
                    TriTri::Improper => true,
                };
                if bad {
                    brute.push((i as u32, j as u32));
                }
            }
        }
        let e = validate_surface(&mut s, &opts()).unwrap_err();
        let SurfaceError::SelfIntersection { count, first } = &e else {
            panic!("round {round}: {e}")
        };
        assert_eq!(*count, brute.len(), "round {round}");
        let got: Vec<(u32, u32)> = first.iter().map(|p| (p.0.index, p.1.index)).collect();
        assert_eq!(got, brute[..5.min(brute.len())].to_vec(), "round {round}");
    }
}

/// A tiny binary-STL reader (biotet cannot depend on biotet-io).
fn read_binary_stl(path: &str) -> SurfaceMesh {
    let bytes = std::fs::read(path).expect("read STL");
    let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
    assert_eq!(bytes.len(), 84 + 50 * n, "binary STL size");
    let f = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap()) as f64;
    let mut points = Vec::with_capacity(3 * n);
    let mut triangles = Vec::with_capacity(n);
    for t in 0..n {
        let base = 84 + 50 * t + 12;
        for c in 0..3 {
            let o = base + 12 * c;
            points.push([f(o), f(o + 4), f(o + 8)]);
        }
        let i = 3 * t as u32;
        triangles.push([i, i + 1, i + 2]);
    }
    let mut s = SurfaceMesh::closed(points, triangles, 1);
    s.weld_exact();
    s
}

#[test]
fn brain_surface_is_valid() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/brain_20k.stl"
    );
    let mut s = read_binary_stl(path);
    assert_eq!(s.points.len(), 9_770);
    assert_eq!(s.triangles.len(), 19_648);
    let before = s.clone();
    let t = std::time::Instant::now();
    let r = validate_surface(&mut s, &opts()).unwrap();
    println!("brain_20k: {r} in {:.3?}", t.elapsed());
    assert_eq!(s, before);
    assert!(!r.flipped_inward);
    assert_eq!(r.n_used_points, 9_770);
    assert_eq!(r.n_triangles, 19_648);
    assert_eq!(r.n_components, 1);
    assert_eq!(r.components[0].genus, Some(28));
    assert_eq!(r.regions[0].shells[0].genus, 28);
    // tests/data/README.md gives 1,659,213 mm³.
    assert!(
        (r.regions[0].volume - 1_659_213.0).abs() < 1.0,
        "{}",
        r.regions[0].volume
    );
    // Inside out, it is turned back.
    let mut inv = reversed(before.clone());
    let r = validate_surface(&mut inv, &opts()).unwrap();
    assert!(r.flipped_inward);
    assert_eq!(inv, before);
}

#[test]
fn nested_brain_and_white_matter() {
    // Both shells in one file, all labelled [1, 0]: the white-matter shell is then a cavity of
    // region 1, facing the wrong way for one, and gets reversed.
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/nested_brain_wm_20k.stl"
    );
    let mut s = read_binary_stl(path);
    let r = validate_surface(&mut s, &opts()).unwrap();
    println!("nested: {r}");
    assert_eq!(r.n_components, 2);
    assert!(r.flipped_inward);
    assert_eq!(r.n_flipped_triangles, 29_576);
    let reg = &r.regions[0];
    assert_eq!((reg.shells[0].genus, reg.shells[1].genus), (28, 32));
    assert_eq!((reg.shells[0].depth, reg.shells[1].depth), (0, 1));
    assert!(
        (reg.volume - (1_659_213.0 - 552_267.0)).abs() < 2.0,
        "{}",
        reg.volume
    );
}

/// A torus from an `n × m` parametric grid (`2nm` triangles), outward.
fn torus(n: usize, m: usize) -> SurfaceMesh {
    let (big, small) = (1.0f64, 0.4f64);
    let mut points = Vec::with_capacity(n * m);
    for i in 0..n {
        let u = std::f64::consts::TAU * i as f64 / n as f64;
        for j in 0..m {
            let v = std::f64::consts::TAU * j as f64 / m as f64;
            let r = big + small * v.cos();
            points.push([r * u.cos(), r * u.sin(), small * v.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let mut triangles = Vec::with_capacity(2 * n * m);
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    SurfaceMesh::closed(points, triangles, 1)
}

#[test]
fn small_torus_is_valid() {
    let mut s = torus(40, 20);
    let r = validate_surface(&mut s, &opts()).unwrap();
    assert_eq!(r.components[0].genus, Some(1));
    assert!(!r.flipped_inward);
}

/// Timing on about a million triangles: `cargo test --release -p biotet -- --ignored timing`.
#[test]
#[ignore]
fn timing_million_triangles() {
    let mut s = torus(1000, 500);
    let t = std::time::Instant::now();
    let r = validate_surface(&mut s, &opts()).unwrap();
    let dt = t.elapsed();
    println!(
        "validated {} triangles in {dt:.3?} ({} threads): {r}",
        r.n_triangles,
        rayon::current_num_threads()
    );
    assert_eq!(r.components[0].genus, Some(1));
    let mut s = reversed(torus(1000, 500));
    let t = std::time::Instant::now();
    let r = validate_surface(&mut s, &opts()).unwrap();
    println!("inward torus fixed in {:.3?}", t.elapsed());
    assert!(r.flipped_inward);
    let o = ValidateOptions {
        self_intersections: false,
        ..opts()
    };
    let t = std::time::Instant::now();
    validate_surface(&mut s, &o).unwrap();
    println!("without self-intersections: {:.3?}", t.elapsed());
}
