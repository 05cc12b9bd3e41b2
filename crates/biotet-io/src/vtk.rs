//! Legacy VTK (`.vtk`): surfaces (`POLYDATA`) and tet meshes (`UNSTRUCTURED_GRID`), read.
//!
//! The "simple legacy format" of VTK's file-format document, any version: the header line
//! `# vtk DataFile Version x.y`, a title line, `ASCII` or `BINARY` (big-endian), then
//! `DATASET POLYDATA` or `DATASET UNSTRUCTURED_GRID` (other datasets are refused by name).
//! Keywords are case-insensitive; blank lines, extra whitespace and `\r\n` line ends are
//! accepted. `POINTS` may have any numeric type. Cells come in both generations: before version
//! 5, `POLYGONS n size` (or `CELLS`, `TRIANGLE_STRIPS`, `VERTICES`, `LINES`) followed by each
//! cell's point count and indices; from 5.1 (VTK 9, PyVista), `POLYGONS n_offsets n_conn` followed
//! by `OFFSETS type` and `CONNECTIVITY type` arrays (told apart by the `OFFSETS` line, not by
//! the version). Array names are decoded from VTK's `%XX` escapes.
//!
//! Surfaces ([`parse_surface`]): from `POLYDATA`, polygons (fan-split, counted in
//! [`SurfaceRead::polygons_split`]) and triangle strips (every triangle turned to the strip's
//! orientation); from an `UNSTRUCTURED_GRID`, triangles, quads, pixels and polygons (VTK types 5,
//! 9, 8, 7; fan-split) and strips (6). Vertices, lines and non-linear surface cells are ignored; a
//! volume cell is an error. Side labels come, as in [`crate::vtu`], from a two-component integer
//! cell array `sides`, `BoundaryLabels` or `boundary_labels`, or two scalar integer arrays
//! `label_back` and `label_front` (or `region_back`, `region_front`), returned in
//! [`SurfaceRead::side_labels`] (the mesh keeps sides `[1, 0]`); a polygon's or strip's
//! triangles share its pair. `POLYDATA` cell data runs over vertices, lines, polygons, then
//! strips, whatever their order in the file.
//!
//! Tet meshes ([`parse_tet`]): `UNSTRUCTURED_GRID` linear tetrahedra (type 10); other volume
//! cells are counted in [`TetRead::skipped_elements`], surface, line and vertex cells are
//! ignored; `POLYDATA` is an error. The label is taken from the first single-component cell array (`SCALARS` or `FIELD`)
//! named `region`, `gmsh:physical`, `medit:ref`, `CellEntityIds`, `tetgen:ref`, `label`,
//! `labels`, `material` or `MaterialIds` (in that order of preference; float arrays of whole
//! numbers are accepted), else from the first single-component integer cell array, else it is 1;
//! labels must be non-negative integers. Tets are oriented like every reader's
//! ([`orient_tets`]).
//!
//! Everything else is parsed past: dataset-level `FIELD` data, `POINT_DATA`, `SCALARS`,
//! `COLOR_SCALARS`, `LOOKUP_TABLE`, `VECTORS`, `NORMALS`, `TENSORS`, `TENSORS6`,
//! `TEXTURE_COORDINATES`, `GLOBAL_IDS`, `PEDIGREE_IDS`, `EDGE_FLAGS`, `TANGENTS`,
//! `RATIONAL_WEIGHTS`, `HIGHERORDERDEGREES`, and VTK 9's `METADATA` blocks; `bit` and `string`
//! arrays are skipped too. `long` is taken as 64-bit (what VTK writes on Linux and macOS) and
//! `vtkIdType` as 32-bit (what VTK writes). ASCII coordinates keep the value of their text as
//! `f64`, whatever the declared type (VTK would round `float` ones to `f32`).
//!
//! Limits: a count is checked against the bytes left before anything is allocated for it, so a
//! small file announcing a huge mesh fails at once as truncated; point indices are checked, and
//! a non-finite coordinate is an error naming the point.

use std::borrow::Cow;
use std::io::Read;

use biotet::{SurfaceMesh, TetMesh};

use crate::common::{
    check_point_count, label_of, label_of_f64, orient_tets, read_all, side_label_of,
};
use crate::error::{Error, Result};
use crate::text::{Lexer, is_ws, parse_f64, parse_i64, parse_u64, show};
use crate::vtu::{LABEL_NAMES, SIDE_ARRAYS, SIDE_PAIRS};
use crate::{MeshKind, SurfaceRead, TetRead};

/// Read a legacy VTK surface from a stream; `file` names it in errors.
pub fn read_surface<R: Read>(r: R, file: &str) -> Result<SurfaceRead> {
    parse_surface(&read_all(r, file)?, file)
}

/// Read a legacy VTK tet mesh from a stream; `file` names it in errors.
pub fn read_tet<R: Read>(r: R, file: &str) -> Result<TetRead> {
    parse_tet(&read_all(r, file)?, file)
}

/// What a legacy VTK file holds: [`MeshKind::Tetrahedra`] for an `UNSTRUCTURED_GRID` with at
/// least one volume cell, else [`MeshKind::Surface`]. Reads only as far as the cell types.
pub fn peek_kind(data: &[u8], file: &str) -> Result<MeshKind> {
    let p = parse(data, file, Mode::Kind)?;
    let volume = p
        .types
        .as_ref()
        .is_some_and(|t| t.iter().any(|&t| is_volume_cell(t)));
    Ok(if volume {
        MeshKind::Tetrahedra
    } else {
        MeshKind::Surface
    })
}

/// Parse a legacy VTK surface held in memory (see the [module documentation](self)).
pub fn parse_surface(data: &[u8], file: &str) -> Result<SurfaceRead> {
    let mut p = parse(data, file, Mode::Surface)?;
    let points = p.points.take().unwrap_or_default();
    let np = points.len();
    let ncells = p.ncells();
    let sides = side_source(&p.arrays, ncells, data, file)?;
    let mut out = Tris {
        triangles: Vec::new(),
        sides: Vec::new(),
        split: 0,
    };
    let side = |i: usize| match &sides {
        Some(s) => s.pair(i, file),
        None => Ok([1, 0]),
    };
    if p.poly {
        // Cell data runs over vertices, lines, polygons, then strips.
        let mut first = 0;
        for (s, cells) in p.sets.iter().enumerate() {
            let Some(cells) = cells else { continue };
            // Vertices and lines only shift the cell-data index.
            if s >= 2 {
                let what = POLY_SETS[s].1;
                for i in 0..cells.len() {
                    let c = corners(cells, i, np, what, file)?;
                    let pair = side(first + i)?;
                    if s == 2 {
                        out.fan(c, pair, what, i, file)?;
                    } else {
                        out.strip(c, pair, what, i, file)?;
                    }
                }
            }
            first += cells.len();
        }
    } else if let Some(cells) = &p.sets[0] {
        let types = p.types.as_deref().unwrap_or_default();
        for (i, &t) in types.iter().enumerate() {
            if is_volume_cell(t) {
                return Err(Error::element(
                    file,
                    "cell",
                    i,
                    format!("a volume cell (VTK type {t}): a tet mesh, expected a surface"),
                ));
            }
            if !matches!(t, 5..=9) {
                continue;
            }
            let c = corners(cells, i, np, "cell", file)?;
            let want = match t {
                5 => 3,
                8 | 9 => 4,
                _ => c.len(),
            };
            if c.len() != want {
                return Err(Error::element(
                    file,
                    "cell",
                    i,
                    format!("a {} (VTK type {t}) with {} points", cell_name(t), c.len()),
                ));
            }
            match t {
                6 => out.strip(c, side(i)?, "cell", i, file)?,
                // A pixel's corners go row by row; as a cycle they are 0, 1, 3, 2.
                8 => out.fan(&[c[0], c[1], c[3], c[2]], side(i)?, "cell", i, file)?,
                _ => out.fan(c, side(i)?, "cell", i, file)?,
            }
        }
    }
    Ok(SurfaceRead {
        mesh: SurfaceMesh::closed(points, out.triangles, 1),
        triangle_refs: None,
        side_labels: sides.is_some().then_some(out.sides),
        welded: 0,
        polygons_split: out.split,
    })
}

/// Parse a legacy VTK tet mesh held in memory (see the [module documentation](self)).
pub fn parse_tet(data: &[u8], file: &str) -> Result<TetRead> {
    let mut p = parse(data, file, Mode::Tet)?;
    if p.poly {
        return Err(Error::format(
            file,
            "a surface (POLYDATA), expected a tet mesh",
        ));
    }
    let points = p.points.take().unwrap_or_default();
    let np = points.len();
    let ncells = p.ncells();
    let label = label_array(&p.arrays);
    if let Some(a) = label {
        a.check_tuples(ncells, data, file)?;
    }
    let (mut tets, mut labels) = (Vec::new(), Vec::new());
    let mut skipped = 0;
    if let Some(cells) = &p.sets[0] {
        let types = p.types.as_deref().unwrap_or_default();
        for (i, &t) in types.iter().enumerate() {
            if t != 10 {
                skipped += usize::from(is_volume_cell(t));
                continue;
            }
            let c = corners(cells, i, np, "cell", file)?;
            let &[a, b, cc, d] = c else {
                return Err(Error::element(
                    file,
                    "cell",
                    i,
                    format!("a tetra (VTK type 10) with {} points", c.len()),
                ));
            };
            let l = match label {
                Some(arr) => {
                    let l = match &arr.vals {
                        Vals::I(v) => label_of(v[i]),
                        Vals::F(v) => label_of_f64(v[i]),
                    };
                    l.map_err(|e| {
                        Error::element(file, "cell", i, format!("array '{}': {e}", show(&arr.name)))
                    })?
                }
                None => 1,
            };
            tets.push([a, b, cc, d]);
            labels.push(l);
        }
    }
    let (flipped, degenerate) = orient_tets(&points, &mut tets);
    Ok(TetRead {
        mesh: TetMesh::new(points, tets, labels),
        flipped,
        degenerate,
        skipped_elements: skipped,
    })
}

// ---------------------------------------------------------------------------------------------
// Cell types and label arrays.

/// VTK cell types that are volumes: linear, quadratic, higher-order (Lagrange, Bézier),
/// parametric regions, convex point sets and polyhedra.
pub(crate) fn is_volume_cell(t: u8) -> bool {
    matches!(
        t,
        10..=16 | 24..=27 | 29 | 31..=33 | 37 | 41 | 42 | 55 | 56 | 64..=67 | 71..=74 | 78..=81
    )
}

/// The name of a surface cell type, for messages.
fn cell_name(t: u8) -> &'static str {
    match t {
        5 => "triangle",
        6 => "triangle strip",
        7 => "polygon",
        8 => "pixel",
        _ => "quad",
    }
}

/// The label array of a tet mesh: a named one first, else the first integer one.
fn label_array<'b, 'a>(arrays: &'b [Arr<'a>]) -> Option<&'b Arr<'a>> {
    LABEL_NAMES
        .iter()
        .find_map(|n| {
            arrays
                .iter()
                .find(|a| a.ncomp == 1 && *a.name == *n.as_bytes())
        })
        .or_else(|| arrays.iter().find(|a| a.ncomp == 1 && a.ty.is_int()))
}

/// Where a surface's side labels come from.
enum Sides<'b, 'a> {
    /// One two-component array.
    One(&'b Arr<'a>),
    /// Back and front scalar arrays.
    Pair(&'b Arr<'a>, &'b Arr<'a>),
}

impl Sides<'_, '_> {
    /// The `[back, front]` labels of cell `i`.
    fn pair(&self, i: usize, file: &str) -> Result<[u32; 2]> {
        let one = |a: &Arr, k: usize| {
            let v = match &a.vals {
                Vals::I(v) => v[k],
                // Side arrays are kept only when integer-typed.
                Vals::F(_) => 0,
            };
            side_label_of(v).map_err(|e| {
                Error::element(file, "cell", i, format!("array '{}': {e}", show(&a.name)))
            })
        };
        match self {
            Sides::One(a) => Ok([one(a, 2 * i)?, one(a, 2 * i + 1)?]),
            Sides::Pair(b, f) => Ok([one(b, i)?, one(f, i)?]),
        }
    }
}

/// The side-label arrays among the cell arrays, checked against the number of cells.
fn side_source<'b, 'a>(
    arrays: &'b [Arr<'a>],
    ncells: usize,
    data: &[u8],
    file: &str,
) -> Result<Option<Sides<'b, 'a>>> {
    let find = |n: &str, ncomp: usize| {
        arrays
            .iter()
            .find(|a| *a.name == *n.as_bytes() && a.ncomp == ncomp && a.ty.is_int())
    };
    if let Some(a) = SIDE_ARRAYS.iter().find_map(|n| find(n, 2)) {
        a.check_tuples(ncells, data, file)?;
        return Ok(Some(Sides::One(a)));
    }
    if let Some((b, f)) = SIDE_PAIRS
        .iter()
        .find_map(|(b, f)| Some((find(b, 1)?, find(f, 1)?)))
    {
        b.check_tuples(ncells, data, file)?;
        f.check_tuples(ncells, data, file)?;
        return Ok(Some(Sides::Pair(b, f)));
    }
    Ok(None)
}

/// Whether a cell array may be needed: side-label candidates for surfaces, single-component
/// label candidates for tets.
fn wanted(mode: Mode, name: &[u8], ncomp: usize, ty: Ty) -> bool {
    match mode {
        Mode::Kind => false,
        Mode::Surface => {
            ty.is_int()
                && ((ncomp == 2 && SIDE_ARRAYS.iter().any(|n| n.as_bytes() == name))
                    || (ncomp == 1
                        && SIDE_PAIRS
                            .iter()
                            .any(|(b, f)| b.as_bytes() == name || f.as_bytes() == name)))
        }
        Mode::Tet => {
            ncomp == 1
                && (ty.is_int()
                    || (ty.is_float() && LABEL_NAMES.iter().any(|n| n.as_bytes() == name)))
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Building triangles.

/// The triangles of a surface being built, with their side labels.
struct Tris {
    triangles: Vec<[u32; 3]>,
    sides: Vec<[u32; 2]>,
    split: usize,
}

impl Tris {
    /// A polygon, fan-split from its first corner.
    fn fan(
        &mut self,
        c: &[u32],
        side: [u32; 2],
        what: &'static str,
        i: usize,
        file: &str,
    ) -> Result<()> {
        if c.len() < 3 {
            return Err(Error::element(
                file,
                what,
                i,
                format!("a polygon with {} corners", c.len()),
            ));
        }
        for t in crate::common::fan(c, &mut self.split) {
            self.triangles.push(t);
            self.sides.push(side);
        }
        Ok(())
    }

    /// A triangle strip: triangle `j` is `j, j+1, j+2`, its first two corners swapped for odd
    /// `j` so that all keep the strip's orientation.
    fn strip(
        &mut self,
        c: &[u32],
        side: [u32; 2],
        what: &'static str,
        i: usize,
        file: &str,
    ) -> Result<()> {
        if c.len() < 3 {
            return Err(Error::element(
                file,
                what,
                i,
                format!("a triangle strip with {} points", c.len()),
            ));
        }
        for t in crate::common::strip(c) {
            self.triangles.push(t);
            self.sides.push(side);
        }
        Ok(())
    }
}

/// The point indices of cell `i`, checked against the `np` points.
fn corners<'c>(
    cells: &'c Cells,
    i: usize,
    np: usize,
    what: &'static str,
    file: &str,
) -> Result<&'c [u32]> {
    let c = cells.get(i);
    match c.iter().find(|&&v| v as usize >= np) {
        Some(v) => Err(Error::element(
            file,
            what,
            i,
            format!("point index {v} out of range ({np} points)"),
        )),
        None => Ok(c),
    }
}

// ---------------------------------------------------------------------------------------------
// Parsing.

/// What a parse is for: which cell arrays to keep, whether to keep points and cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Surface,
    Tet,
    /// Only the dataset type and the cell types.
    Kind,
}

/// The `POLYDATA` cell sections, in cell-data order, with the element name for messages.
const POLY_SETS: [(&str, &str); 4] = [
    ("VERTICES", "vertex cell"),
    ("LINES", "line cell"),
    ("POLYGONS", "polygon"),
    ("TRIANGLE_STRIPS", "triangle strip"),
];

/// The numeric type of an array.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ty {
    Bit,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
    Str,
}

impl Ty {
    fn parse(t: &[u8]) -> Option<Ty> {
        const NAMES: [(&str, Ty); 17] = [
            ("bit", Ty::Bit),
            ("char", Ty::I8),
            ("signed_char", Ty::I8),
            ("unsigned_char", Ty::U8),
            ("short", Ty::I16),
            ("unsigned_short", Ty::U16),
            ("int", Ty::I32),
            // VTK writes id arrays as 32-bit ints in legacy files.
            ("vtkIdType", Ty::I32),
            ("unsigned_int", Ty::U32),
            ("long", Ty::I64),
            ("vtktypeint64", Ty::I64),
            ("unsigned_long", Ty::U64),
            ("vtktypeuint64", Ty::U64),
            ("float", Ty::F32),
            ("double", Ty::F64),
            ("string", Ty::Str),
            ("utf8_string", Ty::Str),
        ];
        NAMES
            .iter()
            .find(|(n, _)| n.as_bytes().eq_ignore_ascii_case(t))
            .map(|&(_, ty)| ty)
    }

    /// Bytes per value in binary data (bits and strings are sized otherwise).
    fn size(self) -> usize {
        match self {
            Ty::Bit | Ty::Str => 0,
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::I64 | Ty::U64 | Ty::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Ty::F32 | Ty::F64)
    }

    fn is_int(self) -> bool {
        !matches!(self, Ty::F32 | Ty::F64 | Ty::Bit | Ty::Str)
    }
}

/// Copy the first `N` bytes of `b` (which has at least `N`).
#[inline]
fn bytes<const N: usize>(b: &[u8]) -> [u8; N] {
    let mut a = [0; N];
    a.copy_from_slice(&b[..N]);
    a
}

/// A big-endian integer of type `ty` (`b` holds `ty.size()` bytes); `None` for a `U64` beyond
/// `i64` (and for non-integer types, which callers exclude).
#[inline]
fn be_int(ty: Ty, b: &[u8]) -> Option<i64> {
    Some(match ty {
        Ty::I8 => b[0] as i8 as i64,
        Ty::U8 => b[0] as i64,
        Ty::I16 => i16::from_be_bytes(bytes(b)) as i64,
        Ty::U16 => u16::from_be_bytes(bytes(b)) as i64,
        Ty::I32 => i32::from_be_bytes(bytes(b)) as i64,
        Ty::U32 => u32::from_be_bytes(bytes(b)) as i64,
        Ty::I64 => i64::from_be_bytes(bytes(b)),
        Ty::U64 => i64::try_from(u64::from_be_bytes(bytes(b))).ok()?,
        Ty::F32 | Ty::F64 | Ty::Bit | Ty::Str => return None,
    })
}

/// A big-endian value of numeric type `ty` as `f64`.
#[inline]
fn be_f64(ty: Ty, b: &[u8]) -> f64 {
    match ty {
        Ty::F32 => f32::from_be_bytes(bytes(b)) as f64,
        Ty::F64 => f64::from_be_bytes(bytes(b)),
        Ty::U64 => u64::from_be_bytes(bytes(b)) as f64,
        _ => be_int(ty, b).unwrap_or(0) as f64,
    }
}

/// Decode VTK's `%XX` escapes in an array name.
fn decode_name(n: &[u8]) -> Cow<'_, [u8]> {
    if !n.contains(&b'%') {
        return Cow::Borrowed(n);
    }
    let hex = |c: u8| (c as char).to_digit(16);
    let mut out = Vec::with_capacity(n.len());
    let mut i = 0;
    while i < n.len() {
        match (
            n[i],
            n.get(i + 1).and_then(|&c| hex(c)),
            n.get(i + 2).and_then(|&c| hex(c)),
        ) {
            (b'%', Some(h), Some(l)) => {
                out.push((h * 16 + l) as u8);
                i += 3;
            }
            (c, _, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    Cow::Owned(out)
}

/// The 1-based line number of byte `pos` (for messages only: it scans the data).
fn line_of(data: &[u8], pos: usize) -> usize {
    1 + data[..pos.min(data.len())]
        .iter()
        .filter(|&&c| c == b'\n')
        .count()
}

/// Cells as offsets into a connectivity list.
#[derive(Debug, Default)]
struct Cells {
    /// `len() + 1` non-decreasing offsets into `conn`, from 0 to `conn.len()`.
    off: Vec<usize>,
    conn: Vec<u32>,
}

impl Cells {
    fn len(&self) -> usize {
        self.off.len().saturating_sub(1)
    }

    fn get(&self, i: usize) -> &[u32] {
        &self.conn[self.off[i]..self.off[i + 1]]
    }
}

/// Values of a kept cell array.
#[derive(Debug)]
enum Vals {
    I(Vec<i64>),
    F(Vec<f64>),
}

/// A cell array kept to look for labels.
#[derive(Debug)]
struct Arr<'a> {
    name: Cow<'a, [u8]>,
    ncomp: usize,
    ntuples: usize,
    ty: Ty,
    vals: Vals,
    /// Where its header line starts, for messages.
    at: usize,
}

impl Arr<'_> {
    fn check_tuples(&self, ncells: usize, data: &[u8], file: &str) -> Result<()> {
        if self.ntuples != ncells {
            return Err(Error::line(
                file,
                line_of(data, self.at),
                format!(
                    "cell array '{}' has {} tuples for {ncells} cells",
                    show(&self.name),
                    self.ntuples
                ),
            ));
        }
        Ok(())
    }
}

/// What a file holds, as far as the mode needs.
#[derive(Debug, Default)]
struct Parsed<'a> {
    poly: bool,
    points: Option<Vec<[f64; 3]>>,
    /// `POLYDATA`: vertices, lines, polygons, strips; `UNSTRUCTURED_GRID`: `CELLS` first.
    sets: [Option<Cells>; 4],
    types: Option<Vec<u8>>,
    /// The cell arrays kept (see [`wanted`]), in file order.
    arrays: Vec<Arr<'a>>,
}

impl Parsed<'_> {
    /// The number of cells (of all kinds).
    fn ncells(&self) -> usize {
        self.sets.iter().flatten().map(Cells::len).sum()
    }
}

/// Reads the file: header lines as tokens, data as ASCII tokens or big-endian binary.
struct Rd<'a> {
    lx: Lexer<'a>,
    data: &'a [u8],
    file: &'a str,
    binary: bool,
    /// Where the last header line starts: line numbers are counted from it only for messages,
    /// so binary data is never scanned for newlines.
    line_pos: usize,
    /// Components of the last array read, for the component names of its `METADATA`.
    last_ncomp: usize,
}

impl<'a> Rd<'a> {
    /// The tokens of the next non-blank line, its newline consumed (binary data starts right
    /// after it); `false` at the end of the file.
    fn line(&mut self, toks: &mut Vec<&'a [u8]>) -> bool {
        self.lx.skip_ws();
        self.line_pos = self.lx.pos;
        if !self.lx.line_tokens(toks) {
            return false;
        }
        if self.data.get(self.lx.pos) == Some(&b'\n') {
            self.lx.pos += 1;
            self.lx.line += 1;
        }
        true
    }

    /// An error at the line of the last header line (binary) or token (ASCII).
    fn err(&self, msg: impl Into<String>) -> Error {
        Error::line(self.file, self.err_line(), msg)
    }

    /// The line for [`Rd::err`]: the lexer counts lines in text, which binary data bypasses.
    fn err_line(&self) -> usize {
        if self.binary {
            line_of(self.data, self.line_pos)
        } else {
            self.lx.tok_line
        }
    }

    /// The line of the last header line.
    fn header_line(&self) -> usize {
        line_of(self.data, self.line_pos)
    }

    /// An error about element `i` of data just read: its line in ASCII, its index in binary.
    fn err_at(&self, what: &'static str, i: usize, msg: impl Into<String>) -> Error {
        if self.binary {
            Error::element(self.file, what, i, msg)
        } else {
            self.lx.err(format!("{what} {i}: {}", msg.into()))
        }
    }

    /// Check that `n` values of `ty` can fit in the bytes left (at least two bytes per ASCII
    /// value, the exact size in binary), before anything is allocated for them.
    fn room(&self, n: u64, ty: Ty, what: &str) -> Result<usize> {
        let left = (self.data.len() - self.lx.pos) as u128;
        let n128 = u128::from(n);
        let need = match (self.binary, ty) {
            (true, Ty::Bit) => n128.div_ceil(8),
            (true, Ty::Str) => n128,
            (true, _) => n128 * ty.size() as u128,
            (false, Ty::Str) => n128.saturating_sub(1),
            (false, _) => (2 * n128).saturating_sub(1),
        };
        if need > left {
            return Err(Error::truncated(
                self.file,
                format!(
                    "{what} (line {}) announces {n} values, which need at least {need} bytes; \
                     {left} bytes are left",
                    self.header_line()
                ),
            ));
        }
        usize::try_from(n).map_err(|_| self.err(format!("{what}: {n} values is too many")))
    }

    /// `count × ncomp` as a number of values.
    fn values_of(&self, count: usize, ncomp: usize) -> Result<u64> {
        (count as u64)
            .checked_mul(ncomp as u64)
            .ok_or_else(|| self.err(format!("{count} tuples of {ncomp} components is too many")))
    }

    /// The next ASCII token; a truncation error naming `what` at the end of the file.
    #[inline]
    fn tok(&mut self, what: &str) -> Result<&'a [u8]> {
        self.lx
            .next_token()
            .ok_or_else(|| Error::truncated(self.file, format!("the file ends inside {what}")))
    }

    /// The next `n` bytes of binary data.
    #[inline]
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        let p = self.lx.pos;
        match p.checked_add(n).and_then(|end| self.data.get(p..end)) {
            Some(b) => {
                self.lx.pos += n;
                Ok(b)
            }
            None => Err(Error::truncated(
                self.file,
                format!("the file ends inside {what}"),
            )),
        }
    }

    /// One integer of integer type `ty`.
    #[inline]
    fn int(&mut self, ty: Ty, what: &str) -> Result<i64> {
        if self.binary {
            let b = self.take(ty.size(), what)?;
            return be_int(ty, b)
                .ok_or_else(|| self.err(format!("{what}: a value beyond 64-bit signed integers")));
        }
        let t = self.tok(what)?;
        parse_i64(t)
            .ok_or_else(|| self.err(format!("expected an integer in {what}, got '{}'", show(t))))
    }

    /// One number of numeric type `ty`, as `f64` (non-finite values are returned).
    #[inline]
    fn float(&mut self, ty: Ty, what: &str) -> Result<f64> {
        if self.binary {
            let b = self.take(ty.size(), what)?;
            return Ok(be_f64(ty, b));
        }
        let t = self.tok(what)?;
        parse_f64(t)
            .ok_or_else(|| self.err(format!("expected a number in {what}, got '{}'", show(t))))
    }

    /// Skip `n` values of `ty` (already checked by [`Rd::room`]).
    fn skip(&mut self, n: usize, ty: Ty, what: &str) -> Result<()> {
        match (self.binary, ty) {
            (true, Ty::Str) => {
                for _ in 0..n {
                    // A length of 6, 14, 30 or 62 bits, by the top two bits of the first byte.
                    let h = self.take(1, what)?[0];
                    let len = match h >> 6 {
                        3 => u64::from(h & 0x3f),
                        2 => u64::from(u16::from_be_bytes([h, self.take(1, what)?[0]]) & 0x3fff),
                        1 => {
                            let b = self.take(3, what)?;
                            u64::from(u32::from_be_bytes([h, b[0], b[1], b[2]]) & 0x3fff_ffff)
                        }
                        _ => {
                            let b = self.take(7, what)?;
                            let mut a = [h; 8];
                            a[1..].copy_from_slice(b);
                            u64::from_be_bytes(a) & 0x3fff_ffff_ffff_ffff
                        }
                    };
                    let len = usize::try_from(len).unwrap_or(usize::MAX);
                    self.take(len, what)?;
                }
            }
            (true, _) => {
                let len = if ty == Ty::Bit {
                    n.div_ceil(8)
                } else {
                    n * ty.size()
                };
                self.take(len, what)?;
            }
            (false, Ty::Str) => {
                for _ in 0..n {
                    if self.lx.pos >= self.data.len() {
                        return Err(Error::truncated(
                            self.file,
                            format!("the file ends inside {what}"),
                        ));
                    }
                    self.lx.raw_line();
                }
            }
            (false, _) => {
                for _ in 0..n {
                    let t = self.tok(what)?;
                    // Catch a keyword read as data, for a clear message; numbers are not parsed.
                    if t[0].is_ascii_alphabetic() && parse_f64(t).is_none() {
                        return Err(
                            self.err(format!("expected a number in {what}, got '{}'", show(t)))
                        );
                    }
                }
            }
        }
        Ok(())
    }

    /// Whether the next non-blank text starts with keyword `kw`; nothing is consumed.
    fn peek_kw(&mut self, kw: &str) -> bool {
        let (pos, line, tok_line) = (self.lx.pos, self.lx.line, self.lx.tok_line);
        self.lx.skip_ws();
        let rest = &self.data[self.lx.pos..];
        let k = kw.len();
        let found = rest.len() >= k
            && rest[..k].eq_ignore_ascii_case(kw.as_bytes())
            && rest.get(k).is_none_or(|&c| is_ws(c));
        (self.lx.pos, self.lx.line, self.lx.tok_line) = (pos, line, tok_line);
        found
    }

    /// Skip the `METADATA` block that may follow an array.
    fn maybe_metadata(&mut self, toks: &mut Vec<&'a [u8]>) {
        if self.peek_kw("METADATA") {
            self.line(toks);
            self.metadata();
        }
    }

    /// Skip a `METADATA` block (its keyword line read): lines up to an empty one, as VTK does,
    /// except that `COMPONENT_NAMES` is followed by one line per component, empty for an
    /// unnamed one.
    fn metadata(&mut self) {
        while self.lx.pos < self.data.len() {
            let l = self.lx.raw_line().trim_ascii();
            if l.is_empty() {
                break;
            }
            if l.eq_ignore_ascii_case(b"COMPONENT_NAMES") {
                // The count comes from the file: stop at its end.
                for _ in 0..self.last_ncomp {
                    if self.lx.pos >= self.data.len() {
                        return;
                    }
                    self.lx.raw_line();
                }
            }
        }
    }

    /// Read or skip an array of `count` tuples of `ncomp` components; the values are returned
    /// when `keep`. A `METADATA` block after it is skipped.
    fn array(
        &mut self,
        (count, ncomp, ty): (usize, usize, Ty),
        what: &str,
        keep: bool,
        toks: &mut Vec<&'a [u8]>,
    ) -> Result<Option<Vals>> {
        let n = self.room(self.values_of(count, ncomp)?, ty, what)?;
        let vals = if !keep {
            self.skip(n, ty, what)?;
            None
        } else if ty.is_float() {
            let mut v = Vec::with_capacity(n);
            for _ in 0..n {
                v.push(self.float(ty, what)?);
            }
            Some(Vals::F(v))
        } else {
            let mut v = Vec::with_capacity(n);
            for _ in 0..n {
                v.push(self.int(ty, what)?);
            }
            Some(Vals::I(v))
        };
        self.last_ncomp = ncomp;
        self.maybe_metadata(toks);
        Ok(vals)
    }

    /// A count token of a header line.
    fn count(&self, t: &[u8], what: &str) -> Result<usize> {
        let n = parse_u64(t).ok_or_else(|| {
            self.err(format!(
                "expected {what} (a non-negative integer), got '{}'",
                show(t)
            ))
        })?;
        usize::try_from(n).map_err(|_| self.err(format!("{what} {n} is too large")))
    }

    /// A type token of a header line.
    fn ty(&self, t: &[u8]) -> Result<Ty> {
        Ty::parse(t).ok_or_else(|| self.err(format!("unknown data type '{}'", show(t))))
    }

    /// An integer type token (cell data).
    fn int_ty(&self, t: &[u8], what: &str) -> Result<Ty> {
        let ty = self.ty(t)?;
        if !ty.is_int() {
            return Err(self.err(format!(
                "{what} of type '{}', expected an integer type",
                show(t)
            )));
        }
        Ok(ty)
    }

    /// Check the number of tokens of a header line, naming its expected form.
    fn args(&self, toks: &[&[u8]], n: std::ops::RangeInclusive<usize>, form: &str) -> Result<()> {
        if !n.contains(&toks.len()) {
            return Err(self.err(format!(
                "expected '{form}', got '{}'",
                toks.iter().map(|t| show(t)).collect::<Vec<_>>().join(" ")
            )));
        }
        Ok(())
    }

    /// The `n` points after a `POINTS` line, kept when `keep`.
    fn points(
        &mut self,
        n: usize,
        ty: Ty,
        keep: bool,
        toks: &mut Vec<&'a [u8]>,
    ) -> Result<Option<Vec<[f64; 3]>>> {
        if !keep {
            self.array((n, 3, ty), "POINTS", false, toks)?;
            return Ok(None);
        }
        self.room(self.values_of(n, 3)?, ty, "POINTS")?;
        let mut pts = Vec::with_capacity(n);
        for i in 0..n {
            let p = [
                self.float(ty, "POINTS")?,
                self.float(ty, "POINTS")?,
                self.float(ty, "POINTS")?,
            ];
            if p.iter().any(|x| !x.is_finite()) {
                return Err(self.err_at("point", i, format!("non-finite coordinate {p:?}")));
            }
            pts.push(p);
        }
        self.last_ncomp = 3;
        self.maybe_metadata(toks);
        Ok(Some(pts))
    }

    /// The cells after a `POLYGONS`/`CELLS`/... line of `toks` (`a b`: cells and size, or
    /// offsets and connectivity entries), kept when `keep`.
    fn cells(
        &mut self,
        (a, b): (usize, usize),
        what: &'static str,
        keep: bool,
        toks: &mut Vec<&'a [u8]>,
    ) -> Result<Option<Cells>> {
        if self.peek_kw("OFFSETS") {
            return self.cells_new((a, b), what, keep, toks);
        }
        // Before 5.1: per cell its point count and indices, `b` values in all.
        let (data, kw_pos) = (self.data, self.line_pos);
        let kw_line = || line_of(data, kw_pos);
        if a > b {
            return Err(self.err(format!("{a} cells cannot fit in {b} values")));
        }
        let size = self.room(b as u64, Ty::I32, "the cells")?;
        if !keep {
            self.skip(size, Ty::I32, "the cells")?;
            return Ok(None);
        }
        let mut cells = Cells {
            off: Vec::with_capacity(a + 1),
            conn: Vec::with_capacity(size - a),
        };
        cells.off.push(0);
        let mut used = 0;
        for i in 0..a {
            if used == size {
                return Err(self.err_at(
                    what,
                    i,
                    format!("past the {size} values announced (line {})", kw_line()),
                ));
            }
            let k = self.int(Ty::I32, what)?;
            used += 1;
            if k < 0 || k as u64 > (size - used) as u64 {
                return Err(self.err_at(
                    what,
                    i,
                    format!(
                        "{k} points: a bad count, or more than the {size} values announced (line {})",
                        kw_line()
                    ),
                ));
            }
            for _ in 0..k {
                let v = self.int(Ty::I32, what)?;
                cells.conn.push(self.index(v, what, i)?);
            }
            used += k as usize;
            cells.off.push(cells.conn.len());
        }
        if used != size {
            return Err(Error::line(
                self.file,
                kw_line(),
                format!("{size} values announced, the {a} cells hold {used}"),
            ));
        }
        Ok(Some(cells))
    }

    /// A point index read from the file, as `u32` (its range is checked against the points
    /// once all are read).
    #[inline]
    fn index(&self, v: i64, what: &'static str, i: usize) -> Result<u32> {
        u32::try_from(v).map_err(|_| self.err_at(what, i, format!("point index {v} out of range")))
    }

    /// Cells in VTK 5.1's layout: an `OFFSETS` and a `CONNECTIVITY` array.
    fn cells_new(
        &mut self,
        (noff, nconn): (usize, usize),
        what: &'static str,
        keep: bool,
        toks: &mut Vec<&'a [u8]>,
    ) -> Result<Option<Cells>> {
        let section = |rd: &mut Self, kw: &str, toks: &mut Vec<&'a [u8]>| -> Result<Ty> {
            if !rd.line(toks) || !toks[0].eq_ignore_ascii_case(kw.as_bytes()) {
                return Err(rd.err(format!("expected '{kw} type'")));
            }
            rd.args(toks, 2..=2, &format!("{kw} type"))?;
            rd.int_ty(toks[1], kw)
        };
        let ty = section(self, "OFFSETS", toks)?;
        let (data, kw_pos) = (self.data, self.line_pos);
        let kw_line = || line_of(data, kw_pos);
        let noff = self.room(noff as u64, ty, "OFFSETS")?;
        let off = if keep {
            let mut off = Vec::with_capacity(noff.max(1));
            let mut prev = 0;
            for j in 0..noff {
                let o = self.int(ty, "OFFSETS")?;
                if (j == 0 && o != 0) || o < prev || o as u64 > nconn as u64 {
                    return Err(self.err_at(
                        "offset",
                        j,
                        format!(
                            "{o}: offsets must start at 0 and not decrease up to {nconn} (line {})",
                            kw_line()
                        ),
                    ));
                }
                prev = o;
                off.push(o as usize);
            }
            if off.is_empty() {
                off.push(0);
            }
            Some(off)
        } else {
            self.skip(noff, ty, "OFFSETS")?;
            None
        };
        self.last_ncomp = 1;
        self.maybe_metadata(toks);
        let ty = section(self, "CONNECTIVITY", toks)?;
        let conn_pos = self.line_pos;
        let nconn = self.room(nconn as u64, ty, "CONNECTIVITY")?;
        let Some(off) = off else {
            self.skip(nconn, ty, "CONNECTIVITY")?;
            self.maybe_metadata(toks);
            return Ok(None);
        };
        if off.last() != Some(&nconn) {
            return Err(Error::line(
                self.file,
                kw_line(),
                format!(
                    "the last offset is {}, the connectivity has {nconn} entries",
                    off.last().copied().unwrap_or(0)
                ),
            ));
        }
        let mut conn = Vec::with_capacity(nconn);
        for j in 0..nconn {
            let v = self.int(ty, "CONNECTIVITY")?;
            let u = u32::try_from(v).map_err(|_| {
                let cell = off.partition_point(|&o| o <= j).saturating_sub(1);
                self.err_at(
                    what,
                    cell,
                    format!(
                        "point index {v} out of range (line {})",
                        line_of(data, conn_pos)
                    ),
                )
            })?;
            conn.push(u);
        }
        self.maybe_metadata(toks);
        Ok(Some(Cells { off, conn }))
    }
}

/// Parse the header and every section, keeping what `mode` needs.
fn parse<'a>(data: &'a [u8], file: &'a str, mode: Mode) -> Result<Parsed<'a>> {
    let mut rd = Rd {
        lx: Lexer::new(data, file, None),
        data,
        file,
        binary: false,
        line_pos: 0,
        last_ncomp: 1,
    };
    let first = rd.lx.raw_line().trim_ascii();
    let words: Vec<&[u8]> = first
        .strip_prefix(b"#")
        .unwrap_or(b"")
        .split(|&c| is_ws(c))
        .filter(|w| !w.is_empty())
        .collect();
    let magic = [b"vtk" as &[u8], b"DataFile", b"Version"];
    if words.len() < 4
        || !words
            .iter()
            .zip(magic)
            .all(|(w, m)| w.eq_ignore_ascii_case(m))
    {
        return Err(Error::line(
            file,
            1,
            format!(
                "not a legacy VTK file: expected '# vtk DataFile Version x.y', got '{}'",
                show(first)
            ),
        ));
    }
    if rd.lx.pos >= data.len() {
        return Err(Error::truncated(file, "the file ends after its first line"));
    }
    // The title: anything, even empty.
    rd.lx.raw_line();
    let mut toks: Vec<&[u8]> = Vec::new();
    if !rd.line(&mut toks) {
        return Err(Error::truncated(file, "no ASCII or BINARY line"));
    }
    rd.binary = match toks[0] {
        t if t.eq_ignore_ascii_case(b"ASCII") => false,
        t if t.eq_ignore_ascii_case(b"BINARY") => true,
        t => {
            return Err(rd.err(format!("expected ASCII or BINARY, got '{}'", show(t))));
        }
    };
    rd.args(&toks, 1..=1, "ASCII or BINARY")?;
    if !rd.line(&mut toks) {
        return Err(Error::truncated(file, "no DATASET line"));
    }
    if !toks[0].eq_ignore_ascii_case(b"DATASET") {
        return Err(rd.err(format!(
            "expected 'DATASET POLYDATA' or 'DATASET UNSTRUCTURED_GRID', got '{}'",
            show(toks[0])
        )));
    }
    rd.args(&toks, 2..=2, "DATASET type")?;
    let poly = match toks[1] {
        t if t.eq_ignore_ascii_case(b"POLYDATA") => true,
        t if t.eq_ignore_ascii_case(b"UNSTRUCTURED_GRID") => false,
        t => {
            return Err(rd.err(format!(
                "DATASET {} is not supported: legacy VTK files are read as POLYDATA or \
                 UNSTRUCTURED_GRID",
                show(t)
            )));
        }
    };
    let mut p = Parsed {
        poly,
        ..Parsed::default()
    };
    if poly && mode == Mode::Kind {
        return Ok(p);
    }
    let keep = mode != Mode::Kind;
    // The attribute section: `Some((cell data?, tuples))` after CELL_DATA or POINT_DATA.
    let mut attr: Option<(bool, usize)> = None;
    let mut lut: Vec<&[u8]> = Vec::new();
    while rd.line(&mut toks) {
        let k = toks[0];
        let is = |s: &str| k.eq_ignore_ascii_case(s.as_bytes());
        let kw = show(k);
        if is("POINTS") {
            rd.args(&toks, 3..=3, "POINTS n type")?;
            if p.points.is_some() {
                return Err(rd.err("a second POINTS section"));
            }
            let n = rd.count(toks[1], "point count")?;
            check_point_count(n, file)?;
            let ty = rd.ty(toks[2])?;
            if !ty.is_int() && !ty.is_float() {
                return Err(rd.err(format!(
                    "POINTS of type '{}', expected a number type",
                    show(toks[2])
                )));
            }
            p.points = Some(rd.points(n, ty, keep, &mut toks)?.unwrap_or_default());
        } else if let Some(s) = POLY_SETS
            .iter()
            .position(|(n, _)| is(n))
            .filter(|_| poly)
            .or_else(|| (!poly && is("CELLS")).then_some(0))
        {
            rd.args(&toks, 3..=3, &format!("{kw} n size"))?;
            if p.sets[s].is_some() {
                return Err(rd.err(format!("a second {kw} section")));
            }
            let a = rd.count(toks[1], "cell count")?;
            let b = rd.count(toks[2], "cell data size")?;
            let what = if poly { POLY_SETS[s].1 } else { "cell" };
            p.sets[s] = Some(rd.cells((a, b), what, keep, &mut toks)?.unwrap_or_default());
        } else if !poly && is("CELL_TYPES") {
            rd.args(&toks, 2..=2, "CELL_TYPES n")?;
            if p.types.is_some() {
                return Err(rd.err("a second CELL_TYPES section"));
            }
            let n = rd.count(toks[1], "cell count")?;
            let n = rd.room(n as u64, Ty::I32, "CELL_TYPES")?;
            let mut types = Vec::with_capacity(n);
            for i in 0..n {
                let t = rd.int(Ty::I32, "CELL_TYPES")?;
                types
                    .push(u8::try_from(t).map_err(|_| {
                        rd.err_at("cell", i, format!("{t} is not a VTK cell type"))
                    })?);
            }
            p.types = Some(types);
            rd.last_ncomp = 1;
            rd.maybe_metadata(&mut toks);
            if mode == Mode::Kind {
                return Ok(p);
            }
        } else if is("CELL_DATA") || is("POINT_DATA") {
            rd.args(&toks, 2..=2, &format!("{kw} n"))?;
            attr = Some((is("CELL_DATA"), rd.count(toks[1], "tuple count")?));
        } else if is("FIELD") {
            rd.args(&toks, 3..=3, "FIELD name n")?;
            let n = rd.count(toks[2], "array count")?;
            let cell = attr.is_some_and(|(c, _)| c);
            let mut i = 0;
            while i < n {
                if !rd.line(&mut toks) {
                    return Err(Error::truncated(
                        file,
                        format!("FIELD announces {n} arrays, the file ends after {i}"),
                    ));
                }
                if toks.len() == 1 && toks[0].eq_ignore_ascii_case(b"METADATA") {
                    rd.metadata();
                    continue;
                }
                i += 1;
                if toks.len() == 1 && toks[0] == b"NULL_ARRAY" {
                    continue;
                }
                rd.args(&toks, 4..=4, "name components tuples type")?;
                let name = decode_name(toks[0]);
                let ncomp = rd.count(toks[1], "component count")?;
                let ntuples = rd.count(toks[2], "tuple count")?;
                let ty = rd.ty(toks[3])?;
                let at = rd.line_pos;
                let want = cell && wanted(mode, &name, ncomp, ty);
                let what = format!("FIELD array '{}'", show(&name));
                if let Some(vals) = rd.array((ntuples, ncomp, ty), &what, want, &mut toks)? {
                    p.arrays.push(Arr {
                        name,
                        ncomp,
                        ntuples,
                        ty,
                        vals,
                        at,
                    });
                }
            }
        } else if is("METADATA") {
            rd.metadata();
        } else {
            // The attributes: (name, type, components) from the line.
            let (name, ty, ncomp) = if is("SCALARS") {
                rd.args(&toks, 3..=4, "SCALARS name type [components]")?;
                let ncomp = match toks.get(3) {
                    Some(t) => rd.count(t, "component count")?,
                    None => 1,
                };
                (toks[1], rd.ty(toks[2])?, ncomp)
            } else if is("COLOR_SCALARS") {
                rd.args(&toks, 3..=3, "COLOR_SCALARS name n")?;
                let ty = if rd.binary { Ty::U8 } else { Ty::F32 };
                (toks[1], ty, rd.count(toks[2], "component count")?)
            } else if is("LOOKUP_TABLE") {
                rd.args(&toks, 3..=3, "LOOKUP_TABLE name size")?;
                let n = rd.count(toks[2], "table size")?;
                let ty = if rd.binary { Ty::U8 } else { Ty::F32 };
                rd.array((n, 4, ty), "LOOKUP_TABLE", false, &mut toks)?;
                continue;
            } else if let Some(ncomp) = [
                ("VECTORS", 3),
                ("NORMALS", 3),
                ("TANGENTS", 3),
                ("TENSORS", 9),
                ("TENSORS6", 6),
                ("GLOBAL_IDS", 1),
                ("PEDIGREE_IDS", 1),
                ("EDGE_FLAGS", 1),
                ("RATIONAL_WEIGHTS", 1),
                ("HIGHERORDERDEGREES", 3),
            ]
            .iter()
            .find(|(n, _)| is(n))
            .map(|&(_, c)| c)
            {
                rd.args(&toks, 3..=3, &format!("{kw} name type"))?;
                (toks[1], rd.ty(toks[2])?, ncomp)
            } else if is("TEXTURE_COORDINATES") {
                rd.args(&toks, 4..=4, "TEXTURE_COORDINATES name dim type")?;
                (toks[1], rd.ty(toks[3])?, rd.count(toks[2], "dimension")?)
            } else {
                return Err(rd.err(format!(
                    "unknown keyword '{kw}' in a {} dataset",
                    if poly {
                        "POLYDATA"
                    } else {
                        "UNSTRUCTURED_GRID"
                    }
                )));
            };
            let Some((cell, n)) = attr else {
                return Err(rd.err(format!("{kw} before CELL_DATA or POINT_DATA")));
            };
            let at = rd.line_pos;
            let kw_is_scalars = is("SCALARS");
            let name = decode_name(name);
            // SCALARS are followed by a LOOKUP_TABLE line (VTK requires it; it may be absent).
            if kw_is_scalars && rd.peek_kw("LOOKUP_TABLE") {
                rd.line(&mut lut);
            }
            let want = cell && kw_is_scalars && wanted(mode, &name, ncomp, ty);
            let what = format!("{kw} '{}'", show(&name));
            if let Some(vals) = rd.array((n, ncomp, ty), &what, want, &mut toks)? {
                p.arrays.push(Arr {
                    name,
                    ncomp,
                    ntuples: n,
                    ty,
                    vals,
                    at,
                });
            }
        }
    }
    if !poly {
        let n = p.sets[0].as_ref().map_or(0, Cells::len);
        let nt = p.types.as_ref().map_or(0, Vec::len);
        if n != nt && keep {
            return Err(Error::format(
                file,
                format!("{n} cells (CELLS) but {nt} cell types (CELL_TYPES)"),
            ));
        }
    }
    if keep && p.points.is_none() {
        return Err(Error::format(file, "no POINTS section"));
    }
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube's corners.
    const CUBE_POINTS: [[f64; 3]; 8] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];

    /// The cube's faces, outward: the bottom as one quad, the other five as two triangles each.
    const CUBE_FACES: [&[u32]; 11] = [
        &[0, 3, 2, 1],
        &[4, 5, 6],
        &[4, 6, 7],
        &[0, 1, 5],
        &[0, 5, 4],
        &[3, 7, 6],
        &[3, 6, 2],
        &[0, 4, 7],
        &[0, 7, 3],
        &[1, 2, 6],
        &[1, 6, 5],
    ];

    fn points_text() -> String {
        CUBE_POINTS
            .iter()
            .map(|p| format!("{} {} {}\n", p[0], p[1], p[2]))
            .collect()
    }

    /// The cube as an old-format (3.0) ASCII POLYDATA file.
    fn cube_legacy_ascii() -> String {
        let size: usize = CUBE_FACES.iter().map(|f| f.len() + 1).sum();
        let mut s = format!(
            "# vtk DataFile Version 3.0\ncube\nASCII\nDATASET POLYDATA\nPOINTS 8 float\n{}\
             POLYGONS {} {size}\n",
            points_text(),
            CUBE_FACES.len()
        );
        for f in CUBE_FACES {
            s += &format!("{} ", f.len());
            s += &f
                .iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(" ");
            s += "\n";
        }
        s
    }

    /// Offsets (with the leading 0) and connectivity of some cells.
    fn offsets_conn(cells: &[&[u32]]) -> (Vec<i64>, Vec<i64>) {
        let mut off = vec![0];
        let mut conn = Vec::new();
        for c in cells {
            conn.extend(c.iter().map(|&v| v as i64));
            off.push(conn.len() as i64);
        }
        (off, conn)
    }

    fn join<T: ToString>(v: &[T]) -> String {
        v.iter().map(T::to_string).collect::<Vec<_>>().join(" ")
    }

    /// The cube as a 5.1 ASCII POLYDATA file (OFFSETS / CONNECTIVITY).
    fn cube_51_ascii() -> String {
        let (off, conn) = offsets_conn(&CUBE_FACES);
        format!(
            "# vtk DataFile Version 5.1\nvtk output\nASCII\nDATASET POLYDATA\nPOINTS 8 double\n{}\n\
             POLYGONS {} {}\nOFFSETS vtktypeint64\n{}\nCONNECTIVITY vtktypeint64\n{}\n",
            points_text(),
            off.len(),
            conn.len(),
            join(&off),
            join(&conn)
        )
    }

    /// The signed volume enclosed by triangles (positive for an outward closed surface).
    fn volume(points: &[[f64; 3]], tris: &[[u32; 3]]) -> f64 {
        tris.iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| points[v as usize]);
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum()
    }

    /// The cube's triangles as the reader should make them (the quad fan-split from corner 0).
    fn cube_triangles() -> Vec<[u32; 3]> {
        let mut t = vec![[0, 3, 2], [0, 2, 1]];
        t.extend(CUBE_FACES[1..].iter().map(|f| [f[0], f[1], f[2]]));
        t
    }

    fn check_cube(r: &SurfaceRead) {
        assert_eq!(r.mesh.points, CUBE_POINTS.to_vec());
        assert_eq!(r.mesh.triangles, cube_triangles());
        assert_eq!(r.polygons_split, 1);
        assert_eq!(r.mesh.sides, vec![[1, 0]; 12]);
        assert_eq!(r.side_labels, None);
        assert!((volume(&r.mesh.points, &r.mesh.triangles) - 1.0).abs() < 1e-12);
    }

    /// Big-endian binary file content, built piece by piece.
    #[derive(Default)]
    struct Bin(Vec<u8>);

    impl Bin {
        fn s(mut self, t: &str) -> Self {
            self.0.extend_from_slice(t.as_bytes());
            self
        }
        fn b(mut self, b: &[u8]) -> Self {
            self.0.extend_from_slice(b);
            self
        }
        fn f32s(mut self, v: &[f64]) -> Self {
            v.iter()
                .for_each(|&x| self.0.extend((x as f32).to_be_bytes()));
            self
        }
        fn f64s(mut self, v: &[f64]) -> Self {
            v.iter().for_each(|&x| self.0.extend(x.to_be_bytes()));
            self
        }
        fn i32s(mut self, v: &[i64]) -> Self {
            v.iter()
                .for_each(|&x| self.0.extend((x as i32).to_be_bytes()));
            self
        }
        fn i64s(mut self, v: &[i64]) -> Self {
            v.iter().for_each(|&x| self.0.extend(x.to_be_bytes()));
            self
        }
    }

    fn cube_flat() -> Vec<f64> {
        CUBE_POINTS.as_flattened().to_vec()
    }

    /// The cube as an old-format binary file, with binary point data holding newline and space
    /// bytes before CELL_DATA.
    fn cube_legacy_binary() -> Vec<u8> {
        let mut cells = Vec::new();
        for f in CUBE_FACES {
            cells.push(f.len() as i64);
            cells.extend(f.iter().map(|&v| v as i64));
        }
        Bin::default()
            .s("# vtk DataFile Version 3.0\ncube\nBINARY\nDATASET POLYDATA\nPOINTS 8 float\n")
            .f32s(&cube_flat())
            .s(&format!("\nPOLYGONS 11 {}\n", cells.len()))
            .i32s(&cells)
            .s("\nPOINT_DATA 8\nSCALARS ws int 1\nLOOKUP_TABLE default\n")
            .i32s(&[10, 32, 13, 9, 0x0a0a_0a0a, 0x2020_2020, 12, 11])
            .s("\nCELL_DATA 11\nSCALARS sides int 2\nLOOKUP_TABLE default\n")
            .i32s(
                &(0..22)
                    .map(|i| if i % 2 == 0 { 1 } else { 0 })
                    .collect::<Vec<_>>(),
            )
            .s("\n")
            .0
    }

    /// The cube as a 5.1 binary file.
    fn cube_51_binary() -> Vec<u8> {
        let (off, conn) = offsets_conn(&CUBE_FACES);
        Bin::default()
            .s("# vtk DataFile Version 5.1\nvtk output\nBINARY\nDATASET POLYDATA\nPOINTS 8 double\n")
            .f64s(&cube_flat())
            .s(&format!(
                "\nPOLYGONS {} {}\nOFFSETS vtktypeint64\n",
                off.len(),
                conn.len()
            ))
            .i64s(&off)
            .s("\nCONNECTIVITY vtktypeint64\n")
            .i64s(&conn)
            .s("\n")
            .0
    }

    #[test]
    fn ascii_legacy_polydata_cube() {
        let r = parse_surface(cube_legacy_ascii().as_bytes(), "c.vtk").unwrap();
        check_cube(&r);
        // The stream entry point reads the same.
        let s = read_surface(std::io::Cursor::new(cube_legacy_ascii()), "c.vtk").unwrap();
        assert_eq!(s, r);
    }

    #[test]
    fn ascii_51_offsets_connectivity() {
        check_cube(&parse_surface(cube_51_ascii().as_bytes(), "c.vtk").unwrap());
    }

    #[test]
    fn binary_legacy_and_51() {
        let r = parse_surface(&cube_legacy_binary(), "c.vtk").unwrap();
        assert_eq!(r.mesh.triangles, cube_triangles());
        assert_eq!(r.mesh.points, CUBE_POINTS.to_vec());
        // The `sides` array after the binary point data: read, [1, 0] for every cell.
        assert_eq!(r.side_labels, Some(vec![[1, 0]; 12]));
        check_cube(&parse_surface(&cube_51_binary(), "c.vtk").unwrap());
        // A line number after binary data counts its newline bytes, as an editor would.
        let mut f = cube_legacy_binary();
        let line = 1 + f.iter().filter(|&&c| c == b'\n').count();
        // 16 newlines in the text, 5 newline bytes in the point data.
        assert_eq!(line, 1 + 16 + 5);
        f.extend_from_slice(b"BOGUS 1\n");
        let e = parse_surface(&f, "c.vtk").unwrap_err().to_string();
        assert!(
            e.contains(&format!("line {line}: unknown keyword 'BOGUS'")),
            "{e}"
        );
        // Non-integer coordinates survive binary floats exactly.
        let pts = [0.1, -2.5e-7, 3.25, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let f = Bin::default()
            .s("# vtk DataFile Version 4.2\nt\nBINARY\nDATASET POLYDATA\nPOINTS 3 double\n")
            .f64s(&pts)
            .s("\nPOLYGONS 1 4\n")
            .i32s(&[3, 0, 1, 2])
            .0;
        let r = parse_surface(&f, "t.vtk").unwrap();
        assert_eq!(r.mesh.points.as_flattened(), pts);
        assert_eq!(r.mesh.triangles, vec![[0, 1, 2]]);
    }

    /// The normal direction (z component of the cross product) of a triangle in the plane.
    fn normal_z(p: &[[f64; 3]], t: [u32; 3]) -> f64 {
        let [a, b, c] = t.map(|v| p[v as usize]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    }

    #[test]
    fn triangle_strips_keep_their_orientation() {
        let pts = "0 0 0 0 1 0 1 0 0 1 1 0 2 0 0";
        let want = vec![[0, 1, 2], [2, 1, 3], [2, 3, 4]];
        let poly = format!(
            "# vtk DataFile Version 3.0\ns\nASCII\nDATASET POLYDATA\nPOINTS 5 float\n{pts}\n\
             TRIANGLE_STRIPS 1 6\n5 0 1 2 3 4\n"
        );
        let grid = format!(
            "# vtk DataFile Version 3.0\ns\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 float\n\
             {pts}\nCELLS 1 6\n5 0 1 2 3 4\nCELL_TYPES 1\n6\n"
        );
        for f in [poly, grid] {
            let r = parse_surface(f.as_bytes(), "s.vtk").unwrap();
            assert_eq!(r.mesh.triangles, want);
            assert_eq!(r.polygons_split, 0);
            for &t in &r.mesh.triangles {
                assert_eq!(normal_z(&r.mesh.points, t), -1.0, "{t:?}");
            }
        }
    }

    #[test]
    fn polydata_cell_data_counts_vertices_and_lines_first() {
        // Strips come before polygons in the file, but cell data runs over vertices, lines,
        // polygons, then strips.
        let f = "# vtk DataFile Version 3.0\nl\nASCII\nDATASET POLYDATA\n\
            POINTS 6 float\n0 0 0 1 0 0 1 1 0 0 1 0 2 0 0 2 1 0\n\
            VERTICES 2 4\n1 0\n1 5\n\
            LINES 1 3\n2 0 1\n\
            TRIANGLE_STRIPS 1 5\n4 1 4 2 5\n\
            POLYGONS 2 9\n3 0 1 2\n4 0 1 2 3\n\
            CELL_DATA 6\nFIELD FieldData 2\n\
            other 2 6 int\n9 9 9 9 9 9 9 9 9 9 9 9\n\
            sides 2 6 int\n100 101 102 103 104 105 1 2 3 4 5 6\n";
        let r = parse_surface(f.as_bytes(), "l.vtk").unwrap();
        assert_eq!(
            r.mesh.triangles,
            vec![[0, 1, 2], [0, 1, 2], [0, 2, 3], [1, 4, 2], [2, 4, 5]]
        );
        assert_eq!(
            r.side_labels,
            Some(vec![[1, 2], [3, 4], [3, 4], [5, 6], [5, 6]])
        );
        // The mesh keeps the default sides; the labels travel beside it, as in vtu.rs.
        assert_eq!(r.mesh.sides, vec![[1, 0]; 5]);
        assert_eq!(r.polygons_split, 1);
        // The scalar pair form.
        let f = f.replace(
            "FIELD FieldData 2\nother 2 6 int\n9 9 9 9 9 9 9 9 9 9 9 9\nsides 2 6 int\n100 101 102 103 104 105 1 2 3 4 5 6\n",
            "SCALARS label_front int\nLOOKUP_TABLE default\n0 0 0 2 4 6\n\
             SCALARS label_back short 1\nLOOKUP_TABLE default\n0 0 0 1 3 5\n",
        );
        assert!(f.contains("label_front"));
        let r = parse_surface(f.as_bytes(), "l.vtk").unwrap();
        assert_eq!(
            r.side_labels,
            Some(vec![[1, 2], [3, 4], [3, 4], [5, 6], [5, 6]])
        );
    }

    #[test]
    fn point_data_field_data_and_metadata_are_skipped() {
        let (off, conn) = offsets_conn(&CUBE_FACES);
        let f = format!(
            "# vtk DataFile Version 5.1\r\nvtk output\r\nASCII\r\nDATASET POLYDATA\r\n\
             FIELD FieldData 2\ninfo 1 2 double\n1.5 2.5\nnames 1 3 string\na%20b\n\nc\n\
             POINTS 8 float\n{}METADATA\nINFORMATION 1\nNAME L2_NORM_RANGE LOCATION vtkDataArray\n\
             DATA 2 0 1.73205 \n\n\
             POLYGONS {} {}\nOFFSETS vtktypeint64\n{}\nCONNECTIVITY vtktypeint64\n{}\n\
             POINT_DATA 8\nSCALARS v double 3\nLOOKUP_TABLE default\n{}\n\
             METADATA\nCOMPONENT_NAMES\nX\n\n\nINFORMATION 1\nNAME L2_NORM_RANGE LOCATION vtkDataArray\n\
             DATA 2 0.4 1.5 \n\n\
             NORMALS n float\n{}\nVECTORS vv int\n{}\nTEXTURE_COORDINATES tc 2 float\n{}\n\
             TENSORS t double\n{}\nCOLOR_SCALARS c 4\n{}\nLOOKUP_TABLE lut 2\n0 0 0 1 1 1 1 1\n\
             FIELD FieldData 2\nregion 1 8 int\n{}\nNULL_ARRAY\n\
             CELL_DATA 11\n\nfield fielddata 1\nBoundary%4cabels 2 11 int\n{}\n\
             METADATA\nINFORMATION 0\n\n\
             POINT_DATA 8\nscalars late int\nlookup_table default\n{}\n",
            points_text(),
            off.len(),
            conn.len(),
            join(&off),
            join(&conn),
            join(&[0.5; 24]),
            join(&[0.0; 24]),
            join(&[7; 24]),
            join(&[0.25; 16]),
            join(&[1.0; 72]),
            join(&[0.5; 32]),
            join(&[-3; 8]),
            join(&(0..22).map(|i| [2, 7][i % 2]).collect::<Vec<_>>()),
            join(&[1; 8]),
        );
        let r = parse_surface(f.as_bytes(), "m.vtk").unwrap();
        assert_eq!(r.mesh.points, CUBE_POINTS.to_vec());
        assert_eq!(r.mesh.triangles, cube_triangles());
        // `BoundaryLabels`, its name %-escaped, is found after the point data.
        assert_eq!(r.side_labels, Some(vec![[2, 7]; 12]));
        // The point array named `region` is not taken for cells (and a tet read refuses
        // POLYDATA anyway).
        let e = parse_tet(f.as_bytes(), "m.vtk").unwrap_err().to_string();
        assert!(e.contains("POLYDATA"), "{e}");
    }

    /// Five points: tets 0-1-2-3 and 1-2-3-4 are positive, on either side of the face 1-2-3.
    const TET_POINTS: &str = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n";

    fn tet_grid(types: &str, cells: &str, ncells: usize, size: usize, data: &str) -> String {
        format!(
            "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n\
             {TET_POINTS}CELLS {ncells} {size}\n{cells}CELL_TYPES {ncells}\n{types}\n{data}"
        )
    }

    #[test]
    fn unstructured_tets_with_region_labels() {
        let f = tet_grid(
            "10 10 12 5 1",
            "4 0 1 2 3\n4 1 2 3 4\n8 0 1 2 3 4 0 1 2\n3 0 1 2\n1 4\n",
            5,
            25,
            "CELL_DATA 5\nFIELD FieldData 1\ngmsh:physical 1 5 int\n8 8 8 8 8\n\
             SCALARS region int 1\nLOOKUP_TABLE default\n3 4 9 9 9\n",
        );
        let r = parse_tet(f.as_bytes(), "t.vtk").unwrap();
        assert_eq!(r.mesh.tets, vec![[0, 1, 2, 3], [1, 2, 3, 4]]);
        // `region` is preferred to `gmsh:physical`, though it comes later.
        assert_eq!(r.mesh.labels, vec![3, 4]);
        assert_eq!(r.skipped_elements, 1);
        assert_eq!((r.flipped, r.degenerate), (0, 0));
        assert_eq!(r.mesh.points[4], [1.0, 1.0, 1.0]);
        // The two tets share the face 1-2-3.
        assert_eq!(r.mesh.neighbors[0].iter().filter(|&&n| n == 1).count(), 1);
        let s = read_tet(std::io::Cursor::new(f), "t.vtk").unwrap();
        assert_eq!(s, r);
    }

    #[test]
    fn field_data_labels_and_fallbacks() {
        let cells = "4 0 1 2 3\n4 1 2 3 4\n";
        let grid = |data: &str| tet_grid("10 10", cells, 2, 10, data);
        let labels = |data: &str| parse_tet(grid(data).as_bytes(), "t.vtk").map(|r| r.mesh.labels);
        // A named FIELD array, after an unnamed integer one.
        let d = "CELL_DATA 2\nFIELD FieldData 3\nq 1 2 double\n0.5 0.25\n\
                 gmsh:geometrical 1 2 int\n5 6\ngmsh:physical 1 2 int\n7 8\n";
        assert_eq!(labels(d).unwrap(), vec![7, 8]);
        // No named array: the first single-component integer one.
        let d = "CELL_DATA 2\nFIELD FieldData 3\nq 1 2 double\n0.5 0.25\n\
                 pair 2 2 int\n1 2 3 4\nids 1 2 vtkIdType\n11 12\n";
        assert_eq!(labels(d).unwrap(), vec![11, 12]);
        // A float array by a label name: whole numbers accepted, others refused.
        let d = "CELL_DATA 2\nSCALARS MaterialIds double\nLOOKUP_TABLE default\n2 3\n";
        assert_eq!(labels(d).unwrap(), vec![2, 3]);
        let d = "CELL_DATA 2\nSCALARS MaterialIds double\nLOOKUP_TABLE default\n2 3.5\n";
        let e = labels(d).unwrap_err().to_string();
        assert!(e.contains("cell 1") && e.contains("MaterialIds"), "{e}");
        // No cell data: label 1.
        assert_eq!(labels("").unwrap(), vec![1, 1]);
        // Negative labels are refused, naming the cell and the array.
        let d = "CELL_DATA 2\nSCALARS region int\nLOOKUP_TABLE default\n1 -4\n";
        let e = labels(d).unwrap_err().to_string();
        assert!(
            e.contains("cell 1") && e.contains("region") && e.contains("-4"),
            "{e}"
        );
        // An array of the wrong length.
        let d = "CELL_DATA 3\nSCALARS region int\nLOOKUP_TABLE default\n1 2 3\n";
        let e = labels(d).unwrap_err().to_string();
        assert!(e.contains("3 tuples for 2 cells"), "{e}");
    }

    #[test]
    fn negatively_oriented_tets_are_flipped() {
        let f = tet_grid("10 10", "4 0 2 1 3\n4 1 3 2 4\n", 2, 10, "");
        let r = parse_tet(f.as_bytes(), "t.vtk").unwrap();
        assert_eq!(r.flipped, 2);
        assert_eq!(r.mesh.tets, vec![[0, 2, 3, 1], [1, 3, 4, 2]]);
        for t in 0..2 {
            let [a, b, c, d] = r.mesh.corners(t);
            let sign = biotet::geom::predicates::orient3d(a, b, c, d);
            assert_eq!(sign, biotet::geom::predicates::Sign::Positive);
        }
    }

    #[test]
    fn binary_unstructured_grid_51() {
        let (off, conn) = offsets_conn(&[&[0, 1, 2, 3], &[1, 2, 3, 4], &[0, 1, 2]]);
        let f = Bin::default()
            .s("# vtk DataFile Version 5.1\nvtk output\nBINARY\nDATASET UNSTRUCTURED_GRID\n")
            .s("POINTS 5 float\n")
            .f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 1., 1., 1.])
            .s("\nMETADATA\nINFORMATION 0\n\n")
            .s("CELLS 4 11\nOFFSETS vtktypeint64\n")
            .i64s(&off)
            .s("\nCONNECTIVITY vtktypeint64\n")
            .i64s(&conn)
            .s("\nCELL_TYPES 3\n")
            .i32s(&[10, 10, 5])
            .s("\nCELL_DATA 3\nFIELD FieldData 2\nnames 1 3 string\n")
            // Strings: "a b", "", "yz" with 6- and 14-bit length headers.
            .b(b"\xc3a b\xc0\x80\x02yz")
            .s("\nregion 1 3 int\n")
            .i32s(&[10, 32, 0])
            .s("\n")
            .0;
        let r = parse_tet(&f, "b.vtk").unwrap();
        assert_eq!(r.mesh.tets, vec![[0, 1, 2, 3], [1, 2, 3, 4]]);
        assert_eq!((r.flipped, r.degenerate), (0, 0));
        assert_eq!(r.mesh.labels, vec![10, 32]);
        assert_eq!(peek_kind(&f, "b.vtk").unwrap(), MeshKind::Tetrahedra);
    }

    #[test]
    fn surfaces_from_an_unstructured_grid() {
        let f = "# vtk DataFile Version 2.0\ng\nASCII\nDATASET UNSTRUCTURED_GRID\n\
            POINTS 6 float\n0 0 0 1 0 0 1 1 0 0 1 0 2 0 0 2 1 0\n\
            CELLS 6 25\n3 0 1 2\n4 0 1 2 3\n4 1 4 2 5\n5 0 1 4 5 3\n1 0\n2 0 1\n\
            CELL_TYPES 6\n5 9 8 7 1 3\n";
        let r = parse_surface(f.as_bytes(), "g.vtk").unwrap();
        assert_eq!(
            r.mesh.triangles,
            vec![
                [0, 1, 2],
                [0, 1, 2],
                [0, 2, 3],
                // The pixel 1 4 2 5 is the cycle 1 4 5 2.
                [1, 4, 5],
                [1, 5, 2],
                [0, 1, 4],
                [0, 4, 5],
                [0, 5, 3],
            ]
        );
        assert_eq!(r.polygons_split, 3);
        let e = parse_surface(
            tet_grid("5 10", "3 0 1 2\n4 0 1 2 3\n", 2, 9, "").as_bytes(),
            "g.vtk",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("cell 1") && e.contains("VTK type 10") && e.contains("expected a surface"),
            "{e}"
        );
    }

    #[test]
    fn peek_kind_on_both_kinds() {
        assert_eq!(
            peek_kind(cube_legacy_ascii().as_bytes(), "c.vtk").unwrap(),
            MeshKind::Surface
        );
        assert_eq!(
            peek_kind(&cube_51_binary(), "c.vtk").unwrap(),
            MeshKind::Surface
        );
        let g = |types: &str| tet_grid(types, "3 0 1 2\n4 0 1 2 3\n", 2, 9, "");
        let kind = |types: &str| peek_kind(g(types).as_bytes(), "g.vtk").unwrap();
        assert_eq!(kind("5 10"), MeshKind::Tetrahedra);
        assert_eq!(kind("5 9"), MeshKind::Surface);
        // A hexahedron is a volume too.
        assert_eq!(kind("5 12"), MeshKind::Tetrahedra);
        assert!(peek_kind(b"# vtk DataFile Version 3.0\n", "x.vtk").is_err());
    }

    #[test]
    fn keywords_any_case_crlf_and_blank_lines() {
        let f = cube_legacy_ascii()
            .replace("POINTS", "points")
            .replace("POLYGONS", "\n\n  Polygons\t")
            .replace("ASCII", "ascii")
            .replace("DATASET POLYDATA", "dataset   polydata  ")
            .replace('\n', "\r\n");
        check_cube(&parse_surface(f.as_bytes(), "c.vtk").unwrap());
    }

    /// Parse as both kinds; both must fail, and the messages must name the file and say
    /// `why`.
    fn refused(data: &[u8], why: &str) {
        let s = parse_surface(data, "bad.vtk").map(|_| ()).unwrap_err();
        assert!(s.to_string().contains(why), "{s} lacks {why:?}");
        tet_refused(data, why);
    }

    /// A tet read must fail, the message naming the file and saying `why`.
    fn tet_refused(data: &[u8], why: &str) {
        let e = parse_tet(data, "bad.vtk")
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("bad.vtk: ") && e.contains(why),
            "{e:?} lacks {why:?}"
        );
    }

    #[test]
    fn hostile_inputs_are_refused() {
        let grid = |body: &str| {
            format!("# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n{body}")
        };
        let pts = "POINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\n";
        refused(b"", "line 1: not a legacy VTK file");
        refused(b"ply\nformat ascii 1.0\n", "line 1: not a legacy VTK file");
        refused(
            b"<?xml version=\"1.0\"?>\n<VTKFile>",
            "not a legacy VTK file",
        );
        refused(b"# vtk DataFile Version 3.0\n", "truncated");
        refused(
            b"# vtk DataFile Version 3.0\nt\nTEXT\nDATASET POLYDATA\n",
            "line 3: expected ASCII or BINARY",
        );
        refused(
            b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n",
            "line 4: DATASET STRUCTURED_POINTS is not supported",
        );
        refused(
            b"# vtk DataFile Version 3.0\nt\nASCII\nPOINTS 1 float\n0 0 0\n",
            "expected 'DATASET POLYDATA'",
        );
        // Absurd counts fail at once, in text and binary.
        refused(
            grid("POINTS 1000000000000 float\n0 0 0\n").as_bytes(),
            "do not fit 32-bit",
        );
        refused(
            grid("POINTS 4000000000 float\n0 0 0\n").as_bytes(),
            "truncated",
        );
        refused(
            grid(&format!(
                "{pts}CELLS 1000000000000000 1000000000000000\n4 0 1 2 3\n"
            ))
            .as_bytes(),
            "truncated",
        );
        refused(
            grid(&format!(
                "{pts}CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\nCELL_DATA 1\n\
                 FIELD f 1\nx 4294967296 4294967296 int\n1\n"
            ))
            .as_bytes(),
            "too many",
        );
        refused(
            grid(&format!("{pts}CELLS 2 2 5\n4 0 1 2 3\n")).as_bytes(),
            "expected 'CELLS n size'",
        );
        // Indices and coordinates.
        tet_refused(
            grid(&format!("{pts}CELLS 1 5\n4 0 1 2 4\nCELL_TYPES 1\n10\n")).as_bytes(),
            "cell 0: point index 4 out of range (4 points)",
        );
        tet_refused(
            grid(&format!("{pts}CELLS 1 5\n4 0 1 -2 3\nCELL_TYPES 1\n10\n")).as_bytes(),
            "cell 0: point index -2 out of range",
        );
        refused(
            grid("POINTS 2 float\n0 0 0\n1 nan 0\n").as_bytes(),
            "line 7: point 1: non-finite coordinate",
        );
        refused(
            grid("POINTS 2 float\n0 0 0\n1 x 0\n").as_bytes(),
            "line 7: expected a number in POINTS, got 'x'",
        );
        tet_refused(
            grid(&format!("{pts}CELLS 1 5\n5 0 1 2 3\nCELL_TYPES 1\n10\n")).as_bytes(),
            "cell 0: 5 points",
        );
        refused(
            grid(&format!("{pts}CELLS 1 6\n4 0 1 2 3\n7\nCELL_TYPES 1\n10\n")).as_bytes(),
            "line 7: 6 values announced, the 1 cells hold 5",
        );
        refused(
            grid(&format!("{pts}CELLS 1 5\n4 0 1 2.5 3\nCELL_TYPES 1\n10\n")).as_bytes(),
            "line 8: expected an integer in cell, got '2.5'",
        );
        tet_refused(
            grid(&format!(
                "{pts}CELLS 2 10\n4 0 1 2 3\n4 0 1 2 3\nCELL_TYPES 1\n10\n"
            ))
            .as_bytes(),
            "2 cells (CELLS) but 1 cell types",
        );
        refused(
            grid(&format!(
                "{pts}CELLS 3 4\nOFFSETS int\n0 4 2\nCONNECTIVITY int\n0 1 2 3\n"
            ))
            .as_bytes(),
            "offset 2: 2: offsets must start at 0 and not decrease",
        );
        refused(
            grid(&format!(
                "{pts}CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\nCELL_DATA 1\nSCALARS r int\n"
            ))
            .as_bytes(),
            "truncated",
        );
        refused(
            grid(&format!(
                "{pts}CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\nWHATEVER 1\n"
            ))
            .as_bytes(),
            "line 11: unknown keyword 'WHATEVER'",
        );
        refused(
            grid(&format!("{pts}CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n300\n")).as_bytes(),
            "300 is not a VTK cell type",
        );
        refused(grid("").as_bytes(), "no POINTS section");
        // Binary: truncated points, a NaN, an index out of range.
        let bin = |b: Bin| {
            Bin::default()
                .s("# vtk DataFile Version 3.0\nt\nBINARY\nDATASET POLYDATA\nPOINTS 3 float\n")
                .0
                .into_iter()
                .chain(b.0)
                .collect::<Vec<u8>>()
        };
        refused(&bin(Bin::default().f32s(&[0.0; 8])), "truncated");
        refused(
            &bin(Bin::default()
                .f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, f64::NAN, 0.0])
                .s("\nPOLYGONS 1 4\n")
                .i32s(&[3, 0, 1, 2])),
            "point 2: non-finite coordinate",
        );
        let one_tri = |idx: i64| {
            bin(Bin::default()
                .f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0])
                .s("\nPOLYGONS 1 4\n")
                .i32s(&[3, 0, idx, 2]))
        };
        assert!(parse_surface(&one_tri(1), "ok.vtk").is_ok());
        let e = parse_surface(&one_tri(7), "bad.vtk")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("polygon 0: point index 7 out of range (3 points)"),
            "{e}"
        );
        let e = parse_surface(&one_tri(1)[..90], "bad.vtk")
            .unwrap_err()
            .to_string();
        assert!(e.contains("truncated"), "{e}");
        // Counts that the data cannot bound: a huge string length, a huge component count of
        // an empty array followed by its component names.
        let f = Bin(cube_51_binary())
            .s("CELL_DATA 11\nFIELD FieldData 1\nnames 1 1 string\n")
            .b(b"\x3f\xff\xff\xff\xff\xff\xff\xffabc\n")
            .0;
        let e = parse_surface(&f, "bad.vtk").unwrap_err().to_string();
        assert!(
            e.contains("truncated file: the file ends inside FIELD array 'names'"),
            "{e}"
        );
        let f = cube_51_ascii()
            + "CELL_DATA 0\nSCALARS x int 1000000000000000000\nLOOKUP_TABLE default\n\
               METADATA\nCOMPONENT_NAMES\na\n";
        check_cube(&parse_surface(f.as_bytes(), "c.vtk").unwrap());
        // Kinds: a surface for a tet read, a two-corner polygon.
        let e = parse_tet(cube_legacy_ascii().as_bytes(), "c.vtk").unwrap_err();
        assert!(
            e.to_string()
                .contains("a surface (POLYDATA), expected a tet mesh")
        );
        let f = cube_legacy_ascii().replace("POLYGONS 11 45\n4 0 3 2 1", "POLYGONS 11 43\n2 0 3");
        assert!(f.contains("43\n2 0 3\n"));
        let e = parse_surface(f.as_bytes(), "c.vtk")
            .unwrap_err()
            .to_string();
        assert!(e.contains("polygon 0: a polygon with 2 corners"), "{e}");
    }

    #[test]
    fn every_truncation_and_byte_flip_is_handled() {
        for f in [
            cube_legacy_binary(),
            cube_51_binary(),
            cube_51_ascii().into_bytes(),
        ] {
            for n in 0..f.len() {
                let _ = parse_surface(&f[..n], "t.vtk");
                let _ = peek_kind(&f[..n], "t.vtk");
            }
            let mut x = 0x2545_f491_4f6c_dd1du64;
            for _ in 0..3000 {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let mut g = f.clone();
                let i = (x % g.len() as u64) as usize;
                g[i] = (x >> 32) as u8;
                let _ = parse_surface(&g, "t.vtk");
                let _ = parse_tet(&g, "t.vtk");
            }
        }
        // Cut anywhere from inside the points to the last value, a binary file is an error (a cut
        // before the cells would leave a valid file of points).
        let f = cube_51_binary();
        let (start, end) = (100, f.len() - 1);
        let polygons = f.windows(8).position(|w| w == b"POLYGONS").unwrap();
        for n in (start..270).chain(polygons + 1..end) {
            assert!(parse_surface(&f[..n], "t.vtk").is_err(), "{n} bytes");
        }
    }
}
