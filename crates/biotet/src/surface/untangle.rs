//! Crossing triangles untangled before the surface stage: a FreeSurfer pial or white surface
//! often has a few triangles passing through others (two banks of a tight sulcus, a bump pushed
//! through the facing wall). The points around each crossing are smoothed (the umbrella
//! operator, half a step at a time, all points of a step computed from the same positions so
//! the result does not depend on the order or the number of threads) until no two triangles
//! meet improperly (the exact test of [`crate::mesh::validate`]), each point kept within a
//! budget of where it was. The smoothed region grows by a ring of points every few steps where
//! the crossings stay. A triangle's points move at most the budget, so every point of the
//! untangled surface is within the budget of the input and every point of the input within it
//! of the untangled surface (the same barycentric point): the two-sided distance is at most the
//! largest move, which the stage subtracts from its tolerance.
//!
//! Limits: a crossing that smoothing does not remove within the budget (two shells pushed deep
//! into each other) is reported, not repaired.

use rustc_hash::FxHashSet;
use serde::Serialize;

use crate::mesh::surface::SurfaceMesh;
use crate::mesh::validate::crossing_pairs;

/// What a refusal of crossing triangles adds, for the CLI and the Python package alike.
pub const HINT: &str = "triangles cross (`--surface-tolerance D`, in Python `surface_tolerance=D`, \
                        untangles them, moving points by at most D/4, and remeshes the surface \
                        within D)";

/// Smoothing steps at most.
const MAX_STEPS: usize = 200;
/// Steps between two growths of the smoothed region.
const STEPS_PER_RING: usize = 8;
/// Rings of points around the crossing triangles smoothed at most.
const MAX_RINGS: usize = 6;
/// The fraction of the way to the neighbours' centroid a step moves a point.
const STEP: f64 = 0.5;

/// What [`untangle`] did.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Untangled {
    /// Pairs of triangles that crossed in the input.
    pub pairs: usize,
    /// Smoothing steps taken.
    pub steps: usize,
    /// Points moved.
    pub points_moved: usize,
    /// The largest distance a point moved.
    pub max_move: f64,
}

/// Why [`untangle`] gave up: crossings left once the budget or the steps were spent.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{left} pairs of crossing triangles left after moving points up to {} (of {pairs} in the \
     input); first: triangles {} and {}",
    crate::text::short(*.budget),
    .first.0,
    .first.1
)]
pub struct UntangleError {
    /// Pairs that crossed in the input.
    pub pairs: usize,
    /// Pairs still crossing.
    pub left: usize,
    /// The lowest of them.
    pub first: (u32, u32),
    /// The budget.
    pub budget: f64,
}

/// `s` without crossing triangles, its points moved at most `budget` (see the module docs);
/// `s` itself (and zero moves) when nothing crosses.
pub fn untangle(s: &SurfaceMesh, budget: f64) -> Result<(SurfaceMesh, Untangled), UntangleError> {
    let mut out = s.clone();
    let mut pairs = crossing_pairs(&out);
    let mut report = Untangled {
        pairs: pairs.len(),
        ..Untangled::default()
    };
    if pairs.is_empty() {
        return Ok((out, report));
    }
    let neighbours = point_neighbours(s);
    let mut moved = vec![false; s.points.len()];
    let b2 = budget * budget;
    while !pairs.is_empty() {
        if report.steps == MAX_STEPS {
            return Err(UntangleError {
                pairs: report.pairs,
                left: pairs.len(),
                first: pairs[0],
                budget,
            });
        }
        let rings = (1 + report.steps / STEPS_PER_RING).min(MAX_RINGS);
        let active = region(&out, &pairs, &neighbours, rings);
        let next: Vec<[f64; 3]> = active
            .iter()
            .map(|&v| {
                let p = out.points[v as usize];
                let nb = &neighbours[v as usize];
                let mut c = [0.0; 3];
                for &u in nb {
                    let q = out.points[u as usize];
                    for k in 0..3 {
                        c[k] += q[k];
                    }
                }
                let n = nb.len().max(1) as f64;
                let mut q = [0.0; 3];
                for k in 0..3 {
                    q[k] = p[k] + STEP * (c[k] / n - p[k]);
                }
                // Kept within the budget of the input's point.
                let o = s.points[v as usize];
                let d = [q[0] - o[0], q[1] - o[1], q[2] - o[2]];
                let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                if d2 > b2 {
                    q = toward(o, d, budget / d2.sqrt(), b2);
                }
                q
            })
            .collect();
        let mut changed = false;
        for (&v, q) in active.iter().zip(next) {
            if q != out.points[v as usize] {
                out.points[v as usize] = q;
                moved[v as usize] = true;
                changed = true;
            }
        }
        if !changed {
            // Every point held at its budget (or at its neighbours' centroid): on to a wider
            // region, or, with none to come, further steps would change nothing.
            if rings == MAX_RINGS {
                return Err(UntangleError {
                    pairs: report.pairs,
                    left: pairs.len(),
                    first: pairs[0],
                    budget,
                });
            }
            report.steps = rings * STEPS_PER_RING;
            continue;
        }
        report.steps += 1;
        pairs = crossing_pairs(&out);
    }
    report.points_moved = moved.iter().filter(|&&m| m).count();
    report.max_move = s
        .points
        .iter()
        .zip(&out.points)
        .map(|(a, b)| {
            let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        })
        .fold(0.0, f64::max);
    Ok((out, report))
}

/// `o + f·d`, `f` lowered until rounding leaves it within `sqrt(b2)` of `o` (far from the
/// origin, a coordinate's rounding is a sizeable part of a small budget); `o` if none is.
fn toward(o: [f64; 3], d: [f64; 3], mut f: f64, b2: f64) -> [f64; 3] {
    for _ in 0..64 {
        let q = [o[0] + f * d[0], o[1] + f * d[1], o[2] + f * d[2]];
        let e = [q[0] - o[0], q[1] - o[1], q[2] - o[2]];
        if e[0] * e[0] + e[1] * e[1] + e[2] * e[2] <= b2 {
            return q;
        }
        f *= 0.999;
    }
    o
}

/// Each point's neighbours along triangle edges, sorted.
fn point_neighbours(s: &SurfaceMesh) -> Vec<Vec<u32>> {
    let mut nb: Vec<Vec<u32>> = vec![Vec::new(); s.points.len()];
    for t in &s.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            nb[a as usize].push(b);
            nb[b as usize].push(a);
        }
    }
    for v in &mut nb {
        v.sort_unstable();
        v.dedup();
    }
    nb
}

/// The corners of the crossing triangles and `rings` rings of points around them, sorted.
fn region(s: &SurfaceMesh, pairs: &[(u32, u32)], nb: &[Vec<u32>], rings: usize) -> Vec<u32> {
    let mut set: FxHashSet<u32> = pairs
        .iter()
        .flat_map(|&(a, b)| [a, b])
        .flat_map(|t| s.triangles[t as usize])
        .collect();
    let mut front: Vec<u32> = set.iter().copied().collect();
    for _ in 0..rings {
        let mut next = Vec::new();
        for v in front {
            for &u in &nb[v as usize] {
                if set.insert(u) {
                    next.push(u);
                }
            }
        }
        front = next;
    }
    let mut out: Vec<u32> = set.into_iter().collect();
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::validate::{ValidateOptions, validate_surface};

    #[test]
    fn a_surface_without_crossings_is_left_as_it_is() {
        let s = SurfaceMesh::icosphere(1.0, 3);
        let (same, r) = untangle(&s, 0.1).unwrap();
        assert_eq!(same, s);
        assert_eq!(r, Untangled::default());
    }

    /// A slab 4 x 4 x 0.2 of a grid of 0.5, closed, outward.
    fn slab() -> SurfaceMesh {
        let mut s = SurfaceMesh::default();
        let n = 8;
        let id = |i: usize, j: usize, top: bool| {
            ((top as usize) * (n + 1) * (n + 1) + i * (n + 1) + j) as u32
        };
        for top in [false, true] {
            for i in 0..=n {
                for j in 0..=n {
                    s.points
                        .push([i as f64 * 0.5, j as f64 * 0.5, if top { 0.2 } else { 0.0 }]);
                }
            }
        }
        for top in [false, true] {
            for i in 0..n {
                for j in 0..n {
                    let [a, b, c, d] = [
                        id(i, j, top),
                        id(i + 1, j, top),
                        id(i + 1, j + 1, top),
                        id(i, j + 1, top),
                    ];
                    if top {
                        s.triangles.extend([[a, b, c], [a, c, d]]);
                    } else {
                        s.triangles.extend([[a, c, b], [a, d, c]]);
                    }
                }
            }
        }
        let ring: Vec<(usize, usize)> = (0..n)
            .map(|k| (k, 0))
            .chain((0..n).map(|k| (n, k)))
            .chain((0..n).map(|k| (n - k, n)))
            .chain((0..n).map(|k| (0, n - k)))
            .collect();
        for w in 0..ring.len() {
            let (i0, j0) = ring[w];
            let (i1, j1) = ring[(w + 1) % ring.len()];
            let [a, b] = [id(i0, j0, false), id(i1, j1, false)];
            let [c, d] = [id(i1, j1, true), id(i0, j0, true)];
            s.triangles.extend([[a, b, c], [a, c, d]]);
        }
        s.sides = vec![[1, 0]; s.triangles.len()];
        s
    }

    /// The slab with its top's middle point pushed down through the bottom.
    fn poked_slab() -> SurfaceMesh {
        let mut s = slab();
        s.points[81 + 4 * 9 + 4][2] = -0.1;
        s
    }

    #[test]
    fn a_point_pushed_through_the_opposite_wall_is_pulled_back() {
        let mut valid = slab();
        validate_surface(&mut valid, &ValidateOptions::default()).unwrap();
        let s = poked_slab();
        let pairs = crossing_pairs(&s).len();
        assert!(pairs > 0);
        // Too small a budget: refused, naming what is left.
        let e = untangle(&s, 0.05).unwrap_err();
        assert_eq!((e.pairs, e.budget), (pairs, 0.05));
        assert!(e.left > 0);
        let (mut out, r) = untangle(&s, 0.5).unwrap();
        assert_eq!(r.pairs, pairs);
        assert!(r.max_move > 0.0 && r.max_move <= 0.5, "{r:?}");
        for (a, b) in s.points.iter().zip(&out.points) {
            let d = (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
            assert!(d <= r.max_move);
        }
        assert!(crossing_pairs(&out).is_empty());
        validate_surface(&mut out, &ValidateOptions::default()).unwrap();
        // Only points near the crossing moved.
        assert!(r.points_moved < s.points.len() / 4, "{r:?}");
    }

    #[test]
    fn the_surface_stage_untangles_first_and_stays_within_its_tolerance() {
        let s = poked_slab();
        let opts = crate::surface::SurfaceOptions {
            tolerance: 1.0,
            ..Default::default()
        };
        let (mut out, r) = crate::surface::improve(&s, &opts).unwrap();
        let u = r.untangled.clone().expect("untangled");
        assert!(u.pairs > 0 && u.max_move <= 0.25, "{u:?}");
        assert_eq!(r.tolerance, 1.0);
        assert!(r.hausdorff_bound <= 1.0, "{r:?}");
        validate_surface(&mut out, &ValidateOptions::default()).unwrap();
        // Without crossings, nothing to untangle.
        let (_, r) = crate::surface::improve(&slab(), &opts).unwrap();
        assert_eq!(r.untangled, None);
    }
}
