//! Solid-angle smoothing (dissertation chapter 4, section 4.3.1): move nodes, never the
//! connectivity, to raise the smallest solid angles of a tet mesh made by any tool.
//!
//! For each movable node, its cluster is the tets around it and Φ(x) the smallest solid angle of
//! the cluster (at every corner, not only at the node) as a function of the node's position
//! (eq. 4.7). `node` raises Φ along the analytic gradient (eq. 4.8; [`gradient`]), or, when
//! several angles are nearly tied, along the ascent direction of all of them ([`ascent`]).
//! A sweep colours the movable nodes to visit greedily, worst cluster first, so that no two nodes
//! of a colour share a tet (`colour`); the classes run in colour order, Gauss–Seidel style
//! between classes (each node sees the new positions of the classes before it), and each class
//! is computed in parallel (rayon) from the positions before it and applied after. Most refused
//! trial positions are proved refused by cheap bounds (`screen`) before the exact test. Sweeps
//! repeat until the smallest solid angle of the tets that can
//! change stops rising, the largest displacement falls below a fraction of the smallest edge, or
//! the sweep cap.
//!
//! Guarantees:
//! - Only coordinates change; point, tet and label arrays keep their order and size.
//! - Every accepted position keeps every tet of the cluster strictly positive by exact
//!   [`orient3d`](crate::geom::predicates::orient3d), and strictly raises the cluster's minimum
//!   solid angle as [`QualityReport`](crate::quality::QualityReport) computes it (the same
//!   function on the same corner order), so the mesh's smallest solid angle never decreases.
//! - Surface nodes — on boundary faces, or on faces between tets of different labels
//!   (interfaces) — with [`Boundary::Fixed`] never move (bit-identical); with [`Boundary::Slide`]
//!   they move along the input surface and stay on its triangles up to round-off ([`slide`]),
//!   while nodes on feature edges and corners, on triple lines, or not at a surface vertex stay.
//! - Deterministic: the same input gives the same output bit for bit, for any number of threads
//!   (a class's nodes read nothing another of them writes, and every reduction is a minimum or
//!   runs in a fixed order).

pub mod ascent;
mod colour;
pub mod gradient;
mod node;
pub mod plane;
mod screen;
pub mod slide;

use std::time::Instant;

use serde::Serialize;

use crate::geom::vec3::{norm, sub};
use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::{NO_NEIGHBOR, TET_EDGES, TetMesh};
use crate::quality::tet::solid_angles;
use colour::Colouring;
use node::{Cluster, LocalParams, Motion, Moved};
use rayon::prelude::*;
use slide::SlideSurface;

/// What surface nodes may do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Boundary {
    /// Surface nodes never move.
    #[default]
    Fixed,
    /// Surface nodes slide on the input surface; feature edges, corners and triple lines stay.
    Slide,
}

/// Options of [`smooth`].
#[derive(Debug, Clone, Serialize)]
pub struct SmoothOptions {
    /// What surface nodes may do.
    pub boundary: Boundary,
    /// With [`Boundary::Slide`]: an edge of the surface whose two triangles' normals turn by
    /// more than this many degrees is a feature; nodes on features stay.
    pub feature_angle_deg: f64,
    /// Most sweeps over the nodes.
    pub max_sweeps: usize,
    /// Stop when a sweep leaves the smallest solid angle of the improvable tets (those with a
    /// movable corner) where it was and raises the nodes' cluster minima by less than this
    /// fraction of what the first sweep raised them (summed over the nodes moved).
    pub min_relative_gain: f64,
    /// Stop when no node moved farther than this fraction of the smallest edge in a sweep.
    pub min_displacement: f64,
    /// Most ascent iterations per node and sweep.
    pub max_node_iterations: usize,
    /// Angles within this fraction of the cluster's minimum count as tied (the active set).
    pub active_tolerance: f64,
    /// The largest step, as a fraction of the mean distance from the node to its cluster's other
    /// corners.
    pub step_fraction: f64,
    /// Step halvings before a direction is given up.
    pub max_halvings: usize,
    /// A node whose ascent direction is shorter than this (times the cluster's size: a
    /// dimensionless rate in steradians per cluster size) is left alone: its cluster's minimum
    /// is at an angle it can barely change.
    pub min_sensitivity: f64,
    /// Nodes whose cluster's smallest solid angle is at least this many steradians at the start
    /// of a sweep are skipped in that sweep (infinity: visit every node).
    pub skip_above_sr: f64,
}

impl Default for SmoothOptions {
    fn default() -> SmoothOptions {
        SmoothOptions {
            boundary: Boundary::Fixed,
            feature_angle_deg: 45.0,
            max_sweeps: 10,
            min_relative_gain: 0.05,
            min_displacement: 1e-3,
            max_node_iterations: 4,
            active_tolerance: 0.05,
            step_fraction: 0.25,
            max_halvings: 6,
            min_sensitivity: 1e-3,
            skip_above_sr: f64::INFINITY,
        }
    }
}

/// One sweep of [`smooth`].
#[derive(Debug, Clone, Serialize)]
pub struct SweepReport {
    /// Nodes that moved.
    pub nodes_moved: usize,
    /// The largest displacement of a node.
    pub max_displacement: f64,
    /// The smallest solid angle of the mesh after the sweep.
    pub min_solid_angle_sr: f64,
    /// The smallest solid angle of the tets with a movable corner after the sweep.
    pub min_improvable_solid_angle_sr: f64,
    /// The nodes' cluster minima's rise, summed over the nodes moved (steradians).
    pub gain_sr: f64,
    /// Nodes visited (movable nodes whose cluster changed since their last visit).
    pub nodes_visited: usize,
    /// Wall seconds.
    pub seconds: f64,
}

/// What [`smooth`] did.
#[derive(Debug, Clone, Serialize)]
pub struct SmoothReport {
    /// The boundary mode used.
    pub boundary: Boundary,
    /// Sweeps run.
    pub sweeps: usize,
    /// Wall seconds in total (classification and sweeps).
    pub seconds: f64,
    /// Mean wall seconds per sweep.
    pub seconds_per_sweep: f64,
    /// Nodes that moved at least once.
    pub nodes_moved: usize,
    /// Nodes used by some tet.
    pub n_nodes: usize,
    /// Nodes on the boundary or an interface.
    pub n_surface_nodes: usize,
    /// Surface nodes allowed to slide.
    pub n_sliding_nodes: usize,
    /// Surface nodes held because they are on a feature edge, a corner or a triple line.
    pub n_feature_nodes: usize,
    /// Surface nodes held because they are not a vertex of the input surface (slide only).
    pub n_unlocated_nodes: usize,
    /// The largest distance of a surface node from the input surface triangle it was placed on
    /// (0 with fixed surface nodes; round-off when sliding).
    pub max_surface_distance: f64,
    /// Smallest solid angle before.
    pub min_solid_angle_before_sr: f64,
    /// Smallest solid angle after.
    pub min_solid_angle_after_sr: f64,
    /// The smallest edge length of the input (the displacement criterion's unit).
    pub min_edge: f64,
    /// Per sweep.
    pub history: Vec<SweepReport>,
}

/// Why [`smooth`] refused a mesh.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SmoothError {
    /// A tet refers to a missing point or repeats one.
    #[error("tet {tet} {vertices:?}: vertex index out of range ({n_points} points) or repeated")]
    BadTet {
        /// The tet.
        tet: usize,
        /// Its vertices.
        vertices: [u32; 4],
        /// Points in the mesh.
        n_points: usize,
    },
    /// The label or adjacency arrays do not match the tets.
    #[error("{what}: {len} entries for {n_tets} tets")]
    Arrays {
        /// Which array.
        what: &'static str,
        /// Its length.
        len: usize,
        /// Tets.
        n_tets: usize,
    },
}

/// The share (0–1) of all solid angles of `mesh` below `sr` steradians (0 for no tets).
pub fn solid_angle_share_below(mesh: &TetMesh, sr: f64) -> f64 {
    let mut below = 0usize;
    for t in 0..mesh.tets.len() {
        below += solid_angles(&mesh.corners(t))
            .iter()
            .filter(|&&a| a < sr)
            .count();
    }
    if mesh.tets.is_empty() {
        0.0
    } else {
        below as f64 / (4 * mesh.tets.len()) as f64
    }
}

/// The role of a node.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Unused,
    Fixed,
    Motion(Motion),
}

/// Smooth `mesh` in place: raise its smallest solid angles by moving nodes (see the module
/// docs). `surface` is the input surface to slide on with [`Boundary::Slide`]; without it the
/// mesh's own boundary and interface faces are the surface. Ignored with [`Boundary::Fixed`].
pub fn smooth(
    mesh: &mut TetMesh,
    surface: Option<&SurfaceMesh>,
    opts: &SmoothOptions,
) -> Result<SmoothReport, SmoothError> {
    let clock = Instant::now();
    let np = mesh.points.len();
    let nt = mesh.tets.len();
    for (what, len) in [
        ("labels", mesh.labels.len()),
        ("neighbors", mesh.neighbors.len()),
    ] {
        if len != nt {
            return Err(SmoothError::Arrays {
                what,
                len,
                n_tets: nt,
            });
        }
    }
    for (t, v) in mesh.tets.iter().enumerate() {
        let distinct = (0..4).all(|i| (i + 1..4).all(|j| v[i] != v[j]));
        if !distinct || v.iter().any(|&i| i as usize >= np) {
            return Err(SmoothError::BadTet {
                tet: t,
                vertices: *v,
                n_points: np,
            });
        }
    }

    // Node → tets.
    let (start, star) = incidence(np, &mesh.tets);

    // Surface nodes and their label pairs (a node on two different pairs is on a triple line).
    const NO_PAIR: [u32; 2] = [u32::MAX; 2];
    let mut pair_of = vec![NO_PAIR; np];
    let mut triple = vec![false; np];
    let mut faces: Vec<([u32; 3], [u32; 2])> = Vec::new();
    for t in 0..nt {
        for f in 0..4 {
            let nb = mesh.neighbors[t][f];
            let other = if nb == NO_NEIGHBOR {
                0
            } else {
                mesh.labels[nb as usize]
            };
            let mine = mesh.labels[t];
            let on_surface = nb == NO_NEIGHBOR || other != mine;
            if !on_surface {
                continue;
            }
            let pair = [mine.min(other), mine.max(other)];
            let face = mesh.face(t, f);
            for &v in &face {
                let p = &mut pair_of[v as usize];
                if *p == NO_PAIR {
                    *p = pair;
                } else if *p != pair {
                    triple[v as usize] = true;
                }
            }
            // Each interface face once (from the tet with the smaller index).
            if nb == NO_NEIGHBOR || (nb as usize) > t {
                faces.push((face, [mine, other]));
            }
        }
    }

    let own;
    let slide_surface = match (opts.boundary, surface) {
        (Boundary::Fixed, _) => None,
        (Boundary::Slide, Some(s)) => Some(SlideSurface::new(s, opts.feature_angle_deg)),
        (Boundary::Slide, None) => {
            own = SurfaceMesh {
                points: mesh.points.clone(),
                triangles: faces.iter().map(|f| f.0).collect(),
                sides: faces.iter().map(|f| f.1).collect(),
            };
            Some(SlideSurface::new(&own, opts.feature_angle_deg))
        }
    };
    drop(faces);

    let mut report = SmoothReport {
        boundary: opts.boundary,
        sweeps: 0,
        seconds: 0.0,
        seconds_per_sweep: 0.0,
        nodes_moved: 0,
        n_nodes: 0,
        n_surface_nodes: 0,
        n_sliding_nodes: 0,
        n_feature_nodes: 0,
        n_unlocated_nodes: 0,
        max_surface_distance: 0.0,
        min_solid_angle_before_sr: f64::NAN,
        min_solid_angle_after_sr: f64::NAN,
        min_edge: f64::INFINITY,
        history: Vec::new(),
    };
    let mut kind = vec![Kind::Unused; np];
    for v in 0..np {
        if start[v] == start[v + 1] {
            continue;
        }
        report.n_nodes += 1;
        if pair_of[v] == NO_PAIR {
            kind[v] = Kind::Motion(Motion::Free);
            continue;
        }
        report.n_surface_nodes += 1;
        kind[v] = Kind::Fixed;
        let Some(s) = &slide_surface else { continue };
        if triple[v] {
            report.n_feature_nodes += 1;
            continue;
        }
        match s.vertex_at(mesh.points[v]) {
            None => report.n_unlocated_nodes += 1,
            Some(sv) if s.is_feature_vertex(sv) || !s.has_triangle(sv) => {
                report.n_feature_nodes += 1
            }
            Some(sv) => {
                if let Some(loc) = s.vertex_location(sv) {
                    kind[v] = Kind::Motion(Motion::Slide(loc));
                    report.n_sliding_nodes += 1;
                } else {
                    report.n_unlocated_nodes += 1;
                }
            }
        }
    }

    // Per-tet minimum solid angle, and the smallest edge, in one pass over the corners. Only the
    // minima are kept: the clusters visited compute their own angles.
    let mut tet_min = vec![0.0; nt];
    // A minimum: the same float whatever the order of the reduction.
    report.min_edge = tet_min
        .par_iter_mut()
        .enumerate()
        .map(|(t, m)| {
            let c = mesh.corners(t);
            *m = min4(solid_angles(&c));
            TET_EDGES
                .iter()
                .map(|&[i, j]| norm(sub(c[i], c[j])))
                .fold(f64::INFINITY, f64::min)
        })
        .reduce(|| f64::INFINITY, f64::min);
    let improvable: Vec<bool> = mesh
        .tets
        .iter()
        .map(|v| {
            v.iter()
                .any(|&i| matches!(kind[i as usize], Kind::Motion(_)))
        })
        .collect();
    let mins = |tet_min: &[f64]| {
        let all = tet_min.iter().copied().fold(f64::INFINITY, f64::min);
        let imp = tet_min
            .iter()
            .zip(&improvable)
            .filter(|x| *x.1)
            .map(|x| *x.0)
            .fold(f64::INFINITY, f64::min);
        (all, imp)
    };
    let (min0, mut imp_prev) = mins(&tet_min);
    report.min_solid_angle_before_sr = min0;
    report.min_solid_angle_after_sr = min0;

    let params = LocalParams {
        max_iterations: opts.max_node_iterations,
        active_tolerance: opts.active_tolerance,
        step_fraction: opts.step_fraction,
        max_halvings: opts.max_halvings,
        min_sensitivity: opts.min_sensitivity,
    };
    let mut moved_ever = vec![false; np];
    // Nodes whose cluster changed since their last visit. A node whose cluster did not change
    // would do exactly what it did last time (nothing), so skipping it changes no result.
    let mut touched = vec![true; np];
    let mut colouring = Colouring::default();
    let mut order: Vec<(f64, u32)> = Vec::new();
    let mut nodes: Vec<u32> = Vec::new();
    let sweeps_clock = Instant::now();
    let mut first_gain: Option<f64> = None;
    for _ in 0..opts.max_sweeps {
        let sweep_clock = Instant::now();
        // Worst clusters first (ties by node index).
        order.clear();
        for v in 0..np {
            if let Kind::Motion(_) = kind[v]
                && touched[v]
            {
                let s = &star[start[v] as usize..start[v + 1] as usize];
                let key = s
                    .iter()
                    .map(|&t| tet_min[t as usize])
                    .fold(f64::INFINITY, f64::min);
                if key < opts.skip_above_sr {
                    order.push((key, v as u32));
                }
            }
        }
        order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        nodes.clear();
        nodes.extend(order.iter().map(|o| o.1));
        let mut moved = 0;
        let mut gain = 0.0;
        let mut max_disp: f64 = 0.0;
        for mut class in colouring.classes(&nodes, &start, &star, &mesh.tets) {
            // No two nodes of a class share a tet: each reads only what the others leave alone,
            // so the class is computed at once from the positions before it and applied after,
            // and its order changes nothing: by node index, for the memory's sake.
            class.sort_unstable();
            let points = &mesh.points;
            let tets = &mesh.tets;
            let kinds = &kind;
            let results: Vec<Option<(Moved, Vec<f64>)>> = class
                .par_iter()
                .map_init(Cluster::default, |cluster, &v| {
                    let Kind::Motion(motion) = kinds[v as usize] else {
                        return None;
                    };
                    let s = &star[start[v as usize] as usize..start[v as usize + 1] as usize];
                    cluster.load(points, tets, s, v);
                    let m = cluster.optimise(
                        points[v as usize],
                        motion,
                        slide_surface.as_ref(),
                        &params,
                    )?;
                    Some((m, cluster.tet_minima().collect()))
                })
                .collect();
            for (&v, r) in class.iter().zip(results) {
                let v = v as usize;
                touched[v] = false;
                let Some((m, new_minima)) = r else {
                    continue;
                };
                debug_assert!(m.phi_after > m.phi_before);
                let x0 = mesh.points[v];
                mesh.points[v] = m.x;
                if let Some(l) = m.loc {
                    kind[v] = Kind::Motion(Motion::Slide(l));
                }
                // The cluster has the star's minima at the new position already.
                let s = &star[start[v] as usize..start[v + 1] as usize];
                for (&t, a) in s.iter().zip(new_minima) {
                    tet_min[t as usize] = a;
                    for &u in &mesh.tets[t as usize] {
                        touched[u as usize] = true;
                    }
                }
                gain += m.phi_after - m.phi_before;
                moved += 1;
                moved_ever[v] = true;
                max_disp = max_disp.max(norm(sub(m.x, x0)));
            }
        }
        let (all, imp) = mins(&tet_min);
        report.sweeps += 1;
        report.min_solid_angle_after_sr = all;
        report.history.push(SweepReport {
            nodes_moved: moved,
            max_displacement: max_disp,
            min_solid_angle_sr: all,
            min_improvable_solid_angle_sr: imp,
            gain_sr: gain,
            nodes_visited: order.len(),
            seconds: sweep_clock.elapsed().as_secs_f64(),
        });
        let first = *first_gain.get_or_insert(gain);
        let stalled = imp <= imp_prev && (gain.is_nan() || gain <= opts.min_relative_gain * first);
        imp_prev = imp;
        if moved == 0 || max_disp < opts.min_displacement * report.min_edge || stalled {
            break;
        }
    }
    if report.sweeps > 0 {
        report.seconds_per_sweep = sweeps_clock.elapsed().as_secs_f64() / report.sweeps as f64;
    }
    report.nodes_moved = moved_ever.iter().filter(|&&m| m).count();
    if let Some(s) = &slide_surface {
        for (k, p) in kind.iter().zip(&mesh.points) {
            if let Kind::Motion(Motion::Slide(l)) = k {
                report.max_surface_distance = report.max_surface_distance.max(s.distance(l, *p));
            }
        }
    }
    report.seconds = clock.elapsed().as_secs_f64();
    Ok(report)
}

#[inline]
fn min4(a: [f64; 4]) -> f64 {
    a[0].min(a[1]).min(a[2]).min(a[3])
}

/// The cells around each of `n` vertices (compressed rows): the cells of vertex `v` are
/// `cells_of[start[v]..start[v + 1]]`, in increasing order. Every index of `cells` is below `n`.
pub(crate) fn incidence<const K: usize>(n: usize, cells: &[[u32; K]]) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; n + 1];
    for c in cells {
        for &i in c {
            start[i as usize + 1] += 1;
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut cells_of = vec![0u32; K * cells.len()];
    for (t, c) in cells.iter().enumerate() {
        for &i in c {
            cells_of[fill[i as usize] as usize] = t as u32;
            fill[i as usize] += 1;
        }
    }
    (start, cells_of)
}
