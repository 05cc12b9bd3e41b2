//! The mesh types shared by every stage: [`surface::SurfaceMesh`] (input boundaries and
//! interfaces), [`tet::TetMesh`] (volume meshes) and [`tri::TriMesh`] (2D meshes), plus surface
//! validation ([`validate`]).
//!
//! All three are flat arrays with `u32` indices, cheap to hand to numpy, VTK or a solver.

pub mod inside;
pub mod shells;
pub mod surface;
pub mod tet;
pub mod tri;
pub mod validate;
