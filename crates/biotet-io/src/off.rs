//! Object File Format (OFF), ASCII.
//!
//! Reading: the header keyword is `OFF` with the optional `ST`, `C`, `N` prefixes (texture
//! coordinates, colours and normals after a vertex's three coordinates are ignored, as are
//! colours after a face's indices); the counts `vertices faces edges` may follow on the same
//! line. `#` starts a comment. Faces with more than three corners are fan-triangulated and
//! counted in [`SurfaceRead::polygons_split`]. `4OFF`, `nOFF` and binary OFF are rejected.
//!
//! Writing: `OFF`, counts, shortest round-trip coordinates, `3 a b c` faces.

use std::io::Write;

use biotet::SurfaceMesh;

use crate::SurfaceRead;
use crate::common::{check_surface, read_all};
use crate::error::{Error, Result};
use crate::text::{Lexer, Out, reserve_cap, show, write_points_and_counted_triangles};

/// Read an OFF surface from a stream; `file` names it in errors.
pub fn read<R: std::io::Read>(r: R, file: &str) -> Result<SurfaceRead> {
    parse(&read_all(r, file)?, file)
}

/// Parse an OFF surface held in memory.
pub fn parse(data: &[u8], file: &str) -> Result<SurfaceRead> {
    let mut lx = Lexer::new(data, file, Some(b'#'));
    let mut toks = Vec::new();
    if !lx.line_tokens(&mut toks) {
        return Err(Error::format(file, "empty file, expected 'OFF'"));
    }
    let kw = toks[0];
    let ok_kw = kw.len() >= 3
        && kw[kw.len() - 3..].eq_ignore_ascii_case(b"OFF")
        && kw[..kw.len() - 3]
            .iter()
            .all(|c| matches!(c.to_ascii_uppercase(), b'S' | b'T' | b'C' | b'N'));
    if !ok_kw {
        if kw.len() >= 3 && kw[kw.len() - 3..].eq_ignore_ascii_case(b"OFF") {
            return Err(lx.err(format!(
                "unsupported OFF variant '{}' (only 3D OFF is read)",
                show(kw)
            )));
        }
        return Err(lx.err(format!("expected 'OFF', got '{}'", show(kw))));
    }
    let mut rest: Vec<&[u8]> = toks[1..].to_vec();
    if rest
        .first()
        .is_some_and(|t| t.eq_ignore_ascii_case(b"BINARY"))
    {
        return Err(lx.err("binary OFF is not supported"));
    }
    if rest.is_empty() {
        if !lx.line_tokens(&mut toks) {
            return Err(Error::truncated(file, "missing vertex and face counts"));
        }
        rest = toks.clone();
    }
    if rest.len() < 2 {
        return Err(lx.err(format!(
            "expected vertex, face and edge counts, got {} numbers",
            rest.len()
        )));
    }
    let nv = lx.tok_u64(rest[0], "vertex count")? as usize;
    let nf = lx.tok_u64(rest[1], "face count")? as usize;
    if nv > u32::MAX as usize {
        return Err(lx.err(format!("{nv} vertices do not fit 32-bit indices")));
    }
    let left = data.len() - lx.pos;
    let mut points = Vec::with_capacity(reserve_cap(nv, left, 6));
    for i in 0..nv {
        if !lx.line_tokens(&mut toks) {
            return Err(Error::truncated(
                file,
                format!("expected {nv} vertices, found {i}"),
            ));
        }
        if toks.len() < 3 {
            return Err(lx.err(format!("expected 3 coordinates, got {}", toks.len())));
        }
        let mut p = [0.0; 3];
        for (x, t) in p.iter_mut().zip(&toks) {
            *x = lx.tok_f64(t, "coordinate")?;
        }
        points.push(p);
    }
    let left = data.len() - lx.pos;
    let mut triangles = Vec::with_capacity(reserve_cap(nf, left, 8));
    let mut split = 0;
    let mut corners: Vec<u32> = Vec::new();
    for i in 0..nf {
        if !lx.line_tokens(&mut toks) {
            return Err(Error::truncated(
                file,
                format!("expected {nf} faces, found {i}"),
            ));
        }
        let k = lx.tok_u64(toks[0], "face corner count")? as usize;
        if k < 3 {
            return Err(lx.err(format!("face with {k} corners, need at least 3")));
        }
        if toks.len() - 1 < k {
            return Err(lx.err(format!(
                "expected {k} vertex indices, got {}",
                toks.len() - 1
            )));
        }
        corners.clear();
        for t in &toks[1..=k] {
            let v = lx.tok_u64(t, "vertex index")?;
            if v >= nv as u64 {
                return Err(lx.err(format!("vertex index {v} out of range ({nv} vertices)")));
            }
            corners.push(v as u32);
        }
        if k > 3 {
            split += 1;
        }
        for j in 1..k - 1 {
            triangles.push([corners[0], corners[j], corners[j + 1]]);
        }
    }
    Ok(SurfaceRead {
        mesh: SurfaceMesh::closed(points, triangles, 1),
        triangle_refs: None,
        side_labels: None,
        welded: 0,
        polygons_split: split,
    })
}

/// Write an OFF surface.
pub fn write<W: Write>(w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    check_surface(mesh, file)?;
    let mut out = Out::new(w);
    out.s("OFF\n");
    out.int(mesh.points.len());
    out.c(b' ');
    out.int(mesh.triangles.len());
    out.s(" 0\n");
    write_points_and_counted_triangles(out, mesh, file, false)
}
