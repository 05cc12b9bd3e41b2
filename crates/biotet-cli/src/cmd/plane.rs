//! The 2D side of `biotet mesh`, `recover`, `smooth` and `check`: each command hands over here
//! when its input is 2D (a PSLG for `mesh`, a `Dimension 2` mesh or Triangle `.node`/`.ele` for
//! the others), detected from the file. `quality` reads 2D meshes by itself.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use biotet::TriMesh;
use biotet::check2d::check_tri;
use biotet::mesh::pslg::Pslg;
use biotet::pipeline2d::{Mesh2dOptions, describe_failure, mesh_pslg, triangulate_pslg};
use biotet::quality::TriQualityReport;
use biotet::recover2d::{carve, recover};
use biotet::smooth::Boundary;
use biotet::smooth::plane::{PlaneSmoothOptions, smooth_tri_with_segments};
use biotet::template::Zone;
use biotet::template::plane::PlaneDeployOptions;
use biotet_io::MeshKind;
use serde_json::json;

use crate::progress::Stage;
use crate::{Common, plot};

/// Is `path` a 2D triangle mesh (as opposed to a tet mesh)?
pub fn is_tri_mesh(path: &Path) -> bool {
    matches!(biotet_io::mesh_kind(path), Ok(MeshKind::Triangles2d))
        && !biotet_io::is_pslg(path).unwrap_or(false)
}

/// Is `path` a PSLG (`.poly`, `.node`/`.edge`, 2D `.mesh` with edges only)?
pub fn is_pslg(path: &Path) -> bool {
    biotet_io::is_pslg(path).unwrap_or(false)
}

/// Read and validate a PSLG; errors name the file.
pub fn read_pslg(path: &Path) -> Result<Pslg> {
    let r = biotet_io::read_pslg(path)?;
    r.pslg
        .validate()
        .with_context(|| format!("{}: invalid planar straight-line graph", path.display()))?;
    Ok(r.pslg)
}

fn read_tri(path: &Path, common: Common) -> Result<TriMesh> {
    let r = biotet_io::read_tri_mesh(path)?;
    if r.flipped > 0 && !common.quiet && !common.json {
        eprintln!(
            "note: {}: stored clockwise; all {} triangles were reoriented",
            path.display(),
            r.flipped
        );
    }
    Ok(r.mesh)
}

fn write(path: &Path, mesh: &TriMesh) -> Result<Vec<PathBuf>> {
    Ok(biotet_io::write_tri_mesh(path, mesh)?)
}

fn files(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Options of the 2D `biotet mesh`.
pub struct MeshArgs<'a> {
    /// The PSLG.
    pub input: &'a Path,
    /// Output.
    pub output: Option<&'a Path>,
    /// Uniform size.
    pub size: Option<f64>,
    /// Pixels per smallest size.
    pub resolution: f64,
    /// Zone shape.
    pub zone: Zone,
    /// Template limit.
    pub max_pixels: usize,
    /// Size growth per unit distance from the boundary.
    pub grading: f64,
    /// Skip smoothing.
    pub no_smooth: bool,
    /// Skip node deployment (the PSLG's own points only).
    pub no_deploy: bool,
    /// Angle histogram SVG.
    pub svg: Option<&'a Path>,
    /// On failure, write the partial mesh beside the output (`OUT.failed.EXT`).
    pub keep_failed: bool,
}

/// `biotet mesh` on a PSLG.
pub fn mesh(a: MeshArgs, common: Common) -> Result<ExitCode> {
    let stage = Stage::start(common.quiet, format!("reading {}", a.input.display()));
    let pslg = read_pslg(a.input)?;
    stage.set("meshing");
    let opts = Mesh2dOptions {
        deploy: PlaneDeployOptions {
            size: a.size,
            resolution: a.resolution,
            zone: a.zone,
            max_pixels: a.max_pixels,
            grading: Some(a.grading),
        },
        smooth: (!a.no_smooth).then(PlaneSmoothOptions::default),
    };
    let (mesh, report) = if a.no_deploy {
        triangulate_pslg(&pslg, &[]).map(|(mut m, mut r)| {
            if let Some(so) = &opts.smooth {
                // Every point but the segments' is free here (the Table 4.1 set-up).
                let clock = std::time::Instant::now();
                let map = &r.carve.point_map;
                let segs: Vec<[u32; 2]> = pslg
                    .segments
                    .iter()
                    .map(|s| s.map(|v| map[v as usize]))
                    .collect();
                r.smooth = Some(smooth_tri_with_segments(&mut m, &segs, &[], so));
                r.seconds_smooth = clock.elapsed().as_secs_f64();
            }
            (m, r)
        })
    } else {
        mesh_pslg(&pslg, &opts)
    }
    .with_context(|| format!("{}: cannot mesh", a.input.display()))?;
    stage.set("checking");
    let check = check_tri(&mesh, Some(&pslg));
    let quality = TriQualityReport::of(&mesh);
    // A run that fails writes nothing at the requested paths (`--keep-failed`: the partial mesh
    // beside the output).
    let (written, failure_note) = if check.valid {
        let mut sides = Vec::new();
        if let Some(svg) = a.svg {
            sides.push((
                svg,
                plot::tri_quality_svg(&quality, &a.input.display().to_string())?,
            ));
        }
        let written = crate::output::write_all(
            || match a.output {
                Some(out) => {
                    stage.set(format!("writing {}", out.display()));
                    biotet_io::write_tri_mesh(out, &mesh)
                }
                None => Ok(Vec::new()),
            },
            &sides,
        )?;
        (written, None)
    } else {
        let requested: Vec<&Path> = a.output.iter().chain(&a.svg).copied().collect();
        let (written, note) =
            crate::output::on_failure("invalid mesh", a.output, &requested, a.keep_failed, |p| {
                biotet_io::write_tri_mesh(p, &mesh)
            });
        (written, Some(note))
    };
    drop(stage);
    if common.json {
        crate::emit(&serde_json::to_string_pretty(&json!({
            "input": a.input.display().to_string(),
            "dimension": 2,
            "written": written.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            "report": report,
            "check": check,
            "quality": quality,
        }))?);
    } else if !common.quiet {
        let t = report.template.as_ref();
        crate::emit(&format!(
            "{}: {} points, {} segments -> {} nodes ({} deployed), {} triangles, labels {:?}\n\
             segments: {} already edges, {} recovered ({} triangles refilled)\n\
             smallest angle {:.2}°, largest {:.2}°; {}",
            a.input.display(),
            pslg.points.len(),
            pslg.segments.len(),
            mesh.points.len(),
            t.map_or(0, |t| t.interior_nodes),
            mesh.triangles.len(),
            report.carve.labels,
            report.recover.n_present,
            report.recover.n_recovered,
            report.recover.n_carved,
            quality.min_angle_deg.unwrap_or(f64::NAN),
            quality.max_angle_deg.unwrap_or(f64::NAN),
            if check.valid { "valid" } else { "INVALID" },
        ));
        if !written.is_empty() && failure_note.is_none() {
            crate::emit(&format!("wrote {}", files(&written)));
        }
    }
    match failure_note {
        None => Ok(ExitCode::SUCCESS),
        Some(note) => {
            eprintln!(
                "error: {}: the mesh is not valid{}",
                a.input.display(),
                if note.is_empty() {
                    note
                } else {
                    format!("; {note}")
                }
            );
            Ok(ExitCode::from(crate::EXIT_INVALID))
        }
    }
}

/// The mesh point of each PSLG point, by exact coordinates; an error names the first missing one.
fn points_in_mesh(
    mesh: &TriMesh,
    g: &Pslg,
    pslg_path: &Path,
    mesh_path: &Path,
) -> Result<Vec<u32>> {
    let key = |p: &[f64; 2]| p.map(|c| (c + 0.0).to_bits());
    let index: std::collections::HashMap<[u64; 2], u32> = mesh
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| (key(p), i as u32))
        .collect();
    g.points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            index.get(&key(p)).copied().with_context(|| {
                format!(
                    "{}: point {i} ({}, {}) is no point of the mesh {}",
                    pslg_path.display(),
                    p[0],
                    p[1],
                    mesh_path.display()
                )
            })
        })
        .collect()
}

/// `biotet recover` on a 2D mesh: every segment of the PSLG `pslg_path` made an edge.
pub fn recover_cmd(
    mesh_path: &Path,
    pslg_path: &Path,
    output: Option<&Path>,
    keep_outside: bool,
    keep_failed: bool,
    common: Common,
) -> Result<ExitCode> {
    let stage = Stage::start(common.quiet, format!("reading {}", mesh_path.display()));
    let mut mesh = read_tri(mesh_path, common)?;
    let valid = check_tri(&mesh, None);
    if !valid.valid {
        anyhow::bail!(
            "{}: not a valid triangulation, cannot recover segments in it:\n{valid}",
            mesh_path.display()
        );
    }
    let mut pslg = read_pslg(pslg_path)?;
    let map = points_in_mesh(&mesh, &pslg, pslg_path, mesh_path)?;
    let segs: Vec<[u32; 2]> = pslg
        .segments
        .iter()
        .map(|s| s.map(|v| map[v as usize]))
        .collect();
    stage.set("recovering the segments");
    let report = recover(&mut mesh, &segs);
    let carved = if keep_outside || !report.complete() {
        None
    } else {
        // Carve with the PSLG renumbered to the mesh's points.
        let mut points = mesh.points.clone();
        std::mem::swap(&mut pslg.points, &mut points);
        pslg.segments = segs.clone();
        Some(carve(&mut mesh, &pslg).with_context(|| format!("{}", pslg_path.display()))?)
    };
    let check = check_tri(&mesh, None);
    // A run that fails writes nothing at the output (`--keep-failed`: the partial mesh beside it).
    let ok = report.complete() && check.valid;
    let (written, failure_note) = if ok {
        let written = match output {
            Some(out) => write(out, &mesh)?,
            None => Vec::new(),
        };
        (written, None)
    } else {
        let requested: Vec<&Path> = output.into_iter().collect();
        let (written, note) =
            crate::output::on_failure("partial mesh", output, &requested, keep_failed, |p| {
                biotet_io::write_tri_mesh(p, &mesh)
            });
        (written, Some(note))
    };
    drop(stage);
    if common.json {
        crate::emit(&serde_json::to_string_pretty(&json!({
            "mesh": mesh_path.display().to_string(),
            "dimension": 2,
            "recover": report,
            "carve": carved,
            "check": check,
            "written": written.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
        }))?);
    } else if !common.quiet {
        crate::emit(&format!(
            "{}: {} segments: {} already edges, {} recovered ({} triangles refilled), {} failed{}",
            mesh_path.display(),
            report.n_segments,
            report.n_present,
            report.n_recovered,
            report.n_carved,
            report.failed.len(),
            carved.as_ref().map_or(String::new(), |c| format!(
                "; {} triangles outside removed, {} kept, labels {:?}",
                c.n_removed, c.n_kept, c.labels
            ))
        ));
        for f in report.failed.iter().take(10) {
            crate::emit(&format!("  {}", describe_failure(f)));
        }
        if !written.is_empty() && failure_note.is_none() {
            crate::emit(&format!("wrote {}", files(&written)));
        }
    }
    match failure_note {
        None => Ok(ExitCode::SUCCESS),
        Some(note) => {
            eprintln!(
                "error: {}: {}{}",
                mesh_path.display(),
                if report.complete() {
                    "the recovered mesh is not valid".to_string()
                } else {
                    format!("{} segments could not be recovered", report.failed.len())
                },
                if note.is_empty() {
                    note
                } else {
                    format!("; {note}")
                }
            );
            Ok(ExitCode::from(crate::EXIT_INVALID))
        }
    }
}

/// `biotet smooth` on a 2D mesh.
pub fn smooth_cmd(
    mesh_path: &Path,
    pslg_path: Option<&Path>,
    slide: bool,
    max_sweeps: usize,
    output: &Path,
    svg: Option<&Path>,
    common: Common,
) -> Result<ExitCode> {
    let stage = Stage::start(common.quiet, format!("reading {}", mesh_path.display()));
    let mut mesh = read_tri(mesh_path, common)?;
    let before = TriQualityReport::of(&mesh);
    stage.set("smoothing");
    let opts = PlaneSmoothOptions {
        boundary: if slide {
            Boundary::Slide
        } else {
            Boundary::Fixed
        },
        max_sweeps,
        ..Default::default()
    };
    // Segments of a given PSLG hold their nodes like boundary edges (open polylines, cracks).
    let (segs, hold) = match pslg_path {
        Some(p) => {
            let g = read_pslg(p)?;
            let map = points_in_mesh(&mesh, &g, p, mesh_path)?;
            let segs: Vec<[u32; 2]> = g
                .segments
                .iter()
                .map(|s| s.map(|v| map[v as usize]))
                .collect();
            let on: std::collections::HashSet<u32> = segs.iter().flatten().copied().collect();
            let hold: Vec<u32> = map.into_iter().filter(|v| !on.contains(v)).collect();
            (segs, hold)
        }
        None => (Vec::new(), Vec::new()),
    };
    let report = smooth_tri_with_segments(&mut mesh, &segs, &hold, &opts);
    let after = TriQualityReport::of(&mesh);
    let mut sides = Vec::new();
    if let Some(svg) = svg {
        sides.push((
            svg,
            plot::tri_quality_svg(&after, &mesh_path.display().to_string())?,
        ));
    }
    let mut written =
        crate::output::write_all(|| biotet_io::write_tri_mesh(output, &mesh), &sides)?;
    written.truncate(written.len() - sides.len());
    drop(stage);
    if common.json {
        crate::emit(&serde_json::to_string_pretty(&json!({
            "mesh": mesh_path.display().to_string(),
            "dimension": 2,
            "smooth": report,
            "before": before,
            "after": after,
            "written": written.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
        }))?);
    } else if !common.quiet {
        crate::emit(&format!(
            "{}: {} nodes ({} free, {} sliding, {} held), {} sweeps, {} moved\n\
             smallest angle {:.2}° -> {:.2}°, largest {:.2}° -> {:.2}°\nwrote {}",
            mesh_path.display(),
            report.n_nodes,
            report.n_free,
            report.n_sliding,
            report.n_fixed,
            report.sweeps.len(),
            report.nodes_moved,
            before.min_angle_deg.unwrap_or(f64::NAN),
            after.min_angle_deg.unwrap_or(f64::NAN),
            before.max_angle_deg.unwrap_or(f64::NAN),
            after.max_angle_deg.unwrap_or(f64::NAN),
            files(&written)
        ));
    }
    Ok(ExitCode::SUCCESS)
}

/// `biotet check` on a 2D mesh, optionally against a PSLG.
pub fn check_cmd(mesh_path: &Path, pslg: Option<&Path>, common: Common) -> Result<ExitCode> {
    let stage = Stage::start(common.quiet, format!("reading {}", mesh_path.display()));
    let mesh = read_tri(mesh_path, common)?;
    let g = match pslg {
        Some(p) => Some(read_pslg(p)?),
        None => None,
    };
    stage.set("checking");
    let report = check_tri(&mesh, g.as_ref());
    drop(stage);
    if common.json {
        crate::emit(&serde_json::to_string_pretty(&report)?);
    } else if !common.quiet {
        crate::emit(&format!("{}: {report}", mesh_path.display()));
    }
    Ok(if report.valid {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(crate::EXIT_INVALID)
    })
}
