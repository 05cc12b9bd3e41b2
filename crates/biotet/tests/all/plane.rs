//! 2D meshes: Delaunay, segment recovery, outside removal, labels, template deployment and
//! max–min angle smoothing, each output run through the 2D checker.

use biotet::check2d::check_tri;
use biotet::delaunay2d::{Delaunay2dError, triangulate};
use biotet::geom::predicates::{Sign, incircle_sos};
use biotet::mesh::pslg::{Pslg, RegionPoint};
use biotet::pipeline2d::{Mesh2dOptions, mesh_pslg, triangulate_pslg};
use biotet::quality::tri::angles;
use biotet::smooth::Boundary;
use biotet::smooth::plane::{PlaneSmoothOptions, smooth_tri};
use biotet::template::plane::PlaneDeployOptions;
use biotet::{NO_NEIGHBOR, TriMesh};

#[path = "../../examples/common/table_4_1_input.rs"]
mod table_input;
use table_input::table_4_1_mesh;

/// A deterministic generator for test points.
pub struct Rng(pub u64);
impl Rng {
    /// A uniform number in [0, 1).
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Every interior edge is locally Delaunay under the symbolic perturbation.
fn assert_delaunay(m: &TriMesh) {
    for (t, tv) in m.triangles.iter().enumerate() {
        for i in 0..3 {
            let n = m.neighbors[t][i];
            if n == NO_NEIGHBOR {
                continue;
            }
            let nv = m.triangles[n as usize];
            let x = *nv.iter().find(|v| !tv.contains(v)).unwrap();
            let p = |v: u32| m.points[v as usize];
            let s = incircle_sos(
                [p(tv[0]), p(tv[1]), p(tv[2]), p(x)],
                [tv[0], tv[1], tv[2], x],
            );
            assert_eq!(
                s,
                Sign::Negative,
                "edge {i} of triangle {t} is not Delaunay"
            );
        }
    }
}

fn hull_count(m: &TriMesh) -> usize {
    m.neighbors
        .iter()
        .flatten()
        .filter(|&&n| n == NO_NEIGHBOR)
        .count()
}

#[test]
fn delaunay_of_random_points_is_valid_and_delaunay() {
    let mut r = Rng(1);
    let pts: Vec<[f64; 2]> = (0..2000).map(|_| [r.next(), r.next()]).collect();
    let m = triangulate(pts).unwrap();
    let rep = check_tri(&m, None);
    assert!(rep.valid, "{rep}");
    assert_eq!(m.triangles.len(), 2 * 2000 - hull_count(&m) - 2);
    assert_delaunay(&m);
}

#[test]
fn delaunay_of_a_lattice_just_works() {
    // Every square of the lattice is cocircular: the perturbation picks the diagonals.
    let pts: Vec<[f64; 2]> = (0..30 * 20)
        .map(|k| [(k % 30) as f64, (k / 30) as f64])
        .collect();
    let m = triangulate(pts.clone()).unwrap();
    let rep = check_tri(&m, None);
    assert!(rep.valid, "{rep}");
    assert_eq!(m.triangles.len(), 2 * 29 * 19);
    assert_delaunay(&m);
    // The same set in another order numbering gives the same triangles up to the renumbering.
    let again = triangulate(pts).unwrap();
    assert_eq!(m, again);
}

#[test]
fn delaunay_with_collinear_start_and_hull_points() {
    let mut pts: Vec<[f64; 2]> = (0..50).map(|i| [i as f64, 0.0]).collect();
    pts.push([10.0, 3.0]);
    pts.push([20.0, -3.0]);
    let m = triangulate(pts.clone()).unwrap();
    assert!(check_tri(&m, None).valid);
    assert_eq!(m.triangles.len(), 2 * 49);
    pts.truncate(50);
    assert_eq!(triangulate(pts).unwrap_err(), Delaunay2dError::Collinear);
    let dup = vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 0.0]];
    assert_eq!(
        triangulate(dup).unwrap_err(),
        Delaunay2dError::Duplicate {
            first: 1,
            second: 3
        }
    );
}

/// A 10 × 10 square with a square hole and an internal boundary (a closed triangle, region 2)
/// and an open internal polyline; segments split so that some are much longer than others.
pub fn holey_pslg() -> Pslg {
    let mut points = vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
    let mut segments = vec![[0, 1], [1, 2], [2, 3], [3, 0]];
    // Hole [6, 8]².
    let h = points.len() as u32;
    points.extend([[6.0, 6.0], [8.0, 6.0], [8.0, 8.0], [6.0, 8.0]]);
    segments.extend([[h, h + 1], [h + 1, h + 2], [h + 2, h + 3], [h + 3, h]]);
    // Internal boundary: a triangle.
    let t = points.len() as u32;
    points.extend([[1.0, 1.0], [5.0, 1.5], [2.0, 5.0]]);
    segments.extend([[t, t + 1], [t + 1, t + 2], [t + 2, t]]);
    // An open polyline inside region 1.
    let o = points.len() as u32;
    points.extend([[6.0, 2.0], [8.5, 3.0], [9.0, 4.5]]);
    segments.extend([[o, o + 1], [o + 1, o + 2]]);
    let n = segments.len();
    Pslg {
        points,
        segments,
        segment_markers: vec![0; n],
        holes: vec![[7.0, 7.0]],
        regions: vec![
            RegionPoint {
                point: [5.0, 9.0],
                label: 1,
            },
            RegionPoint {
                point: [2.0, 2.0],
                label: 2,
            },
        ],
    }
}

fn assert_sides(m: &TriMesh, g: &Pslg) {
    let rep = check_tri(m, Some(g));
    assert!(rep.valid, "{rep}");
    let c = rep.pslg.unwrap();
    assert_eq!(c.n_found, g.segments.len());
    // Outer and hole boundary between 0 and 1; the triangle between 1 and 2; the open polyline
    // inside 1.
    let get = |a: u32, b: u32| {
        c.sides
            .iter()
            .find(|s| s.labels == [a, b])
            .map_or(0, |s| s.count)
    };
    assert_eq!(get(0, 1), 8);
    assert_eq!(get(1, 2), 3);
    assert_eq!(get(1, 1), 2);
}

#[test]
fn pslg_with_hole_and_internal_boundaries() {
    let g = holey_pslg();
    let mut r = Rng(3);
    let nodes: Vec<[f64; 2]> = (0..400)
        .map(|_| [10.0 * r.next(), 10.0 * r.next()])
        .collect();
    let (m, rep) = triangulate_pslg(&g, &nodes).unwrap();
    assert!(rep.recover.n_recovered > 0, "some segment needed recovery");
    assert!(rep.recover.complete());
    assert_sides(&m, &g);
    // Nothing inside the hole.
    for t in 0..m.triangles.len() {
        let c = m.corners(t);
        let cx = (c[0][0] + c[1][0] + c[2][0]) / 3.0;
        let cy = (c[0][1] + c[1][1] + c[2][1]) / 3.0;
        assert!(!(6.0 < cx && cx < 8.0 && 6.0 < cy && cy < 8.0));
    }
    // Without extra nodes: the constrained triangulation of the PSLG alone.
    let (m0, _) = triangulate_pslg(&g, &[]).unwrap();
    assert_sides(&m0, &g);
    assert_eq!(m0.points.len(), g.points.len());
}

#[test]
fn pslg_errors_are_reported() {
    let mut g = holey_pslg();
    g.segments.push([1, 3]);
    g.segment_markers.push(0);
    let e = triangulate_pslg(&g, &[]).unwrap_err();
    assert!(e.to_string().contains("cross"), "{e}");
    let mut g = holey_pslg();
    g.segments.push([0, 2]);
    g.segment_markers.push(0);
    let e = triangulate_pslg(&g, &[]).unwrap_err();
    assert!(e.to_string().contains("point 8 lies on segment 13"), "{e}");
}

/// `g` with every segment split into pieces no longer than `h` (new points appended).
pub fn subdivided(g: &Pslg, h: f64) -> Pslg {
    let mut out = Pslg {
        points: g.points.clone(),
        holes: g.holes.clone(),
        regions: g.regions.clone(),
        ..Default::default()
    };
    for &[a, b] in &g.segments {
        let (p, q) = (g.points[a as usize], g.points[b as usize]);
        let l = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
        let k = (l / h).ceil().max(1.0) as usize;
        let mut prev = a;
        for i in 1..=k {
            let v = if i == k {
                b
            } else {
                let f = i as f64 / k as f64;
                out.points
                    .push([p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1])]);
                (out.points.len() - 1) as u32
            };
            out.segments.push([prev, v]);
            out.segment_markers.push(0);
            prev = v;
        }
    }
    out
}

#[test]
fn template_mesh_of_the_holey_domain() {
    let g = subdivided(&holey_pslg(), 1.0);
    let opts = Mesh2dOptions {
        deploy: PlaneDeployOptions {
            size: Some(0.4),
            ..Default::default()
        },
        smooth: Some(PlaneSmoothOptions {
            boundary: Boundary::Slide,
            ..Default::default()
        }),
    };
    let (m, rep) = mesh_pslg(&g, &opts).unwrap();
    let st = rep.template.as_ref().unwrap();
    assert!(st.interior_nodes > 300, "{st:?}");
    assert!(st.sealed_segments > 0, "long segments are sealed: {st:?}");
    assert_eq!(rep.carve.n_points_dropped, 0, "every node is inside");
    let sm = rep.smooth.as_ref().unwrap();
    assert!(sm.min_angle_after_deg >= sm.min_angle_before_deg);
    assert!(sm.min_angle_after_deg > 20.0, "{sm:?}");
    assert!(sm.n_sliding > 0);
    let rep = check_tri(&m, None);
    assert!(rep.valid, "{rep}");
    // Without smoothing every segment is there, with labels on both sides.
    let (m, _) = mesh_pslg(
        &g,
        &Mesh2dOptions {
            deploy: opts.deploy.clone(),
            smooth: None,
        },
    )
    .unwrap();
    let rep = check_tri(&m, Some(&g));
    assert!(rep.valid, "{rep}");
    let sides: Vec<[u32; 2]> = rep.pslg.unwrap().sides.iter().map(|s| s.labels).collect();
    assert_eq!(sides, vec![[0, 1], [1, 1], [1, 2]]);
}

fn min_angle(m: &TriMesh) -> f64 {
    (0..m.triangles.len())
        .flat_map(|t| angles(&m.corners(t)))
        .fold(f64::INFINITY, f64::min)
        .to_degrees()
}

#[test]
fn table_4_1_fixed_and_sliding() {
    let (m, g) = table_4_1_mesh();
    assert_eq!(m.points.len(), 234);
    assert_eq!(m.triangles.len(), 434);
    assert!(check_tri(&m, Some(&g)).valid);
    let before = min_angle(&m);
    let mut fixed = m.clone();
    let rf = smooth_tri(&mut fixed, &PlaneSmoothOptions::default());
    assert!(
        check_tri(&fixed, Some(&g)).valid,
        "fixed boundary keeps every segment"
    );
    for v in 0..32 {
        assert_eq!(fixed.points[v], m.points[v], "boundary node {v} fixed");
    }
    let mut slid = m.clone();
    let rs = smooth_tri(
        &mut slid,
        &PlaneSmoothOptions {
            boundary: Boundary::Slide,
            ..Default::default()
        },
    );
    assert!(check_tri(&slid, None).valid);
    assert_eq!(rs.n_sliding, 28, "all but the 4 corners slide");
    for v in [0, 8, 16, 24] {
        assert_eq!(slid.points[v], m.points[v], "corner {v} fixed");
    }
    for v in 0..32 {
        let p = slid.points[v];
        assert!(
            p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0,
            "boundary node {v} left the square: {p:?}"
        );
    }
    assert_eq!(rf.min_angle_before_deg, before);
    assert!(rf.min_angle_after_deg > before);
    assert!(rs.min_angle_after_deg >= rf.min_angle_after_deg);
    // The seed reached 6.34° (fixed) and 20.05° (sliding); with sliding no angle stays under 20°.
    assert!(rf.min_angle_after_deg > 6.34, "{rf:?}");
    assert!(rs.min_angle_after_deg > 20.0, "{rs:?}");
    assert_eq!(min_angle(&slid), rs.min_angle_after_deg);
}

#[test]
fn recovery_failures_are_reported_not_hidden() {
    use biotet::recover2d::{SegmentFailure, recover};
    // Node 4 lies on the segment 0–2: no triangulation without a node on it contains it.
    let pts = vec![
        [0.0, 0.0],
        [2.0, 0.0],
        [2.0, 2.0],
        [0.0, 2.0],
        [1.0, 1.0],
        [1.5, 0.2],
    ];
    let mut m = triangulate(pts).unwrap();
    let before = m.clone();
    let r = recover(&mut m, &[[0, 2], [1, 3]]);
    assert_eq!(
        r.failed,
        vec![
            SegmentFailure::NodeOnSegment {
                segment: 0,
                node: 4
            },
            SegmentFailure::NodeOnSegment {
                segment: 1,
                node: 4
            }
        ]
    );
    assert_eq!(m, before, "nothing changed");
    // An L-shaped mesh: the segment between the arms' tips leaves the domain.
    let l = TriMesh::new(
        vec![
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ],
        vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]],
        vec![1; 4],
    );
    assert!(check_tri(&l, None).valid);
    let mut m = l.clone();
    let r = recover(&mut m, &[[2, 4], [1, 5]]);
    assert_eq!(r.failed.len(), 2);
    assert!(matches!(
        r.failed[0],
        SegmentFailure::LeavesMesh { segment: 0 }
    ));
    assert!(check_tri(&m, None).valid);
}

#[test]
fn long_segment_across_a_cocircular_lattice() {
    // The square [0, 40]² with a node at every integer point of its boundary, the interior
    // lattice as free nodes (every lattice square cocircular), and one internal segment between
    // two extra points that crosses the whole lattice without touching a lattice point
    // (304x − 390y = 35 has no integer solution).
    let mut points = Vec::new();
    for s in 0..4 {
        for i in 0..40 {
            let t = f64::from(i);
            points.push(match s {
                0 => [t, 0.0],
                1 => [40.0, t],
                2 => [40.0 - t, 40.0],
                _ => [0.0, 40.0 - t],
            });
        }
    }
    let mut segments: Vec<[u32; 2]> = (0..160).map(|i| [i, (i + 1) % 160]).collect();
    points.push([0.5, 0.3]);
    points.push([39.5, 30.7]);
    segments.push([160, 161]);
    let g = Pslg {
        points,
        segment_markers: vec![0; segments.len()],
        segments,
        ..Default::default()
    };
    let nodes: Vec<[f64; 2]> = (1..40)
        .flat_map(|y| (1..40).map(move |x| [f64::from(x), f64::from(y)]))
        .collect();
    let (m, rep) = triangulate_pslg(&g, &nodes).unwrap();
    assert_eq!(rep.recover.n_recovered, 1);
    assert!(rep.recover.n_carved > 60, "{:?}", rep.recover);
    let c = check_tri(&m, Some(&g));
    assert!(c.valid, "{c}");
    assert_eq!(
        c.pslg.unwrap().sides,
        vec![
            biotet::check2d::SegmentSides {
                labels: [0, 1],
                count: 160
            },
            biotet::check2d::SegmentSides {
                labels: [1, 1],
                count: 1
            },
        ]
    );
    assert_eq!(m.points.len(), 162 + 39 * 39);
}

#[test]
fn graded_deployment_between_fine_boundary_and_coarse_inside() {
    let g = subdivided(&holey_pslg(), 0.25);
    let run = |size: f64, grading: Option<f64>| {
        let opts = Mesh2dOptions {
            deploy: PlaneDeployOptions {
                size: Some(size),
                grading,
                ..Default::default()
            },
            smooth: None,
        };
        let (m, rep) = mesh_pslg(&g, &opts).unwrap();
        let c = check_tri(&m, Some(&g));
        assert!(c.valid, "{c}");
        rep.template.unwrap().interior_nodes
    };
    let coarse = run(1.0, None);
    let graded = run(1.0, Some(0.3));
    let fine = run(0.25, None);
    assert!(coarse < graded && graded < fine, "{coarse} {graded} {fine}");
}

#[test]
fn plane_smoothing_is_the_same_on_any_number_of_threads() {
    let (m, _) = table_4_1_mesh();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut mm = m.clone();
        pool.install(|| {
            smooth_tri(
                &mut mm,
                &PlaneSmoothOptions {
                    boundary: Boundary::Slide,
                    ..Default::default()
                },
            )
        });
        mm
    };
    let one = run(1);
    assert_eq!(one, run(3));
    assert!(check_tri(&one, None).valid);
}
