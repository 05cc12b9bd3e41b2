//! Solid-angle smoothing (chapter 4): the analytic gradient, the ascent direction, and the
//! smoother's guarantees on synthetic and real meshes (TetGen's and biotet's brain meshes).

use crate::common::{cube_surface, load_stl, tetgen_brain};
use biotet::check::check;
use biotet::delaunay::Delaunay;
use biotet::geom::predicates::{Sign, orient3d};
use biotet::pipeline::{PipelineOptions, mesh_surface};
use biotet::quality::QualityReport;
use biotet::quality::tet::solid_angles;
use biotet::sizing::Sizing;
use biotet::smooth::ascent::min_norm_point;
use biotet::smooth::gradient::solid_angle_gradients;
use biotet::smooth::slide::SlideSurface;
use biotet::smooth::{
    Boundary, SmoothError, SmoothOptions, SmoothReport, smooth, solid_angle_share_below,
};
use biotet::{SurfaceMesh, TetMesh};

/// A small deterministic generator (xorshift), uniform in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn point(&mut self) -> [f64; 3] {
        [self.next(), self.next(), self.next()]
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A random positively oriented tet with a volume not too small.
fn random_tet(r: &mut Rng) -> [[f64; 3]; 4] {
    loop {
        let mut c = [r.point(), r.point(), r.point(), r.point()];
        if orient3d(c[0], c[1], c[2], c[3]) == Sign::Negative {
            c.swap(0, 1);
        }
        if biotet::quality::tet::volume(&c) > 0.005 {
            return c;
        }
    }
}

#[test]
fn gradient_matches_finite_differences() {
    let mut r = Rng(0x9e37_79b9_7f4a_7c15);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let c = random_tet(&mut r);
        for k in 0..4 {
            let (omega, grads) = solid_angle_gradients(&c, k);
            assert_eq!(omega, solid_angles(&c), "values are the quality module's");
            for axis in 0..3 {
                let h = 1e-6;
                let (mut p, mut m) = (c, c);
                p[k][axis] += h;
                m[k][axis] -= h;
                let (sp, sm) = (solid_angles(&p), solid_angles(&m));
                for i in 0..4 {
                    let fd = (sp[i] - sm[i]) / (2.0 * h);
                    let err = (fd - grads[i][axis]).abs() / (1.0 + fd.abs());
                    worst = worst.max(err);
                    assert!(
                        err < 1e-6,
                        "d(angle {i})/d(corner {k}.{axis}): analytic {} vs fd {fd}",
                        grads[i][axis]
                    );
                }
            }
        }
    }
    // The four angles' gradients are not trivially equal: the test would catch a gradient that
    // only handles the angle at the moving corner.
    assert!(worst < 1e-6);
}

#[test]
fn gradient_of_the_sum_of_angles_at_a_flat_limit() {
    // Moving the apex of a tet straight away from its base raises the apex's solid angle only
    // while it is near, and the base corners' angles always: check signs on a simple tet.
    let c = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.2, 0.2, 0.05],
    ];
    assert_eq!(orient3d(c[0], c[1], c[2], c[3]), Sign::Positive);
    let (_, g) = solid_angle_gradients(&c, 3);
    // The base corners' angles grow as the apex rises.
    for (i, gi) in g.iter().enumerate().take(3) {
        assert!(gi[2] > 0.0, "angle {i}");
    }
    // The apex's angle (nearly 2π when flat) shrinks as it rises.
    assert!(g[3][2] < 0.0);
}

#[test]
fn min_norm_point_is_optimal() {
    let mut r = Rng(12345);
    for case in 0..300 {
        let m = 1 + case % 6;
        // Gradients mostly in one half-space so the answer is often non-zero.
        let g: Vec<[f64; 3]> = (0..m)
            .map(|_| {
                let p = r.point();
                [p[0] * 2.0 - 0.6, p[1] * 2.0 - 1.0, p[2] * 2.0 - 1.0]
            })
            .collect();
        let d = min_norm_point(&g);
        let dd = dot(d, d);
        // Optimality: every gradient raises along d at least |d|² (or d = 0).
        for x in &g {
            assert!(dot(*x, d) >= dd - 1e-9, "case {case}: {g:?} → {d:?}");
        }
        // No convex combination found by sampling is shorter.
        for _ in 0..200 {
            let w: Vec<f64> = (0..m).map(|_| r.next()).collect();
            let s: f64 = w.iter().sum();
            let mut p = [0.0; 3];
            for (wi, x) in w.iter().zip(&g) {
                for a in 0..3 {
                    p[a] += wi / s * x[a];
                }
            }
            assert!(
                dot(p, p) >= dd - 1e-9,
                "case {case}: {p:?} shorter than {d:?}"
            );
        }
    }
    // Two opposite gradients: no ascent direction.
    assert_eq!(
        min_norm_point(&[[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]]),
        [0.0; 3]
    );
    // Two orthogonal unit gradients: the diagonal.
    let d = min_norm_point(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    assert!((d[0] - 0.5).abs() < 1e-15 && (d[1] - 0.5).abs() < 1e-15 && d[2] == 0.0);
}

/// The unit cube meshed by Delaunay from a jittered n³ lattice: interior points jittered in 3D,
/// face points within their face, edge and corner points exact.
fn jittered_cube(n: usize, amount: f64, seed: u64) -> TetMesh {
    let mut r = Rng(seed);
    let h = 1.0 / (n - 1) as f64;
    let mut pts = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let idx = [i, j, k];
                let mut p = idx.map(|a| a as f64 * h);
                for a in 0..3 {
                    if idx[a] != 0 && idx[a] != n - 1 {
                        p[a] += (r.next() - 0.5) * amount * h;
                    }
                }
                pts.push(p);
            }
        }
    }
    let dt = Delaunay::new(&pts).expect("delaunay");
    dt.to_tet_mesh()
}

fn boundary_nodes(mesh: &TetMesh) -> Vec<bool> {
    let mut b = vec![false; mesh.points.len()];
    for (t, f) in mesh.boundary_faces() {
        for v in mesh.face(t, f) {
            b[v as usize] = true;
        }
    }
    b
}

fn min_solid(mesh: &TetMesh) -> f64 {
    QualityReport::of(mesh).min_solid_angle_sr.unwrap()
}

/// The properties every smoothing must keep: same arrays but coordinates, valid, positive by
/// exact orient3d, minimum not lower, history monotone.
fn assert_kept(before: &TetMesh, after: &TetMesh, report: &SmoothReport) {
    let c = check(after, None);
    assert!(c.valid, "{c}");
    assert_kept_unchecked(before, after, report);
}

/// [`assert_kept`] without requiring the output to pass the checker (for inputs that do not:
/// biotet's meshes before boundary recovery).
fn assert_kept_unchecked(before: &TetMesh, after: &TetMesh, report: &SmoothReport) {
    assert_eq!(before.tets, after.tets, "connectivity unchanged");
    assert_eq!(before.labels, after.labels);
    assert_eq!(before.neighbors, after.neighbors);
    assert_eq!(before.points.len(), after.points.len());
    for t in 0..after.tets.len() {
        let c = after.corners(t);
        assert_eq!(orient3d(c[0], c[1], c[2], c[3]), Sign::Positive, "tet {t}");
    }
    let (m0, m1) = (min_solid(before), min_solid(after));
    assert!(m1 >= m0, "min solid angle fell: {m0} → {m1}");
    assert_eq!(report.min_solid_angle_before_sr, m0);
    assert_eq!(report.min_solid_angle_after_sr, m1);
    let mut prev = m0;
    for s in &report.history {
        assert!(s.min_solid_angle_sr >= prev, "{:?}", report.history);
        prev = s.min_solid_angle_sr;
    }
}

#[test]
fn fixed_cube_improves_and_keeps_the_surface() {
    let before = jittered_cube(7, 0.7, 7);
    let mut mesh = before.clone();
    let report = smooth(&mut mesh, None, &SmoothOptions::default()).unwrap();
    assert_kept(&before, &mesh, &report);
    let b = boundary_nodes(&before);
    let mut moved_inside = 0;
    for (v, (p, q)) in before.points.iter().zip(&mesh.points).enumerate() {
        if b[v] {
            assert_eq!(
                p.map(f64::to_bits),
                q.map(f64::to_bits),
                "surface node {v} moved"
            );
        } else if p != q {
            moved_inside += 1;
        }
    }
    assert!(moved_inside > 0);
    assert_eq!(report.max_surface_distance, 0.0);
    assert!(
        report.min_solid_angle_after_sr > report.min_solid_angle_before_sr,
        "{report:?}"
    );
    // The share of small angles falls.
    assert!(solid_angle_share_below(&mesh, 0.2) < solid_angle_share_below(&before, 0.2));
}

#[test]
fn slide_cube_stays_on_its_faces_and_keeps_corners_and_edges() {
    let before = jittered_cube(7, 0.7, 11);
    let mut mesh = before.clone();
    let opts = SmoothOptions {
        boundary: Boundary::Slide,
        ..SmoothOptions::default()
    };
    let report = smooth(&mut mesh, None, &opts).unwrap();
    assert_kept(&before, &mesh, &report);
    let b = boundary_nodes(&before);
    let on_plane = |x: f64| x == 0.0 || x == 1.0;
    let mut slid = 0;
    for (v, (p, q)) in before.points.iter().zip(&mesh.points).enumerate() {
        if !b[v] {
            continue;
        }
        let planes = p.iter().filter(|&&x| on_plane(x)).count();
        if planes >= 2 {
            // On a cube edge or corner: a feature; never moves.
            assert_eq!(p, q, "edge/corner node {v} moved");
            continue;
        }
        // On one face: the coordinate that puts it there is kept within round-off, the others
        // stay inside the face.
        let a = p.iter().position(|&x| on_plane(x)).unwrap();
        assert!(
            (q[a] - p[a]).abs() <= 1e-15,
            "node {v} left its face: {p:?} → {q:?}"
        );
        for (i, &x) in q.iter().enumerate() {
            if i != a {
                assert!(x > 0.0 && x < 1.0, "node {v} crossed a cube edge: {q:?}");
            }
        }
        slid += usize::from(p != q);
    }
    assert!(slid > 10, "only {slid} surface nodes slid");
    assert!(report.n_sliding_nodes > 0 && report.n_feature_nodes > 0);
    assert!(
        report.max_surface_distance <= 1e-15,
        "{}",
        report.max_surface_distance
    );
    // Sliding does at least as well as fixing the surface on the same mesh.
    let mut fixed = before.clone();
    let rf = smooth(&mut fixed, None, &SmoothOptions::default()).unwrap();
    assert!(report.min_solid_angle_after_sr >= rf.min_solid_angle_after_sr * 0.999);
}

#[test]
fn slide_on_an_explicit_surface_matches_the_own_boundary() {
    // The cube's 12-triangle surface given explicitly: the interior of each face is one or two
    // triangles, and nodes cross the face diagonals while sliding.
    let before = jittered_cube(6, 0.7, 3);
    let surface = cube_surface([0.0; 3], 1.0);
    let opts = SmoothOptions {
        boundary: Boundary::Slide,
        ..SmoothOptions::default()
    };
    let mut mesh = before.clone();
    let report = smooth(&mut mesh, Some(&surface), &opts).unwrap();
    assert_kept(&before, &mesh, &report);
    // Mesh face nodes are not surface vertices: they stay (counted), corners are vertices but
    // features.
    assert!(report.n_unlocated_nodes > 0);
    assert_eq!(report.n_sliding_nodes, 0);
}

#[test]
fn slide_walks_across_triangles_and_stops_at_features() {
    let s = cube_surface([0.0; 3], 2.0);
    let slide = SlideSurface::new(&s, 45.0);
    // Every cube vertex is on a feature edge.
    for v in 0..s.points.len() as u32 {
        assert!(slide.is_feature_vertex(v));
    }
    // A flat square of two triangles, 4×4, one crossable diagonal, border edges features; a
    // walk from one triangle into the other lands on the plane z = 0 inside the square.
    let flat = SurfaceMesh::closed(
        vec![
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [4.0, 4.0, 0.0],
            [0.0, 4.0, 0.0],
        ],
        vec![[0, 1, 2], [0, 2, 3]],
        1,
    );
    let slide = SlideSurface::new(&flat, 45.0);
    let start = biotet::smooth::slide::Location {
        tri: 0,
        bary: [0.5, 0.25, 0.25],
    };
    let p0 = slide.point(&start);
    assert_eq!(p0, [2.0, 1.0, 0.0]);
    // Up across the diagonal, with a normal component that must be dropped.
    let (loc, p) = slide
        .walk(&start, [-1.0, 2.0, 5.0])
        .expect("crosses the diagonal");
    assert_eq!(loc.tri, 1);
    assert!(
        (p[0] - 1.0).abs() < 1e-12 && (p[1] - 3.0).abs() < 1e-12 && p[2] == 0.0,
        "{p:?}"
    );
    // Out through the border: refused.
    assert!(slide.walk(&start, [0.0, -3.0, 0.0]).is_none());
}

#[test]
fn smoothing_is_deterministic() {
    let before = jittered_cube(6, 0.8, 5);
    let opts = SmoothOptions {
        boundary: Boundary::Slide,
        ..SmoothOptions::default()
    };
    let (mut a, mut b) = (before.clone(), before);
    smooth(&mut a, None, &opts).unwrap();
    smooth(&mut b, None, &opts).unwrap();
    assert_eq!(bits(&a), bits(&b));
}

fn bits(m: &TetMesh) -> Vec<[u64; 3]> {
    m.points.iter().map(|p| p.map(f64::to_bits)).collect()
}

/// Smooth a copy of `before` inside a pool of `threads` threads.
fn smooth_with_threads(
    before: &TetMesh,
    opts: &SmoothOptions,
    threads: usize,
) -> (TetMesh, SmoothReport) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut m = before.clone();
        let r = smooth(&mut m, None, opts).unwrap();
        (m, r)
    })
}

/// Parallel sweeps give the same coordinates bit for bit for 1, 2 and 4 threads, on a real mesh
/// (TetGen's of the brain surface, sliding, as the pipeline calls it: clusters above 0.1 sr
/// skipped), and the result is valid with every tet positive.
#[test]
fn same_result_for_any_thread_count() {
    let before = tetgen_brain();
    let opts = SmoothOptions {
        boundary: Boundary::Slide,
        max_sweeps: 3,
        skip_above_sr: 0.1,
        ..SmoothOptions::default()
    };
    let (one, r1) = smooth_with_threads(&before, &opts, 1);
    assert_kept(&before, &one, &r1);
    assert!(r1.nodes_moved > 100, "{r1:?}");
    for threads in [2, 4] {
        let (many, r) = smooth_with_threads(&before, &opts, threads);
        assert!(bits(&one) == bits(&many), "{threads} threads differ from 1");
        assert_eq!(r.sweeps, r1.sweeps);
        assert_eq!(r.nodes_moved, r1.nodes_moved);
    }
    // The small cube, every node visited, fixed surface.
    let cube = jittered_cube(6, 0.8, 9);
    let opts = SmoothOptions::default();
    let (one, r) = smooth_with_threads(&cube, &opts, 1);
    assert_kept(&cube, &one, &r);
    for threads in [2, 4] {
        assert!(bits(&one) == bits(&smooth_with_threads(&cube, &opts, threads).0));
    }
}

#[test]
fn refuses_malformed_meshes_without_panicking() {
    let mut m = jittered_cube(3, 0.0, 1);
    m.tets[0][1] = m.tets[0][0];
    assert!(matches!(
        smooth(&mut m, None, &SmoothOptions::default()),
        Err(SmoothError::BadTet { tet: 0, .. })
    ));
    let mut m = jittered_cube(3, 0.0, 1);
    m.tets[2][3] = 10_000;
    assert!(matches!(
        smooth(&mut m, None, &SmoothOptions::default()),
        Err(SmoothError::BadTet { tet: 2, .. })
    ));
    let mut m = jittered_cube(3, 0.0, 1);
    m.labels.pop();
    assert!(matches!(
        smooth(&mut m, None, &SmoothOptions::default()),
        Err(SmoothError::Arrays { what: "labels", .. })
    ));
    // Non-finite coordinates: nothing around them moves, no panic.
    let mut m = jittered_cube(4, 0.5, 1);
    let interior = boundary_nodes(&m).iter().position(|b| !b).unwrap();
    m.points[interior] = [f64::NAN; 3];
    let before = m.points.clone();
    smooth(&mut m, None, &SmoothOptions::default()).unwrap();
    assert!(m.points[interior][0].is_nan());
    assert_eq!(m.points.len(), before.len());
    // An empty mesh.
    let mut e = TetMesh::default();
    let r = smooth(&mut e, None, &SmoothOptions::default()).unwrap();
    assert_eq!(r.nodes_moved, 0);
}

#[test]
fn two_regions_keep_their_interface_fixed() {
    // Label the tets of the jittered cube by the side of x = 0.5 their centroid is on: the
    // faces between the labels are an interface, and its nodes must not move when fixed.
    let mut before = jittered_cube(7, 0.6, 9);
    for t in 0..before.tets.len() {
        let c = before.corners(t);
        let x = (c[0][0] + c[1][0] + c[2][0] + c[3][0]) / 4.0;
        before.labels[t] = if x < 0.5 { 1 } else { 2 };
    }
    let mut iface = vec![false; before.points.len()];
    for t in 0..before.tets.len() {
        for f in 0..4 {
            let nb = before.neighbors[t][f];
            if nb != biotet::NO_NEIGHBOR && before.labels[nb as usize] != before.labels[t] {
                for v in before.face(t, f) {
                    iface[v as usize] = true;
                }
            }
        }
    }
    assert!(iface.iter().any(|&x| x));
    let mut mesh = before.clone();
    let r = smooth(&mut mesh, None, &SmoothOptions::default()).unwrap();
    assert_kept(&before, &mesh, &r);
    for (v, &on) in iface.iter().enumerate() {
        if on {
            assert_eq!(mesh.points[v], before.points[v], "interface node {v}");
        }
    }
    // Sliding: interface nodes may move but stay on the interface's faces of the input.
    let mut slid = before.clone();
    let opts = SmoothOptions {
        boundary: Boundary::Slide,
        ..SmoothOptions::default()
    };
    let r = smooth(&mut slid, None, &opts).unwrap();
    assert_kept(&before, &slid, &r);
    assert!(
        r.max_surface_distance <= 1e-14,
        "{}",
        r.max_surface_distance
    );
}

// ------------------------------------------------------------------------------------------------
// Real meshes
// ------------------------------------------------------------------------------------------------

fn biotet_brain(h: f64) -> (SurfaceMesh, TetMesh) {
    let s = load_stl("brain_20k.stl");
    let sizing = Sizing::uniform(h).unwrap();
    let (mesh, _) =
        mesh_surface(&s, &sizing, &PipelineOptions::deploy_only(), &mut |_| {}).unwrap();
    (s, mesh)
}

fn summary(name: &str, before: &TetMesh, after: &TetMesh, r: &SmoothReport) {
    let (a, b) = (QualityReport::of(before), QualityReport::of(after));
    eprintln!(
        "{name}: {} tets, {:?}: min solid {:.5} → {:.5} sr, min dihedral {:.3} → {:.3}°, max \
         {:.3} → {:.3}°, tets < 10° {} → {}, share < 0.2 sr {:.4} → {:.4}; {} sweeps, {:.3} s \
         ({:.3} s/sweep), {} nodes moved, surface distance {:e}",
        before.tets.len(),
        r.boundary,
        a.min_solid_angle_sr.unwrap(),
        b.min_solid_angle_sr.unwrap(),
        a.min_dihedral_deg.unwrap(),
        b.min_dihedral_deg.unwrap(),
        a.max_dihedral_deg.unwrap(),
        b.max_dihedral_deg.unwrap(),
        a.n_dihedral_lt_10,
        b.n_dihedral_lt_10,
        solid_angle_share_below(before, 0.2),
        solid_angle_share_below(after, 0.2),
        r.sweeps,
        r.seconds,
        r.seconds_per_sweep,
        r.nodes_moved,
        r.max_surface_distance,
    );
}

/// Smoothing adds no defect: the checker's counts are the same before and after.
fn assert_same_defects(before: &TetMesh, after: &TetMesh, surface: Option<&SurfaceMesh>) {
    let (a, b) = (check(before, surface), check(after, surface));
    assert_eq!(b.n_nonpositive, 0, "{b}");
    let counts = |c: &biotet::check::CheckReport| {
        (
            c.n_nonpositive,
            c.n_overshared_faces,
            c.n_misoriented_faces,
            c.n_adjacency_errors,
            c.n_duplicate_points,
            c.surface
                .as_ref()
                .map(|s| (s.n_found, s.n_missing, s.n_extra_boundary_faces)),
        )
    };
    assert_eq!(counts(&a), counts(&b), "before: {a}\nafter: {b}");
}

/// The low end of the quality distribution improves: fewer tets under 10°, a smaller share of
/// solid angles under 0.2 sr, and the 100th smallest tet minimum solid angle rises (the very
/// smallest can be pinned by tets standing on the input's sub-micron triangles, which no move
/// of a free node repairs).
fn assert_improved(before: &TetMesh, after: &TetMesh) {
    let (a, b) = (QualityReport::of(before), QualityReport::of(after));
    assert!(
        b.n_dihedral_lt_10 < a.n_dihedral_lt_10,
        "{} → {}",
        a.n_dihedral_lt_10,
        b.n_dihedral_lt_10
    );
    let (s0, s1) = (
        solid_angle_share_below(before, 0.2),
        solid_angle_share_below(after, 0.2),
    );
    assert!(s1 < s0, "share under 0.2 sr: {s0} → {s1}");
    let kth = |m: &TetMesh| {
        let mut v: Vec<f64> = (0..m.tets.len())
            .map(|t| {
                solid_angles(&m.corners(t))
                    .into_iter()
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        v.sort_by(f64::total_cmp);
        v[99]
    };
    let (k0, k1) = (kth(before), kth(after));
    assert!(k1 > k0, "100th smallest: {k0} → {k1}");
}

#[test]
fn tetgen_brain_fixed_and_slide() {
    let before = tetgen_brain();
    for boundary in [Boundary::Fixed, Boundary::Slide] {
        let mut mesh = before.clone();
        let opts = SmoothOptions {
            boundary,
            ..SmoothOptions::default()
        };
        let r = smooth(&mut mesh, None, &opts).unwrap();
        summary("brain_tetgen", &before, &mesh, &r);
        assert_kept(&before, &mesh, &r);
        assert_improved(&before, &mesh);
        let b = boundary_nodes(&before);
        match boundary {
            Boundary::Fixed => {
                for (v, &on) in b.iter().enumerate() {
                    if on {
                        assert_eq!(mesh.points[v], before.points[v]);
                    }
                }
            }
            Boundary::Slide => assert!(r.max_surface_distance < 1e-12, "{r:?}"),
        }
    }
}

#[test]
fn biotet_brain_fixed_keeps_the_input_surface_and_slide_stays_on_it() {
    let (surface, before) = biotet_brain(4.0);
    let mut fixed = before.clone();
    let r = smooth(&mut fixed, Some(&surface), &SmoothOptions::default()).unwrap();
    summary("biotet brain h=4", &before, &fixed, &r);
    assert_kept_unchecked(&before, &fixed, &r);
    assert_same_defects(&before, &fixed, Some(&surface));
    assert_improved(&before, &fixed);

    let mut slid = before.clone();
    let opts = SmoothOptions {
        boundary: Boundary::Slide,
        ..SmoothOptions::default()
    };
    let r = smooth(&mut slid, Some(&surface), &opts).unwrap();
    summary("biotet brain h=4", &before, &slid, &r);
    assert_kept_unchecked(&before, &slid, &r);
    assert_same_defects(&before, &slid, None);
    assert_improved(&before, &slid);
    assert!(r.n_sliding_nodes > 0 && r.nodes_moved > 0);
    assert!(r.max_surface_distance < 1e-12, "{r:?}");
    // Every surface node lies on some input triangle: check against the nearest triangle by
    // brute force for a sample of nodes.
    let b = boundary_nodes(&before);
    let mut checked = 0;
    for v in (0..b.len())
        .filter(|&v| b[v] && slid.points[v] != before.points[v])
        .step_by(7)
    {
        let p = slid.points[v];
        let d = (0..surface.triangles.len())
            .map(|t| crate::common::point_triangle_distance(p, surface.corners(t)))
            .fold(f64::INFINITY, f64::min);
        assert!(d < 1e-12, "node {v} is {d} from the surface");
        checked += 1;
    }
    assert!(checked > 10);
}
