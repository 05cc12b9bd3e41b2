//! Sharp folds: an edge where the surface bends so far that a region beside it has an interior
//! dihedral angle under [`FOLD_ANGLE`]. Every tet at that edge has its dihedral angle there at
//! most the fold's, so a fold of 5° forces a tet of 5° whatever the mesher does. The rounds and
//! the clean-up judge triangles by their own angles, which can all be fine at a fold: the end of
//! a thin finger (a white-matter tube 0.7 mm across, remeshed with 1–2 mm triangles) becomes a
//! tip of three triangles folded flat onto each other (the nested model: 5.5°).
//!
//! Opening a fold rotates one of its two wing points away from the other wing's triangle (out of
//! that triangle's plane, on its own side), or pulls an end of the edge back along it, by a
//! fraction of the tolerance, through the guarded point move (distance both ways, covers,
//! crossings, triangle shape). A move is kept only when the smallest fold among the edges it
//! changes grows, so the pass cannot trade one fold for a sharper one.

use super::{Hint, P3, Remesher};
use crate::geom::vec3::{cross, dot, norm, scale, sub};
use crate::mesh::surface::SurfaceMesh;
use rustc_hash::FxHashMap;

/// Folds under this many degrees are opened (the surface stage's aim for the tets is 15°).
pub const FOLD_ANGLE: f64 = 15.0;

/// Moves tried, as fractions of the working tolerance, largest first.
const STEPS: [f64; 4] = [0.75, 0.5, 0.25, 0.125];

/// Passes over the folds at most (each pass only moves points that make some fold wider).
const PASSES: usize = 4;

/// The fold at edge `ab` of triangles `abc` and `bad` with side labels `sides`
/// ([`Remesher::fold_angle`]); `None` for a zero-length edge.
fn fold_at([pa, pb, pc, pd]: [P3; 4], sides: [u32; 2]) -> Option<f64> {
    let e = sub(pb, pa);
    let ee = dot(e, e);
    if ee == 0.0 {
        return None;
    }
    // The wings across the edge; their angle is the one between the two half-planes.
    let across = |q: P3| {
        let u = sub(q, pa);
        sub(u, scale(e, dot(u, e) / ee))
    };
    let (u, w) = (across(pc), across(pd));
    let theta = norm(cross(u, w)).atan2(dot(u, w)).to_degrees();
    // Triangle `abc` faces its front side: `d` behind it puts the small wedge at the back.
    let n1 = cross(e, sub(pc, pa));
    let back = if dot(n1, sub(pd, pa)) < 0.0 {
        theta
    } else {
        360.0 - theta
    };
    let mut fold = f64::INFINITY;
    if sides[0] != 0 {
        fold = fold.min(back);
    }
    if sides[1] != 0 {
        fold = fold.min(360.0 - back);
    }
    Some(fold)
}

/// The smallest fold of a surface (degrees; infinite if none): over the edges with exactly two
/// triangles of one sheet, the interior dihedral angle on each meshed side. No tet at that edge
/// can have a larger dihedral angle there.
pub fn min_fold(s: &SurfaceMesh) -> f64 {
    let mut half: FxHashMap<(u32, u32), (u32, u32, u32)> = FxHashMap::default();
    for (t, tri) in s.triangles.iter().enumerate() {
        for k in 0..3 {
            let e = (tri[k], tri[(k + 1) % 3]);
            // Count per directed edge; a third use marks it non-manifold.
            half.entry(e)
                .and_modify(|x| x.2 += 1)
                .or_insert((t as u32, tri[(k + 2) % 3], 1));
        }
    }
    let mut worst = f64::INFINITY;
    for (&(a, b), &(t1, c, n1)) in &half {
        let Some(&(t2, d, n2)) = half.get(&(b, a)) else {
            continue;
        };
        let sides = s.sides[t1 as usize];
        if a > b || n1 != 1 || n2 != 1 || s.sides[t2 as usize] != sides {
            continue;
        }
        let p = |v: u32| s.points[v as usize];
        if let Some(f) = fold_at([p(a), p(b), p(c), p(d)], sides) {
            worst = worst.min(f);
        }
    }
    worst
}

impl Remesher<'_> {
    /// The interior dihedral angle (degrees) at edge `ab` on the side of each region beside it
    /// (label 0, the outside, is not meshed), the smaller of the two; `None` unless the edge has
    /// exactly two triangles of one sheet. With `at = Some((v, x))` point `v` is taken at `x`.
    /// Floating point: it ranks moves, and the moves themselves are checked exactly.
    pub(super) fn fold_angle(&self, a: u32, b: u32, at: Option<(u32, P3)>) -> Option<f64> {
        let (t1, t2, c, d) = self.edge_pair(a, b)?;
        let sides = self.sides[t1 as usize];
        if self.sides[t2 as usize] != sides {
            return None;
        }
        let p = |v: u32| match at {
            Some((u, x)) if u == v => x,
            _ => self.pts[v as usize],
        };
        fold_at([p(a), p(b), p(c), p(d)], sides)
    }

    /// The smallest fold among the edges a move of `v` changes: the edges at `v` and the edges
    /// opposite it in its triangles (`v` is a wing of those), with `v` at `x` if given.
    fn star_fold(&self, v: u32, x: Option<P3>) -> f64 {
        let at = x.map(|x| (v, x));
        let mut worst = f64::INFINITY;
        for &t in &self.vt[v as usize] {
            let tri = self.tris[t as usize];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                // Each edge at `v` is met from both of its triangles; once is enough.
                if b == v {
                    continue;
                }
                if let Some(f) = self.fold_angle(a, b, at) {
                    worst = worst.min(f);
                }
            }
        }
        worst
    }

    /// Whether the triangles of `v`, with `v` at `x`, lie within the working tolerance of the
    /// input at samples a quarter of it apart (so within 0.95 of it everywhere, the distance
    /// being 1-Lipschitz). The guards' samples are sparser: they serve moves that follow the
    /// input, and a fold is opened by moving a point off it, at pinches of the input where two
    /// sheets pass within hundredths of a millimetre (wm_20k at D = 0.25: a move passed them and
    /// the final measure then found 0.266 between their samples).
    fn fan_near_input(&self, v: u32, x: P3) -> bool {
        let h = self.tol / 4.0;
        let mut hint = Hint::default();
        self.vt[v as usize].iter().all(|&t| {
            let c = self.tris[t as usize].map(|u| if u == v { x } else { self.pts[u as usize] });
            let longest = (0..3)
                .map(|k| norm(sub(c[(k + 1) % 3], c[k])))
                .fold(0.0, f64::max);
            let n = ((longest / h).ceil() as usize).clamp(1, 64) as u8;
            self.near_input(&c, self.sides[t as usize], n, None, &mut hint)
                .is_some()
        })
    }

    /// The directions that open the fold at `ab` (wings `c`, `d`) for each of its points: a wing
    /// out of the other wing's triangle plane on its own side, an end back along the edge.
    fn opening_moves(&self, a: u32, b: u32, c: u32, d: u32) -> Vec<(u32, P3)> {
        let [pa, pb, pc, pd] = [a, b, c, d].map(|v| self.pts[v as usize]);
        let unit = |v: P3| {
            let l = norm(v);
            (l > 0.0).then(|| scale(v, 1.0 / l))
        };
        let mut out = Vec::with_capacity(4);
        // Wing `c` leaves the plane of `b, a, d`, wing `d` the plane of `a, b, c`.
        for (w, q, n) in [
            (c, pc, cross(sub(pa, pb), sub(pd, pb))),
            (d, pd, cross(sub(pb, pa), sub(pc, pa))),
        ] {
            let s = dot(n, sub(q, pa));
            if s != 0.0
                && let Some(n) = unit(n)
            {
                out.push((w, if s > 0.0 { n } else { scale(n, -1.0) }));
            }
        }
        if let Some(e) = unit(sub(pb, pa)) {
            out.push((a, e));
            out.push((b, scale(e, -1.0)));
        }
        out
    }

    /// Open the folds under [`FOLD_ANGLE`] (module docs): returns the points moved.
    pub fn open_folds(&mut self) -> usize {
        let mut moved = 0;
        for _ in 0..PASSES {
            let mut folds: Vec<(f64, u32, u32)> = self
                .edges()
                .into_iter()
                .filter_map(|(a, b)| {
                    let f = self.fold_angle(a, b, None)?;
                    (f < FOLD_ANGLE).then_some((f, a, b))
                })
                .collect();
            if folds.is_empty() {
                break;
            }
            folds.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
            let mut any = false;
            for (_, a, b) in folds {
                // An earlier move may have opened it (or flipped the edge away).
                let Some(f) = self.fold_angle(a, b, None) else {
                    continue;
                };
                if f >= FOLD_ANGLE {
                    continue;
                }
                let Some((_, _, c, d)) = self.edge_pair(a, b) else {
                    continue;
                };
                'point: for (v, dir) in self.opening_moves(a, b, c, d) {
                    let before = self.star_fold(v, None);
                    let worst = self.worst_angle(&self.vt[v as usize]);
                    let p = self.pts[v as usize];
                    for s in STEPS {
                        let x = [0, 1, 2].map(|k| p[k] + dir[k] * s * self.tol);
                        let after = self.star_fold(v, Some(x));
                        if after <= before {
                            continue;
                        }
                        // A triangle angle may drop, but not below the fold as it was: the
                        // smaller of the two, what bounds the tets there, grows.
                        let floor = worst.min(self.target_angle).min(before);
                        if !self.fan_near_input(v, x) {
                            continue;
                        }
                        if let Some(m) = self.check_move_above(v, x, None, floor) {
                            self.apply_move(m);
                            moved += 1;
                            any = true;
                            break 'point;
                        }
                    }
                }
            }
            if !any {
                break;
            }
        }
        moved
    }
}
