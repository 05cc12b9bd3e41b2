//! Reading inputs with the CLI's messages: every error names the file.

use crate::Common;
use crate::progress::Stage;
use anyhow::{Context, Result, bail};
use biotet::mesh::shells::{Part, Shell, assemble};
use biotet::mesh::side_labels::{self, FROM_GEOMETRY};
use biotet::mesh::validate::{
    ValidateOptions, ValidationReport, check_self_intersections, validate_surface,
};
use biotet::{SurfaceMesh, TetMesh};
use std::path::{Path, PathBuf};

/// What a surface's validation does with crossing triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Crossings {
    /// Refused (a command that needs a valid surface and has no way to untangle it).
    Refused,
    /// Refused, the message naming `--surface-tolerance`, which untangles them (`validate`,
    /// `mesh` without it).
    Hinted,
    /// Let through: the surface stage follows and untangles them.
    Allowed,
}

impl Crossings {
    /// `Allowed` when the surface stage will run, else `Hinted`.
    pub fn unless_staged(staged: bool) -> Crossings {
        if staged {
            Crossings::Allowed
        } else {
            Crossings::Hinted
        }
    }
}

/// Read a tet mesh, telling the user about tets that had to be reoriented.
pub fn tet_mesh(path: &Path, common: Common) -> Result<TetMesh> {
    let read = biotet_io::read_tet_mesh(path)?;
    if !common.quiet && !common.json {
        if read.flipped > 0 {
            eprintln!(
                "note: {}: stored with the opposite orientation convention; all {} tets were \
                 reoriented",
                path.display(),
                read.flipped
            );
        }
        if read.skipped_elements > 0 {
            eprintln!(
                "warning: {}: {} volume elements that are not linear tets were ignored",
                path.display(),
                read.skipped_elements
            );
        }
    }
    Ok(read.mesh)
}

/// A surface whose file gives the region labels on both sides of its triangles (see
/// `biotet::mesh::side_labels`): the per-region checks of `validate_surface` (closed,
/// consistently oriented, no crossing triangles) and the labels against the cells of the
/// geometry. Errors name the file, the triangle and the reason.
pub fn side_labelled(
    path: &Path,
    read: biotet_io::SurfaceRead,
    common: Common,
    crossings: Crossings,
) -> Result<(SurfaceMesh, Vec<Shell>, ValidationReport)> {
    let name = path.display().to_string();
    let mut mesh = read.mesh;
    mesh.sides = read.side_labels.unwrap_or_default();
    // Copies of a point that differ only by index are one point, as in `assemble`.
    note_welded(&name, mesh.weld_exact(), common);
    let partial = mesh.sides.iter().flatten().any(|&l| l == FROM_GEOMETRY);
    let invalid = || format!("{name}: invalid surface");
    let opts = ValidateOptions {
        self_intersections: crossings != Crossings::Allowed,
        ..ValidateOptions::default()
    };
    let mut report = None;
    if partial {
        // Fronts come from the cells, which need triangles that do not cross, even where the
        // surface stage would untangle them after.
        let hint = if crossings == Crossings::Allowed {
            Crossings::Refused
        } else {
            crossings
        };
        check_self_intersections(&mesh, opts.max_examples)
            .map_err(|e| refusal(&mesh, e, hint))
            .with_context(invalid)?;
    } else {
        let r = validate_surface(&mut mesh, &opts)
            .map_err(|e| refusal(&mesh, e, crossings))
            .with_context(invalid)?;
        report = Some(r);
    }
    let resolved = side_labels::resolve(&mesh)
        .with_context(|| format!("{name}: side labels disagree with the geometry"))?;
    let mut mesh = resolved.surface;
    let report = match report {
        Some(r) => r,
        None => validate_surface(&mut mesh, &opts)
            .map_err(|e| refusal(&mesh, e, crossings))
            .with_context(invalid)?,
    };
    if crossings == Crossings::Allowed {
        note_crossings(&mesh, &name, common);
    }
    if !common.quiet && !common.json {
        if report.flipped_inward {
            eprintln!(
                "note: {name}: {} of {} triangles faced inward and were flipped",
                report.n_flipped_triangles, report.n_triangles
            );
        }
        if resolved.n_from_geometry > 0 {
            eprintln!(
                "note: {name}: {} triangle sides took their region from the geometry",
                resolved.n_from_geometry
            );
        }
        let regions: Vec<String> = mesh.regions().iter().map(|r| r.to_string()).collect();
        eprintln!(
            "note: {name}: side labels read from the file, regions {}",
            regions.join(", ")
        );
    }
    Ok((mesh, resolved.shells, report))
}

/// `--label FILE=N[,N...]` as labels per input file.
pub fn parse_labels(items: &[String], files: &[PathBuf]) -> Result<Vec<Option<Vec<u32>>>> {
    let mut out = vec![None; files.len()];
    for item in items {
        let (f, l) = item
            .rsplit_once('=')
            .with_context(|| format!("--label {item}: expected FILE=N[,N...]"))?;
        let i = files
            .iter()
            .position(|p| p.as_os_str() == f || p.file_name().is_some_and(|n| n == f))
            .with_context(|| format!("--label {item}: {f} is not one of the input surfaces"))?;
        let v: Option<Vec<u32>> = l
            .split(',')
            .map(|x| x.trim().parse().ok().and_then(biotet_io::checked_label))
            .collect();
        out[i] = Some(v.with_context(|| {
            format!(
                "--label {item}: labels are whole numbers from 0 to {}",
                biotet_io::MAX_LABEL
            )
        })?);
    }
    Ok(out)
}

/// Several closed surfaces as one labelled, validated surface: every closed shell encloses a
/// region, innermost first (see `biotet::mesh::shells`). Returns the surface, its shells and a
/// name for messages.
pub fn labelled_surface(
    paths: &[PathBuf],
    labels: &[String],
    common: Common,
    stage: &Stage,
    crossings: Crossings,
) -> Result<(SurfaceMesh, Vec<Shell>, String)> {
    let (s, shells, _, name) = labelled_surface_report(paths, labels, common, stage, crossings)?;
    Ok((s, shells, name))
}

/// [`labelled_surface`] with the validation report: what `biotet mesh` reads, as `biotet
/// validate` judges it.
pub fn labelled_surface_report(
    paths: &[PathBuf],
    labels: &[String],
    common: Common,
    stage: &Stage,
    crossings: Crossings,
) -> Result<(SurfaceMesh, Vec<Shell>, ValidationReport, String)> {
    let labels = parse_labels(labels, paths)?;
    let mut parts = Vec::new();
    for (i, p) in paths.iter().enumerate() {
        stage.set(format!("reading {}", p.display()));
        let read = biotet_io::read_surface(p)?;
        if read.side_labels.is_some() {
            if paths.len() > 1 {
                anyhow::bail!(
                    "{}: a surface with side labels holds every region and must be given alone",
                    p.display()
                );
            }
            if labels[i].is_some() {
                anyhow::bail!(
                    "{}: --label does not apply: the file gives the region on each side of \
                     every triangle",
                    p.display()
                );
            }
            stage.set("validating the surface");
            let (s, shells, report) = side_labelled(p, read, common, crossings)?;
            note_touching(&s, &p.display().to_string(), common);
            return Ok((s, shells, report, p.display().to_string()));
        }
        // `assemble` welds copies of a point in every format, as the STL reader does: the user
        // hears how many.
        let welded = read.welded + read.mesh.duplicate_points();
        note_welded(&p.display().to_string(), welded, common);
        parts.push(Part {
            surface: read.mesh,
            labels: labels[i].clone(),
        });
    }
    let name = paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(" + ");
    stage.set("validating the surface");
    let (s, shells, report) = assemble_validated(parts, &name, paths, common, crossings)?;
    Ok((s, shells, report, name))
}

/// Assemble and validate parts, telling the user about flipped shells and regions.
pub fn assemble_parts(
    parts: Vec<Part>,
    name: &str,
    paths: &[PathBuf],
    common: Common,
) -> Result<(SurfaceMesh, Vec<Shell>)> {
    let (s, shells, _) = assemble_validated(parts, name, paths, common, Crossings::Refused)?;
    Ok((s, shells))
}

/// A validation error as the user sees it. Where crossing triangles were let through (the
/// surface stage follows) and the validation failed on the nesting all the same, the crossings
/// are the cause to name (shells pushed into one another confuse it); any other failure is its
/// own. Where they were refused with the hint, a crossing's refusal says how the stage
/// untangles them.
fn refusal(
    s: &SurfaceMesh,
    e: biotet::mesh::validate::SurfaceError,
    crossings: Crossings,
) -> anyhow::Error {
    use biotet::mesh::validate::SurfaceError::{LabelsContradictGeometry, SelfIntersection};
    match crossings {
        Crossings::Allowed if matches!(e, LabelsContradictGeometry { .. }) => {
            let first = check_self_intersections(s, ValidateOptions::default().max_examples);
            anyhow::Error::new(first.err().unwrap_or(e))
        }
        Crossings::Hinted if matches!(e, SelfIntersection { .. }) => {
            anyhow::Error::new(e).context(biotet::surface::untangle::HINT)
        }
        _ => anyhow::Error::new(e),
    }
}

/// Tell the user how many copies of points were welded (a triangle soup is the surface it
/// describes).
pub fn note_welded(name: &str, welded: usize, common: Common) {
    if welded > 0 && !common.quiet && !common.json {
        eprintln!("note: {name}: welded {welded} duplicate vertices");
    }
}

/// Tell the user about crossing triangles left for the surface stage to untangle.
fn note_crossings(s: &SurfaceMesh, name: &str, common: Common) {
    if common.quiet || common.json {
        return;
    }
    if let Err(biotet::mesh::validate::SurfaceError::SelfIntersection { count, .. }) =
        check_self_intersections(s, 1)
    {
        eprintln!(
            "note: {name}: {count} pairs of triangles cross; the surface stage untangles them \
             first, moving points by at most a quarter of the tolerance"
        );
    }
}

/// Tell the user where regions touch only along an edge or at a vertex: legitimate (each
/// region's boundary is whole), the edge or vertex shared by the regions in the mesh.
fn note_touching(s: &SurfaceMesh, name: &str, common: Common) {
    if common.quiet || common.json {
        return;
    }
    let t = biotet::mesh::shells::touching(s);
    let p = |v: u32| {
        let q = s.points[v as usize];
        format!("({}, {}, {})", q[0], q[1], q[2])
    };
    let regions = |r: &[u32]| {
        let r: Vec<String> = r.iter().map(|x| x.to_string()).collect();
        r.join(" and ")
    };
    const SHOWN: usize = 5;
    for (e, r) in t.edges.iter().take(SHOWN) {
        eprintln!(
            "note: {name}: shells touch along edge ({}, {}) {}–{}: kept as an edge shared by \
             regions {}",
            e[0],
            e[1],
            p(e[0]),
            p(e[1]),
            regions(r)
        );
    }
    for (v, r) in t.vertices.iter().take(SHOWN) {
        eprintln!(
            "note: {name}: shells touch at vertex {v} {}: kept as a vertex shared by regions {}",
            p(*v),
            regions(r)
        );
    }
    let more = t.edges.len().saturating_sub(SHOWN) + t.vertices.len().saturating_sub(SHOWN);
    if more > 0 {
        eprintln!("note: {name}: and {more} more edges or vertices where shells touch");
    }
}

/// [`assemble_parts`] with the validation report.
fn assemble_validated(
    parts: Vec<Part>,
    name: &str,
    paths: &[PathBuf],
    common: Common,
    crossings: Crossings,
) -> Result<(SurfaceMesh, Vec<Shell>, ValidationReport)> {
    let given: usize = parts.iter().map(|p| p.surface.triangles.len()).sum();
    let (mut surface, shells) =
        assemble(parts).with_context(|| format!("{name}: cannot assemble the surfaces"))?;
    // Shared faces (touching shells, solids of one assembly) come once in each boundary and
    // are kept once: the user hears why the count fell.
    let shared = given.saturating_sub(surface.triangles.len());
    if shared > 0 && !common.quiet && !common.json {
        eprintln!(
            "note: {name}: {shared} triangles given twice (once in each of two touching \
             boundaries) are kept once, as interfaces"
        );
    }
    let opts = ValidateOptions {
        self_intersections: crossings != Crossings::Allowed,
        ..ValidateOptions::default()
    };
    let report = validate_surface(&mut surface, &opts)
        .map_err(|e| refusal(&surface, e, crossings))
        .with_context(|| format!("{name}: invalid surface"))?;
    if crossings == Crossings::Allowed {
        note_crossings(&surface, name, common);
    }
    if !common.quiet && !common.json {
        for (k, sh) in shells.iter().enumerate() {
            let file = paths
                .get(sh.part)
                .map_or(name.to_string(), |p| p.display().to_string());
            if sh.reoriented > 0 {
                eprintln!(
                    "note: {file}: {} of the {} triangles of shell {k} were turned to agree with \
                     their neighbours",
                    sh.reoriented, sh.n_triangles
                );
            }
            if sh.flipped {
                eprintln!(
                    "note: {file}: shell {k} ({} triangles) faced inward and was flipped",
                    sh.n_triangles
                );
            }
        }
        if shells.len() > 1 {
            let desc: Vec<String> = shells
                .iter()
                .map(|sh| match sh.parent {
                    Some(p) => format!("{} (inside {})", sh.label, shells[p].label),
                    None => sh.label.to_string(),
                })
                .collect();
            eprintln!("note: {} shells, regions {}", shells.len(), desc.join(", "));
        }
    }
    note_touching(&surface, name, common);
    Ok((surface, shells, report))
}

/// [`labelled_surface`] for commands whose surface is optional (`None` without paths).
pub fn surfaces(paths: &[PathBuf], common: Common, stage: &Stage) -> Result<Option<SurfaceMesh>> {
    if paths.is_empty() {
        return Ok(None);
    }
    Ok(Some(
        labelled_surface(paths, &[], common, stage, Crossings::Refused)?.0,
    ))
}

/// The `n` comma-separated finite numbers of option `--what`'s value `text`.
pub fn numbers(what: &str, text: &str, n: usize) -> Result<Vec<f64>> {
    let v: Vec<f64> = text
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--{what} {text}: expected {n} numbers separated by commas"))?;
    if v.len() != n || v.iter().any(|x| !x.is_finite()) {
        bail!("--{what} {text}: expected {n} finite numbers separated by commas");
    }
    Ok(v)
}
