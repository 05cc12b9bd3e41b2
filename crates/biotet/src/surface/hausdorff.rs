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
//! A cell neither proves is sampled finer on its own, recursively (`Probe::cell`), so the
//! samples gather where the distance comes near the limit. The largest bound over all cells is
//! [`Sided::bound`].
//!
//! Parallel over triangles; the maximum does not depend on the order, so the result is the same
//! on any number of threads.

use rayon::prelude::*;

use super::bvh::{Bvh, Hint, PatchIndex, closest_on_triangle, dist2, longest_edge};
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

/// Measures the distance from one triangle's samples to the other surface: the largest found,
/// where, and how many samples.
struct Probe<'a> {
    bvh: &'a Bvh,
    triangle: u32,
    hint: Hint,
    max: f64,
    far: Option<Far>,
    count: usize,
}

impl Probe<'_> {
    /// An upper bound on the distance at `p` and the other surface's triangle (slot) within it:
    /// the distance to the first triangle found within the maximum so far, else the exact
    /// distance (a new maximum when over it).
    fn measure(&mut self, p: P3) -> (f64, u32) {
        self.count += 1;
        let r2 = self.max * self.max;
        if let Some((d2, slot)) = self.bvh.first_within_slot(p, r2, &mut self.hint) {
            return (d2.sqrt(), slot);
        }
        let Some(q) = self.bvh.closest(p) else {
            return (f64::INFINITY, NO_SLOT);
        };
        let d = q.d2.sqrt();
        if d > self.max {
            self.max = d;
            self.far = Some(Far {
                triangle: self.triangle,
                point: p,
                distance: d,
                nearest: q.triangle,
            });
        }
        (d, q.slot)
    }

    /// The grid of `n` steps on triangle `c` (row by row: see [`grid_index`]), each point's
    /// upper bound and triangle in `grid`. A point that cannot exceed the maximum so far (the
    /// distance is 1-Lipschitz: the previous point of its row plus the step) is not measured.
    /// With `corners` (the values at `c`), those three are not measured again.
    fn grid(
        &mut self,
        c: &[P3; 3],
        n: usize,
        corners: Option<[(f64, u32); 3]>,
        grid: &mut Vec<(f64, u32)>,
    ) {
        grid.clear();
        for i in 0..=n {
            let mut prev: Option<(P3, (f64, u32))> = None;
            for j in 0..=n - i {
                let p = grid_point(c, n, i, j);
                let known = corners.and_then(|r| match (i, j) {
                    (i, 0) if i == n => Some(r[0]),
                    (0, j) if j == n => Some(r[1]),
                    (0, 0) => Some(r[2]),
                    _ => None,
                });
                let v = if let Some(v) = known {
                    v
                } else {
                    match prev {
                        Some((pp, (pd, slot))) if pd + dist2(p, pp).sqrt() <= self.max => {
                            self.count += 1;
                            (pd + dist2(p, pp).sqrt(), slot)
                        }
                        _ => self.measure(p),
                    }
                };
                prev = Some((p, v));
                grid.push(v);
            }
        }
    }

    /// The largest bound of the cells of the grid of `n` steps on `c` whose values are `grid`
    /// ([`Self::grid`]), each by [`Self::cell`].
    fn cells(
        &mut self,
        c: &[P3; 3],
        n: usize,
        grid: &[(f64, u32)],
        limit: f64,
        fine: f64,
        budget: &mut usize,
    ) -> f64 {
        // Every cell is `c` scaled by 1/n: the Lipschitz bound needs no corner points.
        let h = covering(longest_edge(c) / n as f64);
        let mut worst = 0.0f64;
        for i in 0..n {
            for j in 0..n - i {
                let mut v = [[(i, j), (i + 1, j), (i, j + 1)]; 2];
                let two = i + j + 2 <= n;
                if two {
                    v[1] = [(i + 1, j), (i + 1, j + 1), (i, j + 1)];
                }
                for v in &v[..1 + two as usize] {
                    let r = v.map(|(i, j)| grid[grid_index(n, i, j)]);
                    let lip = r.iter().map(|x| x.0).fold(0.0, f64::max) + h;
                    let b = if lip <= limit {
                        lip
                    } else {
                        let p = v.map(|(i, j)| grid_point(c, n, i, j));
                        self.cell(p, r, limit, fine, budget)
                    };
                    worst = worst.max(b);
                }
            }
        }
        worst
    }

    /// An upper bound on the distance over the cell `p`, whose corners' bounds and triangles
    /// are `r` (from [`Self::measure`]): its largest corner bound plus its covering radius (the
    /// Lipschitz bound); where that is over `limit`, the largest distance of its corners to one
    /// triangle found at one of them (the distance to a triangle is convex, so over the cell
    /// it is largest at a corner); and where that is over too, the bound of a finer grid on
    /// the cell, fine enough for its covering radius to fit under the limit with the corners'
    /// values (2 to [`MAX_SPLIT`] steps), cell by cell again. Only the cells that cannot prove
    /// the limit are sampled finer, so the samples gather where the distance comes near it
    /// (along the other surface's edges and vertices), and a small tolerance costs what those
    /// lines cost, not what a uniformly finer grid would. Splitting stops at cells shorter than
    /// `2 fine`, when the Lipschitz bound could not prove the limit even at that size, when
    /// `budget` (samples) runs out, or once a sample is over the limit (the triangle is beyond
    /// it anyway).
    fn cell(
        &mut self,
        p: [P3; 3],
        r: [(f64, u32); 3],
        limit: f64,
        fine: f64,
        budget: &mut usize,
    ) -> f64 {
        let longest = longest_edge(&p);
        let top = r.iter().map(|x| x.0).fold(0.0, f64::max);
        let lip = top + covering(longest);
        if lip <= limit {
            return lip;
        }
        let mut b = lip;
        for (k, &(_, s)) in r.iter().enumerate() {
            if s == NO_SLOT || r[..k].iter().any(|x| x.1 == s) {
                continue;
            }
            let tri = self.bvh.slot(s);
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
        // The cell size at which the covering radius fits in the margin the corners leave.
        let enough = 3f64.sqrt() * (limit - top);
        if b <= limit || self.max > limit || longest < 2.0 * fine || enough < fine {
            return b;
        }
        let n = (longest / enough).ceil().clamp(2.0, MAX_SPLIT as f64) as usize;
        let new = (n + 1) * (n + 2) / 2 - 3;
        if *budget < new {
            return b;
        }
        *budget -= new;
        let mut grid = Vec::with_capacity(new + 3);
        self.grid(&p, n, Some(r), &mut grid);
        self.cells(&p, n, &grid, limit, fine, budget)
    }
}

/// The place of grid point `(i, j)` of an `n`-step grid, row by row (row `i` holds `n + 1 - i`
/// points).
fn grid_index(n: usize, i: usize, j: usize) -> usize {
    i * (n + 1) - i * i.saturating_sub(1) / 2 + j
}

/// The most steps a cell is split into along an edge at once.
const MAX_SPLIT: usize = 8;

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
    /// radius, or where that is over the limit, the cell's corners' distance to one triangle,
    /// or the bound of its finer cells.
    pub bound: f64,
    /// Per side-label pair, the largest sampled distance.
    pub per_sheet: Vec<([u32; 2], f64)>,
    /// The farthest sample of each triangle farther than the flag distance or whose bound stays
    /// over the limit.
    pub far: Vec<Far>,
    /// Number of samples measured (with [`one_sided_reusing`], those behind the measures kept too).
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

/// A piece is sampled again uniformly up to this many times its grid's steps; beyond, its
/// unproven cells are split.
const UNIFORM_STEPS: usize = 2;

/// The samples a piece's unproven cells may add by splitting, per sample of its grid.
const SPLIT_SAMPLES: usize = 64;

/// The one-sided distance from the triangles `tris` over `pts` (those with `alive[t]`, when
/// given) to `to`, on a grid of step at most `spacing`. Where a grid cell's bound (its sampled
/// maximum plus covering radius, or its corners' distance to one triangle) exceeds `limit`, the
/// cell is split, down to cells of about `fine` (`Probe::cell`; pass `limit = f64::INFINITY`
/// for the grid alone). Triangles farther than `flag`, or whose bound stays over `limit`, are listed in
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
    let s = Sampling {
        spacing,
        fine,
        limit,
        flag,
        floor,
    };
    one_sided_reusing((pts, tris, sides, alive), to, &s, |_| None).0
}

/// How [`one_sided`] samples (its arguments of the same names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sampling {
    /// Grid step at most this.
    pub spacing: f64,
    /// Cells split down to about this.
    pub fine: f64,
    /// The distance to prove.
    pub limit: f64,
    /// Triangles farther than this are listed.
    pub flag: f64,
    /// Samples proven no farther than this are not measured.
    pub floor: f64,
}

/// Triangles as points, corners, side labels and (optionally) which of them are in.
pub type Triangles<'s> = (&'s [P3], &'s [[u32; 3]], &'s [[u32; 2]], Option<&'s [bool]>);

/// One triangle's measure ([`one_sided_reusing`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Per {
    /// Its largest sampled distance.
    pub max: f64,
    /// An upper bound on its distance.
    pub bound: f64,
    /// Its farthest sample, when listed in [`Sided::far`].
    pub far: Option<Far>,
    /// Its samples.
    pub n: usize,
}

/// [`one_sided`], with each triangle's measure taken from `reuse(t)` where it gives one (a
/// measure of the same triangle against the same neighbourhood, kept from before), and the
/// measures of all triangles returned to be kept.
pub fn one_sided_reusing(
    (pts, tris, sides, alive): Triangles<'_>,
    to: &PatchIndex,
    s: &Sampling,
    reuse: impl Fn(usize) -> Option<Per> + Sync,
) -> (Sided, Vec<Per>) {
    let Sampling {
        spacing,
        fine,
        limit,
        flag,
        floor,
    } = *s;
    // Per grid point, row by row: an upper bound on its distance and the other surface's
    // triangle (slot) within it, if one was found (one buffer a job, not one a triangle).
    let per: Vec<Per> = (0..tris.len())
        .into_par_iter()
        .map_init(Vec::new, |grid: &mut Vec<(f64, u32)>, t| {
            if let Some(p) = reuse(t) {
                return p;
            }
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
            let mut probe = Probe {
                bvh,
                triangle: t as u32,
                hint: Hint::default(),
                max: floor,
                far: None,
                count: 0,
            };
            let mut bound_all = 0.0f64;
            for c in pieces(c, spacing) {
                let longest = longest_edge(&c);
                let base = ((longest / spacing).ceil() as usize).max(1);
                let mut n = base;
                // Where the grid cannot prove the limit and a grid fine enough for its
                // covering radius to fit the margin is cheap, the whole piece is sampled again
                // that finely (on the brain models, cheaper than splitting cell by cell); else
                // its unproven cells are split.
                let bound = loop {
                    probe.grid(&c, n, None, grid);
                    let bound = probe.max + covering(longest / n as f64);
                    if bound <= limit {
                        break bound;
                    }
                    let need = if probe.max < limit {
                        (longest / ((limit - probe.max) * 3f64.sqrt())).ceil() as usize
                    } else {
                        0
                    };
                    let uniform = need > n && need <= UNIFORM_STEPS * base;
                    let mut budget = if uniform {
                        0
                    } else {
                        SPLIT_SAMPLES * grid.len()
                    };
                    let bound = probe.cells(&c, n, grid, limit, fine, &mut budget);
                    if bound <= limit || !uniform {
                        break bound;
                    }
                    n = need.max(2 * n);
                };
                bound_all = bound_all.max(bound);
            }
            let bound = bound_all;
            // Listed when farther than the flag, or when the finest samples cannot prove the
            // limit (the bound is then over it though every sample is within).
            let listed = probe.max > flag || bound > limit;
            Per {
                max: probe.max,
                bound,
                far: probe.far.filter(|_| listed),
                n: probe.count,
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
    (out, per)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SurfaceMesh;
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

    /// `from`'s distance to `to` (one sheet), as [`one_sided`] measures it.
    fn measured(
        from: &SurfaceMesh,
        to: &SurfaceMesh,
        spacing: f64,
        fine: f64,
        limit: f64,
    ) -> Sided {
        let idx = index(&to.points, &to.triangles);
        let sides = vec![[0, 1]; from.triangles.len()];
        one_sided(
            &from.points,
            &from.triangles,
            &sides,
            None,
            &idx,
            spacing,
            fine,
            limit,
            limit,
            0.0,
        )
    }

    /// Two spheres of different resolution and radius, each way.
    fn sphere_pairs() -> [(SurfaceMesh, SurfaceMesh); 2] {
        let a = uv_sphere(1.0, [0.0; 3], 24, 12);
        let b = uv_sphere(1.02, [0.01, 0.0, 0.0], 17, 9);
        [(a.clone(), b.clone()), (b, a)]
    }

    /// The bound holds: two spheres, measured with a limit under the Lipschitz bound (so cells
    /// are proven by convexity where they can be), against samples fifty times denser.
    #[test]
    fn the_cells_bound_is_an_upper_bound() {
        for (from, to) in sphere_pairs() {
            let m = |spacing: f64, limit: f64| measured(&from, &to, spacing, spacing, limit);
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

    /// A limit 1% above the true distance is proven by sampling finer only where the distance
    /// comes near it: far fewer samples than a uniform grid fifty times denser than the first
    /// one takes (a uniform grid fine enough for the Lipschitz bound to prove it would take
    /// thousands of times more), and the bound is still above the dense grid's maximum.
    #[test]
    fn a_tight_limit_is_proven_where_the_distance_comes_near_it() {
        for (from, to) in sphere_pairs() {
            let dense = measured(&from, &to, 0.004, 0.004, f64::INFINITY);
            let limit = 1.01 * dense.max;
            let tight = measured(&from, &to, 0.2, 0.2 / 1024.0, limit);
            assert!(tight.bound <= limit, "{} > {limit}", tight.bound);
            assert!(tight.bound >= dense.max, "{} < {}", tight.bound, dense.max);
            assert!(tight.far.is_empty());
            assert!(
                tight.n_samples < dense.n_samples / 4,
                "{} samples, the dense grid {}",
                tight.n_samples,
                dense.n_samples
            );
        }
    }
}
