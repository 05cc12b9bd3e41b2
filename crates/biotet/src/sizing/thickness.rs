//! The surface's local thickness, to cap the sizes measured on it.
//!
//! The size from the surface is the mean edge length at each node. Where the domain is between
//! one and two such sizes thick (a tube a tenth as wide as its ring), the template's sealing
//! zones (eq. 2.7: √(2/3)·size from each wall) cover the whole cross-section, no interior node is
//! placed, and every tet spans the domain from wall to wall: flat tets no later stage can repair
//! without new points (trimesh's thin torus: 441 tets under 10°; 3 with `--size` at half the
//! tube's width). Capping such a node's size at half the distance to the wall facing it leaves
//! room for a node between the two walls. Thinner walls are left alone: their triangles are
//! larger than the thickness and force their tets (a coarse plate, a 1000:1 box), and nodes on
//! poor triangles too (see [`on_poor_triangles`]).
//!
//! The thickness at a node is the distance to the nearest node of a facing wall: behind the node
//! (against its normal), with a normal pointing back at it. Floating point: sizes are a
//! heuristic, never a combinatorial decision.

use crate::geom::vec3::{add, cross, dot, norm, norm2, scale, sub};
use crate::mesh::surface::SurfaceMesh;
use rustc_hash::FxHashMap;

type P3 = [f64; 3];

/// Facing walls: the normals' cosine at most this (more than 120° apart).
const FACING: f64 = -0.5;

/// Triangles with a smaller angle force poor tets (see [`on_poor_triangles`]).
const POOR_DEG: f64 = 10.0;

/// Cells searched each way from a node's cell (bounds the work on a few very large sizes).
const MAX_REACH: i64 = 4;

/// Cap `h[i]` (the size at node `ids[i]` of `surface`) at half the thickness there. Returns how
/// many sizes were lowered.
pub(crate) fn cap_by_thickness(surface: &SurfaceMesh, ids: &[u32], h: &mut [f64]) -> usize {
    if ids.is_empty() {
        return 0;
    }
    let normals = vertex_normals(surface);
    let poor = on_poor_triangles(surface);
    let pts = &surface.points;
    let mut sorted: Vec<f64> = h.to_vec();
    sorted.sort_by(f64::total_cmp);
    let cell = sorted[sorted.len() / 2];
    if !(cell > 0.0 && cell.is_finite()) {
        return 0;
    }
    let key = |p: P3| p.map(|c| (c / cell).floor() as i64);
    let mut grid: FxHashMap<[i64; 3], Vec<u32>> = FxHashMap::default();
    for (k, &v) in ids.iter().enumerate() {
        grid.entry(key(pts[v as usize])).or_default().push(k as u32);
    }
    let mut lowered = 0;
    let old: Vec<f64> = h.to_vec();
    for (k, &v) in ids.iter().enumerate() {
        let p = pts[v as usize];
        let n = normals[v as usize];
        if norm2(n) == 0.0 || poor[v as usize] {
            continue;
        }
        // Only walls closer than twice the size matter (the cap is half the thickness).
        let radius = 2.0 * old[k];
        let reach = ((radius / cell).ceil() as i64).min(MAX_REACH);
        let c = key(p);
        let mut best = radius * radius;
        for dz in -reach..=reach {
            for dy in -reach..=reach {
                for dx in -reach..=reach {
                    let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    for &j in list {
                        let w = ids[j as usize];
                        let q = pts[w as usize];
                        let d = sub(q, p);
                        let d2 = norm2(d);
                        if d2 >= best || d2 == 0.0 {
                            continue;
                        }
                        let m = normals[w as usize];
                        if dot(n, m) <= FACING && dot(d, n) < 0.0 && dot(d, m) > 0.0 {
                            best = d2;
                        }
                    }
                }
            }
        }
        let t = best.sqrt();
        // Walls closer than the size: the triangles are too large for a node between them to
        // make tets any better (a 1000:1 box, a coarse plate: nodes that close only multiply the
        // tets forced flat by those triangles), or the walls' own tets are already as thin as
        // the wall (gmsh's tube with a wall half its triangles' size meshes with none under 10°
        // as it is, and capped it took a template four times finer).
        if t < radius && 0.5 * t < h[k] && t >= old[k] {
            h[k] = 0.5 * t;
            lowered += 1;
        }
    }
    lowered
}

/// Nodes of a triangle with an angle under [`POOR_DEG`]: every tet on such a triangle is poor
/// whatever the nodes around it (forced), and more nodes there only make more of them (trimesh's
/// 256-section cylinder, whose caps are fans of 1.4° triangles: 773 tets under 10° without the
/// cap, 930 with it).
fn on_poor_triangles(surface: &SurfaceMesh) -> Vec<bool> {
    let mut poor = vec![false; surface.points.len()];
    for t in &surface.triangles {
        let c = t.map(|i| surface.points[i as usize]);
        if crate::quality::tri::min_angle_3d_deg(&c) < POOR_DEG {
            for &i in t {
                poor[i as usize] = true;
            }
        }
    }
    poor
}

/// Unit area-weighted normals of the surface's nodes (zero for an unreferenced node).
fn vertex_normals(surface: &SurfaceMesh) -> Vec<P3> {
    let mut n = vec![[0.0; 3]; surface.points.len()];
    for t in &surface.triangles {
        let [a, b, c] = t.map(|i| surface.points[i as usize]);
        let f = cross(sub(b, a), sub(c, a));
        for &i in t {
            n[i as usize] = add(n[i as usize], f);
        }
    }
    for v in &mut n {
        let l = norm(*v);
        if l > 0.0 {
            *v = scale(*v, 1.0 / l);
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mean_edges(s: &SurfaceMesh) -> Vec<f64> {
        let mut sum = vec![0.0; s.points.len()];
        let mut n = vec![0.0; s.points.len()];
        for t in &s.triangles {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                let l = norm(sub(s.points[a], s.points[b]));
                for v in [a, b] {
                    sum[v] += l;
                    n[v] += 1.0;
                }
            }
        }
        sum.iter().zip(&n).map(|(s, n)| s / n).collect()
    }

    #[test]
    fn a_flattened_sphere_caps_its_sizes_at_half_its_thickness() {
        // A lens: the unit icosphere (edges about 0.15) flattened to 0.2 thick at its centre, so
        // near the centre the walls are between one and two sizes apart.
        let mut s = SurfaceMesh::icosphere(1.0, 3);
        for p in &mut s.points {
            p[2] *= 0.1;
        }
        let ids: Vec<u32> = (0..s.points.len() as u32).collect();
        let mut h = mean_edges(&s);
        let before = h.clone();
        assert!(cap_by_thickness(&s, &ids, &mut h) > 0);
        let mut capped = 0;
        for (i, p) in s.points.iter().enumerate() {
            // Near the centre the wall facing a node is about 2|z| away, straight across.
            let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
            if r < 0.3 {
                let t = 2.0 * p[2].abs();
                assert!(
                    before[i] <= t && t < 2.0 * before[i],
                    "{i}: {} {t}",
                    before[i]
                );
                assert!(
                    h[i] <= 0.5 * t * 1.01 && h[i] >= 0.5 * t * 0.95,
                    "{i}: {} {t}",
                    h[i]
                );
                capped += 1;
            }
        }
        assert!(capped > 4);
    }

    #[test]
    fn a_round_sphere_keeps_its_sizes() {
        let s = SurfaceMesh::icosphere(1.0, 3);
        let ids: Vec<u32> = (0..s.points.len() as u32).collect();
        let mut h = mean_edges(&s);
        let before = h.clone();
        assert_eq!(cap_by_thickness(&s, &ids, &mut h), 0);
        assert_eq!(h, before);
    }
}
