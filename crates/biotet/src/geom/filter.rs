//! Semi-static floating-point filters in front of the exact predicates of
//! [`super::predicates`], for hot loops (the Delaunay kernel).
//!
//! Each filter evaluates the determinant once in plain `f64` with the same formula as
//! Shewchuk's first adaptive stage, and compares it with an a-priori error bound built from the
//! largest coordinate differences per axis (a few `max` operations instead of the full
//! permanent). When the sign is certain it is returned; otherwise the filter answers `None` and
//! the caller goes to the exact predicate. The bounds are derived from Shewchuk's stage-A bounds
//! (`(7 + 56u)u · permanent` for orient3d, `(16 + 224u)u · permanent` for insphere, u = 2⁻⁵³),
//! with the permanent bounded by the per-axis maxima:
//!
//! - orient3d: permanent ≤ 6·mx·my·mz, so |error| ≤ 42u(1 + O(u))·mx·my·mz < 4.7e-15·mx·my·mz;
//! - insphere: permanent ≤ 4·(mx² + my² + mz²)·6·mx·my·mz, so |error| ≤ 384u(1 + O(u))·S·mx·my·mz
//!   < 4.3e-14·S·mx·my·mz with S = mx² + my² + mz².
//!
//! The bounds assume no overflow or underflow, so the filters only answer when every per-axis
//! maximum lies in a safe range (otherwise `None`). Signs follow biotet's conventions (see
//! [`super::predicates`]). The wrappers [`orient3d`] and [`insphere`] fall back to the exact
//! predicates and so give exactly the same answers as [`super::predicates::orient3d`] and
//! [`super::predicates::insphere`].

use super::predicates::{self, Sign};

/// `max` that compiles to one instruction (no NaN handling: inputs here are never NaN, and a NaN
/// would only make the filter answer `None` through the range checks).
#[inline(always)]
fn mx(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// `min`, like [`mx`].
#[inline(always)]
fn mn(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

/// Error-bound factor of the orient3d filter (see the module docs).
const O3D_BOUND: f64 = 4.7e-15;
/// Error-bound factor of the insphere filter (see the module docs).
const INS_BOUND: f64 = 4.3e-14;
/// Safe range of the per-axis maxima for orient3d (products of three stay normal and finite).
const O3D_LO: f64 = 1e-90;
const O3D_HI: f64 = 1e90;
/// Safe range of the per-axis maxima for insphere (products of five stay normal and finite).
const INS_LO: f64 = 1e-55;
const INS_HI: f64 = 1e55;

/// Filtered sign of the signed volume of `abcd` (biotet's orient3d convention), or `None` when
/// the floating-point evaluation cannot decide it. `Some(Sign::Zero)` is returned only when the
/// four points share a coordinate value on some axis (an exact zero).
#[inline(always)]
pub fn orient3d_filter(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Option<Sign> {
    let adx = a[0] - d[0];
    let bdx = b[0] - d[0];
    let cdx = c[0] - d[0];
    let ady = a[1] - d[1];
    let bdy = b[1] - d[1];
    let cdy = c[1] - d[1];
    let adz = a[2] - d[2];
    let bdz = b[2] - d[2];
    let cdz = c[2] - d[2];
    // Shewchuk's det[a-d, b-d, c-d], the negative of biotet's orientation.
    let det = adz * (bdx * cdy - cdx * bdy)
        + bdz * (cdx * ady - adx * cdy)
        + cdz * (adx * bdy - bdx * ady);
    let x = mx(mx(adx.abs(), bdx.abs()), cdx.abs());
    let y = mx(mx(ady.abs(), bdy.abs()), cdy.abs());
    let z = mx(mx(adz.abs(), bdz.abs()), cdz.abs());
    let lo = mn(mn(x, y), z);
    let hi = mx(mx(x, y), z);
    if lo == 0.0 {
        // A whole column of the determinant is exactly zero.
        return Some(Sign::Zero);
    }
    if !(lo >= O3D_LO && hi <= O3D_HI) {
        return None;
    }
    let eb = O3D_BOUND * (x * y * z);
    if det > eb {
        Some(Sign::Negative)
    } else if det < -eb {
        Some(Sign::Positive)
    } else {
        None
    }
}

/// Filtered in-sphere sign (biotet's convention: positive when `e` is strictly inside the sphere
/// through the positively oriented `abcd`), or `None` when the floating-point evaluation cannot
/// decide it.
#[inline(always)]
pub fn insphere_filter(
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
    d: [f64; 3],
    e: [f64; 3],
) -> Option<Sign> {
    let aex = a[0] - e[0];
    let bex = b[0] - e[0];
    let cex = c[0] - e[0];
    let dex = d[0] - e[0];
    let aey = a[1] - e[1];
    let bey = b[1] - e[1];
    let cey = c[1] - e[1];
    let dey = d[1] - e[1];
    let aez = a[2] - e[2];
    let bez = b[2] - e[2];
    let cez = c[2] - e[2];
    let dez = d[2] - e[2];

    let ab = aex * bey - bex * aey;
    let bc = bex * cey - cex * bey;
    let cd = cex * dey - dex * cey;
    let da = dex * aey - aex * dey;
    let ac = aex * cey - cex * aey;
    let bd = bex * dey - dex * bey;

    let abc = aez * bc - bez * ac + cez * ab;
    let bcd = bez * cd - cez * bd + dez * bc;
    let cda = cez * da + dez * ac + aez * cd;
    let dab = dez * ab + aez * bd + bez * da;

    let alift = aex * aex + aey * aey + aez * aez;
    let blift = bex * bex + bey * bey + bez * bez;
    let clift = cex * cex + cey * cey + cez * cez;
    let dlift = dex * dex + dey * dey + dez * dez;

    // Shewchuk's insphere: positive when e is inside for his (our negative) orientation.
    let det = (dlift * abc - clift * dab) + (blift * cda - alift * bcd);

    let x = mx(mx(aex.abs(), bex.abs()), mx(cex.abs(), dex.abs()));
    let y = mx(mx(aey.abs(), bey.abs()), mx(cey.abs(), dey.abs()));
    let z = mx(mx(aez.abs(), bez.abs()), mx(cez.abs(), dez.abs()));
    let lo = mn(mn(x, y), z);
    let hi = mx(mx(x, y), z);
    if !(lo >= INS_LO && hi <= INS_HI) {
        return None;
    }
    let eb = INS_BOUND * ((x * x + y * y + z * z) * (x * y * z));
    if det > eb {
        Some(Sign::Negative)
    } else if det < -eb {
        Some(Sign::Positive)
    } else {
        None
    }
}

/// [`super::predicates::orient3d`] with the filter in front: the same exact answer, faster.
#[inline]
pub fn orient3d(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Sign {
    match orient3d_filter(a, b, c, d) {
        Some(s) => s,
        None => predicates::orient3d(a, b, c, d),
    }
}

/// [`super::predicates::insphere`] with the filter in front: the same exact answer, faster.
#[inline]
pub fn insphere(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3], e: [f64; 3]) -> Sign {
    match insphere_filter(a, b, c, d, e) {
        Some(s) => s,
        None => predicates::insphere(a, b, c, d, e),
    }
}

/// [`super::predicates::insphere_sos`] with the filter in front: the same answer, faster when the
/// five points are far from cospherical.
#[inline]
pub fn insphere_sos(p: [[f64; 3]; 5], ids: [u32; 5]) -> Sign {
    match insphere_filter(p[0], p[1], p[2], p[3], p[4]) {
        Some(s) => s,
        None => predicates::insphere_sos(p, ids),
    }
}
