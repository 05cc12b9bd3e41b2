//! Planar straight-line graphs: the 2D input (dissertation fig. 1.4(a): "a 2D boundary defined by
//! line segments"). Points, segments between them (outer boundaries, hole boundaries and internal
//! boundaries alike), hole points and region points, as in Triangle's `.poly` files.
//!
//! [`Pslg::validate`] refuses what no triangulation can keep without new nodes on a segment:
//! duplicate points, repeated or zero-length segments, a point strictly inside a segment, two
//! segments crossing. Every test is exact ([`orient2d`]) — no epsilon.

use crate::geom::predicates::{Sign, in_exact_range, orient2d};
use rustc_hash::FxHashSet;

/// A region point: the connected part of the domain containing `point` gets `label`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegionPoint {
    /// Where.
    pub point: [f64; 2],
    /// The label (≥ 1).
    pub label: u32,
}

/// A planar straight-line graph.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Pslg {
    /// Points.
    pub points: Vec<[f64; 2]>,
    /// Segments, as pairs of point indices.
    pub segments: Vec<[u32; 2]>,
    /// A marker per segment (Triangle's boundary markers, Medit edge refs; 0 when none given).
    pub segment_markers: Vec<i32>,
    /// Hole points: the part of the domain containing each is removed.
    pub holes: Vec<[f64; 2]>,
    /// Region points: the part containing each gets its label.
    pub regions: Vec<RegionPoint>,
}

/// Why a PSLG cannot be meshed as it is. Indices are 0-based positions in [`Pslg`]'s arrays.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PslgError {
    /// No segments.
    #[error("no segments: the domain has no boundary")]
    NoSegments,
    /// A coordinate is NaN, infinite or outside the exact range of the predicates.
    #[error(
        "point {0} has a non-finite coordinate or one outside the exact range (0, or magnitude between 7.0e-46 and 1e50)"
    )]
    BadCoordinate(usize),
    /// Two points coincide.
    #[error("points {0} and {1} have the same coordinates")]
    DuplicatePoint(usize, usize),
    /// A segment refers to a point that does not exist.
    #[error("segment {0} refers to point {1}, but there are {2} points")]
    SegmentIndex(usize, u32, usize),
    /// A segment joins a point to itself.
    #[error("segment {0} has both ends at point {1}")]
    ZeroLength(usize, u32),
    /// The same two points are joined twice.
    #[error("segments {0} and {1} join the same two points")]
    DuplicateSegment(usize, usize),
    /// A point lies strictly inside a segment.
    #[error("point {point} lies on segment {segment} (between its ends): split the segment there")]
    PointOnSegment {
        /// The point.
        point: usize,
        /// The segment.
        segment: usize,
    },
    /// Two segments cross.
    #[error("segments {0} and {1} cross")]
    Crossing(usize, usize),
    /// A region label of 0 (0 is the outside).
    #[error("region point {0} has label 0 (0 means outside; use a hole point instead)")]
    ZeroRegion(usize),
    /// A hole or region point is not finite.
    #[error("{0} point {1} has a non-finite coordinate")]
    BadMarkerPoint(&'static str, usize),
}

/// Sorted pair.
#[inline]
pub fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Is `p` (collinear with `a`, `b`) strictly between them? Exact: compares coordinates.
fn strictly_between(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> bool {
    let k = if a[0] != b[0] { 0 } else { 1 };
    (a[k] < p[k] && p[k] < b[k]) || (b[k] < p[k] && p[k] < a[k])
}

impl Pslg {
    /// Check that a triangulation can contain every segment without new nodes (see the module
    /// docs). Runs in about O((n + s) log n + pairs of segments with overlapping boxes).
    pub fn validate(&self) -> Result<(), PslgError> {
        if self.segments.is_empty() {
            return Err(PslgError::NoSegments);
        }
        let n = self.points.len();
        for (i, p) in self.points.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite() && in_exact_range(*c)) {
                return Err(PslgError::BadCoordinate(i));
            }
        }
        for (i, p) in self.holes.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(PslgError::BadMarkerPoint("hole", i));
            }
        }
        for (i, r) in self.regions.iter().enumerate() {
            if !r.point.iter().all(|c| c.is_finite()) {
                return Err(PslgError::BadMarkerPoint("region", i));
            }
            if r.label == 0 {
                return Err(PslgError::ZeroRegion(i));
            }
        }
        // Points sorted by x (then y): duplicates adjacent; x-ranges by binary search.
        let key = |i: usize| self.points[i].map(|c| c + 0.0);
        let mut by_x: Vec<usize> = (0..n).collect();
        by_x.sort_unstable_by(|&a, &b| {
            let (pa, pb) = (key(a), key(b));
            pa[0]
                .total_cmp(&pb[0])
                .then(pa[1].total_cmp(&pb[1]))
                .then(a.cmp(&b))
        });
        for w in by_x.windows(2) {
            if key(w[0]) == key(w[1]) {
                return Err(PslgError::DuplicatePoint(w[0].min(w[1]), w[0].max(w[1])));
            }
        }
        let mut seen: rustc_hash::FxHashMap<(u32, u32), usize> = Default::default();
        for (s, &[a, b]) in self.segments.iter().enumerate() {
            for v in [a, b] {
                if v as usize >= n {
                    return Err(PslgError::SegmentIndex(s, v, n));
                }
            }
            if a == b {
                return Err(PslgError::ZeroLength(s, a));
            }
            if let Some(&first) = seen.get(&edge_key(a, b)) {
                return Err(PslgError::DuplicateSegment(first, s));
            }
            seen.insert(edge_key(a, b), s);
        }
        let xs: Vec<f64> = by_x.iter().map(|&i| self.points[i][0]).collect();
        let pt = |v: u32| self.points[v as usize];
        // Points strictly inside segments.
        for (s, &[a, b]) in self.segments.iter().enumerate() {
            let (pa, pb) = (pt(a), pt(b));
            let (x0, x1) = (pa[0].min(pb[0]), pa[0].max(pb[0]));
            let (y0, y1) = (pa[1].min(pb[1]), pa[1].max(pb[1]));
            let lo = xs.partition_point(|&x| x < x0);
            let hi = xs.partition_point(|&x| x <= x1);
            for &i in &by_x[lo..hi] {
                let p = self.points[i];
                if i as u32 == a || i as u32 == b || p[1] < y0 || p[1] > y1 {
                    continue;
                }
                if orient2d(pa, pb, p) == Sign::Zero && strictly_between(pa, pb, p) {
                    return Err(PslgError::PointOnSegment {
                        point: i,
                        segment: s,
                    });
                }
            }
        }
        // Crossing segments: sweep by the left end of their x-ranges.
        let mut order: Vec<usize> = (0..self.segments.len()).collect();
        let xr = |s: usize| {
            let [a, b] = self.segments[s];
            (pt(a)[0].min(pt(b)[0]), pt(a)[0].max(pt(b)[0]))
        };
        order.sort_unstable_by(|&s, &t| xr(s).0.total_cmp(&xr(t).0).then(s.cmp(&t)));
        let mut active: Vec<usize> = Vec::new();
        for &s in &order {
            let (x0, _) = xr(s);
            active.retain(|&t| xr(t).1 >= x0);
            for &t in &active {
                if segments_cross(self, s, t) {
                    return Err(PslgError::Crossing(s.min(t), s.max(t)));
                }
            }
            active.push(s);
        }
        Ok(())
    }

    /// The segments as a set of sorted point pairs.
    pub fn segment_set(&self) -> FxHashSet<(u32, u32)> {
        self.segments.iter().map(|&[a, b]| edge_key(a, b)).collect()
    }
}

/// Do segments `s` and `t` cross at a point interior to both (exact)? Segments that share an end
/// do not; collinear overlaps are caught by the point-on-segment test.
fn segments_cross(g: &Pslg, s: usize, t: usize) -> bool {
    let [a, b] = g.segments[s];
    let [c, d] = g.segments[t];
    if a == c || a == d || b == c || b == d {
        return false;
    }
    let p = |v: u32| g.points[v as usize];
    let (pa, pb, pc, pd) = (p(a), p(b), p(c), p(d));
    if pa[1].max(pb[1]) < pc[1].min(pd[1]) || pc[1].max(pd[1]) < pa[1].min(pb[1]) {
        return false;
    }
    let o1 = orient2d(pa, pb, pc).as_i32() * orient2d(pa, pb, pd).as_i32();
    let o2 = orient2d(pc, pd, pa).as_i32() * orient2d(pc, pd, pb).as_i32();
    o1 < 0 && o2 < 0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Pslg {
        Pslg {
            points: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            segments: vec![[0, 1], [1, 2], [2, 3], [3, 0]],
            segment_markers: vec![0; 4],
            ..Default::default()
        }
    }

    #[test]
    fn square_is_valid() {
        assert_eq!(square().validate(), Ok(()));
    }

    #[test]
    fn crossing_and_on_segment_are_refused() {
        let mut g = square();
        g.segments.push([0, 2]);
        g.segments.push([1, 3]);
        g.segment_markers.extend([0, 0]);
        assert_eq!(g.validate(), Err(PslgError::Crossing(4, 5)));
        let mut g = square();
        g.points.push([0.5, 0.0]);
        assert_eq!(
            g.validate(),
            Err(PslgError::PointOnSegment {
                point: 4,
                segment: 0
            })
        );
        let mut g = square();
        g.points.push([1.0, 0.0]);
        assert_eq!(g.validate(), Err(PslgError::DuplicatePoint(1, 4)));
    }
}
