//! Tests: quality. Per-element measures and whole-mesh reports on shapes whose figures are worked
//! out by hand in the comments.

use std::f64::consts::PI;

use biotet::quality::{
    self, Histogram, QualityReport, REGULAR_SOLID_ANGLE, TetMeasures, TriMeasures, TriQualityReport,
};
use biotet::{TetMesh, TriMesh};

/// `|a - b| <= tol`, with both values in the message.
#[track_caller]
fn close(a: f64, b: f64, tol: f64) {
    assert!((a - b).abs() <= tol, "{a} vs {b} (tolerance {tol})");
}

#[track_caller]
fn close_opt(a: Option<f64>, b: f64, tol: f64) {
    close(a.expect("a value, not None"), b, tol);
}

fn tet_mesh(points: Vec<[f64; 3]>, tets: Vec<[u32; 4]>, labels: Vec<u32>) -> TetMesh {
    TetMesh::new(points, tets, labels)
}

/// The regular tetrahedron on alternate corners of the unit cube, edge a = √2, ordered so that
/// volume6 = (1,0,1)·((1,1,0)×(0,1,1)) = (1,0,1)·(1,−1,1) = 2 > 0.
fn regular() -> [[f64; 3]; 4] {
    [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 1.0],
    ]
}

/// acos(1/3) in degrees: the dihedral angle of the regular tet.
fn regular_dihedral_deg() -> f64 {
    (1.0f64 / 3.0).acos().to_degrees()
}

/// A histogram's counts as a Vec, for comparisons.
fn counts(h: &Histogram) -> Vec<u64> {
    h.counts.clone()
}

/// A Vec of `n` zeros with the given (bin, count) pairs set.
fn bins(n: usize, set: &[(usize, u64)]) -> Vec<u64> {
    let mut v = vec![0; n];
    for &(i, c) in set {
        v[i] = c;
    }
    v
}

// ------------------------------------------------------------------------------------------------
// (a) The regular tetrahedron
// ------------------------------------------------------------------------------------------------

#[test]
fn regular_tet() {
    // Every dihedral angle is acos(1/3) = 70.528779°, every solid angle 3·acos(1/3) − π =
    // 0.551286 sr, q = 12·(3V)^(2/3)/ΣL² = 12·(a³/(2√2))^(2/3)/(6a²) = 12·(a²/2)/(6a²) = 1,
    // radius ratio 3r/R = 3·(a/√24)/(a·√(3/8)) = 1, volume a³/(6√2) = 2√2/(6√2) = 1/3.
    let c = regular();
    let m = TetMeasures::of(&c);
    close(regular_dihedral_deg(), 70.528_779_365_509_3, 1e-12);
    close(REGULAR_SOLID_ANGLE, 3.0 * (1.0f64 / 3.0).acos() - PI, 1e-15);
    for d in m.dihedral_deg {
        close(d, regular_dihedral_deg(), 1e-12);
    }
    for s in m.solid_sr {
        close(s, REGULAR_SOLID_ANGLE, 1e-14);
    }
    close(m.q, 1.0, 1e-14);
    close(m.radius_ratio, 1.0, 1e-14);
    close(m.volume, 1.0 / 3.0, 1e-15);

    // Scale and translation do not change the shape measures; the volume scales with a³.
    let a = 3.0;
    let moved = c.map(|p| p.map(|x| a * x + 7.0));
    let m2 = TetMeasures::of(&moved);
    close(m2.q, 1.0, 1e-13);
    close(m2.radius_ratio, 1.0, 1e-13);
    close(m2.volume, a * a * a / 3.0, 1e-12);
    close(m2.min_solid(), REGULAR_SOLID_ANGLE, 1e-13);

    let mesh = tet_mesh(c.to_vec(), vec![[0, 1, 2, 3]], vec![7]);
    let r = QualityReport::of(&mesh);
    assert_eq!((r.n_points, r.n_tets, r.n_regions), (4, 1, 1));
    close(r.volume, 1.0 / 3.0, 1e-15);
    for v in [r.min_dihedral_deg, r.max_dihedral_deg, r.mean_dihedral_deg] {
        close_opt(v, regular_dihedral_deg(), 1e-12);
    }
    for v in [
        r.min_solid_angle_sr,
        r.max_solid_angle_sr,
        r.mean_solid_angle_sr,
    ] {
        close_opt(v, REGULAR_SOLID_ANGLE, 1e-14);
    }
    for v in [
        r.min_q,
        r.max_q,
        r.mean_q,
        r.min_radius_ratio,
        r.mean_radius_ratio,
    ] {
        close_opt(v, 1.0, 1e-14);
    }
    let th = [
        r.n_dihedral_lt_5,
        r.n_dihedral_lt_10,
        r.n_dihedral_lt_20,
        r.n_dihedral_gt_160,
        r.n_dihedral_gt_170,
        r.n_dihedral_gt_175,
        r.n_inverted,
    ];
    assert_eq!(th, [0; 7]);
    // 70.53° is in the 70–80° bin (index 7), six times; the per-tet minimum is in the 70–75° bin
    // of the 5° histogram (index 14); 0.5513 sr is in [0.55, 0.60), index 11, four times.
    assert_eq!(counts(&r.dihedral_histogram), bins(18, &[(7, 6)]));
    assert_eq!(counts(&r.min_dihedral_histogram), bins(18, &[(14, 1)]));
    assert_eq!(counts(&r.solid_angle_histogram), bins(126, &[(11, 4)]));
    assert_eq!(r.worst_tets.len(), 1);
    assert_eq!((r.worst_tets[0].tet, r.worst_tets[0].label), (0, 7));
    assert_eq!(r.regions.len(), 1);
    let g = &r.regions[0];
    assert_eq!((g.label, g.n_tets, g.n_inverted), (7, 1, 0));
    close(g.volume, 1.0 / 3.0, 1e-15);
    close(g.min_q, 1.0, 1e-14);
    close(g.min_solid_angle_sr, REGULAR_SOLID_ANGLE, 1e-14);
}

// ------------------------------------------------------------------------------------------------
// (b) The unit cube in six tets around its main diagonal
// ------------------------------------------------------------------------------------------------

/// The unit cube's corners, corner i at ((i & 1), (i >> 1) & 1, (i >> 2) & 1), and its six Kuhn
/// tets (0, e_a, e_a + e_b, (1,1,1)) for each order (a, b, c) of the axes, positively oriented
/// (for an odd order the two middle vertices are swapped). Labels: the first three tets 1, the
/// others 2.
fn kuhn_cube() -> TetMesh {
    let points: Vec<[f64; 3]> = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    let axis = [1u32, 2, 4];
    let mut tets = Vec::new();
    for (perm, odd) in [
        ([0, 1, 2], false),
        ([1, 2, 0], false),
        ([2, 0, 1], false),
        ([0, 2, 1], true),
        ([1, 0, 2], true),
        ([2, 1, 0], true),
    ] {
        let b = axis[perm[0]];
        let c = b + axis[perm[1]];
        tets.push(if odd { [0, c, b, 7] } else { [0, b, c, 7] });
    }
    tet_mesh(points, tets, vec![1, 1, 1, 2, 2, 2])
}

#[test]
fn cube_in_six_tets() {
    // Take the tet A = (0,0,0), B = (1,0,0), C = (1,1,0), D = (1,1,1); the other five are its
    // images under permutations of the axes, so congruent. Its faces lie in the planes
    // ABC: z = 0, BCD: x = 1, ABD: y = z, ACD: x = y. Dihedral angles (TET_EDGES order):
    //   AB (z = 0 vs y = z, seen along x: directions (1,0) and (1,1) in yz):      45°
    //   AC (B and D off the edge (1,1,0): (½,−½,0) ⟂ (0,0,1)):                   90°
    //   AD (B, C off the diagonal: (2,−1,−1)/3 and (1,1,−2)/3, cos = (3/9)/(6/9)): 60°
    //   BC (z = 0 vs x = 1):                                                      90°
    //   BD (A − B = (−1,0,0) ⟂ the plane x = 1):                                  90°
    //   CD (x = y vs x = 1, seen along z: (−1,−1) and (0,−1)):                    45°
    // Sum 420°, so the mean dihedral angle is 70°.
    // Solid angles: the six tets share A and D and fill the cube's corner octant (π/2) there,
    // so π/12 each; B (and likewise C) is a corner of two tets, mirror images, so π/4 each.
    // Van Oosterom–Strackee at B agrees: u = (−1,0,0), v = (0,1,0), w = (0,1,1), det 1,
    // denominator √2 + 0 + 0 + 1, tan(Ω/2) = 1/(1 + √2) = tan(π/8).
    // Edges 1 (AB, BC, CD), √2 (AC, BD), √3 (AD): ΣL² = 3 + 2 + 2 + 3 = 10, V = 1/6, 3V = 1/2,
    // q = 12·(1/2)^(2/3)/10 = 1.2·2^(−2/3) = 0.755952630.
    // Radius ratio: faces ½, ½, √2/2, √2/2 (right triangles), total 1 + √2, so r = 3V/A =
    // (√2 − 1)/2; the circumsphere is the cube's, R = √3/2; 3r/R = √3(√2 − 1) = 0.717438935.
    let q = 1.2 * 2f64.powf(-2.0 / 3.0);
    let rr = 3f64.sqrt() * (2f64.sqrt() - 1.0);
    close(q, 0.755_952_63, 1e-9);
    close(rr, 0.717_438_935, 1e-9);

    let mesh = kuhn_cube();
    let mut want_dihedral = [45.0, 90.0, 60.0, 90.0, 90.0, 45.0];
    want_dihedral.sort_by(f64::total_cmp);
    let mut want_solid = [PI / 12.0, PI / 12.0, PI / 4.0, PI / 4.0];
    want_solid.sort_by(f64::total_cmp);
    for t in 0..6 {
        let m = TetMeasures::of(&mesh.corners(t));
        close(m.volume, 1.0 / 6.0, 1e-15);
        let mut d = m.dihedral_deg;
        d.sort_by(f64::total_cmp);
        for (x, y) in d.iter().zip(want_dihedral) {
            close(*x, y, 1e-12);
        }
        let mut s = m.solid_sr;
        s.sort_by(f64::total_cmp);
        for (x, y) in s.iter().zip(want_solid) {
            close(*x, y, 1e-14);
        }
        close(m.q, q, 1e-14);
        close(m.radius_ratio, rr, 1e-14);
    }
    // The first tet is exactly A B C D above, so the angles are in TET_EDGES order.
    let m0 = TetMeasures::of(&mesh.corners(0));
    for (x, y) in m0
        .dihedral_deg
        .iter()
        .zip([45.0, 90.0, 60.0, 90.0, 90.0, 45.0])
    {
        close(*x, y, 1e-12);
    }
    for (x, y) in m0
        .solid_sr
        .iter()
        .zip([PI / 12.0, PI / 4.0, PI / 4.0, PI / 12.0])
    {
        close(*x, y, 1e-14);
    }

    let r = QualityReport::of(&mesh);
    assert_eq!((r.n_points, r.n_tets, r.n_regions), (8, 6, 2));
    close(r.volume, 1.0, 1e-14);
    close_opt(r.min_dihedral_deg, 45.0, 1e-12);
    close_opt(r.max_dihedral_deg, 90.0, 1e-12);
    close_opt(r.mean_dihedral_deg, 70.0, 1e-12);
    close_opt(r.min_solid_angle_sr, PI / 12.0, 1e-14);
    close_opt(r.max_solid_angle_sr, PI / 4.0, 1e-14);
    // Mean solid angle: (2·π/12 + 2·π/4)/4 = (2π/3)/4 = π/6.
    close_opt(r.mean_solid_angle_sr, PI / 6.0, 1e-14);
    for v in [r.min_q, r.max_q, r.mean_q] {
        close_opt(v, q, 1e-14);
    }
    close_opt(r.min_radius_ratio, rr, 1e-14);
    close_opt(r.mean_radius_ratio, rr, 1e-14);
    // Smallest angle 45° is above every low threshold, largest 90° below every high one.
    let th = [
        r.n_dihedral_lt_5,
        r.n_dihedral_lt_10,
        r.n_dihedral_lt_20,
        r.n_dihedral_gt_160,
        r.n_dihedral_gt_170,
        r.n_dihedral_gt_175,
        r.n_inverted,
    ];
    assert_eq!(th, [0; 7]);
    // 36 angles: 12 at 45° (40–50), 6 at 60° (60–70: 59.99999999999999° in floating point,
    // snapped onto the edge), 18 at 90° (90–100).
    assert_eq!(
        counts(&r.dihedral_histogram),
        bins(18, &[(4, 12), (6, 6), (9, 18)])
    );
    // Per-tet minimum 45°: the 45–50° bin of the 5° histogram.
    assert_eq!(counts(&r.min_dihedral_histogram), bins(18, &[(9, 6)]));
    // 24 solid angles: 12 at π/12 = 0.2618 (bin 5: 0.25–0.30), 12 at π/4 = 0.7854 (bin 15).
    assert_eq!(
        counts(&r.solid_angle_histogram),
        bins(126, &[(5, 12), (15, 12)])
    );
    // All six tie at 45°: worst list in index order.
    let worst: Vec<usize> = r.worst_tets.iter().map(|w| w.tet).collect();
    assert_eq!(worst, vec![0, 1, 2, 3, 4, 5]);
    assert_eq!(r.regions.len(), 2);
    for (g, label) in r.regions.iter().zip([1, 2]) {
        assert_eq!((g.label, g.n_tets, g.n_inverted), (label, 3, 0));
        close(g.volume, 0.5, 1e-15);
        close(g.min_dihedral_deg, 45.0, 1e-12);
        close(g.max_dihedral_deg, 90.0, 1e-12);
        close(g.min_solid_angle_sr, PI / 12.0, 1e-14);
        close(g.min_q, q, 1e-14);
        close(g.mean_q, q, 1e-14);
    }
}

// ------------------------------------------------------------------------------------------------
// (c) A sliver
// ------------------------------------------------------------------------------------------------

/// The classic sliver: the corners of a square, (±1, 0) at height +h and (0, ±1) at height −h.
/// volume6 = (P1 − P0)·((P2 − P0)×(P3 − P0)) = (−2,0,0)·(−4h,0,2) = 8h > 0.
fn sliver(h: f64) -> [[f64; 3]; 4] {
    [
        [1.0, 0.0, h],
        [-1.0, 0.0, h],
        [0.0, 1.0, -h],
        [0.0, -1.0, -h],
    ]
}

#[test]
fn sliver_tet() {
    // Two opposite edges P0P1 (along x at z = h) and P2P3 (along y at z = −h), both of length 2.
    // Diagonal edges P0P1, P2P3: seen along the edge, the two faces go to (±1, −2h) in the
    // cross-section, so the angle is π − 2·atan(2h).
    // Side edges P0P2, P0P3, P1P2, P1P3 (all alike by symmetry): at P0P2 the outward normals of
    // the faces opposite P3 and P1 are (0, 2h, 1) and (2h, 0, −1), with dot −1 and lengths
    // √(1 + 4h²); the interior angle is π − acos(−1/(1 + 4h²)) = acos(1/(1 + 4h²)).
    // (Check: h = 1/√2 makes all edges 2 and both formulas give acos(1/3).)
    // Volume 8h/6 = 4h/3. Edges: 2, 2 and four of √(2 + 4h²): ΣL² = 16 + 16h², 3V = 4h,
    // q = 12·(4h)^(2/3)/(16(1 + h²)) = ¾·(4h)^(2/3)/(1 + h²).
    // Solid angle (all four alike): at P0, u = (−2,0,0), v = (−1,1,−2h), w = (−1,−1,−2h),
    // det 8h, |u| = 2, |v| = |w| = s = √(2 + 4h²), u·v = u·w = 2, v·w = 4h²; denominator
    // 2s² + 2s + 2s + 8h² = 4(1 + 4h² + s), so Ω = 2·atan(2h/(1 + 4h² + s)).
    // Radius ratio: the circumcentre is the origin, R = √(1 + h²); four congruent faces of area
    // √(1 + 4h²), r = 3V/A = h/√(1 + 4h²); 3r/R = 3h/(√(1 + 4h²)·√(1 + h²)).
    let dihedral_side = |h: f64| (1.0 / (1.0 + 4.0 * h * h)).acos().to_degrees();
    let dihedral_diag = |h: f64| 180.0 - 2.0 * (2.0 * h).atan().to_degrees();
    let q = |h: f64| 0.75 * (4.0 * h).powf(2.0 / 3.0) / (1.0 + h * h);
    let solid = |h: f64| 2.0 * (2.0 * h / (1.0 + 4.0 * h * h + (2.0 + 4.0 * h * h).sqrt())).atan();
    let rr = |h: f64| 3.0 * h / ((1.0 + 4.0 * h * h).sqrt() * (1.0 + h * h).sqrt());

    // The formulas give the regular tet at h = 1/√2.
    let hr = 0.5f64.sqrt();
    close(dihedral_side(hr), regular_dihedral_deg(), 1e-12);
    close(dihedral_diag(hr), regular_dihedral_deg(), 1e-12);
    close(q(hr), 1.0, 1e-14);
    close(solid(hr), REGULAR_SOLID_ANGLE, 1e-14);
    close(rr(hr), 1.0, 1e-14);
    let m = TetMeasures::of(&sliver(hr));
    close(m.min_dihedral(), regular_dihedral_deg(), 1e-12);
    close(m.q, 1.0, 1e-14);

    // h = 0.01: side angles acos(1/1.0004) ≈ 1.6203°, diagonal ones 180° − 2·1.14576° ≈
    // 177.7085°, q = ¾·0.04^(2/3)/1.0001 ≈ 0.0877, solid angles ≈ 0.01656 sr, radius ratio ≈
    // 0.02999, volume 0.04/3.
    let h = 0.01;
    close(dihedral_side(h), 1.620_3, 1e-4);
    close(dihedral_diag(h), 177.708_5, 1e-4);
    close(q(h), 0.087_71, 1e-5);
    close(solid(h), 0.016_56, 1e-5);
    let c = sliver(h);
    let m = TetMeasures::of(&c);
    // TET_EDGES: 01 (diagonal), 02, 03, 12, 13 (sides), 23 (diagonal).
    let want = [
        dihedral_diag(h),
        dihedral_side(h),
        dihedral_side(h),
        dihedral_side(h),
        dihedral_side(h),
        dihedral_diag(h),
    ];
    for (x, y) in m.dihedral_deg.iter().zip(want) {
        close(*x, y, 1e-10);
    }
    for s in m.solid_sr {
        close(s, solid(h), 1e-14);
    }
    close(m.q, q(h), 1e-14);
    close(m.radius_ratio, rr(h), 1e-13);
    close(m.volume, 4.0 * h / 3.0, 1e-16);

    // The sliver next to a regular tet (sharing nothing): the counts see only the sliver.
    let mut points = c.to_vec();
    points.extend(regular().map(|p| p.map(|x| x + 10.0)));
    let mesh = tet_mesh(points, vec![[4, 5, 6, 7], [0, 1, 2, 3]], vec![1, 2]);
    let r = QualityReport::of(&mesh);
    close_opt(r.min_dihedral_deg, dihedral_side(h), 1e-10);
    close_opt(r.max_dihedral_deg, dihedral_diag(h), 1e-10);
    close_opt(r.min_q, q(h), 1e-14);
    close_opt(r.max_q, 1.0, 1e-14);
    close_opt(r.min_solid_angle_sr, solid(h), 1e-14);
    close_opt(r.min_radius_ratio, rr(h), 1e-13);
    close(r.volume, 4.0 * h / 3.0 + 1.0 / 3.0, 1e-14);
    // Smallest 1.62° < 5°, largest 177.7° > 175°: the sliver counts at every threshold, the
    // regular tet at none.
    assert_eq!(
        [r.n_dihedral_lt_5, r.n_dihedral_lt_10, r.n_dihedral_lt_20],
        [1, 1, 1]
    );
    assert_eq!(
        [
            r.n_dihedral_gt_160,
            r.n_dihedral_gt_170,
            r.n_dihedral_gt_175
        ],
        [1, 1, 1]
    );
    assert_eq!(r.n_inverted, 0);
    // Sliver: four angles in 0–10°, two in 170–180°; regular tet: six in 70–80°.
    assert_eq!(
        counts(&r.dihedral_histogram),
        bins(18, &[(0, 4), (7, 6), (17, 2)])
    );
    // Solid angles: the sliver's four 0.0166 sr in bin 0, the regular tet's in bin 11.
    assert_eq!(
        counts(&r.solid_angle_histogram),
        bins(126, &[(0, 4), (11, 4)])
    );
    // The sliver is tet 1 and the worst; then the regular tet.
    let worst: Vec<(usize, u32)> = r.worst_tets.iter().map(|w| (w.tet, w.label)).collect();
    assert_eq!(worst, vec![(1, 2), (0, 1)]);
    close(r.worst_tets[0].min_dihedral_deg, dihedral_side(h), 1e-10);
    close(r.worst_tets[0].max_dihedral_deg, dihedral_diag(h), 1e-10);
    close(r.regions[1].min_dihedral_deg, dihedral_side(h), 1e-10);
    close(r.regions[0].min_dihedral_deg, regular_dihedral_deg(), 1e-12);

    // Thinner still: h = 0.001 gives about 0.162° and 179.77°.
    let m = TetMeasures::of(&sliver(0.001));
    close(m.min_dihedral(), dihedral_side(0.001), 1e-9);
    close(m.max_dihedral(), dihedral_diag(0.001), 1e-9);
    assert!(m.min_dihedral() < 0.17 && m.max_dihedral() > 179.7);
}

// ------------------------------------------------------------------------------------------------
// (d) Inverted and flat tets
// ------------------------------------------------------------------------------------------------

#[test]
fn inverted_tet() {
    // The regular tet with two vertices swapped: the same shape, negative orientation. Volume
    // −1/3, q = −1, radius ratio −1, solid angles −0.5513 sr; dihedral angles stay 70.53°.
    let mut c = regular();
    c.swap(1, 2);
    let m = TetMeasures::of(&c);
    close(m.volume, -1.0 / 3.0, 1e-15);
    close(m.q, -1.0, 1e-14);
    close(m.radius_ratio, -1.0, 1e-14);
    for s in m.solid_sr {
        close(s, -REGULAR_SOLID_ANGLE, 1e-14);
    }
    for d in m.dihedral_deg {
        close(d, regular_dihedral_deg(), 1e-12);
    }

    // Next to a good regular tet.
    let mut points = regular().to_vec();
    points.extend(c.map(|p| p.map(|x| x + 5.0)));
    let mesh = tet_mesh(points, vec![[0, 1, 2, 3], [4, 5, 6, 7]], vec![1, 1]);
    let r = QualityReport::of(&mesh);
    assert_eq!(r.n_inverted, 1);
    assert_eq!(r.regions[0].n_inverted, 1);
    close(r.volume, 0.0, 1e-15);
    close_opt(r.min_q, -1.0, 1e-14);
    close_opt(r.max_q, 1.0, 1e-14);
    close_opt(r.mean_q, 0.0, 1e-14);
    close_opt(r.min_radius_ratio, -1.0, 1e-14);
    close_opt(r.min_solid_angle_sr, -REGULAR_SOLID_ANGLE, 1e-14);
    // The inverted tet's four negative solid angles fall below the histogram.
    assert_eq!(r.solid_angle_histogram.below, 4);
    assert_eq!(r.solid_angle_histogram.total(), 8);
    // Dihedral angles do not see orientation: no threshold counts.
    assert_eq!(r.n_dihedral_lt_5 + r.n_dihedral_gt_175, 0);
    assert_eq!(counts(&r.dihedral_histogram), bins(18, &[(7, 12)]));
}

#[test]
fn flat_tet_is_finite() {
    // Four corners of a square: volume 0 exactly, so q = radius ratio = 0; the diagonals' faces
    // fold flat (0°) or open flat (180°). Counted as inverted (volume <= 0).
    let c = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    let m = TetMeasures::of(&c);
    assert_eq!((m.volume, m.q, m.radius_ratio), (0.0, 0.0, 0.0));
    assert!(
        m.dihedral_deg
            .iter()
            .chain(&m.solid_sr)
            .all(|x| x.is_finite())
    );
    let r = QualityReport::of(&tet_mesh(c.to_vec(), vec![[0, 1, 2, 3]], vec![1]));
    assert_eq!(r.n_inverted, 1);
    close_opt(r.min_dihedral_deg, 0.0, 1e-12);
    close_opt(r.max_dihedral_deg, 180.0, 1e-12);
    assert_eq!(r.n_dihedral_lt_5, 1);
    assert_eq!(r.n_dihedral_gt_175, 1);
    assert!(!debug_text(&r).contains("NaN"));
}

// ------------------------------------------------------------------------------------------------
// Empty meshes, JSON and determinism
// ------------------------------------------------------------------------------------------------

/// Every number of the report, for NaN checks (this crate has no JSON dev-dependency; the CLI's
/// tests check the JSON itself).
fn debug_text(r: &QualityReport) -> String {
    format!("{r:?}")
}

#[test]
fn empty_tet_mesh() {
    let r = QualityReport::of(&TetMesh::default());
    assert_eq!(
        (r.n_points, r.n_tets, r.n_regions, r.n_inverted),
        (0, 0, 0, 0)
    );
    assert_eq!(r.volume, 0.0);
    assert!(r.min_dihedral_deg.is_none() && r.mean_dihedral_deg.is_none());
    assert!(r.min_q.is_none() && r.mean_q.is_none() && r.min_radius_ratio.is_none());
    assert!(r.min_solid_angle_sr.is_none() && r.mean_solid_angle_sr.is_none());
    assert_eq!(r.dihedral_histogram.total(), 0);
    assert_eq!(r.dihedral_histogram.counts.len(), 18);
    assert!(r.worst_tets.is_empty() && r.regions.is_empty());
    assert!(!debug_text(&r).contains("NaN"));
    let text = r.to_string();
    assert!(text.contains("tets 0"), "{text}");

    // Points but no tets.
    let m = TetMesh::new(regular().to_vec(), vec![], vec![]);
    assert_eq!(QualityReport::of(&m).n_points, 4);

    let t = TriQualityReport::of(&TriMesh::default());
    assert_eq!((t.n_triangles, t.n_regions, t.n_inverted), (0, 0, 0));
    assert!(t.min_angle_deg.is_none() && t.mean_q.is_none());
    assert!(!format!("{t:?}").contains("NaN"));
    assert!(t.to_string().contains("triangles 0"));
}

/// A jittered n×n×n grid of Kuhn cubes, labels by slab.
fn jittered_grid(n: usize) -> TetMesh {
    let np = n + 1;
    let id = |i: usize, j: usize, k: usize| (i + np * (j + np * k)) as u32;
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut points = Vec::new();
    for k in 0..np {
        for j in 0..np {
            for i in 0..np {
                let p = [i, j, k].map(|x| x as f64 + 0.3 * rnd());
                points.push(p);
            }
        }
    }
    let mut tets = Vec::new();
    let mut labels = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = |a, b, d| id(i + a, j + b, k + d);
                for [p, q] in [
                    [c(1, 0, 0), c(1, 1, 0)],
                    [c(1, 0, 0), c(1, 0, 1)],
                    [c(0, 1, 0), c(1, 1, 0)],
                    [c(0, 1, 0), c(0, 1, 1)],
                    [c(0, 0, 1), c(1, 0, 1)],
                    [c(0, 0, 1), c(0, 1, 1)],
                ] {
                    let mut t = [c(0, 0, 0), p, q, c(1, 1, 1)];
                    let cs = t.map(|v| points[v as usize]);
                    if quality::volume(&cs) < 0.0 {
                        t.swap(1, 2);
                    }
                    tets.push(t);
                    labels.push(10 + (k * 3 / n) as u32);
                }
            }
        }
    }
    TetMesh::new(points, tets, labels)
}

#[test]
fn report_is_deterministic_and_consistent() {
    let mesh = jittered_grid(8);
    let a = QualityReport::of(&mesh);
    let b = QualityReport::of(&mesh.clone());
    assert_eq!(a, b);
    assert_eq!(format!("{a:?}"), format!("{b:?}"));
    assert_eq!(a.to_string(), b.to_string());
    assert_eq!(a.n_tets, 6 * 512);
    assert_eq!(a.n_regions, 3);
    assert_eq!(a.n_inverted, 0);
    // Every angle is counted once.
    assert_eq!(a.dihedral_histogram.total(), 6 * a.n_tets as u64);
    assert_eq!(a.solid_angle_histogram.total(), 4 * a.n_tets as u64);
    assert_eq!(a.min_dihedral_histogram.total(), a.n_tets as u64);
    assert_eq!(
        a.solid_angle_histogram.below + a.solid_angle_histogram.above,
        0
    );
    // The grid fills its jittered box: the region volumes add up to the total.
    let sum: f64 = a.regions.iter().map(|g| g.volume).sum();
    close(sum, a.volume, 1e-9);
    assert_eq!(
        a.regions.iter().map(|g| g.n_tets).sum::<u64>(),
        a.n_tets as u64
    );
    let labels: Vec<u32> = a.regions.iter().map(|g| g.label).collect();
    assert_eq!(labels, vec![10, 11, 12]);
    // Worst list: ten tets, sorted by min dihedral, starting at the global minimum.
    assert_eq!(a.worst_tets.len(), 10);
    assert!(
        a.worst_tets
            .windows(2)
            .all(|w| w[0].min_dihedral_deg <= w[1].min_dihedral_deg)
    );
    assert_eq!(Some(a.worst_tets[0].min_dihedral_deg), a.min_dihedral_deg);
    let mut mins: Vec<(f64, usize)> = (0..mesh.n_tets())
        .map(|t| (TetMeasures::of(&mesh.corners(t)).min_dihedral(), t))
        .collect();
    mins.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let want: Vec<usize> = mins[..10].iter().map(|x| x.1).collect();
    let got: Vec<usize> = a.worst_tets.iter().map(|w| w.tet).collect();
    assert_eq!(got, want);
    // Threshold counts agree with a direct count.
    let direct = |f: &dyn Fn(&TetMeasures) -> bool| {
        (0..mesh.n_tets())
            .filter(|&t| f(&TetMeasures::of(&mesh.corners(t))))
            .count() as u64
    };
    assert_eq!(a.n_dihedral_lt_20, direct(&|m| m.min_dihedral() < 20.0));
    assert_eq!(a.n_dihedral_gt_160, direct(&|m| m.max_dihedral() > 160.0));
    let mean = a.mean_solid_angle_sr.unwrap();
    assert!(mean > 0.0 && mean < 2.0 * PI);
    let text = a.to_string();
    for word in [
        "dihedral (deg)",
        "solid angle (sr)",
        "radius ratio",
        "<5°",
        ">175°",
    ] {
        assert!(text.contains(word), "{word} missing from\n{text}");
    }
}

// ------------------------------------------------------------------------------------------------
// (e) Triangles
// ------------------------------------------------------------------------------------------------

#[test]
fn triangle_measures() {
    // Equilateral, side 1: angles 60°, area √3/4, ΣL² = 3, q = 4√3·(√3/4)/3 = 1; r = a/(2√3),
    // R = a/√3, 2r/R = 1.
    let eq = [[0.0, 0.0], [1.0, 0.0], [0.5, 3f64.sqrt() / 2.0]];
    let m = TriMeasures::of(&eq);
    for a in m.angles_deg {
        close(a, 60.0, 1e-12);
    }
    close(m.area, 3f64.sqrt() / 4.0, 1e-15);
    close(m.q, 1.0, 1e-14);
    close(m.radius_ratio, 1.0, 1e-14);

    // Right isosceles, legs 1: angles 90° (at the right-angle corner), 45°, 45°; area ½;
    // ΣL² = 1 + 1 + 2 = 4, q = 4√3·½/4 = √3/2 = 0.866025; r = A/s = ½/((2 + √2)/2) =
    // (2 − √2)/2, R = √2/2 (half the hypotenuse), 2r/R = 2√2 − 2 = 0.828427.
    let ri = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let m = TriMeasures::of(&ri);
    for (x, y) in m.angles_deg.iter().zip([90.0, 45.0, 45.0]) {
        close(*x, y, 1e-12);
    }
    close(m.area, 0.5, 0.0);
    close(m.q, 3f64.sqrt() / 2.0, 1e-15);
    close(m.radius_ratio, 2.0 * 2f64.sqrt() - 2.0, 1e-15);

    // Clockwise: the same angles, negative area, q and radius ratio.
    let cw = [ri[0], ri[2], ri[1]];
    let m = TriMeasures::of(&cw);
    close(m.min_angle(), 45.0, 1e-12);
    close(m.max_angle(), 90.0, 1e-12);
    close(m.area, -0.5, 0.0);
    close(m.q, -(3f64.sqrt()) / 2.0, 1e-15);
    close(m.radius_ratio, -(2.0 * 2f64.sqrt() - 2.0), 1e-15);

    // Thin isosceles (0,0), (1,0), (½, h): base angles atan(2h), apex π − 2·atan(2h). h = 0.01:
    // 1.14576° and 177.70848°.
    let h = 0.01;
    let m = TriMeasures::of(&[[0.0, 0.0], [1.0, 0.0], [0.5, h]]);
    close(m.min_angle(), (2.0 * h).atan().to_degrees(), 1e-11);
    close(
        m.max_angle(),
        180.0 - 2.0 * (2.0 * h).atan().to_degrees(),
        1e-11,
    );
    close(m.min_angle(), 1.145_76, 1e-5);

    // Flat: zero area, q = radius ratio = 0, finite angles.
    let m = TriMeasures::of(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]);
    assert_eq!((m.area, m.q, m.radius_ratio), (0.0, 0.0, 0.0));
    assert!(m.angles_deg.iter().all(|a| a.is_finite()));
    assert_eq!(quality::tri::radius_ratio(&[[1.0, 1.0]; 3]), 0.0);
    assert_eq!(quality::tri::q_measure(&[[1.0, 1.0]; 3]), 0.0);
}

#[test]
fn triangle_report() {
    // Triangle 0: equilateral (label 1); 1: right isosceles (label 1); 2: thin, h = 0.01
    // (label 2); 3: the right isosceles clockwise (label 2).
    let s3 = 3f64.sqrt();
    let points = vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [0.5, s3 / 2.0],
        [10.0, 0.0],
        [11.0, 0.0],
        [10.0, 1.0],
        [20.0, 0.0],
        [21.0, 0.0],
        [20.5, 0.01],
    ];
    let triangles = vec![[0, 1, 2], [3, 4, 5], [6, 7, 8], [3, 5, 4]];
    let mesh = TriMesh::new(points, triangles, vec![1, 1, 2, 2]);
    let r = TriQualityReport::of(&mesh);
    let thin_min = 0.02f64.atan().to_degrees();
    let thin_max = 180.0 - 2.0 * thin_min;
    assert_eq!((r.n_points, r.n_triangles, r.n_regions), (9, 4, 2));
    // Areas: √3/4 + ½ + ½·1·0.01 − ½.
    close(r.area, s3 / 4.0 + 0.005, 1e-15);
    close_opt(r.min_angle_deg, thin_min, 1e-11);
    close_opt(r.max_angle_deg, thin_max, 1e-11);
    close_opt(r.mean_angle_deg, 60.0, 1e-12);
    // Per-triangle minimum angles: 60, 45, 1.14576, 45.
    close_opt(
        r.mean_min_angle_deg,
        (60.0 + 45.0 + thin_min + 45.0) / 4.0,
        1e-12,
    );
    // q: 1, √3/2, 4√3·0.005/(1 + 2·(0.25 + 0.0001)) = 0.02√3/1.5002, −√3/2.
    let q_thin = 0.02 * s3 / 1.5002;
    close_opt(r.max_q, 1.0, 1e-14);
    close_opt(r.min_q, -s3 / 2.0, 1e-15);
    close_opt(r.mean_q, (1.0 + q_thin) / 4.0, 1e-14);
    close_opt(r.max_radius_ratio, 1.0, 1e-14);
    close_opt(r.min_radius_ratio, -(2.0 * 2f64.sqrt() - 2.0), 1e-14);
    // Only the thin one is past the thresholds.
    assert_eq!(
        [r.n_angle_lt_5, r.n_angle_lt_10, r.n_angle_lt_20],
        [1, 1, 1]
    );
    assert_eq!(
        [r.n_angle_gt_160, r.n_angle_gt_170, r.n_angle_gt_175],
        [1, 1, 1]
    );
    assert_eq!(r.n_inverted, 1);
    // Angles: 60 ×3 (bin 6, with snapping of 59.99999999999999°), 45 ×4 (bin 4), 90 ×2 (bin 9),
    // 1.15 ×2 (bin 0), 177.7 (bin 17).
    assert_eq!(
        counts(&r.angle_histogram),
        bins(18, &[(0, 2), (4, 4), (6, 3), (9, 2), (17, 1)])
    );
    // Minimum angles in 5° bins: 60 (bin 12), 45 ×2 (bin 9), 1.15 (bin 0).
    assert_eq!(
        counts(&r.min_angle_histogram),
        bins(18, &[(0, 1), (9, 2), (12, 1)])
    );
    let worst: Vec<usize> = r.worst_triangles.iter().map(|w| w.triangle).collect();
    assert_eq!(worst, vec![2, 1, 3, 0]);
    assert_eq!(r.regions.len(), 2);
    let (g1, g2) = (&r.regions[0], &r.regions[1]);
    assert_eq!((g1.label, g1.n_triangles, g1.n_inverted), (1, 2, 0));
    assert_eq!((g2.label, g2.n_triangles, g2.n_inverted), (2, 2, 1));
    close(g1.area, s3 / 4.0 + 0.5, 1e-15);
    close(g2.area, 0.005 - 0.5, 1e-15);
    close(g1.min_angle_deg, 45.0, 1e-12);
    close(g1.max_angle_deg, 90.0, 1e-12);
    close(g2.min_angle_deg, thin_min, 1e-11);
    close(g2.min_q, -s3 / 2.0, 1e-15);
    close(g1.mean_q, (1.0 + s3 / 2.0) / 2.0, 1e-14);
    let text = r.to_string();
    assert!(
        text.contains("triangles 4") && text.contains("angle (deg)"),
        "{text}"
    );
}

#[test]
fn histogram_edges() {
    let mut h = Histogram::new(0.0, 10.0, 18);
    for x in [
        0.0,
        9.999,
        10.0,
        59.999_999_999_999_99,
        180.0,
        -1e-300,
        f64::NAN,
        180.5,
    ] {
        h.add(x);
    }
    assert_eq!(h.counts[0], 2);
    assert_eq!(h.counts[1], 1);
    assert_eq!(h.counts[6], 1, "a hair below 60° counts as 60°");
    assert_eq!(h.counts[17], 1, "180° is in the last bin");
    assert_eq!((h.below, h.above), (2, 1));
    assert_eq!(h.total(), 8);
    assert_eq!((h.bin_lo(3), h.bin_hi(3), h.hi), (30.0, 40.0, 180.0));
    assert_eq!(h.occupied(), Some(0..=17));
}

#[test]
fn single_edge_dihedral_and_chord_agree_with_all_angles() {
    // Random tets, slivers and near-flat ones included: `dihedral_at` is `dihedral_angles[e]`,
    // and `min_dihedral_chord2` is 4·sin²(θ/2) of the smallest angle θ.
    let mut seed = 7u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for k in 0..2000 {
        let mut c = [[0.0; 3]; 4];
        for p in &mut c {
            *p = [next(), next(), next()];
        }
        if k % 3 == 0 {
            // Flatten: the fourth point close to the plane of the first three.
            let t = 10f64.powi(-(k % 9) - 1);
            let [a, b, d] = [c[0], c[1], c[2]];
            for (i, x) in c[3].iter_mut().enumerate() {
                *x = (a[i] + b[i] + d[i]) / 3.0 * (1.0 - t) + *x * t;
            }
        }
        let all = quality::tet::dihedral_angles(&c);
        for (e, &a) in all.iter().enumerate() {
            assert!(
                (quality::tet::dihedral_at(&c, e) - a).abs() < 1e-12,
                "{c:?} edge {e}"
            );
        }
        let min = all.iter().copied().fold(f64::INFINITY, f64::min);
        let chord = quality::tet::min_dihedral_chord2(&c);
        let want = 4.0 * (min / 2.0).sin().powi(2);
        assert!(
            (chord - want).abs() <= 1e-9 * want.max(1e-12),
            "{chord} vs {want}"
        );
    }
}

/// A tet's measures do not depend on its size: the same at 1e±40 and 1e±50 as at unit size.
/// A face normal is the square of the size and the circumradius's terms its eighth power, so the
/// dihedral angles came out 90° at 1e40 (0° and 180° at 1e-45) and the radius ratio 0, for any
/// tet (found by a Python user; the API takes coordinates from 1e-45 to 1e50).
#[test]
fn measures_do_not_depend_on_the_size_of_the_tet() {
    let c = [
        [0.0, 0.0, 0.0],
        [1.0, 0.1, 0.0],
        [0.3, 0.9, 0.2],
        [0.2, 0.3, 0.8],
    ];
    let unit = TetMeasures::of(&c);
    for s in [1e40, 1e-40, 1e50, 1e-45] {
        let m = TetMeasures::of(&c.map(|p| p.map(|x| x * s)));
        for (a, b) in m.dihedral_deg.iter().zip(&unit.dihedral_deg) {
            close(*a, *b, 1e-9);
        }
        close(m.radius_ratio, unit.radius_ratio, 1e-9);
        close(m.q, unit.q, 1e-9);
        for (a, b) in m.solid_sr.iter().zip(&unit.solid_sr) {
            close(*a, *b, 1e-9);
        }
    }
}
