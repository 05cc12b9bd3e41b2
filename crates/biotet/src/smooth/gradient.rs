//! Analytic gradients of a tet's four solid angles with respect to the position of one corner.
//!
//! A solid angle at vertex `i` is `Ω = 2·atan2(N, D)` (Van Oosterom–Strackee, as in
//! [`crate::quality::tet::solid_angles`]) with `N` the tet's signed `6·volume` and
//! `D = |u||v||w| + (u·v)|w| + (u·w)|v| + (v·w)|u|`, where `u, v, w` run from vertex `i` to the
//! other three. So `dΩ = 2·(D·dN − N·dD) / (N² + D²)`.
//!
//! - `∂N/∂c_k = −n_k`, the outward normal (length twice the area) of the face opposite `k`:
//!   pushing a corner away from its opposite face grows the volume.
//! - `∂D/∂u = |v||w|·û + |w|·v + |v|·w + (v·w)·û` and likewise for `v` and `w`; a corner that is
//!   one of the "other three" of vertex `i` moves one of `u, v, w`, and vertex `i` itself moves
//!   all three the opposite way.
//!
//! When the free node moves, every solid angle of every tet around it changes, not only the
//! angle at the node: the function returns the gradients of all four.

use crate::geom::vec3::{add, cross, dot, scale, sub, volume6};
use crate::mesh::tet::{TET_EDGES_AT as EDGES, TET_FACES, TET_OTHERS as OTHERS};
use crate::quality::tet::{edge_lengths, solid_angles};

/// The four solid angles of the tet with corners `c` (exactly the values of
/// [`crate::quality::tet::solid_angles`]) and the gradient of each with respect to the position
/// of corner `k` (`0..4`).
pub fn solid_angle_gradients(c: &[[f64; 3]; 4], k: usize) -> ([f64; 4], [[f64; 3]; 4]) {
    (solid_angles(c), gradients(c, k))
}

/// The gradients of [`solid_angle_gradients`] alone, for a caller that has the angles.
pub fn gradients(c: &[[f64; 3]; 4], k: usize) -> [[f64; 3]; 4] {
    gradients_with(c, k, &edge_lengths(c))
}

/// [`gradients`] with the edge lengths given, as [`edge_lengths`] computes them (the same
/// floats, without the square roots).
pub fn gradients_with(c: &[[f64; 3]; 4], k: usize, len: &[f64; 6]) -> [[f64; 3]; 4] {
    let det = volume6(c[0], c[1], c[2], c[3]);
    let f = TET_FACES[k];
    // ∂N/∂c_k = −(outward normal of the face opposite k).
    let dn = scale(cross(sub(c[f[1]], c[f[0]]), sub(c[f[2]], c[f[0]])), -1.0);
    let mut grads = [[0.0; 3]; 4];
    for (i, g) in grads.iter_mut().enumerate() {
        let [a, b, d] = OTHERS[i];
        let u = sub(c[a], c[i]);
        let v = sub(c[b], c[i]);
        let w = sub(c[d], c[i]);
        let [eu, ev, ew] = EDGES[i];
        let (lu, lv, lw) = (len[eu], len[ev], len[ew]);
        let (uv, uw, vw) = (dot(u, v), dot(u, w), dot(v, w));
        let den = lu * lv * lw + uv * lw + uw * lv + vw * lu;
        // ∂D/∂u, ∂D/∂v, ∂D/∂w.
        let du = add(
            scale(u, (lv * lw + vw) / lu),
            add(scale(v, lw), scale(w, lv)),
        );
        let dv = add(
            scale(v, (lu * lw + uw) / lv),
            add(scale(u, lw), scale(w, lu)),
        );
        let dw = add(
            scale(w, (lu * lv + uv) / lw),
            add(scale(u, lv), scale(v, lu)),
        );
        let dd = if k == i {
            scale(add(du, add(dv, dw)), -1.0)
        } else if k == a {
            du
        } else if k == b {
            dv
        } else {
            dw
        };
        let s = 2.0 / (det * det + den * den);
        *g = scale(sub(scale(dn, den), scale(dd, det)), s);
    }
    grads
}
