//! One relaxation sweep over every point, its checks run in parallel where points are far apart.
//!
//! The points are bucketed in cubes a few edge lengths wide, and the cubes in eight classes by
//! the parity of their coordinates. Each step takes the `k`-th point (by index) of every cube of
//! one class: their moves are checked in parallel against the surface as it stands (checking
//! reads the surface only; [`Remesher::check_relax`]), then applied one by one in cube order. Two
//! points of a step lie in different cubes of one parity, a cube's width apart, which is more
//! than the reach of a move (its fan's box, grown by the tolerance the distance checks look
//! within) in all but rare cases; a move whose reach meets that of a move applied before it in
//! the step is checked again first. So a sweep gives what checking and applying one point at a
//! time in this order gives, on any number of threads ([`super::batch`] does the same for an
//! ordered list of operations).

use super::batch::{Boxed, Taken, Wrote, grow};
use super::{Move, Remesher};

impl Remesher<'_> {
    /// Relax every point once ([`Self::relax`]), in the order of the module's steps; the number
    /// of moves checked again.
    pub fn relax_all(&mut self) -> usize {
        let reach = self.reach();
        let cube = 4.0 * self.l + 4.0 * reach;
        let mut taken = Taken::new(cube / 4.0);
        let mut again = 0;
        for step in self.steps(cube) {
            // Checked in parallel, applied in order ([`super::batch`]).
            again += self.in_batches_with(
                &step,
                &mut taken,
                |r, &v| r.checked_relax(v),
                |r, _, m| match m {
                    Some(m) => {
                        r.apply_move(m);
                        Wrote::Read
                    }
                    None => Wrote::Nothing,
                },
            );
        }
        again
    }

    /// The points to relax, step by step: the `k`-th point of every cube (side `cube`) of one
    /// parity class, classes in turn.
    fn steps(&self, cube: f64) -> Vec<Vec<u32>> {
        let points = (0..self.pts.len() as u32)
            .filter(|&v| !self.vt[v as usize].is_empty() && !self.is_fixed(v));
        if !(cube.is_finite() && cube > 0.0) {
            return points.map(|v| vec![v]).collect();
        }
        // (class, cube, point), sorted: each class's cubes in order, each cube's points in order.
        let mut order: Vec<(u8, [i64; 3], u32)> = points
            .map(|v| {
                let c = self.pts[v as usize].map(|x| (x / cube).floor() as i64);
                let class = (c[0] & 1) | (c[1] & 1) << 1 | (c[2] & 1) << 2;
                (class as u8, c, v)
            })
            .collect();
        order.sort_unstable();
        let mut steps = Vec::new();
        let mut i = 0;
        while i < order.len() {
            let class = order[i].0;
            let end = i + order[i..].partition_point(|x| x.0 == class);
            // The cubes of this class: ranges of `order`.
            let mut cubes: Vec<(usize, usize)> = Vec::new();
            let mut a = i;
            while a < end {
                let b = a + order[a..end].partition_point(|x| x.1 == order[a].1);
                cubes.push((a, b));
                a = b;
            }
            let depth = cubes.iter().map(|&(a, b)| b - a).max().unwrap_or(0);
            for k in 0..depth {
                steps.push(
                    cubes
                        .iter()
                        .filter(|&&(a, b)| a + k < b)
                        .map(|&(a, _)| order[a + k].2)
                        .collect(),
                );
            }
            i = end;
        }
        steps
    }

    /// [`Self::check_relax`] with the box its checks read: the fan's corners and the new
    /// place, grown by [`Self::reach`].
    fn checked_relax(&self, v: u32) -> (Boxed, Option<Move>) {
        let target = self.relax_target(v);
        let m = target.and_then(|(x, h)| self.check_move(v, x, Some(h)));
        let fans = self.fans_box(&[v]);
        let read = match target {
            Some((x, _)) => {
                let (lo, hi) = grow((x, x), self.reach());
                (
                    [0, 1, 2].map(|k| fans.0[k].min(lo[k])),
                    [0, 1, 2].map(|k| fans.1[k].max(hi[k])),
                )
            }
            None => fans,
        };
        (read, m)
    }
}

#[cfg(test)]
mod tests {
    use super::super::batch::tests::{assert_same, two_threads};
    use super::super::tests::Fixture;
    use crate::surface::{median_edge_length, tests::uv_sphere};

    /// The sweep moves every point where relaxing the points one at a time in its order would:
    /// on a sphere whose triangles are ten target lengths long (so neighbours share a step and
    /// moves must be checked again), to the bit.
    #[test]
    fn the_sweep_moves_points_as_one_at_a_time_would() {
        let s = uv_sphere(1.0, [0.0; 3], 24, 12);
        let l = 0.1 * median_edge_length(&s);
        let d = 0.02;
        let fx = Fixture::new(&s, d, l);
        let mut swept = fx.remesher(&s, d, l);
        let mut serial = fx.remesher(&s, d, l);
        let pool = two_threads();
        let mut again = 0;
        for _ in 0..3 {
            let reach = serial.tol * (1.0 + 1e-6);
            for step in serial.steps(4.0 * serial.l + 4.0 * reach) {
                for v in step {
                    serial.relax(v);
                }
            }
            again += pool.install(|| swept.relax_all());
        }
        assert!(again > 0, "no move was checked again");
        assert!(swept.counts.moves > 0);
        assert_same(&swept, &serial);
    }
}
