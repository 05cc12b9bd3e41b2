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
//! [`super::predicates`]).
//!
//! A second stage, [`orient3d_grid`] / [`insphere_grid`], decides lattice-like inputs exactly
//! without expansion arithmetic: when all coordinate differences are exact and, scaled by a
//! power of two, small integers, the same formula evaluated in `f64` makes no rounding error at
//! all. Only then does the adaptive exact predicate run. The wrappers [`orient3d`],
//! [`insphere`] and [`insphere_sos`] chain the stages and give exactly the same answers as
//! [`super::predicates::orient3d`], [`super::predicates::insphere`] and
//! [`super::predicates::insphere_sos`].

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

/// `a - b` when the subtraction is exact, `None` when it rounds (Knuth's two-difference: the
/// rounding error is computed exactly and must be zero).
#[inline(always)]
fn exact_diff(a: f64, b: f64) -> Option<f64> {
    let x = a - b;
    let bvirt = a - x;
    let avirt = x + bvirt;
    let bround = bvirt - b;
    let around = a - avirt;
    if around + bround == 0.0 { Some(x) } else { None }
}

/// The power of two `s` with `hi · s` in `[2^top, 2^(top+1))`, for `hi > 0` normal.
#[inline(always)]
fn grid_scale(hi: f64, top: i64) -> Option<f64> {
    let e = ((hi.to_bits() >> 52) & 0x7ff) as i64; // biased exponent of hi
    let se = 1023 + top - (e - 1023); // biased exponent of s
    if e == 0 || !(1..=2046).contains(&se) {
        return None;
    }
    Some(f64::from_bits((se as u64) << 52))
}

/// Scale the differences by `s` (exact: a power of two) and check they are all integers.
#[inline(always)]
fn scaled_integers<const N: usize>(d: [f64; N], s: f64) -> Option<[f64; N]> {
    let t = d.map(|x| x * s);
    // (A non-zero difference that underflows to zero is not an integer either.)
    let ok = t
        .iter()
        .zip(&d)
        .all(|(&x, &y)| f64::from(x as i32) == x && (x != 0.0 || y == 0.0));
    if ok { Some(t) } else { None }
}

/// Exact orient3d for points on a fine grid: when the coordinate differences are exact and, scaled
/// to below 2^16, all integers, the 3×3 determinant of the scaled differences is computed in
/// `f64` without any rounding (every intermediate is an integer below 2^53). `None` otherwise.
/// This decides the exact zeros of lattice-like inputs much faster than the adaptive predicate.
#[inline(never)]
pub fn orient3d_grid(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Option<Sign> {
    let mut g = [0.0; 9];
    for k in 0..3 {
        g[k] = exact_diff(a[k], d[k])?;
        g[3 + k] = exact_diff(b[k], d[k])?;
        g[6 + k] = exact_diff(c[k], d[k])?;
    }
    let hi = g.iter().fold(0.0, |m, &x| mx(m, x.abs()));
    if hi == 0.0 {
        return Some(Sign::Zero);
    }
    let t = scaled_integers(g, grid_scale(hi, 15)?)?;
    let [adx, ady, adz, bdx, bdy, bdz, cdx, cdy, cdz] = t;
    let det = adz * (bdx * cdy - cdx * bdy)
        + bdz * (cdx * ady - adx * cdy)
        + cdz * (adx * bdy - bdx * ady);
    Some(Sign::of(det).flip())
}

/// Exact insphere for points on a fine grid, like [`orient3d_grid`]: differences exact and, scaled
/// to below 2^9, integers (then every intermediate of the 4×4 lifted determinant is an integer
/// below 2^53). `None` otherwise.
#[inline(never)]
pub fn insphere_grid(
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
    d: [f64; 3],
    e: [f64; 3],
) -> Option<Sign> {
    let mut g = [0.0; 12];
    for k in 0..3 {
        g[k] = exact_diff(a[k], e[k])?;
        g[3 + k] = exact_diff(b[k], e[k])?;
        g[6 + k] = exact_diff(c[k], e[k])?;
        g[9 + k] = exact_diff(d[k], e[k])?;
    }
    let hi = g.iter().fold(0.0, |m, &x| mx(m, x.abs()));
    if hi == 0.0 {
        return Some(Sign::Zero);
    }
    let t = scaled_integers(g, grid_scale(hi, 8)?)?;
    let [aex, aey, aez, bex, bey, bez, cex, cey, cez, dex, dey, dez] = t;
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
    let det = (dlift * abc - clift * dab) + (blift * cda - alift * bcd);
    Some(Sign::of(det).flip())
}

/// [`super::predicates::orient3d`] with the filters in front: the same exact answer, faster.
#[inline]
pub fn orient3d(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Sign {
    match orient3d_filter(a, b, c, d) {
        Some(s) => s,
        None => orient3d_slow(a, b, c, d),
    }
}

#[inline(never)]
fn orient3d_slow(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Sign {
    match orient3d_grid(a, b, c, d) {
        Some(s) => s,
        None => predicates::orient3d(a, b, c, d),
    }
}

/// [`super::predicates::insphere`] with the filters in front: the same exact answer, faster.
#[inline]
pub fn insphere(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3], e: [f64; 3]) -> Sign {
    match insphere_filter(a, b, c, d, e) {
        Some(s) => s,
        None => insphere_slow(a, b, c, d, e),
    }
}

#[inline(never)]
fn insphere_slow(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3], e: [f64; 3]) -> Sign {
    match insphere_grid(a, b, c, d, e) {
        Some(s) => s,
        None => predicates::insphere(a, b, c, d, e),
    }
}

/// [`super::predicates::insphere_sos`] with the filters in front: exactly the same answer (the
/// same determinant, then the same cofactors in the same order), faster.
#[inline]
pub fn insphere_sos(p: [[f64; 3]; 5], ids: [u32; 5]) -> Sign {
    match insphere_filter(p[0], p[1], p[2], p[3], p[4]) {
        Some(s) => s,
        None => insphere_sos_slow(p, ids),
    }
}

/// The perturbation part of [`insphere_sos`] (see [`super::predicates::insphere_sos`]).
#[inline(never)]
pub fn insphere_sos_slow(p: [[f64; 3]; 5], ids: [u32; 5]) -> Sign {
    let s = insphere_slow(p[0], p[1], p[2], p[3], p[4]);
    if s != Sign::Zero {
        return s;
    }
    let mut order = [0usize, 1, 2, 3, 4];
    order.sort_unstable_by(|&i, &j| ids[j].cmp(&ids[i]));
    for &k in &order {
        let mut rest = [[0.0; 3]; 4];
        let mut n = 0;
        for (i, q) in p.iter().enumerate() {
            if i != k {
                rest[n] = *q;
                n += 1;
            }
        }
        let o = orient3d(rest[0], rest[1], rest[2], rest[3]);
        if o != Sign::Zero {
            return o.times(k % 2 == 1);
        }
    }
    Sign::Zero
}
