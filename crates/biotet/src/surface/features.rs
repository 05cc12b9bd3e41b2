//! What remeshing must keep: the feature edges and the points that may not move.
//!
//! An edge is a *feature* when it is not an ordinary edge between two triangles of one sheet:
//! used by other than two triangles (a non-manifold edge, where three or more regions meet —
//! a triple line, or shells touching along an edge), between two triangles with different side
//! labels (the rim of an interface patch), or sharp: the interior dihedral angle between its two
//! triangles below the feature angle. Feature edges are never split, collapsed or flipped by the
//! rounds (one longer than they would split is cut into kept pieces before them,
//! [`super::presplit`]), so the feature polylines, the triple lines and the interface rims stay
//! exactly as given.
//!
//! A point is *fixed* (never moved, never removed) when it lies on a feature edge or when its
//! triangles do not form one fan (regions touching at a point). Every other point has a
//! single fan of triangles with one side-label pair, and may slide on the input surface.

use rustc_hash::{FxHashMap, FxHashSet};

use super::bvh::unit_normal;
use crate::geom::vec3::dot;
use crate::mesh::surface::SurfaceMesh;

/// The edges and points remeshing keeps.
#[derive(Debug, Clone, Default)]
pub struct Features {
    /// Feature edges as `(min, max)` point pairs.
    pub edges: FxHashSet<(u32, u32)>,
    /// Per point: never moved nor removed.
    pub fixed: Vec<bool>,
    /// Edges kept for their dihedral angle alone.
    pub n_sharp: usize,
    /// Edges between triangles with different side labels (interface rims) or used by other
    /// than two triangles (triple lines, touching shells).
    pub n_rim: usize,
}

/// Sorted edge key.
#[inline]
pub fn key(a: u32, b: u32) -> (u32, u32) {
    if a < b { (a, b) } else { (b, a) }
}

/// Find the features of `s` with dihedral angles below `feature_angle_deg` counted as sharp
/// (0 keeps no edge for its angle alone).
pub fn find(s: &SurfaceMesh, feature_angle_deg: f64) -> Features {
    let np = s.points.len();
    let mut edge_tris: FxHashMap<(u32, u32), Vec<u32>> = FxHashMap::default();
    for (t, tri) in s.triangles.iter().enumerate() {
        for k in 0..3 {
            edge_tris
                .entry(key(tri[k], tri[(k + 1) % 3]))
                .or_default()
                .push(t as u32);
        }
    }
    // Dihedral angle φ between two triangles of a consistently oriented sheet: the angle
    // between their normals is 180° − φ.
    let cos_limit = (std::f64::consts::PI - feature_angle_deg.to_radians()).cos();
    let mut f = Features {
        fixed: vec![false; np],
        ..Default::default()
    };
    let mut keys: Vec<(u32, u32)> = edge_tris.keys().copied().collect();
    keys.sort_unstable();
    for e in keys {
        let ts = &edge_tris[&e];
        let rim = ts.len() != 2 || s.sides[ts[0] as usize] != s.sides[ts[1] as usize];
        let sharp = !rim && feature_angle_deg > 0.0 && {
            let n0 = unit_normal(&s.corners(ts[0] as usize));
            let n1 = unit_normal(&s.corners(ts[1] as usize));
            dot(n0, n1) < cos_limit
        };
        if rim || sharp {
            f.edges.insert(e);
            f.fixed[e.0 as usize] = true;
            f.fixed[e.1 as usize] = true;
            if rim {
                f.n_rim += 1;
            } else {
                f.n_sharp += 1;
            }
        }
    }
    // Points whose triangles are not one fan.
    let mut vt: Vec<Vec<u32>> = vec![Vec::new(); np];
    for (t, tri) in s.triangles.iter().enumerate() {
        for &v in tri {
            vt[v as usize].push(t as u32);
        }
    }
    for (v, tris) in vt.iter().enumerate() {
        if !f.fixed[v] && !tris.is_empty() && !single_fan(s, v as u32, tris) {
            f.fixed[v] = true;
        }
    }
    f
}

/// Whether the triangles around `v` form one closed fan: their edges opposite `v` form a single
/// cycle.
pub fn single_fan(s: &SurfaceMesh, v: u32, tris: &[u32]) -> bool {
    let mut next: FxHashMap<u32, u32> = FxHashMap::default();
    for &t in tris {
        let tri = s.triangles[t as usize];
        let i = tri.iter().position(|&x| x == v).unwrap_or(0);
        let (a, b) = (tri[(i + 1) % 3], tri[(i + 2) % 3]);
        if next.insert(a, b).is_some() {
            return false;
        }
    }
    let start = s.triangles[tris[0] as usize]
        .iter()
        .copied()
        .find(|&x| x != v)
        .unwrap_or(v);
    let mut x = start;
    for _ in 0..tris.len() {
        match next.get(&x) {
            Some(&y) => x = y,
            None => return false,
        }
    }
    x == start && {
        // A cycle of length tris.len() through every link point once.
        let mut seen = FxHashSet::default();
        let mut y = start;
        for _ in 0..tris.len() {
            if !seen.insert(y) {
                return false;
            }
            y = next[&y];
        }
        true
    }
}
