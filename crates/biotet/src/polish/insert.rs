//! Steiner points: fix an unforced tet below the threshold with one new interior point.
//!
//! The cavity is the tet and its unforced face neighbours of the same label, or, when that fails,
//! every unforced tet of its label sharing an edge with it, or else the face cavity with its
//! unforced face neighbours of the label (a cavity with an interior point is not tried), or else
//! Delaunay refinement's cavity for its circumcentre, and for a tet on two walls those of the
//! tets inside it. A nearly flat tet's last chance (polish's rescue pass) starts from two rings
//! of face neighbours.
//! Boundary and interface faces are never crossed, so they stay on the cavity's shell.
//! The candidates are the tet's centroid and circumcentre, the centroids of the cavity's tets, the
//! midpoints between the tet's centroid and theirs, the shell's vertex centroid, and points pushed
//! into the shell's kernel from the two centroids (cyclic projection, floating point).
//! - If some candidate is seen strictly on the inner side of every shell face (exact `orient3d`),
//!   the shell is star-shaped from it and its cone fills the cavity exactly: the candidate with
//!   the best cone is added, the cavity coned to it, and the point moved to raise its star's worst
//!   unforced angle ([`Work::relocate`]).
//! - Otherwise the candidate strictly inside a cavity tet (exact) that makes a tet above the
//!   threshold with the most shell faces is added, and only the search can fill the cavity.
//!
//! Unless every tet is then above the threshold, the LAST RESORT search refills the cavity with
//! the point as an inner point every fill uses: first every tet above the threshold, then (face
//! cavities only) every tet above the cavity's worst before. The result is kept only if the
//! cavity's worst unforced angle rises, its worst angle does not fall and no more of its tets are
//! below the threshold; otherwise the old tets come back under their ids and the point is dropped.
//!
//! A wedge (one small angle, at the edge opposite a short one, mostly a short surface edge) that
//! this leaves gets one more try ([`Work::insert_wedge`]): one point in front of the short edge
//! and the stars of its two ends refilled around it.

use rustc_hash::FxHashSet;

use crate::geom::predicates::{Sign, in_exact_range, orient3d};
use crate::geom::vec3::{add, cross, dot, norm2, scale, sub, volume6};
use crate::lastresort::Searcher;
use crate::mesh::tet::{NO_NEIGHBOR, TET_EDGES};
use crate::quality::tet::{circumcentre, dihedral_angles, min_dihedral_chord2};

use super::refill::{
    Judge, RefillParams, every_face_has_candidate, faces_flat_in_hull, faces_without_candidate,
    judge,
};
use super::relocate::StepParams;
use super::work::{Cavity, DEEP_FLAT, DEEP_FLOOR, MAX_STAR, P3, Rescue, Work};

impl Work {
    /// Try to raise `t` (unforced, below `thr` degrees) with one new interior point; the new
    /// tets when accepted. `star` is scratch.
    pub fn insert(
        &mut self,
        t: u32,
        thr: f64,
        searcher: &mut Searcher,
        rp: &RefillParams,
        sp: &StepParams,
        star: &mut Vec<u32>,
    ) -> Option<Vec<u32>> {
        let label = self.labels[t as usize];
        let faces = self.with_face_neighbours(t);
        let by = Judge::MinAngle;
        // A nearly flat tet's last chance starts from two rings of face neighbours: the more room
        // around the new point, the fewer of its tets below the threshold (brain_20k rescues two
        // tets so, wm_20k one, the square-section ring tube ten).
        let mut tried = Vec::new();
        if self.rescue >= Rescue::Flat {
            let ring = self.face_ring(&faces, label);
            let wide = self.face_ring(&ring, label);
            if wide != faces {
                if let Some(ids) =
                    self.insert_into(t, wide.clone(), thr, searcher, rp, sp, star, by)
                {
                    return Some(ids);
                }
                tried.push(wide);
            }
        }
        if let Some(ids) = self.insert_into(t, faces.clone(), thr, searcher, rp, sp, star, by) {
            return Some(ids);
        }
        // Every tet of the label sharing an edge (two corners) with t.
        let tv = self.tets[t as usize];
        let mut edges = Vec::new();
        for v in tv {
            if !self.star_upto(v, star, MAX_STAR) {
                edges.clear();
                break;
            }
            for &s in star.iter() {
                let shared = self.tets[s as usize]
                    .iter()
                    .filter(|x| tv.contains(x))
                    .count();
                if shared >= 2 && self.labels[s as usize] == label && (s == t || !self.is_forced(s))
                {
                    edges.push(s);
                }
            }
        }
        edges.sort_unstable();
        edges.dedup();
        if !edges.is_empty()
            && edges != faces
            && let Some(ids) = self.insert_into(t, edges.clone(), thr, searcher, rp, sp, star, by)
        {
            return Some(ids);
        }
        // The face cavity and its face neighbours (past the edge cavity where a wedge's far
        // edge or a sliver's neighbours need a point further out).
        let ring = self.face_ring(&faces, label);
        if ring != faces
            && ring != edges
            && let Some(ids) = self.insert_into(t, ring.clone(), thr, searcher, rp, sp, star, by)
        {
            return Some(ids);
        }
        // The tets whose circumspheres hold t's circumcentre (Delaunay refinement's cavity): in a
        // domain thinner than the template's sealing zones (a thin tube) no interior node was
        // placed, t spans it from wall to wall, and only a point on its axis with every tet of
        // that cross-section refilled around it helps. A tet on two walls (a cap: the flat tet the
        // Delaunay leaves on a planar quad of cocircular corners) has no useful circumcentre of its
        // own: the balls of the unforced tets inside it, each grown from it, are Delaunay
        // refinement's cavities there (TetGen's `q` puts one point in each segment of a
        // square-section ring tube).
        tried.extend([faces, edges, ring]);
        let mut seeds = vec![t];
        if self.on_two_walls(t) {
            for n in self.nb[t as usize] {
                if !self.outside(label, n) && !self.is_forced(n) {
                    seeds.push(n);
                }
            }
        }
        for s in seeds {
            let Some(ball) = circumcentre(&self.corners(s))
                .and_then(|x| self.circumsphere_cavity(t, x, rp.max_tets))
                .filter(|b| !tried.contains(b))
            else {
                continue;
            };
            if let Some(ids) = self.insert_into(t, ball.clone(), thr, searcher, rp, sp, star, by) {
                return Some(ids);
            }
            tried.push(ball);
        }
        None
    }

    /// Whether `t` lies on two or more boundary or interface faces (its shape is not looked at).
    fn on_two_walls(&self, t: u32) -> bool {
        let label = self.labels[t as usize];
        self.nb[t as usize]
            .iter()
            .filter(|&&n| self.outside(label, n))
            .count()
            >= 2
    }

    /// `t` and the unforced tets of its label whose circumsphere strictly holds `x`, reached from
    /// `t` through faces (so never across a boundary or interface face), sorted; at most `max`
    /// (else `None`). Floating point: it only chooses the cavity, whose use is decided
    /// exactly by [`Self::insert_into`].
    fn circumsphere_cavity(&self, t: u32, x: P3, max: usize) -> Option<Vec<u32>> {
        let label = self.labels[t as usize];
        crate::mesh::cavity::circumsphere_cavity(
            t,
            x,
            max,
            &self.nb,
            |n| self.corners(n),
            |n| !self.outside(label, n) && !self.forced_now(n),
        )
    }

    /// A wedge: `t`'s one small angle, at edge `cd`, comes from the short opposite edge `ab`
    /// (two points close together, mostly a short surface edge), so any fill where the far edge
    /// `cd` sees both `a` and `b` keeps it. One point in front of `ab`, four times its length
    /// towards `cd`, with the stars of `a` and `b` refilled around it, can give `ab` a ring of
    /// near points. The search fills the stars with it as the one inner point (every tet above
    /// the threshold, then, with `lower`, above the cavity's worst); kept only if the cavity's
    /// worst unforced angle rises, its worst does not fall and fewer of its tets are below the
    /// threshold.
    pub fn insert_wedge(
        &mut self,
        t: u32,
        thr: f64,
        searcher: &mut Searcher,
        rp: &RefillParams,
        star: &mut Vec<u32>,
        lower: bool,
    ) -> Option<Vec<u32>> {
        let c = self.corners(t);
        let ang = dihedral_angles(&c);
        let e = (0..6).min_by(|&i, &j| ang[i].total_cmp(&ang[j]))?;
        let [ic, id] = TET_EDGES[e];
        let [ia, ib] = TET_EDGES[5 - e];
        // One small angle, none near flat (not a sliver or a cap), the opposite edge short.
        let lo = thr.to_radians();
        let lab2 = norm2(sub(c[ia], c[ib]));
        if ang.iter().filter(|&&x| x < lo).count() != 1
            || ang.iter().any(|&x| x > std::f64::consts::PI - 3.0 * lo)
            || lab2 > 0.25 * norm2(sub(c[ic], c[id]))
        {
            return None;
        }
        let tv = self.tets[t as usize];
        let label = self.labels[t as usize];
        let mut tets = Vec::new();
        for v in [tv[ia], tv[ib]] {
            if !self.star_upto(v, star, MAX_STAR) {
                return None;
            }
            for &s in star.iter() {
                if self.labels[s as usize] == label && !self.is_forced(s) {
                    tets.push(s);
                }
            }
        }
        tets.sort_unstable();
        tets.dedup();
        if tets.len() > rp.max_tets {
            return None;
        }
        let (cav, on_shell) = self.cavity_of_shell_points(tets)?;
        let m = scale(add(c[ia], c[ib]), 0.5);
        let dir = sub(scale(add(c[ic], c[id]), 0.5), m);
        let ld = norm2(dir).sqrt();
        if ld == 0.0 || lab2 == 0.0 {
            return None;
        }
        let x = add(m, scale(dir, (4.0 * lab2.sqrt()).min(0.5 * ld) / ld));
        if !x.iter().all(|&v| in_exact_range(v)) || !self.strictly_inside(&cav.tets, x) {
            return None;
        }
        let old = judge(self, &cav.tets, thr, Judge::MinAngle);
        let p = self.pts.len() as u32;
        let mut cands: Vec<u32> = on_shell.iter().copied().chain([p]).collect();
        cands.sort_unstable();
        self.pts.push(x);
        let mut out = None;
        for floor in [thr, old.1.max(0.0) * (1.0 + 1e-9)] {
            if floor < thr && !lower {
                break;
            }
            // A fill has a tet below the threshold on at least a quarter of the faces without a
            // point above it: no fewer than before, no fill can pass.
            if floor < thr
                && faces_without_candidate(&self.pts, &cav.shell, &cands, thr).div_ceil(4) + 1
                    > old.2
            {
                break;
            }
            if !every_face_has_candidate(&self.pts, &cav.shell, &cands, floor) {
                continue;
            }
            let Ok(f) = searcher.fill_carved(
                &self.pts,
                &cav.shell,
                &[p],
                &rp.options(floor, Judge::MinAngle, thr),
            ) else {
                continue;
            };
            self.vtet.push(NO_NEIGHBOR);
            self.fixed.push(false);
            let old_tets: Vec<[u32; 4]> = cav.tets.iter().map(|&s| self.tets[s as usize]).collect();
            let ids = self.replace(&cav, &f.tets);
            let new = judge(self, &ids, thr, Judge::MinAngle);
            if new.0 > old.0 && new.1 >= old.1 && new.2 < old.2 {
                out = Some(ids);
            } else {
                let back = self.cavity(ids);
                self.replace_in(&back, &old_tets, Some(&cav.tets));
                debug_assert_eq!(self.vtet[p as usize], NO_NEIGHBOR);
                self.vtet.pop();
                self.fixed.pop();
            }
            break;
        }
        if out.is_none() {
            self.pts.pop();
        }
        out
    }

    /// The cavity of `tets` and its shell's points, if every corner of its tets is on its shell
    /// (an inner point would be lost: the refill takes the new point as its only inner point).
    fn cavity_of_shell_points(&self, tets: Vec<u32>) -> Option<(Cavity, FxHashSet<u32>)> {
        let cav = self.cavity(tets);
        let on_shell: FxHashSet<u32> = cav.shell.iter().flatten().copied().collect();
        let lost = cav
            .tets
            .iter()
            .any(|&s| self.tets[s as usize].iter().any(|v| !on_shell.contains(v)));
        (!lost).then_some((cav, on_shell))
    }

    /// Whether `x` is strictly inside one of `tets` (exact).
    fn strictly_inside(&self, tets: &[u32], x: P3) -> bool {
        tets.iter().any(|&s| {
            let c = self.corners(s);
            (0..4).all(|k| {
                let mut d = c;
                d[k] = x;
                orient3d(d[0], d[1], d[2], d[3]) == Sign::Positive
            })
        })
    }

    /// One new interior point in the cavity `tets` around `t`, kept when the cavity's worst
    /// measure (`by`) rises (see the module documentation); the new tets when kept.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn insert_into(
        &mut self,
        t: u32,
        tets: Vec<u32>,
        thr: f64,
        searcher: &mut Searcher,
        rp: &RefillParams,
        sp: &StepParams,
        star: &mut Vec<u32>,
        by: Judge,
    ) -> Option<Vec<u32>> {
        if tets.len() > rp.max_tets {
            return None;
        }
        // Past the face cavity (at most five tets), only fills with every tet above the
        // threshold are searched: the lower floor's fills there cost twice as much per
        // insertion kept.
        let large = tets.len() > 5;
        let (cav, on_shell) = self.cavity_of_shell_points(tets)?;
        // Shell faces on which every fill has a tet below the threshold, wherever the point
        // goes: more of them than the cavity's tets below it now rule out the cone; a quarter
        // as many more (or a large cavity) the lower floor's search; one below half the
        // threshold a rescue. On a thin box whose faces are gridded much coarser than its
        // thickness, a third of the insertions end here without placing a point. The cavity is
        // judged here only when such a face exists (judging costs more than the count).
        let mut judged = None;
        if self.rescue == Rescue::Off {
            let verts: Vec<u32> = on_shell.iter().copied().collect();
            let doomed = faces_flat_in_hull(&self.pts, &cav.shell, &verts, thr);
            if doomed > 0 {
                let old = judge(self, &cav.tets, thr, by);
                if doomed > old.2
                    && (large || doomed.div_ceil(4) > old.2)
                    && faces_flat_in_hull(&self.pts, &cav.shell, &verts, 0.5 * thr) > 0
                {
                    return None;
                }
                judged = Some(old);
            }
        }
        let (x, cone_ok) = self.best_point(t, &cav.tets, &cav.shell, thr)?;
        let old = match judged {
            Some(old) => old,
            None => judge(self, &cav.tets, thr, by),
        };
        // In the last pass, a flat tet (under a thousandth of the threshold: gmsh's t13 kept two
        // at 3e-15°, a solver's stiffness matrix then singular to round-off) is traded for any
        // fill whose every tet is above a hundredth of it, however many are then below it.
        let deep = self.rescue == Rescue::Deep && old.1 < DEEP_FLAT * thr;
        let old_tets: Vec<[u32; 4]> = cav.tets.iter().map(|&s| self.tets[s as usize]).collect();
        let p = self.pts.len() as u32;
        self.pts.push(x);
        self.vtet.push(NO_NEIGHBOR);
        self.fixed.push(false);
        // With a star-shaped shell, the cone, the point moved; otherwise the old tets, and only a
        // fill the search finds replaces them.
        let (mut ids, mut new) = if cone_ok {
            let cone: Vec<[u32; 4]> = cav.shell.iter().map(|f| [f[0], f[1], f[2], p]).collect();
            let ids = self.replace(&cav, &cone);
            self.relocate(p, thr.to_radians(), sp, star);
            let new = judge(self, &ids, thr, by);
            (ids, new)
        } else {
            (
                cav.tets.clone(),
                (f64::NEG_INFINITY, f64::NEG_INFINITY, usize::MAX),
            )
        };
        let mut filled = cone_ok;
        if new.2 > 0 {
            // The search, with the point as the one inner point: first every tet above the
            // threshold, then every tet above the cavity's worst before and the cone's (any other
            // fill would be rejected, or replace a better cone: a box whose only fill of its
            // corners has a flat tet got a cone at 9.8° and then a search fill through the same
            // flat tet, and kept neither).
            let mut cands: Vec<u32> = on_shell.iter().copied().chain([p]).collect();
            cands.sort_unstable();
            // A tet covers at most four shell faces, so a fill has at least a quarter of the faces
            // with no tet above the threshold below it: more than before, and no fill can pass.
            let poor = faces_without_candidate(&self.pts, &cav.shell, &cands, thr);
            // A flat tet's rescue takes only fills its acceptance would keep (every tet above
            // a hundredth of the threshold): with the cavity's worst as the floor, the search
            // found fills through another flat tet of the same planar quad, and nothing else.
            let mut lower = old.1.max(new.1).max(0.0) * (1.0 + 1e-9);
            if deep {
                lower = lower.max(DEEP_FLOOR * thr);
            }
            for floor in [thr, lower] {
                if floor < thr && (large || poor.div_ceil(4) > old.2) && !deep {
                    break;
                }
                if !every_face_has_candidate(&self.pts, &cav.shell, &cands, floor) {
                    continue;
                }
                let so = rp.options(floor, by, thr);
                let r = searcher.fill_carved(&self.pts, &cav.shell, &[p], &so);
                if let Ok(f) = r {
                    let cur = self.cavity(ids);
                    ids = self.replace(&cur, &f.tets);
                    new = judge(self, &ids, thr, by);
                    filled = true;
                    break;
                }
            }
        }
        // In the last pass, a nearly flat worst tet (under a tenth of the threshold) may go for a
        // few just below the threshold: every new tet at least half of it (a box folded by
        // round-off kept a 0.00° tet whose cone from one point is at 9.8°). Only last: earlier,
        // such a trade can block a later fix that leaves none below the threshold.
        let flat_out = old.1 < 0.1 * thr && new.1 >= 0.5 * thr;
        let deep_out = deep && new.1 >= DEEP_FLOOR * thr;
        let last = self.rescue >= Rescue::Flat;
        if new.0 > old.0 && new.1 >= old.1 && (new.2 <= old.2 || (last && flat_out) || deep_out) {
            return Some(ids);
        }
        if flat_out && new.0 > old.0 && !last {
            self.rescuable.push(t);
        }
        if filled {
            let back = self.cavity(ids);
            self.replace_in(&back, &old_tets, Some(&cav.tets));
        }
        debug_assert_eq!(self.vtet[p as usize], NO_NEIGHBOR);
        self.pts.pop();
        self.vtet.pop();
        self.fixed.pop();
        None
    }

    /// The candidate point whose cone over `shell` has the largest smallest dihedral angle among
    /// those strictly inside every shell face's half-space (exact), with `true`; when there is
    /// none, the candidate strictly inside a tet of `tets` (exact) that makes a tet above `thr`
    /// degrees with the most shell faces, with `false`.
    fn best_point(&self, t: u32, tets: &[u32], shell: &[[u32; 3]], thr: f64) -> Option<(P3, bool)> {
        let c = self.corners(t);
        let ct = centroid(&c);
        let mut cands = vec![ct];
        if let Some(o) = circumcentre(&c) {
            cands.push(o);
        }
        for &s in tets {
            if s != t {
                let cs = centroid(&self.corners(s));
                cands.push(cs);
                cands.push(scale(add(ct, cs), 0.5));
            }
        }
        let mut sum = [0.0; 3];
        let mut n = 0;
        let mut seen: Vec<u32> = shell.iter().flatten().copied().collect();
        seen.sort_unstable();
        seen.dedup();
        for &v in &seen {
            sum = add(sum, self.pts[v as usize]);
            n += 1;
        }
        let sc = scale(sum, 1.0 / n as f64);
        cands.push(sc);
        // Points pushed into the shell's kernel (cyclic projection onto the faces' half-spaces
        // moved inward by a margin), from the tet's and the shell's centroids.
        let planes: Vec<(P3, P3)> = shell
            .iter()
            .filter_map(|f| {
                let q = [f[0], f[1], f[2]].map(|v| self.pts[v as usize]);
                let nv = cross(sub(q[1], q[0]), sub(q[2], q[0]));
                let l = norm2(nv).sqrt();
                (l > 0.0).then(|| (q[0], scale(nv, 1.0 / l)))
            })
            .collect();
        let vol: f64 = tets
            .iter()
            .map(|&s| {
                let c = self.corners(s);
                volume6(c[0], c[1], c[2], c[3]) / 6.0
            })
            .sum();
        let h = vol.max(0.0).cbrt();
        for start in [ct, sc] {
            for m in [0.2, 0.07, 0.02] {
                if let Some(x) = kernel_point(&planes, start, m * h) {
                    cands.push(x);
                }
            }
        }
        let mut scored: Vec<(f64, usize)> = Vec::new();
        'c: for (i, x) in cands.iter().enumerate() {
            if !x.iter().all(|&k| in_exact_range(k)) {
                continue;
            }
            // Every face sees it (floating point first), then the cone's worst tet.
            for f in shell {
                let q = [f[0], f[1], f[2]].map(|v| self.pts[v as usize]);
                if volume6(q[0], q[1], q[2], *x) <= 0.0 {
                    continue 'c;
                }
            }
            let mut worst = f64::INFINITY;
            for f in shell {
                let q = [f[0], f[1], f[2]].map(|v| self.pts[v as usize]);
                worst = worst.min(min_dihedral_chord2(&[q[0], q[1], q[2], *x]));
            }
            if worst.is_finite() {
                scored.push((worst, i));
            }
        }
        scored.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let star = scored.into_iter().map(|(_, i)| cands[i]).find(|x| {
            shell.iter().all(|f| {
                let q = [f[0], f[1], f[2]].map(|v| self.pts[v as usize]);
                orient3d(q[0], q[1], q[2], *x) == Sign::Positive
            })
        });
        if let Some(x) = star {
            return Some((x, true));
        }
        let s = (thr.to_radians() / 2.0).sin();
        let lim = 4.0 * s * s;
        let mut best: Option<(usize, P3)> = None;
        for x in cands {
            if !x.iter().all(|&k| in_exact_range(k)) {
                continue;
            }
            let inside = tets.iter().any(|&s| {
                let c = self.corners(s);
                let sees = |k: usize| {
                    let mut d = c;
                    d[k] = x;
                    d
                };
                (0..4).all(|k| {
                    let d = sees(k);
                    volume6(d[0], d[1], d[2], d[3]) > 0.0
                }) && (0..4).all(|k| {
                    let d = sees(k);
                    orient3d(d[0], d[1], d[2], d[3]) == Sign::Positive
                })
            });
            if !inside {
                continue;
            }
            let floor = best.map_or(0, |b| b.0);
            let mut served = 0;
            for (i, f) in shell.iter().enumerate() {
                if served + (shell.len() - i) <= floor {
                    break;
                }
                let q = [f[0], f[1], f[2]].map(|v| self.pts[v as usize]);
                let c = [q[0], q[1], q[2], x];
                if volume6(c[0], c[1], c[2], c[3]) > 0.0 && min_dihedral_chord2(&c) > lim {
                    served += 1;
                }
            }
            if best.is_none() || served > floor {
                best = Some((served, x));
            }
        }
        best.map(|b| (b.1, false))
    }
}

/// A point at least `margin` inside every plane `(point, unit inward normal)`, by cyclic
/// projection from `x` (floating point; the caller decides exactly).
fn kernel_point(planes: &[(P3, P3)], mut x: P3, margin: f64) -> Option<P3> {
    for _ in 0..40 {
        let mut worst = (0.0, usize::MAX);
        for (i, (q, n)) in planes.iter().enumerate() {
            let d = dot(*n, sub(x, *q)) - margin;
            if d < worst.0 {
                worst = (d, i);
            }
        }
        if worst.1 == usize::MAX {
            return Some(x);
        }
        x = add(x, scale(planes[worst.1].1, -worst.0 * 1.01));
    }
    None
}

fn centroid(c: &[P3; 4]) -> P3 {
    scale(add(add(c[0], c[1]), add(c[2], c[3])), 0.25)
}
