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
    let pts: Vec<P3> = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    // Outward faces, then reversed to point inwards.
    let out = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    let shell: Vec<[u32; 3]> = out.iter().map(|f| [f[0], f[2], f[1]]).collect();
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

/// SplitMix64 points in the unit cube.
fn random_points(n: usize, mut seed: u64) -> Vec<P3> {
    let mut next = move || {
        seed = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n).map(|_| [next(), next(), next()]).collect()
}

#[test]
fn search_refills_delaunay_cavities() {
    // Carve the tets around a few vertices of a random Delaunay mesh and fill the cavity again:
    // a fill exists (the carved tets), the search must find one.
    use biotet::delaunay::Delaunay;
    let pts = random_points(2000, 7);
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
