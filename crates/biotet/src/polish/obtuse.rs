//! The obtuse step: unforced tets whose largest dihedral angle is above the cap while their
//! smallest is at or above the threshold (the rounds before look at the smallest only, and
//! smoothing can leave such a tet: on the MNI brain image 3 of 4 million, at 165.3–165.6°).
//!
//! Each, worst first, is refilled with its unforced face neighbours of its label, else an
//! interior corner's star is refilled without that corner, else one new interior point is put
//! in its face cavity, the ring around it or the ring around that (as polish's insertions are,
//! with fills searched for tets inside the range only: a tet with its four
//! corners on the surface, two faces on a ridge, has nothing else to change); a change is
//! accepted only when the cavity's worst measure rises, the measure being the smallest angle
//! and, for the largest, its distance below the cap added to the threshold ([`Judge::Range`]),
//! and no tet falls below the threshold that was not. Points on the surface never move.

use rayon::prelude::*;

use crate::lastresort::Searcher;
use crate::quality::tet::max_dihedral_chord2;

use super::refill::{Judge, RefillParams};
use super::relocate::StepParams;
use super::work::Work;

/// Refill budget: the fill with the best worst tet is wanted, not the first.
const PARAMS: RefillParams = RefillParams {
    max_nodes: 200,
    improve_nodes: 400,
    max_tets: 200,
};

/// Run the step (`rp` and `sp` are the insertions' search and move parameters); returns the
/// obtuse tets before and after, and whether any tet changed.
pub(super) fn run(
    w: &mut Work,
    thr: f64,
    max_deg: f64,
    searcher: &mut Searcher,
    (rp, sp): (&RefillParams, &StepParams),
    star: &mut Vec<u32>,
) -> (usize, usize, bool) {
    let by = Judge::Range { max_deg };
    let todo = obtuse(w, thr, max_deg);
    let before = todo.len();
    // Only the listed tets and the refills' new ones can be obtuse after.
    let mut check: Vec<u32> = todo.iter().map(|&(_, t)| t).collect();
    for &(_, t) in &todo {
        if !w.alive[t as usize] || w.is_forced(t) || w.max_angle(t) <= max_deg {
            continue;
        }
        let cav = w.with_face_neighbours(t);
        if let Some(ids) = w.refill(searcher, cav, None, false, thr, &PARAMS, by) {
            check.extend(ids);
            continue;
        }
        let mut done = false;
        for v in w.tets[t as usize] {
            if w.fixed[v as usize] {
                continue;
            }
            // A star past the refill's bound is refused by it: not collected whole.
            if !w.star_upto(v, star, PARAMS.max_tets) {
                continue;
            }
            if let Some(ids) = w.refill(searcher, star.clone(), Some(v), true, thr, &PARAMS, by) {
                check.extend(ids);
                done = true;
                break;
            }
        }
        if done {
            continue;
        }
        // No interior corner, or none helps (four corners on the surface, two faces on a
        // shallow ridge): one new interior point in its face cavity, else the rings of face
        // neighbours around it, accepted as polish's insertions are, by the range.
        let faces = w.with_face_neighbours(t);
        let mut got = w.insert_into(t, faces.clone(), thr, searcher, rp, sp, star, by);
        if got.is_none() && w.alive[t as usize] {
            // The ring, then the ring around it (an interface ridge on the MNI brain image
            // left one at 165.5° that only the second ring's point fixes).
            let mut inner = faces;
            for _ in 0..2 {
                let ring = w.face_ring(&inner, w.labels[t as usize]);
                if ring == inner || got.is_some() || !w.alive[t as usize] {
                    break;
                }
                got = w.insert_into(t, ring.clone(), thr, searcher, rp, sp, star, by);
                inner = ring;
            }
        }
        check.extend(got.into_iter().flatten());
    }
    let changed = check.len() > before;
    check.sort_unstable();
    check.dedup();
    let mut after = 0;
    for t in check {
        if w.alive[t as usize]
            && w.max_angle(t) > max_deg
            && w.min_angle(t) >= thr
            && !w.is_forced(t)
        {
            after += 1;
        }
    }
    (before, after, changed)
}

/// The live unforced tets above `max_deg` with their smallest angle at or above `thr`, with
/// their largest angle, worst first (ties by index, so the order is the same on any number of
/// threads).
fn obtuse(w: &mut Work, thr: f64, max_deg: f64) -> Vec<(f64, u32)> {
    // A trigonometry-free screen first, with a margin: the angle decides.
    let s = (max_deg.to_radians() / 2.0).sin();
    let lim = 4.0 * s * s * (1.0 - 1e-6);
    let view: &Work = w;
    let mut out: Vec<(f64, u32)> = (0..view.tets.len() as u32)
        .into_par_iter()
        .filter(|&t| view.alive[t as usize])
        .filter(|&t| max_dihedral_chord2(&view.corners(t)) > lim)
        .filter_map(|t| {
            let a = view.max_angle(t);
            (a > max_deg && view.min_angle(t) >= thr).then_some((a, t))
        })
        .collect();
    out.retain(|&(_, t)| !w.is_forced(t));
    out.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    out
}
