//! Numbers in messages.

/// `x` as Rust writes it, or in scientific notation where that is long (a tolerance of 1e-300
/// came out as 300 zeros, a centre's round-off 1.1e-16 as 32 digits).
pub fn short(x: f64) -> String {
    let s = format!("{x}");
    if s.len() > 20 { format!("{x:.4e}") } else { s }
}

/// A point as `(x, y, z)`, each coordinate [`short`].
pub fn point(p: &[f64; 3]) -> String {
    format!("({}, {}, {})", short(p[0]), short(p[1]), short(p[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_numbers_go_scientific() {
        assert_eq!(short(0.5), "0.5");
        assert_eq!(short(1e-300), "1.0000e-300");
        assert_eq!(
            point(&[1.1102230246251565e-16, 0.0, 2.0]),
            "(1.1102e-16, 0, 2)"
        );
    }
}
