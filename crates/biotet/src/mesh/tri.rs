//! 2D triangle meshes.

use super::tet::NO_NEIGHBOR;

/// The edge opposite local vertex `i` of a triangle, counter-clockwise along the boundary of a
/// counter-clockwise triangle.
pub const TRI_EDGES: [[usize; 2]; 3] = [[1, 2], [2, 0], [0, 1]];

/// A 2D triangle mesh: points, counter-clockwise triangles, edge adjacency and a region label per
/// triangle. `neighbors[t][i]` is the triangle across the edge opposite local vertex `i`, or
/// [`NO_NEIGHBOR`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Point coordinates.
    pub points: Vec<[f64; 2]>,
    /// Three point indices per triangle, counter-clockwise.
    pub triangles: Vec<[u32; 3]>,
    /// Triangle across each edge, [`NO_NEIGHBOR`] for none.
    pub neighbors: Vec<[u32; 3]>,
    /// Region label per triangle.
    pub labels: Vec<u32>,
}

impl TriMesh {
    /// A mesh from points, triangles and labels; adjacency is computed.
    ///
    /// # Panics
    /// If `labels` and `triangles` differ in length.
    pub fn new(points: Vec<[f64; 2]>, triangles: Vec<[u32; 3]>, labels: Vec<u32>) -> TriMesh {
        assert_eq!(triangles.len(), labels.len(), "one label per triangle");
        let mut m = TriMesh {
            points,
            triangles,
            neighbors: Vec::new(),
            labels,
        };
        m.rebuild_neighbors();
        m
    }

    /// Number of triangles.
    pub fn n_triangles(&self) -> usize {
        self.triangles.len()
    }

    /// The three corner coordinates of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [[f64; 2]; 3] {
        let v = self.triangles[t];
        [
            self.points[v[0] as usize],
            self.points[v[1] as usize],
            self.points[v[2] as usize],
        ]
    }

    /// Recompute [`TriMesh::neighbors`]. Returns the number of edges found in more than two
    /// triangles.
    pub fn rebuild_neighbors(&mut self) -> usize {
        let mut keys: Vec<([u32; 2], u32)> = Vec::with_capacity(self.triangles.len() * 3);
        for (t, v) in self.triangles.iter().enumerate() {
            for (e, l) in TRI_EDGES.iter().enumerate() {
                let (a, b) = (v[l[0]], v[l[1]]);
                keys.push(([a.min(b), a.max(b)], (t as u32) << 2 | e as u32));
            }
        }
        keys.sort_unstable();
        let mut nb = vec![[NO_NEIGHBOR; 3]; self.triangles.len()];
        let mut over = 0;
        let mut i = 0;
        while i < keys.len() {
            let mut j = i + 1;
            while j < keys.len() && keys[j].0 == keys[i].0 {
                j += 1;
            }
            if j - i >= 2 {
                let (a, b) = (keys[i].1, keys[i + 1].1);
                nb[(a >> 2) as usize][(a & 3) as usize] = b >> 2;
                nb[(b >> 2) as usize][(b & 3) as usize] = a >> 2;
                if j - i > 2 {
                    over += 1;
                }
            }
            i = j;
        }
        self.neighbors = nb;
        over
    }
}
