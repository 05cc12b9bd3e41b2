//! Small meshes shared by the test modules.

use biotet::geom::predicates::{Sign, orient3d};
use biotet::{SurfaceMesh, TetMesh};

/// The 8 corners of the cube [0, s]^3 offset by `o`, index = x + 2y + 4z.
pub fn cube_points(o: [f64; 3], s: f64) -> Vec<[f64; 3]> {
    (0..8)
        .map(|i| {
            [
                o[0] + s * (i & 1) as f64,
                o[1] + s * ((i >> 1) & 1) as f64,
                o[2] + s * ((i >> 2) & 1) as f64,
            ]
        })
        .collect()
}

/// Swap two vertices of every negatively oriented tet.
pub fn orient_all(points: &[[f64; 3]], tets: &mut [[u32; 4]]) {
    for t in tets {
        let c = t.map(|i| points[i as usize]);
        if orient3d(c[0], c[1], c[2], c[3]) == Sign::Negative {
            t.swap(2, 3);
        }
    }
}

/// The cube split into 6 tets around its main diagonal 0–7 (Kuhn/Freudenthal split).
pub fn cube6_tets(base: u32) -> Vec<[u32; 4]> {
    let axes = [1u32, 2, 4];
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    perms
        .iter()
        .map(|p| {
            let a = axes[p[0]];
            let b = a + axes[p[1]];
            [base, base + a, base + b, base + 7]
        })
        .collect()
}

/// A unit cube as 6 positively oriented tets, one region.
pub fn cube6() -> TetMesh {
    let pts = cube_points([0.0; 3], 1.0);
    let mut tets = cube6_tets(0);
    orient_all(&pts, &mut tets);
    TetMesh::new(pts, tets, vec![1; 6])
}

/// The outward-oriented boundary of the cube of [`cube_points`], 12 triangles, sides [1, 0].
pub fn cube_surface(o: [f64; 3], s: f64) -> SurfaceMesh {
    // Quads as corner indices, counter-clockwise seen from outside.
    let quads = [
        [0, 2, 3, 1], // z = 0, normal -z
        [4, 5, 7, 6], // z = 1
        [0, 1, 5, 4], // y = 0
        [2, 6, 7, 3], // y = 1
        [0, 4, 6, 2], // x = 0
        [1, 3, 7, 5], // x = 1
    ];
    let mut tris = Vec::new();
    for q in quads {
        // Split along the diagonal through corner 0 or 7 to match the Kuhn split's faces.
        if q.contains(&0) || q.contains(&7) {
            let k = q.iter().position(|&v| v == 0 || v == 7).unwrap_or(0);
            let r = |i: usize| q[(k + i) % 4];
            tris.push([r(0), r(1), r(2)]);
            tris.push([r(0), r(2), r(3)]);
        }
    }
    SurfaceMesh::closed(cube_points(o, s), tris, 1)
}

/// Two unit cubes side by side along x, labels 1 and 2, sharing the face x = 1.
pub fn two_cubes() -> TetMesh {
    let mut pts = cube_points([0.0; 3], 1.0);
    let right = cube_points([1.0, 0.0, 0.0], 1.0);
    // Reuse the shared face's points: right cube corners with x = 0 are left corners with x = 1.
    let mut map = [0u32; 8];
    for (i, p) in right.iter().enumerate() {
        if let Some(j) = pts.iter().position(|q| q == p) {
            map[i] = j as u32;
        } else {
            map[i] = pts.len() as u32;
            pts.push(*p);
        }
    }
    let mut tets: Vec<[u32; 4]> = cube6_tets(0);
    tets.extend(cube6_tets(0).iter().map(|t| t.map(|v| map[v as usize])));
    orient_all(&pts, &mut tets);
    let labels = [vec![1; 6], vec![2; 6]].concat();
    TetMesh::new(pts, tets, labels)
}

/// Read a binary STL from `tests/data` of the repository (welded by exact coordinates), as one
/// closed region.
/// TetGen's `pq1.2Y` mesh of brain_20k, bundled in `examples/`.
pub fn tetgen_brain() -> TetMesh {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/brain_tetgen.node"
    );
    biotet_io::read_tet_mesh(std::path::Path::new(path))
        .expect("examples/brain_tetgen.node")
        .mesh
}

pub fn load_stl(name: &str) -> SurfaceMesh {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/");
    let data = std::fs::read(format!("{path}{name}")).expect("test data");
    let n = u32::from_le_bytes(data[80..84].try_into().unwrap()) as usize;
    let mut points = Vec::with_capacity(3 * n);
    let mut tris = Vec::with_capacity(n);
    for t in 0..n {
        let rec = &data[84 + 50 * t..84 + 50 * (t + 1)];
        let mut tri = [0u32; 3];
        for (k, v) in tri.iter_mut().enumerate() {
            let f = |a: usize| {
                let o = 12 + 12 * k + 4 * a;
                f32::from_le_bytes(rec[o..o + 4].try_into().unwrap()) as f64
            };
            *v = points.len() as u32;
            points.push([f(0), f(1), f(2)]);
        }
        tris.push(tri);
    }
    let mut s = SurfaceMesh::closed(points, tris, 1);
    s.weld_exact();
    s
}

/// The sizing `biotet mesh` uses by default: from the surface, graded 0.3 (its `--grading`).
pub fn default_sizing(s: &SurfaceMesh) -> biotet::sizing::Sizing {
    use biotet::sizing::{SizeSpec, Sizing, SizingOptions};
    Sizing::new(
        s,
        SizingOptions::new(SizeSpec::FromSurface { grading: 0.3 }),
    )
    .unwrap()
}

/// A surface of the shape corpus (`tests/data/shapes`), as one closed region.
pub fn load_shape(name: &str) -> SurfaceMesh {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/shapes/");
    biotet_io::read_surface(std::path::Path::new(&format!("{path}{name}")))
        .expect("shape corpus")
        .mesh
}

/// `n` SplitMix64 points in the unit cube [0, 1)^3, reproducible from `seed`.
pub fn random_points(n: usize, mut seed: u64) -> Vec<[f64; 3]> {
    let mut next = move || {
        seed = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n).map(|_| [next(), next(), next()]).collect()
}

/// The octahedron |x| + |y| + |z| = r, outward, sides [1, 0].
pub fn octahedron(r: f64) -> SurfaceMesh {
    let p = vec![
        [r, 0.0, 0.0],
        [-r, 0.0, 0.0],
        [0.0, r, 0.0],
        [0.0, -r, 0.0],
        [0.0, 0.0, r],
        [0.0, 0.0, -r],
    ];
    let t = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    SurfaceMesh::closed(p, t, 1)
}

/// Distance from `p` to the triangle `t` (float; for measuring, not deciding).
pub fn point_triangle_distance(p: [f64; 3], t: [[f64; 3]; 3]) -> f64 {
    use biotet::geom::vec3::{add, cross, dot, norm, scale, sub};
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let nn = dot(n, n);
    // Projection inside the triangle: the plane distance.
    let q = sub(p, scale(n, dot(sub(p, t[0]), n) / nn));
    let inside = (0..3).all(|k| {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        dot(cross(sub(b, a), sub(q, a)), n) >= 0.0
    });
    if inside {
        return norm(sub(p, q));
    }
    (0..3)
        .map(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let ab = sub(b, a);
            let s = (dot(sub(p, a), ab) / dot(ab, ab)).clamp(0.0, 1.0);
            norm(sub(p, add(a, scale(ab, s))))
        })
        .fold(f64::INFINITY, f64::min)
}

/// A label image of `tests/data` through labels, extraction and validation as `biotet mesh
/// IMAGE` does (its voxel surface and summary, before the surface stage).
pub fn image_surface(name: &str) -> (SurfaceMesh, biotet::image::surface::ImageSummary) {
    let path = format!("{}/../../tests/data/{name}", env!("CARGO_MANIFEST_DIR"));
    let img = biotet_io::read_label_image(std::path::Path::new(&path)).expect("reads");
    biotet::image::surface::labelled_surface(
        img,
        &biotet::image::labels::LabelOptions::default(),
        &path,
        &mut |_| {},
    )
    .expect("extracts")
}
