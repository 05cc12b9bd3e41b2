//! biotet: tetrahedral meshes from closed triangulated surfaces.
//!
//! The library follows the dissertation in `shared/seed` (template node deployment, LAST RESORT
//! boundary recovery and solid-angle smoothing). This crate holds the shared ground: the mesh
//! types ([`SurfaceMesh`], [`TetMesh`], [`TriMesh`]), the exact predicates every combinatorial
//! decision goes through ([`geom::predicates`]), the quality metrics ([`quality`]) and the
//! validity checks ([`check`], [`mesh::validate`]).
#![warn(missing_docs)]
#![deny(rustdoc::broken_intra_doc_links)]

pub mod check;
pub mod check2d;
pub mod delaunay;
pub mod delaunay2d;
pub mod geom;
pub mod image;
pub mod inset;
pub mod lastresort;
pub mod mesh;
pub mod pipeline;
pub mod pipeline2d;
pub mod polish;
pub mod quality;
pub mod recover2d;
pub mod remesh;
pub mod seeds;
pub mod sizing;
pub mod sizing_grid;
pub mod smooth;
pub mod star;
pub mod surface;
pub mod template;
pub mod text;

pub use mesh::surface::SurfaceMesh;
pub use mesh::tet::{NO_NEIGHBOR, TET_FACES, TetMesh};
pub use mesh::tri::{TRI_EDGES, TriMesh};

/// The thread count to run with when `asked` are asked for: at most four a core. Every result is
/// the same for any count, so threads past the cores only add their start-up and per-thread
/// scratch (two thousand took 25 s on a run of 0.01 s); a few a core are kept, so a 2-core
/// machine still runs (and tests) four.
pub fn usable_threads(asked: usize) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    asked.clamp(1, 4 * cores)
}

#[cfg(test)]
mod tests {
    #[test]
    fn threads_are_capped_at_four_a_core() {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        assert_eq!(super::usable_threads(1_000_000), 4 * cores);
        assert_eq!(super::usable_threads(4), 4);
        assert_eq!(super::usable_threads(1), 1);
        assert_eq!(super::usable_threads(0), 1);
    }
}
