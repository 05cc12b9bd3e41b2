//! Operations over an ordered list, their checks run in parallel, their outcome as one at a time.
//!
//! A batch of the list's next items is checked in parallel against the surface as it stands
//! (checking reads the surface only), then the items are walked in order and each one's outcome
//! applied. An item's check reads within a box (its fans' corners grown by the reach of the
//! distance checks); what applying it writes lies within that box grown by the reach once more
//! (the input samples it hands to triangles near its fan). An item whose box meets what an
//! earlier item of the batch wrote is checked again before it is applied. So the surface ends as
//! checking and applying one item at a time in list order leaves it, on any number of threads.
//! [`super::sweep`] does the same for points grouped so that few moves meet.

use rayon::prelude::*;

use super::{Grid, P3, Remesher};

/// Items checked together; their boxes rarely meet at this size (the brain surfaces: about one
/// item in twenty checked again).
const BATCH: usize = 128;

/// Fewer items than this are checked on the calling thread.
const PARALLEL_STEP: usize = 8;

/// An axis-aligned box.
pub(super) type Boxed = (P3, P3);

fn meets(a: &Boxed, b: &Boxed) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

/// `b` grown by `r` on every side.
pub(super) fn grow(b: Boxed, r: f64) -> Boxed {
    (b.0.map(|x| x - r), b.1.map(|x| x + r))
}

/// What applying an item changed.
pub(super) enum Wrote {
    /// Nothing another item reads (at most a note of its own refusal).
    Nothing,
    /// The surface, within the box the check read grown by [`Remesher::reach`].
    Read,
    /// That and also within this box grown by the reach (points moved beyond what was read).
    Also(Boxed),
}

/// The boxes written in a batch, in a [`Grid`] by the cells they cover.
pub(super) struct Taken {
    boxes: Vec<Boxed>,
    grid: Grid,
    cand: Vec<u32>,
}

impl Taken {
    pub(super) fn new(h: f64) -> Taken {
        Taken {
            boxes: Vec::new(),
            grid: Grid::new(h),
            cand: Vec::new(),
        }
    }

    pub(super) fn add(&mut self, b: Boxed) {
        self.grid.insert_box(self.boxes.len() as u32, b.0, b.1);
        self.boxes.push(b);
    }

    pub(super) fn meets(&mut self, b: &Boxed) -> bool {
        self.grid.query(b.0, b.1, &mut self.cand);
        self.cand.iter().any(|&i| meets(&self.boxes[i as usize], b))
    }

    pub(super) fn clear(&mut self) {
        self.boxes.clear();
        self.grid.clear();
    }
}

impl Remesher<'_> {
    /// How far beyond its fan a check reads: the working tolerance the distance checks look
    /// within, with a margin for rounding.
    pub(super) fn reach(&self) -> f64 {
        self.tol.max(0.0) * (1.0 + 1e-6)
    }

    /// The box of the triangles at the points `vs` (and the points themselves), grown by
    /// [`Self::reach`]: what an operation on them reads.
    pub(super) fn fans_box(&self, vs: &[u32]) -> Boxed {
        let mut lo = self.pts[vs[0] as usize];
        let mut hi = lo;
        let mut take = |p: P3| {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        };
        for &v in vs {
            take(self.pts[v as usize]);
            for &t in &self.vt[v as usize] {
                for u in self.tris[t as usize] {
                    take(self.pts[u as usize]);
                }
            }
        }
        grow((lo, hi), self.reach())
    }

    /// The box of the points `vs`, grown by [`Self::reach`].
    pub(super) fn points_box(&self, vs: &[u32]) -> Boxed {
        let p0 = self.pts[vs[0] as usize];
        let b = vs.iter().fold((p0, p0), |(lo, hi), &v| {
            let p = self.pts[v as usize];
            (
                [0, 1, 2].map(|k| lo[k].min(p[k])),
                [0, 1, 2].map(|k| hi[k].max(p[k])),
            )
        });
        grow(b, self.reach())
    }

    /// For each item in order, `apply(self, item, check(self, item))`, with the checks of a
    /// batch run in parallel (module docs). `check` returns the box it read with its outcome;
    /// `apply` what it wrote ([`Wrote`]). Returns the number of items checked again.
    pub(super) fn in_batches<T: Sync, R: Send>(
        &mut self,
        items: &[T],
        check: impl Fn(&Self, &T) -> (Boxed, R) + Sync,
        apply: impl FnMut(&mut Self, &T, R) -> Wrote,
    ) -> usize {
        let mut taken = Taken::new(4.0 * self.l + 4.0 * self.reach());
        self.in_batches_with(items, &mut taken, check, apply)
    }

    /// [`Self::in_batches`] keeping the written boxes in `taken` (cleared at each batch).
    pub(super) fn in_batches_with<T: Sync, R: Send>(
        &mut self,
        items: &[T],
        taken: &mut Taken,
        check: impl Fn(&Self, &T) -> (Boxed, R) + Sync,
        mut apply: impl FnMut(&mut Self, &T, R) -> Wrote,
    ) -> usize {
        let reach = self.reach();
        let mut again = 0;
        for batch in items.chunks(BATCH) {
            let checked: Vec<(Boxed, R)> = if batch.len() >= PARALLEL_STEP {
                let this = &*self;
                batch.par_iter().map(|x| check(this, x)).collect()
            } else {
                batch.iter().map(|x| check(self, x)).collect()
            };
            taken.clear();
            for (x, (read, r)) in batch.iter().zip(checked) {
                let (read, r) = if taken.meets(&read) {
                    again += 1;
                    check(self, x)
                } else {
                    (read, r)
                };
                match apply(self, x, r) {
                    Wrote::Nothing => {}
                    Wrote::Read => taken.add(grow(read, reach)),
                    Wrote::Also(more) => {
                        taken.add(grow(read, reach));
                        taken.add(grow(more, reach));
                    }
                }
            }
        }
        again
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::tests::Fixture;
    use super::super::{Remesher, min_angle_deg};
    use crate::surface::{median_edge_length, tests::uv_sphere};

    /// Collapsing in batches leaves the surface that collapsing one edge at a time in the same
    /// order leaves: on a small sphere whose edges are all short for the target (so the boxes
    /// of a batch meet and collapses must be checked again), to the bit.
    #[test]
    fn batched_collapses_end_as_one_at_a_time() {
        let s = uv_sphere(1.0, [0.0; 3], 48, 24);
        let l = 3.0 * median_edge_length(&s);
        let d = 0.05;
        let (lo, hi) = (0.8, 4.0 / 3.0);
        let fx = Fixture::new(&s, d, l);
        let mut batched = fx.remesher(&s, d, l);
        let mut serial = fx.remesher(&s, d, l);
        let again = two_threads().install(|| batched.collapse_short(lo, hi));
        // The same list, one edge at a time.
        for (_, a, b) in serial.short_edges(lo) {
            let r = &mut serial;
            if r.vt[a as usize].is_empty()
                || r.vt[b as usize].is_empty()
                || !r.has_edge(a, b)
                || r.rel(a, b) >= lo
            {
                continue;
            }
            let around = r.changed_around(&[a, b]);
            if r.no_collapse.get(&(a, b)).is_some_and(|&at| at > around) {
                continue;
            }
            if !r.collapse(a, b, hi) && !r.collapse(b, a, hi) {
                r.clock += 1;
                r.no_collapse.insert((a, b), r.clock);
            }
        }
        assert!(again > 0, "no collapse was checked again");
        assert!(batched.counts.collapses > 100, "{:?}", batched.counts);
        assert_same(&batched, &serial);
    }

    /// A pool of two threads, so batches are checked in parallel.
    pub(in super::super) fn two_threads() -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("pool")
    }

    /// The two surfaces are the same to the bit, with the same operations done and the same
    /// covers of the input samples.
    pub(in super::super) fn assert_same(a: &Remesher, b: &Remesher) {
        assert_eq!(a.counts, b.counts);
        assert_eq!(a.tris, b.tris);
        assert_eq!(a.alive, b.alive);
        let bits =
            |p: &[[f64; 3]]| -> Vec<[u64; 3]> { p.iter().map(|x| x.map(f64::to_bits)).collect() };
        assert_eq!(bits(&a.pts), bits(&b.pts));
        assert_eq!(a.cover, b.cover);
    }

    /// The clean-up in batches leaves the surface that treating one triangle at a time leaves
    /// (the loop as it was before batches, below): on a sphere of needles and caps at its
    /// poles, with and without middle collapses, to the bit.
    #[test]
    fn the_batched_clean_up_ends_as_one_at_a_time() {
        let s = uv_sphere(1.0, [0.0; 3], 96, 12);
        let l = median_edge_length(&s);
        let d = 0.02;
        let fx = Fixture::new(&s, d, l);
        let mut batched = fx.remesher(&s, d, l);
        let mut serial = fx.remesher(&s, d, l);
        let pool = two_threads();
        let mut done = 0;
        for middle in [false, true] {
            batched.middle = middle;
            serial.middle = middle;
            for _ in 0..3 {
                done += pool.install(|| batched.clean_up());
                one_at_a_time(&mut serial);
            }
        }
        assert!(done > 50, "{done}: the clean-up did little");
        assert_same(&batched, &serial);
    }

    /// [`Remesher::clean_up`] one triangle at a time.
    fn one_at_a_time(r: &mut Remesher) {
        let hi = 4.0 / 3.0;
        let bad: Vec<u32> = (0..r.tris.len() as u32)
            .filter(|&t| r.alive[t as usize] && min_angle_deg(&r.corners(t)) < r.target_angle)
            .collect();
        if r.failed_middle != r.middle {
            r.failed_middle = r.middle;
            r.failed_at.fill(0);
        }
        for t in bad {
            if !r.alive[t as usize] || min_angle_deg(&r.corners(t)) >= r.target_angle {
                continue;
            }
            if r.failed_at[t as usize] > r.changed_around(&r.tris[t as usize]) {
                continue;
            }
            // The flips and collapses one at a time (what the batches check ahead); the last
            // resorts are applied as they come in either way.
            let e = r.edges_by(t, |a, b| r.len(a, b));
            let mut ok = e.iter().rev().any(|&(_, a, b)| r.flip(a, b));
            for &(_, a, b) in &e {
                if ok {
                    break;
                }
                ok = r.collapse(a, b, hi * 1.25) || r.collapse(b, a, hi * 1.25);
            }
            if !ok && r.middle {
                let (_, a, b) = e[0];
                ok = r.collapse_mid(a, b, hi * 1.25);
            }
            r.clean_rest(t, ok);
        }
    }
}
