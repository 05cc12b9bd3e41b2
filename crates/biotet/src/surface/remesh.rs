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
//!   sheet with the same side labels, a removed point (which lay on the input) within it of
//!   the triangles that replace it, and every input sample ([`InputSamples`]) covered: each
//!   has a triangle within the tolerance, and an operation must find new ones for the samples
//!   its old triangles covered;
//! - shape: no new triangle with a smaller angle than the worst of the triangles it replaces,
//!   unless it is above the target angle.
//!
//! Distances are bounded rather than recomputed where a bound suffices: each triangle keeps an
//! upper bound on its samples' distance to the input and each input sample one on its distance
//! to its covering triangle, and a point move by `m` moves every point of its triangles by at
//! most `m` (by `w m` at barycentric weight `w`), so a bound plus that move within the
//! tolerance needs no distance computed. Each shortcut answers as the full test would.
//!
//! The loop is sequential and visits edges and points in index order, so its output depends on
//! the input alone.

use rustc_hash::{FxHashMap, FxHashSet};

use super::bvh::{
    Hint, PatchIndex, Pre, closest_on_segment, closest_on_triangle, dist2, longest_edge,
    unit_normal, within, within_d2, within_d2_pre,
};
use super::features::{Features, key};
use super::grid::Grid;
use super::guard::InputSamples;
use crate::geom::intersect::{is_degenerate, meet_improperly};
use crate::geom::vec3::bbox;
use crate::geom::vec3::{add, cross, dot, norm, scale, sub};
use crate::mesh::surface::SurfaceMesh;

type P3 = [f64; 3];

mod batch;
use batch::Wrote;
mod folds;
pub use folds::{FOLD_ANGLE, min_fold};
mod necks;
mod sweep;

/// The smallest angle a split may make where the two triangles it splits are above it
/// (degrees; see [`Remesher::split`]).
const SPLIT_FLOOR_DEG: f64 = 3.0;

/// Smallest and largest angle of a triangle, in degrees.
pub fn angles_deg(t: &[P3; 3]) -> (f64, f64) {
    let mut lo = 180.0f64;
    let mut hi = 0.0f64;
    for k in 0..3 {
        let a = angle_at(t, k);
        lo = lo.min(a);
        hi = hi.max(a);
    }
    (lo, hi)
}

/// The angle of triangle `t` at corner `k`, in degrees (the formula of [`angles_deg`]).
#[inline]
fn angle_at(t: &[P3; 3], k: usize) -> f64 {
    let u = sub(t[(k + 1) % 3], t[k]);
    let v = sub(t[(k + 2) % 3], t[k]);
    norm(cross(u, v)).atan2(dot(u, v)).to_degrees()
}

/// `angles_deg(t).0` with one arc tangent instead of three where the shortest edge is shorter
/// than the others by a margin (the smallest angle faces it; a near tie computes all three, so
/// the value is the same to the last bit).
pub fn min_angle_deg(t: &[P3; 3]) -> f64 {
    let e = [0, 1, 2].map(|k| dist2(t[(k + 1) % 3], t[(k + 2) % 3]));
    let k = (0..3).min_by(|&a, &b| e[a].total_cmp(&e[b])).unwrap_or(0);
    let margin = 1.0 - 1e-9;
    if (0..3).all(|j| j == k || e[k] < e[j] * margin) {
        angle_at(t, k)
    } else {
        angles_deg(t).0
    }
}

/// A checked point move ([`Remesher::check_move`]): the point, where it goes, its new target
/// size (a relaxation takes the input's there), its fan's new distance bounds and the input
/// samples' new covers.
struct Move {
    v: u32,
    x: P3,
    size: Option<f64>,
    devs: Vec<(f64, u8)>,
    plan: Vec<(u32, u32, f64)>,
}

/// A checked edge collapse ([`Remesher::check_collapse`]): `a` goes, `b` stays (at `x`); the
/// two triangles at the edge die, the others around `a` (and `b`, if it moves) take the new
/// corners in `kept`, with their distance bounds and the input samples' new covers.
struct Collapse {
    b: u32,
    x: P3,
    size: Option<f64>,
    dead: [u32; 2],
    kept: Vec<(u32, [u32; 3])>,
    devs: Vec<(f64, u8)>,
    plan: Vec<(u32, u32, f64)>,
}

/// A checked edge flip ([`Remesher::check_flip`]).
enum Flip {
    /// Not an edge with two triangles that may flip, or a check refused it.
    Refused,
    /// The flip raises no angle: remembered at triangle `t`, edge `k` (`Remesher::no_flip`).
    NoGain(u32, usize),
    /// Triangles `t[k]` become `tris[k]`, with their bounds and the samples' new covers.
    Do {
        t: [u32; 2],
        tris: [[u32; 3]; 2],
        devs: Vec<(f64, u8)>,
        plan: Vec<(u32, u32, f64)>,
    },
}

/// What [`Remesher::check_clean`] found for a triangle.
struct Clean {
    /// Flips refused for no gain, to remember ([`Flip::NoGain`]).
    no_gain: Vec<(u32, usize)>,
    /// The first flip or collapse that passes.
    op: Option<CleanOp>,
}

/// The operation [`Remesher::check_clean`] found for a triangle: a flip ([`Flip::Do`]) or a
/// collapse.
enum CleanOp {
    Flip(Flip),
    Collapse(Collapse),
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
    /// The ends of the kept edges (see [`Self::split`]).
    kept_ends: FxHashSet<u32>,
    input: &'a PatchIndex,
    samples: &'a InputSamples,
    /// Per input sample: the triangle that covers it (within the working tolerance) and an
    /// upper bound on its distance to it.
    cover: Vec<(u32, f64)>,
    /// Per triangle: the input samples it covers.
    covers: Vec<Vec<u32>>,
    /// Per triangle: an upper bound on the distance of its samples to the input, and their
    /// number per edge (0: unknown).
    dev: Vec<(f64, u8)>,
    /// A clock that ticks at every change below.
    clock: u64,
    /// Per triangle: the tick of its last change (its corners, or one of them moved).
    changed: Vec<u64>,
    /// Per triangle and edge `k` (`tri[k]`, `tri[k + 1]`): the tick at which [`Remesher::flip`]
    /// found that flipping it raises no angle (0: never). That depends on the two triangles'
    /// points alone, so while neither changed since, the answer stands without the angles.
    no_flip: Vec<[u64; 3]>,
    /// Per triangle, the clock when [`Self::clean_up`] last failed on it (0: never), and the
    /// clean-up mode it failed in: while no triangle at its corners changed since, it is not
    /// tried again.
    failed_at: Vec<u64>,
    failed_middle: bool,
    /// Short edges whose collapse the rounds found refused both ways, with the clock then: while
    /// no triangle at either end changed since, they are not tried again.
    no_collapse: FxHashMap<(u32, u32), u64>,
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
    /// Whether [`Self::clean_up`] may collapse a needle's short edge to its middle
    /// ([`Self::collapse_mid`]).
    pub middle: bool,
    /// The tubes of the necks opened so far ([`necks`]), and a hash of them by place.
    tubes: Vec<necks::Tube>,
    tube_cells: FxHashMap<[i32; 3], Vec<u32>>,
}

impl<'a> Remesher<'a> {
    /// Start from `s` with its features, projecting onto `input`. `s` is the input, or the
    /// input with its long edges cut ([`super::presplit`]), whose triangle covering each input
    /// sample and its distance `cover` then gives (else each sample starts on the triangle it
    /// was taken from).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        s: &SurfaceMesh,
        f: &Features,
        input: &'a PatchIndex,
        samples: &'a InputSamples,
        cover: Option<&[(u32, f64)]>,
        point_size: &[f64],
        tri_size: &'a [f64],
        l: f64,
        tol: f64,
    ) -> Remesher<'a> {
        let mut vt = vec![Vec::new(); s.points.len()];
        let mut grid = Grid::new(l.max(1e-300));
        let cover: Vec<(u32, f64)> = match cover {
            Some(c) => c.to_vec(),
            None => samples.tri.iter().map(|&t| (t, 0.0)).collect(),
        };
        let mut covers = vec![Vec::new(); s.triangles.len()];
        for (i, &(t, _)) in cover.iter().enumerate() {
            covers[t as usize].push(i as u32);
        }
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
            kept_ends: f.edges.iter().flat_map(|&(a, b)| [a, b]).collect(),
            input,
            samples,
            cover,
            covers,
            dev: vec![(f64::INFINITY, 0); s.triangles.len()],
            clock: 0,
            changed: vec![0; s.triangles.len()],
            no_flip: vec![[0; 3]; s.triangles.len()],
            failed_at: vec![0; s.triangles.len()],
            failed_middle: false,
            no_collapse: FxHashMap::default(),
            tri_size,
            size: point_size.to_vec(),
            grid,
            l,
            tol,
            spacing: l / 2.0,
            target_angle: 30.0,
            counts: OpCounts::default(),
            repairing: false,
            middle: false,
            tubes: Vec::new(),
            tube_cells: FxHashMap::default(),
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
        let fan = &self.vt[v as usize];
        // Sized up front: growing it from empty reallocated twice a call.
        let mut n: Vec<u32> = Vec::with_capacity(2 * fan.len());
        n.extend(
            fan.iter()
                .flat_map(|&t| self.tris[t as usize])
                .filter(|&x| x != v),
        );
        n.sort_unstable();
        n.dedup();
        n
    }

    /// [`Self::neighbours`] in no particular order: a few points, deduplicated by a scan
    /// rather than a sort.
    fn neighbour_set(&self, v: u32) -> Vec<u32> {
        let fan = &self.vt[v as usize];
        let mut n: Vec<u32> = Vec::with_capacity(2 * fan.len());
        for &t in fan {
            for x in self.tris[t as usize] {
                if x != v && !n.contains(&x) {
                    n.push(x);
                }
            }
        }
        n
    }

    fn has_edge(&self, a: u32, b: u32) -> bool {
        self.vt[a as usize]
            .iter()
            .any(|&t| self.tris[t as usize].contains(&b))
    }

    /// The samples of triangle `c` per edge ([`Self::near_input`]).
    fn sample_count(&self, c: &[P3; 3]) -> u8 {
        ((longest_edge(c) / self.spacing).ceil() as usize).clamp(2, 6) as u8
    }

    /// Whether every sample of triangle `c` (a barycentric grid of `n` steps an edge) is within
    /// the working tolerance of the input sheet `sides`: then an upper bound on their largest
    /// distance to it, else `None`.
    ///
    /// `known = Some((k, d, m))` says that `c` is a triangle whose samples (at this `n`) were
    /// within `d` of the input, with corner `k` since moved by `m`: a sample of weight `w` at
    /// that corner moved by `w m`, so it is within `d + w m`, and where that is within the
    /// tolerance no distance is computed (the samples on the opposite edge did not move).
    fn near_input(
        &self,
        c: &[P3; 3],
        sides: [u32; 2],
        n: u8,
        known: Option<(usize, f64, f64)>,
        hint: &mut Hint,
    ) -> Option<f64> {
        let bvh = self.input.get(sides)?;
        let n = n as usize;
        let t2 = self.tol * self.tol;
        let lim = self.tol * (1.0 - 1e-9);
        let mut worst = 0.0f64;
        for i in 0..=n {
            for j in 0..=n - i {
                let k = n - i - j;
                let w = [i as f64, j as f64, k as f64].map(|x| x / n as f64);
                if let Some((corner, d, m)) = known {
                    let b = d + w[corner] * m;
                    if b <= lim {
                        worst = worst.max(b * b);
                        continue;
                    }
                }
                let p = [0, 1, 2].map(|a| w[0] * c[0][a] + w[1] * c[1][a] + w[2] * c[2][a]);
                worst = worst.max(bvh.first_within_hinted(p, t2, hint)?);
            }
        }
        Some(worst.sqrt())
    }

    /// [`Self::near_input`] for each of the proposed triangles `new` (with the side labels of
    /// `ids`): their bounds, or `None` if one strays. With `moved = Some((v, m))`, `new[k]` is
    /// triangle `ids[k]` with its corner `v` moved by `m`, so where it keeps its number of
    /// samples their old bound serves ([`Self::near_input`]'s `known`).
    fn new_near_input(
        &self,
        new: &[([u32; 3], [P3; 3])],
        ids: &[u32],
        moved: Option<(u32, f64)>,
    ) -> Option<Vec<(f64, u8)>> {
        // One hint over the fan: its triangles are answered by the same few input triangles
        // (the hint speeds the answer and does not change it).
        let mut hint = Hint::default();
        let mut devs = Vec::with_capacity(new.len());
        for ((tri, c), &t) in new.iter().zip(ids) {
            let n = self.sample_count(c);
            let (d, dn) = self.dev[t as usize];
            let known = moved.and_then(|(v, m)| {
                let corner = tri.iter().position(|&x| x == v)?;
                (dn == n).then_some((corner, d, m))
            });
            let d = self.near_input(c, self.sides[t as usize], n, known, &mut hint)?;
            devs.push((d, n));
        }
        Some(devs)
    }

    /// The new covers of the input samples covered by the triangles `old` when they are
    /// replaced by `new` (triangle `new_ids[k]` takes the corners `new[k]`; the other old ones
    /// go), or `None` if one of them would be farther than the working tolerance from every new
    /// triangle and every triangle that stays. Samples covered by a triangle that stays stay
    /// covered, so this keeps every input sample within the tolerance of the surface.
    ///
    /// `moved` > 0 says that `new[k]` is `old[k]` with one corner moved by that distance (a
    /// point move): every point of the old triangle is within `moved` of the new one, so a
    /// sample whose bound plus `moved` is within the tolerance needs no distance computed.
    fn recover_samples(
        &self,
        old: &[u32],
        new: &[([u32; 3], [P3; 3])],
        new_ids: &[u32],
        moved: f64,
    ) -> Option<Vec<(u32, u32, f64)>> {
        let tol = self.tol;
        let t2 = tol * tol;
        let lim = tol * (1.0 - 1e-9);
        let mut plan = Vec::with_capacity(old.iter().map(|&t| self.covers[t as usize].len()).sum());
        let mut cand = Vec::new();
        // What `within_d2` computes per triangle before measuring, once per new triangle.
        let pre: Vec<([u32; 2], Pre)> = new
            .iter()
            .zip(new_ids)
            .map(|((_, c), &t)| (self.sides[t as usize], Pre::new(c)))
            .collect();
        // The new triangle that covered the last sample is tried first (neighbouring samples
        // mostly share it).
        let mut last = 0;
        for &t in old {
            for &s in &self.covers[t as usize] {
                let d = self.cover[s as usize].1;
                if moved > 0.0 && d + moved <= lim {
                    plan.push((s, t, d + moved));
                    continue;
                }
                let p = self.samples.pts[s as usize];
                let sides = self.samples.sides[s as usize];
                let near_new = |k: usize| {
                    let (side, pre) = &pre[k];
                    if *side == sides {
                        within_d2_pre(p, &new[k].1, pre, tol, t2)
                    } else {
                        None
                    }
                };
                let found = near_new(last).map(|d2| (last, d2)).or_else(|| {
                    (0..new.len())
                        .filter(|&k| k != last)
                        .find_map(|k| near_new(k).map(|d2| (k, d2)))
                });
                if let Some((k, d2)) = found {
                    last = k;
                    plan.push((s, new_ids[k], d2.sqrt()));
                    continue;
                }
                // The triangles that stay.
                self.grid
                    .query(p.map(|x| x - tol), p.map(|x| x + tol), &mut cand);
                let kept = cand.iter().find_map(|&u| {
                    if self.alive[u as usize]
                        && !old.contains(&u)
                        && self.sides[u as usize] == sides
                    {
                        within_d2(p, &self.corners(u), tol, t2).map(|d2| (u, d2))
                    } else {
                        None
                    }
                });
                let (u, d2) = kept?;
                plan.push((s, u, d2.sqrt()));
            }
        }
        Some(plan)
    }

    /// Apply the covers of [`Self::recover_samples`].
    fn apply_covers(&mut self, plan: &[(u32, u32, f64)]) {
        for &(s, t, d) in plan {
            let (was, _) = self.cover[s as usize];
            if was != t {
                let l = &mut self.covers[was as usize];
                if let Some(i) = l.iter().position(|&x| x == s) {
                    l.swap_remove(i);
                }
                self.covers[t as usize].push(s);
            }
            self.cover[s as usize] = (t, d);
        }
    }

    /// Whether any of the proposed triangles `new` (corner ids and coordinates) meets another
    /// triangle other than in the corners or the edge they share by index; triangles in
    /// `ignore` are about to go and are not tested.
    fn crosses(&self, new: &[([u32; 3], [P3; 3])], ignore: &[u32]) -> bool {
        let boxes: Vec<(P3, P3)> = new.iter().map(|(_, c)| bbox(c)).collect();
        for (i, (ci, c)) in new.iter().enumerate() {
            for (di, d) in &new[..i] {
                if meet_improperly(c, *ci, d, *di) {
                    return true;
                }
            }
        }
        // One query over all of them: the triangles around a fan are candidates of most of its
        // triangles, and each is fetched once.
        let Some((lo, hi)) = boxes.iter().copied().reduce(|(a, b), (c, d)| {
            (
                [0, 1, 2].map(|k| a[k].min(c[k])),
                [0, 1, 2].map(|k| b[k].max(d[k])),
            )
        }) else {
            return false;
        };
        // The answer is whether any pair meets: the order the candidates come in does not
        // matter.
        self.grid.any(lo, hi, |u| {
            if !self.alive[u as usize] || ignore.contains(&u) {
                return false;
            }
            let d = self.corners(u);
            let (dlo, dhi) = bbox(&d);
            new.iter().zip(&boxes).any(|((ci, c), (lo, hi))| {
                !(0..3).any(|k| dlo[k] > hi[k] || dhi[k] < lo[k])
                    && meet_improperly(c, *ci, &d, self.tris[u as usize])
            })
        })
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
            if min_angle_deg(c) < floor {
                return false;
            }
        }
        true
    }

    fn worst_angle(&self, ts: &[u32]) -> f64 {
        ts.iter()
            .map(|&t| min_angle_deg(&self.corners(t)))
            .fold(180.0, f64::min)
    }

    /// Note that triangle `t` changed.
    fn touch(&mut self, t: u32) {
        self.clock += 1;
        self.changed[t as usize] = self.clock;
    }

    fn replace(&mut self, t: u32, tri: [u32; 3]) {
        self.touch(t);
        for &v in &self.tris[t as usize] {
            let l = &mut self.vt[v as usize];
            if let Some(p) = l.iter().position(|&x| x == t) {
                l.swap_remove(p);
            }
        }
        self.tris[t as usize] = tri;
        self.dev[t as usize] = (f64::INFINITY, 0);
        for &v in &tri {
            self.vt[v as usize].push(t);
        }
        let c = self.corners(t);
        self.grid.update(t, &c);
    }

    fn kill(&mut self, t: u32) {
        self.touch(t);
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
        self.covers.push(Vec::new());
        self.dev.push((f64::INFINITY, 0));
        self.changed.push(0);
        self.no_flip.push([0; 3]);
        self.failed_at.push(0);
        self.touch(t);
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
        Some((self.lift(p, q.point), self.tri_size[q.triangle as usize]))
    }

    /// The target length of edge `ab`.
    fn target(&self, a: u32, b: u32) -> f64 {
        let t = self.size[a as usize].min(self.size[b as usize]);
        if self.tubes.is_empty() {
            return t;
        }
        t.min(self.tube_size(scale(add(self.pts[a as usize], self.pts[b as usize]), 0.5)))
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
        match self.check_move(v, x, None) {
            Some(m) => {
                self.apply_move(m);
                true
            }
            None => false,
        }
    }

    /// The move of point `v` to `x` (and its target size to `size`, if given) with everything
    /// [`Self::apply_move`] needs, if every check passes; reads the surface only.
    fn check_move(&self, v: u32, x: P3, size: Option<f64>) -> Option<Move> {
        let floor = if self.repairing {
            0.0
        } else {
            self.worst_angle(&self.vt[v as usize])
                .min(self.target_angle)
        };
        self.check_move_above(v, x, size, floor)
    }

    /// [`Self::check_move`] with the smallest triangle angle the fan may have after the move
    /// given (`floor`, degrees).
    fn check_move_above(&self, v: u32, x: P3, size: Option<f64>, floor: f64) -> Option<Move> {
        if self.is_fixed(v) || x == self.pts[v as usize] {
            return None;
        }
        let fan = &self.vt[v as usize];
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
            return None;
        }
        let moved = dist2(x, self.pts[v as usize]).sqrt();
        let devs = self.new_near_input(&new, fan, Some((v, moved)))?;
        let plan = self.recover_samples(fan, &new, fan, moved)?;
        if self.crosses(&new, fan) {
            return None;
        }
        Some(Move {
            v,
            x,
            size,
            devs,
            plan,
        })
    }

    /// Apply a move [`Self::check_move`] made on the surface as it stands.
    fn apply_move(&mut self, m: Move) {
        let Move {
            v,
            x,
            size,
            devs,
            plan,
        } = m;
        self.apply_covers(&plan);
        let fan = std::mem::take(&mut self.vt[v as usize]);
        for (&t, d) in fan.iter().zip(devs) {
            self.dev[t as usize] = d;
        }
        self.pts[v as usize] = x;
        if let Some(h) = size {
            self.size[v as usize] = h;
        }
        for &t in &fan {
            self.touch(t);
            let c = self.corners(t);
            self.grid.update(t, &c);
        }
        self.vt[v as usize] = fan;
        self.counts.moves += 1;
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
        let halves = [[pa, m, pc], [m, pb, pc], [pb, m, pd], [m, pa, pd]];
        if halves.iter().any(is_degenerate) {
            return false;
        }
        // At a kept edge, halves may be worse than the pair (flips and moves mend that) but not
        // below SPLIT_FLOOR_DEG unless the pair already was: a triangle on a kept edge longer
        // than the target has its other edges split every round, its far corner closing in on
        // the kept edge (voxels six times longer one way: 9.5° became 2e-4° in four rounds).
        // Elsewhere splits are free (a long thin cylinder needs them: with the floor everywhere
        // one 400 long kept 1.2° triangles). The repair's splits bring the surface within the
        // tolerance, which comes first.
        if !self.repairing {
            let floor = self.worst_angle(&[t1, t2]).min(SPLIT_FLOOR_DEG);
            if halves.iter().any(|h| min_angle_deg(h) < floor)
                && [t1, t2].iter().any(|&t| self.near_kept_edge(t))
            {
                return false;
            }
        }
        // The rounded midpoint may lie off the edge: where another sheet passes that close,
        // the halves can meet it though the two triangles did not.
        let mi = self.pts.len() as u32;
        let ids = [[a, mi, c], [mi, b, c], [b, mi, d], [mi, a, d]];
        let new: Vec<([u32; 3], [P3; 3])> = ids.into_iter().zip(halves).collect();
        if self.crosses(&new, &[t1, t2]) {
            return false;
        }
        self.pts.push(m);
        self.vt.push(Vec::new());
        self.fixed.push(false);
        self.size.push(self.target(a, b));
        let (s1, s2) = (self.sides[t1 as usize], self.sides[t2 as usize]);
        self.replace(t1, [a, mi, c]);
        let h1 = self.add([mi, b, c], s1);
        self.replace(t2, [b, mi, d]);
        let h2 = self.add([mi, a, d], s2);
        // The halves cover what the two triangles covered: each sample goes to the nearer.
        let mut plan = Vec::new();
        for (t, h) in [(t1, h1), (t2, h2)] {
            let (ct, ch) = (self.corners(t), self.corners(h));
            for &s in &self.covers[t as usize] {
                let p = self.samples.pts[s as usize];
                let (dt, dh) = (
                    dist2(p, closest_on_triangle(p, &ct)),
                    dist2(p, closest_on_triangle(p, &ch)),
                );
                plan.push(if dh < dt {
                    (s, h, dh.sqrt())
                } else {
                    (s, t, dt.sqrt())
                });
            }
        }
        self.apply_covers(&plan);
        self.counts.splits += 1;
        if let Some((x, h)) = self.project(mi, m)
            && self.try_move(mi, x)
        {
            self.size[mi as usize] = h;
        }
        true
    }

    /// Whether triangle `t` has a corner on a kept edge (a feature, interface rim or triple
    /// line).
    fn near_kept_edge(&self, t: u32) -> bool {
        self.tris[t as usize]
            .iter()
            .any(|v| self.kept_ends.contains(v))
    }

    /// Collapse edge `ab` by removing `a` (its triangles then use `b`), if every check passes.
    pub fn collapse(&mut self, a: u32, b: u32, factor: f64) -> bool {
        self.collapse_to(a, b, false, factor)
    }

    /// Collapse edge `ab` to one point near its middle (projected onto the input), where
    /// neither end may move onto the other: a needle's short edge longer than the tolerance
    /// (each end then moves by half of it). The checks of [`Self::collapse`] over both fans,
    /// both old points within the tolerance of the new fan, and no new neck.
    pub fn collapse_mid(&mut self, a: u32, b: u32, factor: f64) -> bool {
        self.collapse_to(a, b, true, factor)
    }

    /// [`Self::collapse`] (`b` stays) or [`Self::collapse_mid`] (`b` moves to the middle).
    fn collapse_to(&mut self, a: u32, b: u32, middle: bool, factor: f64) -> bool {
        match self.check_collapse(a, b, middle, factor) {
            Some(c) => {
                self.apply_collapse(c);
                true
            }
            None => false,
        }
    }

    /// [`Self::collapse_to`]'s collapse, if every check passes; reads the surface only.
    fn check_collapse(&self, a: u32, b: u32, middle: bool, factor: f64) -> Option<Collapse> {
        if self.is_fixed(a) || (middle && self.is_fixed(b)) || self.feature.contains(&key(a, b)) {
            return None;
        }
        let (t1, t2, c, d) = self.edge_pair(a, b)?;
        if c == d {
            return None;
        }
        // Link condition: the common neighbours of a and b are c and d alone.
        // Their neighbours as sets: every use below is a count or an `any`.
        let na = self.neighbour_set(a);
        let nb = self.neighbour_set(b);
        let common = na.iter().filter(|x| nb.contains(x)).count();
        if common != 2 {
            return None;
        }
        let (da, db) = (self.vt[a as usize].len(), self.vt[b as usize].len());
        if da + db < 7 || self.vt[c as usize].len() < 4 || self.vt[d as usize].len() < 4 {
            return None;
        }
        let (pa, pb) = (self.pts[a as usize], self.pts[b as usize]);
        let (x, h) = if middle {
            // No new neck: a neighbour of `a` joined to one of `b` by an edge would make a
            // 3-cycle around the merged point that bounds no triangle.
            let others = |n: &[u32]| -> Vec<u32> {
                n.iter()
                    .copied()
                    .filter(|&u| u != a && u != b && u != c && u != d)
                    .collect()
            };
            let (oa, ob) = (others(&na), others(&nb));
            if oa.iter().any(|&u| ob.iter().any(|&w| self.has_edge(u, w))) {
                return None;
            }
            let (x, h) = self.project(b, scale(add(pa, pb), 0.5))?;
            (x, Some(h))
        } else {
            (pb, None)
        };
        // The new edges from the merged point (`b`'s own ones change only if it moves).
        let moved_nb: &[u32] = if middle { &nb } else { &[] };
        if na.iter().chain(moved_nb).any(|&u| {
            let m = factor * self.target(b, u);
            u != a && u != b && dist2(self.pts[u as usize], x) > m * m
        }) {
            return None;
        }
        let mut fan: Vec<u32> = self.vt[a as usize].clone();
        if middle {
            fan.extend_from_slice(&self.vt[b as usize]);
            fan.sort_unstable();
            fan.dedup();
        }
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
                (
                    tri,
                    tri.map(|u| if u == b { x } else { self.pts[u as usize] }),
                )
            })
            .collect();
        if !self.shape_ok(&new, &old_normals, floor) {
            return None;
        }
        let devs = self.new_near_input(&new, &kept, None)?;
        // The removed points lay on (or near) the input: the new fan must pass near them.
        let t2r = self.tol * self.tol;
        let removed: &[P3] = if middle { &[pa, pb] } else { &[pa] };
        if removed
            .iter()
            .any(|&p| !new.iter().any(|(_, c)| within(p, c, self.tol, t2r)))
        {
            return None;
        }
        let plan = self.recover_samples(&fan, &new, &kept, 0.0)?;
        if self.crosses(&new, &fan) {
            return None;
        }
        Some(Collapse {
            b,
            x,
            size: h,
            dead: [t1, t2],
            kept: kept
                .iter()
                .zip(&new)
                .map(|(&t, &(tri, _))| (t, tri))
                .collect(),
            devs,
            plan,
        })
    }

    /// Apply a collapse [`Self::check_collapse`] made on the surface as it stands.
    fn apply_collapse(&mut self, c: Collapse) {
        let Collapse {
            b,
            x,
            size,
            dead,
            kept,
            devs,
            plan,
        } = c;
        for t in dead {
            self.kill(t);
        }
        self.pts[b as usize] = x;
        if let Some(h) = size {
            self.size[b as usize] = self.size[b as usize].min(h);
        }
        for &(t, tri) in &kept {
            self.replace(t, tri);
        }
        self.apply_covers(&plan);
        for (&(t, _), d) in kept.iter().zip(devs) {
            self.dev[t as usize] = d;
        }
        self.counts.collapses += 1;
    }

    /// Flip edge `ab` to `cd` if that raises the smaller of the two triangles' smallest angles
    /// and every check passes.
    pub fn flip(&mut self, a: u32, b: u32) -> bool {
        let f = self.check_flip(a, b);
        self.apply_flip(f)
    }

    /// [`Self::flip`]'s flip, checked; reads the surface only.
    fn check_flip(&self, a: u32, b: u32) -> Flip {
        if self.feature.contains(&key(a, b)) {
            return Flip::Refused;
        }
        let Some((t1, t2, c, d)) = self.edge_pair(a, b) else {
            return Flip::Refused;
        };
        if c == d
            || self.sides[t1 as usize] != self.sides[t2 as usize]
            || self.vt[a as usize].len() < 4
            || self.vt[b as usize].len() < 4
            || self.has_edge(c, d)
        {
            return Flip::Refused;
        }
        let k1 = self.tris[t1 as usize]
            .iter()
            .position(|&x| x == a)
            .unwrap_or(0);
        if self.no_flip[t1 as usize][k1] > self.changed[t1 as usize].max(self.changed[t2 as usize])
        {
            return Flip::Refused;
        }
        let p = |v: u32| self.pts[v as usize];
        let new = [
            ([c, a, d], [p(c), p(a), p(d)]),
            ([d, b, c], [p(d), p(b), p(c)]),
        ];
        let old = [self.corners(t1), self.corners(t2)];
        let old_min = min_angle_deg(&old[0]).min(min_angle_deg(&old[1]));
        let new_min = min_angle_deg(&new[0].1).min(min_angle_deg(&new[1].1));
        if new_min <= old_min + 1e-9 {
            return Flip::NoGain(t1, k1);
        }
        let n_old = {
            let s = add(unit_normal(&old[0]), unit_normal(&old[1]));
            let l = norm(s);
            if l == 0.0 {
                return Flip::Refused;
            }
            scale(s, 1.0 / l)
        };
        if !self.shape_ok(&new, &[n_old, n_old], 0.0) {
            return Flip::Refused;
        }
        if dot(unit_normal(&new[0].1), unit_normal(&new[1].1)) < 0.5 {
            return Flip::Refused;
        }
        let Some(devs) = self.new_near_input(&new, &[t1, t2], None) else {
            return Flip::Refused;
        };
        let Some(plan) = self.recover_samples(&[t1, t2], &new, &[t1, t2], 0.0) else {
            return Flip::Refused;
        };
        if self.crosses(&new, &[t1, t2]) {
            return Flip::Refused;
        }
        Flip::Do {
            t: [t1, t2],
            tris: [new[0].0, new[1].0],
            devs,
            plan,
        }
    }

    /// Apply what [`Self::check_flip`] found on the surface as it stands: whether it flipped.
    fn apply_flip(&mut self, f: Flip) -> bool {
        match f {
            Flip::Refused => false,
            Flip::NoGain(t, k) => {
                self.clock += 1;
                self.no_flip[t as usize][k] = self.clock;
                false
            }
            Flip::Do {
                t,
                tris,
                devs,
                plan,
            } => {
                self.replace(t[0], tris[0]);
                self.replace(t[1], tris[1]);
                self.apply_covers(&plan);
                self.dev[t[0] as usize] = devs[0];
                self.dev[t[1] as usize] = devs[1];
                self.counts.flips += 1;
                true
            }
        }
    }

    /// Tangential relaxation of `v`: towards the mean of its neighbours within its tangent
    /// plane, then onto the input.
    pub fn relax(&mut self, v: u32) -> bool {
        match self.check_relax(v) {
            Some(m) => {
                self.apply_move(m);
                true
            }
            None => false,
        }
    }

    /// [`Self::relax`]'s move of `v`, checked, without applying it.
    fn check_relax(&self, v: u32) -> Option<Move> {
        let (x, h) = self.relax_target(v)?;
        self.check_move(v, x, Some(h))
    }

    /// Where [`Self::relax`] would move `v` (unchecked), and the input's target size there.
    fn relax_target(&self, v: u32) -> Option<(P3, f64)> {
        if self.is_fixed(v) || self.vt[v as usize].is_empty() {
            return None;
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
        self.project(v, q)
    }

    /// The current edges `(a, b)`, `a < b`, sorted.
    pub fn edges(&self) -> Vec<(u32, u32)> {
        self.edges_since(0)
    }

    /// The edges of the triangles changed after clock `since` ([`Self::edges`] for 0).
    fn edges_since(&self, since: u64) -> Vec<(u32, u32)> {
        // Sorted as one `u64` per edge, `a` in the high half: the order of the pairs, compared
        // in one step.
        let mut e: Vec<u64> = Vec::with_capacity(self.tris.len() * 3 / 2);
        for t in 0..self.tris.len() {
            // Every edge is listed by the triangle that has it in increasing order; a changed
            // triangle lists all three of its edges (the one across may not have changed).
            if self.alive[t] && (since == 0 || self.changed[t] > since) {
                let tri = self.tris[t];
                for k in 0..3 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    if a < b || since > 0 {
                        e.push((a.min(b) as u64) << 32 | a.max(b) as u64);
                    }
                }
            }
        }
        e.sort_unstable();
        e.dedup();
        e.into_iter()
            .map(|x| ((x >> 32) as u32, x as u32))
            .collect()
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
        self.collapse_short(lo, hi);
        self.flips();
        self.relax_all();
    }

    /// The edges `(length / target, a, b)` shorter than `lo` times their target, shortest
    /// first (ties by their points).
    fn short_edges(&self, lo: f64) -> Vec<(f64, u32, u32)> {
        let mut short: Vec<(f64, u32, u32)> = self
            .edges()
            .into_iter()
            .map(|(a, b)| (self.rel(a, b), a, b))
            .filter(|e| e.0 < lo)
            .collect();
        short.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
        short
    }

    /// Collapse the edges shorter than `lo` times their target, shortest first, the new edges
    /// no longer than `hi` times theirs; an edge refused both ways is not tried again while the
    /// triangles at its ends stay. The checks run in batches ([`batch`]).
    /// Returns the number of collapses checked again.
    fn collapse_short(&mut self, lo: f64, hi: f64) -> usize {
        let short = self.short_edges(lo);
        self.in_batches(
            &short,
            |r, &(_, a, b)| {
                // Whether to try reads the triangles at `a` and `b` only: an operation that
                // changes one of them has `a` or `b` in its box.
                let skip = r.vt[a as usize].is_empty()
                    || r.vt[b as usize].is_empty()
                    || !r.has_edge(a, b)
                    || r.rel(a, b) >= lo
                    || r.no_collapse
                        .get(&(a, b))
                        .is_some_and(|&at| at > r.changed_around(&[a, b]));
                if skip {
                    return (r.points_box(&[a, b]), None);
                }
                let c = r
                    .check_collapse(a, b, false, hi)
                    .or_else(|| r.check_collapse(b, a, false, hi));
                (r.fans_box(&[a, b]), Some(c))
            },
            |r, &(_, a, b), c| match c {
                None => Wrote::Nothing,
                Some(Some(c)) => {
                    r.apply_collapse(c);
                    Wrote::Read
                }
                Some(None) => {
                    r.clock += 1;
                    r.no_collapse.insert((a, b), r.clock);
                    Wrote::Nothing
                }
            },
        )
    }

    /// Flip edges until no flip raises an angle (bounded number of sweeps).
    pub fn flips(&mut self) {
        self.flips_since(0);
    }

    /// [`Self::flips`] over the edges of the triangles changed after clock `since` (0: every
    /// edge), each later sweep over those the sweep before changed: an edge whose two triangles
    /// stayed was refused and would be again (the clean-up's passes change a few hundred of
    /// tens of thousands).
    pub fn flips_since(&mut self, since: u64) {
        let mut since = since;
        for _ in 0..3 {
            let (before, start) = (self.counts.flips, self.clock);
            // One at a time: in this order (by point index) neighbouring edges follow each
            // other, and in batches most flips met an earlier one's box and were checked again.
            for (a, b) in self.edges_since(since) {
                if self.has_edge(a, b) {
                    self.flip(a, b);
                }
            }
            if self.counts.flips == before {
                break;
            }
            since = start;
        }
    }

    /// The clock ([`Self::flips_since`]): every change to a triangle ticks it.
    pub fn clock(&self) -> u64 {
        self.clock
    }

    /// The latest change to a triangle at any of the points `vs` (0: none since the start): an
    /// operation refused there before then would be refused again.
    fn changed_around(&self, vs: &[u32]) -> u64 {
        vs.iter()
            .flat_map(|&v| &self.vt[v as usize])
            .map(|&u| self.changed[u as usize])
            .max()
            .unwrap_or(0)
    }

    /// Work on the triangles whose smallest angle is below the target: flip their edges,
    /// collapse their shortest edge, split their longest one, relax their corners.
    pub fn clean_up(&mut self) -> usize {
        let hi = 4.0 / 3.0;
        let bad: Vec<u32> = (0..self.tris.len() as u32)
            .filter(|&t| {
                self.alive[t as usize] && min_angle_deg(&self.corners(t)) < self.target_angle
            })
            .collect();
        let mut done = 0;
        // A new mode (middle collapses) may fix what the last one could not.
        if self.failed_middle != self.middle {
            self.failed_middle = self.middle;
            self.failed_at.fill(0);
        }
        self.in_batches(
            &bad,
            |r, &t| {
                let tri = r.tris[t as usize];
                match r.check_clean(t, hi) {
                    None => (r.points_box(&tri), None),
                    Some(c) => (r.fans_box(&tri), Some(c)),
                }
            },
            |r, &t, c| {
                let Some(c) = c else {
                    return Wrote::Nothing;
                };
                if !r.apply_clean(t, c) {
                    return Wrote::Nothing;
                }
                done += 1;
                // A split or relaxation in the fallback may move corners: the box after too.
                let tri = r.tris[t as usize];
                Wrote::Also(r.fans_box(&tri))
            },
        );
        done
    }

    /// What [`Self::clean_up`] does to triangle `t`, as far as it can be checked without
    /// changing the surface: `None` if `t` is left alone (gone, no longer below the target, or
    /// failed before with nothing around it changed since); else the flips refused for no gain
    /// (to remember) and the first flip or collapse that passes, if any.
    fn check_clean(&self, t: u32, hi: f64) -> Option<Clean> {
        if !self.alive[t as usize] || min_angle_deg(&self.corners(t)) >= self.target_angle {
            return None;
        }
        if self.failed_at[t as usize] > self.changed_around(&self.tris[t as usize]) {
            return None;
        }
        let e = self.edges_by(t, |a, b| self.len(a, b));
        let mut no_gain = Vec::new();
        for &(_, a, b) in e.iter().rev() {
            match self.check_flip(a, b) {
                Flip::NoGain(u, k) => no_gain.push((u, k)),
                Flip::Refused => {}
                f @ Flip::Do { .. } => {
                    return Some(Clean {
                        no_gain,
                        op: Some(CleanOp::Flip(f)),
                    });
                }
            }
        }
        let f = hi * 1.25;
        let collapse = e
            .iter()
            .find_map(|&(_, a, b)| {
                self.check_collapse(a, b, false, f)
                    .or_else(|| self.check_collapse(b, a, false, f))
            })
            // A needle whose short edge is too long for either end to move onto the other.
            .or_else(|| {
                let (_, a, b) = e[0];
                self.middle
                    .then(|| self.check_collapse(a, b, true, f))
                    .flatten()
            });
        Some(Clean {
            no_gain,
            op: collapse.map(CleanOp::Collapse),
        })
    }

    /// Apply what [`Self::check_clean`] found for `t`, then what cannot be checked ahead: a
    /// cap's split, the corners' relaxation; whether anything changed.
    fn apply_clean(&mut self, t: u32, c: Clean) -> bool {
        for (u, k) in c.no_gain {
            self.apply_flip(Flip::NoGain(u, k));
        }
        let ok = match c.op {
            Some(CleanOp::Flip(f)) => self.apply_flip(f),
            Some(CleanOp::Collapse(c)) => {
                self.apply_collapse(c);
                true
            }
            None => false,
        };
        self.clean_rest(t, ok)
    }

    /// The clean-up's last resorts for triangle `t` when its flips and collapses did nothing
    /// (`done` false): a cap's split, else its corners' relaxation, else `t` is marked failed
    /// until a triangle at its corners changes. Whether anything changed.
    fn clean_rest(&mut self, t: u32, done: bool) -> bool {
        if done {
            return true;
        }
        let tri = self.tris[t as usize];
        // A cap (an angle over 120°): split the edge opposite it.
        let mut ok = false;
        if angles_deg(&self.corners(t)).1 > 120.0 {
            let (_, a, b) = self.edges_by(t, |a, b| self.len(a, b))[2];
            ok = self.split(a, b);
        }
        if !ok {
            for v in tri {
                ok |= self.relax(v);
            }
        }
        if !ok {
            self.clock += 1;
            self.failed_at[t as usize] = self.clock;
        }
        ok
    }

    /// Points to move or split where the output strays from the input: split the longest
    /// non-feature edge of triangle `t` and project the new point.
    pub fn refine_triangle(&mut self, t: u32) -> bool {
        if !self.alive[t as usize] {
            return false;
        }
        // Longest first; equal lengths in the triangle's order.
        let mut e = self.edges_by(t, |a, b| self.len(a, b));
        e.sort_by(|x, y| y.0.total_cmp(&x.0));
        e.iter().any(|&(_, a, b)| self.split(a, b))
    }

    /// The edges `(key, a, b)` of triangle `t`, by increasing `key(a, b)`.
    fn edges_by(&self, t: u32, key: impl Fn(u32, u32) -> f64) -> Vec<(f64, u32, u32)> {
        let tri = self.tris[t as usize];
        let mut e: Vec<(f64, u32, u32)> = (0..3)
            .map(|k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                (key(a, b), a, b)
            })
            .collect();
        e.sort_by(|x, y| x.0.total_cmp(&y.0));
        e
    }

    /// Bring the surface to an input point `p` that triangle `t` is the nearest to but too far
    /// from: split the edge of `t` nearest to `p` and move the new point onto `p` (a point of
    /// the input, so the move costs no distance that way) or, if the checks refuse that, as far
    /// towards it as they allow.
    pub fn refine_toward(&mut self, t: u32, p: P3) -> bool {
        if !self.alive[t as usize] {
            return false;
        }
        let e = self.edges_by(t, |a, b| {
            dist2(
                p,
                closest_on_segment(p, self.pts[a as usize], self.pts[b as usize]),
            )
        });
        for &(_, a, b) in &e {
            let mi = self.pts.len() as u32;
            if self.split(a, b) {
                // All the way if the checks allow, else as far as they do.
                let q = self.pts[mi as usize];
                for f in [1.0, 0.75, 0.5, 0.25] {
                    let x = [0, 1, 2].map(|k| q[k] + f * (p[k] - q[k]));
                    if self.try_move(mi, x) {
                        break;
                    }
                }
                return true;
            }
        }
        false
    }

    /// Number of triangles in the surface.
    pub fn n_alive(&self) -> usize {
        self.alive.iter().filter(|&&x| x).count()
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::{features, guard::InputSamples, median_edge_length, tests::uv_sphere};
    use super::*;

    /// What a [`Remesher`] borrows, for surface `s` at tolerance `d` and edge length `l`, set
    /// up as the stage does (samples spaced `max(d, l/4)`, uniform sizes, 0.7 D working
    /// tolerance).
    pub(super) struct Fixture {
        f: Features,
        index: PatchIndex,
        samples: InputSamples,
        size: Vec<f64>,
        tri_size: Vec<f64>,
    }

    impl Fixture {
        pub(crate) fn new(s: &SurfaceMesh, d: f64, l: f64) -> Fixture {
            Fixture {
                f: features::find(s, 30.0),
                index: PatchIndex::new(&s.points, &s.triangles, &s.sides, None),
                samples: InputSamples::new(s, d.max(l / 4.0)),
                size: vec![l; s.points.len()],
                tri_size: vec![l; s.triangles.len()],
            }
        }

        pub(crate) fn remesher<'a>(&'a self, s: &SurfaceMesh, d: f64, l: f64) -> Remesher<'a> {
            Remesher::new(
                s,
                &self.f,
                &self.index,
                &self.samples,
                None,
                &self.size,
                &self.tri_size,
                l,
                0.7 * d,
            )
        }
    }

    /// A repair can bring closer a surface the rounds left between 0.8 D (the clean-up's
    /// working tolerance) and D: on a sphere pushed out by 0.85 D, a point split into a triangle
    /// goes onto the input at the repairs' working tolerance, and not at the clean-up's (every
    /// new triangle there has samples beyond it, so every move was refused).
    #[test]
    fn repairs_move_a_surface_between_the_working_tolerance_and_d() {
        let input = uv_sphere(1.0, [0.0; 3], 24, 10);
        let (d, l) = (0.02, median_edge_length(&input));
        let fx = Fixture::new(&input, d, l);
        let mut out = input.clone();
        for p in &mut out.points {
            *p = p.map(|x| x * (1.0 + 0.85 * d));
        }
        // Each input sample covered by its own triangle pushed out.
        let cover: Vec<(u32, f64)> = (fx.samples.pts.iter().zip(&fx.samples.tri))
            .map(|(&p, &t)| {
                let c = out.corners(t as usize);
                (t, dist2(p, closest_on_triangle(p, &c)).sqrt())
            })
            .collect();
        assert!(cover.iter().all(|x| x.1 > 0.8 * d && x.1 < d));
        // A triangle of the middle band and the input point nearest its centroid.
        let t = (0..out.triangles.len() as u32)
            .find(|&t| out.corners(t as usize).iter().all(|c| c[2].abs() < 0.5))
            .expect("a band triangle");
        let c = out.corners(t as usize);
        let g = [0, 1, 2].map(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
        let q = (fx.index.get(input.sides[0]))
            .and_then(|b| b.closest(g))
            .expect("input")
            .point;
        let repaired = |tol: f64| {
            let mut r = Remesher::new(
                &out,
                &fx.f,
                &fx.index,
                &fx.samples,
                Some(&cover),
                &fx.size,
                &fx.tri_size,
                l,
                tol,
            );
            r.repairing = true;
            let mi = r.pts.len();
            r.refine_toward(t, q) && r.pts.get(mi) == Some(&q)
        };
        assert!(repaired(super::super::REPAIR_TOL * d));
        assert!(!repaired(0.8 * d));
    }

    /// The distance bounds the loop keeps instead of recomputing are true bounds: after rounds
    /// of every operation on a needle sphere, every input sample is within the tolerance of the
    /// triangle that covers it (by brute force, no farther than its bound), and every
    /// triangle's samples are no farther from the input than its bound.
    #[test]
    fn the_kept_distance_bounds_hold() {
        let s = uv_sphere(1.0, [0.0; 3], 24, 10);
        let l = 0.6 * median_edge_length(&s);
        let d: f64 = 0.02;
        let fx = Fixture::new(&s, d, l);
        let mut r = fx.remesher(&s, d, l);
        let samples = &fx.samples;
        r.spacing = (0.25 * l).max(d);
        for _ in 0..4 {
            r.round();
        }
        r.clean_up();
        let c = r.counts;
        assert!(
            c.splits > 0 && c.collapses > 0 && c.flips > 0 && c.moves > 0,
            "{c:?}"
        );
        let slack = 1e-12;
        for (i, &(t, b)) in r.cover.iter().enumerate() {
            assert!(r.alive[t as usize], "sample {i} covered by a dead triangle");
            assert!(r.covers[t as usize].contains(&(i as u32)));
            let p = samples.pts[i];
            let dist = dist2(p, closest_on_triangle(p, &r.corners(t))).sqrt();
            assert!(
                dist <= b + slack && b <= r.tol + slack,
                "sample {i}: {dist} {b}"
            );
        }
        let input: Vec<[P3; 3]> = (0..s.n_triangles()).map(|t| s.corners(t)).collect();
        let mut checked = 0;
        for t in 0..r.tris.len() {
            let (b, n) = r.dev[t];
            if !r.alive[t] || n == 0 {
                continue;
            }
            let c = r.corners(t as u32);
            assert_eq!(n, r.sample_count(&c));
            let n = n as usize;
            for i in 0..=n {
                for j in 0..=n - i {
                    let k = n - i - j;
                    let w = [i, j, k].map(|x| x as f64 / n as f64);
                    let p = [0, 1, 2].map(|a| w[0] * c[0][a] + w[1] * c[1][a] + w[2] * c[2][a]);
                    let dist = input
                        .iter()
                        .map(|u| dist2(p, closest_on_triangle(p, u)))
                        .fold(f64::INFINITY, f64::min)
                        .sqrt();
                    assert!(dist <= b + slack, "triangle {t}: {dist} > {b}");
                }
            }
            checked += 1;
        }
        assert!(checked > r.n_alive() / 2, "{checked} of {}", r.n_alive());
    }

    /// A flip refusal on record stands only while its two triangles are as they were: after the
    /// points of a sphere are moved far (a loose tolerance lets them), every refusal still on
    /// record is what the angles say now, and some refusals were dropped.
    #[test]
    fn a_recorded_flip_refusal_is_what_the_angles_say() {
        let s = uv_sphere(1.0, [0.0; 3], 16, 8);
        let l = median_edge_length(&s);
        let d: f64 = 0.5;
        let fx = Fixture::new(&s, d, l);
        let mut r = fx.remesher(&s, d, l);
        r.flips();
        let on_record = |r: &Remesher| {
            let mut n = 0;
            for t in 0..r.tris.len() as u32 {
                let tri = r.tris[t as usize];
                for k in 0..3 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    let Some((t1, t2, c, d)) = r.edge_pair(a, b) else {
                        continue;
                    };
                    assert_eq!(t1, t);
                    let seen = r.no_flip[t as usize][k];
                    if seen <= r.changed[t as usize].max(r.changed[t2 as usize]) {
                        continue;
                    }
                    let p = |v: u32| r.pts[v as usize];
                    let old = min_angle_deg(&r.corners(t1)).min(min_angle_deg(&r.corners(t2)));
                    let new =
                        min_angle_deg(&[p(c), p(a), p(d)]).min(min_angle_deg(&[p(d), p(b), p(c)]));
                    assert!(new <= old + 1e-9, "edge {a} {b}: {old} -> {new}");
                    n += 1;
                }
            }
            n
        };
        let before = on_record(&r);
        assert!(before > r.n_alive(), "{before} refusals on record");
        // Move every third point a third of the way to a neighbour, back onto the sphere.
        let mut moved = 0;
        for v in (0..r.pts.len() as u32).step_by(3) {
            let Some(&u) = r.neighbours(v).first() else {
                continue;
            };
            let q = add(
                r.pts[v as usize],
                scale(sub(r.pts[u as usize], r.pts[v as usize]), 0.33),
            );
            moved += r.try_move(v, scale(q, 1.0 / norm(q))) as usize;
        }
        assert!(moved > 10, "{moved} moved");
        let after = on_record(&r);
        assert!(after < before, "{after} of {before} left");
    }
}
