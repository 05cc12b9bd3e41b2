//! The surface stage on small poor surfaces: latitude–longitude spheres, whose pole fans are
//! needles. Distances are checked by brute force (every triangle of the other surface), apart
//! from the stage's own measure.

use super::bvh::{closest_on_triangle, dist2};
use super::*;
use crate::mesh::shells::{Part, assemble};

/// A latitude–longitude sphere: `nu` meridians, `nv` bands; the triangles at the poles are
/// needles with an apex angle of `360° / nu`.
pub fn uv_sphere(r: f64, c: [f64; 3], nu: usize, nv: usize) -> SurfaceMesh {
    let mut p = vec![[c[0], c[1], c[2] + r]];
    for i in 1..nv {
        let th = std::f64::consts::PI * i as f64 / nv as f64;
        for j in 0..nu {
            let ph = 2.0 * std::f64::consts::PI * j as f64 / nu as f64;
            p.push([
                c[0] + r * th.sin() * ph.cos(),
                c[1] + r * th.sin() * ph.sin(),
                c[2] + r * th.cos(),
            ]);
        }
    }
    p.push([c[0], c[1], c[2] - r]);
    let south = (p.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * nu + j % nu) as u32;
    let mut t = Vec::new();
    for j in 0..nu {
        t.push([0, ring(1, j), ring(1, j + 1)]);
        t.push([south, ring(nv - 1, j + 1), ring(nv - 1, j)]);
    }
    for i in 1..nv - 1 {
        for j in 0..nu {
            let (a, b, c2, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j),
                ring(i + 1, j + 1),
            );
            t.push([a, c2, d]);
            t.push([a, d, b]);
        }
    }
    let mut s = SurfaceMesh::closed(p, t, 1);
    validate_surface(&mut s, &ValidateOptions::default()).expect("a valid sphere");
    s
}

/// The largest distance from every corner and centroid of `from`'s triangles (every `step`-th
/// triangle) to the nearest triangle of `to`, by brute force.
fn brute_one_sided(from: &SurfaceMesh, to: &SurfaceMesh, step: usize) -> f64 {
    let tris: Vec<[[f64; 3]; 3]> = (0..to.n_triangles()).map(|t| to.corners(t)).collect();
    let mut worst = 0.0f64;
    for t in (0..from.n_triangles()).step_by(step) {
        let c = from.corners(t);
        let g = [0, 1, 2].map(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
        for p in [c[0], c[1], c[2], g] {
            let d = tris
                .iter()
                .map(|u| dist2(p, closest_on_triangle(p, u)))
                .fold(f64::INFINITY, f64::min)
                .sqrt();
            worst = worst.max(d);
        }
    }
    worst
}

fn min_angle(s: &SurfaceMesh) -> f64 {
    (0..s.n_triangles())
        .map(|t| remesh::angles_deg(&s.corners(t)).0)
        .fold(180.0, f64::min)
}

#[test]
fn a_needle_sphere_improves_within_the_tolerance() {
    let input = uv_sphere(10.0, [0.0; 3], 24, 12);
    let d = 0.3;
    let opts = SurfaceOptions {
        tolerance: d,
        ..Default::default()
    };
    let (out, report) = improve(&input, &opts).expect("improves");
    assert!(report.hausdorff_in_to_out <= d && report.hausdorff_out_to_in <= d);
    // Independently of the stage's own measure.
    assert!(brute_one_sided(&out, &input, 1) <= d);
    assert!(brute_one_sided(&input, &out, 1) <= d);
    // Shape: the 15° needles at the poles are gone.
    let (a_in, a_out) = (min_angle(&input), min_angle(&out));
    assert!(a_in < 16.0);
    assert!(a_out > a_in + 10.0, "min angle {a_in} → {a_out}");
    assert_eq!(report.min_angle_out, a_out);
    // Valid, closed, one region, volume nearly kept.
    let mut check = out.clone();
    validate_surface(&mut check, &ValidateOptions::default()).expect("valid output");
    assert_eq!(check, out);
    assert_eq!(out.regions(), vec![1]);
    assert!(report.max_volume_change < 0.02, "{report:?}");
}

#[test]
fn nested_shells_keep_their_regions_and_interfaces() {
    let outer = uv_sphere(10.0, [0.0; 3], 24, 12);
    let inner = uv_sphere(6.0, [0.5, 0.0, 0.0], 20, 10);
    let (input, _) = assemble(vec![
        Part {
            surface: outer,
            labels: None,
        },
        Part {
            surface: inner,
            labels: None,
        },
    ])
    .expect("nested");
    let d = 0.3;
    let (out, report) = improve(
        &input,
        &SurfaceOptions {
            tolerance: d,
            ..Default::default()
        },
    )
    .expect("improves");
    assert_eq!(out.regions(), input.regions());
    // The same sheets (side-label pairs), each within the tolerance of its own input sheet.
    let mut si: Vec<[u32; 2]> = input.sides.clone();
    let mut so: Vec<[u32; 2]> = out.sides.clone();
    si.sort_unstable();
    si.dedup();
    so.sort_unstable();
    so.dedup();
    assert_eq!(si, so);
    for &k in &si {
        let sheet = |s: &SurfaceMesh| {
            let keep: Vec<usize> = (0..s.n_triangles()).filter(|&t| s.sides[t] == k).collect();
            SurfaceMesh {
                points: s.points.clone(),
                triangles: keep.iter().map(|&t| s.triangles[t]).collect(),
                sides: keep.iter().map(|&t| s.sides[t]).collect(),
            }
        };
        let (a, b) = (sheet(&input), sheet(&out));
        assert!(brute_one_sided(&a, &b, 1) <= d, "sheet {k:?}");
        assert!(brute_one_sided(&b, &a, 1) <= d, "sheet {k:?}");
    }
    assert_eq!(report.sheets.len(), si.len());
    let mut check = out.clone();
    validate_surface(&mut check, &ValidateOptions::default()).expect("valid output");
    assert!(min_angle(&out) > min_angle(&input));
}

#[test]
fn same_output_on_any_number_of_threads() {
    let input = uv_sphere(10.0, [0.0; 3], 16, 8);
    let opts = SurfaceOptions {
        tolerance: 0.4,
        ..Default::default()
    };
    let run = |n: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(|| improve(&input, &opts).expect("improves").0)
    };
    assert_eq!(run(1), run(3));
}

#[test]
fn a_tolerance_too_small_to_move_fails_clearly_or_keeps_it() {
    let input = uv_sphere(10.0, [0.0; 3], 16, 8);
    let bad = improve(
        &input,
        &SurfaceOptions {
            tolerance: -1.0,
            ..Default::default()
        },
    );
    assert!(matches!(bad, Err(SurfaceError::Options(_))));
    // A small tolerance: whatever is done stays within it.
    let d = 1e-2;
    let (out, r) = improve(
        &input,
        &SurfaceOptions {
            tolerance: d,
            ..Default::default()
        },
    )
    .expect("a tiny tolerance still runs");
    assert!(r.hausdorff_in_to_out <= d && r.hausdorff_out_to_in <= d);
    assert!(brute_one_sided(&out, &input, 1) <= d);
}

/// The steps reported to the progress hook come in order, and watching changes nothing.
#[test]
fn progress_names_each_step_in_order() {
    let input = uv_sphere(1.0, [0.0; 3], 24, 10);
    let opts = SurfaceOptions {
        tolerance: 0.02,
        rounds: 3,
        ..Default::default()
    };
    let log = std::cell::RefCell::new(Vec::new());
    let (watched, _) =
        improve_with_progress(&input, &opts, &|m| log.borrow_mut().push(m.to_string()))
            .expect("improves");
    let (plain, _) = improve(&input, &opts).expect("improves");
    assert_eq!(watched, plain);
    let want = [
        "round 1 of 3",
        "round 2 of 3",
        "round 3 of 3",
        "clean-up",
        "validating",
        "measuring",
    ];
    assert_eq!(*log.borrow(), want);
}

/// The final measure lists, both ways, the triangles with a sample beyond the tolerance (what
/// the stage refines before it gives up), and none when the surfaces are within it.
#[test]
fn the_final_measure_lists_what_lies_beyond_the_tolerance() {
    let input = uv_sphere(1.0, [0.0; 3], 24, 12);
    let mut out = input.clone();
    // Push one point out by 0.05: the triangles around it stray that far.
    out.points[40] = out.points[40].map(|x| x * 1.05);
    let index = PatchIndex::new(&input.points, &input.triangles, &input.sides, None);
    let (oi, io) = final_measure(&input, &out, &index, 0.01, 0.03);
    assert!(
        oi.max > 0.03 && !oi.far.is_empty(),
        "{} {}",
        oi.max,
        oi.far.len()
    );
    for f in &oi.far {
        assert!(f.distance > 0.03);
        assert!(out.triangles[f.triangle as usize].contains(&40), "{f:?}");
    }
    // And the input's point there is as far from the bump.
    assert!(io.max > 0.03 && !io.far.is_empty(), "{}", io.max);
    for f in &io.far {
        assert!(f.distance > 0.03);
        assert!(out.triangles[f.nearest as usize].contains(&40), "{f:?}");
    }
    let (oi, io) = final_measure(&input, &out, &index, 0.01, 0.06);
    assert!(oi.far.is_empty() && io.far.is_empty());
    assert!(oi.max > 0.04 && oi.max <= 0.05 + 1e-12, "{}", oi.max);
    // A tolerance just over the farthest sample, closer than the finest samples' covering
    // radius (0.01 / 32 / √3): the samples alone cannot prove it, but every cell's corners are
    // within it of one input triangle, and the distance to a triangle is convex, so the bump is
    // proven within it and not listed.
    let d = oi.max + 1e-6;
    let (oi, _) = final_measure(&input, &out, &index, 0.01, d);
    assert!(oi.max <= d && oi.bound <= d, "{} {}", oi.max, oi.bound);
    assert!(oi.far.is_empty());
}

/// A flat tetrahedron's triangles have usable angles (20°–70°) but fold onto each other at its
/// base edges (6.5° inside): every tet there would be as flat. With no edge kept as a feature,
/// the stage opens the folds within the tolerance (the apex and base corners move apart).
#[test]
fn a_flat_fold_is_opened_within_the_tolerance() {
    let input = SurfaceMesh {
        points: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.25, 0.25, 0.04],
        ],
        triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
        sides: vec![[1, 0]; 4],
    };
    let d = 0.05;
    let opts = SurfaceOptions {
        tolerance: d,
        feature_angle_deg: 0.0,
        ..Default::default()
    };
    let (out, report) = improve(&input, &opts).expect("improves");
    assert!(report.hausdorff_in_to_out <= d && report.hausdorff_out_to_in <= d);
    assert!(brute_one_sided(&out, &input, 4) <= d);
    assert!(brute_one_sided(&input, &out, 4) <= d);
    let (f_in, f_out) = (remesh::min_fold(&input), remesh::min_fold(&out));
    assert!(f_in < 7.0, "{f_in}");
    assert!(
        f_out >= remesh::FOLD_ANGLE,
        "smallest fold {f_in} → {f_out}"
    );
    assert_eq!((report.min_fold_in, report.min_fold_out), (f_in, f_out));
    assert!(report.n_fold_moves > 0);
    let mut check = out.clone();
    validate_surface(&mut check, &ValidateOptions::default()).expect("valid output");
}

/// A feature angle outside 0–180° (or NaN) is refused, naming it; a tolerance that cannot be kept
/// is named in a short form however small it is (1e-300 came out as 300 zeros).
#[test]
fn bad_options_are_refused_in_a_line_a_user_can_read() {
    let s = uv_sphere(1.0, [0.0; 3], 12, 6);
    for a in [-5.0, 1000.0, f64::NAN] {
        let opts = SurfaceOptions {
            tolerance: 0.05,
            feature_angle_deg: a,
            ..SurfaceOptions::default()
        };
        let e = improve(&s, &opts).unwrap_err();
        assert!(
            matches!(&e, SurfaceError::Options(m) if m.contains("feature angle")),
            "{a}: {e}"
        );
    }
    let e = SurfaceError::Tolerance {
        tolerance: 1e-300,
        in_to_out: 0.25,
        out_to_in: 3.0e-17,
    }
    .to_string();
    assert!(e.len() < 200, "{e}");
    assert!(
        e.contains("within 1.0000e-300:") && e.contains("measured 0.25 from"),
        "{e}"
    );
}
