//! The carved tets to cavities (one per region, grown until each shell is a manifold surface),
//! each cavity refilled by the pipeline and the new tets spliced in.

use super::{CavityReport, RemeshError, RemeshReport};
use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::{NO_NEIGHBOR, TET_FACES, TetMesh, sorted3};
use crate::mesh::validate::{SurfaceError, ValidateOptions, validate_surface};
use crate::pipeline::{PipelineOptions, mesh_surface};
use crate::sizing::{Sizing, SizingError};
use rustc_hash::FxHashMap;
use std::time::Instant;

/// Rounds of carving the tets around a pinched edge or vertex of a cavity's shell.
const MAX_GROW: usize = 32;

/// Local label of a cavity's own region in the surface handed to the pipeline; labels are put
/// back after, so any input label works whatever the template's limit on region count.
const OWN: u32 = 1;
/// Local label of the inside of an inserted surface.
const INSERTED: u32 = 2;

/// One region's carved tets and its shell.
pub(super) struct Cavity {
    /// The region.
    pub region: u32,
    /// Its carved tets.
    pub tets: Vec<u32>,
    /// Its shell, outward, local numbering, sides `[OWN, 0]`.
    pub shell: SurfaceMesh,
    /// Shell point to mesh point.
    pub map: Vec<u32>,
}

/// A closed surface to put inside one region's cavity: its triangles outward, its inside
/// labelled `label`.
pub(super) struct Inner<'a> {
    /// The region whose cavity holds it.
    pub region: u32,
    /// The surface (its sides are ignored: inside is `label`, outside is `region`).
    pub surface: &'a SurfaceMesh,
    /// The label inside it.
    pub label: u32,
}

/// The shell of the carved tets `tets` (all of region `label`): its faces towards tets not
/// carved or of another region, or on the boundary, outward from the cavity, as a closed
/// surface of the local region [`OWN`] with local point numbering; and the local-to-mesh point
/// map.
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
    (SurfaceMesh::closed(points, triangles, OWN), global)
}

/// The carved tets by region (in label order) and their shells. Where a region's carved tets
/// touch themselves at an edge or a vertex, the region's tets around it are carved too (at
/// most [`MAX_GROW`] rounds), so every shell is a closed manifold surface. Returns the cavities
/// and the rounds grown.
pub(super) fn cavities(
    mesh: &TetMesh,
    carved: &mut [bool],
) -> Result<(Vec<Cavity>, usize), RemeshError> {
    let nt = mesh.tets.len();
    let mut grown = 0;
    loop {
        let mut by_region: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
        for t in (0..nt).filter(|&t| carved[t]) {
            by_region.entry(mesh.labels[t]).or_default().push(t as u32);
        }
        let mut out = Vec::new();
        let mut pinched: Vec<(u32, u32)> = Vec::new();
        for (region, tets) in by_region {
            let (mut shell, map) = shell(mesh, carved, &tets, region);
            match validate_surface(&mut shell, &ValidateOptions::default()) {
                Ok(_) => out.push(Cavity {
                    region,
                    tets,
                    shell,
                    map,
                }),
                Err(
                    e @ (SurfaceError::NonManifoldEdge { .. }
                    | SurfaceError::NonManifoldVertex { .. }),
                ) if grown < MAX_GROW => {
                    for t in e.triangles() {
                        for v in shell.triangles[t as usize] {
                            pinched.push((region, map[v as usize]));
                        }
                    }
                }
                Err(source) => return Err(RemeshError::Shell { region, source }),
            }
        }
        if pinched.is_empty() {
            return Ok((out, grown));
        }
        grown += 1;
        pinched.sort_unstable();
        pinched.dedup();
        for ((c, tet), &l) in carved.iter_mut().zip(&mesh.tets).zip(&mesh.labels) {
            if !*c && tet.iter().any(|v| pinched.binary_search(&(l, *v)).is_ok()) {
                *c = true;
            }
        }
    }
}

/// The surface the pipeline meshes for `cavity`: its shell, plus `inner`'s triangles (sides
/// `[INSERTED, OWN]`) when it goes in this cavity. The shell's points come first, so they keep
/// their indices.
fn cavity_surface(cavity: &Cavity, inner: Option<&Inner>) -> Result<SurfaceMesh, RemeshError> {
    let Some(inner) = inner.filter(|i| i.region == cavity.region) else {
        return Ok(cavity.shell.clone());
    };
    let mut s = cavity.shell.clone();
    let mut add = SurfaceMesh::closed(
        inner.surface.points.clone(),
        inner.surface.triangles.clone(),
        INSERTED,
    );
    for sides in &mut add.sides {
        sides[1] = OWN;
    }
    s.append(&add);
    // The inserted surface was kept apart from the shell by the carving: this checks it exactly.
    validate_surface(&mut s, &ValidateOptions::default()).map_err(|source| RemeshError::Shell {
        region: cavity.region,
        source,
    })?;
    Ok(s)
}

/// The sorted corners of face `f` of `tet`.
fn face_key(tet: &[u32; 4], f: usize) -> [u32; 3] {
    sorted3(TET_FACES[f].map(|k| tet[k]))
}

/// Refill every cavity and splice the new tets in after the kept ones; unused points dropped.
#[allow(clippy::too_many_arguments)]
pub(super) fn replace(
    mesh: &TetMesh,
    carved: &[bool],
    cavities: Vec<Cavity>,
    inner: Option<&Inner>,
    sizing: &dyn Fn(&SurfaceMesh) -> Result<Sizing, SizingError>,
    opts: &PipelineOptions,
    progress: &mut dyn FnMut(&str),
    start: Instant,
    grown: usize,
) -> Result<(TetMesh, RemeshReport), RemeshError> {
    let seconds_select = start.elapsed().as_secs_f64();
    let nt = mesh.tets.len();
    let mut points = mesh.points.clone();
    let mut tets: Vec<[u32; 4]> = Vec::with_capacity(nt);
    let mut labels: Vec<u32> = Vec::with_capacity(nt);
    // Adjacency is carried over rather than rebuilt (a full rebuild is most of the cost of a
    // small zone in a large mesh): kept tets keep theirs, renumbered; new tets take their
    // cavity mesh's; the faces left open on either side (the shells) are paired by their corners.
    let mut old_to_new = vec![u32::MAX; nt];
    for t in (0..nt).filter(|&t| !carved[t]) {
        old_to_new[t] = tets.len() as u32;
        tets.push(mesh.tets[t]);
        labels.push(mesh.labels[t]);
    }
    let tets_kept = tets.len();
    let mut neighbors: Vec<[u32; 4]> = Vec::with_capacity(nt);
    let mut open: Vec<([u32; 3], u32)> = Vec::new();
    for (i, t) in (0..nt).filter(|&t| !carved[t]).enumerate() {
        let mut nb = mesh.neighbors[t];
        for (f, n) in nb.iter_mut().enumerate() {
            if *n == NO_NEIGHBOR {
                continue;
            }
            *n = old_to_new[*n as usize];
            if *n == NO_NEIGHBOR {
                open.push((face_key(&tets[i], f), (4 * i + f) as u32));
            }
        }
        neighbors.push(nb);
    }
    let mut reports = Vec::new();
    for cavity in &cavities {
        let region = cavity.region;
        let surface = cavity_surface(cavity, inner)?;
        let sz = sizing(&surface).map_err(|source| RemeshError::Sizing { region, source })?;
        let (mut sub, report) = mesh_surface(&surface, sz, opts, &mut |s| {
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
        let n_shell = cavity.shell.points.len();
        let first_new = points.len() as u32;
        points.extend_from_slice(&sub.points[n_shell..]);
        let to_mesh = |x: u32| {
            if (x as usize) < n_shell {
                cavity.map[x as usize]
            } else {
                first_new + (x - n_shell as u32)
            }
        };
        let inserted = inner.map_or(region, |i| i.label);
        if sub.neighbors.len() != sub.tets.len() {
            sub.rebuild_neighbors();
        }
        let first_tet = tets.len() as u32;
        for ((t, &l), nb) in sub.tets.iter().zip(&sub.labels).zip(&sub.neighbors) {
            let i = tets.len();
            tets.push(t.map(to_mesh));
            labels.push(if l == INSERTED { inserted } else { region });
            let mut nb = *nb;
            for (f, n) in nb.iter_mut().enumerate() {
                if *n == NO_NEIGHBOR {
                    open.push((face_key(&tets[i], f), (4 * i + f) as u32));
                } else {
                    *n += first_tet;
                }
            }
            neighbors.push(nb);
        }
        reports.push(CavityReport {
            region,
            tets_removed: cavity.tets.len(),
            tets_added: sub.tets.len(),
            shell_triangles: cavity.shell.triangles.len(),
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
    // A shell face is open on both sides (kept and new, or two cavities across an interface);
    // a face open once is on the boundary.
    open.sort_unstable();
    for w in open.windows(2) {
        if w[0].0 == w[1].0 {
            let (a, b) = (w[0].1 as usize, w[1].1 as usize);
            neighbors[a / 4][a % 4] = (b / 4) as u32;
            neighbors[b / 4][b % 4] = (a / 4) as u32;
        }
    }
    let out = TetMesh {
        points: kept_points,
        tets,
        neighbors,
        labels,
    };
    let report = RemeshReport {
        tets_before: nt,
        tets_after: out.tets.len(),
        tets_kept,
        points_before: mesh.points.len(),
        points_after: out.points.len(),
        points_dropped,
        cavities: reports,
        grown,
        seconds_select,
        seconds_splice: clock.elapsed().as_secs_f64(),
        seconds_total: start.elapsed().as_secs_f64(),
        shell_changes: None,
        kept_input: (0..nt as u32).filter(|&t| !carved[t as usize]).collect(),
    };
    Ok((out, report))
}
