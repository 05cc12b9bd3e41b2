//! Readers and writers for the mesh files biotet reads and writes.
//!
//! | kind | formats (extension, case-insensitive) | read | write |
//! |---|---|---|---|
//! | surface ([`SurfaceMesh`]) | STL `.stl` (ASCII/binary), OBJ `.obj`, OFF `.off`, PLY `.ply` (ASCII/binary LE/BE), Medit `.mesh`, VTU `.vtu` (triangles with side labels), VTP `.vtp` (poly data, [`vtp`]), legacy VTK `.vtk` ([`vtk`]; written binary) | ✓ | ✓ |
//! | tet mesh ([`TetMesh`]) | VTU `.vtu`, legacy VTK `.vtk` ([`vtk`]; written binary), Medit `.mesh`, Gmsh `.msh` (4.1 ASCII/binary, 2.2 ASCII), TetGen `.node`/`.ele`(/`.face`) | ✓ | ✓ |
//! | 2D mesh ([`TriMesh`]) | Medit `.mesh` (`Dimension 2`), Triangle `.node`/`.ele` | ✓ | ✓ |
//! | 2D mesh ([`TriMesh`]) | VTU `.vtu`, Gmsh `.msh` (2.2 ASCII) | | ✓ |
//! | PSLG ([`biotet::mesh::pslg::Pslg`]) | Triangle `.poly`, `.node`/`.edge`, Medit `.mesh` (`Dimension 2`, `Edges`) ([`poly`]) | ✓ | `.poly` |
//! | scalar grid ([`ScalarGrid`](biotet::sizing_grid::ScalarGrid)) | VTK ImageData `.vti`, NIfTI-1/2 `.nii`, `.nii.gz` ([`read_scalar_grid`], [`grid`]) | ✓ | |
//!
//! The path-based entry points ([`read_surface`], [`write_surface`], [`read_tet_mesh`],
//! [`write_tet_mesh`], [`read_tri_mesh`], [`write_tri_mesh`]) choose the format by extension;
//! [`mesh_kind`] tells which kind of mesh a path holds (peeking into `.mesh` and `.node`
//! files). Each format module also has stream-based functions (`read`/`parse`/`write`, generic
//! over [`std::io::Read`]/[`std::io::Write`], taking a file name for messages) for in-memory use.
//!
//! Conventions shared by all formats:
//! - Writers write shortest round-trip float text (`ryu`), so text formats are exact (binary
//!   STL, which stores `f32`, is the one lossy format). Writers reject meshes with non-finite
//!   coordinates or out-of-range indices ([`Error::InvalidMesh`]).
//! - Every write is atomic ([`atomic`]): temporary file(s) next to the target, renamed when
//!   complete; nothing is left behind on error.
//! - Tet and triangle readers bring a file's orientation convention to ours: when every
//!   non-degenerate tet has negative volume (by the exact
//!   [`biotet::geom::predicates::orient3d`]), all get their last two vertices swapped, counted in
//!   [`TetRead::flipped`]; likewise clockwise triangle meshes ([`TriRead::flipped`]). A file that
//!   mixes orientations holds inverted elements and is returned as it is, for the checker.
//! - Readers never panic on malformed input; every error names the file and the line (text) or
//!   element index (binary) and the reason ([`Error`]).
//! - Tet writers also store the boundary and interface faces between labels, grouped and
//!   numbered the same way everywhere (see [`medit`]): Medit triangle refs, Gmsh 2D physical
//!   groups `boundary_<a>_0`/`interface_<a>_<b>`, TetGen `.face` markers.
#![warn(missing_docs)]

use std::path::{Path, PathBuf};

pub use biotet::{SurfaceMesh, TetMesh, TriMesh};

pub mod atomic;
mod b64;
mod common;
pub mod error;
pub mod freesurfer;
pub mod gifti;
pub mod gmsh;
pub mod grid;
pub mod image;
pub mod limits;
pub mod medit;
pub mod obj;
pub mod off;
pub mod plane_out;
pub mod ply;
pub mod points;
pub mod poly;
pub mod stl;
pub mod tetgen;
mod text;
pub mod vtk;
mod vtk_out;
mod vtkxml;
pub mod vtp;
pub mod vtu;
mod vtu_out;

pub use common::{MAX_LABEL, checked_label, orient_tets};
pub use error::{Error, Result};
pub use grid::{read_scalar_grid, read_scalar_grid_named};
pub use image::{is_label_image, read_label_image};
pub use points::read_points;
pub use poly::{PslgRead, is_pslg, read_pslg};
pub use tetgen::{TetgenFiles, TetgenOptions};
pub use vtu::VtuEncoding;

/// A surface read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceRead {
    /// The surface; every triangle has sides `[1, 0]` (a closed outward surface of region 1).
    pub mesh: SurfaceMesh,
    /// Per-triangle refs when the file has them (Medit triangle refs; a PLY face property named
    /// `ref`, `label`, `region` or `marker`).
    pub triangle_refs: Option<Vec<i32>>,
    /// Region labels on both sides of each triangle, `[back, front]` as in
    /// [`SurfaceMesh::sides`], when the file gives them (a PLY or VTU two-label attribute;
    /// Medit refs naming the region behind each triangle, see [`medit`]), else `None`. A side
    /// the file leaves to the geometry is [`biotet::mesh::side_labels::FROM_GEOMETRY`];
    /// [`biotet::mesh::side_labels::resolve`] fills it and checks the rest.
    pub side_labels: Option<Vec<[u32; 2]>>,
    /// Points removed by welding exact duplicates (STL only; 0 otherwise).
    pub welded: usize,
    /// Polygonal faces (more than three corners) split into fans of triangles (OBJ, OFF, PLY).
    pub polygons_split: usize,
}

/// A tet mesh read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct TetRead {
    /// The mesh, every tet positively oriented (or degenerate), adjacency built.
    pub mesh: TetMesh,
    /// Tets that had negative volume and were fixed by swapping two vertices.
    pub flipped: usize,
    /// Tets of exactly zero volume (kept as they are).
    pub degenerate: usize,
    /// Volume elements other than linear tets (hexahedra, prisms, quadratic tets, ...) that
    /// were ignored.
    pub skipped_elements: usize,
}

/// A 2D triangle mesh read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct TriRead {
    /// The mesh, every triangle counter-clockwise (or degenerate), adjacency built.
    pub mesh: TriMesh,
    /// Clockwise triangles fixed by swapping two vertices.
    pub flipped: usize,
    /// Triangles of exactly zero area (kept).
    pub degenerate: usize,
}

macro_rules! deref_to_mesh {
    ($t:ty, $m:ty) => {
        /// Gives the mesh's fields directly (`read.points`), and lets `&read` be passed where a
        /// mesh reference is expected.
        impl std::ops::Deref for $t {
            type Target = $m;
            fn deref(&self) -> &$m {
                &self.mesh
            }
        }
    };
}
deref_to_mesh!(SurfaceRead, SurfaceMesh);
deref_to_mesh!(TetRead, TetMesh);
deref_to_mesh!(TriRead, TriMesh);

/// Which kind of mesh a file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MeshKind {
    /// A triangulated surface in 3D.
    Surface,
    /// A tetrahedral mesh.
    Tetrahedra,
    /// A 2D triangle mesh.
    Triangles2d,
}

/// Surface file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SurfaceFormat {
    /// STL; read: ASCII or binary (detected); write: binary.
    Stl,
    /// ASCII STL (write; reading detects).
    StlAscii,
    /// Wavefront OBJ.
    Obj,
    /// OFF.
    Off,
    /// PLY; read: any encoding; write: binary little endian.
    Ply,
    /// ASCII PLY (write; reading detects).
    PlyAscii,
    /// Medit `.mesh` (`Dimension 3`, `Triangles`).
    Medit,
    /// VTK XML unstructured grid `.vtu` of triangles with side labels ([`vtu::parse_surface`]).
    Vtu,
    /// VTK XML poly data `.vtp` (polygons and strips; side labels as in `.vtu`, see [`vtp`]).
    Vtp,
    /// Legacy VTK `.vtk` (read: [`vtk`]; written binary, `POLYDATA` with `sides`).
    Vtk,
    /// GIfTI `.gii` (`.surf.gii`; see [`gifti`]).
    Gifti,
    /// A FreeSurfer triangle surface (`lh.pial`, `rh.white`, …; recognised by its first bytes,
    /// or named `.surf`; see [`freesurfer`]).
    FreeSurfer,
}

/// Tet mesh file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TetFormat {
    /// VTK XML unstructured grid `.vtu`.
    Vtu,
    /// Medit `.mesh`.
    Medit,
    /// Gmsh `.msh` (write: 4.1 ASCII).
    Gmsh,
    /// Gmsh `.msh` 4.1 binary (write; reading detects).
    GmshBinary,
    /// TetGen `.node`/`.ele`/`.face` (see [`tetgen`] for the naming rule).
    TetGen,
    /// Legacy VTK `.vtk` (read: [`vtk`]; written binary, `UNSTRUCTURED_GRID` with `region`).
    Vtk,
}

/// 2D triangle mesh file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TriFormat {
    /// Medit `.mesh` with `Dimension 2`.
    Medit,
    /// Triangle `.node`/`.ele`.
    Triangle,
    /// VTU (write only, see [`plane_out`]).
    Vtu,
    /// Gmsh `.msh` 2.2 ASCII (write only, see [`plane_out`]).
    Gmsh,
}

/// Supported surface extensions, for messages.
pub const SURFACE_EXTENSIONS: &str = ".stl, .obj, .off, .ply, .mesh, .vtu, .vtp, .vtk, .gii, .surf or a FreeSurfer surface (lh.pial)";
/// Supported tet mesh extensions, for messages.
pub const TET_EXTENSIONS: &str = ".vtu, .vtk, .mesh, .msh, .node/.ele (TetGen)";
/// Supported 2D mesh extensions, for messages.
pub const TRI_EXTENSIONS: &str = ".mesh, .node/.ele (Triangle); writing also .vtu, .msh";
const ALL_EXTENSIONS: &str = ".stl, .obj, .off, .ply, .mesh, .vtu, .vtp, .vtk, .msh, .node, .ele, \
                              .gii, .surf or a FreeSurfer surface (lh.pial)";

/// The lower-case extension of a path.
fn ext(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default()
}

fn name(path: &Path) -> String {
    path.display().to_string()
}

impl SurfaceFormat {
    /// The format named by a path's extension.
    pub fn from_path(path: &Path) -> Result<SurfaceFormat> {
        Ok(match ext(path).as_str() {
            "stl" => SurfaceFormat::Stl,
            "obj" => SurfaceFormat::Obj,
            "off" => SurfaceFormat::Off,
            "ply" => SurfaceFormat::Ply,
            "mesh" => SurfaceFormat::Medit,
            "vtu" => SurfaceFormat::Vtu,
            "vtp" => SurfaceFormat::Vtp,
            "vtk" => SurfaceFormat::Vtk,
            "surf" => SurfaceFormat::FreeSurfer,
            "gii" => SurfaceFormat::Gifti,
            _ if starts_freesurfer(path) => SurfaceFormat::FreeSurfer,
            _ => {
                return Err(Error::UnknownExtension {
                    path: name(path),
                    kind: "surface",
                    supported: SURFACE_EXTENSIONS,
                });
            }
        })
    }
}

impl TetFormat {
    /// The format named by a path's extension.
    pub fn from_path(path: &Path) -> Result<TetFormat> {
        Ok(match ext(path).as_str() {
            "vtu" => TetFormat::Vtu,
            "mesh" => TetFormat::Medit,
            "msh" => TetFormat::Gmsh,
            "node" | "ele" | "face" => TetFormat::TetGen,
            "vtk" => TetFormat::Vtk,
            _ => {
                return Err(Error::UnknownExtension {
                    path: name(path),
                    kind: "tet mesh",
                    supported: TET_EXTENSIONS,
                });
            }
        })
    }
}

impl TriFormat {
    /// The format named by a path's extension.
    pub fn from_path(path: &Path) -> Result<TriFormat> {
        Ok(match ext(path).as_str() {
            "mesh" => TriFormat::Medit,
            "node" | "ele" => TriFormat::Triangle,
            "vtu" => TriFormat::Vtu,
            "msh" => TriFormat::Gmsh,
            _ => {
                return Err(Error::UnknownExtension {
                    path: name(path),
                    kind: "triangle mesh",
                    supported: TRI_EXTENSIONS,
                });
            }
        })
    }
}

/// Which kind of mesh `path` holds: by extension, looking inside `.mesh` files (their
/// `Dimension` and whether they have tetrahedra, see [`medit::peek_kind`]), `.vtu` and `.vtk`
/// files (volume or surface cells, [`vtu::peek_kind`], [`vtk::peek_kind`]) and TetGen/Triangle
/// `.node`/`.ele` files (the dimension in the `.node` header).
pub fn mesh_kind(path: &Path) -> Result<MeshKind> {
    match ext(path).as_str() {
        "stl" | "obj" | "off" | "ply" | "vtp" | "surf" | "gii" => Ok(MeshKind::Surface),
        "msh" => Ok(MeshKind::Tetrahedra),
        // Unreadable: by extension; reading it will say why.
        "vtu" => match atomic::read_file(path) {
            Ok(data) => vtu::peek_kind(&data, &name(path)),
            Err(_) => Ok(MeshKind::Tetrahedra),
        },
        "vtk" => match atomic::read_file(path) {
            Ok(data) => vtk::peek_kind(&data, &name(path)),
            Err(_) => Ok(MeshKind::Tetrahedra),
        },
        "mesh" => medit::peek_kind(atomic::open(path)?, &name(path)),
        "node" | "ele" => {
            let node = tetgen::files(path).node;
            match tetgen::peek_dim(atomic::open(&node)?, &name(&node))? {
                2 => Ok(MeshKind::Triangles2d),
                _ => Ok(MeshKind::Tetrahedra),
            }
        }
        _ if starts_freesurfer(path) => Ok(MeshKind::Surface),
        _ => Err(Error::UnknownExtension {
            path: name(path),
            kind: "mesh",
            supported: ALL_EXTENSIONS,
        }),
    }
}

/// Whether the file at `path` starts as a FreeSurfer surface does (their names, `lh.pial`,
/// carry no format extension).
fn starts_freesurfer(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 3];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|_| freesurfer::is_freesurfer(&head))
}

/// Read a surface, choosing the format by extension.
pub fn read_surface(path: &Path) -> Result<SurfaceRead> {
    read_surface_as(path, SurfaceFormat::from_path(path)?)
}

/// Read a surface in the given format.
pub fn read_surface_as(path: &Path, format: SurfaceFormat) -> Result<SurfaceRead> {
    let data = atomic::read_file(path)?;
    let n = name(path);
    match format {
        SurfaceFormat::Stl | SurfaceFormat::StlAscii => stl::parse(&data, &n),
        SurfaceFormat::Obj => obj::parse(&data, &n),
        SurfaceFormat::Off => off::parse(&data, &n),
        SurfaceFormat::Ply | SurfaceFormat::PlyAscii => ply::parse(&data, &n),
        SurfaceFormat::Medit => medit::parse_surface(&data, &n),
        SurfaceFormat::Vtu => vtu::parse_surface(&data, &n),
        SurfaceFormat::Vtp => vtp::parse_surface(&data, &n),
        SurfaceFormat::Vtk => vtk::parse_surface(&data, &n),
        SurfaceFormat::FreeSurfer => freesurfer::parse(&data, &n),
        SurfaceFormat::Gifti => gifti::parse(&data, &n),
    }
}

/// Write a surface, choosing the format by extension (`.stl` binary, `.ply` binary). Side labels
/// go where the format holds them (`.vtu`, `.vtp`, `.vtk` `sides`; `.ply` when some side is not
/// `[1, 0]`; `.mesh` refs); a surface whose `sides` is empty is written without them.
pub fn write_surface(path: &Path, mesh: &SurfaceMesh) -> Result<()> {
    write_surface_as(path, mesh, SurfaceFormat::from_path(path)?)
}

/// Write a surface in the given format, atomically.
pub fn write_surface_as(path: &Path, mesh: &SurfaceMesh, format: SurfaceFormat) -> Result<()> {
    let n = name(path);
    atomic::write_atomic(path, |w| match format {
        SurfaceFormat::Stl => stl::write_binary(w, mesh, &n),
        SurfaceFormat::StlAscii => stl::write_ascii(w, mesh, &n),
        SurfaceFormat::Obj => obj::write(w, mesh, &n),
        SurfaceFormat::Off => off::write(w, mesh, &n),
        SurfaceFormat::Ply => ply::write_binary(w, mesh, &n),
        SurfaceFormat::PlyAscii => ply::write_ascii(w, mesh, &n),
        SurfaceFormat::Medit => medit::write_surface(w, mesh, &n),
        SurfaceFormat::Vtu => vtu::write_surface(w, mesh, &n),
        SurfaceFormat::Vtp => vtp::write_surface(w, mesh, &n),
        SurfaceFormat::Vtk => vtk_out::write_surface(w, mesh, &n),
        SurfaceFormat::FreeSurfer => freesurfer::write(w, mesh, &n),
        SurfaceFormat::Gifti => gifti::write(w, mesh, &n),
    })
}

/// Read a tet mesh, choosing the format by extension (TetGen: `.node` or `.ele`, reading both).
pub fn read_tet_mesh(path: &Path) -> Result<TetRead> {
    read_tet_mesh_as(path, TetFormat::from_path(path)?)
}

/// Read a tet mesh in the given format.
pub fn read_tet_mesh_as(path: &Path, format: TetFormat) -> Result<TetRead> {
    let n = name(path);
    match format {
        TetFormat::Vtu => vtu::parse_tet(&atomic::read_file(path)?, &n),
        TetFormat::Vtk => vtk::parse_tet(&atomic::read_file(path)?, &n),
        TetFormat::Medit => medit::parse_tet(&atomic::read_file(path)?, &n),
        TetFormat::Gmsh | TetFormat::GmshBinary => gmsh::parse_tet(&atomic::read_file(path)?, &n),
        TetFormat::TetGen => {
            let f = tetgen::files(path);
            tetgen::parse_tet(
                &atomic::read_file(&f.node)?,
                &atomic::read_file(&f.ele)?,
                &name(&f.base),
            )
        }
    }
}

/// Write a tet mesh, choosing the format by extension; returns the files written (TetGen
/// writes three: see [`tetgen`] for the naming rule).
pub fn write_tet_mesh(path: &Path, mesh: &TetMesh) -> Result<Vec<PathBuf>> {
    write_tet_mesh_as(path, mesh, TetFormat::from_path(path)?)
}

/// Write a tet mesh in the given format, atomically; returns the files written.
pub fn write_tet_mesh_as(path: &Path, mesh: &TetMesh, format: TetFormat) -> Result<Vec<PathBuf>> {
    let n = name(path);
    let one = |f: &dyn Fn(&mut atomic::AtomicWriter) -> Result<()>| -> Result<Vec<PathBuf>> {
        atomic::write_atomic(path, f)?;
        Ok(vec![path.to_path_buf()])
    };
    match format {
        TetFormat::Vtu => one(&|w| vtu::write_tet(w, mesh, &n)),
        TetFormat::Vtk => one(&|w| vtk_out::write_tet(w, mesh, &n)),
        TetFormat::Medit => one(&|w| medit::write_tet(w, mesh, &n)),
        TetFormat::Gmsh => one(&|w| gmsh::write_tet(w, mesh, &n)),
        TetFormat::GmshBinary => one(&|w| gmsh::write_tet_binary(w, mesh, &n)),
        TetFormat::TetGen => {
            let f = tetgen::files(path);
            let paths = vec![f.node.clone(), f.ele.clone(), f.face.clone()];
            let base = name(&f.base);
            atomic::write_atomic_many(&paths, |ws| {
                let [a, b, c] = ws else {
                    unreachable!("three writers")
                };
                tetgen::write_tet(a, b, Some(c), mesh, &base, TetgenOptions::default())
            })?;
            Ok(paths)
        }
    }
}

/// Read a 2D triangle mesh, choosing the format by extension.
pub fn read_tri_mesh(path: &Path) -> Result<TriRead> {
    read_tri_mesh_as(path, TriFormat::from_path(path)?)
}

/// Read a 2D triangle mesh in the given format.
pub fn read_tri_mesh_as(path: &Path, format: TriFormat) -> Result<TriRead> {
    match format {
        TriFormat::Medit => medit::parse_tri(&atomic::read_file(path)?, &name(path)),
        TriFormat::Triangle => {
            let f = tetgen::files(path);
            tetgen::parse_tri(
                &atomic::read_file(&f.node)?,
                &atomic::read_file(&f.ele)?,
                &name(&f.base),
            )
        }
        TriFormat::Vtu | TriFormat::Gmsh => Err(Error::format(
            &name(path),
            "2D meshes are read from .mesh or .node/.ele; .vtu and .msh are written only",
        )),
    }
}

/// Write a 2D triangle mesh, choosing the format by extension; returns the files written.
pub fn write_tri_mesh(path: &Path, mesh: &TriMesh) -> Result<Vec<PathBuf>> {
    write_tri_mesh_as(path, mesh, TriFormat::from_path(path)?)
}

/// Write a 2D triangle mesh in the given format, atomically; returns the files written
/// (Triangle: `base.node` and `base.ele`, named as in [`tetgen`]).
pub fn write_tri_mesh_as(path: &Path, mesh: &TriMesh, format: TriFormat) -> Result<Vec<PathBuf>> {
    match format {
        TriFormat::Medit => {
            atomic::write_atomic(path, |w| medit::write_tri(w, mesh, &name(path)))?;
            Ok(vec![path.to_path_buf()])
        }
        TriFormat::Triangle => {
            let f = tetgen::files(path);
            let paths = vec![f.node.clone(), f.ele.clone()];
            let base = name(&f.base);
            atomic::write_atomic_many(&paths, |ws| {
                let [a, b] = ws else {
                    unreachable!("two writers")
                };
                tetgen::write_tri(a, b, mesh, &base, TetgenOptions::default())
            })?;
            Ok(paths)
        }
        TriFormat::Vtu => {
            atomic::write_atomic(path, |w| plane_out::write_vtu(w, mesh, &name(path)))?;
            Ok(vec![path.to_path_buf()])
        }
        TriFormat::Gmsh => {
            atomic::write_atomic(path, |w| plane_out::write_msh(w, mesh, &name(path)))?;
            Ok(vec![path.to_path_buf()])
        }
    }
}
