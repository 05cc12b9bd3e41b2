//! biotet: tetrahedral meshes from closed triangulated surfaces.
//!
//! The library follows the dissertation in `shared/seed` (template node deployment, LAST RESORT
//! boundary recovery and solid-angle smoothing). This crate holds the shared ground: the mesh
//! types ([`SurfaceMesh`], [`TetMesh`], [`TriMesh`]), the exact predicates every combinatorial
//! decision goes through ([`geom::predicates`]), the quality metrics ([`quality`]) and the
//! validity checks ([`check`], [`mesh::validate`]).
#![warn(missing_docs)]
#![deny(rustdoc::broken_intra_doc_links)]

pub mod check;
pub mod check2d;
pub mod delaunay;
pub mod delaunay2d;
pub mod geom;
pub mod image;
pub mod lastresort;
pub mod mesh;
pub mod pipeline;
pub mod pipeline2d;
pub mod polish;
pub mod quality;
pub mod recover2d;
pub mod remesh;
pub mod sizing;
pub mod sizing_grid;
pub mod smooth;
pub mod surface;
pub mod template;

pub use mesh::surface::SurfaceMesh;
pub use mesh::tet::{NO_NEIGHBOR, TET_FACES, TetMesh};
pub use mesh::tri::{TRI_EDGES, TriMesh};
