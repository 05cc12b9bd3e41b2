//! Thin necks: three points joined pairwise by edges that bound no triangle, all of them shorter
//! than the working tolerance. The surface is a tube there (a handle or a bridge,
//! as marching cubes leaves along a voxel edge where two voxels touch diagonally), and its
//! cross-section is that 3-cycle. No edge of it can collapse (the surface would pinch; the link
//! condition refuses), so the tube's wall triangles keep an angle near zero. Opening the neck —
//! spreading its points around the tube's axis, within the working tolerance — keeps the shell's
//! genus and gives the walls a usable width.
//!
//! An opened neck is remembered as a *tube* (its centroid, axis and radius). The tube's walls are
//! as long as the voxel edge (4 mm on wm_20k) against its 0.6 mm width, so they are needles and
//! the tets inside wedges. Near a tube the target edge length is capped (four radii, growing by
//! half the distance), so the rounds cut the walls into rings; and a point projected onto the
//! input inside the tube's radius is lifted to it, across the axis in the direction of the point
//! it came from, since the input there is a flat fin of the voxel face and the rings' points
//! would otherwise fall back onto it and flatten the tube again.

use super::dist2;
use super::{P3, Remesher};
use crate::geom::vec3::{add, cross, dot, norm, scale, sub};

/// An opened neck's tube.
#[derive(Debug, Clone, Copy)]
pub(super) struct Tube {
    /// The neck's centroid.
    g: P3,
    /// The tube's axis (unit).
    w: P3,
    /// The neck's mean distance from the axis.
    rho: f64,
}

/// The part of `u` across the unit direction `w`.
fn across(u: P3, w: P3) -> P3 {
    sub(u, scale(w, dot(u, w)))
}

/// The edge-length cap near a tube: this many radii at the neck...
const TUBE_SIZE: f64 = 4.0;
/// ...growing by this much per unit of distance beyond the radius.
const TUBE_GRADING: f64 = 0.5;

impl Remesher<'_> {
    /// The cell of `p` in the tubes' hash: cubes of twice the target edge length plus the
    /// tolerance, beyond which a tube's cap exceeds every target and its lift does not reach.
    fn tube_cell(&self, p: P3) -> [i32; 3] {
        p.map(|x| (x / (2.0 * (self.l + self.tol))).floor() as i32)
    }

    /// The tubes whose reach may include `p`.
    fn tubes_near(&self, p: P3) -> &[u32] {
        self.tube_cells
            .get(&self.tube_cell(p))
            .map_or(&[], |v| v.as_slice())
    }

    /// Remember a tube (listed in every cell next to its own).
    fn add_tube(&mut self, t: Tube) {
        let id = self.tubes.len() as u32;
        let c = self.tube_cell(t.g);
        for i in -1..=1 {
            for j in -1..=1 {
                for k in -1..=1 {
                    self.tube_cells
                        .entry([c[0] + i, c[1] + j, c[2] + k])
                        .or_default()
                        .push(id);
                }
            }
        }
        self.tubes.push(t);
    }

    /// The cap on the target edge length at `p` from the tubes (infinite far from them).
    pub(super) fn tube_size(&self, p: P3) -> f64 {
        self.tubes_near(p)
            .iter()
            .map(|&i| {
                let t = &self.tubes[i as usize];
                TUBE_SIZE * t.rho + TUBE_GRADING * (dist2(p, t.g).sqrt() - t.rho).max(0.0)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Input point `q` for the output point near `p`: within a tube's reach (one target edge
    /// length along it) and inside its radius, moved out to the radius in the direction of `p`
    /// around the axis; elsewhere `q` itself.
    pub(super) fn lift(&self, p: P3, q: P3) -> P3 {
        if self.tubes.is_empty() {
            return q;
        }
        for &i in self.tubes_near(q) {
            let t = &self.tubes[i as usize];
            let u = sub(q, t.g);
            let a = dot(u, t.w);
            if a.abs() > self.l || norm(across(u, t.w)) >= t.rho {
                continue;
            }
            let x = across(sub(p, t.g), t.w);
            let r = norm(x);
            if r > 0.0 {
                return add(add(t.g, scale(t.w, a)), scale(x, t.rho / r));
            }
        }
        q
    }

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

    /// The apex of the triangle that has the directed edge `u → v`.
    fn apex(&self, u: u32, v: u32) -> Option<u32> {
        self.vt[u as usize].iter().find_map(|&t| {
            let tri = self.tris[t as usize];
            let k = tri.iter().position(|&x| x == u)?;
            (tri[(k + 1) % 3] == v).then_some(tri[(k + 2) % 3])
        })
    }

    /// The direction of the tube through neck `n`: the triangles on the left of the directed
    /// cycle `n0 → n1 → n2` all lie towards one end of the tube and those on the right towards
    /// the other, so the sum of left apex minus right apex over the three edges runs along it.
    fn neck_axis(&self, n: [u32; 3]) -> Option<P3> {
        let mut w = [0.0; 3];
        for k in 0..3 {
            let (u, v) = (n[k], n[(k + 1) % 3]);
            let (x, y) = (self.apex(u, v)?, self.apex(v, u)?);
            w = add(w, sub(self.pts[x as usize], self.pts[y as usize]));
        }
        let l = norm(w);
        (l > 0.0).then(|| scale(w, 1.0 / l))
    }

    /// Open the necks narrower than the working tolerance (every edge of the cycle shorter): the
    /// cycle's corners are placed on the circle of radius `tol` around its centroid, in the
    /// plane across the tube, 120° apart (the corner farthest from the tube's axis keeps its
    /// direction), each move at most `0.9 tol` and halved while the guards of
    /// [`Remesher::try_move`] refuse it. Moving away from the centroid alone would stretch a
    /// cycle that lies along the tube (a needle of a cross-section) further along it. Wider
    /// necks are left: they are the surface's own shape. Returns the points moved.
    pub fn open_necks(&mut self) -> usize {
        let mut moved = 0;
        for n in self.necks(self.tol) {
            let p = n.map(|v| self.pts[v as usize]);
            let g: P3 = scale(add(add(p[0], p[1]), p[2]), 1.0 / 3.0);
            let Some(w) = self.neck_axis(n) else {
                continue;
            };
            // The corners' offsets across the tube.
            let q = p.map(|x| across(sub(x, g), w));
            let k0 = (0..3)
                .max_by(|&i, &j| dot(q[i], q[i]).total_cmp(&dot(q[j], q[j])))
                .unwrap_or(0);
            let r0 = norm(q[k0]);
            if r0 == 0.0 {
                continue;
            }
            let d0 = scale(q[k0], 1.0 / r0);
            let e = cross(w, d0);
            let at = |deg: f64| {
                let a = deg.to_radians();
                add(
                    g,
                    scale(add(scale(d0, a.cos()), scale(e, a.sin())), self.tol),
                )
            };
            let (k1, k2) = ((k0 + 1) % 3, (k0 + 2) % 3);
            // The two others take 120° and 240° in the order that moves them least.
            let (a1, a2) = if dist2(p[k1], at(120.0)) + dist2(p[k2], at(240.0))
                <= dist2(p[k1], at(240.0)) + dist2(p[k2], at(120.0))
            {
                (120.0, 240.0)
            } else {
                (240.0, 120.0)
            };
            for (k, target) in [(k0, at(0.0)), (k1, at(a1)), (k2, at(a2))] {
                let v = n[k];
                let x0 = self.pts[v as usize];
                let step = sub(target, x0);
                let len = norm(step);
                if len == 0.0 {
                    continue;
                }
                let mut s = (0.9 * self.tol / len).min(1.0);
                for _ in 0..3 {
                    if self.try_move(v, add(x0, scale(step, s))) {
                        moved += 1;
                        break;
                    }
                    s *= 0.5;
                }
            }
            let rho = n
                .iter()
                .map(|&v| norm(across(sub(self.pts[v as usize], g), w)))
                .sum::<f64>()
                / 3.0;
            let known = self.tubes_near(g).iter().any(|&i| {
                let t = &self.tubes[i as usize];
                dist2(t.g, g) < t.rho * t.rho
            });
            // A neck the guards kept narrow is not a tube to ring: its cap would be a fraction of
            // the tolerance (a hair-thin torus would be cut into thousands of rings).
            if rho >= 0.5 * self.tol && !known {
                self.add_tube(Tube { g, w, rho });
            }
        }
        moved
    }
}
