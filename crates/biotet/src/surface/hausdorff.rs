//! The one-sided distance from one labelled surface to another, sheet by sheet: every corner and
//! a barycentric grid of samples on each triangle (spacing at most `spacing` along the longest
//! edge), each measured by its exact closest point on the other surface's triangles with the
//! same side labels ([`super::bvh::PatchIndex`]). Measuring against the same sheet only is
//! stricter than the plain Hausdorff distance (the sheet is a subset of the surface).
//!
//! The distance to a surface is 1-Lipschitz, so the true one-sided distance exceeds the largest
//! sampled one by at most the covering radius of the samples, `h / √3` for grid step `h`. Where
//! that bound is over the limit asked for, each cell of the grid is bounded instead by the
//! largest distance of its three corners to one triangle of the other surface (one found at a
//! corner): the distance to one triangle is convex, so over the cell it is largest at a corner,
//! and the cell is proven without finer samples (on the brain models, a third of the samples).
//! The larger of the two per cell, over all cells, is [`Sided::bound`].
//!
//! Parallel over triangles; the maximum does not depend on the order, so the result is the same
//! on any number of threads.

use rayon::prelude::*;

use super::bvh::{Bvh, Hint, PatchIndex, closest_on_triangle, dist2};
use crate::geom::vec3::{cross, norm, sub};

type P3 = [f64; 3];

/// The covering radius of a barycentric grid of step `h`: every point of the triangle is within
/// it of a sample.
fn covering(h: f64) -> f64 {
    h / 3f64.sqrt()
}

/// No triangle recorded for a grid point.
const NO_SLOT: u32 = u32::MAX;

/// Grid point `(i, j)` of triangle `c` with `n` steps an edge: barycentric weights
/// `(i, j, n - i - j) / n`.
#[inline]
fn grid_point(c: &[P3; 3], n: usize, i: usize, j: usize) -> P3 {
    let w = [i, j, n - i - j].map(|x| x as f64 / n as f64);
    [0, 1, 2].map(|a| w[0] * c[0][a] + w[1] * c[1][a] + w[2] * c[2][a])
}

/// An upper bound on the distance from triangle `c` to `bvh`'s triangles, from the grid of `n`
/// steps (cells of longest edge `step`) whose points' bounds and triangles are `grid` (row by
/// row), cell by cell: the Lipschitz bound (a cell's largest corner bound plus its covering
/// radius), and where that is over `limit`, the largest distance of the cell's corners to one
/// triangle found at one of them — the distance to a triangle is convex, so over the cell it
/// is largest at a corner.
fn cells_bound(
    bvh: &Bvh,
    c: &[P3; 3],
    n: usize,
    step: f64,
    grid: &[(f64, u32)],
    limit: f64,
) -> f64 {
    // Row i holds n + 1 - i points.
    let idx = |i: usize, j: usize| i * (n + 1) - i * i.saturating_sub(1) / 2 + j;
    // Every cell is the triangle scaled by 1/n.
    let h = covering(step);
    let mut worst = 0.0f64;
    let mut cell = |v: [(usize, usize); 3]| {
        let r = v.map(|(i, j)| grid[idx(i, j)]);
        let lip = r.iter().map(|x| x.0).fold(0.0, f64::max) + h;
        let mut b = lip;
        if lip > limit {
            let p = v.map(|(i, j)| grid_point(c, n, i, j));
            for (k, &(_, s)) in r.iter().enumerate() {
                if s == NO_SLOT || r[..k].iter().any(|x| x.1 == s) {
                    continue;
                }
                let tri = bvh.slot(s);
                let m = (0..3)
                    .map(|m| {
                        if r[m].1 == s {
                            r[m].0
                        } else {
                            dist2(p[m], closest_on_triangle(p[m], tri)).sqrt()
                        }
                    })
                    .fold(0.0, f64::max);
                b = b.min(m);
            }
        }
        worst = worst.max(b);
    };
    for i in 0..n {
        for j in 0..n - i {
            cell([(i, j), (i + 1, j), (i, j + 1)]);
            if i + j + 2 <= n {
                cell([(i + 1, j), (i + 1, j + 1), (i, j + 1)]);
            }
        }
    }
    worst
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
    /// An upper bound on the true distance: per grid cell, `max` plus the samples' covering
    /// radius, or where that is over the limit, the cell's corners' distance to one triangle.
    pub bound: f64,
    /// Per side-label pair, the largest sampled distance.
    pub per_sheet: Vec<([u32; 2], f64)>,
    /// The farthest sample of each triangle farther than the flag distance or whose bound stays
    /// over the limit.
    pub far: Vec<Far>,
    /// Number of samples measured.
    pub n_samples: usize,
}

/// A triangle more than [`GRID_STEPS`] sample steps long is measured in pieces (longest-edge
/// bisection, until each piece is at most that many steps long and no longer than
/// [`PIECE_ASPECT`] times its height): the grid's samples grow with the square of a triangle's
/// longest edge however thin it is, and a needle 200 long and 0.4 wide, 1,000 steps, held
/// 500,000 of them, its pieces of about 3 × 0.4 some 17,000. Other triangles are one piece, as
/// before.
fn pieces(c: [P3; 3], spacing: f64) -> Vec<[P3; 3]> {
    // The longest edge (the last of equals) and its squared length.
    let longest = |t: &[P3; 3]| {
        let e = [0, 1, 2].map(|k| dist2(t[k], t[(k + 1) % 3]));
        let k = (0..3).fold(0, |m, i| if e[i] >= e[m] { i } else { m });
        (k, e[k])
    };
    if longest(&c).1.sqrt() / spacing <= GRID_STEPS as f64 {
        return vec![c];
    }
    let mut out = Vec::new();
    let mut stack = vec![c];
    while let Some(t) = stack.pop() {
        let (k, l2) = longest(&t);
        let steps = l2.sqrt() / spacing;
        // Twice the area over the longest edge is the height onto it.
        let fat = l2 <= PIECE_ASPECT * norm(cross(sub(t[1], t[0]), sub(t[2], t[0])));
        if (steps <= GRID_STEPS as f64 && fat) || steps <= 1.0 {
            out.push(t);
            continue;
        }
        let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        let m = [0, 1, 2].map(|x| 0.5 * (a[x] + b[x]));
        stack.push([m, b, c]);
        stack.push([a, m, c]);
    }
    out
}

/// Triangles with more sample steps along their longest edge than this are measured in pieces.
const GRID_STEPS: usize = 64;

/// A piece is no longer than this many times its height onto its longest edge.
const PIECE_ASPECT: f64 = 8.0;

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
        bound: f64,
        far: Option<Far>,
        n: usize,
    }
    // Per grid point, row by row: an upper bound on its distance and the other surface's
    // triangle (slot) within it, if one was found (one buffer a job, not one a triangle).
    let per: Vec<Per> = (0..tris.len())
        .into_par_iter()
        .map_init(Vec::new, |grid: &mut Vec<(f64, u32)>, t| {
            if alive.is_some_and(|a| !a[t]) {
                return Per {
                    max: 0.0,
                    bound: 0.0,
                    far: None,
                    n: 0,
                };
            }
            let c = tris[t].map(|v| pts[v as usize]);
            let Some(bvh) = to.get(sides[t]) else {
                return Per {
                    max: f64::INFINITY,
                    bound: f64::INFINITY,
                    far: None,
                    n: 0,
                };
            };
            let mut max = floor;
            let mut far: Option<Far> = None;
            let mut count = 0;
            let mut hint = Hint::default();
            let mut bound_all = 0.0f64;
            for c in pieces(c, spacing) {
                let longest = (0..3)
                    .map(|k| dist2(c[k], c[(k + 1) % 3]))
                    .fold(0.0, f64::max)
                    .sqrt();
                let mut n = ((longest / spacing).ceil() as usize).max(1);
                let fine_n = ((longest / fine).ceil() as usize).max(1);
                let bound = 'again: loop {
                    grid.clear();
                    for i in 0..=n {
                        // An upper bound on the distance at the previous sample of the row: the
                        // distance is 1-Lipschitz, so a sample that cannot exceed the maximum so far
                        // is not measured.
                        let mut prev: Option<(P3, f64)> = None;
                        for j in 0..=n - i {
                            let p = grid_point(&c, n, i, j);
                            count += 1;
                            if let Some((pp, pd)) = prev {
                                let ub = pd + dist2(p, pp).sqrt();
                                if ub <= max {
                                    prev = Some((p, ub));
                                    grid.push((ub, NO_SLOT));
                                    continue;
                                }
                            }
                            // Only a sample farther than the maximum so far matters.
                            if let Some((d2, slot)) = bvh.first_within_slot(p, max * max, &mut hint)
                            {
                                prev = Some((p, max));
                                grid.push((d2.sqrt(), slot));
                                continue;
                            }
                            let Some(q) = bvh.closest(p) else {
                                grid.push((f64::INFINITY, NO_SLOT));
                                continue;
                            };
                            let d = q.d2.sqrt();
                            prev = Some((p, d));
                            grid.push((d, q.slot));
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
                    let step = longest / n as f64;
                    let mut bound = max + covering(step);
                    if bound > limit {
                        bound = cells_bound(bvh, &c, n, step, grid, limit);
                    }
                    // Refine just enough for the bound to prove the limit (if it can).
                    if bound > limit && fine_n > n && max < limit {
                        let need = (longest / ((limit - max) * 3f64.sqrt())).ceil() as usize;
                        n = need.max(2 * n).min(fine_n);
                        continue 'again;
                    }
                    break bound;
                };
                bound_all = bound_all.max(bound);
            }
            let bound = bound_all;
            // Listed when farther than the flag, or when the finest samples cannot prove the
            // limit (the bound is then over it though every sample is within).
            let listed = max > flag || bound > limit;
            Per {
                max,
                bound,
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
        out.bound = out.bound.max(p.bound);
        out.n_samples += p.n;
        if let Some(f) = p.far {
            out.far.push(f);
        }
    }
    out.per_sheet = per_sheet;
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::tests::uv_sphere;

    fn index(pts: &[P3], tris: &[[u32; 3]]) -> PatchIndex {
        PatchIndex::new(pts, tris, &vec![[0, 1]; tris.len()], None)
    }

    /// A triangle 0.3 above a far larger one: its samples, under 5 apart, prove no better than
    /// about 3 by the Lipschitz bound, and no finer samples are allowed; its cells' corners
    /// are all 0.3 from that one triangle, which proves 0.3 over the whole of it.
    #[test]
    fn cells_near_one_triangle_are_proven_by_convexity() {
        let pts = vec![[0.0, 0.0, 0.3], [10.0, 0.0, 0.3], [0.0, 10.0, 0.3]];
        let below = vec![
            [-100.0, -100.0, 0.0],
            [300.0, -100.0, 0.0],
            [-100.0, 300.0, 0.0],
        ];
        let to = index(&below, &[[0, 1, 2]]);
        let one = |limit: f64| {
            one_sided(
                &pts,
                &[[0, 1, 2]],
                &[[0, 1]],
                None,
                &to,
                5.0,
                5.0,
                limit,
                limit,
                0.0,
            )
        };
        let loose = one(f64::INFINITY);
        assert!((loose.max - 0.3).abs() < 1e-12);
        assert!(loose.bound > 1.0, "{}", loose.bound);
        let tight = one(0.35);
        assert!((tight.bound - 0.3).abs() < 1e-12, "{}", tight.bound);
        assert!(tight.far.is_empty());
    }

    /// The bound holds: two spheres of different resolution and radius, measured with a limit
    /// under the Lipschitz bound (so cells are proven by convexity where they can be), against
    /// samples fifty times denser.
    #[test]
    fn the_cells_bound_is_an_upper_bound() {
        let a = uv_sphere(1.0, [0.0; 3], 24, 12);
        let b = uv_sphere(1.02, [0.01, 0.0, 0.0], 17, 9);
        for (from, to) in [(&a, &b), (&b, &a)] {
            let idx = index(&to.points, &to.triangles);
            let sides = vec![[0, 1]; from.triangles.len()];
            let m = |spacing: f64, limit: f64| {
                one_sided(
                    &from.points,
                    &from.triangles,
                    &sides,
                    None,
                    &idx,
                    spacing,
                    spacing,
                    limit,
                    limit,
                    0.0,
                )
            };
            let dense = m(0.004, f64::INFINITY);
            let coarse = m(0.2, f64::INFINITY);
            let cells = m(0.2, 0.5 * (coarse.bound + dense.max));
            assert!(
                cells.bound < coarse.bound,
                "{} {}",
                cells.bound,
                coarse.bound
            );
            assert!(cells.bound >= dense.max, "{} < {}", cells.bound, dense.max);
        }
    }
}
