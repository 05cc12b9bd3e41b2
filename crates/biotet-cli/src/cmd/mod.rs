//! One module per subcommand, plus the shared input handling.

pub mod check;
pub mod convert;
pub mod delaunay;
pub mod extract;
pub mod improve;
pub mod input;
pub mod mesh;
pub mod plane;
pub mod quality;
pub mod recover;
pub mod remesh;
pub mod smooth;
pub mod surface;
pub mod validate;
pub mod view;
