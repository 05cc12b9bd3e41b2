//! Numbers and labels in messages.

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

/// Labels as `a, b, c`: the first 20, then how many more (`none` for none).
pub fn labels(labels: impl IntoIterator<Item = u32>) -> String {
    let all: Vec<u32> = labels.into_iter().collect();
    let mut s: Vec<String> = all.iter().take(20).map(|l| l.to_string()).collect();
    if all.len() > 20 {
        s.push(format!("and {} more", all.len() - 20));
    }
    if s.is_empty() {
        "none".into()
    } else {
        s.join(", ")
    }
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
