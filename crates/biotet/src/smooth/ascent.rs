//! The ascent direction of a minimum of several smooth functions: the point of smallest norm in
//! the convex hull of their gradients.
//!
//! Where several solid angles are (nearly) tied for the minimum, following the gradient of one of
//! them lowers another and the walk zig-zags. The min-norm point `d = Σ μ_j g_j` (μ ≥ 0,
//! Σ μ = 1) of the hull of the active gradients satisfies `g_j · d ≥ |d|²` for every `j`, so a
//! small step along `d` raises every active angle at once; `d = 0` means no direction raises them
//! all (a stationary point of the max–min problem). This is the small quadratic program of
//! optimisation-based smoothing, solved here exactly by enumerating the faces of the hull: in
//! 3D the minimiser lies on a face spanned by at most three gradients.

use crate::geom::vec3::{add, dot, norm2, scale, sub};

/// The point of smallest norm in the convex hull of `g` (at most [`MAX_ACTIVE`] are used; extra
/// entries are ignored). Zero when the origin is in the hull or `g` is empty.
pub fn min_norm_point(g: &[[f64; 3]]) -> [f64; 3] {
    let g = &g[..g.len().min(MAX_ACTIVE)];
    let m = g.len();
    if m == 0 {
        return [0.0; 3];
    }
    let scale2 = g.iter().map(|x| norm2(*x)).fold(0.0, f64::max);
    if scale2 == 0.0 {
        return [0.0; 3];
    }
    // Candidates: the affine min-norm point of every subset of one, two or three gradients whose
    // weights are all non-negative; the answer is a candidate meeting the optimality condition
    // g_j·d ≥ |d|² for all j (tolerance relative to the gradients' size).
    let tol = 1e-12 * scale2;
    let optimal = |d: [f64; 3]| {
        let dd = norm2(d);
        g.iter().all(|x| dot(*x, d) >= dd - tol)
    };
    let mut best: Option<[f64; 3]> = None;
    let mut consider = |d: [f64; 3]| {
        if optimal(d) && best.is_none_or(|b| norm2(d) < norm2(b)) {
            best = Some(d);
        }
    };
    for i in 0..m {
        consider(g[i]);
        for j in i + 1..m {
            if let Some(d) = segment(g[i], g[j]) {
                consider(d);
            }
            for k in j + 1..m {
                if let Some(d) = triangle(g[i], g[j], g[k]) {
                    consider(d);
                }
            }
        }
    }
    // No face qualifies: the origin is inside the hull.
    best.unwrap_or([0.0; 3])
}

/// At most this many gradients enter [`min_norm_point`] (the nearest-tied ones come first).
pub const MAX_ACTIVE: usize = 8;

/// Min-norm point of segment `ab` in its interior (weights strictly inside), if any.
fn segment(a: [f64; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let e = sub(b, a);
    let ee = norm2(e);
    if ee == 0.0 {
        return None;
    }
    let t = -dot(a, e) / ee;
    (t > 0.0 && t < 1.0).then(|| add(a, scale(e, t)))
}

/// Min-norm point of triangle `abc` in its interior (all weights positive), if any.
fn triangle(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Option<[f64; 3]> {
    let (e1, e2) = (sub(b, a), sub(c, a));
    // Minimise |a + s e1 + t e2|²: the 2×2 normal equations.
    let (m11, m12, m22) = (norm2(e1), dot(e1, e2), norm2(e2));
    let (r1, r2) = (-dot(a, e1), -dot(a, e2));
    let det = m11 * m22 - m12 * m12;
    if det <= 1e-14 * m11 * m22 {
        return None;
    }
    let s = (r1 * m22 - r2 * m12) / det;
    let t = (m11 * r2 - m12 * r1) / det;
    (s > 0.0 && t > 0.0 && s + t < 1.0).then(|| add(a, add(scale(e1, s), scale(e2, t))))
}
