//! The input side of the distance bound during remeshing: sample points of the input (every
//! corner and a barycentric grid on each triangle), each with the triangle it was taken from, so
//! the remesher can give every sample a covering triangle and check, when an operation replaces
//! triangles, that the samples they covered stay within the tolerance of the surface.

use super::bvh::dist2;
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

impl InputSamples {
    /// Sample `s` with grid step at most `spacing` on each triangle.
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
            let longest = (0..3)
                .map(|k| dist2(c[k], c[(k + 1) % 3]))
                .fold(0.0, f64::max)
                .sqrt();
            let n = ((longest / spacing).ceil() as usize).max(1);
            for i in 0..=n {
                for j in 0..=n - i {
                    let k = n - i - j;
                    let w = [i as f64, j as f64, k as f64].map(|x| x / n as f64);
                    let p = [0, 1, 2].map(|a| w[0] * c[0][a] + w[1] * c[1][a] + w[2] * c[2][a]);
                    // A corner belongs to the first triangle that uses it (edge samples
                    // are taken by both triangles of the edge, harmlessly).
                    if (i == n && t > vt_first(t, 0))
                        || (j == n && t > vt_first(t, 1))
                        || (k == n && t > vt_first(t, 2))
                    {
                        continue;
                    }
                    out.pts.push(p);
                    out.sides.push(s.sides[t]);
                    out.tri.push(t as u32);
                }
            }
        }
        out
    }
}
