//! Label images in: `biotet surface-extract IMAGE -o OUT` (the labelled surface alone) and the
//! image path of `biotet mesh IMAGE` (the options of [`ImageArgs`], then the pipeline).

use crate::{Common, progress::Stage};
use anyhow::{Context, Result, bail};
use biotet::SurfaceMesh;
use biotet::image::extract::{ExtractReport, extract};
use biotet::image::labels::{LabelOptions, LabelReport, apply};
use biotet::mesh::validate::{ValidateOptions, validate_surface};
use biotet::quality::QualityReport;
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
                    .parse::<u32>()
                    .with_context(|| format!("--merge {m}: bad target"))?;
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

/// What reading and extracting an image gave, for the reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ImageSummary {
    /// The image file.
    pub file: String,
    /// Voxels per axis.
    pub dims: [usize; 3],
    /// Voxel spacing per index axis (world units).
    pub spacing: [f64; 3],
    /// Volume of one voxel.
    pub voxel_volume: f64,
    /// Voxel → world (RAS+).
    pub voxel_to_world: [[f64; 4]; 4],
    /// For an oblique image, the frame → world map: the surface is extracted (and the mesh
    /// made) in the image's axis-aligned frame, where voxel faces are exactly flat, and mapped
    /// to world at the end (see `LabelImage::to_frame`). `None`: already axis-aligned.
    pub frame_to_world: Option<[[f64; 4]; 4]>,
    /// The surface stage's default tolerance for this image (half the smallest spacing); the
    /// surface stage (issue 20) is not applied here.
    pub default_surface_tolerance: f64,
    /// Labels, islands.
    pub labels: LabelReport,
    /// Extraction: manifold repairs, points, triangles.
    pub extract: ExtractReport,
    /// Per region after everything: label, voxels, voxel volume (voxels × voxel volume).
    pub regions: Vec<RegionVoxels>,
    /// Seconds reading, applying labels, extracting, validating.
    pub seconds_read: f64,
    /// Seconds applying the label options.
    pub seconds_labels: f64,
    /// Seconds extracting the surface (repair included).
    pub seconds_extract: f64,
    /// Seconds validating the surface.
    pub seconds_validate: f64,
}

/// A region's voxels.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RegionVoxels {
    /// Its label (the image's value).
    pub label: u32,
    /// Its voxels, after islands and manifold repair (what the surface encloses).
    pub voxels: usize,
    /// `voxels × voxel volume`.
    pub voxel_volume: f64,
    /// Its 6-connected components in the image (after the label options).
    pub components_in_image: usize,
    /// Its 6-connected components in what the surface encloses (after the manifold repair;
    /// a region the repair split or lost shows here).
    pub components: usize,
}

/// Read an image, apply the label options, extract and validate the labelled surface. The
/// surface is in the image's frame: map it with [`ImageSummary::frame_to_world`] when set.
pub fn surface_from_image(
    path: &Path,
    args: &ImageArgs,
    stage: &Stage,
) -> Result<(SurfaceMesh, ImageSummary)> {
    let clock = Instant::now();
    stage.set(format!("reading {}", path.display()));
    let mut img = biotet_io::read_label_image(path)?;
    let seconds_read = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    stage.set("applying labels");
    let labels = apply(&mut img, &args.options()?).with_context(|| path.display().to_string())?;
    let seconds_labels = clock.elapsed().as_secs_f64();
    let voxel_to_world = img.voxel_to_world;
    let frame_to_world = img.to_frame();
    let clock = Instant::now();
    stage.set("extracting the surface");
    let (mut surface, extract) = extract(&mut img);
    let seconds_extract = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    stage.set("validating the surface");
    // Embedded by construction (faces of the grid meet in grid edges and corners): the
    // self-intersection search is skipped; the rest is checked.
    let opts = ValidateOptions {
        self_intersections: false,
        ..Default::default()
    };
    validate_surface(&mut surface, &opts)
        .with_context(|| format!("{}: the extracted surface", path.display()))?;
    let seconds_validate = clock.elapsed().as_secs_f64();
    let vv = img.voxel_volume();
    let comps = biotet::image::labels::Components::of(&img);
    let count_of = |v: &[(u32, usize)], l: u32| v.iter().find(|c| c.0 == l).map_or(0, |c| c.1);
    let mut after: Vec<(u32, usize)> = Vec::new();
    for c in comps.list.iter().filter(|c| c.label != 0) {
        match after.iter_mut().find(|a| a.0 == c.label) {
            Some(a) => a.1 += 1,
            None => after.push((c.label, 1)),
        }
    }
    drop(comps);
    let mut regions: Vec<RegionVoxels> = img
        .counts()
        .into_iter()
        .filter(|c| c.0 != 0)
        .map(|(label, voxels)| RegionVoxels {
            label,
            voxels,
            voxel_volume: voxels as f64 * vv,
            components_in_image: count_of(&labels.components, label),
            components: count_of(&after, label),
        })
        .collect();
    // A region the repair took whole is reported too, with no voxels.
    for &(label, n) in &labels.components {
        if !regions.iter().any(|r| r.label == label) {
            regions.push(RegionVoxels {
                label,
                voxels: 0,
                voxel_volume: 0.0,
                components_in_image: n,
                components: 0,
            });
        }
    }
    regions.sort_by_key(|r| r.label);
    let summary = ImageSummary {
        file: path.display().to_string(),
        dims: img.dims,
        spacing: img.spacing(),
        voxel_volume: vv,
        voxel_to_world,
        frame_to_world,
        default_surface_tolerance: img.default_surface_tolerance(),
        labels,
        extract,
        regions,
        seconds_read,
        seconds_labels,
        seconds_extract,
        seconds_validate,
    };
    Ok((surface, summary))
}

impl ImageSummary {
    /// Text lines for the reports.
    pub fn text(&self) -> String {
        let mut t = format!(
            "{}: {} × {} × {} voxels of {:.4} × {:.4} × {:.4} → {} triangles, {} points \
             (read {:.3} s, labels {:.3} s, extract {:.3} s, validate {:.3} s)\n",
            self.file,
            self.dims[0],
            self.dims[1],
            self.dims[2],
            self.spacing[0],
            self.spacing[1],
            self.spacing[2],
            self.extract.n_triangles,
            self.extract.n_points,
            self.seconds_read,
            self.seconds_labels,
            self.seconds_extract,
            self.seconds_validate,
        );
        if self.labels.dropped_voxels > 0 {
            t += &format!(
                "  {} voxels of labels not kept set to outside\n",
                self.labels.dropped_voxels
            );
        }
        if !self.labels.islands.is_empty() {
            let v: usize = self.labels.islands.iter().map(|i| i.voxels).sum();
            t += &format!(
                "  {} islands ({} voxels) merged into their surroundings\n",
                self.labels.islands.len(),
                v
            );
        }
        for r in &self.regions {
            if r.components != r.components_in_image {
                t += &format!(
                    "  warning: region {} has {} connected components after the manifold repair, \
                     {} in the image ({} voxels now)\n",
                    r.label, r.components, r.components_in_image, r.voxels
                );
            }
        }
        if !self.extract.relabelled.is_empty() {
            let v: Vec<String> = self
                .extract
                .relabelled
                .iter()
                .map(|(f, to, n)| format!("{n} {f}→{to}"))
                .collect();
            t += &format!(
                "  voxels relabelled so every region is manifold: {}\n",
                v.join(", ")
            );
        }
        t
    }
}

/// Per region: voxel volume beside the mesh's volume (and its relative error), its tets and
/// dihedral angle range.
pub fn region_volumes(summary: &ImageSummary, quality: &QualityReport) -> Vec<serde_json::Value> {
    summary
        .regions
        .iter()
        .map(|r| {
            let q = quality.regions.iter().find(|q| q.label == r.label);
            let m = q.map_or(0.0, |q| q.volume);
            json!({
                "label": r.label,
                "voxels": r.voxels,
                "voxel_volume": r.voxel_volume,
                "mesh_volume": m,
                "relative_error": (m - r.voxel_volume) / r.voxel_volume,
                "tets": q.map_or(0, |q| q.n_tets),
                "min_dihedral_deg": q.map(|q| q.min_dihedral_deg),
                "max_dihedral_deg": q.map(|q| q.max_dihedral_deg),
            })
        })
        .collect()
}

/// Text table of [`region_volumes`].
pub fn region_text(rows: &[serde_json::Value]) -> String {
    let mut t = String::from(
        "region      voxels   voxel volume    mesh volume     error      tets  dihedral\n",
    );
    for r in rows {
        t += &format!(
            "{:>6}  {:>10}  {:>13.6e}  {:>13.6e}  {:>+8.1e}  {:>8}  {:.2}°–{:.2}°\n",
            r["label"].as_u64().unwrap_or(0),
            r["voxels"].as_u64().unwrap_or(0),
            r["voxel_volume"].as_f64().unwrap_or(f64::NAN),
            r["mesh_volume"].as_f64().unwrap_or(f64::NAN),
            r["relative_error"].as_f64().unwrap_or(f64::NAN),
            r["tets"].as_u64().unwrap_or(0),
            r["min_dihedral_deg"].as_f64().unwrap_or(f64::NAN),
            r["max_dihedral_deg"].as_f64().unwrap_or(f64::NAN),
        );
    }
    t
}

/// Arguments of `biotet surface-extract`.
#[derive(clap::Args)]
pub struct Args {
    /// Label image: .nii, .nii.gz, .mgh, .mgz, .nrrd, .nhdr, .mha, .mhd, .vti (world
    /// coordinates RAS+, see docs/formats.md).
    pub(crate) image: PathBuf,
    /// Output labelled surface (.vtu, .ply or .mesh keep the labels on both sides of each
    /// triangle).
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
