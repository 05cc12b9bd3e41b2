//! Tests: predicates.
//!
//! Exactly degenerate inputs (collinear, coplanar, cospherical, cocircular) on which naive
//! floating point gets signs wrong, the exact predicates against integer arithmetic, and the
//! consistency of the Simulation-of-Simplicity versions.

use biotet::geom::predicates::{
    Sign, in_exact_range, incircle, incircle_sos, insphere, insphere_sos, orient2d, orient3d,
};
use proptest::prelude::*;
use proptest::strategy::ValueTree;

type P2 = [f64; 2];
type P3 = [f64; 3];

// ---------------------------------------------------------------------------------------------
// Naive floating-point versions (what one would write without exact arithmetic)
// ---------------------------------------------------------------------------------------------

fn naive_orient2d(a: P2, b: P2, c: P2) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

fn det3(m: [[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

fn sub3(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn naive_orient3d(a: P3, b: P3, c: P3, d: P3) -> f64 {
    det3([sub3(b, a), sub3(c, a), sub3(d, a)])
}

fn norm2(p: P3) -> f64 {
    p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
}

/// The lifted 5×5 determinant `[x, y, z, x²+y²+z², 1]` with `e`'s row subtracted, i.e. the 4×4
/// determinant of rows `(p − e, |p|² − |e|²)`, negated to biotet's convention.
fn naive_insphere(a: P3, b: P3, c: P3, d: P3, e: P3) -> f64 {
    let rows = [a, b, c, d].map(|p| {
        let q = sub3(p, e);
        [q[0], q[1], q[2], norm2(p) - norm2(e)]
    });
    // Laplace expansion along the last column.
    let mut det = 0.0;
    for (i, row) in rows.iter().enumerate() {
        let mut minor = [[0.0; 3]; 3];
        let mut r = 0;
        for (j, other) in rows.iter().enumerate() {
            if j != i {
                minor[r] = [other[0], other[1], other[2]];
                r += 1;
            }
        }
        let sign = if (i + 3) % 2 == 0 { 1.0 } else { -1.0 };
        det += sign * row[3] * det3(minor);
    }
    -det
}

/// The lifted 4×4 determinant `[x, y, x²+y², 1]` with `d`'s row subtracted.
fn naive_incircle(a: P2, b: P2, c: P2, d: P2) -> f64 {
    let n = |p: P2| p[0] * p[0] + p[1] * p[1];
    let rows = [a, b, c].map(|p| [p[0] - d[0], p[1] - d[1], n(p) - n(d)]);
    det3(rows)
}

// ---------------------------------------------------------------------------------------------
// Exact integer versions (i128)
// ---------------------------------------------------------------------------------------------

fn det3_i(m: [[i128; 3]; 3]) -> i128 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

fn det4_i(m: [[i128; 4]; 4]) -> i128 {
    let mut det = 0;
    for c in 0..4 {
        let minor: [[i128; 3]; 3] = [1, 2, 3].map(|r| {
            let mut row = [0; 3];
            let mut k = 0;
            for (j, &x) in m[r].iter().enumerate() {
                if j != c {
                    row[k] = x;
                    k += 1;
                }
            }
            row
        });
        let sign = if c % 2 == 0 { 1 } else { -1 };
        det += sign * m[0][c] * det3_i(minor);
    }
    det
}

fn sign_i(x: i128) -> Sign {
    match x.cmp(&0) {
        std::cmp::Ordering::Less => Sign::Negative,
        std::cmp::Ordering::Equal => Sign::Zero,
        std::cmp::Ordering::Greater => Sign::Positive,
    }
}

type I3 = [i64; 3];
type I2 = [i64; 2];

fn exact_orient3d(a: I3, b: I3, c: I3, d: I3) -> Sign {
    let r = |p: I3| [0, 1, 2].map(|i| (p[i] - a[i]) as i128);
    sign_i(det3_i([r(b), r(c), r(d)]))
}

/// Positive when `e` is inside the sphere of the positively oriented `abcd`: the lifted
/// determinant `det[p − e, |p − e|²]` is positive for `e` inside when `abcd` is *negatively*
/// oriented (it is Shewchuk's convention), hence the minus.
fn exact_insphere(a: I3, b: I3, c: I3, d: I3, e: I3) -> Sign {
    let rows = [a, b, c, d].map(|p| {
        let q = [0, 1, 2].map(|i| (p[i] - e[i]) as i128);
        [q[0], q[1], q[2], q[0] * q[0] + q[1] * q[1] + q[2] * q[2]]
    });
    sign_i(-det4_i(rows))
}

fn exact_orient2d(a: I2, b: I2, c: I2) -> Sign {
    let (b0, b1) = ((b[0] - a[0]) as i128, (b[1] - a[1]) as i128);
    let (c0, c1) = ((c[0] - a[0]) as i128, (c[1] - a[1]) as i128);
    sign_i(b0 * c1 - b1 * c0)
}

fn exact_incircle(a: I2, b: I2, c: I2, d: I2) -> Sign {
    let rows = [a, b, c].map(|p| {
        let q = [(p[0] - d[0]) as i128, (p[1] - d[1]) as i128];
        [q[0], q[1], q[0] * q[0] + q[1] * q[1]]
    });
    sign_i(det3_i(rows))
}

fn f3(p: I3) -> P3 {
    p.map(|x| x as f64)
}

fn f2(p: I2) -> P2 {
    p.map(|x| x as f64)
}

// ---------------------------------------------------------------------------------------------
// Lattice spheres and circles
// ---------------------------------------------------------------------------------------------

/// All integer points on `x² + y² + z² = r2`.
fn sphere_points(r2: i64) -> Vec<I3> {
    let r = (r2 as f64).sqrt() as i64 + 1;
    let mut out = Vec::new();
    for x in -r..=r {
        for y in -r..=r {
            for z in -r..=r {
                if x * x + y * y + z * z == r2 {
                    out.push([x, y, z]);
                }
            }
        }
    }
    out
}

/// All integer points on `x² + y² = r2`.
fn circle_points(r2: i64) -> Vec<I2> {
    let r = (r2 as f64).sqrt() as i64 + 1;
    let mut out = Vec::new();
    for x in -r..=r {
        for y in -r..=r {
            if x * x + y * y == r2 {
                out.push([x, y]);
            }
        }
    }
    out
}

const RADII2: [i64; 6] = [9, 25, 50, 75, 27, 49];

/// Translations that keep small-integer (and 2^k-scaled) lattice points exact in binary.
const OFFSETS: [P3; 4] = [
    [0.0, 0.0, 0.0],
    [1e6 + 0.5, -1e6 - 0.25, 1048576.125],
    [67108864.5, -33554432.25, 134217728.5],
    [3.0e9 + 0.5, 1.5e9 + 0.75, -7.0e8 - 0.5],
];

fn place3(p: I3, scale: f64, t: P3) -> P3 {
    [0, 1, 2].map(|i| p[i] as f64 * scale + t[i])
}

fn exact_offsets() -> impl Strategy<Value = P3> {
    (0usize..4).prop_map(|i| OFFSETS[i])
}

/// A small deterministic generator for the enumerations below.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self, n: usize) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 33) % n as u64) as usize
    }

    /// `k` distinct indices below `n`.
    fn distinct<const K: usize>(&mut self, n: usize) -> [usize; K] {
        let mut out = [0; K];
        let mut i = 0;
        while i < K {
            let x = self.next(n);
            if !out[..i].contains(&x) {
                out[i] = x;
                i += 1;
            }
        }
        out
    }
}

// ---------------------------------------------------------------------------------------------
// Conventions
// ---------------------------------------------------------------------------------------------

#[test]
fn regular_tet_conventions() {
    let (o, x, y, z) = ([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    assert_eq!(orient3d(o, x, y, z), Sign::Positive);
    assert_eq!(orient3d(o, y, x, z), Sign::Negative);
    assert_eq!(orient2d([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]), Sign::Positive);
    // Regular tet inscribed in the sphere of radius √3 around the origin.
    let mut t = [
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ];
    if orient3d(t[0], t[1], t[2], t[3]) == Sign::Negative {
        t.swap(0, 1);
    }
    assert_eq!(orient3d(t[0], t[1], t[2], t[3]), Sign::Positive);
    let ins = |e: P3| insphere(t[0], t[1], t[2], t[3], e);
    assert_eq!(ins([0.0; 3]), Sign::Positive); // centre inside
    assert_eq!(ins([0.5, -0.2, 0.1]), Sign::Positive);
    assert_eq!(ins([3.0, 0.0, 0.0]), Sign::Negative);
    assert_eq!(ins([-1.0, -1.0, -1.0]), Sign::Zero); // another cube corner: on the sphere
    // Negatively oriented: the sign flips.
    assert_eq!(insphere(t[1], t[0], t[2], t[3], [0.0; 3]), Sign::Negative);
    // In-circle: counter-clockwise triangle, centre inside.
    let (a, b, c) = ([1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]);
    assert_eq!(incircle(a, b, c, [0.0, 0.0]), Sign::Positive);
    assert_eq!(incircle(a, b, c, [2.0, 0.0]), Sign::Negative);
    assert_eq!(incircle(a, b, c, [0.0, -1.0]), Sign::Zero);
    assert_eq!(incircle(b, a, c, [0.0, 0.0]), Sign::Negative);
    // SoS: on the sphere/circle, the most perturbed (largest id) point is pushed outside.
    let p = [t[0], t[1], t[2], t[3], [-1.0, -1.0, -1.0]];
    assert_eq!(insphere_sos(p, [0, 1, 2, 3, 4]), Sign::Negative);
    assert_eq!(
        incircle_sos([a, b, c, [0.0, -1.0]], [0, 1, 2, 3]),
        Sign::Negative
    );
    // ... and when a tet corner is the most perturbed, the fifth point counts as inside.
    assert_eq!(insphere_sos(p, [9, 1, 2, 3, 4]), Sign::Positive);
    assert_eq!(
        incircle_sos([a, b, c, [0.0, -1.0]], [9, 1, 2, 3]),
        Sign::Positive
    );
}

// ---------------------------------------------------------------------------------------------
// Naive floating point fails on exactly degenerate inputs; the predicates do not
// ---------------------------------------------------------------------------------------------

/// Kettner et al.'s classroom example: `p` near `(0.5, 0.5)` on a 2^-53 grid, `q`, `r` on the
/// diagonal. The exact sign is `sign(j − i)` (zero on the diagonal, where the points are exactly
/// collinear).
#[test]
fn orient2d_near_diagonal() {
    let u = f64::EPSILON / 2.0; // 2^-53
    let (q, r) = ([12.0, 12.0], [24.0, 24.0]);
    let mut naive_wrong = 0;
    for i in 0..64 {
        for j in 0..64 {
            let p = [0.5 + i as f64 * u, 0.5 + j as f64 * u];
            let want = Sign::of((j - i) as f64);
            assert_eq!(orient2d(p, q, r), want, "i={i} j={j}");
            assert_eq!(orient2d(q, r, p), want);
            assert_eq!(orient2d(r, p, q), want);
            if Sign::of(naive_orient2d(p, q, r)) != want {
                naive_wrong += 1;
            }
        }
    }
    println!("naive orient2d wrong on {naive_wrong} of 4096 points");
    assert!(naive_wrong > 0);
}

/// A double with at most `bits` significant bits: `m · 2^e`.
fn short_double(bits: u32, e: i32) -> impl Strategy<Value = f64> {
    (1i64..(1i64 << bits), any::<bool>())
        .prop_map(move |(m, neg)| (if neg { -m } else { m }) as f64 * 2f64.powi(e))
}

/// Points exactly on the line `y = 3x` (short mantissas keep `3x` exact), one of them tiny and
/// two large, so naive differences round.
#[test]
fn naive_orient2d_fails_on_exactly_collinear_points() {
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let mut naive_nonzero = 0;
    let strat = (
        short_double(50, -60),
        short_double(50, -20),
        short_double(50, -21),
    );
    for _ in 0..500 {
        let (x0, x1, x2) = strat.new_tree(&mut runner).unwrap().current();
        let (a, b, c) = ([x0, 3.0 * x0], [x1, 3.0 * x1], [x2, 3.0 * x2]);
        assert_eq!(orient2d(a, b, c), Sign::Zero);
        assert_eq!(orient2d(b, c, a), Sign::Zero);
        if naive_orient2d(a, b, c) != 0.0 || naive_orient2d(b, c, a) != 0.0 {
            naive_nonzero += 1;
        }
    }
    println!("naive orient2d non-zero on {naive_nonzero} of 500 collinear triples");
    assert!(naive_nonzero > 0);
}

proptest! {
    /// Collinear points offset by large values: the line `y = 3x + c` through `(X, Y)` with
    /// `|X|` up to 2^50, points `(X + t, Y + 3t)` with 40-bit steps `t` on the finest grid
    /// that keeps the sums exact.
    #[test]
    fn collinear_points_are_zero(
        ms in proptest::array::uniform3(-(1i64 << 40)..(1i64 << 40)),
        big in 1i32..30,
        sx in (1i64 << 19)..(1i64 << 20),
        neg in any::<bool>(),
    ) {
        let x0 = (if neg { -sx } else { sx }) as f64 * 2f64.powi(big);
        let y0 = -x0 * 0.5;
        let ts = ms.map(|m| m as f64 * 2f64.powi(big - 31));
        let p = ts.map(|t| [x0 + t, y0 + 3.0 * t]);
        prop_assert!(p.iter().zip(&ts).all(|(q, &t)| q[0] - x0 == t && q[1] - y0 == 3.0 * t));
        prop_assert_eq!(orient2d(p[0], p[1], p[2]), Sign::Zero);
        prop_assert_eq!(orient2d(p[2], p[0], p[1]), Sign::Zero);
        // Lifted into 3D on the vertical plane through the line: coplanar with anything on it.
        let q = p.map(|v| [v[0], v[1], 7.0]);
        let r = [p[0][0], p[0][1], -1.5e9];
        prop_assert_eq!(orient3d(q[0], q[1], q[2], r), Sign::Zero);
        prop_assert_eq!(orient3d(q[0], r, q[1], q[2]), Sign::Zero);
    }

    /// Points exactly on the plane `z = 3x − 5y` (short mantissas), one tiny and three large.
    #[test]
    fn coplanar_points_are_zero(
        small in proptest::array::uniform2(short_double(46, -60)),
        large in proptest::array::uniform3(proptest::array::uniform2(short_double(46, -20))),
    ) {
        let on = |x: f64, y: f64| [x, y, 3.0 * x - 5.0 * y];
        let a = on(small[0], small[1]);
        let [b, c, d] = large.map(|q| on(q[0], q[1]));
        prop_assert_eq!(orient3d(a, b, c, d), Sign::Zero);
        prop_assert_eq!(orient3d(b, c, d, a), Sign::Zero);
        prop_assert_eq!(orient3d(d, a, c, b), Sign::Zero);
    }
}

#[test]
fn naive_orient3d_fails_on_exactly_coplanar_points() {
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let strat = (
        proptest::array::uniform2(short_double(46, -60)),
        proptest::array::uniform3(proptest::array::uniform2(short_double(46, -20))),
    );
    let on = |x: f64, y: f64| [x, y, 3.0 * x - 5.0 * y];
    let mut naive_nonzero = 0;
    for _ in 0..500 {
        let (small, large) = strat.new_tree(&mut runner).unwrap().current();
        let a = on(small[0], small[1]);
        let [b, c, d] = large.map(|q| on(q[0], q[1]));
        assert_eq!(orient3d(a, b, c, d), Sign::Zero);
        if naive_orient3d(a, b, c, d) != 0.0 {
            naive_nonzero += 1;
        }
    }
    println!("naive orient3d non-zero on {naive_nonzero} of 500 coplanar quadruples");
    assert!(naive_nonzero > 0);
}

/// At the bottom of the exact range (coordinates down to 2⁻¹⁵⁰, as a CAD kernel's -7.7e-34 for a
/// zero): lattice points scaled by 2⁻¹⁴⁶, where every value is exact, keep the lattice's exact
/// signs for `orient3d` and `insphere`, zero included.
#[test]
fn the_smallest_coordinates_keep_exact_signs() {
    assert!(in_exact_range(2f64.powi(-150)) && !in_exact_range(2f64.powi(-151)));
    assert!(in_exact_range(-7.703719777548943e-34));
    let s = 2f64.powi(-146);
    let mut rng = Lcg(11);
    let mut signs = [0usize; 3];
    for r2 in RADII2 {
        let pts = sphere_points(r2);
        for _ in 0..300 {
            let i = rng.distinct::<5>(pts.len());
            let mut q = i.map(|k| pts[k]);
            // Off the sphere for half the tuples, so every sign occurs.
            if rng.next(2) == 0 {
                q[4] = q[4].map(|x| x + 1);
            }
            let p = q.map(|x| place3(x, s, [0.0; 3]));
            assert!(p.iter().flatten().all(|&c| in_exact_range(c)));
            let o = orient3d(p[0], p[1], p[2], p[3]);
            assert_eq!(o, exact_orient3d(q[0], q[1], q[2], q[3]), "orient3d {q:?}");
            let e = insphere(p[0], p[1], p[2], p[3], p[4]);
            assert_eq!(
                e,
                exact_insphere(q[0], q[1], q[2], q[3], q[4]),
                "insphere {q:?}"
            );
            signs[(e.as_i32() + 1) as usize] += 1;
        }
    }
    assert!(signs.iter().all(|&n| n > 0), "{signs:?}");
}

/// Integer points on spheres, translated by large exact offsets: `insphere` is exactly zero,
/// the naive lifted determinant is not (and its sign is arbitrary).
#[test]
fn cospherical_lattice_points() {
    let mut rng = Lcg(7);
    let mut tested = 0;
    let mut naive_nonzero = 0;
    let (mut naive_pos, mut naive_neg) = (0, 0);
    for r2 in RADII2 {
        let pts = sphere_points(r2);
        for (oi, &t) in OFFSETS.iter().enumerate() {
            for _ in 0..400 {
                let idx = rng.distinct::<5>(pts.len());
                let scale = 2f64.powi(rng.next(9) as i32 - 4);
                let p = idx.map(|i| place3(pts[i], scale, t));
                assert_eq!(
                    insphere(p[0], p[1], p[2], p[3], p[4]),
                    Sign::Zero,
                    "r2={r2} offset {oi}"
                );
                tested += 1;
                let n = naive_insphere(p[0], p[1], p[2], p[3], p[4]);
                if n != 0.0 {
                    naive_nonzero += 1;
                    if n > 0.0 {
                        naive_pos += 1;
                    } else {
                        naive_neg += 1;
                    }
                }
            }
        }
    }
    println!(
        "naive insphere non-zero on {naive_nonzero} of {tested} cospherical 5-tuples \
         ({naive_pos} say inside, {naive_neg} outside)"
    );
    assert!(naive_pos > 0 && naive_neg > 0);
}

#[test]
fn cocircular_lattice_points() {
    let mut rng = Lcg(11);
    let mut naive_nonzero = 0;
    let mut tested = 0;
    for r2 in [25i64, 50, 65, 85, 2] {
        let pts = circle_points(r2);
        for &t in &OFFSETS {
            for _ in 0..300 {
                let idx = rng.distinct::<4>(pts.len());
                let scale = 2f64.powi(rng.next(9) as i32 - 4);
                let p = idx.map(|i| {
                    [
                        pts[i][0] as f64 * scale + t[0],
                        pts[i][1] as f64 * scale + t[1],
                    ]
                });
                assert_eq!(incircle(p[0], p[1], p[2], p[3]), Sign::Zero);
                tested += 1;
                if naive_incircle(p[0], p[1], p[2], p[3]) != 0.0 {
                    naive_nonzero += 1;
                }
            }
        }
    }
    println!("naive incircle non-zero on {naive_nonzero} of {tested} cocircular 4-tuples");
    assert!(naive_nonzero > 0);
}

// ---------------------------------------------------------------------------------------------
// Exact predicates against integer arithmetic, and invariances
// ---------------------------------------------------------------------------------------------

fn small_i3(r: i64) -> impl Strategy<Value = I3> {
    proptest::array::uniform3(-r..=r)
}

fn small_i2(r: i64) -> impl Strategy<Value = I2> {
    proptest::array::uniform2(-r..=r)
}

fn coord_range() -> impl Strategy<Value = i64> {
    prop_oneof![Just(2i64), Just(4), Just(1000), Just(1 << 20)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn orient3d_matches_integers(
        (a, b, c, d) in coord_range().prop_flat_map(|r| (small_i3(r), small_i3(r), small_i3(r), small_i3(r)))
    ) {
        prop_assert_eq!(orient3d(f3(a), f3(b), f3(c), f3(d)), exact_orient3d(a, b, c, d));
    }

    #[test]
    fn insphere_matches_integers(
        (a, b, c, d, e) in coord_range().prop_flat_map(|r| {
            (small_i3(r), small_i3(r), small_i3(r), small_i3(r), small_i3(r))
        })
    ) {
        prop_assert_eq!(
            insphere(f3(a), f3(b), f3(c), f3(d), f3(e)),
            exact_insphere(a, b, c, d, e)
        );
    }

    #[test]
    fn orient2d_incircle_match_integers(
        (a, b, c, d) in coord_range().prop_flat_map(|r| (small_i2(r), small_i2(r), small_i2(r), small_i2(r)))
    ) {
        prop_assert_eq!(orient2d(f2(a), f2(b), f2(c)), exact_orient2d(a, b, c));
        prop_assert_eq!(incircle(f2(a), f2(b), f2(c), f2(d)), exact_incircle(a, b, c, d));
    }

    /// Translating by an exactly representable offset (the sums stay exact) and scaling by a
    /// power of two change no sign.
    #[test]
    fn translation_and_scale_invariance(
        p in proptest::array::uniform5(small_i3(50)),
        t in exact_offsets(),
        k in -20i32..30,
    ) {
        let s = 2f64.powi(k);
        let q = p.map(|x| place3(x, s, t));
        let o = p.map(f3);
        prop_assert_eq!(orient3d(q[0], q[1], q[2], q[3]), orient3d(o[0], o[1], o[2], o[3]));
        prop_assert_eq!(
            insphere(q[0], q[1], q[2], q[3], q[4]),
            insphere(o[0], o[1], o[2], o[3], o[4])
        );
        let (q2, o2) = (q.map(|x| [x[0], x[1]]), o.map(|x| [x[0], x[1]]));
        prop_assert_eq!(orient2d(q2[0], q2[1], q2[2]), orient2d(o2[0], o2[1], o2[2]));
        prop_assert_eq!(
            incircle(q2[0], q2[1], q2[2], q2[3]),
            incircle(o2[0], o2[1], o2[2], o2[3])
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Simulation of Simplicity
// ---------------------------------------------------------------------------------------------

/// Sign of the permutation `perm` of `0..n`.
fn perm_is_even(perm: &[usize]) -> bool {
    let mut inv = 0;
    for i in 0..perm.len() {
        for j in i + 1..perm.len() {
            if perm[i] > perm[j] {
                inv += 1;
            }
        }
    }
    inv % 2 == 0
}

fn permutations(n: usize) -> Vec<Vec<usize>> {
    if n == 0 {
        return vec![vec![]];
    }
    let mut out = Vec::new();
    for p in permutations(n - 1) {
        for pos in 0..n {
            let mut q = p.clone();
            q.insert(pos, n - 1);
            out.push(q);
        }
    }
    out
}

/// Cospherical lattice points (possibly translated and scaled) with distinct ids.
fn cospherical_five() -> impl Strategy<Value = ([P3; 5], [u32; 5])> {
    (
        0usize..RADII2.len(),
        any::<u64>(),
        exact_offsets(),
        -8i32..8,
        Just(()).prop_perturb(|_, mut rng| {
            let mut ids = [0u32; 5];
            for (i, id) in ids.iter_mut().enumerate() {
                *id = rng.next_u32() % 1000 * 5 + i as u32;
            }
            ids
        }),
    )
        .prop_map(|(ri, seed, t, k, ids)| {
            let pts = sphere_points(RADII2[ri]);
            let idx = Lcg(seed).distinct::<5>(pts.len());
            (idx.map(|i| place3(pts[i], 2f64.powi(k), t)), ids)
        })
}

fn cocircular_four() -> impl Strategy<Value = ([P2; 4], [u32; 4])> {
    (
        prop_oneof![Just(25i64), Just(50), Just(65), Just(2)],
        any::<u64>(),
        exact_offsets(),
        -8i32..8,
        Just(()).prop_perturb(|_, mut rng| {
            let mut ids = [0u32; 4];
            for (i, id) in ids.iter_mut().enumerate() {
                *id = rng.next_u32() % 1000 * 4 + i as u32;
            }
            ids
        }),
    )
        .prop_map(|(r2, seed, t, k, ids)| {
            let pts = circle_points(r2);
            let idx = Lcg(seed).distinct::<4>(pts.len());
            let s = 2f64.powi(k);
            (
                idx.map(|i| [pts[i][0] as f64 * s + t[0], pts[i][1] as f64 * s + t[1]]),
                ids,
            )
        })
}

fn coplanar5(p: &[P3; 5]) -> bool {
    (0..5).all(|k| {
        let r: Vec<P3> = (0..5).filter(|&i| i != k).map(|i| p[i]).collect();
        orient3d(r[0], r[1], r[2], r[3]) == Sign::Zero
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// The perturbed in-sphere determinant is alternating in its five points (ids travel with
    /// the points): an even permutation keeps the sign, an odd one flips it; never zero unless
    /// all five are coplanar; equal to `insphere` when that is non-zero.
    #[test]
    fn insphere_sos_is_an_alternating_perturbed_determinant((p, ids) in cospherical_five()) {
        let s = insphere_sos(p, ids);
        prop_assert_eq!(s == Sign::Zero, coplanar5(&p));
        for perm in permutations(5) {
            let q = [0, 1, 2, 3, 4].map(|i| p[perm[i]]);
            let qi = [0, 1, 2, 3, 4].map(|i| ids[perm[i]]);
            let want = s.times(perm_is_even(&perm));
            prop_assert_eq!(insphere_sos(q, qi), want, "perm {:?}", perm);
        }
    }

    /// Two tets `abcd` and `bace` on the shared face `abc`, both positively oriented, with all
    /// five points cospherical: both in-sphere tests agree on whether the face is locally
    /// Delaunay; after the 2→3 flip (three tets around `de`, when `de` crosses `abc`) every
    /// new face gets the opposite verdict, so exactly one configuration is Delaunay.
    #[test]
    fn insphere_sos_two_tets_agree((p, ids) in cospherical_five()) {
        // Pick a triangle abc with the other two points strictly on opposite sides (exists
        // unless all five are on one circle).
        let split = permutations(5).into_iter().find(|q| {
            let o = |i: usize| orient3d(p[q[0]], p[q[1]], p[q[2]], p[q[i]]);
            o(3) != Sign::Zero && o(4) == o(3).flip()
        });
        prop_assume!(split.is_some());
        let q = split.unwrap();
        let [mut a, mut b, c, d, e] = [0, 1, 2, 3, 4].map(|i| p[q[i]]);
        let [mut ia, mut ib, ic, id, ie] = [0, 1, 2, 3, 4].map(|i| ids[q[i]]);
        let od = orient3d(a, b, c, d);
        if od == Sign::Negative {
            std::mem::swap(&mut a, &mut b);
            std::mem::swap(&mut ia, &mut ib);
        }
        prop_assert_eq!(orient3d(a, b, c, d), Sign::Positive);
        prop_assert_eq!(orient3d(b, a, c, e), Sign::Positive);
        let s1 = insphere_sos([a, b, c, d, e], [ia, ib, ic, id, ie]);
        let s2 = insphere_sos([b, a, c, e, d], [ib, ia, ic, ie, id]);
        prop_assert_ne!(s1, Sign::Zero);
        prop_assert_eq!(s1, s2);
        // The three tets around de, if de crosses the triangle abc.
        let around = [(a, ia, b, ib, c, ic), (b, ib, c, ic, a, ia), (c, ic, a, ia, b, ib)];
        let o: Vec<Sign> = around.iter().map(|&(x, _, y, _, _, _)| orient3d(d, e, x, y)).collect();
        if o[0] != Sign::Zero && o.iter().all(|&s| s == o[0]) {
            for &(x, ix, y, iy, z, iz) in &around {
                let (mut x, mut ix, mut y, mut iy) = (x, ix, y, iy);
                if orient3d(d, e, x, y) == Sign::Negative {
                    std::mem::swap(&mut x, &mut y);
                    std::mem::swap(&mut ix, &mut iy);
                }
                prop_assert_eq!(insphere_sos([d, e, x, y, z], [id, ie, ix, iy, iz]), s1.flip());
            }
        }
    }

    #[test]
    fn incircle_sos_is_an_alternating_perturbed_determinant((p, ids) in cocircular_four()) {
        let s = incircle_sos(p, ids);
        let collinear = (0..4).all(|k| {
            let r: Vec<P2> = (0..4).filter(|&i| i != k).map(|i| p[i]).collect();
            orient2d(r[0], r[1], r[2]) == Sign::Zero
        });
        prop_assert_eq!(s == Sign::Zero, collinear);
        for perm in permutations(4) {
            let q = [0, 1, 2, 3].map(|i| p[perm[i]]);
            let qi = [0, 1, 2, 3].map(|i| ids[perm[i]]);
            prop_assert_eq!(incircle_sos(q, qi), s.times(perm_is_even(&perm)));
        }
    }

    /// Two triangles `abc` and `bad` on the shared edge `ab`, both counter-clockwise, all four
    /// points cocircular: both tests agree, and the other diagonal gets the opposite verdict.
    #[test]
    fn incircle_sos_two_triangles_agree((p, ids) in cocircular_four()) {
        // The diagonal pair: c and d strictly on opposite sides of ab.
        let q = permutations(4)
            .into_iter()
            .find(|q| {
                let o = |i: usize| orient2d(p[q[0]], p[q[1]], p[q[i]]);
                o(2) != Sign::Zero && o(3) == o(2).flip()
            })
            .expect("four distinct cocircular points are in convex position");
        let [mut a, mut b, c, d] = [0, 1, 2, 3].map(|i| p[q[i]]);
        let [mut ia, mut ib, ic, id] = [0, 1, 2, 3].map(|i| ids[q[i]]);
        let oc = orient2d(a, b, c);
        if oc == Sign::Negative {
            std::mem::swap(&mut a, &mut b);
            std::mem::swap(&mut ia, &mut ib);
        }
        let s1 = incircle_sos([a, b, c, d], [ia, ib, ic, id]);
        let s2 = incircle_sos([b, a, d, c], [ib, ia, id, ic]);
        prop_assert_ne!(s1, Sign::Zero);
        prop_assert_eq!(s1, s2);
        // Counter-clockwise quad a, d, b, c; the other diagonal dc.
        prop_assert_eq!(orient2d(d, b, c), Sign::Positive);
        prop_assert_eq!(incircle_sos([d, b, c, a], [id, ib, ic, ia]), s1.flip());
        prop_assert_eq!(incircle_sos([c, a, d, b], [ic, ia, id, ib]), s1.flip());
    }

    /// For points in general position the SoS versions are the plain ones.
    #[test]
    fn sos_equals_plain_when_nonzero(p in proptest::array::uniform5(small_i3(1000))) {
        let q = p.map(f3);
        let s = insphere(q[0], q[1], q[2], q[3], q[4]);
        if s != Sign::Zero {
            prop_assert_eq!(insphere_sos(q, [4, 3, 2, 1, 0]), s);
        }
        let q2 = q.map(|x| [x[0], x[1]]);
        let s = incircle(q2[0], q2[1], q2[2], q2[3]);
        if s != Sign::Zero {
            prop_assert_eq!(incircle_sos([q2[0], q2[1], q2[2], q2[3]], [0, 1, 2, 3]), s);
        }
    }
}
