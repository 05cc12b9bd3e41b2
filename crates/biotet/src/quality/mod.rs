//! Element quality: per-element measures ([`tet`]) and whole-mesh reports ([`report`]).
//!
//! Measures are floating point on purpose: they rank and report, they never decide topology.

pub mod report;
pub mod tet;

pub use report::*;
pub use tet::*;
