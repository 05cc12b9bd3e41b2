//! Writers of 2D triangle meshes in formats read mostly by viewers and solvers: VTU (ASCII,
//! points with z = 0, VTK_TRIANGLE cells, cell data `region` = label and `min_angle_deg`, `q`)
//! and Gmsh `.msh` 2.2 ASCII (triangles with physical group = label, plus the boundary and
//! interface edges as line elements in physical groups numbered as in [`crate::medit`]: outer
//! boundary of label `a` first, then interfaces `a|b`, each named `boundary_<a>_0` or
//! `interface_<a>_<b>`). Output is deterministic.

use std::io::Write;

use biotet::quality::tri::TriMeasures;
use biotet::{NO_NEIGHBOR, TriMesh};

use crate::common::check_tri;
use crate::error::{Error, Result};
use crate::text::Out;

/// Boundary and interface edges of a 2D mesh, grouped by their (sorted) labels, outer first.
fn edge_groups(m: &TriMesh) -> Vec<([u32; 2], Vec<[u32; 2]>)> {
    let mut g: std::collections::BTreeMap<(bool, [u32; 2]), Vec<[u32; 2]>> = Default::default();
    for (t, tv) in m.triangles.iter().enumerate() {
        for i in 0..3 {
            let n = m.neighbors[t][i];
            let (a, b) = (tv[(i + 1) % 3], tv[(i + 2) % 3]);
            let l = m.labels[t];
            if n == NO_NEIGHBOR {
                g.entry((false, [l, 0])).or_default().push([a, b]);
            } else if m.labels[n as usize] != l && l < m.labels[n as usize] {
                g.entry((true, [l, m.labels[n as usize]]))
                    .or_default()
                    .push([a, b]);
            }
        }
    }
    g.into_iter().map(|((_, k), v)| (k, v)).collect()
}

/// Write a 2D mesh as an ASCII VTU.
pub fn write_vtu<W: Write>(w: W, mesh: &TriMesh, file: &str) -> Result<()> {
    check_tri(mesh, file)?;
    let io = |e| Error::io(file, e);
    let mut o = Out::new(w);
    o.s("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"");
    o.int(mesh.points.len());
    o.s("\" NumberOfCells=\"");
    o.int(mesh.triangles.len());
    o.s("\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for p in &mesh.points {
        o.f64s(p);
        o.s(" 0\n");
        o.check().map_err(io)?;
    }
    o.s("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for t in &mesh.triangles {
        o.ints(t);
        o.c(b'\n');
        o.check().map_err(io)?;
    }
    o.s("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for i in 0..mesh.triangles.len() {
        o.int(3 * (i + 1));
        o.c(b'\n');
    }
    o.s("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in 0..mesh.triangles.len() {
        o.s("5\n");
    }
    o.s("</DataArray>\n</Cells>\n<CellData Scalars=\"region\">\n<DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">\n");
    for &l in &mesh.labels {
        o.int(l);
        o.c(b'\n');
    }
    let measures: Vec<TriMeasures> = (0..mesh.triangles.len())
        .map(|t| TriMeasures::of(&mesh.corners(t)))
        .collect();
    o.s("</DataArray>\n<DataArray type=\"Float64\" Name=\"min_angle_deg\" format=\"ascii\">\n");
    for m in &measures {
        o.f64(m.min_angle());
        o.c(b'\n');
        o.check().map_err(io)?;
    }
    o.s("</DataArray>\n<DataArray type=\"Float64\" Name=\"q\" format=\"ascii\">\n");
    for m in &measures {
        o.f64(m.q);
        o.c(b'\n');
        o.check().map_err(io)?;
    }
    o.s("</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    o.finish().map_err(io)?;
    Ok(())
}

/// Write a 2D mesh as Gmsh 2.2 ASCII.
pub fn write_msh<W: Write>(w: W, mesh: &TriMesh, file: &str) -> Result<()> {
    check_tri(mesh, file)?;
    let io = |e| Error::io(file, e);
    let groups = edge_groups(mesh);
    let mut labels: Vec<u32> = mesh.labels.clone();
    labels.sort_unstable();
    labels.dedup();
    let max_label = labels.last().copied().unwrap_or(0);
    let mut o = Out::new(w);
    o.s("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n");
    o.int(labels.len() + groups.len());
    o.c(b'\n');
    for (k, (l, _)) in groups.iter().enumerate() {
        o.s("1 ");
        o.int(max_label as usize + 1 + k);
        o.s(if l[1] == 0 {
            " \"boundary_"
        } else {
            " \"interface_"
        });
        o.int(l[0]);
        o.c(b'_');
        o.int(l[1]);
        o.s("\"\n");
    }
    for &l in &labels {
        o.s("2 ");
        o.int(l);
        o.s(" \"region_");
        o.int(l);
        o.s("\"\n");
    }
    o.s("$EndPhysicalNames\n$Nodes\n");
    o.int(mesh.points.len());
    o.c(b'\n');
    for (i, p) in mesh.points.iter().enumerate() {
        o.int(i + 1);
        o.c(b' ');
        o.f64s(p);
        o.s(" 0\n");
        o.check().map_err(io)?;
    }
    o.s("$EndNodes\n$Elements\n");
    let n_edges: usize = groups.iter().map(|g| g.1.len()).sum();
    o.int(n_edges + mesh.triangles.len());
    o.c(b'\n');
    let mut id = 1usize;
    for (k, (_, edges)) in groups.iter().enumerate() {
        let phys = max_label as usize + 1 + k;
        for e in edges {
            o.int(id);
            o.s(" 1 2 ");
            o.int(phys);
            o.c(b' ');
            o.int(phys);
            o.c(b' ');
            o.int(e[0] + 1);
            o.c(b' ');
            o.int(e[1] + 1);
            o.c(b'\n');
            id += 1;
            o.check().map_err(io)?;
        }
    }
    for (t, tv) in mesh.triangles.iter().enumerate() {
        o.int(id);
        o.s(" 2 2 ");
        o.int(mesh.labels[t]);
        o.c(b' ');
        o.int(mesh.labels[t]);
        for &v in tv {
            o.c(b' ');
            o.int(v + 1);
        }
        o.c(b'\n');
        id += 1;
        o.check().map_err(io)?;
    }
    o.s("$EndElements\n");
    o.finish().map_err(io)?;
    Ok(())
}
