//! The mesh types shared by every stage: [`surface::SurfaceMesh`] (input boundaries and
//! interfaces), [`tet::TetMesh`] (volume meshes) and [`tri::TriMesh`] (2D meshes), plus surface
//! validation ([`validate`]).
//!
//! All three are flat arrays with `u32` indices, cheap to hand to numpy, VTK or a solver.

pub mod cavity;
pub mod inside;
pub mod pslg;
pub mod shells;
pub mod side_labels;
pub mod surface;
pub mod tet;
pub mod tri;
pub mod validate;

/// The exact identity of a point's coordinates, for matching points across meshes (`-0.0` and
/// `0.0` are the same point).
#[inline]
pub fn coord_key(p: &[f64; 3]) -> [u64; 3] {
    p.map(|c| if c == 0.0 { 0 } else { c.to_bits() })
}
