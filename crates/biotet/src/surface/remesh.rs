//! The remeshing loop: split long edges, collapse short ones, flip edges to raise the smallest
//! angle, relax points tangentially and project them onto the input (Botsch and Kobbelt 2004),
//! every operation checked before it is applied:
//!
//! - topology: the link condition for collapses, no point left with fewer than three triangles,
//!   feature edges never touched and fixed points never moved ([`super::features`]);
//! - geometry: new triangles non-degenerate (exact), no normal turned by more than 60°, and no
//!   new triangle meeting any other triangle except in their shared corners or edge
//!   ([`crate::geom::intersect::tri_tri`], exact), candidates from a [`Grid`];
//! - distance: sample points on every new triangle within the working tolerance of the input
//!   sheet with the same side labels, and a removed point (which lay on the input) within it of
//!   the triangles that replace it;
//! - shape: no new triangle with a smaller angle than the worst of the triangles it replaces,
//!   unless it is above the target angle.
//!
//! The loop is sequential and visits edges and points in index order, so its output depends on
//! the input alone.

use rustc_hash::FxHashSet;

use super::bvh::{Hint, PatchIndex, closest_on_triangle, dist2, unit_normal};
use super::features::{Features, key};
use super::grid::Grid;
use super::guard::InputSamples;
use crate::geom::intersect::{is_degenerate, tri_tri};
use crate::geom::vec3::bbox;
use crate::geom::vec3::{add, cross, dot, norm, scale, sub};
use crate::mesh::surface::SurfaceMesh;

type P3 = [f64; 3];

mod necks;

/// Smallest and largest angle of a triangle, in degrees.
pub fn angles_deg(t: &[P3; 3]) -> (f64, f64) {
    let mut lo = 180.0f64;
    let mut hi = 0.0f64;
    for k in 0..3 {
        let u = sub(t[(k + 1) % 3], t[k]);
        let v = sub(t[(k + 2) % 3], t[k]);
        let a = norm(cross(u, v)).atan2(dot(u, v)).to_degrees();
        lo = lo.min(a);
        hi = hi.max(a);
    }
    (lo, hi)
}

/// Counts of applied operations.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct OpCounts {
    /// Edges split.
    pub splits: usize,
    /// Edges collapsed.
    pub collapses: usize,
    /// Edges flipped.
    pub flips: usize,
    /// Points moved (relaxation and projection).
    pub moves: usize,
}

/// The surface being remeshed.
pub struct Remesher<'a> {
    /// Point coordinates (removed points stay, unused).
    pub pts: Vec<P3>,
    /// Triangles (dead ones stay, marked in `alive`).
    pub tris: Vec<[u32; 3]>,
    /// Side labels per triangle.
    pub sides: Vec<[u32; 2]>,
    /// Whether a triangle is in the surface.
    pub alive: Vec<bool>,
    vt: Vec<Vec<u32>>,
    fixed: Vec<bool>,
    feature: FxHashSet<(u32, u32)>,
    input: &'a PatchIndex,
    samples: &'a InputSamples,
    tri_size: &'a [f64],
    /// Target edge length per point.
    pub size: Vec<f64>,
    grid: Grid,
    /// Target edge length.
    pub l: f64,
    /// Working distance tolerance.
    pub tol: f64,
    /// Sample spacing of the distance checks on new triangles.
    pub spacing: f64,
    /// Target smallest angle (degrees): a new triangle above it is always acceptable.
    pub target_angle: f64,
    /// What was done.
    pub counts: OpCounts,
    /// Repair mode: a projection may lower the smallest angle (the distance comes first).
    pub repairing: bool,
    scratch: Vec<u32>,
    scratch2: Vec<u32>,
}

impl<'a> Remesher<'a> {
    /// Start from `s` with its features, projecting onto `input`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        s: &SurfaceMesh,
        f: &Features,
        input: &'a PatchIndex,
        samples: &'a InputSamples,
        point_size: &[f64],
        tri_size: &'a [f64],
        l: f64,
        tol: f64,
    ) -> Remesher<'a> {
        let mut vt = vec![Vec::new(); s.points.len()];
        let mut grid = Grid::new(l.max(1e-300));
        for (t, tri) in s.triangles.iter().enumerate() {
            for &v in tri {
                vt[v as usize].push(t as u32);
            }
            grid.insert(t as u32, &s.corners(t));
        }
        Remesher {
            pts: s.points.clone(),
            tris: s.triangles.clone(),
            sides: s.sides.clone(),
            alive: vec![true; s.triangles.len()],
            vt,
            fixed: f.fixed.clone(),
            feature: f.edges.clone(),
            input,
            samples,
            tri_size,
            size: point_size.to_vec(),
            grid,
            l,
            tol,
            spacing: l / 2.0,
            target_angle: 30.0,
            counts: OpCounts::default(),
            repairing: false,
            scratch: Vec::new(),
            scratch2: Vec::new(),
        }
    }

    /// The surface as it stands, unused points dropped (order of first use kept).
    pub fn to_surface(&self) -> SurfaceMesh {
        let mut id = vec![u32::MAX; self.pts.len()];
        let mut out = SurfaceMesh::default();
        for t in 0..self.tris.len() {
            if !self.alive[t] {
                continue;
            }
            let tri = self.tris[t].map(|v| {
                if id[v as usize] == u32::MAX {
                    id[v as usize] = out.points.len() as u32;
                    out.points.push(self.pts[v as usize]);
                }
                id[v as usize]
            });
            out.triangles.push(tri);
            out.sides.push(self.sides[t]);
        }
        out
    }

    #[inline]
    fn corners(&self, t: u32) -> [P3; 3] {
        self.tris[t as usize].map(|v| self.pts[v as usize])
    }

    fn is_fixed(&self, v: u32) -> bool {
        self.fixed[v as usize]
    }

    /// The two triangles of edge `ab` (`[a, b, c]` and `[b, a, d]` up to rotation) and `c`, `d`;
    /// `None` unless exactly two.
    fn edge_pair(&self, a: u32, b: u32) -> Option<(u32, u32, u32, u32)> {
        let mut t1 = None;
        let mut t2 = None;
        let mut n = 0;
        for &t in &self.vt[a as usize] {
            let tri = self.tris[t as usize];
            if let Some(i) = tri.iter().position(|&x| x == a)
                && tri.contains(&b)
            {
                n += 1;
                if tri[(i + 1) % 3] == b {
                    t1 = Some((t, tri[(i + 2) % 3]));
                } else {
                    t2 = Some((t, tri[(i + 1) % 3]));
                }
            }
        }
        match (n, t1, t2) {
            (2, Some((t1, c)), Some((t2, d))) => Some((t1, t2, c, d)),
            _ => None,
        }
    }

    fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut n: Vec<u32> = self.vt[v as usize]
            .iter()
            .flat_map(|&t| self.tris[t as usize])
            .filter(|&x| x != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }

    fn has_edge(&self, a: u32, b: u32) -> bool {
        self.vt[a as usize]
            .iter()
            .any(|&t| self.tris[t as usize].contains(&b))
    }

    /// Every sample of triangle `c` within the working tolerance of the input sheet `sides`.
    fn near_input(&self, c: &[P3; 3], sides: [u32; 2]) -> bool {
        let Some(bvh) = self.input.get(sides) else {
            return false;
        };
        let longest = (0..3)
            .map(|k| dist2(c[k], c[(k + 1) % 3]))
            .fold(0.0, f64::max)
            .sqrt();
        let n = ((longest / self.spacing).ceil() as usize).clamp(2, 6);
        let t2 = self.tol * self.tol;
        let mut hint = Hint::default();
        for i in 0..=n {
            for j in 0..=n - i {
                let k = n - i - j;
                let w = [i as f64, j as f64, k as f64].map(|x| x / n as f64);
                let p = [0, 1, 2].map(|a| w[0] * c[0][a] + w[1] * c[1][a] + w[2] * c[2][a]);
                if !bvh.any_within_hinted(p, t2, &mut hint) {
                    return false;
                }
            }
        }
        true
    }

    /// Whether the input stays within the working tolerance when the triangles `old` (all with
    /// side labels `sides`, corners `old_c`) are replaced by `new`: every input sample of that
    /// sheet within it of an old triangle is within it of a new triangle or of a triangle that
    /// stays. Samples farther from every old triangle need no test: every sample is within the
    /// tolerance of the current surface (it starts as the input, each operation keeps it so, and
    /// the tolerance never shrinks), so those are covered by triangles that stay.
    fn input_kept(
        &mut self,
        old_c: &[[P3; 3]],
        new: &[([u32; 3], [P3; 3])],
        old: &[u32],
        sides: [u32; 2],
    ) -> bool {
        let tol = self.tol;
        let t2 = tol * tol;
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let boxes: Vec<(P3, P3)> = old_c
            .iter()
            .map(|c| {
                let (a, b) = bbox(c);
                (a.map(|x| x - tol), b.map(|x| x + tol))
            })
            .collect();
        for (a, b) in &boxes {
            for k in 0..3 {
                lo[k] = lo[k].min(a[k]);
                hi[k] = hi[k].max(b[k]);
            }
        }
        let mut near = std::mem::take(&mut self.scratch2);
        self.samples.in_box(lo, hi, &mut near);
        let mut ok = true;
        // The new triangle that covered the last sample is tried first (neighbouring samples
        // mostly share it).
        let mut last = 0;
        for &s in &near {
            if self.samples.sides[s as usize] != sides {
                continue;
            }
            let p = self.samples.pts[s as usize];
            let near_old = old_c.iter().zip(&boxes).any(|(c, (a, b))| {
                (0..3).all(|k| p[k] >= a[k] && p[k] <= b[k])
                    && dist2(p, closest_on_triangle(p, c)) <= t2
            });
            if !near_old {
                continue;
            }
            let within = |k: usize| dist2(p, closest_on_triangle(p, &new[k].1)) <= t2;
            if !new.is_empty() && within(last) {
                continue;
            }
            if let Some(k) = (0..new.len()).find(|&k| k != last && within(k)) {
                last = k;
                continue;
            }
            // The triangles that stay.
            let mut cand = std::mem::take(&mut self.scratch);
            self.grid
                .query(p.map(|x| x - tol), p.map(|x| x + tol), &mut cand);
            let kept = cand.iter().any(|&u| {
                self.alive[u as usize]
                    && !old.contains(&u)
                    && self.sides[u as usize] == sides
                    && dist2(p, closest_on_triangle(p, &self.corners(u))) <= t2
            });
            self.scratch = cand;
            if !kept {
                ok = false;
                break;
            }
        }
        self.scratch2 = near;
        ok
    }

    /// Whether any of the proposed triangles `new` (corner ids and coordinates) meets another
    /// triangle other than in shared corners or a shared edge; triangles in `ignore` are about
    /// to go and are not tested.
    fn crosses(&mut self, new: &[([u32; 3], [P3; 3])], ignore: &[u32]) -> bool {
        for (i, (_, c)) in new.iter().enumerate() {
            for (_, d) in &new[..i] {
                if !tri_tri(c, d).is_legal() {
                    return true;
                }
            }
            let (lo, hi) = bbox(c);
            let mut cand = std::mem::take(&mut self.scratch);
            self.grid.query(lo, hi, &mut cand);
            let mut bad = false;
            for &u in &cand {
                if !self.alive[u as usize] || ignore.contains(&u) {
                    continue;
                }
                let d = self.corners(u);
                let (dlo, dhi) = bbox(&d);
                if (0..3).any(|k| dlo[k] > hi[k] || dhi[k] < lo[k]) {
                    continue;
                }
                if !tri_tri(c, &d).is_legal() {
                    bad = true;
                    break;
                }
            }
            self.scratch = cand;
            if bad {
                return true;
            }
        }
        false
    }

    /// Shape and orientation of the proposed triangles against the ones they replace: each
    /// non-degenerate (exact), its normal within 60° of the replaced one's (`old_normals`, one
    /// per new triangle), and its smallest angle no worse than `floor`.
    fn shape_ok(&self, new: &[([u32; 3], [P3; 3])], old_normals: &[P3], floor: f64) -> bool {
        for ((_, c), n0) in new.iter().zip(old_normals) {
            if is_degenerate(c) {
                return false;
            }
            if dot(unit_normal(c), *n0) < 0.5 {
                return false;
            }
            if angles_deg(c).0 < floor {
                return false;
            }
        }
        true
    }

    fn worst_angle(&self, ts: &[u32]) -> f64 {
        ts.iter()
            .map(|&t| angles_deg(&self.corners(t)).0)
            .fold(180.0, f64::min)
    }

    fn replace(&mut self, t: u32, tri: [u32; 3]) {
        self.grid.remove(t);
        for &v in &self.tris[t as usize] {
            let l = &mut self.vt[v as usize];
            if let Some(p) = l.iter().position(|&x| x == t) {
                l.swap_remove(p);
            }
        }
        self.tris[t as usize] = tri;
        for &v in &tri {
            self.vt[v as usize].push(t);
        }
        let c = self.corners(t);
        self.grid.insert(t, &c);
    }

    fn kill(&mut self, t: u32) {
        self.grid.remove(t);
        for &v in &self.tris[t as usize] {
            let l = &mut self.vt[v as usize];
            if let Some(p) = l.iter().position(|&x| x == t) {
                l.swap_remove(p);
            }
        }
        self.alive[t as usize] = false;
    }

    fn add(&mut self, tri: [u32; 3], sides: [u32; 2]) -> u32 {
        let t = self.tris.len() as u32;
        self.tris.push(tri);
        self.sides.push(sides);
        self.alive.push(true);
        for &v in &tri {
            self.vt[v as usize].push(t);
        }
        let c = self.corners(t);
        self.grid.insert(t, &c);
        t
    }

    /// The closest point of the input sheet of `v`'s triangles to `p`, and the target size
    /// there.
    fn project(&self, v: u32, p: P3) -> Option<(P3, f64)> {
        let t = *self.vt[v as usize].first()?;
        let bvh = self.input.get(self.sides[t as usize])?;
        let q = bvh.closest(p)?;
        Some((q.point, self.tri_size[q.triangle as usize]))
    }

    /// The target length of edge `ab`.
    fn target(&self, a: u32, b: u32) -> f64 {
        self.size[a as usize].min(self.size[b as usize])
    }

    fn vertex_normal(&self, v: u32) -> P3 {
        let mut n = [0.0; 3];
        for &t in &self.vt[v as usize] {
            let c = self.corners(t);
            n = add(n, cross(sub(c[1], c[0]), sub(c[2], c[0])));
        }
        let l = norm(n);
        if l > 0.0 { scale(n, 1.0 / l) } else { n }
    }

    /// Move point `v` to `x` if every check passes.
    pub fn try_move(&mut self, v: u32, x: P3) -> bool {
        if self.is_fixed(v) || x == self.pts[v as usize] {
            return false;
        }
        let fan = self.vt[v as usize].clone();
        let floor = if self.repairing {
            0.0
        } else {
            self.worst_angle(&fan).min(self.target_angle)
        };
        let old_normals: Vec<P3> = fan.iter().map(|&t| unit_normal(&self.corners(t))).collect();
        let new: Vec<([u32; 3], [P3; 3])> = fan
            .iter()
            .map(|&t| {
                let tri = self.tris[t as usize];
                (
                    tri,
                    tri.map(|u| if u == v { x } else { self.pts[u as usize] }),
                )
            })
            .collect();
        if !self.shape_ok(&new, &old_normals, floor) {
            return false;
        }
        if !new
            .iter()
            .zip(&fan)
            .all(|((_, c), &t)| self.near_input(c, self.sides[t as usize]))
        {
            return false;
        }
        let old_c: Vec<[P3; 3]> = fan.iter().map(|&t| self.corners(t)).collect();
        if !self.input_kept(&old_c, &new, &fan, self.sides[fan[0] as usize]) {
            return false;
        }
        if self.crosses(&new, &fan) {
            return false;
        }
        for &t in &fan {
            self.grid.remove(t);
        }
        self.pts[v as usize] = x;
        for &t in &fan {
            let c = self.corners(t);
            self.grid.insert(t, &c);
        }
        self.counts.moves += 1;
        true
    }

    /// Split edge `ab` at its midpoint, then try to project the new point onto the input.
    pub fn split(&mut self, a: u32, b: u32) -> bool {
        if self.feature.contains(&key(a, b)) {
            return false;
        }
        let Some((t1, t2, c, d)) = self.edge_pair(a, b) else {
            return false;
        };
        let (pa, pb) = (self.pts[a as usize], self.pts[b as usize]);
        let m = scale(add(pa, pb), 0.5);
        let (pc, pd) = (self.pts[c as usize], self.pts[d as usize]);
        if [[pa, m, pc], [m, pb, pc], [pb, m, pd], [m, pa, pd]]
            .iter()
            .any(is_degenerate)
        {
            return false;
        }
        let mi = self.pts.len() as u32;
        self.pts.push(m);
        self.vt.push(Vec::new());
        self.fixed.push(false);
        self.size.push(self.target(a, b));
        let (s1, s2) = (self.sides[t1 as usize], self.sides[t2 as usize]);
        self.replace(t1, [a, mi, c]);
        self.add([mi, b, c], s1);
        self.replace(t2, [b, mi, d]);
        self.add([mi, a, d], s2);
        self.counts.splits += 1;
        if let Some((x, h)) = self.project(mi, m)
            && self.try_move(mi, x)
        {
            self.size[mi as usize] = h;
        }
        true
    }

    /// Collapse edge `ab` by removing `a` (its triangles then use `b`), if every check passes.
    pub fn collapse(&mut self, a: u32, b: u32, factor: f64) -> bool {
        if self.is_fixed(a) || self.feature.contains(&key(a, b)) {
            return false;
        }
        let Some((t1, t2, c, d)) = self.edge_pair(a, b) else {
            return false;
        };
        if c == d {
            return false;
        }
        // Link condition: the common neighbours of a and b are c and d alone.
        let na = self.neighbours(a);
        let nb = self.neighbours(b);
        let common = na.iter().filter(|x| nb.binary_search(x).is_ok()).count();
        if common != 2 {
            return false;
        }
        let (da, db) = (self.vt[a as usize].len(), self.vt[b as usize].len());
        if da + db < 7 || self.vt[c as usize].len() < 4 || self.vt[d as usize].len() < 4 {
            return false;
        }
        let pb = self.pts[b as usize];
        let pa = self.pts[a as usize];
        if na.iter().any(|&x| {
            let m = factor * self.target(b, x);
            dist2(self.pts[x as usize], pb) > m * m
        }) {
            return false;
        }
        let fan: Vec<u32> = self.vt[a as usize].clone();
        let kept: Vec<u32> = fan
            .iter()
            .copied()
            .filter(|&t| t != t1 && t != t2)
            .collect();
        let floor = self.worst_angle(&fan).min(self.target_angle);
        let old_normals: Vec<P3> = kept
            .iter()
            .map(|&t| unit_normal(&self.corners(t)))
            .collect();
        let new: Vec<([u32; 3], [P3; 3])> = kept
            .iter()
            .map(|&t| {
                let tri = self.tris[t as usize].map(|u| if u == a { b } else { u });
                (tri, tri.map(|u| self.pts[u as usize]))
            })
            .collect();
        if !self.shape_ok(&new, &old_normals, floor) {
            return false;
        }
        if !new
            .iter()
            .zip(&kept)
            .all(|((_, c), &t)| self.near_input(c, self.sides[t as usize]))
        {
            return false;
        }
        // The removed point lay on (or near) the input: the new fan must pass near it.
        let t2r = self.tol * self.tol;
        if !new
            .iter()
            .any(|(_, c)| dist2(pa, closest_on_triangle(pa, c)) <= t2r)
        {
            return false;
        }
        let old_c: Vec<[P3; 3]> = fan.iter().map(|&t| self.corners(t)).collect();
        if !self.input_kept(&old_c, &new, &fan, self.sides[t1 as usize]) {
            return false;
        }
        if self.crosses(&new, &fan) {
            return false;
        }
        self.kill(t1);
        self.kill(t2);
        for (&t, (tri, _)) in kept.iter().zip(&new) {
            self.replace(t, *tri);
        }
        self.counts.collapses += 1;
        true
    }

    /// Flip edge `ab` to `cd` if that raises the smaller of the two triangles' smallest angles
    /// and every check passes.
    pub fn flip(&mut self, a: u32, b: u32) -> bool {
        if self.feature.contains(&key(a, b)) {
            return false;
        }
        let Some((t1, t2, c, d)) = self.edge_pair(a, b) else {
            return false;
        };
        if c == d
            || self.sides[t1 as usize] != self.sides[t2 as usize]
            || self.vt[a as usize].len() < 4
            || self.vt[b as usize].len() < 4
            || self.has_edge(c, d)
        {
            return false;
        }
        let p = |v: u32| self.pts[v as usize];
        let new = [
            ([c, a, d], [p(c), p(a), p(d)]),
            ([d, b, c], [p(d), p(b), p(c)]),
        ];
        let old = [self.corners(t1), self.corners(t2)];
        let old_min = angles_deg(&old[0]).0.min(angles_deg(&old[1]).0);
        let new_min = angles_deg(&new[0].1).0.min(angles_deg(&new[1].1).0);
        if new_min <= old_min + 1e-9 {
            return false;
        }
        let n_old = {
            let s = add(unit_normal(&old[0]), unit_normal(&old[1]));
            let l = norm(s);
            if l == 0.0 {
                return false;
            }
            scale(s, 1.0 / l)
        };
        if !self.shape_ok(&new, &[n_old, n_old], 0.0) {
            return false;
        }
        if dot(unit_normal(&new[0].1), unit_normal(&new[1].1)) < 0.5 {
            return false;
        }
        let sides = self.sides[t1 as usize];
        if !new.iter().all(|(_, c)| self.near_input(c, sides)) {
            return false;
        }
        if !self.input_kept(&old, &new, &[t1, t2], sides) {
            return false;
        }
        if self.crosses(&new, &[t1, t2]) {
            return false;
        }
        self.replace(t1, new[0].0);
        self.replace(t2, new[1].0);
        self.counts.flips += 1;
        true
    }

    /// Tangential relaxation of `v`: towards the mean of its neighbours within its tangent
    /// plane, then onto the input.
    pub fn relax(&mut self, v: u32) -> bool {
        if self.is_fixed(v) || self.vt[v as usize].is_empty() {
            return false;
        }
        let nb = self.neighbours(v);
        let mut q = [0.0; 3];
        for &u in &nb {
            q = add(q, self.pts[u as usize]);
        }
        q = scale(q, 1.0 / nb.len() as f64);
        let p = self.pts[v as usize];
        let n = self.vertex_normal(v);
        let q = sub(q, scale(n, dot(n, sub(q, p))));
        let Some((x, h)) = self.project(v, q) else {
            return false;
        };
        let moved = self.try_move(v, x);
        if moved {
            self.size[v as usize] = h;
        }
        moved
    }

    /// The current edges `(a, b)`, `a < b`, sorted.
    pub fn edges(&self) -> Vec<(u32, u32)> {
        let mut e: Vec<(u32, u32)> = Vec::with_capacity(self.tris.len() * 3 / 2);
        for t in 0..self.tris.len() {
            if self.alive[t] {
                let tri = self.tris[t];
                for k in 0..3 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    if a < b {
                        e.push((a, b));
                    }
                }
            }
        }
        e.sort_unstable();
        e.dedup();
        e
    }

    fn len(&self, a: u32, b: u32) -> f64 {
        dist2(self.pts[a as usize], self.pts[b as usize]).sqrt()
    }

    /// Length of `ab` relative to its target.
    fn rel(&self, a: u32, b: u32) -> f64 {
        self.len(a, b) / self.target(a, b)
    }

    /// One round of Botsch–Kobbelt: splits, collapses, flips, relaxation.
    pub fn round(&mut self) {
        let hi = 4.0 / 3.0;
        let lo = 4.0 / 5.0;
        // Split long edges (against their target), longest first, until none is left (bounded).
        for _ in 0..4 {
            let mut long: Vec<(f64, u32, u32)> = self
                .edges()
                .into_iter()
                .map(|(a, b)| (self.rel(a, b), a, b))
                .filter(|e| e.0 > hi)
                .collect();
            if long.is_empty() {
                break;
            }
            long.sort_by(|x, y| y.0.total_cmp(&x.0).then((x.1, x.2).cmp(&(y.1, y.2))));
            for (_, a, b) in long {
                if self.rel(a, b) > hi {
                    self.split(a, b);
                }
            }
        }
        // Collapse short edges, shortest first.
        let mut short: Vec<(f64, u32, u32)> = self
            .edges()
            .into_iter()
            .map(|(a, b)| (self.rel(a, b), a, b))
            .filter(|e| e.0 < lo)
            .collect();
        short.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
        for (_, a, b) in short {
            if self.vt[a as usize].is_empty()
                || self.vt[b as usize].is_empty()
                || !self.has_edge(a, b)
                || self.rel(a, b) >= lo
            {
                continue;
            }
            if !self.collapse(a, b, hi) {
                self.collapse(b, a, hi);
            }
        }
        self.flips();
        for v in 0..self.pts.len() as u32 {
            if !self.vt[v as usize].is_empty() {
                self.relax(v);
            }
        }
    }

    /// Flip edges until no flip raises an angle (bounded number of sweeps).
    pub fn flips(&mut self) {
        for _ in 0..3 {
            let before = self.counts.flips;
            for (a, b) in self.edges() {
                if self.has_edge(a, b) {
                    self.flip(a, b);
                }
            }
            if self.counts.flips == before {
                break;
            }
        }
    }

    /// Work on the triangles whose smallest angle is below the target: flip their edges,
    /// collapse their shortest edge, split their longest one, relax their corners.
    pub fn clean_up(&mut self) -> usize {
        let hi = 4.0 / 3.0;
        let bad: Vec<u32> = (0..self.tris.len() as u32)
            .filter(|&t| {
                self.alive[t as usize] && angles_deg(&self.corners(t)).0 < self.target_angle
            })
            .collect();
        let mut done = 0;
        for t in bad {
            if !self.alive[t as usize] || angles_deg(&self.corners(t)).0 >= self.target_angle {
                continue;
            }
            let tri = self.tris[t as usize];
            let mut e: Vec<(f64, u32, u32)> = (0..3)
                .map(|k| {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    (self.len(a, b), a, b)
                })
                .collect();
            e.sort_by(|x, y| x.0.total_cmp(&y.0));
            let mut ok = false;
            for &(_, a, b) in e.iter().rev() {
                if self.flip(a, b) {
                    ok = true;
                    break;
                }
            }
            for &(_, a, b) in &e {
                if ok {
                    break;
                }
                ok = self.collapse(a, b, hi * 1.25) || self.collapse(b, a, hi * 1.25);
            }
            // A cap (an angle over 120°): split the edge opposite it.
            if !ok && angles_deg(&self.corners(t)).1 > 120.0 {
                let (_, a, b) = e[2];
                ok = self.split(a, b);
            }
            if !ok {
                for v in tri {
                    ok |= self.relax(v);
                }
            }
            done += ok as usize;
        }
        done
    }

    /// Points to move or split where the output strays from the input: split the longest
    /// non-feature edge of triangle `t` and project the new point.
    pub fn refine_triangle(&mut self, t: u32) -> bool {
        if !self.alive[t as usize] {
            return false;
        }
        let tri = self.tris[t as usize];
        let mut e: Vec<(f64, u32, u32)> = (0..3)
            .map(|k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                (self.len(a, b), a, b)
            })
            .collect();
        e.sort_by(|x, y| y.0.total_cmp(&x.0));
        e.iter().any(|&(_, a, b)| self.split(a, b))
    }

    /// Number of triangles in the surface.
    pub fn n_alive(&self) -> usize {
        self.alive.iter().filter(|&&x| x).count()
    }
}
