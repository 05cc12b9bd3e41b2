//! Split a set of oriented barrier triangles into the closed cells they bound.
//!
//! Each half-face is an oriented triangle whose right-hand normal points into its cell (a
//! triangle that separates two cells appears twice, once per side). Around every edge the
//! half-faces are sorted by angle (exactly: orient3d, and orient2d in the plane of the reference
//! half-face for the coplanar ones); the sector between two consecutive half-faces belongs to a
//! cell when the first points forwards into it and the second backwards, and the two are then
//! glued. Cells are the connected components of this gluing; each is closed and consistently
//! oriented by construction.

use crate::geom::filter::orient3d;
use crate::geom::intersect::{drop_axis, projection_axis};
use crate::geom::predicates::{Sign, orient2d};
use crate::mesh::dsu::Dsu;
use std::cmp::Ordering;

type P3 = [f64; 3];

/// One half-face at one edge.
#[derive(Debug, Clone, Copy)]
struct Wing {
    /// Edge as (smaller, larger) vertex.
    edge: (u32, u32),
    /// Half-face index.
    face: u32,
    /// The third vertex.
    apex: u32,
    /// The half-face runs along the edge from the smaller to the larger vertex: its normal turns
    /// forwards (increasing angle about the axis smaller → larger).
    forward: bool,
}

/// Reusable buffers for [`Cells::split`].
#[derive(Debug, Default)]
pub(crate) struct Cells {
    wings: Vec<Wing>,
    parent: Dsu,
    group: Vec<Wing>,
    /// The wings of `group` with their angle class, for sorting.
    classed: Vec<(u8, Wing)>,
    root_cell: Vec<u32>,
}

impl Cells {
    /// Assign a cell number (0, 1, …, in order of first half-face) to every half-face of
    /// `faces`, written to `cell`; returns the number of cells. Fails with the offending edge
    /// when the half-faces around it do not alternate (no consistent cells).
    pub(crate) fn split(
        &mut self,
        points: &[P3],
        faces: &[[u32; 3]],
        cell: &mut Vec<u32>,
    ) -> Result<usize, (u32, u32)> {
        self.wings.clear();
        for (i, f) in faces.iter().enumerate() {
            for k in 0..3 {
                let (a, b, c) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
                self.wings.push(Wing {
                    edge: (a.min(b), a.max(b)),
                    face: i as u32,
                    apex: c,
                    forward: a < b,
                });
            }
        }
        self.wings.sort_unstable_by_key(|w| (w.edge, w.face));
        self.parent.reset(faces.len());
        let mut i = 0;
        while i < self.wings.len() {
            let mut j = i + 1;
            while j < self.wings.len() && self.wings[j].edge == self.wings[i].edge {
                j += 1;
            }
            if j - i == 2 {
                let (x, y) = (self.wings[i], self.wings[i + 1]);
                if x.forward == y.forward {
                    return Err(x.edge);
                }
                self.parent.union(x.face, y.face);
            } else {
                self.group.clear();
                self.group.extend_from_slice(&self.wings[i..j]);
                self.sort_group(points)?;
                let m = self.group.len();
                for k in 0..m {
                    let (h, nx) = (self.group[k], self.group[(k + 1) % m]);
                    match (h.forward, nx.forward) {
                        (true, false) => self.parent.union(h.face, nx.face),
                        (false, true) => {}
                        _ => return Err(h.edge),
                    }
                }
            }
            i = j;
        }
        cell.clear();
        let root_cell = &mut self.root_cell;
        root_cell.clear();
        root_cell.resize(faces.len(), u32::MAX);
        let mut n = 0;
        for f in 0..faces.len() {
            let r = self.parent.find(f as u32) as usize;
            if root_cell[r] == u32::MAX {
                root_cell[r] = n;
                n += 1;
            }
            cell.push(root_cell[r]);
        }
        Ok(n as usize)
    }

    /// Sort the wings of one edge by angle about the axis (smaller → larger vertex), starting at
    /// the first wing's half-plane; wings in the same half-plane put the backward one first.
    fn sort_group(&mut self, points: &[P3]) -> Result<(), (u32, u32)> {
        let w0 = self.group[0];
        let (a, b) = (points[w0.edge.0 as usize], points[w0.edge.1 as usize]);
        let c0 = points[w0.apex as usize];
        let Some(axis) = projection_axis(&[a, b, c0]) else {
            return Err(w0.edge);
        };
        let (a2, b2) = (drop_axis(a, axis), drop_axis(b, axis));
        let s0 = orient2d(a2, b2, drop_axis(c0, axis));
        // Class: 0 = the reference half-plane, 1 = angle in (0, π), 2 = π, 3 = (π, 2π).
        self.classed.clear();
        for w in &self.group {
            let c = points[w.apex as usize];
            let cl = match orient3d(a, b, c0, c) {
                Sign::Positive => 1,
                Sign::Negative => 3,
                Sign::Zero => {
                    let s = orient2d(a2, b2, drop_axis(c, axis));
                    if s == Sign::Zero {
                        return Err(w.edge);
                    }
                    if s == s0 { 0 } else { 2 }
                }
            };
            self.classed.push((cl, *w));
        }
        self.classed.sort_by(|&(cx, wx), &(cy, wy)| {
            if cx != cy {
                return cx.cmp(&cy);
            }
            let ang = if cx == 1 || cx == 3 {
                match orient3d(a, b, points[wx.apex as usize], points[wy.apex as usize]) {
                    Sign::Positive => Ordering::Less,
                    Sign::Negative => Ordering::Greater,
                    Sign::Zero => Ordering::Equal,
                }
            } else {
                Ordering::Equal
            };
            // Same half-plane: the backward wing first.
            ang.then(wx.forward.cmp(&wy.forward))
                .then(wx.face.cmp(&wy.face))
        });
        self.group.clear();
        self.group.extend(self.classed.iter().map(|&(_, w)| w));
        Ok(())
    }
}
