//! Benchmarks of the 3D Delaunay tetrahedralization: 10^5 and 10^6 uniform random points in the
//! unit cube and the 100³ integer lattice (massively cospherical: every insertion meets exactly
//! cospherical and coplanar configurations decided by the symbolic perturbation).
//!
//! `cargo bench -p biotet --bench delaunay`; throughput is reported in points per second.

use biotet::delaunay::Delaunay;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

/// SplitMix64, for reproducible inputs.
fn random_points(n: usize, mut seed: u64) -> Vec<[f64; 3]> {
    let mut next = move || {
        seed = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n).map(|_| [next(), next(), next()]).collect()
}

fn lattice(k: usize) -> Vec<[f64; 3]> {
    let mut p = Vec::with_capacity(k * k * k);
    for z in 0..k {
        for y in 0..k {
            for x in 0..k {
                p.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    p
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("delaunay");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    let cases = [
        ("random", random_points(100_000, 1), 5),
        ("random", random_points(1_000_000, 2), 40),
        ("lattice", lattice(100), 50),
    ];
    for (name, pts, secs) in &cases {
        g.measurement_time(Duration::from_secs(*secs));
        g.throughput(Throughput::Elements(pts.len() as u64));
        g.bench_with_input(BenchmarkId::new(*name, pts.len()), pts, |b, pts| {
            b.iter(|| {
                let dt = Delaunay::new(black_box(pts)).expect("triangulation");
                black_box(dt.n_slots())
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
