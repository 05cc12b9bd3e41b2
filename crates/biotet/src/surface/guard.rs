//! The input side of the distance bound during remeshing: sample points of the input (every
//! corner and a barycentric grid, or on a needle rows, on each triangle), each with the triangle it was taken from, so
//! the remesher can give every sample a covering triangle and check, when an operation replaces
//! triangles, that the samples they covered stay within the tolerance of the surface.

use super::bvh::dist2;
use crate::geom::vec3::{cross, norm, sub};
use crate::mesh::surface::SurfaceMesh;

type P3 = [f64; 3];

/// Input samples.
#[derive(Debug, Clone, Default)]
pub struct InputSamples {
    /// Sample points.
    pub pts: Vec<P3>,
    /// Side labels of the triangle each sample came from.
    pub sides: Vec<[u32; 2]>,
    /// The triangle each sample came from.
    pub tri: Vec<u32>,
}

/// Triangles with more grid steps along their longest edge than this are sampled in rows
/// instead ([`InputSamples::new`]).
const GRID_STEPS: usize = 64;

impl InputSamples {
    /// Sample `s` with step at most `spacing` on each triangle: a barycentric grid with that
    /// step along the longest edge, or, on a triangle more than `GRID_STEPS` steps long, rows
    /// parallel to its longest edge, `spacing` apart. The grid's samples grow with the square of
    /// the longest edge however thin the triangle: a needle 200 long and 0.4 wide at spacing 0.25
    /// held 320,000, its rows 1,200.
    pub fn new(s: &SurfaceMesh, spacing: f64) -> InputSamples {
        let mut out = InputSamples::default();
        let mut first = vec![u32::MAX; s.points.len()];
        for (t, tri) in s.triangles.iter().enumerate().rev() {
            for &v in tri {
                first[v as usize] = t as u32;
            }
        }
        let vt_first = |t: usize, k: usize| first[s.triangles[t][k] as usize] as usize;
        for t in 0..s.triangles.len() {
            let c = s.corners(t);
            let lengths = [0, 1, 2].map(|k| dist2(c[k], c[(k + 1) % 3]).sqrt());
            let longest = lengths.iter().copied().fold(0.0, f64::max);
            let n = ((longest / spacing).ceil() as usize).max(1);
            // A corner belongs to the first triangle that uses it (edge samples are taken by both
            // triangles of the edge, harmlessly).
            let owns = |k: usize| t <= vt_first(t, k);
            let mut push = |p: P3| {
                out.pts.push(p);
                out.sides.push(s.sides[t]);
                out.tri.push(t as u32);
            };
            if n <= GRID_STEPS {
                for i in 0..=n {
                    for j in 0..=n - i {
                        let k = n - i - j;
                        if (i == n && !owns(0)) || (j == n && !owns(1)) || (k == n && !owns(2)) {
                            continue;
                        }
                        let w = [i as f64, j as f64, k as f64].map(|x| x / n as f64);
                        push([0, 1, 2].map(|a| w[0] * c[0][a] + w[1] * c[1][a] + w[2] * c[2][a]));
                    }
                }
                continue;
            }
            // Rows from the longest edge `ab` up to the opposite corner `c`.
            let e = (0..3).find(|&k| lengths[k] == longest).unwrap_or(0);
            let (a, b, o) = (e, (e + 1) % 3, (e + 2) % 3);
            let area2 = norm(cross(sub(c[b], c[a]), sub(c[o], c[a])));
            let height = area2 / longest;
            let m = ((height / spacing).ceil() as usize).max(1);
            for i in 0..=m {
                let f = i as f64 / m as f64;
                let steps = ((longest * (1.0 - f) / spacing).ceil() as usize).max(1);
                let from = [0, 1, 2].map(|x| c[a][x] + f * (c[o][x] - c[a][x]));
                let to = [0, 1, 2].map(|x| c[b][x] + f * (c[o][x] - c[b][x]));
                if i == m {
                    if owns(o) {
                        push(c[o]);
                    }
                    continue;
                }
                for j in 0..=steps {
                    if (i == 0 && j == 0 && !owns(a)) || (i == 0 && j == steps && !owns(b)) {
                        continue;
                    }
                    let g = j as f64 / steps as f64;
                    push([0, 1, 2].map(|x| from[x] + g * (to[x] - from[x])));
                }
            }
        }
        out
    }
}
