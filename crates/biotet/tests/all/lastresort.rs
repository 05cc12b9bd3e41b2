//! LAST RESORT: the search on unit shells, and boundary recovery on Delaunay meshes of real
//! surfaces.

use biotet::geom::predicates::{Sign, orient3d};
use biotet::lastresort::{SearchError, SearchOptions, fill};
use biotet::quality::tet::{q_measure, volume};

type P3 = [f64; 3];

/// Signed volume enclosed by an oriented closed shell (normals pointing inwards give a negative
/// sum of outward volumes, so negate).
fn shell_volume_inward(points: &[P3], shell: &[[u32; 3]]) -> f64 {
    let o = [0.0; 3];
    -shell
        .iter()
        .map(|f| {
            volume(&[
                o,
                points[f[0] as usize],
                points[f[1] as usize],
                points[f[2] as usize],
            ])
        })
        .sum::<f64>()
}

/// Every tet positive, the tets' faces pair up except the shell's (each shell face is the face
/// of exactly one tet, seen from inside), volumes add up, every point used.
fn assert_fills(points: &[P3], shell: &[[u32; 3]], inner: &[u32], tets: &[[u32; 4]]) {
    use std::collections::HashMap;
    let faces = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
    let mut count: HashMap<[u32; 3], i32> = HashMap::new();
    let canon = |f: [u32; 3]| {
        let m = (0..3).min_by_key(|&k| f[k]).unwrap();
        [f[m], f[(m + 1) % 3], f[(m + 2) % 3]]
    };
    let mut vol = 0.0;
    for t in tets {
        let c = t.map(|i| points[i as usize]);
        assert_eq!(
            orient3d(c[0], c[1], c[2], c[3]),
            Sign::Positive,
            "tet {t:?}"
        );
        vol += volume(&c);
        for f in faces {
            let g = [t[f[0]], t[f[1]], t[f[2]]];
            let rev = canon([g[0], g[2], g[1]]);
            if let Some(n) = count.get_mut(&rev) {
                *n -= 1;
                if *n == 0 {
                    count.remove(&rev);
                }
            } else {
                *count.entry(canon(g)).or_default() += 1;
            }
        }
    }
    // What is left are the tets' outward faces on the shell: the shell faces reversed.
    let mut want: HashMap<[u32; 3], i32> = HashMap::new();
    for f in shell {
        *want.entry(canon([f[0], f[2], f[1]])).or_default() += 1;
    }
    assert_eq!(count, want, "the fill's boundary is the shell");
    let v0 = shell_volume_inward(points, shell);
    assert!(
        (vol - v0).abs() <= 1e-9 * v0.abs().max(1.0),
        "{vol} vs {v0}"
    );
    for &i in inner {
        assert!(
            tets.iter().any(|t| t.contains(&i)),
            "inner point {i} unused"
        );
    }
}

fn cube() -> (Vec<P3>, Vec<[u32; 3]>) {
    let pts: Vec<P3> = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    // Quads counter-clockwise seen from inside.
    let quads = [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ];
    let mut tris = Vec::new();
    for q in quads {
        tris.push([q[0], q[1], q[2]]);
        tris.push([q[0], q[2], q[3]]);
    }
    (pts, tris)
}

#[test]
fn search_fills_cube() {
    let (pts, shell) = cube();
    let f = fill(&pts, &shell, &[], &SearchOptions::default()).unwrap();
    assert_fills(&pts, &shell, &[], &f.tets);
    assert!(f.tets.len() == 5 || f.tets.len() == 6, "{}", f.tets.len());
    assert!(f.worst_q > 0.0);
    println!(
        "cube: {} tets, {} nodes, worst q {:.3}",
        f.tets.len(),
        f.nodes_visited,
        f.worst_q
    );
}

#[test]
fn search_fills_cube_with_inner_point() {
    let (mut pts, shell) = cube();
    pts.push([0.4, 0.55, 0.45]);
    let f = fill(&pts, &shell, &[8], &SearchOptions::default()).unwrap();
    assert_fills(&pts, &shell, &[8], &f.tets);
    // A point outside the shell is not used.
    pts.push([3.0, 0.5, 0.5]);
    let f = fill(&pts, &shell, &[8, 9], &SearchOptions::default()).unwrap();
    assert_fills(&pts, &shell, &[8], &f.tets);
    assert!(f.tets.iter().all(|t| !t.contains(&9)));
}

#[test]
fn search_fills_octahedron() {
    // Outward faces, reversed to point inwards.
    let s = crate::common::octahedron(1.0);
    let pts = s.points;
    let shell: Vec<[u32; 3]> = s.triangles.iter().map(|f| [f[0], f[2], f[1]]).collect();
    let f = fill(&pts, &shell, &[], &SearchOptions::default()).unwrap();
    assert_fills(&pts, &shell, &[], &f.tets);
    assert_eq!(f.tets.len(), 4);
}

/// A triangular prism whose top is turned by `twist` degrees; the side quads are split by the
/// short diagonals (`short`: the side edges fold outwards and the prism stays convex) or the
/// long ones (they fold inwards, reflex: the Schönhardt polyhedron for a 30° twist). Faces point
/// inwards.
fn twisted_prism(twist: f64, short: bool) -> (Vec<P3>, Vec<[u32; 3]>) {
    let mut pts = Vec::new();
    for z in 0..2 {
        for i in 0..3 {
            let a = (90.0 + 120.0 * i as f64 + if z == 1 { twist } else { 0.0 }).to_radians();
            pts.push([a.cos(), a.sin(), z as f64]);
        }
    }
    // Outward: bottom (0, 2, 1), top (3, 4, 5); side i: a_i a_{i+1} b_{i+1} b_i.
    let mut out = vec![[0u32, 2, 1], [3, 4, 5]];
    for i in 0..3u32 {
        let (a0, a1, b0, b1) = (i, (i + 1) % 3, 3 + i, 3 + (i + 1) % 3);
        if short {
            out.push([a0, a1, b0]);
            out.push([a1, b1, b0]);
        } else {
            out.push([a0, a1, b1]);
            out.push([a0, b1, b0]);
        }
    }
    let shell = out.iter().map(|f| [f[0], f[2], f[1]]).collect();
    (pts, shell)
}

#[test]
fn search_fills_twisted_prism() {
    for twist in [10.0, 30.0, 50.0] {
        let (pts, shell) = twisted_prism(twist, true);
        let f = fill(&pts, &shell, &[], &SearchOptions::default()).unwrap();
        assert_fills(&pts, &shell, &[], &f.tets);
    }
}

#[test]
fn schoenhardt_has_no_fill() {
    let (pts, shell) = twisted_prism(30.0, false);
    // Every candidate of every face is blocked: the root has a face without candidates.
    let e = fill(&pts, &shell, &[], &SearchOptions::default()).unwrap_err();
    assert!(matches!(e, SearchError::NoFill { .. }), "{e}");
    // With a point at the centre it fills.
    let mut pts = pts;
    pts.push([0.0, 0.0, 0.5]);
    let f = fill(&pts, &shell, &[6], &SearchOptions::default()).unwrap();
    assert_fills(&pts, &shell, &[6], &f.tets);
}

#[test]
fn search_improves_worst_quality() {
    // A cube with an inner point: the first fill and the branch-and-bound fill.
    let (mut pts, shell) = cube();
    pts.push([0.3, 0.6, 0.45]);
    let first = fill(&pts, &shell, &[8], &SearchOptions::default()).unwrap();
    let opts = SearchOptions {
        improve: Some(1_000_000),
        ..SearchOptions::default()
    };
    let best = fill(&pts, &shell, &[8], &opts).unwrap();
    assert_fills(&pts, &shell, &[8], &best.tets);
    assert!(best.optimal);
    assert!(best.worst_q >= first.worst_q);
    let worst = best
        .tets
        .iter()
        .map(|t| q_measure(&t.map(|i| pts[i as usize])))
        .fold(f64::INFINITY, f64::min);
    assert_eq!(worst, best.worst_q);
    // A threshold at the optimum leaves no fill.
    let e = fill(
        &pts,
        &shell,
        &[8],
        &SearchOptions {
            min_quality: best.worst_q,
            ..SearchOptions::default()
        },
    )
    .unwrap_err();
    assert!(matches!(e, SearchError::NoFill { .. }));
}

#[test]
fn search_dihedral_cap_bounds_every_tet() {
    // The cube with an inner point: the fills differ in their largest angle.
    let (mut pts, shell) = cube();
    pts.push([0.3, 0.6, 0.45]);
    let max_dihedral = |t: &[u32; 4]| {
        let a = biotet::quality::tet::dihedral_angles(&t.map(|i| pts[i as usize]));
        a.iter().copied().fold(0.0, f64::max).to_degrees()
    };
    let worst = |tets: &[[u32; 4]]| tets.iter().map(max_dihedral).fold(0.0, f64::max);
    let all = SearchOptions {
        improve: Some(1_000_000),
        ..SearchOptions::default()
    };
    let some = fill(&pts, &shell, &[8], &all).unwrap();
    let loose = worst(&some.tets);
    // A cap just under this fill's largest angle excludes it; the fill found then stays under.
    let cap = loose - 1e-6;
    match fill(
        &pts,
        &shell,
        &[8],
        &SearchOptions {
            max_dihedral: cap,
            ..all
        },
    ) {
        Ok(f) => {
            assert_fills(&pts, &shell, &[8], &f.tets);
            assert!(worst(&f.tets) < cap, "{} vs cap {cap}", worst(&f.tets));
        }
        Err(e) => assert!(matches!(e, SearchError::NoFill { .. }), "{e}"),
    }
    // At or above 180°: no cap, the same fill as without the field.
    let same = fill(
        &pts,
        &shell,
        &[8],
        &SearchOptions {
            max_dihedral: 180.0,
            ..all
        },
    )
    .unwrap();
    assert_eq!(same.tets, some.tets);
    // A tet's six dihedral angles sum to more than 360°, so one is above 60°: a cap of 60°
    // leaves no candidate at all.
    let none = SearchOptions {
        max_dihedral: 60.0,
        ..all
    };
    assert!(matches!(
        fill(&pts, &shell, &[8], &none),
        Err(SearchError::NoFill { .. })
    ));
}

#[test]
fn search_dihedral_floor_bounds_every_tet() {
    // The cube with an inner point: a floor just under the best fill's worst angle keeps a fill,
    // every tet of it above the floor; a floor at that angle leaves none.
    let (mut pts, shell) = cube();
    pts.push([0.3, 0.6, 0.45]);
    let min_dihedral = |t: &[u32; 4]| {
        let a = biotet::quality::tet::dihedral_angles(&t.map(|i| pts[i as usize]));
        a.iter().copied().fold(f64::INFINITY, f64::min).to_degrees()
    };
    let all = SearchOptions {
        improve: Some(1_000_000),
        ..SearchOptions::default()
    };
    let some = fill(&pts, &shell, &[8], &all).unwrap();
    let floor = 0.5
        * some
            .tets
            .iter()
            .map(min_dihedral)
            .fold(f64::INFINITY, f64::min);
    let opts = SearchOptions {
        min_dihedral: floor,
        ..all
    };
    let f = fill(&pts, &shell, &[8], &opts).unwrap();
    assert_fills(&pts, &shell, &[8], &f.tets);
    let worst = f
        .tets
        .iter()
        .map(min_dihedral)
        .fold(f64::INFINITY, f64::min);
    assert!(worst > floor, "{worst} vs floor {floor}");
    // The best worst angle over every fill is at least this one; a floor at 90° excludes all
    // (no tet of a cube's points has every dihedral angle above 90°).
    let none = SearchOptions {
        min_dihedral: 90.0,
        ..all
    };
    assert!(matches!(
        fill(&pts, &shell, &[8], &none),
        Err(SearchError::NoFill { .. })
    ));
}

#[test]
fn search_rejects_bad_input() {
    let (pts, mut shell) = cube();
    assert!(matches!(
        fill(&pts, &shell[1..], &[], &SearchOptions::default()),
        Err(SearchError::NotClosed { .. })
    ));
    assert!(matches!(
        fill(&pts, &shell, &[99], &SearchOptions::default()),
        Err(SearchError::IndexOutOfRange { .. })
    ));
    assert!(matches!(
        fill(&pts, &[], &[], &SearchOptions::default()),
        Err(SearchError::Empty)
    ));
    let mut dup = pts.clone();
    dup.push(pts[0]);
    assert!(matches!(
        fill(&dup, &shell, &[8], &SearchOptions::default()),
        Err(SearchError::DuplicatePoint { .. })
    ));
    shell[0] = [0, 1, 1];
    assert!(matches!(
        fill(&pts, &shell, &[], &SearchOptions::default()),
        Err(SearchError::DegenerateFace { .. })
    ));
    let mut nan = pts.clone();
    nan[0][0] = f64::NAN;
    assert!(matches!(
        fill(&nan, &cube().1, &[], &SearchOptions::default()),
        Err(SearchError::BadCoordinate { .. })
    ));
}

#[test]
fn search_refills_delaunay_cavities() {
    // Carve the tets around a few vertices of a random Delaunay mesh and fill the cavity again:
    // a fill exists (the carved tets), the search must find one.
    use biotet::delaunay::Delaunay;
    let pts = crate::common::random_points(2000, 7);
    let mesh = Delaunay::new(&pts).unwrap().to_tet_mesh();
    let mut total_nodes = 0;
    let mut calls = 0;
    for centre in (0..2000u32).step_by(97) {
        // The star of `centre` and of its first neighbour.
        let first: Vec<u32> = (0..mesh.tets.len() as u32)
            .filter(|&t| mesh.tets[t as usize].contains(&centre))
            .collect();
        let other = mesh.tets[first[0] as usize]
            .iter()
            .copied()
            .find(|&v| v != centre)
            .unwrap();
        let cavity: Vec<usize> = (0..mesh.tets.len())
            .filter(|&t| mesh.tets[t].contains(&centre) || mesh.tets[t].contains(&other))
            .collect();
        let mut shell = Vec::new();
        for &t in &cavity {
            for f in 0..4 {
                let n = mesh.neighbors[t][f];
                if n == biotet::NO_NEIGHBOR || !cavity.contains(&(n as usize)) {
                    let g = mesh.face(t, f);
                    shell.push([g[0], g[2], g[1]]);
                }
            }
        }
        let mut inner: Vec<u32> = cavity.iter().flat_map(|&t| mesh.tets[t]).collect();
        inner.sort_unstable();
        inner.dedup();
        inner.retain(|v| !shell.iter().any(|f| f.contains(v)));
        let f = fill(&mesh.points, &shell, &inner, &SearchOptions::default()).unwrap();
        assert_fills(&mesh.points, &shell, &inner, &f.tets);
        total_nodes += f.nodes_visited;
        calls += 1;
    }
    println!("{calls} cavities, {total_nodes} nodes");
}

// ---------------------------------------------------------------------------------------------
// Boundary recovery
// ---------------------------------------------------------------------------------------------

use biotet::check::check;
use biotet::delaunay::Delaunay;
use biotet::geom::intersect::{SegTri, seg_tri};
use biotet::lastresort::{RecoverOptions, recover};
use biotet::{SurfaceMesh, TetMesh};

/// Volume enclosed by a closed outward surface.
fn enclosed_volume(s: &SurfaceMesh) -> f64 {
    (0..s.triangles.len())
        .map(|t| {
            let c = s.corners(t);
            volume(&[[0.0; 3], c[0], c[1], c[2]])
        })
        .sum()
}

fn mesh_volume(m: &TetMesh) -> f64 {
    (0..m.tets.len()).map(|t| volume(&m.corners(t))).sum()
}

/// Point-in-surface by the parity of crossings of the ray towards +z (exact segment–triangle
/// tests against the segment to a point above the surface); `None` when the ray touches an edge
/// or vertex (then the caller decides otherwise). Triangles are bucketed on an xy grid.
struct Inside {
    s: SurfaceMesh,
    top: f64,
    lo: [f64; 2],
    cell: f64,
    n: usize,
    grid: Vec<Vec<u32>>,
}

impl Inside {
    fn new(s: &SurfaceMesh) -> Inside {
        let (lo, hi) = biotet::geom::vec3::points_bbox(&s.points);
        let n = 64;
        let cell = (hi[0] - lo[0]).max(hi[1] - lo[1]) / n as f64 * 1.0001;
        let mut grid = vec![Vec::new(); n * n];
        for t in 0..s.triangles.len() {
            let c = s.corners(t);
            let ix = |x: f64, k: usize| (((x - lo[k]) / cell) as usize).min(n - 1);
            let (x0, x1) = (
                ix(c.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min), 0),
                ix(c.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max), 0),
            );
            let (y0, y1) = (
                ix(c.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min), 1),
                ix(c.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max), 1),
            );
            for x in x0..=x1 {
                for y in y0..=y1 {
                    grid[y * n + x].push(t as u32);
                }
            }
        }
        Inside {
            s: s.clone(),
            top: hi[2] + 1.0,
            lo: [lo[0], lo[1]],
            cell,
            n,
            grid,
        }
    }

    fn contains(&self, p: P3) -> Option<bool> {
        let ix = ((p[0] - self.lo[0]) / self.cell).floor();
        let iy = ((p[1] - self.lo[1]) / self.cell).floor();
        if ix < 0.0 || iy < 0.0 || ix >= self.n as f64 || iy >= self.n as f64 {
            return Some(false);
        }
        let q = [p[0], p[1], self.top];
        let mut odd = false;
        for &t in &self.grid[iy as usize * self.n + ix as usize] {
            match seg_tri(p, q, &self.s.corners(t as usize)) {
                SegTri::Disjoint => {}
                SegTri::Proper => odd = !odd,
                _ => return None,
            }
        }
        Some(odd)
    }
}

/// The Delaunay mesh of the surface's points with the tets whose centroid is outside removed.
fn delaunay_trimmed(s: &SurfaceMesh) -> TetMesh {
    let dt = Delaunay::new(&s.points).unwrap();
    let mut m = dt.to_tet_mesh();
    let inside = Inside::new(s);
    let keep: Vec<bool> = (0..m.tets.len())
        .map(|t| {
            let c = m.corners(t);
            let g = |w: [f64; 4]| [0, 1, 2].map(|k| (0..4).map(|i| w[i] * c[i][k]).sum::<f64>());
            // The centroid, or nearby interior points when its ray grazes an edge.
            [[0.25; 4], [0.3, 0.24, 0.23, 0.23], [0.22, 0.31, 0.26, 0.21]]
                .iter()
                .find_map(|&w| inside.contains(g(w)))
                .unwrap_or(false)
        })
        .collect();
    let mut k = 0;
    for (t, &kept) in keep.iter().enumerate() {
        if kept {
            m.tets[k] = m.tets[t];
            k += 1;
        }
    }
    m.tets.truncate(k);
    m.labels.truncate(k);
    m.rebuild_neighbors();
    m
}

fn recover_and_check(name: &str, s: &SurfaceMesh, mut m: TetMesh, opts: &RecoverOptions) {
    let n_points = m.points.len();
    let t = std::time::Instant::now();
    let r = recover(&mut m, s, opts).unwrap();
    let dt = t.elapsed();
    println!(
        "{name}: {:?}, tets {} -> {}, missing {} -> {}, calls {} ({} ok, {} grown), \
         ms/call median {:.3} max {:.3}, nodes/call median {} max {}, cavity tets median {}, \
         {:.1} ms total ({dt:.2?})",
        r.domain,
        r.tets_before,
        r.tets_after,
        r.missing_before,
        r.missing_after,
        r.calls,
        r.calls_succeeded,
        r.cavities_grown,
        r.call_ms_median,
        r.call_ms_max,
        r.nodes_median,
        r.nodes_max,
        r.cavity_tets_median,
        r.total_ms
    );
    for u in r.unrecovered.iter().take(5) {
        println!("  unrecovered {u:?}");
    }
    assert!(r.missing_before > 0);
    assert!(r.is_complete(), "{} triangles unrecovered", r.missing_after);
    // The crossed-tets cavity is tried first and recovers most triangles on these surfaces.
    assert!(r.crossed_ok <= r.crossed_tried && r.crossed_tried <= r.calls);
    assert!(
        2 * r.crossed_ok > r.crossed_tried,
        "{} of {}",
        r.crossed_ok,
        r.crossed_tried
    );
    assert_eq!(m.points.len(), n_points, "no new points");
    let c = check(&m, Some(s));
    assert!(c.valid, "{c}");
    let (v, v0) = (mesh_volume(&m), enclosed_volume(s));
    assert!((v - v0).abs() < 1e-9 * v0, "volume {v} vs {v0}");
}

#[test]
fn recover_brain_delaunay_trimmed() {
    let s = crate::common::load_stl("brain_20k.stl");
    let m = delaunay_trimmed(&s);
    recover_and_check("brain_20k trimmed", &s, m, &RecoverOptions::default());
}

#[test]
fn recover_brain_delaunay_hull() {
    let s = crate::common::load_stl("brain_20k.stl");
    let m = Delaunay::new(&s.points).unwrap().to_tet_mesh();
    recover_and_check("brain_20k hull", &s, m, &RecoverOptions::default());
}

#[test]
fn recover_white_matter_delaunay_trimmed() {
    let s = crate::common::load_stl("wm_20k.stl");
    let m = delaunay_trimmed(&s);
    recover_and_check("wm_20k trimmed", &s, m, &RecoverOptions::default());
}

/// A closed outward surface from inward shell faces (reversed), one region.
fn surface_of(points: &[P3], inward: &[[u32; 3]]) -> SurfaceMesh {
    SurfaceMesh::closed(
        points.to_vec(),
        inward.iter().map(|f| [f[0], f[2], f[1]]).collect(),
        1,
    )
}

/// Recover `s` in the Delaunay mesh of its points (and `extra` points): valid, every triangle.
fn recover_small(s: &SurfaceMesh, extra: &[P3]) -> biotet::lastresort::RecoverReport {
    let mut pts = s.points.clone();
    pts.extend_from_slice(extra);
    let mut m = Delaunay::new(&pts).unwrap().to_tet_mesh();
    let r = recover(&mut m, s, &RecoverOptions::default()).unwrap();
    assert!(r.is_complete(), "{r:?}");
    let c = check(&m, Some(s));
    assert!(c.valid, "{c}");
    let (v, v0) = (mesh_volume(&m), enclosed_volume(s));
    assert!((v - v0).abs() < 1e-12 * v0.max(1.0), "{v} vs {v0}");
    r
}

#[test]
fn recover_unit_shells() {
    let (p, f) = cube();
    let r = recover_small(&surface_of(&p, &f), &[]);
    println!("cube: missing {}", r.missing_before);
    // Diagonals the other way than the Delaunay split picks: some must be recovered.
    let (p, f) = cube();
    let flipped: Vec<[u32; 3]> = f
        .chunks(2)
        .flat_map(|q| {
            let (a, b) = (q[0], q[1]); // a = [q0 q1 q2], b = [q0 q2 q3]
            [[a[0], a[1], b[2]], [a[1], a[2], b[2]]]
        })
        .collect();
    let s = surface_of(&p, &flipped);
    let r = recover_small(&s, &[[0.5, 0.5, 0.5]]);
    println!("cube, other diagonals: missing {}", r.missing_before);
    let (p, f) = twisted_prism(30.0, true);
    recover_small(&surface_of(&p, &f), &[]);
    // The octahedron with points inside.
    let s = crate::common::octahedron(1.0);
    recover_small(&s, &[[0.1, 0.2, 0.05], [-0.2, 0.1, -0.3]]);
}

#[test]
fn recover_fails_honestly_on_schoenhardt() {
    let (p, f) = twisted_prism(30.0, false);
    let s = surface_of(&p, &f);
    let mut m = Delaunay::new(&p).unwrap().to_tet_mesh();
    let r = recover(&mut m, &s, &no_steiner()).unwrap();
    assert!(!r.is_complete());
    assert_eq!(r.missing_after, r.unrecovered.len());
    assert!(r.missing_before >= 3);
    for u in &r.unrecovered {
        assert!(u.reason.contains("no fill"), "{}", u.reason);
        assert!(u.min_angle_deg > 0.0);
        assert_eq!(u.corners, s.corners(u.triangle));
    }
    assert_eq!(r.steiner_points, 0);
    assert_eq!(m.points.len(), 6);
    // With the fallback (the default), one interior point recovers it.
    let mut m = Delaunay::new(&p).unwrap().to_tet_mesh();
    let r = recover(&mut m, &s, &RecoverOptions::default()).unwrap();
    assert!(r.is_complete(), "{r:?}");
    assert_eq!(r.steiner_points, 1);
    assert_eq!(m.points.len(), 7);
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
}

#[test]
fn recover_nested_interface_labels() {
    // Two nested cubes: region 2 inside, region 1 between; the inner surface is an interface.
    let (p, f) = cube();
    let mut pts: Vec<P3> = p.iter().map(|x| x.map(|c| c * 3.0)).collect();
    pts.extend(p.iter().map(|x| x.map(|c| c + 1.0)));
    let mut tris: Vec<[u32; 3]> = f.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let mut sides = vec![[1, 0]; tris.len()];
    tris.extend(f.iter().map(|t| [t[0] + 8, t[2] + 8, t[1] + 8]));
    sides.extend(std::iter::repeat_n([2, 1], f.len()));
    let s = SurfaceMesh {
        points: pts.clone(),
        triangles: tris,
        sides,
    };
    let mut m = Delaunay::new(&pts).unwrap().to_tet_mesh();
    let r = recover(&mut m, &s, &RecoverOptions::default()).unwrap();
    assert!(r.is_complete(), "{r:?}");
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
    assert_eq!(m.regions(), vec![1, 2]);
    let vol = |l: u32| -> f64 {
        (0..m.tets.len())
            .filter(|&t| m.labels[t] == l)
            .map(|t| volume(&m.corners(t)))
            .sum()
    };
    assert!((vol(2) - 1.0).abs() < 1e-12, "{}", vol(2));
    assert!((vol(1) - 26.0).abs() < 1e-12, "{}", vol(1));
}

#[test]
fn improve_is_the_same_on_any_number_of_threads() {
    // A Delaunay mesh of random points is full of slivers; the batched parallel refill must give
    // bit-identical tets on 1 and 2 threads, and a valid mesh with fewer tets under 10°.
    use biotet::lastresort::{ImproveOptions, improve};
    let pts = crate::common::random_points(800, 11);
    let base = Delaunay::new(&pts).unwrap().to_tet_mesh();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut m = base.clone();
        let r = pool.install(|| improve(&mut m, &ImproveOptions::default()));
        (m, r)
    };
    let (one, r1) = run(1);
    let (two, r2) = run(2);
    assert_eq!(one.tets, two.tets);
    assert_eq!(r1.n_bad_after, r2.n_bad_after);
    assert!(
        r1.star_cavities.accepted + r1.edge_cavities.accepted > 0,
        "{r1:?}"
    );
    assert!(5 * r1.n_bad_after < 4 * r1.n_bad_before, "{r1:?}");
    let c = check(&one, None);
    assert!(c.valid, "{c}");
    assert!((mesh_volume(&one) - mesh_volume(&base)).abs() < 1e-9 * mesh_volume(&base));
}

#[test]
fn recover_is_the_same_on_any_number_of_threads() {
    // Recovery fills the crossed tets of a batch of triangles in parallel and applies them in
    // order: 1 and 2 threads must give the same tets and labels, complete and valid.
    let s = crate::common::load_stl("brain_20k.stl");
    let base = Delaunay::new(&s.points).unwrap().to_tet_mesh();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut m = base.clone();
        let r = pool.install(|| recover(&mut m, &s, &RecoverOptions::default()).unwrap());
        (m, r)
    };
    let (one, r1) = run(1);
    let (two, r2) = run(2);
    assert_eq!(one.tets, two.tets);
    assert_eq!(one.labels, two.labels);
    assert_eq!((r1.calls, r1.nodes_total), (r2.calls, r2.nodes_total));
    assert!(r1.missing_before > 0 && r1.is_complete(), "{r1:?}");
    let c = check(&one, Some(&s));
    assert!(c.valid, "{c}");
}

#[test]
fn recover_puts_back_surface_points_the_mesh_dropped() {
    // A mesher that removes the outside tets and then the points no tet uses leaves surface
    // points out: recover puts them back (they are the surface's own points) before it
    // recovers the triangles.
    let s = crate::common::load_stl("brain_20k.stl");
    let mut m = delaunay_trimmed(&s);
    // Also the tets at every 97th point, as a mesher that lost them would.
    m.tets.retain(|t| t.iter().all(|x| x % 97 != 0));
    m.labels.truncate(m.tets.len());
    let mut used = vec![false; m.points.len()];
    for t in &m.tets {
        for &x in t {
            used[x as usize] = true;
        }
    }
    let mut new_id = vec![u32::MAX; m.points.len()];
    let mut points = Vec::new();
    for (i, p) in m.points.iter().enumerate() {
        if used[i] {
            new_id[i] = points.len() as u32;
            points.push(*p);
        }
    }
    let dropped = m.points.len() - points.len();
    assert!(dropped > 0, "the trimmed mesh uses every point");
    m.points = points;
    for t in &mut m.tets {
        *t = t.map(|x| new_id[x as usize]);
    }
    m.rebuild_neighbors();
    let r = recover(&mut m, &s, &RecoverOptions::default()).unwrap();
    assert_eq!(r.surface_points_reinserted, dropped, "{r:?}");
    assert!(r.is_complete(), "{} unrecovered", r.missing_after);
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
    let (v, v0) = (mesh_volume(&m), enclosed_volume(&s));
    assert!((v - v0).abs() < 1e-9 * v0, "volume {v} vs {v0}");
}

/// The seed's method alone: no new point.
fn no_steiner() -> RecoverOptions {
    RecoverOptions {
        allow_interior_steiner: false,
        ..RecoverOptions::default()
    }
}

/// trimesh's `creation.box` face list: its face diagonals admit no tetrahedralization of the
/// eight corners, so one interior point is needed.
fn twisted_cube() -> SurfaceMesh {
    let p: Vec<P3> = (0..8)
        .map(|i| {
            [
                (i >> 2 & 1) as f64 - 0.5,
                (i >> 1 & 1) as f64 - 0.5,
                (i & 1) as f64 - 0.5,
            ]
        })
        .collect();
    let tris = vec![
        [1, 3, 0],
        [4, 1, 0],
        [0, 3, 2],
        [2, 4, 0],
        [1, 7, 3],
        [5, 1, 4],
        [5, 7, 1],
        [3, 7, 2],
        [6, 4, 2],
        [2, 7, 6],
        [6, 5, 4],
        [7, 5, 6],
    ];
    SurfaceMesh::closed(p, tris, 1)
}

#[test]
fn a_cube_whose_diagonals_twist_gets_one_interior_point() {
    let s = twisted_cube();
    assert!(biotet::mesh::validate::validate_surface(&mut s.clone(), &Default::default()).is_ok());
    let p = s.points.clone();
    // Without new points the seed's method cannot finish ...
    let mut m = Delaunay::new(&p).unwrap().to_tet_mesh();
    let r = recover(&mut m, &s, &no_steiner()).unwrap();
    assert!(!r.is_complete());
    // ... with the fallback (the default) one point strictly inside, never on the surface.
    let mut m = Delaunay::new(&p).unwrap().to_tet_mesh();
    let r = recover(&mut m, &s, &RecoverOptions::default()).unwrap();
    assert!(r.is_complete(), "{r:?}");
    assert_eq!(r.steiner_points, 1);
    assert_eq!(m.points.len(), 9);
    let q = m.points[8];
    assert!(
        q.iter().all(|&c| c > -0.5 && c < 0.5),
        "{q:?} not strictly inside"
    );
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
    assert!((mesh_volume(&m) - 1.0).abs() < 1e-12);
}

/// Meshed as `biotet mesh` does (the Delaunay holds eight far box corners too), a missing face of
/// the twisted cube carves a cavity whose cells are the cube's inside (twelve faces, no fill) and
/// the space between the cube and the box (thirty faces, a fill). Searched smallest first, the
/// inside's failure ends each call before the outside is filled: the largest call visited 39
/// search nodes when the cells were searched in their own order, 16 now.
#[test]
fn recovery_proves_a_cell_empty_before_filling_the_others() {
    let s = twisted_cube();
    let (m, report) = mesh_pipeline(&s, biotet::pipeline::PipelineOptions::default());
    let r = report.recover.as_ref().unwrap();
    assert!(r.is_complete(), "{r:?}");
    assert_eq!(r.steiner_points, 1);
    assert!(r.nodes_max < 30, "{r:?}");
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
    assert!((mesh_volume(&m) - 1.0).abs() < 1e-12);
}

/// `s` meshed by the pipeline at its default size.
fn mesh_pipeline(
    s: &SurfaceMesh,
    opts: biotet::pipeline::PipelineOptions,
) -> (TetMesh, biotet::pipeline::MeshReport) {
    let sizing = crate::common::default_sizing(s);
    biotet::pipeline::mesh_surface(s, &sizing, &opts, &mut |_| {}).unwrap()
}

/// Without new points the twisted cube cannot be recovered whole, and the flood fill cannot
/// label the regions a missing face joins. Their tets get a centroid test on the mesh recovery
/// left (the pipeline leaves those labels to recovery): the whole cube stays, and only the
/// triangles recovery itself left are missing. With the labels the Delaunay's tets had, the
/// outside took four more triangles and a third of the cube.
#[test]
fn an_unrecovered_cube_keeps_its_inside() {
    let s = twisted_cube();
    let mut opts = biotet::pipeline::PipelineOptions::default();
    if let Some(r) = opts.recover.as_mut() {
        r.allow_interior_steiner = false;
    }
    if let Some(p) = opts.polish.as_mut() {
        p.insert = false;
    }
    let (m, report) = mesh_pipeline(&s, opts);
    let r = report.recover.as_ref().unwrap();
    assert!(r.label_conflicts > 0 && r.centroid_tests > 0, "{r:?}");
    assert_eq!(report.n_centroid_tests, r.centroid_tests);
    assert!(!r.unrecovered.is_empty());
    for u in &r.unrecovered {
        assert!(u.reason.contains("search exhausted"), "{u:?}");
    }
    assert_eq!(r.missing_after, r.unrecovered.len());
    let c = check(&m, None);
    assert!(c.valid, "{c}");
    assert!((mesh_volume(&m) - 1.0).abs() < 1e-12, "{}", mesh_volume(&m));
}

/// Points no triangle uses (a file's stray nodes) are left out of the mesh: one on a face and
/// one on an edge of the cube used to block those triangles' recovery, and one inside became a
/// node nobody asked for.
#[test]
fn points_no_triangle_uses_are_left_out() {
    let mut s = crate::common::cube_surface([0.0; 3], 1.0);
    let stray = [
        [1.0 / 3.0, 1.0 / 3.0, 0.0],
        [0.5, 0.0, 0.0],
        [0.3, 0.6, 0.45],
    ];
    s.points.extend_from_slice(&stray);
    let (m, report) = mesh_pipeline(&s, biotet::pipeline::PipelineOptions::default());
    assert_eq!(report.n_unused_points, 3);
    assert_eq!(report.missing_triangles, 0);
    assert!(!m.points.iter().any(|p| stray.contains(p)));
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
    assert!((mesh_volume(&m) - 1.0).abs() < 1e-12);
}

/// The pipeline recovers the faces of a cube fanned from a corner (coplanar points the
/// Delaunay splits another way) in small cavities with a few interior points, not by searches
/// of cavities of a hundred tets and more (189 nodes, 140 ms before the bounds escalated).
#[test]
fn fanned_faces_are_recovered_in_small_cavities() {
    let s = crate::common::load_shape("gen_cube_fans.off");
    let (m, report) = mesh_pipeline(&s, biotet::pipeline::PipelineOptions::default());
    let r = report.recover.as_ref().unwrap();
    assert!(r.is_complete(), "{r:?}");
    assert!(r.nodes_max < 100, "{r:?}");
    assert!(r.steiner_points > 0 && r.steiner_points < 20, "{r:?}");
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
    assert!((mesh_volume(&m) - enclosed_volume(&s)).abs() < 1e-9 * enclosed_volume(&s));
}

/// Steiner points put in cavity cells outside the surface go with the outside tets: recovery
/// alone on the brain's Delaunay with small first cavities (the pipeline's bounds) put 8 such
/// points in, and the mesh it returned had points no tet used.
#[test]
fn steiner_points_outside_the_surface_are_dropped() {
    let s = crate::common::load_stl("brain_20k.stl");
    let mut m = Delaunay::new(&s.points).unwrap().to_tet_mesh();
    let n = m.points.len();
    let opts = RecoverOptions {
        first_cavity_tets: biotet::lastresort::recover::PIPELINE_FIRST_CAVITY_TETS,
        ..RecoverOptions::default()
    };
    let r = recover(&mut m, &s, &opts).unwrap();
    assert!(r.is_complete(), "{} unrecovered", r.missing_after);
    assert!(r.steiner_points > 0, "{r:?}");
    assert_eq!(m.points.len(), n + r.steiner_points);
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
}

/// A plate with a row of hexagonal holes (their walls nearly coplanar along each row): with a
/// first cavity bound of 300 tets instead of the pipeline's 40, recovery's Steiner fallback met
/// cells whose kernels are thin slivers of long cells reaching the enclosing box's corners,
/// which the kernel point's ascent missed; the inset fallback then left 2 triangles and the run
/// failed. The linear program finds those kernels.
#[test]
fn extrude_holes_meshes_with_large_first_cavities() {
    let s = crate::common::load_shape("tm_extrude_holes.off");
    let mut opts = biotet::pipeline::PipelineOptions::default();
    if let Some(r) = opts.recover.as_mut() {
        r.first_cavity_tets = 300;
    }
    let (m, report) = mesh_pipeline(&s, opts);
    let r = report.recover.as_ref().unwrap();
    assert!(r.is_complete(), "{:?}", r.unrecovered);
    assert_eq!(report.missing_triangles, 0);
    let c = check(&m, Some(&s));
    assert!(c.valid, "{c}");
    assert!((mesh_volume(&m) - enclosed_volume(&s)).abs() < 1e-9 * enclosed_volume(&s));
}
