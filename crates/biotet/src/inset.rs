//! Interior points just behind surface triangles: the pipeline's last fallback when recovery
//! leaves triangles missing.
//!
//! A triangle recovery cannot make a face (a long strip of a CAD face, a fan over collinear
//! points) often has no apex among the points around it that makes a tet with it without
//! crossing another constraint, and its cavities' cells have no kernel for one point. A point
//! just behind it, near its centroid, is such an apex. The pipeline puts one behind each
//! triangle left and each triangle sharing a corner with one (their cavities are the same
//! tets), tetrahedralizes again with them as interior nodes and recovers again (a cube of
//! strip-cut faces: 61 triangles left, none after 247 such points).
//!
//! Each point is `c - δ n`: `c` the triangle's centroid, `n` its unit normal (towards its front
//! side; turned where the region behind is the outside, label 0), `δ` half its inradius, halved
//! until the point is at least `δ / 2` from every other surface triangle (a thin wall behind it)
//! and, by the exact ray-parity test of [`crate::mesh::inside`], strictly inside the region behind
//! the triangle; never on the surface, so every triangle stays as given. Floating point chooses the
//! place; the region test decides.

use crate::geom::vec3::{cross, norm, scale, sub};
use crate::mesh::inside::{Location, RegionLocator};
use crate::mesh::surface::SurfaceMesh;
use crate::surface::bvh::Bvh;

type P3 = [f64; 3];

/// Halvings of the offset before a triangle is given up.
const HALVINGS: usize = 6;

/// The triangles of `surface` sharing a corner with one of `tris` (those included), sorted.
pub fn with_corner_neighbours(surface: &SurfaceMesh, tris: &[usize]) -> Vec<usize> {
    let mut corner = vec![false; surface.points.len()];
    for &t in tris {
        for v in surface.triangles[t] {
            corner[v as usize] = true;
        }
    }
    (0..surface.triangles.len())
        .filter(|&t| surface.triangles[t].iter().any(|&v| corner[v as usize]))
        .collect()
}

/// A point strictly inside the region behind each of `tris` (see the module docs), with that
/// region's label; a triangle whose point cannot be placed (a wall thinner than its offsets)
/// gives none.
pub fn points_behind(surface: &SurfaceMesh, tris: &[usize]) -> Vec<(P3, u32)> {
    let bvh = Bvh::of_surface(surface);
    let locator = RegionLocator::new(surface);
    let mut out: Vec<(P3, u32)> = Vec::with_capacity(tris.len());
    for &t in tris {
        let [a, b, c] = surface.corners(t);
        let n = cross(sub(b, a), sub(c, a));
        let area2 = norm(n);
        let perimeter = norm(sub(b, a)) + norm(sub(c, b)) + norm(sub(a, c));
        if area2 == 0.0 || !area2.is_finite() || perimeter == 0.0 {
            continue;
        }
        // Behind the triangle, or in front where behind is the outside (a sheet of a label
        // image facing its region).
        let [back, front] = surface.sides[t];
        let (n, behind) = if back != 0 {
            (scale(n, 1.0 / area2), back)
        } else {
            (scale(n, -1.0 / area2), front)
        };
        if behind == 0 {
            continue;
        }
        let centroid = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
        let mut delta = 0.5 * area2 / perimeter;
        for _ in 0..HALVINGS {
            let p = sub(centroid, scale(n, delta));
            // This triangle is `delta` away: another one within half of that is a wall behind
            // (or a fold beside), too close for a useful tet.
            let clear = bvh.closest_within(p, 0.25 * delta * delta).is_none();
            if clear && locator.locate(p) == Location::Region(behind) {
                out.push((p, behind));
                break;
            }
            delta *= 0.5;
        }
    }
    out.sort_by(|x, y| x.0.map(f64::to_bits).cmp(&y.0.map(f64::to_bits)));
    out.dedup_by(|x, y| x.0 == y.0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle of a sphere gets a point inside it, half its inradius behind it; with the
    /// triangles turned inward and the sides swapped (the region in front), the same points.
    #[test]
    fn points_lie_behind_each_triangle_in_its_region() {
        let s = SurfaceMesh::icosphere(1.0, 1);
        let all: Vec<usize> = (0..s.triangles.len()).collect();
        let pts = points_behind(&s, &all);
        assert_eq!(pts.len(), s.triangles.len());
        for &(p, label) in &pts {
            assert_eq!(label, 1);
            let r = norm(p);
            assert!(r < 1.0 && r > 0.8, "{r}");
        }
        let mut turned = s.clone();
        for (t, sides) in turned.triangles.iter_mut().zip(turned.sides.iter_mut()) {
            t.swap(1, 2);
            *sides = [0, 1];
        }
        assert_eq!(points_behind(&turned, &all), pts);
        // Corner neighbours of one triangle: itself and those sharing a corner with it.
        let near = with_corner_neighbours(&s, &[0]);
        assert!(near.contains(&0) && near.len() > 3 && near.len() < 16);
    }
}
