//! Label images in: `biotet surface-extract IMAGE -o OUT` (the labelled surface alone) and the
//! image path of `biotet mesh IMAGE` (the options of [`ImageArgs`], then the pipeline).

use crate::{Common, progress::Stage};
use anyhow::{Context, Result, bail};
use biotet::image::labels::LabelOptions;
pub use biotet::image::surface::ImageSummary;
use biotet::image::surface::{ImageSurfaceError, RegionVolume, labelled_surface};
use biotet::quality::QualityReport;
use biotet::surface::SheetDistance;
use biotet::{SurfaceMesh, TetMesh};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// How an image's voxel values become regions (for `biotet mesh IMAGE` and
/// `biotet surface-extract`).
#[derive(clap::Args, Clone, Debug, Default)]
pub struct ImageArgs {
    /// Image input only: keep only these labels (after --merge); the others become outside.
    #[arg(long, value_name = "L,L,...", value_delimiter = ',')]
    pub labels: Option<Vec<u32>>,
    /// Image input only: join labels, as A,B,...=TARGET (repeatable).
    #[arg(long, value_name = "A,B=T")]
    pub merge: Vec<String>,
    /// Image input only: the value of the outside.
    #[arg(long, value_name = "V", default_value_t = 0)]
    pub outside: u32,
    /// Image input only: 6-connected islands of fewer voxels are merged into the label most of
    /// their neighbours have (0 keeps all).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub min_component_voxels: usize,
}

impl ImageArgs {
    fn options(&self) -> Result<LabelOptions> {
        let merge = self
            .merge
            .iter()
            .map(|m| {
                let (from, to) = m
                    .split_once('=')
                    .with_context(|| format!("--merge {m}: expected A,B,...=TARGET"))?;
                let from = from
                    .split(',')
                    .map(|t| t.trim().parse::<u32>())
                    .collect::<Result<Vec<u32>, _>>()
                    .with_context(|| format!("--merge {m}: bad label"))?;
                let to = to
                    .trim()
                    .parse()
                    .ok()
                    .and_then(biotet_io::checked_label)
                    .with_context(|| {
                        format!(
                            "--merge {m}: the target is a whole number from 0 to {}",
                            biotet_io::MAX_LABEL
                        )
                    })?;
                Ok((from, to))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(LabelOptions {
            keep: self.labels.clone(),
            merge,
            outside: self.outside,
            min_component_voxels: self.min_component_voxels,
        })
    }
}

/// Read an image, apply the label options, extract and validate the labelled surface
/// ([`labelled_surface`]). The surface is in the image's frame: map it with
/// [`ImageSummary::frame_to_world`] when set.
pub fn surface_from_image(
    path: &Path,
    args: &ImageArgs,
    stage: &Stage,
) -> Result<(SurfaceMesh, ImageSummary)> {
    let clock = Instant::now();
    stage.set(format!("reading {}", path.display()));
    let img = biotet_io::read_label_image(path)?;
    let seconds_read = clock.elapsed().as_secs_f64();
    let name = path.display().to_string();
    let (surface, mut summary) =
        labelled_surface(img, &args.options()?, &name, &mut |s| stage.set(s)).map_err(
            |e| match e {
                // The surface's own error kept, so `main` exits as for any invalid surface.
                ImageSurfaceError::Surface(e) => {
                    anyhow::Error::new(e).context(format!("{name}: the extracted surface"))
                }
                ImageSurfaceError::Labels(e) => anyhow::Error::new(e).context(name.clone()),
            },
        )?;
    summary.seconds_read = seconds_read;
    Ok((surface, summary))
}

/// Per region: voxel volume beside the mesh's volume (and its relative error), its tets and
/// dihedral angle range.
pub fn region_volumes(
    summary: &ImageSummary,
    mesh: &TetMesh,
    quality: &QualityReport,
    sheets: &[SheetDistance],
) -> Vec<RegionVolume> {
    summary.region_volumes(mesh, quality, sheets)
}

/// Text table of [`region_volumes`].
pub fn region_text(rows: &[RegionVolume]) -> String {
    let mut t = String::from(
        "region      voxels   voxel volume    mesh volume     error      tets  dihedral         \
         to voxels / back\n",
    );
    for r in rows {
        t += &format!(
            "{:>6}  {:>10}  {:>13.6e}  {:>13.6e}  {:>+8.1e}  {:>8}  {:.2}°–{:.2}°  {:.3} / {:.3}\n",
            r.label,
            r.voxels,
            r.voxel_volume,
            r.mesh_volume,
            r.relative_error,
            r.tets,
            r.min_dihedral_deg.unwrap_or(f64::NAN),
            r.max_dihedral_deg.unwrap_or(f64::NAN),
            r.hausdorff_in_to_out,
            r.hausdorff_out_to_in,
        );
    }
    for r in rows {
        if r.components != r.components_voxels {
            t += &format!(
                "warning: region {} ({} voxels) has {} connected components in the mesh, {} in \
                 its voxels\n",
                r.label, r.voxels, r.components, r.components_voxels
            );
        }
    }
    t
}

/// Arguments of `biotet surface-extract`.
#[derive(clap::Args)]
pub struct Args {
    /// Label image: .nii, .nii.gz, .mgh, .mgz, .nrrd, .nhdr, .mha, .mhd, .vti (world
    /// coordinates RAS+, see docs/formats.md).
    pub(crate) image: PathBuf,
    /// Output labelled surface (.vtu, .vtp, .vtk, .ply or .mesh keep the labels on both sides of
    /// each triangle).
    #[arg(short, long, value_name = "OUT")]
    pub(crate) output: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) image_args: ImageArgs,
    #[command(flatten)]
    pub(crate) common: Common,
}

/// Run `biotet surface-extract`.
pub fn run(a: Args) -> Result<ExitCode> {
    if !biotet_io::is_label_image(&a.image) {
        bail!(
            "{}: not a label image ({})",
            a.image.display(),
            biotet_io::image::IMAGE_EXTENSIONS
        );
    }
    let stage = Stage::start(a.common.quiet, "reading");
    let (surface, summary) = surface_from_image(&a.image, &a.image_args, &stage)?;
    let mut surface = surface;
    if let Some(m) = &summary.frame_to_world {
        biotet::image::map_points(m, &mut surface.points);
    }
    if let Some(out) = &a.output {
        stage.set(format!("writing {}", out.display()));
        biotet_io::write_surface(out, &surface)?;
    }
    drop(stage);
    if a.common.json {
        crate::emit(&serde_json::to_string_pretty(&json!({
            "input": a.image,
            "output": a.output,
            "image": summary,
        }))?);
    } else if !a.common.quiet {
        let mut t = summary.text();
        t += "region      voxels   voxel volume  components (in the image)\n";
        for r in &summary.regions {
            t += &format!(
                "{:>6}  {:>10}  {:>13.6e}  {} ({})\n",
                r.label, r.voxels, r.voxel_volume, r.components, r.components_in_image
            );
        }
        crate::emit(t.trim_end());
    }
    Ok(ExitCode::SUCCESS)
}
