//! Tests: the 3D Delaunay tetrahedralization (`biotet::delaunay`).
//!
//! Every triangulation made here goes through [`validate`]: the validity checker, the local
//! Delaunay property of every interior face under the perturbed in-sphere test, convexity of the
//! hull (exact), Euler's relation, every input point a vertex through the duplicate map, and the
//! tets' volumes summing to the hull's volume. Small sets are compared tet by tet with a
//! brute-force implementation (which, with the perturbation, is unique even for degenerate sets);
//! a larger random set with Qhull through scipy when it is installed.

use biotet::TetMesh;
use biotet::check::check;
use biotet::delaunay::{Delaunay, DelaunayError, INFINITE};
use biotet::geom::filter;
use biotet::geom::predicates::{Sign, insphere_sos, orient3d};
use biotet::mesh::tet::{NO_NEIGHBOR, TET_EDGES, TET_FACES};
use std::collections::HashMap;

/// SplitMix64, for reproducible test inputs.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

fn random_points(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = Rng(seed);
    (0..n).map(|_| [r.unit(), r.unit(), r.unit()]).collect()
}

fn lattice(nx: usize, ny: usize, nz: usize) -> Vec<[f64; 3]> {
    let mut p = Vec::with_capacity(nx * ny * nz);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                p.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    p
}

/// All integer points with x² + y² + z² = r2.
fn sphere_points(r2: i64) -> Vec<[f64; 3]> {
    let r = (r2 as f64).sqrt() as i64 + 1;
    let mut p = Vec::new();
    for x in -r..=r {
        for y in -r..=r {
            for z in -r..=r {
                if x * x + y * y + z * z == r2 {
                    p.push([x as f64, y as f64, z as f64]);
                }
            }
        }
    }
    p
}

fn vol6(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
    u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0])
}

/// The vertex numbering the triangulation must use: first occurrences in input order.
fn expected_vertex_map(points: &[[f64; 3]]) -> (Vec<u32>, usize) {
    let mut first: HashMap<[u64; 3], u32> = HashMap::new();
    let mut map = Vec::with_capacity(points.len());
    for p in points {
        let key = p.map(|c| (c + 0.0).to_bits());
        let n = first.len() as u32;
        map.push(*first.entry(key).or_insert(n));
    }
    let n = first.len();
    (map, n)
}

/// Build, validate everything, return the mesh.
fn build_and_validate(points: &[[f64; 3]]) -> TetMesh {
    let dt = match Delaunay::new(points) {
        Ok(dt) => dt,
        Err(e) => panic!("Delaunay::new failed: {e}"),
    };
    validate(points, &dt)
}

/// All the checks of the issue on the triangulation `dt` of `points` (every input point, in
/// order, duplicates included).
fn validate(points: &[[f64; 3]], dt: &Delaunay) -> TetMesh {
    let mesh = dt.to_tet_mesh();
    // Validity: orientation, conformity, adjacency, no unused or duplicate points.
    let report = check(&mesh, None);
    assert!(report.valid, "{report}");
    assert_eq!(mesh.n_tets(), dt.n_finite_tets());

    // Every input point is a vertex, numbered by first occurrence.
    let (want, nv) = expected_vertex_map(points);
    assert_eq!(dt.n_input_points(), points.len());
    assert_eq!(dt.n_vertices(), nv);
    assert_eq!(mesh.points.len(), nv);
    assert_eq!(dt.vertex_map(), want);
    for (i, p) in points.iter().enumerate() {
        let v = dt.vertex_of_input(i) as usize;
        assert_eq!(mesh.points[v], *p, "input {i} is not vertex {v}");
    }

    // Local Delaunay under the perturbed in-sphere test, with the vertex numbers as indices.
    for (t, nb) in mesh.neighbors.iter().enumerate() {
        let tv = mesh.tets[t];
        for (i, &u) in nb.iter().enumerate() {
            if u == NO_NEIGHBOR || (u as usize) < t {
                continue;
            }
            let uv = mesh.tets[u as usize];
            let opp = uv
                .iter()
                .copied()
                .find(|w| !tv.contains(w))
                .expect("neighbour has a vertex off the shared face");
            let c = mesh.corners(t);
            let s = insphere_sos(
                [c[0], c[1], c[2], c[3], mesh.points[opp as usize]],
                [tv[0], tv[1], tv[2], tv[3], opp],
            );
            assert_eq!(
                s,
                Sign::Negative,
                "face {i} of tet {t} {tv:?} is not locally Delaunay"
            );
            // And symmetrically from the other side.
            let c = mesh.corners(u as usize);
            let s = insphere_sos(
                [c[0], c[1], c[2], c[3], mesh.points[tv[i] as usize]],
                [uv[0], uv[1], uv[2], uv[3], tv[i]],
            );
            assert_eq!(s, Sign::Negative, "tet {u} sees vertex {} inside", tv[i]);
        }
    }

    // The hull is convex: every point on the inner side of every hull face or on its plane.
    let hull: Vec<[u32; 3]> = mesh
        .boundary_faces()
        .map(|(t, f)| mesh.face(t, f))
        .collect();
    for f in &hull {
        let [a, b, c] = f.map(|v| mesh.points[v as usize]);
        for q in &mesh.points {
            assert_ne!(
                filter::orient3d(a, b, c, *q),
                Sign::Positive,
                "hull face {f:?} is not convex: {q:?} outside"
            );
        }
    }

    // Euler: V - E + F - T = 1 for a triangulated ball.
    let mut edges: Vec<(u32, u32)> = mesh
        .tets
        .iter()
        .flat_map(|t| TET_EDGES.map(|[a, b]| (t[a].min(t[b]), t[a].max(t[b]))))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let n_t = mesh.n_tets() as i64;
    let n_f = (4 * n_t + hull.len() as i64) / 2;
    assert_eq!((4 * n_t + hull.len() as i64) % 2, 0);
    let euler = nv as i64 - edges.len() as i64 + n_f - n_t;
    assert_eq!(euler, 1, "V - E + F - T = {euler}");

    // Volumes: the tets fill the hull.
    let o = mesh.points[0];
    let tet_vol: f64 = (0..mesh.n_tets())
        .map(|t| {
            let c = mesh.corners(t);
            vol6(c[0], c[1], c[2], c[3])
        })
        .sum();
    let hull_vol: f64 = hull
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| mesh.points[v as usize]);
            vol6(o, a, b, c)
        })
        .sum();
    assert!(tet_vol > 0.0);
    assert!(
        (tet_vol - hull_vol).abs() <= 1e-9 * hull_vol.abs(),
        "tets {tet_vol} vs hull {hull_vol}"
    );

    // Ghost tets are the hull faces, consistently linked.
    assert_eq!(dt.n_hull_faces(), hull.len());
    for t in 0..dt.n_slots() as u32 {
        if dt.is_free(t) {
            continue;
        }
        let tv = dt.tet(t);
        assert!(!tv[..3].contains(&INFINITE));
        for (i, u) in dt.adjacent(t).into_iter().enumerate() {
            let (back, j) = dt.adjacent_face(t, i);
            assert_eq!(back, u);
            assert_eq!(dt.adjacent_face(u, j), (t, i), "link {t}.{i} is not mutual");
        }
    }
    mesh
}

/// The perturbed Delaunay tets of `points` (distinct) by brute force: every non-flat 4-tuple
/// whose perturbed circumsphere contains no other point. Sorted vertex quadruples.
fn brute_force(points: &[[f64; 3]]) -> Vec<[u32; 4]> {
    let n = points.len() as u32;
    let mut out = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            for c in b + 1..n {
                for d in c + 1..n {
                    let mut v = [a, b, c, d];
                    let q = |i: u32| points[i as usize];
                    match orient3d(q(a), q(b), q(c), q(d)) {
                        Sign::Zero => continue,
                        Sign::Negative => v.swap(2, 3),
                        Sign::Positive => {}
                    }
                    let empty = (0..n).filter(|e| !v.contains(e)).all(|e| {
                        filter::insphere_sos(
                            [q(v[0]), q(v[1]), q(v[2]), q(v[3]), q(e)],
                            [v[0], v[1], v[2], v[3], e],
                        ) == Sign::Negative
                    });
                    if empty {
                        out.push([a, b, c, d]);
                    }
                }
            }
        }
    }
    out.sort_unstable();
    out
}

fn sorted_tets(mesh: &TetMesh) -> Vec<[u32; 4]> {
    let mut t: Vec<[u32; 4]> = mesh
        .tets
        .iter()
        .map(|t| {
            let mut s = *t;
            s.sort_unstable();
            s
        })
        .collect();
    t.sort_unstable();
    t
}

fn assert_matches_brute_force(points: &[[f64; 3]]) {
    let mesh = build_and_validate(points);
    let want = brute_force(points);
    let got = sorted_tets(&mesh);
    assert_eq!(got.len(), want.len(), "tet count differs from brute force");
    assert_eq!(got, want, "tets differ from brute force");
}

#[test]
fn uniform_random_points() {
    let pts = random_points(10_000, 1);
    let mesh = build_and_validate(&pts);
    let per_point = mesh.n_tets() as f64 / pts.len() as f64;
    assert!(
        (5.5..7.0).contains(&per_point),
        "{per_point} tets per point"
    );
}

#[test]
fn lattice_20x20x20() {
    let pts = lattice(20, 20, 20);
    let mesh = build_and_validate(&pts);
    let vol: f64 = (0..mesh.n_tets())
        .map(|t| {
            let c = mesh.corners(t);
            vol6(c[0], c[1], c[2], c[3])
        })
        .sum();
    assert_eq!(vol, 6.0 * 19.0f64.powi(3), "integer volumes sum exactly");
}

#[test]
fn integer_points_on_a_sphere() {
    // 1032 lattice points on the sphere x² + y² + z² = 2966: every 5 of them cospherical.
    let pts = sphere_points(2966);
    assert_eq!(pts.len(), 1032);
    build_and_validate(&pts);
    // With the centre and a concentric sphere: interior cospherical sets as well.
    let mut pts = sphere_points(425);
    pts.extend(sphere_points(81));
    pts.push([0.0; 3]);
    build_and_validate(&pts);
}

#[test]
fn points_on_a_few_planes() {
    let mut r = Rng(3);
    let mut pts = Vec::new();
    // Random integer points on the planes z = 0, z = 7, x = 3 (inside the slab) and on the slanted
    // plane x + y + z = 12; lots of coplanar hull faces and coplanar interior quadruples.
    for _ in 0..400 {
        let (a, b) = (r.below(16) as f64, r.below(16) as f64);
        match r.below(4) {
            0 => pts.push([a, b, 0.0]),
            1 => pts.push([a, b, 7.0]),
            2 => pts.push([3.0, a, b * 7.0 / 15.0]),
            _ => pts.push([a, b, 12.0 - a - b]),
        }
    }
    build_and_validate(&pts);
    // A square grid in one plane plus two apexes: all but two points on one hull plane.
    let mut pts: Vec<[f64; 3]> = lattice(12, 12, 1);
    pts.push([5.5, 5.5, 3.0]);
    pts.push([2.0, 9.0, -1.0]);
    build_and_validate(&pts);
    // Only the surface of a lattice cube: every point is on a hull plane.
    let pts: Vec<[f64; 3]> = lattice(9, 9, 9)
        .into_iter()
        .filter(|p| p.iter().any(|&c| c == 0.0 || c == 8.0))
        .collect();
    build_and_validate(&pts);
    // Two parallel planes only.
    let pts: Vec<[f64; 3]> = lattice(10, 10, 2)
        .into_iter()
        .map(|p| [p[0], p[1], p[2] * 5.0])
        .collect();
    build_and_validate(&pts);
}

#[test]
fn nearly_degenerate_float_inputs() {
    // Points computed in floating point on a sphere, on tilted planes and on a lattice with a
    // spacing that is not a binary fraction: almost cospherical and coplanar, so the filters
    // fail and the exact predicates decide.
    let mut r = Rng(13);
    let mut pts = Vec::new();
    for _ in 0..1500 {
        let (u, v) = (r.unit() * std::f64::consts::TAU, r.unit() * 2.0 - 1.0);
        let w = (1.0 - v * v).sqrt();
        pts.push([0.3 + w * u.cos(), -0.2 + w * u.sin(), 0.1 + v]);
    }
    build_and_validate(&pts);
    let mut pts = Vec::new();
    let n = [0.36, -0.48, 0.8];
    for k in 0..4 {
        for _ in 0..300 {
            let (a, b) = (r.unit() * 4.0 - 2.0, r.unit() * 4.0 - 2.0);
            // Two directions in the plane orthogonal to n, offset along n.
            let (e1, e2) = ([0.8, 0.6, 0.0], [-0.48, 0.64, 0.6]);
            let o = f64::from(k) * 0.7;
            pts.push([0, 1, 2].map(|i| a * e1[i] + b * e2[i] + o * n[i]));
        }
    }
    build_and_validate(&pts);
    let pts: Vec<[f64; 3]> = lattice(9, 8, 7)
        .into_iter()
        .map(|p| p.map(|c| 0.1 * c + 0.05))
        .collect();
    build_and_validate(&pts);
}

#[test]
fn many_duplicates() {
    let mut r = Rng(4);
    let base = lattice(8, 8, 8);
    let extra = random_points(200, 5);
    let mut pts = Vec::new();
    for _ in 0..5000 {
        if r.below(10) == 0 {
            pts.push(extra[r.below(200) as usize]);
        } else {
            let p = base[r.below(base.len() as u64) as usize];
            // Sometimes a negative zero: the same point.
            pts.push(p.map(|c| if c == 0.0 && r.below(2) == 0 { -0.0 } else { c }));
        }
    }
    let mesh = build_and_validate(&pts);
    assert!(mesh.points.len() < 8 * 8 * 8 + 200);
    // Random points with a random subset repeated.
    let mut pts = random_points(3000, 6);
    for i in 0..3000 {
        let j = r.below(3000) as usize;
        pts.push(pts[j]);
        if i % 3 == 0 {
            pts.swap(i, 3000 + i);
        }
    }
    build_and_validate(&pts);
}

#[test]
fn brute_force_random() {
    for seed in 0..4 {
        assert_matches_brute_force(&random_points(35, 100 + seed));
    }
}

#[test]
fn brute_force_degenerate() {
    // Lattices: every cube's 8 corners cospherical, many coplanar quadruples.
    assert_matches_brute_force(&lattice(3, 3, 3));
    assert_matches_brute_force(&lattice(4, 3, 2));
    // Cospherical: the 30 integer points with x² + y² + z² = 9.
    let s = sphere_points(9);
    assert_eq!(s.len(), 30);
    assert_matches_brute_force(&s);
    // Points on planes, with coplanar hull faces.
    let mut r = Rng(7);
    let pts: Vec<[f64; 3]> = (0..30)
        .map(|i| {
            let (a, b) = (r.below(5) as f64, r.below(5) as f64);
            match i % 3 {
                0 => [a, b, 0.0],
                1 => [a, b, 2.0],
                _ => [0.0, a, b / 2.0],
            }
        })
        .collect();
    let (_, nv) = expected_vertex_map(&pts);
    let mut uniq: Vec<[f64; 3]> = Vec::new();
    for p in pts {
        if !uniq.contains(&p) {
            uniq.push(p);
        }
    }
    assert_eq!(uniq.len(), nv);
    assert_matches_brute_force(&uniq);
    // A grid in a plane and one apex, in shuffled orders: SoS decides by number, not order.
    for seed in 0..3 {
        let mut pts = lattice(4, 4, 1);
        pts.push([1.5, 1.5, 1.0]);
        let mut r = Rng(seed);
        for i in (1..pts.len()).rev() {
            pts.swap(i, r.below(i as u64 + 1) as usize);
        }
        assert_matches_brute_force(&pts);
    }
}

#[test]
fn incremental_insertion_gives_the_same_triangulation() {
    // The perturbed Delaunay triangulation is unique, so building from a part and inserting the
    // rest (one by one or as a batch) must give exactly the same tets; on a lattice this
    // exercises every degenerate decision.
    let mut pts = lattice(7, 6, 5);
    pts.extend(sphere_points(17).into_iter().map(|p| p.map(|c| c + 3.0)));
    let all = build_and_validate(&pts);
    let k = pts.len() / 3;

    let mut dt = Delaunay::new(&pts[..k]).unwrap();
    for (i, p) in pts[k..].iter().enumerate() {
        let v = dt.insert(*p).unwrap();
        assert_eq!(v, dt.vertex_of_input(k + i));
    }
    let one = validate(&pts, &dt);
    assert_eq!(sorted_tets(&one), sorted_tets(&all));

    let mut dt = Delaunay::new(&pts[..k]).unwrap();
    let vs = dt.insert_points(&pts[k..]).unwrap();
    assert_eq!(vs, dt.vertex_map()[k..].to_vec());
    let batch = validate(&pts, &dt);
    assert_eq!(sorted_tets(&batch), sorted_tets(&all));
}

#[test]
fn batch_insertion_with_duplicates() {
    // A batch repeating its own points and points already in the triangulation: numbering by
    // first occurrence, and the same triangulation as one build over everything.
    let mut r = Rng(12);
    let first: Vec<[f64; 3]> = lattice(4, 4, 4);
    let mut batch = Vec::new();
    for _ in 0..400 {
        let p = [
            r.below(7) as f64 - 1.0,
            r.below(6) as f64,
            r.below(5) as f64 - 0.5,
        ];
        batch.push(p);
        if r.below(4) == 0 {
            batch.push(first[r.below(64) as usize]);
        }
    }
    let mut dt = Delaunay::new(&first).unwrap();
    let vs = dt.insert_points(&batch).unwrap();
    let mut all = first.clone();
    all.extend_from_slice(&batch);
    assert_eq!(vs, dt.vertex_map()[first.len()..].to_vec());
    let mesh = validate(&all, &dt);
    assert_eq!(sorted_tets(&mesh), sorted_tets(&build_and_validate(&all)));
    // And inserted one by one.
    let mut dt = Delaunay::new(&first).unwrap();
    for p in &batch {
        dt.insert(*p).unwrap();
    }
    assert_eq!(sorted_tets(&validate(&all, &dt)), sorted_tets(&mesh));
}

#[test]
fn insertion_outside_and_on_the_hull() {
    // Start from a small block and insert points outside it, on its hull planes and duplicates.
    let mut pts = lattice(3, 3, 3);
    let mut dt = Delaunay::new(&pts).unwrap();
    let mut r = Rng(9);
    for _ in 0..300 {
        let p = [
            r.below(9) as f64 - 3.0,
            r.below(9) as f64 - 3.0,
            r.below(9) as f64 - 3.0,
        ];
        pts.push(p);
        dt.insert(p).unwrap();
    }
    let mesh = validate(&pts, &dt);
    assert_eq!(sorted_tets(&mesh), sorted_tets(&build_and_validate(&pts)));
}

#[test]
fn nearly_all_collinear_or_coplanar() {
    // The first tet needs points found deep in the insertion order.
    let mut pts: Vec<[f64; 3]> = (0..500).map(|i| [f64::from(i), 0.0, 0.0]).collect();
    pts.push([3.5, 2.0, 0.0]);
    pts.push([7.0, 1.0, -4.0]);
    build_and_validate(&pts);
    let mut pts: Vec<[f64; 3]> = lattice(30, 30, 1);
    pts.insert(417, [3.0, 4.0, 1.0]);
    build_and_validate(&pts);
}

#[test]
fn from_points_is_new() {
    let mut pts = random_points(2000, 14);
    pts.extend_from_within(..300);
    let a = Delaunay::new(&pts).unwrap();
    let b = Delaunay::from_points(pts.clone()).unwrap();
    assert_eq!(a.to_tet_mesh(), b.to_tet_mesh());
    assert_eq!(a.vertex_map(), b.vertex_map());
    validate(&pts, &b);
}

#[test]
fn deterministic() {
    let pts = random_points(3000, 11);
    let a = Delaunay::new(&pts).unwrap().to_tet_mesh();
    let b = Delaunay::new(&pts).unwrap().to_tet_mesh();
    assert_eq!(a, b);
}

#[test]
fn degenerate_inputs_are_errors() {
    let too_few = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]];
    assert_eq!(
        Delaunay::new(&too_few).unwrap_err(),
        DelaunayError::TooFewPoints { distinct: 3 }
    );
    let line: Vec<[f64; 3]> = (0..50).map(|i| [i as f64, 2.0 * i as f64, 1.0]).collect();
    assert_eq!(Delaunay::new(&line).unwrap_err(), DelaunayError::Collinear);
    let plane: Vec<[f64; 3]> = lattice(6, 6, 1)
        .into_iter()
        .map(|p| [p[0], p[1], p[0] + p[1]])
        .collect();
    assert_eq!(Delaunay::new(&plane).unwrap_err(), DelaunayError::Coplanar);
    let mut nan = random_points(10, 1);
    nan[4][1] = f64::NAN;
    assert_eq!(
        Delaunay::new(&nan).unwrap_err(),
        DelaunayError::NonFinite { index: 4 }
    );
    let mut huge = random_points(10, 2);
    huge[7][2] = -1e200;
    assert_eq!(
        Delaunay::new(&huge).unwrap_err(),
        DelaunayError::OutOfRange { index: 7 }
    );
    assert!(Delaunay::new(&[]).is_err());
    // Exactly four points: one tet.
    let four = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mesh = build_and_validate(&four);
    assert_eq!(mesh.n_tets(), 1);
}

#[test]
fn qhull_through_scipy_agrees() {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let probe = Command::new("python3")
        .args(["-c", "import scipy.spatial"])
        .output();
    if !matches!(probe, Ok(ref o) if o.status.success()) {
        eprintln!("skipped: python3 with scipy is not available");
        return;
    }
    let pts = random_points(3000, 21);
    let script = "import sys, numpy as np\n\
        from scipy.spatial import Delaunay\n\
        p = np.loadtxt(sys.stdin).reshape(-1, 3)\n\
        s = np.sort(Delaunay(p).simplices, axis=1)\n\
        for t in s: print(*t)\n";
    let mut child = Command::new("python3")
        .args(["-c", script])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("python3 runs");
    {
        let mut stdin = child.stdin.take().expect("stdin");
        let mut text = String::new();
        for p in &pts {
            text.push_str(&format!("{:e} {:e} {:e}\n", p[0], p[1], p[2]));
        }
        stdin.write_all(text.as_bytes()).expect("write points");
    }
    let out = child.wait_with_output().expect("python3 finishes");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut qhull: Vec<[u32; 4]> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            let v: Vec<u32> = l.split_whitespace().map(|w| w.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect();
    qhull.sort_unstable();
    let mesh = build_and_validate(&pts);
    assert_eq!(mesh.n_tets(), qhull.len(), "tet count differs from Qhull");
    assert_eq!(sorted_tets(&mesh), qhull, "tets differ from Qhull");
}

#[test]
fn face_table_consistency() {
    // The ghost convention: a ghost's hull face is counter-clockwise seen from outside.
    let pts = lattice(3, 3, 3);
    let dt = Delaunay::new(&pts).unwrap();
    let vp = dt.vertex_points();
    for t in 0..dt.n_slots() as u32 {
        if !dt.is_ghost(t) {
            continue;
        }
        let v = dt.tet(t);
        assert_eq!(v[3], INFINITE);
        let (a, b, c) = (vp[v[0] as usize], vp[v[1] as usize], vp[v[2] as usize]);
        for q in &vp {
            assert_ne!(orient3d(a, b, c, *q), Sign::Positive);
        }
        let (u, j) = dt.adjacent_face(t, 3);
        assert!(dt.is_finite(u));
        let l = TET_FACES[j];
        let w = dt.tet(u);
        let mut f = [w[l[0]], w[l[1]], w[l[2]]];
        f.sort_unstable();
        let mut g = [v[0], v[1], v[2]];
        g.sort_unstable();
        assert_eq!(f, g);
    }
}

/// Scaling by a power of two is exact, so the triangulation must not change — down to the
/// smallest scale the predicates are exact at, and up to the largest.
#[test]
fn power_of_two_scales_give_the_same_tets_and_out_of_range_is_refused() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        // In [0.001, 1): far from zero, so scaled coordinates stay in range.
        0.001 + 0.999 * ((state >> 11) as f64 / (1u64 << 53) as f64)
    };
    let pts: Vec<[f64; 3]> = (0..1500).map(|_| [next(), next(), next()]).collect();
    let reference = biotet::delaunay::Delaunay::new(&pts).unwrap().to_tet_mesh();
    for k in [-80, -40, 40, 150] {
        let s = 2f64.powi(k);
        let scaled: Vec<[f64; 3]> = pts.iter().map(|p| p.map(|c| c * s)).collect();
        let m = biotet::delaunay::Delaunay::new(&scaled)
            .unwrap()
            .to_tet_mesh();
        assert_eq!(m.tets, reference.tets, "scale 2^{k}");
        assert!(biotet::check::check(&m, None).valid, "scale 2^{k}");
    }
    // Below the exact range (differences would underflow) and above it: a clear error.
    for s in [2f64.powi(-250), 1e-80, 1e60] {
        let scaled: Vec<[f64; 3]> = pts.iter().map(|p| p.map(|c| c * s)).collect();
        let e = biotet::delaunay::Delaunay::new(&scaled).unwrap_err();
        assert!(
            matches!(e, biotet::delaunay::DelaunayError::OutOfRange { .. }),
            "scale {s}: {e}"
        );
    }
    // A unit tet with a cluster of tiny points: refused, not silently meshed wrong.
    let mut cluster = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    cluster.push([1e-80, 2e-80, 3e-80]);
    assert!(biotet::delaunay::Delaunay::new(&cluster).is_err());
}
