//! `biotet delaunay`: the 3D Delaunay tetrahedralization of a point cloud.

use crate::{Common, progress::Stage};
use anyhow::{Context, Result};
use biotet::delaunay::Delaunay;
use serde_json::json;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Examples at the end of `biotet delaunay --help`.
const EXAMPLES: &str = "\
Examples:
  biotet delaunay points.xyz -o points.vtu
  biotet delaunay points.node --json        (counts and times only, no file)";

/// Arguments of `biotet delaunay`.
#[derive(clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// The points: a TetGen .node file, or text with one `x y z` point per line (`#` comments).
    points: PathBuf,
    /// Output tet mesh (.vtu, .vtk, .mesh, .msh, .node/.ele). Without it, the triangulation is
    /// built and measured only.
    #[arg(short, long, value_name = "OUT")]
    output: Option<PathBuf>,
    #[command(flatten)]
    common: Common,
}

/// Peak and current resident memory of this process in KiB (Linux; `None` elsewhere).
pub fn memory_kb() -> (Option<u64>, Option<u64>) {
    let Ok(status) = std::fs::read_to_string("/proc/self/status") else {
        return (None, None);
    };
    (
        status_field(&status, "VmHWM:"),
        status_field(&status, "VmRSS:"),
    )
}

/// The number (kB) on the line `name` of a `/proc/self/status` text.
pub fn status_field(status: &str, name: &str) -> Option<u64> {
    status
        .lines()
        .find(|l| l.starts_with(name))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
}

/// Run `biotet delaunay`.
pub fn run(a: Args) -> Result<ExitCode> {
    let stage = Stage::start(a.common.quiet, format!("reading {}", a.points.display()));
    let points = biotet_io::read_points(&a.points)?;
    // 250 bytes a point measured (19,903 points: 5.0 MB); refused before any work above the limit.
    let need = points.len() as u64 * 300;
    let limit = biotet_io::limits::max_memory();
    if need > limit {
        anyhow::bail!(
            "{}: the Delaunay of {} points needs about {} of memory, more than the limit of {} \
             (--max-memory)",
            a.points.display(),
            points.len(),
            biotet_io::limits::human(need),
            biotet_io::limits::human(limit)
        );
    }
    let (_, rss_before) = memory_kb();
    stage.set(format!("triangulating {} points", points.len()));
    let t0 = Instant::now();
    let n = points.len();
    // from_points reorders the Vec in place: no second copy of the points.
    let dt = Delaunay::from_points(points).with_context(|| format!("{}", a.points.display()))?;
    let seconds = t0.elapsed().as_secs_f64();
    let (peak, _) = memory_kb();
    let n_tets = dt.n_finite_tets();
    if let Some(out) = &a.output {
        stage.set(format!("writing {}", out.display()));
        biotet_io::write_tet_mesh(out, &dt.to_tet_mesh())?;
    }
    drop(stage);
    let pps = n as f64 / seconds.max(1e-12);
    if a.common.json {
        crate::emit(
            &json!({
                "n_points": n,
                "n_vertices": dt.n_vertices(),
                "n_tets": n_tets,
                "n_hull_faces": dt.n_hull_faces(),
                "seconds": seconds,
                "points_per_second": pps,
                "triangulation_bytes": dt.heap_bytes(),
                "rss_before_kb": rss_before,
                "peak_rss_kb": peak,
                "output": a.output,
            })
            .to_string(),
        );
    } else if !a.common.quiet {
        crate::emit(&format!(
            "{}: {n} points ({} distinct), {n_tets} tets, {} hull faces\n\
             triangulated in {seconds:.3} s ({pps:.0} points/s), {:.1} MB for the triangulation",
            a.points.display(),
            dt.n_vertices(),
            dt.n_hull_faces(),
            dt.heap_bytes() as f64 / 1e6
        ));
    }
    Ok(ExitCode::SUCCESS)
}
