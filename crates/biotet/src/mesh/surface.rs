//! Triangulated surfaces: the boundaries and internal interfaces a volume mesh must keep.

/// A triangle surface with the region label on each side of every triangle.
///
/// `sides[t] = [back, front]`: `front` is the region on the side the triangle's normal points to
/// (the normal of `(b - a) × (c - a)` for `triangles[t] = [a, b, c]`), `back` the region behind
/// it. Label 0 is the outside. A single closed, outward-oriented surface of region 1 has
/// `sides[t] = [1, 0]` for every triangle; an interface between regions 1 and 2 is an ordinary
/// triangle with `[1, 2]` or `[2, 1]`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceMesh {
    /// Point coordinates.
    pub points: Vec<[f64; 3]>,
    /// Three point indices per triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Region labels behind and in front of each triangle.
    pub sides: Vec<[u32; 2]>,
}

/// Whether `b` is triangle `a` with the same orientation (a rotation of its corners); `false`
/// for the reversed triangle and for other corners.
pub fn same_turn(a: [u32; 3], b: [u32; 3]) -> bool {
    (0..3).any(|r| [a[r], a[(r + 1) % 3], a[(r + 2) % 3]] == b)
}

impl SurfaceMesh {
    /// An icosphere of radius `r` centred at the origin: the icosahedron, `levels` times split
    /// into four, its points pushed onto the sphere at the end; outward, one region (label 1).
    /// A test and benchmark shape.
    pub fn icosphere(r: f64, levels: usize) -> SurfaceMesh {
        let g = (1.0 + 5f64.sqrt()) / 2.0;
        let mut p: Vec<[f64; 3]> = vec![
            [-1.0, g, 0.0],
            [1.0, g, 0.0],
            [-1.0, -g, 0.0],
            [1.0, -g, 0.0],
            [0.0, -1.0, g],
            [0.0, 1.0, g],
            [0.0, -1.0, -g],
            [0.0, 1.0, -g],
            [g, 0.0, -1.0],
            [g, 0.0, 1.0],
            [-g, 0.0, -1.0],
            [-g, 0.0, 1.0],
        ];
        let mut t: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..levels {
            let mut mid = std::collections::HashMap::new();
            let mut next = Vec::new();
            for tri in &t {
                let mut m = [0u32; 3];
                for k in 0..3 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    let key = (a.min(b), a.max(b));
                    m[k] = *mid.entry(key).or_insert_with(|| {
                        let (pa, pb) = (p[a as usize], p[b as usize]);
                        p.push([0, 1, 2].map(|i| (pa[i] + pb[i]) / 2.0));
                        (p.len() - 1) as u32
                    });
                }
                next.push([tri[0], m[0], m[2]]);
                next.push([tri[1], m[1], m[0]]);
                next.push([tri[2], m[2], m[1]]);
                next.push(m);
            }
            t = next;
        }
        for q in &mut p {
            let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            *q = q.map(|c| c * r / l);
        }
        Self::closed(p, t, 1)
    }

    /// A closed boundary of one region: every triangle gets `[label, 0]`.
    pub fn closed(points: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>, label: u32) -> SurfaceMesh {
        let sides = vec![[label, 0]; triangles.len()];
        SurfaceMesh {
            points,
            triangles,
            sides,
        }
    }

    /// Number of triangles.
    pub fn n_triangles(&self) -> usize {
        self.triangles.len()
    }

    /// The three corner coordinates of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [[f64; 3]; 3] {
        let v = self.triangles[t];
        [
            self.points[v[0] as usize],
            self.points[v[1] as usize],
            self.points[v[2] as usize],
        ]
    }

    /// Reverse the orientation of triangle `t` (swapping its two side labels with it).
    pub fn flip_triangle(&mut self, t: usize) {
        self.triangles[t].swap(1, 2);
        self.sides[t].swap(0, 1);
    }

    /// The distinct non-zero region labels, sorted.
    pub fn regions(&self) -> Vec<u32> {
        let mut r: Vec<u32> = self
            .sides
            .iter()
            .flatten()
            .copied()
            .filter(|&l| l != 0)
            .collect();
        r.sort_unstable();
        r.dedup();
        r
    }

    /// The number of points no triangle uses.
    pub fn n_unused_points(&self) -> usize {
        let mut used = vec![false; self.points.len()];
        for &v in self.triangles.iter().flatten() {
            if let Some(u) = used.get_mut(v as usize) {
                *u = true;
            }
        }
        used.iter().filter(|&&u| !u).count()
    }

    /// Drop the points no triangle uses, keeping the others' order; returns how many went.
    pub fn drop_unused_points(&mut self) -> usize {
        super::drop_unused_points(&mut self.points, self.triangles.as_flattened_mut(), 0)
    }

    /// Append another surface (points are not merged).
    pub fn append(&mut self, other: &SurfaceMesh) {
        let off = self.points.len() as u32;
        self.points.extend_from_slice(&other.points);
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + off, t[1] + off, t[2] + off]),
        );
        self.sides.extend_from_slice(&other.sides);
    }

    /// How many points repeat the coordinates of an earlier one (what [`Self::weld_exact`]
    /// would remove; -0.0 and 0.0 are the same coordinate).
    pub fn duplicate_points(&self) -> usize {
        let mut seen = rustc_hash::FxHashSet::default();
        self.points
            .iter()
            .filter(|p| !seen.insert(super::coord_key(p)))
            .count()
    }

    /// Merge points with exactly equal coordinates (as STL needs), keeping the first occurrence's
    /// index order; returns the number of points removed. Deterministic.
    pub fn weld_exact(&mut self) -> usize {
        let n = self.points.len();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let key = |p: &[f64; 3]| [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()];
        // -0.0 and 0.0 are the same point: normalise before comparing bits.
        for p in &mut self.points {
            for c in p.iter_mut() {
                if *c == 0.0 {
                    *c = 0.0;
                }
            }
        }
        order.sort_unstable_by_key(|&i| (key(&self.points[i as usize]), i));
        let mut rep = vec![0u32; n];
        let mut i = 0;
        while i < n {
            let mut j = i + 1;
            while j < n
                && key(&self.points[order[j] as usize]) == key(&self.points[order[i] as usize])
            {
                j += 1;
            }
            for k in i..j {
                rep[order[k] as usize] = order[i];
            }
            i = j;
        }
        // Renumber survivors in first-occurrence order.
        let mut new_id = vec![u32::MAX; n];
        let mut pts = Vec::new();
        for v in 0..n {
            if rep[v] == v as u32 {
                new_id[v] = pts.len() as u32;
                pts.push(self.points[v]);
            }
        }
        for t in &mut self.triangles {
            for v in t.iter_mut() {
                *v = new_id[rep[*v as usize] as usize];
            }
        }
        let removed = n - pts.len();
        self.points = pts;
        removed
    }
}
