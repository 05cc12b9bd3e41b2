//! Insertion order: exact duplicate detection, a Hilbert curve sort and BRIO rounds.
//!
//! All points are sorted once along a 3D Hilbert curve (keys on a 2¹⁰ grid per axis over the
//! bounding cube). Exact duplicates share a grid cell, so a sort of each run of equal keys by
//! coordinates puts them side by side. The distinct points are then dealt into BRIO rounds (each
//! point goes to round k with probability ~ (1 − r)·rᵏ counted from the last round) by a
//! fixed-seed RNG, and a stable counting sort by round keeps the Hilbert order inside each round.

/// SplitMix64: a tiny, fast, deterministic generator (no `rand` dependency needed).
#[derive(Debug, Clone)]
pub(crate) struct SplitMix64(u64);

impl SplitMix64 {
    pub(crate) fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    #[inline]
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

/// Bits per axis of the Hilbert grid (3 × 10 = 30 key bits, leaving 32 bits for the index).
const HILBERT_BITS: u32 = 10;
/// log2 of the growth factor between consecutive BRIO rounds (8, as CGAL's ratio 1/8: faster
/// than 2 or 16 on 10⁶ random points).
const BRIO_LOG2_GROWTH: u32 = 3;
/// Smallest first round.
const BRIO_MIN_ROUND: usize = 64;

/// The Hilbert index of a grid cell with `HILBERT_BITS` bits per coordinate (Skilling's
/// transpose form: undo the excess work of the Gray code per bit plane, then Gray-encode).
#[inline]
pub(crate) fn hilbert_key(mut x: [u32; 3]) -> u64 {
    let m = 1u32 << (HILBERT_BITS - 1);
    let mut q = m;
    while q > 1 {
        let p = q - 1;
        for i in 0..3 {
            if x[i] & q != 0 {
                x[0] ^= p;
            } else {
                let t = (x[0] ^ x[i]) & p;
                x[0] ^= t;
                x[i] ^= t;
            }
        }
        q >>= 1;
    }
    x[1] ^= x[0];
    x[2] ^= x[1];
    let mut t = 0;
    let mut q = m;
    while q > 1 {
        if x[2] & q != 0 {
            t ^= q - 1;
        }
        q >>= 1;
    }
    for c in &mut x {
        *c ^= t;
    }
    (interleave(x[0]) << 2) | (interleave(x[1]) << 1) | interleave(x[2])
}

/// Spread the low 10 bits of `x` so that bit i lands on bit 3i.
#[inline]
fn interleave(x: u32) -> u64 {
    let mut x = u64::from(x) & 0x3ff;
    x = (x | (x << 16)) & 0x0300_00FF;
    x = (x | (x << 8)) & 0x0300_F00F;
    x = (x | (x << 4)) & 0x030C_30C3;
    x = (x | (x << 2)) & 0x0924_9249;
    x
}

/// The result of [`insertion_order`].
pub(crate) struct Order {
    /// Distinct input indices in insertion order.
    pub seq: Vec<u32>,
    /// For every input index, the smallest input index with exactly the same coordinates
    /// (itself when unique); `None` when the input has no duplicates.
    pub rep: Option<Vec<u32>>,
}

/// Coordinates with `-0.0` made `0.0`, for exact comparisons.
#[inline]
fn norm0(p: [f64; 3]) -> [f64; 3] {
    p.map(|c| c + 0.0)
}

fn cmp_coords(a: [f64; 3], b: [f64; 3]) -> std::cmp::Ordering {
    let (a, b) = (norm0(a), norm0(b));
    a[0].total_cmp(&b[0])
        .then(a[1].total_cmp(&b[1]))
        .then(a[2].total_cmp(&b[2]))
}

/// Sort `idx` (input indices) along the Hilbert curve of their bounding cube; returns the sorted
/// keys `(hilbert << 32) | index`.
fn hilbert_sort(points: &[[f64; 3]], idx: impl Iterator<Item = u32> + Clone) -> Vec<u64> {
    let (lo, hi) = crate::geom::vec3::points_bbox(idx.clone().map(|i| &points[i as usize]));
    let ext = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f64, f64::max);
    let cells = f64::from(1u32 << HILBERT_BITS);
    let scale = if ext > 0.0 { cells / ext } else { 0.0 };
    let top = (1u32 << HILBERT_BITS) - 1;
    let mut keys: Vec<u64> = idx
        .map(|i| {
            let p = points[i as usize];
            let q = [0, 1, 2].map(|k| (((p[k] - lo[k]) * scale) as u32).min(top));
            (hilbert_key(q) << 32) | u64::from(i)
        })
        .collect();
    radix_sort(&mut keys);
    keys
}

/// LSD radix sort of u64 keys, 11 bits per pass, skipping digits that are the same in all keys.
pub(crate) fn radix_sort(keys: &mut Vec<u64>) {
    if keys.len() < 256 {
        keys.sort_unstable();
        return;
    }
    let (mut or, mut and) = (0u64, u64::MAX);
    for &k in keys.iter() {
        or |= k;
        and &= k;
    }
    let varying = or ^ and;
    let mut tmp = vec![0u64; keys.len()];
    const R: u32 = 11;
    let mut shift = 0;
    while shift < 64 {
        let mask = ((1u64 << R) - 1) << shift;
        if varying & mask != 0 {
            let mut count = vec![0usize; 1 << R];
            for &k in keys.iter() {
                count[((k >> shift) & ((1 << R) - 1)) as usize] += 1;
            }
            let mut sum = 0;
            for c in &mut count {
                let n = *c;
                *c = sum;
                sum += n;
            }
            for &k in keys.iter() {
                let d = ((k >> shift) & ((1 << R) - 1)) as usize;
                tmp[count[d]] = k;
                count[d] += 1;
            }
            std::mem::swap(keys, &mut tmp);
        }
        shift += R;
    }
}

/// The insertion order of `points` (all finite): duplicates found, distinct points in BRIO rounds
/// with Hilbert order inside each round. Deterministic for a given `seed`.
pub(crate) fn insertion_order(points: &[[f64; 3]], seed: u64) -> Order {
    let n = points.len();
    let mut keys = hilbert_sort(points, 0..n as u32);

    // Exact duplicates: equal coordinates give equal Hilbert keys; sort each run of equal keys by
    // (coordinates, index) so that duplicates are adjacent, smallest index first.
    let mut rep: Option<Vec<u32>> = None;
    let mut i = 0;
    while i < n {
        let h = keys[i] >> 32;
        let mut j = i + 1;
        while j < n && keys[j] >> 32 == h {
            j += 1;
        }
        if j - i > 1 {
            let run = &mut keys[i..j];
            run.sort_unstable_by(|&a, &b| {
                let (ia, ib) = (a as u32 as usize, b as u32 as usize);
                cmp_coords(points[ia], points[ib]).then(ia.cmp(&ib))
            });
            for k in 1..run.len() {
                let (a, b) = (run[k - 1] as u32, run[k] as u32);
                if norm0(points[a as usize]) == norm0(points[b as usize]) {
                    let r = rep.get_or_insert_with(|| (0..n as u32).collect());
                    r[b as usize] = r[a as usize];
                }
            }
        }
        i = j;
    }
    let uniq: Vec<u32> = match &rep {
        None => keys.iter().map(|&k| k as u32).collect(),
        Some(r) => keys
            .iter()
            .map(|&k| k as u32)
            .filter(|&i| r[i as usize] == i)
            .collect(),
    };
    drop(keys);
    let seq = brio(uniq, seed);
    Order { seq, rep }
}

/// Deal the Hilbert-sorted `sorted` into BRIO rounds (a stable counting sort by round, first
/// round first).
pub(crate) fn brio(sorted: Vec<u32>, seed: u64) -> Vec<u32> {
    let n = sorted.len();
    let mut levels = 0u32;
    while (n >> ((levels + 1) * BRIO_LOG2_GROWTH)) >= BRIO_MIN_ROUND {
        levels += 1;
    }
    if levels == 0 {
        return sorted;
    }
    let mut rng = SplitMix64::new(seed);
    // Level of each point: ℓ with probability ~ 2^(-g(ℓ+1))·(2^g − 1) for ℓ < levels; the
    // highest level takes the rest. Higher levels are inserted first.
    let mut lev: Vec<u8> = Vec::with_capacity(n);
    let mut count = vec![0usize; levels as usize + 1];
    for _ in 0..n {
        let r = rng.next_u64() | (1u64 << 63);
        let l = (r.trailing_zeros() / BRIO_LOG2_GROWTH).min(levels);
        lev.push(l as u8);
        count[l as usize] += 1;
    }
    // Start offsets, highest level first.
    let mut start = vec![0usize; levels as usize + 1];
    let mut sum = 0;
    for l in (0..=levels as usize).rev() {
        start[l] = sum;
        sum += count[l];
    }
    let mut out = vec![0u32; n];
    for (k, &i) in sorted.iter().enumerate() {
        let l = lev[k] as usize;
        out[start[l]] = i;
        start[l] += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hilbert_is_a_continuous_curve() {
        // Consecutive cells along the curve are face neighbours on a small grid: check on the
        // full grid restricted to the first 8^3 cells (the low bits of keys form a sub-cube).
        let mut cells: Vec<(u64, [u32; 3])> = Vec::new();
        let s = 1u32 << HILBERT_BITS;
        // A coarse check on the whole grid would be 2^30 cells; sample the curve on the 8×8×8
        // corner block instead, which is one contiguous key range of the Hilbert curve.
        for x in 0..8 {
            for y in 0..8 {
                for z in 0..8 {
                    cells.push((hilbert_key([x, y, z]), [x, y, z]));
                }
            }
        }
        let _ = s;
        cells.sort_unstable();
        for w in cells.windows(2) {
            assert_eq!(
                w[1].0,
                w[0].0 + 1,
                "keys of the corner block are contiguous"
            );
            let d: u32 = (0..3).map(|k| w[0].1[k].abs_diff(w[1].1[k])).sum();
            assert_eq!(d, 1, "{:?} -> {:?}", w[0], w[1]);
        }
    }

    #[test]
    fn radix_sort_sorts() {
        let mut r = SplitMix64::new(7);
        let mut v: Vec<u64> = (0..10_000).map(|_| r.next_u64() >> 3).collect();
        let mut w = v.clone();
        radix_sort(&mut v);
        w.sort_unstable();
        assert_eq!(v, w);
    }
}
