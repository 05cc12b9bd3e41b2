//! The input of the dissertation's section 4.4 experiment (fig. 4.4, Table 4.1), shared by the
//! `table_4_1` example and the tests: the unit square with 32 boundary nodes (8 per side) and 202
//! random interior points (a fixed-seed generator), 234 nodes, whose Delaunay triangulation has
//! 434 triangles.

use biotet::TriMesh;
use biotet::mesh::pslg::Pslg;
use biotet::pipeline2d::triangulate_pslg;

/// SplitMix64 to uniform [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The mesh (Delaunay, every segment present) and the square's PSLG.
pub fn table_4_1_mesh() -> (TriMesh, Pslg) {
    let mut points = Vec::new();
    for k in 0..8 {
        points.push([k as f64 / 8.0, 0.0]);
    }
    for k in 0..8 {
        points.push([1.0, k as f64 / 8.0]);
    }
    for k in 0..8 {
        points.push([1.0 - k as f64 / 8.0, 1.0]);
    }
    for k in 0..8 {
        points.push([0.0, 1.0 - k as f64 / 8.0]);
    }
    let segments: Vec<[u32; 2]> = (0..32).map(|k| [k, (k + 1) % 32]).collect();
    let g = Pslg {
        points,
        segment_markers: vec![0; 32],
        segments,
        ..Default::default()
    };
    let mut r = Rng(44);
    let nodes: Vec<[f64; 2]> = (0..202)
        .map(|_| [0.01 + 0.98 * r.next(), 0.01 + 0.98 * r.next()])
        .collect();
    let (m, _) = triangulate_pslg(&g, &nodes).unwrap();
    (m, g)
}
