//! The native part of the `biotet` Python package (`biotet._core`): numpy arrays in and out,
//! the library's functions run with the GIL released, errors as one exception type carrying a
//! kind, the message and the offending triangles (the pure-Python layer maps the kind to
//! `InvalidSurfaceError`, `MeshingError` or an `OSError`).
//!
//! Inputs are borrowed read-only from numpy and copied once into the library's types (the
//! library owns its arrays); outputs are moved into numpy without a copy.
//!
//! Meshing follows `biotet mesh` step for step, through the same library calls, so the bytes
//! written are the CLI's: a surface validated (shells assembled, or side labels resolved), or a
//! label image through `image::surface::labelled_surface` with its labels renumbered for the
//! template and put back after; sizes from `SizeSpec::from_grid` for a size field.

mod arrays;
mod run;

use arrays::{
    Ints1, Ints2, Surface, grid_from, mesh_from, mesh_out, points_from, surface_from, volume_from,
};
use biotet::check::check as check_mesh;
use biotet::delaunay::Delaunay;
use biotet::image::LabelImage;
use biotet::image::labels::{Compaction, LabelOptions};
use biotet::image::surface::{ImageSummary, ImageSurfaceError, labelled_surface};
use biotet::lastresort::{ImproveOptions, Metric, RecoverOptions, improve, recover};
use biotet::mesh::shells::{Part, assemble};
use biotet::mesh::side_labels;
use biotet::mesh::validate::{
    SurfaceError, ValidateOptions, check_self_intersections, validate_surface,
};
use biotet::pipeline::{PipelineOptions, mesh_surface};
use biotet::quality::{QualityReport, forced};
use biotet::sizing::{SizeSpec, Sizing, SizingOptions};
use biotet::sizing_grid::ScalarGrid;
use biotet::smooth::{Boundary, SmoothOptions, smooth};
use biotet::template::Zone;
use biotet::{SurfaceMesh, TetMesh};
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use run::{Failure, Kind, guarded};
use serde_json::json;
use std::path::PathBuf;

pyo3::create_exception!(
    _core,
    CoreError,
    pyo3::exceptions::PyException,
    "A failure inside biotet: args are (kind, message, triangles)."
);

/// A tet mesh handed to Python: points (n×3 float64), tets (m×4 int32), labels (m int32) and
/// the report as JSON text.
type MeshOut<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i32>>,
    Bound<'py, PyArray1<i32>>,
    String,
);

/// A surface handed to Python: points (n×3 float64), triangles (m×3 int32) and the side labels
/// (m×2 int32).
type SurfaceOut<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i32>>,
    Bound<'py, PyArray2<i32>>,
);

/// Tets under this smallest dihedral angle are reported as forced when an input face or fold
/// under it causes them (as `biotet mesh` does).
const FORCED_DEG: f64 = 10.0;

/// Sizing and stage switches of `mesh`, as the CLI's flags: a dict from the Python layer
/// (`biotet._mesh_options`), one key per field.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
struct MeshOptions {
    size: Option<f64>,
    grading: f64,
    min_size: Option<f64>,
    max_size: Option<f64>,
    region_sizes: Vec<(u32, f64)>,
    resolution: f64,
    zone: String,
    max_voxels: usize,
    steiner: bool,
    stages: [bool; 4],
    surface_tolerance: Option<f64>,
    exact_surface: bool,
    surface_feature_angle: f64,
    surface_rounds: usize,
    adaptive_size: bool,
    size_field: Option<SizeFieldIn>,
}

/// A size field as given (`--size-field`): a file (.vti with an optional array name, NIfTI), or
/// samples `values[i, j, k]` at `affine · (i, j, k, 1)`.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
struct SizeFieldIn {
    path: Option<PathBuf>,
    array: Option<String>,
    values: Option<Py<PyArray3<f64>>>,
    affine: Option<[[f64; 4]; 4]>,
}

/// A size field ready for meshing: a file is read with the GIL released, with the rest.
enum SizeField {
    File(PathBuf, Option<String>),
    Grid(ScalarGrid),
}

impl SizeFieldIn {
    /// Copy numpy samples into a grid (needs the GIL).
    fn resolve(self, py: Python<'_>) -> PyResult<SizeField> {
        match (self.path, self.values, self.affine) {
            (Some(p), None, _) => Ok(SizeField::File(p, self.array)),
            (None, Some(v), Some(a)) => {
                let v = v.bind(py).try_readonly().map_err(|e| {
                    pyo3::exceptions::PyValueError::new_err(format!("size_field: {e}"))
                })?;
                Ok(SizeField::Grid(grid_from(&v, &a)?))
            }
            _ => Err(pyo3::exceptions::PyValueError::new_err(
                "size_field: give a path, or values with their affine",
            )),
        }
    }
}

/// How an image's values become regions, as the CLI's `--labels`, `--merge`, `--outside`,
/// `--min-component-voxels`: a dict from the Python layer (`biotet._image_options`).
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
struct ImageOptions {
    keep: Option<Vec<u32>>,
    merge: Vec<(Vec<u32>, u32)>,
    outside: u32,
    min_component_voxels: usize,
}

impl ImageOptions {
    fn to_library(&self) -> LabelOptions {
        LabelOptions {
            keep: self.keep.clone(),
            merge: self.merge.clone(),
            outside: self.outside,
            min_component_voxels: self.min_component_voxels,
        }
    }
}

/// A surface ready for the pipeline: validated, its shells (for the report), the input's name,
/// and for an image the summary of its extraction.
struct Prepared {
    surface: SurfaceMesh,
    shells: serde_json::Value,
    name: String,
    image: Option<ImageSummary>,
}

/// What a surface's validation does with crossing triangles (as the CLI's `input::Crossings`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Crossings {
    /// Refused (no way to untangle them here: `check`, `recover`, `smooth`).
    Refused,
    /// Refused, the message naming `surface_tolerance`, which untangles them.
    Hinted,
    /// Let through: the surface stage follows and untangles them.
    Allowed,
}

/// Validate a labelled surface as `biotet mesh` does: shells assembled and labelled innermost
/// first, or the file's own side labels resolved against the geometry (a file giving only one
/// side's labels needs triangles that do not cross: its fronts come from the cells).
fn prepare(
    surface: Surface,
    crossings: Crossings,
) -> Result<(SurfaceMesh, serde_json::Value), Failure> {
    let opts = ValidateOptions {
        self_intersections: crossings != Crossings::Allowed,
        ..ValidateOptions::default()
    };
    match surface {
        Surface::Parts(parts, name) => {
            let (mut s, shells) = assemble(parts).map_err(|e| {
                Failure::new(
                    Kind::InvalidSurface,
                    format!("{name}: cannot assemble the surfaces: {e}"),
                )
            })?;
            validate_surface(&mut s, &opts).map_err(|e| refusal(&s, &name, e, crossings))?;
            Ok((s, serde_json::to_value(shells).unwrap_or_default()))
        }
        Surface::Sided(mut s, name) => {
            // Copies of a point that differ only by index are one point, as in `assemble`.
            s.weld_exact();
            let partial = s
                .sides
                .iter()
                .flatten()
                .any(|&l| l == side_labels::FROM_GEOMETRY);
            if partial {
                let hint = if crossings == Crossings::Allowed {
                    Crossings::Refused
                } else {
                    crossings
                };
                check_self_intersections(&s, opts.max_examples)
                    .map_err(|e| refusal(&s, &name, e, hint))?;
            } else {
                validate_surface(&mut s, &opts).map_err(|e| refusal(&s, &name, e, crossings))?;
            }
            let resolved = side_labels::resolve(&s).map_err(|e| {
                Failure::new(
                    Kind::InvalidSurface,
                    format!("{name}: side labels disagree with the geometry: {e}"),
                )
            })?;
            let mut s = resolved.surface;
            validate_surface(&mut s, &opts).map_err(|e| refusal(&s, &name, e, crossings))?;
            Ok((s, serde_json::to_value(resolved.shells).unwrap_or_default()))
        }
    }
}

/// A validation error as the CLI says it: where crossing triangles were let through and the
/// nesting failed all the same, the crossings named as the cause; a crossing's refusal with the
/// way out where that was asked for; else as it is.
fn refusal(s: &SurfaceMesh, name: &str, e: SurfaceError, crossings: Crossings) -> Failure {
    match crossings {
        Crossings::Allowed if matches!(e, SurfaceError::LabelsContradictGeometry { .. }) => {
            let first = check_self_intersections(s, ValidateOptions::default().max_examples);
            Failure::refused(name, &first.err().unwrap_or(e), false)
        }
        Crossings::Hinted => Failure::refused(name, &e, true),
        _ => Failure::refused(name, &e, false),
    }
}

/// The labelled surface of a label image as `biotet mesh IMAGE` makes it (label options,
/// extraction, validation), named `name`; `seconds_read` is the time its file took to read.
fn prepare_image(
    img: LabelImage,
    opts: &ImageOptions,
    name: String,
    seconds_read: f64,
    progress: &dyn Fn(&str),
) -> Result<Prepared, Failure> {
    let (surface, mut summary) =
        labelled_surface(img, &opts.to_library(), &name, &mut |s| progress(s)).map_err(
            |e| match e {
                ImageSurfaceError::Labels(e) => Failure::new(Kind::Value, format!("{name}: {e}")),
                ImageSurfaceError::Surface(e) => Failure {
                    kind: Kind::InvalidSurface,
                    message: format!("{name}: the extracted surface: {e}"),
                    triangles: e.triangles(),
                },
            },
        )?;
    summary.seconds_read = seconds_read;
    Ok(Prepared {
        surface,
        shells: json!([]),
        name,
        image: Some(summary),
    })
}

/// The pipeline on a validated surface, with the report `biotet mesh --json` gives (without
/// its process-level figures: memory, reading time), as `biotet mesh` runs it: an image's
/// labels renumbered for the template and put back after, an oblique image meshed in its
/// frame and the mesh rotated to world.
fn mesh_with(
    input: Prepared,
    o: &MeshOptions,
    field: Option<SizeField>,
    progress: &dyn Fn(&str),
) -> Result<(TetMesh, serde_json::Value), Failure> {
    let Prepared {
        mut surface,
        shells,
        name,
        image,
    } = input;
    // Image labels are the image's values; the template holds small labels.
    let compaction = (image.is_some() || Compaction::needed(&surface))
        .then(|| Compaction::of_surface(&mut surface));
    let frame_to_world = image.as_ref().and_then(|i| i.frame_to_world);
    // The surface stage (as `biotet mesh --surface-tolerance D`; an image's default).
    let tolerance = match &image {
        Some(i) => i.stage_tolerance(o.surface_tolerance, o.exact_surface),
        None => o.surface_tolerance,
    };
    let (mut surface, mut surface_report) = match tolerance {
        None => (surface, None),
        Some(d) => {
            progress("improving the surface");
            let so = biotet::surface::SurfaceOptions {
                tolerance: d,
                edge_length: o.size,
                feature_angle_deg: o.surface_feature_angle,
                rounds: o.surface_rounds,
                adaptive: o.adaptive_size,
                orient_sheets: image.as_ref().is_none_or(|i| i.orient_sheets()),
                ..Default::default()
            };
            // Each step a progress point, so Ctrl-C stops the stage within a round.
            let (s, r) = biotet::surface::improve_with_progress(&surface, &so, &|step| {
                progress(&format!("improving the surface: {step}"))
            })
            .map_err(|e| {
                // A bad option is the caller's value; the error names the stage itself.
                let kind = match e {
                    biotet::surface::SurfaceError::Options(_) => Kind::Value,
                    // Crossings the untangling cannot remove: the input, as the CLI judges it.
                    biotet::surface::SurfaceError::Crossings(_) => Kind::InvalidSurface,
                    _ => Kind::Meshing,
                };
                let triangles = match &e {
                    biotet::surface::SurfaceError::Crossings(u) => vec![u.first.0, u.first.1],
                    _ => Vec::new(),
                };
                Failure {
                    kind,
                    message: format!("{name}: {e}"),
                    triangles,
                }
            })?;
            (s, Some(r))
        }
    };
    let clock = std::time::Instant::now();
    let spec = match (o.size, field) {
        (Some(h), _) => SizeSpec::UpTo {
            size: h,
            grading: o.grading,
        },
        (None, Some(field)) => {
            let (grid, what) = match field {
                SizeField::File(path, array) => (
                    biotet_io::read_scalar_grid_named(&path, array.as_deref())
                        .map_err(Failure::io)?,
                    path.display().to_string(),
                ),
                SizeField::Grid(g) => (g, "size_field".to_string()),
            };
            SizeSpec::from_grid(grid, frame_to_world)
                .map_err(|e| Failure::new(Kind::Value, format!("{what}: {e}")))?
        }
        (None, None) => SizeSpec::FromSurface { grading: o.grading },
    };
    let mut sizing = SizingOptions::new(spec);
    sizing.min_size = o.min_size;
    sizing.max_size = o.max_size;
    sizing.region_sizes = o.region_sizes.clone();
    if let Some(c) = &compaction {
        for (l, _) in sizing.region_sizes.iter_mut() {
            *l = c.compact(*l).ok_or_else(|| {
                Failure::new(
                    Kind::Value,
                    format!("region_sizes: no region {l} in the image"),
                )
            })?;
        }
    }
    biotet::sizing::check_region_labels(&surface, &sizing.region_sizes)
        .map_err(|e| Failure::new(Kind::Value, format!("region_sizes: {e}")))?;
    let sizing = Sizing::new(&surface, sizing)
        .map_err(|e| Failure::new(Kind::Value, format!("sizing: {e}")))?;
    let seconds_sizing = clock.elapsed().as_secs_f64();
    let mut opts = PipelineOptions::default();
    opts.deploy.resolution = o.resolution;
    opts.deploy.zone = if o.zone == "box" {
        Zone::Box
    } else {
        Zone::Euclidean
    };
    opts.deploy.max_voxels = o.max_voxels;
    let [recover_on, improve_on, smooth_on, polish_on] = o.stages;
    if !recover_on {
        opts.recover = None;
    }
    if let Some(r) = opts.recover.as_mut() {
        r.allow_interior_steiner = o.steiner;
    }
    opts.seeds = o.steiner && improve_on;
    if !improve_on {
        opts.improve = None;
    }
    if !smooth_on {
        opts.smooth = None;
    }
    if !o.steiner
        && let Some(p) = opts.polish.as_mut()
    {
        p.insert = false;
    }
    if !polish_on || !improve_on {
        opts.polish = None;
    }
    let (mut mesh, report) = mesh_surface(&surface, sizing, &opts, &mut |s| progress(s))
        .map_err(|e| Failure::new(Kind::Meshing, format!("{name}: {e}")))?;
    if let Some(c) = &compaction {
        c.restore_tets(&mut mesh);
        c.restore_surface(&mut surface);
        if let Some(r) = &mut surface_report {
            c.restore_report(r);
        }
    }
    if let Some(m) = &frame_to_world {
        // Meshed in the image's frame; a rotation (positive determinant) to world.
        biotet::image::map_points(m, &mut mesh.points);
        biotet::image::map_points(m, &mut surface.points);
    }
    let quality = QualityReport::of(&mesh);
    let forcing = forced::summarise(
        &mesh,
        &forced::classify(&mesh, &surface, FORCED_DEG),
        FORCED_DEG,
    );
    if let Some(r) = report.recover.as_ref().filter(|r| !r.is_complete()) {
        let triangles = r.unrecovered.iter().map(|u| u.triangle as u32).collect();
        return Err(Failure {
            kind: Kind::Meshing,
            message: format!(
                "{name}: {} input triangles could not be recovered",
                r.missing_after
            ),
            triangles,
        });
    }
    let sheets = surface_report.as_ref().map_or(&[][..], |r| &r.sheets[..]);
    let image_regions = image
        .as_ref()
        .map(|i| i.region_volumes(&mesh, &quality, sheets));
    let mut report = json!({
        "input": name,
        "n_surface_triangles": surface.triangles.len(),
        "shells": shells,
        "seconds_sizing": seconds_sizing,
        "pipeline": report,
        "quality": quality,
        "forcing": forcing,
        "mesh_bytes": mesh.bytes(),
        "image": image,
        "image_regions": image_regions,
    });
    if let Some(r) = surface_report {
        report["surface"] = serde_json::to_value(r).unwrap_or_default();
    }
    Ok((mesh, report))
}

/// The validated surface of `prepare` as the pipeline's input (crossing triangles let through
/// when `o` asks for the surface stage, which untangles them).
fn prepared(surface: Surface, o: &MeshOptions) -> Result<Prepared, Failure> {
    let name = surface.name().to_string();
    let crossings = if o.surface_tolerance.is_some() {
        Crossings::Allowed
    } else {
        Crossings::Hinted
    };
    let (surface, shells) = prepare(surface, crossings)?;
    Ok(Prepared {
        surface,
        shells,
        name,
        image: None,
    })
}

/// Refuse a zone other than the two the template knows.
fn check_zone(o: &MeshOptions) -> PyResult<()> {
    match o.zone.as_str() {
        "euclidean" | "box" => Ok(()),
        z => Err(pyo3::exceptions::PyValueError::new_err(format!(
            "zone must be 'euclidean' or 'box', not {z:?}"
        ))),
    }
}

/// The checks every meshing call makes while it holds the GIL: the zone, and the size field's
/// numpy samples copied out (taken from the options, which then cross into the worker).
fn take_field(py: Python<'_>, o: &mut MeshOptions) -> PyResult<Option<SizeField>> {
    check_zone(o)?;
    o.size_field.take().map(|f| f.resolve(py)).transpose()
}

/// Mesh the volume inside a closed surface given as arrays (see `biotet.mesh`).
#[pyfunction]
#[pyo3(signature = (points, triangles, shell_labels, side_labels, name, options, threads,
    progress))]
#[allow(clippy::too_many_arguments)]
fn mesh_arrays<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    triangles: Ints2<'py>,
    shell_labels: Option<Vec<u32>>,
    side_labels: Option<Ints2<'py>>,
    name: String,
    mut options: MeshOptions,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<MeshOut<'py>> {
    let field = take_field(py, &mut options)?;
    let surface = surface_from(
        &points,
        &triangles,
        shell_labels,
        side_labels.as_ref(),
        name,
    )?;
    let (mesh, report) = guarded(py, threads, move || {
        let progress = |s: &str| run::report_progress(progress.as_ref(), s);
        mesh_with(prepared(surface, &options)?, &options, field, &progress)
    })?;
    Ok(mesh_out(py, mesh, report.to_string()))
}

/// Mesh the regions of a label volume (see `biotet.mesh_image`): `labels[i, j, k]` is the
/// label of the voxel centred at `affine · (i, j, k, 1)`.
#[pyfunction]
#[pyo3(signature = (labels, affine, name, image, options, threads, progress))]
#[allow(clippy::too_many_arguments)]
fn mesh_image<'py>(
    py: Python<'py>,
    labels: PyReadonlyArray3<'py, u32>,
    affine: [[f64; 4]; 4],
    name: String,
    image: ImageOptions,
    mut options: MeshOptions,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<MeshOut<'py>> {
    let field = take_field(py, &mut options)?;
    let (values, dims) = volume_from(&labels);
    let img = LabelImage::new(dims, affine, values)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(format!("labels: {e}")))?;
    let (mesh, report) = guarded(py, threads, move || {
        let progress = |s: &str| run::report_progress(progress.as_ref(), s);
        let input = prepare_image(img, &image, name, 0.0, &progress)?;
        mesh_with(input, &options, field, &progress)
    })?;
    Ok(mesh_out(py, mesh, report.to_string()))
}

/// The labelled surface of a label image in world coordinates, as `biotet surface IMAGE`
/// writes it.
fn extracted(img: LabelImage, opts: &ImageOptions, name: String) -> Result<SurfaceMesh, Failure> {
    let p = prepare_image(img, opts, name, 0.0, &|_| {})?;
    let mut s = p.surface;
    if let Some(m) = p.image.and_then(|i| i.frame_to_world) {
        biotet::image::map_points(&m, &mut s.points);
    }
    Ok(s)
}

/// The labelled surface of a label volume (see `biotet.surface_extract`): `labels[i, j, k]` is
/// the label of the voxel centred at `affine · (i, j, k, 1)`.
#[pyfunction]
#[pyo3(signature = (labels, affine, name, image))]
fn surface_image<'py>(
    py: Python<'py>,
    labels: PyReadonlyArray3<'py, u32>,
    affine: [[f64; 4]; 4],
    name: String,
    image: ImageOptions,
) -> PyResult<SurfaceOut<'py>> {
    let (values, dims) = volume_from(&labels);
    let img = LabelImage::new(dims, affine, values)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(format!("labels: {e}")))?;
    let s = guarded(py, None, move || extracted(img, &image, name))?;
    Ok(arrays::surface_out(py, s))
}

/// The labelled surface of a label image file (see `biotet.surface_extract`).
#[pyfunction]
#[pyo3(signature = (path, image))]
fn surface_image_file<'py>(
    py: Python<'py>,
    path: PathBuf,
    image: ImageOptions,
) -> PyResult<SurfaceOut<'py>> {
    let s = guarded(py, None, move || {
        if !biotet_io::is_label_image(&path) {
            return Err(Failure::new(
                Kind::File,
                format!(
                    "{}: not a label image ({})",
                    path.display(),
                    biotet_io::image::IMAGE_EXTENSIONS
                ),
            ));
        }
        let img = biotet_io::read_label_image(&path).map_err(Failure::io)?;
        extracted(img, &image, path.display().to_string())
    })?;
    Ok(arrays::surface_out(py, s))
}

/// Mesh the volume inside the closed surfaces in files (see `biotet.mesh_file`).
#[pyfunction]
#[pyo3(signature = (paths, labels, image, options, threads, progress))]
#[allow(clippy::too_many_arguments)]
fn mesh_files<'py>(
    py: Python<'py>,
    paths: Vec<PathBuf>,
    labels: Vec<Option<Vec<u32>>>,
    image: ImageOptions,
    mut options: MeshOptions,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<MeshOut<'py>> {
    let field = take_field(py, &mut options)?;
    let (mesh, report) = guarded(py, threads, move || {
        let progress = |s: &str| run::report_progress(progress.as_ref(), s);
        let input = match &paths[..] {
            // One label image: its labelled surface, as `biotet mesh IMAGE`.
            [path] if biotet_io::is_label_image(path) => {
                let clock = std::time::Instant::now();
                progress(&format!("reading {}", path.display()));
                let img = biotet_io::read_label_image(path).map_err(Failure::io)?;
                let seconds_read = clock.elapsed().as_secs_f64();
                prepare_image(
                    img,
                    &image,
                    path.display().to_string(),
                    seconds_read,
                    &progress,
                )?
            }
            _ => prepared(read_surfaces(&paths, labels)?, &options)?,
        };
        mesh_with(input, &options, field, &progress)
    })?;
    Ok(mesh_out(py, mesh, report.to_string()))
}

/// Surfaces from files as `biotet mesh` reads them: one side-labelled file alone, or closed
/// shells from one or more files with optional labels per file.
fn read_surfaces(paths: &[PathBuf], labels: Vec<Option<Vec<u32>>>) -> Result<Surface, Failure> {
    let mut parts = Vec::new();
    for (p, l) in paths
        .iter()
        .zip(labels.into_iter().chain(std::iter::repeat(None)))
    {
        let read = biotet_io::read_surface(p).map_err(Failure::io)?;
        if let Some(sides) = read.side_labels {
            if paths.len() > 1 {
                return Err(Failure::new(
                    Kind::Value,
                    format!(
                        "{}: a surface with side labels holds every region and must be given alone",
                        p.display()
                    ),
                ));
            }
            let mut s = read.mesh;
            s.sides = sides;
            return Ok(Surface::Sided(s, p.display().to_string()));
        }
        parts.push(Part {
            surface: read.mesh,
            labels: l,
        });
    }
    let name = paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(" + ");
    Ok(Surface::Parts(parts, name))
}

/// Check a tet mesh and, given a surface, that it holds every surface triangle; the report as
/// JSON text.
#[pyfunction]
#[pyo3(signature = (points, tets, labels, surface_points=None, surface_triangles=None,
    shell_labels=None, side_labels=None, threads=None))]
#[allow(clippy::too_many_arguments)]
fn check<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    tets: Ints2<'py>,
    labels: Ints1<'py>,
    surface_points: Option<PyReadonlyArray2<'py, f64>>,
    surface_triangles: Option<Ints2<'py>>,
    shell_labels: Option<Vec<u32>>,
    side_labels: Option<Ints2<'py>>,
    threads: Option<usize>,
) -> PyResult<String> {
    let mesh = mesh_from(&points, &tets, &labels)?;
    let surface = match (&surface_points, &surface_triangles) {
        (Some(p), Some(t)) => Some(surface_from(
            p,
            t,
            shell_labels,
            side_labels.as_ref(),
            "surface".into(),
        )?),
        (None, None) => None,
        _ => {
            return Err(pyo3::exceptions::PyValueError::new_err(
                "give both surface_points and surface_triangles, or neither",
            ));
        }
    };
    guarded(py, threads, move || {
        let surface = surface
            .map(|s| prepare(s, Crossings::Refused))
            .transpose()?
            .map(|(s, _)| s);
        let c = check_mesh(&mesh, surface.as_ref());
        Ok(serde_json::to_string(&c).unwrap_or_default())
    })
}

/// Quality measures of a tet mesh (the report of `biotet quality --json`) as JSON text.
#[pyfunction]
#[pyo3(signature = (points, tets, labels, threads=None))]
fn quality<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    tets: Ints2<'py>,
    labels: Ints1<'py>,
    threads: Option<usize>,
) -> PyResult<String> {
    let mesh = mesh_from(&points, &tets, &labels)?;
    guarded(py, threads, move || {
        Ok(serde_json::to_string(&QualityReport::of(&mesh)).unwrap_or_default())
    })
}

/// The Delaunay tetrahedralization of a point cloud.
#[pyfunction]
#[pyo3(signature = (points, threads=None))]
fn delaunay<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    threads: Option<usize>,
) -> PyResult<MeshOut<'py>> {
    let pts = points_from(&points)?;
    let mesh = guarded(py, threads, move || {
        let dt = Delaunay::from_points(pts)
            .map_err(|e| Failure::new(Kind::Value, format!("delaunay: {e}")))?;
        Ok(dt.to_tet_mesh())
    })?;
    Ok(mesh_out(py, mesh, "{}".into()))
}

/// Boundary recovery (LAST RESORT) of a surface in a tet mesh.
#[pyfunction]
#[pyo3(signature = (points, tets, labels, surface_points, surface_triangles, steiner=true,
    keep_outside=false, threads=None))]
#[allow(clippy::too_many_arguments)]
fn recover_surface<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    tets: Ints2<'py>,
    labels: Ints1<'py>,
    surface_points: PyReadonlyArray2<'py, f64>,
    surface_triangles: Ints2<'py>,
    steiner: bool,
    keep_outside: bool,
    threads: Option<usize>,
) -> PyResult<MeshOut<'py>> {
    let mut mesh = mesh_from(&points, &tets, &labels)?;
    let surface = surface_from(
        &surface_points,
        &surface_triangles,
        None,
        None,
        "surface".into(),
    )?;
    let (mesh, report) = guarded(py, threads, move || {
        let (s, _) = prepare(surface, Crossings::Refused)?;
        let opts = RecoverOptions {
            allow_interior_steiner: steiner,
            remove_outside: !keep_outside,
            ..RecoverOptions::default()
        };
        let r = recover(&mut mesh, &s, &opts)
            .map_err(|e| Failure::new(Kind::Meshing, format!("recover: {e}")))?;
        if !r.is_complete() {
            return Err(Failure {
                kind: Kind::Meshing,
                message: format!(
                    "recover: {} input triangles could not be recovered",
                    r.missing_after
                ),
                triangles: r.unrecovered.iter().map(|u| u.triangle as u32).collect(),
            });
        }
        Ok((mesh, serde_json::to_string(&r).unwrap_or_default()))
    })?;
    Ok(mesh_out(py, mesh, report))
}

/// Sliver removal (LAST RESORT) in place of a tet mesh's poor tets: those under `threshold`
/// (default 10° for the dihedral angle, 0.2 for q, as `biotet improve`).
#[pyfunction]
#[pyo3(signature = (points, tets, labels, threshold=None, metric="dihedral", threads=None))]
#[allow(clippy::too_many_arguments)]
fn improve_mesh<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    tets: Ints2<'py>,
    labels: Ints1<'py>,
    threshold: Option<f64>,
    metric: &str,
    threads: Option<usize>,
) -> PyResult<MeshOut<'py>> {
    let (metric, threshold) = match metric {
        "dihedral" => (Metric::Dihedral, threshold.unwrap_or(10.0)),
        "q" => (Metric::Q, threshold.unwrap_or(0.2)),
        m => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "metric must be 'dihedral' or 'q', not {m:?}"
            )));
        }
    };
    if !threshold.is_finite() || threshold <= 0.0 {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "threshold {threshold}: expected a positive number"
        )));
    }
    let mut mesh = mesh_from(&points, &tets, &labels)?;
    let (mesh, report) = guarded(py, threads, move || {
        let opts = ImproveOptions {
            metric,
            threshold,
            ..ImproveOptions::default()
        };
        let r = improve(&mut mesh, &opts);
        Ok((mesh, serde_json::to_string(&r).unwrap_or_default()))
    })?;
    Ok(mesh_out(py, mesh, report))
}

/// Solid-angle smoothing of a tet mesh (surface fixed, or sliding on the given surface).
#[pyfunction]
#[pyo3(signature = (points, tets, labels, surface_points=None, surface_triangles=None,
    slide=false, max_sweeps=None, feature_angle=45.0, threads=None))]
#[allow(clippy::too_many_arguments)]
fn smooth_mesh<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    tets: Ints2<'py>,
    labels: Ints1<'py>,
    surface_points: Option<PyReadonlyArray2<'py, f64>>,
    surface_triangles: Option<Ints2<'py>>,
    slide: bool,
    max_sweeps: Option<usize>,
    feature_angle: f64,
    threads: Option<usize>,
) -> PyResult<MeshOut<'py>> {
    if !(0.0..=180.0).contains(&feature_angle) {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "feature_angle {feature_angle}: expected degrees between 0 and 180"
        )));
    }
    let mut mesh = mesh_from(&points, &tets, &labels)?;
    let surface = match (&surface_points, &surface_triangles) {
        (Some(p), Some(t)) => Some(surface_from(p, t, None, None, "surface".into())?),
        _ => None,
    };
    let (mesh, report) = guarded(py, threads, move || {
        let surface = surface
            .map(|s| prepare(s, Crossings::Refused))
            .transpose()?
            .map(|(s, _)| s);
        let mut opts = SmoothOptions {
            boundary: if slide {
                Boundary::Slide
            } else {
                Boundary::Fixed
            },
            feature_angle_deg: feature_angle,
            ..SmoothOptions::default()
        };
        if let Some(n) = max_sweeps {
            opts.max_sweeps = n;
        }
        let r = smooth(&mut mesh, surface.as_ref(), &opts)
            .map_err(|e| Failure::new(Kind::Value, format!("smooth: {e}")))?;
        Ok((mesh, serde_json::to_string(&r).unwrap_or_default()))
    })?;
    Ok(mesh_out(py, mesh, report))
}

/// Read a tet mesh file: (points, tets, labels, "{}").
#[pyfunction]
fn read_tet_mesh<'py>(py: Python<'py>, path: PathBuf) -> PyResult<MeshOut<'py>> {
    let mesh = guarded(py, None, move || {
        Ok(biotet_io::read_tet_mesh(&path).map_err(Failure::io)?.mesh)
    })?;
    Ok(mesh_out(py, mesh, "{}".into()))
}

/// Which kind of mesh a file holds, as `biotet` tells (extension, then a look inside `.vtu`,
/// `.vtk`, `.mesh` and `.node` files): "surface", "tetrahedra" or "triangles2d".
#[pyfunction]
fn mesh_kind(py: Python<'_>, path: PathBuf) -> PyResult<&'static str> {
    guarded(py, None, move || {
        Ok(match biotet_io::mesh_kind(&path).map_err(Failure::io)? {
            biotet_io::MeshKind::Surface => "surface",
            biotet_io::MeshKind::Tetrahedra => "tetrahedra",
            biotet_io::MeshKind::Triangles2d => "triangles2d",
        })
    })
}

/// Read a surface file: (points, triangles, sides) with sides the region labels behind and in
/// front of each triangle (`[1, 0]` for a plain closed surface).
#[pyfunction]
fn read_surface<'py>(py: Python<'py>, path: PathBuf) -> PyResult<SurfaceOut<'py>> {
    let s = guarded(py, None, move || {
        let read = biotet_io::read_surface(&path).map_err(Failure::io)?;
        let mut s = read.mesh;
        if let Some(sides) = read.side_labels {
            s.sides = sides;
        }
        Ok(s)
    })?;
    Ok(arrays::surface_out(py, s))
}

/// Write a tet mesh (format from the extension; written to a temporary file, then renamed).
/// Returns the paths written.
#[pyfunction]
fn write_tet_mesh<'py>(
    py: Python<'py>,
    path: PathBuf,
    points: PyReadonlyArray2<'py, f64>,
    tets: Ints2<'py>,
    labels: Ints1<'py>,
) -> PyResult<Vec<PathBuf>> {
    let mesh = mesh_from(&points, &tets, &labels)?;
    guarded(py, None, move || {
        biotet_io::write_tet_mesh(&path, &mesh).map_err(Failure::io)
    })
}

/// The native module.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("CoreError", m.py().get_type::<CoreError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(mesh_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_files, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_image, m)?)?;
    m.add_function(wrap_pyfunction!(surface_image, m)?)?;
    m.add_function(wrap_pyfunction!(surface_image_file, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(quality, m)?)?;
    m.add_function(wrap_pyfunction!(delaunay, m)?)?;
    m.add_function(wrap_pyfunction!(recover_surface, m)?)?;
    m.add_function(wrap_pyfunction!(improve_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(smooth_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(read_tet_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(read_surface, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_kind, m)?)?;
    m.add_function(wrap_pyfunction!(write_tet_mesh, m)?)?;
    Ok(())
}
