//! `biotet remesh`: replace one region, or the tets meeting a box or a sphere, at a new size, or
//! embed a closed surface as a new region; every other tet stays exactly as it was (see
//! `biotet::remesh`).

use super::input::numbers;
use crate::{Common, progress::Stage};
use anyhow::{Context, Result, bail};
use biotet::TetMesh;
use biotet::pipeline::PipelineOptions;
use biotet::quality::QualityReport;
use biotet::remesh::{RemeshReport, Zone, across_shell, insert, remesh};
use biotet::sizing::{SizeSpec, Sizing, SizingError, SizingOptions};
use serde_json::json;
use std::path::PathBuf;
use std::process::ExitCode;

/// Examples at the end of `biotet remesh --help`.
const EXAMPLES: &str = "\
Examples:
  biotet remesh head.vtu --region 2 --size 1.5 -o head_fine_wm.vtu
  biotet remesh head.vtu --sphere 10,-20,35,10 --size 0.8 -o head_electrode.vtu
  biotet remesh head.vtu --box 0,0,0,20,20,20 --size 3 -o head_coarse.vtu --json
  biotet remesh head.vtu --region 3 --size-field sizes.vti -o head_graded_csf.vtu
  biotet remesh head.vtu --insert lesion.stl --label 5 --margin 2 -o head_lesion.vtu
  biotet remesh head.vtu --region 2 --size 3 --allow-shell-changes -o head_coarse_wm.vtu

--insert embeds a closed surface lying inside one region: the tets meeting it and those within
--margin of it are refilled, its inside labelled L. Without --size the sizes come from the
surface's and the cavity shell's edges, which suits a surface finer than the mesh. A surface that meets or crosses an
interface or the outer boundary (or encloses part of one) is refused, naming the triangle, the
interface and the point; crossing an interface is not handled yet.";

/// Arguments of `biotet remesh`.
#[derive(clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// The tet mesh (.vtu, .vtk, .mesh, .msh, .node/.ele) with its region labels.
    mesh: PathBuf,
    /// Output tet mesh (.vtu, .vtk, .mesh, .msh, .node/.ele).
    #[arg(short, long, value_name = "OUT")]
    output: PathBuf,
    /// Replace every tet of this region.
    #[arg(long, value_name = "L", conflicts_with_all = ["box_zone", "sphere", "insert"])]
    region: Option<u32>,
    /// Replace every tet meeting the box X0,Y0,Z0,X1,Y1,Z1 (each region refilled with its own
    /// label).
    #[arg(
        long = "box",
        value_name = "X0,Y0,Z0,X1,Y1,Z1",
        conflicts_with_all = ["sphere", "insert"],
        allow_hyphen_values = true
    )]
    box_zone: Option<String>,
    /// Replace every tet meeting the ball X,Y,Z,R.
    #[arg(
        long,
        value_name = "X,Y,Z,R",
        allow_hyphen_values = true,
        conflicts_with = "insert"
    )]
    sphere: Option<String>,
    /// Embed this closed surface (inside one region) as a new region labelled --label.
    #[arg(long, value_name = "SURFACE", requires = "label")]
    insert: Option<PathBuf>,
    /// The label of the inside of the --insert surface.
    #[arg(long, value_name = "L", requires = "insert")]
    label: Option<u32>,
    /// With --insert: also replace the tets with a corner within this distance of the surface
    /// (default: --size, or the surface's mean edge length).
    #[arg(long, value_name = "M", requires = "insert")]
    margin: Option<f64>,
    /// Uniform size of the new tets. Without it (or --size-field), sizes come from the cavity's
    /// shell (its edges, growing inward by --grading).
    #[arg(long, value_name = "H", conflicts_with = "size_field")]
    size: Option<f64>,
    /// Size of the new tets from a regular grid file (VTK image data .vti, NIfTI .nii/.nii.gz),
    /// interpolated trilinearly, clamped to the grid outside it; in the mesh's coordinates.
    #[arg(long, value_name = "FILE")]
    size_field: Option<PathBuf>,
    /// Which array of a .vti size field (default: the active point scalars, else the first).
    #[arg(long, value_name = "NAME", requires = "size_field")]
    size_field_array: Option<String>,
    /// Let sliver removal work across the zone's shell: the kept tets sharing a corner with the
    /// new ones may be replaced too (no point added, moved or dropped; boundary and interfaces
    /// kept). The replaced tets are reported by their input index.
    #[arg(long)]
    allow_shell_changes: bool,
    /// Growth of the shell-derived size per unit distance (without --size).
    #[arg(long, value_name = "G", default_value_t = 0.3)]
    grading: f64,
    #[command(flatten)]
    common: Common,
}

fn zone(a: &Args) -> Result<Zone> {
    if let Some(r) = a.region {
        return Ok(Zone::Region(r));
    }
    if let Some(b) = &a.box_zone {
        let v = numbers("box", b, 6)?;
        let (lo, hi) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]]);
        if (0..3).any(|k| lo[k] > hi[k]) {
            bail!("--box {b}: the first corner must be below the second in x, y and z");
        }
        return Ok(Zone::Box { lo, hi });
    }
    if let Some(s) = &a.sphere {
        let v = numbers("sphere", s, 4)?;
        if v[3] <= 0.0 {
            bail!("--sphere {s}: the radius must be positive");
        }
        return Ok(Zone::Sphere {
            centre: [v[0], v[1], v[2]],
            radius: v[3],
        });
    }
    bail!(
        "give the zone to remesh: --region L, --box X0,Y0,Z0,X1,Y1,Z1, --sphere X,Y,Z,R or \
         --insert SURFACE --label L"
    )
}

/// The mean edge length of a surface (0 for none).
fn mean_edge(s: &biotet::SurfaceMesh) -> f64 {
    let mut sum = 0.0;
    for t in 0..s.triangles.len() {
        let c = s.corners(t);
        for k in 0..3 {
            sum += biotet::geom::vec3::norm(biotet::geom::vec3::sub(c[(k + 1) % 3], c[k]));
        }
    }
    sum / (3 * s.triangles.len()).max(1) as f64
}

/// Run `biotet remesh`.
pub fn run(a: Args) -> Result<ExitCode> {
    if let Some(h) = a.size
        && !(h > 0.0 && h.is_finite())
    {
        bail!("--size {h}: expected a positive number");
    }
    if let Some(m) = a.margin
        && !(m >= 0.0 && m.is_finite())
    {
        bail!("--margin {m}: expected a number at least 0");
    }
    // The zone's arguments are checked before anything is read.
    let zone = match a.insert {
        Some(_) => Zone::Region(0),
        None => zone(&a)?,
    };
    let stage = Stage::start(a.common.quiet, format!("reading {}", a.mesh.display()));
    let mesh = super::input::tet_mesh(&a.mesh, a.common)?;
    let name = a.mesh.display().to_string();
    // One grid shared by every cavity's sizing.
    let field = match &a.size_field {
        Some(path) => {
            let grid = std::sync::Arc::new(biotet_io::read_scalar_grid_named(
                path,
                a.size_field_array.as_deref(),
            )?);
            // Checked once here, so each cavity's use below cannot fail.
            SizeSpec::from_grid(grid.clone(), None).with_context(|| path.display().to_string())?;
            Some(grid)
        }
        None => None,
    };
    let spec = || match (a.size, &field) {
        (Some(h), _) => Ok(SizeSpec::Uniform(h)),
        (None, Some(grid)) => SizeSpec::from_grid(grid.clone(), None),
        (None, None) => Ok(SizeSpec::FromSurface { grading: a.grading }),
    };
    let opts = PipelineOptions::default();
    // Each cavity is refused before its meshing starts when its estimate exceeds --max-memory.
    let limit = biotet_io::limits::max_memory();
    let sizing = |s: &biotet::SurfaceMesh| {
        let z = Sizing::new(s, SizingOptions::new(spec()?))?;
        if let Some(e) = crate::memory::over_limit(s, &z, &opts.deploy, limit as f64) {
            return Err(SizingError::OverBudget(format!(
                "refilling a cavity needs about {} of memory (about {:.0} nodes), more than the \
                 limit of {} (--max-memory); give a larger --size or a larger limit",
                biotet_io::limits::human(e.bytes.min(u64::MAX as f64) as u64),
                e.nodes,
                biotet_io::limits::human(limit)
            )));
        }
        Ok(z)
    };
    let mut progress = |s: &str| stage.set(s.to_string());
    let (mut out, mut report, what): (TetMesh, RemeshReport, _) = match &a.insert {
        None => {
            let (out, report) = remesh(&mesh, &zone, &sizing, &opts, &mut progress)
                .with_context(|| format!("{name}: cannot remesh"))?;
            (out, report, json!(format!("{zone:?}")))
        }
        Some(path) => {
            stage.set(format!("reading {}", path.display()));
            let mut surface = biotet_io::read_surface(path)?.mesh;
            // A soup is the surface it describes, as for `biotet mesh`.
            let welded = surface.weld_exact();
            super::input::note_welded(&path.display().to_string(), welded, a.common);
            let label = a.label.unwrap_or(0);
            let margin = a.margin.unwrap_or(match a.size {
                Some(h) => h,
                None => mean_edge(&surface),
            });
            let (out, report) = insert(
                &mesh,
                &surface,
                label,
                margin,
                &sizing,
                &opts,
                &mut progress,
            )
            .with_context(|| format!("{name}: cannot insert {}", path.display()))?;
            let what = json!({ "insert": path, "label": label, "margin": margin });
            (out, report, what)
        }
    };
    if a.allow_shell_changes {
        stage.set("sliver removal across the shell");
        out = across_shell(&out, &mut report, &opts.improve.unwrap_or_default());
    }
    stage.set("measuring");
    let new_tets = TetMesh {
        points: out.points.clone(),
        tets: out.tets[report.tets_kept..].to_vec(),
        neighbors: Vec::new(),
        labels: out.labels[report.tets_kept..].to_vec(),
    };
    let q_new = QualityReport::of(&new_tets);
    let q_all = QualityReport::of(&out);
    stage.set(format!("writing {}", a.output.display()));
    let written = crate::output::write_all(|| biotet_io::write_tet_mesh(&a.output, &out), &[])?;
    drop(stage);
    if a.common.json {
        crate::emit(&serde_json::to_string_pretty(&json!({
            "input": name,
            "output": a.output,
            "written": written,
            "zone": what,
            "remesh": report,
            "quality_new": q_new,
            "quality": q_all,
        }))?);
    } else if !a.common.quiet {
        let mut text = format!(
            "{name}: {} of {} tets replaced by {} in {:.3} s; {} kept untouched\n",
            report.tets_before - report.tets_kept,
            report.tets_before,
            report.tets_after - report.tets_kept,
            report.seconds_total,
            report.tets_kept
        );
        for c in &report.cavities {
            text += &format!(
                "  region {}: {} → {} tets, shell of {} triangles kept, {} points added, {:.3} s\n",
                c.region,
                c.tets_removed,
                c.tets_added,
                c.shell_triangles,
                c.points_added,
                c.pipeline.seconds_total
            );
        }
        if let Some(c) = &report.shell_changes {
            text += &format!(
                "  across the shell: {} of {} kept tets around the zone replaced by sliver removal \
                 ({} → {} tets there, {:.3} s)\n",
                c.kept_replaced.len(),
                c.kept_offered,
                c.tets_before,
                c.tets_after,
                c.seconds
            );
        }
        if let Some(l) = a.label.filter(|_| a.insert.is_some()) {
            let inside = out.labels[report.tets_kept..]
                .iter()
                .filter(|&&x| x == l)
                .count();
            text += &format!("  inside the inserted surface: {inside} tets labelled {l}\n");
        }
        text += &format!(
            "new tets: min dihedral {:.3}°, max {:.3}°, below 10°: {}\nwhole mesh: min dihedral {:.3}°, max {:.3}°, below 10°: {}",
            q_new.min_dihedral_deg.unwrap_or(f64::NAN),
            q_new.max_dihedral_deg.unwrap_or(f64::NAN),
            q_new.n_dihedral_lt_10,
            q_all.min_dihedral_deg.unwrap_or(f64::NAN),
            q_all.max_dihedral_deg.unwrap_or(f64::NAN),
            q_all.n_dihedral_lt_10,
        );
        crate::emit(&text);
    }
    Ok(ExitCode::SUCCESS)
}
