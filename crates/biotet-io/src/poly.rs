//! Planar straight-line graphs ([`Pslg`]): Triangle's `.poly`, Triangle's `.node` + `.edge`, and
//! 2D Medit `.mesh` files with `Edges` and no `Triangles` (see [`crate::medit::parse_pslg`]).
//!
//! `.poly` (Triangle's format, `#` comments):
//! ```text
//! <points> 2 <attributes> <markers 0|1>      (0 points: read them from the sibling .node)
//! <i> <x> <y> [attributes...] [marker]
//! <segments> <markers 0|1>
//! <j> <a> <b> [marker]
//! <holes>
//! <k> <x> <y>
//! [<regions>
//!  <l> <x> <y> <label> [<max area>]]
//! ```
//! Points are numbered from 0 or 1 (the first point's index decides, as Triangle does). Region
//! labels must be positive integers (0 is the outside in biotet). Every error names the file and
//! the line.

use std::path::Path;

use biotet::mesh::pslg::{Pslg, RegionPoint};

use crate::common::label_of_f64;
use crate::error::{Error, Result};
use crate::tetgen::{node_section, parse_node};
use crate::text::Lexer;
use crate::{atomic, name};

/// A PSLG read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct PslgRead {
    /// The graph (not yet validated: see [`Pslg::validate`]).
    pub pslg: Pslg,
    /// The files read, for messages.
    pub files: Vec<String>,
}

/// Read the segments of a `.poly` (after its points) or an `.edge` file.
/// The `n` lines of a counted section (`what`, plural), each with at least `min` numbers as
/// `usage` shows, handed to `row`.
fn rows<'a>(
    lx: &mut Lexer<'a>,
    toks: &mut Vec<&'a [u8]>,
    n: usize,
    what: &str,
    min: usize,
    usage: &str,
    mut row: impl FnMut(&Lexer<'a>, &[&'a [u8]]) -> Result<()>,
) -> Result<()> {
    for i in 0..n {
        if !lx.line_tokens(toks) {
            return Err(Error::truncated(
                lx.file,
                format!("expected {n} {what}, found {i}"),
            ));
        }
        if toks.len() < min {
            return Err(lx.err(format!(
                "expected {usage} in the {what}, got {} numbers",
                toks.len()
            )));
        }
        row(lx, toks)?;
    }
    Ok(())
}

fn segments<'a>(
    lx: &mut Lexer<'a>,
    toks: &mut Vec<&'a [u8]>,
    n_points: usize,
    base: u64,
    what: &str,
    g: &mut Pslg,
) -> Result<()> {
    if !lx.line_tokens(toks) {
        return Err(Error::truncated(
            lx.file,
            format!("expected the {what} header"),
        ));
    }
    let n = lx.tok_u64(toks[0], &format!("number of {what}"))? as usize;
    let markers = match toks.get(1) {
        Some(t) => lx.tok_u64(t, "number of boundary markers")? > 0,
        None => false,
    };
    let usage = format!(
        "'<index> <point> <point>{}'",
        if markers { " <marker>" } else { "" }
    );
    rows(lx, toks, n, what, 3, &usage, |lx, toks| {
        lx.tok_u64(toks[0], "segment index")?;
        let mut s = [0u32; 2];
        for (x, t) in s.iter_mut().zip(&toks[1..3]) {
            let v = lx.tok_u64(t, "point index")?;
            if v < base || v - base >= n_points as u64 {
                return Err(lx.err(format!(
                    "point index {v} out of range ({n_points} points numbered from {base})"
                )));
            }
            *x = (v - base) as u32;
        }
        let m = if markers && toks.len() > 3 {
            let v = lx.tok_u64(toks[3], "segment marker").or_else(|_| {
                crate::text::parse_i64(toks[3])
                    .map(|x| x as u64)
                    .ok_or_else(|| lx.err("expected an integer segment marker"))
            })?;
            v as i64 as i32
        } else {
            0
        };
        g.segments.push(s);
        g.segment_markers.push(m);
        Ok(())
    })
}

/// Parse a `.poly` held in memory; `node` gives the sibling `.node` data when the `.poly` lists no
/// points (Triangle's convention).
pub fn parse_poly(data: &[u8], file: &str, node: Option<(&[u8], &str)>) -> Result<PslgRead> {
    let mut lx = Lexer::new(data, file, Some(b'#'));
    let mut toks = Vec::new();
    if !lx.line_tokens(&mut toks) {
        return Err(Error::format(file, "empty .poly file"));
    }
    // The point section is a `.node` file's; Triangle lists no points when a sibling `.node`
    // holds them.
    let (points, mut base) = node_section::<2>(&mut lx, &mut toks, data.len())?;
    let mut g = Pslg {
        points,
        ..Default::default()
    };
    let mut files = vec![file.to_string()];
    if g.points.is_empty() {
        let Some((nd, nf)) = node else {
            return Err(lx.err("no points listed and no .node file next to the .poly"));
        };
        let (pts, b) = parse_node::<2>(nd, nf)?;
        g.points = pts;
        base = b;
        files.push(nf.to_string());
    }
    let np = g.points.len();
    segments(&mut lx, &mut toks, np, base, "segments", &mut g)?;
    // Holes (a missing section means none).
    if lx.line_tokens(&mut toks) {
        let nh = lx.tok_u64(toks[0], "number of holes")? as usize;
        rows(
            &mut lx,
            &mut toks,
            nh,
            "holes",
            3,
            "'<index> <x> <y>'",
            |lx, toks| {
                g.holes
                    .push([lx.tok_f64(toks[1], "x")?, lx.tok_f64(toks[2], "y")?]);
                Ok(())
            },
        )?;
        if lx.line_tokens(&mut toks) {
            let nr = lx.tok_u64(toks[0], "number of regions")? as usize;
            let usage = "'<index> <x> <y> <label> [<max area>]'";
            rows(&mut lx, &mut toks, nr, "regions", 4, usage, |lx, toks| {
                let point = [lx.tok_f64(toks[1], "x")?, lx.tok_f64(toks[2], "y")?];
                let a = lx.tok_f64(toks[3], "region label")?;
                let label = label_of_f64(a).map_err(|e| lx.err(e))?;
                if label == 0 {
                    return Err(lx.err("region label 0 (0 means outside; use a hole instead)"));
                }
                g.regions.push(RegionPoint { point, label });
                Ok(())
            })?;
        }
    }
    Ok(PslgRead { pslg: g, files })
}

/// Parse Triangle's `.node` + `.edge` pair.
pub fn parse_node_edge(
    node: &[u8],
    node_file: &str,
    edge: &[u8],
    edge_file: &str,
) -> Result<PslgRead> {
    let (points, base) = parse_node::<2>(node, node_file)?;
    let mut g = Pslg {
        points,
        ..Default::default()
    };
    let mut lx = Lexer::new(edge, edge_file, Some(b'#'));
    let mut toks = Vec::new();
    let np = g.points.len();
    segments(&mut lx, &mut toks, np, base, "edges", &mut g)?;
    Ok(PslgRead {
        pslg: g,
        files: vec![node_file.to_string(), edge_file.to_string()],
    })
}

/// Is `path` a PSLG: a `.poly`, an `.edge`, a 2D `.node` with a sibling `.edge` and no `.ele`, or
/// a 2D Medit `.mesh` with edges and no triangles?
pub fn is_pslg(path: &Path) -> Result<bool> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    Ok(match ext.as_str() {
        "poly" | "edge" => true,
        "node" => {
            path.with_extension("edge").exists()
                && !path.with_extension("ele").exists()
                && crate::tetgen::peek_dim(atomic::open(path)?, &name(path))? == 2
        }
        "mesh" => {
            crate::medit::peek_kind(atomic::open(path)?, &name(path))?
                == crate::MeshKind::Triangles2d
                && crate::medit::parse_pslg(&atomic::read_file(path)?, &name(path))
                    .map(|r| !r.pslg.segments.is_empty())
                    .unwrap_or(false)
                && crate::medit::parse_tri(&atomic::read_file(path)?, &name(path))
                    .map(|r| r.mesh.triangles.is_empty())
                    .unwrap_or(false)
        }
        _ => false,
    })
}

/// Read a PSLG from `.poly`, `.node`/`.edge` or a 2D Medit `.mesh` (edges as segments).
pub fn read_pslg(path: &Path) -> Result<PslgRead> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "poly" => {
            let node_path = path.with_extension("node");
            let data = atomic::read_file(path)?;
            let node = if node_path.exists() {
                Some(atomic::read_file(&node_path)?)
            } else {
                None
            };
            let nn = name(&node_path);
            parse_poly(
                &data,
                &name(path),
                node.as_deref().map(|d| (d, nn.as_str())),
            )
        }
        "node" | "edge" => {
            let (n, e) = (path.with_extension("node"), path.with_extension("edge"));
            parse_node_edge(
                &atomic::read_file(&n)?,
                &name(&n),
                &atomic::read_file(&e)?,
                &name(&e),
            )
        }
        "mesh" => crate::medit::parse_pslg(&atomic::read_file(path)?, &name(path)),
        _ => Err(Error::UnknownExtension {
            path: name(path),
            kind: "planar straight-line graph",
            supported: PSLG_EXTENSIONS,
        }),
    }
}

/// Supported PSLG extensions, for messages.
pub const PSLG_EXTENSIONS: &str = ".poly, .node/.edge (Triangle), .mesh (Dimension 2, Edges)";

/// Write a PSLG as a `.poly` (points numbered from 1, markers, holes and regions).
pub fn write_poly<W: std::io::Write>(w: W, g: &Pslg, file: &str) -> Result<()> {
    let mut out = crate::text::Out::new(w);
    out.int(g.points.len());
    out.s(" 2 0 0\n");
    for (i, p) in g.points.iter().enumerate() {
        out.int(i + 1);
        out.c(b' ');
        out.f64s(p);
        out.c(b'\n');
    }
    out.int(g.segments.len());
    out.s(" 1\n");
    for (i, s) in g.segments.iter().enumerate() {
        out.ints(&[i as i64 + 1, s[0] as i64 + 1, s[1] as i64 + 1]);
        out.c(b' ');
        out.int(g.segment_markers.get(i).copied().unwrap_or(0));
        out.c(b'\n');
    }
    out.int(g.holes.len());
    out.c(b'\n');
    for (i, p) in g.holes.iter().enumerate() {
        out.int(i + 1);
        out.c(b' ');
        out.f64s(p);
        out.c(b'\n');
    }
    out.int(g.regions.len());
    out.c(b'\n');
    for (i, r) in g.regions.iter().enumerate() {
        out.int(i + 1);
        out.c(b' ');
        out.f64s(&r.point);
        out.c(b' ');
        out.int(r.label);
        out.c(b'\n');
    }
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}
