//! Element quality: per-element measures ([`tet`] for tets, [`tri`] for 2D triangles) and
//! whole-mesh reports ([`report`]).
//!
//! Measures are floating point on purpose: they rank and report, they never decide topology.

pub mod distance;
pub mod forced;
pub mod interfaces;
pub mod report;
pub mod tet;
pub mod tri;

pub use interfaces::{InterfaceFaces, interface_faces};
pub use report::*;
pub use tet::*;
pub use tri::TriMeasures;
