//! Boundary recovery in the plane (dissertation fig. 1.4 and fig. 3.2): make every input segment
//! an edge of a triangle mesh without putting a node on it, then remove the outside and label the
//! regions.
//!
//! # The 2D LAST RESORT
//! Fig. 3.2 carves the elements around a defect into a closed cavity and refills it with elements
//! made only of the cavity's own nodes, best first. In the plane this is exactly segment recovery
//! by cavity retriangulation: the triangles a missing segment `ab` crosses are carved out (found by
//! an exact walk along `ab`), which leaves two polygons, one on each side of `ab`, whose nodes are
//! the carved triangles' nodes. Each polygon is refilled recursively: on its base edge `pq` the
//! triangle `pqc` is made with the node `c` whose circumcircle holds no other node of the polygon
//! (the best candidate in the Delaunay sense, chosen by [`incircle_sos`], so ties are broken
//! symbolically), then the two smaller polygons on `pc` and `cq` are filled the same way. Unlike
//! 3D, a polygon always has a triangulation, and this choice always gives one (it is the
//! constrained Delaunay triangulation of the cavity), so the 2D search never needs to backtrack
//! or grow the cavity. Edge flips would reach the same edges; the cavity form is the one that
//! matches fig. 3.2 and produces the constrained Delaunay triangulation directly.
//!
//! Recovery can fail only when no triangulation without a new node contains the segment: a mesh
//! node lies strictly inside it, or the segment leaves the meshed domain. Such segments are
//! reported ([`RecoverReport::failed`]), never hidden.
//!
//! # Outside removal and labels
//! [`carve`] flood-fills the triangles across edges that are not segments. A part that reaches the
//! mesh boundary through a non-segment edge (the convex hull around the domain) or contains a hole
//! point is removed; a part containing a region point gets its label; the other parts are
//! numbered after the largest region label, in order of their smallest node. Unused points are
//! dropped, the others keep their relative order (input points first, so segments keep their
//! indices when every input point is used).

use crate::geom::predicates::{Sign, incircle_sos, orient2d};
use crate::mesh::pslg::{Pslg, edge_key};
use crate::mesh::tet::NO_NEIGHBOR;
use crate::mesh::tri::TriMesh;
use rustc_hash::{FxHashMap, FxHashSet};
use serde::Serialize;

/// Why a segment was not recovered.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub enum SegmentFailure {
    /// A mesh node lies strictly inside the segment.
    NodeOnSegment {
        /// The segment (index into the given list).
        segment: usize,
        /// The node.
        node: u32,
    },
    /// The segment leaves the meshed domain (crosses a boundary edge).
    LeavesMesh {
        /// The segment.
        segment: usize,
    },
    /// An end of the segment is used by no triangle.
    UnusedEnd {
        /// The segment.
        segment: usize,
        /// The unused end.
        node: u32,
    },
}

/// What [`recover`] did.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct RecoverReport {
    /// Segments given.
    pub n_segments: usize,
    /// Segments that were edges already.
    pub n_present: usize,
    /// Segments made edges by carving and refilling.
    pub n_recovered: usize,
    /// Triangles carved out in total.
    pub n_carved: usize,
    /// Segments that could not be recovered, and why.
    pub failed: Vec<SegmentFailure>,
}

impl RecoverReport {
    /// Every segment is an edge.
    pub fn complete(&self) -> bool {
        self.failed.is_empty()
    }
}

/// Recovery state: the mesh plus a triangle at each vertex.
struct Work<'a> {
    m: &'a mut TriMesh,
    vtri: Vec<u32>,
}

impl Work<'_> {
    fn p(&self, v: u32) -> [f64; 2] {
        self.m.points[v as usize]
    }

    fn orient(&self, a: u32, b: u32, c: u32) -> Sign {
        orient2d(self.p(a), self.p(b), self.p(c))
    }

    /// The triangles around `a`, starting from `vtri[a]`, both ways round.
    fn star(&self, a: u32) -> Vec<u32> {
        let t0 = self.vtri[a as usize];
        let mut out = vec![t0];
        let local = |t: u32| {
            self.m.triangles[t as usize]
                .iter()
                .position(|&x| x == a)
                .expect("the vertex is in its triangles")
        };
        // Counter-clockwise: across the edge (a, w), opposite local vertex k + 1.
        let mut t = t0;
        loop {
            let k = local(t);
            let n = self.m.neighbors[t as usize][(k + 1) % 3];
            if n == NO_NEIGHBOR {
                break;
            }
            if n == t0 {
                return out;
            }
            out.push(n);
            t = n;
        }
        let mut t = t0;
        loop {
            let k = local(t);
            let n = self.m.neighbors[t as usize][(k + 2) % 3];
            if n == NO_NEIGHBOR || n == t0 {
                break;
            }
            out.push(n);
            t = n;
        }
        out
    }

    /// Recover segment `s = (a, b)`; Ok(true) when it was already an edge.
    fn segment(&mut self, s: usize, a: u32, b: u32) -> Result<Option<usize>, SegmentFailure> {
        for (v, other) in [(a, b), (b, a)] {
            if self.vtri[v as usize] == NO_NEIGHBOR {
                let _ = other;
                return Err(SegmentFailure::UnusedEnd {
                    segment: s,
                    node: v,
                });
            }
        }
        let (pa, pb) = (self.p(a), self.p(b));
        let on_segment = |w: &Work, x: u32| {
            let px = w.p(x);
            let k = if pa[0] != pb[0] { 0 } else { 1 };
            (pa[k] < px[k] && px[k] < pb[k]) || (pb[k] < px[k] && px[k] < pa[k])
        };
        // The triangle at a whose opposite edge (r, l) the segment crosses, r right of ab.
        let mut first: Option<(u32, u32, u32)> = None;
        for t in self.star(a) {
            let tv = self.m.triangles[t as usize];
            let k = tv.iter().position(|&x| x == a).unwrap_or(0);
            let (u, w) = (tv[(k + 1) % 3], tv[(k + 2) % 3]);
            if u == b || w == b {
                return Ok(None);
            }
            for x in [u, w] {
                if self.orient(a, b, x) == Sign::Zero && on_segment(self, x) {
                    return Err(SegmentFailure::NodeOnSegment {
                        segment: s,
                        node: x,
                    });
                }
            }
            if self.orient(a, b, u) == Sign::Negative && self.orient(a, b, w) == Sign::Positive {
                first = Some((t, u, w));
            }
        }
        let Some((t0, mut r, mut l)) = first else {
            return Err(SegmentFailure::LeavesMesh { segment: s });
        };
        // Walk along ab, collecting the crossed triangles and the nodes on either side.
        let mut carved = vec![t0];
        let mut left = vec![l];
        let mut right = vec![r];
        let mut t = t0;
        loop {
            let tv = self.m.triangles[t as usize];
            let i = (0..3)
                .find(|&i| tv[(i + 1) % 3] == r && tv[(i + 2) % 3] == l)
                .expect("the crossed edge is in the triangle");
            let n = self.m.neighbors[t as usize][i];
            if n == NO_NEIGHBOR {
                return Err(SegmentFailure::LeavesMesh { segment: s });
            }
            let nv = self.m.triangles[n as usize];
            let x = nv
                .into_iter()
                .find(|&x| x != l && x != r)
                .expect("a triangle has a third node");
            carved.push(n);
            t = n;
            if x == b {
                break;
            }
            match self.orient(a, b, x) {
                Sign::Positive => {
                    l = x;
                    left.push(x);
                }
                Sign::Negative => {
                    r = x;
                    right.push(x);
                }
                Sign::Zero => {
                    return Err(SegmentFailure::NodeOnSegment {
                        segment: s,
                        node: x,
                    });
                }
            }
        }
        // Refill: the left polygon on a→b, the right one on b→a.
        let mut new: Vec<[u32; 3]> = Vec::with_capacity(carved.len());
        self.fill(a, b, &left, &mut new);
        right.reverse();
        self.fill(b, a, &right, &mut new);
        debug_assert_eq!(new.len(), carved.len());
        if new.len() != carved.len()
            || new
                .iter()
                .any(|t| self.orient(t[0], t[1], t[2]) != Sign::Positive)
        {
            // Cannot happen for a cavity cut by one segment; refuse rather than corrupt.
            return Err(SegmentFailure::LeavesMesh { segment: s });
        }
        self.replace(&carved, &new);
        Ok(Some(carved.len()))
    }

    /// Triangulate the polygon `p, chain..., q` lying left of `p → q` (Delaunay in the polygon):
    /// on base `pq`, the chain node `c` whose circle through `p, q` holds no other chain node
    /// (one pass: circles through `p, q` on one side are nested), then the sub-polygons on `pc`
    /// and `cq` (an explicit stack, so long chains cannot overflow the call stack).
    fn fill(&self, p: u32, q: u32, chain: &[u32], out: &mut Vec<[u32; 3]>) {
        let mut todo: Vec<(u32, u32, usize, usize)> = vec![(p, q, 0, chain.len())];
        while let Some((p, q, lo, hi)) = todo.pop() {
            if lo >= hi {
                continue;
            }
            let mut c = lo;
            for d in lo + 1..hi {
                let (cv, dv) = (chain[c], chain[d]);
                if incircle_sos(
                    [self.p(p), self.p(q), self.p(cv), self.p(dv)],
                    [p, q, cv, dv],
                ) == Sign::Positive
                {
                    c = d;
                }
            }
            out.push([p, q, chain[c]]);
            todo.push((chain[c], q, c + 1, hi));
            todo.push((p, chain[c], lo, c));
        }
    }

    /// Put `new` in the slots of `carved` and relink adjacency.
    fn replace(&mut self, carved: &[u32], new: &[[u32; 3]]) {
        let inside: FxHashSet<u32> = carved.iter().copied().collect();
        // Outer neighbours by directed edge (as the carved triangle had it).
        let mut outer: FxHashMap<(u32, u32), u32> = FxHashMap::default();
        for &t in carved {
            let tv = self.m.triangles[t as usize];
            for i in 0..3 {
                let n = self.m.neighbors[t as usize][i];
                if !inside.contains(&n) {
                    outer.insert((tv[(i + 1) % 3], tv[(i + 2) % 3]), n);
                }
            }
        }
        let mut own: FxHashMap<(u32, u32), u32> = FxHashMap::default();
        for (&t, tv) in carved.iter().zip(new) {
            self.m.triangles[t as usize] = *tv;
            for i in 0..3 {
                own.insert((tv[(i + 1) % 3], tv[(i + 2) % 3]), t);
                self.vtri[tv[i] as usize] = t;
            }
        }
        for (&t, tv) in carved.iter().zip(new) {
            for i in 0..3 {
                let (u, w) = (tv[(i + 1) % 3], tv[(i + 2) % 3]);
                let n = if let Some(&n) = outer.get(&(u, w)) {
                    if n != NO_NEIGHBOR {
                        let nv = self.m.triangles[n as usize];
                        for j in 0..3 {
                            if nv[(j + 1) % 3] == w && nv[(j + 2) % 3] == u {
                                self.m.neighbors[n as usize][j] = t;
                            }
                        }
                    }
                    n
                } else {
                    *own.get(&(w, u)).expect("inner edges pair up")
                };
                self.m.neighbors[t as usize][i] = n;
            }
        }
    }
}

/// Make every segment (pairs of point indices of `mesh`) an edge of `mesh`, carving and refilling
/// the triangles it crosses (see the module docs). Points never move and none is added; labels of
/// refilled triangles are those of the first carved triangle. Deterministic.
pub fn recover(mesh: &mut TriMesh, segments: &[[u32; 2]]) -> RecoverReport {
    let mut vtri = vec![NO_NEIGHBOR; mesh.points.len()];
    for (t, tv) in mesh.triangles.iter().enumerate() {
        for &v in tv {
            vtri[v as usize] = t as u32;
        }
    }
    let mut w = Work { m: mesh, vtri };
    let mut report = RecoverReport {
        n_segments: segments.len(),
        ..Default::default()
    };
    for (s, &[a, b]) in segments.iter().enumerate() {
        if a as usize >= w.m.points.len() || b as usize >= w.m.points.len() || a == b {
            report.failed.push(SegmentFailure::UnusedEnd {
                segment: s,
                node: a.max(b),
            });
            continue;
        }
        match w.segment(s, a, b) {
            Ok(None) => report.n_present += 1,
            Ok(Some(k)) => {
                report.n_recovered += 1;
                report.n_carved += k;
            }
            Err(f) => report.failed.push(f),
        }
    }
    report
}

/// Why [`carve`] refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CarveError {
    /// A hole or region point is outside the mesh or exactly on a segment.
    #[error("{what} point {index} is {why}")]
    MarkerPoint {
        /// "hole" or "region".
        what: &'static str,
        /// Its index.
        index: usize,
        /// Why it cannot be used.
        why: &'static str,
    },
    /// Nothing is left.
    #[error("no triangle is inside the boundary (is the outer boundary closed?)")]
    Empty,
}

/// What [`carve`] did.
#[derive(Debug, Clone, Default, Serialize)]
pub struct CarveReport {
    /// Triangles removed (outside or in holes).
    pub n_removed: usize,
    /// Triangles kept.
    pub n_kept: usize,
    /// Labels of the kept parts, in label order.
    pub labels: Vec<u32>,
    /// Points dropped because no kept triangle uses them.
    pub n_points_dropped: usize,
    /// New index of each old point (`u32::MAX` for dropped ones).
    #[serde(skip)]
    pub point_map: Vec<u32>,
}

/// The triangle containing `p` (closed, exact), if any; `on_segment` when it is on a segment.
fn locate_brute(
    mesh: &TriMesh,
    seg: &FxHashSet<(u32, u32)>,
    p: [f64; 2],
) -> Result<u32, &'static str> {
    for (t, tv) in mesh.triangles.iter().enumerate() {
        let c = tv.map(|v| mesh.points[v as usize]);
        let o = [0, 1, 2].map(|i| orient2d(c[(i + 1) % 3], c[(i + 2) % 3], p));
        if o.contains(&Sign::Negative) {
            continue;
        }
        for i in 0..3 {
            if o[i] == Sign::Zero && seg.contains(&edge_key(tv[(i + 1) % 3], tv[(i + 2) % 3])) {
                return Err("exactly on a segment");
            }
        }
        return Ok(t as u32);
    }
    Err("outside the triangulation")
}

/// Remove the outside and the holes of `mesh` (which should contain every segment of `pslg`,
/// with the same point numbering) and label the parts (see the module docs).
pub fn carve(mesh: &mut TriMesh, pslg: &Pslg) -> Result<CarveReport, CarveError> {
    let seg = pslg.segment_set();
    let nt = mesh.triangles.len();
    let mut part = vec![u32::MAX; nt];
    let mut parts: Vec<(bool, u32)> = Vec::new(); // (removed, smallest node)
    for t0 in 0..nt {
        if part[t0] != u32::MAX {
            continue;
        }
        let id = parts.len() as u32;
        let mut outside = false;
        let mut smallest = u32::MAX;
        let mut stack = vec![t0 as u32];
        part[t0] = id;
        while let Some(t) = stack.pop() {
            let tv = mesh.triangles[t as usize];
            smallest = smallest.min(tv[0]).min(tv[1]).min(tv[2]);
            for i in 0..3 {
                if seg.contains(&edge_key(tv[(i + 1) % 3], tv[(i + 2) % 3])) {
                    continue;
                }
                let n = mesh.neighbors[t as usize][i];
                if n == NO_NEIGHBOR {
                    outside = true;
                } else if part[n as usize] == u32::MAX {
                    part[n as usize] = id;
                    stack.push(n);
                }
            }
        }
        parts.push((outside, smallest));
    }
    let mut label: Vec<Option<u32>> = parts.iter().map(|&(o, _)| o.then_some(0)).collect();
    for (i, &h) in pslg.holes.iter().enumerate() {
        match locate_brute(mesh, &seg, h) {
            Ok(t) => label[part[t as usize] as usize] = Some(0),
            // A hole point outside the triangulation removes nothing (Triangle does the same).
            Err("outside the triangulation") => {}
            Err(why) => {
                return Err(CarveError::MarkerPoint {
                    what: "hole",
                    index: i,
                    why,
                });
            }
        }
    }
    let mut max_label = 0;
    for (i, r) in pslg.regions.iter().enumerate() {
        max_label = max_label.max(r.label);
        match locate_brute(mesh, &seg, r.point) {
            Ok(t) => {
                let p = part[t as usize] as usize;
                if label[p] != Some(0) {
                    label[p] = Some(r.label);
                }
            }
            Err("outside the triangulation") => {}
            Err(why) => {
                return Err(CarveError::MarkerPoint {
                    what: "region",
                    index: i,
                    why,
                });
            }
        }
    }
    let mut rest: Vec<usize> = (0..parts.len()).filter(|&p| label[p].is_none()).collect();
    rest.sort_by_key(|&p| parts[p].1);
    for (k, p) in rest.into_iter().enumerate() {
        label[p] = Some(max_label + 1 + k as u32);
    }
    let mut report = CarveReport::default();
    let mut tris = Vec::with_capacity(nt);
    let mut labels = Vec::with_capacity(nt);
    let mut new_index = vec![NO_NEIGHBOR; nt];
    for t in 0..nt {
        let l = label[part[t] as usize].unwrap_or(0);
        if l == 0 {
            report.n_removed += 1;
        } else {
            new_index[t] = tris.len() as u32;
            tris.push(mesh.triangles[t]);
            labels.push(l);
        }
    }
    // Adjacency carried over: kept triangles keep their kept neighbours.
    let neighbors: Vec<[u32; 3]> = (0..nt)
        .filter(|&t| new_index[t] != NO_NEIGHBOR)
        .map(|t| {
            mesh.neighbors[t].map(|n| {
                if n == NO_NEIGHBOR {
                    NO_NEIGHBOR
                } else {
                    new_index[n as usize]
                }
            })
        })
        .collect();
    if tris.is_empty() {
        return Err(CarveError::Empty);
    }
    report.n_kept = tris.len();
    let mut ls = labels.clone();
    ls.sort_unstable();
    ls.dedup();
    report.labels = ls;
    // Drop unused points, keeping the order of the others.
    let mut used = vec![false; mesh.points.len()];
    for tv in &tris {
        for &v in tv {
            used[v as usize] = true;
        }
    }
    let mut map = vec![u32::MAX; mesh.points.len()];
    let mut points = Vec::with_capacity(mesh.points.len());
    for (i, &p) in mesh.points.iter().enumerate() {
        if used[i] {
            map[i] = points.len() as u32;
            points.push(p);
        }
    }
    report.n_points_dropped = mesh.points.len() - points.len();
    for tv in &mut tris {
        *tv = tv.map(|v| map[v as usize]);
    }
    *mesh = TriMesh {
        points,
        triangles: tris,
        neighbors,
        labels,
    };
    report.point_map = map;
    Ok(report)
}
