//! Surface to volume mesh: deploy nodes ([`crate::template`]), tetrahedralize them
//! ([`crate::delaunay`]), keep the tets inside the surface, then the later stages. This module
//! only strings the stages together, times them and counts what they did.

use std::borrow::Borrow;
use std::time::Instant;

use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};
use serde::Serialize;

use crate::delaunay::{Delaunay, DelaunayError};
use crate::lastresort::recover::{PIPELINE_FIRST_CAVITY_TETS, recover_built};
use crate::lastresort::{
    ImproveOptions, ImproveReport, RecoverError, RecoverOptions, RecoverReport, improve,
};
use crate::mesh::coord_key;
use crate::mesh::inside::{RegionLocator, Transitions, centroid_region};
use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::{NO_NEIGHBOR, TetMesh, retain_tets};
use crate::polish::{PolishOptions, PolishReport, polish};
use crate::sizing::Sizing;
use crate::smooth::{SmoothError, SmoothOptions, SmoothReport, smooth};
use crate::star::StarReport;
use crate::template::{DeployError, DeployOptions, TemplateStats, deploy};

/// Options of [`mesh_surface`].
#[derive(Debug, Clone)]
pub struct PipelineOptions {
    /// Node deployment.
    pub deploy: DeployOptions,
    /// Boundary recovery (`None` skips it).
    pub recover: Option<RecoverOptions>,
    /// Sliver removal (`None` skips it).
    pub improve: Option<ImproveOptions>,
    /// Smoothing (`None` skips it). Surface nodes stay fixed by default, so the surface is kept
    /// exactly.
    pub smooth: Option<SmoothOptions>,
    /// Polish of the unforced tets still poor after smoothing (`None` skips it). Surface points
    /// stay. It runs only after recovery, which makes the boundary faces exact.
    pub polish: Option<PolishOptions>,
    /// Interior seeds in sections too thin for the template's nodes ([`crate::seeds`]), after
    /// recovery.
    pub seeds: bool,
}

impl PipelineOptions {
    /// Node deployment, Delaunay and outside removal only (no later stage).
    pub fn deploy_only() -> PipelineOptions {
        PipelineOptions {
            recover: None,
            improve: None,
            smooth: None,
            polish: None,
            seeds: false,
            ..PipelineOptions::default()
        }
    }
}

impl Default for PipelineOptions {
    fn default() -> PipelineOptions {
        PipelineOptions {
            deploy: DeployOptions::default(),
            // Small cavities first, then an interior point, before large cavities: see
            // `RecoverOptions::first_cavity_tets`.
            // One wide round: the fallbacks follow (`RecoverOptions::max_wide_rounds`). Kernel
            // points by linear program from the first round (`RecoverOptions::exact_kernel`): the
            // bar lattice 11.6 s -> 1.7 s, 825 -> 717 tets under 10°, at the price of gmsh's t13
            // (491 -> 511, TetGen 605).
            recover: Some(RecoverOptions {
                first_cavity_tets: PIPELINE_FIRST_CAVITY_TETS,
                max_wide_rounds: 1,
                exact_kernel: true,
                ..RecoverOptions::default()
            }),
            // No grown cavities: polish, which follows, fixes what they would (wm_20k: 2,502
            // tets under 10° without them, 2,510 with; brain_20k 1,366 and 1,368) and they were a
            // third of sliver removal's searches' time (the whole run 9% faster on wm_20k,
            // median of 9 alternating pairs). `biotet improve` alone keeps them.
            improve: Some(ImproveOptions {
                grow: false,
                ..ImproveOptions::default()
            }),
            // Clusters already above 0.1 sr are left alone: on brain_20k that halves the time and
            // changes the tets below 10° by 0.1%.
            smooth: Some(SmoothOptions {
                skip_above_sr: 0.1,
                ..SmoothOptions::default()
            }),
            polish: Some(PolishOptions::default()),
            seeds: true,
        }
    }
}

/// Time and outcome of one stage.
#[derive(Debug, Clone, Serialize)]
pub struct StageReport {
    /// Stage name.
    pub name: &'static str,
    /// Wall seconds.
    pub seconds: f64,
}

/// What the pipeline did.
#[derive(Debug, Clone, Default, Serialize)]
pub struct MeshReport {
    /// Stages in order with their times.
    pub stages: Vec<StageReport>,
    /// Seconds from start to finish (excluding reading and writing files).
    pub seconds_total: f64,
    /// Template figures.
    pub template: TemplateStats,
    /// Surface points (all become mesh points).
    pub n_surface_points: usize,
    /// Points of the input surface that no triangle uses, left out (a file's stray nodes: one
    /// lying on a triangle would block its recovery, one inside would be a node nobody asked
    /// for).
    pub n_unused_points: usize,
    /// Interior nodes deployed.
    pub n_interior_nodes: usize,
    /// Finite tets of the Delaunay tetrahedralization (the convex hull).
    pub n_delaunay_tets: usize,
    /// Tets whose region needed a centroid test (two or more surface corners); with recovery,
    /// only those of the regions its flood fill cannot label (none when every triangle is
    /// recovered).
    pub n_centroid_tests: usize,
    /// Tets kept (inside a region).
    pub n_tets: usize,
    /// Points of the output mesh.
    pub n_points: usize,
    /// Input triangles that are not faces of the output mesh.
    pub missing_triangles: usize,
    /// What boundary recovery did (if it ran; the last try's report after retries).
    pub recover: Option<RecoverReport>,
    /// Retries of recovery without the interior nodes near the triangles it left, in order (after
    /// cones set aside, [`StarReport::kept`], the first is a wide one with every node).
    pub retries: Vec<RetryReport>,
    /// Where recovery left triangles and every region is star-shaped: the regions coned from
    /// interior points instead ([`crate::star`]).
    pub star: Option<crate::star::StarReport>,
    /// Interior seeds added in thin sections after recovery ([`crate::seeds`]).
    pub seeds: usize,
    /// What sliver removal did (if it ran).
    pub improve: Option<ImproveReport>,
    /// What smoothing did (if it ran).
    pub smooth: Option<SmoothReport>,
    /// What polishing did (if it ran).
    pub polish: Option<PolishReport>,
}

/// Why the pipeline failed.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// Node deployment failed.
    #[error(transparent)]
    Deploy(#[from] DeployError),
    /// The Delaunay tetrahedralization failed.
    #[error(transparent)]
    Delaunay(#[from] DelaunayError),
    /// Boundary recovery could not run.
    #[error(transparent)]
    Recover(#[from] RecoverError),
    /// Smoothing failed.
    #[error(transparent)]
    Smooth(#[from] SmoothError),
}

/// Mesh the volume bounded by `surface` (validated: closed, consistently oriented, labelled).
///
/// The output's first points are the surface's points (same order; points no triangle uses are
/// left out), then the interior nodes;
/// tets carry the label of the region containing them. `progress` hears each stage's name as it
/// starts. The sizing is used by node deployment only: passed by value (rather than as
/// `&Sizing`), it is freed once the nodes are placed, before the later stages' peaks.
pub fn mesh_surface<S: Borrow<Sizing>>(
    surface: &SurfaceMesh,
    sizing: S,
    opts: &PipelineOptions,
    progress: &mut dyn FnMut(&str),
) -> Result<(TetMesh, MeshReport), PipelineError> {
    let start = Instant::now();
    let mut report = MeshReport {
        n_unused_points: surface.n_unused_points(),
        ..MeshReport::default()
    };
    let used;
    let surface = if report.n_unused_points > 0 {
        let mut s = surface.clone();
        s.drop_unused_points();
        used = s;
        &used
    } else {
        surface
    };

    progress("deploying nodes");
    let clock = Instant::now();
    let dep = deploy(surface, sizing.borrow(), &opts.deploy)?;
    drop(sizing);
    report.template = dep.stats.clone();
    report.n_surface_points = dep.n_surface;
    report.n_interior_nodes = dep.interior_regions.len();
    stage(&mut report, "deploy", clock);

    let ns = dep.n_surface;
    // The nodes are kept for a retry: a surface triangle far larger than the spacing around it
    // can cross so many tets that no cavity within the bounds holds it (the Schönhardt prism
    // or two cubes at a twentieth of their size). Without the nodes near it, it can.
    // The nodes, kept for the fallbacks when points may be added: the retries without the nodes
    // near the triangles recovery left, then with points just behind them.
    let steiner = opts.recover.is_some_and(|o| o.allow_interior_steiner);
    let mut nodes = steiner.then(|| Nodes {
        points: dep.points.clone(),
        regions: dep.interior_regions.clone(),
        ns,
    });
    // Where every region is star-shaped, the cones of `crate::star` follow a first try that
    // leaves triangles, in place of the retries and the wide rounds (seconds of search on a cube
    // of strip-cut faces, where the cones take milliseconds and keep every node) where they
    // take back at least half the nodes ([`recover_star`]).
    let kernels = if steiner {
        crate::star::kernels(surface)
    } else {
        None
    };
    let retry = steiner && !dep.interior_regions.is_empty() && kernels.is_none();
    // With nodes to clear, the first try skips the wide rounds (seconds where a retry takes
    // milliseconds); they come last, if clearing does not do.
    // With the cones to follow, the first try keeps to its small cavities too, and ends at its
    // first round that leaves triangles: where those leave triangles, larger cavities and more
    // rounds cost seconds (cubes of strip-cut faces: 1.85 s -> 0.47 s, the same mesh) and the
    // cones milliseconds.
    let first = opts.recover.map(|o| RecoverOptions {
        widen: o.widen && !retry && kernels.is_none(),
        max_cavity_tets: if kernels.is_some() {
            o.first_cavity_tets.min(o.max_cavity_tets)
        } else {
            o.max_cavity_tets
        },
        max_wide_rounds: if kernels.is_some() {
            0
        } else {
            o.max_wide_rounds
        },
        ..o
    });
    let mut mesh = tetrahedralize(
        surface,
        dep.points,
        dep.interior_regions,
        ns,
        first.as_ref(),
        &mut report,
        progress,
    )?;
    if let (Some(nodes), Some(first), Some(last), true) = (&mut nodes, first, opts.recover, retry) {
        let clock = Instant::now();
        if let Some(m) = recover_again(surface, nodes, [first, last], &mut report, progress)? {
            mesh = m;
            stage(&mut report, "retry", clock);
        }
    }
    // Cones that leave out nodes are kept for the end: the other fallbacks go first.
    let mut cones = None;
    if let (Some(nodes), Some(kernels)) = (&mut nodes, &kernels)
        && let Some((m, star)) = recover_star(surface, kernels, nodes, &mut report, progress)
    {
        if star.kept {
            mesh = m;
        } else {
            cones = Some((m, star));
            // Recovery again from its start, with its wide rounds at once: the first try's small
            // cavities were chosen for the cones to follow, and clearing nodes first cost what
            // the cones had (a union of marching-cubes blobs, 3 triangles left: 2,012 of its
            // 3,406 nodes cleared before the wide round recovered them, 5,760 tets under 10°;
            // the wide round at once, 669 and a third of the time).
            if let Some(last) = opts.recover {
                let clock = Instant::now();
                progress("recovering again without the cones");
                let retry = RetryReport {
                    nodes_removed: 0,
                    nodes_added: 0,
                    wide: true,
                    missing_after: 0,
                };
                mesh = retry_once(surface, nodes, &last, retry, &mut report)?;
                if let Some(m) = recover_again(surface, nodes, [last, last], &mut report, progress)?
                {
                    mesh = m;
                }
                stage(&mut report, "retry", clock);
            }
        }
    }
    if let (Some(nodes), Some(last)) = (&mut nodes, opts.recover) {
        let clock = Instant::now();
        if let Some(m) = recover_inset(surface, nodes, last, &mut report, progress)? {
            mesh = m;
            stage(&mut report, "inset", clock);
        }
    }
    // Triangles left after every other fallback: the cones, nodes left out or not.
    if let Some((m, mut star)) = cones
        && report.recover.as_ref().is_some_and(|r| r.missing_after > 0)
    {
        star.kept = true;
        use_cones(&mut report, star, m.tets.len());
        mesh = m;
    }

    // Triangles recovery left let the region labels through, and the stages after it keep only
    // the faces between labels: they would take recovered triangles with them (a lattice of
    // crossing bars: 7 left by recovery, 26 after sliver removal). The run fails either way;
    // its partial mesh (`--keep-failed`) is recovery's.
    let recovered = report.recover.as_ref().is_none_or(|r| r.missing_after == 0);
    if opts.seeds && opts.recover.is_some() && recovered {
        progress("seeding thin sections");
        let clock = Instant::now();
        report.seeds = crate::seeds::insert_seeds(&mut mesh, ns, surface);
        stage(&mut report, "seeds", clock);
    }
    if let Some(o) = opts.improve.as_ref().filter(|_| recovered) {
        progress("removing slivers");
        let clock = Instant::now();
        report.improve = Some(improve(&mut mesh, o));
        stage(&mut report, "improve", clock);
    }
    if let Some(o) = opts.smooth.as_ref().filter(|_| recovered) {
        progress("smoothing");
        let clock = Instant::now();
        report.smooth = Some(smooth(&mut mesh, Some(surface), o)?);
        stage(&mut report, "smooth", clock);
    }
    if let Some(o) = opts
        .polish
        .as_ref()
        .filter(|_| opts.recover.is_some() && recovered)
    {
        progress("polishing");
        let clock = Instant::now();
        report.polish = Some(polish(&mut mesh, o));
        stage(&mut report, "polish", clock);
    }

    report.missing_triangles = missing_triangles(&mesh, surface);
    report.n_tets = mesh.tets.len();
    report.n_points = mesh.points.len();
    report.seconds_total = start.elapsed().as_secs_f64();
    Ok((mesh, report))
}

/// Record a stage's time since `clock`.
fn stage(report: &mut MeshReport, name: &'static str, clock: Instant) {
    report.stages.push(StageReport {
        name,
        seconds: clock.elapsed().as_secs_f64(),
    });
}

/// Node-clearing retries of recovery at most (each doubles the radius around the triangles).
const MAX_RETRIES: usize = 5;

/// One retry of recovery without the nodes near the triangles it left.
#[derive(Debug, Clone, Serialize)]
pub struct RetryReport {
    /// Interior nodes removed before it.
    pub nodes_removed: usize,
    /// Nodes added before it, just behind the triangles left and their corner neighbours
    /// ([`crate::inset`]; the last fallback).
    pub nodes_added: usize,
    /// Whether it was the last, with recovery's wide rounds (no node left to remove near).
    pub wide: bool,
    /// Input triangles still missing after it.
    pub missing_after: usize,
}

/// Tetrahedralize the points (surface points first, `ns` of them, then interior nodes with
/// their regions), label the tets, and recover the boundary when asked.
fn tetrahedralize(
    surface: &SurfaceMesh,
    mut points: Vec<[f64; 3]>,
    mut regions: Vec<u32>,
    ns: usize,
    recover: Option<&RecoverOptions>,
    report: &mut MeshReport,
    progress: &mut dyn FnMut(&str),
) -> Result<TetMesh, PipelineError> {
    progress("tetrahedralizing");
    let clock = Instant::now();
    if recover.is_some() {
        // Eight corners of a box around everything, outside (region 0): no surface triangle
        // then lies on the convex hull, where a planar facet split otherwise than the hull's
        // faces has no cavity to be recovered in. Only outside tets use them; they go with
        // those after recovery.
        enclose(&mut points, &mut regions);
    }
    // The triangulation takes the points (no second copy); they come back by vertex number,
    // which is the input order for distinct points.
    let n_points = points.len();
    let del = Delaunay::from_points(points)?;
    report.n_delaunay_tets = del.n_finite_tets();
    stage(report, "delaunay", clock);

    progress("removing outside tets");
    let clock = Instant::now();
    let map = del.vertex_map();
    // Delaunay vertex number -> deployment index (inputs are distinct: interior nodes are never
    // on the surface, so the map is a bijection unless the surface repeats a point).
    let mut input_of = vec![u32::MAX; del.n_vertices()];
    for (i, &v) in map.iter().enumerate() {
        if input_of[v as usize] == u32::MAX {
            input_of[v as usize] = i as u32;
        }
    }
    let ns = ns as u32;
    // The finite slots as a bitset with a rank per word: the tets' neighbours come from the
    // triangulation's own adjacency (no face sorting, no per-slot index array).
    let mut finite = vec![0u64; del.n_slots().div_ceil(64)];
    for t in del.finite_tets() {
        finite[t as usize / 64] |= 1 << (t % 64);
    }
    let mut rank = Vec::with_capacity(finite.len());
    let mut r = 0u32;
    for w in &finite {
        rank.push(r);
        r += w.count_ones();
    }
    let index_of = |t: u32| {
        let (w, b) = (t as usize / 64, t % 64);
        if finite[w] >> b & 1 == 0 {
            NO_NEIGHBOR
        } else {
            rank[w] + (finite[w] & ((1u64 << b) - 1)).count_ones()
        }
    };
    // Every finite tet and its neighbours, at exact capacity; the labels wait until the
    // triangulation, the largest thing held here, is gone.
    let mut tets: Vec<[u32; 4]> = Vec::with_capacity(report.n_delaunay_tets);
    let mut neighbors: Vec<[u32; 4]> = Vec::with_capacity(report.n_delaunay_tets);
    for t in del.finite_tets() {
        tets.push(del.tet(t).map(|x| input_of[x as usize]));
        neighbors.push(del.adjacent(t).map(index_of));
    }
    drop((finite, rank, input_of));
    let mut points = del.into_vertex_points();
    if points.len() != n_points {
        // Repeated input points share a vertex: give every input index its coordinates back.
        points = (0..n_points).map(|i| points[map[i] as usize]).collect();
    }
    drop(map);
    // Labels: tets with an interior node by its region; the others (two or more surface corners)
    // by a centroid test, on all threads (the order, and so the result, is fixed). With recovery
    // to follow, the centroid tests wait: its flood fill labels every tet once the surface is
    // recovered, and it tests only the tets of the regions it cannot label.
    let locator = recover.is_none().then(|| RegionLocator::new(surface));
    let mut labels: Vec<u32> = Vec::new();
    tets.par_iter()
        .map_init(Transitions::default, |scratch, v| {
            if v.iter().filter(|&&x| x < ns).count() < 2 {
                let i = v.iter().find(|&&x| x >= ns).copied().unwrap_or(0);
                regions[(i - ns) as usize]
            } else if let Some(locator) = &locator {
                centroid_region(v.map(|x| points[x as usize]), locator, scratch)
            } else {
                0
            }
        })
        .collect_into_vec(&mut labels);
    if locator.is_some() {
        report.n_centroid_tests = tets
            .iter()
            .filter(|v| v.iter().filter(|&&x| x < ns).count() >= 2)
            .count();
    }
    drop((locator, regions));
    // With recovery to follow, every tet is kept: recovery works on the convex hull and labels
    // by flood fill across the recovered surface (centroid tests only where it cannot: triangles
    // left unrecovered). Without it, the outside tets go here.
    if recover.is_none() {
        let inside: Vec<bool> = labels.iter().map(|&l| l != 0).collect();
        retain_tets(&mut tets, &mut neighbors, &mut labels, &inside);
    }
    let mut mesh = compact(TetMesh {
        points,
        tets,
        neighbors,
        labels,
    });
    stage(report, "keep inside", clock);

    if let Some(o) = recover {
        progress("recovering the boundary");
        let clock = Instant::now();
        let r = recover_built(&mut mesh, surface, o, true)?;
        report.n_centroid_tests = r.centroid_tests;
        report.recover = Some(r);
        // Recovery drops the outside tets; drop the points only they used.
        mesh = compact(mesh);
        stage(report, "recover", clock);
    }
    Ok(mesh)
}

/// The points of a tetrahedralization: `ns` surface points, then interior nodes with their
/// regions.
struct Nodes {
    points: Vec<[f64; 3]>,
    regions: Vec<u32>,
    ns: usize,
}

/// While triangles are missing: remove the interior nodes near them (balls doubling from a
/// quarter of each triangle's size) and tetrahedralize and recover again with `opts[0]`; when no
/// node is left to remove near them, or after [`MAX_RETRIES`], once more with `opts[1]` (the
/// wide rounds). The last mesh, or `None` when recovery left nothing missing.
fn recover_again(
    surface: &SurfaceMesh,
    nodes: &mut Nodes,
    opts: [RecoverOptions; 2],
    report: &mut MeshReport,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<TetMesh>, PipelineError> {
    let mut mesh = None;
    let mut radius = 0.25;
    let mut wide = false;
    let span = extent(&nodes.points);
    while let Some(left) = report
        .recover
        .as_ref()
        .filter(|r| !wide && r.missing_after > 0)
    {
        let mut removed = 0;
        while report.retries.len() < MAX_RETRIES {
            let balls = unrecovered_balls(left, radius);
            removed = clear_nodes(nodes, &balls);
            radius *= 2.0;
            if removed > 0 || balls.iter().all(|b| b.1 > span) {
                break;
            }
        }
        wide = removed == 0;
        progress("recovering again without the nodes near the missing triangles");
        let retry = RetryReport {
            nodes_removed: removed,
            nodes_added: 0,
            wide,
            missing_after: 0,
        };
        mesh = Some(retry_once(
            surface,
            nodes,
            &opts[wide as usize],
            retry,
            report,
        )?);
    }
    Ok(mesh)
}

/// Tetrahedralize `nodes` and recover with `opts` once more; `retry` (its `missing_after` filled
/// in) goes to the report, whose recovery figures become this try's.
fn retry_once(
    surface: &SurfaceMesh,
    nodes: &Nodes,
    opts: &RecoverOptions,
    mut retry: RetryReport,
    report: &mut MeshReport,
) -> Result<TetMesh, PipelineError> {
    let mut again = MeshReport::default();
    let mesh = tetrahedralize(
        surface,
        nodes.points.clone(),
        nodes.regions.clone(),
        nodes.ns,
        Some(opts),
        &mut again,
        &mut |_| {},
    )?;
    retry.missing_after = again.recover.as_ref().map_or(0, |r| r.missing_after);
    report.retries.push(retry);
    report.n_delaunay_tets = again.n_delaunay_tets;
    report.n_centroid_tests = again.n_centroid_tests;
    report.recover = again.recover;
    Ok(mesh)
}

/// Rounds of [`recover_inset`] at most.
const INSET_ROUNDS: usize = 2;

/// While triangles are missing (at most [`INSET_ROUNDS`] times): a node just behind each of
/// them and of the triangles sharing a corner with them ([`crate::inset`]), then tetrahedralize
/// and recover again with `opts`. The nodes added stay in `nodes`.
fn recover_inset(
    surface: &SurfaceMesh,
    nodes: &mut Nodes,
    opts: RecoverOptions,
    report: &mut MeshReport,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<TetMesh>, PipelineError> {
    let mut mesh = None;
    for _ in 0..INSET_ROUNDS {
        let Some(left) = report.recover.as_ref().filter(|r| r.missing_after > 0) else {
            break;
        };
        let tris: Vec<usize> = left.unrecovered.iter().map(|u| u.triangle).collect();
        let added = crate::inset::points_behind(
            surface,
            &crate::inset::with_corner_neighbours(surface, &tris),
        );
        if added.is_empty() {
            break;
        }
        progress("recovering again with points behind the missing triangles");
        for &(p, region) in &added {
            nodes.points.push(p);
            nodes.regions.push(region);
        }
        let retry = RetryReport {
            nodes_removed: 0,
            nodes_added: added.len(),
            wide: true,
            missing_after: 0,
        };
        mesh = Some(retry_once(surface, nodes, &opts, retry, report)?);
    }
    Ok(mesh)
}

/// Where recovery leaves triangles and every region is star-shaped from its point in `kernels`
/// ([`crate::star`]): the regions coned from those points with `nodes` put back, and what that
/// did. The cones are kept ([`StarReport::kept`], and the report made to describe them:
/// [`use_cones`]) when at least half the nodes go back into them; else the caller tries
/// recovery's other fallbacks first, and the cones only if those leave triangles too. A convex
/// part takes its nodes back (a cube of strip-cut faces at `--size 0.05`: 4,838 of 6,670, where
/// the other fallbacks took 41 s to remove them all); an organic surface that happens to be
/// star-shaped does not (16,204 marching-cubes triangles of anisotropic voxels, 3 left by the
/// first try: 1 of 5,733 put back among the cones' needles, and polish then spent 198 s on
/// them, where the other fallbacks recover the 3 in 0.2 s with every node).
fn recover_star(
    surface: &SurfaceMesh,
    kernels: &[(u32, [f64; 3])],
    nodes: &Nodes,
    report: &mut MeshReport,
    progress: &mut dyn FnMut(&str),
) -> Option<(TetMesh, StarReport)> {
    let r = report.recover.as_ref().filter(|r| r.missing_after > 0)?;
    let left = r.missing_after;
    let clock = Instant::now();
    progress("coning the star-shaped regions");
    let (mesh, mut star) =
        crate::star::coned(surface, kernels, &nodes.points, &nodes.regions, nodes.ns);
    star.triangles_left_by_recovery = left;
    star.kept = star.nodes_left_out <= star.nodes_inserted;
    let mesh = compact(mesh);
    if star.kept {
        use_cones(report, star.clone(), mesh.tets.len());
    } else {
        report.star = Some(star.clone());
    }
    stage(report, "star", clock);
    Some((mesh, star))
}

/// Recovery's report made to describe the cones: nothing missing, the cone points counted as
/// Steiner points; `star` says how many triangles recovery had left.
fn use_cones(report: &mut MeshReport, star: StarReport, n_tets: usize) {
    if let Some(r) = report.recover.as_mut() {
        r.missing_after = 0;
        r.unrecovered.clear();
        r.steiner_points = star.regions;
        r.tets_after = n_tets;
    }
    report.star = Some(star);
}

/// Balls around the triangles recovery left (centroid, `factor` times the farthest corner's
/// distance), as (centre, radius).
fn unrecovered_balls(r: &RecoverReport, factor: f64) -> Vec<([f64; 3], f64)> {
    r.unrecovered
        .iter()
        .map(|u| {
            let c = [0, 1, 2].map(|k| u.corners.iter().map(|p| p[k]).sum::<f64>() / 3.0);
            let d = u
                .corners
                .iter()
                .map(|p| crate::geom::vec3::norm(crate::geom::vec3::sub(*p, c)))
                .fold(0.0, f64::max);
            (c, factor * d)
        })
        .collect()
}

/// Remove the interior nodes inside any of the balls; returns how many.
fn clear_nodes(nodes: &mut Nodes, balls: &[([f64; 3], f64)]) -> usize {
    let Nodes {
        points,
        regions,
        ns,
    } = nodes;
    let ns = *ns;
    let before = points.len();
    // The balls' bounding box first: most nodes are far from every ball.
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (c, r) in balls {
        for k in 0..3 {
            lo[k] = lo[k].min(c[k] - r);
            hi[k] = hi[k].max(c[k] + r);
        }
    }
    let mut k = ns;
    for i in ns..points.len() {
        let p = points[i];
        let near = (0..3).all(|a| p[a] >= lo[a] && p[a] <= hi[a])
            && balls.iter().any(|(c, r)| {
                let d = crate::geom::vec3::sub(p, *c);
                crate::geom::vec3::dot(d, d) < r * r
            });
        if !near {
            points[k] = p;
            regions[k - ns] = regions[i - ns];
            k += 1;
        }
    }
    points.truncate(k);
    regions.truncate(k - ns);
    before - k
}

/// The largest extent of the points' bounding box.
fn extent(points: &[[f64; 3]]) -> f64 {
    let (lo, hi) = crate::geom::vec3::points_bbox(points.iter());
    (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max)
}

/// `mesh` without the points no tet uses (the others keep their order, surface points
/// first). In place: after recovery this runs on top of that stage's peak.
fn compact(mut mesh: TetMesh) -> TetMesh {
    crate::mesh::drop_unused_points(&mut mesh.points, mesh.tets.as_flattened_mut(), 0);
    // Recovery truncates the arrays in place: give the slack back for the later stages.
    mesh.points.shrink_to_fit();
    mesh.tets.shrink_to_fit();
    mesh.neighbors.shrink_to_fit();
    mesh.labels.shrink_to_fit();
    mesh
}

/// Input triangles that are not a face of any tet (matched by point coordinates).
pub fn missing_triangles(mesh: &TetMesh, surface: &SurfaceMesh) -> usize {
    let mut index: FxHashMap<[u64; 3], u32> = Default::default();
    for (i, p) in surface.points.iter().enumerate() {
        index.insert(coord_key(p), i as u32);
    }
    // Mesh point -> surface point (u32::MAX for the others); only faces with three surface
    // points can be surface triangles, so only those are hashed.
    let on_surface: Vec<u32> = mesh
        .points
        .iter()
        .map(|p| index.get(&coord_key(p)).copied().unwrap_or(u32::MAX))
        .collect();
    let mut faces: FxHashSet<[u32; 3]> = Default::default();
    for t in 0..mesh.tets.len() {
        for f in 0..4 {
            let mut k = mesh.face(t, f).map(|v| on_surface[v as usize]);
            if k.contains(&u32::MAX) {
                continue;
            }
            k.sort_unstable();
            faces.insert(k);
        }
    }
    surface
        .triangles
        .iter()
        .filter(|tri| {
            let mut k = **tri;
            k.sort_unstable();
            !faces.contains(&k)
        })
        .count()
}

/// How far the enclosing corners stand off the points' bounding box, in extents. A large face
/// is a Delaunay face only if some sphere through its corners is empty: with interior nodes at
/// height h over a face of circumradius R, that sphere bulges at most h inward, so its radius is
/// about R²/2h and its centre that far outside. Corners a quarter extent out sat in those
/// spheres, and a unit cube at `--size 0.1` lost all 12 triangles; 64 extents keep them out down
/// to sizes near a hundredth of the extent, and beyond that only outside tets are affected.
const ENCLOSE_MARGIN: f64 = 64.0;

/// Append the corners of a box [`ENCLOSE_MARGIN`] extents larger than the points' bounding box
/// on every side, labelled 0 (outside).
fn enclose(points: &mut Vec<[f64; 3]>, regions: &mut Vec<u32>) {
    if points.is_empty() {
        return;
    }
    let (lo, hi) = crate::geom::vec3::points_bbox(points.iter());
    let margin = ENCLOSE_MARGIN * extent(points).max(1e-300);
    for i in 0..8 {
        let pick = |k: usize| {
            if i >> k & 1 == 0 {
                lo[k] - margin
            } else {
                hi[k] + margin
            }
        };
        points.push([pick(0), pick(1), pick(2)]);
        regions.push(0);
    }
}
