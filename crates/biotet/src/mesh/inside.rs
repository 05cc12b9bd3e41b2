//! Which region of a surface contains a point: exact ray casting along +x (dissertation section
//! 2.3.1, Lemma 1), with a symbolic perturbation instead of the seed's random one.
//!
//! The ray from `p` towards +x is moved, symbolically, to start at `(p.x, p.y + ε, p.z + ε²)`.
//! It then never passes through a vertex or along an edge, so every triangle is either crossed in
//! its interior or missed, and the answer is consistent for all triangles at once: rays through
//! vertices and along edges of the input are counted exactly once per sheet of surface.
//! Triangles parallel to the ray (their projection on the yz plane has zero area) are never
//! crossed by the perturbed ray.
//!
//! The crossing of triangle `abc` lies beyond `p` when `p` is behind the triangle's plane as seen
//! along the ray, an exact `orient3d` sign; zero means `p` is on the triangle itself.
//!
//! The region in front of the last crossing is the region containing `p`. Crossings are not sorted
//! (their exact order would need a higher-degree predicate): on a valid surface, the crossings of
//! a ray chain region to region, so the last region is the one entered more often than left (or
//! the starting region when all balance), which needs counts only.

use crate::geom::filter::orient3d;
use crate::geom::intersect::{drop_axis, point_in_triangle_2d, projection_axis};
use crate::geom::predicates::{Sign, orient2d};
use crate::mesh::surface::SurfaceMesh;

/// Where a point lies relative to a surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// Strictly inside the region with this label (0 = outside every region).
    Region(u32),
    /// Exactly on a triangle of the surface.
    OnSurface,
}

/// Sign of `orient2d(a, b, q)` in the yz plane for `q` perturbed to `(q.y + ε, q.z + ε²)`.
///
/// Antisymmetric in `a, b`, so the perturbed point is on one consistent side of every edge.
#[inline]
pub fn orient_yz_perturbed(a: [f64; 3], b: [f64; 3], q: [f64; 3]) -> Sign {
    let s = orient2d([a[1], a[2]], [b[1], b[2]], [q[1], q[2]]);
    if s != Sign::Zero {
        return s;
    }
    // d/dε of (b−a)×(q−a) is −(b.z − a.z); of ε² it is (b.y − a.y). Both are exact differences'
    // signs, decided by comparison without rounding.
    if a[2] != b[2] {
        return if a[2] > b[2] {
            Sign::Positive
        } else {
            Sign::Negative
        };
    }
    if a[1] != b[1] {
        return if b[1] > a[1] {
            Sign::Positive
        } else {
            Sign::Negative
        };
    }
    Sign::Zero
}

/// Orientation of triangle `t` projected on the yz plane: the sign of its normal's x component.
#[inline]
pub fn projected_sign(t: &[[f64; 3]; 3]) -> Sign {
    orient2d([t[0][1], t[0][2]], [t[1][1], t[1][2]], [t[2][1], t[2][2]])
}

/// Whether the perturbed ray through `q` (any x) pierces triangle `t`, whose projected
/// orientation is `s` (non-zero).
#[inline]
pub fn ray_pierces(t: &[[f64; 3]; 3], s: Sign, q: [f64; 3]) -> bool {
    orient_yz_perturbed(t[0], t[1], q) == s
        && orient_yz_perturbed(t[1], t[2], q) == s
        && orient_yz_perturbed(t[2], t[0], q) == s
}

/// Whether the (y, z) of `q`, unperturbed, lies in the closed projection of triangle `t` whose
/// projected sign is `s` (non-zero): the x line through `q` meets the closed triangle.
#[inline]
pub fn line_meets_closed(t: &[[f64; 3]; 3], s: Sign, q: [f64; 3]) -> bool {
    let bad = s.flip();
    let yz = |p: [f64; 3]| [p[1], p[2]];
    orient2d(yz(t[0]), yz(t[1]), yz(q)) != bad
        && orient2d(yz(t[1]), yz(t[2]), yz(q)) != bad
        && orient2d(yz(t[2]), yz(t[0]), yz(q)) != bad
}

/// Whether `p` lies on the closed triangle `t` (exact; false for a degenerate triangle).
pub fn on_triangle(t: &[[f64; 3]; 3], p: [f64; 3]) -> bool {
    if orient3d(t[0], t[1], t[2], p) != Sign::Zero {
        return false;
    }
    match projection_axis(t) {
        None => false,
        Some(k) => point_in_triangle_2d(drop_axis(p, k), &t.map(|q| drop_axis(q, k))),
    }
}

/// Whether `p` lies in the closed axis-aligned box of `t` (exact comparisons).
#[inline]
pub fn in_box(t: &[[f64; 3]; 3], p: [f64; 3]) -> bool {
    (0..3).all(|a| {
        let lo = t[0][a].min(t[1][a]).min(t[2][a]);
        let hi = t[0][a].max(t[1][a]).max(t[2][a]);
        lo <= p[a] && p[a] <= hi
    })
}

/// Whether `p` lies beyond (after, along +x) the plane of a triangle with projected sign `s`:
/// `Some(true)` when the ray has crossed it before reaching `p`, `None` when `p` is on the plane.
#[inline]
pub fn is_after(t: &[[f64; 3]; 3], s: Sign, p: [f64; 3]) -> Option<bool> {
    // orient3d(a, b, c, p) > 0 puts p in front of the triangle (the side its normal points to);
    // moving along +x with normal.x > 0 (s positive) the ray goes from back to front.
    match orient3d(t[0], t[1], t[2], p) {
        Sign::Zero => None,
        o => Some(o == s),
    }
}

/// Tally of region transitions along a ray, giving the last region without sorting crossings.
#[derive(Debug, Default, Clone)]
pub struct Transitions {
    /// `(region, entered − left)` for each region touched.
    balance: Vec<(u32, i32)>,
}

impl Transitions {
    /// Forget all crossings.
    #[inline]
    pub fn clear(&mut self) {
        self.balance.clear();
    }

    fn add(&mut self, region: u32, d: i32) {
        match self.balance.iter_mut().find(|(r, _)| *r == region) {
            Some(e) => e.1 += d,
            None => self.balance.push((region, d)),
        }
    }

    /// Record a crossing from region `from` into region `to`.
    #[inline]
    pub fn cross(&mut self, from: u32, to: u32) {
        if from != to {
            self.add(from, -1);
            self.add(to, 1);
        }
    }

    /// The region after all crossings recorded, starting in `start`.
    pub fn last(&self, start: u32) -> u32 {
        self.balance
            .iter()
            .filter(|&&(_, b)| b > 0)
            .map(|&(r, _)| r)
            .next()
            .unwrap_or(start)
    }
}

/// Region transition of a crossing: `(from, to)` for a ray along +x through a triangle with sides
/// `[back, front]` and projected sign `s`.
#[inline]
pub fn crossing_regions(sides: [u32; 2], s: Sign) -> (u32, u32) {
    if s == Sign::Positive {
        (sides[0], sides[1])
    } else {
        (sides[1], sides[0])
    }
}

/// Answers "which region contains this point" for many points against one surface.
///
/// Triangles are bucketed by their yz bounding box on a uniform grid, so a query tests only the
/// triangles whose box covers the query's (y, z).
pub struct RegionLocator<'a> {
    surface: &'a SurfaceMesh,
    /// Projected sign per triangle (zero for triangles parallel to x, which are never crossed).
    signs: Vec<Sign>,
    lo: [f64; 2],
    inv_cell: [f64; 2],
    n: [usize; 2],
    starts: Vec<u32>,
    items: Vec<u32>,
}

impl<'a> RegionLocator<'a> {
    /// Index the surface. The surface should be valid (closed regions, consistent sides).
    pub fn new(surface: &'a SurfaceMesh) -> RegionLocator<'a> {
        let nt = surface.triangles.len();
        let signs: Vec<Sign> = (0..nt)
            .map(|t| projected_sign(&surface.corners(t)))
            .collect();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in &surface.points {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a + 1]);
                hi[a] = hi[a].max(p[a + 1]);
            }
        }
        // About two triangles per cell along a side: cells of the mean triangle size.
        let side = ((nt.max(1) as f64) / 2.0).sqrt().clamp(1.0, 4096.0);
        let mut n = [1usize; 2];
        let mut inv_cell = [0.0; 2];
        for a in 0..2 {
            let ext = hi[a] - lo[a];
            if ext > 0.0 && ext.is_finite() {
                n[a] = side as usize;
                inv_cell[a] = n[a] as f64 / ext;
            }
        }
        let cell_range = |t: usize| {
            let c = surface.corners(t);
            let mut r = [[usize::MAX, 0usize]; 2];
            for a in 0..2 {
                for p in &c {
                    let k = ((p[a + 1] - lo[a]) * inv_cell[a]) as usize;
                    let k = k.min(n[a] - 1);
                    r[a][0] = r[a][0].min(k);
                    r[a][1] = r[a][1].max(k);
                }
            }
            r
        };
        let mut counts = vec![0u32; n[0] * n[1] + 1];
        // Triangles parallel to x are bucketed too: never crossed, but a point can lie on them.
        for t in 0..nt {
            let r = cell_range(t);
            for k in r[1][0]..=r[1][1] {
                for j in r[0][0]..=r[0][1] {
                    counts[j + n[0] * k + 1] += 1;
                }
            }
        }
        for i in 1..counts.len() {
            counts[i] += counts[i - 1];
        }
        let mut items = vec![0u32; counts[counts.len() - 1] as usize];
        let mut fill = counts.clone();
        for t in 0..nt {
            let r = cell_range(t);
            for k in r[1][0]..=r[1][1] {
                for j in r[0][0]..=r[0][1] {
                    let c = j + n[0] * k;
                    items[fill[c] as usize] = t as u32;
                    fill[c] += 1;
                }
            }
        }
        RegionLocator {
            surface,
            signs,
            lo,
            inv_cell,
            n,
            starts: counts,
            items,
        }
    }

    /// The region containing `p`, or [`Location::OnSurface`]. Exact for the given coordinates.
    pub fn locate(&self, p: [f64; 3]) -> Location {
        let mut tr = Transitions::default();
        self.locate_with(p, &mut tr)
    }

    /// [`locate`](Self::locate) reusing a scratch tally.
    pub fn locate_with(&self, p: [f64; 3], tr: &mut Transitions) -> Location {
        tr.clear();
        let mut cell = [0usize; 2];
        for a in 0..2 {
            let f = (p[a + 1] - self.lo[a]) * self.inv_cell[a];
            // Outside the surface's yz box the ray meets nothing; the perturbation cannot reach
            // a triangle more than a cell away, and boxes cover their triangles exactly.
            if !(f >= -1.0 && f <= self.n[a] as f64 + 1.0) {
                return Location::Region(0);
            }
            cell[a] = (f.max(0.0) as usize).min(self.n[a] - 1);
        }
        let c = cell[0] + self.n[0] * cell[1];
        for &t in &self.items[self.starts[c] as usize..self.starts[c + 1] as usize] {
            let t = t as usize;
            let s = self.signs[t];
            let corners = self.surface.corners(t);
            if s == Sign::Zero {
                if in_box(&corners, p) && on_triangle(&corners, p) {
                    return Location::OnSurface;
                }
                continue;
            }
            if !line_meets_closed(&corners, s, p) {
                continue;
            }
            // p's x line meets the closed triangle: p is on it exactly when on its plane.
            let Some(after) = is_after(&corners, s, p) else {
                return Location::OnSurface;
            };
            if after && ray_pierces(&corners, s, p) {
                let (from, to) = crossing_regions(self.surface.sides[t], s);
                tr.cross(from, to);
            }
        }
        Location::Region(tr.last(0))
    }
}

/// Region of a tet (corners `c`) by its centroid; if the centroid lies exactly on the surface,
/// other interior points of the tet decide.
pub fn centroid_region(
    c: [[f64; 3]; 4],
    locator: &RegionLocator,
    scratch: &mut Transitions,
) -> u32 {
    for w in [
        [1.0, 1.0, 1.0, 1.0],
        [2.0, 1.0, 1.0, 1.0],
        [1.0, 2.0, 1.0, 1.0],
        [1.0, 1.0, 2.0, 1.0],
    ] {
        let s: f64 = w.iter().sum();
        let p = [0, 1, 2].map(|a| (0..4).map(|k| w[k] * c[k][a]).sum::<f64>() / s);
        if let Location::Region(r) = locator.locate_with(p, scratch) {
            return r;
        }
    }
    0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transitions_balance() {
        let mut t = Transitions::default();
        assert_eq!(t.last(0), 0);
        t.cross(0, 1);
        assert_eq!(t.last(0), 1);
        t.cross(1, 2);
        assert_eq!(t.last(0), 2);
        t.cross(2, 1);
        assert_eq!(t.last(0), 1);
        t.cross(1, 0);
        assert_eq!(t.last(0), 0);
        // Out and back in, recorded in either order.
        let mut t = Transitions::default();
        t.cross(0, 1);
        t.cross(0, 1);
        t.cross(1, 0);
        assert_eq!(t.last(0), 1);
    }
}
