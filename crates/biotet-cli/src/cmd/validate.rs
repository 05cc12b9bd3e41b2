//! `biotet validate`: is a surface fit to be meshed?

use crate::{Common, progress::Stage};
use anyhow::Result;
use serde_json::json;
use std::path::PathBuf;
use std::process::ExitCode;

/// Examples at the end of `biotet validate --help`.
const EXAMPLES: &str = "\
Examples:
  biotet validate brain.stl
  biotet validate scalp.stl skull.stl brain.stl --json";

/// Arguments of `biotet validate`.
#[derive(clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// Surfaces: .stl .obj .off .ply .mesh .vtu .vtp .vtk .gii, FreeSurfer surfaces (lh.pial).
    #[arg(required = true)]
    surfaces: Vec<PathBuf>,
    #[command(flatten)]
    common: Common,
}

/// Run `biotet validate`: exits 1 at the first invalid surface, naming it and the problem.
/// Each file is judged as `biotet mesh` reads it alone: its closed shells assembled into
/// regions (shells touching along an edge or at a vertex are separate regions sharing it, and
/// the user is told), then validated region by region.
pub fn run(a: Args) -> Result<ExitCode> {
    let mut out = Vec::new();
    for path in &a.surfaces {
        let stage = Stage::start(a.common.quiet, format!("validating {}", path.display()));
        let (mesh, shells, report, _) = super::input::labelled_surface_report(
            std::slice::from_ref(path),
            &[],
            a.common,
            &stage,
            super::input::Crossings::Hinted,
        )?;
        drop(stage);
        if !a.common.quiet && !a.common.json {
            let unused = mesh.points.len() - report.n_used_points;
            crate::emit(&format!(
                "{}: valid: {} points, {} triangles{}\n{report}",
                path.display(),
                mesh.points.len(),
                mesh.triangles.len(),
                if unused > 0 {
                    format!(" ({unused} points used by no triangle: left out when meshing)")
                } else {
                    String::new()
                }
            ));
        }
        // The shells say what was repaired (triangles turned back, shells flipped outward).
        out.push(json!({"file": path, "report": report, "shells": shells}));
    }
    if a.common.json {
        crate::emit(&serde_json::to_string_pretty(&json!({"surfaces": out}))?);
    }
    Ok(ExitCode::SUCCESS)
}
