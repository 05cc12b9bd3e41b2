//! The surface-to-mesh pipeline's deployment stages (node deployment, Delaunay, outside removal;
//! smoothing has its own bench) on the real brain
//! surface at four uniform sizes, from about 150 thousand to 2.6 million tets: the time per tet
//! should stay flat (dissertation fig. 2.16: time linear in the number of tets).
//!
//! `cargo bench -p biotet --bench pipeline`; throughput is reported in tets per second.
//!
//! Also the whole default pipeline on brain_20k as `biotet mesh` runs it (surface-derived sizes,
//! recovery, sliver removal, smoothing, polishing): the run that issue 4 times against TetGen
//! (`scripts/bench_mesh.py` runs both tools side by side), and sliver removal alone on the mesh
//! the pipeline has before it.

use biotet::lastresort::{ImproveOptions, improve};
use biotet::pipeline::{PipelineOptions, mesh_surface};
use biotet::sizing::{SizeSpec, Sizing, SizingOptions};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::path::Path;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/brain_20k.stl");
    let surface = biotet_io::read_surface(&path).expect("brain_20k.stl").mesh;
    let mut g = c.benchmark_group("pipeline");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    for h in [4.0, 3.0, 2.0, 1.5] {
        let sizing = Sizing::uniform(h).expect("size");
        let opts = PipelineOptions::deploy_only();
        let (mesh, _) = mesh_surface(&surface, &sizing, &opts, &mut |_| {}).expect("mesh");
        g.throughput(Throughput::Elements(mesh.tets.len() as u64));
        g.bench_with_input(
            BenchmarkId::new(
                "brain_20k_uniform",
                format!("h={h} ({} tets)", mesh.tets.len()),
            ),
            &sizing,
            |b, sizing| {
                b.iter(|| mesh_surface(&surface, sizing, &opts, &mut |_| {}).expect("mesh"))
            },
        );
    }
    g.finish();

    // The default pipeline, as `biotet mesh brain_20k.stl` runs it.
    let sizing = Sizing::new(
        &surface,
        SizingOptions::new(SizeSpec::FromSurface { grading: 0.3 }),
    )
    .expect("sizing");
    let full = PipelineOptions::default();
    let (mesh, _) = mesh_surface(&surface, &sizing, &full, &mut |_| {}).expect("mesh");
    let mut g = c.benchmark_group("pipeline_full");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    g.measurement_time(Duration::from_secs(20));
    g.throughput(Throughput::Elements(mesh.tets.len() as u64));
    g.bench_function("brain_20k defaults", |b| {
        b.iter(|| mesh_surface(&surface, &sizing, &full, &mut |_| {}).expect("mesh"))
    });
    // Sliver removal alone, on the recovered mesh before it.
    let raw_opts = PipelineOptions {
        improve: None,
        smooth: None,
        polish: None,
        ..PipelineOptions::default()
    };
    let (raw, _) = mesh_surface(&surface, &sizing, &raw_opts, &mut |_| {}).expect("mesh");
    g.bench_function("brain_20k sliver removal", |b| {
        b.iter(|| {
            let mut m = raw.clone();
            improve(&mut m, &ImproveOptions::default()).n_bad_after
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
