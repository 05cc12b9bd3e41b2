//! Mesh sizing functions: the desired edge length at every point (dissertation section 2.3).
//!
//! Four sources, combined by [`Sizing`]:
//! - **uniform**: one size everywhere;
//! - **from the surface**: at each surface node the mean length of its edges, growing away from
//!   the surface at a grading rate `g`: `size(p) = min over surface nodes s of (h_s + g·|p − s|)`,
//!   capped at a maximum. Evaluated through a coarse grid that remembers, per grid node, which
//!   surface node gives the smallest cone there (a Dijkstra propagation of sources); a query takes
//!   the exact minimum over the 8 sources of its cell, so the field is the seed's "size from the
//!   triangles near the node" made smooth and graded;
//! - **a field on a regular grid** (any closure; the CLI reads VTK image data or NIfTI);
//! - **per region**: a size for every point of a region of a multi-material model, overriding the
//!   base size there (interfaces still take the finer side, because the deployment never removes a
//!   node).
//!
//! Every size is clamped to `[min_size, max_size]`; `min_size` sets the template spacing (eq. 2.1).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::geom::vec3::{norm, sub};

mod thickness;
use crate::mesh::surface::SurfaceMesh;

/// Where the base size comes from.
pub enum SizeSpec {
    /// The same size everywhere.
    Uniform(f64),
    /// `size` in the volume, but near the surface no coarser than the surface's own edges,
    /// growing away from them by `grading` (as [`SizeSpec::FromSurface`] capped at `size`): the
    /// surface is kept exactly, so a node spacing coarser than its triangles only leaves flat
    /// tets on them (gmsh extends its boundary sizes into the volume the same way). Where the
    /// median surface node size is `size` or more, this is `Uniform(size)`.
    UpTo {
        /// The size in the volume.
        size: f64,
        /// Growth of the size per unit distance from the surface.
        grading: f64,
    },
    /// From the surface's edge lengths, graded away from it.
    FromSurface {
        /// Growth of the size per unit distance from the surface (0 keeps the smallest size).
        grading: f64,
    },
    /// A user field (e.g. interpolated from a grid file) with a lower bound of its values.
    Field {
        /// The size at a point.
        size: Box<dyn Fn([f64; 3]) -> f64 + Send + Sync>,
        /// The smallest value the field takes over the domain.
        min: f64,
        /// The largest value the field takes over the domain.
        max: f64,
    },
}

impl SizeSpec {
    /// A [`SizeSpec::Field`] interpolated trilinearly from a grid (clamped to the grid outside
    /// it), refused unless every value is positive. `frame_to_world` maps the points the mesher
    /// asks about to the grid's coordinates: set for an oblique label image meshed in its
    /// axis-aligned frame ([`crate::image::LabelImage::to_frame`]), where the grid is in world.
    /// The grid is taken as owned or shared (`Arc`: one grid for several sizings, as remesh's
    /// cavities use).
    pub fn from_grid<G>(
        grid: G,
        frame_to_world: Option<[[f64; 4]; 4]>,
    ) -> Result<SizeSpec, SizingError>
    where
        G: std::borrow::Borrow<crate::sizing_grid::ScalarGrid> + Send + Sync + 'static,
    {
        let (min, max) = (grid.borrow().min_value(), grid.borrow().max_value());
        if min.is_nan() || min <= 0.0 {
            return Err(SizingError::FieldNotPositive { min });
        }
        Ok(SizeSpec::Field {
            size: Box::new(move |p| {
                let mut q = [p];
                if let Some(m) = &frame_to_world {
                    crate::image::map_points(m, &mut q);
                }
                grid.borrow().value_at(q[0])
            }),
            min,
            max,
        })
    }
}

impl std::fmt::Debug for SizeSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SizeSpec::Uniform(h) => write!(f, "Uniform({h})"),
            SizeSpec::UpTo { size, grading } => {
                write!(f, "UpTo {{ size: {size}, grading: {grading} }}")
            }
            SizeSpec::FromSurface { grading } => write!(f, "FromSurface {{ grading: {grading} }}"),
            SizeSpec::Field { min, max, .. } => write!(f, "Field {{ min: {min}, max: {max} }}"),
        }
    }
}

/// Options of [`Sizing::new`].
#[derive(Debug)]
pub struct SizingOptions {
    /// The base size.
    pub spec: SizeSpec,
    /// Smallest size anywhere. Default: the uniform size; half the median surface node size for
    /// [`SizeSpec::FromSurface`] (marching-cubes surfaces have a few nodes with tiny edges that
    /// would otherwise shrink the whole template); the field's minimum for a field.
    pub min_size: Option<f64>,
    /// Largest size anywhere (default: unbounded).
    pub max_size: Option<f64>,
    /// `(region label, size)`: a uniform size inside that region, overriding the base (not
    /// clamped).
    pub region_sizes: Vec<(u32, f64)>,
}

impl SizingOptions {
    /// Options for a base size with no clamps and no region sizes.
    pub fn new(spec: SizeSpec) -> SizingOptions {
        SizingOptions {
            spec,
            min_size: None,
            max_size: None,
            region_sizes: Vec::new(),
        }
    }
}

/// Why a sizing function cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum SizingError {
    /// The sizes would need more memory than the caller allows (a caller's check, e.g. the
    /// CLI's `--max-memory` on each cavity `biotet remesh` refills).
    #[error("{0}")]
    OverBudget(String),
    /// A size or rate that must be positive and finite is not.
    #[error("{what} must be a positive finite number, got {value}")]
    NotPositive {
        /// Which parameter.
        what: String,
        /// Its value.
        value: f64,
    },
    /// `min_size > max_size`.
    #[error("minimum size {min} exceeds maximum size {max}")]
    MinAboveMax {
        /// The minimum.
        min: f64,
        /// The maximum.
        max: f64,
    },
    /// A size field whose smallest value is not positive.
    #[error("the size field's smallest value is {min}; sizes must be positive")]
    FieldNotPositive {
        /// Its smallest value.
        min: f64,
    },
    /// Sizing from a surface that has no edges.
    #[error("the surface has no triangles to take sizes from")]
    EmptySurface,
    /// A size asked for a region the surface does not bound.
    #[error("a size for region {label}, which the surface does not bound (its regions: {regions})")]
    NoRegion {
        /// The label asked for.
        label: u32,
        /// The surface's region labels, comma-separated.
        regions: String,
    },
}

/// Refuse a size for a region `surface` does not bound (a mistyped label would otherwise be
/// ignored silently): for the caller that meshes the whole surface, not for one that meshes a
/// part of it (`biotet remesh`'s cavities).
pub fn check_region_labels(
    surface: &SurfaceMesh,
    region_sizes: &[(u32, f64)],
) -> Result<(), SizingError> {
    let labels = surface.regions();
    match region_sizes
        .iter()
        .find(|(l, _)| labels.binary_search(l).is_err())
    {
        None => Ok(()),
        Some(&(label, _)) => Err(SizingError::NoRegion {
            label,
            regions: crate::text::labels(labels),
        }),
    }
}

/// A sizing function: the desired edge length at a point of a region.
pub struct Sizing {
    base: Base,
    min: f64,
    max: f64,
    /// Override per region label (index = label).
    region: Vec<Option<f64>>,
}

enum Base {
    Uniform(f64),
    Surface(SurfaceField),
    Field(Box<dyn Fn([f64; 3]) -> f64 + Send + Sync>, f64),
}

fn positive(what: &str, value: f64) -> Result<f64, SizingError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(SizingError::NotPositive {
            what: what.to_string(),
            value,
        })
    }
}

impl Sizing {
    /// Build the sizing function for `surface` (used by [`SizeSpec::FromSurface`] and
    /// [`SizeSpec::UpTo`] only).
    pub fn new(surface: &SurfaceMesh, opts: SizingOptions) -> Result<Sizing, SizingError> {
        let mut max = match opts.max_size {
            Some(m) => positive("maximum size", m)?,
            None => f64::INFINITY,
        };
        let (base, default_min) = match opts.spec {
            SizeSpec::Uniform(h) => {
                let h = positive("size", h)?;
                (Base::Uniform(h), h)
            }
            SizeSpec::UpTo { size, grading } if !surface.triangles.is_empty() => {
                let h = positive("size", size)?;
                let sizes = SurfaceSizes::of(surface, grading)?;
                if sizes.median >= h && opts.min_size.is_none() {
                    (Base::Uniform(h), h)
                } else {
                    // Not below the median surface size: the few short edges of a
                    // marching-cubes surface do not pull the size under H.
                    max = max.min(h);
                    let lo = opts.min_size.unwrap_or(sizes.median.min(h));
                    let median = sizes.median;
                    (Base::Surface(sizes.field(lo, max)), median.min(h))
                }
            }
            SizeSpec::UpTo { size, .. } => {
                let h = positive("size", size)?;
                (Base::Uniform(h), h)
            }
            SizeSpec::FromSurface { grading } => {
                let sizes = SurfaceSizes::of(surface, grading)?;
                let half = 0.5 * sizes.median;
                let lo = opts.min_size.unwrap_or(half);
                (Base::Surface(sizes.field(lo, max)), half)
            }
            SizeSpec::Field {
                size,
                min,
                max: fmax,
            } => {
                let min = positive("smallest value of the size field", min)?;
                positive("largest value of the size field", fmax)?;
                (Base::Field(size, min), min)
            }
        };
        let min = match opts.min_size {
            Some(m) => positive("minimum size", m)?,
            None => default_min,
        };
        if min > max {
            return Err(SizingError::MinAboveMax { min, max });
        }
        let mut region = Vec::new();
        for &(label, h) in &opts.region_sizes {
            let h = positive(&format!("size of region {label}"), h)?;
            let l = label as usize;
            if region.len() <= l {
                region.resize(l + 1, None);
            }
            // An explicit request: not clamped.
            region[l] = Some(h);
        }
        Ok(Sizing {
            base,
            min,
            max,
            region,
        })
    }

    /// A uniform size `h` (convenience for tests and the library).
    pub fn uniform(h: f64) -> Result<Sizing, SizingError> {
        Sizing::new(
            &SurfaceMesh::default(),
            SizingOptions::new(SizeSpec::Uniform(h)),
        )
    }

    /// The desired edge length at `p` inside region `region` (0 = outside; uses the base size).
    #[inline]
    pub fn at(&self, p: [f64; 3], region: u32) -> f64 {
        if let Some(Some(h)) = self.region.get(region as usize) {
            return *h;
        }
        let h = match &self.base {
            Base::Uniform(h) => *h,
            Base::Surface(f) => f.at(p),
            Base::Field(f, _) => f(p),
        };
        // NaN from a user field falls to the minimum: finer is the safe side.
        if h.is_nan() {
            self.min
        } else {
            h.clamp(self.min, self.max)
        }
    }

    /// The smallest size this function returns anywhere: the template spacing is this over the
    /// resolution (eq. 2.1).
    pub fn min_size(&self) -> f64 {
        let mut m = match &self.base {
            Base::Uniform(h) => h.clamp(self.min, self.max),
            Base::Surface(f) => f.min_h.clamp(self.min, self.max),
            Base::Field(_, lo) => lo.clamp(self.min, self.max),
        };
        for h in self.region.iter().flatten() {
            m = m.min(*h);
        }
        m
    }

    /// The clamps `[min, max]`.
    pub fn bounds(&self) -> (f64, f64) {
        (self.min, self.max)
    }
}

/// The node sizes of the surface-derived field ([`node_sizes`]), their median and the grading.
struct SurfaceSizes {
    nodes: Vec<[f64; 3]>,
    h: Vec<f64>,
    median: f64,
    grading: f64,
}

impl SurfaceSizes {
    fn of(surface: &SurfaceMesh, grading: f64) -> Result<SurfaceSizes, SizingError> {
        if !(grading >= 0.0 && grading.is_finite()) {
            return Err(SizingError::NotPositive {
                what: "grading".into(),
                value: grading,
            });
        }
        let (nodes, h) = node_sizes(surface)?;
        let mut sorted = h.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[sorted.len() / 2];
        Ok(SurfaceSizes {
            nodes,
            h,
            median,
            grading,
        })
    }

    /// The graded field, between `lo` (at most `max`) and `max`.
    fn field(self, lo: f64, max: f64) -> SurfaceField {
        SurfaceField::new(self.nodes, self.h, self.grading, lo.min(max), max)
    }
}

/// Mean length of the edges at each referenced surface node, capped at half the local thickness
/// ([`thickness`]): `(positions, sizes)`.
fn node_sizes(surface: &SurfaceMesh) -> Result<(Vec<[f64; 3]>, Vec<f64>), SizingError> {
    let n = surface.points.len();
    let mut sum = vec![0.0f64; n];
    let mut count = vec![0u32; n];
    // Each interior edge appears in two triangles, a boundary one in one; counting every
    // (triangle, edge) pair weights both the same for a closed surface.
    for t in &surface.triangles {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let l = norm(sub(surface.points[a], surface.points[b]));
            sum[a] += l;
            sum[b] += l;
            count[a] += 1;
            count[b] += 1;
        }
    }
    let mut pos = Vec::new();
    let mut h = Vec::new();
    let mut ids = Vec::new();
    for v in 0..n {
        if count[v] > 0 && sum[v] > 0.0 {
            pos.push(surface.points[v]);
            h.push(sum[v] / count[v] as f64);
            ids.push(v as u32);
        }
    }
    if h.is_empty() {
        return Err(SizingError::EmptySurface);
    }
    thickness::cap_by_thickness(surface, &ids, &mut h);
    Ok((pos, h))
}

/// `min_s (h_s + g·|p − s|)` through a coarse grid of nearest sources.
struct SurfaceField {
    nodes: Vec<[f64; 3]>,
    h: Vec<f64>,
    grading: f64,
    min_h: f64,
    origin: [f64; 3],
    inv_cell: f64,
    dims: [usize; 3],
    source: Vec<u32>,
}

impl SurfaceField {
    fn new(nodes: Vec<[f64; 3]>, h: Vec<f64>, grading: f64, lo: f64, hi: f64) -> SurfaceField {
        let h: Vec<f64> = h.iter().map(|&x| x.clamp(lo, hi.max(lo))).collect();
        let min_h = h.iter().copied().fold(f64::INFINITY, f64::min);
        let mut bmin = [f64::INFINITY; 3];
        let mut bmax = [f64::NEG_INFINITY; 3];
        for p in &nodes {
            for a in 0..3 {
                bmin[a] = bmin[a].min(p[a]);
                bmax[a] = bmax[a].max(p[a]);
            }
        }
        let ext = (0..3).map(|a| bmax[a] - bmin[a]).fold(0.0, f64::max);
        let mut sorted = h.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[sorted.len() / 2];
        // Cells of about the median size, at most 128 along the longest side.
        let cell = median.max(ext / 128.0).max(f64::MIN_POSITIVE);
        let origin = [bmin[0] - cell, bmin[1] - cell, bmin[2] - cell];
        let dims = [0, 1, 2].map(|a| ((bmax[a] - bmin[a]) / cell).ceil() as usize + 3);
        let mut f = SurfaceField {
            nodes,
            h,
            grading,
            min_h,
            origin,
            inv_cell: 1.0 / cell,
            dims,
            source: Vec::new(),
        };
        f.propagate(cell);
        f
    }

    #[inline]
    fn cone(&self, s: u32, p: [f64; 3]) -> f64 {
        let s = s as usize;
        self.h[s] + self.grading * norm(sub(p, self.nodes[s]))
    }

    fn grid_point(&self, i: usize, j: usize, k: usize, cell: f64) -> [f64; 3] {
        [
            self.origin[0] + i as f64 * cell,
            self.origin[1] + j as f64 * cell,
            self.origin[2] + k as f64 * cell,
        ]
    }

    /// Dijkstra over grid nodes (26 neighbours), carrying the source that gives the smallest cone.
    fn propagate(&mut self, cell: f64) {
        let [nx, ny, nz] = self.dims;
        let n = nx * ny * nz;
        let mut best = vec![f64::INFINITY; n];
        let mut source = vec![u32::MAX; n];
        let mut heap = BinaryHeap::new();
        for s in 0..self.nodes.len() {
            let c = self.cell_of(self.nodes[s]);
            for dk in 0..2 {
                for dj in 0..2 {
                    for di in 0..2 {
                        let (i, j, k) = (c[0] + di, c[1] + dj, c[2] + dk);
                        let idx = i + nx * (j + ny * k);
                        let v = self.cone(s as u32, self.grid_point(i, j, k, cell));
                        if v < best[idx] {
                            best[idx] = v;
                            source[idx] = s as u32;
                            heap.push(Reverse((v.to_bits(), idx)));
                        }
                    }
                }
            }
        }
        while let Some(Reverse((bits, idx))) = heap.pop() {
            if f64::from_bits(bits) > best[idx] {
                continue;
            }
            let s = source[idx];
            let (i, j, k) = (idx % nx, (idx / nx) % ny, idx / (nx * ny));
            for dk in -1i64..=1 {
                for dj in -1i64..=1 {
                    for di in -1i64..=1 {
                        let (a, b, c) = (i as i64 + di, j as i64 + dj, k as i64 + dk);
                        if a < 0
                            || b < 0
                            || c < 0
                            || a >= nx as i64
                            || b >= ny as i64
                            || c >= nz as i64
                        {
                            continue;
                        }
                        let (a, b, c) = (a as usize, b as usize, c as usize);
                        let m = a + nx * (b + ny * c);
                        let v = self.cone(s, self.grid_point(a, b, c, cell));
                        if v < best[m] {
                            best[m] = v;
                            source[m] = s;
                            heap.push(Reverse((v.to_bits(), m)));
                        }
                    }
                }
            }
        }
        self.source = source;
    }

    /// The grid cell containing `p` (clamped to the grid): its lowest corner.
    #[inline]
    fn cell_of(&self, p: [f64; 3]) -> [usize; 3] {
        [0, 1, 2].map(|a| {
            let f = (p[a] - self.origin[a]) * self.inv_cell;
            (f.max(0.0) as usize).min(self.dims[a] - 2)
        })
    }

    #[inline]
    fn at(&self, p: [f64; 3]) -> f64 {
        let c = self.cell_of(p);
        let [nx, ny, _] = self.dims;
        let mut v = f64::INFINITY;
        let mut last = u32::MAX;
        for dk in 0..2 {
            for dj in 0..2 {
                for di in 0..2 {
                    let s = self.source[(c[0] + di) + nx * ((c[1] + dj) + ny * (c[2] + dk))];
                    if s != last && s != u32::MAX {
                        v = v.min(self.cone(s, p));
                        last = s;
                    }
                }
            }
        }
        v
    }
}
