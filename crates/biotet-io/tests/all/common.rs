//! Synthetic meshes and comparisons shared by the tests (and the benchmark, which includes this
//! file by path).
#![allow(dead_code)]

use biotet::{SurfaceMesh, TetMesh, TriMesh};

/// Tiny deterministic generator (SplitMix64).
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The six Kuhn tets of the unit cube, by axis permutation; odd permutations are reoriented.
const PERMS: [([usize; 3], bool); 6] = [
    ([0, 1, 2], true),
    ([1, 2, 0], true),
    ([2, 0, 1], true),
    ([0, 2, 1], false),
    ([2, 1, 0], false),
    ([1, 0, 2], false),
];

/// A structured grid of `n³` cubes of size `h`, each split into 6 tets (conforming Kuhn
/// split), positively oriented. Points are `origin + h·(i, j, k)`, optionally jittered by up to
/// `jitter·h` (keeps every tet positive for `jitter` ≤ 0.05). `label(center)` labels each tet.
pub fn grid(n: usize, h: f64, jitter: f64, seed: u64, label: impl Fn([f64; 3]) -> u32) -> TetMesh {
    let m = n + 1;
    let id = |i: usize, j: usize, k: usize| (i + m * (j + m * k)) as u32;
    let mut rng = Rng(seed);
    let mut points = Vec::with_capacity(m * m * m);
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                let mut p = [0.3 + h * i as f64, -1.7 + h * j as f64, 0.1 + h * k as f64];
                if jitter > 0.0 {
                    for c in &mut p {
                        *c += (rng.f64() - 0.5) * 2.0 * jitter * h;
                    }
                }
                points.push(p);
            }
        }
    }
    let mut tets = Vec::with_capacity(6 * n * n * n);
    let mut labels = Vec::with_capacity(6 * n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                for (perm, even) in PERMS {
                    let mut c = [i, j, k];
                    let mut t = [id(c[0], c[1], c[2]); 4];
                    for (s, &axis) in perm.iter().enumerate() {
                        c[axis] += 1;
                        t[s + 1] = id(c[0], c[1], c[2]);
                    }
                    if !even {
                        t.swap(2, 3);
                    }
                    let mut ctr = [0.0; 3];
                    for &v in &t {
                        for d in 0..3 {
                            ctr[d] += points[v as usize][d] / 4.0;
                        }
                    }
                    tets.push(t);
                    labels.push(label(ctr));
                }
            }
        }
    }
    TetMesh::new(points, tets, labels)
}

/// A unit cube split into 6 tets, labels 1 (three tets) and 2 (three tets).
pub fn cube6() -> TetMesh {
    let mut m = grid(1, 1.0, 0.0, 0, |_| 1);
    for (t, l) in m.labels.iter_mut().enumerate() {
        *l = if t < 3 { 1 } else { 2 };
    }
    m
}

/// A moderate mesh: 10³ jittered cubes (6000 tets), three labels (a ball, and two halves).
pub fn moderate() -> TetMesh {
    let c = [0.3 + 0.5 * 1.1, -1.7 + 0.5 * 1.1, 0.1 + 0.5 * 1.1];
    grid(10, 0.11, 0.04, 7, move |p| {
        let d2: f64 = (0..3).map(|k| (p[k] - c[k]).powi(2)).sum();
        if d2 < 0.3 * 0.3 {
            3
        } else if p[0] < c[0] {
            1
        } else {
            2
        }
    })
}

/// The canonical form of a tet under orientation-preserving vertex permutations: the smallest of
/// its 12 even permutations.
pub fn canon_tet(t: [u32; 4]) -> [u32; 4] {
    const EVEN: [[usize; 4]; 12] = [
        [0, 1, 2, 3],
        [0, 2, 3, 1],
        [0, 3, 1, 2],
        [1, 0, 3, 2],
        [1, 2, 0, 3],
        [1, 3, 2, 0],
        [2, 0, 1, 3],
        [2, 1, 3, 0],
        [2, 3, 0, 1],
        [3, 0, 2, 1],
        [3, 1, 0, 2],
        [3, 2, 1, 0],
    ];
    EVEN.iter()
        .map(|p| [t[p[0]], t[p[1]], t[p[2]], t[p[3]]])
        .min()
        .unwrap()
}

/// Same points (exactly), same tets in the same order up to even permutation, same labels.
pub fn assert_same_tet(a: &TetMesh, b: &TetMesh, ctx: &str) {
    assert_eq!(a.points.len(), b.points.len(), "{ctx}: point count");
    for (i, (p, q)) in a.points.iter().zip(&b.points).enumerate() {
        assert!(
            p.iter().zip(q).all(|(x, y)| x.to_bits() == y.to_bits()),
            "{ctx}: point {i}: {p:?} vs {q:?}"
        );
    }
    assert_eq!(a.tets.len(), b.tets.len(), "{ctx}: tet count");
    for (i, (s, t)) in a.tets.iter().zip(&b.tets).enumerate() {
        assert_eq!(canon_tet(*s), canon_tet(*t), "{ctx}: tet {i}");
    }
    assert_eq!(a.labels, b.labels, "{ctx}: labels");
}

/// Rotation of a triangle that puts its smallest index first (orientation kept).
pub fn canon_tri(t: [u32; 3]) -> [u32; 3] {
    let r = [t, [t[1], t[2], t[0]], [t[2], t[0], t[1]]];
    *r.iter().min().unwrap()
}

/// Same points, triangles up to rotation, labels.
pub fn assert_same_tri(a: &TriMesh, b: &TriMesh, ctx: &str) {
    assert_eq!(a.points.len(), b.points.len(), "{ctx}: point count");
    for (i, (p, q)) in a.points.iter().zip(&b.points).enumerate() {
        assert!(
            p.iter().zip(q).all(|(x, y)| x.to_bits() == y.to_bits()),
            "{ctx}: point {i}: {p:?} vs {q:?}"
        );
    }
    assert_eq!(
        a.triangles.len(),
        b.triangles.len(),
        "{ctx}: triangle count"
    );
    for (i, (s, t)) in a.triangles.iter().zip(&b.triangles).enumerate() {
        assert_eq!(canon_tri(*s), canon_tri(*t), "{ctx}: triangle {i}");
    }
    assert_eq!(a.labels, b.labels, "{ctx}: labels");
}

/// Same surface geometry: every triangle has the same corner coordinates in the same order (up
/// to rotation). Works across formats that renumber points (STL).
pub fn assert_same_surface_geometry(a: &SurfaceMesh, b: &SurfaceMesh, ctx: &str) {
    assert_eq!(
        a.triangles.len(),
        b.triangles.len(),
        "{ctx}: triangle count"
    );
    let bits = |p: [f64; 3]| p.map(|x| if x == 0.0 { 0u64 } else { x.to_bits() });
    for t in 0..a.triangles.len() {
        let ca = a.corners(t).map(bits);
        let cb = b.corners(t).map(bits);
        let rots = [cb, [cb[1], cb[2], cb[0]], [cb[2], cb[0], cb[1]]];
        assert!(rots.contains(&ca), "{ctx}: triangle {t}: {ca:?} vs {cb:?}");
    }
}

/// Same surface: points exactly, triangles up to rotation.
pub fn assert_same_surface(a: &SurfaceMesh, b: &SurfaceMesh, ctx: &str) {
    assert_eq!(a.points, b.points, "{ctx}: points");
    assert_eq!(
        a.triangles.len(),
        b.triangles.len(),
        "{ctx}: triangle count"
    );
    for (i, (s, t)) in a.triangles.iter().zip(&b.triangles).enumerate() {
        assert_eq!(canon_tri(*s), canon_tri(*t), "{ctx}: triangle {i}");
    }
}

/// A closed surface: the boundary of an `n × n × n` grid of unit cubes scaled by `h` (two
/// triangles per boundary square), outward, f32-representable coordinates when `h` is.
pub fn box_surface(n: usize, h: f64) -> SurfaceMesh {
    let m = grid(n, h, 0.0, 0, |_| 1);
    let mut used = vec![u32::MAX; m.points.len()];
    let mut points = Vec::new();
    let mut triangles = Vec::new();
    for (t, f) in m.boundary_faces() {
        let face = m.face(t, f).map(|v| {
            if used[v as usize] == u32::MAX {
                used[v as usize] = points.len() as u32;
                // Shift to f32-exact coordinates.
                let p = m.points[v as usize];
                points.push([p[0] - 0.3, p[1] + 1.7, p[2] - 0.1].map(|x| (x as f32) as f64));
            }
            used[v as usize]
        });
        triangles.push(face);
    }
    SurfaceMesh::closed(points, triangles, 1)
}

/// A 2D mesh: `n × n` squares split into two triangles each (counter-clockwise), jittered, with
/// labels 1 and 2 by x.
pub fn tri_grid(n: usize, jitter: f64) -> TriMesh {
    let m = n + 1;
    let mut rng = Rng(11);
    let mut points = Vec::new();
    for j in 0..m {
        for i in 0..m {
            let mut p = [0.1 * i as f64 + 0.05, 0.1 * j as f64 - 0.3];
            for c in &mut p {
                *c += (rng.f64() - 0.5) * 2.0 * jitter * 0.1;
            }
            points.push(p);
        }
    }
    let id = |i: usize, j: usize| (i + m * j) as u32;
    let mut tris = Vec::new();
    let mut labels = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let l = if i < n / 2 { 1 } else { 2 };
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            labels.push(l);
            labels.push(l);
        }
    }
    TriMesh::new(points, tris, labels)
}
