//! `biotet improve`: remove slivers by refilling their cavities with LAST RESORT (dissertation
//! sections 3.3.1 and 3.4); points, boundary and interface faces are untouched.

use crate::{Common, progress::Stage};
use anyhow::Result;
use biotet::lastresort::{ImproveOptions, Metric, improve};
use biotet::quality::{QualityReport, forced};
use serde_json::json;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum MetricArg {
    /// The smallest dihedral angle (threshold in degrees).
    Dihedral,
    /// q of eq. 4.9 (threshold between 0 and 1).
    Q,
}

/// Examples at the end of `biotet improve --help`.
const EXAMPLES: &str = "\
Examples:
  biotet improve tetgen_brain.vtu --surface brain.stl -o brain_improved.vtu
  biotet improve brain.vtu --threshold 15 -o brain_15.vtu --json";

/// Arguments of `biotet improve`.
#[derive(clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// The tet mesh: .vtu, .vtk, .mesh, .msh, or TetGen .node/.ele.
    mesh: PathBuf,
    /// The input surface (repeat for several): used to report forced tets. Boundary and
    /// interface faces are kept whether it is given or not.
    #[arg(long = "surface", short = 's', value_name = "SURFACE")]
    surfaces: Vec<PathBuf>,
    /// Output tet mesh (.vtu, .vtk, .mesh, .msh, .node/.ele).
    #[arg(short, long, value_name = "OUT")]
    output: PathBuf,
    /// Which measure selects and judges tets.
    #[arg(long, value_enum, default_value = "dihedral")]
    metric: MetricArg,
    /// Tets below this are improved (degrees for dihedral, q otherwise). Default 10° or 0.2.
    #[arg(long, value_name = "X")]
    threshold: Option<f64>,
    #[command(flatten)]
    common: Common,
}

/// Run `biotet improve`.
pub fn run(a: Args) -> Result<ExitCode> {
    let stage = Stage::start(a.common.quiet, format!("reading {}", a.mesh.display()));
    let mut mesh = super::input::tet_mesh(&a.mesh, a.common)?;
    let surface = super::input::surfaces(&a.surfaces, a.common, &stage)?;
    let (metric, threshold) = match a.metric {
        MetricArg::Dihedral => (Metric::Dihedral, a.threshold.unwrap_or(10.0)),
        MetricArg::Q => (Metric::Q, a.threshold.unwrap_or(0.2)),
    };
    if !threshold.is_finite() || threshold <= 0.0 {
        anyhow::bail!("--threshold {threshold}: expected a positive number");
    }
    stage.set("measuring");
    let before = QualityReport::of(&mesh);
    let forced_before = surface.as_ref().map(|s| {
        let f = forced::classify(&mesh, s, 10.0);
        forced::summarise(&mesh, &f, 10.0)
    });
    stage.set("removing slivers");
    let opts = ImproveOptions {
        metric,
        threshold,
        ..ImproveOptions::default()
    };
    let report = improve(&mut mesh, &opts);
    stage.set("measuring");
    let after = QualityReport::of(&mesh);
    let forced_after = surface.as_ref().map(|s| {
        let f = forced::classify(&mesh, s, 10.0);
        forced::summarise(&mesh, &f, 10.0)
    });
    stage.set(format!("writing {}", a.output.display()));
    biotet_io::write_tet_mesh(&a.output, &mesh)?;
    drop(stage);
    let slivers = |q: &QualityReport| json!({ "lt_5": q.n_dihedral_lt_5, "lt_10": q.n_dihedral_lt_10, "lt_20": q.n_dihedral_lt_20 });
    if a.common.json {
        crate::emit(&serde_json::to_string_pretty(&json!({
            "input": a.mesh,
            "output": a.output,
            "slivers_before": slivers(&before),
            "slivers_after": slivers(&after),
            "n_forced": forced_after.as_ref().map(|f| f.n_forced),
            "n_unforced_dihedral_lt_10": forced_after.as_ref().map(|f| f.n_unforced_dihedral_lt_10),
            "forcing_before": forced_before,
            "forcing_after": forced_after,
            "calls": report.calls,
            "call_ms_median": report.call_ms_median,
            "call_ms_max": report.call_ms_max,
            "improve": report,
            "quality_before": before,
            "quality_after": after,
        }))?);
    } else if !a.common.quiet {
        let f = |x: Option<f64>| x.unwrap_or(f64::NAN);
        let mut text = format!(
            "{} → {}: {} tets → {}; below the threshold {} → {}\n\
             tets below 5°/10°/20°: {}/{}/{} → {}/{}/{}; min dihedral {:.4}° → {:.4}°\n\
             {} searches (median {:.3} ms, max {:.1} ms): face flips {}/{}, edge removals {}/{}, \
             edge cavities {}/{}, corner cavities {}/{}, grown {}/{} (accepted/tried); {:.2} s",
            a.mesh.display(),
            a.output.display(),
            report.n_tets_before,
            report.n_tets_after,
            report.n_bad_before,
            report.n_bad_after,
            before.n_dihedral_lt_5,
            before.n_dihedral_lt_10,
            before.n_dihedral_lt_20,
            after.n_dihedral_lt_5,
            after.n_dihedral_lt_10,
            after.n_dihedral_lt_20,
            f(before.min_dihedral_deg),
            f(after.min_dihedral_deg),
            report.calls,
            report.call_ms_median,
            report.call_ms_max,
            report.face_flips.accepted,
            report.face_flips.calls,
            report.edge_removals.accepted,
            report.edge_removals.calls,
            report.edge_cavities.accepted,
            report.edge_cavities.calls,
            report.star_cavities.accepted,
            report.star_cavities.calls,
            report.grown_cavities.accepted,
            report.grown_cavities.calls,
            report.seconds,
        );
        if let (Some(b), Some(f)) = (&forced_before, &forced_after) {
            text += &format!(
                "\nforced by the input: {} tets; unforced tets below 10°: {} → {} ({})",
                f.n_forced,
                b.n_unforced_dihedral_lt_10,
                f.n_unforced_dihedral_lt_10,
                f.cause_text()
            );
        }
        crate::emit(&text);
    }
    Ok(ExitCode::SUCCESS)
}
