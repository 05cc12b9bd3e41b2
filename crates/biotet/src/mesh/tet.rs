//! Tetrahedral meshes.

/// Marks "no tet across this face" in [`TetMesh::neighbors`] (a boundary face).
pub const NO_NEIGHBOR: u32 = u32::MAX;

/// The face opposite local vertex `i` of a tet, as local vertex indices ordered so that the face
/// is counter-clockwise seen from outside the tet (its normal points away from vertex `i`) when
/// the tet is positively oriented. This is the one face table of the whole crate.
pub const TET_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// The six edges of a tet as local vertex pairs; edge `e` is opposite edge `5 - e`.
pub const TET_EDGES: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];

/// The other three local vertices of each local vertex, in increasing order.
pub const TET_OTHERS: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];

/// The edges of [`TET_EDGES`] from each local vertex to its [`TET_OTHERS`], in that order (the
/// three edges that change when the vertex moves).
pub const TET_EDGES_AT: [[usize; 3]; 4] = [[0, 1, 2], [0, 3, 4], [1, 3, 5], [2, 4, 5]];

/// A tetrahedral mesh: points, positively oriented tets, face adjacency and a region label per
/// tet.
///
/// `neighbors[t][i]` is the tet across the face opposite local vertex `i` of tet `t` (see
/// [`TET_FACES`]), or [`NO_NEIGHBOR`] on the boundary. Keep it in step with `tets` by calling
/// [`TetMesh::rebuild_neighbors`] after editing connectivity by hand.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TetMesh {
    /// Point coordinates.
    pub points: Vec<[f64; 3]>,
    /// Four point indices per tet, positively oriented (positive signed volume).
    pub tets: Vec<[u32; 4]>,
    /// Tet across each face, [`NO_NEIGHBOR`] for none.
    pub neighbors: Vec<[u32; 4]>,
    /// Region label per tet (a material or tissue id; 0 is reserved for "outside").
    pub labels: Vec<u32>,
}

impl TetMesh {
    /// A mesh from points, tets and labels; adjacency is computed. Faces shared by more than two
    /// tets keep only one pairing (the validity checker reports them).
    ///
    /// # Panics
    /// If `labels` and `tets` differ in length.
    pub fn new(points: Vec<[f64; 3]>, tets: Vec<[u32; 4]>, labels: Vec<u32>) -> TetMesh {
        assert_eq!(tets.len(), labels.len(), "one label per tet");
        let mut m = TetMesh {
            points,
            tets,
            neighbors: Vec::new(),
            labels,
        };
        m.rebuild_neighbors();
        m
    }

    /// Number of tets.
    pub fn n_tets(&self) -> usize {
        self.tets.len()
    }

    /// Number of points.
    pub fn n_points(&self) -> usize {
        self.points.len()
    }

    /// Bytes of the mesh's arrays by length (not capacity): 24 per point (coordinates), 36 per
    /// tet (corners 16, face neighbours 16, label 4).
    pub fn bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.points[..])
            + size_of_val(&self.tets[..])
            + size_of_val(&self.neighbors[..])
            + size_of_val(&self.labels[..])
    }

    /// The four corner coordinates of tet `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [[f64; 3]; 4] {
        let v = self.tets[t];
        [
            self.points[v[0] as usize],
            self.points[v[1] as usize],
            self.points[v[2] as usize],
            self.points[v[3] as usize],
        ]
    }

    /// Global vertex indices of face `f` of tet `t`, oriented outward (see [`TET_FACES`]).
    #[inline]
    pub fn face(&self, t: usize, f: usize) -> [u32; 3] {
        let v = self.tets[t];
        let l = TET_FACES[f];
        [v[l[0]], v[l[1]], v[l[2]]]
    }

    /// The distinct region labels, sorted.
    pub fn regions(&self) -> Vec<u32> {
        let mut r = self.labels.clone();
        r.sort_unstable();
        r.dedup();
        r
    }

    /// Recompute [`TetMesh::neighbors`] from [`TetMesh::tets`]. Returns the number of faces found
    /// in more than two tets (left unpaired beyond the first two).
    pub fn rebuild_neighbors(&mut self) -> usize {
        let (nb, over) = face_adjacency(&self.tets);
        self.neighbors = nb;
        over
    }

    /// Each region's connected components (its tets joined through shared faces), as
    /// `(label, components)` sorted by label. Uses [`TetMesh::neighbors`] when it is in step
    /// with the tets, else computes the adjacency.
    pub fn region_components(&self) -> Vec<(u32, usize)> {
        let rebuilt;
        let nb = if self.neighbors.len() == self.tets.len() {
            &self.neighbors
        } else {
            rebuilt = face_adjacency(&self.tets).0;
            &rebuilt
        };
        let n = self.tets.len();
        let mut sets = super::dsu::Dsu::new(n);
        let label = |t: usize| self.labels.get(t).copied().unwrap_or(0);
        for (t, across) in nb.iter().enumerate().take(n) {
            for &u in across {
                if u != NO_NEIGHBOR && (u as usize) < n && label(u as usize) == label(t) {
                    sets.union(t as u32, u);
                }
            }
        }
        let mut count: Vec<(u32, usize)> = Vec::new();
        for t in 0..n {
            if sets.find(t as u32) == t as u32 {
                match count.binary_search_by_key(&label(t), |c| c.0) {
                    Ok(i) => count[i].1 += 1,
                    Err(i) => count.insert(i, (label(t), 1)),
                }
            }
        }
        count
    }

    /// Boundary faces (no tet across), each as `(tet, local face)`.
    pub fn boundary_faces(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.neighbors.iter().enumerate().flat_map(|(t, nb)| {
            (0..4).filter_map(move |f| (nb[f] == NO_NEIGHBOR).then_some((t, f)))
        })
    }
}

/// A face key: the sorted vertex triple.
#[inline]
pub(crate) fn sorted3(mut f: [u32; 3]) -> [u32; 3] {
    if f[0] > f[1] {
        f.swap(0, 1);
    }
    if f[1] > f[2] {
        f.swap(1, 2);
    }
    if f[0] > f[1] {
        f.swap(0, 1);
    }
    f
}

/// Keep the tets `t` with `keep[t]`, in place, in their order; a neighbour dropped becomes
/// [`NO_NEIGHBOR`], the others are renumbered.
pub fn retain_tets(
    tets: &mut Vec<[u32; 4]>,
    neighbors: &mut Vec<[u32; 4]>,
    labels: &mut Vec<u32>,
    keep: &[bool],
) {
    let mut new_index = vec![NO_NEIGHBOR; tets.len()];
    let mut k = 0u32;
    for (slot, &kept) in new_index.iter_mut().zip(keep) {
        if kept {
            *slot = k;
            k += 1;
        }
    }
    // New index <= old index: moving down never overwrites a tet still to be moved.
    for t in 0..tets.len() {
        let new = new_index[t];
        if new == NO_NEIGHBOR {
            continue;
        }
        let nb = neighbors[t].map(|n| {
            if n == NO_NEIGHBOR {
                n
            } else {
                new_index[n as usize]
            }
        });
        let new = new as usize;
        tets[new] = tets[t];
        neighbors[new] = nb;
        labels[new] = labels[t];
    }
    let k = k as usize;
    tets.truncate(k);
    neighbors.truncate(k);
    labels.truncate(k);
}

/// Face adjacency of a tet array: `(neighbors, faces in more than two tets)`. Each face is
/// matched among the tets around its corner of fewest tets (a vertex-to-tet incidence built by
/// a counting sort): linear, no hashing, no sort, and 16 bytes per tet of scratch (the mesh
/// itself is 36), so it never sets a meshing run's peak memory. Deterministic: a face's two
/// tets of smallest index are paired.
pub fn face_adjacency(tets: &[[u32; 4]]) -> (Vec<[u32; 4]>, usize) {
    let n_vertices = tets.iter().flatten().max().map_or(0, |&m| m as usize + 1);
    let mut start = vec![0u32; n_vertices + 1];
    for &v in tets.iter().flatten() {
        start[v as usize + 1] += 1;
    }
    for i in 0..n_vertices {
        start[i + 1] += start[i];
    }
    // Tets around each vertex, in increasing tet order.
    let mut inc = vec![0u32; tets.len() * 4];
    let mut fill = start.clone();
    for (t, v) in tets.iter().enumerate() {
        for &x in v {
            inc[fill[x as usize] as usize] = t as u32;
            fill[x as usize] += 1;
        }
    }
    drop(fill);
    let around = |x: u32| &inc[start[x as usize] as usize..start[x as usize + 1] as usize];
    let mut nb = vec![[NO_NEIGHBOR; 4]; tets.len()];
    let mut over = 0;
    let mut found: Vec<(u32, usize)> = Vec::new();
    for (t, v) in tets.iter().enumerate() {
        for (f, l) in TET_FACES.iter().enumerate() {
            if nb[t][f] != NO_NEIGHBOR {
                continue;
            }
            let face = [v[l[0]], v[l[1]], v[l[2]]];
            let pivot = *face
                .iter()
                .min_by_key(|&&x| start[x as usize + 1] - start[x as usize])
                .unwrap_or(&face[0]);
            // Every tet holding the face, in tet order, with the face's local index.
            found.clear();
            for &u in around(pivot) {
                let w = tets[u as usize];
                if face.iter().all(|x| w.contains(x)) {
                    let k = (0..4).find(|&k| !face.contains(&w[k])).unwrap_or(0);
                    found.push((u, k));
                }
            }
            if found.len() >= 2 && found[0].0 == t as u32 {
                let ((a, fa), (b, fb)) = (found[0], found[1]);
                nb[a as usize][fa] = b;
                nb[b as usize][fb] = a;
                if found.len() > 2 {
                    over += 1;
                }
            }
        }
    }
    (nb, over)
}
