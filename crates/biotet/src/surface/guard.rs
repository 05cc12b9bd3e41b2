//! The input side of the distance bound during remeshing: sample points of the input (every
//! corner and a barycentric grid on each triangle), bucketed in a uniform grid, so an operation
//! can check that the input near the triangles it replaces stays within the tolerance of the
//! surface that replaces them.

use rustc_hash::FxHashMap;

use super::bvh::dist2;
use crate::mesh::surface::SurfaceMesh;

type P3 = [f64; 3];

/// Input samples in a hashed grid.
#[derive(Debug, Clone, Default)]
pub struct InputSamples {
    /// Sample points.
    pub pts: Vec<P3>,
    /// Side labels of the triangle each sample came from.
    pub sides: Vec<[u32; 2]>,
    h: f64,
    cells: FxHashMap<[i32; 3], Vec<u32>>,
}

impl InputSamples {
    /// Sample `s` with grid step at most `spacing` on each triangle; cells of size `h`.
    pub fn new(s: &SurfaceMesh, spacing: f64, h: f64) -> InputSamples {
        let mut out = InputSamples {
            h,
            ..Default::default()
        };
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
                    let id = out.pts.len() as u32;
                    out.pts.push(p);
                    out.sides.push(s.sides[t]);
                    out.cells.entry(out.cell(p)).or_default().push(id);
                }
            }
        }
        out
    }

    fn cell(&self, p: P3) -> [i32; 3] {
        p.map(|c| (c / self.h).floor() as i32)
    }

    /// The samples in the box `lo..hi`, in index order.
    pub fn in_box(&self, lo: P3, hi: P3, out: &mut Vec<u32>) {
        out.clear();
        let a = self.cell(lo);
        let b = self.cell(hi);
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                for k in a[2]..=b[2] {
                    if let Some(v) = self.cells.get(&[i, j, k]) {
                        for &s in v {
                            let p = self.pts[s as usize];
                            if (0..3).all(|x| p[x] >= lo[x] && p[x] <= hi[x]) {
                                out.push(s);
                            }
                        }
                    }
                }
            }
        }
        out.sort_unstable();
    }
}
