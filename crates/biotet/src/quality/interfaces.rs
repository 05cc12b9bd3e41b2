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

/// Every pair of labels that meet at a face of `mesh` (boundary faces pair a tet's label with
/// 0), by increasing pair. Uses the adjacency; a mesh whose adjacency is missing gives nothing.
pub fn interface_faces(mesh: &TetMesh) -> Vec<InterfaceFaces> {
    if mesh.neighbors.len() != mesh.tets.len() || mesh.labels.len() != mesh.tets.len() {
        return Vec::new();
    }
    let mut pairs: FxHashMap<[u32; 2], (u64, f64)> = FxHashMap::default();
    for (t, nb) in mesh.neighbors.iter().enumerate() {
        let a = mesh.labels[t];
        for (f, &n) in nb.iter().enumerate() {
            let b = if n == NO_NEIGHBOR {
                0
            } else if (n as usize) < t {
                continue; // counted from the other tet
            } else {
                mesh.labels.get(n as usize).copied().unwrap_or(0)
            };
            if a == b {
                continue;
            }
            let [p, q, r] = mesh.face(t, f).map(|v| mesh.points[v as usize]);
            let e = pairs.entry([a.min(b), a.max(b)]).or_insert((0, 0.0));
            e.0 += 1;
            e.1 += 0.5 * norm(cross(sub(q, p), sub(r, p)));
        }
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
