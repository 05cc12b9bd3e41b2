//! STL, ASCII and binary.
//!
//! Reading: the file is binary when its size is exactly `84 + 50·n` for the triangle count `n`
//! stored at byte 80 — even if the 80-byte header begins with `solid`, as many exporters write.
//! Otherwise a file that begins with `solid` and looks like text is ASCII, and anything else is
//! binary (and too short a binary file is reported as truncated; bytes after the announced
//! triangles are ignored). STL stores every triangle with its own three corners: corners with
//! exactly equal coordinates are welded ([`SurfaceMesh::weld_exact`]) and
//! [`SurfaceRead::welded`] says how many points that removed. Normals are ignored. ASCII
//! facets must have exactly three vertices.
//!
//! Writing: binary STL stores `f32` coordinates, so [`write_binary`] rounds (use [`write_ascii`],
//! which writes shortest round-trip `f64` text, to keep coordinates exact). Normals are computed
//! from the corners. Side labels are not stored; a read surface has sides `[1, 0]`.

use std::io::Write;

use biotet::SurfaceMesh;

use crate::SurfaceRead;
use crate::common::{check_surface, read_all};
use crate::error::{Error, Result};
use crate::text::{Lexer, Out, show};

/// Read an STL surface (ASCII or binary, detected) from a stream; `file` names it in errors.
pub fn read<R: std::io::Read>(r: R, file: &str) -> Result<SurfaceRead> {
    parse(&read_all(r, file)?, file)
}

/// Parse an STL surface held in memory.
pub fn parse(data: &[u8], file: &str) -> Result<SurfaceRead> {
    let mut mesh = if is_binary(data) {
        parse_binary(data, file)?
    } else {
        parse_ascii(data, file)?
    };
    let welded = mesh.weld_exact();
    Ok(SurfaceRead {
        mesh,
        triangle_refs: None,
        side_labels: None,
        welded,
        polygons_split: 0,
    })
}

/// Whether `data` is a binary STL (see the module documentation for the rule).
pub fn is_binary(data: &[u8]) -> bool {
    if data.len() >= 84 {
        let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
        if 84 + 50 * n == data.len() as u64 {
            return true;
        }
    }
    let start = data
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(data.len());
    let rest = &data[start..];
    let solid = rest.len() >= 5 && rest[..5].eq_ignore_ascii_case(b"solid");
    if !solid {
        return true;
    }
    // Text check on the first kilobyte: binary headers are followed by a count and floats that
    // nearly always contain NUL or high bytes.
    let probe = &data[..data.len().min(1024)];
    probe.iter().any(|&c| c == 0 || c >= 0x80)
}

fn parse_binary(data: &[u8], file: &str) -> Result<SurfaceMesh> {
    if data.len() < 84 {
        return Err(Error::truncated(
            file,
            format!(
                "binary STL needs an 84-byte header, file has {} bytes",
                data.len()
            ),
        ));
    }
    let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
    let need = 84 + 50 * n;
    if (data.len() as u64) < need {
        return Err(Error::truncated(
            file,
            format!(
                "header announces {n} triangles ({need} bytes), file has {} bytes",
                data.len()
            ),
        ));
    }
    let n = n as usize;
    if 3 * n > u32::MAX as usize {
        return Err(Error::format(
            file,
            format!("{n} triangles do not fit 32-bit indices"),
        ));
    }
    let mut points = Vec::with_capacity(3 * n);
    let mut triangles = Vec::with_capacity(n);
    for t in 0..n {
        let rec = &data[84 + 50 * t + 12..84 + 50 * t + 48];
        for k in 0..3 {
            let mut p = [0.0f64; 3];
            for (c, x) in p.iter_mut().enumerate() {
                let o = 12 * k + 4 * c;
                *x = f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as f64;
            }
            if p.iter().any(|x| !x.is_finite()) {
                return Err(Error::element(
                    file,
                    "triangle",
                    t,
                    format!("non-finite coordinate in corner {k}: {p:?}"),
                ));
            }
            points.push(p);
        }
        let b = 3 * t as u32;
        triangles.push([b, b + 1, b + 2]);
    }
    Ok(SurfaceMesh::closed(points, triangles, 1))
}

fn parse_ascii(data: &[u8], file: &str) -> Result<SurfaceMesh> {
    let mut lx = Lexer::new(data, file, None);
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut scratch = Vec::new();
    let mut in_facet = false;
    let mut corners = 0usize;
    let mut solids = 0usize;
    while let Some(t) = lx.next_token() {
        let kw = |k: &str| t.eq_ignore_ascii_case(k.as_bytes());
        if kw("solid") {
            if in_facet {
                return Err(lx.err("'solid' inside a facet"));
            }
            solids += 1;
            lx.rest_of_line(&mut scratch);
        } else if kw("endsolid") {
            if in_facet {
                return Err(lx.err("'endsolid' inside a facet"));
            }
            lx.rest_of_line(&mut scratch);
        } else if kw("facet") {
            if in_facet {
                return Err(lx.err("'facet' before the previous facet's 'endfacet'"));
            }
            if solids == 0 {
                return Err(lx.err("'facet' before 'solid'"));
            }
            in_facet = true;
            corners = 0;
            // "normal nx ny nz": ignored (often missing or garbage).
            lx.rest_of_line(&mut scratch);
        } else if kw("outer") || kw("endloop") {
            lx.rest_of_line(&mut scratch);
        } else if kw("vertex") {
            if !in_facet {
                return Err(lx.err("'vertex' outside a facet"));
            }
            let mut p = [0.0; 3];
            for x in &mut p {
                *x = lx.f64("vertex coordinate")?;
            }
            corners += 1;
            if corners > 3 {
                return Err(lx.err("facet with more than 3 vertices (STL facets are triangles)"));
            }
            points.push(p);
        } else if kw("endfacet") {
            if !in_facet {
                return Err(lx.err("'endfacet' without 'facet'"));
            }
            if corners != 3 {
                return Err(lx.err(format!("facet with {corners} vertices, expected 3")));
            }
            if points.len() > u32::MAX as usize {
                return Err(lx.err("too many points for 32-bit indices"));
            }
            let b = points.len() as u32 - 3;
            triangles.push([b, b + 1, b + 2]);
            in_facet = false;
        } else {
            return Err(lx.err(format!("unexpected '{}' in ASCII STL", show(t))));
        }
    }
    if in_facet {
        return Err(Error::truncated(file, "ASCII STL ends inside a facet"));
    }
    if solids == 0 {
        return Err(Error::format(file, "no 'solid' in ASCII STL"));
    }
    Ok(SurfaceMesh::closed(points, triangles, 1))
}

fn unit_normal(c: [[f64; 3]; 3]) -> [f64; 3] {
    let u = [c[1][0] - c[0][0], c[1][1] - c[0][1], c[1][2] - c[0][2]];
    let v = [c[2][0] - c[0][0], c[2][1] - c[0][1], c[2][2] - c[0][2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 && l.is_finite() {
        [n[0] / l, n[1] / l, n[2] / l]
    } else {
        [0.0; 3]
    }
}

/// Write a binary STL (coordinates rounded to `f32`).
pub fn write_binary<W: Write>(w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    check_surface(mesh, file)?;
    let n = u32::try_from(mesh.triangles.len())
        .map_err(|_| Error::invalid(file, "more than 2^32-1 triangles do not fit binary STL"))?;
    let mut out = Out::new(w);
    let mut header = [b' '; 80];
    let h = b"binary STL written by biotet";
    header[..h.len()].copy_from_slice(h);
    out.bytes(&header);
    out.bytes(&n.to_le_bytes());
    for t in 0..mesh.triangles.len() {
        let c = mesh.corners(t);
        for x in unit_normal(c) {
            out.bytes(&(x as f32).to_le_bytes());
        }
        for p in c {
            for x in p {
                out.bytes(&(x as f32).to_le_bytes());
            }
        }
        out.bytes(&[0, 0]);
        out.check().map_err(|e| Error::io(file, e))?;
    }
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}

/// Write an ASCII STL with exact (shortest round-trip) coordinates.
pub fn write_ascii<W: Write>(w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    check_surface(mesh, file)?;
    let mut out = Out::new(w);
    out.s("solid biotet\n");
    for t in 0..mesh.triangles.len() {
        let c = mesh.corners(t);
        out.s("facet normal");
        for x in unit_normal(c) {
            out.c(b' ');
            out.f64(x);
        }
        out.s("\n outer loop\n");
        for p in c {
            out.s("  vertex");
            for x in p {
                out.c(b' ');
                out.f64(x);
            }
            out.c(b'\n');
        }
        out.s(" endloop\nendfacet\n");
        out.check().map_err(|e| Error::io(file, e))?;
    }
    out.s("endsolid biotet\n");
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}
