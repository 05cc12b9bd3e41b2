//! Whole-mesh quality reports: [`QualityReport`] for tet meshes and [`TriQualityReport`] for 2D
//! triangle meshes.
//!
//! Both are one sequential pass over the elements in index order, so every sum is taken in the
//! same order and the same mesh always gives the same report, bit for bit (and byte-identical
//! JSON). Both serialize with serde; `Display` prints a compact table for a terminal.
//!
//! Empty meshes are fine: statistics that need at least one element (`min_*`, `max_*`, `mean_*`)
//! are `None` (JSON `null`), counts and totals are 0, histograms are all zeros and the lists are
//! empty. No field is ever NaN unless the coordinates are.

use std::fmt;

use rustc_hash::FxHashMap;
use serde::Serialize;

use super::interfaces::{InterfaceFaces, interface_faces};
use super::tet::{REGULAR_SOLID_ANGLE, TetMeasures};
use super::tri::TriMeasures;
use crate::mesh::tet::TetMesh;
use crate::mesh::tri::TriMesh;

/// Width (degrees) of the bins of the dihedral-angle and triangle-angle histograms: 18 bins over
/// `[0°, 180°]`.
pub const ANGLE_BIN_DEG: f64 = 10.0;
/// Width (degrees) of the bins of the per-element minimum-angle histograms: 18 bins over
/// `[0°, 90°]` (a tet's smallest dihedral angle is at most acos(1/3) ≈ 70.53°, a triangle's
/// smallest angle at most 60°).
pub const MIN_ANGLE_BIN_DEG: f64 = 5.0;
/// Width (steradians) of the bins of the solid-angle histogram.
pub const SOLID_BIN_SR: f64 = 0.05;
/// Number of solid-angle bins: 126 × 0.05 sr covers `[0, 6.3]`, which holds every solid angle of
/// a positively oriented tet (they are below 2π ≈ 6.2832, the limit of a vertex pushed flat into
/// its opposite face). Inverted tets have negative solid angles; they land in
/// [`Histogram::below`].
pub const SOLID_BINS: usize = 126;
/// Number of worst elements listed in [`QualityReport::worst_tets`] and
/// [`TriQualityReport::worst_triangles`].
pub const N_WORST: usize = 10;
/// The thresholds (degrees) of the `n_*_lt_*` counts: elements whose smallest angle is below.
pub const LOW_ANGLE_THRESHOLDS_DEG: [f64; 3] = [5.0, 10.0, 20.0];
/// The thresholds (degrees) of the `n_*_gt_*` counts: elements whose largest angle is above.
pub const HIGH_ANGLE_THRESHOLDS_DEG: [f64; 3] = [160.0, 170.0, 175.0];

/// A histogram with equal-width bins.
///
/// Bin `i` holds the values `x` with `lo + i·width <= x < lo + (i+1)·width`, so a value on a bin
/// edge goes to the bin above; the last bin also holds `x == hi`. Values below `lo` (and NaN) are
/// counted in `below`, values above `hi` in `above`.
///
/// Values less than [`Histogram::EDGE_SNAP`] bin widths below an edge count as on it: angles that
/// are exactly 60° or 90° in theory come out as 59.99999999999999° or 90.00000000000001° in
/// floating point, and a structured mesh would otherwise split them between two bins at random.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Histogram {
    /// Left edge of the first bin.
    pub lo: f64,
    /// Right edge of the last bin, `lo + width · counts.len()`.
    pub hi: f64,
    /// Bin width.
    pub width: f64,
    /// Count per bin.
    pub counts: Vec<u64>,
    /// Values below `lo`, or NaN.
    pub below: u64,
    /// Values above `hi`.
    pub above: u64,
}

impl Histogram {
    /// How far below a bin edge (in bin widths) a value still counts as on the edge.
    pub const EDGE_SNAP: f64 = 1e-9;

    /// An empty histogram of `n` bins of `width` starting at `lo`.
    pub fn new(lo: f64, width: f64, n: usize) -> Histogram {
        assert!(
            n > 0 && width > 0.0,
            "a histogram needs bins of positive width"
        );
        Histogram {
            lo,
            hi: lo + width * n as f64,
            width,
            counts: vec![0; n],
            below: 0,
            above: 0,
        }
    }

    /// Count `x`.
    #[inline]
    pub fn add(&mut self, x: f64) {
        if x.is_nan() || x < self.lo {
            self.below += 1;
            return;
        }
        // `as` saturates for huge values.
        let i = ((x - self.lo) / self.width + Self::EDGE_SNAP) as usize;
        if let Some(c) = self.counts.get_mut(i) {
            *c += 1;
        } else if x <= self.hi {
            *self.counts.last_mut().expect("at least one bin") += 1;
        } else {
            self.above += 1;
        }
    }

    /// Left edge of bin `i`.
    pub fn bin_lo(&self, i: usize) -> f64 {
        self.lo + self.width * i as f64
    }

    /// Right edge of bin `i`.
    pub fn bin_hi(&self, i: usize) -> f64 {
        self.lo + self.width * (i + 1) as f64
    }

    /// Every counted value: the bins plus `below` and `above`.
    pub fn total(&self) -> u64 {
        self.counts.iter().sum::<u64>() + self.below + self.above
    }

    /// The index range from the first to the last non-empty bin, `None` if all bins are empty.
    pub fn occupied(&self) -> Option<std::ops::RangeInclusive<usize>> {
        let first = self.counts.iter().position(|&c| c > 0)?;
        let last = self.counts.iter().rposition(|&c| c > 0)?;
        Some(first..=last)
    }
}

/// Running min / max / sum of one measure.
#[derive(Debug, Clone, Copy)]
struct Stat {
    n: u64,
    min: f64,
    max: f64,
    sum: f64,
}

impl Stat {
    const EMPTY: Stat = Stat {
        n: 0,
        min: f64::INFINITY,
        max: f64::NEG_INFINITY,
        sum: 0.0,
    };

    #[inline]
    fn add(&mut self, x: f64) {
        self.n += 1;
        self.min = self.min.min(x);
        self.max = self.max.max(x);
        self.sum += x;
    }

    fn min(&self) -> Option<f64> {
        (self.n > 0).then_some(self.min)
    }

    fn max(&self) -> Option<f64> {
        (self.n > 0).then_some(self.max)
    }

    fn mean(&self) -> Option<f64> {
        (self.n > 0).then(|| self.sum / self.n as f64)
    }
}

/// Label → slot in a per-region table, remembering the last label (consecutive elements usually
/// share one).
struct RegionIndex {
    map: FxHashMap<u32, usize>,
    last: Option<(u32, usize)>,
}

impl RegionIndex {
    fn new() -> RegionIndex {
        RegionIndex {
            map: FxHashMap::default(),
            last: None,
        }
    }

    /// The slot of `label`, calling `push` to make one when it is new.
    #[inline]
    fn slot(&mut self, label: u32, push: impl FnOnce() -> usize) -> usize {
        if let Some((l, s)) = self.last
            && l == label
        {
            return s;
        }
        let s = *self.map.entry(label).or_insert_with(push);
        self.last = Some((label, s));
        s
    }
}

/// The `N_WORST` smallest keys seen, ties broken by the lower element index (the earlier one).
struct Worst<T> {
    items: Vec<(f64, usize, T)>,
}

impl<T> Worst<T> {
    fn new() -> Worst<T> {
        Worst {
            items: Vec::with_capacity(N_WORST + 1),
        }
    }

    /// Offer element `idx` with `key` (elements must come in increasing index order).
    #[inline]
    fn offer(&mut self, key: f64, idx: usize, item: impl FnOnce() -> T) {
        if self.items.len() == N_WORST
            && key.total_cmp(&self.items[N_WORST - 1].0) != std::cmp::Ordering::Less
        {
            return;
        }
        // Strictly after every equal key: those have lower indices.
        let pos = self
            .items
            .partition_point(|(k, _, _)| k.total_cmp(&key) != std::cmp::Ordering::Greater);
        self.items.insert(pos, (key, idx, item()));
        self.items.truncate(N_WORST);
    }
}

/// Counts of elements past the angle thresholds, in the order of [`LOW_ANGLE_THRESHOLDS_DEG`]
/// and [`HIGH_ANGLE_THRESHOLDS_DEG`].
#[derive(Debug, Clone, Copy, Default)]
struct Thresholds {
    low: [u64; 3],
    high: [u64; 3],
}

impl Thresholds {
    #[inline]
    fn add(&mut self, min_deg: f64, max_deg: f64) {
        for (c, &th) in self.low.iter_mut().zip(&LOW_ANGLE_THRESHOLDS_DEG) {
            *c += u64::from(min_deg < th);
        }
        for (c, &th) in self.high.iter_mut().zip(&HIGH_ANGLE_THRESHOLDS_DEG) {
            *c += u64::from(max_deg > th);
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Tet meshes
// ------------------------------------------------------------------------------------------------

/// Quality of a tet mesh: summary statistics, threshold counts, histograms, the worst tets and a
/// summary per region. Built by [`QualityReport::of`]; every measure comes from
/// [`TetMeasures::of`] on the tet's corners.
///
/// Angles are in degrees, solid angles in steradians. `q` is eq. 4.9 (1 for the regular tet),
/// the radius ratio is 3·r_in/R_circ (1 for the regular tet); both are negative for inverted
/// tets. Statistics over no tets are `None`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct QualityReport {
    /// Number of points of the mesh (used or not).
    pub n_points: usize,
    /// Number of tets.
    pub n_tets: usize,
    /// Number of distinct region labels among the tets.
    pub n_regions: usize,
    /// Sum of the signed tet volumes (0 for no tets).
    pub volume: f64,
    /// Smallest dihedral angle of any tet.
    pub min_dihedral_deg: Option<f64>,
    /// Largest dihedral angle of any tet.
    pub max_dihedral_deg: Option<f64>,
    /// Mean over all six dihedral angles of every tet.
    pub mean_dihedral_deg: Option<f64>,
    /// Mean over the tets of their smallest dihedral angle.
    pub mean_min_dihedral_deg: Option<f64>,
    /// Smallest solid angle at any tet corner.
    pub min_solid_angle_sr: Option<f64>,
    /// Largest solid angle at any tet corner.
    pub max_solid_angle_sr: Option<f64>,
    /// Mean over all four solid angles of every tet.
    pub mean_solid_angle_sr: Option<f64>,
    /// Smallest q.
    pub min_q: Option<f64>,
    /// Largest q.
    pub max_q: Option<f64>,
    /// Mean q.
    pub mean_q: Option<f64>,
    /// Smallest radius ratio.
    pub min_radius_ratio: Option<f64>,
    /// Largest radius ratio.
    pub max_radius_ratio: Option<f64>,
    /// Mean radius ratio.
    pub mean_radius_ratio: Option<f64>,
    /// Tets whose smallest dihedral angle is below 5°.
    pub n_dihedral_lt_5: u64,
    /// Tets whose smallest dihedral angle is below 10°.
    pub n_dihedral_lt_10: u64,
    /// Tets whose smallest dihedral angle is below 20°.
    pub n_dihedral_lt_20: u64,
    /// Tets whose largest dihedral angle is above 160°.
    pub n_dihedral_gt_160: u64,
    /// Tets whose largest dihedral angle is above 170°.
    pub n_dihedral_gt_170: u64,
    /// Tets whose largest dihedral angle is above 175°.
    pub n_dihedral_gt_175: u64,
    /// Tets whose floating-point signed volume is `<= 0` (informational: orientation is decided
    /// by the exact predicates, not by this count).
    pub n_inverted: u64,
    /// All six dihedral angles of every tet, 10° bins over `[0°, 180°]`
    /// ([`ANGLE_BIN_DEG`]).
    pub dihedral_histogram: Histogram,
    /// The smallest dihedral angle of every tet, 5° bins over `[0°, 90°]`
    /// ([`MIN_ANGLE_BIN_DEG`]).
    pub min_dihedral_histogram: Histogram,
    /// All four solid angles of every tet, 0.05 sr bins over `[0, 6.3]` ([`SOLID_BIN_SR`],
    /// [`SOLID_BINS`]); inverted tets' negative angles are in `below`.
    pub solid_angle_histogram: Histogram,
    /// The [`N_WORST`] tets with the smallest minimum dihedral angle, worst first (ties: lower
    /// index first).
    pub worst_tets: Vec<WorstTet>,
    /// One summary per region label, by increasing label.
    pub regions: Vec<RegionQuality>,
    /// The faces between each pair of labels that meet (`[0, r]`: region r's boundary), by
    /// increasing pair ([`interface_faces`]).
    pub interfaces: Vec<InterfaceFaces>,
}

/// One of the worst tets of a [`QualityReport`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WorstTet {
    /// Tet index.
    pub tet: usize,
    /// Its region label.
    pub label: u32,
    /// Its smallest dihedral angle.
    pub min_dihedral_deg: f64,
    /// Its largest dihedral angle.
    pub max_dihedral_deg: f64,
    /// Its six dihedral angles, at the edges of [`crate::mesh::tet::TET_EDGES`].
    pub dihedral_deg: [f64; 6],
    /// Its four solid angles.
    pub solid_angle_sr: [f64; 4],
    /// Its q.
    pub q: f64,
    /// Its signed volume.
    pub volume: f64,
}

/// The quality of one region (the tets with one label) of a [`QualityReport`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegionQuality {
    /// Region label.
    pub label: u32,
    /// Number of tets.
    pub n_tets: u64,
    /// Sum of their signed volumes.
    pub volume: f64,
    /// Smallest dihedral angle.
    pub min_dihedral_deg: f64,
    /// Largest dihedral angle.
    pub max_dihedral_deg: f64,
    /// Smallest solid angle.
    pub min_solid_angle_sr: f64,
    /// Smallest q.
    pub min_q: f64,
    /// Mean q.
    pub mean_q: f64,
    /// Tets with floating-point signed volume `<= 0`.
    pub n_inverted: u64,
}

impl QualityReport {
    /// Measure every tet of `mesh`. A tet without a label (`labels` shorter than `tets`, a
    /// malformed mesh) counts as label 0.
    ///
    /// # Panics
    /// If a tet refers to a point that does not exist.
    pub fn of(mesh: &TetMesh) -> QualityReport {
        let mut dihedral = Stat::EMPTY;
        let mut min_dihedral = Stat::EMPTY;
        let mut solid = Stat::EMPTY;
        let mut q = Stat::EMPTY;
        let mut rr = Stat::EMPTY;
        let mut volume = 0.0;
        let mut n_inverted = 0;
        let mut th = Thresholds::default();
        let mut h_dihedral = Histogram::new(0.0, ANGLE_BIN_DEG, 18);
        let mut h_min_dihedral = Histogram::new(0.0, MIN_ANGLE_BIN_DEG, 18);
        let mut h_solid = Histogram::new(0.0, SOLID_BIN_SR, SOLID_BINS);
        let mut worst = Worst::new();
        let mut regions: Vec<RegionQuality> = Vec::new();
        let mut index = RegionIndex::new();

        for t in 0..mesh.tets.len() {
            let m = TetMeasures::of(&mesh.corners(t));
            let (dmin, dmax) = (m.min_dihedral(), m.max_dihedral());
            let smin = m.min_solid();
            for &d in &m.dihedral_deg {
                dihedral.add(d);
                h_dihedral.add(d);
            }
            for &s in &m.solid_sr {
                solid.add(s);
                h_solid.add(s);
            }
            min_dihedral.add(dmin);
            h_min_dihedral.add(dmin);
            q.add(m.q);
            rr.add(m.radius_ratio);
            volume += m.volume;
            let inverted = m.volume <= 0.0;
            n_inverted += u64::from(inverted);
            th.add(dmin, dmax);

            let label = mesh.labels.get(t).copied().unwrap_or(0);
            worst.offer(dmin, t, || (label, m));

            let s = index.slot(label, || {
                regions.push(RegionQuality {
                    label,
                    n_tets: 0,
                    volume: 0.0,
                    min_dihedral_deg: f64::INFINITY,
                    max_dihedral_deg: f64::NEG_INFINITY,
                    min_solid_angle_sr: f64::INFINITY,
                    min_q: f64::INFINITY,
                    mean_q: 0.0, // the sum until the end
                    n_inverted: 0,
                });
                regions.len() - 1
            });
            let r = &mut regions[s];
            r.n_tets += 1;
            r.volume += m.volume;
            r.min_dihedral_deg = r.min_dihedral_deg.min(dmin);
            r.max_dihedral_deg = r.max_dihedral_deg.max(dmax);
            r.min_solid_angle_sr = r.min_solid_angle_sr.min(smin);
            r.min_q = r.min_q.min(m.q);
            r.mean_q += m.q;
            r.n_inverted += u64::from(inverted);
        }

        for r in &mut regions {
            r.mean_q /= r.n_tets as f64;
        }
        regions.sort_unstable_by_key(|r| r.label);

        QualityReport {
            n_points: mesh.points.len(),
            n_tets: mesh.tets.len(),
            n_regions: regions.len(),
            volume,
            min_dihedral_deg: dihedral.min(),
            max_dihedral_deg: dihedral.max(),
            mean_dihedral_deg: dihedral.mean(),
            mean_min_dihedral_deg: min_dihedral.mean(),
            min_solid_angle_sr: solid.min(),
            max_solid_angle_sr: solid.max(),
            mean_solid_angle_sr: solid.mean(),
            min_q: q.min(),
            max_q: q.max(),
            mean_q: q.mean(),
            min_radius_ratio: rr.min(),
            max_radius_ratio: rr.max(),
            mean_radius_ratio: rr.mean(),
            n_dihedral_lt_5: th.low[0],
            n_dihedral_lt_10: th.low[1],
            n_dihedral_lt_20: th.low[2],
            n_dihedral_gt_160: th.high[0],
            n_dihedral_gt_170: th.high[1],
            n_dihedral_gt_175: th.high[2],
            n_inverted,
            dihedral_histogram: h_dihedral,
            min_dihedral_histogram: h_min_dihedral,
            solid_angle_histogram: h_solid,
            worst_tets: worst
                .items
                .into_iter()
                .map(|(_, tet, (label, m))| WorstTet {
                    tet,
                    label,
                    min_dihedral_deg: m.min_dihedral(),
                    max_dihedral_deg: m.max_dihedral(),
                    dihedral_deg: m.dihedral_deg,
                    solid_angle_sr: m.solid_sr,
                    q: m.q,
                    volume: m.volume,
                })
                .collect(),
            regions,
            interfaces: interface_faces(mesh),
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Triangle meshes
// ------------------------------------------------------------------------------------------------

/// Quality of a 2D triangle mesh: summary statistics, threshold counts, histograms, the worst
/// triangles and a summary per region. Built by [`TriQualityReport::of`] from
/// [`TriMeasures::of`].
///
/// Angles are in degrees. `q` is 4√3·A/ΣL² and the radius ratio 2·r_in/R_circ (both 1 for the
/// equilateral triangle, negative for a clockwise one). Statistics over no triangles are `None`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TriQualityReport {
    /// Number of points of the mesh (used or not).
    pub n_points: usize,
    /// Number of triangles.
    pub n_triangles: usize,
    /// Number of distinct region labels among the triangles.
    pub n_regions: usize,
    /// Sum of the signed triangle areas (0 for no triangles).
    pub area: f64,
    /// Smallest angle of any triangle.
    pub min_angle_deg: Option<f64>,
    /// Largest angle of any triangle.
    pub max_angle_deg: Option<f64>,
    /// Mean over all three angles of every triangle: 60° by construction (the angles of a
    /// triangle sum to 180°), up to rounding; kept for symmetry with the tet report.
    pub mean_angle_deg: Option<f64>,
    /// Mean over the triangles of their smallest angle (the informative mean).
    pub mean_min_angle_deg: Option<f64>,
    /// Smallest q.
    pub min_q: Option<f64>,
    /// Largest q.
    pub max_q: Option<f64>,
    /// Mean q.
    pub mean_q: Option<f64>,
    /// Smallest radius ratio.
    pub min_radius_ratio: Option<f64>,
    /// Largest radius ratio.
    pub max_radius_ratio: Option<f64>,
    /// Mean radius ratio.
    pub mean_radius_ratio: Option<f64>,
    /// Triangles whose smallest angle is below 5°.
    pub n_angle_lt_5: u64,
    /// Triangles whose smallest angle is below 10°.
    pub n_angle_lt_10: u64,
    /// Triangles whose smallest angle is below 20°.
    pub n_angle_lt_20: u64,
    /// Triangles whose largest angle is above 160°.
    pub n_angle_gt_160: u64,
    /// Triangles whose largest angle is above 170°.
    pub n_angle_gt_170: u64,
    /// Triangles whose largest angle is above 175°.
    pub n_angle_gt_175: u64,
    /// Triangles whose floating-point signed area is `<= 0` (clockwise or flat; informational).
    pub n_inverted: u64,
    /// All three angles of every triangle, 10° bins over `[0°, 180°]` ([`ANGLE_BIN_DEG`]).
    pub angle_histogram: Histogram,
    /// The smallest angle of every triangle, 5° bins over `[0°, 90°]` ([`MIN_ANGLE_BIN_DEG`]).
    pub min_angle_histogram: Histogram,
    /// The [`N_WORST`] triangles with the smallest minimum angle, worst first (ties: lower index
    /// first).
    pub worst_triangles: Vec<WorstTriangle>,
    /// One summary per region label, by increasing label.
    pub regions: Vec<TriRegionQuality>,
}

/// One of the worst triangles of a [`TriQualityReport`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WorstTriangle {
    /// Triangle index.
    pub triangle: usize,
    /// Its region label.
    pub label: u32,
    /// Its smallest angle.
    pub min_angle_deg: f64,
    /// Its largest angle.
    pub max_angle_deg: f64,
    /// Its three angles, at its corners.
    pub angles_deg: [f64; 3],
    /// Its q.
    pub q: f64,
    /// Its signed area.
    pub area: f64,
}

/// The quality of one region (the triangles with one label) of a [`TriQualityReport`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TriRegionQuality {
    /// Region label.
    pub label: u32,
    /// Number of triangles.
    pub n_triangles: u64,
    /// Sum of their signed areas.
    pub area: f64,
    /// Smallest angle.
    pub min_angle_deg: f64,
    /// Largest angle.
    pub max_angle_deg: f64,
    /// Smallest q.
    pub min_q: f64,
    /// Mean q.
    pub mean_q: f64,
    /// Triangles with floating-point signed area `<= 0`.
    pub n_inverted: u64,
}

impl TriQualityReport {
    /// Measure every triangle of `mesh`. A triangle without a label (a malformed mesh) counts as
    /// label 0.
    ///
    /// # Panics
    /// If a triangle refers to a point that does not exist.
    pub fn of(mesh: &TriMesh) -> TriQualityReport {
        let mut angle = Stat::EMPTY;
        let mut min_angle = Stat::EMPTY;
        let mut q = Stat::EMPTY;
        let mut rr = Stat::EMPTY;
        let mut area = 0.0;
        let mut n_inverted = 0;
        let mut th = Thresholds::default();
        let mut h_angle = Histogram::new(0.0, ANGLE_BIN_DEG, 18);
        let mut h_min_angle = Histogram::new(0.0, MIN_ANGLE_BIN_DEG, 18);
        let mut worst = Worst::new();
        let mut regions: Vec<TriRegionQuality> = Vec::new();
        let mut index = RegionIndex::new();

        for t in 0..mesh.triangles.len() {
            let m = TriMeasures::of(&mesh.corners(t));
            let (amin, amax) = (m.min_angle(), m.max_angle());
            for &a in &m.angles_deg {
                angle.add(a);
                h_angle.add(a);
            }
            min_angle.add(amin);
            h_min_angle.add(amin);
            q.add(m.q);
            rr.add(m.radius_ratio);
            area += m.area;
            let inverted = m.area <= 0.0;
            n_inverted += u64::from(inverted);
            th.add(amin, amax);

            let label = mesh.labels.get(t).copied().unwrap_or(0);
            worst.offer(amin, t, || (label, m));

            let s = index.slot(label, || {
                regions.push(TriRegionQuality {
                    label,
                    n_triangles: 0,
                    area: 0.0,
                    min_angle_deg: f64::INFINITY,
                    max_angle_deg: f64::NEG_INFINITY,
                    min_q: f64::INFINITY,
                    mean_q: 0.0, // the sum until the end
                    n_inverted: 0,
                });
                regions.len() - 1
            });
            let r = &mut regions[s];
            r.n_triangles += 1;
            r.area += m.area;
            r.min_angle_deg = r.min_angle_deg.min(amin);
            r.max_angle_deg = r.max_angle_deg.max(amax);
            r.min_q = r.min_q.min(m.q);
            r.mean_q += m.q;
            r.n_inverted += u64::from(inverted);
        }

        for r in &mut regions {
            r.mean_q /= r.n_triangles as f64;
        }
        regions.sort_unstable_by_key(|r| r.label);

        TriQualityReport {
            n_points: mesh.points.len(),
            n_triangles: mesh.triangles.len(),
            n_regions: regions.len(),
            area,
            min_angle_deg: angle.min(),
            max_angle_deg: angle.max(),
            mean_angle_deg: angle.mean(),
            mean_min_angle_deg: min_angle.mean(),
            min_q: q.min(),
            max_q: q.max(),
            mean_q: q.mean(),
            min_radius_ratio: rr.min(),
            max_radius_ratio: rr.max(),
            mean_radius_ratio: rr.mean(),
            n_angle_lt_5: th.low[0],
            n_angle_lt_10: th.low[1],
            n_angle_lt_20: th.low[2],
            n_angle_gt_160: th.high[0],
            n_angle_gt_170: th.high[1],
            n_angle_gt_175: th.high[2],
            n_inverted,
            angle_histogram: h_angle,
            min_angle_histogram: h_min_angle,
            worst_triangles: worst
                .items
                .into_iter()
                .map(|(_, triangle, (label, m))| WorstTriangle {
                    triangle,
                    label,
                    min_angle_deg: m.min_angle(),
                    max_angle_deg: m.max_angle(),
                    angles_deg: m.angles_deg,
                    q: m.q,
                    area: m.area,
                })
                .collect(),
            regions,
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Display
// ------------------------------------------------------------------------------------------------

/// `x` with at least `prec` decimals, and enough more to show three significant digits of a small
/// value (a 0.0123° sliver angle must not print as 0.01); below 0.001 in scientific notation.
fn num(x: f64, prec: usize) -> String {
    let a = x.abs();
    if a > 0.0 && a < 1e-3 {
        return format!("{x:.2e}");
    }
    let prec = if a > 0.0 && a < 1.0 {
        prec.max((-a.log10()).floor() as usize + 3).min(12)
    } else {
        prec
    };
    format!("{x:.prec$}")
}

/// [`num`], or "-" for `None`.
fn opt(x: Option<f64>, prec: usize) -> String {
    x.map_or_else(|| "-".to_string(), |x| num(x, prec))
}

/// One `min mean max` row of the summary table.
fn stat_row(
    f: &mut fmt::Formatter<'_>,
    name: &str,
    [min, mean, max]: [Option<f64>; 3],
    prec: usize,
) -> fmt::Result {
    writeln!(
        f,
        "  {name:<18}{:>12}{:>12}{:>12}",
        opt(min, prec),
        opt(mean, prec),
        opt(max, prec)
    )
}

/// The non-empty stretch of an angle histogram, one line per bin with a bar scaled to the fullest
/// bin (a bin with any count gets at least one `#`).
fn histogram_rows(f: &mut fmt::Formatter<'_>, h: &Histogram) -> fmt::Result {
    const BAR: u64 = 40;
    let Some(range) = h.occupied() else {
        return Ok(());
    };
    let peak = h.counts.iter().copied().max().unwrap_or(0).max(1);
    for i in range {
        let c = h.counts[i];
        let bar = if c == 0 { 0 } else { (c * BAR).div_ceil(peak) };
        writeln!(
            f,
            "  {:>4}-{:<4}{c:>12}  {}",
            h.bin_lo(i),
            h.bin_hi(i),
            "#".repeat(bar as usize)
        )?;
    }
    Ok(())
}

/// Shortest decimal form of a threshold, e.g. `5` or `17.5`.
fn th(x: f64) -> String {
    format!("{x}")
}

/// The threshold-count lines.
fn threshold_rows(
    f: &mut fmt::Formatter<'_>,
    what: &str,
    noun: &str,
    low: [u64; 3],
    high: [u64; 3],
) -> fmt::Result {
    write!(f, "  {noun} with min {what}")?;
    for (t, c) in LOW_ANGLE_THRESHOLDS_DEG.iter().zip(low) {
        write!(f, "  <{}°: {c}", th(*t))?;
    }
    writeln!(f)?;
    write!(f, "  {noun} with max {what}")?;
    for (t, c) in HIGH_ANGLE_THRESHOLDS_DEG.iter().zip(high) {
        write!(f, "  >{}°: {c}", th(*t))?;
    }
    writeln!(f)
}

impl fmt::Display for QualityReport {
    /// A compact table: totals, min/mean/max of each measure, threshold counts, the dihedral
    /// histogram, the worst tets and one line per region.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "tets {}  points {}  regions {}  volume {:.6e}  inverted {}",
            self.n_tets, self.n_points, self.n_regions, self.volume, self.n_inverted
        )?;
        if self.n_tets == 0 {
            return Ok(());
        }
        writeln!(f, "  {:<18}{:>12}{:>12}{:>12}", "", "min", "mean", "max")?;
        let s = self;
        stat_row(
            f,
            "dihedral (deg)",
            [s.min_dihedral_deg, s.mean_dihedral_deg, s.max_dihedral_deg],
            2,
        )?;
        stat_row(
            f,
            "smallest dihedral",
            [s.min_dihedral_deg, s.mean_min_dihedral_deg, None],
            2,
        )?;
        stat_row(
            f,
            "solid angle (sr)",
            [
                s.min_solid_angle_sr,
                s.mean_solid_angle_sr,
                s.max_solid_angle_sr,
            ],
            4,
        )?;
        stat_row(f, "q", [s.min_q, s.mean_q, s.max_q], 4)?;
        stat_row(
            f,
            "radius ratio",
            [s.min_radius_ratio, s.mean_radius_ratio, s.max_radius_ratio],
            4,
        )?;
        writeln!(
            f,
            "  (regular tet: dihedral {:.2}°, solid angle {:.4} sr, q = radius ratio = 1)",
            (1.0f64 / 3.0).acos().to_degrees(),
            REGULAR_SOLID_ANGLE
        )?;
        threshold_rows(
            f,
            "dihedral",
            "tets",
            [s.n_dihedral_lt_5, s.n_dihedral_lt_10, s.n_dihedral_lt_20],
            [
                s.n_dihedral_gt_160,
                s.n_dihedral_gt_170,
                s.n_dihedral_gt_175,
            ],
        )?;
        writeln!(f, "dihedral angles (deg, all 6 per tet):")?;
        histogram_rows(f, &s.dihedral_histogram)?;
        if !s.worst_tets.is_empty() {
            write!(f, "worst tets:")?;
            for w in s.worst_tets.iter().take(5) {
                write!(f, " #{} {}°", w.tet, num(w.min_dihedral_deg, 2))?;
            }
            writeln!(f)?;
        }
        writeln!(
            f,
            "  {:>8}{:>10}{:>14}{:>9}{:>9}{:>10}{:>8}{:>5}",
            "region", "tets", "volume", "min dih", "max dih", "min solid", "min q", "inv"
        )?;
        for r in &s.regions {
            writeln!(
                f,
                "  {:>8}{:>10}{:>14.6e}{:>9}{:>9}{:>10}{:>8}{:>5}",
                r.label,
                r.n_tets,
                r.volume,
                num(r.min_dihedral_deg, 2),
                num(r.max_dihedral_deg, 2),
                num(r.min_solid_angle_sr, 4),
                num(r.min_q, 4),
                r.n_inverted
            )?;
        }
        for i in &s.interfaces {
            let name = if i.labels[0] == 0 {
                format!("boundary of region {}", i.labels[1])
            } else {
                format!("interface {}|{}", i.labels[0], i.labels[1])
            };
            writeln!(f, "  {name}: {} faces, area {:.6e}", i.n_faces, i.area)?;
        }
        Ok(())
    }
}

impl fmt::Display for TriQualityReport {
    /// A compact table: totals, min/mean/max of each measure, threshold counts, the angle
    /// histogram, the worst triangles and one line per region.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "triangles {}  points {}  regions {}  area {:.6e}  inverted {}",
            self.n_triangles, self.n_points, self.n_regions, self.area, self.n_inverted
        )?;
        if self.n_triangles == 0 {
            return Ok(());
        }
        writeln!(f, "  {:<18}{:>12}{:>12}{:>12}", "", "min", "mean", "max")?;
        let s = self;
        stat_row(
            f,
            "angle (deg)",
            [s.min_angle_deg, s.mean_angle_deg, s.max_angle_deg],
            2,
        )?;
        stat_row(
            f,
            "smallest angle",
            [s.min_angle_deg, s.mean_min_angle_deg, None],
            2,
        )?;
        stat_row(f, "q", [s.min_q, s.mean_q, s.max_q], 4)?;
        stat_row(
            f,
            "radius ratio",
            [s.min_radius_ratio, s.mean_radius_ratio, s.max_radius_ratio],
            4,
        )?;
        threshold_rows(
            f,
            "angle",
            "triangles",
            [s.n_angle_lt_5, s.n_angle_lt_10, s.n_angle_lt_20],
            [s.n_angle_gt_160, s.n_angle_gt_170, s.n_angle_gt_175],
        )?;
        writeln!(f, "angles (deg, all 3 per triangle):")?;
        histogram_rows(f, &s.angle_histogram)?;
        if !s.worst_triangles.is_empty() {
            write!(f, "worst triangles:")?;
            for w in s.worst_triangles.iter().take(5) {
                write!(f, " #{} {}°", w.triangle, num(w.min_angle_deg, 2))?;
            }
            writeln!(f)?;
        }
        writeln!(
            f,
            "  {:>8}{:>10}{:>14}{:>9}{:>9}{:>8}{:>5}",
            "region", "triangles", "area", "min ang", "max ang", "min q", "inv"
        )?;
        for r in &s.regions {
            writeln!(
                f,
                "  {:>8}{:>10}{:>14.6e}{:>9}{:>9}{:>8}{:>5}",
                r.label,
                r.n_triangles,
                r.area,
                num(r.min_angle_deg, 2),
                num(r.max_angle_deg, 2),
                num(r.min_q, 4),
                r.n_inverted
            )?;
        }
        Ok(())
    }
}
