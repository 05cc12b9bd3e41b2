//! The library's integration tests: one binary, a module per topic.

mod check;
mod common;
mod delaunay;
mod forced;
mod image;
mod lastresort;
mod plane;
mod polish;
mod predicates;
mod quality;
mod remesh;
mod seeds;
mod shells;
mod side_labels;
mod sizing;
mod sizing_grid;
mod smooth;
mod surface;
mod template;
mod validate;
