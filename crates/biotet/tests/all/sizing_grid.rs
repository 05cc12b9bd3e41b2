//! The regular-grid scalar field: interpolation, clamping, geometry and validation.

use biotet::sizing_grid::{GridError, IDENTITY, ScalarGrid};

/// Sample `f` at the grid points.
fn sample(
    dims: [usize; 3],
    origin: [f64; 3],
    spacing: [f64; 3],
    direction: [[f64; 3]; 3],
    f: impl Fn([f64; 3]) -> f64,
) -> ScalarGrid {
    let mut g = ScalarGrid::new(
        dims,
        origin,
        spacing,
        direction,
        vec![0.0; dims[0] * dims[1] * dims[2]],
    )
    .unwrap();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let w = g.world([i as f64, j as f64, k as f64]);
                g.values[i + dims[0] * (j + dims[1] * k)] = f(w);
            }
        }
    }
    g
}

fn linear(p: [f64; 3]) -> f64 {
    0.5 + 2.0 * p[0] - 3.0 * p[1] + 0.25 * p[2]
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()))
}

/// A rotation by `angle` about the (normalised) axis `u`, as rows.
fn rotation(u: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let n = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let [x, y, z] = u.map(|c| c / n);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

/// Deterministic pseudo-random numbers in [0, 1).
fn rng(seed: &mut u64) -> f64 {
    *seed ^= *seed << 13;
    *seed ^= *seed >> 7;
    *seed ^= *seed << 17;
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

#[test]
fn reproduces_a_linear_field_exactly() {
    let g = sample(
        [5, 4, 3],
        [-1.0, 2.0, 0.5],
        [0.5, 0.25, 2.0],
        IDENTITY,
        linear,
    );
    let [lo, hi] = g.bounds();
    assert_eq!(lo, [-1.0, 2.0, 0.5]);
    assert_eq!(hi, [1.0, 2.75, 4.5]);
    let mut s = 1u64;
    for _ in 0..1000 {
        let p: [f64; 3] = std::array::from_fn(|a| lo[a] + (hi[a] - lo[a]) * rng(&mut s));
        assert!(close(g.value_at(p), linear(p)), "{p:?}");
    }
    // At the samples themselves, and on the far faces (the last cell is used there).
    assert_eq!(g.value_at([-1.0, 2.0, 0.5]), g.get(0, 0, 0));
    assert!(close(g.value_at(hi), g.get(4, 3, 2)));
    assert!(close(g.value_at([1.0, 2.1, 4.5]), linear([1.0, 2.1, 4.5])));
    assert!(close(g.min_value(), linear([-1.0, 2.75, 0.5])));
    assert!(close(g.max_value(), linear([1.0, 2.0, 4.5])));
}

#[test]
fn interpolates_trilinearly_between_samples() {
    // f = x·y·z on the unit cube is exactly trilinear.
    let g = sample([2, 2, 2], [0.0; 3], [1.0; 3], IDENTITY, |p| {
        p[0] * p[1] * p[2]
    });
    assert_eq!(g.value_at([0.5, 0.5, 0.5]), 0.125);
    assert_eq!(g.value_at([0.25, 1.0, 0.5]), 0.125);
    assert_eq!(g.value_at([1.0, 1.0, 1.0]), 1.0);
}

#[test]
fn clamps_outside_the_grid() {
    let g = sample([3, 3, 3], [0.0; 3], [1.0; 3], IDENTITY, linear);
    // Beyond a face: the value at the projection onto it.
    assert!(close(g.value_at([-5.0, 1.5, 0.5]), linear([0.0, 1.5, 0.5])));
    assert!(close(
        g.value_at([1.25, 9.0, 0.5]),
        linear([1.25, 2.0, 0.5])
    ));
    assert!(close(
        g.value_at([1.25, 0.5, -1e300]),
        linear([1.25, 0.5, 0.0])
    ));
    // Beyond a corner: the corner's value.
    assert_eq!(g.value_at([-1.0, -1.0, -1.0]), g.get(0, 0, 0));
    assert_eq!(g.value_at([10.0, 10.0, 10.0]), g.get(2, 2, 2));
    assert_eq!(g.value_at([10.0, -10.0, 10.0]), g.get(2, 0, 2));
    // Never outside the sample range, wherever the point is.
    let mut s = 7u64;
    for _ in 0..1000 {
        let p: [f64; 3] = std::array::from_fn(|_| 20.0 * rng(&mut s) - 10.0);
        let v = g.value_at(p);
        assert!(v >= g.min_value() - 1e-12 && v <= g.max_value() + 1e-12);
    }
    assert!(g.value_at([f64::NAN, 0.0, 0.0]).is_nan());
    // Infinite coordinates do not panic.
    let _ = g.value_at([f64::INFINITY, f64::NEG_INFINITY, 0.0]);
}

#[test]
fn rotated_direction_matrix() {
    let r = rotation([1.0, 2.0, -0.5], 0.7);
    let origin = [3.0, -1.0, 2.0];
    let spacing = [0.5, 1.5, 0.75];
    let g = sample([6, 4, 5], origin, spacing, r, linear);
    // world() follows the definition: origin + R · (spacing ∘ ijk).
    let w = g.world([1.0, 2.0, 3.0]);
    for a in 0..3 {
        let expected = origin[a] + r[a][0] * 0.5 + r[a][1] * 3.0 + r[a][2] * 2.25;
        assert!(close(w[a], expected));
    }
    let back = g.index_of(w);
    for (b, e) in back.iter().zip([1.0, 2.0, 3.0]) {
        assert!((b - e).abs() < 1e-12);
    }
    // Exact for a linear field anywhere inside the (rotated) grid.
    let mut s = 3u64;
    for _ in 0..1000 {
        let ijk: [f64; 3] = std::array::from_fn(|a| (g.dims[a] - 1) as f64 * rng(&mut s));
        let p = g.world(ijk);
        assert!(close(g.value_at(p), linear(p)), "{ijk:?}");
    }
    // Clamping is along the grid's axes: stepping outside along grid axis 0 from a point on
    // the face i = 0 keeps the face's value.
    let on_face = g.world([0.0, 1.3, 2.6]);
    let outside = g.world([-4.0, 1.3, 2.6]);
    assert!(close(g.value_at(outside), g.value_at(on_face)));
    assert!(close(g.value_at(outside), linear(on_face)));
    // The bounding box holds every corner and is touched by some.
    let [lo, hi] = g.bounds();
    for c in 0..8 {
        let ijk: [f64; 3] = std::array::from_fn(|a| {
            if c >> a & 1 == 1 {
                (g.dims[a] - 1) as f64
            } else {
                0.0
            }
        });
        let p = g.world(ijk);
        for a in 0..3 {
            assert!(lo[a] <= p[a] && p[a] <= hi[a]);
        }
    }
}

#[test]
fn single_sample_axes() {
    // A slab: one sample along z, so constant along z everywhere.
    let g = sample([3, 2, 1], [0.0, 0.0, 5.0], [1.0, 1.0, 1.0], IDENTITY, |p| {
        p[0] + 10.0 * p[1]
    });
    assert_eq!(g.bounds(), [[0.0, 0.0, 5.0], [2.0, 1.0, 5.0]]);
    for z in [-100.0, 0.0, 5.0, 5.5, 100.0] {
        assert!(close(g.value_at([1.5, 0.25, z]), 1.5 + 2.5));
    }
    // A single sample: constant everywhere.
    let g = ScalarGrid::axis_aligned([1, 1, 1], [1.0; 3], [2.0; 3], vec![0.3]).unwrap();
    assert_eq!(g.value_at([0.0; 3]), 0.3);
    assert_eq!(g.value_at([1e9, -1e9, 7.0]), 0.3);
    assert_eq!(g.bounds(), [[1.0; 3], [1.0; 3]]);
    assert_eq!((g.min_value(), g.max_value()), (0.3, 0.3));
    // A line along y.
    let g = ScalarGrid::axis_aligned([1, 3, 1], [0.0; 3], [1.0; 3], vec![1.0, 2.0, 4.0]).unwrap();
    assert_eq!(g.value_at([5.0, 1.5, -5.0]), 3.0);
    assert_eq!(g.value_at([5.0, 7.0, -5.0]), 4.0);
}

#[test]
fn validation_errors() {
    let ok = |n: usize| vec![1.0; n];
    let e = |r: Result<ScalarGrid, GridError>| r.unwrap_err();
    assert_eq!(
        e(ScalarGrid::axis_aligned(
            [2, 0, 2],
            [0.0; 3],
            [1.0; 3],
            ok(0)
        )),
        GridError::EmptyAxis {
            dims: [2, 0, 2],
            axis: 1
        }
    );
    assert!(matches!(
        e(ScalarGrid::axis_aligned(
            [usize::MAX, 2, 2],
            [0.0; 3],
            [1.0; 3],
            ok(1)
        )),
        GridError::TooLarge { .. }
    ));
    let err = e(ScalarGrid::axis_aligned(
        [10, 10, 10],
        [0.0; 3],
        [1.0; 3],
        ok(100),
    ));
    assert_eq!(
        err,
        GridError::ValueCount {
            dims: [10, 10, 10],
            expected: 1000,
            got: 100
        }
    );
    assert_eq!(
        err.to_string(),
        "100 values for a 10×10×10 grid, expected 1000"
    );
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            e(ScalarGrid::axis_aligned(
                [2, 2, 2],
                [0.0; 3],
                [1.0, 1.0, bad],
                ok(8)
            )),
            GridError::BadSpacing { axis: 2, .. }
        ));
    }
    assert!(matches!(
        e(ScalarGrid::axis_aligned(
            [2, 2, 2],
            [0.0, f64::NAN, 0.0],
            [1.0; 3],
            ok(8)
        )),
        GridError::NonFiniteOrigin(_)
    ));
    let mut d = IDENTITY;
    d[1][2] = f64::INFINITY;
    assert!(matches!(
        e(ScalarGrid::new([2, 2, 2], [0.0; 3], [1.0; 3], d, ok(8))),
        GridError::NonFiniteDirection(_)
    ));
    for d in [
        [[1.0, 1.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        [[1.0, 1.0, 0.0], [0.0, 1e-12, 0.0], [0.0, 0.0, 1.0]],
    ] {
        assert!(matches!(
            e(ScalarGrid::new([2, 2, 2], [0.0; 3], [1.0; 3], d, ok(8))),
            GridError::SingularDirection(_)
        ));
    }
    // Tiny but well-conditioned: fine (the test is scale-free).
    let tiny = IDENTITY.map(|r| r.map(|x| x * 1e-20));
    assert!(ScalarGrid::new([2, 2, 2], [0.0; 3], [1.0; 3], tiny, ok(8)).is_ok());
    assert_eq!(
        e(ScalarGrid::axis_aligned(
            [2, 2, 2],
            [1e308, 0.0, 0.0],
            [1e308, 1.0, 1.0],
            ok(8)
        )),
        GridError::NonFiniteExtent
    );
    let mut v = ok(24);
    v[18] = f64::NAN; // (i, j, k) = (2, 1, 1): 2 + 4·(1 + 3·1)
    let err = e(ScalarGrid::axis_aligned([4, 3, 2], [0.0; 3], [1.0; 3], v));
    assert!(
        matches!(
            err,
            GridError::NonFiniteValue {
                index: 18,
                ijk: [2, 1, 1],
                ..
            }
        ),
        "{err:?}"
    );
}
