//! The faces between regions of a tet mesh: per pair of labels, how many faces separate them
//! and their area (`[0, r]` is region `r`'s outer boundary).

use rustc_hash::FxHashMap;
use serde::Serialize;

use crate::geom::vec3::{cross, norm, sub};
use crate::mesh::tet::{NO_NEIGHBOR, TetMesh};

/// The faces between two regions (or a region and the outside) of a mesh.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InterfaceFaces {
    /// The two labels, smaller first (0 = outside: `[0, r]` is region r's boundary).
    pub labels: [u32; 2],
    /// Faces between them.
    pub n_faces: u64,
    /// Their total area.
    pub area: f64,
}

/// The faces of `mesh` between two labels, each once, as `(tet, local face, [its label, the
/// label across])` (0 across a boundary face). Uses the adjacency; a mesh whose adjacency or
/// labels are missing gives nothing.
pub fn labelled_faces(mesh: &TetMesh) -> impl Iterator<Item = (usize, usize, [u32; 2])> + '_ {
    let ok = mesh.neighbors.len() == mesh.tets.len() && mesh.labels.len() == mesh.tets.len();
    let n = if ok { mesh.tets.len() } else { 0 };
    (0..n).flat_map(move |t| {
        let a = mesh.labels[t];
        (0..4).filter_map(move |f| {
            let nb = mesh.neighbors[t][f];
            let b = if nb == NO_NEIGHBOR {
                0
            } else if (nb as usize) < t {
                return None; // met from the other tet
            } else {
                mesh.labels[nb as usize]
            };
            (a != b).then_some((t, f, [a, b]))
        })
    })
}

/// Every pair of labels that meet at a face of `mesh` (boundary faces pair a tet's label with
/// 0), by increasing pair. Uses the adjacency; a mesh whose adjacency is missing gives nothing.
pub fn interface_faces(mesh: &TetMesh) -> Vec<InterfaceFaces> {
    let mut pairs: FxHashMap<[u32; 2], (u64, f64)> = FxHashMap::default();
    for (t, f, [a, b]) in labelled_faces(mesh) {
        let [p, q, r] = mesh.face(t, f).map(|v| mesh.points[v as usize]);
        let e = pairs.entry([a.min(b), a.max(b)]).or_insert((0, 0.0));
        e.0 += 1;
        e.1 += 0.5 * norm(cross(sub(q, p), sub(r, p)));
    }
    let mut out: Vec<InterfaceFaces> = pairs
        .into_iter()
        .map(|(labels, (n_faces, area))| InterfaceFaces {
            labels,
            n_faces,
            area,
        })
        .collect();
    out.sort_unstable_by_key(|i| i.labels);
    out
}
