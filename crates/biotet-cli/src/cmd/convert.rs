//! `biotet convert`: between every mesh format biotet reads and writes.

use crate::{Common, progress::Stage};
use anyhow::Result;
use biotet::SurfaceMesh;
use biotet::mesh::shells::Part;
use biotet_io::MeshKind;
use serde_json::json;
use std::path::PathBuf;
use std::process::ExitCode;

/// Examples at the end of `biotet convert --help`.
const EXAMPLES: &str = "\
Examples:
  biotet convert brain.vtu -o brain.msh
  biotet convert head.stl --regions -o head_labelled.vtu";

/// Arguments of `biotet convert`.
#[derive(clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// Input mesh; its format is chosen by extension.
    input: PathBuf,
    /// Output mesh; its format is chosen by extension (.vtu .vtk .mesh .msh .node/.ele for tets;
    /// .vtu .mesh .msh .node/.ele for 2D triangles; .stl .obj .off .ply .mesh .vtu .vtp .vtk .gii .surf for
    /// surfaces).
    #[arg(short, long, value_name = "OUT")]
    output: PathBuf,
    /// For a surface: label its regions as `biotet mesh` does (closed shells nested innermost
    /// first, or a non-manifold surface's cells; validated) and write the labels of both sides of
    /// every triangle (.vtu, .vtp and .vtk `sides`, .ply `label_back`/`label_front`, .mesh refs). A
    /// surface that already has side labels keeps them (checked against the geometry when some side
    /// is left to it).
    #[arg(long)]
    regions: bool,
    #[command(flatten)]
    common: Common,
}

/// Run `biotet convert`.
pub fn run(a: Args) -> Result<ExitCode> {
    let stage = Stage::start(a.common.quiet, format!("reading {}", a.input.display()));
    let kind = biotet_io::mesh_kind(&a.input)?;
    let out_ext = a
        .output
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    let surface_ext =
        ["stl", "obj", "off", "ply", "vtp", "surf", "gii"].contains(&out_ext.as_str());
    if surface_ext && kind != MeshKind::Surface {
        anyhow::bail!(
            "{}: cannot write a volume or 2D mesh as a surface (.{out_ext}); \
             use .vtu, .mesh, .msh or .node/.ele (tets also .vtk)",
            a.output.display()
        );
    }
    if kind == MeshKind::Surface && ["msh", "node", "ele"].contains(&out_ext.as_str()) {
        anyhow::bail!(
            "{}: {} is a surface; write it as .stl, .obj, .off, .ply, .mesh, .vtu, .vtp, .vtk, .gii or .surf \
             (meshing a surface is `biotet mesh`, coming with the mesher)",
            a.output.display(),
            a.input.display()
        );
    }
    let (what, n_points, n_elements) = match kind {
        MeshKind::Tetrahedra => {
            let m = super::input::tet_mesh(&a.input, a.common)?;
            stage.set(format!("writing {}", a.output.display()));
            biotet_io::write_tet_mesh(&a.output, &m)?;
            ("tets", m.points.len(), m.tets.len())
        }
        MeshKind::Triangles2d => {
            let m = biotet_io::read_tri_mesh(&a.input)?;
            stage.set(format!("writing {}", a.output.display()));
            biotet_io::write_tri_mesh(&a.output, &m)?;
            ("triangles", m.points.len(), m.triangles.len())
        }
        MeshKind::Surface => {
            // Conversion keeps the surface as it is (no validation), welded like any read;
            // side labels travel with it, and a surface without them is written without.
            let read = biotet_io::read_surface(&a.input)?;
            let partial = read.side_labels.as_ref().is_some_and(|s| {
                s.iter()
                    .flatten()
                    .any(|&l| l == biotet::mesh::side_labels::FROM_GEOMETRY)
            });
            let m = if read.side_labels.is_some() && (partial || a.regions) {
                super::input::side_labelled(
                    &a.input,
                    read,
                    a.common,
                    super::input::Crossings::Refused,
                )?
                .0
            } else if let Some(sides) = read.side_labels {
                SurfaceMesh { sides, ..read.mesh }
            } else if a.regions {
                let part = Part {
                    surface: read.mesh,
                    labels: None,
                };
                let name = a.input.display().to_string();
                super::input::assemble_parts(
                    vec![part],
                    &name,
                    std::slice::from_ref(&a.input),
                    a.common,
                )?
                .0
            } else {
                // No labels read or derived: none written (VTK's `sides` would declare every
                // shell region 1).
                SurfaceMesh {
                    sides: Vec::new(),
                    ..read.mesh
                }
            };
            stage.set(format!("writing {}", a.output.display()));
            biotet_io::write_surface(&a.output, &m)?;
            ("surface triangles", m.points.len(), m.triangles.len())
        }
    };
    drop(stage);
    if a.common.json {
        let key = if what == "tets" {
            "n_tets"
        } else {
            "n_triangles"
        };
        crate::emit(
            &json!({"input": a.input, "output": a.output, "n_points": n_points, key: n_elements})
                .to_string(),
        );
    } else if !a.common.quiet {
        crate::emit(&format!(
            "{} -> {}: {n_points} points, {n_elements} {what}",
            a.input.display(),
            a.output.display()
        ));
    }
    Ok(ExitCode::SUCCESS)
}
