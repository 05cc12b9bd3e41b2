//! The final measure of the output surface against the input, both ways
//! ([`super::hausdorff`]), kept from one repair round to the next.
//!
//! A repair round changes a few triangles of tens of thousands, and measuring the whole output
//! again cost a quarter of a second a round on wm_20k. So each triangle's measure is kept and
//! reused where it cannot have changed:
//! - output → input: a triangle's measure depends on its corners and the input alone, so an
//!   output triangle with the same corners (to the bit) and side labels keeps its measure;
//! - input → output: a triangle's bound was proven by output triangles within the tolerance of
//!   it (its bound is at most the tolerance unless it was listed as far), so where no output
//!   triangle within the tolerance of its box was removed or added, the bound stands. Listed
//!   triangles are always measured again (their nearest output triangle is named by index).
//!
//! The reused measures are the ones a full measure made on an earlier output; where added
//! triangles come closer than before, they are upper bounds still.

use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};

use super::bvh::PatchIndex;
use super::grid::Grid;
use super::hausdorff::{Per, Sampling, Sided, one_sided_reusing};
use crate::geom::vec3::bbox;
use crate::mesh::surface::SurfaceMesh;

type P3 = [f64; 3];

/// A triangle by its corners (to the bit, in order) and side labels.
type Key = ([[u64; 3]; 3], [u32; 2]);

fn key(s: &SurfaceMesh, t: usize) -> Key {
    (
        s.triangles[t].map(|v| s.points[v as usize].map(f64::to_bits)),
        s.sides[t],
    )
}

/// The measures made at one floor ([`Sampling::floor`]) on the output measured last at it.
struct Kept {
    floor: f64,
    /// Per triangle of that output: its measure output → input and its box.
    oi: FxHashMap<Key, (Per, (P3, P3))>,
    /// Per input triangle: its measure input → output.
    io: Vec<Per>,
}

/// The final measure of outputs of one input at tolerance `d`, keeping what it measured.
pub(super) struct Measure<'a> {
    input: &'a SurfaceMesh,
    index: &'a PatchIndex,
    spacing: f64,
    d: f64,
    kept: Vec<Kept>,
}

impl<'a> Measure<'a> {
    /// Measures against `input` (indexed by `index`) with samples at most `spacing` apart,
    /// proving the tolerance `d`.
    pub(super) fn new(
        input: &'a SurfaceMesh,
        index: &'a PatchIndex,
        spacing: f64,
        d: f64,
    ) -> Measure<'a> {
        Measure {
            input,
            index,
            spacing,
            d,
            kept: Vec::new(),
        }
    }

    /// The distances output → input and input → output of `out` (dense samples, every cell that
    /// cannot prove the tolerance `d` sampled finer until it does or its samples are a thousandth
    /// of `spacing` apart), listing the triangles beyond `d` or not proven within it.
    pub(super) fn measure(&mut self, out: &SurfaceMesh) -> (Sided, Sided) {
        let out_index = PatchIndex::new(&out.points, &out.triangles, &out.sides, None);
        let keys: Vec<Key> = (0..out.triangles.len()).map(|t| key(out, t)).collect();
        let d = self.d;
        // First with the samples under 0.4 D left unmeasured (then a triangle whose samples are
        // all under it is proven within 0.4 D + D/√3 < D by its coarse samples alone); exactly
        // if some sheet is below that.
        let (oi, io) = self.at(0.4 * d, out, &out_index, &keys);
        if oi
            .per_sheet
            .iter()
            .chain(&io.per_sheet)
            .any(|x| x.1 <= 0.4 * d)
        {
            return self.at(0.0, out, &out_index, &keys);
        }
        (oi, io)
    }

    /// Both ways at one floor, reusing what was kept at it.
    fn at(
        &mut self,
        floor: f64,
        out: &SurfaceMesh,
        out_index: &PatchIndex,
        keys: &[Key],
    ) -> (Sided, Sided) {
        let s = Sampling {
            spacing: self.spacing,
            fine: self.spacing / 1024.0,
            limit: self.d,
            flag: self.d,
            floor,
        };
        let i = self.kept.iter().position(|k| k.floor == floor);
        let kept = i.map(|i| &self.kept[i]);
        let (oi, oi_per) = one_sided_reusing(
            (&out.points, &out.triangles, &out.sides, None),
            self.index,
            &s,
            |t| {
                let (p, _) = kept?.oi.get(&keys[t])?;
                let mut p = p.clone();
                if let Some(f) = &mut p.far {
                    f.triangle = t as u32;
                }
                Some(p)
            },
        );
        let stale = kept.map(|k| self.stale(k, out, keys));
        let input = self.input;
        let (io, io_per) = one_sided_reusing(
            (&input.points, &input.triangles, &input.sides, None),
            out_index,
            &s,
            |t| {
                let (k, stale) = (kept?, stale.as_ref()?);
                let p = k.io.get(t).filter(|p| p.far.is_none() && !stale[t])?;
                Some(p.clone())
            },
        );
        let oi_kept = keys
            .iter()
            .zip(oi_per)
            .enumerate()
            .map(|(t, (&k, p))| (k, (p, bbox(&out.corners(t)))))
            .collect();
        let new = Kept {
            floor,
            oi: oi_kept,
            io: io_per,
        };
        match i {
            Some(i) => self.kept[i] = new,
            None => self.kept.push(new),
        }
        (oi, io)
    }

    /// Per input triangle: whether an output triangle within the tolerance of its box is new
    /// since `k` was measured, or gone.
    fn stale(&self, k: &Kept, out: &SurfaceMesh, keys: &[Key]) -> Vec<bool> {
        let d = self.d;
        let mut changed = Grid::new(4.0 * d.max(self.spacing));
        let mut n = 0u32;
        for (t, key) in keys.iter().enumerate() {
            if !k.oi.contains_key(key) {
                let (lo, hi) = bbox(&out.corners(t));
                changed.insert_box(n, lo, hi);
                n += 1;
            }
        }
        let now: FxHashSet<&Key> = keys.iter().collect();
        for (key, (_, (lo, hi))) in &k.oi {
            if !now.contains(key) {
                changed.insert_box(n, *lo, *hi);
                n += 1;
            }
        }
        let input = self.input;
        (0..input.triangles.len())
            .into_par_iter()
            .map(|t| {
                let (lo, hi) = bbox(&input.corners(t));
                changed.any(lo.map(|x| x - d), hi.map(|x| x + d), |_| true)
            })
            .collect()
    }
}

/// The distances output → input and input → output of `out` ([`Measure::measure`], nothing
/// kept).
#[cfg(test)]
pub(super) fn final_measure(
    input: &SurfaceMesh,
    out: &SurfaceMesh,
    index: &PatchIndex,
    spacing: f64,
    d: f64,
) -> (Sided, Sided) {
    Measure::new(input, index, spacing, d).measure(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::hausdorff::Far;
    use crate::surface::tests::uv_sphere;

    fn far_of(s: &Sided) -> Vec<(u32, u32, [u64; 3])> {
        let mut v: Vec<_> = s
            .far
            .iter()
            .map(|f: &Far| (f.triangle, f.nearest, f.point.map(f64::to_bits)))
            .collect();
        v.sort_unstable();
        v
    }

    /// Measured again after one point of the output moved beyond the tolerance and its
    /// triangles were listed in the opposite order, the kept measure finds what a fresh one
    /// finds: the same largest distances and bounds both ways and the same far samples, named by
    /// the new triangle numbers.
    #[test]
    fn a_kept_measure_finds_what_a_fresh_one_finds() {
        let input = uv_sphere(1.0, [0.0; 3], 48, 24);
        let index = PatchIndex::new(&input.points, &input.triangles, &input.sides, None);
        let (spacing, d) = (0.01, 0.03);
        let mut out = uv_sphere(1.0, [0.0; 3], 40, 20);
        let mut kept = Measure::new(&input, &index, spacing, d);
        let (oi0, io0) = kept.measure(&out);
        assert!(oi0.far.is_empty() && io0.far.is_empty(), "{}", oi0.max);
        out.points[300] = out.points[300].map(|x| x * 1.06);
        out.triangles.reverse();
        out.sides.reverse();
        let (oi, io) = kept.measure(&out);
        let (oi_f, io_f) = final_measure(&input, &out, &index, spacing, d);
        assert!(oi.max > d && io.max > d, "{} {}", oi.max, io.max);
        for (a, b) in [(&oi, &oi_f), (&io, &io_f)] {
            assert_eq!(a.max.to_bits(), b.max.to_bits());
            assert_eq!(a.bound.to_bits(), b.bound.to_bits());
            assert_eq!(far_of(a), far_of(b));
        }
    }
}
