//! `biotet check`: is a tet mesh valid, and does it contain every surface triangle?

use crate::{Common, progress::Stage};
use anyhow::Result;
use biotet::SurfaceMesh;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `biotet check`.
#[derive(clap::Args)]
pub struct Args {
    /// The tet mesh: .vtu, .mesh, .msh, or TetGen .node/.ele.
    mesh: PathBuf,
    /// A surface whose every triangle must be a face of the mesh (matched by exact
    /// coordinates, either orientation). Repeat for several surfaces.
    #[arg(long = "surface", short = 's', value_name = "SURFACE")]
    surfaces: Vec<PathBuf>,
    #[command(flatten)]
    common: Common,
}

/// Run `biotet check`; exits 1 when the mesh is invalid.
pub fn run(a: Args) -> Result<ExitCode> {
    let stage = Stage::start(a.common.quiet, format!("reading {}", a.mesh.display()));
    let mesh = super::input::tet_mesh(&a.mesh, a.common)?;
    let mut surface: Option<SurfaceMesh> = None;
    for s in &a.surfaces {
        stage.set(format!("reading {}", s.display()));
        let (m, _) = super::input::surface(s, a.common)?;
        surface.get_or_insert_with(SurfaceMesh::default).append(&m);
    }
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
