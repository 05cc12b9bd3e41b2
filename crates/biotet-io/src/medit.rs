//! Medit `.mesh` (ASCII): surfaces, tet meshes and 2D triangle meshes.
//!
//! Reading: keywords are matched case-insensitively and may be followed by their numbers on
//! the same or the next lines (the format is free-form); `#` starts a comment. Sections read:
//! `MeshVersionFormatted`, `Dimension` (2 or 3), `Vertices` (coordinates and a ref, ignored),
//! `Triangles` and `Tetrahedra` (1-based indices and a ref), `End`. Every other section
//! (`Edges`, `Corners`, `Ridges`, `Normals`, `Quadrilaterals`, ...) is skipped by skipping its
//! numbers; the element counts of `Hexahedra`, `Prisms` and `Pyramids` are reported as skipped
//! volume elements. As a surface, the triangles' refs become [`SurfaceRead::triangle_refs`];
//! as a tet mesh, tet refs are the region labels (negative refs are errors) and triangles are
//! ignored; as a 2D mesh (`Dimension 2`), triangle refs are the labels.
//!
//! A surface (a file without tetrahedra) whose triangle refs are not all equal is a labelled
//! multi-material surface, [`SurfaceRead::side_labels`]: each ref is the region *behind* its
//! triangle (the normal points out of it; 0 = the outside), which is what the surface writer
//! below writes. A triangle between two regions is given either once (its front region is then
//! taken from the geometry: the region that the other triangles of that cell name) or twice with
//! opposite orientations, once in the closed boundary of each region, as a file concatenating
//! every region's outward surface has it; the second copy is merged into the first (copies are
//! matched by their corners' coordinates, so each region may come on its own points). A negative
//! ref, a copy with the same orientation or the same ref, or a third copy is an error naming
//! the line and the triangle. Refs that are all equal (say all 0 or all 1), or that include a
//! negative one, carry no regions: the surface is read as closed shells, as from any other
//! format, its refs kept in [`SurfaceRead::triangle_refs`].
//!
//! The surface writer writes every triangle with ref = the region behind it, and a triangle
//! with a region in front (an interface) a second time, reversed, with ref = that region: every
//! region's boundary is then complete in the file and reads back without the geometry.
//!
//! Writing (`MeshVersionFormatted 2`, shortest round-trip coordinates, vertex refs 0):
//! - a surface: `Triangles` with ref = the region behind each triangle (`sides[t][0]`), or
//!   given refs ([`write_surface_with_refs`]);
//! - a tet mesh: `Tetrahedra` with ref = label, then `Triangles` holding every boundary face and
//!   every face between two different labels, each once, oriented outward from the smaller
//!   label. A triangle's ref numbers its group: groups are sorted, outer boundaries first
//!   (`boundary_a_0` for each region `a` in increasing order), then interfaces (`interface_a_b`
//!   for pairs `a < b` in increasing order), and the k-th group (from 1) has ref k — the same
//!   numbering as the Gmsh surface physical tags and TetGen `.face` markers;
//! - a 2D mesh: `Dimension 2`, `Vertices` with two coordinates, `Triangles` with ref = label.

use std::io::{BufRead, Write};

use biotet::mesh::coord_key;
use biotet::mesh::side_labels::FROM_GEOMETRY;
use biotet::mesh::surface::same_turn;
use biotet::{SurfaceMesh, TetMesh, TriMesh};

use crate::common::{
    check_surface, check_tet, check_tri, face_groups, label_of, orient_tets, orient_tris, read_all,
    side_label_of,
};
use crate::error::{Error, Result};
use crate::text::{Lexer, Out, show};
use crate::{MeshKind, SurfaceRead, TetRead, TriRead};

/// Everything a Medit file holds that we use.
struct Medit {
    dim: usize,
    verts: Vec<[f64; 3]>,
    tris: Vec<[u32; 3]>,
    tri_refs: Vec<i64>,
    tri_lines: Vec<usize>,
    edges: Vec<[u32; 2]>,
    edge_refs: Vec<i64>,
    edge_lines: Vec<usize>,
    tets: Vec<[u32; 4]>,
    tet_refs: Vec<i64>,
    tet_lines: Vec<usize>,
    skipped_volume: usize,
}

fn skip_numbers(lx: &mut Lexer) {
    loop {
        let (p, l) = (lx.pos, lx.line);
        match lx.next_token() {
            Some(t) if !t[0].is_ascii_alphabetic() => {}
            Some(_) => {
                lx.pos = p;
                lx.line = l;
                return;
            }
            None => return,
        }
    }
}

fn cells<const K: usize>(
    lx: &mut Lexer,
    nv: usize,
    what: &str,
    out: &mut Vec<[u32; K]>,
    refs: &mut Vec<i64>,
    lines: &mut Vec<usize>,
) -> Result<()> {
    let (n, cap) = lx.count(&format!("number of {what}"), 2 * (K + 1))?;
    out.reserve(cap);
    refs.reserve(cap);
    lines.reserve(cap);
    for _ in 0..n {
        let mut c = [0u32; K];
        for x in &mut c {
            let v = lx.u64("vertex index")?;
            if v == 0 || v > nv as u64 {
                return Err(lx.err(format!("vertex index {v} out of range ({nv} vertices)")));
            }
            *x = (v - 1) as u32;
        }
        refs.push(lx.i64("ref")?);
        out.push(c);
        lines.push(lx.tok_line);
    }
    Ok(())
}

fn parse(data: &[u8], file: &str) -> Result<Medit> {
    let mut lx = Lexer::new(data, file, Some(b'#'));
    let mut m = Medit {
        dim: 0,
        verts: Vec::new(),
        tris: Vec::new(),
        tri_refs: Vec::new(),
        tri_lines: Vec::new(),
        edges: Vec::new(),
        edge_refs: Vec::new(),
        edge_lines: Vec::new(),
        tets: Vec::new(),
        tet_refs: Vec::new(),
        tet_lines: Vec::new(),
        skipped_volume: 0,
    };
    let mut seen_vertices = false;
    while let Some(t) = lx.next_token() {
        if !t[0].is_ascii_alphabetic() {
            return Err(lx.err(format!("expected a keyword, got '{}'", show(t))));
        }
        let kw = t.to_ascii_lowercase();
        match &kw[..] {
            b"meshversionformatted" => {
                lx.u64("version")?;
            }
            b"dimension" => {
                let d = lx.u64("dimension")?;
                if d != 2 && d != 3 {
                    return Err(lx.err(format!("dimension {d}, expected 2 or 3")));
                }
                m.dim = d as usize;
            }
            b"vertices" => {
                if m.dim == 0 {
                    return Err(lx.err("'Vertices' before 'Dimension'"));
                }
                let (n, cap) = lx.count("number of vertices", 2 * (m.dim + 1))?;
                if n > u32::MAX as usize {
                    return Err(lx.err(format!("{n} vertices do not fit 32-bit indices")));
                }
                m.verts.reserve(cap);
                for _ in 0..n {
                    let mut p = [0.0; 3];
                    for x in &mut p[..m.dim] {
                        *x = lx.f64("coordinate")?;
                    }
                    lx.i64("vertex ref")?;
                    m.verts.push(p);
                }
                seen_vertices = true;
            }
            b"triangles" | b"tetrahedra" => {
                if !seen_vertices {
                    return Err(lx.err(format!("'{}' before 'Vertices'", show(t))));
                }
                let nv = m.verts.len();
                if kw == b"triangles" {
                    cells(
                        &mut lx,
                        nv,
                        "triangles",
                        &mut m.tris,
                        &mut m.tri_refs,
                        &mut m.tri_lines,
                    )?;
                } else {
                    cells(
                        &mut lx,
                        nv,
                        "tetrahedra",
                        &mut m.tets,
                        &mut m.tet_refs,
                        &mut m.tet_lines,
                    )?;
                }
            }
            b"edges" => {
                if !seen_vertices {
                    return Err(lx.err("'Edges' before 'Vertices'"));
                }
                let nv = m.verts.len();
                cells(
                    &mut lx,
                    nv,
                    "edges",
                    &mut m.edges,
                    &mut m.edge_refs,
                    &mut m.edge_lines,
                )?;
            }
            b"hexahedra" | b"prisms" | b"pyramids" => {
                let n = lx.u64("element count")?;
                m.skipped_volume = m.skipped_volume.saturating_add(n as usize);
                skip_numbers(&mut lx);
            }
            b"end" => break,
            _ => skip_numbers(&mut lx),
        }
    }
    if m.dim == 0 {
        return Err(Error::format(
            file,
            "no 'Dimension' keyword: not a Medit mesh",
        ));
    }
    Ok(m)
}

/// Read a Medit surface (`Dimension 3`, `Vertices`, `Triangles`) from a stream.
pub fn read_surface<R: std::io::Read>(r: R, file: &str) -> Result<SurfaceRead> {
    parse_surface(&read_all(r, file)?, file)
}

/// Parse a Medit surface held in memory.
pub fn parse_surface(data: &[u8], file: &str) -> Result<SurfaceRead> {
    let m = parse(data, file)?;
    if m.dim != 3 {
        return Err(Error::format(
            file,
            "a 2D mesh (Dimension 2), expected a 3D surface",
        ));
    }
    let labelled = m.tets.is_empty()
        && m.tri_refs.windows(2).any(|w| w[0] != w[1])
        && m.tri_refs.iter().all(|&r| side_label_of(r).is_ok());
    let (tris, tri_refs, side_labels) = if labelled {
        let (t, r, sides) = sides_from_refs(&m.verts, &m.tris, &m.tri_refs, &m.tri_lines, file)?;
        (t, r, Some(sides))
    } else {
        (m.tris, m.tri_refs, None)
    };
    let refs = tri_refs
        .iter()
        .map(|&r| r.clamp(i32::MIN as i64, i32::MAX as i64) as i32)
        .collect();
    Ok(SurfaceRead {
        mesh: SurfaceMesh::closed(m.verts, tris, 1),
        triangle_refs: Some(refs),
        side_labels,
        welded: 0,
        polygons_split: 0,
    })
}

/// Triangle refs as region labels (see the module documentation): each ref names the region
/// behind its triangle; a triangle given twice, with opposite orientations, names both sides and
/// is kept once (the first copy); a triangle given once leaves its front to the geometry
/// ([`FROM_GEOMETRY`]). Copies are matched by their corners' coordinates, so a file that gives
/// each region's boundary on its own copies of the points pairs its interfaces too. Returns the
/// kept triangles, their refs and their side labels.
#[allow(clippy::type_complexity)]
fn sides_from_refs(
    verts: &[[f64; 3]],
    tris: &[[u32; 3]],
    refs: &[i64],
    lines: &[usize],
    file: &str,
) -> Result<(Vec<[u32; 3]>, Vec<i64>, Vec<[u32; 2]>)> {
    // Each point as the first point of its coordinates (corners are in range: `parse` checks).
    let mut at: std::collections::HashMap<[u64; 3], u32> = Default::default();
    let canon: Vec<u32> = (0..verts.len() as u32)
        .map(|i| *at.entry(coord_key(&verts[i as usize])).or_insert(i))
        .collect();
    let canon = |t: &[u32; 3]| t.map(|v| canon[v as usize]);
    let mut first: std::collections::HashMap<[u32; 3], usize> = Default::default();
    let mut kept = Vec::with_capacity(tris.len());
    let mut kept_refs = Vec::with_capacity(tris.len());
    let mut sides: Vec<[u32; 2]> = Vec::with_capacity(tris.len());
    // Index of each kept triangle in the file, for messages.
    let mut origin: Vec<usize> = Vec::with_capacity(tris.len());
    for (j, (t, &r)) in tris.iter().zip(refs).enumerate() {
        let err = |msg: String| Error::line(file, lines[j], format!("triangle {j}: {msg}"));
        let label = side_label_of(r).map_err(&err)?;
        let c = canon(t);
        let mut key = c;
        key.sort_unstable();
        match first.get(&key) {
            None => {
                first.insert(key, kept.len());
                kept.push(*t);
                kept_refs.push(r);
                sides.push([label, FROM_GEOMETRY]);
                origin.push(j);
            }
            Some(&k) => {
                let i = origin[k];
                if same_turn(canon(&kept[k]), c) {
                    return Err(err(format!(
                        "repeats triangle {i} with the same orientation; a triangle between two \
                         regions is given once, or twice with opposite orientations (once in \
                         the boundary of each region)"
                    )));
                }
                if sides[k][1] != FROM_GEOMETRY {
                    return Err(err(format!(
                        "the third copy of triangle {i}; a triangle has two sides"
                    )));
                }
                if sides[k][0] == label {
                    return Err(err(format!(
                        "repeats triangle {i} with the same ref {label}: the same region on \
                         both sides"
                    )));
                }
                sides[k][1] = label;
            }
        }
    }
    Ok((kept, kept_refs, sides))
}

/// Read a Medit tet mesh (`Dimension 3`, `Vertices`, `Tetrahedra`) from a stream.
pub fn read_tet<R: std::io::Read>(r: R, file: &str) -> Result<TetRead> {
    parse_tet(&read_all(r, file)?, file)
}

/// Parse a Medit tet mesh held in memory.
pub fn parse_tet(data: &[u8], file: &str) -> Result<TetRead> {
    let m = parse(data, file)?;
    if m.dim != 3 {
        return Err(Error::format(
            file,
            "a 2D mesh (Dimension 2), expected a tet mesh",
        ));
    }
    let mut labels = Vec::with_capacity(m.tets.len());
    for (i, &r) in m.tet_refs.iter().enumerate() {
        labels.push(label_of(r).map_err(|e| Error::line(file, m.tet_lines[i], e))?);
    }
    let mut tets = m.tets;
    let (flipped, degenerate) = orient_tets(&m.verts, &mut tets);
    Ok(TetRead {
        mesh: TetMesh::new(m.verts, tets, labels),
        flipped,
        degenerate,
        skipped_elements: m.skipped_volume,
    })
}

/// Read a Medit 2D mesh (`Dimension 2`, `Vertices`, `Triangles`) from a stream.
pub fn read_tri<R: std::io::Read>(r: R, file: &str) -> Result<TriRead> {
    parse_tri(&read_all(r, file)?, file)
}

/// Parse a Medit 2D mesh held in memory.
pub fn parse_tri(data: &[u8], file: &str) -> Result<TriRead> {
    let m = parse(data, file)?;
    if m.dim != 2 {
        return Err(Error::format(
            file,
            "a 3D mesh (Dimension 3), expected a 2D triangle mesh",
        ));
    }
    let mut labels = Vec::with_capacity(m.tris.len());
    for (i, &r) in m.tri_refs.iter().enumerate() {
        labels.push(label_of(r).map_err(|e| Error::line(file, m.tri_lines[i], e))?);
    }
    let points: Vec<[f64; 2]> = m.verts.iter().map(|p| [p[0], p[1]]).collect();
    let mut tris = m.tris;
    let (flipped, degenerate) = orient_tris(&points, &mut tris);
    Ok(TriRead {
        mesh: TriMesh::new(points, tris, labels),
        flipped,
        degenerate,
    })
}

/// Parse a 2D Medit file's `Vertices` and `Edges` as a PSLG (edge refs become segment markers).
pub fn parse_pslg(data: &[u8], file: &str) -> Result<crate::poly::PslgRead> {
    let m = parse(data, file)?;
    if m.dim != 2 {
        return Err(Error::format(
            file,
            "a 3D mesh (Dimension 3), expected a 2D boundary (Dimension 2, Edges)",
        ));
    }
    if m.edges.is_empty() {
        return Err(Error::format(file, "no 'Edges': no boundary segments"));
    }
    let markers = m
        .edge_refs
        .iter()
        .map(|&r| r.clamp(i32::MIN as i64, i32::MAX as i64) as i32)
        .collect();
    Ok(crate::poly::PslgRead {
        pslg: biotet::mesh::pslg::Pslg {
            points: m.verts.iter().map(|p| [p[0], p[1]]).collect(),
            segments: m.edges,
            segment_markers: markers,
            ..Default::default()
        },
        files: vec![file.to_string()],
    })
}

/// What a Medit file holds, from its `Dimension` and sections: [`MeshKind::Triangles2d`] for
/// `Dimension 2`, [`MeshKind::Tetrahedra`] when it has a non-empty `Tetrahedra` section, else
/// [`MeshKind::Surface`]. Stops reading as soon as the answer is known.
pub fn peek_kind<R: BufRead>(mut r: R, file: &str) -> Result<MeshKind> {
    let mut line = Vec::new();
    let mut dim = 0u64;
    // Keyword whose count (or value) is still to come: 1 = Dimension, 2 = Tetrahedra.
    let mut pending = 0u8;
    loop {
        line.clear();
        let n = r
            .read_until(b'\n', &mut line)
            .map_err(|e| Error::io(file, e))?;
        if n == 0 {
            break;
        }
        let text = match line.iter().position(|&c| c == b'#') {
            Some(i) => &line[..i],
            None => &line[..],
        };
        for tok in text
            .split(|c| c.is_ascii_whitespace())
            .filter(|t| !t.is_empty())
        {
            if pending != 0 {
                let v = crate::text::parse_u64(tok).unwrap_or(0);
                if pending == 1 {
                    dim = v;
                    if dim == 2 {
                        return Ok(MeshKind::Triangles2d);
                    }
                } else if v > 0 {
                    return Ok(MeshKind::Tetrahedra);
                }
                pending = 0;
            } else if tok[0].is_ascii_alphabetic() {
                if tok.eq_ignore_ascii_case(b"dimension") {
                    pending = 1;
                } else if tok.eq_ignore_ascii_case(b"tetrahedra") {
                    pending = 2;
                } else if tok.eq_ignore_ascii_case(b"end") {
                    return Ok(MeshKind::Surface);
                }
            }
        }
    }
    if dim == 0 {
        return Err(Error::format(
            file,
            "no 'Dimension' keyword: not a Medit mesh",
        ));
    }
    Ok(MeshKind::Surface)
}

fn vertices3<W: Write>(out: &mut Out<W>, pts: &[[f64; 3]], file: &str) -> Result<()> {
    out.s("Vertices\n");
    out.int(pts.len());
    out.c(b'\n');
    for p in pts {
        out.f64(p[0]);
        out.c(b' ');
        out.f64(p[1]);
        out.c(b' ');
        out.f64(p[2]);
        out.s(" 0\n");
        out.check().map_err(|e| Error::io(file, e))?;
    }
    Ok(())
}

fn cells_out<W: Write, const K: usize>(
    out: &mut Out<W>,
    kw: &str,
    cells: &[[u32; K]],
    mut refs: impl FnMut(usize) -> i64,
    file: &str,
) -> Result<()> {
    out.s(kw);
    out.c(b'\n');
    out.int(cells.len());
    out.c(b'\n');
    for (i, c) in cells.iter().enumerate() {
        for &v in c {
            out.int(v as u64 + 1);
            out.c(b' ');
        }
        out.int(refs(i));
        out.c(b'\n');
        out.check().map_err(|e| Error::io(file, e))?;
    }
    Ok(())
}

/// Write a surface with ref = the region behind each triangle (`sides[t][0]`), and each
/// triangle with a region in front of it (`sides[t][1] != 0`) once more, reversed, with that
/// region as ref (see the module documentation).
pub fn write_surface<W: Write>(w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    if mesh.sides.len() != mesh.triangles.len() || mesh.sides.iter().all(|s| s[1] == 0) {
        return write_surface_with_refs(w, mesh, None, file);
    }
    let mut both = mesh.clone();
    for (t, s) in mesh.triangles.iter().zip(&mesh.sides) {
        if s[1] != 0 {
            both.triangles.push([t[0], t[2], t[1]]);
            both.sides.push([s[1], s[0]]);
        }
    }
    write_surface_with_refs(w, &both, None, file)
}

/// Write a surface with the given triangle refs (or the back regions when `None`).
pub fn write_surface_with_refs<W: Write>(
    w: W,
    mesh: &SurfaceMesh,
    refs: Option<&[i32]>,
    file: &str,
) -> Result<()> {
    check_surface(mesh, file)?;
    if let Some(r) = refs
        && r.len() != mesh.triangles.len()
    {
        return Err(Error::invalid(
            file,
            format!("{} refs for {} triangles", r.len(), mesh.triangles.len()),
        ));
    }
    let mut out = Out::new(w);
    out.s("MeshVersionFormatted 2\nDimension 3\n");
    vertices3(&mut out, &mesh.points, file)?;
    cells_out(
        &mut out,
        "Triangles",
        &mesh.triangles,
        |i| match refs {
            Some(r) => r[i] as i64,
            None => mesh.sides.get(i).map_or(1, |s| s[0]) as i64,
        },
        file,
    )?;
    out.s("End\n");
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}

/// Write a tet mesh: vertices, tets with ref = label, and the boundary and interface triangles
/// with their group ref (see the module documentation).
pub fn write_tet<W: Write>(w: W, mesh: &TetMesh, file: &str) -> Result<()> {
    check_tet(mesh, file)?;
    let g = face_groups(mesh);
    let mut out = Out::new(w);
    out.s("MeshVersionFormatted 2\nDimension 3\n");
    vertices3(&mut out, &mesh.points, file)?;
    cells_out(
        &mut out,
        "Tetrahedra",
        &mesh.tets,
        |i| mesh.labels[i] as i64,
        file,
    )?;
    cells_out(
        &mut out,
        "Triangles",
        &g.faces,
        |i| g.group_of[i] as i64 + 1,
        file,
    )?;
    out.s("End\n");
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}

/// Write a 2D triangle mesh (`Dimension 2`) with ref = label.
pub fn write_tri<W: Write>(w: W, mesh: &TriMesh, file: &str) -> Result<()> {
    check_tri(mesh, file)?;
    let mut out = Out::new(w);
    out.s("MeshVersionFormatted 2\nDimension 2\nVertices\n");
    out.int(mesh.points.len());
    out.c(b'\n');
    for p in &mesh.points {
        out.f64(p[0]);
        out.c(b' ');
        out.f64(p[1]);
        out.s(" 0\n");
        out.check().map_err(|e| Error::io(file, e))?;
    }
    cells_out(
        &mut out,
        "Triangles",
        &mesh.triangles,
        |i| mesh.labels[i] as i64,
        file,
    )?;
    out.s("End\n");
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}
