//! TetGen `.node`/`.ele`/`.face` (3D) and Triangle `.node`/`.ele` (2D).
//!
//! File naming rule (used by [`files`] and the path-based entry points): a path ending in
//! `.node`, `.ele` or `.face` (any case) names the mesh by its *base* — the path without that
//! extension — and the mesh's files are `base.node`, `base.ele` and (3D output) `base.face`.
//! Any other path *is* the base and the extensions are appended: writing `out` or `out.1` with
//! the TetGen format gives `out.node`/`out.1.node`, ... (TetGen's own naming). Reading needs the
//! `.node` and `.ele` files; `.face` is written but not read.
//!
//! Reading: `#` starts a comment. The `.node` header is `count dim attributes markers`; the
//! first node's index sets the numbering base (TetGen and Triangle accept 0 or 1) and later
//! nodes must follow in sequence; point attributes and markers are ignored. The `.ele` header
//! is `count corners attributes` (4 or 10 corners in 3D, 3 or 6 in 2D: only the first 4/3 are
//! used); the first attribute — TetGen's region attribute (`-A`) — is the label, which must be
//! a non-negative integer; without attributes every element gets label 1.
//!
//! Writing: 1-based by default ([`TetgenOptions::zero_based`] for 0-based), no point
//! attributes or markers, one element attribute = the label; the 3D `.face` file lists every
//! boundary face and every face between two labels with marker = the group number described in
//! [`crate::medit`] (faces oriented outward from the smaller label).

use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

use biotet::{TetMesh, TriMesh};

use crate::common::{
    check_tet, check_tri, face_groups, label_of_f64, orient_tets, orient_tris, read_all,
};
use crate::error::{Error, Result};
use crate::text::{Lexer, Out, reserve_cap};
use crate::{TetRead, TriRead};

/// The files of a TetGen/Triangle mesh, from any of their paths (see the module documentation).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TetgenFiles {
    /// The common base path.
    pub base: PathBuf,
    /// `base.node`.
    pub node: PathBuf,
    /// `base.ele`.
    pub ele: PathBuf,
    /// `base.face`.
    pub face: PathBuf,
}

/// Whether `path` ends in `.node`, `.ele` or `.face` (any case).
pub fn is_tetgen_path(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| {
        ["node", "ele", "face"]
            .iter()
            .any(|x| e.eq_ignore_ascii_case(x))
    })
}

/// The mesh files named by `path`.
pub fn files(path: &Path) -> TetgenFiles {
    let base = if is_tetgen_path(path) {
        path.with_extension("")
    } else {
        path.to_path_buf()
    };
    let with = |ext: &str| {
        let mut s = base.clone().into_os_string();
        s.push(".");
        s.push(ext);
        PathBuf::from(s)
    };
    TetgenFiles {
        node: with("node"),
        ele: with("ele"),
        face: with("face"),
        base,
    }
}

/// Options of the TetGen/Triangle writers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TetgenOptions {
    /// Number points from 0 instead of 1 (TetGen's `-z`).
    pub zero_based: bool,
}

pub(crate) fn parse_node<const D: usize>(data: &[u8], file: &str) -> Result<(Vec<[f64; D]>, u64)> {
    let mut lx = Lexer::new(data, file, Some(b'#'));
    let mut toks = Vec::new();
    if !lx.line_tokens(&mut toks) {
        return Err(Error::format(file, "empty .node file"));
    }
    node_section(&mut lx, &mut toks, data.len())
}

/// The point section of a `.node` file, which also opens a `.poly`: its header line (already in
/// `toks`: `<points> <dimension> [<attributes> <markers>]`), then one line per point; returns the
/// points and the first index (0 or 1). `len` is the data's size, to cap the reservation.
pub(crate) fn node_section<'a, const D: usize>(
    lx: &mut Lexer<'a>,
    toks: &mut Vec<&'a [u8]>,
    len: usize,
) -> Result<(Vec<[f64; D]>, u64)> {
    if toks.len() < 2 {
        return Err(lx.err("expected '<points> <dimension> [<attributes> <markers>]'"));
    }
    let n = lx.tok_u64(toks[0], "number of points")? as usize;
    let dim = lx.tok_u64(toks[1], "dimension")?;
    if dim != D as u64 {
        return Err(lx.err(format!("dimension {dim}, expected {D}")));
    }
    if n > u32::MAX as usize {
        return Err(lx.err(format!("{n} points do not fit 32-bit indices")));
    }
    let mut pts = Vec::with_capacity(reserve_cap(n, len, 2 * (D + 1)));
    let mut base = 0u64;
    for i in 0..n {
        if !lx.line_tokens(toks) {
            return Err(Error::truncated(
                lx.file,
                format!("expected {n} points, found {i}"),
            ));
        }
        let idx = lx.tok_u64(toks[0], "point index")?;
        if i == 0 {
            if idx > 1 {
                return Err(lx.err(format!("first point index {idx}, expected 0 or 1")));
            }
            base = idx;
        } else if idx != base + i as u64 {
            return Err(lx.err(format!(
                "point index {idx} out of sequence (expected {})",
                base + i as u64
            )));
        }
        if toks.len() < D + 1 {
            return Err(lx.err(format!("expected {D} coordinates, got {}", toks.len() - 1)));
        }
        let mut p = [0.0; D];
        for (x, t) in p.iter_mut().zip(&toks[1..]) {
            *x = lx.tok_f64(t, "coordinate")?;
        }
        pts.push(p);
    }
    Ok((pts, base))
}

/// Parse an `.ele` file with `K`-corner elements (or the quadratic `Q`-node variant).
fn parse_ele<const K: usize>(
    data: &[u8],
    file: &str,
    quadratic: usize,
    n_points: usize,
    base: u64,
) -> Result<(Vec<[u32; K]>, Vec<u32>)> {
    let mut lx = Lexer::new(data, file, Some(b'#'));
    let mut toks = Vec::new();
    if !lx.line_tokens(&mut toks) {
        return Err(Error::format(file, "empty .ele file"));
    }
    if toks.len() < 2 {
        return Err(lx.err("expected '<elements> <corners> [<attributes>]'"));
    }
    let n = lx.tok_u64(toks[0], "number of elements")? as usize;
    let npe = lx.tok_u64(toks[1], "corners per element")? as usize;
    if npe != K && npe != quadratic {
        return Err(lx.err(format!(
            "{npe} corners per element, expected {K} or {quadratic}"
        )));
    }
    let nattr = match toks.get(2) {
        Some(t) => lx.tok_u64(t, "number of attributes")?.min(1 << 20) as usize,
        None => 0,
    };
    let mut cells = Vec::with_capacity(reserve_cap(n, data.len(), 2 * (K + 1)));
    let mut labels = Vec::with_capacity(reserve_cap(n, data.len(), 2 * (K + 1)));
    for i in 0..n {
        if !lx.line_tokens(&mut toks) {
            return Err(Error::truncated(
                file,
                format!("expected {n} elements, found {i}"),
            ));
        }
        if toks.len() < 1 + npe + nattr {
            return Err(lx.err(format!(
                "expected {} numbers (index, {npe} corners, {nattr} attributes), got {}",
                1 + npe + nattr,
                toks.len()
            )));
        }
        lx.tok_u64(toks[0], "element index")?;
        let mut c = [0u32; K];
        for (x, t) in c.iter_mut().zip(&toks[1..]) {
            let v = lx.tok_u64(t, "point index")?;
            if v < base || v - base >= n_points as u64 {
                return Err(lx.err(format!(
                    "point index {v} out of range ({n_points} points numbered from {base})"
                )));
            }
            *x = (v - base) as u32;
        }
        let label = if nattr > 0 {
            let a = lx.tok_f64(toks[1 + npe], "region attribute")?;
            label_of_f64(a).map_err(|e| lx.err(e))?
        } else {
            1
        };
        cells.push(c);
        labels.push(label);
    }
    Ok((cells, labels))
}

/// Read a TetGen tet mesh from its `.node` and `.ele` streams; `base` names the files in errors
/// (as `base.node`, `base.ele`).
pub fn read_tet<R1: std::io::Read, R2: std::io::Read>(
    node: R1,
    ele: R2,
    base: &str,
) -> Result<TetRead> {
    let nf = format!("{base}.node");
    let ef = format!("{base}.ele");
    parse_tet(&read_all(node, &nf)?, &read_all(ele, &ef)?, base)
}

/// Parse a TetGen tet mesh held in memory.
pub fn parse_tet(node: &[u8], ele: &[u8], base: &str) -> Result<TetRead> {
    let (points, b) = parse_node::<3>(node, &format!("{base}.node"))?;
    let (mut tets, labels) = parse_ele::<4>(ele, &format!("{base}.ele"), 10, points.len(), b)?;
    let (flipped, degenerate) = orient_tets(&points, &mut tets);
    Ok(TetRead {
        mesh: TetMesh::new(points, tets, labels),
        flipped,
        degenerate,
        skipped_elements: 0,
    })
}

/// Read a Triangle 2D mesh from its `.node` and `.ele` streams.
pub fn read_tri<R1: std::io::Read, R2: std::io::Read>(
    node: R1,
    ele: R2,
    base: &str,
) -> Result<TriRead> {
    let nf = format!("{base}.node");
    let ef = format!("{base}.ele");
    parse_tri(&read_all(node, &nf)?, &read_all(ele, &ef)?, base)
}

/// Parse a Triangle 2D mesh held in memory.
pub fn parse_tri(node: &[u8], ele: &[u8], base: &str) -> Result<TriRead> {
    let (points, b) = parse_node::<2>(node, &format!("{base}.node"))?;
    let (mut tris, labels) = parse_ele::<3>(ele, &format!("{base}.ele"), 6, points.len(), b)?;
    let (flipped, degenerate) = orient_tris(&points, &mut tris);
    Ok(TriRead {
        mesh: TriMesh::new(points, tris, labels),
        flipped,
        degenerate,
    })
}

/// The dimension (2 or 3) declared by a `.node` file's header.
pub fn peek_dim<R: BufRead>(mut r: R, file: &str) -> Result<usize> {
    let mut line = Vec::new();
    let mut no = 0;
    loop {
        line.clear();
        no += 1;
        if r.read_until(b'\n', &mut line)
            .map_err(|e| Error::io(file, e))?
            == 0
        {
            return Err(Error::format(file, "empty .node file"));
        }
        let text = match line.iter().position(|&c| c == b'#') {
            Some(i) => &line[..i],
            None => &line[..],
        };
        let mut toks = text
            .split(|c| c.is_ascii_whitespace())
            .filter(|t| !t.is_empty());
        if toks.next().is_none() {
            continue;
        }
        return match toks.next().and_then(crate::text::parse_u64) {
            Some(d @ (2 | 3)) => Ok(d as usize),
            _ => Err(Error::line(
                file,
                no,
                "expected '<points> <dimension 2 or 3> ...' header",
            )),
        };
    }
}

fn write_nodes<W: Write, const D: usize>(
    w: W,
    pts: &[[f64; D]],
    base: u64,
    file: &str,
) -> Result<()> {
    let mut out = Out::new(w);
    out.int(pts.len());
    out.c(b' ');
    out.int(D);
    out.s(" 0 0\n");
    for (i, p) in pts.iter().enumerate() {
        out.int(i as u64 + base);
        for &x in p {
            out.c(b' ');
            out.f64(x);
        }
        out.c(b'\n');
        out.check().map_err(|e| Error::io(file, e))?;
    }
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}

fn write_cells<W: Write, const K: usize>(
    w: W,
    cells: &[[u32; K]],
    header_tail: &str,
    attr: impl Fn(usize) -> u64,
    base: u64,
    file: &str,
) -> Result<()> {
    let mut out = Out::new(w);
    out.int(cells.len());
    out.s(header_tail);
    for (i, c) in cells.iter().enumerate() {
        out.int(i as u64 + base);
        for &v in c {
            out.c(b' ');
            out.int(v as u64 + base);
        }
        out.c(b' ');
        out.int(attr(i));
        out.c(b'\n');
        out.check().map_err(|e| Error::io(file, e))?;
    }
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}

/// Write a TetGen tet mesh to its `.node`, `.ele` and (when given) `.face` streams; `base` names
/// the files in errors.
pub fn write_tet<W1: Write, W2: Write, W3: Write>(
    node: W1,
    ele: W2,
    face: Option<W3>,
    mesh: &TetMesh,
    base: &str,
    opts: TetgenOptions,
) -> Result<()> {
    check_tet(mesh, &format!("{base}.ele"))?;
    let b = if opts.zero_based { 0 } else { 1 };
    write_nodes(node, &mesh.points, b, &format!("{base}.node"))?;
    write_cells(
        ele,
        &mesh.tets,
        " 4 1\n",
        |i| mesh.labels[i] as u64,
        b,
        &format!("{base}.ele"),
    )?;
    if let Some(face) = face {
        let g = face_groups(mesh);
        write_cells(
            face,
            &g.faces,
            " 1\n",
            |i| g.group_of[i] as u64 + 1,
            b,
            &format!("{base}.face"),
        )?;
    }
    Ok(())
}

/// Write a Triangle 2D mesh to its `.node` and `.ele` streams.
pub fn write_tri<W1: Write, W2: Write>(
    node: W1,
    ele: W2,
    mesh: &TriMesh,
    base: &str,
    opts: TetgenOptions,
) -> Result<()> {
    check_tri(mesh, &format!("{base}.ele"))?;
    let b = if opts.zero_based { 0 } else { 1 };
    write_nodes(node, &mesh.points, b, &format!("{base}.node"))?;
    write_cells(
        ele,
        &mesh.triangles,
        " 3 1\n",
        |i| mesh.labels[i] as u64,
        b,
        &format!("{base}.ele"),
    )?;
    Ok(())
}
