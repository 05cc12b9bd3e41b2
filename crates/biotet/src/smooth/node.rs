//! Moving one node: raise the smallest solid angle of the tets around it (its cluster).
//!
//! Φ(x) is the minimum of every solid angle of every tet of the cluster — the angles at the
//! other corners too, which change as the node moves. Each iteration takes the ascent direction
//! of the angles tied (within a tolerance) for the minimum ([`super::ascent::min_norm_point`] of
//! their analytic gradients, projected onto the tangent plane when sliding), predicts the step
//! where the first other angle would catch up with them (linear model, as optimisation-based
//! smoothers do), capped by a fraction of the cluster's size, and halves the step until Φ
//! strictly increases and every tet of the cluster is strictly positive by exact `orient3d`.
//! It stops when no step improves or after an iteration cap.

use super::ascent::{MAX_ACTIVE, min_norm_point};
use super::gradient::gradients_with;
use super::screen::certainly_rejected;
use super::slide::{Location, SlideSurface};
use crate::geom::predicates::{Sign, in_exact_range, orient3d};
use crate::geom::vec3::{add, dot, norm, norm2, scale, sub};
use crate::mesh::tet::{TET_EDGES, TET_EDGES_AT as EDGES_AT};
use crate::quality::tet::{REGULAR_SOLID_ANGLE, edge_lengths, solid_angle_parts_with};

/// How a node may move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Motion {
    /// Anywhere (an interior node).
    Free,
    /// On the surface, from this location.
    Slide(Location),
}

/// Tuning of the local search, from [`super::SmoothOptions`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct LocalParams {
    pub max_iterations: usize,
    pub active_tolerance: f64,
    pub step_fraction: f64,
    pub max_halvings: usize,
    pub min_sensitivity: f64,
}

/// Reusable buffers for one node's cluster.
#[derive(Debug, Default)]
pub(crate) struct Cluster {
    /// Corners of each tet of the cluster, the free node's at `local[i]`.
    corners: Vec<[[f64; 3]; 4]>,
    local: Vec<usize>,
    /// Edge lengths of each tet at the current position (those away from the free node stay).
    lengths: Vec<[f64; 6]>,
    /// Edge lengths of each tet at a trial position.
    trial_lengths: Vec<[f64; 6]>,
    /// The solid angles of each tet at the current position.
    angles: Vec<[f64; 4]>,
    trial: Vec<[f64; 4]>,
    /// The Van Oosterom–Strackee arguments of each tet at a trial position.
    parts: Vec<(f64, [f64; 4])>,
    /// Gradients with respect to the free node of each tet's four angles.
    grads: Vec<[[f64; 3]; 4]>,
    /// The angles tied for the minimum: (angle, tet, corner).
    active: Vec<(f64, usize, usize)>,
    /// Their gradients, tangential when sliding.
    g: Vec<[f64; 3]>,
}

/// The result of moving one node.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Moved {
    pub x: [f64; 3],
    pub loc: Option<Location>,
    pub phi_before: f64,
    pub phi_after: f64,
}

impl Cluster {
    /// Load the tets `star` around node `v` of a mesh with these points and tets, with their
    /// solid angles (computed here, the same floats as
    /// [`solid_angles`](crate::quality::tet::solid_angles): caching them for every tet of the
    /// mesh would cost 32 bytes a tet for the few clusters visited).
    pub fn load(&mut self, points: &[[f64; 3]], tets: &[[u32; 4]], star: &[u32], v: u32) {
        self.corners.clear();
        self.local.clear();
        self.angles.clear();
        self.lengths.clear();
        for &t in star {
            let tv = tets[t as usize];
            let c = tv.map(|i| points[i as usize]);
            self.corners.push(c);
            let len = edge_lengths(&c);
            let (det, den) = solid_angle_parts_with(&c, &len);
            self.angles.push(den.map(|d| 2.0 * det.atan2(d)));
            self.lengths.push(len);
            self.local
                .push(tv.iter().position(|&i| i == v).unwrap_or(0));
        }
    }

    /// The smallest solid angle of each tet of the cluster at the free node's current position
    /// (after [`Cluster::optimise`]: where it left the node), in the order of the loaded star.
    pub fn tet_minima(&self) -> impl Iterator<Item = f64> + '_ {
        self.angles
            .iter()
            .map(|a| a[0].min(a[1]).min(a[2]).min(a[3]))
    }

    /// The cluster's minimum solid angle at the loaded position.
    fn measure(&self) -> f64 {
        self.tet_minima().fold(f64::INFINITY, f64::min)
    }

    /// Φ at `x` and the cluster's soft measure there, the angles into `trial`, if Φ is strictly
    /// above `floor`, the soft measure does not fall, and every tet is strictly positive (exact);
    /// `None` otherwise. `soft_old` caches the soft measure of `angles` (filled when first needed).
    fn try_at(
        &mut self,
        x: [f64; 3],
        floor: f64,
        soft_old: &mut Option<f64>,
    ) -> Option<(f64, f64)> {
        if !x.iter().all(|&c| c.is_finite() && in_exact_range(c)) {
            return None;
        }
        self.parts.clear();
        self.trial_lengths.clear();
        for ((c, &k), len) in self.corners.iter().zip(&self.local).zip(&self.lengths) {
            let mut c = *c;
            c[k] = x;
            let mut len = *len;
            for e in EDGES_AT[k] {
                let [i, j] = TET_EDGES[e];
                len[e] = norm(sub(c[j], c[i]));
            }
            self.parts.push(solid_angle_parts_with(&c, &len));
            self.trial_lengths.push(len);
        }
        let soft_old = *soft_old.get_or_insert_with(|| soft(&self.angles));
        // Most trials fail; most failures are proved without an arctangent or a logarithm.
        if certainly_rejected(&self.parts, floor, soft_old) {
            return None;
        }
        self.trial.clear();
        let mut phi = f64::INFINITY;
        for &(det, den) in &self.parts {
            let a = den.map(|d| 2.0 * det.atan2(d));
            let m = a[0].min(a[1]).min(a[2]).min(a[3]);
            // Also rejects NaN.
            if m.is_nan() || m <= floor {
                return None;
            }
            phi = phi.min(m);
            self.trial.push(a);
        }
        // The rest of the cluster must not pay for the minimum's gain: the sum of the logarithms
        // of the angles (each capped at the regular tet's, so that flattening a large angle
        // counts for nothing) must not fall. Without it, max-min drags the cluster's other
        // angles down to the minimum and fattens the low end of the histogram.
        let soft_new = soft(&self.trial);
        if soft_new.is_nan() || soft_new < soft_old {
            return None;
        }
        for (c, &k) in self.corners.iter().zip(&self.local) {
            let mut c = *c;
            c[k] = x;
            if orient3d(c[0], c[1], c[2], c[3]) != Sign::Positive {
                return None;
            }
        }
        Some((phi, soft_new))
    }

    /// Move the free node, starting at `x0`; `None` when it stays where it is.
    pub fn optimise(
        &mut self,
        x0: [f64; 3],
        motion: Motion,
        surface: Option<&SlideSurface>,
        p: &LocalParams,
    ) -> Option<Moved> {
        if self.corners.is_empty() {
            return None;
        }
        let phi0 = self.measure();
        if !phi0.is_finite() {
            return None;
        }
        // The cluster's size: the mean distance to the other corners.
        let mut size = 0.0;
        let mut n = 0;
        for (c, &k) in self.corners.iter().zip(&self.local) {
            for (i, q) in c.iter().enumerate() {
                if i != k {
                    size += norm(sub(*q, x0));
                    n += 1;
                }
            }
        }
        let delta_max = p.step_fraction * size / n as f64;
        let min_step = 1e-9 * delta_max;
        let (mut x, mut loc, mut phi) = (x0, motion, phi0);
        // The soft measure of `angles` once known, carried from an accepted trial to the next.
        let mut soft_x = None;
        let mut active = std::mem::take(&mut self.active);
        let mut g = std::mem::take(&mut self.g);
        for _ in 0..p.max_iterations {
            // Gradients of every angle (for the active set and the step prediction).
            self.grads.clear();
            for ((c, &k), len) in self.corners.iter().zip(&self.local).zip(&self.lengths) {
                let mut c = *c;
                c[k] = x;
                self.grads.push(gradients_with(&c, k, len));
            }
            let normal = match (loc, surface) {
                (Motion::Slide(l), Some(s)) => Some(s.normal(&l)),
                _ => None,
            };
            let tangent = |v: [f64; 3]| match normal {
                Some(n) => sub(v, scale(n, dot(v, n))),
                None => v,
            };
            let window = phi + p.active_tolerance * phi.abs();
            active.clear();
            for (t, a) in self.angles.iter().enumerate() {
                for (i, &w) in a.iter().enumerate() {
                    if w <= window {
                        active.push((w, t, i));
                    }
                }
            }
            active.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
            active.truncate(MAX_ACTIVE);
            g.clear();
            g.extend(active.iter().map(|&(_, t, i)| tangent(self.grads[t][i])));
            let d = min_norm_point(&g);
            let dd = norm2(d);
            let gmax = g.iter().map(|x| norm2(*x)).fold(0.0, f64::max);
            // Stationary, or the minimum barely depends on this node (a tet it cannot repair):
            // moving it would only trade the cluster's other angles for nothing.
            if dd.is_nan()
                || dd <= 1e-20 * gmax
                || dd.sqrt() * size / (n as f64) < p.min_sensitivity
            {
                break;
            }
            // Linear model: the active angles rise at least at `rate`; an inactive angle j
            // rising slower meets them after (ξ_j − Φ) / (rate − g_j·d).
            let rate = g.iter().map(|x| dot(*x, d)).fold(f64::INFINITY, f64::min);
            let mut alpha = delta_max / dd.sqrt();
            for (t, a) in self.angles.iter().enumerate() {
                for (i, &w) in a.iter().enumerate() {
                    if w > window {
                        let r = dot(tangent(self.grads[t][i]), d);
                        if r < rate {
                            alpha = alpha.min((w - phi) / (rate - r));
                        }
                    }
                }
            }
            let mut accepted = None;
            for _ in 0..=p.max_halvings {
                if alpha * dd.sqrt() < min_step {
                    break;
                }
                let step = scale(d, alpha);
                let cand = match (loc, surface) {
                    (Motion::Slide(l), Some(s)) => {
                        s.walk(&l, step).map(|(nl, nx)| (nx, Motion::Slide(nl)))
                    }
                    _ => Some((add(x, step), Motion::Free)),
                };
                if let Some((nx, nl)) = cand
                    && let Some((np, ns)) = self.try_at(nx, phi, &mut soft_x)
                {
                    accepted = Some((nx, nl, np, ns));
                    break;
                }
                alpha *= 0.5;
            }
            let Some((nx, nl, np, ns)) = accepted else {
                break;
            };
            x = nx;
            loc = nl;
            phi = np;
            soft_x = Some(ns);
            std::mem::swap(&mut self.angles, &mut self.trial);
            std::mem::swap(&mut self.lengths, &mut self.trial_lengths);
        }
        self.active = active;
        self.g = g;
        (x != x0).then_some(Moved {
            x,
            loc: match loc {
                Motion::Slide(l) => Some(l),
                Motion::Free => None,
            },
            phi_before: phi0,
            phi_after: phi,
        })
    }
}

/// The cluster's soft measure: the sum over all its angles of the logarithm of the angle, capped
/// at the regular tet's (see [`Cluster::try_at`]).
fn soft(angles: &[[f64; 4]]) -> f64 {
    let mut s = 0.0;
    for a in angles {
        for &w in a {
            s += w.min(REGULAR_SOLID_ANGLE).ln();
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::tet::{solid_angle_parts, solid_angles};

    /// The edges at each local vertex are those of `TET_EDGES` containing it, and the parts
    /// from known lengths are the parts (so the trial angles are `solid_angles` bit for bit).
    #[test]
    fn edges_at_and_parts_with_lengths() {
        for (k, es) in EDGES_AT.iter().enumerate() {
            let want: Vec<usize> = (0..6).filter(|&e| TET_EDGES[e].contains(&k)).collect();
            assert_eq!(es.to_vec(), want);
        }
        let c = [
            [0.1, 0.2, 0.3],
            [1.7, 0.1, -0.2],
            [0.3, 1.9, 0.05],
            [0.4, 0.35, 1.3],
        ];
        let (det, den) = solid_angle_parts(&c);
        assert_eq!(solid_angle_parts_with(&c, &edge_lengths(&c)), (det, den));
        let a = solid_angles(&c);
        for i in 0..4 {
            assert_eq!((2.0 * det.atan2(den[i])).to_bits(), a[i].to_bits());
        }
    }
}
