//! Write and read a structured tet mesh in every tet format and print the times.
//!
//! `cargo run --release -p biotet-io --example timing -- [cubes per side = 55] [dir]`
//! (55³ cubes × 6 ≈ 1M tets). With a directory the files are kept there (to open them in other
//! tools); otherwise a temporary directory is used.

#[path = "../tests/all/common.rs"]
mod common;

use std::path::PathBuf;
use std::time::Instant;

use biotet_io::{TetFormat, VtuEncoding};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(Ok(55), |s| s.parse())?;
    let keep = args.next().map(PathBuf::from);
    let tmp = tempfile::tempdir()?;
    let dir = keep.clone().unwrap_or_else(|| tmp.path().to_path_buf());
    std::fs::create_dir_all(&dir)?;
    let t0 = Instant::now();
    let h = 1.0 / n as f64;
    let mesh = common::grid(n, h, 0.02, 1, |p| if p[0] < 0.3 + 0.5 { 1 } else { 2 });
    println!(
        "mesh: {} points, {} tets (generated in {:.2} s)",
        mesh.points.len(),
        mesh.tets.len(),
        t0.elapsed().as_secs_f64()
    );
    let cases: [(&str, Option<TetFormat>); 6] = [
        ("mesh.vtu", Some(TetFormat::Vtu)),
        ("mesh.mesh", Some(TetFormat::Medit)),
        ("mesh.msh", Some(TetFormat::Gmsh)),
        ("mesh_bin.msh", Some(TetFormat::GmshBinary)),
        ("mesh.node", Some(TetFormat::TetGen)),
        ("mesh_zlib.vtu", None),
    ];
    println!(
        "{:<14} {:>9} {:>9} {:>10}",
        "file", "write s", "read s", "MB"
    );
    for (name, f) in cases {
        let p = dir.join(name);
        let t = Instant::now();
        let files = match f {
            Some(f) => biotet_io::write_tet_mesh_as(&p, &mesh, f)?,
            None => {
                let s = p.display().to_string();
                biotet_io::atomic::write_atomic(&p, |w| {
                    biotet_io::vtu::write_tet_with(w, &mesh, &s, VtuEncoding::RawZlib)
                })?;
                vec![p.clone()]
            }
        };
        let tw = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let r = biotet_io::read_tet_mesh(&p)?;
        let tr = t.elapsed().as_secs_f64();
        assert_eq!(r.mesh.tets.len(), mesh.tets.len());
        assert_eq!(r.mesh.points, mesh.points);
        let mb: u64 = files
            .iter()
            .map(|f| std::fs::metadata(f).map_or(0, |m| m.len()))
            .sum();
        println!("{name:<14} {tw:>9.3} {tr:>9.3} {:>10.1}", mb as f64 / 1e6);
    }
    Ok(())
}
