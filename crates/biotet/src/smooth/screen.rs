//! A cheap, certain rejection of a trial position, in front of the exact test of
//! [`super::node`].
//!
//! Most trial positions of the ascent are refused because the cluster's soft measure (the sum of
//! the logarithms of its solid angles, each capped at the regular tet's) would fall, and the
//! exact test needs one `atan2` and one `ln` per angle to say so. Here each angle
//! `2·atan2(det, den)` is bounded instead:
//! - when `den ≤ 0` or `det/den ≥ tan(Ω_reg/2)` (with a margin) the angle is at least the regular
//!   tet's, so its capped value is exactly `Ω_reg`;
//! - otherwise `2·atan(r)` comes from its Taylor series in `r² < 0.081` (11 terms: relative
//!   error below 10⁻¹³),
//!
//! and one logarithm is taken per trial, of the product of all capped angles (kept in range by
//! moving its binary exponent aside after each tet: exact scalings by powers of two). A trial
//! is rejected here only when the bounds prove that the exact test would reject it: an angle
//! certainly at or below the floor, or a soft measure certainly below the current one (the
//! error allowance covers the series, the roundings of both computations and the summation).
//! Otherwise the exact test decides, so the outcome is the same bit for bit.

use crate::quality::tet::REGULAR_SOLID_ANGLE;

/// `(−1)^k / (2k + 1)`, k = 0..=10: `atan(r)/r = Σ c_k r^{2k}`.
const ATAN_SERIES: [f64; 11] = [
    1.0,
    -1.0 / 3.0,
    1.0 / 5.0,
    -1.0 / 7.0,
    1.0 / 9.0,
    -1.0 / 11.0,
    1.0 / 13.0,
    -1.0 / 15.0,
    1.0 / 17.0,
    -1.0 / 19.0,
    1.0 / 21.0,
];

/// `tan(Ω_reg / 2)` rounded up with a wide margin: `det/den` at or above it means an angle at
/// least `Ω_reg` (the true value is 0.282842712…, `1/√12.5`).
const TAN_HALF_REGULAR: f64 = 0.282_842_713;

/// Relative error allowed for one angle (series truncation below 5·10⁻¹⁴, roundings ~10⁻¹⁵).
const ANGLE_RELATIVE_ERROR: f64 = 1e-12;

/// `2·atan(r)` for `0 ≤ r < TAN_HALF_REGULAR`, within [`ANGLE_RELATIVE_ERROR`].
#[inline]
pub fn twice_atan_small(r: f64) -> f64 {
    let x = r * r;
    let mut p = ATAN_SERIES[10];
    for &c in ATAN_SERIES[..10].iter().rev() {
        p = c + x * p;
    }
    2.0 * r * p
}

/// Whether the exact test of a trial position certainly rejects it, from the Van
/// Oosterom–Strackee arguments ([`crate::quality::tet::solid_angle_parts`]) of every tet of the
/// cluster at that position: some solid angle at or below `floor`, or the soft measure below
/// `soft_old`. `false` means "not proved": the exact test must decide.
pub fn certainly_rejected(parts: &[(f64, [f64; 4])], floor: f64, soft_old: f64) -> bool {
    // Below this an approximate angle proves the exact one is at most `floor`.
    let floor_low = if floor > 0.0 {
        floor * (1.0 - 1e-10)
    } else {
        f64::NEG_INFINITY
    };
    // The product of the capped angles is `mantissa · 2^exponent`, mantissa in [1, 2).
    let mut mantissa = 1.0f64;
    let mut exponent = 0i64;
    for &(det, den) in parts {
        if !(det > 0.0 && det.is_finite()) {
            return false;
        }
        for d in den {
            if !d.is_finite() {
                return false;
            }
            let capped = if d <= 0.0 || det >= TAN_HALF_REGULAR * d {
                REGULAR_SOLID_ANGLE
            } else {
                let w = twice_atan_small(det / d);
                if w < floor_low {
                    return true;
                }
                w.min(REGULAR_SOLID_ANGLE)
            };
            mantissa *= capped;
        }
        // Four factors in (0, 2] from a mantissa in [1, 2): normal unless an angle is tiny.
        if mantissa.is_nan() || mantissa < f64::MIN_POSITIVE {
            return false;
        }
        let bits = mantissa.to_bits();
        exponent += ((bits >> 52) & 0x7ff) as i64 - 1023;
        mantissa = f64::from_bits((bits & !(0x7ff << 52)) | (1023 << 52));
    }
    if !soft_old.is_finite() {
        return false;
    }
    let sum = mantissa.ln() + exponent as f64 * std::f64::consts::LN_2;
    let n = (4 * parts.len()) as f64;
    // Per angle: the approximation's and the exact value's errors in the logarithm, and one
    // rounding of the product; per sum: the roundings of the exact summation (n · u · Σ|terms|,
    // Σ|terms| = |sum| as every capped angle is below 1), with a wide margin.
    let allowance = n * 10.0 * ANGLE_RELATIVE_ERROR + 1e-14 * n * (sum.abs() + n);
    sum + allowance < soft_old
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::tet::{solid_angle_parts, solid_angles};

    /// A small deterministic generator (xorshift), for reproducible random tets.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn series_matches_libm() {
        let mut r = 0.0;
        while r < TAN_HALF_REGULAR {
            let exact = 2.0 * r.atan();
            let approx = twice_atan_small(r);
            assert!(
                (approx - exact).abs() <= 1e-13 * exact + f64::MIN_POSITIVE,
                "r = {r}: {approx} vs {exact}"
            );
            r += 1.3e-5;
        }
    }

    #[test]
    fn regular_threshold_is_above_tan_half_regular() {
        assert!(TAN_HALF_REGULAR > (REGULAR_SOLID_ANGLE / 2.0).tan());
        assert!(TAN_HALF_REGULAR < (REGULAR_SOLID_ANGLE / 2.0).tan() * (1.0 + 1e-8));
    }

    fn soft(angles: &[[f64; 4]]) -> f64 {
        angles
            .iter()
            .flatten()
            .map(|w| w.min(REGULAR_SOLID_ANGLE).ln())
            .sum()
    }

    /// Whenever the screen rejects, the exact test (the smallest angle at or below the floor,
    /// or the soft measure below the old one) rejects too; and near the exact values it does not
    /// pretend to know.
    #[test]
    fn rejects_only_what_the_exact_test_rejects() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut rejected = 0;
        for _ in 0..2000 {
            let n = 1 + (rng.next() * 30.0) as usize;
            let mut parts = Vec::new();
            let mut angles = Vec::new();
            for _ in 0..n {
                let mut c = [[0.0; 3]; 4];
                for p in &mut c {
                    for x in p.iter_mut() {
                        *x = rng.next();
                    }
                }
                // Flatten some tets to get tiny angles.
                if rng.next() < 0.3 {
                    c[3][2] = c[0][2] * 1e-6 + 0.5 * (c[1][2] + c[2][2]) * (1.0 - 1e-6);
                }
                if solid_angles(&c)[0] < 0.0 {
                    c.swap(0, 1);
                }
                parts.push(solid_angle_parts(&c));
                angles.push(solid_angles(&c));
            }
            let min = angles
                .iter()
                .flatten()
                .copied()
                .fold(f64::INFINITY, f64::min);
            let s = soft(&angles);
            for (floor, soft_old) in [
                (min * (1.0 + 1e-9), s - 1.0),
                (min * (1.0 - 1e-15), s),
                (min * 0.5, s + 1e-9),
                (min * 0.5, s + 1e-3),
                (min * 0.5, s - 1e-12),
                (min, s + 1e-14),
            ] {
                let exact = min <= floor || s < soft_old;
                let screened = certainly_rejected(&parts, floor, soft_old);
                assert!(
                    !screened || exact,
                    "floor {floor} min {min} soft {s} old {soft_old}"
                );
                rejected += screened as usize;
            }
        }
        assert!(
            rejected > 1000,
            "the screen should reject the clear cases ({rejected})"
        );
    }
}
