//! Fast paths in front of the exact predicates of [`super::predicates`], for hot loops (the
//! Delaunay kernel). Every function here returns exactly the sign the exact predicate returns;
//! only the cost differs.
//!
//! Three stages, cheapest first:
//!
//! 1. **Semi-static filter** ([`orient3d_filter`], [`insphere_filter`]): the determinant in
//!    plain `f64` with the formula of Shewchuk's first adaptive stage, compared with an a-priori
//!    error bound built from the largest coordinate difference per axis. The bounds come from
//!    Shewchuk's stage-A bounds (`(7 + 56u)u · permanent` for orient3d, `(16 + 224u)u ·
//!    permanent` for insphere, u = 2⁻⁵³) with the permanent bounded by the per-axis maxima
//!    `mx, my, mz`: for orient3d the permanent is at most `6·mx·my·mz`, so the error is below
//!    `42u(1 + O(u))·mx·my·mz < 4.7e-15·mx·my·mz`. For insphere the permanent is
//!    `Σ lift_i · perm3_i` with every lift at most `m = max_i |q_i − e|²` and every 3×3
//!    permanent at most `6·mx·my·mz ≤ 6·m^1.5`, so it is at most `24·m^2.5` and the error is
//!    below `384u(1 + O(u))·m^2.5 < 4.36e-14·m^2.5`; the lifts are computed anyway, and the
//!    comparison is made squared (`det² > 1.9e-27·m⁵`), so the bound costs four
//!    multiplications.
//!    The bounds assume no overflow or underflow, so the filters only answer when the maxima lie
//!    in a safe range.
//! 2. **Grid exactness.** When all coordinates are integer multiples of a common power of two
//!    `2^G` (integer lattices, or any points on a binary grid) and small in those units, the very
//!    same `f64` evaluation makes no rounding error at all: with differences below `2^9·2^G` per
//!    axis every intermediate of the insphere formula is an integer multiple of a power of
//!    `2^G` below `2^53` of it (below `2^16·2^G` for orient3d). A [`Grid`] computed once for a
//!    point set certifies this, and the `*_on` functions then return the sign of the filter's own
//!    determinant — zero included — when the filter is unsure. This makes the massively
//!    degenerate lattice inputs nearly as fast as random ones. [`orient3d_grid`] and
//!    [`insphere_grid`] make the same check locally (exact differences that are small integers
//!    after scaling by a power of two), for inputs without a global grid.
//! 3. The adaptive exact predicates of [`super::predicates`] (Shewchuk's, via `robust`).
//!
//! Signs follow biotet's conventions (see [`super::predicates`]).

use super::predicates::{self, Sign};

/// `max` that compiles to one instruction (no NaN handling: the inputs are never NaN here, and a
/// NaN only makes the filters answer `None` through their range checks).
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
/// Square of the error-bound factor of the insphere filter, `(4.36e-14)²` (see the module docs).
const INS_BOUND2: f64 = 1.9e-27;
/// Safe range of the per-axis maxima for orient3d (products of three stay normal and finite).
const O3D_LO: f64 = 1e-90;
const O3D_HI: f64 = 1e90;
/// Safe range of the largest lift for insphere (products of five differences and the squared
/// bound stay normal and finite).
const INS_LO: f64 = 1e-50;
const INS_HI: f64 = 1e50;

/// A certificate that a point set lies on a binary grid: all coordinates are integer multiples
/// of `2^G` below `2^52·2^G` in magnitude. Then coordinate differences are exact, and a
/// determinant whose per-axis differences stay below [`Grid::insphere_limit`] (insphere) or
/// [`Grid::orient_limit`] (orient3d) is computed exactly in `f64`. [`Grid::NONE`] certifies
/// nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    ins: f64,
    ins2: f64,
    o3d: f64,
    /// Smallest lowest-set-bit exponent and largest magnitude exponent seen (`i32::MAX`,
    /// `i32::MIN` when only zeros were seen); `broken` once some point was off every grid.
    low: i32,
    top: i32,
    broken: bool,
}

/// The binary exponent of the lowest set bit of `c` (`c = odd · 2^low`) and the exponent `top`
/// with `|c| < 2^top`, for `c` finite and non-zero.
fn bit_range(c: f64) -> (i32, i32) {
    let bits = c.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i32;
    let m = bits & ((1u64 << 52) - 1);
    if e == 0 {
        let low = -1074 + m.trailing_zeros() as i32;
        let top = -1074 + (64 - m.leading_zeros() as i32);
        (low, top)
    } else {
        let low = e - 1075 + (m | 1u64 << 52).trailing_zeros() as i32;
        (low, e - 1022)
    }
}

impl Grid {
    /// No certificate: the `*_on` functions behave like the plain ones.
    pub const NONE: Grid = Grid {
        ins: 0.0,
        ins2: 0.0,
        o3d: 0.0,
        low: i32::MAX,
        top: i32::MIN,
        broken: true,
    };

    /// The finest common grid of `points` (all coordinates finite), or [`Grid::NONE`].
    pub fn of(points: &[[f64; 3]]) -> Grid {
        let mut g = Grid {
            broken: false,
            ..Grid::NONE
        };
        for p in points {
            g = g.with(*p);
        }
        g
    }

    /// The certificate for the points certified by `self` and the point `p` as well (never
    /// finer than `self`; `NONE` stays `NONE`).
    pub fn with(self, p: [f64; 3]) -> Grid {
        if self.broken {
            return Grid::NONE;
        }
        let (mut low, mut top) = (self.low, self.top);
        for c in p {
            if c != 0.0 {
                let (l, t) = bit_range(c);
                low = low.min(l);
                top = top.max(t);
            }
        }
        if low == i32::MAX {
            // Only zeros so far: nothing to certify yet, nothing broken.
            return Grid {
                broken: false,
                ..Grid::NONE
            };
        }
        // Coordinates must be integers (in units of 2^low) below 2^52, and intermediates, which
        // are multiples of 2^(5·low) below 2^(53 + 5·low), must stay representable and finite.
        if top > 52 + low || !(-200..=150).contains(&low) {
            return Grid::NONE;
        }
        Grid {
            ins: 2f64.powi(9 + low),
            ins2: 2f64.powi(18 + 2 * low),
            o3d: 2f64.powi(16 + low),
            low,
            top,
            broken: false,
        }
    }

    /// Exclusive bound on the per-axis coordinate differences of an exact insphere evaluation
    /// (0 when nothing is certified).
    pub fn insphere_limit(self) -> f64 {
        self.ins
    }

    /// Exclusive bound on the per-axis coordinate differences of an exact orient3d evaluation
    /// (0 when nothing is certified).
    pub fn orient_limit(self) -> f64 {
        self.o3d
    }
}

/// Filtered sign of the signed volume of `abcd` (biotet's orient3d convention), or `None` when
/// the floating-point evaluation cannot decide it.
#[inline(always)]
pub fn orient3d_filter(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Option<Sign> {
    orient3d_filter_on(a, b, c, d, Grid::NONE)
}

/// [`orient3d_filter`] that also answers exactly (zero included) when the points are certified
/// by `grid` and close enough together.
#[inline(always)]
pub fn orient3d_filter_on(
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
    d: [f64; 3],
    grid: Grid,
) -> Option<Sign> {
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
    if lo >= O3D_LO && hi <= O3D_HI {
        let eb = O3D_BOUND * (x * y * z);
        if det > eb {
            return Some(Sign::Negative);
        } else if det < -eb {
            return Some(Sign::Positive);
        }
    }
    if hi < grid.o3d {
        return Some(Sign::of(det).flip());
    }
    None
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
    insphere_filter_on(a, b, c, d, e, Grid::NONE)
}

/// [`insphere_filter`] that also answers exactly (zero included) when the points are certified
/// by `grid` and close enough together.
#[inline(always)]
pub fn insphere_filter_on(
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
    d: [f64; 3],
    e: [f64; 3],
    grid: Grid,
) -> Option<Sign> {
    let [det, m] = insphere_det(a, b, c, d, e);
    insphere_decide(det, m, grid)
}

/// Whether the first-stage determinant `det` with largest lift `m` (of [`insphere_det`] or
/// [`insphere_det_fma`]) certifies a nonzero sign without any grid: then the sign of
/// [`insphere_filter_on`] is that of `-det`. No branch on the sign itself, so callers can use
/// `det < 0` as data.
#[inline(always)]
pub fn insphere_certified(det: f64, m: f64) -> bool {
    // |error| < INS_BOUND · m^2.5 (see the module docs); compared squared, without a root.
    (INS_LO..=INS_HI).contains(&m) & (det * det > INS_BOUND2 * ((m * m) * (m * m) * m))
}

/// The sign [`insphere_filter_on`] certifies from the first-stage determinant `det` and the
/// largest lift `m` of [`insphere_det`] (or `det` of [`insphere_det_fma`]).
#[inline(always)]
pub fn insphere_decide(det: f64, m: f64, grid: Grid) -> Option<Sign> {
    // |error| < INS_BOUND · m^2.5 (see the module docs); compared squared, without a root.
    if (INS_LO..=INS_HI).contains(&m) {
        let eb2 = INS_BOUND2 * ((m * m) * (m * m) * m);
        if det * det > eb2 {
            return Some(if det > 0.0 {
                Sign::Negative
            } else {
                Sign::Positive
            });
        }
    }
    // Every per-axis difference is below √m.
    if m < grid.ins2 {
        return Some(Sign::of(det).flip());
    }
    None
}

/// [`insphere_filter_on`] evaluated with fused multiply-adds: fewer instructions where FMA is in
/// hardware, and never a larger error (each fused operation rounds once where the plain formula
/// rounds twice, so the same bound holds). Only call it from code compiled with the `fma` target
/// feature; elsewhere `mul_add` is a slow library call.
#[inline(always)]
pub fn insphere_filter_fma_on(
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
    d: [f64; 3],
    e: [f64; 3],
    grid: Grid,
) -> Option<Sign> {
    let [det, m] = insphere_det_fma(a, b, c, d, e);
    insphere_decide(det, m, grid)
}

/// [`insphere_det`] with fused multiply-adds (see [`insphere_filter_fma_on`]: only call it from
/// code compiled with the `fma` target feature). The same bound holds for its `det`.
#[inline(always)]
pub fn insphere_det_fma(
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
    d: [f64; 3],
    e: [f64; 3],
) -> [f64; 2] {
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

    let ab = aex.mul_add(bey, -(bex * aey));
    let bc = bex.mul_add(cey, -(cex * bey));
    let cd = cex.mul_add(dey, -(dex * cey));
    let da = dex.mul_add(aey, -(aex * dey));
    let ac = aex.mul_add(cey, -(cex * aey));
    let bd = bex.mul_add(dey, -(dex * bey));

    let abc = aez.mul_add(bc, (-bez).mul_add(ac, cez * ab));
    let bcd = bez.mul_add(cd, (-cez).mul_add(bd, dez * bc));
    let cda = cez.mul_add(da, dez.mul_add(ac, aez * cd));
    let dab = dez.mul_add(ab, aez.mul_add(bd, bez * da));

    let alift = aex.mul_add(aex, aey.mul_add(aey, aez * aez));
    let blift = bex.mul_add(bex, bey.mul_add(bey, bez * bez));
    let clift = cex.mul_add(cex, cey.mul_add(cey, cez * cez));
    let dlift = dex.mul_add(dex, dey.mul_add(dey, dez * dez));

    let det = dlift.mul_add(abc, -(clift * dab)) + blift.mul_add(cda, -(alift * bcd));
    let m = mx(mx(alift, blift), mx(clift, dlift));
    [det, m]
}

/// Shewchuk's first-stage insphere determinant of `abcd` and `e` (positive when `e` is inside
/// for his orientation, our negative one) and the largest lift `m = max |q − e|²`.
///
/// (A two-lane SSE2 version of the same operations was tried: fewer instructions, but slower on
/// a wide out-of-order core, which already runs the scalar formula's independent operations in
/// parallel.)
#[inline(always)]
pub fn insphere_det(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3], e: [f64; 3]) -> [f64; 2] {
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

    let det = (dlift * abc - clift * dab) + (blift * cda - alift * bcd);
    [det, mx(mx(alift, blift), mx(clift, dlift))]
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
    if around + bround == 0.0 {
        Some(x)
    } else {
        None
    }
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

/// Exact orient3d for points on a local grid: when the coordinate differences are exact and,
/// scaled to below 2^16, all integers, the 3×3 determinant of the scaled differences is computed
/// in `f64` without any rounding (every intermediate is an integer below 2^53). `None`
/// otherwise.
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

/// Exact insphere for points on a local grid, like [`orient3d_grid`]: differences exact and,
/// scaled to below 2^9, integers (then every intermediate of the 4×4 lifted determinant is an
/// integer below 2^53). `None` otherwise.
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

/// [`super::predicates::orient3d`], faster: the same exact answer.
#[inline]
pub fn orient3d(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Sign {
    orient3d_on(a, b, c, d, Grid::NONE)
}

/// [`orient3d`] for points certified by `grid`.
#[inline(always)]
pub fn orient3d_on(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3], grid: Grid) -> Sign {
    match orient3d_filter_on(a, b, c, d, grid) {
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

/// [`super::predicates::insphere`], faster: the same exact answer.
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

/// [`super::predicates::insphere_sos`], faster: exactly the same answer (the same determinant,
/// then the same cofactors in the same order).
#[inline]
pub fn insphere_sos(p: [[f64; 3]; 5], ids: [u32; 5]) -> Sign {
    insphere_sos_on(p, ids, Grid::NONE)
}

/// [`insphere_sos`] for points certified by `grid`.
#[inline]
pub fn insphere_sos_on(p: [[f64; 3]; 5], ids: [u32; 5], grid: Grid) -> Sign {
    let s = match insphere_filter_on(p[0], p[1], p[2], p[3], p[4], grid) {
        Some(s) => s,
        None => insphere_slow(p[0], p[1], p[2], p[3], p[4]),
    };
    if s != Sign::Zero {
        return s;
    }
    sos_cofactors(p, ids, grid)
}

/// [`insphere_sos_on`] after its filter failed: the exact determinant, then the perturbation.
#[inline(never)]
pub fn insphere_sos_slow(p: [[f64; 3]; 5], ids: [u32; 5], grid: Grid) -> Sign {
    let s = insphere_slow(p[0], p[1], p[2], p[3], p[4]);
    if s != Sign::Zero {
        return s;
    }
    sos_cofactors(p, ids, grid)
}

/// The perturbation part of [`super::predicates::insphere_sos`] for an exactly cospherical
/// `p`: the first non-zero cofactor of the lifted coordinates, largest id first.
#[inline(never)]
pub fn sos_cofactors(p: [[f64; 3]; 5], ids: [u32; 5], grid: Grid) -> Sign {
    super::predicates::insphere_sos_cofactors(p, ids, |a, b, c, d| orient3d_on(a, b, c, d, grid))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SplitMix64.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }
        fn unit(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 53) as f64
        }
        fn small(&mut self, n: u64) -> f64 {
            (self.next() % n) as f64
        }
    }

    /// Point sets that stress the stages: random, near-degenerate (1-ulp moves of cospherical
    /// points), integer lattices at several offsets and scales, non-representable spacings.
    fn cases(r: &mut Rng, k: usize) -> [[f64; 3]; 5] {
        let mut p = [[0.0; 3]; 5];
        match k % 6 {
            0 => p
                .iter_mut()
                .for_each(|q| *q = [r.unit(), r.unit(), r.unit()]),
            1 => {
                // Small lattice, offset and scaled by powers of two.
                let s = [1.0, 0.5, 4.0, 1.0 / 1024.0][(r.next() % 4) as usize];
                let o = [0.0, 1e6, -3.5, 1e-3][(r.next() % 4) as usize];
                p.iter_mut()
                    .for_each(|q| *q = [r.small(4), r.small(4), r.small(4)].map(|c| o + s * c));
            }
            2 => {
                // Lattice with a non-representable spacing.
                p.iter_mut()
                    .for_each(|q| *q = [r.small(3), r.small(3), r.small(3)].map(|c| 0.1 * c));
            }
            3 => {
                // Cospherical integer points, one nudged by an ulp sometimes.
                let s = [
                    [3.0, 0.0, 0.0],
                    [0.0, 3.0, 0.0],
                    [0.0, 0.0, 3.0],
                    [-3.0, 0.0, 0.0],
                    [2.0, 2.0, 1.0],
                    [2.0, -2.0, 1.0],
                    [-2.0, 1.0, -2.0],
                ];
                for q in &mut p {
                    *q = s[(r.next() % 7) as usize];
                }
                if r.next().is_multiple_of(2) {
                    let i = (r.next() % 5) as usize;
                    p[i][0] = f64::from_bits(p[i][0].to_bits() + 1);
                }
            }
            4 => {
                // Large coordinates, small differences.
                p.iter_mut().for_each(|q| {
                    *q = [r.small(3), r.small(3), r.small(3)].map(|c| 1e15 + c * 0.125)
                });
            }
            _ => {
                // Mixed magnitudes.
                p.iter_mut().for_each(|q| {
                    *q = [r.unit() * 1e-60, r.unit(), r.small(2) * 1e40];
                });
            }
        }
        p
    }

    #[test]
    fn every_stage_agrees_with_the_exact_predicates() {
        let mut r = Rng(1);
        for k in 0..60_000 {
            let p = cases(&mut r, k);
            let grid = Grid::of(&p);
            let ids = [0, 1, 2, 3, 4].map(|_| (r.next() % 1000) as u32);
            let o = predicates::orient3d(p[0], p[1], p[2], p[3]);
            assert_eq!(orient3d(p[0], p[1], p[2], p[3]), o, "{p:?}");
            assert_eq!(orient3d_on(p[0], p[1], p[2], p[3], grid), o, "{p:?}");
            if let Some(s) = orient3d_grid(p[0], p[1], p[2], p[3]) {
                assert_eq!(s, o, "{p:?}");
            }
            if let Some(s) = orient3d_filter(p[0], p[1], p[2], p[3]) {
                assert_eq!(s, o, "{p:?}");
            }
            let i = predicates::insphere(p[0], p[1], p[2], p[3], p[4]);
            assert_eq!(insphere(p[0], p[1], p[2], p[3], p[4]), i, "{p:?}");
            if let Some(s) = insphere_grid(p[0], p[1], p[2], p[3], p[4]) {
                assert_eq!(s, i, "{p:?}");
            }
            if let Some(s) = insphere_filter_on(p[0], p[1], p[2], p[3], p[4], grid) {
                assert_eq!(s, i, "{p:?} grid {grid:?}");
            }
            // (Software fused multiply-add here: slow but exact, so the same answers.)
            if let Some(s) = insphere_filter_fma_on(p[0], p[1], p[2], p[3], p[4], grid) {
                assert_eq!(s, i, "fma {p:?} grid {grid:?}");
            }
            let mut uniq = ids;
            uniq.sort_unstable();
            if uniq.windows(2).all(|w| w[0] != w[1]) {
                let s = predicates::insphere_sos(p, ids);
                assert_eq!(insphere_sos(p, ids), s, "{p:?}");
                assert_eq!(insphere_sos_on(p, ids, grid), s, "{p:?}");
            }
        }
    }

    /// Nearly cospherical and nearly coplanar configurations in bulk, at several scales and
    /// offsets: every answer of every filter is the exact one. (Long; run with `--ignored`.)
    #[test]
    #[ignore]
    fn filters_near_degenerate_stress() {
        let mut r = Rng(77);
        let mut decided = 0u64;
        for k in 0..3_000_000u64 {
            let scale = [1e-3, 1.0, 1e3, 7.5][(k % 4) as usize];
            let off = [0.0, 1.0, -1e3, 0.3][(k / 4 % 4) as usize];
            let c = [r.unit(), r.unit(), r.unit()];
            let rad = 0.1 + r.unit();
            let mut p = [[0.0; 3]; 5];
            for q in &mut p {
                // A point on the sphere (rounded), or near a common plane.
                let (u, v) = (r.unit() * std::f64::consts::TAU, r.unit() * 2.0 - 1.0);
                let w = (1.0 - v * v).sqrt();
                *q = if k % 3 == 0 {
                    [c[0] + r.unit(), c[1] + r.unit(), c[2] + 1e-12 * r.unit()]
                } else {
                    [
                        c[0] + rad * w * u.cos(),
                        c[1] + rad * w * u.sin(),
                        c[2] + rad * v,
                    ]
                };
                *q = q.map(|x| off + scale * x);
            }
            let exact = predicates::insphere(p[0], p[1], p[2], p[3], p[4]);
            for f in [insphere_filter_on, insphere_filter_fma_on] {
                if let Some(s) = f(p[0], p[1], p[2], p[3], p[4], Grid::NONE) {
                    assert_eq!(s, exact, "{p:?}");
                    decided += 1;
                }
            }
            if let Some(s) = orient3d_filter(p[0], p[1], p[2], p[3]) {
                assert_eq!(s, predicates::orient3d(p[0], p[1], p[2], p[3]), "{p:?}");
            }
        }
        assert!(decided > 0);
    }

    #[test]
    fn grid_certificates() {
        assert_eq!(Grid::of(&[[0.5, 3.0, -2.0]]).insphere_limit(), 256.0);
        assert_eq!(Grid::of(&[[1.0, 3.0, 7.0]]).insphere_limit(), 512.0);
        assert_eq!(Grid::of(&[[1.0, 2.0, 4.0]]).orient_limit(), 65536.0);
        // Every double is on some grid: 0.1 is an odd multiple of 2^-55.
        assert_eq!(
            Grid::of(&[[0.1, 0.0, 0.0]]).insphere_limit(),
            2f64.powi(9 - 55)
        );
        assert_eq!(Grid::of(&[[0.1, 1e6, 0.0]]), Grid::NONE);
        assert_eq!(Grid::of(&[[2f64.powi(60), 1.0, 0.0]]), Grid::NONE);
        assert_eq!(Grid::of(&[[0.0; 3]]).insphere_limit(), 0.0);
        assert_eq!(
            Grid::of(&[[0.0; 3], [1.0, 0.0, 0.0]]).insphere_limit(),
            512.0
        );
        let g = Grid::of(&[[1.0, 2.0, 3.0]]);
        assert_eq!(
            g.with([0.25, 0.0, 0.0]),
            Grid::of(&[[1.0, 2.0, 3.0], [0.25, 0.0, 0.0]])
        );
        assert_eq!(g.with([0.25, 0.0, 0.0]).insphere_limit(), 128.0);
        assert_eq!(
            Grid::of(&[[2f64.powi(51), 1.0, 0.0]]).insphere_limit(),
            512.0
        );
        assert_eq!(Grid::of(&[[2f64.powi(52), 1.0, 0.0]]), Grid::NONE);
        assert_eq!(g.with([0.1, 0.0, 0.0]), Grid::NONE);
        assert_eq!(g.with([0.1, 0.0, 0.0]).with([1.0, 0.0, 0.0]), Grid::NONE);
        assert_eq!(g.with([2f64.powi(60), 0.0, 0.0]), Grid::NONE);
    }
}
