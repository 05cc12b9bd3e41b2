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
//!
//! And the multi-material cost per tet (issue 8): the nested brain and white matter meshed as two
//! regions in one conforming mesh, beside the single-region runs of its tissues (the grey matter
//! with the white matter a hole, and the white matter alone). Throughput is in tets per second, so
//! the rows compare per tet; `scripts/bench_materials.py` runs the same cases through the CLI.

use biotet::lastresort::{ImproveOptions, improve};
use biotet::mesh::shells::{Part, assemble};
use biotet::mesh::surface::SurfaceMesh;
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
    materials(c);
}

/// The nested model with `labels` for its two shells (outer, inner), as `biotet mesh --label`.
fn nested(labels: [u32; 2]) -> SurfaceMesh {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/nested_brain_wm_20k.stl");
    let surface = biotet_io::read_surface(&path)
        .expect("nested_brain_wm_20k.stl")
        .mesh;
    let mut surface = assemble(vec![Part {
        surface,
        labels: Some(labels.to_vec()),
    }])
    .expect("two nested shells")
    .0;
    biotet::mesh::validate::validate_surface(&mut surface, &Default::default()).expect("valid");
    surface
}

fn materials(c: &mut Criterion) {
    let wm_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/wm_20k.stl");
    let cases = [
        ("two regions (grey + white)", nested([1, 2])),
        ("grey matter alone (white a hole)", nested([1, 0])),
        (
            "white matter alone",
            biotet_io::read_surface(&wm_path).expect("wm_20k.stl").mesh,
        ),
    ];
    let mut g = c.benchmark_group("pipeline_materials");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    g.measurement_time(Duration::from_secs(40));
    let full = PipelineOptions::default();
    for (name, surface) in &cases {
        let sizing = Sizing::new(
            surface,
            SizingOptions::new(SizeSpec::FromSurface { grading: 0.3 }),
        )
        .expect("sizing");
        let (mesh, _) = mesh_surface(surface, &sizing, &full, &mut |_| {}).expect("mesh");
        g.throughput(Throughput::Elements(mesh.tets.len() as u64));
        g.bench_function(*name, |b| {
            b.iter(|| mesh_surface(surface, &sizing, &full, &mut |_| {}).expect("mesh"))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
