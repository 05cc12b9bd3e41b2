//! The library's integration tests: one binary, a module per topic.

mod check;
mod common;
mod delaunay;
mod lastresort;
mod predicates;
mod quality;
mod validate;
