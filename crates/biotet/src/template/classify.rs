//! Inside or outside for every voxel: exact ray parity along the template's x lines (section
//! 2.3.1, Lemma 1), with the symbolic perturbation of [`crate::mesh::inside`] in place of the
//! seed's random one.
//!
//! Each triangle is rasterised over the lattice rows `(y_j, z_k)` its projection covers. For a
//! pierced row, the first voxel beyond the crossing is found from a float estimate corrected by
//! exact `orient3d` signs (the sign is monotone along the row), and a voxel whose centre lies on
//! the triangle is recorded as on the surface. Rows are then swept once, regions changing at the
//! crossings, so the cost is one pass over the voxels plus the crossings.

use crate::geom::predicates::Sign;
use crate::mesh::inside::{
    Transitions, crossing_regions, in_box, is_after, line_meets_closed, on_triangle,
    projected_sign, ray_pierces,
};
use crate::mesh::surface::SurfaceMesh;

use super::voxels::{BUFFER, Template};

/// Counts from the classification.
#[derive(Debug, Clone, Copy, Default)]
pub struct Classified {
    /// Ray crossings recorded.
    pub crossings: usize,
    /// Voxel centres exactly on the surface.
    pub on_surface: usize,
}

struct Crossing {
    row: u32,
    first_after: u32,
    from: u32,
    to: u32,
}

/// Set the region bits of every voxel; voxels exactly on the surface become buffer.
pub fn classify(t: &mut Template, surface: &SurfaceMesh) -> Classified {
    let [nx, ny, nz] = t.n;
    let mut crossings: Vec<Crossing> = Vec::new();
    let mut on_surface: Vec<usize> = Vec::new();
    let inv = 1.0 / t.dx;
    for (ti, tri) in surface.triangles.iter().enumerate() {
        let c = [
            surface.points[tri[0] as usize],
            surface.points[tri[1] as usize],
            surface.points[tri[2] as usize],
        ];
        let s = projected_sign(&c);
        // Lattice rows whose (y, z) may lie in the projection; one row of slack each way, the
        // exact test decides.
        let range = |a: usize, n: usize| {
            let lo = c.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min);
            let hi = c.iter().map(|p| p[a]).fold(f64::NEG_INFINITY, f64::max);
            let l = ((lo - t.origin[a]) * inv).floor() - 1.0;
            let h = ((hi - t.origin[a]) * inv).ceil() + 1.0;
            (l.max(0.0) as usize, (h.max(-1.0) as i64).min(n as i64 - 1))
        };
        let (j0, j1) = range(1, ny);
        let (k0, k1) = range(2, nz);
        if s == Sign::Zero {
            // Parallel to x: never pierced by the perturbed rays, but voxel centres may lie on
            // it.
            let (i0, i1) = range(0, nx);
            for k in k0 as i64..=k1 {
                for j in j0 as i64..=j1 {
                    for i in i0 as i64..=i1 {
                        let (i, j, k) = (i as usize, j as usize, k as usize);
                        let p = t.point([i, j, k]);
                        if in_box(&c, p) && on_triangle(&c, p) {
                            on_surface.push(t.index(i, j, k));
                        }
                    }
                }
            }
            continue;
        }
        let (from, to) = crossing_regions(surface.sides[ti], s);
        let n = crate::geom::vec3::cross(
            crate::geom::vec3::sub(c[1], c[0]),
            crate::geom::vec3::sub(c[2], c[0]),
        );
        for k in k0 as i64..=k1 {
            let k = k as usize;
            let z = t.coord(2, k);
            for j in j0 as i64..=j1 {
                let j = j as usize;
                let y = t.coord(1, j);
                // Rows meeting the closed triangle may hold a voxel centre on it; only rows the
                // perturbed ray pierces count a crossing.
                if !line_meets_closed(&c, s, [0.0, y, z]) {
                    continue;
                }
                let pierced = ray_pierces(&c, s, [0.0, y, z]);
                // Estimate where the row meets the plane, then correct exactly.
                let xc = c[0][0] - (n[1] * (y - c[0][1]) + n[2] * (z - c[0][2])) / n[0];
                let est = ((xc - t.origin[0]) * inv).ceil();
                let mut i = if est.is_finite() {
                    est.clamp(0.0, nx as f64) as usize
                } else {
                    0
                };
                let after = |i: usize| is_after(&c, s, [t.coord(0, i), y, z]);
                // The signed volume is monotone along the row: step back while the previous
                // voxel is already beyond, then forward to the first voxel beyond.
                while i > 0 && after(i - 1) == Some(true) {
                    i -= 1;
                }
                while i < nx {
                    match after(i) {
                        Some(true) => break,
                        Some(false) => i += 1,
                        None => {
                            on_surface.push(t.index(i, j, k));
                            i += 1;
                        }
                    }
                }
                if !pierced {
                    continue;
                }
                crossings.push(Crossing {
                    row: (j + ny * k) as u32,
                    first_after: i as u32,
                    from,
                    to,
                });
            }
        }
    }
    let n_crossings = crossings.len();
    crossings.sort_unstable_by_key(|c| ((c.row as u64) << 32) | c.first_after as u64);
    let mut tr = Transitions::default();
    let mut g = 0;
    while g < crossings.len() {
        let row = crossings[g].row as usize;
        let row_start = row * nx;
        let mut region = 0u32;
        let mut at = 0usize;
        while g < crossings.len() && crossings[g].row as usize == row {
            let first = crossings[g].first_after as usize;
            if region != 0 && first > at {
                t.set_region_span(row_start, at, first, region);
            }
            tr.clear();
            while g < crossings.len()
                && crossings[g].row as usize == row
                && crossings[g].first_after as usize == first
            {
                tr.cross(crossings[g].from, crossings[g].to);
                g += 1;
            }
            region = tr.last(region);
            at = first;
        }
        if region != 0 && at < nx {
            // A closed surface leaves every row outside; an open one would not, and the rest of
            // the row keeps the last region (validation rejects open surfaces before this).
            t.set_region_span(row_start, at, nx, region);
        }
    }
    on_surface.sort_unstable();
    on_surface.dedup();
    for &v in &on_surface {
        t.set_state(v, BUFFER);
    }
    Classified {
        crossings: n_crossings,
        on_surface: on_surface.len(),
    }
}
