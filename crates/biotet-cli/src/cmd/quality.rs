//! `biotet quality`: element quality of a tet or 2D triangle mesh.

use crate::{Common, plot, progress::Stage};
use anyhow::Result;
use biotet::quality::{QualityReport, TriQualityReport};
use biotet_io::MeshKind;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `biotet quality`.
#[derive(clap::Args)]
pub struct Args {
    /// The mesh: .vtu, .mesh, .msh, or TetGen .node/.ele (tets or 2D triangles).
    mesh: PathBuf,
    /// Also draw the dihedral- and solid-angle histograms (angle histogram in 2D) to this SVG.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    #[command(flatten)]
    common: Common,
}

/// Run `biotet quality`.
pub fn run(a: Args) -> Result<ExitCode> {
    let stage = Stage::start(a.common.quiet, format!("reading {}", a.mesh.display()));
    let title = a
        .mesh
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let kind = biotet_io::mesh_kind(&a.mesh)?;
    if kind == MeshKind::Surface {
        anyhow::bail!(
            "{}: a surface file; `biotet quality` measures tet meshes and 2D triangle meshes \
             (.vtu, .mesh, .msh, .node/.ele)",
            a.mesh.display()
        );
    }
    if kind == MeshKind::Triangles2d {
        let mesh = biotet_io::read_tri_mesh(&a.mesh)?;
        stage.set("measuring");
        let report = TriQualityReport::of(&mesh);
        drop(stage);
        if let Some(svg) = &a.svg {
            plot::write_tri_quality_svg(&report, svg, &title)?;
        }
        print(&report, a.common)?;
    } else {
        let mesh = super::input::tet_mesh(&a.mesh, a.common)?;
        stage.set("measuring");
        let report = QualityReport::of(&mesh);
        drop(stage);
        if let Some(svg) = &a.svg {
            plot::write_quality_svg(&report, svg, &title)?;
        }
        print(&report, a.common)?;
    }
    Ok(ExitCode::SUCCESS)
}

fn print<R: serde::Serialize + std::fmt::Display>(report: &R, common: Common) -> Result<()> {
    if common.json {
        crate::emit(&serde_json::to_string_pretty(report)?);
    } else if !common.quiet {
        crate::emit(&report.to_string());
    }
    Ok(())
}
