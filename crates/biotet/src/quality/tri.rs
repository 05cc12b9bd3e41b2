//! Per-triangle measures for 2D meshes: angles, q and radius ratio.

/// The three interior angles (radians) at the corners, in corner order. Each is in `[0, π]`
/// whatever the orientation (a clockwise triangle gets the same angles as its mirror image), and
/// they sum to π up to rounding. A corner whose two edges have zero length gets angle 0.
pub fn angles(c: &[[f64; 2]; 3]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (i, o) in out.iter_mut().enumerate() {
        let p = c[i];
        let a = c[(i + 1) % 3];
        let b = c[(i + 2) % 3];
        let u = [a[0] - p[0], a[1] - p[1]];
        let v = [b[0] - p[0], b[1] - p[1]];
        let cr = u[0] * v[1] - u[1] * v[0];
        let dt = u[0] * v[0] + u[1] * v[1];
        *o = cr.abs().atan2(dt);
    }
    out
}

/// Signed area: positive for a counter-clockwise triangle.
pub fn area(c: &[[f64; 2]; 3]) -> f64 {
    let u = [c[1][0] - c[0][0], c[1][1] - c[0][1]];
    let v = [c[2][0] - c[0][0], c[2][1] - c[0][1]];
    0.5 * (u[0] * v[1] - u[1] * v[0])
}

/// Squared edge lengths, of the edge opposite each corner (see [`crate::TRI_EDGES`]).
fn edge_lengths2(c: &[[f64; 2]; 3]) -> [f64; 3] {
    let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    [d(c[1], c[2]), d(c[2], c[0]), d(c[0], c[1])]
}

/// q = 4√3·A / ΣL²: 1 for the equilateral triangle, 0 for a flat one, negative for a clockwise
/// one. The 2D analogue of [`super::tet::q_measure`].
pub fn q_measure(c: &[[f64; 2]; 3]) -> f64 {
    let l2: f64 = edge_lengths2(c).iter().sum();
    if l2 == 0.0 {
        return 0.0;
    }
    4.0 * 3f64.sqrt() * area(c) / l2
}

/// Radius ratio 2·r_in / R_circ = 16·A² / (P·abc) (P the perimeter, abc the product of the edge
/// lengths): 1 for the equilateral triangle, 0 for a flat one, negative for a clockwise one.
pub fn radius_ratio(c: &[[f64; 2]; 3]) -> f64 {
    let a = area(c);
    if a == 0.0 {
        return 0.0;
    }
    let l = edge_lengths2(c).map(f64::sqrt);
    let perimeter = l[0] + l[1] + l[2];
    // r = A / s with s = P/2, R = abc / (4A) ⇒ 2r/R = 16A² / (P·abc).
    a.signum() * 16.0 * a * a / (perimeter * l[0] * l[1] * l[2])
}

/// Every measure of one triangle at once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriMeasures {
    /// Interior angles in degrees, at the three corners.
    pub angles_deg: [f64; 3],
    /// q = 4√3·A / ΣL².
    pub q: f64,
    /// Radius ratio 2r/R.
    pub radius_ratio: f64,
    /// Signed area.
    pub area: f64,
}

impl TriMeasures {
    /// Measure the triangle with corners `c`.
    pub fn of(c: &[[f64; 2]; 3]) -> TriMeasures {
        TriMeasures {
            angles_deg: angles(c).map(f64::to_degrees),
            q: q_measure(c),
            radius_ratio: radius_ratio(c),
            area: area(c),
        }
    }

    /// Smallest angle (degrees).
    pub fn min_angle(&self) -> f64 {
        self.angles_deg
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
    }

    /// Largest angle (degrees).
    pub fn max_angle(&self) -> f64 {
        self.angles_deg
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// Smallest angle of a triangle in space, in degrees (0 for a degenerate one).
pub fn min_angle_3d_deg(c: &[[f64; 3]; 3]) -> f64 {
    use crate::geom::vec3::{cross, dot, norm, sub};
    (0..3)
        .map(|k| {
            let (u, v) = (sub(c[(k + 1) % 3], c[k]), sub(c[(k + 2) % 3], c[k]));
            norm(cross(u, v)).atan2(dot(u, v)).to_degrees()
        })
        .fold(f64::INFINITY, f64::min)
}
