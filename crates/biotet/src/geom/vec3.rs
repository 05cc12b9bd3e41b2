//! Small `[f64; 3]` helpers. Floating point here measures (lengths, angles, volumes); it never
//! decides topology — that is [`super::predicates`]' job.

/// `a - b`.
#[inline]
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a + b`.
#[inline]
pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `s * a`.
#[inline]
pub fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Dot product.
#[inline]
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
#[inline]
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean length.
#[inline]
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Squared Euclidean length.
#[inline]
pub fn norm2(a: [f64; 3]) -> f64 {
    dot(a, a)
}

/// Six times the signed volume of the tet `abcd` (positive for a positively oriented tet).
/// A measure only: use [`super::predicates::orient3d`] for the sign.
#[inline]
pub fn volume6(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    dot(sub(b, a), cross(sub(c, a), sub(d, a)))
}

/// The determinant of a 3×3 matrix given by rows (cofactor expansion along the first row). A
/// measure only.
#[inline]
pub fn det3(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// The axis-aligned box `(lo, hi)` of any number of points; `lo` above `hi` (infinite) when
/// there are none.
pub fn points_bbox<'a>(pts: impl IntoIterator<Item = &'a [f64; 3]>) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in pts {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// The axis-aligned box `(lo, hi)` of `N` points (a triangle's or a tet's corners): exact, as
/// min and max are; callers cull with it before exact tests.
#[inline]
pub fn bbox<const N: usize>(c: &[[f64; 3]; N]) -> ([f64; 3], [f64; 3]) {
    points_bbox(c)
}
