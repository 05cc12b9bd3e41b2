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

mod cavity;
mod insert;
mod shell;
mod zone;

pub use insert::insert;
pub use shell::{ShellChanges, across_shell};

use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::TetMesh;
use crate::mesh::validate::SurfaceError;
use crate::pipeline::{MeshReport, PipelineError, PipelineOptions};
use crate::sizing::{Sizing, SizingError};
use serde::Serialize;
use std::time::Instant;

type P3 = [f64; 3];

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

impl std::fmt::Display for Zone {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use crate::text::{point as p, short};
        match self {
            Zone::Region(r) => write!(f, "region {r}"),
            Zone::Box { lo, hi } => write!(f, "the box from {} to {}", p(lo), p(hi)),
            Zone::Sphere { centre, radius } => {
                write!(
                    f,
                    "the ball of radius {} around {}",
                    short(*radius),
                    p(centre)
                )
            }
        }
    }
}

/// Why remeshing could not run.
#[derive(Debug, thiserror::Error)]
pub enum RemeshError {
    /// No tet is in the zone.
    #[error("no tet in {0}")]
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
    /// The surface to insert is not a valid closed surface.
    #[error("the surface to insert is not a valid closed surface")]
    Surface(#[source] SurfaceError),
    /// The surface to insert meets the mesh's outer boundary or an interface between regions.
    #[error(
        "triangle {triangle} of the inserted surface {how} {what} (mesh face {face:?}) near ({}, {}, {}); \
         only a surface inside one region is inserted",
        point[0], point[1], point[2]
    )]
    Crossing {
        /// The triangle of the inserted surface.
        triangle: usize,
        /// "crosses" or "touches".
        how: &'static str,
        /// "the interface between regions A and B" or "the outer boundary of region A".
        what: String,
        /// The mesh face (point indices of the input mesh).
        face: [u32; 3],
        /// A point of the intersection (rounded; the decision is exact).
        point: P3,
    },
    /// The surface to insert lies outside the mesh.
    #[error("the inserted surface lies outside the mesh (its point {point} at {at:?})")]
    Outside {
        /// A point of the surface.
        point: usize,
        /// Its coordinates.
        at: P3,
    },
    /// The surface to insert encloses part of the outer boundary or of an interface.
    #[error(
        "the inserted surface encloses part of {what} (mesh point {point} at {at:?}); only a surface inside one region is inserted"
    )]
    Encloses {
        /// "the interface between regions A and B" or "the outer boundary of region A".
        what: String,
        /// The mesh point inside the surface.
        point: u32,
        /// Its coordinates.
        at: P3,
    },
    /// The label to give the inside cannot be used.
    #[error("label {label}: {reason}")]
    Label {
        /// The label.
        label: u32,
        /// Why.
        reason: &'static str,
    },
    /// The inserted surface's shells lie in different regions.
    #[error(
        "the inserted surface has shells in regions {0} and {1}: insert one region's at a time"
    )]
    Regions(u32, u32),
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
    /// With `--allow-shell-changes` ([`across_shell`]): the kept tets sliver removal replaced.
    pub shell_changes: Option<ShellChanges>,
    /// The input index of each kept tet (the first `tets_kept` of the output).
    #[serde(skip)]
    pub kept_input: Vec<u32>,
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
    let mut carved: Vec<bool> = (0..mesh.tets.len())
        .map(|t| zone::meets(zone, mesh.labels[t], &mesh.corners(t)))
        .collect();
    if !carved.contains(&true) {
        return Err(RemeshError::Empty(zone.to_string()));
    }
    let (cavities, grown) = cavity::cavities(mesh, &mut carved)?;
    cavity::replace(
        mesh, &carved, cavities, None, sizing, opts, progress, start, grown,
    )
}
