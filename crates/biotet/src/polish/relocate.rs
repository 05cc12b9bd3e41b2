//! Move one interior point to raise the smallest dihedral angle of the unforced tets around it.
//!
//! The objective is the smallest dihedral angle over the star's unforced tets (forced ones are
//! pinned by the input, so they only constrain). No star tet may fall below its angle before or
//! the threshold, whichever is lower: max-min alone would drag good tets below the threshold to
//! lift the worst one a little. Where several
//! angles are nearly tied, the step follows the min-norm point of their gradients
//! ([`min_norm_point`]), which raises them all at once; the gradients are one-sided finite
//! differences of the tied tets alone. A step is taken only when the objective strictly rises
//! and every star tet stays strictly positive by exact [`orient3d`].

use crate::geom::predicates::{Sign, orient3d};
use crate::geom::vec3::{add, cross, norm, norm2, scale, sub};
use crate::mesh::tet::{TET_EDGES, TET_FACES};
use crate::quality::tet::dihedral_at;
use crate::smooth::ascent::{MAX_ACTIVE, min_norm_point};

use super::work::{MAX_STAR, P3, Work, angles_upto};

/// Step parameters of [`Work::relocate`].
#[derive(Debug, Clone, Copy)]
pub(super) struct StepParams {
    /// Ascent iterations.
    pub iterations: usize,
    /// First step, as a fraction of the mean distance to the star's other corners.
    pub step_fraction: f64,
    /// Step halvings before giving up a direction.
    pub halvings: usize,
    /// Angles within this many radians of the minimum are tied.
    pub tie: f64,
}

/// One star tet: corners, the moving point's slot, its floor (the chord of its smallest angle
/// before, or the threshold's if lower) and whether it is forced (left out of the objective).
struct Member {
    c: [P3; 4],
    k: usize,
    floor: f64,
    /// `angle(floor)`.
    floor_rad: f64,
    /// The unit normal of the face opposite the moving point (it does not move).
    uk: P3,
    forced: bool,
}

impl Work {
    /// Move point `v` (not fixed) to raise its star's worst unforced angle; true when it moved.
    /// `star` is scratch.
    pub fn relocate(
        &mut self,
        v: u32,
        threshold_rad: f64,
        p: &StepParams,
        star: &mut Vec<u32>,
    ) -> bool {
        if !self.star_upto(v, star, MAX_STAR) {
            return false;
        }
        let mut members = Vec::with_capacity(star.len());
        for &t in star.iter() {
            let c = self.corners(t);
            let k = self.tets[t as usize]
                .iter()
                .position(|&x| x == v)
                .unwrap_or(0);
            let m = min_chord(&c, k, unit_normal(&c, k));
            let floor = m.min(chord(threshold_rad));
            members.push(Member {
                c,
                k,
                floor,
                floor_rad: angle(floor),
                uk: unit_normal(&c, k),
                forced: self.is_forced(t),
            });
        }
        // The worst first: failing trials stop early.
        members.sort_by(|a, b| a.floor.total_cmp(&b.floor));
        let x0 = self.pts[v as usize];
        let Some(mut phi) = objective(&members, x0, -1.0) else {
            return false;
        };
        let mut size = 0.0;
        let mut n = 0;
        for m in &members {
            for (i, q) in m.c.iter().enumerate() {
                if i != m.k {
                    size += norm(sub(*q, x0));
                    n += 1;
                }
            }
        }
        size /= n.max(1) as f64;
        let h = 1e-7 * size;
        let mut x = x0;
        let mut grads: Vec<(f64, P3)> = Vec::new();
        for _ in 0..p.iterations {
            grads.clear();
            let phi_rad = angle(phi);
            for m in &members {
                let mut c = m.c;
                c[m.k] = x;
                // Only angles that can pass one of the two tests below need their value.
                let floor_rad = m.floor_rad + p.tie;
                let upto = if m.forced {
                    floor_rad
                } else {
                    floor_rad.max(phi_rad + p.tie)
                };
                let a = angles_upto(&c, upto);
                for (e, &ae) in a.iter().enumerate() {
                    // The tied minimum, and angles about to hit their floor.
                    let tied = !m.forced && ae <= phi_rad + p.tie;
                    if !tied && ae > floor_rad {
                        continue;
                    }
                    let g = [0, 1, 2].map(|axis| {
                        let mut cc = c;
                        cc[m.k][axis] += h;
                        (dihedral_at(&cc, e) - ae) / h
                    });
                    grads.push((ae, g));
                }
            }
            grads.sort_by(|a, b| a.0.total_cmp(&b.0));
            let g: Vec<P3> = grads.iter().take(MAX_ACTIVE).map(|x| x.1).collect();
            let d = min_norm_point(&g);
            let dn = norm(d);
            if dn == 0.0 || !dn.is_finite() {
                break;
            }
            let dir = scale(d, 1.0 / dn);
            let mut s = p.step_fraction * size;
            let mut moved = false;
            for _ in 0..=p.halvings {
                let y = add(x, scale(dir, s));
                if let Some(f) = objective(&members, y, phi)
                    && positive(&members, y)
                {
                    x = y;
                    phi = f;
                    moved = true;
                    break;
                }
                s *= 0.5;
            }
            if !moved {
                break;
            }
        }
        if x == x0 {
            return false;
        }
        self.pts[v as usize] = x;
        true
    }
}

/// The smallest chord (see [`min_chord`]) of the unforced members with the point at `x`, if it
/// beats `beat` and no member falls below its floor (stops at the first failure).
fn objective(members: &[Member], x: P3, beat: f64) -> Option<f64> {
    let mut phi = f64::INFINITY;
    for m in members {
        let mut c = m.c;
        c[m.k] = x;
        let a = min_chord(&c, m.k, m.uk);
        if a.is_nan() || a < m.floor || (!m.forced && a <= beat) {
            return None;
        }
        if !m.forced {
            phi = phi.min(a);
        }
    }
    Some(phi)
}

/// The unit outward normal of the face opposite corner `i` (NaN for a degenerate face).
fn unit_normal(c: &[P3; 4], i: usize) -> P3 {
    let l = TET_FACES[i];
    let n = cross(sub(c[l[1]], c[l[0]]), sub(c[l[2]], c[l[0]]));
    scale(n, 1.0 / norm(n))
}

/// The smallest `4·sin²(θ/2)` of the six dihedral angles θ (increasing in θ; no trigonometry):
/// `|u + v|²` of the unit outward normals of the two faces at each edge, `uk` the one opposite
/// corner `k`. NaN for a degenerate tet.
fn min_chord(c: &[P3; 4], k: usize, uk: P3) -> f64 {
    let u = [0, 1, 2, 3].map(|i| if i == k { uk } else { unit_normal(c, i) });
    let mut out = f64::INFINITY;
    for [i, j] in TET_EDGES.iter().rev() {
        out = out.min(norm2(add(u[*i], u[*j])));
    }
    out
}

/// The chord of angle `a` (radians).
fn chord(a: f64) -> f64 {
    let s = (a / 2.0).sin();
    4.0 * s * s
}

/// The angle (radians) of chord `c`.
fn angle(c: f64) -> f64 {
    2.0 * (c.sqrt() / 2.0).min(1.0).asin()
}

/// Every member strictly positive with the point at `x` (exact).
fn positive(members: &[Member], x: P3) -> bool {
    members.iter().all(|m| {
        let mut c = m.c;
        c[m.k] = x;
        orient3d(c[0], c[1], c[2], c[3]) == Sign::Positive
    })
}
