//! `biotet smooth`: raise the smallest solid angles of a tet mesh by moving nodes (dissertation
//! chapter 4); connectivity and node order are kept.

use crate::{Common, output, plot, progress::Stage};
use anyhow::{Context, Result};
use biotet::quality::QualityReport;
use biotet::smooth::{Boundary, SmoothOptions, smooth, solid_angle_share_below};
use serde_json::json;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum BoundaryArg {
    /// Surface and interface nodes never move.
    Fixed,
    /// Surface and interface nodes slide on the input surface; feature edges, corners and
    /// triple lines stay.
    Slide,
}

/// Examples at the end of `biotet smooth --help`.
const EXAMPLES: &str = "\
Examples:
  biotet smooth brain.vtu --surface brain.stl -o brain_smooth.vtu --svg smooth.svg
  biotet smooth tetgen.vtu --boundary slide --surface brain.stl -o smooth.vtu";

/// Arguments of `biotet smooth`.
#[derive(clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// The tet mesh: .vtu, .vtk, .mesh, .msh, or TetGen .node/.ele.
    mesh: PathBuf,
    /// The input surface to slide on (repeat for several). Without it, sliding nodes stay on the
    /// mesh's own boundary and interface faces.
    #[arg(long = "surface", short = 's', value_name = "SURFACE")]
    surfaces: Vec<PathBuf>,
    /// What surface nodes may do.
    #[arg(long, value_enum, default_value = "fixed")]
    boundary: BoundaryArg,
    /// With --boundary slide: surface edges whose normals turn by more than this many degrees
    /// are features, and nodes on them stay.
    #[arg(long, value_name = "DEG", default_value_t = 45.0)]
    feature_angle: f64,
    /// Most sweeps over the nodes.
    #[arg(long, value_name = "N", default_value_t = 10)]
    max_sweeps: usize,
    /// Output tet mesh (.vtu, .vtk, .mesh, .msh, .node/.ele): same nodes and tets in the same
    /// order.
    #[arg(short, long, value_name = "OUT")]
    output: PathBuf,
    /// Draw the dihedral- and solid-angle histograms before and after to this SVG.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    #[command(flatten)]
    common: Common,
}

/// Run `biotet smooth`.
pub fn run(a: Args) -> Result<ExitCode> {
    if super::plane::is_tri_mesh(&a.mesh) {
        let slide = matches!(a.boundary, BoundaryArg::Slide);
        if a.surfaces.len() > 1 {
            anyhow::bail!("a 2D mesh takes at most one --surface: the PSLG");
        }
        return super::plane::smooth_cmd(
            &a.mesh,
            a.surfaces.first().map(|p| p.as_path()),
            slide,
            a.max_sweeps,
            &a.output,
            a.svg.as_deref(),
            a.common,
        );
    }
    if !(0.0..=180.0).contains(&a.feature_angle) {
        anyhow::bail!(
            "--feature-angle {}: expected degrees between 0 and 180",
            a.feature_angle
        );
    }
    let stage = Stage::start(a.common.quiet, format!("reading {}", a.mesh.display()));
    let mut mesh = super::input::tet_mesh(&a.mesh, a.common)?;
    let surface = super::input::surfaces(&a.surfaces, a.common, &stage)?;
    stage.set("measuring");
    let before = QualityReport::of(&mesh);
    let share_before = solid_angle_share_below(&mesh, 0.2);
    let opts = SmoothOptions {
        boundary: match a.boundary {
            BoundaryArg::Fixed => Boundary::Fixed,
            BoundaryArg::Slide => Boundary::Slide,
        },
        feature_angle_deg: a.feature_angle,
        max_sweeps: a.max_sweeps,
        ..SmoothOptions::default()
    };
    stage.set("smoothing");
    let report = smooth(&mut mesh, surface.as_ref(), &opts)
        .with_context(|| format!("{}", a.mesh.display()))?;
    stage.set("measuring");
    let after = QualityReport::of(&mesh);
    let share_after = solid_angle_share_below(&mesh, 0.2);
    let mut sides = Vec::new();
    if let Some(svg) = &a.svg {
        let title = a
            .mesh
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let text = plot::smooth_svg(
            &before,
            &after,
            (share_before, share_after),
            &format!("{title}: smoothed ({:?} boundary)", opts.boundary).to_lowercase(),
        )?;
        sides.push((svg.as_path(), text));
    }
    stage.set(format!("writing {}", a.output.display()));
    // The SVG only with the mesh: an error writing either leaves both unwritten.
    output::write_all(|| biotet_io::write_tet_mesh(&a.output, &mesh), &sides)?;
    drop(stage);
    if a.common.json {
        crate::emit(&serde_json::to_string_pretty(&json!({
            "input": a.mesh,
            "output": a.output,
            "boundary": report.boundary,
            "sweeps": report.sweeps,
            "seconds": report.seconds,
            "seconds_per_sweep": report.seconds_per_sweep,
            "nodes_moved": report.nodes_moved,
            "max_surface_distance": report.max_surface_distance,
            "share_solid_below_0_2_sr": { "before": share_before, "after": share_after },
            "smooth": report,
            "quality_before": before,
            "quality_after": after,
        }))?);
    } else if !a.common.quiet {
        let f = |x: Option<f64>| x.unwrap_or(f64::NAN);
        crate::emit(&format!(
            "{} → {}: {} sweeps in {:.3} s ({:.3} s per sweep), {} of {} nodes moved \
             ({} surface nodes: {} sliding, {} on features, {} not on the surface)\n\
             min solid angle {:.4e} → {:.4e} sr, share < 0.2 sr {:.2}% → {:.2}%\n\
             min dihedral {:.3}° → {:.3}°, max {:.3}° → {:.3}°, tets below 10°: {} → {}\n\
             mean q {:.4} → {:.4}, largest distance of a surface node from the surface {:e}",
            a.mesh.display(),
            a.output.display(),
            report.sweeps,
            report.seconds,
            report.seconds_per_sweep,
            report.nodes_moved,
            report.n_nodes,
            report.n_surface_nodes,
            report.n_sliding_nodes,
            report.n_feature_nodes,
            report.n_unlocated_nodes,
            f(before.min_solid_angle_sr),
            f(after.min_solid_angle_sr),
            100.0 * share_before,
            100.0 * share_after,
            f(before.min_dihedral_deg),
            f(after.min_dihedral_deg),
            f(before.max_dihedral_deg),
            f(after.max_dihedral_deg),
            before.n_dihedral_lt_10,
            after.n_dihedral_lt_10,
            f(before.mean_q),
            f(after.mean_q),
            report.max_surface_distance,
        ));
    }
    Ok(ExitCode::SUCCESS)
}
