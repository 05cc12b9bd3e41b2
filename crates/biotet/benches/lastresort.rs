//! Benchmark of LAST RESORT boundary recovery: the Delaunay tetrahedralization of the points of
//! `tests/data/brain_20k.stl` (convex hull, all tets kept; the outside is removed by the
//! recovery's labelling), every missing surface triangle recovered.
//!
//! `cargo bench -p biotet --bench lastresort`. Besides criterion's timing of the whole recovery,
//! the first run prints the Table 3.1 columns (elements, missing faces, calls, median and
//! maximum time per call, nodes visited per call).

use biotet::SurfaceMesh;
use biotet::delaunay::Delaunay;
use biotet::lastresort::{RecoverOptions, recover};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

/// Binary STL, exact duplicates welded.
fn read_stl(name: &str) -> SurfaceMesh {
    let path = format!("{}/../../tests/data/{name}", env!("CARGO_MANIFEST_DIR"));
    let bytes = std::fs::read(path).expect("read STL");
    let n = u32::from_le_bytes(bytes[80..84].try_into().expect("header")) as usize;
    let f = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().expect("float")) as f64;
    let mut points = Vec::with_capacity(3 * n);
    let mut triangles = Vec::with_capacity(n);
    for t in 0..n {
        let base = 84 + 50 * t + 12;
        for c in 0..3 {
            let o = base + 12 * c;
            points.push([f(o), f(o + 4), f(o + 8)]);
        }
        let i = 3 * t as u32;
        triangles.push([i, i + 1, i + 2]);
    }
    let mut s = SurfaceMesh::closed(points, triangles, 1);
    s.weld_exact();
    s
}

fn bench(c: &mut Criterion) {
    let s = read_stl("brain_20k.stl");
    let mesh = Delaunay::new(&s.points).expect("Delaunay").to_tet_mesh();
    let opts = RecoverOptions::default();
    {
        let mut m = mesh.clone();
        let r = recover(&mut m, &s, &opts).expect("recover");
        println!(
            "brain_20k: {} Delaunay tets, {} missing -> {}, {} calls ({} ok, {} grown), \
             ms/call median {:.3} max {:.3}, nodes/call median {} max {}, total {:.1} ms",
            r.tets_before,
            r.missing_before,
            r.missing_after,
            r.calls,
            r.calls_succeeded,
            r.cavities_grown,
            r.call_ms_median,
            r.call_ms_max,
            r.nodes_median,
            r.nodes_max,
            r.total_ms
        );
    }
    let mut g = c.benchmark_group("lastresort");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    g.measurement_time(Duration::from_secs(30));
    g.bench_function("recover brain_20k delaunay", |b| {
        b.iter(|| {
            let mut m = mesh.clone();
            let r = recover(&mut m, black_box(&s), &opts).expect("recover");
            black_box(r.missing_after)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
