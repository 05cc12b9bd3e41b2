//! The 2D pipeline: a PSLG (plus interior nodes) to a labelled triangle mesh keeping every segment
//! — Delaunay ([`crate::delaunay2d`]), segment recovery and outside removal
//! ([`crate::recover2d`]); with [`mesh_pslg`], template node deployment first
//! ([`crate::template::plane`]) and max–min angle smoothing last ([`crate::smooth::plane`]).

use std::time::Instant;

use serde::Serialize;

use crate::delaunay2d::{Delaunay2d, Delaunay2dError};
use crate::mesh::pslg::{Pslg, PslgError};
use crate::mesh::tri::TriMesh;
use crate::recover2d::{CarveError, CarveReport, RecoverReport, SegmentFailure, carve, recover};
use crate::smooth::plane::{PlaneSmoothOptions, PlaneSmoothReport, smooth_tri_with_segments};
use crate::template::plane::{PlaneDeployOptions, PlaneTemplateStats, deploy_plane};

/// Why the 2D pipeline stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Pipeline2dError {
    /// The PSLG is invalid.
    #[error("invalid PSLG: {0}")]
    Pslg(#[from] PslgError),
    /// The Delaunay triangulation failed.
    #[error("Delaunay: {0}")]
    Delaunay(#[from] Delaunay2dError),
    /// Segments could not be recovered.
    #[error("{} of {} segments could not be recovered; first: {:?}", .0.failed.len(), .0.n_segments, .0.failed.first())]
    Recover(Box<RecoverReport>),
    /// Outside removal failed.
    #[error("{0}")]
    Carve(#[from] CarveError),
    /// Node deployment failed.
    #[error("template: {0}")]
    Template(String),
}

/// Counts and times of [`triangulate_pslg`] / [`mesh_pslg`].
#[derive(Debug, Clone, Default, Serialize)]
pub struct Mesh2dReport {
    /// Node deployment, when run.
    pub template: Option<PlaneTemplateStats>,
    /// Points triangulated.
    pub n_points: usize,
    /// Delaunay triangles (finite).
    pub n_delaunay_triangles: usize,
    /// Segment recovery.
    pub recover: RecoverReport,
    /// Outside removal and labels.
    pub carve: CarveReport,
    /// Smoothing, when run.
    pub smooth: Option<PlaneSmoothReport>,
    /// Seconds per stage.
    pub seconds_template: f64,
    /// Seconds of Delaunay.
    pub seconds_delaunay: f64,
    /// Seconds of recovery and outside removal.
    pub seconds_recover: f64,
    /// Seconds of smoothing.
    pub seconds_smooth: f64,
}

/// Triangulate `pslg` with extra interior `nodes` (appended after the PSLG's points; nodes outside
/// the domain are dropped with the outside): Delaunay, recover every segment, remove the outside
/// and holes, label. No node is added; the PSLG's points keep their indices.
pub fn triangulate_pslg(
    pslg: &Pslg,
    nodes: &[[f64; 2]],
) -> Result<(TriMesh, Mesh2dReport), Pipeline2dError> {
    pslg.validate()?;
    let mut report = Mesh2dReport::default();
    let mut points = pslg.points.clone();
    points.extend_from_slice(nodes);
    report.n_points = points.len();
    let clock = Instant::now();
    let mut mesh = Delaunay2d::new(points)?.into_tri_mesh();
    report.n_delaunay_triangles = mesh.triangles.len();
    report.seconds_delaunay = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    let rec = recover(&mut mesh, &pslg.segments);
    if !rec.complete() {
        return Err(Pipeline2dError::Recover(Box::new(rec)));
    }
    report.recover = rec;
    report.carve = carve(&mut mesh, pslg)?;
    report.seconds_recover = clock.elapsed().as_secs_f64();
    Ok((mesh, report))
}

/// Options of [`mesh_pslg`].
#[derive(Debug, Clone, Default)]
pub struct Mesh2dOptions {
    /// Node deployment.
    pub deploy: PlaneDeployOptions,
    /// Smoothing; `None` to skip.
    pub smooth: Option<PlaneSmoothOptions>,
}

/// Mesh the domain of `pslg`: template node deployment, [`triangulate_pslg`], then smoothing.
pub fn mesh_pslg(
    pslg: &Pslg,
    opts: &Mesh2dOptions,
) -> Result<(TriMesh, Mesh2dReport), Pipeline2dError> {
    pslg.validate()?;
    let clock = Instant::now();
    let dep =
        deploy_plane(pslg, &opts.deploy).map_err(|e| Pipeline2dError::Template(e.to_string()))?;
    let seconds_template = clock.elapsed().as_secs_f64();
    let (mut mesh, mut report) = triangulate_pslg(pslg, &dep.nodes)?;
    report.template = Some(dep.stats);
    report.seconds_template = seconds_template;
    if let Some(so) = &opts.smooth {
        let clock = Instant::now();
        let map = &report.carve.point_map;
        let segs: Vec<[u32; 2]> = pslg
            .segments
            .iter()
            .map(|s| s.map(|v| map[v as usize]))
            .collect();
        let hold: Vec<u32> = map.iter().copied().filter(|&v| v != u32::MAX).collect();
        let hold: Vec<u32> = if so.boundary == crate::smooth::Boundary::Fixed {
            hold
        } else {
            // Sliding: points on segments may slide; isolated input points stay.
            let on: rustc_hash::FxHashSet<u32> = segs.iter().flatten().copied().collect();
            hold.into_iter().filter(|v| !on.contains(v)).collect()
        };
        report.smooth = Some(smooth_tri_with_segments(&mut mesh, &segs, &hold, so));
        report.seconds_smooth = clock.elapsed().as_secs_f64();
    }
    Ok((mesh, report))
}

/// A readable line per failed segment.
pub fn describe_failure(f: &SegmentFailure) -> String {
    match f {
        SegmentFailure::NodeOnSegment { segment, node } => {
            format!("segment {segment}: node {node} lies on it")
        }
        SegmentFailure::LeavesMesh { segment } => {
            format!("segment {segment}: leaves the meshed domain")
        }
        SegmentFailure::UnusedEnd { segment, node } => {
            format!("segment {segment}: its end {node} is no node of the mesh")
        }
    }
}
