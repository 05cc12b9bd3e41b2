//! Point clouds: a TetGen `.node` file, or plain text with one `x y z` point per line.

use std::path::Path;

use crate::error::{Error, Result};
use crate::text::Lexer;

/// Read a 3D point cloud. A `.node` path is read as TetGen's format (header, indexed points,
/// attributes and markers ignored); any other path as text lines of exactly three numbers, with
/// blank lines and `#` comments skipped. Non-finite coordinates are refused.
pub fn read_points(path: &Path) -> Result<Vec<[f64; 3]>> {
    let file = path.display().to_string();
    let data = std::fs::read(path).map_err(|e| Error::io(&file, e))?;
    let is_node = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("node"));
    if is_node {
        Ok(crate::tetgen::parse_node::<3>(&data, &file)?.0)
    } else {
        parse_xyz(&data, &file)
    }
}

/// Parse text lines of `x y z` (whitespace- or comma-separated is not accepted: whitespace only).
pub fn parse_xyz(data: &[u8], file: &str) -> Result<Vec<[f64; 3]>> {
    let mut lx = Lexer::new(data, file, Some(b'#'));
    let mut toks = Vec::new();
    let mut pts = Vec::with_capacity(data.len() / 24);
    while lx.line_tokens(&mut toks) {
        if toks.len() != 3 {
            return Err(lx.err(format!(
                "point {}: expected 3 coordinates 'x y z', got {} values",
                pts.len(),
                toks.len()
            )));
        }
        let p = [
            lx.tok_f64(toks[0], "x")?,
            lx.tok_f64(toks[1], "y")?,
            lx.tok_f64(toks[2], "z")?,
        ];
        pts.push(p);
        if pts.len() > u32::MAX as usize - 2 {
            return Err(lx.err("too many points for 32-bit indices"));
        }
    }
    if pts.is_empty() {
        return Err(Error::format(file, "no points"));
    }
    Ok(pts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xyz_lines_with_comments() {
        let p = parse_xyz(b"# cloud\n0 0 0\n\n1 2.5 -3e2 # tail\n", "c.xyz").unwrap();
        assert_eq!(p, vec![[0.0, 0.0, 0.0], [1.0, 2.5, -300.0]]);
    }

    #[test]
    fn bad_lines_are_named() {
        let e = parse_xyz(b"0 0 0\n1 2\n", "c.xyz").unwrap_err().to_string();
        assert!(
            e.contains("c.xyz") && e.contains("line 2") && e.contains("got 2"),
            "{e}"
        );
        let e = parse_xyz(b"0 0 nan\n", "c.xyz").unwrap_err().to_string();
        assert!(e.contains("non-finite"), "{e}");
        assert!(parse_xyz(b"\n# nothing\n", "c.xyz").is_err());
    }
}
