//! Reading inputs with the CLI's messages: every error names the file.

use crate::Common;
use anyhow::{Context, Result};
use biotet::mesh::validate::{ValidateOptions, ValidationReport, validate_surface};
use biotet::{SurfaceMesh, TetMesh};
use std::path::Path;

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
/// flips an inward-oriented surface and says so.
pub fn surface(path: &Path, common: Common) -> Result<(SurfaceMesh, ValidationReport)> {
    let read = biotet_io::read_surface(path)?;
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

/// Read and validate several surfaces into one (`None` when no path is given).
pub fn surfaces(
    paths: &[std::path::PathBuf],
    common: Common,
    stage: &crate::progress::Stage,
) -> Result<Option<SurfaceMesh>> {
    let mut out: Option<SurfaceMesh> = None;
    for s in paths {
        stage.set(format!("reading {}", s.display()));
        let (m, _) = surface(s, common)?;
        out.get_or_insert_with(SurfaceMesh::default).append(&m);
    }
    Ok(out)
}
