//! Max–min angle smoothing of 2D triangle meshes (dissertation section 4.3.1 in the plane,
//! fig. 4.3 and Table 4.1): move nodes, never the connectivity, to raise the smallest angle.
//!
//! For a movable node its cluster is the triangles around it and Φ(x) the smallest angle of the
//! cluster, at every corner (eq. 4.7 with angles for solid angles). The analytic gradient of each
//! angle with respect to the node (eq. 4.8 in the plane: the angle at `A` of `ABC` has
//! `∂α/∂B = (B−A)^⊥ / |B−A|²` turned clockwise, `∂α/∂C = (C−A)^⊥ / |C−A|²` turned
//! counter-clockwise and `∂α/∂A = −∂α/∂B − ∂α/∂C`) gives the step direction; when several angles
//! are nearly tied the direction is the min-norm point of their gradients' hull
//! ([`super::ascent::min_norm_point`], shared with 3D), which raises all of them at once. A step is
//! taken along it, halved until every triangle of the cluster stays strictly counter-clockwise
//! (exact [`orient2d`]) and Φ strictly rises; then the gradient is recomputed (fig. 4.3 (b)).
//!
//! Nodes: interior nodes are free. Boundary nodes — on an edge of one triangle, or between two
//! labels — are fixed with [`Boundary::Fixed`]; with [`Boundary::Slide`] a boundary node whose two
//! boundary edges are collinear (exact) slides along that line between its neighbours, and corners
//! (two boundary edges at an angle, or more than two) stay.
//!
//! A sweep visits the movable nodes worst cluster first, in colour classes of nodes that share no
//! triangle (the greedy colouring of the 3D smoothing, `smooth::colour`): each class is optimised
//! in parallel from the positions before it and applied after, Gauss–Seidel between classes.
//!
//! Guarantees: only coordinates change; the smallest angle of the mesh never decreases (every
//! accepted move raises its cluster's smallest angle, computed by the formula of
//! [`crate::quality::tri::angles`] at the corner opposite the shortest edge, so up to round-off
//! when two edges are within round-off of each other); fixed nodes are bit-identical; sliding nodes stay on their line up to
//! round-off; deterministic, bit for bit, for any number of threads.

use serde::Serialize;

use super::Boundary;
use super::ascent::min_norm_point;
use super::colour::Colouring;
use crate::geom::predicates::{Sign, orient2d};
use crate::mesh::tri::TriMesh;
use crate::quality::tri::angles;
use rayon::prelude::*;

/// Options of [`smooth_tri`].
#[derive(Debug, Clone, Serialize)]
pub struct PlaneSmoothOptions {
    /// What boundary nodes may do.
    pub boundary: Boundary,
    /// Most sweeps over the nodes (the dissertation's Table 4.1 used 20).
    pub max_sweeps: usize,
    /// Most gradient steps per node and sweep.
    pub max_node_iterations: usize,
    /// Angles within this many degrees of the cluster's minimum are tied (the active set).
    pub active_tolerance_deg: f64,
    /// The first step, as a fraction of the mean length of the node's edges.
    pub step_fraction: f64,
    /// Step halvings before a direction is given up.
    pub max_halvings: usize,
    /// Nodes whose cluster's smallest angle is at least this (degrees) are left alone.
    pub skip_above_deg: f64,
    /// Stop when a sweep raises the mesh's smallest angle by less than this (degrees) and moves
    /// no node farther than `min_displacement` times the node's mean edge.
    pub min_gain_deg: f64,
    /// See `min_gain_deg`.
    pub min_displacement: f64,
}

impl Default for PlaneSmoothOptions {
    fn default() -> Self {
        PlaneSmoothOptions {
            boundary: Boundary::Fixed,
            max_sweeps: 20,
            max_node_iterations: 6,
            active_tolerance_deg: 0.5,
            step_fraction: 0.2,
            max_halvings: 8,
            skip_above_deg: 180.0,
            min_gain_deg: 1e-6,
            min_displacement: 1e-4,
        }
    }
}

/// One sweep.
#[derive(Debug, Clone, Serialize)]
pub struct PlaneSweep {
    /// Nodes visited.
    pub visited: usize,
    /// Nodes moved.
    pub moved: usize,
    /// Smallest angle of the mesh after the sweep (degrees).
    pub min_angle_deg: f64,
}

/// What [`smooth_tri`] did.
#[derive(Debug, Clone, Default, Serialize)]
pub struct PlaneSmoothReport {
    /// Boundary mode.
    pub boundary: Boundary,
    /// Nodes used by a triangle.
    pub n_nodes: usize,
    /// Free interior nodes.
    pub n_free: usize,
    /// Boundary nodes that slide.
    pub n_sliding: usize,
    /// Boundary nodes held (all of them when fixed; corners when sliding).
    pub n_fixed: usize,
    /// Smallest angle before (degrees).
    pub min_angle_before_deg: f64,
    /// Smallest angle after (degrees).
    pub min_angle_after_deg: f64,
    /// Nodes that moved at least once.
    pub nodes_moved: usize,
    /// Per sweep.
    pub sweeps: Vec<PlaneSweep>,
}

#[derive(Clone, Copy)]
enum Motion {
    Fixed,
    Free,
    /// Along the unit direction.
    Slide([f64; 2]),
}

fn min3(a: [f64; 3]) -> f64 {
    a[0].min(a[1]).min(a[2])
}

/// A monotone key of the smallest angle of a triangle: `−cos` of the angle opposite its shortest
/// edge (increasing with the angle on [0, π]; no `atan2` on the smoothing's hot path). Equals
/// `−cos(min3(angles(c)))` up to round-off.
fn min_angle_key(c: &[[f64; 2]; 3]) -> f64 {
    let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    let l = [d(c[1], c[2]), d(c[2], c[0]), d(c[0], c[1])];
    let i = if l[0] <= l[1] && l[0] <= l[2] {
        0
    } else if l[1] <= l[2] {
        1
    } else {
        2
    };
    let p = c[i];
    let a = c[(i + 1) % 3];
    let b = c[(i + 2) % 3];
    let u = [a[0] - p[0], a[1] - p[1]];
    let v = [b[0] - p[0], b[1] - p[1]];
    let den = (l[(i + 2) % 3] * l[(i + 1) % 3]).sqrt();
    if den > 0.0 {
        -((u[0] * v[0] + u[1] * v[1]) / den).clamp(-1.0, 1.0)
    } else {
        -1.0
    }
}

/// The keys (−cos) of the three angles, in corner order.
fn corner_keys(c: &[[f64; 2]; 3]) -> [f64; 3] {
    let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    let l = [d(c[1], c[2]), d(c[2], c[0]), d(c[0], c[1])];
    let mut k = [0.0; 3];
    for (i, ki) in k.iter_mut().enumerate() {
        let p = c[i];
        let a = c[(i + 1) % 3];
        let b = c[(i + 2) % 3];
        let dot = (a[0] - p[0]) * (b[0] - p[0]) + (a[1] - p[1]) * (b[1] - p[1]);
        let den = (l[(i + 2) % 3] * l[(i + 1) % 3]).sqrt();
        *ki = if den > 0.0 {
            -(dot / den).clamp(-1.0, 1.0)
        } else {
            -1.0
        };
    }
    k
}

/// The angle of a key of [`min_angle_key`].
fn key_angle(k: f64) -> f64 {
    (-k).clamp(-1.0, 1.0).acos()
}

/// Gradient of the angle at corner `j` of the (counter-clockwise) triangle `c` with respect to the
/// position of corner `k`.
fn angle_gradient(c: &[[f64; 2]; 3], j: usize, k: usize) -> [f64; 2] {
    let a = c[j];
    let b = c[(j + 1) % 3];
    let cc = c[(j + 2) % 3];
    let u = [b[0] - a[0], b[1] - a[1]];
    let w = [cc[0] - a[0], cc[1] - a[1]];
    let uu = u[0] * u[0] + u[1] * u[1];
    let ww = w[0] * w[0] + w[1] * w[1];
    let gb = if uu > 0.0 {
        [u[1] / uu, -u[0] / uu]
    } else {
        [0.0; 2]
    };
    let gc = if ww > 0.0 {
        [-w[1] / ww, w[0] / ww]
    } else {
        [0.0; 2]
    };
    if k == j {
        [-gb[0] - gc[0], -gb[1] - gc[1]]
    } else if k == (j + 1) % 3 {
        gb
    } else {
        gc
    }
}

/// A node's accepted move: new position, length of the last accepted step, displacement
/// relative to its mean edge.
type Move = ([f64; 2], f64, f64);

struct Smoother<'a> {
    m: &'a mut TriMesh,
    /// Length of each node's last accepted step (0: none yet).
    last: Vec<f64>,
    start: Vec<u32>,
    star: Vec<u32>,
}

impl Smoother<'_> {
    fn cluster(&self, v: usize) -> &[u32] {
        &self.star[self.start[v] as usize..self.start[v + 1] as usize]
    }

    /// Corners of triangle `t` with node `v` at `x`.
    fn corners_at(&self, t: u32, v: u32, x: [f64; 2]) -> [[f64; 2]; 3] {
        let tv = self.m.triangles[t as usize];
        tv.map(|u| if u == v { x } else { self.m.points[u as usize] })
    }

    /// Key ([`min_angle_key`]) of the smallest angle of the cluster of `v` at `x`; `None` if a
    /// triangle is not strictly counter-clockwise there.
    fn phi(&self, v: u32, x: [f64; 2]) -> Option<f64> {
        let mut m = f64::INFINITY;
        for &t in self.cluster(v as usize) {
            let c = self.corners_at(t, v, x);
            if orient2d(c[0], c[1], c[2]) != Sign::Positive {
                return None;
            }
            m = m.min(min_angle_key(&c));
        }
        Some(m)
    }

    /// Raise the cluster minimum of `v` from the current positions (nothing is written): the new
    /// position, the length of its last accepted step and the displacement relative to the
    /// node's mean edge; `None` when it does not move.
    fn optimise(&self, v: u32, motion: Motion, o: &PlaneSmoothOptions) -> Option<Move> {
        let x0 = self.m.points[v as usize];
        let mut x = x0;
        let mut last = self.last[v as usize];
        let phi0 = self.phi(v, x)?;
        let mut phi = phi0;
        let tol = o.active_tolerance_deg.to_radians();
        // Mean edge length of the node.
        let mut len = 0.0;
        let mut cnt = 0.0;
        for &t in self.cluster(v as usize) {
            for &u in &self.m.triangles[t as usize] {
                if u != v {
                    let p = self.m.points[u as usize];
                    len += ((p[0] - x[0]).powi(2) + (p[1] - x[1]).powi(2)).sqrt();
                    cnt += 1.0;
                }
            }
        }
        if cnt == 0.0 {
            return None;
        }
        let scale = len / cnt;
        let mut tied: Vec<(f64, [f64; 3])> = Vec::with_capacity(8);
        let mut grads: Vec<[f64; 3]> = Vec::with_capacity(8);
        for _ in 0..o.max_node_iterations {
            tied.clear();
            // Active angles: within `tol` of the minimum, i.e. a key (−cos) below this.
            let lim = -(key_angle(phi) + tol).min(std::f64::consts::PI).cos();
            for &t in self.cluster(v as usize) {
                let c = self.corners_at(t, v, x);
                let k = self.m.triangles[t as usize]
                    .iter()
                    .position(|&u| u == v)
                    .unwrap_or(0);
                for (j, aj) in corner_keys(&c).into_iter().enumerate() {
                    if aj <= lim {
                        let g = angle_gradient(&c, j, k);
                        tied.push((
                            aj,
                            match motion {
                                Motion::Slide(d) => [g[0] * d[0] + g[1] * d[1], 0.0, 0.0],
                                _ => [g[0], g[1], 0.0],
                            },
                        ));
                    }
                }
            }
            // The tied angles nearest the minimum first (min_norm_point uses a bounded number).
            tied.sort_by(|a, b| a.0.total_cmp(&b.0));
            grads.clear();
            grads.extend(tied.iter().map(|t| t.1));
            let d3 = min_norm_point(&grads);
            let d = match motion {
                Motion::Slide(s) => [d3[0] * s[0], d3[0] * s[1]],
                _ => [d3[0], d3[1]],
            };
            let dn = (d[0] * d[0] + d[1] * d[1]).sqrt();
            if dn.is_nan() || dn <= 1e-12 / scale {
                break;
            }
            // The first trial: a fraction of the node's edges, or a few times its last step.
            let len0 = if last > 0.0 {
                (4.0 * last).min(o.step_fraction * scale)
            } else {
                o.step_fraction * scale
            };
            let mut h = len0 / dn;
            let mut accepted = false;
            for _ in 0..=o.max_halvings {
                let y = [x[0] + h * d[0], x[1] + h * d[1]];
                if let Some(p) = self.phi(v, y)
                    && p > phi
                {
                    x = y;
                    phi = p;
                    accepted = true;
                    last = h * dn;
                    break;
                }
                h *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        (phi > phi0).then(|| {
            let disp = ((x[0] - x0[0]).powi(2) + (x[1] - x0[1]).powi(2)).sqrt() / scale;
            (x, last, disp)
        })
    }
}

/// Smooth `mesh` in place (see the module docs). The mesh should be valid (counter-clockwise,
/// conforming); triangles that are not strictly counter-clockwise keep their nodes still.
pub fn smooth_tri(mesh: &mut TriMesh, o: &PlaneSmoothOptions) -> PlaneSmoothReport {
    smooth_tri_with_segments(mesh, &[], &[], o)
}

/// [`smooth_tri`] where the edges `segments` (pairs of point indices) also count as boundary, so
/// that segments inside one region (open polylines, cracks) are kept like the others, and the
/// points `hold` never move (input points off every segment).
pub fn smooth_tri_with_segments(
    mesh: &mut TriMesh,
    segments: &[[u32; 2]],
    hold: &[u32],
    o: &PlaneSmoothOptions,
) -> PlaneSmoothReport {
    let n = mesh.points.len();
    if mesh.triangles.iter().flatten().any(|&v| v as usize >= n) {
        return PlaneSmoothReport::default();
    }
    let (start, star) = super::incidence::<3>(n, &mesh.triangles);
    // Boundary edges: edges of one triangle, or between different labels.
    let mut bnb: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (t, tv) in mesh.triangles.iter().enumerate() {
        for i in 0..3 {
            let nb = mesh.neighbors.get(t).map_or(u32::MAX, |nb| nb[i]);
            let (a, b) = (tv[(i + 1) % 3], tv[(i + 2) % 3]);
            let boundary =
                nb == u32::MAX || (mesh.labels.get(nb as usize) != mesh.labels.get(t) && a < b);
            if boundary {
                bnb[a as usize].push(b);
                bnb[b as usize].push(a);
            }
        }
    }
    let mut extra: Vec<(u32, u32)> = segments
        .iter()
        .filter(|s| s[0] != s[1] && (s[0] as usize) < n && (s[1] as usize) < n)
        .map(|s| (s[0].min(s[1]), s[0].max(s[1])))
        .collect();
    extra.sort_unstable();
    extra.dedup();
    for (a, b) in extra {
        if !bnb[a as usize].contains(&b) {
            bnb[a as usize].push(b);
            bnb[b as usize].push(a);
        }
    }
    let mut report = PlaneSmoothReport {
        boundary: o.boundary,
        ..Default::default()
    };
    let mut motion = vec![Motion::Fixed; n];
    let mut held = vec![false; n];
    for &v in hold {
        if let Some(h) = held.get_mut(v as usize) {
            *h = true;
        }
    }
    for v in 0..n {
        if start[v] == start[v + 1] {
            continue;
        }
        report.n_nodes += 1;
        let b = &bnb[v];
        if held[v] {
            report.n_fixed += 1;
        } else if b.is_empty() {
            motion[v] = Motion::Free;
            report.n_free += 1;
        } else if o.boundary == Boundary::Slide && b.len() == 2 {
            let (p, q, x) = (
                mesh.points[b[0] as usize],
                mesh.points[b[1] as usize],
                mesh.points[v],
            );
            if orient2d(p, q, x) == Sign::Zero {
                let d = [q[0] - p[0], q[1] - p[1]];
                let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
                // Axis-parallel lines keep the other coordinate exact.
                motion[v] = Motion::Slide([d[0] / l, d[1] / l]);
                report.n_sliding += 1;
            } else {
                report.n_fixed += 1;
            }
        } else {
            report.n_fixed += 1;
        }
    }
    let mesh_min = |m: &TriMesh| {
        (0..m.triangles.len())
            .map(|t| min3(angles(&m.corners(t))))
            .fold(f64::INFINITY, f64::min)
            .to_degrees()
    };
    report.min_angle_before_deg = mesh_min(mesh);
    let mut s = Smoother {
        last: vec![0.0; n],
        m: mesh,
        start,
        star,
    };
    let mut colouring = Colouring::default();
    let mut moved_ever = vec![false; n];
    let mut dirty = vec![true; n];
    let mut last_min = report.min_angle_before_deg;
    let skip = o.skip_above_deg.to_radians();
    for _ in 0..o.max_sweeps {
        // Worst cluster first.
        let mut order: Vec<(f64, u32)> = (0..n as u32)
            .filter(|&v| dirty[v as usize] && !matches!(motion[v as usize], Motion::Fixed))
            .filter_map(|v| s.phi(v, s.m.points[v as usize]).map(|p| (p, v)))
            .filter(|&(p, _)| key_angle(p) < skip)
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        dirty.iter_mut().for_each(|d| *d = false);
        let mut sweep = PlaneSweep {
            visited: order.len(),
            moved: 0,
            min_angle_deg: 0.0,
        };
        let mut max_disp: f64 = 0.0;
        // Colour classes (no two nodes of a class share a triangle), worst first; each class is
        // optimised in parallel from the positions before it and applied after, so the result
        // is the same for any number of threads.
        let nodes: Vec<u32> = order.iter().map(|&(_, v)| v).collect();
        let classes = colouring.classes(&nodes, &s.start, &s.star, &s.m.triangles);
        for class in classes {
            let moves: Vec<(u32, Option<Move>)> = class
                .par_iter()
                .map(|&v| (v, s.optimise(v, motion[v as usize], o)))
                .collect();
            for (v, m) in moves {
                let Some((x, last, disp)) = m else { continue };
                s.m.points[v as usize] = x;
                s.last[v as usize] = last;
                sweep.moved += 1;
                moved_ever[v as usize] = true;
                max_disp = max_disp.max(disp);
                for &t in s.cluster(v as usize) {
                    for &u in &s.m.triangles[t as usize] {
                        dirty[u as usize] = true;
                    }
                }
            }
        }
        sweep.min_angle_deg = mesh_min(s.m);
        let gain = sweep.min_angle_deg - last_min;
        last_min = sweep.min_angle_deg;
        report.sweeps.push(sweep);
        if report.sweeps.last().is_some_and(|w| w.moved == 0)
            || (gain < o.min_gain_deg && max_disp < o.min_displacement)
        {
            break;
        }
    }
    report.min_angle_after_deg = last_min;
    report.nodes_moved = moved_ever.iter().filter(|&&m| m).count();
    report
}
