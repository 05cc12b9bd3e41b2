//! Long input edges cut into pieces of the target length before the rounds.
//!
//! The rounds split an edge longer than 4/3 of its target at its midpoint. On a needle (two long
//! edges, one short) that makes a fan: the split of one long edge leaves a new edge from its
//! midpoint to the far corner as long as the halves, and the other long edge whole, so each pass
//! over a strip of needles triples its long edges and puts points inside the strip that the
//! collapses then take out. A trimesh cylinder 200 long and 1 wide (its sides 32 needles) took
//! 88,738 splits and 82,596 collapses to reach 12,322 triangles, 9.4 s in one round.
//!
//! Here every edge longer than [`RATIO`] times the target edge length is cut into equal pieces
//! no longer than the target, and each triangle with a cut edge is triangulated anew inside its
//! own plane: its boundary is a convex polygon, cut by ears along the shortest diagonal first
//! (from a needle's sharp corner outwards that is the zig-zag of the strip). The surface is the
//! same point set as the input, so the new points are on it and its samples stay covered.
//!
//! A kept edge (a sharp edge, an interface rim, a triple line) is never split by the rounds, so
//! one longer than the rounds' split threshold ([`KEPT_RATIO`]) is cut here too, its points fixed
//! and its pieces kept: the polyline stays exactly as given, with points a target apart. Whole,
//! a kept edge longer than the target bounds the triangles on it: an image of 0.5 × 0.5 × 3 mm
//! voxels, whose triple lines are staircases of 3 mm steps, kept 3° triangles and 186 tets under
//! 10° (1.52°); cut, 27° and none. Inputs without such edges (the brain surfaces, images of
//! cubic voxels, the shape corpus at 1% of its diagonal) start from themselves as before.

use rustc_hash::{FxHashMap, FxHashSet};

use super::bvh::{box_d2, closest_on_triangle, dist2};
use super::features::{Features, key};
use super::guard::InputSamples;
use crate::geom::vec3::{add, bbox, scale, sub};
use crate::mesh::surface::SurfaceMesh;

type P3 = [f64; 3];

/// Edges longer than this many target lengths are cut before the rounds (four bisections: below
/// it the rounds' own splits cost a few times the cuts; at eight, gmsh's t13 took 30% longer
/// for its fans, cut and triangulated again, and at sixteen it is as before).
pub const RATIO: f64 = 16.0;

/// Kept edges (features, rims, triple lines) longer than this many target lengths are cut: the
/// rounds split any other edge that long.
pub const KEPT_RATIO: f64 = 4.0 / 3.0;

/// Where the remeshing starts when long edges were cut.
pub struct Start {
    /// The input with its long edges cut and their triangles triangulated anew (the input's
    /// points first, in order; a cut triangle's first piece in its place, the others after).
    pub mesh: SurfaceMesh,
    /// The features' fixed points, extended to the new points (free, but on a cut kept edge).
    pub fixed: Vec<bool>,
    /// The kept edges, a cut one replaced by its pieces.
    pub edges: FxHashSet<(u32, u32)>,
    /// The point sizes extended (a cut point: the smaller of its edge's ends).
    pub point_size: Vec<f64>,
    /// Per input sample: the triangle of `mesh` that covers it (the piece nearest to it) and
    /// its distance.
    pub cover: Vec<(u32, f64)>,
    /// Edges cut.
    pub edges_cut: usize,
}

/// Cut the edges of `s` longer than [`RATIO`]·`l` (`None` when there is none).
pub fn presplit(
    s: &SurfaceMesh,
    f: &Features,
    samples: &InputSamples,
    point_size: &[f64],
    l: f64,
) -> Option<Start> {
    let mut pts = s.points.clone();
    let mut size = point_size.to_vec();
    // Per cut edge (min, max): its inner points from min to max.
    let mut cut: FxHashMap<(u32, u32), Vec<u32>> = FxHashMap::default();
    let mut order: Vec<(u32, u32)> = Vec::new();
    for tri in &s.triangles {
        for k in 0..3 {
            let e = key(tri[k], tri[(k + 1) % 3]);
            if cut.contains_key(&e) {
                continue;
            }
            // A kept edge is never split by the rounds: cut here when the rounds would split
            // it (over 4/3 of the target), its pieces kept edges too.
            let lim = if f.edges.contains(&e) {
                KEPT_RATIO * l
            } else {
                RATIO * l
            };
            let (a, b) = (s.points[e.0 as usize], s.points[e.1 as usize]);
            if dist2(a, b).sqrt() > lim {
                cut.insert(e, Vec::new());
                order.push(e);
            }
        }
    }
    if order.is_empty() {
        return None;
    }
    for &e in &order {
        let (a, b) = (s.points[e.0 as usize], s.points[e.1 as usize]);
        let n = (dist2(a, b).sqrt() / l).ceil() as usize;
        let h = size[e.0 as usize].min(size[e.1 as usize]);
        let d = sub(b, a);
        let inner: Vec<u32> = (1..n)
            .map(|i| {
                pts.push(add(a, scale(d, i as f64 / n as f64)));
                size.push(h);
                (pts.len() - 1) as u32
            })
            .collect();
        cut.insert(e, inner);
    }
    let mut mesh = SurfaceMesh {
        points: pts,
        triangles: s.triangles.clone(),
        sides: s.sides.clone(),
    };
    // Per input triangle: its pieces (empty when not cut).
    let mut pieces: Vec<Vec<u32>> = vec![Vec::new(); s.triangles.len()];
    for (t, tri) in s.triangles.iter().enumerate() {
        if !(0..3).any(|k| cut.contains_key(&key(tri[k], tri[(k + 1) % 3]))) {
            continue;
        }
        // The boundary, each vertex with the input edge it lies inside (3: a corner).
        let mut poly: Vec<(u32, u8)> = Vec::new();
        for k in 0..3 {
            let (v, w) = (tri[k], tri[(k + 1) % 3]);
            poly.push((v, 3));
            if let Some(inner) = cut.get(&key(v, w)) {
                let on = k as u8;
                if v < w {
                    poly.extend(inner.iter().map(|&x| (x, on)));
                } else {
                    poly.extend(inner.iter().rev().map(|&x| (x, on)));
                }
            }
        }
        let tris = ears(&mesh.points, &poly);
        let mut ids = Vec::with_capacity(tris.len());
        for (i, piece) in tris.into_iter().enumerate() {
            if i == 0 {
                mesh.triangles[t] = piece;
                ids.push(t as u32);
            } else {
                mesh.triangles.push(piece);
                mesh.sides.push(s.sides[t]);
                ids.push((mesh.triangles.len() - 1) as u32);
            }
        }
        pieces[t] = ids;
    }
    // Each sample to the first piece (in order) at its least distance. The pieces' boxes, grown
    // by far more than rounding, skip the pieces that cannot be closer than the best so far,
    // which starts at the piece the triangle's previous sample took (samples come in rows):
    // a needle's thousand samples against its hundreds of pieces cost a quarter of the stage
    // on a cylinder 400 long when every piece was measured.
    let boxes: Vec<(P3, P3)> = (0..mesh.triangles.len())
        .map(|u| {
            let (lo, hi) = bbox(&mesh.corners(u));
            let m = 1e-9
                * (0..3)
                    .map(|k| lo[k].abs().max(hi[k].abs()))
                    .fold(0.0, f64::max);
            (lo.map(|x| x - m), hi.map(|x| x + m))
        })
        .collect();
    let mut last: Vec<usize> = vec![0; s.triangles.len()];
    let cover = samples
        .tri
        .iter()
        .zip(&samples.pts)
        .map(|(&t, &p)| {
            let ids = &pieces[t as usize];
            if ids.is_empty() {
                return (t, 0.0);
            }
            let dist = |i: usize| dist2(p, closest_on_triangle(p, &mesh.corners(ids[i] as usize)));
            let g = last[t as usize];
            let mut best = (dist(g), g);
            for i in 0..ids.len() {
                let (lo, hi) = boxes[ids[i] as usize];
                if i == g || box_d2(p, lo, hi) > best.0 {
                    continue;
                }
                let d = dist(i);
                if d < best.0 || (d == best.0 && i < best.1) {
                    best = (d, i);
                }
            }
            last[t as usize] = best.1;
            (ids[best.1], best.0.sqrt())
        })
        .collect();
    // The points of a cut kept edge are fixed and its pieces kept, like the edge.
    let mut fixed = f.fixed.clone();
    fixed.resize(mesh.points.len(), false);
    let mut edges = f.edges.clone();
    for e in &order {
        if !edges.remove(e) {
            continue;
        }
        let inner = &cut[e];
        let chain: Vec<u32> = std::iter::once(e.0)
            .chain(inner.iter().copied())
            .chain(std::iter::once(e.1))
            .collect();
        for w in chain.windows(2) {
            edges.insert(key(w[0], w[1]));
        }
        for &x in inner {
            fixed[x as usize] = true;
        }
    }
    Some(Start {
        mesh,
        fixed,
        edges,
        point_size: size,
        cover,
        edges_cut: order.len(),
    })
}

/// Triangulate a convex polygon whose vertices (in order) lie on a triangle's corners (tag 3)
/// or inside its edges (tag: the edge `k`, from corner `k` to corner `k + 1`): the ear with the
/// shortest diagonal first (ties: the first in order). Never an ear at a vertex inside an edge
/// whose neighbours are on that edge too (three points on a line), nor one that leaves every
/// other vertex on one edge (the rest would be flat).
fn ears(pts: &[P3], poly: &[(u32, u8)]) -> Vec<[u32; 3]> {
    let mut p: Vec<(u32, u8)> = poly.to_vec();
    let mut out = Vec::with_capacity(p.len().saturating_sub(2));
    let corners: Vec<u32> = poly.iter().filter(|x| x.1 == 3).map(|x| x.0).collect();
    // Whether vertex `x` lies on the closed edge `e` (its end corners included).
    let on = |x: (u32, u8), e: usize| {
        usize::from(x.1) == e || (x.1 == 3 && (x.0 == corners[e] || x.0 == corners[(e + 1) % 3]))
    };
    // Per edge: the vertices not on it (none left would make the rest a segment).
    let mut off = [0usize; 3];
    for &x in &p {
        for (e, n) in off.iter_mut().enumerate() {
            *n += usize::from(!on(x, e));
        }
    }
    while p.len() > 3 {
        let n = p.len();
        let mut best: Option<(f64, usize)> = None;
        for i in 0..n {
            let (u, v, w) = (p[(i + n - 1) % n], p[i], p[(i + 1) % n]);
            if v.1 != 3 && on(u, usize::from(v.1)) && on(w, usize::from(v.1)) {
                continue;
            }
            if (0..3).any(|e| !on(v, e) && off[e] == 1) {
                continue;
            }
            let d = dist2(pts[u.0 as usize], pts[w.0 as usize]);
            if best.is_none_or(|b| d < b.0) {
                best = Some((d, i));
            }
        }
        let Some((_, i)) = best else {
            break;
        };
        let (u, v, w) = (p[(i + n - 1) % n], p[i], p[(i + 1) % n]);
        out.push([u.0, v.0, w.0]);
        for (e, n) in off.iter_mut().enumerate() {
            *n -= usize::from(!on(v, e));
        }
        p.remove(i);
    }
    if p.len() == 3 {
        out.push([p[0].0, p[1].0, p[2].0]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::vec3::{cross, dot};

    /// The pieces of `tri` with its edges cut `cuts[k]` times (edge `k` from corner `k`): each
    /// turned like the triangle, and their areas adding up to its area.
    fn check_pieces(c: [P3; 3], cuts: [usize; 3]) -> Vec<[u32; 3]> {
        let mut pts = c.to_vec();
        let mut poly = Vec::new();
        for k in 0..3 {
            poly.push((k as u32, 3u8));
            let (a, b) = (c[k], c[(k + 1) % 3]);
            for i in 1..=cuts[k] {
                let t = i as f64 / (cuts[k] + 1) as f64;
                pts.push(add(a, scale(sub(b, a), t)));
                poly.push(((pts.len() - 1) as u32, k as u8));
            }
        }
        let tris = ears(&pts, &poly);
        assert_eq!(tris.len(), poly.len() - 2);
        let n0 = cross(sub(c[1], c[0]), sub(c[2], c[0]));
        let mut area = 0.0;
        for t in &tris {
            let q = t.map(|v| pts[v as usize]);
            let n = cross(sub(q[1], q[0]), sub(q[2], q[0]));
            assert!(dot(n, n0) > 0.0, "piece {t:?} turned or flat");
            area += dot(n, n0) / dot(n0, n0).sqrt();
        }
        assert!((area - dot(n0, n0).sqrt()).abs() < 1e-9 * dot(n0, n0).sqrt());
        tris
    }

    #[test]
    fn one_cut_edge_is_fanned_from_the_far_corner() {
        let c = [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [4.0, 3.0, 0.0]];
        let tris = check_pieces(c, [5, 0, 0]);
        assert!(tris.iter().all(|t| t.contains(&2)), "{tris:?}");
    }

    #[test]
    fn a_needle_is_cut_into_a_strip() {
        // 100 long, 0.4 wide at its short edge: pieces as long as the cuts, not fans.
        let c = [[0.0, 0.0, 0.0], [100.0, 0.0, 0.0], [100.0, 0.4, 0.0]];
        let tris = check_pieces(c, [49, 0, 49]);
        let pts_len = |t: &[u32; 3], pts: &[P3]| {
            (0..3)
                .map(|k| dist2(pts[t[k] as usize], pts[t[(k + 1) % 3] as usize]).sqrt())
                .fold(0.0, f64::max)
        };
        let mut pts = c.to_vec();
        for k in [0usize, 2] {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            for i in 1..=49 {
                pts.push(add(a, scale(sub(b, a), i as f64 / 50.0)));
            }
        }
        // Edge points in the order check_pieces made them: edge 0, then edge 2.
        assert!(
            tris.iter().all(|t| pts_len(t, &pts) < 4.5),
            "a piece longer than two cuts"
        );
    }
}
