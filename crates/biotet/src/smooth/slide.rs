//! Sliding on the input surface: surface nodes move tangentially and are carried back exactly
//! onto the input triangles, walking across to neighbouring triangles as needed, never across a
//! feature edge.
//!
//! A position on the surface is a [`Location`]: a triangle and barycentric coordinates. A move
//! walks the displacement along the surface: projected into the current triangle's plane, it
//! goes straight until it leaves the triangle through an edge, then continues in the neighbour
//! with the rest of the displacement unfolded about the shared edge. The point is always
//! `Σ λ_i v_i` with `λ ≥ 0`, `Σ λ = 1`: on a triangle of the input up to round-off.
//!
//! **Features.** An edge is a feature (a wall the walk never crosses) when it has other than two
//! triangles (an open border or a junction of interfaces), when its two triangles carry different
//! pairs of region labels (where a boundary meets an interface: a triple line), when a triangle at
//! it has no area, or when the normals of its two triangles turn by more than the feature angle.
//! A vertex on a feature edge is a feature vertex; mesh nodes there never move, so corners and
//! ridges keep their shape.

use rustc_hash::FxHashMap;

use crate::geom::vec3::{add, cross, dot, norm, scale, sub};
use crate::mesh::surface::SurfaceMesh;

/// No crossable neighbour across this edge.
const NONE: u32 = u32::MAX;
/// Most triangle edges one move may cross before it gives up.
const MAX_CROSSINGS: usize = 64;

/// A point on the surface: a triangle and barycentric coordinates (non-negative, summing to 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Location {
    /// Triangle index.
    pub tri: u32,
    /// Barycentric coordinates of the triangle's three corners.
    pub bary: [f64; 3],
}

/// The input surface prepared for sliding: adjacency across non-feature edges, unit normals and
/// the feature vertices.
#[derive(Debug, Clone)]
pub struct SlideSurface {
    points: Vec<[f64; 3]>,
    tris: Vec<[u32; 3]>,
    /// Unit normal per triangle (zero for a triangle without area).
    normals: Vec<[f64; 3]>,
    /// Twice the area per triangle.
    area2: Vec<f64>,
    /// Per triangle and edge `i` (opposite corner `i`): the triangle across when the edge is not
    /// a feature, else `NONE`.
    across: Vec<[u32; 3]>,
    /// Vertices on a feature edge.
    feature: Vec<bool>,
    /// Triangles around each vertex (CSR).
    fan_start: Vec<u32>,
    fan: Vec<u32>,
    /// Vertex by exact coordinates.
    by_coords: FxHashMap<[u64; 3], u32>,
}

#[inline]
fn key(p: [f64; 3]) -> [u64; 3] {
    crate::mesh::coord_key(&p)
}

impl SlideSurface {
    /// Prepare `surface` (points with equal coordinates are merged) with edges whose normals turn
    /// by more than `feature_angle_deg` marked as features.
    pub fn new(surface: &SurfaceMesh, feature_angle_deg: f64) -> SlideSurface {
        let mut s = surface.clone();
        s.weld_exact();
        let np = s.points.len();
        let nt = s.triangles.len();
        let mut normals = Vec::with_capacity(nt);
        let mut area2 = Vec::with_capacity(nt);
        for t in 0..nt {
            let [a, b, c] = s.corners(t);
            let n = cross(sub(b, a), sub(c, a));
            let l = norm(n);
            area2.push(l);
            normals.push(if l > 0.0 && l.is_finite() {
                scale(n, 1.0 / l)
            } else {
                [0.0; 3]
            });
        }
        // Edges: sort (sorted vertex pair, tri * 3 + edge).
        let mut keys: Vec<([u32; 2], u32)> = Vec::with_capacity(3 * nt);
        for (t, v) in s.triangles.iter().enumerate() {
            for e in 0..3 {
                let (a, b) = (v[(e + 1) % 3], v[(e + 2) % 3]);
                keys.push(([a.min(b), a.max(b)], (t * 3 + e) as u32));
            }
        }
        keys.sort_unstable();
        let cos_limit = feature_angle_deg.to_radians().cos();
        let mut across = vec![[NONE; 3]; nt];
        let mut feature = vec![false; np];
        let pair = |t: usize| {
            let [x, y] = s.sides[t];
            [x.min(y), x.max(y)]
        };
        let mut i = 0;
        while i < keys.len() {
            let mut j = i + 1;
            while j < keys.len() && keys[j].0 == keys[i].0 {
                j += 1;
            }
            let mut crossable = false;
            if j - i == 2 {
                let (t1, e1) = ((keys[i].1 / 3) as usize, (keys[i].1 % 3) as usize);
                let (t2, e2) = ((keys[i + 1].1 / 3) as usize, (keys[i + 1].1 % 3) as usize);
                let (n1, mut n2) = (normals[t1], normals[t2]);
                // Consistently oriented neighbours run along the edge in opposite directions.
                let dir1 = s.triangles[t1][(e1 + 1) % 3];
                let dir2 = s.triangles[t2][(e2 + 1) % 3];
                if dir1 == dir2 {
                    n2 = scale(n2, -1.0);
                }
                let smooth = area2[t1] > 0.0
                    && area2[t2] > 0.0
                    && pair(t1) == pair(t2)
                    && t1 != t2
                    && dot(n1, n2) >= cos_limit;
                if smooth {
                    across[t1][e1] = t2 as u32;
                    across[t2][e2] = t1 as u32;
                    crossable = true;
                }
            }
            if !crossable {
                let [a, b] = keys[i].0;
                feature[a as usize] = true;
                feature[b as usize] = true;
            }
            i = j;
        }
        let (fan_start, fan) = super::incidence(np, &s.triangles);
        let mut by_coords = FxHashMap::default();
        for (i, p) in s.points.iter().enumerate() {
            by_coords.entry(key(*p)).or_insert(i as u32);
        }
        SlideSurface {
            points: s.points,
            tris: s.triangles,
            normals,
            area2,
            across,
            feature,
            fan_start,
            fan,
            by_coords,
        }
    }

    /// The surface vertex at exactly `p`, if any.
    pub fn vertex_at(&self, p: [f64; 3]) -> Option<u32> {
        self.by_coords.get(&key(p)).copied()
    }

    /// Whether vertex `v` lies on a feature edge.
    pub fn is_feature_vertex(&self, v: u32) -> bool {
        self.feature[v as usize]
    }

    /// Whether vertex `v` belongs to at least one triangle with area.
    pub fn has_triangle(&self, v: u32) -> bool {
        self.fan_of(v).iter().any(|&t| self.area2[t as usize] > 0.0)
    }

    /// The location of vertex `v` (in its first triangle), `None` for an unused vertex.
    pub fn vertex_location(&self, v: u32) -> Option<Location> {
        let &t = self.fan_of(v).first()?;
        let corner = self.tris[t as usize].iter().position(|&x| x == v)?;
        let mut bary = [0.0; 3];
        bary[corner] = 1.0;
        Some(Location { tri: t, bary })
    }

    fn fan_of(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.fan[self.fan_start[v] as usize..self.fan_start[v + 1] as usize]
    }

    /// The point of a location: `Σ λ_i v_i`.
    pub fn point(&self, loc: &Location) -> [f64; 3] {
        let [a, b, c] = self.tris[loc.tri as usize].map(|i| self.points[i as usize]);
        let l = loc.bary;
        add(add(scale(a, l[0]), scale(b, l[1])), scale(c, l[2]))
    }

    /// Distance from `p` to the plane of the location's triangle (for a point of the triangle,
    /// its distance from the surface up to round-off).
    pub fn distance(&self, loc: &Location, p: [f64; 3]) -> f64 {
        let t = loc.tri as usize;
        let a = self.points[self.tris[t][0] as usize];
        dot(sub(p, a), self.normals[t]).abs()
    }

    /// The unit normal to slide against at a location: the triangle's, or at a vertex the
    /// normalised sum of its triangles' normals.
    pub fn normal(&self, loc: &Location) -> [f64; 3] {
        if let Some(corner) = loc.bary.iter().position(|&l| l == 1.0) {
            let v = self.tris[loc.tri as usize][corner];
            let mut n = [0.0; 3];
            for &t in self.fan_of(v) {
                n = add(n, self.normals[t as usize]);
            }
            let l = norm(n);
            if l > 0.0 {
                return scale(n, 1.0 / l);
            }
        }
        self.normals[loc.tri as usize]
    }

    /// Gradients of the barycentric coordinates of triangle `t` (in its plane).
    fn bary_gradients(&self, t: usize) -> [[f64; 3]; 3] {
        let v = self.tris[t].map(|i| self.points[i as usize]);
        let n = self.normals[t];
        let a2 = self.area2[t];
        std::array::from_fn(|i| scale(cross(n, sub(v[(i + 2) % 3], v[(i + 1) % 3])), 1.0 / a2))
    }

    /// Walk `disp` along the surface from `loc`. `None` when the walk meets a feature edge or
    /// does not settle within a bounded number of crossings (a shorter move may still succeed).
    pub fn walk(&self, loc: &Location, disp: [f64; 3]) -> Option<(Location, [f64; 3])> {
        let mut tri = loc.tri as usize;
        let mut lam = loc.bary;
        let mut s = disp;
        if let Some(corner) = lam.iter().position(|&l| l == 1.0) {
            // At a vertex: start in the triangle of the fan whose sector holds the direction.
            let v = self.tris[tri][corner];
            let (t, c) = self.fan_sector(v, s)?;
            tri = t;
            lam = [0.0; 3];
            lam[c] = 1.0;
        }
        for _ in 0..MAX_CROSSINGS {
            if self.area2[tri] <= 0.0 {
                return None;
            }
            let n = self.normals[tri];
            let st = sub(s, scale(n, dot(s, n)));
            let g = self.bary_gradients(tri);
            let delta = g.map(|gi| dot(gi, st));
            let mut t_exit = f64::INFINITY;
            let mut exit = 3;
            for i in 0..3 {
                if delta[i] < 0.0 {
                    let t = lam[i] / -delta[i];
                    if t < t_exit {
                        t_exit = t;
                        exit = i;
                    }
                }
            }
            if t_exit >= 1.0 {
                for i in 0..3 {
                    lam[i] += delta[i];
                }
                let loc = Location {
                    tri: tri as u32,
                    bary: normalise(lam),
                };
                return Some((loc, self.point(&loc)));
            }
            for i in 0..3 {
                lam[i] += t_exit * delta[i];
            }
            lam[exit] = 0.0;
            lam = normalise(lam);
            let nb = self.across[tri][exit];
            if nb == NONE {
                return None;
            }
            let nb = nb as usize;
            let (a, b) = (
                self.tris[tri][(exit + 1) % 3],
                self.tris[tri][(exit + 2) % 3],
            );
            let (pa, pb) = (self.points[a as usize], self.points[b as usize]);
            // Unfold the rest of the displacement about the edge ab.
            let rest = scale(st, 1.0 - t_exit);
            let e = sub(pb, pa);
            let e = scale(e, 1.0 / norm(e));
            let opp_t = self.points[self.tris[tri][exit] as usize];
            let opp_n_corner = self.tris[nb]
                .iter()
                .position(|&x| x != a && x != b)
                .expect("a triangle has a third corner");
            let opp_n = self.points[self.tris[nb][opp_n_corner] as usize];
            let perp = |p: [f64; 3]| {
                let w = sub(p, pa);
                let w = sub(w, scale(e, dot(w, e)));
                scale(w, 1.0 / norm(w))
            };
            let m_out = scale(perp(opp_t), -1.0);
            let m_in = perp(opp_n);
            s = add(scale(e, dot(rest, e)), scale(m_in, dot(rest, m_out)));
            let mut new_lam = [0.0; 3];
            for (c, &x) in self.tris[nb].iter().enumerate() {
                if x == a {
                    new_lam[c] = lam[(exit + 1) % 3];
                } else if x == b {
                    new_lam[c] = lam[(exit + 2) % 3];
                }
            }
            lam = new_lam;
            tri = nb;
        }
        None
    }

    /// The triangle of vertex `v`'s fan (and `v`'s corner in it) whose sector contains the
    /// direction `s` projected into its plane; failing that, the one it points into most.
    fn fan_sector(&self, v: u32, s: [f64; 3]) -> Option<(usize, usize)> {
        let mut best: Option<(f64, usize, usize)> = None;
        for &t in self.fan_of(v) {
            let t = t as usize;
            if self.area2[t] <= 0.0 {
                continue;
            }
            let c = self.tris[t].iter().position(|&x| x == v)?;
            let n = self.normals[t];
            let st = sub(s, scale(n, dot(s, n)));
            let g = self.bary_gradients(t);
            let (d1, d2) = (dot(g[(c + 1) % 3], st), dot(g[(c + 2) % 3], st));
            let score = d1.min(d2) / (d1.abs() + d2.abs()).max(f64::MIN_POSITIVE);
            if best.is_none_or(|(b, _, _)| score > b) {
                best = Some((score, t, c));
            }
        }
        best.map(|(_, t, c)| (t, c))
    }
}

/// Clamp barycentric coordinates to be non-negative and rescale them to sum to 1.
fn normalise(mut l: [f64; 3]) -> [f64; 3] {
    for x in &mut l {
        if *x < 0.0 || x.is_nan() {
            *x = 0.0;
        }
    }
    let s = l[0] + l[1] + l[2];
    if s > 0.0 {
        l.map(|x| x / s)
    } else {
        [1.0 / 3.0; 3]
    }
}
