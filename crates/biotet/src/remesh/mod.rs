//! Remeshing part of a tet mesh in place: one region, or the tets meeting a box or a sphere,
//! carved out and refilled at a new size while every other tet stays as it was.
//!
//! The carved tets of each region form a cavity whose shell (the faces towards kept tets, other
//! regions and the outer boundary) is a closed surface with the region inside. The pipeline
//! meshes inside it exactly as `biotet mesh` meshes any surface: template nodes at the new size,
//! Delaunay, LAST RESORT recovery of every shell triangle (never a new point on it), sliver
//! removal, smoothing and polishing, the shell's points fixed. The new tets are spliced in: the
//! shell's points are the mesh's own, so they meet the kept tets face to face. Points of the old
//! cavity interior that no tet uses any more are dropped; every kept tet keeps its corners'
//! coordinates bit for bit and its label. The cost is that of meshing the cavity, plus one pass
//! over the mesh to select, splice and rebuild adjacency.

use crate::geom::vec3::{cross, dot, norm, sub};
use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::{NO_NEIGHBOR, TET_FACES, TetMesh};
use crate::mesh::validate::{SurfaceError, ValidateOptions, validate_surface};
use crate::pipeline::{MeshReport, PipelineError, PipelineOptions, mesh_surface};
use crate::sizing::{Sizing, SizingError};
use crate::surface::bvh::closest_on_triangle;
use rustc_hash::FxHashMap;
use serde::Serialize;
use std::time::Instant;

type P3 = [f64; 3];

/// Rounds of carving the tets around a pinched edge or vertex of a cavity's shell.
const MAX_GROW: usize = 32;

/// Which tets to replace.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Zone {
    /// Every tet of this region.
    Region(u32),
    /// Every tet meeting the closed box `[lo, hi]`.
    Box {
        /// The smallest corner.
        lo: P3,
        /// The largest corner.
        hi: P3,
    },
    /// Every tet meeting the closed ball of this centre and radius.
    Sphere {
        /// Its centre.
        centre: P3,
        /// Its radius.
        radius: f64,
    },
}

/// Why remeshing could not run.
#[derive(Debug, thiserror::Error)]
pub enum RemeshError {
    /// No tet is in the zone.
    #[error("no tet in the zone ({0})")]
    Empty(String),
    /// The sizing could not be built on a cavity's shell.
    #[error("region {region}: sizing")]
    Sizing {
        /// The region.
        region: u32,
        /// Why.
        #[source]
        source: SizingError,
    },
    /// Meshing a cavity failed.
    #[error("region {region}")]
    Pipeline {
        /// The region.
        region: u32,
        /// Why.
        #[source]
        source: PipelineError,
    },
    /// A cavity's shell is not a valid closed surface (the input mesh is invalid).
    #[error("region {region}: the cavity's shell is not a valid closed surface")]
    Shell {
        /// The region.
        region: u32,
        /// Why.
        #[source]
        source: SurfaceError,
    },
    /// Recovery left shell triangles out of a cavity's mesh.
    #[error(
        "region {region}: {missing} triangles of the cavity's shell could not be recovered; first: {first}"
    )]
    Unrecovered {
        /// The region.
        region: u32,
        /// Triangles missing.
        missing: usize,
        /// The first one and why.
        first: String,
    },
}

/// One region's cavity.
#[derive(Debug, Clone, Serialize)]
pub struct CavityReport {
    /// The region.
    pub region: u32,
    /// Tets carved out.
    pub tets_removed: usize,
    /// Tets filled in.
    pub tets_added: usize,
    /// Triangles of its shell (kept exactly).
    pub shell_triangles: usize,
    /// Points added inside it (interior nodes and Steiner points).
    pub points_added: usize,
    /// The pipeline's report on it.
    pub pipeline: MeshReport,
}

/// What [`remesh`] did.
#[derive(Debug, Clone, Serialize)]
pub struct RemeshReport {
    /// Tets in.
    pub tets_before: usize,
    /// Tets out.
    pub tets_after: usize,
    /// Tets kept untouched.
    pub tets_kept: usize,
    /// Points in.
    pub points_before: usize,
    /// Points out.
    pub points_after: usize,
    /// Old cavity-interior points no tet uses any more, dropped.
    pub points_dropped: usize,
    /// One entry per region with carved tets, by label.
    pub cavities: Vec<CavityReport>,
    /// Rounds that carved the tets around edges or vertices where a cavity touched itself.
    pub grown: usize,
    /// Seconds selecting the zone and extracting shells.
    pub seconds_select: f64,
    /// Seconds splicing the new tets in and rebuilding adjacency.
    pub seconds_splice: f64,
    /// Seconds in all.
    pub seconds_total: f64,
}

/// Does the tet with corners `c` meet the zone? Floating point: the zone is the user's choice
/// of what to replace, not a combinatorial decision of the mesh.
fn meets(zone: &Zone, label: u32, c: &[P3; 4]) -> bool {
    match *zone {
        Zone::Region(r) => label == r,
        Zone::Box { lo, hi } => tet_meets_box(c, lo, hi),
        Zone::Sphere { centre, radius } => tet_distance(c, centre) <= radius,
    }
}

/// Separating-axis test of a tet and an axis-aligned box (both closed).
fn tet_meets_box(c: &[P3; 4], lo: P3, hi: P3) -> bool {
    let box_corners: Vec<P3> = (0..8)
        .map(|i| {
            [
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ]
        })
        .collect();
    let separated = |axis: P3| {
        if dot(axis, axis) == 0.0 {
            return false;
        }
        let (a0, a1) = c
            .iter()
            .map(|p| dot(*p, axis))
            .fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)));
        let (b0, b1) = box_corners
            .iter()
            .map(|p| dot(*p, axis))
            .fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)));
        a1 < b0 || b1 < a0
    };
    let axes_box = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if axes_box.iter().any(|&a| separated(a)) {
        return false;
    }
    for f in TET_FACES {
        if separated(cross(sub(c[f[1]], c[f[0]]), sub(c[f[2]], c[f[0]]))) {
            return false;
        }
    }
    for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
        let e = sub(c[j], c[i]);
        if axes_box.iter().any(|&a| separated(cross(e, a))) {
            return false;
        }
    }
    true
}

/// Distance from `p` to the closed tet `c` (0 inside).
fn tet_distance(c: &[P3; 4], p: P3) -> f64 {
    let inside = TET_FACES.iter().all(|f| {
        let n = cross(sub(c[f[1]], c[f[0]]), sub(c[f[2]], c[f[0]]));
        dot(n, sub(p, c[f[0]])) <= 0.0
    });
    if inside {
        return 0.0;
    }
    TET_FACES
        .iter()
        .map(|f| norm(sub(p, closest_on_triangle(p, &[c[f[0]], c[f[1]], c[f[2]]]))))
        .fold(f64::INFINITY, f64::min)
}

/// The shell of the carved tets `tets` (all of region `label`): its faces towards tets not
/// carved or of another region, or on the boundary, outward from the cavity, as a closed surface of region `label`
/// with local point numbering; and the local-to-mesh point map.
fn shell(mesh: &TetMesh, carved: &[bool], tets: &[u32], label: u32) -> (SurfaceMesh, Vec<u32>) {
    let mut local: FxHashMap<u32, u32> = FxHashMap::default();
    let mut global: Vec<u32> = Vec::new();
    let mut triangles = Vec::new();
    for &t in tets {
        for (i, f) in TET_FACES.iter().enumerate() {
            let n = mesh.neighbors[t as usize][i];
            // A carved neighbour of another region is across an interface: the face belongs
            // to both cavities' shells, recovered in each, so the two refills meet on it.
            if n != NO_NEIGHBOR && carved[n as usize] && mesh.labels[n as usize] == label {
                continue;
            }
            let v = f.map(|k| mesh.tets[t as usize][k]);
            triangles.push(v.map(|x| {
                *local.entry(x).or_insert_with(|| {
                    global.push(x);
                    global.len() as u32 - 1
                })
            }));
        }
    }
    let points = global.iter().map(|&g| mesh.points[g as usize]).collect();
    (SurfaceMesh::closed(points, triangles, label), global)
}

/// Replace the tets of `zone` (see the module docs). `sizing` builds the size function on each
/// cavity's shell; `opts` are the pipeline's options for the refill; `progress` hears
/// `"region L: stage"`.
pub fn remesh(
    mesh: &TetMesh,
    zone: &Zone,
    sizing: &dyn Fn(&SurfaceMesh) -> Result<Sizing, SizingError>,
    opts: &PipelineOptions,
    progress: &mut dyn FnMut(&str),
) -> Result<(TetMesh, RemeshReport), RemeshError> {
    let start = Instant::now();
    let nt = mesh.tets.len();
    let mut carved: Vec<bool> = (0..nt)
        .map(|t| meets(zone, mesh.labels[t], &mesh.corners(t)))
        .collect();
    if !carved.contains(&true) {
        return Err(RemeshError::Empty(format!("{zone:?}")));
    }
    let mut grown = 0;
    let shells = loop {
        // Carved tets by region, in label order (deterministic), and their shells.
        let mut by_region: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
        for t in (0..nt).filter(|&t| carved[t]) {
            by_region.entry(mesh.labels[t]).or_default().push(t as u32);
        }
        let mut shells = Vec::new();
        let mut pinched: Vec<(u32, u32)> = Vec::new();
        for (r, tets) in by_region {
            let (mut s, map) = shell(mesh, &carved, &tets, r);
            match validate_surface(&mut s, &ValidateOptions::default()) {
                Ok(_) => shells.push((r, tets, s, map)),
                // The carved tets touch themselves at an edge or a vertex: carve the tets of
                // the region around it too, until the shell is a manifold surface.
                Err(
                    e @ (SurfaceError::NonManifoldEdge { .. }
                    | SurfaceError::NonManifoldVertex { .. }),
                ) if grown < MAX_GROW => {
                    for t in e.triangles() {
                        for v in s.triangles[t as usize] {
                            pinched.push((r, map[v as usize]));
                        }
                    }
                }
                Err(source) => return Err(RemeshError::Shell { region: r, source }),
            }
        }
        if pinched.is_empty() {
            break shells;
        }
        grown += 1;
        pinched.sort_unstable();
        pinched.dedup();
        for ((c, tet), &l) in carved.iter_mut().zip(&mesh.tets).zip(&mesh.labels) {
            if !*c && tet.iter().any(|v| pinched.binary_search(&(l, *v)).is_ok()) {
                *c = true;
            }
        }
    };
    let seconds_select = start.elapsed().as_secs_f64();

    let mut points = mesh.points.clone();
    let mut tets: Vec<[u32; 4]> = Vec::with_capacity(nt);
    let mut labels: Vec<u32> = Vec::with_capacity(nt);
    for t in (0..nt).filter(|&t| !carved[t]) {
        tets.push(mesh.tets[t]);
        labels.push(mesh.labels[t]);
    }
    let tets_kept = tets.len();
    let mut cavities = Vec::new();
    for (region, carved_tets, surface, map) in shells {
        let sz = sizing(&surface).map_err(|source| RemeshError::Sizing { region, source })?;
        let (sub, report) = mesh_surface(&surface, sz, opts, &mut |s| {
            progress(&format!("region {region}: {s}"))
        })
        .map_err(|source| RemeshError::Pipeline { region, source })?;
        if report.missing_triangles > 0 {
            let first = report
                .recover
                .as_ref()
                .and_then(|r| r.unrecovered.first())
                .map_or(String::new(), |u| format!("{:?}: {}", u.corners, u.reason));
            return Err(RemeshError::Unrecovered {
                region,
                missing: report.missing_triangles,
                first,
            });
        }
        let n_shell = surface.points.len();
        let first_new = points.len() as u32;
        points.extend_from_slice(&sub.points[n_shell..]);
        let to_mesh = |x: u32| {
            if (x as usize) < n_shell {
                map[x as usize]
            } else {
                first_new + (x - n_shell as u32)
            }
        };
        for (t, &l) in sub.tets.iter().zip(&sub.labels) {
            tets.push(t.map(to_mesh));
            labels.push(l);
        }
        cavities.push(CavityReport {
            region,
            tets_removed: carved_tets.len(),
            tets_added: sub.tets.len(),
            shell_triangles: surface.triangles.len(),
            points_added: sub.points.len() - n_shell,
            pipeline: report,
        });
    }

    // Drop the points no tet uses any more (the old cavities' interiors), keeping the order.
    let clock = Instant::now();
    let mut used = vec![false; points.len()];
    for t in &tets {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut renumber = vec![u32::MAX; points.len()];
    let mut kept_points = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        if used[i] {
            renumber[i] = kept_points.len() as u32;
            kept_points.push(*p);
        }
    }
    let points_dropped = points.len() - kept_points.len();
    for t in &mut tets {
        *t = t.map(|v| renumber[v as usize]);
    }
    let out = TetMesh::new(kept_points, tets, labels);
    let report = RemeshReport {
        tets_before: nt,
        tets_after: out.tets.len(),
        tets_kept,
        points_before: mesh.points.len(),
        points_after: out.points.len(),
        points_dropped,
        cavities,
        grown,
        seconds_select,
        seconds_splice: clock.elapsed().as_secs_f64(),
        seconds_total: start.elapsed().as_secs_f64(),
    };
    Ok((out, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_and_sphere_tests_agree_with_simple_cases() {
        let c = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(tet_meets_box(&c, [0.2; 3], [0.3; 3]));
        assert!(!tet_meets_box(&c, [0.4; 3], [0.5; 3])); // beyond the slanted face
        assert!(tet_meets_box(&c, [-1.0; 3], [0.0; 3])); // touching at a corner
        assert!(!tet_meets_box(&c, [1.1, -1.0, -1.0], [2.0, 1.0, 1.0]));
        assert_eq!(tet_distance(&c, [0.1; 3]), 0.0);
        assert!((tet_distance(&c, [-1.0, 0.0, 0.0]) - 1.0).abs() < 1e-15);
        let d = tet_distance(&c, [1.0; 3]);
        assert!((d - (2.0 / 3f64.sqrt())).abs() < 1e-12, "{d}");
    }
}
