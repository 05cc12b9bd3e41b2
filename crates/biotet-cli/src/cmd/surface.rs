//! `biotet surface improve`: remesh a surface within a distance bound (the opt-in surface stage
//! that `biotet mesh --surface-tolerance` runs before node deployment).

use crate::{Common, progress::Stage};
use anyhow::{Context, Result};
use biotet::SurfaceMesh;
use biotet::surface::{SurfaceOptions, SurfaceReport, improve_with_progress};
use serde_json::json;
use std::path::PathBuf;
use std::process::ExitCode;

const EXAMPLES: &str = "\
Examples:
  biotet surface improve brain.stl --tolerance 0.5 -o brain_improved.ply
      Remesh brain.stl to well-shaped triangles of about its median edge length, every point of
      the output within 0.5 of the input and every point of the input within 0.5 of the output
      (measured after the fact, both ways, and reported); fails if that bound cannot be kept.
  biotet mesh brain.stl --surface-tolerance 0.5 -o brain.vtu
      The same stage, then the usual pipeline with the improved surface kept exactly.";

/// Examples at the end of `biotet surface --help`.
const SURFACE_EXAMPLES: &str = "\
Examples:
  biotet surface tests/data/mni_head.nii.gz -o head_surface.vtu
  biotet surface improve brain.stl --tolerance 0.5 -o brain_improved.ply";

/// Arguments of `biotet surface`.
#[derive(clap::Args)]
#[command(
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true,
    after_help = SURFACE_EXAMPLES
)]
pub struct Args {
    #[command(subcommand)]
    command: Option<Sub>,
    /// Label image: .nii, .nii.gz, .mgh, .mgz, .nrrd, .nhdr, .mha, .mhd, .vti (world coordinates
    /// RAS+, see docs/formats.md); its labelled surface is written, as `surface extract`.
    #[arg(required = true)]
    image: Option<PathBuf>,
    /// Output labelled surface (.vtu, .vtp, .vtk, .ply or .mesh keep the labels on both sides of
    /// each triangle).
    #[arg(short, long, value_name = "OUT")]
    output: Option<PathBuf>,
    #[command(flatten)]
    image_args: super::extract::ImageArgs,
    #[command(flatten)]
    common: Common,
}

#[derive(clap::Subcommand)]
enum Sub {
    /// Remesh a (labelled) surface to well-shaped triangles within a two-sided distance bound:
    /// features, interfaces and triple lines kept, no self-intersection, Hausdorff distance and
    /// volume change reported.
    #[command(after_help = EXAMPLES)]
    Improve(ImproveArgs),
    /// The labelled surface of a label image (NIfTI, MGH, NRRD, MetaImage, VTI): every interface
    /// between two labels, shared by both (`biotet surface IMAGE -o OUT` is the same).
    Extract(super::extract::Args),
}

/// Options of the stage, shared with `biotet mesh`.
#[derive(clap::Args, Clone, Debug)]
pub struct StageArgs {
    /// Edges whose dihedral angle is below this (degrees, 0–180) are kept as features
    /// (polylines and corners stay exactly); 0: none for its angle alone.
    #[arg(long, value_name = "DEG", default_value_t = 30.0)]
    pub feature_angle: f64,
    /// Curvature-adapted edge lengths (shorter where the surface bends, down to half the edge
    /// length); experimental.
    #[arg(long)]
    pub adaptive_size: bool,
    /// Remeshing rounds (split, collapse, flip, relax).
    #[arg(long, value_name = "N", default_value_t = biotet::surface::DEFAULT_ROUNDS)]
    pub surface_rounds: usize,
}

/// Arguments of `biotet surface improve`.
#[derive(clap::Args)]
pub struct ImproveArgs {
    /// Closed surfaces, read as `biotet mesh` reads them (shells nested into regions, or one
    /// file with side labels).
    #[arg(required = true)]
    surfaces: Vec<PathBuf>,
    /// Labels of one file's shells in order, as FILE=N[,N...] (repeatable).
    #[arg(long, value_name = "FILE=N[,N...]")]
    label: Vec<String>,
    /// The largest distance D the surface may move (two-sided Hausdorff distance).
    #[arg(long, value_name = "D", required = true)]
    tolerance: f64,
    /// Target edge length (default: the input's median edge length).
    #[arg(long, value_name = "L")]
    edge_length: Option<f64>,
    /// The improved surface (.ply, .vtu, .vtp and .vtk keep the region labels of both sides; .mesh
    /// the labels as references; .stl .obj .off geometry only).
    #[arg(short, long, value_name = "OUT")]
    output: Option<PathBuf>,
    #[command(flatten)]
    stage: StageArgs,
    #[command(flatten)]
    common: Common,
}

/// Run `biotet surface`.
pub fn run(a: Args) -> Result<ExitCode> {
    match (a.command, a.image) {
        (Some(Sub::Improve(a)), _) => run_improve(a),
        (Some(Sub::Extract(a)), _) => super::extract::run(a),
        (None, Some(image)) => super::extract::run(super::extract::Args {
            image,
            output: a.output,
            image_args: a.image_args,
            common: a.common,
        }),
        (None, None) => anyhow::bail!("give a label image, or a subcommand (see --help)"),
    }
}

/// Bytes the stage holds per output triangle, generously (points, triangles, their incidence,
/// bounds and sample covers, the crossing grid; then the output and its measure).
const BYTES_PER_TRIANGLE: f64 = 1024.0;

/// Refuse, before any work, a target edge length `l` whose remeshed surface would need more
/// memory than `--max-memory` (an image at `--size 0.02` with 1 mm voxels grew past 2 GB and ran
/// on, where meshing at that size is refused at once).
fn refuse_over_limit(surface: &SurfaceMesh, l: f64) -> Result<()> {
    use biotet::geom::vec3::{cross, norm, sub};
    let area: f64 = (0..surface.triangles.len())
        .map(|t| {
            let [a, b, c] = surface.corners(t);
            0.5 * norm(cross(sub(b, a), sub(c, a)))
        })
        .sum();
    // Equilateral triangles of edge l.
    let triangles = area / (0.25 * 3f64.sqrt() * l * l);
    let bytes = triangles * BYTES_PER_TRIANGLE;
    let limit = biotet_io::limits::max_memory();
    if bytes > limit as f64 {
        anyhow::bail!(
            "the surface stage at edge length {} needs about {} of memory (about {:.0} \
             triangles), more than the limit of {} (--max-memory); give a larger size or a \
             larger limit",
            biotet::text::short(l),
            biotet_io::limits::human(bytes.min(u64::MAX as f64) as u64),
            triangles,
            biotet_io::limits::human(limit)
        );
    }
    Ok(())
}

/// The stage with the CLI's options.
pub fn stage(
    surface: &SurfaceMesh,
    tolerance: f64,
    edge_length: Option<f64>,
    s: &StageArgs,
    orient_sheets: bool,
    progress: &Stage,
) -> Result<(SurfaceMesh, SurfaceReport)> {
    if let Some(l) = edge_length {
        refuse_over_limit(surface, l)?;
    }
    let opts = SurfaceOptions {
        tolerance,
        edge_length,
        feature_angle_deg: s.feature_angle,
        rounds: s.surface_rounds,
        adaptive: s.adaptive_size,
        orient_sheets,
        ..Default::default()
    };
    Ok(improve_with_progress(surface, &opts, &|step| {
        progress.set(format!("improving the surface: {step}"))
    })?)
}

/// A distance with four decimals, or four significant digits when that would print zeros.
fn length(x: f64) -> String {
    if x == 0.0 || x.abs() >= 1e-3 {
        format!("{x:.4}")
    } else {
        format!("{x:.3e}")
    }
}

/// The report as text lines.
pub fn report_text(r: &SurfaceReport) -> String {
    let mut t = format!(
        "surface: {} → {} triangles in {:.3} s (edge length {:.4}, tolerance {})\n\
         \x20 Hausdorff input→output {} (bound {}), output→input {} (bound {}); {} samples\n\
         \x20 triangle angles: min {:.2}° → {:.2}°, max {:.2}° → {:.2}°; under {}°: {} → {} \
         ({} at kept features)\n\
         \x20 folds (dihedral angle inside at an edge): min {:.2}° → {:.2}° ({} points moved to \
         open them)\n",
        r.triangles_in,
        r.triangles_out,
        r.seconds,
        r.edge_length,
        r.tolerance,
        length(r.hausdorff_in_to_out),
        length(r.hausdorff_bound_in_to_out),
        length(r.hausdorff_out_to_in),
        length(r.hausdorff_bound_out_to_in),
        r.n_samples,
        r.min_angle_in,
        r.min_angle_out,
        r.max_angle_in,
        r.max_angle_out,
        30,
        r.n_below_target_in,
        r.n_below_target_out,
        r.n_below_target_at_features,
        r.min_fold_in,
        r.min_fold_out,
        r.n_fold_moves,
    );
    if let Some(u) = &r.untangled {
        t += &format!(
            "  untangled first: {} crossing pairs of input triangles, {} points moved by at most \
             {} in {} steps (the distances above are to the untangled surface; the bounds \
             include the move)\n",
            u.pairs,
            u.points_moved,
            length(u.max_move),
            u.steps
        );
    }
    if r.hausdorff_bound > r.tolerance {
        t += &format!(
            "  note: every sample is within the tolerance, but the distance is proven only to \
             within {} (too small a tolerance for the samples to prove on this surface)\n",
            length(r.hausdorff_bound)
        );
    }
    for v in &r.regions {
        t += &format!(
            "  region {}: volume {:.4} → {:.4} ({:+.3}%)\n",
            v.label,
            v.volume_in,
            v.volume_out,
            100.0 * v.relative_change
        );
    }
    t += &format!(
        "  kept: {} sharp edges, {} interface-rim or triple-line edges; {} splits, {} collapses, \
         {} flips, {} moves, {} repair rounds",
        r.n_sharp_edges,
        r.n_rim_edges,
        r.ops.splits,
        r.ops.collapses,
        r.ops.flips,
        r.ops.moves,
        r.repair_rounds
    );
    if r.retries > 0 {
        t += &format!(
            "\n  ran {} more time{} with smaller working tolerances: the repairs had left the \
             surface beyond the tolerance",
            r.retries,
            if r.retries == 1 { "" } else { "s" }
        );
    }
    t
}

fn run_improve(a: ImproveArgs) -> Result<ExitCode> {
    let stage_ = Stage::start(a.common.quiet, "reading the surface");
    let (surface, _, name) = super::input::labelled_surface(
        &a.surfaces,
        &a.label,
        a.common,
        &stage_,
        super::input::Crossings::Allowed,
    )?;
    stage_.set("improving the surface");
    let (out, report) = stage(
        &surface,
        a.tolerance,
        a.edge_length,
        &a.stage,
        true,
        &stage_,
    )
    .with_context(|| name.clone())?;
    if let Some(path) = &a.output {
        stage_.set(format!("writing {}", path.display()));
        biotet_io::write_surface(path, &out)?;
    }
    drop(stage_);
    if a.common.json {
        crate::emit(&serde_json::to_string_pretty(&json!({
            "input": name,
            "output": a.output,
            "surface": report,
        }))?);
    } else if !a.common.quiet {
        crate::emit(&format!("{name}: {}", report_text(&report)));
    }
    Ok(ExitCode::SUCCESS)
}
