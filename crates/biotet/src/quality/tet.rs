//! Per-tet measures: dihedral angles, solid angles, q (eq. 4.9 of the seed) and radius ratio.

use crate::geom::vec3::{add, cross, dot, norm, norm2, scale, sub, volume6};
use crate::mesh::tet::TET_EDGES;

/// The circumcentre of a tet (None when flat in floating point).
pub fn circumcentre(c: &[[f64; 3]; 4]) -> Option<[f64; 3]> {
    let a = sub(c[1], c[0]);
    let b = sub(c[2], c[0]);
    let d = sub(c[3], c[0]);
    let den = 2.0 * dot(a, cross(b, d));
    if den == 0.0 || !den.is_finite() {
        return None;
    }
    let num = add(
        add(scale(cross(b, d), norm2(a)), scale(cross(d, a), norm2(b))),
        scale(cross(a, b), norm2(d)),
    );
    let o = add(c[0], scale(num, 1.0 / den));
    o.iter().all(|k| k.is_finite()).then_some(o)
}

/// Solid angle at each vertex of a regular tetrahedron, `3·acos(1/3) − π` steradians (eq. 4.2).
pub const REGULAR_SOLID_ANGLE: f64 = 0.551_285_598_432_530_8;

/// The six interior dihedral angles (radians) at the edges of [`TET_EDGES`], in that order.
/// Negative-volume tets still get angles in `[0, π]`; check orientation separately.
pub fn dihedral_angles(c: &[[f64; 3]; 4]) -> [f64; 6] {
    // Area-weighted outward normals of the faces opposite each vertex.
    let n = face_normals(c);
    let mut out = [0.0; 6];
    for (e, &[i, j]) in TET_EDGES.iter().enumerate() {
        // The two faces at edge ij are those opposite the other two vertices k, l.
        let [k, l] = TET_EDGES[5 - e];
        debug_assert!(k != i && k != j && l != i && l != j);
        let (nk, nl) = balanced(n[k], n[l]);
        // Interior angle = π − angle between outward normals.
        out[e] = norm(cross(nk, nl)).atan2(-dot(nk, nl));
    }
    out
}

/// The `[y, x]` pairs whose `y.atan2(x)` is [`dihedral_angles`]`(c)[e]` bit for bit (`y ≥ 0`),
/// for callers that order or screen the angles without trigonometry and take `atan2` of a few.
pub fn dihedral_yx(c: &[[f64; 3]; 4]) -> [[f64; 2]; 6] {
    let n = face_normals(c);
    let mut out = [[0.0; 2]; 6];
    for (e, o) in out.iter_mut().enumerate() {
        let [k, l] = TET_EDGES[5 - e];
        let (nk, nl) = (n[k], n[l]);
        *o = [norm(cross(nk, nl)), -dot(nk, nl)];
    }
    out
}

/// The interior dihedral angle (radians) at edge `e` of [`TET_EDGES`] alone: the same value as
/// `dihedral_angles(c)[e]`, for callers that need one edge.
pub fn dihedral_at(c: &[[f64; 3]; 4], e: usize) -> f64 {
    let [k, l] = TET_EDGES[5 - e];
    let (nk, nl) = balanced(face_normal(c, k), face_normal(c, l));
    norm(cross(nk, nl)).atan2(-dot(nk, nl))
}

/// `4·sin²(θ/2)` of the smallest interior dihedral angle θ: increasing in θ, computed without
/// trigonometry and without cancellation for small angles (as `|u + v|²` of the two faces' unit
/// outward normals), for ranking many tets cheaply. 0 for a degenerate tet.
pub fn min_dihedral_chord2(c: &[[f64; 3]; 4]) -> f64 {
    edge_chords2(c).map_or(0.0, |e| e.into_iter().fold(f64::INFINITY, f64::min))
}

/// `|u + v|²` of the two faces' unit outward normals at each edge of [`TET_EDGES`]
/// (`4·sin²(θ/2)` of its dihedral angle θ); `None` for a degenerate tet.
fn edge_chords2(c: &[[f64; 3]; 4]) -> Option<[f64; 6]> {
    let n = face_normals(c);
    let mut u = [[0.0; 3]; 4];
    for (ui, ni) in u.iter_mut().zip(&n) {
        let l = norm(*ni);
        if l == 0.0 {
            return None;
        }
        *ui = scale(*ni, 1.0 / l);
    }
    Some(TET_EDGES.map(|[k, l]| norm2(add(u[k], u[l]))))
}

/// `4·sin²(θ/2)` of the largest interior dihedral angle θ (as [`min_dihedral_chord2`] for the
/// smallest): a cheap screen for tets above an angle. 4 for a degenerate tet.
pub fn max_dihedral_chord2(c: &[[f64; 3]; 4]) -> f64 {
    edge_chords2(c).map_or(4.0, |e| e.into_iter().fold(0.0, f64::max))
}

/// The smallest interior dihedral angle in degrees, from [`min_dihedral_chord2`]: one `asin`
/// instead of six `atan2`, for code that ranks many tets (0 for a degenerate tet). It may differ
/// from [`min_dihedral_deg`] in the last bits.
pub fn min_dihedral_deg_by_chord(c: &[[f64; 3]; 4]) -> f64 {
    let half_chord = 0.5 * min_dihedral_chord2(c).sqrt();
    2.0 * half_chord.min(1.0).asin().to_degrees()
}

/// The power of two that brings `m` (a largest magnitude) to about 1, when `m` lies outside
/// `1/range..range`; `None` inside it (or for 0 and non-finite `m`). Scaling by a power of two
/// is exact, so a measure of scaled values has the same bits as of the originals wherever the
/// originals did not over- or underflow.
fn unit_scale(m: f64, range: f64) -> Option<f64> {
    (m != 0.0 && m.is_finite() && !(1.0 / range..=range).contains(&m))
        .then(|| 2f64.powi(-(m.log2().round() as i32)))
}

/// `a` and `b` scaled alike by [`unit_scale`] beyond 1e±60: the squares in the angle between
/// them (a face normal is the square of the tet's size, their cross product its fourth power)
/// then neither overflow nor underflow on a tet 1e40 across or 1e-40 (90° and 0° came out for
/// any tet there); `atan2` sees both arguments scaled alike, so the angle is the same.
fn balanced(a: [f64; 3], b: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let m = a.iter().chain(&b).fold(0.0f64, |m, x| m.max(x.abs()));
    match unit_scale(m, 1e60) {
        Some(s) => (scale(a, s), scale(b, s)),
        None => (a, b),
    }
}

/// `c` scaled by [`unit_scale`] of its extent beyond 1e±30 (when the scaled corners are
/// finite), for measures whose terms take high powers of the size.
fn sized(c: &[[f64; 3]; 4]) -> [[f64; 3]; 4] {
    let ext = (1..4)
        .flat_map(|i| (0..3).map(move |k| (c[i][k] - c[0][k]).abs()))
        .fold(0.0f64, f64::max);
    let Some(s) = unit_scale(ext, 1e30) else {
        return *c;
    };
    let out = c.map(|p| scale(p, s));
    if out.iter().flatten().all(|x| x.is_finite()) {
        out
    } else {
        *c
    }
}

/// Outward normals (length = twice the face area) of the faces opposite each vertex, for a
/// positively oriented tet.
fn face_normals(c: &[[f64; 3]; 4]) -> [[f64; 3]; 4] {
    [0, 1, 2, 3].map(|i| face_normal(c, i))
}

/// The outward normal (length twice the area) of the face opposite vertex `i`.
#[inline]
fn face_normal(c: &[[f64; 3]; 4], i: usize) -> [f64; 3] {
    let l = crate::mesh::tet::TET_FACES[i];
    let (a, b, cc) = (c[l[0]], c[l[1]], c[l[2]]);
    cross(sub(b, a), sub(cc, a))
}

/// The four solid angles (steradians) at the vertices, by the Van Oosterom–Strackee formula.
/// Positive for a positively oriented tet, negative for an inverted one.
pub fn solid_angles(c: &[[f64; 3]; 4]) -> [f64; 4] {
    let (det, den) = solid_angle_parts(c);
    den.map(|d| 2.0 * det.atan2(d))
}

/// The two arguments of the Van Oosterom–Strackee formula: the tet's signed `6·volume` and, at
/// each vertex, the denominator `|u||v||w| + (u·v)|w| + (u·w)|v| + (v·w)|u|` (u, v, w from the
/// vertex to the other three), so that `solid_angles(c)[i] == 2.0 * det.atan2(den[i])` bit for
/// bit (it is how [`solid_angles`] computes them). For callers that can decide a comparison
/// without the arctangent.
#[inline]
pub fn solid_angle_parts(c: &[[f64; 3]; 4]) -> (f64, [f64; 4]) {
    solid_angle_parts_with(c, &edge_lengths(c))
}

/// The lengths of the six edges of [`TET_EDGES`], in that order. `|p − q|` and `|q − p|` are the
/// same float, so one length serves both ends of an edge.
#[inline]
pub fn edge_lengths(c: &[[f64; 3]; 4]) -> [f64; 6] {
    TET_EDGES.map(|[i, j]| norm(sub(c[j], c[i])))
}

/// [`solid_angle_parts`] with the edge lengths given (`len[e]` of edge `TET_EDGES[e]`, as
/// [`edge_lengths`] computes them): the same floats, for a caller that knows some lengths
/// already (a tet with one corner moving keeps three).
#[inline]
pub fn solid_angle_parts_with(c: &[[f64; 3]; 4], len: &[f64; 6]) -> (f64, [f64; 4]) {
    use crate::mesh::tet::{TET_EDGES_AT as EDGES, TET_OTHERS as OTHERS};
    let det = volume6(c[0], c[1], c[2], c[3]);
    let mut den = [0.0; 4];
    for (i, o) in den.iter_mut().enumerate() {
        let [a, b, d] = OTHERS[i];
        let u = sub(c[a], c[i]);
        let v = sub(c[b], c[i]);
        let w = sub(c[d], c[i]);
        let [eu, ev, ew] = EDGES[i];
        let (lu, lv, lw) = (len[eu], len[ev], len[ew]);
        // The formula's numerator is the triple product [u v w], which is ±det: −det at vertices 1
        // and 3, whose `OTHERS` order is an odd permutation away from the tet's. The denominator
        // is symmetric in u, v, w, so use det itself: the same sign at every vertex, the sign of
        // the tet's orientation.
        *o = lu * lv * lw + dot(u, v) * lw + dot(u, w) * lv + dot(v, w) * lu;
    }
    (det, den)
}

/// Signed volume of the tet.
pub fn volume(c: &[[f64; 3]; 4]) -> f64 {
    volume6(c[0], c[1], c[2], c[3]) / 6.0
}

/// q = 12·(3V)^(2/3) / ΣL² (eq. 4.9): 1 for the regular tet, 0 for a flat one, negative for an
/// inverted one.
pub fn q_measure(c: &[[f64; 3]; 4]) -> f64 {
    let v = volume(c);
    let l2: f64 = TET_EDGES.iter().map(|&[i, j]| norm2(sub(c[i], c[j]))).sum();
    if l2 == 0.0 {
        return 0.0;
    }
    // cbrt² rather than powf(2/3): this runs for every candidate tet of the cavity search.
    let c = (3.0 * v.abs()).cbrt();
    v.signum() * 12.0 * c * c / l2
}

/// Radius ratio 3·r_in / R_circ: 1 for the regular tet, 0 for a flat one, negative when inverted.
pub fn radius_ratio(c: &[[f64; 3]; 4]) -> f64 {
    // Its circumradius takes the eighth power of the tet's size.
    let c = &sized(c);
    let det = volume6(c[0], c[1], c[2], c[3]);
    if det == 0.0 {
        return 0.0;
    }
    let n = face_normals(c);
    let area: f64 = n.iter().map(|x| 0.5 * norm(*x)).sum();
    let r_in = (det.abs() / 2.0) / area; // 3V / A
    let (u, v, w) = (sub(c[1], c[0]), sub(c[2], c[0]), sub(c[3], c[0]));
    let num = add(
        add(scale(cross(v, w), norm2(u)), scale(cross(w, u), norm2(v))),
        scale(cross(u, v), norm2(w)),
    );
    let r_circ = norm(num) / (2.0 * det.abs());
    det.signum() * 3.0 * r_in / r_circ
}

/// Every measure of one tet at once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TetMeasures {
    /// Dihedral angles in degrees, at the edges of [`TET_EDGES`].
    pub dihedral_deg: [f64; 6],
    /// Solid angles in steradians at the four vertices.
    pub solid_sr: [f64; 4],
    /// q of eq. 4.9.
    pub q: f64,
    /// Radius ratio.
    pub radius_ratio: f64,
    /// Signed volume.
    pub volume: f64,
}

impl TetMeasures {
    /// Measure the tet with corners `c`.
    pub fn of(c: &[[f64; 3]; 4]) -> TetMeasures {
        let d = dihedral_angles(c);
        TetMeasures {
            dihedral_deg: d.map(f64::to_degrees),
            solid_sr: solid_angles(c),
            q: q_measure(c),
            radius_ratio: radius_ratio(c),
            volume: volume(c),
        }
    }

    /// Smallest dihedral angle (degrees).
    pub fn min_dihedral(&self) -> f64 {
        self.dihedral_deg
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
    }

    /// Largest dihedral angle (degrees).
    pub fn max_dihedral(&self) -> f64 {
        self.dihedral_deg
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Smallest solid angle (steradians).
    pub fn min_solid(&self) -> f64 {
        self.solid_sr.iter().copied().fold(f64::INFINITY, f64::min)
    }
}

/// The smallest dihedral angle in degrees alone: bit for bit
/// `TetMeasures::of(c).min_dihedral()`, without the other measures.
pub fn min_dihedral_deg(c: &[[f64; 3]; 4]) -> f64 {
    dihedral_angles(c)
        .map(f64::to_degrees)
        .into_iter()
        .fold(f64::INFINITY, f64::min)
}

/// The smallest solid angle in steradians alone: bit for bit `TetMeasures::of(c).min_solid()`.
pub fn min_solid_sr(c: &[[f64; 3]; 4]) -> f64 {
    solid_angles(c).into_iter().fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_measures_match_every_measure_bit_for_bit() {
        // Regular, needle, sliver, flat and inverted tets, and pseudo-random ones.
        let mut tets = vec![
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.5, 0.8, 0.0],
                [0.5, 0.3, 0.8],
            ],
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.5, 0.5, 1e-9],
            ],
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.0],
            ],
            [
                [0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.2, 0.2, 0.7],
            ],
        ];
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut r = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 * 10.0 - 5.0
        };
        for _ in 0..200 {
            tets.push([0, 1, 2, 3].map(|_| [r(), r(), r()]));
        }
        for c in &tets {
            let m = TetMeasures::of(c);
            assert_eq!(min_dihedral_deg(c).to_bits(), m.min_dihedral().to_bits());
            assert_eq!(min_solid_sr(c).to_bits(), m.min_solid().to_bits());
            let a = dihedral_angles(c);
            for (e, [y, x]) in dihedral_yx(c).into_iter().enumerate() {
                assert_eq!(y.atan2(x).to_bits(), a[e].to_bits());
            }
        }
    }
}
