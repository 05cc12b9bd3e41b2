//! Boundary recovery (Algorithm 3.2 of the seed, section 3.3.2): make every triangle of a
//! surface a face of a tet mesh by carving cavities and refilling them with the LAST RESORT
//! search, without new points on the surface.
//!
//! # Algorithm
//! 1. **Domain.** The cavities are refilled inside the mesh, so the mesh must cover the space
//!    the surface needs. A mesh whose boundary is convex (a Delaunay mesh of the convex hull) is
//!    used as it is. A mesh with outside tets removed (centroid test) is first completed: if its
//!    tets are tets of the Delaunay tetrahedralization of its points (as when it was made by a
//!    Delaunay mesher), the missing Delaunay tets are put back as outside (label 0). Otherwise
//!    recovery fails with [`RecoverError::NotCovering`].
//! 2. **Missing triangles**: surface triangles (corners matched to mesh points by exact
//!    coordinates) that are no face of any tet.
//! 3. For each missing triangle `M` (a queue): the **cavity** is first the tets `M` crosses (a
//!    face meets `M` improperly, exact [`tri_tri`]; found by walking from its corners), the
//!    smallest cavity that can hold it — a few tets, so the search is cheap; if that fails, those
//!    tets and their face neighbours; then the seed's cavity: every tet with a corner of `M`
//!    (on brain_20k the first two recover all but 2 of 2,153 triangles, at a tenth of the cost
//!    of the seed's cavities). Its shell (faces shared with kept tets and mesh boundary faces) is kept exactly. Every
//!    surface triangle with its three corners in the cavity that lies inside it becomes a
//!    constrained face (`M` itself and any other missing triangles "the hole offers", and the
//!    present ones already inside): inside means no improper contact with a shell face (exact
//!    [`tri_tri`]) and a point of its interior inside a cavity tet (exact, by a symbolic point
//!    infinitesimally close to a corner, see `Recovery::inside_cavity`). A surface triangle in
//!    the plane of mesh boundary faces of the cavity (on the convex hull, split differently)
//!    replaces them, one-sided. The shell and both sides of each constrained face split the
//!    cavity into closed cells (exact angular order of the faces around each edge), and
//!    [`Searcher`] fills each cell with cavity points only (points left isolated by the carving
//!    are offered to every cell).
//! 4. A seed's cavity that fails is **grown** by the next ring (every tet across one of its faces) and
//!    tried again, up to [`RecoverOptions::max_grow`] times or [`RecoverOptions::max_cavity_tets`]
//!    tets; a triangle whose cavity still fails moves to the back of the queue. The queue stops
//!    when every remaining triangle failed since the last success.
//!
//!    **Batches.** The queue is taken 64 triangles at a time (no two sharing a corner:
//!    they would carve the same tets). Their crossed-tets fills (the first two cavities of step
//!    3, nearly every call) are searched in parallel on the unchanged mesh, then applied in
//!    queue order; a fill that touches a tet carved earlier in the batch (its tets or the tets
//!    across its shell) waits for the next batch, and a triangle without such a fill takes the
//!    serial path of steps 3–4 on the mesh as it is then. The batch does not depend on the
//!    number of threads, so neither does the result.
//! 5. **Labels** by flood fill: tets connected without crossing a surface triangle form a
//!    region; the side labels of the surface triangles around it name it (`sides = [back,
//!    front]`), so interfaces get the right label on each side. Tets of region 0 (the outside)
//!    are removed.
//!
//! # Steiner fallback and honest failure
//! Some shells have no tetrahedralization without new points (the Schönhardt polyhedron, a
//! cube whose face diagonals twist). Recovery stays total on valid input:
//! - surface points the mesh lacks (or holds in no tet) are put back before anything else, by
//!   splitting the tets that hold them (`kernel::split_insert`) or, outside
//!   the mesh, by growing its convex hull to them;
//! - the no-new-point queue is bounded by work: [`RecoverOptions::max_tries`] attempts a
//!   triangle, [`RecoverOptions::max_grow`] rings, [`RecoverOptions::max_cavity_tets`] tets
//!   and the search's node budget, so no triangle costs seconds;
//! - with [`RecoverOptions::allow_interior_steiner`] (the default) the triangles left are tried
//!   again, smallest cavities first; a cell with no fill of its own points gets one point
//!   strictly inside its kernel (exact check, the `kernel` module): the fill through it the search
//!   finds, or the cone from it. The point is strictly inside a cell, so never on the surface
//!   (checked exactly against every surface triangle too). This alternates with the
//!   no-new-point queue while either makes progress;
//! - the bounds escalate: the first rounds carve at most [`RecoverOptions::first_cavity_tets`]
//!   tets, a round without progress lifts that to [`RecoverOptions::max_cavity_tets`], and a
//!   further one to the wide bounds. A search over a cavity of a hundred tets costs
//!   milliseconds where one interior point in a small cavity costs microseconds, so a triangle
//!   that a small cavity recovers with one point is not searched for in a large one (at the
//!   price of that point: a few on the brain surfaces, seven on a cube with fanned faces). The
//!   pipeline escalates; `recover` alone by default does not (the bound starts at the full
//!   size);
//! - when the bounds are spent, one last round finds the kernel points the ascent missed by a
//!   linear program (the kernel's Chebyshev centre, [`RecoverOptions::exact_kernel`]): a cell
//!   reaching the enclosing box's corners can have a kernel a ten-thousandth of its size deep;
//! - a Steiner point that ends up outside the surface is dropped with the outside tets.
//!
//! What still fails (a cell that is star-shaped for no point, within the bounds) is reported:
//! each unrecovered triangle with its corners, smallest angle and the reason.
//!
//! # Limits
//! The surface must be valid (closed, oriented, not self-intersecting: [`crate::mesh::validate`]);
//! a mesh that does not cover the surface's domain and is not a sub-complex of the Delaunay
//! tetrahedralization of its points is refused. Cost: on the brain_20k pipeline mesh, 93% of the
//! missing triangles are recovered in their crossed tets (median 2 tets, 5 search nodes, 0.02 ms);
//! a seed's cavity (about 60 tets) takes about 60 search nodes and 1–3 ms in release; a cavity
//! whose search exhausts its node budget costs up to a few hundred ms.

use super::cells::Cells;
use super::kernel::{cone, kernel_point, split_insert};
use super::search::{SearchError, SearchOptions, Searcher, bbox, boxes_apart};
use crate::delaunay::Delaunay;
// The filtered orient3d: the exact predicate's answer, faster.
use crate::geom::filter::orient3d;
use crate::geom::intersect::{TriTri, tri_tri};
use crate::geom::predicates::{Sign, in_exact_range};
use crate::mesh::coord_key;
use crate::mesh::inside::{RegionLocator, Transitions, centroid_region};
use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::{NO_NEIGHBOR, TET_FACES, TetMesh, sorted3};
use crate::quality::tri::min_angle_3d_deg;
use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};
use serde::Serialize;
use std::cell::Cell;
use std::collections::VecDeque;
use std::sync::Mutex;
use std::time::Instant;
use thiserror::Error;

type P3 = [f64; 3];

/// Options of [`recover`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecoverOptions {
    /// Options of each cell's search (quality threshold ηe, node budget).
    pub search: SearchOptions,
    /// How many times a failing cavity is grown by one ring of tets before the triangle is put
    /// back in the queue. Once by default: each ring costs more than all before it (the search
    /// scans the whole front at every node), and the second ring mostly proved cavities without
    /// a fill that one interior point then fixes at once (the trimesh annulus: 0.66 s → 0.22 s,
    /// the same mesh; gmsh's t13: 1.73 s → 1.12 s, fewer tets under 10°). The wide rounds grow
    /// further where no point helps.
    pub max_grow: u32,
    /// Cavities larger than this many tets are not searched.
    pub max_cavity_tets: usize,
    /// With [`Self::allow_interior_steiner`], the first rounds carve at most this many tets
    /// (the no-new-point queue, then the Steiner fallback, alternating), and only a round without
    /// progress lifts the bound to [`Self::max_cavity_tets`]: a cavity of a hundred tets or more
    /// costs milliseconds a search, where one interior point in a small cavity costs
    /// microseconds (the planar faces of CAD shapes, whose coplanar points the Delaunay splits
    /// another way: a cube with fanned faces 140 → 20 ms, the trimesh annulus 145 → 40 ms),
    /// at the price of a few points a no-new-point search would have spared. At or above
    /// `max_cavity_tets` (the default) no escalation; the pipeline sets
    /// [`PIPELINE_FIRST_CAVITY_TETS`].
    pub first_cavity_tets: usize,
    /// As a last resort, add one point strictly inside a failed cavity and search again.
    pub allow_interior_steiner: bool,
    /// A triangle whose cavities failed this many times (each time the whole growth) is not
    /// queued again: it goes to the Steiner fallback, or is reported. Bounds the work where
    /// many triangles fail, which otherwise retries each after every success.
    pub max_tries: u32,
    /// Remove the tets of region 0 (outside the surface) at the end.
    pub remove_outside: bool,
    /// Each cell is first searched with this quality threshold ηe (fewer candidates, better
    /// tets), then with [`SearchOptions::min_quality`] if that fails; at or below it, one search.
    pub first_quality: f64,
    /// After a Steiner round without progress, carve wider cavities and search longer (see
    /// `WIDE_GROW`). The pipeline's first try goes without: it clears the nodes around what
    /// is left and tries again instead, which costs milliseconds where wide cavities of a
    /// triangle far larger than the spacing cost seconds.
    pub widen: bool,
    /// Rounds with the wide bounds at most: each may cost seconds in cavities of hundreds of
    /// tets. The pipeline, whose fallbacks follow, takes one (a lattice of crossing bars: a
    /// second wide round spent 6.6 s on the two triangles the first left, which points just
    /// behind them then recovered in 0.9 s); `recover` alone takes as many as make progress.
    pub max_wide_rounds: usize,
    /// The kernel points of the Steiner fallback also by linear program where the ascent finds
    /// none. Off by default: recovery turns it on for a last round when the bounds are spent
    /// (from the first rounds, the program's deep points in thin cells make poorer cones than
    /// the larger cavities the ascent's failures lead to: gmsh's t13 491 -> 511 tets under
    /// 10°). The pipeline turns it on from the start: the bar lattice's cells it finds points
    /// for would otherwise go to the wide round (11.6 s -> 1.7 s, 825 -> 717 under 10°).
    pub exact_kernel: bool,
}

/// The crossed-tets cavity is tried only up to this many tets (larger ones go straight to the
/// cavity of the corners, whose search is better conditioned).
const CROSSED_MAX_TETS: usize = 64;

/// The bounds of the rounds after a Steiner round without progress (a surface triangle far
/// larger than the interior spacing needs a wide cavity): rings, cavity tets, search nodes.
const WIDE_GROW: u32 = 6;
const WIDE_MAX_TETS: usize = 2000;
const WIDE_NODES: u64 = 2000;

/// The pipeline's [`RecoverOptions::first_cavity_tets`] (measured against 60 and no
/// escalation over the shape corpus and the brain surfaces: no run slower, the CAD shapes two to
/// seven times faster in recovery).
pub const PIPELINE_FIRST_CAVITY_TETS: usize = 40;

/// Rounds of the Steiner fallback, each followed by the no-new-point queue.
const STEINER_ROUNDS: usize = 10;

/// Node budget of the first, higher-threshold try.
const FIRST_TRY_NODES: u64 = 500;

impl Default for RecoverOptions {
    fn default() -> Self {
        RecoverOptions {
            search: SearchOptions {
                max_nodes: 400,
                ..SearchOptions::default()
            },
            max_grow: 1,
            max_cavity_tets: 300,
            first_cavity_tets: 300,
            allow_interior_steiner: true,
            max_tries: 1,
            remove_outside: true,
            first_quality: 0.05,
            widen: true,
            max_wide_rounds: STEINER_ROUNDS,
            exact_kernel: false,
        }
    }
}

/// Why [`recover`] could not run.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum RecoverError {
    /// The mesh is malformed (indices, labels, orientation, faces in more than two tets).
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// The surface's arrays are inconsistent (indices out of range, one side pair per triangle).
    #[error("invalid surface: {0}")]
    InvalidSurface(String),
    /// The mesh's boundary is not convex and its tets are not all tets of the Delaunay
    /// tetrahedralization of its points, so the space outside it cannot be restored.
    #[error(
        "the mesh does not cover the convex hull of its points and is not part of their Delaunay \
         tetrahedralization: {0}"
    )]
    NotCovering(String),
}

/// How the mesh was made to cover its domain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Domain {
    /// The mesh boundary was convex: used as given.
    Convex,
    /// Outside tets had been removed; the Delaunay tets of the points were put back first.
    DelaunayCompleted {
        /// Tets put back.
        tets_added: usize,
    },
}

/// A surface triangle that could not be recovered.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Unrecovered {
    /// Index in the surface.
    pub triangle: usize,
    /// Its corners.
    pub corners: [P3; 3],
    /// Its smallest angle in degrees (a very small one is the usual root cause).
    pub min_angle_deg: f64,
    /// Why the last attempt failed.
    pub reason: String,
}

/// What [`recover`] did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecoverReport {
    /// How the domain was covered.
    pub domain: Domain,
    /// Tets of the input mesh.
    pub tets_before: usize,
    /// Tets of the output mesh.
    pub tets_after: usize,
    /// Surface triangles missing from the input mesh.
    pub missing_before: usize,
    /// Surface triangles missing from the output mesh.
    pub missing_after: usize,
    /// Cavity fills attempted (LAST RESORT calls, growth attempts included).
    pub calls: usize,
    /// Of those, the ones that succeeded.
    pub calls_succeeded: usize,
    /// Cavities grown by a ring after a failure.
    pub cavities_grown: usize,
    /// First tries on the tets the missing triangle crosses (counted in `calls` too).
    pub crossed_tried: usize,
    /// Of those, the ones that recovered their triangle (in the crossed tets or in those and
    /// their face neighbours).
    pub crossed_ok: usize,
    /// Median and largest time of one call, in milliseconds.
    pub call_ms_median: f64,
    /// Largest time of one call, in milliseconds.
    pub call_ms_max: f64,
    /// Median search nodes visited per call.
    pub nodes_median: u64,
    /// Largest search nodes visited by one call.
    pub nodes_max: u64,
    /// Total search nodes visited.
    pub nodes_total: u64,
    /// Median number of tets carved per call.
    pub cavity_tets_median: usize,
    /// Steiner points added strictly inside the domain (never on the surface) where no fill of a
    /// cavity with the existing points was found (only with `allow_interior_steiner`).
    pub steiner_points: usize,
    /// Surface points the input mesh lacked (or held in no tet), put back by splitting the
    /// tets that hold them before any triangle is recovered.
    pub surface_points_reinserted: usize,
    /// Tets of region 0 removed at the end.
    pub outside_tets_removed: usize,
    /// Regions whose surrounding surface triangles disagree about their label (left as they
    /// were; only when some triangle is unrecovered).
    pub label_conflicts: usize,
    /// Tets of such regions (or of regions no surface triangle bounds) labelled by a centroid
    /// test, when the pipeline left their labels to recovery.
    pub centroid_tests: usize,
    /// Total wall time in milliseconds.
    pub total_ms: f64,
    /// The triangles still missing.
    pub unrecovered: Vec<Unrecovered>,
}

impl RecoverReport {
    /// True when every surface triangle is a face of the output mesh.
    pub fn is_complete(&self) -> bool {
        self.missing_after == 0
    }
}

/// Recover every triangle of `surface` in `mesh` (see the module docs). The mesh is modified in
/// place; its points are kept (with `allow_interior_steiner`, points may be appended, never on
/// the surface). Returns the report, or an error when the inputs cannot be used.
pub fn recover(
    mesh: &mut TetMesh,
    surface: &SurfaceMesh,
    opts: &RecoverOptions,
) -> Result<RecoverReport, RecoverError> {
    let t0 = Instant::now();
    validate_inputs(mesh, surface, true)?;
    recover_checked(mesh, surface, opts, false, t0)
}

/// [`recover`] on a mesh valid by construction (the pipeline's: positive tets from the exact
/// Delaunay, its adjacency kept): the tet orientations and the adjacency are not checked again
/// (a quarter of recovery's time on brain_20k), except in debug builds. With `deferred`, the
/// labels of the tets with two or more surface corners were not computed (the flood fill
/// labels every tet once the surface is recovered): the tets of a region it cannot label get a
/// centroid test instead of keeping their labels.
pub(crate) fn recover_built(
    mesh: &mut TetMesh,
    surface: &SurfaceMesh,
    opts: &RecoverOptions,
    deferred: bool,
) -> Result<RecoverReport, RecoverError> {
    let t0 = Instant::now();
    validate_inputs(mesh, surface, cfg!(debug_assertions))?;
    recover_checked(mesh, surface, opts, deferred, t0)
}

fn recover_checked(
    mesh: &mut TetMesh,
    surface: &SurfaceMesh,
    opts: &RecoverOptions,
    deferred: bool,
    t0: Instant,
) -> Result<RecoverReport, RecoverError> {
    let tets_before = mesh.tets.len();
    // Surface corners → mesh points.
    // (The index is dropped before the recovery's arrays are built: it would set the peak.)
    let tri_map = map_triangles(surface, &point_index(&mesh.points));
    let mut r = Recovery::new(mesh, surface, tri_map, *opts);
    r.scan_present();
    let missing_before = r.count_missing();
    let domain = r.cover()?;
    // Surface points the mesh lacks (or holds in no tet: a mesh whose outside tets were
    // removed drops them) are the surface's own points, not new ones: put them back first.
    let (mut r, reinserted) = if r.corners_live() {
        (r, 0)
    } else {
        let mut at = point_index(&r.mesh.points);
        let absent = r.absent_surface_points(&at);
        drop(r);
        insert_points(mesh, &absent, &mut at)?;
        let tri_map = map_triangles(surface, &at);
        drop(at);
        (Recovery::new(mesh, surface, tri_map, *opts), absent.len())
    };
    // Points from here on are Steiner points.
    let n_base = r.mesh.points.len();
    if domain != Domain::Convex || reinserted > 0 {
        // Tets put back may hold surface triangles.
        r.scan_present();
    }
    // Small cavities first where a point may be added (`first_cavity_tets`).
    let mut small = opts.allow_interior_steiner && opts.first_cavity_tets < opts.max_cavity_tets;
    if small {
        r.opts.max_cavity_tets = opts.first_cavity_tets;
    }
    r.run();
    if opts.allow_interior_steiner {
        // A Steiner fill changes the cavities of the triangles around it: alternate the
        // fallback with the no-new-point queue while either makes progress.
        let mut wide_rounds = 0;
        for _ in 0..STEINER_ROUNDS {
            let before = r.count_missing();
            r.run_steiner();
            r.tries.clear();
            r.run();
            let after = r.count_missing();
            wide_rounds += r.wide as usize;
            if after == 0 {
                break;
            }
            // The bounds spent: a last round whose kernel points the linear program finds where
            // the ascent missed them (a cell whose kernel is a thin sliver of a long cell).
            let spent = wide_rounds >= opts.max_wide_rounds
                || (after >= before && !small && (r.wide || !opts.widen));
            if spent {
                if r.opts.exact_kernel {
                    break;
                }
                r.opts.exact_kernel = true;
                continue;
            }
            if after < before {
                continue;
            }
            // Stuck: first the configured cavities, then wide ones searched longer, with and
            // without new points (a surface triangle far larger than the interior spacing
            // needs a wide cavity).
            if small {
                small = false;
                r.opts.max_cavity_tets = opts.max_cavity_tets;
            } else if r.wide || !opts.widen {
                break;
            } else {
                r.widen();
            }
        }
    }
    // What recovery itself left: the list below names these first. Through them the region
    // labels can leak, and removing the outside then takes the surface's other triangles too.
    let left: FxHashSet<u32> = r.missing_mapped().collect();
    r.compact();
    // Also sets the final `is_present`.
    let (removed, conflicts, centroid_tests) = r.relabel(deferred);
    // Steiner points in cells outside the surface went with the outside tets.
    r.steiner_points = r.steiner_points.saturating_sub(r.drop_orphans(n_base));

    if cfg!(debug_assertions) {
        r.assert_present();
    }
    let mut unrecovered = Vec::new();
    for s in 0..r.tri_map.len() {
        if !r.is_present[s] {
            let corners = surface.corners(s);
            unrecovered.push(Unrecovered {
                triangle: s,
                corners,
                min_angle_deg: min_angle_3d_deg(&corners),
                reason: r.reason.get(&(s as u32)).cloned().unwrap_or_else(|| {
                    if r.tri_map[s].is_some() && !left.contains(&(s as u32)) {
                        "removed with the outside tets (the region labels leaked through the \
                         triangles recovery left)"
                            .to_string()
                    } else {
                        "a corner is not a mesh point".to_string()
                    }
                }),
            });
        }
    }
    // Recovery's own failures first: the others follow from them.
    unrecovered.sort_by_key(|u| (!left.contains(&(u.triangle as u32)), u.triangle));
    let mut ms: Vec<f64> = r.call_ms.clone();
    ms.sort_by(f64::total_cmp);
    let mut nodes = r.call_nodes.clone();
    nodes.sort_unstable();
    let mut sizes = r.call_sizes.clone();
    sizes.sort_unstable();
    let report = RecoverReport {
        domain,
        tets_before,
        tets_after: r.mesh.tets.len(),
        missing_before,
        missing_after: unrecovered.len(),
        calls: r.call_ms.len(),
        calls_succeeded: r.calls_ok,
        cavities_grown: r.grown,
        crossed_tried: r.crossed_tried,
        crossed_ok: r.crossed_ok,
        call_ms_median: ms.get(ms.len() / 2).copied().unwrap_or(0.0),
        call_ms_max: ms.last().copied().unwrap_or(0.0),
        nodes_median: nodes.get(nodes.len() / 2).copied().unwrap_or(0),
        nodes_max: nodes.last().copied().unwrap_or(0),
        nodes_total: nodes.iter().sum(),
        cavity_tets_median: sizes.get(sizes.len() / 2).copied().unwrap_or(0),
        steiner_points: r.steiner_points,
        surface_points_reinserted: reinserted,
        outside_tets_removed: removed,
        label_conflicts: conflicts,
        centroid_tests,
        total_ms: t0.elapsed().as_secs_f64() * 1e3,
        unrecovered,
    };
    Ok(report)
}

/// A cell as [`Recovery::no_fill`] keys it, in mesh point numbers (`points`: the cavity's):
/// its isolated points sorted, a separator, then its faces rotated to their smallest corner
/// (orientation kept), sorted. The same cell from any cavity has the same key.
fn cell_key(points: &[u32], faces: &[[u32; 3]], inner: &[u32]) -> Vec<u32> {
    let mut key: Vec<u32> = inner.iter().map(|&x| points[x as usize]).collect();
    key.sort_unstable();
    key.push(u32::MAX);
    let mut rot: Vec<[u32; 3]> = faces
        .iter()
        .map(|f| {
            let g = f.map(|x| points[x as usize]);
            let k = (0..3).min_by_key(|&k| g[k]).unwrap_or(0);
            [g[k], g[(k + 1) % 3], g[(k + 2) % 3]]
        })
        .collect();
    rot.sort_unstable();
    key.extend(rot.iter().flatten());
    key
}

/// Mesh point numbers by exact coordinates (the first of equal points).
fn point_index(points: &[P3]) -> FxHashMap<[u64; 3], u32> {
    let mut at: FxHashMap<[u64; 3], u32> = FxHashMap::default();
    at.reserve(points.len());
    for (i, p) in points.iter().enumerate() {
        at.entry(coord_key(p)).or_insert(i as u32);
    }
    at
}

/// Surface triangles in mesh point numbers, by exact coordinates (`None`: a corner is no mesh
/// point).
fn map_triangles(surface: &SurfaceMesh, at: &FxHashMap<[u64; 3], u32>) -> Vec<Option<[u32; 3]>> {
    surface
        .triangles
        .iter()
        .map(|t| {
            let v = t.map(|i| at.get(&coord_key(&surface.points[i as usize])).copied());
            match v {
                [Some(a), Some(b), Some(c)] => Some([a, b, c]),
                _ => None,
            }
        })
        .collect()
}

/// Put each point of `pts` into `mesh` (appended unless a mesh point has its coordinates) by
/// splitting every tet whose closure holds it (exact, [`split_insert`]), or outside the mesh
/// by growing its hull ([`extend_hull`]); `at` ([`point_index`]) gains the appended points
/// and the adjacency is rebuilt once at the end. A point outside every tet that no boundary
/// face sees is an error (the mesh does not cover the surface).
fn insert_points(
    mesh: &mut TetMesh,
    pts: &[P3],
    at: &mut FxHashMap<[u64; 3], u32>,
) -> Result<(), RecoverError> {
    let mut holding = Vec::new();
    let mut local = Vec::new();
    for &p in pts {
        let id = *at.entry(coord_key(&p)).or_insert_with(|| {
            mesh.points.push(p);
            (mesh.points.len() - 1) as u32
        });
        holding.clear();
        for (t, v) in mesh.tets.iter().enumerate() {
            let c = v.map(|x| mesh.points[x as usize]);
            if v.contains(&id)
                || (0..3).any(|k| c.iter().all(|q| q[k] < p[k]) || c.iter().all(|q| q[k] > p[k]))
            {
                continue;
            }
            if TET_FACES
                .iter()
                .all(|f| orient3d(c[f[0]], c[f[1]], c[f[2]], p) != Sign::Positive)
            {
                holding.push(t);
            }
        }
        if holding.is_empty() {
            // Outside the (convex) mesh: the cone from it over the boundary faces it sees
            // strictly is the convex hull grown by it (outside tets, label 0).
            if !extend_hull(mesh, id) {
                return Err(RecoverError::NotCovering(format!(
                    "surface point {p:?} lies outside the mesh"
                )));
            }
            continue;
        }
        local.clear();
        local.extend(holding.iter().map(|&t| mesh.tets[t]));
        if !split_insert(&mesh.points, &mut local, id) {
            return Err(RecoverError::NotCovering(format!(
                "surface point {p:?} lies outside the mesh"
            )));
        }
        let label = mesh.labels[holding[0]];
        for (k, t) in local.drain(..).enumerate() {
            if let Some(&slot) = holding.get(k) {
                mesh.tets[slot] = t;
            } else {
                mesh.tets.push(t);
                mesh.labels.push(label);
            }
        }
    }
    mesh.rebuild_neighbors();
    Ok(())
}

/// Add the tets from point `x` to every mesh boundary face that sees it strictly from outside
/// (exact); the adjacency is rebuilt. False when no face sees it.
fn extend_hull(mesh: &mut TetMesh, x: u32) -> bool {
    mesh.rebuild_neighbors();
    let p = mesh.points[x as usize];
    let mut added = Vec::new();
    for t in 0..mesh.tets.len() {
        for f in 0..4 {
            if mesh.neighbors[t][f] == NO_NEIGHBOR {
                let g = mesh.face(t, f);
                let c = g.map(|v| mesh.points[v as usize]);
                if orient3d(c[0], c[1], c[2], p) == Sign::Positive {
                    added.push([g[0], g[1], g[2], x]);
                }
            }
        }
    }
    let any = !added.is_empty();
    for t in added {
        mesh.tets.push(t);
        mesh.labels.push(0);
    }
    any
}

/// Check the inputs; `full`: also every tet's orientation (exact) and the adjacency (rebuilt).
fn validate_inputs(
    mesh: &mut TetMesh,
    surface: &SurfaceMesh,
    full: bool,
) -> Result<(), RecoverError> {
    let np = mesh.points.len();
    if mesh.labels.len() != mesh.tets.len() {
        return Err(RecoverError::InvalidMesh(format!(
            "{} labels for {} tets",
            mesh.labels.len(),
            mesh.tets.len()
        )));
    }
    if mesh.tets.len() >= 1 << 30 || np >= 1 << 31 {
        return Err(RecoverError::InvalidMesh("too large".into()));
    }
    for (i, p) in mesh.points.iter().enumerate() {
        if !p.iter().all(|&c| in_exact_range(c)) {
            return Err(RecoverError::InvalidMesh(format!(
                "point {i} is not finite or outside the exact range"
            )));
        }
    }
    for (t, v) in mesh.tets.iter().enumerate() {
        if v.iter().any(|&i| i as usize >= np) {
            return Err(RecoverError::InvalidMesh(format!(
                "tet {t} has a vertex out of range"
            )));
        }
        let c = v.map(|i| mesh.points[i as usize]);
        if full && orient3d(c[0], c[1], c[2], c[3]) != Sign::Positive {
            return Err(RecoverError::InvalidMesh(format!(
                "tet {t} is not positively oriented"
            )));
        }
    }
    if full && mesh.rebuild_neighbors() > 0 {
        return Err(RecoverError::InvalidMesh(
            "a face is shared by more than two tets".into(),
        ));
    }
    if surface.sides.len() != surface.triangles.len() {
        return Err(RecoverError::InvalidSurface(format!(
            "{} side pairs for {} triangles",
            surface.sides.len(),
            surface.triangles.len()
        )));
    }
    let ns = surface.points.len();
    if surface
        .triangles
        .iter()
        .flatten()
        .any(|&i| i as usize >= ns)
    {
        return Err(RecoverError::InvalidSurface(
            "a triangle corner is out of range".into(),
        ));
    }
    Ok(())
}

/// The recovery state: the mesh with dead slots, incidences and statistics.
struct Recovery<'a> {
    mesh: &'a mut TetMesh,
    surface: &'a SurfaceMesh,
    opts: RecoverOptions,
    /// Surface triangles in mesh point numbers (`None`: a corner is no mesh point).
    tri_map: Vec<Option<[u32; 3]>>,
    /// Mapped surface triangles by sorted corners (the last of equal ones) ...
    face_tri: FaceIndex,
    /// ... and the previous triangle with the same corners (`NO_NEIGHBOR`: none).
    same_face: Vec<u32>,
    /// Which surface triangles are faces of live tets: set by [`Self::scan_present`], then kept
    /// by [`Self::insert`] (carving never removes a present triangle: it is kept as a shell
    /// face or refilled as a constrained one).
    is_present: Vec<bool>,
    alive: Vec<bool>,
    free: Vec<u32>,
    /// A live tet at each point (`NO_NEIGHBOR` for none): stars are walked from it across the
    /// adjacency, instead of keeping a list per point (a third of recovery's memory).
    vtet: Vec<u32>,
    /// Surface triangles at each mesh point `x`: `surf_list[surf_start[x]..surf_start[x + 1]]`
    /// (flat: most points are interior and have none).
    surf_start: Vec<u32>,
    surf_list: Vec<u32>,
    /// The serial path's scratch.
    work: Work,
    /// Tets carved in the current batch (equal to `batch`): later fills of the batch that touch
    /// them were computed on a stale mesh.
    claim: Vec<u32>,
    batch: u32,
    /// Points at corners of the current batch's triangles (equal to `batch`).
    picked: Vec<u32>,
    reason: FxHashMap<u32, String>,
    call_ms: Vec<f64>,
    call_nodes: Vec<u64>,
    call_sizes: Vec<usize>,
    calls_ok: usize,
    crossed_tried: usize,
    crossed_ok: usize,
    grown: usize,
    steiner_points: usize,
    /// Failed serial attempts per triangle.
    tries: FxHashMap<u32, u8>,
    /// The Steiner fallback carves wider cavities (after a round without progress).
    wide: bool,
    /// Cells proven to have no fill of their own points (see [`cell_key`]): searched again they
    /// fail again, so they are not (a twisted cube's inside, in every cavity that holds it).
    no_fill: FxHashSet<Vec<u32>>,
}

/// Stamped marks and buffers of the read-only stages (walks, carving, searches): one for the
/// serial path and one per thread for the batches. Results never depend on what a scratch held
/// before (fresh stamps).
#[derive(Default)]
struct Work {
    /// Per-tet marks hold the low 16 bits of a stamp (2 bytes a tet and thread, not 4): they
    /// are cleared whenever those bits wrap, see [`Work::next_stamp`].
    tet_mark: Vec<u16>,
    /// Stamps of the star walks (cleared when they wrap), and the buffer of [`View::with_star`].
    star_mark: Vec<Cell<u16>>,
    star_stamp: Cell<u16>,
    star_buf: Cell<Vec<u32>>,
    /// Cached sides of points of the plane of the triangle whose crossed tets are walked.
    side_mark: Vec<u32>,
    side: Vec<Sign>,
    /// The stack of that walk.
    walk_buf: Vec<u32>,
    pt_mark: Vec<u32>,
    pt_local: Vec<u32>,
    stamp: u32,
    /// Buffers of [`View::carve`] and [`View::fill_cells`].
    keys: Vec<[u32; 3]>,
    cell: Vec<u32>,
    faces: Vec<[u32; 3]>,
    on_face: Vec<bool>,
    inner: Vec<u32>,
    searcher: Searcher,
    /// Keys of the cells this scratch's calls proved to have no fill, for
    /// [`Recovery::no_fill`] (merged after each serial call and each batch).
    proven: Vec<Vec<u32>>,
    cells: Cells,
}

/// Surface triangles by sorted corners, sorted: half the memory of a hash map, and looked up
/// only at faces with three surface corners.
struct FaceIndex(Vec<([u32; 3], u32)>);

impl FaceIndex {
    fn get(&self, key: [u32; 3]) -> Option<u32> {
        self.0
            .binary_search_by(|e| e.0.cmp(&key))
            .ok()
            .map(|i| self.0[i].1)
    }
}

/// The per-tet mark of stamp `st`.
fn low(st: u32) -> u16 {
    st as u16
}

impl Work {
    /// A fresh stamp. Its low 16 bits are never 0 (the cleared mark), and the per-tet marks are
    /// cleared when they wrap, so a mark equals `low(st)` only if set with `st`.
    fn next_stamp(&mut self) -> u32 {
        self.stamp = self.stamp.wrapping_add(1);
        if low(self.stamp) == 0 {
            self.tet_mark.fill(0);
            self.stamp = self.stamp.wrapping_add(1);
        }
        self.stamp
    }

    /// A fresh star-walk stamp (never 0, the marks cleared when it wraps).
    fn next_star_stamp(&self) -> u16 {
        let mut st = self.star_stamp.get().wrapping_add(1);
        if st == 0 {
            for m in &self.star_mark {
                m.set(0);
            }
            st = 1;
        }
        self.star_stamp.set(st);
        st
    }

    /// Grow the per-tet and per-point marks to `tets` and `points` (new entries unmarked).
    /// Exact growth: `resize` would double the capacity, and each thread's marks are as long
    /// as the mesh.
    fn fit(&mut self, tets: usize, points: usize) {
        if self.tet_mark.len() < tets {
            self.tet_mark.reserve_exact(tets - self.tet_mark.len());
            self.star_mark.reserve_exact(tets - self.star_mark.len());
            self.tet_mark.resize(tets, 0);
            self.star_mark.resize(tets, Cell::new(0));
        }
        if self.pt_mark.len() < points {
            let more = points - self.pt_mark.len();
            self.pt_mark.reserve_exact(more);
            self.pt_local.reserve_exact(more);
            self.side_mark.reserve_exact(more);
            self.side.reserve_exact(more);
            self.pt_mark.resize(points, 0);
            self.pt_local.resize(points, 0);
            self.side_mark.resize(points, 0);
            self.side.resize(points, Sign::Zero);
        }
    }
}

/// The read-only part of the recovery, shared by the threads of a batch.
#[derive(Clone, Copy)]
struct View<'r> {
    mesh: &'r TetMesh,
    tri_map: &'r [Option<[u32; 3]>],
    vtet: &'r [u32],
    surf_start: &'r [u32],
    surf_list: &'r [u32],
    opts: &'r RecoverOptions,
    face_tri: &'r FaceIndex,
    /// [`Recovery::no_fill`] as it was when the view was taken.
    no_fill: &'r FxHashSet<Vec<u32>>,
}

/// A fill of a triangle's crossed tets found on a batch's view, applied later if nothing it
/// read changed meanwhile.
struct Speculative {
    cav: Cavity,
    new_tets: Vec<[u32; 4]>,
    /// Time, search nodes and cavity size of each call.
    calls: Vec<(f64, u64, usize)>,
}

/// What the crossed-tets stage found (see [`View::try_crossed`]).
enum Crossed {
    /// A fill, not yet inserted.
    Filled(Speculative),
    /// Both cavities searched without a fill (the calls' time, nodes and size).
    Failed { calls: Vec<(f64, u64, usize)> },
    /// No crossed tets, or too many for this stage.
    Skipped,
}

/// A cavity point made by the kernel fallback, not yet a mesh point (see [`pending_id`]).
const PENDING: u32 = u32::MAX;

/// The id a new tet holds for the pending point of local index `x` until it is numbered (mesh
/// ids stay below 2³¹, see `validate_inputs`).
fn pending_id(x: u32) -> u32 {
    u32::MAX - 1 - x
}

/// The local index behind a [`pending_id`].
fn pending_local(id: u32) -> u32 {
    u32::MAX - 1 - id
}

/// Missing triangles tried at once on one view; fixed, so the result does not depend on the
/// number of threads.
const BATCH: usize = 64;

/// A carved cavity ready to fill.
#[derive(Default)]
struct Cavity {
    tets: Vec<u32>,
    /// Global point ids, local order.
    points: Vec<u32>,
    coords: Vec<P3>,
    /// Shell faces (global ids, outward from the cavity) with the kept tet across and its face
    /// (or `NO_NEIGHBOR`).
    shell: Vec<([u32; 3], u32, u8)>,
    /// Half-faces in local ids, pointing into their cell.
    half: Vec<[u32; 3]>,
}

/// Where a surface triangle lies relative to a cavity.
enum Place {
    Inside,
    Outside,
    /// In the plane of the listed mesh boundary faces of the cavity (indices into the shell),
    /// overlapping them; `inward`: its own orientation faces into the cavity.
    OnBoundary {
        faces: Vec<usize>,
        inward: bool,
    },
}

enum Failure {
    /// The missing triangle is not inside the cavity (crosses its shell).
    NotInside,
    TooLarge,
    Cells,
    /// A cell with no fill of its points has no point strictly inside its kernel.
    NoKernel,
    /// The kernel point found lies on a surface triangle that crosses the cavity.
    OnSurface,
    Search(SearchError),
}

impl Failure {
    fn describe(&self) -> String {
        match self {
            Failure::NotInside => "the triangle leaves the largest cavity tried".into(),
            Failure::TooLarge => "the cavity grew too large".into(),
            Failure::Cells => "the cavity's constrained faces do not split it into cells".into(),
            Failure::NoKernel => "no fill exists without new points, and no cell of the cavity \
                                  is star-shaped for one interior point"
                .into(),
            Failure::OnSurface => "the only interior point found lies on another surface \
                                   triangle"
                .into(),
            Failure::Search(SearchError::NoFill { .. }) => {
                "no fill of the cavity exists without new points (search exhausted)".into()
            }
            Failure::Search(e) => format!("search failed: {e}"),
        }
    }
}

impl View<'_> {
    /// The surface triangles (one of equal ones) that are faces of tet `t`.
    fn faces_on_surface(&self, t: usize) -> [Option<u32>; 4] {
        let tv = self.mesh.tets[t];
        let on = tv.map(|x| self.surf_start[x as usize] != self.surf_start[x as usize + 1]);
        let mut out = [None; 4];
        for (f, g) in TET_FACES.iter().enumerate() {
            if on[g[0]] && on[g[1]] && on[g[2]] {
                out[f] = self.face_tri.get(sorted3(self.mesh.face(t, f)));
            }
        }
        out
    }

    /// The live tets with corner `v` (into `out`, in walk order).
    fn star_into(&self, w: &Work, v: u32, out: &mut Vec<u32>) {
        out.clear();
        let t0 = self.vtet[v as usize];
        if t0 == NO_NEIGHBOR {
            return;
        }
        let st = w.next_star_stamp();
        w.star_mark[t0 as usize].set(st);
        out.push(t0);
        let mut i = 0;
        while i < out.len() {
            let t = out[i] as usize;
            i += 1;
            let tv = self.mesh.tets[t];
            for (&x, &n) in tv.iter().zip(&self.mesh.neighbors[t]) {
                // The faces holding v are those opposite the other corners.
                if x != v && n != NO_NEIGHBOR && w.star_mark[n as usize].get() != st {
                    w.star_mark[n as usize].set(st);
                    out.push(n);
                }
            }
        }
    }

    /// The live tets with corner `v`, sorted.
    fn star(&self, w: &Work, v: u32) -> Vec<u32> {
        let mut out = Vec::new();
        self.star_into(w, v, &mut out);
        out.sort_unstable();
        out
    }

    /// `f` of the live tets with corner `v` (in walk order), without allocating.
    fn with_star<R>(&self, w: &Work, v: u32, f: impl FnOnce(&[u32]) -> R) -> R {
        let mut buf = w.star_buf.take();
        self.star_into(w, v, &mut buf);
        let r = f(&buf);
        w.star_buf.set(buf);
        r
    }

    /// The tets that the missing triangle `v` crosses: those with a face meeting it other than
    /// in shared corners or edges (exact), found by walking from its corners across such faces.
    /// Refilling just these recovers most triangles at a fraction of the cost of the corners'
    /// cavity (a few tets instead of dozens). `None` when there are more than
    /// [`CROSSED_MAX_TETS`].
    fn crossed_tets(&self, w: &mut Work, v: [u32; 3], limit: usize) -> Option<Vec<u32>> {
        let tp = v.map(|x| self.mesh.points[x as usize]);
        let (lo, hi) = bbox(&tp);
        let st = w.next_stamp();
        let mut out = Vec::new();
        let mut stack = std::mem::take(&mut w.walk_buf);
        let mut star = w.star_buf.take();
        stack.clear();
        for &c in &v {
            self.star_into(w, c, &mut star);
            for &t in &star {
                if w.tet_mark[t as usize] != low(st) {
                    w.tet_mark[t as usize] = low(st);
                    stack.push(t);
                }
            }
        }
        w.star_buf.set(star);
        while let Some(t) = stack.pop() {
            let mut crossed = false;
            let tv = self.mesh.tets[t as usize];
            // Each corner's side of the plane of `v` (exact, once per point and walk).
            let side = tv.map(|x| self.side_of(w, x, &tp, st));
            for (f, face) in TET_FACES.iter().enumerate() {
                // A face with its corners off the plane on one side, or on it only at corners of
                // `v`, meets `v` at most in shared corners or a shared edge: `tri_tri` would not
                // call it improper (same answer, without its tests).
                let mut pos = false;
                let mut neg = false;
                let mut stray = false;
                for &k in face {
                    match side[k] {
                        Sign::Positive => pos = true,
                        Sign::Negative => neg = true,
                        Sign::Zero => stray |= !v.contains(&tv[k]),
                    }
                }
                if !stray && pos != neg {
                    continue;
                }
                let g = self.mesh.face(t as usize, f);
                let gp = g.map(|x| self.mesh.points[x as usize]);
                let (glo, ghi) = bbox(&gp);
                if boxes_apart(glo, ghi, lo, hi) {
                    continue;
                }
                if tri_tri(&tp, &gp) != TriTri::Improper {
                    continue;
                }
                crossed = true;
                let n = self.mesh.neighbors[t as usize][f];
                if n != NO_NEIGHBOR && w.tet_mark[n as usize] != low(st) {
                    w.tet_mark[n as usize] = low(st);
                    stack.push(n);
                }
            }
            if crossed {
                out.push(t);
                if out.len() > limit {
                    w.walk_buf = stack;
                    return None;
                }
            }
        }
        w.walk_buf = stack;
        if out.is_empty() {
            return None;
        }
        out.sort_unstable();
        Some(out)
    }

    /// The side of point `x` of the plane through `tp` (exact), cached for stamp `st`.
    fn side_of(&self, w: &mut Work, x: u32, tp: &[P3; 3], st: u32) -> Sign {
        let i = x as usize;
        if w.side_mark[i] != st {
            w.side_mark[i] = st;
            w.side[i] = orient3d(tp[0], tp[1], tp[2], self.mesh.points[i]);
        }
        w.side[i]
    }

    /// Add the next ring: every tet across a face of the cavity.
    fn grow(&self, w: &mut Work, tets: &mut Vec<u32>) {
        let st = w.next_stamp();
        for &t in tets.iter() {
            w.tet_mark[t as usize] = low(st);
        }
        let n = tets.len();
        for i in 0..n {
            for &nb in &self.mesh.neighbors[tets[i] as usize] {
                if nb != NO_NEIGHBOR && w.tet_mark[nb as usize] != low(st) {
                    w.tet_mark[nb as usize] = low(st);
                    tets.push(nb);
                }
            }
        }
    }

    fn carve(
        &self,
        w: &mut Work,
        m: [u32; 3],
        tets: &[u32],
        cav: &mut Cavity,
    ) -> Result<(), Failure> {
        let st = w.next_stamp();
        for &t in tets {
            w.tet_mark[t as usize] = low(st);
        }
        cav.tets.extend_from_slice(tets);
        for &t in &cav.tets {
            for &x in &self.mesh.tets[t as usize] {
                if w.pt_mark[x as usize] != st {
                    w.pt_mark[x as usize] = st;
                    w.pt_local[x as usize] = cav.points.len() as u32;
                    cav.points.push(x);
                    cav.coords.push(self.mesh.points[x as usize]);
                }
            }
        }
        let mut shell_keys = std::mem::take(&mut w.keys);
        shell_keys.clear();
        for &t in &cav.tets {
            for f in 0..4 {
                let n = self.mesh.neighbors[t as usize][f];
                if n == NO_NEIGHBOR || w.tet_mark[n as usize] != low(st) {
                    let g = self.mesh.face(t as usize, f);
                    let nf = if n == NO_NEIGHBOR {
                        0
                    } else {
                        self.mesh.neighbors[n as usize]
                            .iter()
                            .position(|&x| x == t)
                            .unwrap_or(0) as u8
                    };
                    cav.shell.push((g, n, nf));
                    shell_keys.push(sorted3(g));
                    let l = g.map(|x| w.pt_local[x as usize]);
                    cav.half.push([l[0], l[2], l[1]]);
                }
            }
        }
        // Constrained faces.
        shell_keys.sort_unstable();
        let r = self.constrain(w, m, cav, st, &shell_keys);
        w.keys = shell_keys;
        r
    }

    /// The constrained faces of a carved cavity (`shell_keys`: its shell faces, sorted).
    fn constrain(
        &self,
        w: &mut Work,
        m: [u32; 3],
        cav: &mut Cavity,
        st: u32,
        shell_keys: &[[u32; 3]],
    ) -> Result<(), Failure> {
        let mut dropped = Vec::new();
        let mut found_m = false;
        let mkey = sorted3(m);
        for &x in &cav.points {
            let (a, b) = (self.surf_start[x as usize], self.surf_start[x as usize + 1]);
            for &s in &self.surf_list[a as usize..b as usize] {
                let Some(v) = self.tri_map[s as usize] else {
                    continue;
                };
                if v.iter().any(|&y| w.pt_mark[y as usize] != st) {
                    continue;
                }
                // Once, at its first corner in the cavity's order.
                if v.iter()
                    .any(|&y| w.pt_local[y as usize] < w.pt_local[x as usize])
                {
                    continue;
                }
                let key = sorted3(v);
                if shell_keys.binary_search(&key).is_ok() {
                    continue;
                }
                let place = if self.interior_face(w, v, cav, st) {
                    Place::Inside
                } else {
                    self.inside_cavity(w, v, cav, st)
                };
                let l = v.map(|y| w.pt_local[y as usize]);
                match place {
                    Place::Outside => {
                        if key == mkey {
                            return Err(Failure::NotInside);
                        }
                        continue;
                    }
                    Place::Inside => {
                        cav.half.push(l);
                        cav.half.push([l[0], l[2], l[1]]);
                    }
                    Place::OnBoundary { faces, inward } => {
                        dropped.resize(cav.shell.len(), false);
                        for k in faces {
                            dropped[k] = true;
                        }
                        cav.half.push(if inward { l } else { [l[0], l[2], l[1]] });
                    }
                }
                if key == mkey {
                    found_m = true;
                }
            }
        }
        if !dropped.is_empty() {
            // Boundary faces re-triangulated by surface triangles in their plane.
            let mut i = 0;
            cav.half.retain(|_| {
                i += 1;
                dropped.get(i - 1).is_none_or(|&d| !d)
            });
        }
        if !found_m {
            return Err(Failure::NotInside);
        }
        Ok(())
    }

    /// Is `v` a face between two tets of the cavity?
    fn interior_face(&self, w: &Work, v: [u32; 3], cav: &Cavity, st: u32) -> bool {
        if cav.tets.len() <= 16 {
            // A face is in at most two tets: two carved ones leave none outside.
            let holds = |&t: &u32| {
                let tv = self.mesh.tets[t as usize];
                v.iter().all(|x| tv.contains(x))
            };
            return cav.tets.iter().filter(|t| holds(t)).count() == 2;
        }
        self.with_star(w, v[0], |star| {
            let mut n = 0;
            for &t in star {
                let tv = self.mesh.tets[t as usize];
                if tv.contains(&v[1]) && tv.contains(&v[2]) {
                    if w.tet_mark[t as usize] != low(st) {
                        return false;
                    }
                    n += 1;
                }
            }
            n == 2
        })
    }

    /// Does triangle `v` (corners in the cavity) lie inside the cavity? Exact: no improper
    /// contact with any shell face, so its open part is entirely inside or entirely outside;
    /// then the point `x = u + ε(w − u) + δ(v − u)` (0 < δ ≪ ε infinitesimal, inside the
    /// triangle next to corner `u`) is located in the carved tets at `u`. The orientation of `x`
    /// against a plane is the first non-zero of its orientations of `u`, `w`, `v`.
    ///
    /// A triangle in the plane of mesh boundary faces of the cavity (a surface triangle on the
    /// convex hull, split differently) is [`Place::OnBoundary`]: those faces are replaced by it.
    fn inside_cavity(&self, w: &Work, v: [u32; 3], cav: &Cavity, st: u32) -> Place {
        let tp = v.map(|x| self.mesh.points[x as usize]);
        let (lo, hi) = bbox(&tp);
        let mut on_boundary = Vec::new();
        for (i, (g, n, _)) in cav.shell.iter().enumerate() {
            let gp = g.map(|x| self.mesh.points[x as usize]);
            if (0..3).any(|k| gp.iter().all(|p| p[k] < lo[k]) || gp.iter().all(|p| p[k] > hi[k])) {
                continue;
            }
            if tri_tri(&tp, &gp) == TriTri::Improper {
                let coplanar = tp
                    .iter()
                    .all(|&p| orient3d(gp[0], gp[1], gp[2], p) == Sign::Zero);
                if *n == NO_NEIGHBOR && coplanar {
                    on_boundary.push(i);
                    continue;
                }
                return Place::Outside;
            }
        }
        if let Some(&i) = on_boundary.first() {
            // Orient it like the boundary faces seen from inside: towards the cavity tet's apex.
            let g = cav.shell[i].0;
            let apex = cav.tets.iter().find_map(|&t| {
                let tv = self.mesh.tets[t as usize];
                let inside = g.iter().all(|x| tv.contains(x));
                inside.then(|| tv.into_iter().find(|x| !g.contains(x)))?
            });
            let Some(apex) = apex else {
                return Place::Outside;
            };
            let inward =
                orient3d(tp[0], tp[1], tp[2], self.mesh.points[apex as usize]) == Sign::Positive;
            return Place::OnBoundary {
                faces: on_boundary,
                inward,
            };
        }
        let [u, vv, ww] = tp;
        // Any carved tet at u holding the symbolic point answers: no order, no allocation.
        let inside = self.with_star(w, v[0], |star| {
            star.iter().any(|&t| {
                w.tet_mark[t as usize] == low(st) && {
                    let c = self.mesh.corners(t as usize);
                    TET_FACES.iter().all(|f| {
                        let (a, b, cc) = (c[f[0]], c[f[1]], c[f[2]]);
                        let mut s = orient3d(a, b, cc, u);
                        if s == Sign::Zero {
                            s = orient3d(a, b, cc, ww);
                        }
                        if s == Sign::Zero {
                            s = orient3d(a, b, cc, vv);
                        }
                        s != Sign::Positive
                    })
                }
            })
        });
        if inside {
            Place::Inside
        } else {
            Place::Outside
        }
    }

    /// Split into cells and search each; the new tets in global numbering.
    /// With `kernel`, a cell that has no fill of its own points gets one new point strictly
    /// inside its kernel (see [`kernel_point`]): a fill through it is searched, else the cone
    /// from it is taken. Such points enter `cav.points` as [`PENDING`], for the caller to
    /// number.
    fn fill_cells(
        &self,
        w: &mut Work,
        cav: &mut Cavity,
        nodes: &mut u64,
        kernel: bool,
    ) -> Result<Vec<[u32; 4]>, Failure> {
        let mut cell = std::mem::take(&mut w.cell);
        let mut faces = std::mem::take(&mut w.faces);
        let mut inner = std::mem::take(&mut w.inner);
        let r = self.fill_cells_with(w, cav, nodes, kernel, &mut cell, &mut faces, &mut inner);
        w.cell = cell;
        w.faces = faces;
        w.inner = inner;
        r
    }

    /// [`Self::fill_cells`] with its buffers.
    // The three buffers are the scratch's, taken out for the call.
    #[allow(clippy::too_many_arguments)]
    fn fill_cells_with(
        &self,
        w: &mut Work,
        cav: &mut Cavity,
        nodes: &mut u64,
        kernel: bool,
        cell: &mut Vec<u32>,
        faces: &mut Vec<[u32; 3]>,
        inner: &mut Vec<u32>,
    ) -> Result<Vec<[u32; 4]>, Failure> {
        cell.clear();
        let n = w
            .cells
            .split(&cav.coords, &cav.half, cell)
            .map_err(|_| Failure::Cells)?;
        let on_face = &mut w.on_face;
        on_face.clear();
        on_face.resize(cav.points.len(), false);
        for f in &cav.half {
            for &x in f {
                on_face[x as usize] = true;
            }
        }
        inner.clear();
        inner.extend((0..cav.points.len() as u32).filter(|&x| !on_face[x as usize]));
        // Without new points the first cell with no fill ends the call, so the cells are searched
        // smallest first (a cube's inside, proven unfillable in two nodes, after its outside took
        // thirty); the fills are put back in cell order, so the result is the same. With new
        // points, in cell order: each failing cell's point is numbered as it comes.
        let mut order: Vec<(usize, u32)> = (0..n as u32).map(|c| (0, c)).collect();
        if !kernel {
            for &k in cell.iter() {
                order[k as usize].0 += 1;
            }
            order.sort_unstable();
        }
        let mut parts: Vec<Vec<[u32; 4]>> = vec![Vec::new(); n];
        for &(_, c) in &order {
            let out = &mut parts[c as usize];
            faces.clear();
            faces.extend(
                cav.half
                    .iter()
                    .zip(cell.iter())
                    .filter(|(_, k)| **k == c)
                    .map(|(f, _)| *f),
            );
            // A first, cheaper try among better tets only (ηe raised): fewer candidates, and
            // fewer slivers for the sliver removal that follows; the configured search if not.
            // The key only where it is looked up or recorded (most cells: neither).
            let known = !self.no_fill.is_empty()
                && self.no_fill.contains(&cell_key(&cav.points, faces, inner));
            let result = if known {
                Err(SearchError::NoFill { nodes_visited: 0 })
            } else {
                let mut first = None;
                if self.opts.first_quality > self.opts.search.min_quality {
                    let o = SearchOptions {
                        min_quality: self.opts.first_quality,
                        max_nodes: self.opts.search.max_nodes.min(FIRST_TRY_NODES),
                        ..self.opts.search
                    };
                    first = Some(w.searcher.fill(&cav.coords, faces, inner, &o));
                }
                let result = match first {
                    Some(Ok(f)) => Ok(f),
                    // No fill, and no apex refused for quality alone: the configured search
                    // would take the same candidates everywhere (a twisted cube's inside, four
                    // times a triangle on the unit cube), so it is not run. (Its budget is no
                    // smaller than the first try's.)
                    Some(Err(e @ SearchError::NoFill { .. })) if !w.searcher.cut_by_quality() => {
                        Err(e)
                    }
                    // The shell is loaded: searched again without loading it again.
                    Some(Err(e @ (SearchError::NoFill { .. } | SearchError::Budget { .. }))) => {
                        *nodes += nodes_of(&e);
                        w.searcher.refill(&self.opts.search)
                    }
                    Some(Err(e)) => {
                        *nodes += nodes_of(&e);
                        w.searcher
                            .fill(&cav.coords, faces, inner, &self.opts.search)
                    }
                    None => w
                        .searcher
                        .fill(&cav.coords, faces, inner, &self.opts.search),
                };
                // A complete search's proof holds for this cell in any later cavity (the
                // options that bound the fills do not change; widening only adds nodes).
                if matches!(result, Err(SearchError::NoFill { .. })) {
                    w.proven.push(cell_key(&cav.points, faces, inner));
                }
                result
            };
            match result {
                Ok(f) => {
                    *nodes += f.nodes_visited;
                    out.extend(f.tets.iter().map(|t| t.map(|x| cav.points[x as usize])));
                }
                Err(e) => {
                    *nodes += nodes_of(&e);
                    if !kernel {
                        return Err(Failure::Search(e));
                    }
                    let p = kernel_point(&cav.coords, faces, self.opts.exact_kernel)
                        .ok_or(Failure::NoKernel)?;
                    let k = cav.points.len() as u32;
                    cav.points.push(PENDING);
                    cav.coords.push(p);
                    // A fill through the new point (better tets than the cone, usually).
                    let o = SearchOptions {
                        max_nodes: self.opts.search.max_nodes.min(FIRST_TRY_NODES),
                        ..self.opts.search
                    };
                    inner.push(k);
                    let found = w.searcher.fill(&cav.coords, faces, inner, &o);
                    inner.pop();
                    let tets = match found {
                        Ok(f) => {
                            *nodes += f.nodes_visited;
                            f.tets
                        }
                        Err(e) => {
                            *nodes += nodes_of(&e);
                            // The cone, with the isolated points inside the cell split in.
                            let mut tets: Vec<[u32; 4]> = cone(faces, k).collect();
                            for &x in inner.iter() {
                                split_insert(&cav.coords, &mut tets, x);
                            }
                            tets
                        }
                    };
                    out.extend(tets.iter().map(|t| {
                        t.map(|x| {
                            let g = cav.points[x as usize];
                            if g == PENDING { pending_id(x) } else { g }
                        })
                    }));
                }
            }
        }
        Ok(parts.concat())
    }

    /// Carve `tets` and fill the cavity (not inserted); the call's time, nodes and size are
    /// pushed to `calls`.
    fn carve_fill(
        &self,
        w: &mut Work,
        m: [u32; 3],
        tets: &[u32],
        calls: &mut Vec<(f64, u64, usize)>,
    ) -> Result<(Cavity, Vec<[u32; 4]>), Failure> {
        let start = Instant::now();
        let mut nodes = 0u64;
        let mut cav = Cavity::default();
        let r = self
            .carve(w, m, tets, &mut cav)
            .and_then(|()| self.fill_cells(w, &mut cav, &mut nodes, false));
        calls.push((start.elapsed().as_secs_f64() * 1e3, nodes, cav.tets.len()));
        r.map(|t| (cav, t))
    }

    /// The crossed-tets stage of [`Recovery::attempt`] (the tets `v` crosses, then those and
    /// their face neighbours), without inserting.
    fn try_crossed(&self, w: &mut Work, v: [u32; 3]) -> Crossed {
        let Some(crossed) = self.crossed_tets(w, v, CROSSED_MAX_TETS) else {
            return Crossed::Skipped;
        };
        let mut calls = Vec::new();
        if let Ok((cav, new_tets)) = self.carve_fill(w, v, &crossed, &mut calls) {
            return Crossed::Filled(Speculative {
                cav,
                new_tets,
                calls,
            });
        }
        let mut ring = crossed;
        self.grow(w, &mut ring);
        match self.carve_fill(w, v, &ring, &mut calls) {
            Ok((cav, new_tets)) => Crossed::Filled(Speculative {
                cav,
                new_tets,
                calls,
            }),
            Err(_) => Crossed::Failed { calls },
        }
    }
}

impl<'a> Recovery<'a> {
    fn new(
        mesh: &'a mut TetMesh,
        surface: &'a SurfaceMesh,
        tri_map: Vec<Option<[u32; 3]>>,
        opts: RecoverOptions,
    ) -> Recovery<'a> {
        let np = mesh.points.len();
        let mut surf_start = vec![0u32; np + 1];
        for v in tri_map.iter().flatten() {
            for &x in v {
                surf_start[x as usize + 1] += 1;
            }
        }
        for i in 0..np {
            surf_start[i + 1] += surf_start[i];
        }
        let mut fill = surf_start.clone();
        let mut surf_list = vec![0u32; surf_start[np] as usize];
        for (s, m) in tri_map.iter().enumerate() {
            if let Some(v) = m {
                for &x in v {
                    surf_list[fill[x as usize] as usize] = s as u32;
                    fill[x as usize] += 1;
                }
            }
        }
        drop(fill);
        let mut same_face = vec![NO_NEIGHBOR; tri_map.len()];
        let mut faces: Vec<([u32; 3], u32)> = tri_map
            .iter()
            .enumerate()
            .filter_map(|(s, m)| m.map(|v| (sorted3(v), s as u32)))
            .collect();
        faces.sort_unstable();
        // Equal corners: each triangle remembers the one before it, the index keeps the last.
        for k in 1..faces.len() {
            if faces[k].0 == faces[k - 1].0 {
                same_face[faces[k].1 as usize] = faces[k - 1].1;
            }
        }
        faces.dedup_by(|later, earlier| {
            let equal = later.0 == earlier.0;
            if equal {
                earlier.1 = later.1;
            }
            equal
        });
        let face_tri = FaceIndex(faces);
        let mut r = Recovery {
            mesh,
            surface,
            opts,
            tri_map,
            face_tri,
            same_face,
            is_present: Vec::new(),
            alive: Vec::new(),
            free: Vec::new(),
            vtet: Vec::new(),
            surf_start,
            surf_list,
            work: Work::default(),
            claim: Vec::new(),
            batch: 0,
            picked: vec![0; np],
            reason: FxHashMap::default(),
            call_ms: Vec::new(),
            call_nodes: Vec::new(),
            call_sizes: Vec::new(),
            calls_ok: 0,
            crossed_tried: 0,
            crossed_ok: 0,
            grown: 0,
            steiner_points: 0,
            tries: FxHashMap::default(),
            wide: false,
            no_fill: FxHashSet::default(),
        };
        r.index();
        r
    }

    /// Drop the per-tet and per-point scratch that [`Self::index`] rebuilds.
    fn free_scratch(&mut self) {
        self.alive = Vec::new();
        self.claim = Vec::new();
        self.vtet = Vec::new();
        self.work.tet_mark = Vec::new();
        self.work.star_mark = Vec::new();
    }

    /// Rebuild the incidence lists from scratch.
    fn index(&mut self) {
        self.free_scratch();
        let np = self.mesh.points.len();
        self.alive = vec![true; self.mesh.tets.len()];
        self.free.clear();
        self.work.tet_mark = vec![0; self.mesh.tets.len()];
        self.work.star_mark = vec![Cell::new(0); self.mesh.tets.len()];
        self.work.star_stamp.set(0);
        self.work.fit(0, np);
        self.claim = vec![0; self.mesh.tets.len()];
        self.vtet = vec![NO_NEIGHBOR; np];
        for (t, v) in self.mesh.tets.iter().enumerate() {
            for &x in v {
                self.vtet[x as usize] = t as u32;
            }
        }
    }

    fn view(&self) -> View<'_> {
        View {
            mesh: self.mesh,
            tri_map: &self.tri_map,
            vtet: &self.vtet,
            surf_start: &self.surf_start,
            surf_list: &self.surf_list,
            opts: &self.opts,
            face_tri: &self.face_tri,
            no_fill: &self.no_fill,
        }
    }

    /// `f` on the view with the serial scratch.
    fn with_work<R>(&mut self, f: impl FnOnce(View<'_>, &mut Work) -> R) -> R {
        let mut w = std::mem::take(&mut self.work);
        // Marks for every tet slot the mesh can hold before it grows again.
        w.fit(self.mesh.tets.capacity(), self.mesh.points.len());
        let r = f(self.view(), &mut w);
        self.no_fill.extend(w.proven.drain(..));
        self.work = w;
        r
    }

    /// Surface triangles missing (by [`Self::is_present`]).
    fn count_missing(&self) -> usize {
        self.is_present.iter().filter(|&&p| !p).count()
    }

    /// The missing triangles whose corners are all mesh points.
    fn missing_mapped(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.tri_map.len() as u32)
            .filter(|&s| self.tri_map[s as usize].is_some() && !self.is_present[s as usize])
    }

    /// Set [`Self::is_present`] from scratch: one pass over the tets' faces (cheaper than a star
    /// walk per triangle).
    fn scan_present(&mut self) {
        self.is_present.clear();
        self.is_present.resize(self.tri_map.len(), false);
        let (view, alive) = (self.view(), &self.alive);
        let hits: Vec<u32> = (0..self.mesh.tets.len())
            .into_par_iter()
            .with_min_len(4096)
            .filter(|&t| alive[t])
            .flat_map_iter(|t| view.faces_on_surface(t).into_iter().flatten())
            .collect();
        for s in hits {
            self.mark_chain(s);
        }
    }

    /// Mark surface triangle `s` and those with the same corners present.
    fn mark_chain(&mut self, mut s: u32) {
        while s != NO_NEIGHBOR {
            self.is_present[s as usize] = true;
            s = self.same_face[s as usize];
        }
    }

    /// Mark the surface triangles that are faces of tet `t` present.
    fn mark_present(&mut self, t: usize) {
        for s in self.view().faces_on_surface(t).into_iter().flatten() {
            self.mark_chain(s);
        }
    }

    /// Make the mesh cover the convex hull of its points (module docs, step 1).
    fn cover(&mut self) -> Result<Domain, RecoverError> {
        if boundary_is_convex(self.mesh) {
            return Ok(Domain::Convex);
        }
        let dt = Delaunay::new(&self.mesh.points)
            .map_err(|e| RecoverError::NotCovering(format!("Delaunay failed: {e}")))?;
        if dt.n_vertices() != self.mesh.points.len() {
            return Err(RecoverError::NotCovering("duplicate points".into()));
        }
        let full = dt.to_tet_mesh();
        let key = |t: &[u32; 4]| {
            let mut k = *t;
            k.sort_unstable();
            k
        };
        let have: FxHashSet<[u32; 4]> = self.mesh.tets.iter().map(key).collect();
        let dt_keys: FxHashSet<[u32; 4]> = full.tets.iter().map(key).collect();
        if let Some(t) = self
            .mesh
            .tets
            .iter()
            .position(|t| !dt_keys.contains(&key(t)))
        {
            return Err(RecoverError::NotCovering(format!(
                "tet {t} is not a Delaunay tet of the points"
            )));
        }
        let mut added = 0;
        for t in &full.tets {
            if !have.contains(&key(t)) {
                self.mesh.tets.push(*t);
                self.mesh.labels.push(0);
                added += 1;
            }
        }
        self.mesh.rebuild_neighbors();
        self.index();
        Ok(Domain::DelaunayCompleted { tets_added: added })
    }

    /// Process the queue of missing triangles (module docs, steps 3–4), in batches: the
    /// crossed-tets fills of [`BATCH`] triangles are searched in parallel on the same mesh, then
    /// applied in queue order; a fill whose tets or neighbours an earlier one of the batch carved
    /// waits for the next batch, and a triangle without a crossed-tets fill goes through
    /// [`Self::attempt`] on the mesh as it is then. The result does not depend on the threads.
    fn run(&mut self) {
        let mut queue: VecDeque<u32> = self.missing_mapped().collect();
        // The serial scratch joins the pool for each batch's parallel part: one scratch a
        // thread, not one more (each holds 8 bytes a tet).
        let threads = rayon::current_num_threads().max(1);
        let mut pool: Vec<Mutex<Work>> = (1..threads).map(|_| Mutex::default()).collect();
        let mut stalled = 0usize;
        let mut batch: Vec<u32> = Vec::with_capacity(BATCH);
        let mut wait: Vec<u32> = Vec::new();
        loop {
            // Triangles sharing a corner would mostly carve the same tets: one per batch, the
            // others keep their place in the queue.
            batch.clear();
            self.batch += 1;
            let mut scanned = 0;
            while batch.len() < BATCH
                && scanned < 8 * BATCH
                && let Some(s) = queue.pop_front()
            {
                scanned += 1;
                let Some(v) = self.tri_map[s as usize] else {
                    continue;
                };
                if self.is_present[s as usize] {
                    continue;
                }
                if v.iter().any(|&x| self.picked[x as usize] == self.batch) {
                    wait.push(s);
                    continue;
                }
                for &x in &v {
                    self.picked[x as usize] = self.batch;
                }
                batch.push(s);
            }
            for &s in wait.iter().rev() {
                queue.push_front(s);
            }
            wait.clear();
            if batch.is_empty() {
                break;
            }
            // To the mesh's capacity, which grows by a 32nd: few reallocations.
            let (nt, np) = (self.mesh.tets.capacity(), self.mesh.points.len());
            pool.push(Mutex::new(std::mem::take(&mut self.work)));
            for w in &mut pool {
                w.get_mut().unwrap_or_else(|e| e.into_inner()).fit(nt, np);
            }
            let view = self.view();
            let found: Vec<Crossed> = batch
                .par_iter()
                .map(|&s| {
                    let Some(v) = view.tri_map[s as usize] else {
                        return Crossed::Skipped;
                    };
                    let k = rayon::current_thread_index().unwrap_or(0) % pool.len();
                    let mut w = pool[k].lock().unwrap_or_else(|e| e.into_inner());
                    view.try_crossed(&mut w, v)
                })
                .collect();
            // Every call of the batch read the memo as it was before it: the union is the same
            // for any thread count.
            for w in &mut pool {
                let w = w.get_mut().unwrap_or_else(|e| e.into_inner());
                self.no_fill.extend(w.proven.drain(..));
            }
            if let Some(w) = pool.pop() {
                self.work = w.into_inner().unwrap_or_else(|e| e.into_inner());
            }
            // Whether this batch has changed the mesh yet: until it has, a failed crossed stage
            // stands as tried on the mesh as it is.
            let mut changed = false;
            for (i, (&s, found)) in batch.iter().zip(found).enumerate() {
                let Some(v) = self.tri_map[s as usize] else {
                    continue;
                };
                if self.is_present[s as usize] {
                    continue;
                }
                // Every triangle left failed since the last success.
                if stalled > queue.len() + wait.len() + (batch.len() - i - 1) {
                    return;
                }
                let tried = match found {
                    Crossed::Filled(f) if !self.stale(&f.cav) => {
                        self.record_calls(&f.calls);
                        self.crossed_tried += 1;
                        self.crossed_ok += 1;
                        self.calls_ok += 1;
                        self.insert(&f.cav, &f.new_tets);
                        changed = true;
                        stalled = 0;
                        self.reason.remove(&s);
                        continue;
                    }
                    Crossed::Filled(_) => {
                        wait.push(s);
                        continue;
                    }
                    Crossed::Failed { calls } if !changed => {
                        self.record_calls(&calls);
                        self.crossed_tried += 1;
                        true
                    }
                    _ => false,
                };
                if self.attempt_after(s, v, false, tried) {
                    changed = true;
                    stalled = 0;
                    self.reason.remove(&s);
                } else {
                    // Bounded by work: a triangle failed this often is left to the Steiner
                    // fallback (or reported), not retried after every success.
                    let n = self.tries.entry(s).or_insert(0);
                    *n += 1;
                    if u32::from(*n) < self.opts.max_tries {
                        stalled += 1;
                        queue.push_back(s);
                    }
                }
            }
            for &s in wait.iter().rev() {
                queue.push_front(s);
            }
            wait.clear();
        }
    }

    /// Whether a fill found on the batch's view touches a tet carved since (its tets or the
    /// kept tets across its shell).
    fn stale(&self, cav: &Cavity) -> bool {
        let b = self.batch;
        cav.tets.iter().any(|&t| self.claim[t as usize] == b)
            || cav
                .shell
                .iter()
                .any(|&(_, n, _)| n != NO_NEIGHBOR && self.claim[n as usize] == b)
    }

    /// One triangle: first the smallest cavity (the tets it crosses), then the cavity of its
    /// corners, grown on failure.
    /// With `kernel` (the Steiner fallback), the small cavities come first too: a cell of few
    /// faces is more likely star-shaped, and its cone is small.
    fn attempt(&mut self, s: u32, v: [u32; 3], kernel: bool) -> bool {
        self.attempt_after(s, v, kernel, false)
    }

    /// Time, search nodes and cavity size of calls made on a view.
    fn record_calls(&mut self, calls: &[(f64, u64, usize)]) {
        for &(ms, nodes, size) in calls {
            self.call_ms.push(ms);
            self.call_nodes.push(nodes);
            self.call_sizes.push(size);
        }
    }

    /// [`Self::attempt`], the crossed stage not repeated when `tried` says it already failed
    /// on the mesh as it is.
    fn attempt_after(&mut self, s: u32, v: [u32; 3], kernel: bool, tried: bool) -> bool {
        // Wide rounds take the crossed tets however many (within the cavity bound): a surface
        // triangle far larger than the interior spacing crosses hundreds, and a cavity grown
        // from its corners alone would not reach its middle.
        let limit = if self.wide {
            self.opts.max_cavity_tets
        } else {
            CROSSED_MAX_TETS
        };
        let crossed = self.with_work(|view, w| view.crossed_tets(w, v, limit));
        if let Some(crossed) = crossed.as_ref().filter(|_| !tried) {
            self.crossed_tried += 1;
            if self.carve_and_fill(v, crossed, kernel).is_ok() {
                self.crossed_ok += 1;
                return true;
            }
            // Then those and their face neighbours: still far smaller than the corners' cavity,
            // and on brain_20k it recovers all but 2 of the triangles the crossed tets miss.
            let mut ring = crossed.clone();
            self.with_work(|view, w| view.grow(w, &mut ring));
            if self.carve_and_fill(v, &ring, kernel).is_ok() {
                self.crossed_ok += 1;
                return true;
            }
        }
        // The tets around the corners.
        let mut tets = self.with_work(|view, w| {
            let st = w.next_stamp();
            let mut tets = Vec::new();
            for &t in crossed.iter().flatten() {
                w.tet_mark[t as usize] = low(st);
                tets.push(t);
            }
            for &c in &v {
                for t in view.star(w, c) {
                    if w.tet_mark[t as usize] != low(st) {
                        w.tet_mark[t as usize] = low(st);
                        tets.push(t);
                    }
                }
            }
            tets
        });
        for ring in 0..=self.opts.max_grow {
            if ring > 0 {
                self.grown += 1;
                self.with_work(|view, w| view.grow(w, &mut tets));
            }
            if tets.len() > self.opts.max_cavity_tets {
                self.reason.insert(s, Failure::TooLarge.describe());
                break;
            }
            match self.carve_and_fill(v, &tets, kernel) {
                Ok(()) => return true,
                Err(f) => {
                    self.reason.insert(s, f.describe());
                }
            }
        }
        false
    }

    /// Carve the tets `tets`, fill the cavity, and insert the fill.
    fn carve_and_fill(&mut self, m: [u32; 3], tets: &[u32], steiner: bool) -> Result<(), Failure> {
        let start = Instant::now();
        let mut nodes = 0u64;
        let n0 = self.mesh.points.len();
        let mut cav = Cavity::default();
        let result = self
            .with_work(|view, w| view.carve(w, m, tets, &mut cav))
            .and_then(|()| {
                self.with_work(|view, w| view.fill_cells(w, &mut cav, &mut nodes, steiner))
            })
            .and_then(|new_tets| self.number_pending(&mut cav, new_tets));
        let ok = match result {
            Ok(new_tets) => {
                self.insert(&cav, &new_tets);
                self.calls_ok += 1;
                Ok(())
            }
            Err(f) => {
                self.drop_unused_points(n0);
                Err(f)
            }
        };
        self.call_ms.push(start.elapsed().as_secs_f64() * 1e3);
        self.call_nodes.push(nodes);
        self.call_sizes.push(cav.tets.len());
        ok
    }

    /// Replace the cavity's tets by `new_tets`, keeping adjacency.
    fn insert(&mut self, cav: &Cavity, new_tets: &[[u32; 4]]) {
        // Provisional label: the most common label of the carved tets.
        let mut labels: Vec<u32> = cav
            .tets
            .iter()
            .map(|&t| self.mesh.labels[t as usize])
            .collect();
        labels.sort_unstable();
        let mut label = labels.first().copied().unwrap_or(1);
        let mut best = 0;
        let mut i = 0;
        while i < labels.len() {
            let mut j = i;
            while j < labels.len() && labels[j] == labels[i] {
                j += 1;
            }
            if j - i > best {
                best = j - i;
                label = labels[i];
            }
            i = j;
        }
        for &t in &cav.tets {
            self.alive[t as usize] = false;
            self.claim[t as usize] = self.batch;
            self.free.push(t);
        }
        let mut slots = Vec::with_capacity(new_tets.len());
        for t in new_tets {
            let slot = if let Some(s) = self.free.pop() {
                self.mesh.tets[s as usize] = *t;
                self.mesh.labels[s as usize] = label;
                self.mesh.neighbors[s as usize] = [NO_NEIGHBOR; 4];
                self.alive[s as usize] = true;
                s
            } else {
                if self.mesh.tets.len() == self.mesh.tets.capacity() {
                    // Grow by a 32nd, not double: a fill adds few tets beyond the ones it
                    // frees (brain_20k: 2% in all), and the slack of every per-tet array
                    // would set the peak memory. Large blocks are mapped on their own, so a
                    // reallocation remaps instead of copying.
                    let extra = self.mesh.tets.len() / 32 + 64;
                    self.mesh.tets.reserve_exact(extra);
                    self.mesh.labels.reserve_exact(extra);
                    self.mesh.neighbors.reserve_exact(extra);
                    self.alive.reserve_exact(extra);
                    self.claim.reserve_exact(extra);
                }
                self.mesh.tets.push(*t);
                self.mesh.labels.push(label);
                self.mesh.neighbors.push([NO_NEIGHBOR; 4]);
                self.alive.push(true);
                self.claim.push(0);
                (self.mesh.tets.len() - 1) as u32
            };
            for &x in t {
                self.vtet[x as usize] = slot;
            }
            slots.push(slot);
        }
        // A cavity point the fill left out has no tet now (its old one is dead or reused).
        for &x in &cav.points {
            let t = self.vtet[x as usize];
            if t != NO_NEIGHBOR
                && (!self.alive[t as usize] || !self.mesh.tets[t as usize].contains(&x))
            {
                self.vtet[x as usize] = NO_NEIGHBOR;
            }
        }
        // Adjacency: among the new tets, then across the shell.
        let mut open: FxHashMap<[u32; 3], (u32, u8)> = FxHashMap::default();
        for &s in &slots {
            for f in 0..4 {
                let key = sorted3(self.mesh.face(s as usize, f));
                if let Some((o, of)) = open.remove(&key) {
                    self.mesh.neighbors[s as usize][f] = o;
                    self.mesh.neighbors[o as usize][of as usize] = s;
                } else {
                    open.insert(key, (s, f as u8));
                }
            }
        }
        for (g, n, nf) in &cav.shell {
            if let Some((s, f)) = open.remove(&sorted3(*g)) {
                self.mesh.neighbors[s as usize][f as usize] = *n;
                if *n != NO_NEIGHBOR {
                    self.mesh.neighbors[*n as usize][*nf as usize] = s;
                }
            }
        }
        for &s in &slots {
            self.mark_present(s as usize);
        }
    }

    /// Give the kernel points of a fill (see [`View::fill_cells`]) mesh numbers, in local
    /// order, and put them in its tets; refused when one lies on a surface triangle (exact).
    fn number_pending(
        &mut self,
        cav: &mut Cavity,
        mut new_tets: Vec<[u32; 4]>,
    ) -> Result<Vec<[u32; 4]>, Failure> {
        let pending: Vec<usize> = (0..cav.points.len())
            .filter(|&x| cav.points[x] == PENDING)
            .collect();
        if pending.is_empty() {
            return Ok(new_tets);
        }
        if pending.iter().any(|&x| self.on_surface(cav.coords[x])) {
            return Err(Failure::OnSurface);
        }
        for x in pending {
            let id = self.mesh.points.len() as u32;
            self.mesh.points.push(cav.coords[x]);
            self.vtet.push(NO_NEIGHBOR);
            self.surf_start.push(self.surf_list.len() as u32);
            let w = &mut self.work;
            w.pt_mark.push(0);
            w.side_mark.push(0);
            w.side.push(Sign::Zero);
            w.pt_local.push(x as u32);
            cav.points[x] = id;
        }
        for t in &mut new_tets {
            for v in t.iter_mut() {
                if *v >= 1 << 31 {
                    *v = cav.points[pending_local(*v) as usize];
                }
            }
        }
        Ok(new_tets)
    }

    /// Whether `p` lies on a surface triangle (exact).
    fn on_surface(&self, p: P3) -> bool {
        (0..self.surface.triangles.len()).any(|s| {
            let c = self.surface.corners(s);
            if (0..3).any(|k| c.iter().all(|q| q[k] < p[k]) || c.iter().all(|q| q[k] > p[k])) {
                return false;
            }
            crate::geom::intersect::seg_tri(p, p, &c).meets()
        })
    }

    /// Switch to the wide bounds for the rounds left (see [`WIDE_GROW`]).
    fn widen(&mut self) {
        self.wide = true;
        self.opts.max_grow = self.opts.max_grow.max(WIDE_GROW);
        self.opts.max_cavity_tets = self.opts.max_cavity_tets.max(WIDE_MAX_TETS);
        self.opts.search.max_nodes = self.opts.search.max_nodes.max(WIDE_NODES);
    }

    /// Debug check: `is_present` is what the output's faces say. (Not a star walk: with the
    /// outside removed, regions touching only at a vertex or an edge leave that vertex's star
    /// in pieces that share no face.)
    fn assert_present(&self) {
        let faces: FxHashSet<[u32; 3]> = self
            .mesh
            .tets
            .iter()
            .flat_map(|v| TET_FACES.map(|l| sorted3([v[l[0]], v[l[1]], v[l[2]]])))
            .collect();
        for (s, m) in self.tri_map.iter().enumerate() {
            assert_eq!(
                self.is_present[s],
                m.is_some_and(|v| faces.contains(&sorted3(v))),
                "surface triangle {s}"
            );
        }
    }

    /// Whether every surface triangle's corners are mesh points in live tets (as in the
    /// pipeline), so no point needs putting back.
    fn corners_live(&self) -> bool {
        self.tri_map
            .iter()
            .all(|m| m.is_some_and(|v| v.iter().all(|&x| self.vtet[x as usize] != NO_NEIGHBOR)))
    }

    /// Coordinates of the triangles' corners (once each) that are no mesh point or a mesh
    /// point in no live tet (`at`: [`point_index`] of the mesh).
    fn absent_surface_points(&self, at: &FxHashMap<[u64; 3], u32>) -> Vec<P3> {
        let mut seen: FxHashSet<[u64; 3]> = FxHashSet::default();
        let mut out = Vec::new();
        for &c in self.surface.triangles.iter().flatten() {
            let p = self.surface.points[c as usize];
            let key = coord_key(&p);
            let lacks = at
                .get(&key)
                .is_none_or(|&i| self.vtet[i as usize] == NO_NEIGHBOR);
            if lacks && seen.insert(key) {
                out.push(p);
            }
        }
        out
    }

    /// Last resort: the failed triangles again, each cavity with one interior point.
    fn run_steiner(&mut self) {
        let todo: Vec<u32> = self.missing_mapped().collect();
        for s in todo {
            let Some(v) = self.tri_map[s as usize] else {
                continue;
            };
            if self.is_present[s as usize] {
                continue;
            }
            let n0 = self.mesh.points.len();
            if self.attempt(s, v, true) {
                self.steiner_points += self.mesh.points.len() - n0;
                self.reason.remove(&s);
            }
        }
    }

    /// Remove points appended after `n0` that no tet uses (failed Steiner tries), from the end.
    fn drop_unused_points(&mut self, n0: usize) {
        while self.mesh.points.len() > n0 {
            let last = self.mesh.points.len() - 1;
            if self.vtet[last] != NO_NEIGHBOR {
                break;
            }
            self.mesh.points.pop();
            self.vtet.pop();
            self.surf_start.pop();
            self.work.pt_mark.pop();
            self.work.side_mark.pop();
            self.work.side.pop();
            self.work.pt_local.pop();
        }
    }

    /// Drop the points from `n_base` on that no tet uses (renumbering the others); returns how
    /// many. Run after the outside tets are removed, so only the reports use the incidences
    /// after it (rebuilt).
    fn drop_orphans(&mut self, n_base: usize) -> usize {
        let dropped = crate::mesh::drop_unused_points(
            &mut self.mesh.points,
            self.mesh.tets.as_flattened_mut(),
            n_base,
        );
        if dropped > 0 {
            self.surf_start.truncate(self.mesh.points.len() + 1);
            self.index();
        }
        dropped
    }

    /// Drop dead slots and rebuild adjacency.
    fn compact(&mut self) {
        self.retain_tets(|r, t| r.alive[t]);
    }

    /// Keep the tets for which `keep` holds (in order), renumber the adjacency (kept up to date
    /// by every insertion, so no rebuild and no sort) and rebuild the incidences; returns how
    /// many were removed.
    fn retain_tets(&mut self, keep: impl Fn(&Self, usize) -> bool) -> usize {
        let before = self.mesh.tets.len();
        let mut index = vec![NO_NEIGHBOR; before];
        let mut k = 0u32;
        for (t, slot) in index.iter_mut().enumerate() {
            if keep(self, t) {
                *slot = k;
                k += 1;
            }
        }
        for t in 0..before {
            let new = index[t];
            if new == NO_NEIGHBOR {
                continue;
            }
            let nb = self.mesh.neighbors[t].map(|n| {
                if n == NO_NEIGHBOR {
                    n
                } else {
                    index[n as usize]
                }
            });
            let new = new as usize;
            self.mesh.tets[new] = self.mesh.tets[t];
            self.mesh.labels[new] = self.mesh.labels[t];
            self.mesh.neighbors[new] = nb;
        }
        drop(index);
        let k = k as usize;
        self.mesh.tets.truncate(k);
        self.mesh.labels.truncate(k);
        self.mesh.neighbors.truncate(k);
        self.mesh.tets.shrink_to_fit();
        self.mesh.labels.shrink_to_fit();
        self.mesh.neighbors.shrink_to_fit();
        debug_assert_eq!(
            self.mesh.neighbors,
            crate::mesh::tet::face_adjacency(&self.mesh.tets).0,
            "recovery keeps the adjacency"
        );
        self.index();
        before - k
    }

    /// Whether mesh point `x` is a corner of some surface triangle.
    fn is_surface_point(&self, x: u32) -> bool {
        self.surf_start[x as usize] != self.surf_start[x as usize + 1]
    }

    /// Flood-fill region labels from the surface's side labels and remove region 0; sets
    /// [`Self::is_present`] for the output. Returns (tets removed, regions with conflicting
    /// votes).
    fn relabel(&mut self, deferred: bool) -> (usize, usize, usize) {
        // Which tet faces are surface triangles, looked up in parallel: one bit a face (a byte a
        // tet, not 16), the few walls looked up again when met.
        let view = self.view();
        let walls: Vec<u8> = (0..self.mesh.tets.len())
            .into_par_iter()
            .with_min_len(4096)
            .map(|t| {
                let on = view.faces_on_surface(t);
                (0..4).filter(|&f| on[f].is_some()).map(|f| 1u8 << f).sum()
            })
            .collect();
        let wall = |r: &Self, t: usize, f: usize| -> u32 {
            if walls[t] & (1 << f) == 0 {
                return NO_NEIGHBOR;
            }
            r.face_tri
                .get(sorted3(r.mesh.face(t, f)))
                .unwrap_or(NO_NEIGHBOR)
        };
        let n = self.mesh.tets.len();
        let mut comp = vec![u32::MAX; n];
        let mut conflicts = 0;
        let (mut locator, mut tally, mut tested) = (None, Transitions::default(), 0);
        let mut stack = Vec::new();
        let mut members = Vec::new();
        for seed in 0..n {
            if comp[seed] != u32::MAX {
                continue;
            }
            comp[seed] = seed as u32;
            stack.push(seed as u32);
            members.clear();
            let mut vote: Option<u32> = None;
            let mut conflict = false;
            while let Some(t) = stack.pop() {
                members.push(t);
                for f in 0..4 {
                    let s = wall(self, t as usize, f);
                    if s != NO_NEIGHBOR
                        && let Some(v) = self.tri_map[s as usize]
                    {
                        let g = self.mesh.face(t as usize, f);
                        let behind = same_cyclic(g, v);
                        let sides = self.surface.sides[s as usize];
                        let l = if behind { sides[0] } else { sides[1] };
                        match vote {
                            None => vote = Some(l),
                            Some(x) if x != l => conflict = true,
                            _ => {}
                        }
                        continue;
                    }
                    let nb = self.mesh.neighbors[t as usize][f];
                    if nb != NO_NEIGHBOR && comp[nb as usize] == u32::MAX {
                        comp[nb as usize] = seed as u32;
                        stack.push(nb);
                    }
                }
            }
            if conflict {
                conflicts += 1;
            }
            match vote {
                Some(l) if !conflict => {
                    for &t in &members {
                        self.mesh.labels[t as usize] = l;
                    }
                }
                // Labels the pipeline left to the flood fill: a centroid test.
                _ if deferred => {
                    let locator = locator.get_or_insert_with(|| RegionLocator::new(self.surface));
                    for &t in &members {
                        let v = self.mesh.tets[t as usize];
                        let on = v.iter().filter(|&&x| self.is_surface_point(x)).count();
                        if on >= 2 {
                            let c = v.map(|x| self.mesh.points[x as usize]);
                            self.mesh.labels[t as usize] = centroid_region(c, locator, &mut tally);
                            tested += 1;
                        }
                    }
                }
                _ => {}
            }
        }
        drop(comp);
        drop(stack);
        drop(members);
        // The triangles present in the output: faces of the tets kept.
        self.is_present.fill(false);
        for (t, &bits) in walls.iter().enumerate() {
            if bits != 0 && (!self.opts.remove_outside || self.mesh.labels[t] != 0) {
                for f in 0..4 {
                    let s = wall(self, t, f);
                    if s != NO_NEIGHBOR {
                        self.mark_chain(s);
                    }
                }
            }
        }
        drop(walls);
        if !self.opts.remove_outside {
            return (0, conflicts, tested);
        }
        let removed = self.remove_outside();
        (removed, conflicts, tested)
    }

    /// Remove the tets labelled 0.
    fn remove_outside(&mut self) -> usize {
        self.retain_tets(|r, t| r.mesh.labels[t] != 0)
    }
}

/// Search nodes a failed search visited (none for an input error).
fn nodes_of(e: &SearchError) -> u64 {
    match *e {
        SearchError::NoFill { nodes_visited } | SearchError::Budget { nodes_visited } => {
            nodes_visited
        }
        _ => 0,
    }
}

/// Same three vertices in the same cyclic order.
fn same_cyclic(a: [u32; 3], b: [u32; 3]) -> bool {
    (0..3).any(|r| a == [b[r], b[(r + 1) % 3], b[(r + 2) % 3]])
}

/// Whether the mesh boundary is a closed surface that is convex at every edge (exact): then it
/// bounds the convex hull of its points. A mesh without boundary faces is not convex.
fn boundary_is_convex(mesh: &TetMesh) -> bool {
    let faces: Vec<[u32; 3]> = mesh
        .boundary_faces()
        .map(|(t, f)| mesh.face(t, f))
        .collect();
    if faces.is_empty() {
        return false;
    }
    let mut edges: FxHashMap<(u32, u32), u32> = FxHashMap::default();
    for (i, f) in faces.iter().enumerate() {
        for k in 0..3 {
            edges.insert((f[k], f[(k + 1) % 3]), i as u32);
        }
    }
    for f in &faces {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            let Some(&j) = edges.get(&(b, a)) else {
                return false;
            };
            let g = faces[j as usize];
            let Some(&d) = g.iter().find(|&&x| x != a && x != b) else {
                return false;
            };
            let p = f.map(|x| mesh.points[x as usize]);
            if orient3d(p[0], p[1], p[2], mesh.points[d as usize]) == Sign::Positive {
                return false;
            }
        }
    }
    true
}
