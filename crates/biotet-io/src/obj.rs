//! Wavefront OBJ (geometry only).
//!
//! Reading: `v x y z [w | r g b]` lines give points (extra values ignored); `f` lines give faces
//! whose corners may be written `v`, `v/vt`, `v//vn` or `v/vt/vn`, with 1-based or negative
//! (relative to the last vertex defined so far) indices. Faces with more than three corners are
//! **fan-triangulated** (`a b c d` → `a b c`, `a c d`, which is right for the convex, planar
//! polygons modelling tools write) and counted in [`SurfaceRead::polygons_split`]; faces with
//! fewer than three corners are errors. Every other statement (`vt`, `vn`, `g`, `o`, `s`,
//! `usemtl`, `l`, ...) is ignored.
//!
//! Writing: `v` and `f` lines only, 1-based, shortest round-trip coordinates.

use std::io::Write;

use biotet::SurfaceMesh;

use crate::SurfaceRead;
use crate::common::{check_surface, read_all};
use crate::error::{Error, Result};
use crate::text::{Lexer, Out, parse_i64, show};

/// Read an OBJ surface from a stream; `file` names it in errors.
pub fn read<R: std::io::Read>(r: R, file: &str) -> Result<SurfaceRead> {
    parse(&read_all(r, file)?, file)
}

/// Parse an OBJ surface held in memory.
pub fn parse(data: &[u8], file: &str) -> Result<SurfaceRead> {
    let mut lx = Lexer::new(data, file, Some(b'#'));
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    // Line of each triangle's face, for range errors found at the end (positive indices may
    // refer to vertices defined later).
    let mut tri_line: Vec<u32> = Vec::new();
    let mut split = 0usize;
    let mut toks = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    while lx.line_tokens(&mut toks) {
        match toks[0] {
            b"v" => {
                if toks.len() < 4 {
                    return Err(lx.err(format!("expected 3 coordinates, got {}", toks.len() - 1)));
                }
                let mut p = [0.0; 3];
                for (x, t) in p.iter_mut().zip(&toks[1..4]) {
                    *x = lx.tok_f64(t, "coordinate")?;
                }
                points.push(p);
            }
            b"f" | b"fo" => {
                corners.clear();
                for t in &toks[1..] {
                    let idx = t.split(|&c| c == b'/').next().unwrap_or(t);
                    let v = parse_i64(idx)
                        .ok_or_else(|| lx.err(format!("bad face corner '{}'", show(t))))?;
                    let n = points.len() as i64;
                    let i = if v > 0 {
                        v - 1
                    } else if v < 0 {
                        if -v > n {
                            return Err(lx.err(format!(
                                "relative vertex index {v} out of range ({n} vertices so far)"
                            )));
                        }
                        n + v
                    } else {
                        return Err(lx.err("vertex index 0 (OBJ indices start at 1)"));
                    };
                    let i = u32::try_from(i)
                        .map_err(|_| lx.err(format!("vertex index {v} too large")))?;
                    corners.push(i);
                }
                if corners.len() < 3 {
                    return Err(lx.err(format!(
                        "face with {} corners, need at least 3",
                        corners.len()
                    )));
                }
                let line = lx.tok_line.min(u32::MAX as usize) as u32;
                for t in crate::common::fan(&corners, &mut split) {
                    triangles.push(t);
                    tri_line.push(line);
                }
            }
            _ => {}
        }
    }
    let n = points.len();
    if n > u32::MAX as usize {
        return Err(Error::format(file, "too many vertices for 32-bit indices"));
    }
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(v) = tri.iter().find(|&&v| v as usize >= n) {
            return Err(Error::line(
                file,
                tri_line[t] as usize,
                format!("vertex index {} out of range ({n} vertices)", *v as u64 + 1),
            ));
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

/// Write an OBJ surface.
pub fn write<W: Write>(w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    check_surface(mesh, file)?;
    let mut out = Out::new(w);
    out.s("# written by biotet\n");
    for p in &mesh.points {
        out.c(b'v');
        for &x in p {
            out.c(b' ');
            out.f64(x);
        }
        out.c(b'\n');
        out.check().map_err(|e| Error::io(file, e))?;
    }
    for t in &mesh.triangles {
        out.c(b'f');
        for &v in t {
            out.c(b' ');
            out.int(v as u64 + 1);
        }
        out.c(b'\n');
        out.check().map_err(|e| Error::io(file, e))?;
    }
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}
