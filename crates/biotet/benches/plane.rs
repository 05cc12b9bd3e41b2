//! Benchmarks of the 2D pipeline at a million triangles (issue 9):
//! - `delaunay2d/random/500000`: the Delaunay triangulation of 500 000 uniform random points (about
//!   10⁶ triangles);
//! - `delaunay2d/lattice/707²`: the 707 × 707 integer lattice (every square exactly cocircular,
//!   decided by the symbolic perturbation);
//! - `mesh2d/disk`: `mesh_pslg` of the unit disk (2 507 boundary points) at size 0.0025: template
//!   deployment, Delaunay, segment recovery, outside removal and smoothing — about 10⁶ triangles;
//! - `smooth2d/random`: 5 sweeps of max–min angle smoothing of the Delaunay mesh of 500 000 random
//!   points in the unit square (boundary fixed).
//!
//! `cargo bench -p biotet --bench plane`. `scripts/bench_2d.py` runs the CLI beside Triangle.

use biotet::delaunay2d::triangulate;
use biotet::mesh::pslg::Pslg;
use biotet::pipeline2d::{Mesh2dOptions, mesh_pslg, triangulate_pslg};
use biotet::smooth::plane::{PlaneSmoothOptions, smooth_tri};
use biotet::template::plane::PlaneDeployOptions;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

fn random_points(n: usize, mut seed: u64) -> Vec<[f64; 2]> {
    let mut next = move || {
        seed = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n).map(|_| [next(), next()]).collect()
}

fn disk(n: usize) -> Pslg {
    let points = (0..n)
        .map(|k| {
            let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            [a.cos(), a.sin()]
        })
        .collect();
    let segments = (0..n as u32).map(|k| [k, (k + 1) % n as u32]).collect();
    Pslg {
        points,
        segments,
        segment_markers: vec![0; n],
        ..Default::default()
    }
}

/// The unit square's boundary (4·64 segments) plus `inner` random points inside.
fn square_with_points(inner: usize) -> (Pslg, Vec<[f64; 2]>) {
    let k = 64;
    let mut points = Vec::new();
    for s in 0..4 {
        for i in 0..k {
            let t = i as f64 / k as f64;
            points.push(match s {
                0 => [t, 0.0],
                1 => [1.0, t],
                2 => [1.0 - t, 1.0],
                _ => [0.0, 1.0 - t],
            });
        }
    }
    let m = points.len() as u32;
    let g = Pslg {
        points,
        segments: (0..m).map(|i| [i, (i + 1) % m]).collect(),
        segment_markers: vec![0; m as usize],
        ..Default::default()
    };
    let nodes = random_points(inner, 9)
        .into_iter()
        .map(|p| [0.001 + 0.998 * p[0], 0.001 + 0.998 * p[1]])
        .collect();
    (g, nodes)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("delaunay2d");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    g.measurement_time(Duration::from_secs(15));
    let random = random_points(500_000, 1);
    let lattice: Vec<[f64; 2]> = (0..707 * 707)
        .map(|i| [(i % 707) as f64, (i / 707) as f64])
        .collect();
    for (name, pts) in [("random", &random), ("lattice", &lattice)] {
        g.throughput(Throughput::Elements(pts.len() as u64));
        g.bench_with_input(BenchmarkId::new(name, pts.len()), pts, |b, pts| {
            b.iter(|| {
                black_box(
                    triangulate(pts.clone())
                        .expect("triangulation")
                        .triangles
                        .len(),
                )
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("mesh2d");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    g.measurement_time(Duration::from_secs(30));
    let d = disk(2507);
    let opts = Mesh2dOptions {
        deploy: PlaneDeployOptions {
            size: Some(0.0025),
            ..Default::default()
        },
        smooth: Some(PlaneSmoothOptions::default()),
    };
    g.bench_function("disk_1M_triangles", |b| {
        b.iter(|| black_box(mesh_pslg(&d, &opts).expect("mesh").0.triangles.len()))
    });
    g.finish();

    let mut g = c.benchmark_group("smooth2d");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    g.measurement_time(Duration::from_secs(60));
    let (sq, nodes) = square_with_points(500_000 - 256);
    let (mesh, _) = triangulate_pslg(&sq, &nodes).expect("mesh");
    let so = PlaneSmoothOptions {
        max_sweeps: 5,
        ..Default::default()
    };
    g.throughput(Throughput::Elements(mesh.triangles.len() as u64));
    g.bench_function("random_1M_triangles_5_sweeps", |b| {
        b.iter(|| {
            let mut m = mesh.clone();
            black_box(smooth_tri(&mut m, &so).nodes_moved)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
