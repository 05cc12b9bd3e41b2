//! `biotet view`: a picture of a tet mesh, cut by a plane or its boundary seen from one
//! viewpoint, as SVG or PNG.

use super::input::numbers;
use crate::view::section::{Coloring, Plane};
use crate::view::{Layout, iso, raster, section, svg};
use crate::{Common, progress::Stage};
use anyhow::{Result, bail};
use biotet::TetMesh;
use serde_json::json;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Examples at the end of `biotet view --help`.
const EXAMPLES: &str = "\
Examples:
  biotet view brain.vtu -o brain_cut.svg                      (cut at the middle in z)
  biotet view head.vtu --cut y=-18 --color quality -o head_quality.png
  biotet view brain.vtu --cut-normal 1,1,0 --surface brain.stl -o brain_oblique.svg
  biotet view head.vtu --view iso -o head.png";

/// What is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum View {
    /// The tets a plane cuts, as their cross-sections.
    Cut,
    /// The boundary surface seen from +x, −y, +z, shaded.
    Iso,
}

/// Arguments of `biotet view`.
#[derive(clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// The tet mesh (.vtu, .vtk, .mesh, .msh, .node/.ele).
    mesh: PathBuf,
    /// The picture: .svg or .png.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// The cutting plane across an axis, as AXIS=VALUE (x=12.5, y=-3, z=0). Default: z through
    /// the middle of the mesh's bounding box.
    #[arg(
        long,
        value_name = "AXIS=VALUE",
        conflicts_with = "cut_normal",
        allow_hyphen_values = true
    )]
    cut: Option<String>,
    /// An oblique cutting plane by its normal NX,NY,NZ, through --cut-point (default: the
    /// middle of the bounding box).
    #[arg(long, value_name = "NX,NY,NZ", allow_hyphen_values = true)]
    cut_normal: Option<String>,
    /// A point of the oblique plane, X,Y,Z.
    #[arg(
        long,
        value_name = "X,Y,Z",
        requires = "cut_normal",
        allow_hyphen_values = true
    )]
    cut_point: Option<String>,
    /// Colour the cut tets by region label or by their smallest dihedral angle.
    #[arg(long, value_enum, default_value_t = Coloring::Label)]
    color: Coloring,
    /// Draw a cut (default) or the boundary seen from one viewpoint.
    #[arg(long, value_enum, default_value_t = View::Cut)]
    view: View,
    /// A surface whose trace on the plane is drawn over the cut (magenta). Repeatable.
    #[arg(long = "surface", short = 's', value_name = "SURFACE")]
    surfaces: Vec<PathBuf>,
    /// Width of the picture in pixels (the height follows the mesh).
    #[arg(long, value_name = "PX", default_value_t = 1000)]
    width: u32,
    #[command(flatten)]
    common: Common,
}

/// The middle of the points' bounding box.
fn middle(mesh: &TetMesh) -> [f64; 3] {
    let (lo, hi) = biotet::geom::vec3::points_bbox(&mesh.points);
    if lo[0] > hi[0] {
        return [0.0; 3];
    }
    [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]))
}

/// The plane of the options, and its description for the title.
fn plane(a: &Args, mesh: &TetMesh) -> Result<(Plane, String)> {
    let mid = middle(mesh);
    if let Some(n) = &a.cut_normal {
        let n = numbers("cut-normal", n, 3)?;
        let p = match &a.cut_point {
            Some(p) => numbers("cut-point", p, 3)?,
            None => mid.to_vec(),
        };
        let p = [p[0], p[1], p[2]];
        let Some(pl) = Plane::through(p, [n[0], n[1], n[2]]) else {
            bail!("--cut-normal: the normal must not be zero");
        };
        let d = |x: f64| crate::view::short((x * 100.0).round() / 100.0);
        return Ok((
            pl,
            format!(
                "normal ({}, {}, {}) through ({}, {}, {})",
                d(n[0]),
                d(n[1]),
                d(n[2]),
                d(p[0]),
                d(p[1]),
                d(p[2])
            ),
        ));
    }
    let (axis, value) = match &a.cut {
        None => (2, mid[2]),
        Some(spec) => {
            let Some((ax, v)) = spec.split_once('=') else {
                bail!("--cut {spec}: expected AXIS=VALUE, e.g. z=10");
            };
            let axis = match ax.trim() {
                "x" | "X" => 0,
                "y" | "Y" => 1,
                "z" | "Z" => 2,
                other => bail!("--cut {spec}: the axis must be x, y or z, not {other:?}"),
            };
            let Ok(value) = v.trim().parse::<f64>() else {
                bail!("--cut {spec}: {v:?} is not a number");
            };
            if !value.is_finite() {
                bail!("--cut {spec}: the value must be finite");
            }
            (axis, value)
        }
    };
    let name = ["x", "y", "z"][axis];
    Ok((
        Plane::axis(axis, value),
        format!(
            "{name} = {}",
            crate::view::short((value * 1000.0).round() / 1000.0)
        ),
    ))
}

enum Format {
    Svg,
    Png,
}

fn format_of(path: &Path) -> Result<Format> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("svg") => Ok(Format::Svg),
        Some("png") => Ok(Format::Png),
        _ => bail!("{}: the picture must be .svg or .png", path.display()),
    }
}

/// Run `biotet view`.
pub fn run(a: Args) -> Result<ExitCode> {
    let start = Instant::now();
    let format = format_of(&a.output)?;
    if !(64..=20_000).contains(&a.width) {
        bail!("--width {}: expected 64 to 20000 pixels", a.width);
    }
    let stage = Stage::start(a.common.quiet, format!("reading {}", a.mesh.display()));
    let mesh = super::input::tet_mesh(&a.mesh, a.common)?;
    let surface = super::input::surfaces(&a.surfaces, a.common, &stage)?;
    stage.set("drawing");
    let name = a
        .mesh
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let (mut scene, report) = match a.view {
        View::Cut => {
            let (pl, desc) = plane(&a, &mesh)?;
            let (scene, counts) = section::cut(&mesh, &pl, a.color, surface.as_ref());
            let colour = match a.color {
                Coloring::Label => "by region",
                Coloring::Quality => "by smallest dihedral angle",
            };
            let title = format!(
                "{name}: cut at {desc}, {} tets, coloured {colour}",
                counts.tets_cut
            );
            (
                scene,
                json!({ "view": "cut", "plane": desc, "counts": counts, "title": title }),
            )
        }
        View::Iso => {
            let (scene, faces) = iso::boundary(&mesh);
            let title = format!("{name}: boundary, {faces} faces facing the viewer");
            (
                scene,
                json!({ "view": "iso", "faces_drawn": faces, "title": title }),
            )
        }
    };
    scene.title = report["title"].as_str().unwrap_or_default().to_string();
    let bytes = match format {
        Format::Svg => svg::render(&scene, a.width).into_bytes(),
        Format::Png => raster::render(&scene, a.width)?,
    };
    stage.set(format!("writing {}", a.output.display()));
    let out = a.output.display().to_string();
    biotet_io::atomic::write_atomic(&a.output, |w| {
        w.write_all(&bytes)
            .map_err(|e| biotet_io::Error::io(&out, e))
    })?;
    drop(stage);
    let layout = Layout::fit(&scene, a.width);
    let seconds = start.elapsed().as_secs_f64();
    if a.common.json {
        let mut r = report;
        r["output"] = json!(out);
        r["width"] = json!(layout.width);
        r["height"] = json!(layout.height);
        r["bytes"] = json!(bytes.len());
        r["seconds"] = json!(seconds);
        crate::emit(&serde_json::to_string_pretty(&r)?);
    } else if !a.common.quiet {
        crate::emit(&format!(
            "{} ({}×{} px, {:.2} s): {}",
            out, layout.width, layout.height, seconds, scene.title
        ));
    }
    Ok(ExitCode::SUCCESS)
}
