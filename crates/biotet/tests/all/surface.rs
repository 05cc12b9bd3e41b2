//! The surface stage on a real marching-cubes surface with handles nobody designed for.

use biotet::SurfaceMesh;
use biotet::mesh::validate::{ValidateOptions, validate_surface};
use biotet::surface::{SurfaceOptions, improve};
use rustc_hash::FxHashSet;

use crate::common::{load_shape, load_stl};

/// The necks: three points joined pairwise by edges that bound no triangle (the cross-section
/// of a tube).
fn necks(s: &SurfaceMesh) -> Vec<[u32; 3]> {
    let faces: FxHashSet<[u32; 3]> = s
        .triangles
        .iter()
        .map(|t| {
            let mut k = *t;
            k.sort_unstable();
            k
        })
        .collect();
    let mut nb: Vec<FxHashSet<u32>> = vec![FxHashSet::default(); s.points.len()];
    for t in &s.triangles {
        for k in 0..3 {
            nb[t[k] as usize].insert(t[(k + 1) % 3]);
            nb[t[(k + 1) % 3] as usize].insert(t[k]);
        }
    }
    let mut out = Vec::new();
    for a in 0..s.points.len() as u32 {
        for &b in nb[a as usize].iter().filter(|&&b| b > a) {
            for &c in nb[a as usize].iter().filter(|&&c| c > b) {
                if nb[b as usize].contains(&c) && !faces.contains(&[a, b, c]) {
                    out.push([a, b, c]);
                }
            }
        }
    }
    out
}

/// A neck's three edge lengths and its largest angle (degrees).
fn neck_shape(s: &SurfaceMesh, n: [u32; 3]) -> ([f64; 3], f64) {
    let p = n.map(|v| s.points[v as usize]);
    let d = |i: usize, j: usize| -> [f64; 3] { [0, 1, 2].map(|k| p[j][k] - p[i][k]) };
    let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let angle = |i: usize, j: usize, k: usize| {
        let (u, v) = (d(i, j), d(i, k));
        let c = (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / (len(u) * len(v));
        c.clamp(-1.0, 1.0).acos().to_degrees()
    };
    let edges = [len(d(0, 1)), len(d(1, 2)), len(d(0, 2))];
    let largest = angle(0, 1, 2).max(angle(1, 2, 0)).max(angle(2, 0, 1));
    (edges, largest)
}

/// The shortest edge of the thinnest neck, `None` without necks.
fn thinnest_neck(s: &SurfaceMesh) -> Option<f64> {
    necks(s)
        .into_iter()
        .map(|n| neck_shape(s, n).0.into_iter().fold(f64::INFINITY, f64::min))
        .min_by(f64::total_cmp)
}

#[test]
fn thin_necks_of_a_marching_cubes_surface_are_opened() {
    // wm_20k (genus 32) has tubes along voxel edges a few hundredths to tenths of a millimetre
    // across; remeshed but not opened, their walls were 0.4° needles (a 0.031 mm cross edge)
    // and forced slivers.
    let mut input = load_stl("wm_20k.stl");
    validate_surface(&mut input, &ValidateOptions::default()).expect("valid input");
    let before = thinnest_neck(&input).expect("the input has necks");
    assert!(before < 0.2, "{before}");
    let d = 0.5;
    let out = improve_within(&input, d);
    // Same genus: the necks are widened, not cut.
    let euler = |s: &SurfaceMesh| {
        let mut edges = FxHashSet::default();
        for t in &s.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        s.points.len() as i64 - edges.len() as i64 + s.triangles.len() as i64
    };
    assert_eq!(euler(&out), euler(&input));
    // No needle left: those whose short edge was longer than the tolerance (0.56-0.91 mm at
    // tubes too wide to be necks) kept a 7.5° triangle when only an end could move onto the
    // other; collapsed to their middle, none is under 11°.
    let smallest = (0..out.triangles.len())
        .map(|t| biotet::surface::remesh::angles_deg(&out.corners(t)).0)
        .fold(180.0, f64::min);
    assert!(smallest > 11.0, "a triangle of {smallest}°");
    let after = thinnest_neck(&out).expect("the handles stay");
    assert!(after > d / 5.0, "thinnest neck {before} -> {after}");
    // Opened across the tube, not along it: two necks there were needles of cross-sections
    // lying along their tubes (0.27, 0.27 and 0.53 mm, 166°), and the tets inside were wedges.
    // And cut into rings along the tube: the walls within 4 D of a neck were needles of 6°
    // (a 0.6 mm neck, 4 mm walls).
    for n in necks(&out) {
        let (edges, largest) = neck_shape(&out, n);
        if edges.iter().all(|&e| e < 2.0 * d) {
            assert!(
                largest < 120.0,
                "neck {n:?}: edges {edges:?}, largest angle {largest}"
            );
            let worst = smallest_angle_near(&out, n, 4.0 * d);
            assert!(worst > 12.0, "neck {n:?}: a wall triangle of {worst}°");
        }
    }
}

/// The smallest angle (degrees) of the triangles whose centroids lie within `r` of neck `n`'s.
fn smallest_angle_near(s: &SurfaceMesh, n: [u32; 3], r: f64) -> f64 {
    let centroid = |c: [[f64; 3]; 3]| [0, 1, 2].map(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
    let g = centroid(n.map(|v| s.points[v as usize]));
    let mut worst = 180.0f64;
    for t in 0..s.triangles.len() {
        let c = s.corners(t);
        let m = centroid(c);
        if (0..3).map(|k| (m[k] - g[k]).powi(2)).sum::<f64>() > r * r {
            continue;
        }
        for k in 0..3 {
            let (p, a, b) = (c[k], c[(k + 1) % 3], c[(k + 2) % 3]);
            let u = [0, 1, 2].map(|i| a[i] - p[i]);
            let v = [0, 1, 2].map(|i| b[i] - p[i]);
            let dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
            let nu = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            let nv = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            worst = worst.min((dot / (nu * nv)).clamp(-1.0, 1.0).acos().to_degrees());
        }
    }
    worst
}

#[test]
fn a_hair_thin_torus_improves_within_a_tolerance_wider_than_its_tube() {
    // trimesh's torus of radius 1 with a tube 0.002 across: at a tolerance of seven tube widths
    // the two sides of the tube come within rounding of each other, and a split's rounded
    // midpoint once folded one side through the other (an invalid output, refused).
    let input = load_shape("tm_hair_torus.off");
    let (lo, hi) = input
        .points
        .iter()
        .fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
            (
                [0, 1, 2].map(|k| lo[k].min(p[k])),
                [0, 1, 2].map(|k| hi[k].max(p[k])),
            )
        });
    let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    improve_within(&input, 0.005 * diag);
}

/// The stage's output at tolerance `d`, checked: within `d` both ways, by the samples and by
/// their bound (0.522 on wm_20k when the measure refined only to D/8), and a valid surface.
fn improve_within(input: &SurfaceMesh, d: f64) -> SurfaceMesh {
    let (out, report) = improve(
        input,
        &SurfaceOptions {
            tolerance: d,
            ..Default::default()
        },
    )
    .expect("improves");
    assert!(report.hausdorff_in_to_out <= d && report.hausdorff_out_to_in <= d);
    assert!(report.hausdorff_bound <= d, "{}", report.hausdorff_bound);
    let mut check = out.clone();
    validate_surface(&mut check, &ValidateOptions::default()).expect("valid output");
    out
}

#[test]
fn the_stage_gives_the_same_surface_on_any_number_of_threads() {
    // The relaxation sweep checks far-apart points' moves in parallel and applies them in a
    // fixed order; a move checked against a surface that a nearer move then changed is checked
    // again. One thread and two must agree to the bit.
    let input = load_stl("brain_20k.stl");
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| improve_within(&input, 0.5))
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.triangles, two.triangles);
    assert_eq!(one.sides, two.sides);
    let bits = |s: &SurfaceMesh| -> Vec<[u64; 3]> {
        s.points.iter().map(|p| p.map(f64::to_bits)).collect()
    };
    assert_eq!(bits(&one), bits(&two));
}

/// A closed cylinder as trimesh's `creation.cylinder(radius, height, sections)` makes it: a fan
/// on each cap, each side section two needles as long as the cylinder.
fn prism(radius: f64, height: f64, sections: usize) -> SurfaceMesh {
    let mut s = SurfaceMesh::default();
    let z = [-0.5 * height, 0.5 * height];
    s.points.push([0.0, 0.0, z[0]]);
    s.points.push([0.0, 0.0, z[1]]);
    for i in 0..sections {
        let a = std::f64::consts::TAU * i as f64 / sections as f64;
        for zk in z {
            s.points.push([radius * a.cos(), radius * a.sin(), zk]);
        }
    }
    let ring = |i: usize, top: usize| (2 + 2 * (i % sections) + top) as u32;
    for i in 0..sections {
        let (b0, t0, b1, t1) = (ring(i, 0), ring(i, 1), ring(i + 1, 0), ring(i + 1, 1));
        s.triangles.push([0, b0, b1]);
        s.triangles.push([1, t1, t0]);
        s.triangles.push([b0, t1, b1]);
        s.triangles.push([b0, t0, t1]);
    }
    s.sides = vec![[0, 1]; s.triangles.len()];
    s
}

#[test]
fn a_long_thin_cylinder_is_cut_to_size_not_fanned_out() {
    // Its sides are needles 100 long and 0.39 wide against a target edge of 1 (the median).
    // Split at midpoints, each pass over a strip of needles tripled its long edges and left
    // points inside the strip for the collapses to take out: 27,617 splits and 24,983 collapses
    // for 5,332 triangles; the final measure's grid on each needle, 20.7 M samples in all. Cut
    // into pieces of the target length first (`surface::presplit`) and measured in pieces: 3
    // splits and 2,256 collapses for 1,926 triangles, 2.0 M samples.
    let input = prism(1.0, 100.0, 16);
    let (out, report) = improve(
        &input,
        &SurfaceOptions {
            tolerance: 0.2,
            ..Default::default()
        },
    )
    .expect("improves");
    assert!(report.hausdorff_bound <= 0.2, "{}", report.hausdorff_bound);
    let ops = report.ops.splits + report.ops.collapses;
    assert!(
        ops < 2 * out.triangles.len(),
        "{:?}, {} triangles",
        report.ops,
        out.triangles.len()
    );
    assert!(report.n_samples < 5_000_000, "{} samples", report.n_samples);
    assert!(report.min_angle_out >= 25.0, "{}°", report.min_angle_out);
    let mut check = out.clone();
    validate_surface(&mut check, &ValidateOptions::default()).expect("valid output");
}

/// A CAD bolt (planar and curved faces, every triangle angle over 40°) at tolerances down to a
/// forty-millionth of its size: the surface comes back as well shaped as it came. At 0.003
/// (1/14,000 of its size) the distance is proven within the tolerance; the measure once
/// refined whole triangles uniformly there, could not prove it, and four repair rounds split
/// the surface down to a 0.012° triangle (32 s). At 1e-6 no sample grid can prove the distance
/// on the flat faces (their output triangles span several coplanar input triangles): the
/// samples are within it, the bound is reported as it is, and no repair round shreds the
/// surface trying (it made a 4e-10° triangle in 20 s; 1e-12 never finished).
#[test]
fn a_tiny_tolerance_keeps_a_cad_surface_as_it_came() {
    let input = load_shape("cad_as1_bolt.off");
    for d in [0.003, 1e-6] {
        let (out, report) = improve(
            &input,
            &SurfaceOptions {
                tolerance: d,
                ..Default::default()
            },
        )
        .expect("improves");
        assert!(report.hausdorff_in_to_out <= d && report.hausdorff_out_to_in <= d);
        assert!(report.hausdorff_bound_in_to_out >= report.hausdorff_in_to_out);
        assert!(report.hausdorff_bound_out_to_in >= report.hausdorff_out_to_in);
        assert_eq!(
            report.hausdorff_bound,
            report
                .hausdorff_bound_in_to_out
                .max(report.hausdorff_bound_out_to_in)
        );
        if d == 0.003 {
            assert!(report.hausdorff_bound <= d, "{}", report.hausdorff_bound);
        }
        assert!(
            report.min_angle_out >= report.min_angle_in - 2.0,
            "{d}: {}° from {}°",
            report.min_angle_out,
            report.min_angle_in
        );
        assert!(
            out.triangles.len() <= input.triangles.len() * 11 / 10,
            "{d}: {}",
            out.triangles.len()
        );
    }
}

/// A thin CAD tube whose 90° rims are no features at the default feature angle: within 0.5% of
/// its diagonal the rounds cut the rims' corners, and four repair rounds could not follow them
/// back (the stage failed, 0.0207 measured against 0.0206). It comes within the tolerance, as a
/// valid surface with its one region's volume nearly kept.
#[test]
fn a_thin_tube_with_rounded_off_rims_comes_back_within_the_tolerance() {
    let input = load_shape("cad_tube_thin.off");
    let diagonal = (0..3)
        .map(|k| {
            let (lo, hi) = input
                .points
                .iter()
                .fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                    (lo.min(p[k]), hi.max(p[k]))
                });
            (hi - lo).powi(2)
        })
        .sum::<f64>()
        .sqrt();
    let d = 0.005 * diagonal;
    let out = improve_within(&input, d);
    let volume = |s: &SurfaceMesh| biotet::surface::region_volumes(s)[0].1;
    let change = (volume(&out) / volume(&input) - 1.0).abs();
    assert!(change < 0.05, "volume changed by {change}");
}

/// trimesh's hair-thin torus within a tenth of its diagonal, far wider than its tube: the
/// clean-up's cap splits and relaxations projected points onto input points the output already
/// had, and the crossing test, by coordinates alone, took the two points in one place for a
/// shared corner (the stage then failed its own validation: 54 pairs of triangles meeting at a
/// point that is no shared corner). It comes out valid, within the tolerance.
#[test]
fn a_squashed_hair_torus_comes_out_without_two_points_in_one_place() {
    let input = load_shape("tm_hair_torus.off");
    let out = improve_within(&input, 0.283);
    let mut places: Vec<[u64; 3]> = out.points.iter().map(|p| p.map(f64::to_bits)).collect();
    places.sort_unstable();
    places.dedup();
    assert_eq!(places.len(), out.points.len(), "points in one place");
}
