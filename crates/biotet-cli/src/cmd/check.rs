//! `biotet check`: is a tet mesh valid, and does it contain every surface triangle?

use crate::{Common, progress::Stage};
use anyhow::Result;
use std::path::PathBuf;
use std::process::ExitCode;

/// Examples at the end of `biotet check --help`.
const EXAMPLES: &str = "\
Examples:
  biotet check brain.vtu --surface brain.stl
  biotet check head.vtu -s scalp.stl -s skull.stl -s brain.stl --json";

/// Arguments of `biotet check`.
#[derive(clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// The tet mesh: .vtu, .vtk, .mesh, .msh, or TetGen .node/.ele.
    mesh: PathBuf,
    /// A surface whose every triangle must be a face of the mesh (matched by exact
    /// coordinates, either orientation). Repeat for several surfaces.
    /// Several closed shells make regions as in `biotet mesh` (innermost first).
    #[arg(long = "surface", short = 's', value_name = "SURFACE")]
    surfaces: Vec<PathBuf>,
    /// Labels of one surface file's shells in order, as FILE=N[,N...], as for `biotet mesh`.
    #[arg(long, value_name = "FILE=N[,N...]")]
    label: Vec<String>,
    #[command(flatten)]
    common: Common,
}

/// Run `biotet check`; exits 1 when the mesh is invalid.
pub fn run(a: Args) -> Result<ExitCode> {
    // One look at the file (a VTU is read whole to see its cell types).
    let kind = biotet_io::mesh_kind(&a.mesh)?;
    if kind == biotet_io::MeshKind::Triangles2d && !super::plane::is_pslg(&a.mesh) {
        if a.surfaces.len() > 1 {
            anyhow::bail!("a 2D mesh takes at most one --surface: the PSLG");
        }
        return super::plane::check_cmd(&a.mesh, a.surfaces.first().map(|p| p.as_path()), a.common);
    }
    // A file of triangles only would read as a mesh of no tets, "invalid" for no stated reason.
    if kind == biotet_io::MeshKind::Surface {
        anyhow::bail!(
            "{}: holds triangles and no tets (a surface, or a 2D mesh written as .vtu, which is \
             written only); `biotet check` reads tet meshes, and 2D meshes from .mesh or .node/.ele",
            a.mesh.display()
        );
    }
    let stage = Stage::start(a.common.quiet, format!("reading {}", a.mesh.display()));
    let mesh = super::input::tet_mesh(&a.mesh, a.common)?;
    let surface = if a.surfaces.is_empty() {
        None
    } else {
        Some(
            super::input::labelled_surface(
                &a.surfaces,
                &a.label,
                a.common,
                &stage,
                super::input::Crossings::Refused,
            )?
            .0,
        )
    };
    stage.set("checking");
    let report = biotet::check::check(&mesh, surface.as_ref());
    drop(stage);
    if a.common.json {
        crate::emit(&serde_json::to_string_pretty(&report)?);
    } else if !a.common.quiet {
        crate::emit(&format!("{}: {report}", a.mesh.display()));
    }
    Ok(if report.valid {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}
