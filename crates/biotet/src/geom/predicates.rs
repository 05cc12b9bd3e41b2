//! Exact geometric predicates — the one place in biotet that decides signs.
//!
//! The adaptive-precision determinants come from the `robust` crate (Shewchuk's predicates);
//! this module fixes biotet's sign conventions on top of them and adds Simulation of Simplicity
//! (SoS) versions of the in-sphere and in-circle tests, so that exactly cospherical or
//! cocircular inputs (lattice points, by design) always get one consistent, non-zero answer.
//!
//! Conventions (right-handed, unlike Shewchuk's orient3d):
//! - [`orient3d`]`(a, b, c, d)` is the sign of `det[b-a, c-a, d-a]`, i.e. of the signed volume
//!   of the tet `abcd`; positive when `d` is on the side the normal of the counter-clockwise
//!   triangle `abc` points to.
//! - [`orient2d`]`(a, b, c)` is positive when `abc` turns counter-clockwise.
//! - [`insphere`]`(a, b, c, d, e)` is positive when `e` is strictly inside the sphere through
//!   `abcd` and `abcd` is positively oriented (the sign flips with the orientation).
//! - [`incircle`]`(a, b, c, d)` is positive when `d` is strictly inside the circle through `abc`
//!   and `abc` is counter-clockwise.

use robust::{Coord, Coord3D};

/// Largest coordinate magnitude for which the predicates stay exact: the degree-5 products of
/// in-sphere cannot overflow.
pub const MAX_COORDINATE: f64 = 1e50;

/// Smallest non-zero coordinate magnitude for which the predicates stay exact, 2⁻¹⁵⁰ (about
/// 7.0e-46): every coordinate (and coordinate difference) is then a multiple of 2⁻²⁰², so the
/// degree-5 products of the exact stages are multiples of 2⁻¹⁰¹⁰, never below the smallest normal
/// double 2⁻¹⁰²² (the adaptive predicates are exact only without underflow). CAD kernels write
/// zeros as noise of 1e-32 or so (OpenCASCADE through gmsh: -7.7e-34); such files are meshed as
/// they are, not refused.
pub const MIN_COORDINATE: f64 = 7.006_492_321_624_085e-46;

/// True when `c` is 0 or its magnitude lies in [[`MIN_COORDINATE`], [`MAX_COORDINATE`]]: the range
/// in which every predicate of this module is exact.
#[inline]
pub fn in_exact_range(c: f64) -> bool {
    c == 0.0 || (MIN_COORDINATE..=MAX_COORDINATE).contains(&c.abs())
}

/// The sign of a determinant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Sign {
    /// Strictly negative.
    Negative = -1,
    /// Exactly zero.
    Zero = 0,
    /// Strictly positive.
    Positive = 1,
}

impl Sign {
    /// The sign of an `f64` (the exact value computed by an adaptive predicate).
    #[inline]
    pub fn of(x: f64) -> Sign {
        if x > 0.0 {
            Sign::Positive
        } else if x < 0.0 {
            Sign::Negative
        } else {
            Sign::Zero
        }
    }

    /// The opposite sign.
    #[inline]
    #[must_use]
    pub fn flip(self) -> Sign {
        match self {
            Sign::Negative => Sign::Positive,
            Sign::Zero => Sign::Zero,
            Sign::Positive => Sign::Negative,
        }
    }

    /// `self` if `positive`, otherwise the opposite sign.
    #[inline]
    #[must_use]
    pub fn times(self, positive: bool) -> Sign {
        if positive { self } else { self.flip() }
    }

    /// -1, 0 or 1.
    #[inline]
    pub fn as_i32(self) -> i32 {
        self as i32
    }
}

#[inline]
fn c3(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

#[inline]
fn c2(p: [f64; 2]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}

/// Exact sign of the signed area of the triangle `abc` (positive when counter-clockwise).
#[inline]
pub fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> Sign {
    Sign::of(robust::orient2d(c2(a), c2(b), c2(c)))
}

/// Exact sign of the signed volume of the tet `abcd` (see the module conventions).
#[inline]
pub fn orient3d(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Sign {
    // Shewchuk's orient3d is det[a-d, b-d, c-d], the negative of our signed volume.
    Sign::of(-robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
}

/// Exact in-circle test (see the module conventions); zero when the four points are cocircular.
#[inline]
pub fn incircle(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> Sign {
    Sign::of(robust::incircle(c2(a), c2(b), c2(c), c2(d)))
}

/// Exact in-sphere test (see the module conventions); zero when the five points are cospherical.
#[inline]
pub fn insphere(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3], e: [f64; 3]) -> Sign {
    // Shewchuk's insphere is positive for e inside when his orient3d(a,b,c,d) > 0, which is our
    // negative orientation; negate to follow ours.
    Sign::of(-robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e)))
}

/// In-sphere test with Simulation of Simplicity: never zero unless all five points are coplanar.
///
/// Each point `p_i` is lifted to `|p_i|² + ε^(rank)` where a larger index `ids[i]` gets a larger
/// infinitesimal (distinct ids are required). When the exact determinant is zero, the sign is
/// that of the first non-zero cofactor, taking points from the largest id down: the cofactor of
/// the lifted coordinate of the point in slot `k` (0-based) is `(-1)^(k+1) · orient3d(other four,
/// in order)`. Geometrically, the most perturbed point is pushed outside the sphere of the others.
/// This is a consistent total order, so a Delaunay triangulation built with it is unique even for
/// lattice points.
pub fn insphere_sos(p: [[f64; 3]; 5], ids: [u32; 5]) -> Sign {
    let s = insphere(p[0], p[1], p[2], p[3], p[4]);
    if s != Sign::Zero {
        return s;
    }
    insphere_sos_cofactors(p, ids, orient3d)
}

/// The perturbation part of [`insphere_sos`] for five exactly cospherical points: the sign of
/// the first non-zero cofactor of the lifted coordinates, taking points from the largest id down;
/// the cofactor of slot `k` is `(-1)^(k+1) · orient(other four, in order)`. `orient` must be an
/// exact orient3d (the plain one, or a filtered one that falls back to it). The one definition of
/// the tie-break rule, shared by every caller so that all of them perturb alike.
#[inline]
pub fn insphere_sos_cofactors(
    p: [[f64; 3]; 5],
    ids: [u32; 5],
    orient: impl Fn([f64; 3], [f64; 3], [f64; 3], [f64; 3]) -> Sign,
) -> Sign {
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
        let o = orient(rest[0], rest[1], rest[2], rest[3]);
        if o != Sign::Zero {
            return o.times(k % 2 == 1);
        }
    }
    Sign::Zero
}

/// In-circle test with Simulation of Simplicity: never zero unless all four points are collinear.
///
/// Same scheme as [`insphere_sos`]: the cofactor of the lifted coordinate of the point in slot `k`
/// (0-based) is `(-1)^k · orient2d(other three, in order)`.
pub fn incircle_sos(p: [[f64; 2]; 4], ids: [u32; 4]) -> Sign {
    let s = incircle(p[0], p[1], p[2], p[3]);
    if s != Sign::Zero {
        return s;
    }
    let mut order = [0usize, 1, 2, 3];
    order.sort_unstable_by(|&i, &j| ids[j].cmp(&ids[i]));
    for &k in &order {
        let mut rest = [[0.0; 2]; 3];
        let mut n = 0;
        for (i, q) in p.iter().enumerate() {
            if i != k {
                rest[n] = *q;
                n += 1;
            }
        }
        let o = orient2d(rest[0], rest[1], rest[2]);
        if o != Sign::Zero {
            return o.times(k % 2 == 0);
        }
    }
    Sign::Zero
}
