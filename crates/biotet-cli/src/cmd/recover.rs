//! `biotet recover`: make every triangle of the input surface a face of a tet mesh (LAST
//! RESORT, dissertation chapter 3), without new points on the surface.

use crate::{Common, EXIT_INVALID, output, progress::Stage};
use anyhow::{Context, Result};
use biotet::lastresort::{RecoverOptions, RecoverReport, recover};
use serde_json::json;
use std::path::PathBuf;
use std::process::ExitCode;

/// Examples at the end of `biotet recover --help`.
const EXAMPLES: &str = "\
Examples:
  biotet delaunay part.node -o dt.vtu && biotet recover dt.vtu -s part.stl -o part.vtu
      Every triangle of part.stl made a face; where no fill exists without new points, Steiner
      points are added strictly inside the domain (never on the surface).
  biotet recover dt.vtu -s part.stl -o part.vtu --no-steiner --keep-failed
      No new points (the seed's method alone). If triangles stay missing, the run exits 1,
      part.vtu is neither created nor replaced, and the partial mesh goes to part.failed.vtu.";

/// Arguments of `biotet recover`.
#[derive(clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// The tet mesh (any tool's): .vtu, .vtk, .mesh, .msh, or TetGen .node/.ele. Its boundary must
    /// be convex (a Delaunay mesh of the hull), or its tets Delaunay tets of its points with the
    /// outside removed.
    mesh: PathBuf,
    /// The surface whose triangles must be faces (repeat for several).
    #[arg(long = "surface", short = 's', value_name = "SURFACE", required = true)]
    surfaces: Vec<PathBuf>,
    /// Output tet mesh (.vtu, .vtk, .mesh, .msh, .node/.ele). Not written when some triangles stay
    /// missing (the exit status is then 1; see --keep-failed).
    #[arg(short, long, value_name = "OUT")]
    output: PathBuf,
    /// When some triangles stay missing, write the partial mesh beside the output as
    /// OUT.failed.EXT for inspection (OUT itself is never written by a failed run).
    #[arg(long)]
    keep_failed: bool,
    /// Add no new points: the seed's method alone (the run fails if a triangle then cannot be
    /// recovered). By default, where no fill exists without new points, Steiner points are added
    /// strictly inside the domain (never on the surface).
    #[arg(long)]
    no_steiner: bool,
    /// The default now (Steiner points strictly inside, where needed); kept for old scripts.
    #[arg(long, hide = true, conflicts_with = "no_steiner")]
    allow_interior_steiner: bool,
    /// Keep the tets outside the surface (labelled 0) instead of removing them.
    #[arg(long)]
    keep_outside: bool,
    #[command(flatten)]
    common: Common,
}

/// The first ten unrecovered triangles, one line each: index, corners, smallest angle, reason.
pub fn unrecovered_lines(r: &RecoverReport) -> impl Iterator<Item = String> + '_ {
    r.unrecovered.iter().take(10).map(|u| {
        format!(
            "triangle {} at {:?}, smallest angle {:.4}°: {}",
            u.triangle, u.corners, u.min_angle_deg, u.reason
        )
    })
}

/// How an error about unrecovered triangles names what was allowed.
pub fn steiner_text(no_steiner: bool) -> &'static str {
    if no_steiner {
        " without new points (--no-steiner)"
    } else {
        ""
    }
}

/// Run `biotet recover`.
pub fn run(a: Args) -> Result<ExitCode> {
    if super::plane::is_tri_mesh(&a.mesh) {
        let [pslg] = &a.surfaces[..] else {
            anyhow::bail!("a 2D mesh takes one --surface: the PSLG (.poly, .node/.edge, .mesh)");
        };
        return super::plane::recover_cmd(
            &a.mesh,
            pslg,
            Some(a.output.as_path()),
            a.keep_outside,
            a.keep_failed,
            a.common,
        );
    }
    let stage = Stage::start(a.common.quiet, format!("reading {}", a.mesh.display()));
    let mut mesh = super::input::tet_mesh(&a.mesh, a.common)?;
    let surface = super::input::surfaces(&a.surfaces, a.common, &stage)?.unwrap_or_default();
    stage.set("recovering the boundary");
    let opts = RecoverOptions {
        allow_interior_steiner: !a.no_steiner,
        remove_outside: !a.keep_outside,
        ..RecoverOptions::default()
    };
    let report = recover(&mut mesh, &surface, &opts).with_context(|| {
        format!(
            "{}: cannot recover the surface in this mesh",
            a.mesh.display()
        )
    })?;
    // A run that fails writes nothing at the output (`--keep-failed`: the partial mesh beside it).
    let (written, failure_note) = if report.is_complete() {
        stage.set(format!("writing {}", a.output.display()));
        (biotet_io::write_tet_mesh(&a.output, &mesh)?, None)
    } else {
        let (written, note) = output::on_failure(
            "partial mesh",
            Some(&a.output),
            &[&a.output],
            a.keep_failed,
            |path| {
                stage.set(format!("writing {}", path.display()));
                biotet_io::write_tet_mesh(path, &mesh)
            },
        );
        (written, Some(note))
    };
    drop(stage);
    if a.common.json {
        crate::emit(&serde_json::to_string_pretty(&json!({
            "input": a.mesh,
            "output": a.output,
            "written": written,
            "complete": report.is_complete(),
            "recover": report,
        }))?);
    } else if !a.common.quiet {
        let target = match failure_note {
            None => a.output.display().to_string(),
            Some(_) => format!("{} (not written)", a.output.display()),
        };
        let mut text = format!(
            "{} → {}: {} missing triangles before, {} after; {} LAST RESORT calls ({} succeeded, \
             {} cavities grown), median {:.3} ms, max {:.1} ms per call; {} Steiner points added \
             strictly inside (never on the surface); {} outside tets removed; {:.3} s",
            a.mesh.display(),
            target,
            report.missing_before,
            report.missing_after,
            report.calls,
            report.calls_succeeded,
            report.cavities_grown,
            report.call_ms_median,
            report.call_ms_max,
            report.steiner_points,
            report.outside_tets_removed,
            report.total_ms / 1e3,
        );
        for line in unrecovered_lines(&report) {
            text += &format!("\n  unrecovered: {line}");
        }
        crate::emit(&text);
    }
    let Some(note) = failure_note else {
        return Ok(ExitCode::SUCCESS);
    };
    // An error: printed with --quiet too.
    eprintln!(
        "error: {}: {} surface triangles could not be recovered{}; {note}",
        a.mesh.display(),
        report.missing_after,
        steiner_text(a.no_steiner),
    );
    if a.no_steiner {
        eprintln!(
            "  (without --no-steiner, points are added strictly inside the domain where no fill \
             exists without new points)"
        );
    }
    Ok(ExitCode::from(EXIT_INVALID))
}
