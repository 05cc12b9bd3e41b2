//! Refill a closed cavity with the LAST RESORT search ([`Searcher`]), optionally without one of
//! its interior points (which is then removed from the mesh).
//!
//! The search's dihedral floor is first the threshold (a fill is then accepted at once), then
//! the cavity's worst tet, so it only explores fills whose every tet beats it; the fill is applied, its forced tets are found (that needs the new adjacency),
//! and it is kept only if the worst unforced tet rises while no more tets than before fall below
//! the threshold; otherwise the old tets are put back.

use rustc_hash::FxHashSet;

use crate::lastresort::{SearchOptions, Searcher};

use super::work::{P3, Work};
use crate::geom::vec3::{cross, dot, norm, sub, volume6};
use crate::quality::tet::min_dihedral_chord2;

/// Search budget of one refill.
#[derive(Debug, Clone, Copy)]
pub(super) struct RefillParams {
    /// Nodes for a first fill.
    pub max_nodes: u64,
    /// Extra nodes looking for a better one.
    pub improve_nodes: u64,
    /// Cavities with more tets are not searched.
    pub max_tets: usize,
}

impl RefillParams {
    /// The search's options for fills whose every tet measures above `floor` degrees by `by`
    /// (for [`Judge::Range`], a largest angle below the cap less what `floor` lacks of the
    /// threshold `thr`).
    pub(super) fn options(&self, floor: f64, by: Judge, thr: f64) -> SearchOptions {
        SearchOptions {
            min_quality: 0.0,
            min_dihedral: floor,
            max_dihedral: match by {
                Judge::MinAngle => 180.0,
                Judge::Range { max_deg } => max_deg + (thr - floor).max(0.0),
            },
            max_nodes: self.max_nodes,
            improve: Some(self.improve_nodes),
        }
    }
}

/// What a refill must improve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Judge {
    /// The smallest dihedral angle.
    MinAngle,
    /// The smallest dihedral angle and, measured as its distance below `max_deg` added to the
    /// threshold, the largest: a tet at 10.2° and 165.6° counts as 9.4° against 10° and 165°.
    Range {
        /// The largest dihedral angle wanted, degrees.
        max_deg: f64,
    },
}

/// The unforced worst measure, overall worst measure and count below `thr` of `tets`.
pub(super) fn judge(w: &mut Work, tets: &[u32], thr: f64, by: Judge) -> (f64, f64, usize) {
    let (mut unforced, mut all, mut below) = (f64::INFINITY, f64::INFINITY, 0);
    for &t in tets {
        let a = match by {
            Judge::MinAngle => w.min_angle(t),
            Judge::Range { max_deg } => w.min_angle(t).min(thr + max_deg - w.max_angle(t)),
        };
        all = all.min(a);
        below += usize::from(a < thr);
        if !w.is_forced(t) {
            unforced = unforced.min(a);
        }
    }
    (unforced, all, below)
}

/// Whether shell face `f` has a point of `cands` making a tet with it whose smallest dihedral
/// angle is above `floor` degrees (chord `lim`). Such a tet is far from flat, so its orientation
/// in floating point is certain.
fn has_candidate(pts: &[P3], f: &[u32; 3], cands: &[u32], lim: f64) -> bool {
    cands.iter().any(|&p| {
        if f.contains(&p) {
            return false;
        }
        let c = [f[0], f[1], f[2], p].map(|v| pts[v as usize]);
        volume6(c[0], c[1], c[2], c[3]) > 0.0 && min_dihedral_chord2(&c) > lim
    })
}

fn chord_of(floor: f64) -> f64 {
    let s = (floor.to_radians() / 2.0).sin();
    4.0 * s * s
}

/// The search's root test, cheaply: every shell face has a point making a tet with it whose
/// smallest dihedral angle is above `floor` degrees; without one no fill exists.
pub(super) fn every_face_has_candidate(
    pts: &[P3],
    shell: &[[u32; 3]],
    cands: &[u32],
    floor: f64,
) -> bool {
    let lim = chord_of(floor);
    shell.iter().all(|f| has_candidate(pts, f, cands, lim))
}

/// How many shell faces have every tet with its fourth corner in the hull of `verts` below
/// `deg` degrees. A tet on face f whose apex is at height H over f's plane has a dihedral angle
/// at an edge of f of at most atan(H / r), r the inradius of f: the apex's projection is at
/// least r from one of f's edge lines on f's side (the edges' signed distances weighted by their
/// lengths sum to twice f's area). With the fill's points in the hull, H is at most the largest
/// height of `verts`. Floating point with a margin of 1e-6 relative, far above its rounding, so
/// a face counted has its tets below `deg` as the angles are measured.
pub(super) fn faces_flat_in_hull(pts: &[P3], shell: &[[u32; 3]], verts: &[u32], deg: f64) -> usize {
    let t = deg.to_radians().tan() * (1.0 - 1e-6);
    shell
        .iter()
        .filter(|f| {
            let q = f.map(|v| pts[v as usize]);
            let n = cross(sub(q[1], q[0]), sub(q[2], q[0]));
            let per: f64 = (0..3).map(|k| norm(sub(q[(k + 1) % 3], q[k]))).sum();
            // Each point's H·|n| against the bound (|n| twice the area, r = |n| / per); the first
            // point above it ends the face's scan, so a cavity that is not flat costs little.
            let lim = t * dot(n, n);
            verts
                .iter()
                .all(|&v| dot(n, sub(pts[v as usize], q[0])).abs() * per < lim)
        })
        .count()
}

/// How many shell faces have no point making a tet with them above `floor` degrees: every fill
/// has a tet below `floor` on each of them.
pub(super) fn faces_without_candidate(
    pts: &[P3],
    shell: &[[u32; 3]],
    cands: &[u32],
    floor: f64,
) -> usize {
    let lim = chord_of(floor);
    shell
        .iter()
        .filter(|f| !has_candidate(pts, f, cands, lim))
        .count()
}

impl Work {
    /// Refill the cavity of `tets` (one label), without point `drop` if given; the new tets when
    /// accepted (better by `by`). With `perfect_only`, only fills whose every tet is above the
    /// threshold are searched.
    #[allow(clippy::too_many_arguments)]
    pub fn refill(
        &mut self,
        searcher: &mut Searcher,
        tets: Vec<u32>,
        drop: Option<u32>,
        perfect_only: bool,
        thr: f64,
        p: &RefillParams,
        by: Judge,
    ) -> Option<Vec<u32>> {
        if tets.len() > p.max_tets {
            return None;
        }
        let label = self.labels[tets[0] as usize];
        if tets.iter().any(|&t| self.labels[t as usize] != label) {
            return None;
        }
        let old = judge(self, &tets, thr, by);
        let cav = self.cavity(tets);
        let on_shell: FxHashSet<u32> = cav.shell.iter().flatten().copied().collect();
        if drop.is_some_and(|v| on_shell.contains(&v)) {
            return None;
        }
        let mut inner: Vec<u32> = cav
            .tets
            .iter()
            .flat_map(|&t| self.tets[t as usize])
            .filter(|v| !on_shell.contains(v) && Some(*v) != drop)
            .collect();
        inner.sort_unstable();
        inner.dedup();
        // First every tet above the threshold (any such fill is accepted), then, unless only that
        // is wanted, anything above the worst tet.
        let mut floors = vec![thr];
        if !perfect_only && old.1 < thr {
            floors.push(old.1.max(0.0) * (1.0 + 1e-9));
        }
        let mut fill = None;
        let mut cands: Vec<u32> = on_shell
            .iter()
            .copied()
            .chain(inner.iter().copied())
            .collect();
        cands.sort_unstable();
        for floor in floors {
            if !every_face_has_candidate(&self.pts, &cav.shell, &cands, floor) {
                continue;
            }
            let so = p.options(floor, by, thr);
            if let Ok(f) = searcher.fill_carved(&self.pts, &cav.shell, &inner, &so) {
                fill = Some(f);
                break;
            }
        }
        let fill = fill?;
        let old_tets: Vec<[u32; 4]> = cav.tets.iter().map(|&t| self.tets[t as usize]).collect();
        let ids = self.replace(&cav, &fill.tets);
        let new = judge(self, &ids, thr, by);
        if new.0 > old.0 && new.1 >= old.1 && new.2 <= old.2 {
            return Some(ids);
        }
        let back = self.cavity(ids);
        self.replace_in(&back, &old_tets, Some(&cav.tets));
        None
    }
}
