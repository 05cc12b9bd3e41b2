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
//! [`TetMeasures`](biotet::quality::tet::TetMeasures): `min_dihedral_deg`, `min_solid_angle_sr` and `q` (`Float64`).
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

use biotet::quality::tet::{min_dihedral_deg, min_solid_sr, q_measure};
use biotet::{SurfaceMesh, TetMesh};

use crate::common::{check_sided_surface, check_tet, orient_tets, read_all};
use crate::error::{Error, Result};
use crate::text::show;
use crate::vtkxml::{ArrayRef, Ctx, Values};
use crate::vtu_out::{self, Array, Data, Ty};
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

/// The arrays of a tet mesh, made on demand: points, cells, `region` and the per-tet quality
/// (computed a chunk at a time on all cores, never held whole).
fn tet_arrays<'a>(mesh: &'a TetMesh, file: &str) -> Result<Vec<Array<'a>>> {
    if let Some((t, &l)) = mesh
        .labels
        .iter()
        .enumerate()
        .find(|&(_, &l)| i32::try_from(l).is_err())
    {
        return Err(Error::invalid(
            file,
            format!("tet {t}: label {l} does not fit Int32"),
        ));
    }
    let (np, nt) = (mesh.points.len(), mesh.tets.len());
    let threads = vtu_out::threads();
    let corners = move |t: usize| mesh.corners(t);
    let measure = move |name, f: fn(&[[f64; 3]; 4]) -> f64| {
        Array::new(name, 1, Ty::F64, nt, move |r| {
            vtu_out::par_map(r, threads, &|t| f(&corners(t)))
        })
    };
    Ok(vec![
        Array::new("Points", 3, Ty::F64, np, |r| {
            Data::F64(mesh.points[r].as_flattened().to_vec())
        }),
        cells_connectivity(&mesh.tets, np > i32::MAX as usize),
        cells_offsets::<4>(nt, 4 * nt > i32::MAX as usize),
        Array::new("types", 1, Ty::U8, nt, |r| Data::U8(vec![10; r.len()])),
        Array::new("region", 1, Ty::I32, nt, |r| {
            Data::I32(mesh.labels[r].iter().map(|&l| l as i32).collect())
        }),
        measure("min_dihedral_deg", min_dihedral_deg),
        measure("min_solid_angle_sr", min_solid_sr),
        measure("q", q_measure),
    ])
}

/// The `connectivity` array of cells with `K` corners (`Int64` if `wide`, else `Int32`).
pub(crate) fn cells_connectivity<const K: usize>(cells: &[[u32; K]], wide: bool) -> Array<'_> {
    if wide {
        Array::new("connectivity", 1, Ty::I64, K * cells.len(), move |r| {
            let c = &cells.as_flattened()[r];
            Data::I64(c.iter().map(|&v| v as i64).collect())
        })
    } else {
        Array::new("connectivity", 1, Ty::I32, K * cells.len(), move |r| {
            let c = &cells.as_flattened()[r];
            Data::I32(c.iter().map(|&v| v as i32).collect())
        })
    }
}

/// The `offsets` array of `n` cells of `K` corners each: `K, 2K, …` (`Int64` if `wide`, else
/// `Int32`).
pub(crate) fn cells_offsets<'a, const K: usize>(n: usize, wide: bool) -> Array<'a> {
    let end = |r: std::ops::Range<usize>| (r.start as i64 + 1..=r.end as i64).map(|i| K as i64 * i);
    if wide {
        Array::new("offsets", 1, Ty::I64, n, move |r| {
            Data::I64(end(r).collect())
        })
    } else {
        Array::new("offsets", 1, Ty::I32, n, move |r| {
            Data::I32(end(r).map(|x| x as i32).collect())
        })
    }
}

/// Write a tet mesh as VTU with appended raw binary data.
pub fn write_tet<W: Write>(w: W, mesh: &TetMesh, file: &str) -> Result<()> {
    write_tet_with(w, mesh, file, VtuEncoding::Raw)
}

/// Write a tet mesh as VTU with the chosen encoding. Arrays are made and encoded a chunk at a
/// time, so the writer needs little memory beside the mesh (compressed encodings also hold the
/// compressed data).
pub fn write_tet_with<W: Write>(w: W, mesh: &TetMesh, file: &str, enc: VtuEncoding) -> Result<()> {
    write_tet_chunked(w, mesh, file, enc, vtu_out::CHUNK)
}

/// [`write_tet_with`] with `chunk` tuples per chunk (small in tests, to cross chunk boundaries).
fn write_tet_chunked<W: Write>(
    w: W,
    mesh: &TetMesh,
    file: &str,
    enc: VtuEncoding,
    chunk: usize,
) -> Result<()> {
    check_tet(mesh, file)?;
    let arrays = tet_arrays(mesh, file)?;
    let sizes = (mesh.points.len(), mesh.tets.len());
    let grid = vtu_out::Grid::Unstructured;
    vtu_out::write_grid(w, grid, sizes, &arrays, (4, "region"), file, enc, chunk)
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

/// VTK cell types that are volumes (the list of [`crate::vtk`]).
pub(crate) fn is_volume_cell(t: i64) -> bool {
    u8::try_from(t).is_ok_and(crate::vtk::is_volume_cell)
}

/// Names of label arrays, in order of preference (also for legacy VTK).
pub(crate) const LABEL_NAMES: [&str; 9] = [
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
    crate::vtkxml::read_pieces(
        data,
        file,
        ("UnstructuredGrid", ".vtu"),
        &[b"Points", b"Cells", b"CellData", b"PointData", b"FieldData"],
        |num| {
            Ok(Piece {
                npts: num("NumberOfPoints", true)?,
                ncells: num("NumberOfCells", true)?,
                ..Piece::default()
            })
        },
        |p, section, a| match section {
            b"Points" if p.points.is_none() => p.points = Some(a),
            b"Cells" => match a.name {
                b"connectivity" => p.conn = Some(a),
                b"offsets" => p.offsets = Some(a),
                b"types" => p.types = Some(a),
                _ => {}
            },
            b"CellData" => p.cell_data.push(a),
            _ => {}
        },
    )
}

/// Append the points of piece `pi` to `points`.
pub(crate) fn read_points(
    ctx: &Ctx,
    (npts, array): (usize, Option<&ArrayRef>),
    pi: usize,
    points: &mut Vec<[f64; 3]>,
) -> Result<()> {
    let file = ctx.file;
    let base = points.len();
    if npts == 0 {
        return Ok(());
    }
    let a = array.ok_or_else(|| Error::format(file, format!("piece {pi} has no Points array")))?;
    if a.ncomp != 3 {
        return Err(ctx.err_at(
            a.at,
            format!("Points with {} components, expected 3", a.ncomp),
        ));
    }
    let cap = npts
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
pub(crate) fn cell_points(
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
        read_points(&ctx, (p.npts, p.points.as_ref()), pi, &mut points)?;
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
pub(crate) const SIDE_ARRAYS: [&str; 3] = ["sides", "BoundaryLabels", "boundary_labels"];
/// Scalar cell-data array pairs holding the side labels, `(back, front)`.
pub(crate) const SIDE_PAIRS: [(&str, &str); 2] = [
    ("label_back", "label_front"),
    ("region_back", "region_front"),
];

/// Side labels of a piece's cells: the array name(s), then back and front values per cell.
pub(crate) type SideArrays<'a> = (Vec<&'a [u8]>, Vec<i64>, Vec<i64>);

/// The side labels among the cell data `cell_data` of a piece of `ncells` cells (every kind of
/// cell, in the order VTK numbers them): a two-component array of [`SIDE_ARRAYS`], else a scalar
/// pair of [`SIDE_PAIRS`], integer-typed; `None` when there is none.
pub(crate) fn side_arrays<'a>(
    ctx: &Ctx,
    cell_data: &[ArrayRef<'a>],
    ncells: usize,
) -> Result<Option<SideArrays<'a>>> {
    let find = |n: &str, ncomp: usize| {
        cell_data
            .iter()
            .find(|a| a.name == n.as_bytes() && a.ncomp == ncomp && !a.ty.is_float())
    };
    if let Some(a) = SIDE_ARRAYS.iter().find_map(|n| find(n, 2)) {
        let cap = ncells
            .checked_mul(2)
            .ok_or_else(|| Error::format(ctx.file, "too many cells"))?;
        let v = ctx.ints(a, Some(cap))?;
        let (b, f) = v.chunks_exact(2).map(|x| (x[0], x[1])).unzip();
        return Ok(Some((vec![a.name], b, f)));
    }
    if let Some((b, f)) = SIDE_PAIRS
        .iter()
        .find_map(|(b, f)| Some((find(b, 1)?, find(f, 1)?)))
    {
        return Ok(Some((
            vec![b.name, f.name],
            ctx.ints(b, Some(ncells))?,
            ctx.ints(f, Some(ncells))?,
        )));
    }
    Ok(None)
}

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
        read_points(&ctx, (p.npts, p.points.as_ref()), pi, &mut points)?;
        if p.ncells == 0 {
            continue;
        }
        let (offsets, types, conn) = read_cells(&ctx, p, pi)?;
        let lab = side_arrays(&ctx, &p.cell_data, p.ncells)?;
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
            for t in crate::common::fan(&c, &mut split) {
                triangles.push(t);
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
/// `sides` (`Int32`, two components: the regions behind and in front of each triangle; left out
/// when `mesh.sides` is empty, a surface without labels).
pub fn write_surface<W: Write>(w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    check_sided_surface(mesh, file)?;
    let nt = mesh.triangles.len();
    let np = mesh.points.len();
    let wide = np > i32::MAX as usize || 3 * nt > i32::MAX as usize;
    let mut arrays = vec![
        Array::new("Points", 3, Ty::F64, np, |r| {
            Data::F64(mesh.points[r].as_flattened().to_vec())
        }),
        cells_connectivity(&mesh.triangles, wide),
        cells_offsets::<3>(nt, wide),
        Array::new("types", 1, Ty::U8, nt, |r| Data::U8(vec![5; r.len()])),
    ];
    if !mesh.sides.is_empty() {
        arrays.push(Array::new("sides", 2, Ty::I32, nt, |r| {
            Data::I32(
                mesh.sides[r]
                    .as_flattened()
                    .iter()
                    .map(|&l| l as i32)
                    .collect(),
            )
        }));
    }
    vtu_out::write_grid(
        w,
        vtu_out::Grid::Unstructured,
        (np, nt),
        &arrays,
        (4, "sides"),
        file,
        VtuEncoding::Raw,
        vtu_out::CHUNK,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use biotet::quality::tet::TetMeasures;

    /// The tet arrays as whole little-endian byte arrays: (type, name, components, bytes).
    type Whole = (&'static str, &'static str, usize, Vec<u8>);

    fn le<T: Copy, const N: usize>(v: &[T], f: impl Fn(T) -> [u8; N]) -> Vec<u8> {
        v.iter().flat_map(|&x| f(x)).collect()
    }

    /// The reference: every array built whole, quality from [`TetMeasures`] (how the writer
    /// worked before it streamed).
    fn whole_arrays(m: &TetMesh) -> Vec<Whole> {
        let nt = m.tets.len();
        let q: Vec<TetMeasures> = (0..nt).map(|t| TetMeasures::of(&m.corners(t))).collect();
        let f64s =
            |f: fn(&TetMeasures) -> f64| le(&q.iter().map(f).collect::<Vec<_>>(), f64::to_le_bytes);
        let conn: Vec<i32> = m.tets.iter().flatten().map(|&v| v as i32).collect();
        let offsets: Vec<i32> = (1..=nt as i32).map(|i| 4 * i).collect();
        let region: Vec<i32> = m.labels.iter().map(|&l| l as i32).collect();
        vec![
            (
                "Float64",
                "Points",
                3,
                le(m.points.as_flattened(), f64::to_le_bytes),
            ),
            ("Int32", "connectivity", 1, le(&conn, i32::to_le_bytes)),
            ("Int32", "offsets", 1, le(&offsets, i32::to_le_bytes)),
            ("UInt8", "types", 1, vec![10; nt]),
            ("Int32", "region", 1, le(&region, i32::to_le_bytes)),
            (
                "Float64",
                "min_dihedral_deg",
                1,
                f64s(TetMeasures::min_dihedral),
            ),
            (
                "Float64",
                "min_solid_angle_sr",
                1,
                f64s(TetMeasures::min_solid),
            ),
            ("Float64", "q", 1, f64s(|m| m.q)),
        ]
    }

    /// VTK's zlib layout of whole bytes, in one go.
    fn zlib(bytes: &[u8]) -> (Vec<u8>, Vec<u8>) {
        let mut h: Vec<u8> = [
            bytes.len().div_ceil(1 << 16),
            1 << 16,
            bytes.len() % (1 << 16),
        ]
        .iter()
        .flat_map(|&x| (x as u64).to_le_bytes())
        .collect();
        let mut p = Vec::new();
        for c in bytes.chunks(1 << 16) {
            let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
            e.write_all(c).unwrap();
            let z = e.finish().unwrap();
            h.extend_from_slice(&(z.len() as u64).to_le_bytes());
            p.extend_from_slice(&z);
        }
        (h, p)
    }

    /// The whole file from whole arrays, encoded in memory.
    fn reference(m: &TetMesh, enc: VtuEncoding) -> Vec<u8> {
        let zl = matches!(enc, VtuEncoding::RawZlib | VtuEncoding::Base64Zlib);
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"",
        );
        if zl {
            s += " compressor=\"vtkZLibDataCompressor\"";
        }
        s += &format!(
            ">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
            m.points.len(),
            m.tets.len()
        );
        let mut out = Vec::new();
        let mut appended = Vec::new();
        for (k, (ty, name, ncomp, bytes)) in whole_arrays(m).into_iter().enumerate() {
            s += [
                "      <Points>\n",
                "      <Cells>\n",
                "",
                "",
                "      <CellData Scalars=\"region\">\n",
            ]
            .get(k)
            .unwrap_or(&"");
            s += &format!("        <DataArray type=\"{ty}\" Name=\"{name}\"");
            if ncomp != 1 {
                s += &format!(" NumberOfComponents=\"{ncomp}\"");
            }
            let (h, p) = if zl {
                zlib(&bytes)
            } else {
                ((bytes.len() as u64).to_le_bytes().to_vec(), bytes.clone())
            };
            match enc {
                VtuEncoding::Raw | VtuEncoding::RawZlib => {
                    s += &format!(" format=\"appended\" offset=\"{}\"/>\n", appended.len());
                    appended.extend_from_slice(&h);
                    appended.extend_from_slice(&p);
                }
                VtuEncoding::Base64 | VtuEncoding::Base64Zlib => {
                    s += " format=\"binary\">\n";
                    let mut b = Vec::new();
                    if zl {
                        crate::b64::encode(&h, &mut b);
                        crate::b64::encode(&p, &mut b);
                    } else {
                        crate::b64::encode(&[h, p].concat(), &mut b);
                    }
                    s += std::str::from_utf8(&b).unwrap();
                    s += "\n        </DataArray>\n";
                }
                VtuEncoding::Ascii => {
                    s += " format=\"ascii\">\n";
                    let size = if ty == "UInt8" {
                        1
                    } else if ty == "Int32" {
                        4
                    } else {
                        8
                    };
                    for (i, c) in bytes.chunks(size).enumerate() {
                        let mut w = [0u8; 8];
                        w[..size].copy_from_slice(c);
                        s += &match ty {
                            "Float64" => {
                                ryu::Buffer::new().format(f64::from_le_bytes(w)).to_string()
                            }
                            "Int32" => i32::from_le_bytes(w[..4].try_into().unwrap()).to_string(),
                            _ => c[0].to_string(),
                        };
                        s.push(if i % 12 == 11 { '\n' } else { ' ' });
                    }
                    s += "\n        </DataArray>\n";
                }
            }
            s += ["      </Points>\n", "", "", "      </Cells>\n"]
                .get(k)
                .unwrap_or(&"");
        }
        s += "      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n";
        out.extend_from_slice(s.as_bytes());
        if matches!(enc, VtuEncoding::Raw | VtuEncoding::RawZlib) {
            out.extend_from_slice(b"  <AppendedData encoding=\"raw\">\n   _");
            out.extend_from_slice(&appended);
            out.extend_from_slice(b"\n  </AppendedData>\n");
        }
        out.extend_from_slice(b"</VTKFile>\n");
        out
    }

    /// A labelled Delaunay mesh of pseudo-random points (large enough for several zlib blocks).
    fn mesh(n: usize) -> TetMesh {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut r = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let pts = (0..n).map(|_| [r(), r(), r()]).collect();
        let mut m = biotet::delaunay::Delaunay::from_points(pts)
            .unwrap()
            .to_tet_mesh();
        m.labels = (0..m.tets.len() as u32).map(|t| 1 + t % 3).collect();
        m
    }

    const ENCODINGS: [VtuEncoding; 5] = [
        VtuEncoding::Raw,
        VtuEncoding::RawZlib,
        VtuEncoding::Base64,
        VtuEncoding::Base64Zlib,
        VtuEncoding::Ascii,
    ];

    #[test]
    fn streaming_matches_the_whole_array_encoding() {
        for n in [5, 40, 2500] {
            let m = mesh(n);
            for enc in ENCODINGS {
                let want = reference(&m, enc);
                // One chunk, chunks of awkward sizes (base64 carries, zlib blocks across chunks).
                let one = if n < 100 { 1 } else { vtu_out::CHUNK };
                for chunk in [vtu_out::CHUNK, one, 7, 1000] {
                    let mut got = Vec::new();
                    write_tet_chunked(&mut got, &m, "m.vtu", enc, chunk).unwrap();
                    assert!(
                        got == want,
                        "{n} points, {enc:?}, chunks of {chunk}: differs"
                    );
                }
            }
        }
    }

    #[test]
    fn streamed_files_read_back() {
        let m = mesh(300);
        for enc in ENCODINGS {
            let mut buf = Vec::new();
            write_tet_chunked(&mut buf, &m, "m.vtu", enc, 13).unwrap();
            let r = parse_tet(&buf, "m.vtu").unwrap();
            assert_eq!(r.mesh.points, m.points, "{enc:?}");
            assert_eq!(r.mesh.tets, m.tets, "{enc:?}");
            assert_eq!(r.mesh.labels, m.labels, "{enc:?}");
        }
    }

    #[test]
    fn labels_beyond_int32_are_refused_before_writing() {
        let mut m = mesh(20);
        m.labels[3] = u32::MAX;
        let mut buf = Vec::new();
        let e = write_tet_with(&mut buf, &m, "m.vtu", VtuEncoding::Raw).unwrap_err();
        assert!(e.to_string().contains("tet 3"), "{e}");
        assert!(buf.is_empty());
    }
}
