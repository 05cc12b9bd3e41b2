//! How far a tet mesh's surface lies from a given surface: the two-sided distance between the
//! mesh's boundary and interface faces and the surface's triangles, all as one sheet. The same
//! measure for every mesher's output, whether it kept the surface (distance 0), moved it within
//! a tolerance (biotet's surface stage, MMG's `-hausd`) or approximated it (fTetWild's envelope).

use serde::Serialize;

use crate::SurfaceMesh;
use crate::mesh::tet::TetMesh;
use crate::quality::interfaces::labelled_faces;
use crate::surface::bvh::PatchIndex;
use crate::surface::hausdorff::one_sided;

/// The two-sided distance between a mesh's surface and a given surface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SurfaceDistance {
    /// Largest sampled distance from the given surface to the mesh's faces.
    pub in_to_out: f64,
    /// Largest sampled distance from the mesh's faces to the given surface.
    pub out_to_in: f64,
    /// An upper bound on the true two-sided distance (the larger maximum plus the samples'
    /// covering radius; the distance to a surface is 1-Lipschitz).
    pub bound: f64,
    /// The grid step of the samples on each triangle.
    pub spacing: f64,
    /// The mesh faces measured (boundary and interfaces).
    pub n_mesh_faces: usize,
    /// Samples measured, both ways.
    pub n_samples: usize,
}

/// The faces of `mesh` on its boundary or between two labels, each once.
pub fn surface_faces(mesh: &TetMesh) -> Vec<[u32; 3]> {
    labelled_faces(mesh)
        .map(|(t, f, _)| mesh.face(t, f))
        .collect()
}

/// The two-sided distance between `mesh`'s boundary and interface faces and `surface`, with
/// samples spaced `spacing` on each triangle (both as one sheet: every face is measured against
/// every triangle of the other side). `mesh` needs its adjacency and labels.
pub fn surface_distance(mesh: &TetMesh, surface: &SurfaceMesh, spacing: f64) -> SurfaceDistance {
    let faces = surface_faces(mesh);
    let one = |n: usize| vec![[0u32, 0u32]; n];
    let (mesh_sides, surf_sides) = (one(faces.len()), one(surface.triangles.len()));
    let to_mesh = PatchIndex::new(&mesh.points, &faces, &mesh_sides, None);
    let to_surface = PatchIndex::new(&surface.points, &surface.triangles, &surf_sides, None);
    let inf = f64::INFINITY;
    let io = one_sided(
        &surface.points,
        &surface.triangles,
        &surf_sides,
        None,
        &to_mesh,
        spacing,
        spacing,
        inf,
        inf,
        0.0,
    );
    let oi = one_sided(
        &mesh.points,
        &faces,
        &mesh_sides,
        None,
        &to_surface,
        spacing,
        spacing,
        inf,
        inf,
        0.0,
    );
    SurfaceDistance {
        in_to_out: io.max,
        out_to_in: oi.max,
        bound: io.bound.max(oi.bound),
        spacing,
        n_mesh_faces: faces.len(),
        n_samples: io.n_samples + oi.n_samples,
    }
}
