//! Template node deployment in the plane (dissertation section 2.3.1 as drawn in figs. 2.2, 2.5,
//! 2.6, 2.9 and 2.10): the same one-byte template as 3D ([`super::voxels::Template`] with one
//! layer of pixels), the same buffer zones ([`Template::mark_zone`]) and the same inward sweep
//! ([`super::sweep::sweep`]); only classification and sealing are planar.
//!
//! 1. **Spacing** (eq. 2.1): `dx` = smallest size / resolution, rounded down to an 8-bit mantissa
//!    and the origin put on a multiple of it, so every pixel centre is exact (eq. 2.9).
//! 2. **Inside pixels.** The seed casts rays (Jordan) after perturbing the boundary nodes; here a
//!    pixel is inside when it lies in a triangle of the PSLG's own constrained triangulation with
//!    the outside and holes removed ([`crate::pipeline2d::triangulate_pslg`] with no extra node),
//!    decided exactly by [`orient2d`]: closed across edges that are no segment, strictly inside
//!    across segments, so no node can land on a segment and nothing needs perturbing. This also
//!    handles holes and internal boundaries, where ray parity would not.
//! 3. **Boundary buffer** (eq. 2.6, 2.8): each PSLG point claims its nearest pixel and a zone of
//!    radius (its size / dx) pixels; its size is the mean length of its segments, capped by the
//!    interior size.
//! 4. **Rectangle sealing** (fig. 2.5): a segment longer than the sum of its ends' zone radii
//!    leaves a hole in the buffer; the segment is extended at each end by that end's size and the
//!    region within that size on either side (a trapezoid, vertex-dependent widths) is marked
//!    buffer.
//! 5. **Inward sweep** (fig. 2.9): breadth-first from the buffer, each unprocessed inside pixel
//!    becomes a node and claims its zone — of the interior size, or with
//!    [`PlaneDeployOptions::grading`] of a size growing from the boundary points' sizes by that
//!    rate per unit distance (a chamfer distance field over the pixels), up to the interior size.

use serde::Serialize;

use super::dyadic_below;
use super::sweep::sweep;
use super::voxels::{BUFFER, INTERIOR_NODE, SURFACE_NODE, Template, UNPROCESSED, Zone};
use crate::geom::predicates::{Sign, orient2d};
use crate::mesh::pslg::{Pslg, edge_key};
use crate::pipeline2d::triangulate_pslg;

/// Options of [`deploy_plane`].
#[derive(Debug, Clone, Serialize)]
pub struct PlaneDeployOptions {
    /// Desired edge length inside; `None`: the mean segment length.
    pub size: Option<f64>,
    /// Pixels per smallest size (eq. 2.1; the seed uses 2).
    pub resolution: f64,
    /// Zone shape.
    pub zone: Zone,
    /// Refuse templates with more pixels than this.
    pub max_pixels: usize,
    /// Grading: the size grows from each PSLG point's size by this much per unit of distance, up
    /// to `size` (`None`: `size` everywhere away from the boundary buffer).
    pub grading: Option<f64>,
}

impl Default for PlaneDeployOptions {
    fn default() -> Self {
        PlaneDeployOptions {
            size: None,
            resolution: 2.0,
            zone: Zone::Euclidean,
            max_pixels: 1 << 31,
            grading: None,
        }
    }
}

/// The graded size at every pixel: `min(h, min_i(s_i + g·d(pixel, x_i)))` over the PSLG points,
/// with `d` the 3×3 chamfer distance (steps 1 and √2 pixels, within 8% of Euclidean) computed in
/// two raster passes — a sizing field, so floating point.
fn graded_field(t: &Template, seeds: &[([usize; 3], f64)], h: f64, g: f64) -> Vec<f32> {
    let [nx, ny, _] = t.n;
    let mut f = vec![f32::INFINITY; nx * ny];
    for &(c, s) in seeds {
        let i = c[0] + nx * c[1];
        f[i] = f[i].min(s as f32);
    }
    let a = (g * t.dx) as f32;
    let b = a * std::f32::consts::SQRT_2;
    for j in 0..ny {
        for i in 0..nx {
            let k = i + nx * j;
            let mut v = f[k];
            if i > 0 {
                v = v.min(f[k - 1] + a);
            }
            if j > 0 {
                v = v.min(f[k - nx] + a);
                if i > 0 {
                    v = v.min(f[k - nx - 1] + b);
                }
                if i + 1 < nx {
                    v = v.min(f[k - nx + 1] + b);
                }
            }
            f[k] = v;
        }
    }
    for j in (0..ny).rev() {
        for i in (0..nx).rev() {
            let k = i + nx * j;
            let mut v = f[k];
            if i + 1 < nx {
                v = v.min(f[k + 1] + a);
            }
            if j + 1 < ny {
                v = v.min(f[k + nx] + a);
                if i + 1 < nx {
                    v = v.min(f[k + nx + 1] + b);
                }
                if i > 0 {
                    v = v.min(f[k + nx - 1] + b);
                }
            }
            f[k] = v.min(h as f32);
        }
    }
    f
}

/// Figures of one deployment.
#[derive(Debug, Clone, Default, Serialize)]
pub struct PlaneTemplateStats {
    /// Pixels along x and y.
    pub dims: [usize; 2],
    /// Pixel spacing.
    pub dx: f64,
    /// Interior size used.
    pub size: f64,
    /// Pixels inside the domain.
    pub inside_pixels: usize,
    /// Segments sealed with a rectangle (fig. 2.5).
    pub sealed_segments: usize,
    /// Boundary (PSLG) nodes.
    pub boundary_nodes: usize,
    /// Interior nodes placed.
    pub interior_nodes: usize,
}

/// Deployed interior nodes (the PSLG's points are not repeated).
#[derive(Debug, Clone)]
pub struct PlaneDeployment {
    /// Interior nodes, in pixel order.
    pub nodes: Vec<[f64; 2]>,
    /// Figures.
    pub stats: PlaneTemplateStats,
}

/// Why nodes cannot be deployed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlaneDeployError {
    /// Bad size or resolution.
    #[error("{0} must be a positive finite number, got {1}")]
    Option(&'static str, f64),
    /// The template would be too large.
    #[error(
        "the template would have {pixels} pixels at spacing {dx} (size / resolution), over the \
         limit of {limit}: use a larger size or a lower resolution"
    )]
    TooLarge {
        /// Pixels needed.
        pixels: f64,
        /// Spacing.
        dx: f64,
        /// Limit.
        limit: usize,
    },
    /// The PSLG itself could not be triangulated.
    #[error("{0}")]
    Domain(String),
}

/// Deploy interior nodes for the domain of `pslg` (see the module docs).
pub fn deploy_plane(
    pslg: &Pslg,
    opts: &PlaneDeployOptions,
) -> Result<PlaneDeployment, PlaneDeployError> {
    let (domain, _) =
        triangulate_pslg(pslg, &[]).map_err(|e| PlaneDeployError::Domain(e.to_string()))?;
    let pt = |v: u32| pslg.points[v as usize];
    let len = |[a, b]: [u32; 2]| {
        let (p, q) = (pt(a), pt(b));
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
    };
    let mean = pslg.segments.iter().map(|&s| len(s)).sum::<f64>() / pslg.segments.len() as f64;
    let h = opts.size.unwrap_or(mean);
    if !(h > 0.0 && h.is_finite()) {
        return Err(PlaneDeployError::Option("size", h));
    }
    if !(opts.resolution > 0.0 && opts.resolution.is_finite()) {
        return Err(PlaneDeployError::Option("resolution", opts.resolution));
    }
    // Node sizes: mean of the node's segments, capped by h.
    let mut sum = vec![0.0; pslg.points.len()];
    let mut cnt = vec![0u32; pslg.points.len()];
    for &s in &pslg.segments {
        for v in s {
            sum[v as usize] += len(s);
            cnt[v as usize] += 1;
        }
    }
    let size: Vec<f64> = (0..pslg.points.len())
        .map(|v| {
            if cnt[v] == 0 {
                h
            } else {
                (sum[v] / f64::from(cnt[v])).min(h)
            }
        })
        .collect();
    let min_size = size.iter().copied().fold(h, f64::min);
    let dx = dyadic_below(min_size / opts.resolution);
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &pslg.points {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let margin = 2.0;
    let dims_f = [0, 1].map(|a| (hi[a] / dx).ceil() - (lo[a] / dx).floor() + 2.0 * margin + 1.0);
    let pixels = dims_f[0] * dims_f[1];
    if pixels.is_nan() || pixels > opts.max_pixels as f64 {
        return Err(PlaneDeployError::TooLarge {
            pixels,
            dx,
            limit: opts.max_pixels,
        });
    }
    let dims = dims_f.map(|d| d as usize);
    let origin = [0, 1].map(|a| ((lo[a] / dx).floor() - margin) * dx);
    let mut t = Template::new([dims[0], dims[1], 1], [origin[0], origin[1], 0.0], dx);
    let mut stats = PlaneTemplateStats {
        dims,
        dx,
        size: h,
        boundary_nodes: pslg.points.len(),
        ..Default::default()
    };

    // 2. Inside pixels: rasterise the domain triangles, exactly.
    let segs = pslg.segment_set();
    for tv in &domain.triangles {
        let c = tv.map(|v| domain.points[v as usize]);
        // Edge i (opposite corner i) is strict when it is a segment.
        let strict = [0, 1, 2].map(|i| segs.contains(&edge_key(tv[(i + 1) % 3], tv[(i + 2) % 3])));
        let ymin = c.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        let ymax = c.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max);
        let j0 = (((ymin - origin[1]) / dx).floor() as i64).max(0) as usize;
        let j1 = (((ymax - origin[1]) / dx).ceil() as i64)
            .min(dims[1] as i64 - 1)
            .max(0) as usize;
        for j in j0..=j1 {
            let y = t.coord(1, j);
            // The row's x-range in floating point, widened; the exact test decides.
            let mut x0 = f64::INFINITY;
            let mut x1 = f64::NEG_INFINITY;
            for i in 0..3 {
                let (p, q) = (c[i], c[(i + 1) % 3]);
                if (p[1] - y) * (q[1] - y) <= 0.0 {
                    let x = if p[1] == q[1] {
                        x0 = x0.min(p[0].min(q[0]));
                        p[0].max(q[0])
                    } else {
                        p[0] + (y - p[1]) / (q[1] - p[1]) * (q[0] - p[0])
                    };
                    x0 = x0.min(x);
                    x1 = x1.max(x);
                }
            }
            if x0 > x1 {
                continue;
            }
            let i0 = (((x0 - origin[0]) / dx).floor() as i64 - 1).max(0) as usize;
            let i1 = (((x1 - origin[0]) / dx).ceil() as i64 + 1)
                .min(dims[0] as i64 - 1)
                .max(0) as usize;
            let row = t.index(0, j, 0);
            for i in i0..=i1 {
                let idx = row + i;
                if t.region(idx) != 0 {
                    continue;
                }
                let p = [t.coord(0, i), y];
                let inside = (0..3).all(|e| match orient2d(c[(e + 1) % 3], c[(e + 2) % 3], p) {
                    Sign::Positive => true,
                    Sign::Zero => !strict[e],
                    Sign::Negative => false,
                });
                if inside {
                    t.set_region_span(row, i, i + 1, 1);
                    stats.inside_pixels += 1;
                }
            }
        }
    }

    // 3. Boundary buffer.
    let radius = |s: f64| (s / dx).round().max(1.0) as usize;
    for (v, &p) in pslg.points.iter().enumerate() {
        let c = t.nearest([p[0], p[1], 0.0]);
        let idx = t.index(c[0], c[1], 0);
        t.set_state(idx, SURFACE_NODE);
        t.mark_zone(c, radius(size[v]), opts.zone);
    }
    // 4. Rectangle sealing of long segments (fig. 2.5).
    for &[a, b] in &pslg.segments {
        let (sa, sb) = (size[a as usize], size[b as usize]);
        let l = len([a, b]);
        if l <= (radius(sa) + radius(sb)) as f64 * dx {
            continue;
        }
        stats.sealed_segments += 1;
        let (pa, pb) = (pt(a), pt(b));
        let u = [(pb[0] - pa[0]) / l, (pb[1] - pa[1]) / l];
        let n = [-u[1], u[0]];
        let a0 = [pa[0] - sa * u[0], pa[1] - sa * u[1]];
        let b0 = [pb[0] + sb * u[0], pb[1] + sb * u[1]];
        let quad = [
            [a0[0] + sa * n[0], a0[1] + sa * n[1]],
            [a0[0] - sa * n[0], a0[1] - sa * n[1]],
            [b0[0] - sb * n[0], b0[1] - sb * n[1]],
            [b0[0] + sb * n[0], b0[1] + sb * n[1]],
        ];
        mark_convex(&mut t, &quad);
    }
    // 5. Inward sweep, with the graded size when asked.
    let r = radius(h);
    stats.interior_nodes = match opts.grading {
        Some(g) if g > 0.0 && g.is_finite() => {
            let seeds: Vec<([usize; 3], f64)> = pslg
                .points
                .iter()
                .zip(&size)
                .map(|(p, &s)| (t.nearest([p[0], p[1], 0.0]), s))
                .collect();
            let field = graded_field(&t, &seeds, h, g);
            let (nx, o, dx) = (t.n[0], t.origin, t.dx);
            let at = move |p: [f64; 3], _: u32| {
                let i = ((p[0] - o[0]) / dx).round() as usize;
                let j = ((p[1] - o[1]) / dx).round() as usize;
                radius(f64::from(field[i + nx * j]))
            };
            sweep(&mut t, opts.zone, &at)
        }
        _ => sweep(&mut t, opts.zone, &|_, _| r),
    };
    let mut nodes = Vec::with_capacity(stats.interior_nodes);
    for idx in 0..t.cells.len() {
        if t.state(idx) == INTERIOR_NODE {
            let p = t.point(t.ijk(idx));
            nodes.push([p[0], p[1]]);
        }
    }
    Ok(PlaneDeployment { nodes, stats })
}

/// Mark as buffer the unprocessed pixels inside a convex polygon (a sizing decision, so floating
/// point: being off by a pixel only moves a node by a pixel).
fn mark_convex(t: &mut Template, poly: &[[f64; 2]]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in poly {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let cell = |a: usize, x: f64, up: bool| {
        let f = (x - t.origin[a]) / t.dx;
        let f = if up { f.ceil() } else { f.floor() };
        (f.max(0.0) as usize).min(t.n[a] - 1)
    };
    let (i0, i1, j0, j1) = (
        cell(0, lo[0], false),
        cell(0, hi[0], true),
        cell(1, lo[1], false),
        cell(1, hi[1], true),
    );
    // Orientation of the polygon, to test "left of every edge".
    let area: f64 = (0..poly.len())
        .map(|k| {
            let (p, q) = (poly[k], poly[(k + 1) % poly.len()]);
            p[0] * q[1] - p[1] * q[0]
        })
        .sum();
    let s = area.signum();
    for j in j0..=j1 {
        for i in i0..=i1 {
            let p = [t.coord(0, i), t.coord(1, j)];
            let inside = (0..poly.len()).all(|k| {
                let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                s * ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])) >= 0.0
            });
            let idx = t.index(i, j, 0);
            if inside && t.state(idx) == UNPROCESSED {
                t.set_state(idx, BUFFER);
            }
        }
    }
}
