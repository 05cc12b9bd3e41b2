//! Solid-angle smoothing: one sweep (fixed surface, every movable node visited) over biotet
//! meshes of the real brain surface at four uniform sizes (151k to 1.1M tets), on one thread and
//! on all cores. The time per tet should stay flat (dissertation fig. 4.10: time linear in the
//! number of tets); the result is the same bit for bit on any number of threads.
//!
//! `cargo bench -p biotet --bench smooth`; throughput is reported in tets per second.

use biotet::pipeline::{PipelineOptions, mesh_surface};
use biotet::sizing::Sizing;
use biotet::smooth::{SmoothOptions, smooth};
use criterion::{BatchSize, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::path::Path;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/brain_20k.stl");
    let surface = biotet_io::read_surface(&path).expect("brain_20k.stl").mesh;
    let mut g = c.benchmark_group("smooth");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    let opts = SmoothOptions {
        max_sweeps: 1,
        ..SmoothOptions::default()
    };
    for h in [4.0, 3.0, 2.5, 2.0] {
        let sizing = Sizing::uniform(h).expect("size");
        let (mesh, _) = mesh_surface(
            &surface,
            &sizing,
            &PipelineOptions::deploy_only(),
            &mut |_| {},
        )
        .expect("mesh");
        g.throughput(Throughput::Elements(mesh.tets.len() as u64));
        let all = std::thread::available_parallelism().map_or(1, |n| n.get());
        let mut counts = vec![1];
        if all > 1 {
            counts.push(all);
        }
        for threads in counts {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            g.bench_with_input(
                BenchmarkId::new(
                    format!("brain_20k_one_sweep_{threads}_threads"),
                    format!("h={h} ({} tets)", mesh.tets.len()),
                ),
                &mesh,
                |b, mesh| {
                    b.iter_batched(
                        || mesh.clone(),
                        |mut m| pool.install(|| smooth(&mut m, None, &opts).expect("smooth")),
                        BatchSize::LargeInput,
                    )
                },
            );
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
