//! Region labels given per triangle side (read from a file) checked against the geometry.
//!
//! A multi-material surface — one non-manifold surface whose triangles carry the labels of the
//! regions on both sides, as a multi-material marching cubes writes it — states in its labels
//! what its geometry already decides: which cell of space each side of each triangle faces.
//! [`resolve`] computes the cells ([`label_arrangement`]: the exact angular order of the
//! triangles around every edge, nesting by exact point location) and checks that the given
//! labels name them consistently:
//!
//! - every cell gets one label: the label most of its triangle sides give it (ties go to the
//!   smaller label); a side that gives another label is an error naming the triangle, the side
//!   and both labels; when both sides of a triangle disagree and the swapped pair agrees, the
//!   triangle faces the wrong way and the error says so;
//! - the unbounded cell is the outside, label 0;
//! - a side given as [`FROM_GEOMETRY`] (a Medit triangle written once, whose ref names only the
//!   region behind it) takes the label of its cell; a cell no side labels is a cavity (0).
//!
//! Several cells may share a label (separate bodies of one tissue). The per-region checks —
//! the triangles bounding each region form a closed, consistently oriented surface, and no
//! triangles cross — are [`crate::mesh::validate::validate_surface`]'s, run on the result.

use rustc_hash::FxHashMap;

use crate::mesh::shells::{AssembleError, Shell, label_arrangement};
use crate::mesh::surface::SurfaceMesh;

/// A side label meaning "the label of the cell this side faces": set by [`resolve`].
pub const FROM_GEOMETRY: u32 = u32::MAX;

/// Which side of a triangle, for messages.
fn side_name(k: usize) -> &'static str {
    if k == 0 { "back" } else { "front" }
}

/// Why the given side labels do not fit the geometry. Triangle indices are 0-based.
#[derive(Debug, thiserror::Error)]
pub enum SideLabelError {
    /// The triangles do not split space into cells.
    #[error(transparent)]
    Arrangement(#[from] AssembleError),
    /// A side labelled differently from the rest of its cell.
    #[error(
        "triangle {triangle}: its {side} side is labelled {label}, but that side faces the region \
         labelled {expected} by {votes} other triangle sides (first: the {other_side} side of \
         triangle {other})"
    )]
    Conflict {
        /// The triangle.
        triangle: usize,
        /// `back` or `front`.
        side: &'static str,
        /// Its label.
        label: u32,
        /// The label of the cell.
        expected: u32,
        /// How many sides give the cell that label.
        votes: usize,
        /// A triangle that gives it.
        other: usize,
        /// Its side.
        other_side: &'static str,
    },
    /// Both sides of a triangle disagree with their cells and the swapped pair agrees.
    #[error(
        "triangle {triangle} faces the wrong way: its labels are [back {back}, front {front}] but \
         its normal points into region {back} (flip the triangle or swap its labels)"
    )]
    Flipped {
        /// The triangle.
        triangle: usize,
        /// Its back label.
        back: u32,
        /// Its front label.
        front: u32,
    },
    /// A side facing the unbounded outside with a non-zero label.
    #[error(
        "triangle {triangle}: its {side} side faces the unbounded outside but is labelled \
         {label} (the outside is 0)"
    )]
    Outside {
        /// The triangle.
        triangle: usize,
        /// `back` or `front`.
        side: &'static str,
        /// Its label.
        label: u32,
    },
}

/// The outcome of [`resolve`].
#[derive(Debug, Clone)]
pub struct Resolved {
    /// The surface with every side labelled.
    pub surface: SurfaceMesh,
    /// The bounded cells with their labels (as [`label_arrangement`] lists them).
    pub shells: Vec<Shell>,
    /// Sides that were [`FROM_GEOMETRY`] and got their cell's label.
    pub n_from_geometry: usize,
}

/// Check `s.sides` against the cells of `s`'s triangles and fill the [`FROM_GEOMETRY`] sides.
/// See the module documentation.
pub fn resolve(s: &SurfaceMesh) -> Result<Resolved, SideLabelError> {
    let (geo, mut shells) = label_arrangement(s, None)?;
    let n_cells = geo.sides.iter().flatten().copied().max().unwrap_or(0) as usize + 1;
    // Votes per cell: label -> (count, first triangle side).
    let mut votes: Vec<FxHashMap<u32, (usize, usize, usize)>> = vec![Default::default(); n_cells];
    for (t, (given, cells)) in s.sides.iter().zip(&geo.sides).enumerate() {
        for k in 0..2 {
            if given[k] != FROM_GEOMETRY {
                let e = votes[cells[k] as usize]
                    .entry(given[k])
                    .or_insert((0, t, k));
                e.0 += 1;
            }
        }
    }
    // The label of each cell: the unbounded one is 0; the others by majority.
    let mut label = vec![0u32; n_cells];
    let mut winner = vec![None; n_cells];
    for c in 1..n_cells {
        let best = votes[c]
            .iter()
            .max_by_key(|&(&l, &(n, _, _))| (n, std::cmp::Reverse(l)));
        if let Some((&l, &v)) = best {
            label[c] = l;
            winner[c] = Some(v);
        }
    }
    let mut out = s.clone();
    let mut n_from_geometry = 0;
    for (t, (given, cells)) in s.sides.iter().zip(&geo.sides).enumerate() {
        let want = cells.map(|c| label[c as usize]);
        let ok = |k: usize| given[k] == FROM_GEOMETRY || given[k] == want[k];
        if ok(0) && ok(1) {
            for k in 0..2 {
                if given[k] == FROM_GEOMETRY {
                    out.sides[t][k] = want[k];
                    n_from_geometry += 1;
                }
            }
            continue;
        }
        if given[0] == want[1] && given[1] == want[0] && given[0] != given[1] {
            return Err(SideLabelError::Flipped {
                triangle: t,
                back: given[0],
                front: given[1],
            });
        }
        let k = if ok(0) { 1 } else { 0 };
        let c = cells[k] as usize;
        return Err(match winner[c] {
            _ if c == 0 => SideLabelError::Outside {
                triangle: t,
                side: side_name(k),
                label: given[k],
            },
            Some((votes, other, other_side)) => SideLabelError::Conflict {
                triangle: t,
                side: side_name(k),
                label: given[k],
                expected: want[k],
                votes,
                other,
                other_side: side_name(other_side),
            },
            None => unreachable!("a labelled side votes for its cell"),
        });
    }
    // The shells of the arrangement carry its own numbering (cell c has label c); rename.
    for sh in &mut shells {
        sh.label = label[sh.label as usize];
    }
    Ok(Resolved {
        surface: out,
        shells,
        n_from_geometry,
    })
}
