//! `biotet quality`: element quality of a tet or 2D triangle mesh.

use crate::{Common, plot, progress::Stage};
use anyhow::Result;
use biotet::quality::{QualityReport, TriQualityReport, distance, forced};
use biotet_io::MeshKind;
use serde_json::json;
use std::path::PathBuf;
use std::process::ExitCode;

/// Examples at the end of `biotet quality --help`.
const EXAMPLES: &str = "\
Examples:
  biotet quality brain.vtu --surface brain.stl --svg brain_quality.svg
  biotet quality brain.vtu --json > brain_quality.json
  biotet quality smooth.vtu --surface brain.stl --distance";

/// Arguments of `biotet quality`.
#[derive(clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// The mesh: .vtu, .vtk, .mesh, .msh, or TetGen .node/.ele (tets or 2D triangles).
    mesh: PathBuf,
    /// Also draw the dihedral- and solid-angle histograms (angle histogram in 2D) to this SVG.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// The input surface (repeat for several, read as `biotet mesh` reads them): also split the
    /// quality by where each tet is (a face on the surface, a vertex only, interior) and count
    /// the tets forced poor by the input (a face that is an input triangle with an angle under
    /// 10°, or an input edge where the surface folds under 10°). Tet meshes only.
    #[arg(long = "surface", short = 's', value_name = "SURFACE")]
    surfaces: Vec<PathBuf>,
    /// With --surface: also measure the two-sided distance between the mesh's boundary and
    /// interface faces and the surface (sampled; with a Lipschitz upper bound), as one sheet —
    /// how far a mesher moved the surface.
    #[arg(long, requires = "surfaces")]
    distance: bool,
    /// The sample step of --distance on each triangle [default: the surface's median edge
    /// length / 16].
    #[arg(long, value_name = "H", requires = "distance")]
    distance_spacing: Option<f64>,
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
             (.vtu, .vtk, .mesh, .msh, .node/.ele)",
            a.mesh.display()
        );
    }
    if kind == MeshKind::Triangles2d {
        if !a.surfaces.is_empty() {
            anyhow::bail!("{}: --surface applies to tet meshes only", a.mesh.display());
        }
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
        let surface = super::input::surfaces(&a.surfaces, a.common, &stage)?;
        stage.set("measuring");
        let report = QualityReport::of(&mesh);
        let distance = match (&surface, a.distance) {
            (Some(s), true) => {
                stage.set("measuring the distance to the surface");
                let h = match a.distance_spacing {
                    Some(h) if h > 0.0 && h.is_finite() => h,
                    Some(h) => anyhow::bail!("--distance-spacing must be positive, got {h}"),
                    None => biotet::surface::median_edge_length(s) / 16.0,
                };
                Some(distance::surface_distance(&mesh, s, h))
            }
            _ => None,
        };
        let placement = surface.map(|s| {
            let f = forced::classify(&mesh, &s, FORCED_DEG);
            (
                forced::placement_quality(&mesh, &f),
                forced::summarise(&mesh, &f, FORCED_DEG),
            )
        });
        drop(stage);
        if let Some(svg) = &a.svg {
            plot::write_quality_svg(&report, svg, &title)?;
        }
        match placement {
            None => print(&report, a.common)?,
            Some((by_place, forcing)) => {
                print_placement(&report, &by_place, &forcing, distance.as_ref(), a.common)?
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The angle below which an input triangle or fold forces its tets (as `biotet mesh` reports).
const FORCED_DEG: f64 = 10.0;

/// The report with the placement split and the forcing: the JSON object gains `placement`,
/// `forcing`, `n_forced` and `n_unforced_dihedral_lt_10` (and `surface_distance` with
/// `--distance`).
fn print_placement(
    report: &QualityReport,
    by_place: &forced::PlacementQuality,
    forcing: &forced::ForcingSummary,
    dist: Option<&distance::SurfaceDistance>,
    common: Common,
) -> Result<()> {
    if common.json {
        let mut v = serde_json::to_value(report)?;
        if let Some(o) = v.as_object_mut() {
            o.insert("placement".into(), serde_json::to_value(by_place)?);
            o.insert("forcing".into(), serde_json::to_value(forcing)?);
            o.insert("n_forced".into(), json!(forcing.n_forced));
            o.insert(
                "n_unforced_dihedral_lt_10".into(),
                json!(forcing.n_unforced_dihedral_lt_10),
            );
            if let Some(d) = dist {
                o.insert("surface_distance".into(), serde_json::to_value(d)?);
            }
        }
        crate::emit(&serde_json::to_string_pretty(&v)?);
    } else if !common.quiet {
        let deg = |x: Option<f64>| x.map_or("–".to_string(), |d| format!("{d:.3}°"));
        let mut text = format!("{report}\nby placement (tets, min dihedral, below 10°, forced):\n");
        for (name, c) in [
            ("face on the surface", &by_place.face),
            ("vertex on the surface", &by_place.vertex),
            ("interior", &by_place.interior),
        ] {
            text += &format!(
                "  {name:<22} {:>9} {:>11} {:>9} {:>9}\n",
                c.n_tets,
                deg(c.min_dihedral_deg),
                c.n_dihedral_lt_10,
                c.n_forced
            );
        }
        text += &format!(
            "forced by the input (a face or fold under {FORCED_DEG}°): {} tets; unforced tets \
             below 10°: {} ({})",
            forcing.n_forced,
            forcing.n_unforced_dihedral_lt_10,
            forcing.cause_text()
        );
        if let Some(d) = dist {
            text += &format!(
                "\ndistance to the surface: {:.4} surface → mesh, {:.4} mesh → surface (bound \
                 {:.4}; {} faces, {} samples spaced {:.4})",
                d.in_to_out, d.out_to_in, d.bound, d.n_mesh_faces, d.n_samples, d.spacing
            );
        }
        crate::emit(&text);
    }
    Ok(())
}

fn print<R: serde::Serialize + std::fmt::Display>(report: &R, common: Common) -> Result<()> {
    if common.json {
        crate::emit(&serde_json::to_string_pretty(report)?);
    } else if !common.quiet {
        crate::emit(&report.to_string());
    }
    Ok(())
}
