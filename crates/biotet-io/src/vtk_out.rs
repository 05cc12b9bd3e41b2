//! Legacy VTK (`.vtk`) written: binary (big-endian), in the layout every VTK since 4 reads
//! (`# vtk DataFile Version 3.0`, each cell as its point count and indices).
//!
//! - Tet meshes ([`write_tet`]): `UNSTRUCTURED_GRID`, `Float64` points, linear tetrahedra
//!   (type 10) and the cell scalars `region` (`int`, the label). The per-tet quality arrays of
//!   a `.vtu` are left out: the legacy format is for tools that read nothing newer.
//! - Surfaces ([`write_surface`]): `POLYDATA`, the triangles as polygons and the cell field
//!   array `sides` (`int`, two components: the regions behind and in front of each triangle),
//!   as [`crate::vtk`] and PyVista read it back.
//!
//! Indices and labels must fit `int` (32 bits); larger meshes belong in `.vtu`.

use std::io::Write;

use biotet::{SurfaceMesh, TetMesh};

use crate::common::{check_sided_surface, check_tet};
use crate::error::{Error, Result};
use crate::text::Out;

/// Refuse what `int` cannot hold: `n` point indices, or a label.
fn fits(n: usize, what: &str, file: &str) -> Result<()> {
    if n > i32::MAX as usize {
        return Err(Error::invalid(
            file,
            format!("{n} {what} do not fit legacy VTK's 32-bit int; write .vtu"),
        ));
    }
    Ok(())
}

/// The header and the points (binary `double`, big-endian).
fn head<W: Write>(out: &mut Out<W>, title: &str, dataset: &str, points: &[[f64; 3]]) {
    out.s("# vtk DataFile Version 3.0\n");
    out.s(title);
    out.s("\nBINARY\nDATASET ");
    out.s(dataset);
    out.s("\nPOINTS ");
    out.int(points.len());
    out.s(" double\n");
    for p in points {
        for c in p {
            out.bytes(&c.to_be_bytes());
        }
    }
    out.c(b'\n');
}

/// Cells of `K` corners as `keyword n size` and each cell's count and indices (`int`).
fn cells<W: Write, const K: usize>(out: &mut Out<W>, keyword: &str, cells: &[[u32; K]]) {
    out.s(keyword);
    out.c(b' ');
    out.int(cells.len());
    out.c(b' ');
    out.int(cells.len() * (K + 1));
    out.c(b'\n');
    for c in cells {
        out.bytes(&(K as i32).to_be_bytes());
        for &v in c {
            out.bytes(&(v as i32).to_be_bytes());
        }
    }
    out.c(b'\n');
}

/// Write a tet mesh as binary legacy VTK (see the module docs).
pub fn write_tet<W: Write>(w: W, mesh: &TetMesh, file: &str) -> Result<()> {
    check_tet(mesh, file)?;
    fits(mesh.points.len(), "points", file)?;
    fits(5 * mesh.tets.len(), "cell entries", file)?;
    if let Some((t, &l)) = mesh
        .labels
        .iter()
        .enumerate()
        .find(|(_, l)| i32::try_from(**l).is_err())
    {
        return Err(Error::invalid(
            file,
            format!("tet {t}: label {l} does not fit int"),
        ));
    }
    let mut out = Out::new(w);
    head(
        &mut out,
        "biotet tet mesh",
        "UNSTRUCTURED_GRID",
        &mesh.points,
    );
    cells(&mut out, "CELLS", &mesh.tets);
    out.s("CELL_TYPES ");
    out.int(mesh.tets.len());
    out.c(b'\n');
    for _ in &mesh.tets {
        out.bytes(&10i32.to_be_bytes());
    }
    out.s("\nCELL_DATA ");
    out.int(mesh.tets.len());
    out.s("\nSCALARS region int 1\nLOOKUP_TABLE default\n");
    for &l in &mesh.labels {
        out.bytes(&(l as i32).to_be_bytes());
    }
    out.c(b'\n');
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}

/// Write a surface as binary legacy VTK (see the module docs); `sides` left out when
/// `mesh.sides` is empty (a surface without labels).
pub fn write_surface<W: Write>(w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    check_sided_surface(mesh, file)?;
    let nt = mesh.triangles.len();
    fits(mesh.points.len(), "points", file)?;
    fits(4 * nt, "cell entries", file)?;
    let mut out = Out::new(w);
    head(&mut out, "biotet surface", "POLYDATA", &mesh.points);
    cells(&mut out, "POLYGONS", &mesh.triangles);
    if !mesh.sides.is_empty() {
        out.s("CELL_DATA ");
        out.int(nt);
        out.s("\nFIELD FieldData 1\nsides 2 ");
        out.int(nt);
        out.s(" int\n");
        for s in &mesh.sides {
            for &l in s {
                out.bytes(&(l as i32).to_be_bytes());
            }
        }
        out.c(b'\n');
    }
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed surface whose coordinates no decimal text holds exactly.
    fn ball() -> SurfaceMesh {
        SurfaceMesh::icosphere(1.5, 1)
    }

    #[test]
    fn a_written_surface_and_tet_mesh_read_back_exactly() {
        let mut s = ball();
        s.sides[5] = [3, 1];
        let mut buf = Vec::new();
        write_surface(&mut buf, &s, "c.vtk").unwrap();
        assert!(buf.starts_with(b"# vtk DataFile Version 3.0\n"));
        let r = crate::vtk::parse_surface(&buf, "c.vtk").unwrap();
        assert_eq!(r.mesh.points, s.points);
        assert_eq!(r.mesh.triangles, s.triangles);
        assert_eq!(r.side_labels.as_deref(), Some(&s.sides[..]));
        let pts = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ];
        let mut m = TetMesh::new(pts, vec![[0, 1, 2, 3], [1, 2, 3, 4]], vec![7, 2]);
        crate::orient_tets(&m.points.clone(), &mut m.tets);
        let mut buf = Vec::new();
        write_tet(&mut buf, &m, "t.vtk").unwrap();
        assert_eq!(
            crate::vtk::peek_kind(&buf, "t.vtk").unwrap(),
            crate::MeshKind::Tetrahedra
        );
        let r = crate::vtk::parse_tet(&buf, "t.vtk").unwrap();
        assert_eq!(r.mesh.points, m.points);
        assert_eq!(r.mesh.tets, m.tets);
        assert_eq!(r.mesh.labels, vec![7, 2]);
        assert_eq!(r.flipped, 0);
    }

    #[test]
    fn a_label_int_cannot_hold_is_refused() {
        let mut s = ball();
        s.sides[0] = [u32::MAX, 0];
        let e = write_surface(&mut Vec::new(), &s, "c.vtk")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.vtk: cannot write: triangle 0"), "{e}");
    }
}
