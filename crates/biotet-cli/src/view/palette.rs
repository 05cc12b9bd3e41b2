//! Colours: a qualitative palette for region labels and a sequential ramp for angles.

use super::{Key, Rgb};

/// Twelve colours that stay apart for the usual colour-vision deficiencies and on grey
/// print; labels beyond twelve cycle with a darker shade.
const QUALITATIVE: [Rgb; 12] = [
    [68, 119, 170],
    [238, 102, 119],
    [34, 136, 51],
    [204, 187, 68],
    [102, 204, 238],
    [170, 51, 119],
    [187, 187, 187],
    [238, 153, 51],
    [0, 153, 136],
    [153, 153, 51],
    [136, 34, 85],
    [51, 34, 136],
];

/// The colour of region label `l` among the sorted `labels` of the mesh (by rank, so the
/// first regions get the most distinct colours whatever their values).
pub fn label_color(rank: usize) -> Rgb {
    let c = QUALITATIVE[rank % QUALITATIVE.len()];
    if (rank / QUALITATIVE.len()) % 2 == 1 {
        c.map(|x| (f64::from(x) * 0.6) as u8)
    } else {
        c
    }
}

/// A ramp over the smallest dihedral angle, as a fraction of the regular tet's 70.53°: dark
/// red at 0°, red at 10° (the usual sliver line), yellow at 20°, green at 35°, blue at the
/// regular tet, so the eye finds the tets under 10° first.
const RAMP: [(f64, Rgb); 5] = [
    (0.0, [103, 0, 31]),
    (0.1418, [227, 26, 28]),
    (0.2836, [254, 217, 118]),
    (0.4963, [120, 198, 121]),
    (1.0, [34, 94, 168]),
];

/// The ramp's colour at `t` in [0, 1] (clamped), linear between stops.
pub fn ramp(t: f64) -> Rgb {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    for w in RAMP.windows(2) {
        let ((a, ca), (b, cb)) = (w[0], w[1]);
        if t <= b {
            let s = (t - a) / (b - a);
            return [0, 1, 2].map(|k| {
                (f64::from(ca[k]) + s * (f64::from(cb[k]) - f64::from(ca[k]))).round() as u8
            });
        }
    }
    RAMP[RAMP.len() - 1].1
}

/// `c` scaled by a shading factor in [0, 1].
pub fn shade(c: Rgb, f: f64) -> Rgb {
    c.map(|x| (f64::from(x) * f.clamp(0.0, 1.0)).round() as u8)
}

/// The legend of the regions drawn: `regions` sorted (the mesh's labels), `shown[r]` whether
/// region rank `r` appears in the picture.
pub fn label_key(regions: &[u32], shown: &[bool]) -> Key {
    Key::Labels(
        regions
            .iter()
            .enumerate()
            .filter(|&(r, _)| shown[r])
            .map(|(r, &l)| (l, label_color(r)))
            .collect(),
    )
}
