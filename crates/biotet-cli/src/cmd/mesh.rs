//! `biotet mesh`: surface in, volume mesh out (the whole pipeline).

use crate::memory::{StagePeaks, map_mesh_sized_blocks, release_free_memory};
use crate::{Common, output, plot, progress::Stage};
use anyhow::{Context, Result};
use biotet::geom::vec3::{norm, sub};
use biotet::mesh::shells::Part;
use biotet::mesh::surface::SurfaceMesh;
use biotet::pipeline::{PipelineOptions, mesh_surface};
use biotet::quality::{QualityReport, forced};
use biotet::sizing::{SizeSpec, Sizing, SizingOptions};
use biotet::template::Zone;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// The bundled example: a real brain surface (MNI ICBM152, 19,648 triangles), see tests/data.
const EXAMPLE: &[u8] = include_bytes!("../../../../tests/data/brain_20k.stl");
const EXAMPLE_NAME: &str = "brain_20k.stl (bundled example)";
/// Angle below which an input triangle or fold forces its tets (degrees).
const FORCED_DEG: f64 = 10.0;

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum ZoneArg {
    /// L∞ ball (a cube of voxels), as in the dissertation.
    Box,
    /// Euclidean ball (integer squared distance).
    Euclidean,
}

/// Examples at the end of `biotet mesh --help`.
const EXAMPLES: &str = "\
Examples:
  biotet mesh part.stl -o part.vtu --svg part.svg
      Where no fill exists without new points (a twisted cube, a Schönhardt prism), recovery adds
      Steiner points strictly inside the domain, never on the surface; the report counts them.
  biotet mesh part.stl -o part.vtu --no-steiner --keep-failed
      No new points at all (the seed's recovery alone). If a triangle then cannot be recovered,
      the run exits 1, part.vtu is neither created nor replaced, and the partial mesh is written
      to part.failed.vtu for inspection.
  biotet mesh aseg.mgz -o head.vtu --json
      A label image: one region per label (the image's values), its voxel faces remeshed within
      half a voxel first; image_regions gives each region's volume and distance to its voxels.
  biotet mesh aseg.mgz -o blocks.vtu --exact-surface
      The voxel faces meshed as they are: every region's volume is its voxel volume.";

/// Arguments of `biotet mesh`.
#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("sizing").args(["size", "size_from_surface", "size_field"])))]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// Closed surfaces (.stl, .obj, .off, .ply, .mesh, .vtu, .vtp, .vtk, .gii, FreeSurfer surfaces
    /// such as lh.pial). Every closed shell encloses a region; a point belongs to the innermost shell around it. Shells are labelled 1,
    /// 2, … in order of files and of shells within a file, unless --label says otherwise. Without a
    /// surface, the bundled brain example is meshed. A 2D planar straight-line graph (.poly,
    /// .node/.edge, or a Dimension 2 .mesh with Edges) is meshed in 2D (see docs/commands.md, "2D
    /// meshes").
    surfaces: Vec<PathBuf>,
    /// Labels of one file's shells in order, as FILE=N[,N...] (repeatable); 0 makes a shell a
    /// cavity (not meshed).
    #[arg(long, value_name = "FILE=N[,N...]")]
    label: Vec<String>,
    /// Output tet mesh (.vtu, .vtk, .mesh, .msh, .node/.ele). Without it, the mesh is built and
    /// reported only. A run that fails (exit 1) neither creates nor replaces it.
    #[arg(short, long, value_name = "OUT")]
    output: Option<PathBuf>,
    /// When the run fails (input triangles left unrecovered), write the partial mesh beside the
    /// output as OUT.failed.EXT for inspection (OUT itself is never written by a failed run).
    #[arg(long, requires = "output")]
    keep_failed: bool,
    /// Desired edge length in the volume; near the surface no coarser than the surface's own
    /// edges, growing away from them by --grading up to H (a finer H is uniform).
    #[arg(long, value_name = "H")]
    size: Option<f64>,
    /// Size from the surface (the default): at each surface node the mean length of its edges,
    /// growing with distance from the surface by --grading, up to --max-size.
    #[arg(long)]
    size_from_surface: bool,
    /// Desired edge length from a regular grid file (VTK image data .vti, NIfTI .nii/.nii.gz),
    /// interpolated trilinearly, clamped to the grid outside it; in the surface's coordinates.
    #[arg(long, value_name = "FILE")]
    size_field: Option<PathBuf>,
    /// Which array of a .vti size field (default: the active point scalars, else the first).
    #[arg(long, value_name = "NAME", requires = "size_field")]
    size_field_array: Option<String>,
    /// Growth of the surface-derived size per unit of distance from the surface.
    #[arg(long, value_name = "G", default_value_t = 0.3)]
    grading: f64,
    /// Largest edge length anywhere.
    #[arg(long, value_name = "M")]
    max_size: Option<f64>,
    /// Smallest edge length anywhere (sets the template spacing). Default: the uniform size, or
    /// half the median surface node size.
    #[arg(long, value_name = "M")]
    min_size: Option<f64>,
    /// Uniform size inside one region of a multi-material model, as LABEL=H (repeatable).
    #[arg(long, value_name = "LABEL=H")]
    region_size: Vec<String>,
    /// Template voxels per smallest edge length (eq. 2.1).
    #[arg(long, value_name = "R", default_value_t = 2.0)]
    resolution: f64,
    /// Shape of the buffer zone around each node (Euclidean measured better; see docs/commands.md).
    #[arg(long, value_enum, default_value = "euclidean")]
    zone: ZoneArg,
    /// Largest template size in voxels (two bytes each).
    #[arg(long, value_name = "N", default_value_t = 1 << 31)]
    max_voxels: usize,
    /// Skip boundary recovery (LAST RESORT), and polishing, which needs it; missing input
    /// triangles are only counted.
    #[arg(long)]
    no_recover: bool,
    /// Skip sliver removal (and the polish, its last pass).
    #[arg(long)]
    no_improve: bool,
    /// Skip smoothing.
    #[arg(long)]
    no_smooth: bool,
    /// Skip polishing (the last pass that moves, removes or adds interior points around the
    /// unforced tets still below 10°).
    #[arg(long)]
    no_polish: bool,
    /// Skip the interior seeds: points added after recovery at the circumcentres of poor tets
    /// spanning a section too thin for the template's nodes (a square-section ring tube).
    /// `--no-improve` skips them too.
    #[arg(long)]
    no_seeds: bool,
    /// Add no new points: recovery uses the seed's method alone (the run fails if a triangle
    /// then cannot be recovered), no interior seeds are added and polishing adds no interior
    /// point. By default, where no fill
    /// exists without new points, recovery adds Steiner points strictly inside the domain (never
    /// on the surface).
    #[arg(long)]
    no_steiner: bool,
    /// The default now (Steiner points strictly inside, where needed); kept for old scripts.
    #[arg(long, hide = true, conflicts_with = "no_steiner")]
    allow_interior_steiner: bool,
    /// 2D only: triangulate the PSLG's own points (isolated points included) without deploying
    /// template nodes.
    #[arg(long)]
    no_deploy: bool,
    /// Before node deployment, remesh the surface to well-shaped triangles within this
    /// two-sided (Hausdorff) distance D of the input (see `biotet surface improve --help`); the
    /// improved surface is then kept exactly. The edge length is --size, else the input's
    /// median edge length. Default for a surface: off (kept exactly); for a label image: half
    /// the smallest voxel spacing (see --exact-surface).
    #[arg(long, value_name = "D")]
    surface_tolerance: Option<f64>,
    /// Keep the input surface exactly, with no surface stage: for a label image, mesh its voxel
    /// faces as they are (each region's mesh volume is then its voxel volume, the boundary a
    /// staircase). A surface input is kept exactly anyway unless --surface-tolerance is given.
    #[arg(long, conflicts_with = "surface_tolerance")]
    exact_surface: bool,
    /// Write the surface that was meshed here (after the surface stage, if it ran; .ply, .vtu,
    /// .vtp and .vtk keep the region labels).
    #[arg(long, value_name = "FILE")]
    surface_output: Option<PathBuf>,
    #[command(flatten)]
    surface_stage: super::surface::StageArgs,
    /// Draw the output's dihedral- and solid-angle histograms to this SVG.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    #[command(flatten)]
    image: super::extract::ImageArgs,
    #[command(flatten)]
    common: Common,
}

fn parse_region_sizes(items: &[String]) -> Result<Vec<(u32, f64)>> {
    items
        .iter()
        .map(|s| {
            let (l, h) = s
                .split_once('=')
                .with_context(|| format!("--region-size {s}: expected LABEL=H"))?;
            let l: u32 = l
                .trim()
                .parse()
                .with_context(|| format!("--region-size {s}: bad label"))?;
            let h: f64 = h
                .trim()
                .parse()
                .with_context(|| format!("--region-size {s}: bad size"))?;
            Ok((l, h))
        })
        .collect()
}

/// Run `biotet mesh`.
pub fn run(a: Args) -> Result<ExitCode> {
    if let [input] = &a.surfaces[..]
        && super::plane::is_pslg(input)
    {
        return super::plane::mesh(
            super::plane::MeshArgs {
                input,
                output: a.output.as_deref(),
                size: a.size,
                resolution: a.resolution,
                zone: match a.zone {
                    ZoneArg::Box => Zone::Box,
                    ZoneArg::Euclidean => Zone::Euclidean,
                },
                max_pixels: a.max_voxels,
                grading: a.grading,
                no_smooth: a.no_smooth,
                no_deploy: a.no_deploy,
                svg: a.svg.as_deref(),
                keep_failed: a.keep_failed,
            },
            a.common,
        );
    }
    let clock = Instant::now();
    let stage = Stage::start(a.common.quiet, "reading the surface");
    let mut image = None;
    let (surface, shells, name) = if a.surfaces.is_empty() {
        let part = Part {
            surface: biotet_io::stl::parse(EXAMPLE, EXAMPLE_NAME)?.mesh,
            labels: None,
        };
        stage.set("validating the surface");
        let (s, sh) = super::input::assemble_parts(vec![part], EXAMPLE_NAME, &[], a.common)?;
        (s, sh, EXAMPLE_NAME.to_string())
    } else if let [input] = &a.surfaces[..]
        && biotet_io::is_label_image(input)
    {
        // A label image: its labelled surface (see `extract`), then the pipeline as for any.
        let (s, summary) = super::extract::surface_from_image(input, &a.image, &stage)?;
        image = Some(summary);
        (s, Vec::new(), input.display().to_string())
    } else {
        super::input::labelled_surface(
            &a.surfaces,
            &a.label,
            a.common,
            &stage,
            super::input::Crossings::unless_staged(a.surface_tolerance.is_some()),
        )?
    };
    let seconds_read = clock.elapsed().as_secs_f64();
    // Image labels are the image's values (FreeSurfer's 2035 stays 2035); the template holds
    // small labels, so they are renumbered for meshing and put back after (a surface's too,
    // when it uses one the template cannot hold).
    let mut surface = surface;
    use biotet::image::labels::Compaction;
    let compaction = (image.is_some() || Compaction::needed(&surface))
        .then(|| Compaction::of_surface(&mut surface));
    // The surface stage (opt-in for a surface, the default for an image): the improved surface
    // replaces the input from here on.
    let tolerance = match &image {
        Some(i) => i.stage_tolerance(a.surface_tolerance, a.exact_surface),
        None => a.surface_tolerance,
    };
    let (mut surface, mut surface_report) = match tolerance {
        None => (surface, None),
        Some(d) => {
            stage.set("improving the surface");
            let orient = image.as_ref().is_none_or(|i| i.orient_sheets());
            let (s, r) =
                super::surface::stage(&surface, d, a.size, &a.surface_stage, orient, &stage)
                    .with_context(|| name.clone())?;
            (s, Some(r))
        }
    };
    // Restart the peak-memory count so it measures meshing, not reading and validating (Linux),
    // and keep one peak per stage.
    let mut peaks = StagePeaks::start("sizing");
    let (_, rss_before_kb) = super::delaunay::memory_kb();
    map_mesh_sized_blocks();

    let clock = Instant::now();
    let spec = match (a.size, &a.size_field) {
        (Some(h), _) => SizeSpec::UpTo {
            size: h,
            grading: a.grading,
        },
        (None, Some(path)) => {
            let grid = biotet_io::read_scalar_grid_named(path, a.size_field_array.as_deref())?;
            // An oblique image is meshed in its frame: the field is looked up in world.
            let to_world = image.as_ref().and_then(|i| i.frame_to_world);
            SizeSpec::from_grid(grid, to_world).with_context(|| path.display().to_string())?
        }
        (None, None) => SizeSpec::FromSurface { grading: a.grading },
    };
    let mut sizing = SizingOptions::new(spec);
    sizing.min_size = a.min_size;
    sizing.max_size = a.max_size;
    sizing.region_sizes = parse_region_sizes(&a.region_size)?;
    if let Some(c) = &compaction {
        for (l, _) in sizing.region_sizes.iter_mut() {
            *l = c
                .compact(*l)
                .with_context(|| format!("--region-size: no region {l} in the image"))?;
        }
    }
    biotet::sizing::check_region_labels(&surface, &sizing.region_sizes).context("--region-size")?;
    let sizing = Sizing::new(&surface, sizing).context("sizing")?;
    // Part of meshing: the surface-derived size is built from the surface here.
    let seconds_sizing = clock.elapsed().as_secs_f64();
    // Kept exactly, a surface triangle far larger than the size cannot have well-shaped tets
    // on it among nodes at that size: counted, for a note where such tets remain.
    let over_size = if surface_report.is_none() {
        triangles_over_size(&surface, &sizing)
    } else {
        0
    };

    let mut opts = PipelineOptions::default();
    opts.deploy.resolution = a.resolution;
    opts.deploy.zone = match a.zone {
        ZoneArg::Box => Zone::Box,
        ZoneArg::Euclidean => Zone::Euclidean,
    };
    opts.deploy.max_voxels = a.max_voxels;
    if a.no_smooth {
        opts.smooth = None;
    }
    if a.no_recover {
        opts.recover = None;
    }
    if let Some(r) = opts.recover.as_mut() {
        r.allow_interior_steiner = !a.no_steiner;
    }
    if a.no_improve {
        opts.improve = None;
    }
    // Seeds are a quality step, as polishing is: a raw mesh (--no-improve) has none.
    opts.seeds = !(a.no_seeds || a.no_steiner || a.no_improve);
    if a.no_steiner
        && let Some(p) = opts.polish.as_mut()
    {
        p.insert = false;
    }
    if a.no_polish || a.no_improve {
        opts.polish = None;
    }
    // Refused before any work when the estimate exceeds --max-memory.
    let limit = biotet_io::limits::max_memory();
    if let Some(estimate) = crate::memory::over_limit(&surface, &sizing, &opts.deploy, limit as f64)
    {
        anyhow::bail!(
            "{name}: meshing needs about {} of memory (about {:.0} nodes, {:.0} template voxels), \
             more than the limit of {} (--max-memory); give a larger size or a larger limit",
            biotet_io::limits::human(estimate.bytes.min(u64::MAX as f64) as u64),
            estimate.nodes,
            estimate.voxels,
            biotet_io::limits::human(limit)
        );
    }
    // Each stage starts from what the previous ones left in use, not from their peaks. The sizing
    // goes in by value, to be freed after deployment.
    let (mut mesh, report) = mesh_surface(&surface, sizing, &opts, &mut |s| {
        release_free_memory();
        peaks.next(Some(s));
        stage.set(s)
    })
    .with_context(|| name.clone())?;
    if let Some(c) = &compaction {
        c.restore_tets(&mut mesh);
        c.restore_surface(&mut surface);
        if let Some(r) = &mut surface_report {
            c.restore_report(r);
        }
    }
    if let Some(m) = image.as_ref().and_then(|i| i.frame_to_world.as_ref()) {
        // Meshed in the image's frame; a rotation (positive determinant) to world.
        biotet::image::map_points(m, &mut mesh.points);
        biotet::image::map_points(m, &mut surface.points);
    }
    if let Some(path) = &a.surface_output {
        biotet_io::write_surface(path, &surface)?;
    }
    let sheets = surface_report.as_ref().map_or(&[][..], |r| &r.sheets[..]);

    release_free_memory();
    peaks.next(Some("measuring"));
    stage.set("measuring");
    let quality = QualityReport::of(&mesh);
    let forcing = {
        let f = forced::classify(&mesh, &surface, FORCED_DEG);
        forced::summarise(&mesh, &f, FORCED_DEG)
    };
    // The peak of meshing alone, before the writer builds its arrays.
    peaks.next(None);
    let peak_meshing_kb = peaks.max();
    // A run that fails writes nothing at the requested paths (`--keep-failed`: the partial mesh
    // beside the output).
    let failed = report.recover.as_ref().is_some_and(|r| !r.is_complete());
    let (written, failure_note) = if failed {
        let requested: Vec<&Path> = a.output.iter().chain(&a.svg).map(|p| p.as_path()).collect();
        let (written, note) = output::on_failure(
            "partial mesh",
            a.output.as_deref(),
            &requested,
            a.keep_failed,
            |path| {
                release_free_memory();
                peaks.next(Some("writing"));
                stage.set(format!("writing {}", path.display()));
                biotet_io::write_tet_mesh(path, &mesh)
            },
        );
        (
            written,
            Some(if note.is_empty() {
                note
            } else {
                format!("; {note}")
            }),
        )
    } else {
        let mut sides = Vec::new();
        if let Some(svg) = &a.svg {
            peaks.next(Some("plotting"));
            sides.push((svg.as_path(), plot::quality_svg(&quality, &name)?));
        }
        let written = output::write_all(
            || match &a.output {
                Some(out) => {
                    release_free_memory();
                    peaks.next(Some("writing"));
                    stage.set(format!("writing {}", out.display()));
                    biotet_io::write_tet_mesh(out, &mesh)
                }
                None => Ok(Vec::new()),
            },
            &sides,
        )?;
        (written, None)
    };
    drop(stage);
    peaks.next(None);
    let peak_kb = peaks.max();
    if a.common.json {
        let mut v = json!({
            "input": name,
            "output": a.output,
            "written": written,
            "n_surface_triangles": surface.triangles.len(),
            "shells": shells,
            "seconds_read_validate": seconds_read,
            "seconds_sizing": seconds_sizing,
            "pipeline": report,
            "quality": quality,
            "forcing": forcing,
            "rss_before_kb": rss_before_kb,
            "peak_rss_kb": peak_kb,
            "peak_rss_meshing_kb": peak_meshing_kb,
            "stage_peak_rss_kb": peaks
                .peaks
                .iter()
                .map(|(stage, kb)| json!({"stage": stage, "peak_rss_kb": kb}))
                .collect::<Vec<_>>(),
            "mesh_bytes": mesh.bytes(),
            "input_triangles_over_size": over_size,
            "image": image,
            "image_regions": image
                .as_ref()
                .map(|i| super::extract::region_volumes(i, &mesh, &quality, sheets)),
        });
        if let Some(r) = &surface_report {
            v["surface"] = serde_json::to_value(r)?;
        }
        crate::emit(&serde_json::to_string_pretty(&v)?);
    } else if !a.common.quiet {
        let t = &report.template;
        if let Some(i) = &image {
            crate::emit(i.text().trim_end());
        }
        let mut text = format!(
            "{name}: {} triangles → {} points, {} tets in {:.3} s\n\
             template: {} × {} × {} voxels at {:.4} ({:.1} MB, {} zones), {} surface and {} interior nodes\n",
            surface.triangles.len(),
            report.n_points,
            report.n_tets,
            report.seconds_total,
            t.dims[0],
            t.dims[1],
            t.dims[2],
            t.dx,
            t.bytes as f64 / 1e6,
            match a.zone {
                ZoneArg::Box => "box",
                ZoneArg::Euclidean => "Euclidean",
            },
            report.n_surface_points,
            report.n_interior_nodes,
        );
        if report.n_unused_points > 0 {
            text += &format!(
                "{} input points used by no triangle left out\n",
                report.n_unused_points
            );
        }
        if let Some(r) = &surface_report {
            text += &super::surface::report_text(r);
            text.push('\n');
        }
        for s in &report.stages {
            text += &format!("  {:<22} {:.3} s\n", s.name, s.seconds);
        }
        text += &format!(
            "input triangles missing from the mesh: {}\n",
            report.missing_triangles
        );
        if let Some(r) = &report.recover
            && r.steiner_points > 0
        {
            text += &format!(
                "recover: {} Steiner points added strictly inside (never on the surface)\n",
                r.steiner_points
            );
        }
        if report.seeds > 0 {
            text += &format!(
                "seeds: {} interior points at the circumcentres of poor tets of surface points \
                 (thin sections)\n",
                report.seeds
            );
        }
        // Retries that neither removed nor added nodes (wide rounds) change no spacing.
        let (clearing, inset): (Vec<_>, Vec<_>) = report
            .retries
            .iter()
            .filter(|r| r.nodes_added > 0 || r.nodes_removed > 0)
            .partition(|r| r.nodes_added == 0);
        if !clearing.is_empty() {
            let removed: usize = clearing.iter().map(|r| r.nodes_removed).sum();
            text += &format!(
                "recover: tried again without the interior nodes near the triangles left ({} {}, \
                 {removed} nodes removed of {}): the mesh is coarser there than asked\n",
                clearing.len(),
                if clearing.len() == 1 { "time" } else { "times" },
                report.n_interior_nodes
            );
        }
        if let Some(s) = report.star.as_ref().filter(|s| !s.kept) {
            text += &format!(
                "recover: {} triangles left; every region is star-shaped, but its cones left out \
                 {} of {} interior nodes, so recovery's other fallbacks went first\n",
                s.triangles_left_by_recovery,
                s.nodes_left_out,
                s.nodes_inserted + s.nodes_left_out
            );
        }
        if let Some(s) = report.star.as_ref().filter(|s| s.kept) {
            text += &format!(
                "recover: {} triangles left; every region is star-shaped, so each was coned from \
                 one interior point ({} in all) and the {} interior nodes put back{}\n",
                s.triangles_left_by_recovery,
                s.regions,
                s.nodes_inserted,
                if s.nodes_left_out > 0 {
                    format!(
                        " ({} left out, no valid cavity among the cone's thin tets: the mesh is \
                         coarser there than asked)",
                        s.nodes_left_out
                    )
                } else {
                    String::new()
                }
            );
        }
        if !inset.is_empty() {
            let added: usize = inset.iter().map(|r| r.nodes_added).sum();
            text += &format!(
                "recover: tried again with {added} nodes just behind the triangles left and their \
                 neighbours ({} {}; the last fallback)\n",
                inset.len(),
                if inset.len() == 1 { "time" } else { "times" }
            );
        }
        text += &format!(
            "min dihedral {:.3}°, max {:.3}°, tets below 10°: {}, mean q {:.3}",
            quality.min_dihedral_deg.unwrap_or(f64::NAN),
            quality.max_dihedral_deg.unwrap_or(f64::NAN),
            quality.n_dihedral_lt_10,
            quality.mean_q.unwrap_or(f64::NAN)
        );
        text += &format!(
            "\nforced by the input (a face or fold under {FORCED_DEG}°): {} tets; unforced tets \
             below 10°: {} ({})",
            forcing.n_forced,
            forcing.n_unforced_dihedral_lt_10,
            forcing.cause_text()
        );
        if over_size > 0 && forcing.n_unforced_dihedral_lt_10 > 0 {
            text += &format!(
                "\nnote: {over_size} input triangles are over {OVER_SIZE} times the size where \
                 they lie, and kept exactly the tets on them cannot all be well shaped: \
                 --surface-tolerance D remeshes the surface to the size, moving it at most D"
            );
        }
        if let Some(i) = &image {
            text += "\n";
            text += super::extract::region_text(&super::extract::region_volumes(
                i, &mesh, &quality, sheets,
            ))
            .trim_end();
        }
        crate::emit(&text);
    }
    if let (Some(r), Some(note)) = (&report.recover, &failure_note) {
        // An error: printed with --quiet too.
        eprintln!(
            "error: {name}: {} input triangles could not be recovered{}{note}; the first ones:",
            r.missing_after,
            super::recover::steiner_text(a.no_steiner)
        );
        for line in super::recover::unrecovered_lines(r) {
            eprintln!("  {line}");
        }
        if a.no_steiner {
            eprintln!(
                "  (without --no-steiner, recovery adds points strictly inside the domain where \
                 no fill exists without new points)"
            );
        }
        eprintln!(
            "  (a size much finer than these triangles makes their cavities large: a size \
             closer to the surface's edges, or --size-from-surface, usually recovers them)"
        );
        return Ok(ExitCode::from(crate::EXIT_INVALID));
    }
    Ok(ExitCode::SUCCESS)
}

/// A surface triangle whose longest edge is over this many times the size at its centroid is
/// counted by [`triangles_over_size`].
const OVER_SIZE: f64 = 3.0;

/// Surface triangles whose longest edge is over [`OVER_SIZE`] times the size at their centroid
/// (in the region on either side with the smaller size).
fn triangles_over_size(surface: &SurfaceMesh, sizing: &Sizing) -> usize {
    (0..surface.triangles.len())
        .filter(|&t| {
            let c = surface.corners(t);
            let longest = (0..3)
                .map(|k| norm(sub(c[k], c[(k + 1) % 3])))
                .fold(0.0, f64::max);
            let g = [0, 1, 2].map(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
            let size = surface.sides[t]
                .iter()
                .filter(|&&r| r != 0)
                .map(|&r| sizing.at(g, r))
                .fold(f64::INFINITY, f64::min);
            size.is_finite() && longest > OVER_SIZE * size
        })
        .count()
}
