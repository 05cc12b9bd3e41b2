//! VTK XML unstructured grid (`.vtu`): tet meshes, and surfaces with side labels.
//!
//! Surfaces ([`parse_surface`], [`write_surface`]): triangle, quad and polygon cells (quads and
//! polygons fan-split), with the region labels on both sides of each as the two-component
//! cell-data array `sides` (`[back, front]`: behind and in front of the right-hand normal of the
//! corner order, 0 = the outside; `BoundaryLabels`, as VTK's SurfaceNets filters write, and
//! `boundary_labels`, as PyVista writes, are read the same way) or two scalar arrays
//! `label_back` and `label_front`. [`peek_kind`] tells the two kinds apart.
//!
//! Writing: by default ([`VtuEncoding::Raw`]) all arrays go, uncompressed, into one
//! `<AppendedData encoding="raw">` block with `UInt64` byte-count headers — the fastest to write
//! and read, and what ParaView itself writes with compression off. Also available: zlib-compressed
//! appended data, inline base64 (optionally compressed) and ASCII. Points are `Float64` (exact),
//! connectivity and offsets `Int32` (`Int64` when needed), cell types `UInt8` (10 = tetra).
//! Cell data: `region` (`Int32`, the label; marked as the active scalars), and per tet, from
//! [`TetMeasures`]: `min_dihedral_deg`, `min_solid_angle_sr` and `q` (`Float64`).
//!
//! Reading: `UnstructuredGrid` files with any number of pieces; data arrays in `ascii`, inline
//! `binary` (base64) or `appended` (`raw` or `base64`) format, optionally compressed with
//! `vtkZLibDataCompressor`, `UInt32` or `UInt64` headers, either byte order, any numeric type.
//! Only linear tetrahedra (cell type 10) are read; other volume cells (hexahedra, wedges,
//! pyramids, voxels, quadratic or higher-order cells, polyhedra) are counted in
//! [`TetRead::skipped_elements`], and vertices, lines and surface cells are ignored silently.
//! The label comes from the first cell-data array named `region`, `gmsh:physical`,
//! `medit:ref`, `CellEntityIds`, `tetgen:ref`, `label`, `labels`, `material` or `MaterialIds`,
//! else from the first single-component integer cell-data array, else it is 1; labels must be
//! non-negative integers. LZ4 and LZMA compression are rejected with a clear error.

use std::io::{Read, Write};

use biotet::quality::tet::TetMeasures;
use biotet::{SurfaceMesh, TetMesh};

use crate::b64;
use crate::common::{check_surface, check_tet, orient_tets, read_all};
use crate::error::{Error, Result};
use crate::text::{Out, show};
use crate::vtkxml::{ArrayRef, Ctx, Values};
use crate::{MeshKind, SurfaceRead, TetRead};

/// How [`write_tet_with`] encodes the data arrays.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VtuEncoding {
    /// Appended raw binary (the default; fastest).
    #[default]
    Raw,
    /// Appended raw binary, zlib-compressed (smaller, slower).
    RawZlib,
    /// Inline base64 binary.
    Base64,
    /// Inline base64 binary, zlib-compressed.
    Base64Zlib,
    /// Inline ASCII.
    Ascii,
}

/// Array values to write.
enum Data {
    F64(Vec<f64>),
    I32(Vec<i32>),
    I64(Vec<i64>),
    U8(Vec<u8>),
}

impl Data {
    fn ty(&self) -> &'static str {
        match self {
            Data::F64(_) => "Float64",
            Data::I32(_) => "Int32",
            Data::I64(_) => "Int64",
            Data::U8(_) => "UInt8",
        }
    }

    fn bytes(&self) -> Vec<u8> {
        match self {
            Data::F64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Data::I32(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Data::I64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Data::U8(v) => v.clone(),
        }
    }
}

struct Array {
    name: &'static str,
    ncomp: usize,
    data: Data,
}

/// Per-tet quality: (min dihedral degrees, min solid angle steradians, q), computed on all cores.
fn quality(mesh: &TetMesh) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = mesh.tets.len();
    let mut dih = vec![0.0; n];
    let mut sol = vec![0.0; n];
    let mut q = vec![0.0; n];
    let threads = std::thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(16);
    let chunk = n.div_ceil(threads).max(4096);
    std::thread::scope(|s| {
        for (k, ((d, so), qq)) in dih
            .chunks_mut(chunk)
            .zip(sol.chunks_mut(chunk))
            .zip(q.chunks_mut(chunk))
            .enumerate()
        {
            s.spawn(move || {
                for i in 0..d.len() {
                    let m = TetMeasures::of(&mesh.corners(k * chunk + i));
                    d[i] = m.min_dihedral();
                    so[i] = m.min_solid();
                    qq[i] = m.q;
                }
            });
        }
    });
    (dih, sol, q)
}

fn arrays(mesh: &TetMesh, file: &str) -> Result<(Vec<Array>, usize)> {
    let nt = mesh.tets.len();
    let wide_conn = mesh.points.len() > i32::MAX as usize;
    let wide_off = 4 * nt > i32::MAX as usize;
    let conn = if wide_conn {
        Data::I64(mesh.tets.iter().flatten().map(|&v| v as i64).collect())
    } else {
        Data::I32(mesh.tets.iter().flatten().map(|&v| v as i32).collect())
    };
    let offsets = if wide_off {
        Data::I64((1..=nt as i64).map(|i| 4 * i).collect())
    } else {
        Data::I32((1..=nt as i32).map(|i| 4 * i).collect())
    };
    let mut region = Vec::with_capacity(nt);
    for (t, &l) in mesh.labels.iter().enumerate() {
        region.push(
            i32::try_from(l).map_err(|_| {
                Error::invalid(file, format!("tet {t}: label {l} does not fit Int32"))
            })?,
        );
    }
    let (dih, sol, q) = quality(mesh);
    let a = |name, ncomp, data| Array { name, ncomp, data };
    Ok((
        vec![
            a("Points", 3, Data::F64(mesh.points.as_flattened().to_vec())),
            a("connectivity", 1, conn),
            a("offsets", 1, offsets),
            a("types", 1, Data::U8(vec![10; nt])),
            a("region", 1, Data::I32(region)),
            a("min_dihedral_deg", 1, Data::F64(dih)),
            a("min_solid_angle_sr", 1, Data::F64(sol)),
            a("q", 1, Data::F64(q)),
        ],
        4,
    ))
}

const ZBLOCK: usize = 1 << 16;

/// The header and payload of one binary array: uncompressed `[nbytes]` + data, or VTK's zlib
/// layout `[nblocks, blocksize, lastsize, csize...]` + compressed blocks.
fn block(bytes: &[u8], zlib: bool, file: &str) -> Result<(Vec<u8>, Vec<u8>)> {
    if !zlib {
        return Ok(((bytes.len() as u64).to_le_bytes().to_vec(), bytes.to_vec()));
    }
    let mut header = Vec::new();
    let mut payload = Vec::new();
    let nblocks = bytes.len().div_ceil(ZBLOCK);
    let last = bytes.len() % ZBLOCK;
    for x in [nblocks as u64, ZBLOCK as u64, last as u64] {
        header.extend_from_slice(&x.to_le_bytes());
    }
    for c in bytes.chunks(ZBLOCK) {
        let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
        e.write_all(c).map_err(|e| Error::io(file, e))?;
        let z = e.finish().map_err(|e| Error::io(file, e))?;
        header.extend_from_slice(&(z.len() as u64).to_le_bytes());
        payload.extend_from_slice(&z);
    }
    Ok((header, payload))
}

/// Write a tet mesh as VTU with appended raw binary data.
pub fn write_tet<W: Write>(w: W, mesh: &TetMesh, file: &str) -> Result<()> {
    write_tet_with(w, mesh, file, VtuEncoding::Raw)
}

/// Write a tet mesh as VTU with the chosen encoding.
pub fn write_tet_with<W: Write>(w: W, mesh: &TetMesh, file: &str, enc: VtuEncoding) -> Result<()> {
    check_tet(mesh, file)?;
    let (arrays, first_cell_array) = arrays(mesh, file)?;
    write_grid(
        w,
        (mesh.points.len(), mesh.tets.len()),
        &arrays,
        first_cell_array,
        "region",
        file,
        enc,
    )
}

/// Write an unstructured grid of `sizes = (points, cells)` from its arrays: `Points`, the three
/// cell arrays, then cell data from index `first_cell_array` on, `scalars` the active one.
fn write_grid<W: Write>(
    w: W,
    sizes: (usize, usize),
    arrays: &[Array],
    first_cell_array: usize,
    scalars: &str,
    file: &str,
    enc: VtuEncoding,
) -> Result<()> {
    let zlib = matches!(enc, VtuEncoding::RawZlib | VtuEncoding::Base64Zlib);
    let io = |e| Error::io(file, e);
    let mut out = Out::new(w);
    out.s("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"");
    if zlib {
        out.s(" compressor=\"vtkZLibDataCompressor\"");
    }
    out.s(">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"");
    out.int(sizes.0);
    out.s("\" NumberOfCells=\"");
    out.int(sizes.1);
    out.s("\">\n");
    // Appended blocks, computed up front for their offsets.
    let appended = matches!(enc, VtuEncoding::Raw | VtuEncoding::RawZlib);
    let mut blocks = Vec::new();
    let mut offset = 0usize;
    for (k, a) in arrays.iter().enumerate() {
        match k {
            0 => out.s("      <Points>\n"),
            1 => out.s("      <Cells>\n"),
            _ if k == first_cell_array => {
                out.s("      <CellData Scalars=\"");
                out.s(scalars);
                out.s("\">\n");
            }
            _ => {}
        }
        out.s("        <DataArray type=\"");
        out.s(a.data.ty());
        out.s("\" Name=\"");
        out.s(a.name);
        out.s("\"");
        if a.ncomp != 1 {
            out.s(" NumberOfComponents=\"");
            out.int(a.ncomp);
            out.s("\"");
        }
        match enc {
            VtuEncoding::Raw | VtuEncoding::RawZlib => {
                let (h, p) = block(&a.data.bytes(), zlib, file)?;
                out.s(" format=\"appended\" offset=\"");
                out.int(offset);
                out.s("\"/>\n");
                offset += h.len() + p.len();
                blocks.push((h, p));
            }
            VtuEncoding::Base64 | VtuEncoding::Base64Zlib => {
                out.s(" format=\"binary\">\n");
                let (h, p) = block(&a.data.bytes(), zlib, file)?;
                if zlib {
                    b64::encode(&h, &mut out.buf);
                    b64::encode(&p, &mut out.buf);
                } else {
                    let mut all = h;
                    all.extend_from_slice(&p);
                    b64::encode(&all, &mut out.buf);
                }
                out.s("\n        </DataArray>\n");
            }
            VtuEncoding::Ascii => {
                out.s(" format=\"ascii\">\n");
                macro_rules! nums {
                    ($v:expr, $f:ident) => {
                        for (i, x) in $v.iter().enumerate() {
                            out.$f(*x);
                            out.c(if i % 12 == 11 { b'\n' } else { b' ' });
                            out.check().map_err(io)?;
                        }
                    };
                }
                match &a.data {
                    Data::F64(v) => nums!(v, f64),
                    Data::I32(v) => nums!(v, int),
                    Data::I64(v) => nums!(v, int),
                    Data::U8(v) => nums!(v, int),
                }
                out.s("\n        </DataArray>\n");
            }
        }
        out.check().map_err(io)?;
        match k {
            0 => out.s("      </Points>\n"),
            3 => out.s("      </Cells>\n"),
            _ => {}
        }
    }
    out.s("      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n");
    if appended {
        out.s("  <AppendedData encoding=\"raw\">\n   _");
        for (h, p) in &blocks {
            out.bytes(h);
            out.check().map_err(io)?;
            for c in p.chunks(1 << 16) {
                out.bytes(c);
                out.check().map_err(io)?;
            }
        }
        out.s("\n  </AppendedData>\n");
    }
    out.s("</VTKFile>\n");
    out.finish().map_err(io)?;
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Reading.

#[derive(Debug, Default)]
struct Piece<'a> {
    npts: usize,
    ncells: usize,
    points: Option<ArrayRef<'a>>,
    conn: Option<ArrayRef<'a>>,
    offsets: Option<ArrayRef<'a>>,
    types: Option<ArrayRef<'a>>,
    cell_data: Vec<ArrayRef<'a>>,
}

/// Read a VTU tet mesh from a stream.
pub fn read_tet<R: Read>(r: R, file: &str) -> Result<TetRead> {
    parse_tet(&read_all(r, file)?, file)
}

/// VTK cell types that are volumes (other than the linear tet, 10).
fn is_volume_cell(t: i64) -> bool {
    matches!(t, 10..=16 | 24..=27 | 29 | 32 | 33 | 42 | 71..=74 | 78..=81)
}

const LABEL_NAMES: [&str; 9] = [
    "region",
    "gmsh:physical",
    "medit:ref",
    "CellEntityIds",
    "tetgen:ref",
    "label",
    "labels",
    "material",
    "MaterialIds",
];

/// The pieces of a VTU file, with the context to decode their arrays.
fn read_pieces<'a>(data: &'a [u8], file: &'a str) -> Result<(Ctx<'a>, Vec<Piece<'a>>)> {
    let (mut ctx, xml_end) = Ctx::new(data, file)?;
    let xml = &data[..xml_end];
    let mut pos = 0;
    let mut pieces: Vec<Piece> = Vec::new();
    let mut cur: Option<Piece> = None;
    let mut section: &[u8] = b"";
    let mut seen_root = false;
    while let Some(tag) = ctx.next_tag(xml, &mut pos)? {
        match tag.name {
            b"VTKFile" if !tag.closing => {
                seen_root = true;
                ctx.root(&tag, "UnstructuredGrid", ".vtu")?;
            }
            b"Piece" if !tag.closing => {
                if !seen_root {
                    return Err(ctx.err_at(tag.start, "Piece outside VTKFile"));
                }
                let num = |k: &str| -> Result<usize> {
                    let v = tag
                        .attr(k)
                        .ok_or_else(|| ctx.err_at(tag.start, format!("Piece without {k}")))?;
                    crate::text::parse_u64(v)
                        .and_then(|x| usize::try_from(x).ok())
                        .ok_or_else(|| ctx.err_at(tag.start, format!("bad {k} '{}'", show(v))))
                };
                let p = Piece {
                    npts: num("NumberOfPoints")?,
                    ncells: num("NumberOfCells")?,
                    ..Piece::default()
                };
                if tag.self_closing {
                    pieces.push(p);
                } else {
                    cur = Some(p);
                }
            }
            b"Piece" => {
                if let Some(p) = cur.take() {
                    pieces.push(p);
                }
            }
            b"Points" | b"Cells" | b"CellData" | b"PointData" | b"FieldData" => {
                section = if tag.closing || tag.self_closing {
                    b""
                } else {
                    tag.name
                };
            }
            b"DataArray" if !tag.closing => {
                let a = ctx.data_array(&tag, xml, &mut pos)?;
                if let Some(p) = cur.as_mut() {
                    match section {
                        b"Points" if p.points.is_none() => p.points = Some(a),
                        b"Cells" => match a.name {
                            b"connectivity" => p.conn = Some(a),
                            b"offsets" => p.offsets = Some(a),
                            b"types" => p.types = Some(a),
                            _ => {}
                        },
                        b"CellData" => p.cell_data.push(a),
                        _ => {}
                    }
                }
            }
            _ => {}
        }
    }
    if !seen_root {
        return Err(Error::format(
            file,
            "no VTKFile element: not a VTK XML file",
        ));
    }
    if let Some(p) = cur.take() {
        pieces.push(p);
    }
    ctx.end_of_xml();
    Ok((ctx, pieces))
}

/// Append the points of piece `pi` to `points`.
fn read_points(ctx: &Ctx, p: &Piece, pi: usize, points: &mut Vec<[f64; 3]>) -> Result<()> {
    let file = ctx.file;
    let base = points.len();
    if p.npts == 0 {
        return Ok(());
    }
    let a = p
        .points
        .as_ref()
        .ok_or_else(|| Error::format(file, format!("piece {pi} has no Points array")))?;
    if a.ncomp != 3 {
        return Err(ctx.err_at(
            a.at,
            format!("Points with {} components, expected 3", a.ncomp),
        ));
    }
    let cap = p
        .npts
        .checked_mul(3)
        .ok_or_else(|| Error::format(file, "too many points"))?;
    let v = match ctx.values(a, Some(cap))? {
        Values::F(v) => v,
        Values::I(v) => v.into_iter().map(|x| x as f64).collect(),
    };
    for (i, c) in v.chunks_exact(3).enumerate() {
        if c.iter().any(|x| !x.is_finite()) {
            return Err(Error::element(
                file,
                "point",
                base + i,
                format!("non-finite coordinate {c:?}"),
            ));
        }
        points.push([c[0], c[1], c[2]]);
    }
    if points.len() > u32::MAX as usize {
        return Err(Error::format(file, "too many points for 32-bit indices"));
    }
    Ok(())
}

/// The cells of piece `pi`: offsets, types and connectivity, decoded.
fn read_cells(ctx: &Ctx, p: &Piece, pi: usize) -> Result<(Vec<i64>, Vec<i64>, Vec<i64>)> {
    let file = ctx.file;
    fn need<'b, 'c>(
        a: &'b Option<ArrayRef<'c>>,
        n: &str,
        pi: usize,
        file: &str,
    ) -> Result<&'b ArrayRef<'c>> {
        a.as_ref()
            .ok_or_else(|| Error::format(file, format!("piece {pi} has no '{n}' cell array")))
    }
    let offsets = ctx.ints(need(&p.offsets, "offsets", pi, file)?, Some(p.ncells))?;
    let types = ctx.ints(need(&p.types, "types", pi, file)?, Some(p.ncells))?;
    let nconn = offsets.last().copied().unwrap_or(0);
    let nconn = usize::try_from(nconn)
        .map_err(|_| Error::element(file, "cell", p.ncells - 1, format!("bad offset {nconn}")))?;
    let conn = ctx.ints(need(&p.conn, "connectivity", pi, file)?, Some(nconn))?;
    Ok((offsets, types, conn))
}

/// The point indices of cell `i`, checked against the connectivity and the piece's points and
/// shifted by `base`; `prev` is the end of the previous cell in the connectivity.
fn cell_points(
    file: &str,
    i: usize,
    (offsets, conn): (&[i64], &[i64]),
    prev: &mut usize,
    npts: usize,
    base: usize,
    out: &mut Vec<u32>,
) -> Result<()> {
    let end = offsets[i];
    if end < *prev as i64 || end > conn.len() as i64 {
        return Err(Error::element(
            file,
            "cell",
            i,
            format!(
                "offset {end} out of order or past the connectivity ({} entries)",
                conn.len()
            ),
        ));
    }
    let end = end as usize;
    out.clear();
    for &v in &conn[*prev..end] {
        if v < 0 || v as u64 >= npts as u64 {
            return Err(Error::element(
                file,
                "cell",
                i,
                format!("point index {v} out of range ({npts} points)"),
            ));
        }
        out.push((base + v as usize) as u32);
    }
    *prev = end;
    Ok(())
}

/// Parse a VTU tet mesh held in memory.
pub fn parse_tet(data: &[u8], file: &str) -> Result<TetRead> {
    let (ctx, pieces) = read_pieces(data, file)?;
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut tets: Vec<[u32; 4]> = Vec::new();
    let mut labels: Vec<u32> = Vec::new();
    let mut skipped = 0;
    let mut c: Vec<u32> = Vec::new();
    for (pi, p) in pieces.iter().enumerate() {
        let base = points.len();
        read_points(&ctx, p, pi, &mut points)?;
        if p.ncells == 0 {
            continue;
        }
        let (offsets, types, conn) = read_cells(&ctx, p, pi)?;
        let label_arr = LABEL_NAMES
            .iter()
            .find_map(|n| {
                p.cell_data
                    .iter()
                    .find(|a| a.name == n.as_bytes() && a.ncomp == 1)
            })
            .or_else(|| {
                p.cell_data
                    .iter()
                    .find(|a| a.ncomp == 1 && !a.ty.is_float())
            });
        let lab = match label_arr {
            Some(a) => Some((a, ctx.ints(a, Some(p.ncells))?)),
            None => None,
        };
        let mut prev = 0usize;
        for i in 0..p.ncells {
            cell_points(file, i, (&offsets, &conn), &mut prev, p.npts, base, &mut c)?;
            if types[i] != 10 || c.len() != 4 {
                if is_volume_cell(types[i]) {
                    skipped += 1;
                }
                continue;
            }
            let t = [c[0], c[1], c[2], c[3]];
            let l = match &lab {
                Some((a, v)) => crate::common::label_of(v[i]).map_err(|e| {
                    Error::element(file, "cell", i, format!("array '{}': {e}", show(a.name)))
                })?,
                None => 1,
            };
            tets.push(t);
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
// Surfaces.

/// VTK cell types read as surface polygons: triangle, polygon, quad.
fn is_surface_cell(t: i64) -> bool {
    matches!(t, 5 | 7 | 9)
}

/// Two-component cell-data arrays holding the side labels `[back, front]`, in order of
/// preference (`sides`: biotet; `BoundaryLabels`: VTK's SurfaceNets; `boundary_labels`: PyVista).
const SIDE_ARRAYS: [&str; 3] = ["sides", "BoundaryLabels", "boundary_labels"];
/// Scalar cell-data array pairs holding the side labels, `(back, front)`.
const SIDE_PAIRS: [(&str, &str); 2] = [
    ("label_back", "label_front"),
    ("region_back", "region_front"),
];

/// Side labels of a piece's cells: the array name(s), then back and front values per cell.
type SideArrays<'a> = (Vec<&'a [u8]>, Vec<i64>, Vec<i64>);

/// What a VTU file holds: [`MeshKind::Tetrahedra`] when it has a volume cell (or no surface
/// cell), else [`MeshKind::Surface`]. Decodes only the cell types.
pub fn peek_kind(data: &[u8], file: &str) -> Result<MeshKind> {
    let (ctx, pieces) = read_pieces(data, file)?;
    let mut surface = false;
    for p in &pieces {
        let Some(t) = p.types.as_ref().filter(|_| p.ncells > 0) else {
            continue;
        };
        for ty in ctx.ints(t, Some(p.ncells))? {
            if is_volume_cell(ty) {
                return Ok(MeshKind::Tetrahedra);
            }
            surface |= is_surface_cell(ty);
        }
    }
    Ok(if surface {
        MeshKind::Surface
    } else {
        MeshKind::Tetrahedra
    })
}

/// Read a VTU surface from a stream.
pub fn read_surface<R: Read>(r: R, file: &str) -> Result<SurfaceRead> {
    parse_surface(&read_all(r, file)?, file)
}

/// Parse a VTU surface held in memory: triangles, quads and polygons (fan-split), the side
/// labels from a two-component cell-data array `sides`, `BoundaryLabels` or `boundary_labels`,
/// or from two scalar arrays `label_back` and `label_front` (or `region_back`, `region_front`).
/// Volume cells are an error (a tet mesh); vertices and lines are ignored.
pub fn parse_surface(data: &[u8], file: &str) -> Result<SurfaceRead> {
    let (ctx, pieces) = read_pieces(data, file)?;
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut sides: Vec<[u32; 2]> = Vec::new();
    let mut labelled = None;
    let mut split = 0;
    let mut c: Vec<u32> = Vec::new();
    for (pi, p) in pieces.iter().enumerate() {
        let base = points.len();
        read_points(&ctx, p, pi, &mut points)?;
        if p.ncells == 0 {
            continue;
        }
        let (offsets, types, conn) = read_cells(&ctx, p, pi)?;
        let find = |n: &str, ncomp: usize| {
            p.cell_data
                .iter()
                .find(|a| a.name == n.as_bytes() && a.ncomp == ncomp && !a.ty.is_float())
        };
        let mut lab: Option<SideArrays> = None;
        if let Some(a) = SIDE_ARRAYS.iter().find_map(|n| find(n, 2)) {
            let v = ctx.ints(a, Some(2 * p.ncells))?;
            let (b, f) = v.chunks_exact(2).map(|x| (x[0], x[1])).unzip();
            lab = Some((vec![a.name], b, f));
        } else if let Some((b, f)) = SIDE_PAIRS
            .iter()
            .find_map(|(b, f)| Some((find(b, 1)?, find(f, 1)?)))
        {
            lab = Some((
                vec![b.name, f.name],
                ctx.ints(b, Some(p.ncells))?,
                ctx.ints(f, Some(p.ncells))?,
            ));
        }
        if let Some(prev) = labelled
            && prev != lab.is_some()
        {
            return Err(Error::format(
                file,
                format!("piece {pi}: side labels in some pieces but not in others"),
            ));
        }
        labelled = Some(lab.is_some());
        let mut prev = 0usize;
        for i in 0..p.ncells {
            cell_points(file, i, (&offsets, &conn), &mut prev, p.npts, base, &mut c)?;
            if is_volume_cell(types[i]) {
                return Err(Error::element(
                    file,
                    "cell",
                    i,
                    format!(
                        "a volume cell (VTK type {}): a tet mesh, expected a surface",
                        types[i]
                    ),
                ));
            }
            if !is_surface_cell(types[i]) {
                continue;
            }
            if c.len() < 3 {
                return Err(Error::element(
                    file,
                    "cell",
                    i,
                    format!("a polygon with {} corners", c.len()),
                ));
            }
            // VTK's quad (9) is a cycle like a polygon, so a fan splits both.
            let side = match &lab {
                Some((names, b, f)) => {
                    let one = |v: i64, k: usize| {
                        crate::common::side_label_of(v).map_err(|e| {
                            let n = names[k.min(names.len() - 1)];
                            Error::element(file, "cell", i, format!("array '{}': {e}", show(n)))
                        })
                    };
                    [one(b[i], 0)?, one(f[i], 1)?]
                }
                None => [1, 0],
            };
            if c.len() > 3 {
                split += 1;
            }
            for k in 1..c.len() - 1 {
                triangles.push([c[0], c[k], c[k + 1]]);
                sides.push(side);
            }
        }
    }
    let has_labels = labelled == Some(true);
    Ok(SurfaceRead {
        mesh: SurfaceMesh::closed(points, triangles, 1),
        triangle_refs: None,
        side_labels: has_labels.then_some(sides),
        welded: 0,
        polygons_split: split,
    })
}

/// Write a surface as VTU (appended raw binary): triangles (VTK type 5) and the cell-data array
/// `sides` (`Int32`, two components: the regions behind and in front of each triangle).
pub fn write_surface<W: Write>(w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    check_surface(mesh, file)?;
    let nt = mesh.triangles.len();
    if mesh.sides.len() != nt {
        return Err(Error::invalid(
            file,
            format!("{} side-label pairs for {nt} triangles", mesh.sides.len()),
        ));
    }
    let wide = mesh.points.len() > i32::MAX as usize || 3 * nt > i32::MAX as usize;
    let (conn, offsets) = if wide {
        (
            Data::I64(mesh.triangles.iter().flatten().map(|&v| v as i64).collect()),
            Data::I64((1..=nt as i64).map(|i| 3 * i).collect()),
        )
    } else {
        (
            Data::I32(mesh.triangles.iter().flatten().map(|&v| v as i32).collect()),
            Data::I32((1..=nt as i32).map(|i| 3 * i).collect()),
        )
    };
    let mut sides = Vec::with_capacity(2 * nt);
    for (t, s) in mesh.sides.iter().enumerate() {
        for &l in s {
            sides.push(i32::try_from(l).map_err(|_| {
                Error::invalid(file, format!("triangle {t}: label {l} does not fit Int32"))
            })?);
        }
    }
    let a = |name, ncomp, data| Array { name, ncomp, data };
    let arrays = [
        a("Points", 3, Data::F64(mesh.points.as_flattened().to_vec())),
        a("connectivity", 1, conn),
        a("offsets", 1, offsets),
        a("types", 1, Data::U8(vec![5; nt])),
        a("sides", 2, Data::I32(sides)),
    ];
    write_grid(
        w,
        (mesh.points.len(), nt),
        &arrays,
        4,
        "sides",
        file,
        VtuEncoding::Raw,
    )
}
