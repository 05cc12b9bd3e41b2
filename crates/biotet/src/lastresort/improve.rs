//! Sliver removal with LAST RESORT (dissertation sections 3.3.1 and 3.4): carve the cavity
//! around a poor tet, keep its shell exactly, and refill it with the best tets the existing points
//! allow; accept only if the cavity's worst tet improves.
//!
//! For each tet below the threshold, worst first, these moves are tried in order of cost, each a
//! search ([`Searcher`]) on a closed cavity with branch and bound on the worst tet:
//! 1. **edge removal**: the ring of tets around one of its edges (3-2 flips and their
//!    generalisation n-to-(2n−4), or any better fill of the ring); 2-3 **face flips** (the tet
//!    and its neighbour across a face) are an option ([`ImproveOptions::face_flips`]);
//! 2. **the edge cavity**: every tet sharing an edge with it;
//! 3. **the seed's cavity**: every tet sharing a corner with it, grown once by the next ring if
//!    that fails past the search's root.
//!
//! When the queue is empty, a second pass tries edge removal again on the bad tets whose
//! surroundings a later fill changed.
//!
//! **Parallel.** Every search runs in batches on all threads. A bad tet enters a batch twice at
//! most: first with its local moves (move 1), then, if they all failed, with its larger
//! cavities (moves 2 and 3). A batch takes bad tets worst first while their cavities, grown ones
//! included, share no tet and touch no tet of the batch across a face, so each fill stays valid
//! whatever the others do; fills are applied in batch order. Batches are of a fixed size and do
//! not depend on the number of threads, so neither does the result (tested).
//!
//! Cavities never cross a region: only tets with the bad tet's label are carved, so boundary
//! and interface faces are always on the shell and stay exactly as they are. Points are never
//! added, moved or removed (the corners strictly inside a cavity are handed to the search as
//! points that every fill must use).
//!
//! The search's quality threshold ηe is set to the cavity's current worst q and, with the
//! dihedral metric, its floor on the smallest dihedral angle to the cavity's current worst angle
//! ([`SearchOptions::min_dihedral`]), so it only explores fills that would be accepted;
//! acceptance compares the chosen metric (q or the smallest dihedral angle) of the worst tet
//! before and after.

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::time::Instant;

use rustc_hash::FxHashSet;
use serde::Serialize;

use super::search::{Fill, SearchError, SearchOptions, Searcher};
use crate::mesh::tet::{NO_NEIGHBOR, TET_FACES, TetMesh};
use crate::quality::tet::{dihedral_at, min_dihedral_deg_by_chord, q_measure};
use crate::quality::tri::min_angle_3d_deg;
use rayon::prelude::*;

type P3 = [f64; 3];

/// Which measure selects and judges tets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Metric {
    /// q of eq. 4.9 (1 for the regular tet).
    Q,
    /// The smallest dihedral angle, in degrees.
    Dihedral,
}

/// Options of [`improve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImproveOptions {
    /// The measure.
    pub metric: Metric,
    /// Tets whose measure is below this are improved (q, or degrees).
    pub threshold: f64,
    /// Try edge removal (and face flips, if `face_flips`) before the larger cavities.
    pub local_moves: bool,
    /// With `local_moves`, also try 2-3 face flips (the bad tet and a neighbour across a face).
    /// Off by default: on brain_20k they fixed 1 tet in 22,507 tries, for 35 ms; edge removal
    /// and the larger cavities fix what they would.
    pub face_flips: bool,
    /// Grow a failing cavity once by the next ring of tets (unless its search failed at the root,
    /// see [`improve`]).
    pub grow: bool,
    /// Search nodes for a first fill of one cavity.
    pub max_nodes: u64,
    /// A cavity of n tets gets at most `nodes_per_tet`·n + 20 nodes for its first fill (and
    /// `max_nodes` at most): a fill of n tets takes n nodes without backtracking, and a search
    /// that needs many times that is mostly thrashing on a shell without a better fill.
    pub nodes_per_tet: u64,
    /// Extra search nodes spent looking for a better worst tet (branch and bound).
    pub improve_nodes: u64,
    /// Cavities with more tets than this are not searched.
    pub max_cavity_tets: usize,
    /// How many times a tet may re-enter the queue after its cavity was refilled.
    pub max_rounds: u32,
    /// A tet is forced poor by the input when one of its boundary or interface faces has an
    /// angle below this (degrees), or the boundary folds to a wedge below it at one of its
    /// edges; forced tets get the local moves only (no refill can remove a poor input triangle).
    pub forced_deg: f64,
}

impl Default for ImproveOptions {
    fn default() -> ImproveOptions {
        ImproveOptions {
            metric: Metric::Dihedral,
            threshold: 10.0,
            local_moves: true,
            face_flips: false,
            grow: true,
            // Searches that need more are rare and slow (nested_brain_wm_20k: 3 of 725 accepted
            // fills took 250–500 nodes; the 36 that ran out of 500 cost a fifth of the time).
            max_nodes: 250,
            // nested_brain_wm_20k: 2 per tet keeps 723 of the 731 star and grown fills that 250
            // nodes give, for about a quarter less search time in them.
            nodes_per_tet: 2,
            // More barely changes the result (brain_20k: 100 gives 1 tet fewer below 10° than
            // 20, for 10% more time).
            improve_nodes: 20,
            max_cavity_tets: 400,
            max_rounds: 4,
            forced_deg: 10.0,
        }
    }
}

/// Counts of one kind of move.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct MoveCounts {
    /// Searches run.
    pub calls: usize,
    /// Fills accepted.
    pub accepted: usize,
    /// Milliseconds spent in these searches.
    pub ms: f64,
    /// Searches that found no fill above the current worst tet (the tree was exhausted).
    pub no_fill: usize,
    /// Searches stopped by the node budget.
    pub budget: usize,
    /// Fills found but not better by the metric.
    pub not_better: usize,
}

/// What [`improve`] did.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ImproveReport {
    /// Metric and threshold.
    pub metric: Option<Metric>,
    /// The threshold.
    pub threshold: f64,
    /// Tets below the threshold before.
    pub n_bad_before: usize,
    /// Tets below the threshold after.
    pub n_bad_after: usize,
    /// Tets before and after.
    pub n_tets_before: usize,
    /// Tets after.
    pub n_tets_after: usize,
    /// Face-flip cavities (two tets).
    pub face_flips: MoveCounts,
    /// Edge-removal cavities (the ring around an edge).
    pub edge_removals: MoveCounts,
    /// Cavities of every tet sharing an edge with the bad tet (tried before the seed's).
    pub edge_cavities: MoveCounts,
    /// The seed's cavities (every tet sharing a corner with the bad tet).
    pub star_cavities: MoveCounts,
    /// The seed's cavities grown by a ring.
    pub grown_cavities: MoveCounts,
    /// Tets skipped by the seed's cavity because the input forces them poor.
    pub forced_skipped: usize,
    /// All searches.
    pub calls: usize,
    /// Median time of one search, milliseconds.
    pub call_ms_median: f64,
    /// Largest time of one search, milliseconds.
    pub call_ms_max: f64,
    /// Median search nodes per call.
    pub nodes_median: u64,
    /// Wall seconds.
    pub seconds: f64,
}

/// The measure of a tet.
#[inline]
fn measure(c: &[P3; 4], m: Metric) -> f64 {
    match m {
        Metric::Q => q_measure(c),
        Metric::Dihedral => min_dihedral_deg_by_chord(c),
    }
}

/// A tet in the queue, worst first.
#[derive(Debug, Clone, Copy)]
struct Entry {
    value: f64,
    tet: u32,
}

impl PartialEq for Entry {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        // BinaryHeap is a max-heap: the smallest value (worst) must compare greatest; ties by
        // lower tet id first, for determinism.
        o.value
            .total_cmp(&self.value)
            .then_with(|| o.tet.cmp(&self.tet))
    }
}

/// The mesh being edited: tets with tombstones, adjacency, one incident tet per point.
struct Work<'a> {
    pts: &'a [P3],
    tets: Vec<[u32; 4]>,
    nb: Vec<[u32; 4]>,
    labels: Vec<u32>,
    alive: Vec<bool>,
    /// Per tet: refills since the start that made it (at most `max_rounds` + 1 matters).
    rounds: Vec<u8>,
    /// Per tet: 0 unknown, 1 forced, 2 not forced.
    forced: Vec<u8>,
    /// Per point: on a boundary or interface face (fixed: those faces never change).
    on_boundary: Vec<bool>,
    /// Per tet: the batch that claimed it (see [`improve`]).
    claim: Vec<u32>,
    /// The pending batch's id.
    batch_id: u32,
    /// Per tet: its metric (NaN until computed).
    cache: Vec<f64>,
    vtet: Vec<u32>,
    /// Only local moves (the second pass).
    local_only: bool,
    /// Per tet: the batch that last searched its moves.
    tried_at: Vec<u32>,
    /// Per point: the last batch whose fill changed a tet with this corner.
    changed_at: Vec<u32>,
    /// Per tet: the stamp of the last star walk that met it (see [`Work::star`]).
    star_mark: Vec<u8>,
    star_stamp: u8,
    free: Vec<u32>,
    /// Per tet: its local moves were tried and failed (it waits for its larger cavities).
    local_tried: Vec<bool>,
    /// Rings around an edge (their tets' corners, sorted) whose search proved that no fill
    /// exists: each tet around the edge would search the same ring again.
    ring_no_fill: FxHashSet<Vec<[u32; 4]>>,
    opts: ImproveOptions,
    report: ImproveReport,
    /// Per search: milliseconds and nodes (for the medians; a byte count per search matters on
    /// large meshes).
    call_ms: Vec<f32>,
    call_nodes: Vec<u32>,
    queue: BinaryHeap<Entry>,
}

/// One carved cavity: its tets, the shell (faces pointing into it) with the tet outside each
/// shell face and that tet's local face, and the corners strictly inside.
struct Cavity {
    tets: Vec<u32>,
    shell: Vec<[u32; 3]>,
    outer: Vec<(u32, u8)>,
    inner: Vec<u32>,
}

/// The search of one cavity: options and the worst tet it must beat.
struct Plan {
    so: SearchOptions,
    old_worst: f64,
}

/// What one search found, and its cost.
struct Outcome {
    result: Result<Fill, SearchError>,
    ms: f64,
    /// The fill's worst tet in the metric (`-inf` without a fill).
    new_worst: f64,
}

impl Outcome {
    fn accepted(&self, plan: &Plan) -> bool {
        self.result.is_ok() && self.new_worst > plan.old_worst
    }

    /// Pruned at the root: a shell face without any candidate.
    fn root_pruned(&self) -> bool {
        matches!(self.result, Err(SearchError::NoFill { nodes_visited: 1 }))
    }
}

/// Search a refill of `cav` (reads the points only: runs on any thread).
fn search_cavity(
    searcher: &mut Searcher,
    pts: &[P3],
    cav: &Cavity,
    plan: &Plan,
    metric: Metric,
) -> Outcome {
    let clock = Instant::now();
    let result = searcher.fill_carved(pts, &cav.shell, &cav.inner, &plan.so);
    let ms = clock.elapsed().as_secs_f64() * 1e3;
    let new_worst = match &result {
        Ok(fill) => fill
            .tets
            .iter()
            .map(|t| measure(&t.map(|v| pts[v as usize]), metric))
            .fold(f64::INFINITY, f64::min),
        Err(_) => f64::NEG_INFINITY,
    };
    Outcome {
        result,
        ms,
        new_worst,
    }
}

/// The moves of a [`Task`], in the order they are tried.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// The bad tet and a neighbour across a face (a 2-3 flip or better).
    Flip,
    /// The ring of tets around one of its edges (edge removal).
    Ring,
    /// Every tet sharing an edge with the bad tet.
    Edges,
    /// The seed's cavity: every tet sharing a corner.
    Star,
    /// The seed's cavity grown by a ring.
    Grown,
}

/// The moves of one bad tet in a batch, tried in order until one is accepted: its local moves
/// (`local`), or else its larger cavities.
struct Task {
    tet: u32,
    local: bool,
    tries: Vec<(Kind, Vec<u32>)>,
}

/// One move of a task as tried on a worker thread.
struct Tried {
    kind: Kind,
    cav: Cavity,
    /// `None`: the cavity is too large to search.
    plan: Option<Plan>,
    out: Option<Outcome>,
}

/// A worker's reusable buffers: kept per thread across batches, so that a search does not
/// start from empty buffers each time rayon splits a batch.
#[derive(Default)]
struct WorkerScratch {
    searcher: Searcher,
    mark: FxHashSet<u32>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<WorkerScratch> = std::cell::RefCell::default();
}

/// The mesh as the workers read it while a batch is searched (nothing changes meanwhile).
struct View<'b> {
    pts: &'b [P3],
    tets: &'b [[u32; 4]],
    nb: &'b [[u32; 4]],
    opts: ImproveOptions,
}

impl View<'_> {
    /// Build the cavity of `tets` (all of one label): shell faces turned inward, the tets across
    /// them, and the inner corners.
    fn cavity(&self, tets: Vec<u32>, mark: &mut FxHashSet<u32>) -> Cavity {
        mark.clear();
        mark.extend(tets.iter().copied());
        let (shell, outer) =
            crate::mesh::cavity::shell(&tets, self.tets, self.nb, |n| mark.contains(&n));
        let on_shell: FxHashSet<u32> = shell.iter().flatten().copied().collect();
        let mut all: Vec<u32> = tets
            .iter()
            .flat_map(|&t| self.tets[t as usize])
            .filter(|v| !on_shell.contains(v))
            .collect();
        all.sort_unstable();
        all.dedup();
        Cavity {
            tets,
            shell,
            outer,
            inner: all,
        }
    }

    /// The search options for refilling `cav` and its current worst tet; `None` when the cavity
    /// is too large to search.
    fn plan(&self, cav: &Cavity) -> Option<Plan> {
        if cav.tets.len() > self.opts.max_cavity_tets {
            return None;
        }
        let (mut old_worst, mut old_q) = (f64::INFINITY, f64::INFINITY);
        for &t in &cav.tets {
            let c = self.tets[t as usize].map(|v| self.pts[v as usize]);
            old_worst = old_worst.min(measure(&c, self.opts.metric));
            old_q = old_q.min(q_measure(&c));
        }
        // With the dihedral metric, candidates must also beat the cavity's worst angle (by more
        // than rounding: the search's formula differs), so every fill found is accepted.
        let so = SearchOptions {
            min_quality: old_q.max(0.0),
            min_dihedral: match self.opts.metric {
                Metric::Q => 0.0,
                Metric::Dihedral => old_worst.max(0.0) * (1.0 + 1e-9),
            },
            max_dihedral: 180.0,
            max_nodes: self.opts.max_nodes.min(
                self.opts
                    .nodes_per_tet
                    .saturating_mul(cav.tets.len() as u64)
                    + 20,
            ),
            improve: Some(self.opts.improve_nodes),
        };
        Some(Plan { so, old_worst })
    }

    /// The moves of a [`Task`], run on any thread, until one is accepted. The grown cavity is
    /// skipped when the seed's cavity failed at its search's root (see [`step`]).
    fn run_task(&self, ws: &mut WorkerScratch, task: &Task) -> Vec<Tried> {
        let WorkerScratch { searcher, mark } = ws;
        let mut done = Vec::with_capacity(task.tries.len());
        for (kind, tets) in &task.tries {
            let cav = self.cavity(tets.clone(), mark);
            let plan = self.plan(&cav);
            let out = plan
                .as_ref()
                .map(|p| search_cavity(searcher, self.pts, &cav, p, self.opts.metric));
            let stop = match (&out, &plan) {
                (Some(o), Some(p)) => o.accepted(p) || (*kind == Kind::Star && o.root_pruned()),
                _ => false,
            };
            done.push(Tried {
                kind: *kind,
                cav,
                plan,
                out,
            });
            if stop {
                break;
            }
        }
        done
    }
}

impl<'a> Work<'a> {
    fn corners(&self, t: u32) -> [P3; 4] {
        self.tets[t as usize].map(|v| self.pts[v as usize])
    }

    /// The metric of tet `t`, computed once per tet (a tet's corners never change).
    fn value(&mut self, t: u32) -> f64 {
        let m = self.cache[t as usize];
        if !m.is_nan() {
            return m;
        }
        let m = measure(&self.corners(t), self.opts.metric);
        self.cache[t as usize] = m;
        m
    }

    /// Every live tet with corner `v` (walking across the faces around `v`), appended to `out`.
    fn star(&mut self, v: u32, out: &mut Vec<u32>) {
        let start = self.vtet[v as usize];
        if start == NO_NEIGHBOR {
            return;
        }
        // Tets seen by this walk carry its stamp: no set to build or clear per walk.
        self.star_stamp = self.star_stamp.wrapping_add(1);
        if self.star_stamp == 0 {
            self.star_mark.fill(0);
            self.star_stamp = 1;
        }
        let stamp = self.star_stamp;
        if self.star_mark.len() < self.tets.len() {
            self.star_mark.resize(self.tets.len(), 0);
        }
        let first = out.len();
        out.push(start);
        self.star_mark[start as usize] = stamp;
        let mut next = first;
        while next < out.len() {
            let t = out[next];
            next += 1;
            let tv = self.tets[t as usize];
            for (i, &n) in self.nb[t as usize].iter().enumerate() {
                // Faces containing v are those opposite the other corners.
                if tv[i] != v && n != NO_NEIGHBOR && self.star_mark[n as usize] != stamp {
                    self.star_mark[n as usize] = stamp;
                    out.push(n);
                }
            }
        }
    }

    /// Count a search's outcome in the report; true when its fill is to be accepted.
    fn record(
        &mut self,
        out: &Outcome,
        plan: &Plan,
        counts: fn(&mut ImproveReport) -> &mut MoveCounts,
    ) -> bool {
        self.call_ms.push(out.ms as f32);
        counts(&mut self.report).calls += 1;
        counts(&mut self.report).ms += out.ms;
        match &out.result {
            Ok(fill) => {
                self.call_nodes
                    .push(fill.nodes_visited.min(u32::MAX as u64) as u32);
                if out.accepted(plan) {
                    counts(&mut self.report).accepted += 1;
                    true
                } else {
                    counts(&mut self.report).not_better += 1;
                    false
                }
            }
            Err(e) => {
                self.call_nodes.push(0);
                match e {
                    SearchError::Budget { .. } => counts(&mut self.report).budget += 1,
                    _ => counts(&mut self.report).no_fill += 1,
                }
                false
            }
        }
    }

    /// Is any of `tets` claimed by the pending batch?
    fn claimed(&self, tets: &[u32]) -> bool {
        tets.iter().any(|&t| {
            self.claim
                .get(t as usize)
                .is_some_and(|&c| c == self.batch_id)
        })
    }

    /// Claim `tets` and every tet across their faces for the pending batch.
    fn claim(&mut self, tets: &[u32]) {
        let n = self.tets.len();
        if self.claim.len() < n {
            self.claim.resize(n, 0);
        }
        for &t in tets {
            self.claim[t as usize] = self.batch_id;
            for &nb in &self.nb[t as usize] {
                if nb != NO_NEIGHBOR {
                    self.claim[nb as usize] = self.batch_id;
                }
            }
        }
    }

    /// Swap the cavity's tets for `new` and stitch the adjacency.
    fn replace(&mut self, cav: &Cavity, new: &[[u32; 4]]) {
        let label = self.labels[cav.tets[0] as usize];
        let rounds = cav
            .tets
            .iter()
            .map(|&t| self.rounds[t as usize])
            .max()
            .unwrap_or(0)
            .saturating_add(1);
        for &t in &cav.tets {
            self.alive[t as usize] = false;
            self.free.push(t);
            for &x in &self.tets[t as usize] {
                self.changed_at[x as usize] = self.batch_id;
            }
        }
        let mut ids = Vec::with_capacity(new.len());
        for tv in new {
            let t = match self.free.pop() {
                Some(t) => {
                    self.forced[t as usize] = 0;
                    self.local_tried[t as usize] = false;
                    self.tried_at[t as usize] = 0;
                    self.cache[t as usize] = f64::NAN;
                    self.tets[t as usize] = *tv;
                    self.nb[t as usize] = [NO_NEIGHBOR; 4];
                    self.labels[t as usize] = label;
                    self.alive[t as usize] = true;
                    self.rounds[t as usize] = rounds;
                    t
                }
                None => {
                    self.tets.push(*tv);
                    self.nb.push([NO_NEIGHBOR; 4]);
                    self.labels.push(label);
                    self.alive.push(true);
                    self.rounds.push(rounds);
                    self.forced.push(0);
                    self.local_tried.push(false);
                    self.tried_at.push(0);
                    self.cache.push(f64::NAN);
                    (self.tets.len() - 1) as u32
                }
            };
            ids.push(t);
            for &v in tv {
                self.vtet[v as usize] = t;
            }
        }
        crate::mesh::cavity::stitch(&self.tets, &mut self.nb, &ids, &cav.shell, &cav.outer);
        for &t in &ids {
            let v = self.value(t);
            // (`rounds` saturates at 255.)
            let max_rounds = self.opts.max_rounds.min(254);
            if v < self.opts.threshold && u32::from(self.rounds[t as usize]) <= max_rounds {
                self.queue_push(v, t);
            }
        }
    }

    /// The tets around edge `ab` of `tet`, if they all carry `label` and close a ring (the edge
    /// is not on a boundary or interface).
    fn ring(&self, tet: u32, a: u32, b: u32, label: u32) -> Option<Vec<u32>> {
        let mut ring = vec![tet];
        let mut prev = NO_NEIGHBOR;
        let mut t = tet;
        loop {
            let tv = self.tets[t as usize];
            // The two faces holding edge ab are opposite the two other corners; step across the
            // one that does not lead back.
            let mut next = NO_NEIGHBOR;
            for (i, &x) in tv.iter().enumerate() {
                if x == a || x == b {
                    continue;
                }
                let n = self.nb[t as usize][i];
                if n == NO_NEIGHBOR || self.labels[n as usize] != label {
                    return None;
                }
                if n != prev {
                    next = n;
                }
            }
            if next == tet {
                return (ring.len() >= 3).then_some(ring);
            }
            if next == NO_NEIGHBOR || ring.len() > 16 {
                return None;
            }
            prev = t;
            t = next;
            ring.push(t);
        }
    }

    /// A ring's content: its tets' corners, sorted (points never move here, so equal keys
    /// are equal cavities, and an exhausted search of one is exhausted for the other).
    fn ring_key(&self, ring: &[u32]) -> Vec<[u32; 4]> {
        let mut key: Vec<[u32; 4]> = ring.iter().map(|&t| self.tets[t as usize]).collect();
        key.sort_unstable();
        key
    }

    /// Whether the input forces `tet` to be poor (see [`ImproveOptions::forced_deg`]).
    fn is_forced(&mut self, tet: u32) -> bool {
        match self.forced[tet as usize] {
            1 => return true,
            2 => return false,
            _ => {}
        }
        let f = self.compute_forced(tet);
        self.forced[tet as usize] = if f { 1 } else { 2 };
        f
    }

    fn compute_forced(&self, tet: u32) -> bool {
        let tv = self.tets[tet as usize];
        // Forcing needs a boundary face or edge: two corners on the boundary at least.
        if tv.iter().filter(|&&v| self.on_boundary[v as usize]).count() < 2 {
            return false;
        }
        let label = self.labels[tet as usize];
        let lim = self.opts.forced_deg;
        // Any poor input face forces here, a flat tet on one too (unlike the report's and
        // polish's `face_forces`): refilling such tets from the first rounds left more tets under
        // 10° (the hair torus 589 -> 634); polish's last pass takes them instead.
        let fixed = |n: u32| n == NO_NEIGHBOR || self.labels[n as usize] != label;
        for (i, l) in TET_FACES.iter().enumerate() {
            if fixed(self.nb[tet as usize][i]) {
                let c = l.map(|k| self.pts[tv[k] as usize]);
                if min_angle_3d_deg(&c) < lim {
                    return true;
                }
            }
        }
        // A boundary edge: the wedge of this region around it, summed over its tets.
        for e in crate::mesh::tet::TET_EDGES {
            let (a, b) = (tv[e[0]], tv[e[1]]);
            if !self.on_boundary[a as usize] || !self.on_boundary[b as usize] {
                continue;
            }
            if let Some(w) = self.wedge(tet, a, b, label)
                && w.to_degrees() < lim
            {
                return true;
            }
        }
        false
    }

    /// The region's dihedral wedge at edge `ab` of `tet` when the edge is on the region's
    /// boundary (the sum of the angles at `ab` of the region's tets around it); `None` for an
    /// interior edge.
    fn wedge(&self, tet: u32, a: u32, b: u32, label: u32) -> Option<f64> {
        let angle_at = |t: u32| {
            let tv = self.tets[t as usize];
            let ia = tv.iter().position(|&v| v == a).unwrap_or(0);
            let ib = tv.iter().position(|&v| v == b).unwrap_or(0);
            let e = crate::mesh::tet::TET_EDGES
                .iter()
                .position(|&[x, y]| (x == ia && y == ib) || (x == ib && y == ia))
                .unwrap_or(0);
            dihedral_at(&self.corners(t), e)
        };
        // Walk both ways around the edge first (no geometry): most edges are interior.
        let mut ring = [0u32; 66];
        let mut n = 0;
        let tv = self.tets[tet as usize];
        let mut open = false;
        for (i, &x) in tv.iter().enumerate() {
            if x == a || x == b {
                continue;
            }
            // Walk away from tet across face i around the edge until the region ends.
            let (mut prev, mut t) = (tet, self.nb[tet as usize][i]);
            loop {
                if t == NO_NEIGHBOR || self.labels[t as usize] != label {
                    open = true;
                    break;
                }
                if t == tet || n == ring.len() {
                    return None; // closed ring: an interior edge
                }
                ring[n] = t;
                n += 1;
                let v = self.tets[t as usize];
                let next = (0..4)
                    .filter(|&k| v[k] != a && v[k] != b)
                    .map(|k| self.nb[t as usize][k])
                    .find(|&nb| nb != prev)
                    .unwrap_or(NO_NEIGHBOR);
                prev = t;
                t = next;
            }
        }
        open.then(|| angle_at(tet) + ring[..n].iter().map(|&t| angle_at(t)).sum::<f64>())
    }

    fn queue_push(&mut self, value: f64, tet: u32) {
        self.queue.push(Entry { value, tet });
    }
}

/// Tasks per batch (fixed, so that results do not depend on the number of threads).
const BATCH: usize = 128;

/// What [`step`] made of one bad tet.
enum Step {
    /// Forced, or nothing to try.
    Done,
    /// Its moves, to search in the batch.
    Task(Box<Task>),
    /// It touches the pending batch: it waits until the batch is done.
    Conflict,
}

/// One bad tet: its local moves as a task, first; if they failed, its larger cavities as a
/// task: the tets sharing an edge with it, the seed's cavity and the grown one.
fn step(w: &mut Work, tet: u32, scratch: &mut Vec<u32>) -> Step {
    let opts = w.opts;
    let label = w.labels[tet as usize];
    if opts.local_moves && !w.local_tried[tet as usize] {
        let mut tries = Vec::new();
        if opts.face_flips {
            for i in 0..4 {
                let n = w.nb[tet as usize][i];
                if n != NO_NEIGHBOR && w.labels[n as usize] == label && !w.is_forced(n) {
                    tries.push((Kind::Flip, vec![tet, n]));
                }
            }
        }
        let tv = w.tets[tet as usize];
        // A ring known to have no fill is not searched again, but still claimed: the batches,
        // and so the result, stay as they were.
        let mut known = Vec::new();
        for e in crate::mesh::tet::TET_EDGES {
            if let Some(ring) = w.ring(tet, tv[e[0]], tv[e[1]], label) {
                if w.ring_no_fill.contains(&w.ring_key(&ring)) {
                    known.extend_from_slice(&ring);
                } else {
                    tries.push((Kind::Ring, ring));
                }
            }
        }
        if !tries.is_empty() || !known.is_empty() {
            let mut all: Vec<u32> = tries.iter().flat_map(|(_, t)| t.iter().copied()).collect();
            all.extend_from_slice(&known);
            all.sort_unstable();
            all.dedup();
            if w.claimed(&all) {
                return Step::Conflict;
            }
            w.claim(&all);
            return Step::Task(Box::new(Task {
                tet,
                local: true,
                tries,
            }));
        }
    }
    if w.local_only {
        return Step::Done;
    }
    if w.is_forced(tet) {
        w.report.forced_skipped += 1;
        return Step::Done;
    }
    // The seed's cavity: every tet of this label sharing a corner.
    scratch.clear();
    let tv = w.tets[tet as usize];
    for v in tv {
        w.star(v, scratch);
    }
    // Forced tets stay: their poor input face would pin the cavity's worst tet, so no refill
    // could be accepted; leaving them out puts their faces on the shell.
    let mut tets: Vec<u32> = Vec::new();
    for &t in scratch.iter() {
        if w.labels[t as usize] == label && (t == tet || !w.is_forced(t)) {
            tets.push(t);
        }
    }
    tets.sort_unstable();
    tets.dedup();
    // The tets sharing an edge with it: a third of the seed's cavity, and it fixes over half
    // of what the seed's cavity fixes (brain_20k), at a fifth of the cost per search.
    let edges: Vec<u32> = tets
        .iter()
        .copied()
        .filter(|&t| w.tets[t as usize].iter().filter(|v| tv.contains(v)).count() >= 2)
        .collect();
    // A star too large to be searched (a corner of a large input face over fine nodes holds
    // thousands of tets): only the edge cavity is tried, and only it is claimed, else every bad
    // tet around that corner conflicts with the others and the queue turns over one at a time
    // (a unit cube at --size 0.05 spent 25 s so).
    if tets.len() > opts.max_cavity_tets {
        if edges.len() > opts.max_cavity_tets {
            return Step::Done;
        }
        if w.claimed(&edges) {
            return Step::Conflict;
        }
        w.claim(&edges);
        return Step::Task(Box::new(Task {
            tet,
            local: false,
            tries: vec![(Kind::Edges, edges)],
        }));
    }
    // Grown by the next ring, tried when the search fails past its root: a cavity pruned at once
    // (a shell face without any candidate) almost never has a better grown fill (brain_20k: 11
    // of 620 such grown cavities succeeded, for a third of the sliver removal's time).
    let mut grown = tets.clone();
    if opts.grow {
        for &t in &tets {
            for i in 0..4 {
                let n = w.nb[t as usize][i];
                if n != NO_NEIGHBOR && w.labels[n as usize] == label && !w.is_forced(n) {
                    grown.push(n);
                }
            }
        }
        grown.sort_unstable();
        grown.dedup();
    }
    if w.claimed(&grown) {
        return Step::Conflict;
    }
    w.claim(&grown);
    let mut tries: Vec<(Kind, Vec<u32>)> = Vec::with_capacity(3);
    for (kind, c) in [
        (Kind::Edges, edges),
        (Kind::Star, tets),
        (Kind::Grown, grown),
    ] {
        if tries.last().is_none_or(|(_, p)| c.len() > p.len()) {
            tries.push((kind, c));
        }
    }
    Step::Task(Box::new(Task {
        tet,
        local: false,
        tries,
    }))
}

/// Search the batch's tasks in parallel, then apply their fills in order. A bad tet whose local
/// moves all failed goes back to the queue for its larger cavities.
fn run_batch(w: &mut Work, batch: &mut Vec<Task>) {
    let view = View {
        pts: w.pts,
        tets: &w.tets,
        nb: &w.nb,
        opts: w.opts,
    };
    // Largest tasks first, one task per job: the batch's tail is then made of small tasks, not
    // of one long search with the other thread idle. Results go back in batch order.
    let mut order: Vec<(usize, usize)> = batch
        .iter()
        .enumerate()
        .map(|(i, t)| (t.tries.iter().map(|(_, c)| c.len() * c.len()).sum(), i))
        .collect();
    order.sort_unstable_by(|a, b| b.cmp(a));
    let mut found: Vec<(usize, Vec<Tried>)> = order
        .par_iter()
        .with_max_len(1)
        .map(|&(_, i)| {
            (
                i,
                SCRATCH.with_borrow_mut(|ws| view.run_task(ws, &batch[i])),
            )
        })
        .collect();
    found.sort_unstable_by_key(|x| x.0);
    let results: Vec<Vec<Tried>> = found.into_iter().map(|x| x.1).collect();
    for (task, tried) in batch.drain(..).zip(results) {
        w.tried_at[task.tet as usize] = w.batch_id;
        let mut fixed = false;
        for t in &tried {
            let (Some(out), Some(plan)) = (&t.out, &t.plan) else {
                continue;
            };
            let counts: fn(&mut ImproveReport) -> &mut MoveCounts = match t.kind {
                Kind::Flip => |r| &mut r.face_flips,
                Kind::Ring => |r| &mut r.edge_removals,
                Kind::Edges => |r| &mut r.edge_cavities,
                Kind::Star => |r| &mut r.star_cavities,
                Kind::Grown => |r| &mut r.grown_cavities,
            };
            if t.kind == Kind::Ring
                && matches!(&out.result, Err(e) if !matches!(e, SearchError::Budget { .. }))
            {
                let key = w.ring_key(&t.cav.tets);
                w.ring_no_fill.insert(key);
            }
            if w.record(out, plan, counts) {
                if let Ok(fill) = &out.result {
                    w.replace(&t.cav, &fill.tets);
                }
                fixed = true;
                break;
            }
        }
        if task.local && !fixed {
            w.local_tried[task.tet as usize] = true;
            let v = w.value(task.tet);
            w.queue_push(v, task.tet);
        }
    }
    w.batch_id += 1;
}

/// Take bad tets from the queue, worst first, into batches until it is empty (see [`improve`]).
fn run_queue(w: &mut Work) {
    let mut scratch = Vec::new();
    let mut batch: Vec<Task> = Vec::new();
    // Tets whose moves touch the pending batch wait for it (in their order), so that a cluster
    // of bad tets does not cut the batches short.
    let mut waiting: Vec<Entry> = Vec::new();
    loop {
        let entry = w.queue.pop();
        let flush = match entry {
            None => true,
            Some(e) => {
                if !w.alive[e.tet as usize] || w.value(e.tet) != e.value {
                    continue;
                }
                match step(w, e.tet, &mut scratch) {
                    Step::Done => false,
                    Step::Task(t) => {
                        batch.push(*t);
                        batch.len() >= BATCH
                    }
                    Step::Conflict => {
                        waiting.push(e);
                        waiting.len() >= 2 * BATCH
                    }
                }
            }
        };
        if flush {
            if batch.is_empty() && waiting.is_empty() && entry.is_none() {
                break;
            }
            run_batch(w, &mut batch);
            for e in waiting.drain(..) {
                w.queue.push(e);
            }
        }
    }
}

/// Improve the tets of `mesh` below the threshold (see the module docs). Points, boundary and
/// interface faces are untouched; tets keep their labels; tet order is not kept.
pub fn improve(mesh: &mut TetMesh, opts: &ImproveOptions) -> ImproveReport {
    let clock = Instant::now();
    let mut w = Work {
        pts: &mesh.points,
        tets: std::mem::take(&mut mesh.tets),
        nb: std::mem::take(&mut mesh.neighbors),
        labels: std::mem::take(&mut mesh.labels),
        alive: Vec::new(),
        rounds: Vec::new(),
        forced: Vec::new(),
        on_boundary: vec![false; mesh.points.len()],
        claim: Vec::new(),
        batch_id: 1,
        cache: Vec::new(),
        vtet: vec![NO_NEIGHBOR; mesh.points.len()],
        tried_at: Vec::new(),
        local_only: false,
        changed_at: vec![0; mesh.points.len()],
        star_mark: Vec::new(),
        star_stamp: 0,
        free: Vec::new(),
        local_tried: Vec::new(),
        ring_no_fill: FxHashSet::default(),
        opts: *opts,
        report: ImproveReport {
            metric: Some(opts.metric),
            threshold: opts.threshold,
            ..ImproveReport::default()
        },
        call_ms: Vec::new(),
        call_nodes: Vec::new(),
        queue: BinaryHeap::new(),
    };
    let n = w.tets.len();
    w.alive = vec![true; n];
    w.rounds = vec![0; n];
    w.forced = vec![0; n];
    w.local_tried = vec![false; n];
    w.tried_at = vec![0; n];
    for t in 0..n {
        for (i, f) in TET_FACES.iter().enumerate() {
            let nb = w.nb[t][i];
            if nb == NO_NEIGHBOR || w.labels[nb as usize] != w.labels[t] {
                for &k in f {
                    w.on_boundary[w.tets[t][k] as usize] = true;
                }
            }
        }
    }
    // Every tet's metric, on all threads (the same values in any order).
    let (pts, metric) = (w.pts, opts.metric);
    w.cache = w
        .tets
        .par_iter()
        .map(|t| measure(&t.map(|v| pts[v as usize]), metric))
        .collect();
    // Which tets the input forces poor, on all threads: the queue's first pass asks it of most
    // tets near the boundary.
    let forced: Vec<u8> = (0..n as u32)
        .into_par_iter()
        .map(|t| if w.compute_forced(t) { 1 } else { 2 })
        .collect();
    w.forced = forced;
    w.report.n_tets_before = n;
    for t in 0..n {
        for &v in &w.tets[t] {
            w.vtet[v as usize] = t as u32;
        }
    }
    for t in 0..n as u32 {
        let v = w.value(t);
        if v < opts.threshold {
            w.report.n_bad_before += 1;
            w.queue_push(v, t);
        }
    }
    // Seed's cavities are searched in batches, in parallel: a batch takes the worst tets in
    // order while their cavities (grown ones included) are apart from the batch's (no shared or
    // face-adjacent tet), so every fill stays valid whatever the others do; the fills are then
    // applied in batch order. The batches do not depend on the number of threads, so neither
    // does the result. Local moves run at once, unless they touch the pending batch.
    run_queue(&mut w);
    // A second pass, edge removal only, over the bad tets whose surroundings changed since their
    // moves were searched: a neighbour's refill often opens a ring that was closed (brain_20k:
    // 79 more tets fixed for 2,100 more small searches; the larger cavities again fix 1 in 400).
    w.local_only = true;
    for t in 0..w.tets.len() as u32 {
        if !w.alive[t as usize] {
            continue;
        }
        let since = w.tried_at[t as usize];
        let changed = w.tets[t as usize]
            .iter()
            .any(|&x| w.changed_at[x as usize] > since);
        let v = w.value(t);
        if changed && v < opts.threshold && !w.is_forced(t) {
            w.local_tried[t as usize] = false;
            w.queue_push(v, t);
        }
    }
    run_queue(&mut w);
    // Compact, with the per-tet side arrays freed first (the index below would sit on top of
    // them at the stage's peak).
    for v in [&mut w.claim, &mut w.tried_at] {
        *v = Vec::new();
    }
    for v in [&mut w.forced, &mut w.star_mark, &mut w.rounds] {
        *v = Vec::new();
    }
    w.cache = Vec::new();
    w.local_tried = Vec::new();
    let mut index = vec![NO_NEIGHBOR; w.tets.len()];
    let mut k = 0u32;
    for (t, slot) in index.iter_mut().enumerate() {
        if w.alive[t] {
            *slot = k;
            k += 1;
        }
    }
    // In place (new index <= old index), so the mesh is never held twice.
    let scratch_len = w.tets.len();
    for t in 0..scratch_len {
        let new = index[t];
        if new == NO_NEIGHBOR {
            continue;
        }
        let nb = w.nb[t].map(|n| {
            if n == NO_NEIGHBOR {
                n
            } else {
                index[n as usize]
            }
        });
        let new = new as usize;
        w.tets[new] = w.tets[t];
        w.nb[new] = nb;
        w.labels[new] = w.labels[t];
    }
    drop(index);
    let k = k as usize;
    let mut tets = std::mem::take(&mut w.tets);
    let mut nb = std::mem::take(&mut w.nb);
    let mut labels = std::mem::take(&mut w.labels);
    tets.truncate(k);
    nb.truncate(k);
    labels.truncate(k);
    tets.shrink_to_fit();
    nb.shrink_to_fit();
    labels.shrink_to_fit();
    let pts = &mesh.points;
    let bad_after = tets
        .par_iter()
        .filter(|t| measure(&t.map(|v| pts[v as usize]), opts.metric) < opts.threshold)
        .count();
    let mut report = std::mem::take(&mut w.report);
    report.n_bad_after = bad_after;
    report.n_tets_after = tets.len();
    let mut ms = std::mem::take(&mut w.call_ms);
    ms.sort_by(f32::total_cmp);
    let mut nodes = std::mem::take(&mut w.call_nodes);
    nodes.sort_unstable();
    report.calls = ms.len();
    report.call_ms_median = ms.get(ms.len() / 2).map_or(0.0, |&x| f64::from(x));
    report.call_ms_max = ms.last().map_or(0.0, |&x| f64::from(x));
    report.nodes_median = nodes.get(nodes.len() / 2).map_or(0, |&x| u64::from(x));
    drop(w);
    // The workers' buffers go too (they would stay with the threads for the rest of the run).
    rayon::broadcast(|_| SCRATCH.take());
    mesh.tets = tets;
    mesh.neighbors = nb;
    mesh.labels = labels;
    report.seconds = clock.elapsed().as_secs_f64();
    report
}
