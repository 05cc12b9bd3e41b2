//! Thin necks: three points joined pairwise by edges that bound no triangle, all of them shorter
//! than the working tolerance. The surface is a tube there (a handle or a bridge,
//! as marching cubes leaves along a voxel edge where two voxels touch diagonally), and its
//! cross-section is that 3-cycle. No edge of it can collapse (the surface would pinch; the link
//! condition refuses), so the tube's wall triangles keep an angle near zero. Opening the neck —
//! moving its points apart, away from the cycle's centroid, within the working tolerance — keeps
//! the shell's genus and gives the walls a usable width.

use super::{P3, Remesher};
use crate::geom::vec3::{add, dot, scale, sub};

impl Remesher<'_> {
    /// The necks whose edges are all shorter than `width`: sorted corner triples, each once.
    fn necks(&self, width: f64) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        for (a, b) in self.edges() {
            if self.len(a, b) >= width {
                continue;
            }
            for c in self.neighbours(a) {
                if c == b
                    || !self.has_edge(b, c)
                    || self.len(a, c) >= width
                    || self.len(b, c) >= width
                {
                    continue;
                }
                let face = self.vt[a as usize].iter().any(|&t| {
                    let tri = self.tris[t as usize];
                    tri.contains(&b) && tri.contains(&c)
                });
                if !face {
                    let mut n = [a, b, c];
                    n.sort_unstable();
                    out.push(n);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Open the necks narrower than the working tolerance (every edge of the cycle shorter): each
    /// free corner is moved away from the cycle's centroid so that its distance to it becomes
    /// `tol` (the move at most `0.9 tol`, halved while the guards of [`Remesher::try_move`]
    /// refuse it). Wider necks are left: they are the surface's own shape. Returns the points
    /// moved.
    pub fn open_necks(&mut self) -> usize {
        let mut moved = 0;
        for n in self.necks(self.tol) {
            let g: P3 = scale(
                add(
                    add(self.pts[n[0] as usize], self.pts[n[1] as usize]),
                    self.pts[n[2] as usize],
                ),
                1.0 / 3.0,
            );
            for v in n {
                let p = self.pts[v as usize];
                let u = sub(p, g);
                let r = dot(u, u).sqrt();
                if r == 0.0 || r >= self.tol {
                    continue;
                }
                let mut step = (self.tol - r).min(0.9 * self.tol);
                for _ in 0..3 {
                    let x = add(p, scale(u, step / r));
                    if self.try_move(v, x) {
                        moved += 1;
                        break;
                    }
                    step *= 0.5;
                }
            }
        }
        moved
    }
}
