//! Helpers shared by several formats: orientation repair, writer-side validation and the
//! boundary/interface face groups written by the tet writers.

use std::io::Read;

use biotet::geom::predicates::{Sign, orient2d, orient3d};
use biotet::mesh::tet::face_adjacency;
use biotet::{NO_NEIGHBOR, SurfaceMesh, TetMesh, TriMesh};

use crate::error::{Error, Result};

/// Read a whole stream into memory.
pub(crate) fn read_all<R: Read>(mut r: R, file: &str) -> Result<Vec<u8>> {
    let mut data = Vec::new();
    r.read_to_end(&mut data).map_err(|e| Error::io(file, e))?;
    Ok(data)
}

/// Bring a file's orientation convention to ours. Other tools may store every tet the other way
/// round (negative signed volume); when every non-degenerate tet is negative, all of them are
/// reoriented by swapping their last two vertices. A file that MIXES orientations holds inverted
/// elements: it is left as it is, so the checker and the quality report see them. Returns
/// `(flipped, degenerate)`; degenerate (zero-volume) tets are kept and counted.
pub fn orient_tets(points: &[[f64; 3]], tets: &mut [[u32; 4]]) -> (usize, usize) {
    let signs: Vec<Sign> = tets
        .iter()
        .map(|t| {
            let p = |i: usize| points[t[i] as usize];
            orient3d(p(0), p(1), p(2), p(3))
        })
        .collect();
    reorient(&signs, tets, |t| t.swap(2, 3))
}

/// Like [`orient_tets`] for 2D triangles: a file that is clockwise throughout is made
/// counter-clockwise; mixed orientations are left for the checker.
pub(crate) fn orient_tris(points: &[[f64; 2]], tris: &mut [[u32; 3]]) -> (usize, usize) {
    let signs: Vec<Sign> = tris
        .iter()
        .map(|t| {
            let p = |i: usize| points[t[i] as usize];
            orient2d(p(0), p(1), p(2))
        })
        .collect();
    reorient(&signs, tris, |t| t.swap(1, 2))
}

fn reorient<T>(signs: &[Sign], cells: &mut [T], flip: impl Fn(&mut T)) -> (usize, usize) {
    let negative = signs.iter().filter(|&&s| s == Sign::Negative).count();
    let degenerate = signs.iter().filter(|&&s| s == Sign::Zero).count();
    let all_negative = negative > 0 && negative + degenerate == signs.len();
    if !all_negative {
        return (0, degenerate);
    }
    for (c, &s) in cells.iter_mut().zip(signs) {
        if s == Sign::Negative {
            flip(c);
        }
    }
    (negative, degenerate)
}

/// The largest region label: the formats written (VTU's and Gmsh's Int32, numpy's int32 labels)
/// hold labels up to 2³¹ − 1, so larger ones are refused where they are read.
pub const MAX_LABEL: u32 = i32::MAX as u32;

/// `v` as a region label, if it is one (`0..=MAX_LABEL`): the one range check of every reader.
pub fn checked_label(v: i128) -> Option<u32> {
    u32::try_from(v).ok().filter(|&l| l <= MAX_LABEL)
}

/// A label from an integer read from a file.
pub(crate) fn label_of(v: i64) -> std::result::Result<u32, String> {
    checked_label(v.into()).ok_or_else(|| format!("region label {v} is not in 0..={MAX_LABEL}"))
}

/// A region label on one side of a surface triangle: [`label_of`], with
/// [`FROM_GEOMETRY`](biotet::mesh::side_labels::FROM_GEOMETRY) reserved.
pub(crate) fn side_label_of(v: i64) -> std::result::Result<u32, String> {
    match label_of(v)? {
        biotet::mesh::side_labels::FROM_GEOMETRY => Err(format!("region label {v} is reserved")),
        l => Ok(l),
    }
}

/// A label from a float attribute (TetGen writes attributes as reals).
pub(crate) fn label_of_f64(v: f64) -> std::result::Result<u32, String> {
    if v.fract() == 0.0 && (0.0..=f64::from(MAX_LABEL)).contains(&v) {
        Ok(v as u32)
    } else {
        Err(format!(
            "region attribute {v} is not an integer in 0..={MAX_LABEL}"
        ))
    }
}

/// Number of points as `u32`, or an error.
pub(crate) fn check_point_count(n: usize, file: &str) -> Result<()> {
    if n > u32::MAX as usize {
        return Err(Error::format(
            file,
            format!("{n} points do not fit 32-bit indices"),
        ));
    }
    Ok(())
}

fn check_points<const D: usize>(points: &[[f64; D]], file: &str) -> Result<()> {
    check_point_count(points.len(), file)?;
    for (i, p) in points.iter().enumerate() {
        if p.iter().any(|c| !c.is_finite()) {
            return Err(Error::invalid(
                file,
                format!("point {i} has a non-finite coordinate {p:?}"),
            ));
        }
    }
    Ok(())
}

fn check_cells<const K: usize>(cells: &[[u32; K]], n: usize, what: &str, file: &str) -> Result<()> {
    for (i, c) in cells.iter().enumerate() {
        if let Some(v) = c.iter().find(|&&v| v as usize >= n) {
            return Err(Error::invalid(
                file,
                format!("{what} {i}: vertex index {v} out of range ({n} points)"),
            ));
        }
    }
    Ok(())
}

/// Validate a surface before writing it.
pub(crate) fn check_surface(m: &SurfaceMesh, file: &str) -> Result<()> {
    check_points(&m.points, file)?;
    check_cells(&m.triangles, m.points.len(), "triangle", file)
}

/// A surface read from a format without labels, refs or polygons (FreeSurfer, GIfTI): checked
/// (indices in range, finite coordinates), every triangle `[1, 0]`.
pub(crate) fn plain_surface(
    points: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    file: &str,
) -> Result<crate::SurfaceRead> {
    let mesh = SurfaceMesh::closed(points, triangles, 1);
    check_surface(&mesh, file)?;
    Ok(crate::SurfaceRead {
        mesh,
        triangle_refs: None,
        side_labels: None,
        welded: 0,
        polygons_split: 0,
    })
}

/// Validate a surface with its side labels before writing them: one pair a triangle (or none: a
/// surface without labels), each label fitting a signed 32-bit integer (VTK's `Int32`).
pub(crate) fn check_sided_surface(m: &SurfaceMesh, file: &str) -> Result<()> {
    check_surface(m, file)?;
    let nt = m.triangles.len();
    if m.sides.len() != nt && !m.sides.is_empty() {
        return Err(Error::invalid(
            file,
            format!("{} side-label pairs for {nt} triangles", m.sides.len()),
        ));
    }
    if let Some((t, l)) = m.sides.iter().enumerate().find_map(|(t, s)| {
        s.iter()
            .find(|&&l| i32::try_from(l).is_err())
            .map(|&l| (t, l))
    }) {
        return Err(Error::invalid(
            file,
            format!("triangle {t}: label {l} does not fit Int32"),
        ));
    }
    Ok(())
}

/// Validate a tet mesh before writing it.
pub(crate) fn check_tet(m: &TetMesh, file: &str) -> Result<()> {
    if m.labels.len() != m.tets.len() {
        return Err(Error::invalid(
            file,
            format!("{} labels for {} tets", m.labels.len(), m.tets.len()),
        ));
    }
    check_points(&m.points, file)?;
    check_cells(&m.tets, m.points.len(), "tet", file)
}

/// Validate a triangle mesh before writing it.
pub(crate) fn check_tri(m: &TriMesh, file: &str) -> Result<()> {
    if m.labels.len() != m.triangles.len() {
        return Err(Error::invalid(
            file,
            format!(
                "{} labels for {} triangles",
                m.labels.len(),
                m.triangles.len()
            ),
        ));
    }
    check_points(&m.points, file)?;
    check_cells(&m.triangles, m.points.len(), "triangle", file)
}

/// One group of surface faces of a tet mesh: the outer boundary of a region, or the interface
/// between two regions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) struct FaceGroup {
    /// `false`: faces between region `a` and the outside (`b` = 0). `true`: faces between
    /// regions `a < b`.
    pub interface: bool,
    /// The region whose tets own the faces (faces are oriented outward from it).
    pub a: u32,
    /// The region on the other side (0 for the outside).
    pub b: u32,
}

impl FaceGroup {
    /// "boundary_a_0" or "interface_a_b".
    pub fn name(&self) -> String {
        if self.interface {
            format!("interface_{}_{}", self.a, self.b)
        } else {
            format!("boundary_{}_0", self.a)
        }
    }
}

/// Boundary and interface faces of a tet mesh, grouped.
pub(crate) struct FaceGroups {
    /// The groups, sorted: boundaries by region, then interfaces by region pair. A face's marker
    /// or ref in the Medit/Gmsh/TetGen writers is its group index + 1.
    pub groups: Vec<FaceGroup>,
    /// Faces (outward from the owning region), sorted by group, in tet order within a group.
    pub faces: Vec<[u32; 3]>,
    /// Group index of each face.
    pub group_of: Vec<u32>,
}

/// Collect the faces with no tet behind them and the faces between tets of different labels
/// (each once, oriented outward from the smaller label).
pub(crate) fn face_groups(m: &TetMesh) -> FaceGroups {
    let recomputed;
    let nb: &[[u32; 4]] = if m.neighbors.len() == m.tets.len() {
        &m.neighbors
    } else {
        recomputed = face_adjacency(&m.tets).0;
        &recomputed
    };
    let mut raw: Vec<(FaceGroup, u32)> = Vec::new();
    for (t, n) in nb.iter().enumerate() {
        let a = m.labels[t];
        for (f, &o) in n.iter().enumerate() {
            let g = if o == NO_NEIGHBOR {
                FaceGroup {
                    interface: false,
                    a,
                    b: 0,
                }
            } else {
                let b = m.labels[o as usize];
                if a >= b {
                    continue;
                }
                FaceGroup {
                    interface: true,
                    a,
                    b,
                }
            };
            raw.push((g, (t as u32) << 2 | f as u32));
        }
    }
    raw.sort_unstable();
    let mut groups: Vec<FaceGroup> = Vec::new();
    let mut faces = Vec::with_capacity(raw.len());
    let mut group_of = Vec::with_capacity(raw.len());
    for (g, tf) in raw {
        if groups.last() != Some(&g) {
            groups.push(g);
        }
        faces.push(m.face((tf >> 2) as usize, (tf & 3) as usize));
        group_of.push(groups.len() as u32 - 1);
    }
    FaceGroups {
        groups,
        faces,
        group_of,
    }
}

/// The triangles of polygon `c` (three corners or more) fanned from its first corner; a polygon
/// of more than three corners counts in `split`.
pub(crate) fn fan<'c>(c: &'c [u32], split: &mut usize) -> impl Iterator<Item = [u32; 3]> + 'c {
    if c.len() > 3 {
        *split += 1;
    }
    (1..c.len().saturating_sub(1)).map(move |k| [c[0], c[k], c[k + 1]])
}

/// The triangles of triangle strip `c`: triangle `j` is `j, j+1, j+2`, its first two corners
/// swapped for odd `j` so that all keep the strip's orientation.
pub(crate) fn strip(c: &[u32]) -> impl Iterator<Item = [u32; 3]> + '_ {
    (0..c.len().saturating_sub(2)).map(move |j| {
        if j % 2 == 0 {
            [c[j], c[j + 1], c[j + 2]]
        } else {
            [c[j + 1], c[j], c[j + 2]]
        }
    })
}
