//! Benchmark of LAST RESORT boundary recovery: the Delaunay tetrahedralization of the points of
//! `tests/data/brain_20k.stl` (convex hull, all tets kept; the outside is removed by the
//! recovery's labelling), every missing surface triangle recovered.
//!
//! `cargo bench -p biotet --bench lastresort`. Besides criterion's timing of the whole recovery,
//! the first run prints the Table 3.1 columns (elements, missing faces, calls, median and
//! maximum time per call, nodes visited per call).

use biotet::delaunay::Delaunay;
use biotet::lastresort::{RecoverOptions, recover};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/brain_20k.stl");
    let s = biotet_io::read_surface(&path).expect("brain_20k.stl").mesh;
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
