//! `biotet recover`: make every triangle of the input surface a face of a tet mesh (LAST
//! RESORT, dissertation chapter 3), without new points on the surface.

use crate::{Common, EXIT_INVALID, progress::Stage};
use anyhow::{Context, Result};
use biotet::lastresort::{RecoverOptions, RecoverReport, recover};
use serde_json::json;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `biotet recover`.
#[derive(clap::Args)]
pub struct Args {
    /// The tet mesh (any tool's): .vtu, .mesh, .msh, or TetGen .node/.ele. Its boundary must be
    /// convex (a Delaunay mesh of the hull), or its tets Delaunay tets of its points with the
    /// outside removed.
    mesh: PathBuf,
    /// The surface whose triangles must be faces (repeat for several).
    #[arg(long = "surface", short = 's', value_name = "SURFACE", required = true)]
    surfaces: Vec<PathBuf>,
    /// Output tet mesh (.vtu, .mesh, .msh, .node/.ele). Written even when some triangles stay
    /// missing (the exit status is then 1).
    #[arg(short, long, value_name = "OUT")]
    output: PathBuf,
    /// As a last resort, add points strictly inside a failed cavity (never on the surface).
    #[arg(long)]
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
            a.common,
        );
    }
    let stage = Stage::start(a.common.quiet, format!("reading {}", a.mesh.display()));
    let mut mesh = super::input::tet_mesh(&a.mesh, a.common)?;
    let surface = super::input::surfaces(&a.surfaces, a.common, &stage)?.unwrap_or_default();
    stage.set("recovering the boundary");
    let opts = RecoverOptions {
        allow_interior_steiner: a.allow_interior_steiner,
        remove_outside: !a.keep_outside,
        ..RecoverOptions::default()
    };
    let report = recover(&mut mesh, &surface, &opts).with_context(|| {
        format!(
            "{}: cannot recover the surface in this mesh",
            a.mesh.display()
        )
    })?;
    stage.set(format!("writing {}", a.output.display()));
    biotet_io::write_tet_mesh(&a.output, &mesh)?;
    drop(stage);
    if a.common.json {
        crate::emit(&serde_json::to_string_pretty(&json!({
            "input": a.mesh,
            "output": a.output,
            "complete": report.is_complete(),
            "recover": report,
        }))?);
    } else if !a.common.quiet {
        let mut text = format!(
            "{} → {}: {} missing triangles before, {} after; {} LAST RESORT calls ({} succeeded, \
             {} cavities grown), median {:.3} ms, max {:.1} ms per call; {} points added; {} \
             outside tets removed; {:.3} s",
            a.mesh.display(),
            a.output.display(),
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
    Ok(if report.is_complete() {
        ExitCode::SUCCESS
    } else {
        if !a.common.quiet {
            eprintln!(
                "error: {}: {} surface triangles could not be recovered without new points{}",
                a.mesh.display(),
                report.missing_after,
                if a.allow_interior_steiner {
                    ""
                } else {
                    " (try --allow-interior-steiner)"
                }
            );
        }
        ExitCode::from(EXIT_INVALID)
    })
}
