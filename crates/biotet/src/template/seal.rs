//! The boundary buffer: a zone around every surface node (section 2.3.1) and the scaled-prism
//! seal over triangles larger than their nodes' zones (eq. 2.7, fig. 2.7).
//!
//! Heights: a triangle's prism reaches `√(2/3)·d` from its plane, `d` interpolated from the sizes
//! at its corners: the height of a regular tet of edge `d`, so the first interior node above a
//! triangle makes a well-shaped tet with it. A triangle needs no prism when its longest edge is at
//! most the smallest of its corner sizes: then every point of it is within `d/√3` of a corner and
//! the corner zones alone keep nodes at least that same height away.
//!
//! A sealed triangle's smallest circumsphere is cleared too, unless the triangle is obtuse beyond
//! 150° or its circumradius exceeds [`BALL_MAX_SIZES`] sizes (then, for a boundary triangle up to
//! [`CAP_MAX_SIZES`], the flattest inner cap of a sphere through its corners that no other
//! surface point enters): no interior node then keeps it out of the Delaunay tetrahedralization, which is what keeps recovery linear when the size is finer than
//! the surface (brain_20k at `--size 1.0`: 6,132 missing triangles instead of 11,063, recovery
//! 2.9 s instead of 62 s).

use crate::geom::vec3::{add, cross, dot, norm, scale, sub};
use crate::mesh::surface::SurfaceMesh;
use crate::surface::grid::Grid;
use rayon::prelude::*;

use super::voxels::{BUFFER, SURFACE_NODE, Template, UNPROCESSED, Zone};

/// Ratio of a regular tet's height to its edge.
pub const HEIGHT_FACTOR: f64 = 0.816_496_580_927_726; // √(2/3)

/// Mark surface node voxels and their zones; `size[v]` is the desired size at surface point `v`
/// (0 for unreferenced points, which are skipped).
pub fn mark_surface_nodes(t: &mut Template, surface: &SurfaceMesh, size: &[f64], zone: Zone) {
    for (v, p) in surface.points.iter().enumerate() {
        if size[v] <= 0.0 {
            continue;
        }
        let c = t.nearest(*p);
        let idx = t.index(c[0], c[1], c[2]);
        t.set_state(idx, SURFACE_NODE);
        let r = (size[v] / t.dx).round().max(1.0) as usize;
        t.mark_zone(c, r, zone);
    }
}

/// A sealed triangle's circumsphere is cleared of interior nodes only when its radius is at
/// most this many times the smallest size at its corners.
pub const BALL_MAX_SIZES: f64 = 3.0;

/// A boundary triangle whose circumradius is above [`BALL_MAX_SIZES`] sizes but at most this
/// many has the inner cap of a larger sphere through its corners cleared instead of its ball
/// (see `cap_height`).
pub const CAP_MAX_SIZES: f64 = 32.0;

/// Triangles per wave of [`seal_triangles`], and per parallel piece of a wave: bounded memory
/// for the voxel lists, enough pieces to share.
const WAVE: usize = 4096;
const PIECE: usize = 128;

/// Seal every triangle larger than its nodes' zones with a scaled prism; returns how many.
///
/// The prisms' voxels are found on all threads against the template as it is, then marked:
/// sealing only turns unprocessed voxels into buffer, so the order does not matter and the
/// result is the same on any number of threads.
pub fn seal_triangles(t: &mut Template, surface: &SurfaceMesh, size: &[f64]) -> usize {
    let mut sealed = 0;
    // Built on first use: most surfaces have no triangle that needs a cap.
    let points = std::sync::OnceLock::new();
    let n_tri = surface.triangles.len();
    let ids: Vec<usize> = (0..n_tri).collect();
    for wave in ids.chunks(WAVE) {
        let found: Vec<(usize, Vec<usize>)> = wave
            .par_chunks(PIECE)
            .map(|piece| {
                let mut out = Vec::new();
                let n = piece
                    .iter()
                    .filter(|&&s| seal_one(t, surface, &points, size, s, &mut out))
                    .count();
                (n, out)
            })
            .collect();
        for (n, voxels) in found {
            sealed += n;
            for idx in voxels {
                if t.state(idx) == UNPROCESSED {
                    t.set_state(idx, BUFFER);
                }
            }
        }
    }
    sealed
}

/// The voxels of one triangle's prism (appended to `out`); false when it needs none.
fn seal_one(
    t: &Template,
    surface: &SurfaceMesh,
    points: &std::sync::OnceLock<Grid>,
    size: &[f64],
    s: usize,
    out: &mut Vec<usize>,
) -> bool {
    {
        let v = surface.triangles[s].map(|i| i as usize);
        let p = v.map(|i| surface.points[i]);
        let d = v.map(|i| size[i]);
        let edges = [
            norm(sub(p[1], p[2])),
            norm(sub(p[2], p[0])),
            norm(sub(p[0], p[1])),
        ];
        let longest = edges.iter().copied().fold(0.0, f64::max);
        if longest <= d.iter().copied().fold(f64::INFINITY, f64::min) {
            return false;
        }
        let nrm = cross(sub(p[1], p[0]), sub(p[2], p[0]));
        let len = norm(nrm);
        let per = edges[0] + edges[1] + edges[2];
        if len == 0.0 || per == 0.0 || !len.is_finite() {
            return false; // degenerate: validation rejects these before deployment
        }
        let n = scale(nrm, 1.0 / len);
        // Incentre, and the corners pushed away from it by their sizes (eq. 2.7).
        let o = scale(
            add(
                add(scale(p[0], edges[0]), scale(p[1], edges[1])),
                scale(p[2], edges[2]),
            ),
            1.0 / per,
        );
        let q = [0, 1, 2].map(|i| {
            let r = sub(p[i], o);
            let l = norm(r);
            add(o, scale(r, 1.0 + d[i] / l))
        });
        let h = d.map(|x| x * HEIGHT_FACTOR);
        prism_voxels(t, q, h, n, out);
        // Interior spacing finer than the triangle: nodes inside its smallest circumsphere keep
        // it out of the Delaunay, and recovery's cavities grow with the square of the ratio.
        // Clearing the sphere makes the triangle Gabriel against interior nodes. Larger
        // triangles on the boundary get the flattest cap that makes them Delaunay instead
        // (none on a convex part, where the prism is enough): the whole ball would empty the
        // interior. Skipped for obtuse
        // slivers (circumradius above the longest edge, an angle over 150°) and for triangles
        // far larger still (a CAD face), which recovery handles with few cavities.
        let dmin = d.iter().copied().fold(f64::INFINITY, f64::min);
        if let Some((c, r)) = circumsphere(p)
            && r <= longest
        {
            if r <= BALL_MAX_SIZES * dmin {
                ball_voxels(t, c, r, out);
            } else if r <= CAP_MAX_SIZES * dmin
                && let Some(inward) = inward_normal(surface.sides[s], n)
                && let Some(h) = cap_height(
                    surface,
                    points.get_or_init(|| point_grid(surface)),
                    s,
                    c,
                    r,
                    inward,
                    dmin * HEIGHT_FACTOR,
                )
            {
                cap_voxels(t, c, r, h, inward, out);
            }
        }
        true
    }
}

/// The smallest sphere through a triangle's corners: its circumcentre (in its plane) and
/// circumradius; `None` when degenerate.
fn circumsphere(p: [[f64; 3]; 3]) -> Option<([f64; 3], f64)> {
    let a = sub(p[1], p[0]);
    let b = sub(p[2], p[0]);
    let axb = cross(a, b);
    let den = 2.0 * dot(axb, axb);
    if den <= 0.0 || !den.is_finite() {
        return None;
    }
    // c - p0 = (|a|² (b × (a × b)) + |b|² ((a × b) × a)) / (2 |a × b|²)
    let r = scale(
        add(
            scale(cross(b, axb), dot(a, a)),
            scale(cross(axb, a), dot(b, b)),
        ),
        1.0 / den,
    );
    Some((add(p[0], r), norm(r)))
}

/// The unprocessed voxels in the box `lo..hi` whose centre passes `keep` (appended to `out`),
/// for a `keep` that implies `parts(x)[m] >= 0` for every `m`, each part an affine
/// function of `x`, and, with `sphere = Some((c, r2))`, `|x - c|² < r2`: along each row of the
/// box the parts' roots and the sphere's chord bound the voxels worth testing, so a long thin
/// shape turned across the grid costs its own voxels, not its bounding box's (a turned
/// capsule's side triangles have caps and prisms whose boxes span most of its 6.2M voxels).
/// Conservative: the range is widened by two voxels past each root, a part nearly constant along
/// the row (its root not known to within a voxel) does not clip, and a row leaves the sphere only
/// by a margin far above round-off; `keep` decides every voxel in the range, so the voxels found
/// are those of the whole box's scan, in the same order. Each row is also clipped to its inside
/// span ([`Template::inside_rows`]; only inside voxels become nodes): a turned capsule's balls
/// and prisms reach far outside it (its buffer 0.16 s → 0.05 s, the nodes the same).
fn box_voxels_clipped<const M: usize>(
    t: &Template,
    lo: [f64; 3],
    hi: [f64; 3],
    parts: impl Fn([f64; 3]) -> [f64; M],
    sphere: Option<([f64; 3], f64)>,
    keep: impl Fn([f64; 3]) -> bool,
    out: &mut Vec<usize>,
) {
    let inv = 1.0 / t.dx;
    let span = |a: usize| {
        let l = ((lo[a] - t.origin[a]) * inv).ceil().max(0.0) as usize;
        let h = ((hi[a] - t.origin[a]) * inv).floor();
        (l, (h >= 0.0).then(|| (h as usize).min(t.n[a] - 1)))
    };
    let ((i0, Some(i1)), (j0, Some(j1)), (k0, Some(k1))) = (span(0), span(1), span(2)) else {
        return;
    };
    // Short rows are scanned whole: clipping them costs more than it saves (brain_20k's
    // prisms and balls span a few voxels).
    let clip = i1 >= i0 + SHORT_ROW;
    for k in k0..=k1 {
        for j in j0..=j1 {
            let row = t.index(0, j, k);
            // Only inside voxels become nodes: the rest of the row need not be marked.
            let inside = t.inside_rows[j + t.n[1] * k];
            if inside[0] > inside[1] || (inside[1] as usize) < i0 || inside[0] as usize > i1 {
                continue;
            }
            let (mut a, mut b) = if M == 0 || !clip {
                (i0, i1)
            } else {
                row_range(
                    &parts(t.point([i0, j, k])),
                    &parts(t.point([i1, j, k])),
                    i0,
                    i1,
                )
            };
            if let Some((c, r2)) = sphere.filter(|_| clip) {
                let y = t.point([i0, j, k]);
                let d = r2 - (y[1] - c[1]).powi(2) - (y[2] - c[2]).powi(2);
                if d < -1e-9 * r2 {
                    continue;
                }
                let w = d.max(0.0).sqrt();
                let from = ((c[0] - w - t.origin[0]) * inv).floor() - 2.0;
                let to = ((c[0] + w - t.origin[0]) * inv).ceil() + 2.0;
                if to < a as f64 || from > b as f64 {
                    continue;
                }
                a = a.max(from.max(0.0) as usize);
                b = b.min(to as usize);
            }
            let (a, b) = (a.max(inside[0] as usize), b.min(inside[1] as usize));
            for i in a..=b.min(i1) {
                let idx = row + i;
                if t.state(idx) == UNPROCESSED && keep(t.point([i, j, k])) {
                    out.push(idx);
                }
            }
        }
    }
}

/// Rows of fewer voxels than this are not clipped by [`box_voxels_clipped`].
const SHORT_ROW: usize = 32;

/// The voxels `a..=b` of the row `i0..=i1` where every part, affine along the row with the values
/// `p0` at `i0` and `p1` at `i1`, can be non-negative (see [`box_voxels_clipped`]); empty as
/// `a > b`.
fn row_range<const M: usize>(p0: &[f64; M], p1: &[f64; M], i0: usize, i1: usize) -> (usize, usize) {
    let n = (i1 - i0) as f64;
    let (mut a, mut b) = (i0 as f64, i1 as f64);
    for m in 0..M {
        let (g0, g1) = (p0[m], p1[m]);
        if !(g0.is_finite() && g1.is_finite()) {
            continue;
        }
        let slope = (g1 - g0) / n;
        // The values' round-off is about 1e-16 of their size: clip only where a voxel's step is
        // far larger, so the root is known to well within the two voxels' margin.
        let size = g0.abs().max(g1.abs());
        if slope.abs() <= 1e-9 * size {
            continue;
        }
        let root = i0 as f64 - g0 / slope;
        if slope > 0.0 {
            a = a.max(root.floor() - 2.0);
        } else {
            b = b.min(root.ceil() + 2.0);
        }
    }
    if a > b {
        return (1, 0);
    }
    (a.max(i0 as f64) as usize, b.min(i1 as f64) as usize)
}

/// The unprocessed voxels strictly inside the ball of centre `c` and radius `r` (appended to
/// `out`).
fn ball_voxels(t: &Template, c: [f64; 3], r: f64, out: &mut Vec<usize>) {
    let r2 = r * r;
    box_voxels_clipped(
        t,
        c.map(|x| x - r),
        c.map(|x| x + r),
        |_| [0.0; 0],
        Some((c, r2)),
        |x| {
            let d = sub(x, c);
            dot(d, d) < r2
        },
        out,
    );
}

/// The unit normal pointing into the meshed side of a triangle whose other side is the outside
/// (label 0); `None` for an interface (both sides meshed).
fn inward_normal(sides: [u32; 2], n: [f64; 3]) -> Option<[f64; 3]> {
    match sides {
        [b, 0] if b != 0 => Some(scale(n, -1.0)),
        [0, f] if f != 0 => Some(n),
        _ => None,
    }
}

/// The surface's points in a hashed grid of cells about twice its mean edge length (each point
/// listed as a triangle with three equal corners).
fn point_grid(surface: &SurfaceMesh) -> Grid {
    let mut sum = 0.0;
    for tri in &surface.triangles {
        let p = tri.map(|i| surface.points[i as usize]);
        sum += norm(sub(p[1], p[0])) + norm(sub(p[2], p[1])) + norm(sub(p[0], p[2]));
    }
    let mean = sum / (3 * surface.triangles.len()).max(1) as f64;
    let mut g = Grid::new(if mean > 0.0 && mean.is_finite() {
        2.0 * mean
    } else {
        1.0
    });
    for (i, p) in surface.points.iter().enumerate() {
        g.insert(i as u32, &[*p; 3]);
    }
    g
}

/// The height, on the side `inward`, of the smallest cap to clear over boundary triangle `s`
/// (circumcentre `c`, circumradius `r`) so that a sphere through its corners holds no other
/// surface point, or `None` when its prism (height `prism`) is enough or no such sphere exists.
///
/// The spheres through the corners have centres `c − t·inward`, radius² `r² + t²`. A point `q`
/// with `a = |q − c|² − r²` and `b = (q − c)·inward` is inside for `a + 2tb < 0`: points behind
/// the plane bound `t` from above, points in front inside the smallest sphere from below. The
/// largest allowed `t` (the flattest cap, searched up to a cap of about r/8) is taken, slightly
/// less so the point that bounds it stays outside. Floating point: this only chooses voxels.
fn cap_height(
    surface: &SurfaceMesh,
    points: &Grid,
    s: usize,
    c: [f64; 3],
    r: f64,
    inward: [f64; 3],
    prism: f64,
) -> Option<f64> {
    let h0 = prism.max(r / 8.0).min(r);
    let far = (r * r - h0 * h0) / (2.0 * h0);
    let big = (r * r + far * far).sqrt();
    let centre = add(c, scale(inward, -far));
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    for k in 0..3 {
        lo[k] = (centre[k] - big).min(c[k] - r);
        hi[k] = (centre[k] + big).max(c[k] + r);
    }
    let mut near = Vec::new();
    points.query(lo, hi, &mut near);
    let corners = surface.triangles[s];
    let (mut t_lo, mut t_hi) = (0.0f64, far);
    for &i in &near {
        if corners.contains(&i) {
            continue;
        }
        let d = sub(surface.points[i as usize], c);
        let (a, b) = (dot(d, d) - r * r, dot(d, inward));
        if b < 0.0 {
            if a <= 0.0 {
                return None;
            }
            t_hi = t_hi.min(a / (-2.0 * b));
        } else if b > 0.0 {
            if a < 0.0 {
                t_lo = t_lo.max(-a / (2.0 * b));
            }
        } else if a < 0.0 {
            return None;
        }
    }
    if t_hi <= t_lo {
        return None;
    }
    let t = if t_hi < far {
        (0.99 * t_hi).max(0.5 * (t_lo + t_hi))
    } else {
        far
    };
    let h = (r * r + t * t).sqrt() - t;
    (h > prism).then_some(h)
}

/// The unprocessed voxels strictly inside the cap, of height `h` on the side `inward`, of the
/// sphere through the triangle's corners whose centre lies on the other side (circumcentre `c`,
/// circumradius `r > h`): with that cap empty, the triangle is a Delaunay face unless a surface
/// point lies in the sphere's outer part.
fn cap_voxels(t: &Template, c: [f64; 3], r: f64, h: f64, inward: [f64; 3], out: &mut Vec<usize>) {
    // Centre at distance d behind the plane, radius R: R − d = h and R² = r² + d².
    let d = (r * r - h * h) / (2.0 * h);
    let big = d + h;
    let centre = add(c, scale(inward, -d));
    let top = add(c, scale(inward, h));
    let lo = [0, 1, 2].map(|a| c[a].min(top[a]) - r);
    let hi = [0, 1, 2].map(|a| c[a].max(top[a]) + r);
    let big2 = big * big;
    box_voxels_clipped(
        t,
        lo,
        hi,
        |x| [dot(sub(x, c), inward)],
        Some((centre, big2)),
        |x| {
            let e = sub(x, centre);
            dot(sub(x, c), inward) > 0.0 && dot(e, e) < big2
        },
        out,
    );
}

/// The unprocessed voxels strictly inside the prism over triangle `q` (mid-plane) with normal
/// `n` and half-height `h[i]` at corner `i`, interpolated linearly (appended to `out`).
fn prism_voxels(t: &Template, q: [[f64; 3]; 3], h: [f64; 3], n: [f64; 3], out: &mut Vec<usize>) {
    let hmax = h.iter().copied().fold(0.0, f64::max);
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for c in &q {
        for a in 0..3 {
            let e = hmax * n[a].abs();
            lo[a] = lo[a].min(c[a] - e);
            hi[a] = hi[a].max(c[a] + e);
        }
    }
    let Some(parts) = prism_parts(q, h, n) else {
        return;
    };
    box_voxels_clipped(t, lo, hi, &parts, None, |x| inside_prism(parts(x)), out);
}

/// The prism's five affine parts at `x` (see [`box_voxels_clipped`]): its barycentric coordinates
/// in the mid-plane (solved with the 2×2 Gram system of two edges) and the half-height there
/// less and plus the signed distance to the plane; `None` for a degenerate triangle.
fn prism_parts(
    q: [[f64; 3]; 3],
    h: [f64; 3],
    n: [f64; 3],
) -> Option<impl Fn([f64; 3]) -> [f64; 5]> {
    let e1 = sub(q[1], q[0]);
    let e2 = sub(q[2], q[0]);
    let (a11, a12, a22) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
    let det = a11 * a22 - a12 * a12;
    if det <= 0.0 || !det.is_finite() {
        return None;
    }
    let inv_det = 1.0 / det;
    Some(move |x: [f64; 3]| {
        let r = sub(x, q[0]);
        let dist = dot(r, n);
        let (b1, b2) = (dot(r, e1), dot(r, e2));
        let l1 = (a22 * b1 - a12 * b2) * inv_det;
        let l2 = (a11 * b2 - a12 * b1) * inv_det;
        let l0 = 1.0 - l1 - l2;
        let rhs = l0 * h[0] + l1 * h[1] + l2 * h[2];
        [l0, l1, l2, rhs - dist, rhs + dist]
    })
}

/// Whether [`prism_parts`] place a point strictly inside the prism: barycentric coordinates
/// non-negative and |distance| below the half-height (`rhs - dist > 0` is `dist < rhs` exactly
/// in floating point).
fn inside_prism(p: [f64; 5]) -> bool {
    p[0] >= 0.0 && p[1] >= 0.0 && p[2] >= 0.0 && p[3] > 0.0 && p[4] > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SplitMix64 in [0, 1): reproducible without a dependency.
    fn rand(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The inside voxels of the whole test grid that pass `keep`, scanned one by one in index
    /// order.
    fn whole_box(t: &Template, keep: impl Fn([f64; 3]) -> bool) -> Vec<usize> {
        (0..t.cells.len())
            .filter(|&idx| {
                t.region(idx) != 0 && t.state(idx) == UNPROCESSED && keep(t.point(t.ijk(idx)))
            })
            .collect()
    }

    /// Row clipping only skips voxels `keep` refuses: on long thin prisms, balls and caps turned
    /// every way across the grid, the clipped scans find exactly the voxels of a whole-box scan,
    /// in the same order.
    #[test]
    fn clipped_scans_find_the_voxels_of_the_whole_box() {
        let mut t = Template::new([96, 80, 72], [-1.0, -0.5, -0.75], 1.0 / 32.0);
        // Everything inside: the shapes' own clipping alone.
        for row in (0..t.cells.len()).step_by(t.n[0]) {
            t.set_region_span(row, 0, t.n[0], 1);
        }
        clipped_scans_match(t);
    }

    /// The scans find exactly the inside voxels of a whole-box scan: here the inside is a ball
    /// that most of the shapes cross, and rows miss it whole.
    #[test]
    fn clipped_scans_keep_to_the_inside_rows() {
        let mut t = Template::new([96, 80, 72], [-1.0, -0.5, -0.75], 1.0 / 32.0);
        let (c, r) = ([0.4, 0.6, 0.5], 0.7);
        for k in 0..t.n[2] {
            for j in 0..t.n[1] {
                let row = t.index(0, j, k);
                let y = t.point([0, j, k]);
                let d = r * r - (y[1] - c[1]).powi(2) - (y[2] - c[2]).powi(2);
                if d <= 0.0 {
                    continue;
                }
                let inside = |i: usize| (t.coord(0, i) - c[0]).abs() < d.sqrt();
                let lo = (0..t.n[0]).find(|&i| inside(i));
                let hi = (0..t.n[0]).rev().find(|&i| inside(i));
                if let (Some(lo), Some(hi)) = (lo, hi) {
                    t.set_region_span(row, lo, hi + 1, 1);
                }
            }
        }
        assert!(t.inside_rows.iter().any(|r| r[0] > r[1]));
        assert!(t.inside_rows.iter().any(|r| r[0] <= r[1]));
        clipped_scans_match(t);
    }

    fn clipped_scans_match(t: Template) {
        let mut s = 7u64;
        let mut p = || [0, 1, 2].map(|_| rand(&mut s) * 2.0 - 0.5);
        let mut nonempty = 0;
        for _ in 0..60 {
            let q = [p(), p(), p()];
            let n = cross(sub(q[1], q[0]), sub(q[2], q[0]));
            let len = norm(n);
            if len == 0.0 {
                continue;
            }
            let n = scale(n, 1.0 / len);
            let mut clipped = Vec::new();
            prism_voxels(&t, q, [0.05, 0.02, 0.1], n, &mut clipped);
            // The same prism through the whole box, unclipped.
            let parts = prism_parts(q, [0.05, 0.02, 0.1], n).unwrap();
            let whole = whole_box(&t, |x| inside_prism(parts(x)));
            assert_eq!(clipped, whole, "prism {q:?}");
            nonempty += !whole.is_empty() as usize;
            // A ball and a cap through the same corners.
            let (c, r) = (q[0], norm(sub(q[1], q[0])).min(1.0));
            let mut clipped = Vec::new();
            ball_voxels(&t, c, r, &mut clipped);
            let whole = whole_box(&t, |x| dot(sub(x, c), sub(x, c)) < r * r);
            assert_eq!(clipped, whole, "ball {c:?} {r}");
            let h = 0.1 * r;
            let d = (r * r - h * h) / (2.0 * h);
            let centre = add(c, scale(n, -d));
            let big2 = (d + h) * (d + h);
            let mut clipped = Vec::new();
            cap_voxels(&t, c, r, h, n, &mut clipped);
            let mut whole = whole_box(&t, |x| {
                let e = sub(x, centre);
                dot(sub(x, c), n) > 0.0 && dot(e, e) < big2
            });
            let lo = [0, 1, 2].map(|a| c[a].min(c[a] + h * n[a]) - r);
            let hi = [0, 1, 2].map(|a| c[a].max(c[a] + h * n[a]) + r);
            // The cap's own box is smaller than [-2, 3]³: compare within its voxel span.
            let inv = 1.0 / t.dx;
            let span = |a: usize| {
                let l = ((lo[a] - t.origin[a]) * inv).ceil().max(0.0) as usize;
                let h = ((hi[a] - t.origin[a]) * inv).floor().max(-1.0);
                (l, h)
            };
            whole.retain(|&idx| {
                let ijk = t.ijk(idx);
                (0..3).all(|a| {
                    let (l, h) = span(a);
                    ijk[a] >= l && (ijk[a] as f64) <= h
                })
            });
            assert_eq!(clipped, whole, "cap {c:?} {r}");
        }
        assert!(nonempty > 40, "{nonempty} prisms met the grid");
    }
}
