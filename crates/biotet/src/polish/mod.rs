//! Polish: the last pass over the few unforced tets whose smallest dihedral angle is still below
//! the threshold after sliver removal and smoothing. Unforced here includes the tets on needles
//! of 3° or more ([`PolishOptions::needle_deg`]), which the quality report counts as forced: many
//! of them have a better apex.
//!
//! Sliver removal ([`crate::lastresort::improve()`]) has proved, for each of them, that no refill
//! of its cavity with the existing points beats it, so the points must change. For each such
//! tet, worst first, and for each of its interior corners:
//! 1. **move** the corner to raise the smallest dihedral angle of the unforced tets around it
//!    (`relocate`);
//! 2. **remove** it, its star refilled without it with every tet above the threshold (`refill`);
//!
//! then **refill** the tet and its face neighbours with the moved points (`refill`). After
//! these rounds come up to three rounds of Steiner points: each tet still bad (in later rounds
//! only those whose neighbourhood changed) gets one try to **insert** a new interior point
//! strictly inside a small cavity around it, or, for a wedge, in front of its short edge with
//! the stars of that edge's ends refilled (`insert`); then a round of moves around the tets
//! still bad (the new points move too).
//!
//! Last, the **obtuse** step: an unforced tet whose largest dihedral angle is above
//! [`PolishOptions::max_deg`] (its smallest already at or above the threshold) is refilled with
//! its face neighbours, or an interior corner's star refilled without it, or split by one new
//! interior point in its cavity (`obtuse`).
//!
//! Surface points (on a boundary or interface face) never move and are never removed, and no
//! point is added on a boundary or interface face; every accepted change keeps every tet strictly
//! positive (exact `orient3d`) and never lowers a forced tet below its angle before or the
//! threshold. Sequential and in a fixed order, so the result is the same for any number of
//! threads.

mod insert;
mod obtuse;
mod refill;
mod relocate;
mod work;

use std::time::Instant;

use serde::Serialize;

use rayon::prelude::*;
use rustc_hash::FxHashSet;

use crate::lastresort::Searcher;
use crate::mesh::tet::{NO_NEIGHBOR, TetMesh};
use crate::quality::tet::min_dihedral_chord2;
use refill::{Judge, RefillParams};
use relocate::StepParams;
use work::{DEEP_FLAT, Rescue, Work};

/// Options of [`polish`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolishOptions {
    /// Unforced tets whose smallest dihedral angle is below this many degrees are polished.
    pub threshold_deg: f64,
    /// A tet is forced poor when one of its boundary or interface faces has an angle below this
    /// many degrees, or the boundary folds to a wedge below it at one of its edges (as in
    /// [`crate::lastresort::ImproveOptions::forced_deg`]).
    pub forced_deg: f64,
    /// Only a boundary or interface face whose smallest angle is below this many degrees (and
    /// [`Self::forced_deg`]) forces the tets on it here; folds still force below `forced_deg`.
    /// A tet on a needle of a few degrees can have every dihedral angle above the threshold (its
    /// apex in front of the needle's short edge), and polish's points find such apexes for most
    /// of them: 3° by default (brain_20k 1,365 -> 699 tets under 10°, wm_20k 2,390 -> 1,353, the
    /// pipeline 0.99 -> 1.21 s and 1.42 -> 1.83 s; at 2° 636 and 1,219 but wm_20k at 2.0 s, at
    /// 4° 784 and 1,481; below 2° the strip-cut cubes' 1.6° needles cost a second of polish and
    /// none gets better).
    pub needle_deg: f64,
    /// Passes over the tets still bad (a pass only revisits tets that changed).
    pub max_rounds: usize,
    /// Ascent iterations per point move.
    pub move_iterations: usize,
    /// Try removing interior corners (their star refilled without them, every tet above the
    /// threshold).
    pub remove: bool,
    /// Try refilling the tet and its face neighbours (after the moves).
    pub refill: bool,
    /// Try one interior Steiner point per tet still bad after the rounds (see the `insert`
    /// module), then one more round of moves.
    pub insert: bool,
    /// Rounds of insertions (each followed by moves), while one helps; later rounds retry only
    /// the tets whose neighbourhood changed.
    pub insert_rounds: usize,
    /// Where the one-point insertion fails on a wedge (one small angle opposite a short edge),
    /// try a point in front of the short edge with the stars of its ends refilled.
    pub wedge: bool,
    /// Unforced tets whose largest dihedral angle is above this many degrees (their smallest
    /// at or above the threshold) get a last step (see the `obtuse` module); 180 turns it off.
    pub max_deg: f64,
    /// Let the wedge step also search fills above the cavity's worst tet, not only above the
    /// threshold: on brain_20k 7 wedges fixed instead of 3, at 0.07 s (0.5 s on the nested
    /// model). Off by default: the pipeline's time is worth more than those few tets.
    pub wedge_lower_floor: bool,
}

impl Default for PolishOptions {
    fn default() -> PolishOptions {
        PolishOptions {
            threshold_deg: 10.0,
            forced_deg: 10.0,
            needle_deg: 3.0,
            max_rounds: 3,
            move_iterations: 8,
            remove: true,
            refill: true,
            insert: true,
            insert_rounds: 3,
            wedge: true,
            max_deg: 165.0,
            wedge_lower_floor: false,
        }
    }
}

/// A point with more tets around it than this is not removed: no fill of so large a star
/// without it was ever kept (none of 77 tries over 80 tets on the brain models, the corpus and
/// marching-cubes surfaces of random fields, against 62 of 5,300 from 40 to 80), and each try
/// costs milliseconds (a revolved zigzag's polish 0.33 → 0.26 s, the same mesh).
const REMOVE_MAX_STAR: usize = 80;

/// What [`polish`] did. Its counts of tets below the threshold are polish's own: the tets it
/// works on, which take in those on a needle between [`PolishOptions::needle_deg`] and the
/// threshold (the report's forcing counts them as forced).
#[derive(Debug, Clone, Default, Serialize)]
pub struct PolishReport {
    /// Unforced tets (polish's sense, above) below the threshold before.
    pub n_bad_before: usize,
    /// Unforced tets (polish's sense) below the threshold after.
    pub n_bad_after: usize,
    /// Point moves tried.
    pub moves_tried: usize,
    /// Point moves accepted.
    pub moves_accepted: usize,
    /// Point removals (the point's star refilled without it) tried.
    pub removals_tried: usize,
    /// Point removals accepted.
    pub removals_accepted: usize,
    /// Refills of a bad tet and its face neighbours tried.
    pub refills_tried: usize,
    /// Those accepted.
    pub refills_accepted: usize,
    /// Steiner point insertions tried.
    pub inserts_tried: usize,
    /// Those accepted.
    pub inserts_accepted: usize,
    /// Of those, points in front of a wedge's short edge.
    pub wedges_accepted: usize,
    /// Nearly flat unforced tets (under a tenth of the threshold) replaced in the last pass by a
    /// point's tets, all at least half the threshold (possibly more of them below it); and flat
    /// ones (under a thousandth of it) by tets all above a hundredth of it.
    pub flat_rescued: usize,
    /// Points added (inserted and still there at the end).
    pub points_added: usize,
    /// Unforced tets below the threshold before, by interior corners (see
    /// [`PolishReport::bad_by_interior_corners`]).
    pub bad_before_by_interior_corners: [usize; 5],
    /// The unforced tets still below the threshold by how many interior (movable) corners they
    /// have: `[0, 1, 2, 3, 4]`.
    pub bad_by_interior_corners: [usize; 5],
    /// Unforced tets above [`PolishOptions::max_deg`] (and at or above the threshold) before
    /// the obtuse step.
    pub n_obtuse_before: usize,
    /// Those left after it.
    pub n_obtuse_after: usize,
    /// Smallest dihedral angle of an unforced tet after, degrees.
    pub min_unforced_deg: Option<f64>,
    /// Milliseconds spent: `[scan, moves, removals, refills, inserts, obtuse]` (inserts with
    /// the round of moves after them).
    pub ms: [f64; 6],
    /// Wall seconds.
    pub seconds: f64,
}

/// Polish the unforced tets of `mesh` below the threshold (see the module docs). Points on
/// boundary and interface faces keep their coordinates and index; tet order is not kept.
pub fn polish(mesh: &mut TetMesh, opts: &PolishOptions) -> PolishReport {
    let clock = Instant::now();
    let mut report = PolishReport::default();
    let mut w = Work::new(mesh, opts.forced_deg, opts.needle_deg);
    let thr = opts.threshold_deg;
    let params = StepParams {
        iterations: opts.move_iterations,
        step_fraction: 0.25,
        halvings: 8,
        tie: 0.5f64.to_radians(),
    };
    let np0 = w.pts.len();
    let mut bad = scan_all(&mut w, thr);
    report.ms[0] = clock.elapsed().as_secs_f64() * 1e3;
    report.n_bad_before = bad.len();
    report.bad_before_by_interior_corners = by_interior_corners(&w, &bad);
    let rp = RefillParams {
        max_nodes: 100,
        improve_nodes: 0,
        max_tets: 200,
    };
    let mut searcher = Searcher::new();
    let mut star = Vec::new();
    for _ in 0..opts.max_rounds {
        let mut touched: Vec<u32> = Vec::new();
        for &(_, t) in &bad {
            if !w.alive[t as usize] || w.min_angle(t) >= thr {
                continue;
            }
            let c = Instant::now();
            move_corners(
                &mut w,
                t,
                thr,
                &params,
                &mut star,
                &mut report,
                &mut touched,
            );
            report.ms[1] += c.elapsed().as_secs_f64() * 1e3;
            if w.min_angle(t) >= thr {
                continue;
            }
            // Remove an interior corner: its star refilled without it, every tet above the
            // threshold (lower floors find fills that mostly add tets below it, at ten times the
            // cost).
            let mut done = false;
            for v in w.tets[t as usize] {
                if !opts.remove || w.fixed[v as usize] {
                    continue;
                }
                report.removals_tried += 1;
                if !w.star_upto(v, &mut star, REMOVE_MAX_STAR) {
                    continue;
                }
                let c = Instant::now();
                let r = w.refill(
                    &mut searcher,
                    star.clone(),
                    Some(v),
                    true,
                    thr,
                    &rp,
                    Judge::MinAngle,
                );
                report.ms[2] += c.elapsed().as_secs_f64() * 1e3;
                if let Some(ids) = r {
                    report.removals_accepted += 1;
                    touched.extend_from_slice(&ids);
                    done = true;
                    break;
                }
            }
            if done {
                continue;
            }
            if opts.refill
                && try_refill(
                    &mut w,
                    t,
                    thr,
                    &mut searcher,
                    &rp,
                    &mut report,
                    &mut touched,
                )
            {
                continue;
            }
        }
        if touched.is_empty() {
            break;
        }
        // Only tets that changed are retried: the others would fail as before.
        touched.sort_unstable();
        touched.dedup();
        bad = scan(&mut w, &touched, thr);
    }
    let mut bad = scan_all(&mut w, thr);
    if opts.insert {
        let c = Instant::now();
        let mut tried = FxHashSet::default();
        for _ in 0..opts.insert_rounds {
            if !insert_round(
                &mut w,
                &mut bad,
                thr,
                &mut searcher,
                &rp,
                &params,
                &mut star,
                &mut report,
                &mut tried,
                opts.wedge.then_some(opts.wedge_lower_floor),
            ) {
                break;
            }
        }
        // The flat ones, from the scan after the rounds, flattest first (`bad` is sorted; the
        // pass below adds no tet under half the threshold).
        let deep: Vec<(f64, u32)> = bad
            .iter()
            .copied()
            .filter(|x| x.0 < DEEP_FLAT * thr)
            .collect();
        // Last, the nearly flat tets still there: a point whose tets are all at least half the
        // threshold replaces one even with more of them below the threshold.
        // Only those refused before for the count alone: the others would fail again.
        let mut flat = std::mem::take(&mut w.rescuable);
        flat.sort_unstable();
        flat.dedup();
        if !flat.is_empty() {
            w.rescue = Rescue::Flat;
            for t in flat {
                if w.alive[t as usize]
                    && w.min_angle(t) < 0.1 * thr
                    && w.insert(t, thr, &mut searcher, &rp, &params, &mut star)
                        .is_some()
                {
                    report.inserts_accepted += 1;
                    report.flat_rescued += 1;
                }
            }
            w.rescue = Rescue::Off;
        }
        // Then the flat ones (under a thousandth of the threshold), flattest first, each for
        // any fill above a hundredth of it (`Work::insert`): the worst tet is what a solver
        // feels, so this stops at the first that stays (past it, each rescue would only add tets
        // below the threshold without raising the worst).
        w.rescue = Rescue::Deep;
        for (_, t) in deep {
            if !w.alive[t as usize] || w.min_angle(t) >= DEEP_FLAT * thr {
                continue;
            }
            if w.insert(t, thr, &mut searcher, &rp, &params, &mut star)
                .is_none()
            {
                break;
            }
            report.inserts_accepted += 1;
            report.flat_rescued += 1;
        }
        w.rescue = Rescue::Off;
        if report.flat_rescued > 0 {
            moves_after_points(&mut w, &mut bad, thr, &params, &mut star, &mut report);
        }
        report.ms[4] = c.elapsed().as_secs_f64() * 1e3;
    }
    if opts.max_deg < 180.0 {
        let c = Instant::now();
        let (before, after, changed) = obtuse::run(
            &mut w,
            thr,
            opts.max_deg,
            &mut searcher,
            (&rp, &params),
            &mut star,
        );
        report.n_obtuse_before = before;
        report.n_obtuse_after = after;
        report.ms[5] = c.elapsed().as_secs_f64() * 1e3;
        // A refill never adds a tet below the threshold, but may replace one: recount.
        if changed {
            bad = scan_all(&mut w, thr);
        }
    }
    report.n_bad_after = bad.len();
    report.bad_by_interior_corners = by_interior_corners(&w, &bad);
    report.min_unforced_deg = bad.first().map(|x| x.0);
    report.points_added = (np0..w.pts.len())
        .filter(|&i| w.vtet[i] != NO_NEIGHBOR)
        .count();
    w.finish(mesh);
    report.seconds = clock.elapsed().as_secs_f64();
    report
}

/// Refill `t` and its unforced face neighbours of its label; true when accepted.
fn try_refill(
    w: &mut Work,
    t: u32,
    thr: f64,
    searcher: &mut Searcher,
    rp: &RefillParams,
    report: &mut PolishReport,
    touched: &mut Vec<u32>,
) -> bool {
    // The tet and its face neighbours, refilled with the moved points (larger cavities,
    // such as every tet sharing a corner, cost thirty times more for a third more).
    let cav = w.with_face_neighbours(t);
    report.refills_tried += 1;
    let c = Instant::now();
    let r = w.refill(searcher, cav, None, false, thr, rp, Judge::MinAngle);
    report.ms[3] += c.elapsed().as_secs_f64() * 1e3;
    if let Some(ids) = r {
        report.refills_accepted += 1;
        touched.extend_from_slice(&ids);
        return true;
    }
    false
}

/// Move the interior corners of bad tet `t`, one at a time, until it is above `thr`; the moved
/// corners' stars go to `touched`. True when any corner moved.
fn move_corners(
    w: &mut Work,
    t: u32,
    thr: f64,
    params: &StepParams,
    star: &mut Vec<u32>,
    report: &mut PolishReport,
    touched: &mut Vec<u32>,
) -> bool {
    let mut moved = false;
    for v in w.tets[t as usize] {
        if w.fixed[v as usize] {
            continue;
        }
        report.moves_tried += 1;
        if w.relocate(v, thr.to_radians(), params, star) {
            report.moves_accepted += 1;
            touched.extend_from_slice(star);
            moved = true;
        }
        if w.min_angle(t) >= thr {
            break;
        }
    }
    moved
}

/// The live unforced tets of `ts` below `thr` degrees with their angle, worst first. The
/// measures in parallel (read only), the forced test after (it caches).
fn scan(w: &mut Work, ts: &[u32], thr: f64) -> Vec<(f64, u32)> {
    // A trigonometry-free screen first (with a margin: the angle decides).
    let s = (thr.to_radians() / 2.0).sin();
    let lim = 4.0 * s * s * (1.0 + 1e-6);
    let view: &Work = w;
    let mut out: Vec<(f64, u32)> = ts
        .par_iter()
        .filter_map(|&t| {
            if !view.alive[t as usize] || min_dihedral_chord2(&view.corners(t)) > lim {
                return None;
            }
            let a = view.min_angle(t);
            (a < thr).then_some((a, t))
        })
        .collect();
    out.retain(|&(_, t)| !w.is_forced(t));
    out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    out
}

/// [`scan`] over every tet.
fn scan_all(w: &mut Work, thr: f64) -> Vec<(f64, u32)> {
    let all: Vec<u32> = (0..w.tets.len() as u32).collect();
    scan(w, &all, thr)
}

/// How many of `bad` have 0, 1, 2, 3 or 4 interior corners.
fn by_interior_corners(w: &Work, bad: &[(f64, u32)]) -> [usize; 5] {
    let mut out = [0; 5];
    for &(_, t) in bad {
        let n = w.tets[t as usize]
            .iter()
            .filter(|&&v| !w.fixed[v as usize])
            .count();
        out[n] += 1;
    }
    out
}

/// One try at a Steiner point per tet of `bad` still bad, worst first, then one round of moves
/// around the tets still bad (the new points, and those next to them, may now move); `bad`
/// rescanned. True when a point was added.
#[allow(clippy::too_many_arguments)]
fn insert_round(
    w: &mut Work,
    bad: &mut Vec<(f64, u32)>,
    thr: f64,
    searcher: &mut Searcher,
    rp: &RefillParams,
    params: &StepParams,
    star: &mut Vec<u32>,
    report: &mut PolishReport,
    tried: &mut FxHashSet<u64>,
    wedge: Option<bool>,
) -> bool {
    let mut any = false;
    for &(_, t) in bad.iter() {
        if !w.alive[t as usize] || w.min_angle(t) >= thr {
            continue;
        }
        // A tet tried before with the same neighbourhood fails again: only changed ones.
        if !tried.insert(neighbourhood_key(w, t)) {
            continue;
        }
        report.inserts_tried += 1;
        if w.insert(t, thr, searcher, rp, params, star).is_some() {
            report.inserts_accepted += 1;
            any = true;
            continue;
        }
        if let Some(lower) = wedge
            && w.insert_wedge(t, thr, searcher, rp, star, lower).is_some()
        {
            report.inserts_accepted += 1;
            report.wedges_accepted += 1;
            any = true;
        }
    }
    if !any {
        return false;
    }
    moves_after_points(w, bad, thr, params, star, report);
    true
}

/// After points were added: `bad` rescanned, one round of moves around the tets still bad (the
/// new points, and those next to them, may now move), and `bad` rescanned again if one moved.
fn moves_after_points(
    w: &mut Work,
    bad: &mut Vec<(f64, u32)>,
    thr: f64,
    params: &StepParams,
    star: &mut Vec<u32>,
    report: &mut PolishReport,
) {
    *bad = scan_all(w, thr);
    let mut moved = false;
    for &(_, t) in bad.iter() {
        if w.alive[t as usize] && w.min_angle(t) < thr {
            let mut touched = Vec::new();
            moved |= move_corners(w, t, thr, params, star, report, &mut touched);
        }
    }
    if moved {
        *bad = scan_all(w, thr);
    }
}

/// A hash of `t` and its face neighbours: their corners and the corners' coordinates.
fn neighbourhood_key(w: &Work, t: u32) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = rustc_hash::FxHasher::default();
    for s in std::iter::once(t).chain(w.nb[t as usize]) {
        if s == NO_NEIGHBOR {
            s.hash(&mut h);
            continue;
        }
        for v in w.tets[s as usize] {
            v.hash(&mut h);
            for k in w.pts[v as usize] {
                k.to_bits().hash(&mut h);
            }
        }
    }
    h.finish()
}
