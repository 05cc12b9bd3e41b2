//! Surface validation: is a [`SurfaceMesh`] a valid input for meshing?
//!
//! [`validate_surface`] runs the checks below in this order and stops at the first kind of
//! problem found, returning a [`SurfaceError`] that gives the number of offending items and the
//! first few (lowest indices first) with triangle indices and coordinates:
//!
//! 1. sizes and indices: no triangles, `sides` of the wrong length, point indices out of range
//!    ([`SurfaceError::IndexOutOfRange`]), non-finite or out-of-range coordinates ([`SurfaceError::NonFinite`]),
//!    the same region on both sides of a triangle ([`SurfaceError::SameRegionBothSides`]);
//! 2. degenerate triangles: a repeated vertex or collinear corners, decided exactly
//!    ([`SurfaceError::Degenerate`]);
//! 3. duplicate triangles: the same vertex set twice ([`SurfaceError::Duplicate`]);
//! 4. per region `r` (every non-zero label), on the triangles with `r` on one side, each taken in
//!    the orientation that has `r` behind it (triangles with `r` in front count reversed): every
//!    edge must be used by exactly two of them ([`SurfaceError::NotClosed`] for one,
//!    [`SurfaceError::NonManifoldEdge`] for more), the triangles around each vertex must form one
//!    fan ([`SurfaceError::NonManifoldVertex`]) and the two triangles of each edge must traverse
//!    it in opposite directions ([`SurfaceError::Flipped`], which lists the triangles to flip,
//!    or [`SurfaceError::NonOrientable`]);
//! 5. self-intersection: any two triangles that meet other than in their shared vertex or shared
//!    edge, decided exactly by [`crate::geom::intersect::tri_tri`] on the candidate pairs of a
//!    bounding-volume hierarchy, in parallel; the lowest-index pairs are reported
//!    ([`SurfaceError::SelfIntersection`]);
//! 6. orientation of the shells (see below): inside-out closed surfaces are reversed in place
//!    (reported as [`ValidationReport::flipped_inward`]), or an error if that is switched off
//!    ([`SurfaceError::Inward`]) or the labels contradict each other
//!    ([`SurfaceError::LabelsContradictGeometry`]).
//!
//! Everything combinatorial is decided by the exact predicates (through
//! [`crate::geom::intersect`]); floating point is used for bounding boxes and for the volume
//! measure below.
//!
//! # Regions, shells and the inward check
//!
//! For a region `r`, its boundary triangles (oriented with `r` behind) form closed, oriented
//! 2-manifolds once the checks of step 4 pass; their connected components are the *shells* of
//! `r`. A region may have several shells: separate bodies, and cavities. The *nesting depth* of a
//! shell is the number of other shells of the same region that enclose it, decided exactly by
//! ray parity with [`crate::geom::intersect::seg_tri`] (a ray that touches an edge or a vertex is
//! replaced by another one). Walking in from infinity every shell toggles between outside and
//! inside `r`, so with correct orientation shells at even depth enclose positive volume and
//! shells at odd depth (cavities) negative volume.
//!
//! The signed volume of a shell is a floating-point sum of tet volumes from the shell's centroid.
//! That is safe for a *sign*: by then the shell is a closed, embedded surface of non-degenerate
//! triangles, so it bounds a solid of clearly non-zero volume (of order `size² · thickness`),
//! while the rounding error of the sum is of order `n · ε · size³` for `n` triangles; only a
//! shell thinner than about `n · 10⁻¹⁶` of its size could be misjudged. (Without the
//! self-intersection check, nesting and volumes are best effort.)
//!
//! The unit of repair is a *cluster* of shells: shells linked through two-sided triangles (an
//! interface `[r, q]` belongs to a shell of `r` and a shell of `q`). Reversing all triangles of
//! a cluster (vertex order only, labels kept) reverses exactly its shells, for every region. If
//! all shells of a cluster contradict their depth, it was written inside out and is reversed; if
//! only some do, no reversal can fix it, the labels are wrong, and
//! [`SurfaceError::LabelsContradictGeometry`] is returned. (Labels are checked region by region:
//! a cell claimed by two different regions through shells that share no triangle, say an
//! inner `[1, 0]` surface inside region 2, is not detected.)
//! A single closed outward surface with sides `[1, 0]` is one shell of region 1 at depth 0; the
//! same surface written inward is reversed and reported.

use std::fmt;

use rayon::prelude::*;

use crate::geom::intersect::{SegPart, SegTri, is_degenerate, meet_improperly, seg_tri};
use crate::mesh::dsu::Dsu;
use crate::mesh::surface::SurfaceMesh;

type P3 = [f64; 3];
type Aabb = [[f64; 3]; 2];

/// Marks a half-edge whose neighbour traverses the edge in the same direction.
const SAME_DIR: u32 = 1 << 31;
const NONE: u32 = u32::MAX;

/// What [`validate_surface`] does besides the always-on checks.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ValidateOptions {
    /// Look for self-intersections (the most expensive check). Default `true`.
    pub self_intersections: bool,
    /// Reverse components that are inside out (and say so in the report) instead of failing
    /// with [`SurfaceError::Inward`]. Default `true`.
    pub fix_inward: bool,
    /// How many offending items an error lists. Default 5.
    pub max_examples: usize,
}

impl Default for ValidateOptions {
    fn default() -> Self {
        ValidateOptions {
            self_intersections: true,
            fix_inward: true,
            max_examples: 5,
        }
    }
}

/// What a valid surface looks like.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ValidationReport {
    /// Number of points (including unused ones).
    pub n_points: usize,
    /// Number of points used by some triangle.
    pub n_used_points: usize,
    /// Number of triangles.
    pub n_triangles: usize,
    /// Number of distinct edges.
    pub n_edges: usize,
    /// One entry per non-zero region label, sorted by label.
    pub regions: Vec<RegionReport>,
    /// Number of connected components of the whole surface (through shared edges).
    pub n_components: usize,
    /// The components, ordered by their lowest triangle index.
    pub components: Vec<ComponentReport>,
    /// Whether some component was inside out and has been reversed in place.
    pub flipped_inward: bool,
    /// How many triangles were reversed.
    pub n_flipped_triangles: usize,
    /// Whether self-intersections were looked for ([`ValidateOptions::self_intersections`]).
    pub self_intersections_checked: bool,
}

/// One region of a valid surface.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RegionReport {
    /// The region label.
    pub label: u32,
    /// Number of triangles with this region on one side.
    pub n_triangles: usize,
    /// The enclosed volume (sum of the shells' signed volumes; positive).
    pub volume: f64,
    /// The closed shells bounding the region, ordered by their lowest triangle index.
    pub shells: Vec<ShellReport>,
}

/// One shell (connected closed boundary surface) of a region.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ShellReport {
    /// Index into [`ValidationReport::components`] of the component holding the shell.
    pub component: usize,
    /// The lowest triangle index in the shell.
    pub first_triangle: u32,
    /// Number of triangles.
    pub n_triangles: usize,
    /// Number of vertices.
    pub n_vertices: usize,
    /// Euler characteristic `V − E + F`.
    pub euler_characteristic: i64,
    /// Genus `(2 − χ) / 2` (number of handles).
    pub genus: i64,
    /// Number of other shells of the region enclosing this one (odd: a cavity).
    pub depth: usize,
    /// Signed volume with the region behind the triangles (negative for cavities).
    pub volume: f64,
}

/// One connected component of the whole surface.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ComponentReport {
    /// The lowest triangle index in the component.
    pub first_triangle: u32,
    /// Number of triangles.
    pub n_triangles: usize,
    /// Number of vertices.
    pub n_vertices: usize,
    /// Number of edges.
    pub n_edges: usize,
    /// Euler characteristic `V − E + F`.
    pub euler_characteristic: i64,
    /// Genus `(2 − χ) / 2` when the component is a closed 2-manifold (every edge in exactly two
    /// of its triangles), `None` when interfaces between regions meet along its edges.
    pub genus: Option<i64>,
    /// The non-zero region labels on its triangles, sorted.
    pub regions: Vec<u32>,
    /// Whether some of its triangles were inside out and have been reversed.
    pub flipped: bool,
}

impl fmt::Display for ValidationReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} triangles, {} points, {} edges, {} component{}",
            self.n_triangles,
            self.n_used_points,
            self.n_edges,
            self.n_components,
            if self.n_components == 1 { "" } else { "s" }
        )?;
        let genera: Vec<String> = self
            .components
            .iter()
            .map(|c| c.genus.map_or("-".to_string(), |g| g.to_string()))
            .collect();
        write!(f, " (genus {})", genera.join(", "))?;
        for r in &self.regions {
            write!(
                f,
                "; region {}: {} triangles, {} shell{}, volume {:.6e}",
                r.label,
                r.n_triangles,
                r.shells.len(),
                if r.shells.len() == 1 { "" } else { "s" },
                r.volume
            )?;
        }
        if self.flipped_inward {
            write!(
                f,
                "; {} inward-facing triangles reversed",
                self.n_flipped_triangles
            )?;
        }
        Ok(())
    }
}

// -------------------------------------------------------------------------------------------
// Errors
// -------------------------------------------------------------------------------------------

/// A point for messages: `(x, y, z)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pt(pub [f64; 3]);

impl fmt::Display for Pt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}, {}, {})", self.0[0], self.0[1], self.0[2])
    }
}

/// A triangle as error messages show it.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleInfo {
    /// Triangle index.
    pub index: u32,
    /// Its point indices.
    pub vertices: [u32; 3],
    /// Its corner coordinates.
    pub corners: [[f64; 3]; 3],
}

impl TriangleInfo {
    fn new(s: &SurfaceMesh, t: usize) -> TriangleInfo {
        TriangleInfo {
            index: t as u32,
            vertices: s.triangles[t],
            corners: s.corners(t),
        }
    }
}

impl fmt::Display for TriangleInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [a, b, c] = self.corners;
        write!(
            f,
            "triangle {} [{}, {}, {}]",
            self.index,
            Pt(a),
            Pt(b),
            Pt(c)
        )
    }
}

/// An edge as error messages show it.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeInfo {
    /// Its two point indices, smaller first.
    pub edge: [u32; 2],
    /// The region whose boundary is at fault (`None` when the surface has a single region).
    pub region: Option<u32>,
    /// The triangles of that region on the edge (in full for a hole; the first few otherwise).
    pub triangles: Vec<TriangleInfo>,
    /// How many triangles of that region use the edge.
    pub n_triangles: usize,
}

impl fmt::Display for EdgeInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "edge ({}, {})", self.edge[0], self.edge[1])?;
        if self.n_triangles == 1 {
            write!(f, " of {}", self.triangles[0])?;
        } else {
            let ids: Vec<String> = self.triangles.iter().map(|t| t.index.to_string()).collect();
            let more = if self.n_triangles > ids.len() {
                ", …"
            } else {
                ""
            };
            let ends = if let Some(t) = self.triangles.first() {
                let i = t
                    .vertices
                    .iter()
                    .position(|&v| v == self.edge[0])
                    .unwrap_or(0);
                let j = t
                    .vertices
                    .iter()
                    .position(|&v| v == self.edge[1])
                    .unwrap_or(0);
                format!(" {}–{}", Pt(t.corners[i]), Pt(t.corners[j]))
            } else {
                String::new()
            };
            write!(
                f,
                "{ends} in {} triangles ({}{more})",
                self.n_triangles,
                ids.join(", ")
            )?;
        }
        if let Some(r) = self.region {
            write!(f, " of region {r}")?;
        }
        Ok(())
    }
}

/// A non-manifold vertex as error messages show it.
#[derive(Debug, Clone, PartialEq)]
pub struct VertexInfo {
    /// Point index.
    pub vertex: u32,
    /// Its coordinates.
    pub point: [f64; 3],
    /// The region whose boundary is at fault (`None` when the surface has a single region).
    pub region: Option<u32>,
    /// Number of separate fans of triangles around it.
    pub fans: usize,
    /// The lowest-index triangle of each fan (at most a few).
    pub triangles: Vec<u32>,
}

impl fmt::Display for VertexInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let ids: Vec<String> = self.triangles.iter().map(|t| t.to_string()).collect();
        write!(
            f,
            "vertex {} {} where {} separate fans of triangles meet (triangles {})",
            self.vertex,
            Pt(self.point),
            self.fans,
            ids.join(", ")
        )?;
        if let Some(r) = self.region {
            write!(f, " of region {r}")?;
        }
        Ok(())
    }
}

/// A pair of triangles as error messages show it.
#[derive(Debug, Clone, PartialEq)]
pub struct PairInfo(pub TriangleInfo, pub TriangleInfo);

impl fmt::Display for PairInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} and {}", self.0, self.1)
    }
}

/// A shell as error messages show it.
#[derive(Debug, Clone, PartialEq)]
pub struct ShellInfo {
    /// The region it bounds.
    pub region: u32,
    /// Number of triangles.
    pub n_triangles: usize,
    /// Nesting depth among the region's shells.
    pub depth: usize,
    /// Signed volume with the region behind its triangles.
    pub volume: f64,
    /// Its lowest-index triangle.
    pub triangle: TriangleInfo,
}

impl fmt::Display for ShellInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "shell of region {} with {} triangles (nesting depth {}, signed volume {:.6e}) \
             containing {}",
            self.region, self.n_triangles, self.depth, self.volume, self.triangle
        )
    }
}

fn list<T: fmt::Display>(items: &[T]) -> String {
    items
        .iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join("; ")
}

fn plural(n: usize, word: &str) -> String {
    if n == 1 {
        return format!("{n} {word}");
    }
    match word {
        "vertex" => format!("{n} vertices"),
        "pair of triangles" => format!("{n} pairs of triangles"),
        "closed surface is" => format!("{n} closed surfaces are"),
        w => format!("{n} {w}s"),
    }
}

fn unwelded_note(n: usize) -> String {
    if n == 0 {
        String::new()
    } else {
        format!(
            "; note: {} share coordinates with another point (weld them first)",
            plural(n, "used point")
        )
    }
}

fn index_list(items: &[(u32, [u32; 3])]) -> String {
    items
        .iter()
        .map(|(t, v)| format!("triangle {t} ({}, {}, {})", v[0], v[1], v[2]))
        .collect::<Vec<_>>()
        .join("; ")
}

fn point_list(items: &[(u32, [f64; 3])]) -> String {
    items
        .iter()
        .map(|(i, p)| format!("point {i} {}", Pt(*p)))
        .collect::<Vec<_>>()
        .join("; ")
}

fn sides_list(items: &[(u32, [u32; 2])]) -> String {
    items
        .iter()
        .map(|(t, s)| format!("triangle {t} [{}, {}]", s[0], s[1]))
        .collect::<Vec<_>>()
        .join("; ")
}

fn flip_list(items: &[TriangleInfo], n: usize) -> String {
    let more = if n > items.len() { "; …" } else { "" };
    format!("{}{more}", list(items))
}

/// Why a surface is not a valid meshing input. Each variant gives the number of offending items
/// (`count`) and the first few (`first`, lowest indices first).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SurfaceError {
    /// No triangles.
    #[error("empty surface: no triangles")]
    Empty,
    /// Too many triangles for 32-bit half-edge indices.
    #[error("too many triangles: {0} (at most 300,000,000)")]
    TooLarge(usize),
    /// `sides` and `triangles` differ in length.
    #[error("{sides} side-label pairs for {triangles} triangles")]
    SidesLength {
        /// Number of triangles.
        triangles: usize,
        /// Number of side-label pairs.
        sides: usize,
    },
    /// Triangles referring to points that do not exist.
    #[error(
        "point index out of range: {} refer to points beyond the {n_points} points; first: {}",
        plural(*.count, "triangle"), index_list(.first)
    )]
    IndexOutOfRange {
        /// Number of offending triangles.
        count: usize,
        /// Number of points.
        n_points: usize,
        /// Triangle index and its point indices.
        first: Vec<(u32, [u32; 3])>,
    },
    /// Points with NaN, infinite, or out-of-range coordinates (outside the exact range of the
    /// predicates, [`crate::geom::predicates::in_exact_range`]).
    #[error(
        "non-finite or out-of-range coordinates (exact predicates need 0 or a magnitude between \
         7.0e-46 and 1e50): {}; first: {}",
        plural(*.count, "point"),
        point_list(.first)
    )]
    NonFinite {
        /// Number of offending points.
        count: usize,
        /// Point index and coordinates.
        first: Vec<(u32, [f64; 3])>,
    },
    /// Triangles with the same region on both sides (or 0 on both).
    #[error(
        "invalid side labels: {} have the same region on both sides; first: {}",
        plural(*.count, "triangle"), sides_list(.first)
    )]
    SameRegionBothSides {
        /// Number of offending triangles.
        count: usize,
        /// Triangle index and its `[back, front]` labels.
        first: Vec<(u32, [u32; 2])>,
    },
    /// Zero-area triangles: a repeated vertex or collinear corners (decided exactly).
    #[error(
        "degenerate (zero-area) triangles: {}; first: {}",
        plural(*.count, "triangle"), list(.first)
    )]
    Degenerate {
        /// Number of degenerate triangles.
        count: usize,
        /// The first ones.
        first: Vec<TriangleInfo>,
    },
    /// Triangles with the same vertex set as an earlier triangle.
    #[error(
        "duplicate triangles: {} repeat the vertices of an earlier one; first: {}",
        plural(*.count, "triangle"), list(.first)
    )]
    Duplicate {
        /// Number of triangles that repeat an earlier one.
        count: usize,
        /// (earlier triangle, duplicate), by duplicate index.
        first: Vec<PairInfo>,
    },
    /// Edges used by only one triangle of a region.
    #[error(
        "not closed: {} (a hole); first: {}{}",
        plural(*.count, "boundary edge"), list(.first), unwelded_note(*.unwelded_points)
    )]
    NotClosed {
        /// Number of boundary edges.
        count: usize,
        /// The first ones.
        first: Vec<EdgeInfo>,
        /// Number of used points with the same coordinates as another used point (an unwelded
        /// surface, e.g. STL read without merging points, has only boundary edges).
        unwelded_points: usize,
    },
    /// Edges used by more than two triangles of a region.
    #[error(
        "non-manifold edges: {} used by more than two triangles of one region; first: {}",
        plural(*.count, "edge"), list(.first)
    )]
    NonManifoldEdge {
        /// Number of offending edges.
        count: usize,
        /// The first ones.
        first: Vec<EdgeInfo>,
    },
    /// Vertices where the triangles of a region form more than one fan.
    #[error(
        "non-manifold vertices: {} where separate sheets of one region meet; first: {}",
        plural(*.count, "vertex"), list(.first)
    )]
    NonManifoldVertex {
        /// Number of offending vertices (per region).
        count: usize,
        /// The first ones.
        first: Vec<VertexInfo>,
    },
    /// Triangles whose orientation disagrees with their neighbours'.
    #[error(
        "inconsistent orientation: {} traversed in the same direction by both of their \
         triangles; flip {}: {}",
        plural(*.n_edges, "edge"), plural(*.count, "triangle"), flip_list(.first, *.count)
    )]
    Flipped {
        /// Number of triangles to flip (the minority orientation of each shell).
        count: usize,
        /// Number of edges traversed twice in the same direction.
        n_edges: usize,
        /// The first triangles to flip.
        first: Vec<TriangleInfo>,
        /// All triangles to flip (reverse their vertex order, keep their labels), sorted.
        to_flip: Vec<u32>,
    },
    /// Closed shells that cannot be oriented (Klein-bottle-like).
    #[error(
        "non-orientable surface: {} cannot be oriented consistently; first: shell containing {}",
        plural(*.count, "shell"), list(.first)
    )]
    NonOrientable {
        /// Number of non-orientable shells.
        count: usize,
        /// A triangle of each of the first ones.
        first: Vec<TriangleInfo>,
    },
    /// Pairs of triangles that meet other than in a shared vertex or a shared edge.
    #[error(
        "self-intersection: {} intersect other than at a shared vertex or edge; first: {}",
        plural(*.count, "pair of triangles"),
        list(.first)
    )]
    SelfIntersection {
        /// Number of intersecting pairs.
        count: usize,
        /// The lowest-index pairs.
        first: Vec<PairInfo>,
    },
    /// Inside-out closed surfaces (clusters of shells, see the module docs), with
    /// [`ValidateOptions::fix_inward`] off.
    #[error(
        "inward-facing surface: {} inside out (normals point into the region); first: {}",
        plural(*.count, "closed surface is"),
        list(.first)
    )]
    Inward {
        /// Number of inside-out clusters of shells.
        count: usize,
        /// A shell of each of the first ones.
        first: Vec<ShellInfo>,
    },
    /// Shells whose orientation contradicts their nesting while other shells of the same
    /// cluster agree: reversing the cluster cannot fix it, the labels are wrong.
    #[error(
        "region labels contradict the geometry: {} facing the wrong way for {} nesting depth, \
         linked through interface triangles to shells facing the right way; first: {}",
        plural(*.count, "shell"), if *.count == 1 { "its" } else { "their" }, list(.first)
    )]
    LabelsContradictGeometry {
        /// Number of wrong-facing shells in mixed components.
        count: usize,
        /// The first ones.
        first: Vec<ShellInfo>,
    },
}

impl SurfaceError {
    /// The indices of the offending triangles the error lists (its first examples, in order,
    /// without repeats; empty when it names points or no element).
    pub fn triangles(&self) -> Vec<u32> {
        use SurfaceError::*;
        let mut out: Vec<u32> = match self {
            Empty | TooLarge(_) | SidesLength { .. } | NonFinite { .. } => Vec::new(),
            IndexOutOfRange { first, .. } => first.iter().map(|(t, _)| *t).collect(),
            SameRegionBothSides { first, .. } => first.iter().map(|(t, _)| *t).collect(),
            Degenerate { first, .. } | Flipped { first, .. } | NonOrientable { first, .. } => {
                first.iter().map(|t| t.index).collect()
            }
            Duplicate { first, .. } | SelfIntersection { first, .. } => {
                first.iter().flat_map(|p| [p.0.index, p.1.index]).collect()
            }
            NotClosed { first, .. } | NonManifoldEdge { first, .. } => first
                .iter()
                .flat_map(|e| e.triangles.iter().map(|t| t.index))
                .collect(),
            NonManifoldVertex { first, .. } => first
                .iter()
                .flat_map(|v| v.triangles.iter().copied())
                .collect(),
            Inward { first, .. } | LabelsContradictGeometry { first, .. } => {
                first.iter().map(|s| s.triangle.index).collect()
            }
        };
        let mut seen = rustc_hash::FxHashSet::default();
        out.retain(|t| seen.insert(*t));
        out
    }
}

// -------------------------------------------------------------------------------------------
// Small helpers
// -------------------------------------------------------------------------------------------

fn tri_box(c: &[P3; 3]) -> Aabb {
    let mut b = [c[0], c[0]];
    for p in &c[1..] {
        for i in 0..3 {
            b[0][i] = b[0][i].min(p[i]);
            b[1][i] = b[1][i].max(p[i]);
        }
    }
    b
}

#[inline]
fn boxes_overlap(a: &Aabb, b: &Aabb) -> bool {
    (0..3).all(|i| a[0][i] <= b[1][i] && b[0][i] <= a[1][i])
}

fn box_union(a: &Aabb, b: &Aabb) -> Aabb {
    let mut r = *a;
    for i in 0..3 {
        r[0][i] = r[0][i].min(b[0][i]);
        r[1][i] = r[1][i].max(b[1][i]);
    }
    r
}

fn box_contains(outer: &Aabb, inner: &Aabb) -> bool {
    (0..3).all(|i| outer[0][i] <= inner[0][i] && inner[1][i] <= outer[1][i])
}

/// The corners of region-side `rs = 2t + s` in the orientation that has its region behind.
#[inline]
fn rs_vertices(s: &SurfaceMesh, rs: u32) -> [u32; 3] {
    let v = s.triangles[(rs / 2) as usize];
    if rs.is_multiple_of(2) {
        v
    } else {
        [v[0], v[2], v[1]]
    }
}

// -------------------------------------------------------------------------------------------
// The validator
// -------------------------------------------------------------------------------------------

/// Step 5 of [`validate_surface`] alone: any two triangles that meet other than in their
/// shared vertex or edge ([`SurfaceError::SelfIntersection`], listing up to `max_examples`
/// pairs). Labels and orientation play no part, so it also serves surfaces whose side labels
/// are not known yet.
pub fn check_self_intersections(s: &SurfaceMesh, max_examples: usize) -> Result<(), SurfaceError> {
    let (count, pairs) = self_intersections(s, max_examples);
    if count == 0 {
        return Ok(());
    }
    Err(SurfaceError::SelfIntersection {
        count,
        first: pairs
            .iter()
            .map(|&(a, b)| {
                PairInfo(
                    TriangleInfo::new(s, a as usize),
                    TriangleInfo::new(s, b as usize),
                )
            })
            .collect(),
    })
}

/// Validate a surface for meshing, reversing inside-out components in place.
///
/// See the [module documentation](self) for the checks, their order and how regions, shells and
/// orientation are handled. On success the report describes the surface; the only change made
/// to `s` is the reversal of inside-out components (vertex order reversed, labels kept), reported
/// by [`ValidationReport::flipped_inward`]. Deterministic for a given input, whatever the
/// number of threads.
pub fn validate_surface(
    s: &mut SurfaceMesh,
    opts: &ValidateOptions,
) -> Result<ValidationReport, SurfaceError> {
    let k = opts.max_examples;
    let nt = s.triangles.len();
    let np = s.points.len();
    if nt == 0 {
        return Err(SurfaceError::Empty);
    }
    if nt > 300_000_000 {
        return Err(SurfaceError::TooLarge(nt));
    }
    if s.sides.len() != nt {
        return Err(SurfaceError::SidesLength {
            triangles: nt,
            sides: s.sides.len(),
        });
    }

    // 1. Indices, coordinates, labels.
    let bad: Vec<u32> = (0..nt as u32)
        .into_par_iter()
        .filter(|&t| s.triangles[t as usize].iter().any(|&v| v as usize >= np))
        .collect();
    if !bad.is_empty() {
        return Err(SurfaceError::IndexOutOfRange {
            count: bad.len(),
            n_points: np,
            first: bad
                .iter()
                .take(k)
                .map(|&t| (t, s.triangles[t as usize]))
                .collect(),
        });
    }
    let bad: Vec<u32> = (0..np as u32)
        .into_par_iter()
        .filter(|&i| {
            s.points[i as usize]
                .iter()
                .any(|&c| !crate::geom::predicates::in_exact_range(c))
        })
        .collect();
    if !bad.is_empty() {
        return Err(SurfaceError::NonFinite {
            count: bad.len(),
            first: bad
                .iter()
                .take(k)
                .map(|&i| (i, s.points[i as usize]))
                .collect(),
        });
    }
    let bad: Vec<u32> = (0..nt as u32)
        .filter(|&t| s.sides[t as usize][0] == s.sides[t as usize][1])
        .collect();
    if !bad.is_empty() {
        return Err(SurfaceError::SameRegionBothSides {
            count: bad.len(),
            first: bad
                .iter()
                .take(k)
                .map(|&t| (t, s.sides[t as usize]))
                .collect(),
        });
    }

    // 2. Degenerate triangles.
    let bad: Vec<u32> = (0..nt as u32)
        .into_par_iter()
        .filter(|&t| {
            let v = s.triangles[t as usize];
            v[0] == v[1] || v[1] == v[2] || v[0] == v[2] || is_degenerate(&s.corners(t as usize))
        })
        .collect();
    if !bad.is_empty() {
        return Err(SurfaceError::Degenerate {
            count: bad.len(),
            first: bad
                .iter()
                .take(k)
                .map(|&t| TriangleInfo::new(s, t as usize))
                .collect(),
        });
    }

    // 3. Duplicate triangles.
    {
        let mut keys: Vec<([u32; 3], u32)> = s
            .triangles
            .par_iter()
            .enumerate()
            .map(|(t, v)| {
                let mut v = *v;
                v.sort_unstable();
                (v, t as u32)
            })
            .collect();
        keys.par_sort_unstable();
        let mut dups: Vec<(u32, u32)> = Vec::new();
        let mut i = 0;
        while i < keys.len() {
            let mut j = i + 1;
            while j < keys.len() && keys[j].0 == keys[i].0 {
                dups.push((keys[j].1, keys[i].1));
                j += 1;
            }
            i = j;
        }
        if !dups.is_empty() {
            dups.sort_unstable();
            return Err(SurfaceError::Duplicate {
                count: dups.len(),
                first: dups
                    .iter()
                    .take(k)
                    .map(|&(d, e)| {
                        PairInfo(
                            TriangleInfo::new(s, e as usize),
                            TriangleInfo::new(s, d as usize),
                        )
                    })
                    .collect(),
            });
        }
    }

    // 4. Edges, per region.
    let multi = s.regions().len() > 1;
    let edges = EdgeTable::build(s);
    let ec = edges.check_regions(s, multi, k);
    if ec.n_holes > 0 {
        let unwelded = unwelded_points(s);
        return Err(SurfaceError::NotClosed {
            count: ec.n_holes,
            first: ec.holes,
            unwelded_points: unwelded,
        });
    }
    if ec.n_nonmanifold > 0 {
        return Err(SurfaceError::NonManifoldEdge {
            count: ec.n_nonmanifold,
            first: ec.nonmanifold,
        });
    }
    let nbr = ec.nbr;
    check_vertex_fans(s, &nbr, multi, k)?;
    let shells = Shells::build(s, &nbr);
    if !shells.non_orientable.is_empty() {
        return Err(SurfaceError::NonOrientable {
            count: shells.non_orientable.len(),
            first: shells
                .non_orientable
                .iter()
                .take(k)
                .map(|&sh| TriangleInfo::new(s, (shells.members(sh)[0] / 2) as usize))
                .collect(),
        });
    }
    if ec.n_inconsistent > 0 {
        let to_flip = shells.minority_triangles();
        return Err(SurfaceError::Flipped {
            count: to_flip.len(),
            n_edges: ec.n_inconsistent,
            first: to_flip
                .iter()
                .take(k)
                .map(|&t| TriangleInfo::new(s, t as usize))
                .collect(),
            to_flip,
        });
    }

    // 5. Self-intersections.
    if opts.self_intersections {
        check_self_intersections(s, k)?;
    }

    // 6. Components, shell nesting and orientation.
    let comps = Components::build(s, &edges);
    let n_shells = shells.n_shells();
    let mut vol: Vec<f64> = (0..n_shells)
        .map(|sh| shell_volume(s, shells.members(sh)))
        .collect();
    let boxes: Vec<Aabb> = (0..n_shells)
        .map(|sh| shell_box(s, shells.members(sh)))
        .collect();
    // Nesting depth: containment candidates from a BVH over the shells' boxes; a shell's
    // triangle BVH is built once, when first needed.
    let mut depth = vec![0usize; n_shells];
    if n_shells > 1 {
        let shell_bvh = Bvh::build(&boxes);
        let mut tri_bvh: Vec<Option<Bvh>> = (0..n_shells).map(|_| None).collect();
        let mut stack = Vec::new();
        let mut cands = Vec::new();
        for a in 0..n_shells {
            cands.clear();
            shell_bvh.query(0, &boxes[a], &mut stack, |pos| {
                cands.push(shell_bvh.order[pos as usize] as usize)
            });
            cands.sort_unstable();
            let p = s.points[s.triangles[(shells.members(a)[0] / 2) as usize][0] as usize];
            for &b in &cands {
                if b == a
                    || shells.label[a] != shells.label[b]
                    || !box_contains(&boxes[b], &boxes[a])
                {
                    continue;
                }
                let m = shells.members(b);
                let bvh = tri_bvh[b].get_or_insert_with(|| {
                    let bx: Vec<Aabb> = m
                        .iter()
                        .map(|&rs| tri_box(&s.corners((rs / 2) as usize)))
                        .collect();
                    Bvh::build(&bx)
                });
                if point_inside_shell(s, m, bvh, &boxes[b], p) {
                    depth[a] += 1;
                }
            }
        }
    }
    let shell_comp: Vec<usize> = (0..n_shells)
        .map(|sh| comps.of_triangle[(shells.members(sh)[0] / 2) as usize] as usize)
        .collect();
    let wrong: Vec<bool> = (0..n_shells)
        .map(|sh| {
            if depth[sh].is_multiple_of(2) {
                vol[sh] < 0.0
            } else {
                vol[sh] > 0.0
            }
        })
        .collect();
    let shell_info = |sh: usize, vol: &[f64]| ShellInfo {
        region: shells.label[sh],
        n_triangles: shells.members(sh).len(),
        depth: depth[sh],
        volume: vol[sh],
        triangle: TriangleInfo::new(s, (shells.members(sh)[0] / 2) as usize),
    };
    let nc = comps.n;
    // Units of repair: shells linked by two-sided triangles (reversing a triangle reverses the
    // shells on both of its sides), identified by their lowest shell.
    let unit: Vec<usize> = {
        let mut dsu = Dsu::new(n_shells);
        for t in 0..nt {
            let [a, b] = [shells.of_rs[2 * t], shells.of_rs[2 * t + 1]];
            if a != NONE && b != NONE {
                dsu.union(a, b);
            }
        }
        (0..n_shells)
            .map(|sh| dsu.find(sh as u32) as usize)
            .collect()
    };
    let mut n_wrong = vec![0usize; n_shells];
    let mut n_in = vec![0usize; n_shells];
    for (sh, &u) in unit.iter().enumerate() {
        n_in[u] += 1;
        n_wrong[u] += wrong[sh] as usize;
    }
    let mixed: Vec<usize> = (0..n_shells)
        .filter(|&sh| wrong[sh] && n_wrong[unit[sh]] < n_in[unit[sh]])
        .collect();
    if !mixed.is_empty() {
        return Err(SurfaceError::LabelsContradictGeometry {
            count: mixed.len(),
            first: mixed
                .iter()
                .take(k)
                .map(|&sh| shell_info(sh, &vol))
                .collect(),
        });
    }
    let flip_unit: Vec<bool> = (0..n_shells)
        .map(|u| n_in[u] > 0 && n_wrong[u] == n_in[u])
        .collect();
    let n_flip_units = flip_unit.iter().filter(|&&f| f).count();
    if n_flip_units > 0 && !opts.fix_inward {
        let first = (0..n_shells)
            .filter(|&sh| unit[sh] == sh && flip_unit[sh])
            .take(k)
            .map(|sh| shell_info(sh, &vol))
            .collect();
        return Err(SurfaceError::Inward {
            count: n_flip_units,
            first,
        });
    }
    let mut n_flipped = 0;
    let mut comp_flipped = vec![false; nc];
    for t in 0..nt {
        let sh = shells.of_rs[2 * t].min(shells.of_rs[2 * t + 1]);
        if flip_unit[unit[sh as usize]] {
            s.triangles[t].swap(1, 2);
            n_flipped += 1;
            comp_flipped[comps.of_triangle[t] as usize] = true;
        }
    }
    for sh in 0..n_shells {
        if flip_unit[unit[sh]] {
            vol[sh] = -vol[sh];
        }
    }

    // Report.
    let mut vmark = vec![NONE; np];
    let mut regions: Vec<RegionReport> = Vec::new();
    for label in s.regions() {
        let n_triangles = s.sides.iter().filter(|sd| sd.contains(&label)).count();
        let mut rep = RegionReport {
            label,
            n_triangles,
            volume: 0.0,
            shells: Vec::new(),
        };
        for sh in (0..n_shells).filter(|&sh| shells.label[sh] == label) {
            let m = shells.members(sh);
            let mut nv = 0usize;
            for &rs in m {
                for v in s.triangles[(rs / 2) as usize] {
                    if vmark[v as usize] != sh as u32 {
                        vmark[v as usize] = sh as u32;
                        nv += 1;
                    }
                }
            }
            let f = m.len() as i64;
            let chi = nv as i64 - 3 * f / 2 + f;
            rep.volume += vol[sh];
            rep.shells.push(ShellReport {
                component: shell_comp[sh],
                first_triangle: m[0] / 2,
                n_triangles: m.len(),
                n_vertices: nv,
                euler_characteristic: chi,
                genus: (2 - chi) / 2,
                depth: depth[sh],
                volume: vol[sh],
            });
        }
        regions.push(rep);
    }
    let components = comps.reports(s, &edges, &comp_flipped);
    let n_used_points = np - s.n_unused_points();
    Ok(ValidationReport {
        n_points: np,
        n_used_points,
        n_triangles: nt,
        n_edges: edges.n_edges(),
        regions,
        n_components: nc,
        components,
        flipped_inward: n_flipped > 0,
        n_flipped_triangles: n_flipped,
        self_intersections_checked: opts.self_intersections,
    })
}

/// Number of used points whose coordinates equal another used point's.
fn unwelded_points(s: &SurfaceMesh) -> usize {
    let mut used = vec![false; s.points.len()];
    for t in &s.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let key = super::coord_key;
    let mut keys: Vec<[u64; 3]> = (0..s.points.len())
        .filter(|&i| used[i])
        .map(|i| key(&s.points[i]))
        .collect();
    keys.par_sort_unstable();
    let mut n = 0;
    let mut i = 0;
    while i < keys.len() {
        let mut j = i + 1;
        while j < keys.len() && keys[j] == keys[i] {
            j += 1;
        }
        if j - i > 1 {
            n += j - i;
        }
        i = j;
    }
    n
}

// -------------------------------------------------------------------------------------------
// Edges
// -------------------------------------------------------------------------------------------

/// All half-edges sorted by undirected edge. Half-edge `3t + k` is edge `k` of triangle `t`
/// (opposite corner `k`), from corner `k+1` to corner `k+2`.
struct EdgeTable {
    /// `(min << 96) | (max << 64) | half-edge`, sorted.
    he: Vec<u128>,
    /// Start of each edge group in `he`, plus the end.
    start: Vec<u32>,
}

/// (lowest triangle, edge, region, triangles, number of region-sides on the edge)
type NonManifoldEdge = (u32, [u32; 2], u32, Vec<u32>, usize);

struct EdgeCheck {
    n_holes: usize,
    holes: Vec<EdgeInfo>,
    n_nonmanifold: usize,
    nonmanifold: Vec<EdgeInfo>,
    n_inconsistent: usize,
    /// For region-side half-edge `3 rs + k`: the neighbouring region-side half-edge, with
    /// [`SAME_DIR`] set when both traverse the edge in the same direction; [`NONE`] if unset.
    nbr: Vec<u32>,
}

impl EdgeTable {
    fn build(s: &SurfaceMesh) -> EdgeTable {
        let mut he: Vec<u128> = s
            .triangles
            .par_iter()
            .enumerate()
            .flat_map_iter(|(t, v)| {
                let v = *v;
                (0..3).map(move |k| {
                    let (a, b) = (v[(k + 1) % 3], v[(k + 2) % 3]);
                    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                    ((lo as u128) << 96) | ((hi as u128) << 64) | (3 * t + k) as u128
                })
            })
            .collect();
        he.par_sort_unstable();
        let mut start = Vec::with_capacity(he.len() / 2 + 1);
        for i in 0..he.len() {
            if i == 0 || (he[i] >> 64) != (he[i - 1] >> 64) {
                start.push(i as u32);
            }
        }
        start.push(he.len() as u32);
        EdgeTable { he, start }
    }

    fn n_edges(&self) -> usize {
        self.start.len() - 1
    }

    /// The half-edges of edge group `g`.
    fn group(&self, g: usize) -> impl Iterator<Item = u32> + '_ {
        self.he[self.start[g] as usize..self.start[g + 1] as usize]
            .iter()
            .map(|&x| x as u64 as u32)
    }

    fn edge(&self, g: usize) -> [u32; 2] {
        let x = self.he[self.start[g] as usize];
        [(x >> 96) as u32, (x >> 64) as u32]
    }

    fn check_regions(&self, s: &SurfaceMesh, multi: bool, k_max: usize) -> EdgeCheck {
        let nt = s.triangles.len();
        let mut out = EdgeCheck {
            n_holes: 0,
            holes: Vec::new(),
            n_nonmanifold: 0,
            nonmanifold: Vec::new(),
            n_inconsistent: 0,
            nbr: vec![NONE; 6 * nt],
        };
        let mut hole_list: Vec<(u32, [u32; 2], u32)> = Vec::new();
        let mut nm_list: Vec<NonManifoldEdge> = Vec::new();
        let mut labels: Vec<u32> = Vec::new();
        // (region-side half-edge, forward along the edge as seen with the region behind)
        let mut members: Vec<(u32, bool)> = Vec::new();
        for g in 0..self.n_edges() {
            let [e0, _] = self.edge(g);
            labels.clear();
            for h in self.group(g) {
                for l in s.sides[(h / 3) as usize] {
                    if l != 0 && !labels.contains(&l) {
                        labels.push(l);
                    }
                }
            }
            let (mut hole, mut nm, mut inc) = (false, false, false);
            for &r in &labels {
                members.clear();
                for h in self.group(g) {
                    let (t, k) = ((h / 3) as usize, (h % 3) as usize);
                    let from_lo = s.triangles[t][(k + 1) % 3] == e0;
                    for side in 0..2 {
                        if s.sides[t][side] == r {
                            let rs = (2 * t + side) as u32;
                            members.push((3 * rs + k as u32, from_lo != (side == 1)));
                        }
                    }
                }
                match members.len() {
                    1 => {
                        if !hole {
                            hole_list.push((members[0].0 / 6, self.edge(g), r));
                        }
                        hole = true;
                    }
                    2 => {
                        let (a, fa) = members[0];
                        let (b, fb) = members[1];
                        let flag = if fa == fb {
                            inc = true;
                            SAME_DIR
                        } else {
                            0
                        };
                        out.nbr[a as usize] = b | flag;
                        out.nbr[b as usize] = a | flag;
                    }
                    n if !nm => {
                        nm = true;
                        let mut ts: Vec<u32> = members.iter().map(|m| m.0 / 6).collect();
                        ts.sort_unstable();
                        ts.dedup();
                        nm_list.push((ts[0], self.edge(g), r, ts, n));
                    }
                    _ => {}
                }
            }
            // Counted per edge, whatever the number of regions at fault.
            out.n_holes += hole as usize;
            out.n_nonmanifold += nm as usize;
            out.n_inconsistent += inc as usize;
        }
        // Lowest triangle index first.
        hole_list.sort_unstable();
        nm_list.sort_unstable_by_key(|a| (a.0, a.1, a.2));
        let info = |t: u32| TriangleInfo::new(s, t as usize);
        out.holes = hole_list
            .iter()
            .take(k_max)
            .map(|&(t, e, r)| EdgeInfo {
                edge: e,
                region: multi.then_some(r),
                triangles: vec![info(t)],
                n_triangles: 1,
            })
            .collect();
        out.nonmanifold = nm_list
            .iter()
            .take(k_max)
            .map(|(_, e, r, ts, n)| EdgeInfo {
                edge: *e,
                region: multi.then_some(*r),
                triangles: ts.iter().take(6).map(|&t| info(t)).collect(),
                n_triangles: *n,
            })
            .collect();
        out
    }
}

/// Step 4b: the triangles of each region around each vertex must form a single fan. Union–find
/// over region-side corners `3 rs + i`, joining the corners of the same vertex across each
/// manifold edge; a vertex with several classes in one region is non-manifold.
fn check_vertex_fans(
    s: &SurfaceMesh,
    nbr: &[u32],
    multi: bool,
    k: usize,
) -> Result<(), SurfaceError> {
    let n = nbr.len();
    let mut dsu = Dsu::new(n);
    for (h, &x) in nbr.iter().enumerate() {
        if x == NONE {
            continue;
        }
        let h2 = (x & !SAME_DIR) as usize;
        if h2 < h {
            continue;
        }
        let (rs1, k1) = (h / 3, h % 3);
        let (rs2, _) = (h2 / 3, h2 % 3);
        let v1 = s.triangles[rs1 / 2];
        let v2 = s.triangles[rs2 / 2];
        for c in [(k1 + 1) % 3, (k1 + 2) % 3] {
            let vert = v1[c];
            let c2 = v2
                .iter()
                .position(|&w| w == vert)
                .expect("edge endpoint in both triangles");
            dsu.union((3 * rs1 + c) as u32, (3 * rs2 + c2) as u32);
        }
    }
    // Roots: one per fan. Count fans per (vertex, region).
    let mut roots: Vec<(u32, u32, u32)> = Vec::new(); // (vertex, region, corner)
    for c in 0..n as u32 {
        let rs = (c / 3) as usize;
        let label = s.sides[rs / 2][rs % 2];
        if label != 0 && dsu.find(c) == c {
            roots.push((s.triangles[rs / 2][(c % 3) as usize], label, c));
        }
    }
    roots.sort_unstable();
    let mut bad: Vec<VertexInfo> = Vec::new();
    let mut count = 0;
    let mut i = 0;
    while i < roots.len() {
        let mut j = i + 1;
        while j < roots.len() && roots[j].0 == roots[i].0 && roots[j].1 == roots[i].1 {
            j += 1;
        }
        if j - i > 1 {
            count += 1;
            if bad.len() < k {
                let (v, r, _) = roots[i];
                bad.push(VertexInfo {
                    vertex: v,
                    point: s.points[v as usize],
                    region: multi.then_some(r),
                    fans: j - i,
                    // Roots are the smallest corner of each class: their triangles are the
                    // lowest-index triangle of each fan.
                    triangles: roots[i..j].iter().take(6).map(|x| x.2 / 6).collect(),
                });
            }
        }
        i = j;
    }
    if count > 0 {
        return Err(SurfaceError::NonManifoldVertex { count, first: bad });
    }
    Ok(())
}

// -------------------------------------------------------------------------------------------
// Shells and components
// -------------------------------------------------------------------------------------------

/// The shells: connected components of the region-sides through manifold edges, each with a
/// parity per region-side (relative to its lowest region-side) from the orientation walk.
struct Shells {
    /// Region-sides grouped by shell, each group sorted.
    order: Vec<u32>,
    start: Vec<u32>,
    label: Vec<u32>,
    /// Parity of each region-side (indexed by rs).
    parity: Vec<bool>,
    /// Shell of each region-side, [`NONE`] for the outside (label 0).
    of_rs: Vec<u32>,
    non_orientable: Vec<usize>,
}

impl Shells {
    fn build(s: &SurfaceMesh, nbr: &[u32]) -> Shells {
        let nrs = 2 * s.triangles.len();
        let mut shell = vec![NONE; nrs];
        let mut parity = vec![false; nrs];
        let mut order = Vec::new();
        let mut start = Vec::new();
        let mut label = Vec::new();
        let mut non_orientable = Vec::new();
        let mut stack = Vec::new();
        for seed in 0..nrs {
            let l = s.sides[seed / 2][seed % 2];
            if l == 0 || shell[seed] != NONE {
                continue;
            }
            let id = label.len() as u32;
            label.push(l);
            start.push(order.len() as u32);
            let first = order.len();
            let mut bad = false;
            shell[seed] = id;
            stack.push(seed as u32);
            while let Some(rs) = stack.pop() {
                order.push(rs);
                for k in 0..3 {
                    let x = nbr[3 * rs as usize + k];
                    if x == NONE {
                        continue;
                    }
                    let other = ((x & !SAME_DIR) / 3) as usize;
                    let p = parity[rs as usize] ^ (x & SAME_DIR != 0);
                    if shell[other] == NONE {
                        shell[other] = id;
                        parity[other] = p;
                        stack.push(other as u32);
                    } else if parity[other] != p {
                        bad = true;
                    }
                }
            }
            order[first..].sort_unstable();
            if bad {
                non_orientable.push(id as usize);
            }
        }
        start.push(order.len() as u32);
        Shells {
            order,
            start,
            label,
            parity,
            of_rs: shell,
            non_orientable,
        }
    }

    fn n_shells(&self) -> usize {
        self.label.len()
    }

    fn members(&self, sh: usize) -> &[u32] {
        &self.order[self.start[sh] as usize..self.start[sh + 1] as usize]
    }

    /// The triangles of the minority orientation of each shell (ties: those disagreeing with the
    /// shell's lowest triangle), sorted.
    fn minority_triangles(&self) -> Vec<u32> {
        let mut out = Vec::new();
        for sh in 0..self.n_shells() {
            let m = self.members(sh);
            let ones = m.iter().filter(|&&rs| self.parity[rs as usize]).count();
            let flip_ones = 2 * ones <= m.len();
            out.extend(
                m.iter()
                    .filter(|&&rs| self.parity[rs as usize] == flip_ones)
                    .map(|&rs| rs / 2),
            );
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

fn shell_box(s: &SurfaceMesh, members: &[u32]) -> Aabb {
    members
        .iter()
        .map(|&rs| tri_box(&s.corners((rs / 2) as usize)))
        .reduce(|a, b| box_union(&a, &b))
        .expect("a shell has triangles")
}

/// Signed volume of a shell with its region behind (a measure, see the module docs).
/// Deterministic: fixed chunks, summed in order.
fn shell_volume(s: &SurfaceMesh, members: &[u32]) -> f64 {
    let n = (3 * members.len()) as f64;
    let mut c = [0.0; 3];
    for &rs in members {
        for p in s.corners((rs / 2) as usize) {
            for i in 0..3 {
                c[i] += p[i] / n;
            }
        }
    }
    let parts: Vec<f64> = members
        .par_chunks(4096)
        .map(|ch| {
            ch.iter()
                .map(|&rs| {
                    let v = rs_vertices(s, rs).map(|i| s.points[i as usize]);
                    crate::geom::vec3::volume6(c, v[0], v[1], v[2])
                })
                .sum::<f64>()
        })
        .collect();
    parts.iter().sum::<f64>() / 6.0
}

/// Whether `p` (not on the shell) is inside the closed shell, by the exact parity of proper
/// crossings of a segment from `p` to a point outside the shell's box. The segment runs nearly
/// along a coordinate axis (so its bounding box is thin and the shell's BVH prunes well) but in a
/// generic direction; one that touches an edge or a vertex (or lies in a triangle's plane) is
/// replaced by another one, from a fixed sequence.
fn point_inside_shell(s: &SurfaceMesh, members: &[u32], bvh: &Bvh, bx: &Aabb, p: P3) -> bool {
    let span = (0..3).map(|i| bx[1][i] - bx[0][i]).fold(0.0, f64::max);
    let mut seed: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut stack = Vec::new();
    let mut last = false;
    for attempt in 0..96 {
        let axis = attempt % 3;
        let forward = (attempt / 3) % 2 == 0;
        let mut d = [0.0; 3];
        d[axis] = if forward { 1.0 } else { -1.0 };
        // Small generic tilts; wider after many failures.
        let tilt = if attempt < 48 { 1e-3 } else { 0.5 };
        d[(axis + 1) % 3] = tilt * rnd();
        d[(axis + 2) % 3] = tilt * rnd();
        let gap = if forward {
            bx[1][axis] - p[axis]
        } else {
            p[axis] - bx[0][axis]
        };
        let mut len = gap.max(0.0) * 1.01 + 0.01 * span;
        let q = loop {
            let q = [0, 1, 2].map(|i| p[i] + len * d[i]);
            let outside = if forward {
                q[axis] > bx[1][axis]
            } else {
                q[axis] < bx[0][axis]
            };
            if outside {
                break q;
            }
            len *= 2.0;
        };
        let sb = tri_box(&[p, q, q]);
        let (mut crossings, mut degenerate, mut on) = (0usize, false, false);
        bvh.query(0, &sb, &mut stack, |pos| {
            let rs = members[bvh.order[pos as usize] as usize];
            match seg_tri(p, q, &s.corners((rs / 2) as usize)) {
                SegTri::Disjoint => {}
                SegTri::Proper => crossings += 1,
                // p on the shell (only possible without the self-intersection check): call it
                // outside.
                SegTri::Touch {
                    seg: SegPart::Endpoint(0),
                    ..
                } => on = true,
                _ => degenerate = true,
            }
        });
        if on {
            return false;
        }
        last = crossings % 2 == 1;
        if !degenerate {
            return last;
        }
    }
    last
}

/// Connected components of the whole surface through shared edges.
struct Components {
    n: usize,
    of_triangle: Vec<u32>,
}

impl Components {
    fn build(s: &SurfaceMesh, edges: &EdgeTable) -> Components {
        let nt = s.triangles.len();
        let mut dsu = Dsu::new(nt);
        for g in 0..edges.n_edges() {
            let mut it = edges.group(g);
            let first = it.next().expect("non-empty group") / 3;
            for h in it {
                dsu.union(first, h / 3);
            }
        }
        let mut id = vec![NONE; nt];
        let mut of_triangle = vec![0u32; nt];
        let mut n = 0u32;
        for (t, c) in of_triangle.iter_mut().enumerate() {
            let r = dsu.find(t as u32) as usize;
            if id[r] == NONE {
                id[r] = n;
                n += 1;
            }
            *c = id[r];
        }
        Components {
            n: n as usize,
            of_triangle,
        }
    }

    fn reports(
        &self,
        s: &SurfaceMesh,
        edges: &EdgeTable,
        flipped: &[bool],
    ) -> Vec<ComponentReport> {
        let mut reps: Vec<ComponentReport> = (0..self.n)
            .map(|c| ComponentReport {
                first_triangle: 0,
                n_triangles: 0,
                n_vertices: 0,
                n_edges: 0,
                euler_characteristic: 0,
                genus: None,
                regions: Vec::new(),
                flipped: flipped[c],
            })
            .collect();
        let mut manifold = vec![true; self.n];
        let mut vmark = vec![NONE; s.points.len()];
        for t in (0..s.triangles.len()).rev() {
            let r = &mut reps[self.of_triangle[t] as usize];
            r.first_triangle = t as u32;
        }
        for (t, tri) in s.triangles.iter().enumerate() {
            let c = self.of_triangle[t];
            let r = &mut reps[c as usize];
            r.n_triangles += 1;
            for &v in tri {
                if vmark[v as usize] != c {
                    vmark[v as usize] = c;
                    r.n_vertices += 1;
                }
            }
            for l in s.sides[t] {
                if l != 0 && !r.regions.contains(&l) {
                    r.regions.push(l);
                }
            }
        }
        for g in 0..edges.n_edges() {
            let mut it = edges.group(g);
            let c = self.of_triangle[(it.next().expect("non-empty") / 3) as usize] as usize;
            reps[c].n_edges += 1;
            if it.count() != 1 {
                manifold[c] = false;
            }
        }
        for (c, r) in reps.iter_mut().enumerate() {
            r.regions.sort_unstable();
            r.euler_characteristic = r.n_vertices as i64 - r.n_edges as i64 + r.n_triangles as i64;
            if manifold[c] && r.euler_characteristic % 2 == 0 {
                r.genus = Some((2 - r.euler_characteristic) / 2);
            }
        }
        reps
    }
}

// -------------------------------------------------------------------------------------------
// Self-intersections
// -------------------------------------------------------------------------------------------

/// A bounding-volume hierarchy over boxes: nodes in depth-first order (left child right after
/// its parent), every node covering a contiguous range of `order`.
struct Bvh {
    nodes: Vec<Node>,
    /// Triangles in leaf order.
    order: Vec<u32>,
    /// Boxes in leaf order.
    boxes: Vec<Aabb>,
}

struct Node {
    bx: Aabb,
    start: u32,
    end: u32,
    /// Right child, or 0 for a leaf.
    right: u32,
}

const LEAF: usize = 4;

/// Interleave the low 21 bits of three integers.
fn morton3(q: [u64; 3]) -> u64 {
    let spread = |mut x: u64| {
        x &= 0x1f_ffff;
        x = (x | x << 32) & 0x1f00000000ffff;
        x = (x | x << 16) & 0x1f0000ff0000ff;
        x = (x | x << 8) & 0x100f00f00f00f00f;
        x = (x | x << 4) & 0x10c30c30c30c30c3;
        x = (x | x << 2) & 0x1249249249249249;
        x
    };
    spread(q[0]) | spread(q[1]) << 1 | spread(q[2]) << 2
}

impl Bvh {
    /// A linear BVH: boxes sorted by the Morton code of their centres (in parallel), ranges
    /// split where the highest differing code bit changes, node boxes computed bottom-up.
    fn build(boxes: &[Aabb]) -> Bvh {
        let all = boxes
            .iter()
            .copied()
            .reduce(|a, b| box_union(&a, &b))
            .expect("non-empty");
        let scale = [0, 1, 2].map(|i| {
            let ext = all[1][i] - all[0][i];
            if ext > 0.0 { 2097151.0 / ext } else { 0.0 }
        });
        let mut keyed: Vec<(u64, u32)> = boxes
            .par_iter()
            .enumerate()
            .map(|(t, b)| {
                let q = [0, 1, 2].map(|i| {
                    let c = 0.5 * (b[0][i] + b[1][i]) - all[0][i];
                    ((c * scale[i]) as u64).min(2097151)
                });
                (morton3(q), t as u32)
            })
            .collect();
        keyed.par_sort_unstable();
        let codes: Vec<u64> = keyed.iter().map(|x| x.0).collect();
        let order: Vec<u32> = keyed.iter().map(|x| x.1).collect();
        let sorted: Vec<Aabb> = order.iter().map(|&t| boxes[t as usize]).collect();
        let mut nodes = Vec::with_capacity(2 * boxes.len() / LEAF + 1);
        Self::build_node(&mut nodes, &codes, &sorted, 0, boxes.len());
        Bvh {
            nodes,
            order,
            boxes: sorted,
        }
    }

    fn build_node(
        nodes: &mut Vec<Node>,
        codes: &[u64],
        boxes: &[Aabb],
        lo: usize,
        hi: usize,
    ) -> u32 {
        let id = nodes.len();
        nodes.push(Node {
            bx: boxes[lo],
            start: lo as u32,
            end: hi as u32,
            right: 0,
        });
        if hi - lo <= LEAF {
            nodes[id].bx = boxes[lo..hi]
                .iter()
                .copied()
                .reduce(|a, b| box_union(&a, &b))
                .expect("non-empty leaf");
            return id as u32;
        }
        // Split at the first code whose highest bit differing from codes[lo] is the top one in
        // the range; equal codes split in the middle.
        let (a, b) = (codes[lo], codes[hi - 1]);
        let mid = if a == b {
            (lo + hi) / 2
        } else {
            let bit = 63 - (a ^ b).leading_zeros();
            let m = lo + codes[lo..hi].partition_point(|&c| (c ^ a) >> bit == 0);
            m.clamp(lo + 1, hi - 1)
        };
        let left = Self::build_node(nodes, codes, boxes, lo, mid);
        let right = Self::build_node(nodes, codes, boxes, mid, hi);
        nodes[id].right = right;
        nodes[id].bx = box_union(&nodes[left as usize].bx, &nodes[right as usize].bx);
        id as u32
    }

    /// Calls `f(pos)` for every leaf position `pos >= min_pos` whose box overlaps `bx`.
    fn query(&self, min_pos: u32, bx: &Aabb, stack: &mut Vec<u32>, mut f: impl FnMut(u32)) {
        stack.clear();
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if node.end <= min_pos || !boxes_overlap(&node.bx, bx) {
                continue;
            }
            if node.right == 0 {
                for p2 in node.start.max(min_pos)..node.end {
                    if boxes_overlap(&self.boxes[p2 as usize], bx) {
                        f(p2);
                    }
                }
            } else {
                stack.push(node.right);
                stack.push(n + 1);
            }
        }
    }
}

/// Whether triangles `i` and `j` meet other than in the vertices they share by index.
fn improper_pair(s: &SurfaceMesh, i: usize, j: usize) -> bool {
    meet_improperly(&s.corners(i), s.triangles[i], &s.corners(j), s.triangles[j])
}

/// Every pair `(i, j)`, `i < j`, of triangles that meet improperly (cross, or touch other than
/// in their shared vertex or edge), sorted.
pub(crate) fn crossing_pairs(s: &SurfaceMesh) -> Vec<(u32, u32)> {
    self_intersections(s, usize::MAX / 8).1
}

/// The number of improperly intersecting pairs and the `k` lowest ones `(i, j)`, `i < j`.
fn self_intersections(s: &SurfaceMesh, k: usize) -> (usize, Vec<(u32, u32)>) {
    let boxes: Vec<Aabb> = (0..s.triangles.len())
        .into_par_iter()
        .map(|t| tri_box(&s.corners(t)))
        .collect();
    let bvh = Bvh::build(&boxes);
    let keep = |v: &mut Vec<(u32, u32)>| {
        v.sort_unstable();
        v.truncate(k);
    };
    let (count, mut pairs) = (0..bvh.order.len() as u32)
        .into_par_iter()
        .with_min_len(512)
        .fold(
            || (0usize, Vec::new(), Vec::new()),
            |(mut n, mut pairs, mut stack), pos| {
                let i = bvh.order[pos as usize];
                bvh.query(pos + 1, &bvh.boxes[pos as usize], &mut stack, |p2| {
                    let j = bvh.order[p2 as usize];
                    if improper_pair(s, i as usize, j as usize) {
                        n += 1;
                        pairs.push((i.min(j), i.max(j)));
                        if pairs.len() > 4 * k + 16 {
                            keep(&mut pairs);
                        }
                    }
                });
                (n, pairs, stack)
            },
        )
        .map(|(n, p, _)| (n, p))
        .reduce(
            || (0, Vec::new()),
            |(n1, mut p1), (n2, p2)| {
                p1.extend(p2);
                keep(&mut p1);
                (n1 + n2, p1)
            },
        );
    keep(&mut pairs);
    (count, pairs)
}
