//! Template-based node deployment (dissertation chapter 2, eq. 2.1–2.9).
//!
//! A grid of voxels of spacing `dx = smallest size / resolution` (eq. 2.1) covers the surface's
//! bounding box plus a margin (eq. 2.2). Every voxel is classified inside a region or outside by
//! exact ray parity along the grid lines ([`classify`]); each surface node claims its nearest
//! voxel (eq. 2.6) and a buffer zone sized by the sizing function there; triangles too large for
//! their nodes' zones are sealed with scaled prisms (eq. 2.7, [`seal`]); then a front advancing
//! inward from that boundary buffer turns each unprocessed inside voxel it reaches into an
//! interior node with its own zone (eq. 2.8, [`sweep`]). Node coordinates follow eq. 2.9. The
//! template is two bytes per voxel ([`voxels`]) and is freed before the nodes are returned.
//!
//! Interior nodes are strictly inside the surface (exactly decided) and never on it.

pub mod classify;
pub mod plane;
pub mod seal;
pub mod sweep;
pub mod voxels;

use std::time::Instant;

use serde::Serialize;

use crate::mesh::surface::SurfaceMesh;
use crate::sizing::Sizing;
pub use voxels::Zone;
use voxels::{INTERIOR_NODE, MAX_REGION, Template};

/// Options of [`deploy`].
#[derive(Debug, Clone)]
pub struct DeployOptions {
    /// Voxels per smallest desired edge (eq. 2.1; the seed uses 2).
    pub resolution: f64,
    /// Shape of buffer zones.
    pub zone: Zone,
    /// Voxels of margin around the bounding box on each side (eq. 2.2 uses one each side, "+2").
    pub margin: usize,
    /// Refuse templates with more voxels than this (two bytes each).
    pub max_voxels: usize,
}

impl Default for DeployOptions {
    fn default() -> DeployOptions {
        DeployOptions {
            resolution: 2.0,
            zone: Zone::Euclidean,
            margin: 2,
            max_voxels: 1 << 31,
        }
    }
}

/// Why nodes cannot be deployed.
#[derive(Debug, thiserror::Error)]
pub enum DeployError {
    /// The template would be too large.
    #[error(
        "the template would have {voxels} voxels ({nx} × {ny} × {nz} at spacing {dx:.4} = smallest size {min_size:.4} / resolution {resolution}), over the limit of {limit}; use a larger minimum size or a lower resolution"
    )]
    TooLarge {
        /// Voxels needed.
        voxels: u128,
        /// Grid dimensions.
        nx: u64,
        /// Grid dimensions.
        ny: u64,
        /// Grid dimensions.
        nz: u64,
        /// Spacing.
        dx: f64,
        /// Smallest size of the sizing function.
        min_size: f64,
        /// Resolution.
        resolution: f64,
        /// The limit.
        limit: usize,
    },
    /// Resolution not positive.
    #[error("resolution must be a positive finite number, got {0}")]
    Resolution(f64),
    /// More regions than the template's byte can hold.
    #[error("the template holds region labels up to {MAX_REGION}; the surface uses label {0}")]
    RegionLabel(u32),
    /// No triangles.
    #[error("the surface has no triangles")]
    Empty,
}

/// Figures of one deployment (what Table 2.1 reports, and more).
#[derive(Debug, Clone, Default, Serialize)]
pub struct TemplateStats {
    /// Voxels along x, y, z.
    pub dims: [usize; 3],
    /// Voxel spacing.
    pub dx: f64,
    /// Total voxels.
    pub voxels: usize,
    /// Bytes of the template (one per voxel), freed before returning.
    pub bytes: usize,
    /// Zone shape used.
    pub zone: Option<Zone>,
    /// Voxels whose centre is inside a region.
    pub inside_voxels: usize,
    /// Voxel centres exactly on the surface.
    pub on_surface_voxels: usize,
    /// Ray crossings counted.
    pub crossings: usize,
    /// Surface triangles sealed with a prism.
    pub sealed_triangles: usize,
    /// Surface nodes.
    pub surface_nodes: usize,
    /// Interior nodes placed.
    pub interior_nodes: usize,
    /// Seconds classifying voxels.
    pub seconds_classify: f64,
    /// Seconds marking the boundary buffer and sealing.
    pub seconds_buffer: f64,
    /// Seconds of the inward sweep.
    pub seconds_sweep: f64,
}

/// Deployed nodes: the surface's points first (same indices), then the interior nodes.
#[derive(Debug, Clone)]
pub struct Deployment {
    /// Surface points followed by interior nodes.
    pub points: Vec<[f64; 3]>,
    /// How many of `points` are the surface's.
    pub n_surface: usize,
    /// Region label of each interior node (`points[n_surface + i]`).
    pub interior_regions: Vec<u32>,
    /// Figures.
    pub stats: TemplateStats,
}

/// The largest `m·2^e ≤ x` with an 8-bit mantissa `m` (at most 0.8% below `x`).
pub(crate) fn dyadic_below(x: f64) -> f64 {
    if !(x > 0.0 && x.is_finite()) {
        return x;
    }
    let scale = 2f64.powi(x.log2().floor() as i32 - 7);
    let d = (x / scale).floor() * scale;
    if d > 0.0 { d } else { x }
}

/// The size at each surface point: the smallest over the regions on either side of its
/// triangles (0 for points no triangle uses).
pub fn surface_node_sizes(surface: &SurfaceMesh, sizing: &Sizing) -> Vec<f64> {
    let mut size = vec![f64::INFINITY; surface.points.len()];
    for (t, tri) in surface.triangles.iter().enumerate() {
        for &side in &surface.sides[t] {
            for &v in tri {
                let v = v as usize;
                // Region 0 (outside) uses the base size, so one-sided shells still get one.
                let h = sizing.at(surface.points[v], side);
                if h < size[v] {
                    size[v] = h;
                }
            }
        }
    }
    for s in &mut size {
        if !s.is_finite() {
            *s = 0.0;
        }
    }
    size
}

/// Deploy interior nodes for `surface` (which should be valid: closed, oriented, labelled).
pub fn deploy(
    surface: &SurfaceMesh,
    sizing: &Sizing,
    opts: &DeployOptions,
) -> Result<Deployment, DeployError> {
    if surface.triangles.is_empty() {
        return Err(DeployError::Empty);
    }
    if let Some(&l) = surface.sides.iter().flatten().find(|&&l| l > MAX_REGION) {
        return Err(DeployError::RegionLabel(l));
    }
    if !(opts.resolution > 0.0 && opts.resolution.is_finite()) {
        return Err(DeployError::Resolution(opts.resolution));
    }
    let min_size = sizing.min_size();
    let dx = dyadic_below(min_size / opts.resolution);
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for tri in &surface.triangles {
        for &v in tri {
            let p = surface.points[v as usize];
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
    }
    let m = opts.margin as f64;
    let dims_f = [0, 1, 2].map(|a| (hi[a] / dx).ceil() - (lo[a] / dx).floor() + 2.0 * m + 1.0);
    let voxels = dims_f[0] * dims_f[1] * dims_f[2];
    if voxels.is_nan() || voxels > opts.max_voxels as f64 {
        return Err(DeployError::TooLarge {
            voxels: voxels.min(u128::MAX as f64) as u128,
            nx: dims_f[0] as u64,
            ny: dims_f[1] as u64,
            nz: dims_f[2] as u64,
            dx,
            min_size,
            resolution: opts.resolution,
            limit: opts.max_voxels,
        });
    }
    let dims = dims_f.map(|d| d as usize);
    // Origin on a multiple of dx: with dx's 8-bit mantissa every voxel coordinate k·dx is then
    // exact, so interior nodes form an exact lattice whose degeneracies (cospherical cubes) are
    // exact zeros for the predicates' symbolic perturbation, not float noise near zero.
    let origin = [0, 1, 2].map(|a| ((lo[a] / dx).floor() - m) * dx);
    let mut t = Template::new(dims, origin, dx);
    let mut stats = TemplateStats {
        dims,
        dx,
        voxels: t.cells.len(),
        bytes: t.bytes(),
        zone: Some(opts.zone),
        ..TemplateStats::default()
    };

    let clock = Instant::now();
    let c = classify::classify(&mut t, surface);
    stats.crossings = c.crossings;
    stats.on_surface_voxels = c.on_surface;
    stats.seconds_classify = clock.elapsed().as_secs_f64();

    let clock = Instant::now();
    let sizes = surface_node_sizes(surface, sizing);
    seal::mark_surface_nodes(&mut t, surface, &sizes, opts.zone);
    stats.surface_nodes = sizes.iter().filter(|&&s| s > 0.0).count();
    stats.sealed_triangles = seal::seal_triangles(&mut t, surface, &sizes);
    stats.seconds_buffer = clock.elapsed().as_secs_f64();

    let clock = Instant::now();
    let radius = |p: [f64; 3], region: u32| (sizing.at(p, region) / dx).round().max(1.0) as usize;
    stats.interior_nodes = sweep::sweep(&mut t, opts.zone, &radius);
    stats.seconds_sweep = clock.elapsed().as_secs_f64();

    let mut points = surface.points.clone();
    let n_surface = points.len();
    points.reserve(stats.interior_nodes);
    let mut interior_regions = Vec::with_capacity(stats.interior_nodes);
    let mut inside = 0;
    for idx in 0..t.cells.len() {
        let r = t.region(idx);
        if r != 0 {
            inside += 1;
        }
        if t.state(idx) == INTERIOR_NODE {
            points.push(t.point(t.ijk(idx)));
            interior_regions.push(r);
        }
    }
    stats.inside_voxels = inside;
    drop(t);
    Ok(Deployment {
        points,
        n_surface,
        interior_regions,
        stats,
    })
}
