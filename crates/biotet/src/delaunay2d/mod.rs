//! 2D Delaunay triangulation: incremental Bowyer–Watson insertion with the exact predicates and
//! Simulation of Simplicity, the plane counterpart of [`crate::delaunay`] (dissertation fig. 1.1,
//! fig. 2.10: the nodes of the template go to a Delaunay routine).
//!
//! The structure is the 3D one cut down by a dimension:
//! - **Order.** Points are sorted along a 2D Hilbert curve and dealt into BRIO rounds
//!   (`delaunay::order::brio`, the same rounds and seed rule as in 3D), so each walk is
//!   short and the expected work is linear.
//! - **Infinite vertex.** Every hull edge `ab` carries a ghost triangle `(a, b, ∞)`, so points
//!   outside the hull need no special case. A ghost conflicts with a point `p` strictly outside
//!   its hull edge; when `p` is on the line of the edge, it conflicts exactly when the finite
//!   triangle behind the edge does (the 2D case of the rule derived in [`crate::delaunay`]: the
//!   ghost's "circle" is the limit of circles through `a`, `b` and a point going to infinity,
//!   which meets the line in the segment `ab`, perturbed the same way).
//! - **Walk and cavity.** A remembering stochastic walk by exact [`orient2d`] finds a triangle
//!   containing `p` (or a ghost seeing it); the cavity is grown over neighbours in conflict by
//!   [`incircle_sos`] and replaced by the fan of `p` to its boundary.
//!
//! # Which triangulation
//! Vertex `i` is input point `i` (no renumbering). Cocircular points (lattices, by design) get the
//! unique Delaunay triangulation of the points lifted to `|p_i|² + ε_i`, `ε_i` growing with `i`
//! (see [`incircle_sos`]): it depends on the point set and the numbering only, not on the
//! insertion order, and it has no flat triangle (a point strictly inside a segment lifts below
//! the chord of its endpoints).
//!
//! Exact duplicate points are refused ([`Delaunay2dError::Duplicate`]): in a PSLG two copies of a
//! point would be two nodes at one place.

use crate::delaunay::order::{brio, radix_sort};
use crate::geom::predicates::{Sign, in_exact_range, incircle_sos, orient2d};
use crate::mesh::tet::NO_NEIGHBOR;
use crate::mesh::tri::TriMesh;

/// The infinite vertex.
pub const GHOST: u32 = u32::MAX;
/// Marks a free triangle slot (in its first vertex).
const FREE: u32 = u32::MAX - 1;
/// BRIO seed (the same as 3D's, any fixed value would do).
const SEED: u64 = 0x5EED_B107;

/// Why a triangulation could not be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Delaunay2dError {
    /// A coordinate is NaN or infinite.
    #[error("point {index} has a non-finite coordinate")]
    NonFinite {
        /// Index of the point.
        index: usize,
    },
    /// A coordinate is outside the exact range of the predicates.
    #[error(
        "point {index} has a coordinate outside the exact range (0, or magnitude between 7.0e-46 \
         and 1e50): rescale the input"
    )]
    OutOfRange {
        /// Index of the point.
        index: usize,
    },
    /// Two points have exactly the same coordinates.
    #[error("points {first} and {second} have the same coordinates")]
    Duplicate {
        /// The smaller index.
        first: usize,
        /// The larger index.
        second: usize,
    },
    /// Fewer than three points.
    #[error("only {0} points: a triangulation needs at least 3")]
    TooFewPoints(usize),
    /// All points lie on one line.
    #[error("all points are collinear: no triangulation exists")]
    Collinear,
    /// More points than 32-bit indices hold.
    #[error("too many points for 32-bit indices")]
    TooLarge,
}

/// A 2D Delaunay triangulation closed by ghost triangles on the hull.
#[derive(Debug, Clone)]
pub struct Delaunay2d {
    points: Vec<[f64; 2]>,
    /// Vertices of each slot, counter-clockwise; [`GHOST`] for the infinite vertex; a free slot
    /// has `FREE` first.
    tri: Vec<[u32; 3]>,
    /// Neighbour across the edge opposite each local vertex.
    nbr: Vec<[u32; 3]>,
    free: Vec<u32>,
    last: u32,
    rng: u32,
    // Scratch reused by every insertion.
    mark: Vec<u32>,
    epoch: u32,
    cavity: Vec<u32>,
    boundary: Vec<(u32, u32, u32)>,
}

/// Hilbert index of a cell on a 2¹⁶ × 2¹⁶ grid.
fn hilbert_key2(mut x: u32, mut y: u32) -> u64 {
    let n = 1u32 << 16;
    let mut d = 0u64;
    let mut s = n / 2;
    while s > 0 {
        let rx = u32::from(x & s > 0);
        let ry = u32::from(y & s > 0);
        d += u64::from(s) * u64::from(s) * u64::from((3 * rx) ^ ry);
        if ry == 0 {
            if rx == 1 {
                x = n - 1 - x;
                y = n - 1 - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        s /= 2;
    }
    d
}

/// Input indices in insertion order (Hilbert sort, then BRIO rounds); duplicates refused.
fn insertion_order(points: &[[f64; 2]]) -> Result<Vec<u32>, Delaunay2dError> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let ext = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let cells = 65536.0;
    let scale = if ext > 0.0 { cells / ext } else { 0.0 };
    let cell = |p: [f64; 2], k: usize| (((p[k] - lo[k]) * scale) as u32).min(65535);
    let mut keys: Vec<u64> = points
        .iter()
        .enumerate()
        .map(|(i, &p)| (hilbert_key2(cell(p, 0), cell(p, 1)) << 32) | i as u64)
        .collect();
    radix_sort(&mut keys);
    // Duplicates share a Hilbert cell: compare within runs of equal keys.
    let mut i = 0;
    while i < keys.len() {
        let mut j = i + 1;
        while j < keys.len() && keys[j] >> 32 == keys[i] >> 32 {
            j += 1;
        }
        if j - i > 1 {
            let mut run: Vec<usize> = keys[i..j].iter().map(|&k| k as u32 as usize).collect();
            run.sort_unstable_by(|&a, &b| {
                let (pa, pb) = (points[a].map(|c| c + 0.0), points[b].map(|c| c + 0.0));
                pa[0]
                    .total_cmp(&pb[0])
                    .then(pa[1].total_cmp(&pb[1]))
                    .then(a.cmp(&b))
            });
            for w in run.windows(2) {
                if points[w[0]].map(|c| c + 0.0) == points[w[1]].map(|c| c + 0.0) {
                    return Err(Delaunay2dError::Duplicate {
                        first: w[0].min(w[1]),
                        second: w[0].max(w[1]),
                    });
                }
            }
        }
        i = j;
    }
    let sorted: Vec<u32> = keys.iter().map(|&k| k as u32).collect();
    Ok(brio(sorted, SEED))
}

impl Delaunay2d {
    /// The Delaunay triangulation of `points` (at least three, distinct, not all collinear, every
    /// coordinate finite and in the exact range of the predicates).
    pub fn new(points: Vec<[f64; 2]>) -> Result<Delaunay2d, Delaunay2dError> {
        for (index, p) in points.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(Delaunay2dError::NonFinite { index });
            }
            if !p.iter().all(|&c| in_exact_range(c)) {
                return Err(Delaunay2dError::OutOfRange { index });
            }
        }
        if points.len() >= (u32::MAX / 4) as usize {
            return Err(Delaunay2dError::TooLarge);
        }
        if points.len() < 3 {
            return Err(Delaunay2dError::TooFewPoints(points.len()));
        }
        let mut seq = insertion_order(&points)?;
        // The first triangle: the first two points and the first point off their line.
        let (a, b) = (seq[0], seq[1]);
        let k = (2..seq.len())
            .find(|&k| {
                orient2d(
                    points[a as usize],
                    points[b as usize],
                    points[seq[k] as usize],
                ) != Sign::Zero
            })
            .ok_or(Delaunay2dError::Collinear)?;
        let c = seq.remove(k);
        seq.insert(2, c);
        let n = points.len();
        let mut dt = Delaunay2d {
            points,
            tri: Vec::with_capacity(2 * n + 8),
            nbr: Vec::with_capacity(2 * n + 8),
            free: Vec::new(),
            last: 0,
            rng: 0x2545_F491,
            mark: Vec::with_capacity(2 * n + 8),
            epoch: 0,
            cavity: Vec::new(),
            boundary: Vec::new(),
        };
        dt.first_triangle(a, b, c);
        for &v in &seq[3..] {
            dt.insert(v);
        }
        Ok(dt)
    }

    fn p(&self, v: u32) -> [f64; 2] {
        self.points[v as usize]
    }

    /// The finite triangle `abc` (made counter-clockwise) and its three ghosts.
    fn first_triangle(&mut self, a: u32, b: u32, c: u32) {
        let (a, b, c) = if orient2d(self.p(a), self.p(b), self.p(c)) == Sign::Positive {
            (a, b, c)
        } else {
            (a, c, b)
        };
        // 0 = abc; 1 = ghost on bc, 2 = ghost on ca, 3 = ghost on ab.
        self.tri = vec![[a, b, c], [c, b, GHOST], [a, c, GHOST], [b, a, GHOST]];
        // Ghost (c, b, ∞): opposite c is (b, ∞) shared with ghost (b, a, ∞)'s edge (∞, b);
        // opposite b is (∞, c) shared with ghost (a, c, ∞)'s edge (c, ∞).
        self.nbr = vec![[1, 2, 3], [3, 2, 0], [1, 3, 0], [2, 1, 0]];
        self.mark = vec![0; 4];
        self.last = 0;
    }

    fn alloc(&mut self) -> u32 {
        if let Some(t) = self.free.pop() {
            t
        } else {
            self.tri.push([FREE; 3]);
            self.nbr.push([NO_NEIGHBOR; 3]);
            self.mark.push(0);
            (self.tri.len() - 1) as u32
        }
    }

    fn is_ghost(&self, t: u32) -> bool {
        self.tri[t as usize].contains(&GHOST)
    }

    /// Does triangle `t` conflict with vertex `v` (is `v` inside its perturbed circumcircle)?
    fn conflict(&self, t: u32, v: u32) -> bool {
        let tv = self.tri[t as usize];
        let p = self.p(v);
        if let Some(j) = tv.iter().position(|&x| x == GHOST) {
            let (a, b) = (tv[(j + 1) % 3], tv[(j + 2) % 3]);
            return match orient2d(self.p(a), self.p(b), p) {
                Sign::Positive => true,
                Sign::Negative => false,
                // On the hull line: as the finite triangle behind the edge.
                Sign::Zero => self.finite_conflict(self.nbr[t as usize][j], v),
            };
        }
        self.finite_conflict(t, v)
    }

    fn finite_conflict(&self, t: u32, v: u32) -> bool {
        let [a, b, c] = self.tri[t as usize];
        incircle_sos([self.p(a), self.p(b), self.p(c), self.p(v)], [a, b, c, v]) == Sign::Positive
    }

    /// A finite triangle containing vertex `v`'s point (closed), or a ghost whose hull edge sees it.
    fn locate(&mut self, v: u32) -> u32 {
        let p = self.p(v);
        let mut t = self.last;
        if self.tri[t as usize][0] == FREE {
            t = (0..self.tri.len() as u32)
                .find(|&s| self.tri[s as usize][0] != FREE)
                .unwrap_or(0);
        }
        if self.is_ghost(t) {
            let j = self.tri[t as usize]
                .iter()
                .position(|&x| x == GHOST)
                .unwrap_or(0);
            t = self.nbr[t as usize][j];
        }
        'walk: loop {
            let tv = self.tri[t as usize];
            if tv.contains(&GHOST) {
                return t;
            }
            self.rng ^= self.rng << 13;
            self.rng ^= self.rng >> 17;
            self.rng ^= self.rng << 5;
            let s = (self.rng % 3) as usize;
            for k in 0..3 {
                let i = (s + k) % 3;
                let (a, b) = (tv[(i + 1) % 3], tv[(i + 2) % 3]);
                if orient2d(self.p(a), self.p(b), p) == Sign::Negative {
                    t = self.nbr[t as usize][i];
                    continue 'walk;
                }
            }
            return t;
        }
    }

    /// Insert vertex `v` (its point distinct from every inserted one).
    fn insert(&mut self, v: u32) {
        let start = self.locate(v);
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.mark.iter_mut().for_each(|m| *m = 0);
            self.epoch = 1;
        }
        let epoch = self.epoch;
        let mut cavity = std::mem::take(&mut self.cavity);
        let mut boundary = std::mem::take(&mut self.boundary);
        cavity.clear();
        boundary.clear();
        cavity.push(start);
        self.mark[start as usize] = epoch;
        let mut k = 0;
        while k < cavity.len() {
            let c = cavity[k];
            k += 1;
            for i in 0..3 {
                let n = self.nbr[c as usize][i];
                if self.mark[n as usize] == epoch {
                    continue;
                }
                if self.conflict(n, v) {
                    self.mark[n as usize] = epoch;
                    cavity.push(n);
                } else {
                    let tv = self.tri[c as usize];
                    boundary.push((tv[(i + 1) % 3], tv[(i + 2) % 3], n));
                }
            }
        }
        // Fan of v to the cavity boundary: triangle (u, w, v) for each boundary edge (u, w).
        let mut new: Vec<(u32, u32)> = Vec::with_capacity(boundary.len());
        let old: Vec<u32> = cavity.clone();
        for (slot, &(u, w, n)) in boundary.iter().enumerate() {
            let t = if slot < old.len() {
                old[slot]
            } else {
                self.alloc()
            };
            self.tri[t as usize] = [u, w, v];
            self.mark[t as usize] = 0;
            // The outside neighbour pointed at a cavity triangle across (w, u).
            let nb = &mut self.nbr[n as usize];
            let tn = self.tri[n as usize];
            for j in 0..3 {
                if tn[(j + 1) % 3] == w && tn[(j + 2) % 3] == u {
                    nb[j] = t;
                }
            }
            self.nbr[t as usize][2] = n;
            new.push((u, t));
        }
        for &c in old.iter().skip(boundary.len()) {
            self.tri[c as usize] = [FREE; 3];
            self.free.push(c);
        }
        // Link the fan: (u, w, v) meets (w, x, v) across (w, v) and (z, u, v) across (v, u).
        new.sort_unstable();
        for &(u, t) in &new {
            let w = self.tri[t as usize][1];
            let i = new
                .binary_search_by(|&(s, _)| s.cmp(&w))
                .expect("the cavity boundary is one cycle");
            let tw = new[i].1;
            self.nbr[t as usize][0] = tw;
            self.nbr[tw as usize][1] = t;
            if u != GHOST && w != GHOST {
                self.last = t;
            }
        }
        self.cavity = cavity;
        self.boundary = boundary;
    }

    /// The points (vertex `i` is input point `i`).
    pub fn points(&self) -> &[[f64; 2]] {
        &self.points
    }

    /// Number of finite triangles.
    pub fn n_triangles(&self) -> usize {
        self.finite().count()
    }

    fn finite(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.tri.len()).filter(|&t| {
            let v = self.tri[t];
            v[0] != FREE && !v.contains(&GHOST)
        })
    }

    /// The finite triangles as a [`TriMesh`] (label 1, hull edges without neighbour), in slot
    /// order: deterministic for given points.
    pub fn to_tri_mesh(&self) -> TriMesh {
        let mut m = self.tri_mesh_without_points();
        m.points = self.points.clone();
        m
    }

    fn tri_mesh_without_points(&self) -> TriMesh {
        let mut index = vec![NO_NEIGHBOR; self.tri.len()];
        let mut triangles = Vec::new();
        for t in self.finite() {
            index[t] = triangles.len() as u32;
            triangles.push(self.tri[t]);
        }
        let neighbors = self
            .finite()
            .map(|t| self.nbr[t].map(|n| index[n as usize]))
            .collect();
        TriMesh {
            points: Vec::new(),
            labels: vec![1; triangles.len()],
            triangles,
            neighbors,
        }
    }

    /// Consume the triangulation into a [`TriMesh`] (see [`Delaunay2d::to_tri_mesh`]).
    pub fn into_tri_mesh(self) -> TriMesh {
        let mut m = self.tri_mesh_without_points();
        m.points = self.points;
        m
    }
}

/// The Delaunay triangulation of `points` as a [`TriMesh`] (label 1 everywhere).
pub fn triangulate(points: Vec<[f64; 2]>) -> Result<TriMesh, Delaunay2dError> {
    Ok(Delaunay2d::new(points)?.into_tri_mesh())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hilbert2_is_continuous() {
        let mut cells: Vec<(u64, [u32; 2])> = Vec::new();
        for x in 0..16 {
            for y in 0..16 {
                cells.push((hilbert_key2(x, y), [x, y]));
            }
        }
        cells.sort_unstable();
        for w in cells.windows(2) {
            let d = w[0].1[0].abs_diff(w[1].1[0]) + w[0].1[1].abs_diff(w[1].1[1]);
            assert_eq!(d, 1, "{:?} -> {:?}", w[0], w[1]);
        }
    }
}
