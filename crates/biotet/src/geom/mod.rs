//! Geometry: exact predicates (the only place that decides signs), exact intersection tests
//! built from them, and small floating-point vector helpers for measures (never for decisions).

pub mod filter;
pub mod intersect;
pub mod predicates;
pub mod vec3;
