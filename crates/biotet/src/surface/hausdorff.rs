//! The one-sided distance from one labelled surface to another, sheet by sheet: every corner and
//! a barycentric grid of samples on each triangle (spacing at most `spacing` along the longest
//! edge), each measured by its exact closest point on the other surface's triangles with the
//! same side labels ([`super::bvh::PatchIndex`]). Measuring against the same sheet only is
//! stricter than the plain Hausdorff distance (the sheet is a subset of the surface).
//!
//! The distance to a surface is 1-Lipschitz, so the true one-sided distance exceeds the largest
//! sampled one by at most the covering radius of the samples, `h / √3` for grid step `h`
//! (reported as [`Sided::bound`]).
//!
//! Parallel over triangles; the maximum does not depend on the order, so the result is the same
//! on any number of threads.

use rayon::prelude::*;

use super::bvh::{Hint, PatchIndex, dist2};

type P3 = [f64; 3];

/// The covering radius of a barycentric grid of step `h`: every point of the triangle is within
/// it of a sample.
fn covering(h: f64) -> f64 {
    h / 3f64.sqrt()
}

/// A sample farther from the other surface than the flag distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Far {
    /// The triangle of the measured surface it lies on.
    pub triangle: u32,
    /// The sample.
    pub point: P3,
    /// Its distance.
    pub distance: f64,
    /// The closest triangle of the other surface.
    pub nearest: u32,
}

/// The distance of one surface from another.
#[derive(Debug, Clone, PartialEq)]
pub struct Sided {
    /// The largest sampled distance.
    pub max: f64,
    /// An upper bound on the true distance: `max` plus the samples' covering radius.
    pub bound: f64,
    /// Per side-label pair, the largest sampled distance.
    pub per_sheet: Vec<([u32; 2], f64)>,
    /// The farthest sample of each triangle farther than the flag distance or whose bound stays
    /// over the limit.
    pub far: Vec<Far>,
    /// Number of samples measured.
    pub n_samples: usize,
}

/// The one-sided distance from the triangles `tris` over `pts` (those with `alive[t]`, when
/// given) to `to`. A triangle whose bound (sampled maximum plus covering radius) exceeds
/// `limit` is sampled again with spacing `fine` (pass `limit = f64::INFINITY` for one pass).
/// Triangles farther than `flag`, or whose bound stays over `limit`, are listed in
/// [`Sided::far`] (their farthest sample). Samples proven (by the Lipschitz bound
/// from the previous sample of their row) no farther than `floor` or than the maximum so far are
/// not measured, so every distance reported is at least `floor`: pass 0 for exact values, or a
/// lower bound of the answer to save time.
#[allow(clippy::too_many_arguments)]
pub fn one_sided(
    pts: &[P3],
    tris: &[[u32; 3]],
    sides: &[[u32; 2]],
    alive: Option<&[bool]>,
    to: &PatchIndex,
    spacing: f64,
    fine: f64,
    limit: f64,
    flag: f64,
    floor: f64,
) -> Sided {
    struct Per {
        max: f64,
        step: f64,
        far: Option<Far>,
        n: usize,
    }
    let per: Vec<Per> = (0..tris.len())
        .into_par_iter()
        .map(|t| {
            if alive.is_some_and(|a| !a[t]) {
                return Per {
                    max: 0.0,
                    step: 0.0,
                    far: None,
                    n: 0,
                };
            }
            let c = tris[t].map(|v| pts[v as usize]);
            let Some(bvh) = to.get(sides[t]) else {
                return Per {
                    max: f64::INFINITY,
                    step: 0.0,
                    far: None,
                    n: 0,
                };
            };
            let longest = (0..3)
                .map(|k| dist2(c[k], c[(k + 1) % 3]))
                .fold(0.0, f64::max)
                .sqrt();
            let mut n = ((longest / spacing).ceil() as usize).max(1);
            let mut max = floor;
            let mut far: Option<Far> = None;
            let mut count = 0;
            let mut hint = Hint::default();
            let fine_n = ((longest / fine).ceil() as usize).max(1);
            'again: loop {
                for i in 0..=n {
                    // An upper bound on the distance at the previous sample of the row: the
                    // distance is 1-Lipschitz, so a sample that cannot exceed the maximum so far
                    // is not measured.
                    let mut prev: Option<(P3, f64)> = None;
                    for j in 0..=n - i {
                        let k = n - i - j;
                        let w = [i as f64, j as f64, k as f64].map(|x| x / n as f64);
                        let p = [0, 1, 2].map(|a| w[0] * c[0][a] + w[1] * c[1][a] + w[2] * c[2][a]);
                        count += 1;
                        if let Some((pp, pd)) = prev {
                            let ub = pd + dist2(p, pp).sqrt();
                            if ub <= max {
                                prev = Some((p, ub));
                                continue;
                            }
                        }
                        // Only a sample farther than the maximum so far matters.
                        if bvh.any_within_hinted(p, max * max, &mut hint) {
                            prev = Some((p, max));
                            continue;
                        }
                        let Some(q) = bvh.closest(p) else { continue };
                        let d = q.d2.sqrt();
                        prev = Some((p, d));
                        if d > max {
                            max = d;
                            far = Some(Far {
                                triangle: t as u32,
                                point: p,
                                distance: d,
                                nearest: q.triangle,
                            });
                        }
                    }
                }
                // Refine just enough for the bound to prove the limit (if it can).
                if max + covering(longest / n as f64) > limit && fine_n > n && max < limit {
                    let need = (longest / ((limit - max) * 3f64.sqrt())).ceil() as usize;
                    n = need.max(2 * n).min(fine_n);
                    continue 'again;
                }
                break;
            }
            let step = longest / n as f64;
            // Listed when farther than the flag, or when the finest samples cannot prove the
            // limit (the bound is then over it though every sample is within).
            let listed = max > flag || max + covering(step) > limit;
            Per {
                max,
                step,
                far: far.filter(|_| listed),
                n: count,
            }
        })
        .collect();
    let mut keys: Vec<[u32; 2]> = sides.to_vec();
    keys.sort_unstable();
    keys.dedup();
    let mut per_sheet: Vec<([u32; 2], f64)> = keys.iter().map(|&k| (k, 0.0)).collect();
    let mut out = Sided {
        max: 0.0,
        bound: 0.0,
        per_sheet: Vec::new(),
        far: Vec::new(),
        n_samples: 0,
    };
    for (t, p) in per.iter().enumerate() {
        if alive.is_some_and(|a| !a[t]) {
            continue;
        }
        let k = keys.binary_search(&sides[t]).unwrap_or(0);
        per_sheet[k].1 = per_sheet[k].1.max(p.max);
        out.max = out.max.max(p.max);
        out.bound = out.bound.max(p.max + covering(p.step));
        out.n_samples += p.n;
        if let Some(f) = p.far {
            out.far.push(f);
        }
    }
    out.per_sheet = per_sheet;
    out
}
