//! Write and read a ~1M-tet mesh (55³ cubes × 6 tets = 998,250 tets, 175,616 points) in every
//! tet format. `cargo bench -p biotet-io --bench io`.

#[path = "../tests/all/common.rs"]
mod common;

use std::hint::black_box;
use std::time::Duration;

use biotet_io::{TetFormat, VtuEncoding};
use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};

fn io(c: &mut Criterion) {
    let n = 55;
    let mesh = common::grid(
        n,
        1.0 / n as f64,
        0.02,
        1,
        |p| if p[0] < 0.8 { 1 } else { 2 },
    );
    let dir = tempfile::tempdir().unwrap();
    let mut g = c.benchmark_group("tet_1M");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(4));
    let cases: [(&str, Option<TetFormat>); 7] = [
        ("vtu_raw", Some(TetFormat::Vtu)),
        ("vtu_zlib", None),
        ("medit", Some(TetFormat::Medit)),
        ("gmsh41_ascii", Some(TetFormat::Gmsh)),
        ("gmsh41_binary", Some(TetFormat::GmshBinary)),
        ("tetgen", Some(TetFormat::TetGen)),
        ("vtk_binary", Some(TetFormat::Vtk)),
    ];
    for (name, f) in cases {
        let ext = match f {
            Some(TetFormat::Medit) => "mesh",
            Some(TetFormat::Gmsh | TetFormat::GmshBinary) => "msh",
            Some(TetFormat::TetGen) => "node",
            Some(TetFormat::Vtk) => "vtk",
            _ => "vtu",
        };
        let path = dir.path().join(format!("{name}.{ext}"));
        let write = || match f {
            Some(f) => {
                biotet_io::write_tet_mesh_as(&path, &mesh, f).unwrap();
            }
            None => {
                biotet_io::atomic::write_atomic(&path, |w| {
                    biotet_io::vtu::write_tet_with(w, &mesh, "bench.vtu", VtuEncoding::RawZlib)
                })
                .unwrap();
            }
        };
        g.bench_function(format!("write_{name}"), |b| b.iter(write));
        g.bench_function(format!("read_{name}"), |b| {
            b.iter(|| black_box(biotet_io::read_tet_mesh(&path).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, io);
criterion_main!(benches);
