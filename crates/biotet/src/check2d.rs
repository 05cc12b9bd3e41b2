//! The validity checker for 2D triangle meshes, the plane counterpart of [`crate::check`]: is a
//! [`TriMesh`] a conforming, counter-clockwise triangulation, and does it contain every segment of
//! a given [`Pslg`] with consistent labels?
//!
//! Every decision is exact: orientation by [`orient2d`], segment crossing by orientations,
//! matching of PSLG points to mesh points by exact coordinates.

use crate::geom::predicates::{Sign, in_exact_range, orient2d};
use crate::mesh::pslg::{Pslg, edge_key};
use crate::mesh::tet::NO_NEIGHBOR;
use crate::mesh::tri::{TRI_EDGES, TriMesh};
use rustc_hash::FxHashMap;
use serde::Serialize;

const LIST_FIRST: usize = 5;

/// One triangle's use of an edge: (triangle, local edge, traversed from smaller to larger index).
type EdgeUse = (u32, usize, bool);

/// The result of [`check_tri`].
#[derive(Debug, Clone, Default, Serialize)]
pub struct TriCheckReport {
    /// True when no defect was found.
    pub valid: bool,
    /// Points.
    pub n_points: usize,
    /// Triangles.
    pub n_triangles: usize,
    /// Boundary edges (edges of one triangle).
    pub n_boundary_edges: usize,
    /// Triangles with an index out of range or a repeated vertex.
    pub n_bad_triangles: usize,
    /// Triangles that are not strictly counter-clockwise (exact).
    pub n_nonpositive: usize,
    /// Edges in more than two triangles.
    pub n_overshared_edges: usize,
    /// Interior edges that both triangles traverse the same way (overlap).
    pub n_misoriented_edges: usize,
    /// Entries of the adjacency array that disagree with the edges.
    pub n_adjacency_errors: usize,
    /// Pairs of boundary edges that cross or overlap (the mesh would cover some area twice).
    pub n_boundary_crossings: usize,
    /// Points used by no triangle.
    pub n_unused_points: usize,
    /// Points with the coordinates of an earlier point.
    pub n_duplicate_points: usize,
    /// Non-finite coordinates or outside the exact range of the predicates.
    pub n_nonfinite_points: usize,
    /// Label array length differs from the triangle count (0 or 1).
    pub n_label_errors: usize,
    /// Conformity to a PSLG, when one was given.
    pub pslg: Option<PslgConformity>,
    /// The first offenders of each kind.
    pub problems: Vec<String>,
}

/// How a [`TriMesh`] conforms to a [`Pslg`].
#[derive(Debug, Clone, Default, Serialize)]
pub struct PslgConformity {
    /// Segments.
    pub n_segments: usize,
    /// Segments present as mesh edges.
    pub n_found: usize,
    /// Segments with an end that is no mesh point.
    pub n_points_missing: usize,
    /// Segments whose ends are mesh points but that are no mesh edge.
    pub n_missing: usize,
    /// Mesh boundary edges that are no segment.
    pub n_extra_boundary_edges: usize,
    /// Interior edges that are no segment but have different labels on their two sides.
    pub n_label_jumps: usize,
    /// Per pair of side labels (smaller first, 0 = outside): segments found there.
    pub sides: Vec<SegmentSides>,
}

/// Segments found between two labels.
#[derive(Debug, Clone, Default, Serialize, PartialEq, Eq)]
pub struct SegmentSides {
    /// The labels on the two sides, smaller first (0 = the outside).
    pub labels: [u32; 2],
    /// Segments.
    pub count: usize,
}

/// Check `mesh` and, if given, its conformity to `pslg`: triangles index distinct points in range
/// and are strictly counter-clockwise (exact); no edge in more than two triangles, the two
/// triangles of an interior edge traverse it in opposite directions; the adjacency matches; no two
/// boundary edges cross or overlap; every point used, none duplicated, all finite; one label per
/// triangle. With a PSLG: every segment is an edge, every boundary edge is a segment, and labels
/// change only across segments.
pub fn check_tri(mesh: &TriMesh, pslg: Option<&Pslg>) -> TriCheckReport {
    let mut r = TriCheckReport {
        n_points: mesh.points.len(),
        n_triangles: mesh.triangles.len(),
        ..Default::default()
    };
    let np = mesh.points.len();
    let note = |problems: &mut Vec<String>, count: usize, msg: String| {
        if count <= LIST_FIRST {
            problems.push(msg);
        }
    };
    if mesh.triangles.is_empty() {
        r.problems.push("the mesh has no triangles".to_string());
    }
    for (i, p) in mesh.points.iter().enumerate() {
        if !p.iter().all(|c| c.is_finite() && in_exact_range(*c)) {
            r.n_nonfinite_points += 1;
            note(
                &mut r.problems,
                r.n_nonfinite_points,
                format!("point {i} has a non-finite or out-of-range coordinate"),
            );
        }
    }
    let mut by_coord: FxHashMap<[u64; 2], u32> = FxHashMap::default();
    for (i, p) in mesh.points.iter().enumerate() {
        let k = p.map(|c| (c + 0.0).to_bits());
        if let Some(&j) = by_coord.get(&k) {
            r.n_duplicate_points += 1;
            note(
                &mut r.problems,
                r.n_duplicate_points,
                format!("point {i} has the coordinates of point {j}"),
            );
        } else {
            by_coord.insert(k, i as u32);
        }
    }
    if mesh.labels.len() != mesh.triangles.len() {
        r.n_label_errors = 1;
        r.problems.push(format!(
            "{} labels for {} triangles",
            mesh.labels.len(),
            mesh.triangles.len()
        ));
    }
    let mut used = vec![false; np];
    let mut good = vec![true; mesh.triangles.len()];
    for (t, tv) in mesh.triangles.iter().enumerate() {
        if tv.iter().any(|&v| v as usize >= np)
            || tv[0] == tv[1]
            || tv[1] == tv[2]
            || tv[0] == tv[2]
        {
            r.n_bad_triangles += 1;
            good[t] = false;
            note(
                &mut r.problems,
                r.n_bad_triangles,
                format!("triangle {t} {tv:?} has an index out of range or a repeated vertex"),
            );
            continue;
        }
        for &v in tv {
            used[v as usize] = true;
        }
        let c = mesh.corners(t);
        if orient2d(c[0], c[1], c[2]) != Sign::Positive {
            r.n_nonpositive += 1;
            note(
                &mut r.problems,
                r.n_nonpositive,
                format!("triangle {t} {tv:?} is not strictly counter-clockwise"),
            );
        }
    }
    r.n_unused_points = used.iter().filter(|&&u| !u).count();
    if r.n_unused_points > 0 {
        r.problems.push(format!(
            "{} points are used by no triangle",
            r.n_unused_points
        ));
    }
    // Edges: directed occurrences per undirected edge.
    let mut edges: FxHashMap<(u32, u32), Vec<EdgeUse>> = FxHashMap::default();
    for (t, tv) in mesh.triangles.iter().enumerate() {
        if !good[t] {
            continue;
        }
        for (i, e) in TRI_EDGES.iter().enumerate() {
            let (a, b) = (tv[e[0]], tv[e[1]]);
            edges
                .entry(edge_key(a, b))
                .or_default()
                .push((t as u32, i, a < b));
        }
    }
    let mut boundary: Vec<(u32, u32)> = Vec::new();
    let mut keys: Vec<&(u32, u32)> = edges.keys().collect();
    keys.sort_unstable();
    for k in keys {
        let occ = &edges[k];
        match occ.len() {
            1 => {
                boundary.push(*k);
                let (t, i, _) = occ[0];
                if mesh.neighbors.get(t as usize).map(|n| n[i]) != Some(NO_NEIGHBOR) {
                    r.n_adjacency_errors += 1;
                }
            }
            2 => {
                let ((t, i, d), (u, j, e)) = (occ[0], occ[1]);
                if d == e {
                    r.n_misoriented_edges += 1;
                    note(
                        &mut r.problems,
                        r.n_misoriented_edges,
                        format!("triangles {t} and {u} overlap across edge {k:?}"),
                    );
                }
                if mesh.neighbors.get(t as usize).map(|n| n[i]) != Some(u)
                    || mesh.neighbors.get(u as usize).map(|n| n[j]) != Some(t)
                {
                    r.n_adjacency_errors += 1;
                }
            }
            _ => {
                r.n_overshared_edges += 1;
                note(
                    &mut r.problems,
                    r.n_overshared_edges,
                    format!("edge {k:?} is in {} triangles", occ.len()),
                );
            }
        }
    }
    r.n_boundary_edges = boundary.len();
    if r.n_adjacency_errors > 0 {
        r.problems.push(format!(
            "{} adjacency entries disagree with the edges",
            r.n_adjacency_errors
        ));
    }
    // Boundary edges must not cross: reuse the PSLG's exact tests on them.
    if np > 0
        && boundary
            .iter()
            .all(|&(a, b)| (a as usize) < np && (b as usize) < np)
    {
        let g = Pslg {
            points: mesh.points.clone(),
            segments: boundary.iter().map(|&(a, b)| [a, b]).collect(),
            ..Default::default()
        };
        if r.n_duplicate_points == 0
            && r.n_nonfinite_points == 0
            && !boundary.is_empty()
            && let Err(e) = g.validate()
        {
            r.n_boundary_crossings = 1;
            r.problems.push(format!("boundary edges: {e}"));
        }
    }

    if let Some(g) = pslg {
        let mut c = PslgConformity {
            n_segments: g.segments.len(),
            ..Default::default()
        };
        let label = |t: u32| mesh.labels.get(t as usize).copied().unwrap_or(0);
        let mut seg_keys = rustc_hash::FxHashSet::default();
        let mut sides: FxHashMap<[u32; 2], usize> = FxHashMap::default();
        for (s, &[a, b]) in g.segments.iter().enumerate() {
            let m = |v: u32| {
                g.points
                    .get(v as usize)
                    .and_then(|p| by_coord.get(&p.map(|c| (c + 0.0).to_bits())).copied())
            };
            let (Some(ma), Some(mb)) = (m(a), m(b)) else {
                c.n_points_missing += 1;
                note(
                    &mut r.problems,
                    c.n_points_missing,
                    format!("segment {s}: an end is not a mesh point"),
                );
                continue;
            };
            seg_keys.insert(edge_key(ma, mb));
            match edges.get(&edge_key(ma, mb)) {
                Some(occ) => {
                    c.n_found += 1;
                    let mut l = [0, 0];
                    for (k, &(t, _, _)) in occ.iter().take(2).enumerate() {
                        l[k] = label(t);
                    }
                    l.sort_unstable();
                    *sides.entry(l).or_default() += 1;
                }
                None => {
                    c.n_missing += 1;
                    note(
                        &mut r.problems,
                        c.n_missing,
                        format!("segment {s} ({a}, {b}) is not a mesh edge"),
                    );
                }
            }
        }
        for &k in &boundary {
            if !seg_keys.contains(&k) {
                c.n_extra_boundary_edges += 1;
                note(
                    &mut r.problems,
                    c.n_extra_boundary_edges,
                    format!("boundary edge {k:?} is no segment"),
                );
            }
        }
        for (k, occ) in &edges {
            if occ.len() == 2 && !seg_keys.contains(k) && label(occ[0].0) != label(occ[1].0) {
                c.n_label_jumps += 1;
            }
        }
        if c.n_label_jumps > 0 {
            r.problems.push(format!(
                "{} edges that are no segment separate different labels",
                c.n_label_jumps
            ));
        }
        let mut sides: Vec<SegmentSides> = sides
            .into_iter()
            .map(|(labels, count)| SegmentSides { labels, count })
            .collect();
        sides.sort_by_key(|s| s.labels);
        c.sides = sides;
        r.pslg = Some(c);
    }
    let p = r.pslg.as_ref();
    r.valid = !mesh.triangles.is_empty()
        && r.n_bad_triangles == 0
        && r.n_nonpositive == 0
        && r.n_overshared_edges == 0
        && r.n_misoriented_edges == 0
        && r.n_adjacency_errors == 0
        && r.n_boundary_crossings == 0
        && r.n_unused_points == 0
        && r.n_duplicate_points == 0
        && r.n_nonfinite_points == 0
        && r.n_label_errors == 0
        && p.is_none_or(|c| {
            c.n_points_missing == 0
                && c.n_missing == 0
                && c.n_extra_boundary_edges == 0
                && c.n_label_jumps == 0
        });
    r
}

impl std::fmt::Display for TriCheckReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "{}: {} points, {} triangles, {} boundary edges",
            if self.valid { "valid" } else { "INVALID" },
            self.n_points,
            self.n_triangles,
            self.n_boundary_edges
        )?;
        if let Some(c) = &self.pslg {
            writeln!(
                f,
                "segments: {} of {} present ({} missing, {} with an end that is no mesh point), \
                 {} boundary edges that are no segment",
                c.n_found, c.n_segments, c.n_missing, c.n_points_missing, c.n_extra_boundary_edges
            )?;
            for s in &c.sides {
                writeln!(
                    f,
                    "  labels {} | {}: {} segments",
                    s.labels[0], s.labels[1], s.count
                )?;
            }
        }
        for p in &self.problems {
            writeln!(f, "  {p}")?;
        }
        Ok(())
    }
}
