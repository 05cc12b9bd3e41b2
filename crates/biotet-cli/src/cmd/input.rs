//! Reading inputs with the CLI's messages: every error names the file.

use crate::Common;
use crate::progress::Stage;
use anyhow::{Context, Result};
use biotet::mesh::shells::{Part, Shell, assemble};
use biotet::mesh::side_labels::{self, FROM_GEOMETRY};
use biotet::mesh::validate::{
    ValidateOptions, ValidationReport, check_self_intersections, validate_surface,
};
use biotet::{SurfaceMesh, TetMesh};
use std::path::{Path, PathBuf};

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

/// Read and validate a closed surface. Refuses invalid surfaces with an error naming the file;
/// flips an inward-oriented surface and says so. A file with side labels is checked as
/// [`side_labelled`] does.
pub fn surface(path: &Path, common: Common) -> Result<(SurfaceMesh, ValidationReport)> {
    let read = biotet_io::read_surface(path)?;
    if read.side_labels.is_some() {
        let (mesh, _, report) = side_labelled(path, read, common)?;
        return Ok((mesh, report));
    }
    let mut mesh = read.mesh;
    let report = validate_surface(&mut mesh, &ValidateOptions::default())
        .with_context(|| format!("{}: invalid surface", path.display()))?;
    if !common.quiet && !common.json {
        if read.welded > 0 {
            eprintln!(
                "note: {}: welded {} duplicate vertices",
                path.display(),
                read.welded
            );
        }
        if report.flipped_inward {
            eprintln!(
                "note: {}: {} of {} triangles faced inward and were flipped",
                path.display(),
                report.n_flipped_triangles,
                report.n_triangles
            );
        }
    }
    Ok((mesh, report))
}

/// A surface whose file gives the region labels on both sides of its triangles (see
/// `biotet::mesh::side_labels`): the per-region checks of `validate_surface` (closed,
/// consistently oriented, no crossing triangles) and the labels against the cells of the
/// geometry. Errors name the file, the triangle and the reason.
pub fn side_labelled(
    path: &Path,
    read: biotet_io::SurfaceRead,
    common: Common,
) -> Result<(SurfaceMesh, Vec<Shell>, ValidationReport)> {
    let name = path.display().to_string();
    let mut mesh = read.mesh;
    mesh.sides = read.side_labels.unwrap_or_default();
    let partial = mesh.sides.iter().flatten().any(|&l| l == FROM_GEOMETRY);
    let invalid = || format!("{name}: invalid surface");
    let opts = ValidateOptions::default();
    let mut report = None;
    if partial {
        // Fronts come from the cells, which need triangles that do not cross.
        check_self_intersections(&mesh, opts.max_examples).with_context(invalid)?;
    } else {
        report = Some(validate_surface(&mut mesh, &opts).with_context(invalid)?);
    }
    let resolved = side_labels::resolve(&mesh)
        .with_context(|| format!("{name}: side labels disagree with the geometry"))?;
    let mut mesh = resolved.surface;
    let report = match report {
        Some(r) => r,
        None => validate_surface(&mut mesh, &opts).with_context(invalid)?,
    };
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
        let v: Result<Vec<u32>, _> = l.split(',').map(|x| x.trim().parse::<u32>()).collect();
        out[i] = Some(v.with_context(|| format!("--label {item}: bad label"))?);
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
) -> Result<(SurfaceMesh, Vec<Shell>, String)> {
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
            let (s, shells, _) = side_labelled(p, read, common)?;
            return Ok((s, shells, p.display().to_string()));
        }
        if read.welded > 0 && !common.quiet && !common.json {
            eprintln!(
                "note: {}: welded {} duplicate vertices",
                p.display(),
                read.welded
            );
        }
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
    let (s, shells) = assemble_parts(parts, &name, paths, common)?;
    Ok((s, shells, name))
}

/// Assemble and validate parts, telling the user about flipped shells and regions.
pub fn assemble_parts(
    parts: Vec<Part>,
    name: &str,
    paths: &[PathBuf],
    common: Common,
) -> Result<(SurfaceMesh, Vec<Shell>)> {
    let (mut surface, shells) =
        assemble(parts).with_context(|| format!("{name}: cannot assemble the surfaces"))?;
    validate_surface(&mut surface, &ValidateOptions::default())
        .with_context(|| format!("{name}: invalid surface"))?;
    if !common.quiet && !common.json {
        for (k, sh) in shells.iter().enumerate() {
            if sh.flipped {
                eprintln!(
                    "note: {}: shell {k} ({} triangles) faced inward and was flipped",
                    paths
                        .get(sh.part)
                        .map_or(name.to_string(), |p| p.display().to_string()),
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
    Ok((surface, shells))
}

/// [`labelled_surface`] for commands whose surface is optional (`None` without paths).
pub fn surfaces(paths: &[PathBuf], common: Common, stage: &Stage) -> Result<Option<SurfaceMesh>> {
    if paths.is_empty() {
        return Ok(None);
    }
    Ok(Some(labelled_surface(paths, &[], common, stage)?.0))
}
