//! Tests of biotet-io: one binary, a module per topic.

mod atomic;
mod common;
mod dispatch;
mod external;
mod grid;
mod label_image;
mod malformed;
mod pslg;
mod real_data;
mod surface;
mod tet;
mod tri;
