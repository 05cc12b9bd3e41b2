//! A closest-point index over a fixed set of triangles: a bounding-volume hierarchy (median
//! split on the longest axis of the centroids' box, leaves of a few triangles) queried depth
//! first, nearer child first, pruned by the squared distance to each node's box.
//!
//! Used for projection onto the input surface and for the Hausdorff measure. Floating point
//! only: it measures distances, it decides nothing combinatorial.

use crate::geom::vec3::{add, cross, dot, scale, sub};

type P3 = [f64; 3];

const LEAF: usize = 4;

#[derive(Debug, Clone)]
struct Node {
    lo: P3,
    hi: P3,
    /// Leaf: `start..start + count` in `tris`; inner: `start` is the right child (the left one
    /// follows the node), `count == 0`.
    start: u32,
    count: u32,
}

/// The closest point of a triangle set to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// Squared distance.
    pub d2: f64,
    /// The closest point.
    pub point: P3,
    /// Index of the triangle it lies on (in the order the triangles were given).
    pub triangle: u32,
    /// That triangle's place in the hierarchy ([`Bvh::slot`]).
    pub slot: u32,
}

/// The triangles that answered a caller's last few [`Bvh::any_within_hinted`] queries, latest
/// first (one per caller and thread; start from `Hint::default()`).
#[derive(Debug, Clone, Copy)]
pub struct Hint([u32; HINTS]);

/// How many recent answers a [`Hint`] keeps.
const HINTS: usize = 4;

impl Default for Hint {
    fn default() -> Self {
        Hint([u32::MAX; HINTS])
    }
}

impl Hint {
    /// Put `k` first.
    #[inline]
    fn note(&mut self, k: u32) {
        let at = self.0.iter().position(|&x| x == k).unwrap_or(HINTS - 1);
        // Mostly the first hint answers again: nothing moves.
        if at > 0 {
            self.0.copy_within(0..at, 1);
            self.0[0] = k;
        }
    }
}

/// The nodes still to visit in a depth-first descent, each with its box's squared distance to
/// the query point (computed once, when its parent is opened): a median split keeps the tree's
/// depth under 64 for any `u32` count, and a descent holds at most the depth plus one, so a
/// fixed array serves without allocating.
struct NodeStack {
    nodes: [(u32, f64); 64],
    len: usize,
}

impl NodeStack {
    fn new() -> NodeStack {
        NodeStack {
            nodes: [(0, 0.0); 64],
            len: 0,
        }
    }

    #[inline]
    fn push(&mut self, i: u32, d2: f64) {
        self.nodes[self.len] = (i, d2);
        self.len += 1;
    }

    #[inline]
    fn pop(&mut self) -> Option<(u32, f64)> {
        self.len = self.len.checked_sub(1)?;
        Some(self.nodes[self.len])
    }
}

/// A bounding-volume hierarchy over triangles, for closest-point queries.
#[derive(Debug, Clone)]
pub struct Bvh {
    /// The triangles in leaf order (a leaf's are contiguous).
    tris: Vec<[P3; 3]>,
    /// What [`within_d2`] computes before measuring, kept per triangle (same order).
    pre: Vec<Pre>,
    ids: Vec<u32>,
    nodes: Vec<Node>,
}

/// A triangle's box and unnormalized normal (and its squared length): the two cheap rejections
/// of [`within_d2`], precomputed with the same arithmetic so the answers are the same.
#[derive(Debug, Clone, Copy)]
pub(super) struct Pre {
    lo: P3,
    hi: P3,
    n: P3,
    nn: f64,
}

/// A triangle's bounding box.
#[inline]
fn tri_box(t: &[P3; 3]) -> (P3, P3) {
    let lo = [0, 1, 2].map(|k| t[0][k].min(t[1][k]).min(t[2][k]));
    let hi = [0, 1, 2].map(|k| t[0][k].max(t[1][k]).max(t[2][k]));
    (lo, hi)
}

impl Pre {
    pub(super) fn new(t: &[P3; 3]) -> Pre {
        let (lo, hi) = tri_box(t);
        let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
        Pre {
            lo,
            hi,
            n,
            nn: dot(n, n),
        }
    }
}

/// Whether `p` lies outside the box `lo..hi` grown by `r` (and a relative margin).
#[inline]
fn outside_box(p: P3, lo: P3, hi: P3, r: f64) -> bool {
    let m = r * (1.0 + 1e-9);
    (0..3).any(|k| p[k] < lo[k] - m || p[k] > hi[k] + m)
}

/// [`within_d2`] past its box test: the plane test with the triangle's normal `n` (unnormalized,
/// `nn` its squared length), then the distance.
#[inline]
fn within_d2_plane(p: P3, t: &[P3; 3], n: P3, nn: f64, r2: f64) -> Option<f64> {
    let h = dot(sub(p, t[0]), n);
    if h * h > r2 * nn * (1.0 + 1e-9) {
        return None;
    }
    let d2 = dist2(p, closest_on_triangle(p, t));
    (d2 <= r2).then_some(d2)
}

/// [`within_d2`] with the rejections' data precomputed.
#[inline]
pub(super) fn within_d2_pre(p: P3, t: &[P3; 3], pre: &Pre, r: f64, r2: f64) -> Option<f64> {
    if outside_box(p, pre.lo, pre.hi, r) {
        return None;
    }
    within_d2_plane(p, t, pre.n, pre.nn, r2)
}

/// The closest point of triangle `t` to `p` (Voronoi regions of the corners, edges and face,
/// tested in turn with barycentric dot products).
pub fn closest_on_triangle(p: P3, t: &[P3; 3]) -> P3 {
    let [a, b, c] = *t;
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return add(a, scale(ab, v));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return add(a, scale(ac, w));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return add(b, scale(sub(c, b), w));
    }
    let denom = va + vb + vc;
    if denom == 0.0 || !denom.is_finite() {
        // Degenerate triangle: the best of its three edges.
        let mut best = a;
        let mut bd = f64::INFINITY;
        for (u, v) in [(a, b), (b, c), (c, a)] {
            let q = closest_on_segment(p, u, v);
            let d = dist2(p, q);
            if d < bd {
                bd = d;
                best = q;
            }
        }
        return best;
    }
    let v = vb / denom;
    let w = vc / denom;
    add(a, add(scale(ab, v), scale(ac, w)))
}

/// The squared distance from `p` to triangle `t` if it is at most `r2` (`r` its root), else
/// `None`: after two cheap rejections, the triangle's box grown by `r` and the distance to its
/// plane (both bound the distance from below; a relative margin of 1e-9 keeps rounding from
/// deciding a borderline case differently from `dist2(p, closest_on_triangle(p, t)) <= r2`).
#[inline]
pub fn within_d2(p: P3, t: &[P3; 3], r: f64, r2: f64) -> Option<f64> {
    let (lo, hi) = tri_box(t);
    if outside_box(p, lo, hi, r) {
        return None;
    }
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    within_d2_plane(p, t, n, dot(n, n), r2)
}

/// Whether `p` is within `sqrt(r2)` of triangle `t` ([`within_d2`]).
#[inline]
pub fn within(p: P3, t: &[P3; 3], r: f64, r2: f64) -> bool {
    within_d2(p, t, r, r2).is_some()
}

/// The closest point of segment `uv` to `p`.
pub fn closest_on_segment(p: P3, u: P3, v: P3) -> P3 {
    let d = sub(v, u);
    let l = dot(d, d);
    if l == 0.0 {
        return u;
    }
    let s = (dot(sub(p, u), d) / l).clamp(0.0, 1.0);
    add(u, scale(d, s))
}

/// Squared distance.
#[inline]
pub fn dist2(a: P3, b: P3) -> f64 {
    let d = sub(a, b);
    dot(d, d)
}

/// The length of the longest edge of triangle `c`.
pub fn longest_edge(c: &[P3; 3]) -> f64 {
    (0..3)
        .map(|k| dist2(c[k], c[(k + 1) % 3]))
        .fold(0.0, f64::max)
        .sqrt()
}

/// The squared distance from `p` to the box `lo..hi` (0 inside).
///
/// Without branches: for `lo <= hi` the larger of `lo - p`, `p - hi` and 0 is the per-axis gap
/// the comparisons would pick, the same subtraction to the bit (and 0 for a NaN coordinate, as
/// there); the query points fall either side of a box at random, so branches mispredict.
#[inline]
pub(super) fn box_d2(p: P3, lo: P3, hi: P3) -> f64 {
    let mut s = 0.0;
    for k in 0..3 {
        let (a, b) = (lo[k] - p[k], p[k] - hi[k]);
        let e = if a > b { a } else { b };
        let e = if e > 0.0 { e } else { 0.0 };
        s += e * e;
    }
    s
}

/// The unit normal of a triangle (zero if degenerate).
pub fn unit_normal(t: &[P3; 3]) -> P3 {
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let l = dot(n, n).sqrt();
    if l > 0.0 { scale(n, 1.0 / l) } else { [0.0; 3] }
}

impl Bvh {
    /// Index every triangle of `s`, each answering with its index.
    pub fn of_surface(s: &crate::mesh::surface::SurfaceMesh) -> Bvh {
        let tris: Vec<[P3; 3]> = (0..s.triangles.len()).map(|t| s.corners(t)).collect();
        let ids = (0..tris.len() as u32).collect();
        Bvh::new(tris, ids)
    }

    /// Index the given triangles; `ids[i]` is what a query returns for `tris[i]`.
    pub fn new(tris: Vec<[P3; 3]>, ids: Vec<u32>) -> Bvh {
        assert_eq!(tris.len(), ids.len());
        let n = tris.len();
        let cent: Vec<P3> = tris
            .iter()
            .map(|t| [0, 1, 2].map(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0))
            .collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n / LEAF + 1);
        if n > 0 {
            build(&tris, &cent, &mut order, 0, n, &mut nodes);
        }
        let tris: Vec<[P3; 3]> = order.iter().map(|&k| tris[k as usize]).collect();
        let ids = order.iter().map(|&k| ids[k as usize]).collect();
        Bvh {
            pre: tris.iter().map(Pre::new).collect(),
            tris,
            ids,
            nodes,
        }
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// Whether there are no triangles.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The closest point to `p` no farther than `sqrt(max_d2)` (`None` if none is).
    pub fn closest_within(&self, p: P3, max_d2: f64) -> Option<Closest> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best = Closest {
            d2: max_d2,
            point: p,
            triangle: u32::MAX,
            slot: u32::MAX,
        };
        // A node's distance is taken when its parent is opened and it is pushed only if it may
        // hold a closer point; the best distance only shrinks, so the test again at its turn
        // skips what the test at its turn alone skipped, in the same order.
        let root = &self.nodes[0];
        let d = box_d2(p, root.lo, root.hi);
        if d >= best.d2 {
            return None;
        }
        let mut stack = NodeStack::new();
        stack.push(0, d);
        while let Some((i, d)) = stack.pop() {
            if d >= best.d2 {
                continue;
            }
            let node = &self.nodes[i as usize];
            if node.count > 0 {
                for k in node.start..node.start + node.count {
                    let q = closest_on_triangle(p, &self.tris[k as usize]);
                    let d = dist2(p, q);
                    if d < best.d2 || (d == best.d2 && best.triangle == u32::MAX) {
                        best = Closest {
                            d2: d,
                            point: q,
                            triangle: self.ids[k as usize],
                            slot: k,
                        };
                    }
                }
            } else {
                let bound = best.d2;
                self.push_children(p, i, node.start, &mut stack, |d| d >= bound);
            }
        }
        (best.triangle != u32::MAX).then_some(best)
    }

    /// Push the children of inner node `i` (left `i + 1`, right `r`) with their distances to
    /// `p`, the nearer last so that it is popped first, leaving out those `skip` says a pop
    /// would skip.
    #[inline]
    fn push_children(
        &self,
        p: P3,
        i: u32,
        r: u32,
        stack: &mut NodeStack,
        skip: impl Fn(f64) -> bool,
    ) {
        let l = i + 1;
        let (nl, nr) = (&self.nodes[l as usize], &self.nodes[r as usize]);
        let dl = box_d2(p, nl.lo, nl.hi);
        let dr = box_d2(p, nr.lo, nr.hi);
        let (first, second) = if dl <= dr {
            ((r, dr), (l, dl))
        } else {
            ((l, dl), (r, dr))
        };
        if !skip(first.1) {
            stack.push(first.0, first.1);
        }
        if !skip(second.1) {
            stack.push(second.0, second.1);
        }
    }

    /// Whether some triangle is within `sqrt(r2)` of `p` (stops at the first one found).
    pub fn any_within(&self, p: P3, r2: f64) -> bool {
        self.any_within_hinted(p, r2, &mut Hint::default())
    }

    /// [`Self::any_within`], trying first the triangles that answered the last queries with the
    /// same `hint` (samples of one triangle are answered by the same few input triangles, so
    /// most queries cost a distance or two instead of a descent); the answer does not depend on
    /// it.
    pub fn any_within_hinted(&self, p: P3, r2: f64, hint: &mut Hint) -> bool {
        self.first_within_hinted(p, r2, hint).is_some()
    }

    /// The squared distance to the first triangle [`Self::any_within_hinted`] finds within
    /// `sqrt(r2)` of `p`: an upper bound on the distance to the set, found as cheaply.
    pub fn first_within_hinted(&self, p: P3, r2: f64, hint: &mut Hint) -> Option<f64> {
        self.first_within_slot(p, r2, hint).map(|x| x.0)
    }

    /// The corners of the triangle in place `k` of the hierarchy ([`Closest::slot`]).
    pub fn slot(&self, k: u32) -> &[P3; 3] {
        &self.tris[k as usize]
    }

    /// [`Self::first_within_hinted`] with the place of the triangle found ([`Self::slot`]).
    pub fn first_within_slot(&self, p: P3, r2: f64, hint: &mut Hint) -> Option<(f64, u32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let r = r2.sqrt();
        for i in 0..HINTS {
            let k = hint.0[i];
            if k == u32::MAX {
                break;
            }
            if let Some(d2) = within_d2_pre(p, &self.tris[k as usize], &self.pre[k as usize], r, r2)
            {
                hint.note(k);
                return Some((d2, k));
            }
        }
        // Nodes farther than `r` are not pushed rather than skipped when popped: the same
        // nodes are searched in the same order.
        let root = &self.nodes[0];
        let d = box_d2(p, root.lo, root.hi);
        if d > r2 {
            return None;
        }
        let mut stack = NodeStack::new();
        stack.push(0, d);
        while let Some((i, _)) = stack.pop() {
            let node = &self.nodes[i as usize];
            if node.count > 0 {
                for k in node.start..node.start + node.count {
                    let (t, pre) = (&self.tris[k as usize], &self.pre[k as usize]);
                    if let Some(d2) = within_d2_pre(p, t, pre, r, r2) {
                        hint.note(k);
                        return Some((d2, k));
                    }
                }
            } else {
                self.push_children(p, i, node.start, &mut stack, |d| d > r2);
            }
        }
        None
    }

    /// The closest point to `p` (`None` only for an empty index).
    pub fn closest(&self, p: P3) -> Option<Closest> {
        self.closest_within(p, f64::INFINITY)
    }
}

/// One [`Bvh`] per side-label pair: projection and distances stay on the sheet a triangle
/// belongs to (an interface is never measured against another interface or shell).
#[derive(Debug, Clone, Default)]
pub struct PatchIndex {
    keys: Vec<[u32; 2]>,
    bvhs: Vec<Bvh>,
}

impl PatchIndex {
    /// Index the triangles of `tris` (over `points`) by their `sides`, skipping those with
    /// `alive[t] == false` when `alive` is given. Returned triangle ids are indices into `tris`.
    pub fn new(
        points: &[P3],
        tris: &[[u32; 3]],
        sides: &[[u32; 2]],
        alive: Option<&[bool]>,
    ) -> PatchIndex {
        let mut keys: Vec<[u32; 2]> = sides.to_vec();
        keys.sort_unstable();
        keys.dedup();
        let mut parts: Vec<(Vec<[P3; 3]>, Vec<u32>)> = vec![Default::default(); keys.len()];
        for (t, tri) in tris.iter().enumerate() {
            if alive.is_some_and(|a| !a[t]) {
                continue;
            }
            let k = keys.binary_search(&sides[t]).unwrap_or(0);
            parts[k].0.push(tri.map(|v| points[v as usize]));
            parts[k].1.push(t as u32);
        }
        let bvhs = parts.into_iter().map(|(t, i)| Bvh::new(t, i)).collect();
        PatchIndex { keys, bvhs }
    }

    /// The index of the triangles with side labels `sides`.
    pub fn get(&self, sides: [u32; 2]) -> Option<&Bvh> {
        self.keys.binary_search(&sides).ok().map(|k| &self.bvhs[k])
    }

    /// The side-label pairs indexed.
    pub fn keys(&self) -> &[[u32; 2]] {
        &self.keys
    }
}

fn build(
    tris: &[[P3; 3]],
    cent: &[P3],
    order: &mut [u32],
    start: usize,
    end: usize,
    nodes: &mut Vec<Node>,
) -> usize {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut clo = [f64::INFINITY; 3];
    let mut chi = [f64::NEG_INFINITY; 3];
    for &k in &order[start..end] {
        for p in &tris[k as usize] {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let c = cent[k as usize];
        for a in 0..3 {
            clo[a] = clo[a].min(c[a]);
            chi[a] = chi[a].max(c[a]);
        }
    }
    let me = nodes.len();
    nodes.push(Node {
        lo,
        hi,
        start: start as u32,
        count: (end - start) as u32,
    });
    if end - start <= LEAF {
        return me;
    }
    let axis = (0..3)
        .max_by(|&a, &b| (chi[a] - clo[a]).total_cmp(&(chi[b] - clo[b])))
        .unwrap_or(0);
    let mid = (start + end) / 2;
    order[start..end].select_nth_unstable_by(mid - start, |&x, &y| {
        cent[x as usize][axis]
            .total_cmp(&cent[y as usize][axis])
            .then(x.cmp(&y))
    });
    build(tris, cent, order, start, mid, nodes);
    let r = build(tris, cent, order, mid, end, nodes);
    nodes[me].start = r as u32;
    nodes[me].count = 0;
    me
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_point_matches_brute_force() {
        let s = crate::SurfaceMesh::icosphere(2.0, 2);
        let tris: Vec<[P3; 3]> = (0..s.n_triangles()).map(|t| s.corners(t)).collect();
        let bvh = Bvh::new(tris.clone(), (0..tris.len() as u32).collect());
        let mut x = 0.1234f64;
        for _ in 0..200 {
            let mut p = [0.0; 3];
            for c in &mut p {
                x = (x * 9301.0 + 49297.0) % 233280.0;
                *c = x / 233280.0 * 6.0 - 3.0;
            }
            let got = bvh.closest(p).unwrap();
            let want = tris
                .iter()
                .map(|t| dist2(p, closest_on_triangle(p, t)))
                .fold(f64::INFINITY, f64::min);
            assert!((got.d2 - want).abs() <= 1e-12 * (1.0 + want));
        }
    }

    #[test]
    fn closest_on_triangle_regions() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!(dist2(closest_on_triangle([0.2, 0.2, 1.0], &t), [0.2, 0.2, 0.0]) < 1e-30);
        assert_eq!(closest_on_triangle([-1.0, -1.0, 0.0], &t), [0.0, 0.0, 0.0]);
        assert_eq!(closest_on_triangle([2.0, -1.0, 0.0], &t), [1.0, 0.0, 0.0]);
        assert_eq!(closest_on_triangle([0.5, -1.0, 0.0], &t), [0.5, 0.0, 0.0]);
        let q = closest_on_triangle([1.0, 1.0, 0.0], &t);
        assert!((q[0] - 0.5).abs() < 1e-15 && (q[1] - 0.5).abs() < 1e-15);
    }
}
