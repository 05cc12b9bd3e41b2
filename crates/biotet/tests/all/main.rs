//! The library's integration tests: one binary, a module per topic.

mod check;
mod predicates;
mod quality;
mod validate;
