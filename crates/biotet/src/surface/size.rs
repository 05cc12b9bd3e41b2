//! Curvature-adapted target edge lengths (Dunyach, Vanderhaeghe, Barthe and Botsch 2013): at a
//! point where the surface bends with radius `r`, an edge of length `L` strays from it by about
//! `L² / (8 r)`; the target is `sqrt(6 ε r − 3 ε²)` for an allowed deviation `ε`, clamped to
//! `[min, max]`, then graded so neighbouring targets differ by at most `grading` times their
//! distance.
//!
//! The curvature at a point is estimated from its edges: the circle through the point, tangent
//! to the surface there (normal `n`, area-weighted), and through the neighbour `u` has curvature
//! `2 |n · (u − p)| / |u − p|²`; the mean over the edges is used (the maximum follows the
//! staircase noise of marching-cubes surfaces).

use crate::geom::vec3::{add, cross, dot, norm, scale, sub};
use crate::mesh::surface::SurfaceMesh;

/// Per point of `s`, the target edge length for deviation `eps`, between `min` and `max`.
pub fn point_sizes(s: &SurfaceMesh, eps: f64, min: f64, max: f64, grading: f64) -> Vec<f64> {
    let np = s.points.len();
    let mut normal = vec![[0.0; 3]; np];
    for t in 0..s.triangles.len() {
        let c = s.corners(t);
        let n = cross(sub(c[1], c[0]), sub(c[2], c[0]));
        for &v in &s.triangles[t] {
            normal[v as usize] = add(normal[v as usize], n);
        }
    }
    for n in &mut normal {
        let l = norm(*n);
        if l > 0.0 {
            *n = scale(*n, 1.0 / l);
        }
    }
    let mut sum = vec![0.0; np];
    let mut count = vec![0u32; np];
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(3 * s.triangles.len());
    for tri in &s.triangles {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b)));
        }
    }
    edges.sort_unstable();
    edges.dedup();
    for &(a, b) in &edges {
        let d = sub(s.points[b as usize], s.points[a as usize]);
        let l2 = dot(d, d);
        if l2 == 0.0 {
            continue;
        }
        for (v, sign) in [(a, 1.0), (b, -1.0)] {
            let k = 2.0 * (sign * dot(normal[v as usize], d)).abs() / l2;
            sum[v as usize] += k;
            count[v as usize] += 1;
        }
    }
    let mut size: Vec<f64> = (0..np)
        .map(|v| {
            if count[v] == 0 {
                return max;
            }
            let k = sum[v] / count[v] as f64;
            if k <= 0.0 {
                return max;
            }
            let r = 1.0 / k;
            let x = 6.0 * eps * r - 3.0 * eps * eps;
            if x <= 0.0 {
                min
            } else {
                x.sqrt().clamp(min, max)
            }
        })
        .collect();
    // Grading: a few Gauss–Seidel sweeps in index order (deterministic).
    for _ in 0..8 {
        let mut changed = false;
        for &(a, b) in &edges {
            let d = norm(sub(s.points[b as usize], s.points[a as usize]));
            let (sa, sb) = (size[a as usize], size[b as usize]);
            if sa > sb + grading * d {
                size[a as usize] = sb + grading * d;
                changed = true;
            } else if sb > sa + grading * d {
                size[b as usize] = sa + grading * d;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    size
}
