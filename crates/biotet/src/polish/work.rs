//! The mesh being polished: tets with tombstones, adjacency, one incident tet per point, which
//! points are fixed (on a boundary or interface face) and which tets the input forces poor.

use crate::mesh::tet::{NO_NEIGHBOR, TET_EDGES, TET_FACES, TetMesh};
use crate::quality::forced::face_forces;
use crate::quality::tet::{dihedral_at, dihedral_yx};
use crate::quality::tri::min_angle_3d_deg;
use rustc_hash::FxHashSet;

pub(super) type P3 = [f64; 3];

/// A closed cavity: its tets, the shell (faces pointing into it) with the tet outside each shell
/// face and that tet's local face.
pub(super) struct Cavity {
    pub tets: Vec<u32>,
    pub shell: Vec<[u32; 3]>,
    pub outer: Vec<(u32, u8)>,
}

pub(super) struct Work {
    pub pts: Vec<P3>,
    pub tets: Vec<[u32; 4]>,
    pub nb: Vec<[u32; 4]>,
    pub labels: Vec<u32>,
    pub alive: Vec<bool>,
    /// One live tet per point ([`NO_NEIGHBOR`] once the point is removed).
    pub vtet: Vec<u32>,
    /// Per point: on a boundary or interface face (never moves, never removed).
    pub fixed: Vec<bool>,
    /// Per tet: 0 unknown, 1 forced, 2 not forced.
    forced: Vec<u8>,
    free: Vec<u32>,
    forced_deg: f64,
    needle_deg: f64,
    /// Which of polish's last passes runs ([`Work::insert`] accepts more in them).
    pub rescue: Rescue,
    /// Tets whose insertion was refused only for that count (the last pass retries these alone).
    pub rescuable: Vec<u32>,
}

/// Polish's last passes, each accepting more than the one before (ordered).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Rescue {
    /// The rounds: an insertion may not add tets below the threshold.
    Off,
    /// A nearly flat tet (under a tenth of the threshold) may go for a few just below it, every
    /// new tet at least half of it.
    Flat,
    /// Also a flat one (under [`DEEP_FLAT`] of the threshold), for any fill above
    /// [`DEEP_FLOOR`] of it.
    Deep,
}

/// Tets under this fraction of the threshold are flat: [`Rescue::Deep`] takes them.
pub const DEEP_FLAT: f64 = 1e-3;

/// Lists of tets up to this long are searched by a scan; longer ones through a set.
const SCAN_LIMIT: usize = 64;

/// Points with more tets than this around them are neither moved nor searched around: a cone's
/// apex (thousands of tets) was tried once per poor tet at it, each try over its whole star (31 s
/// of polish on one model), and one point cannot lift that many tets at once. Interior points
/// have a few dozen.
pub const MAX_STAR: usize = 512;

/// [`Rescue::Deep`] accepts a fill whose every tet is above this fraction of the threshold.
pub const DEEP_FLOOR: f64 = 1e-2;

impl Work {
    pub fn new(mesh: &mut TetMesh, forced_deg: f64, needle_deg: f64) -> Work {
        let n = mesh.tets.len();
        let np = mesh.points.len();
        let mut w = Work {
            pts: std::mem::take(&mut mesh.points),
            tets: std::mem::take(&mut mesh.tets),
            nb: std::mem::take(&mut mesh.neighbors),
            labels: std::mem::take(&mut mesh.labels),
            alive: vec![true; n],
            vtet: vec![NO_NEIGHBOR; np],
            fixed: vec![false; np],
            forced: vec![0; n],
            free: Vec::new(),
            forced_deg,
            needle_deg,
            rescue: Rescue::Off,
            rescuable: Vec::new(),
        };
        for t in 0..n {
            for (i, f) in TET_FACES.iter().enumerate() {
                let o = w.nb[t][i];
                if w.outside(w.labels[t], o) {
                    for &k in f {
                        w.fixed[w.tets[t][k] as usize] = true;
                    }
                }
            }
            for &v in &w.tets[t] {
                w.vtet[v as usize] = t as u32;
            }
        }
        w
    }

    /// Put the (compacted) result back into `mesh`: dead tets and removed points dropped, point
    /// order otherwise kept. In place (a new index is never above the old one), so the mesh is
    /// never held twice: this is the peak of the pipeline's memory otherwise.
    pub fn finish(mut self, mesh: &mut TetMesh) {
        let mut new_pt = vec![u32::MAX; self.pts.len()];
        let mut k = 0usize;
        for (i, slot) in new_pt.iter_mut().enumerate() {
            if self.vtet[i] != NO_NEIGHBOR {
                *slot = k as u32;
                self.pts[k] = self.pts[i];
                k += 1;
            }
        }
        self.pts.truncate(k);
        let mut new_tet = vec![NO_NEIGHBOR; self.tets.len()];
        let mut k = 0u32;
        for (t, slot) in new_tet.iter_mut().enumerate() {
            if self.alive[t] {
                *slot = k;
                k += 1;
            }
        }
        for t in 0..self.tets.len() {
            let new = new_tet[t];
            if new == NO_NEIGHBOR {
                continue;
            }
            let new = new as usize;
            self.tets[new] = self.tets[t].map(|v| new_pt[v as usize]);
            self.nb[new] = self.nb[t].map(|n| {
                if n == NO_NEIGHBOR {
                    n
                } else {
                    new_tet[n as usize]
                }
            });
            self.labels[new] = self.labels[t];
        }
        let k = k as usize;
        self.tets.truncate(k);
        self.nb.truncate(k);
        self.labels.truncate(k);
        *mesh = TetMesh {
            points: self.pts,
            tets: self.tets,
            neighbors: self.nb,
            labels: self.labels,
        };
    }

    pub fn corners(&self, t: u32) -> [P3; 4] {
        self.tets[t as usize].map(|v| self.pts[v as usize])
    }

    /// The smallest dihedral angle of `t`, degrees.
    pub fn min_angle(&self, t: u32) -> f64 {
        min_deg(&self.corners(t))
    }

    /// Whether neighbour `n` (a tet id or [`NO_NEIGHBOR`]) lies outside the region `label`: the
    /// face between is a boundary or interface face, a wall.
    pub fn outside(&self, label: u32, n: u32) -> bool {
        n == NO_NEIGHBOR || self.labels[n as usize] != label
    }

    /// Tet `t` and its unforced face neighbours of its label, sorted.
    pub fn with_face_neighbours(&mut self, t: u32) -> Vec<u32> {
        let label = self.labels[t as usize];
        self.face_ring(&[t], label)
    }

    /// `tets` and their unforced face neighbours of label `label`, sorted.
    pub fn face_ring(&mut self, tets: &[u32], label: u32) -> Vec<u32> {
        let mut out = tets.to_vec();
        for &s in tets {
            for n in self.nb[s as usize] {
                if !self.outside(label, n) && !self.is_forced(n) {
                    out.push(n);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The largest dihedral angle of tet `t`, degrees.
    pub fn max_angle(&self, t: u32) -> f64 {
        crate::quality::tet::dihedral_angles(&self.corners(t))
            .into_iter()
            .fold(0.0, f64::max)
            .to_degrees()
    }

    /// Every live tet with corner `v`, across the faces around `v` (all labels), into `out`,
    /// stopping once it holds more than `limit` tets; whether it is whole.
    pub fn star_upto(&self, v: u32, out: &mut Vec<u32>, limit: usize) -> bool {
        out.clear();
        let start = self.vtet[v as usize];
        if start == NO_NEIGHBOR {
            return true;
        }
        out.push(start);
        // A scan of the list while the star is small, a set past that (a cone's apex holds
        // thousands of tets, and the scans made each star quadratic: 198 s of polish).
        let mut seen: Option<FxHashSet<u32>> = None;
        let mut i = 0;
        while i < out.len() {
            let t = out[i];
            i += 1;
            let tv = self.tets[t as usize];
            for (k, &n) in self.nb[t as usize].iter().enumerate() {
                // Faces containing v are those opposite the other corners.
                if tv[k] == v || n == NO_NEIGHBOR {
                    continue;
                }
                let new = match &mut seen {
                    Some(set) => set.insert(n),
                    None => !out.contains(&n),
                };
                if new {
                    out.push(n);
                    if out.len() > limit {
                        return false;
                    }
                    if seen.is_none() && out.len() > SCAN_LIMIT {
                        seen = Some(out.iter().copied().collect());
                    }
                }
            }
        }
        true
    }

    /// Whether the input forces `t` poor: a boundary or interface face with an angle below the
    /// threshold, or a boundary edge where the region's wedge is below it.
    pub fn is_forced(&mut self, t: u32) -> bool {
        match self.forced[t as usize] {
            1 => true,
            2 => false,
            _ => {
                let f = self.compute_forced(t);
                self.forced[t as usize] = if f { 1 } else { 2 };
                f
            }
        }
    }

    /// [`Self::is_forced`] without filling its cache.
    pub fn forced_now(&self, t: u32) -> bool {
        match self.forced[t as usize] {
            1 => true,
            2 => false,
            _ => self.compute_forced(t),
        }
    }

    fn compute_forced(&self, t: u32) -> bool {
        let tv = self.tets[t as usize];
        if tv.iter().filter(|&&v| self.fixed[v as usize]).count() < 2 {
            return false;
        }
        let label = self.labels[t as usize];
        let lim = self.forced_deg;
        let needle = self.needle_deg.min(lim);
        for (i, l) in TET_FACES.iter().enumerate() {
            let n = self.nb[t as usize][i];
            if !self.outside(label, n) {
                continue;
            }
            let a = min_angle_3d_deg(&l.map(|k| self.pts[tv[k] as usize]));
            if a < needle && face_forces(a, self.min_angle(t), lim) {
                return true;
            }
        }
        for e in TET_EDGES {
            let (a, b) = (tv[e[0]], tv[e[1]]);
            if self.fixed[a as usize] && self.fixed[b as usize] && self.wedge_below(t, a, b, lim) {
                return true;
            }
        }
        false
    }

    /// Whether edge `ab` of `t` is on the region's boundary with the region's wedge there (the
    /// sum of the angles of the region's tets around it) below `lim` degrees. The walk stops
    /// once the partial sum reaches `lim`: the angles are not negative, so the sum only grows.
    fn wedge_below(&self, t: u32, a: u32, b: u32, lim: f64) -> bool {
        let label = self.labels[t as usize];
        let angle_at = |s: u32| {
            let tv = self.tets[s as usize];
            let ia = tv.iter().position(|&v| v == a).unwrap_or(0);
            let ib = tv.iter().position(|&v| v == b).unwrap_or(0);
            let e = TET_EDGES
                .iter()
                .position(|&[x, y]| (x == ia && y == ib) || (x == ib && y == ia))
                .unwrap_or(0);
            dihedral_at(&self.corners(s), e)
        };
        let mut sum = angle_at(t);
        if sum.to_degrees() >= lim {
            return false;
        }
        let mut open = false;
        let tv = self.tets[t as usize];
        for (i, &x) in tv.iter().enumerate() {
            if x == a || x == b {
                continue;
            }
            let (mut prev, mut s) = (t, self.nb[t as usize][i]);
            let mut steps = 0;
            loop {
                if self.outside(label, s) {
                    open = true;
                    break;
                }
                if s == t || steps > 64 {
                    return false;
                }
                steps += 1;
                sum += angle_at(s);
                if sum.to_degrees() >= lim {
                    return false;
                }
                let v = self.tets[s as usize];
                let next = (0..4)
                    .filter(|&k| v[k] != a && v[k] != b)
                    .map(|k| self.nb[s as usize][k])
                    .find(|&n| n != prev)
                    .unwrap_or(NO_NEIGHBOR);
                prev = s;
                s = next;
            }
        }
        open && sum.to_degrees() < lim
    }

    /// The cavity of `tets` (all of one label).
    pub fn cavity(&self, tets: Vec<u32>) -> Cavity {
        let (shell, outer) = if tets.len() <= SCAN_LIMIT {
            crate::mesh::cavity::shell(&tets, &self.tets, &self.nb, |n| tets.contains(&n))
        } else {
            let set: FxHashSet<u32> = tets.iter().copied().collect();
            crate::mesh::cavity::shell(&tets, &self.tets, &self.nb, |n| set.contains(&n))
        };
        Cavity { tets, shell, outer }
    }

    /// Swap the cavity's tets for `new` (which fill it exactly) and stitch the adjacency; the
    /// new tets' ids. Points no new tet uses are marked removed when they lose their last tet.
    pub fn replace(&mut self, cav: &Cavity, new: &[[u32; 4]]) -> Vec<u32> {
        self.replace_in(cav, new, None)
    }

    /// [`Work::replace`], the new tets taking the dead slots `slots` (one per new tet) when
    /// given: an undone change puts the old tets back under their old ids.
    pub fn replace_in(
        &mut self,
        cav: &Cavity,
        new: &[[u32; 4]],
        slots: Option<&[u32]>,
    ) -> Vec<u32> {
        let label = self.labels[cav.tets[0] as usize];
        for &t in &cav.tets {
            self.alive[t as usize] = false;
            self.free.push(t);
            for v in self.tets[t as usize] {
                self.vtet[v as usize] = NO_NEIGHBOR;
            }
        }
        let mut ids = Vec::with_capacity(new.len());
        if let Some(sl) = slots {
            debug_assert_eq!(sl.len(), new.len());
            self.free.retain(|x| !sl.contains(x));
        }
        for (i, tv) in new.iter().enumerate() {
            let t = match slots.map(|sl| sl[i]).or_else(|| self.free.pop()) {
                Some(t) => {
                    self.tets[t as usize] = *tv;
                    self.nb[t as usize] = [NO_NEIGHBOR; 4];
                    self.labels[t as usize] = label;
                    self.alive[t as usize] = true;
                    self.forced[t as usize] = 0;
                    t
                }
                None => {
                    self.tets.push(*tv);
                    self.nb.push([NO_NEIGHBOR; 4]);
                    self.labels.push(label);
                    self.alive.push(true);
                    self.forced.push(0);
                    (self.tets.len() - 1) as u32
                }
            };
            ids.push(t);
        }
        for &t in &ids {
            for v in self.tets[t as usize] {
                self.vtet[v as usize] = t;
            }
        }
        crate::mesh::cavity::stitch(&self.tets, &mut self.nb, &ids, &cav.shell, &cav.outer);
        // Shell corners keep a live tet outside the cavity when no new tet uses them.
        for (f, &(n, _)) in cav.shell.iter().zip(&cav.outer) {
            for &v in f {
                if self.vtet[v as usize] == NO_NEIGHBOR && n != NO_NEIGHBOR {
                    self.vtet[v as usize] = n;
                }
            }
        }
        ids
    }
}

/// The smallest dihedral angle of a tet, degrees: bit for bit the smallest of
/// [`crate::quality::tet::dihedral_angles`], with `atan2` taken only of the edges that can be it.
pub(super) fn min_deg(c: &[P3; 4]) -> f64 {
    let yx = dihedral_yx(c);
    let p = yx.map(pseudo);
    let mut m = f64::INFINITY;
    if p.iter().all(|v| v.is_finite()) {
        let lim = widen(p.iter().copied().fold(f64::INFINITY, f64::min));
        for (e, &[y, x]) in yx.iter().enumerate() {
            if p[e] <= lim {
                m = m.min(y.atan2(x));
            }
        }
    } else {
        for [y, x] in yx {
            m = m.min(y.atan2(x));
        }
    }
    m.to_degrees()
}

/// The dihedral angles (radians) of a tet that may be at most `a` radians, bit for bit those of
/// [`crate::quality::tet::dihedral_angles`]; the others are `f64::INFINITY`.
pub(super) fn angles_upto(c: &[P3; 4], a: f64) -> [f64; 6] {
    let yx = dihedral_yx(c);
    let all = a >= std::f64::consts::PI;
    let lim = if all {
        f64::INFINITY
    } else if a < 0.0 {
        -1.0
    } else {
        widen(pseudo([a.sin(), a.cos()]))
    };
    let p = yx.map(pseudo);
    let all = all || !p.iter().all(|v| v.is_finite());
    let mut out = [f64::INFINITY; 6];
    for (e, &[y, x]) in yx.iter().enumerate() {
        if all || p[e] <= lim {
            out[e] = y.atan2(x);
        }
    }
    out
}

/// A trigonometry-free stand-in for `y.atan2(x)` with `y ≥ 0`: increasing in the angle, from 0
/// to 2, with a small relative error everywhere (no cancellation near 0).
fn pseudo([y, x]: [f64; 2]) -> f64 {
    if x >= 0.0 {
        y / (x + y)
    } else {
        2.0 - y / (y - x)
    }
}

/// A screen's bound loosened far past the rounding of [`pseudo`] and `atan2`, so an angle left
/// out is certainly above the one it is compared with.
fn widen(p: f64) -> f64 {
    p * (1.0 + 1e-9) + 1e-290
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::tet::dihedral_angles;

    /// A star is every tet at the point, whether collected by the scan or past
    /// [`SCAN_LIMIT`] through the set, and one past the limit is reported cut: on an icosphere
    /// coned from its centre (the apex in all 1,280 tets, a surface point in five or six).
    #[test]
    fn stars_are_whole_or_reported_cut() {
        let s = crate::mesh::surface::SurfaceMesh::icosphere(1.0, 3);
        let k = crate::star::kernels(&s).expect("a sphere is star-shaped");
        let ns = s.points.len();
        let (mut mesh, _) = crate::star::coned(&s, &k, &s.points, &[], ns);
        let n = mesh.tets.len();
        assert_eq!(n, s.triangles.len());
        let w = Work::new(&mut mesh, 10.0, 3.0);
        let apex = ns as u32;
        let mut out = Vec::new();
        let cases = [
            (apex, usize::MAX),
            (apex, n),
            (apex, 100),
            (apex, 10),
            (0, usize::MAX),
            (0, 4),
        ];
        for (v, limit) in cases {
            let whole = w.star_upto(v, &mut out, limit);
            let mut all: Vec<u32> = (0..n as u32)
                .filter(|&t| w.tets[t as usize].contains(&v))
                .collect();
            let mut got = out.clone();
            got.sort_unstable();
            assert_eq!(whole, all.len() <= limit, "point {v}, limit {limit}");
            if whole {
                assert_eq!(got, all, "point {v}");
            } else {
                assert_eq!(got.len(), limit + 1);
                all.retain(|t| got.binary_search(t).is_ok());
                assert_eq!(all.len(), got.len(), "point {v}: a tet not at it");
            }
        }
        assert!(!w.star_upto(apex, &mut out, MAX_STAR));
    }

    /// The screened measures are those of `dihedral_angles` bit for bit, on regular, flat,
    /// needle, sliver and random tets (ties between equal angles included).
    #[test]
    fn screened_angles_match_every_angle_bit_for_bit() {
        let mut tets: Vec<[P3; 4]> = vec![
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.0],
            ],
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.5, 0.5, 1e-12],
            ],
            [
                [0.0, 0.0, 0.0],
                [1e-9, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
        ];
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut r = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..2000 {
            tets.push([0, 1, 2, 3].map(|_| [r(), r(), r()]));
        }
        for _ in 0..500 {
            // Slivers: four points near a plane.
            let h = 1e-4 * r();
            tets.push([0, 1, 2, 3].map(|_| [r(), r(), h * r()]));
        }
        for c in &tets {
            let a = dihedral_angles(c);
            let m = a.iter().copied().fold(f64::INFINITY, f64::min).to_degrees();
            assert_eq!(min_deg(c).to_bits(), m.to_bits(), "{c:?}");
            for lim in [0.01, 0.1, 0.2, 1.0, 2.0, 3.2, -1.0] {
                let u = angles_upto(c, lim);
                for e in 0..6 {
                    if a[e] <= lim {
                        assert_eq!(u[e].to_bits(), a[e].to_bits(), "{c:?} {lim}");
                    } else {
                        assert!(u[e] == f64::INFINITY || u[e].to_bits() == a[e].to_bits());
                    }
                }
            }
        }
    }
}
