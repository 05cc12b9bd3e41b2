//! A label image to the labelled surface the mesher takes, with what was done on the way: the
//! label options applied, an oblique image moved to its axis-aligned frame, the voxel-face
//! surface extracted and validated, and the voxels of each region counted (for the reports of
//! `biotet mesh IMAGE`, `biotet surface-extract` and the Python package's `mesh_image`).

use super::LabelImage;
use super::extract::{ExtractReport, extract};
use super::labels::{Components, LabelError, LabelOptions, LabelReport, apply};
use crate::mesh::validate::{SurfaceError, ValidateOptions, validate_surface};
use crate::quality::QualityReport;
use crate::surface::SheetDistance;
use crate::{SurfaceMesh, TetMesh};
use std::time::Instant;

/// What applying the labels, extracting and validating an image gave, for the reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ImageSummary {
    /// The image file (or the name given to an image from memory).
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
    /// to world at the end (see [`LabelImage::to_frame`]). `None`: already axis-aligned.
    pub frame_to_world: Option<[[f64; 4]; 4]>,
    /// The surface stage's default tolerance for this image (half the smallest spacing); the
    /// stage itself runs after extraction ([`Self::stage_tolerance`]).
    pub default_surface_tolerance: f64,
    /// Labels, islands.
    pub labels: LabelReport,
    /// Extraction: manifold repairs, points, triangles.
    pub extract: ExtractReport,
    /// Per region after everything: label, voxels, voxel volume (voxels × voxel volume).
    pub regions: Vec<RegionVoxels>,
    /// Seconds reading the file (set by the caller that read it; 0 for an image from memory).
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

/// A region's voxel volume beside its mesh's volume (see [`ImageSummary::region_volumes`]).
#[derive(Debug, Clone, serde::Serialize)]
pub struct RegionVolume {
    /// The image label.
    pub label: u32,
    /// Its voxels.
    pub voxels: usize,
    /// `voxels × voxel volume`.
    pub voxel_volume: f64,
    /// The volume of its tets.
    pub mesh_volume: f64,
    /// `(mesh − voxel) / voxel` (not finite for a region with no voxels).
    pub relative_error: f64,
    /// Its tets.
    pub tets: u64,
    /// Its smallest dihedral angle (degrees), `None` without tets.
    pub min_dihedral_deg: Option<f64>,
    /// Its largest dihedral angle (degrees), `None` without tets.
    pub max_dihedral_deg: Option<f64>,
    /// Its tets' connected components (through shared faces), beside `components_voxels`: a
    /// region the surface stage pinched off or the mesher lost shows here.
    pub components: usize,
    /// Its voxels' 6-connected components after the manifold repair
    /// ([`RegionVoxels::components`]: what the extracted surface encloses).
    pub components_voxels: usize,
    /// The largest distance from its voxel boundary to its mesh boundary, measured sheet by
    /// sheet by the surface stage (0 when the voxel faces are kept exactly).
    pub hausdorff_in_to_out: f64,
    /// The largest distance from its mesh boundary to its voxel boundary.
    pub hausdorff_out_to_in: f64,
}

/// Why an image gives no surface to mesh.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImageSurfaceError {
    /// The label options cannot be applied (or leave no region).
    #[error(transparent)]
    Labels(#[from] LabelError),
    /// The extracted surface is not valid (a bug: extraction makes every region manifold).
    #[error("the extracted surface: {0}")]
    Surface(SurfaceError),
}

/// Apply the label options to an image, extract its labelled surface and validate it. The
/// surface is in the image's frame: map it (and a mesh made from it) to world with
/// [`ImageSummary::frame_to_world`] when set. `file` names the image in the summary; `progress`
/// hears the step names.
pub fn labelled_surface(
    mut img: LabelImage,
    opts: &LabelOptions,
    file: &str,
    progress: &mut dyn FnMut(&str),
) -> Result<(SurfaceMesh, ImageSummary), ImageSurfaceError> {
    let clock = Instant::now();
    progress("applying labels");
    let labels = apply(&mut img, opts)?;
    let seconds_labels = clock.elapsed().as_secs_f64();
    let voxel_to_world = img.voxel_to_world;
    // The world voxel's volume: the frame's is the product of the spacings, which a sheared map
    // does not keep.
    let vv = img.voxel_volume();
    let frame_to_world = img.to_frame();
    let clock = Instant::now();
    progress("extracting the surface");
    let (mut surface, extract) = extract(&mut img);
    let seconds_extract = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    progress("validating the surface");
    // Embedded by construction (faces of the grid meet in grid edges and corners): the
    // self-intersection search is skipped; the rest is checked.
    let vopts = ValidateOptions {
        self_intersections: false,
        ..Default::default()
    };
    validate_surface(&mut surface, &vopts).map_err(ImageSurfaceError::Surface)?;
    let seconds_validate = clock.elapsed().as_secs_f64();
    let comps = Components::of(&img);
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
        file: file.to_string(),
        dims: img.dims,
        spacing: img.spacing(),
        voxel_volume: vv,
        voxel_to_world,
        frame_to_world,
        default_surface_tolerance: img.default_surface_tolerance(),
        labels,
        extract,
        regions,
        seconds_read: 0.0,
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

    /// Whether the surface stage turns each sheet one way first
    /// ([`crate::surface::SurfaceOptions::orient_sheets`]): when the voxels are not cubes (the
    /// longest spacing over 1.5 times the shortest). The voxel faces are oriented by their axis,
    /// so every staircase edge between faces of differently signed axes reads as an interface
    /// rim, kept as it is. On cubic voxels those rims are right-angled and the stage was built
    /// and measured with them (turned, mni_brain's stage took 2.3 times as long and its smallest
    /// triangle angle was 10.6° instead of 30°); on voxels six times longer one way they are
    /// needles nothing may touch, and the tets came out flat.
    pub fn orient_sheets(&self) -> bool {
        let s = self.spacing;
        let (lo, hi) = s.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
        hi > 1.5 * lo
    }

    /// The surface stage's tolerance when meshing this image: `requested` if given, else none
    /// when `exact` (the voxel faces kept as they are), else [`Self::default_surface_tolerance`].
    pub fn stage_tolerance(&self, requested: Option<f64>, exact: bool) -> Option<f64> {
        requested.or((!exact).then_some(self.default_surface_tolerance))
    }

    /// Per region: voxel volume beside the mesh's volume (and its relative error), its tets,
    /// dihedral angle range, and the distances of its boundary to the voxel boundary from the
    /// stage's `sheets` (in image labels; none when the voxel faces were kept).
    pub fn region_volumes(
        &self,
        mesh: &TetMesh,
        quality: &QualityReport,
        sheets: &[SheetDistance],
    ) -> Vec<RegionVolume> {
        let comps = mesh.region_components();
        self.regions
            .iter()
            .map(|r| {
                let q = quality.regions.iter().find(|q| q.label == r.label);
                let m = q.map_or(0.0, |q| q.volume);
                let own = || sheets.iter().filter(|s| s.sides.contains(&r.label));
                RegionVolume {
                    label: r.label,
                    voxels: r.voxels,
                    voxel_volume: r.voxel_volume,
                    mesh_volume: m,
                    relative_error: (m - r.voxel_volume) / r.voxel_volume,
                    tets: q.map_or(0, |q| q.n_tets),
                    min_dihedral_deg: q.map(|q| q.min_dihedral_deg),
                    max_dihedral_deg: q.map(|q| q.max_dihedral_deg),
                    components: comps
                        .binary_search_by_key(&r.label, |c| c.0)
                        .map_or(0, |i| comps[i].1),
                    components_voxels: r.components,
                    hausdorff_in_to_out: own().map(|s| s.in_to_out).fold(0.0, f64::max),
                    hausdorff_out_to_in: own().map(|s| s.out_to_in).fold(0.0, f64::max),
                }
            })
            .collect()
    }
}
