//! VTK XML poly data (`.vtp`): surfaces, as PyVista, ParaView and 3D Slicer write them.
//!
//! Reading ([`parse_surface`]): `PolyData` files with any number of pieces, their arrays encoded
//! as the VTU reader takes them ([`crate::vtu`]: ascii, inline or appended binary, zlib, either
//! byte order). Polygons (`Polys`) are fan-split; triangle strips (`Strips`) give one triangle
//! per point past the second, every other one with its corners swapped so that all keep the
//! strip's orientation; vertices and lines are ignored. Side labels come from cell data as in a
//! VTU surface (a two-component `sides`, `BoundaryLabels` or `boundary_labels`, or the scalar
//! pairs `label_back`/`label_front` and `region_back`/`region_front`). Cell data covers every
//! cell in VTK's order — vertices, lines, polygons, strips — so a polygon's values sit past the
//! piece's vertices and lines. Errors number a polygon or strip among its kind (as the offsets
//! do) and say which kind.
//!
//! Writing ([`write_surface`]): appended raw binary, `Float64` points, the triangles as
//! polygons and the cell-data array `sides` (`Int32`, two components), as [`crate::vtu`] writes
//! a surface.

use std::io::{Read, Write};

use biotet::SurfaceMesh;

use crate::SurfaceRead;
use crate::common::{check_sided_surface, read_all};
use crate::error::{Error, Result};
use crate::text::show;
use crate::vtkxml::{ArrayRef, Ctx};
use crate::vtu::{
    VtuEncoding, cell_points, cells_connectivity, cells_offsets, read_points, side_arrays,
};
use crate::vtu_out::{self, Array, Data, Grid, Ty};

/// The cells of one kind (`Verts`, `Lines`, `Polys` or `Strips`) of a piece.
#[derive(Default)]
struct Cells<'a> {
    n: usize,
    conn: Option<ArrayRef<'a>>,
    offsets: Option<ArrayRef<'a>>,
}

/// One `Piece` of a poly data file.
#[derive(Default)]
struct Piece<'a> {
    npts: usize,
    points: Option<ArrayRef<'a>>,
    /// Vertices, lines, polygons, strips: the order of the cell data.
    cells: [Cells<'a>; 4],
    cell_data: Vec<ArrayRef<'a>>,
}

const KINDS: [(&[u8], &str); 4] = [
    (b"Verts", "NumberOfVerts"),
    (b"Lines", "NumberOfLines"),
    (b"Polys", "NumberOfPolys"),
    (b"Strips", "NumberOfStrips"),
];
const POLYS: usize = 2;
const STRIPS: usize = 3;

/// The pieces of a VTP file, with the context to decode their arrays.
fn read_pieces<'a>(data: &'a [u8], file: &'a str) -> Result<(Ctx<'a>, Vec<Piece<'a>>)> {
    crate::vtkxml::read_pieces(
        data,
        file,
        ("PolyData", ".vtp"),
        &[
            b"Points",
            b"Verts",
            b"Lines",
            b"Polys",
            b"Strips",
            b"CellData",
            b"PointData",
            b"FieldData",
        ],
        |num| {
            // Counts absent from the tag are zero (VTK writes only what it has).
            let mut p = Piece {
                npts: num("NumberOfPoints", true)?,
                ..Piece::default()
            };
            for (k, (_, attr)) in KINDS.iter().enumerate() {
                p.cells[k].n = num(attr, false)?;
            }
            Ok(p)
        },
        |p, section, a| {
            if section == b"Points" {
                p.points.get_or_insert(a);
            } else if section == b"CellData" {
                p.cell_data.push(a);
            } else if let Some(k) = KINDS.iter().position(|(s, _)| *s == section) {
                match a.name {
                    b"connectivity" => p.cells[k].conn = Some(a),
                    b"offsets" => p.cells[k].offsets = Some(a),
                    _ => {}
                }
            }
        },
    )
}

/// The offsets and connectivity of one kind of cells of piece `pi`, decoded.
fn read_cells(ctx: &Ctx, c: &Cells, kind: &str, pi: usize) -> Result<(Vec<i64>, Vec<i64>)> {
    let file = ctx.file;
    let need = |a: &Option<ArrayRef>, n: &str| -> Result<()> {
        if a.is_none() {
            return Err(Error::format(
                file,
                format!("piece {pi}: {kind} without a '{n}' array"),
            ));
        }
        Ok(())
    };
    need(&c.offsets, "offsets")?;
    need(&c.conn, "connectivity")?;
    let offsets = ctx.ints(c.offsets.as_ref().expect("checked"), Some(c.n))?;
    let nconn = offsets.last().copied().unwrap_or(0);
    let nconn = usize::try_from(nconn)
        .map_err(|_| Error::element(file, "cell", c.n - 1, format!("bad offset {nconn}")))?;
    let conn = ctx.ints(c.conn.as_ref().expect("checked"), Some(nconn))?;
    Ok((offsets, conn))
}

/// Read a VTP surface from a stream.
pub fn read_surface<R: Read>(r: R, file: &str) -> Result<SurfaceRead> {
    parse_surface(&read_all(r, file)?, file)
}

/// Parse a VTP surface held in memory (see the module docs).
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
        let ncells = p
            .cells
            .iter()
            .try_fold(0usize, |a, k| a.checked_add(k.n))
            .ok_or_else(|| Error::format(file, format!("piece {pi}: too many cells")))?;
        let labels = side_arrays(&ctx, &p.cell_data, ncells)?;
        if p.cells[POLYS].n + p.cells[STRIPS].n > 0 {
            if let Some(prev) = labelled
                && prev != labels.is_some()
            {
                return Err(Error::format(
                    file,
                    format!("piece {pi}: side labels in some pieces but not in others"),
                ));
            }
            labelled = Some(labels.is_some());
        }
        // The cell-data index of the first polygon: past the vertices and lines.
        let mut cell = p.cells[0].n + p.cells[1].n;
        for kind in [POLYS, STRIPS] {
            let cells = &p.cells[kind];
            if cells.n == 0 {
                continue;
            }
            let (name, word) = if kind == POLYS {
                ("Polys", "polygon")
            } else {
                ("Strips", "triangle strip")
            };
            let (offsets, conn) = read_cells(&ctx, cells, name, pi)?;
            let mut prev = 0usize;
            for i in 0..cells.n {
                cell_points(file, i, (&offsets, &conn), &mut prev, p.npts, base, &mut c)?;
                if c.len() < 3 {
                    return Err(Error::element(
                        file,
                        "cell",
                        i,
                        format!("a {word} with {} points", c.len()),
                    ));
                }
                let side = match &labels {
                    Some((names, b, f)) => {
                        let one = |v: i64, k: usize| {
                            crate::common::side_label_of(v).map_err(|e| {
                                let n = names[k.min(names.len() - 1)];
                                Error::element(
                                    file,
                                    "cell",
                                    i,
                                    format!("a {word}'s array '{}': {e}", show(n)),
                                )
                            })
                        };
                        [one(b[cell], 0)?, one(f[cell], 1)?]
                    }
                    None => [1, 0],
                };
                if kind == POLYS {
                    for t in crate::common::fan(&c, &mut split) {
                        triangles.push(t);
                        sides.push(side);
                    }
                } else {
                    for t in crate::common::strip(&c) {
                        triangles.push(t);
                        sides.push(side);
                    }
                }
                cell += 1;
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

/// Write a surface as VTP (appended raw binary): the triangles as polygons and the cell-data
/// array `sides` (`Int32`, two components: the regions behind and in front of each triangle; left out
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
        Grid::Poly,
        (np, nt),
        &arrays,
        (3, "sides"),
        file,
        VtuEncoding::Raw,
        vtu_out::CHUNK,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed surface whose coordinates no decimal text holds exactly.
    fn ball() -> SurfaceMesh {
        SurfaceMesh::icosphere(1.5, 1)
    }

    #[test]
    fn a_written_surface_reads_back_exactly_with_its_sides() {
        let mut s = ball();
        s.sides[3] = [2, 1];
        let mut buf = Vec::new();
        write_surface(&mut buf, &s, "c.vtp").unwrap();
        let text = String::from_utf8_lossy(&buf);
        assert!(
            text.contains("type=\"PolyData\"") && text.contains("<Polys>"),
            "{text}"
        );
        let r = parse_surface(&buf, "c.vtp").unwrap();
        assert_eq!(r.mesh.points, s.points);
        assert_eq!(r.mesh.triangles, s.triangles);
        assert_eq!(r.side_labels.as_deref(), Some(&s.sides[..]));
        // A VTU surface is refused by the VTP reader, naming what it is.
        let mut vtu = Vec::new();
        crate::vtu::write_surface(&mut vtu, &s, "c.vtu").unwrap();
        let e = parse_surface(&vtu, "c.vtp").unwrap_err().to_string();
        assert!(
            e.contains("UnstructuredGrid") && e.contains("PolyData"),
            "{e}"
        );
    }

    /// An ASCII poly data file of four points of the unit square (and a fifth): one vertex
    /// cell, one line cell, then `body` (counted by `counts`), with cell data `data`.
    fn ascii(counts: &str, body: &str, data: &str) -> String {
        format!(
            r#"<?xml version="1.0"?>
<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">
  <PolyData>
    <Piece NumberOfPoints="5" NumberOfVerts="1" NumberOfLines="1" {counts}>
      <PointData Normals="n"><DataArray type="Float32" Name="n" NumberOfComponents="3" format="ascii">0 0 1 0 0 1 0 0 1 0 0 1 0 0 1</DataArray></PointData>
      <CellData>{data}</CellData>
      <Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 1 1 0 0 1 0 2 0 0</DataArray></Points>
      <Verts><DataArray type="Int64" Name="connectivity" format="ascii">4</DataArray><DataArray type="Int64" Name="offsets" format="ascii">1</DataArray></Verts>
      <Lines><DataArray type="Int64" Name="connectivity" format="ascii">0 4</DataArray><DataArray type="Int64" Name="offsets" format="ascii">2</DataArray></Lines>
      {body}
    </Piece>
  </PolyData>
</VTKFile>
"#
        )
    }

    /// `kind` cells (`Polys` or `Strips`) of the given connectivity and offsets.
    fn cells(kind: &str, conn: &str, offsets: &str) -> String {
        format!(
            r#"<{kind}><DataArray type="Int32" Name="connectivity" format="ascii">{conn}</DataArray><DataArray type="Int32" Name="offsets" format="ascii">{offsets}</DataArray></{kind}>"#
        )
    }

    #[test]
    fn polygons_and_strips_read_with_their_cells_labels() {
        // A quad as one polygon, fan-split; its label pair is the third cell's (after the
        // vertex and the line).
        let sides = r#"<DataArray type="Int32" Name="sides" NumberOfComponents="2" format="ascii">9 9 8 8 3 0</DataArray>"#;
        let f = ascii(
            r#"NumberOfPolys="1""#,
            &cells("Polys", "0 1 2 3", "4"),
            sides,
        );
        let r = parse_surface(f.as_bytes(), "q.vtp").unwrap();
        assert_eq!(r.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(r.polygons_split, 1);
        assert_eq!(r.side_labels, Some(vec![[3, 0], [3, 0]]));
        // The square as a strip of its four points: two triangles, both turning the same way.
        let f = ascii(
            r#"NumberOfStrips="1""#,
            &cells("Strips", "1 2 0 3", "4"),
            "",
        );
        let r = parse_surface(f.as_bytes(), "s.vtp").unwrap();
        assert_eq!(r.mesh.triangles.len(), 2);
        assert!(r.side_labels.is_none());
        let normal_z = |t: &[u32; 3]| {
            let p = |k: usize| r.mesh.points[t[k] as usize];
            let (a, b, c) = (p(0), p(1), p(2));
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        };
        let n: Vec<f64> = r.mesh.triangles.iter().map(normal_z).collect();
        assert!(
            n.iter().all(|&z| z > 0.0) || n.iter().all(|&z| z < 0.0),
            "{n:?}"
        );
    }

    #[test]
    fn bad_poly_data_is_refused_naming_the_cell() {
        let f = ascii(r#"NumberOfPolys="1""#, &cells("Polys", "0 1 7", "3"), "");
        let e = parse_surface(f.as_bytes(), "b.vtp")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("b.vtp: cell 0:") && e.contains("out of range"),
            "{e}"
        );
        let body = r#"<Polys><DataArray type="Int32" Name="connectivity" format="ascii">0 1 2</DataArray></Polys>"#;
        let f = ascii(r#"NumberOfPolys="1""#, body, "");
        let e = parse_surface(f.as_bytes(), "b.vtp")
            .unwrap_err()
            .to_string();
        assert!(e.contains("Polys without a 'offsets' array"), "{e}");
        let f = ascii(r#"NumberOfPolys="1""#, &cells("Polys", "0 1", "2"), "");
        let e = parse_surface(f.as_bytes(), "b.vtp")
            .unwrap_err()
            .to_string();
        assert!(e.contains("with 2 points"), "{e}");
    }
}
