//! The insertion kernel: point location by a remembering stochastic walk, the Bowyer–Watson
//! cavity by a depth-first search over conflicting tets, and the star of new tets that fills it.
//!
//! Storage is one flat array of [`Tet`] records (4 vertices + 4 neighbour links, 32 bytes). A
//! neighbour link is `tet << 2 | face`: the tet across the face and the index of that face in it,
//! so no search is needed to go back. Ghost tets have the infinite vertex [`INF`] in slot 3 (an
//! invariant kept by construction: new tets copy a cavity tet and replace one slot by the new
//! vertex, and slot 3 of a ghost is never replaced without the result becoming finite).
//!
//! Marks need no clearing: a tet in the current cavity carries [`FLAG`] in `v[0]`; every cavity
//! tet is then either overwritten by a new tet or put on the free list, where it stays flagged.

use super::Delaunay;
use crate::geom::filter::{insphere_filter, orient3d};
use crate::geom::predicates::{Sign, insphere_sos};
use crate::mesh::tet::TET_FACES;

/// The infinite vertex (internal id).
pub(crate) const INF: u32 = 0x7FFF_FFFF;
/// Cavity / dead mark, or-ed into `v[0]`.
pub(crate) const FLAG: u32 = 0x8000_0000;
/// "No tet" (end of the free list).
pub(crate) const NONE: u32 = u32::MAX;
/// Largest number of tet slots (links keep 2 bits for the face).
pub(crate) const MAX_TETS: usize = 1 << 30;

/// One tet: vertices (internal ids, positively oriented; ghosts have [`INF`] in slot 3) and the
/// links `neighbor << 2 | face in neighbor` across the face opposite each vertex.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[repr(C, align(32))]
pub(crate) struct Tet {
    pub v: [u32; 4],
    pub n: [u32; 4],
}

/// A face of the cavity boundary: the new tet to build (`v`, the cavity tet with slot `f`
/// replaced by the new vertex) and the link to the tet outside.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Boundary {
    pub v: [u32; 4],
    pub outer: u32,
    pub f: u32,
}

/// An entry of the table that pairs the new tets' faces around the new vertex: the directed
/// cavity-boundary edge `(a, b)` and the link of the face that holds it.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct EdgeSlot {
    pub a: u32,
    pub b: u32,
    pub link: u32,
    pub stamp: u32,
}

/// `EDGE[f][j]`: for a new tet whose new vertex is in slot `f`, the face `j ≠ f` rotated to start
/// at slot `f` is `(f, a, b)`; the directed edge `(v[a], v[b])` identifies it, and the new tet on
/// the other side sees the same face as `(f', b', a')`.
const EDGE: [[(usize, usize); 4]; 4] = edge_table();

const fn edge_table() -> [[(usize, usize); 4]; 4] {
    let mut t = [[(0usize, 0usize); 4]; 4];
    let mut f = 0;
    while f < 4 {
        let mut j = 0;
        while j < 4 {
            if j != f {
                let l = TET_FACES[j];
                let k = if l[0] == f {
                    0
                } else if l[1] == f {
                    1
                } else {
                    2
                };
                t[f][j] = (l[(k + 1) % 3], l[(k + 2) % 3]);
            }
            j += 1;
        }
        f += 1;
    }
    t
}

/// The outcome of [`Delaunay::insert_internal`].
pub(crate) enum Inserted {
    /// The vertex is in the triangulation.
    Done,
    /// The point is exactly this existing vertex (internal id); nothing changed.
    Duplicate(u32),
    /// The tet array is full ([`MAX_TETS`]); nothing changed.
    Full,
}

/// What [`Delaunay::locate`] found.
pub(crate) enum Located {
    /// A tet in conflict with the point (contains it, or a ghost that sees it).
    Conflict(u32),
    /// The point is exactly this existing vertex (internal id).
    Duplicate(u32),
}

impl Delaunay {
    #[inline(always)]
    fn pt(&self, v: u32) -> [f64; 3] {
        // SAFETY-free: bounds-checked indexing; internal ids are always < pts.len().
        self.pts[v as usize]
    }

    #[inline(always)]
    fn next_rand(&mut self) -> u32 {
        // xorshift32
        let mut x = self.walk_rng;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.walk_rng = x;
        x
    }

    /// Remembering stochastic walk from `self.last` to a tet in conflict with `p`.
    #[inline(never)]
    pub(crate) fn locate(&mut self, p: [f64; 3]) -> Located {
        let mut t = self.last;
        let mut from = 4usize;
        loop {
            let tt = self.tets[t as usize];
            if tt.v[3] == INF {
                // Ghost: its finite face 3 = (v0, v2, v1) faces the hull's interior.
                let (a, b, c) = (self.pt(tt.v[0]), self.pt(tt.v[2]), self.pt(tt.v[1]));
                if orient3d(a, b, c, p) == Sign::Negative {
                    return Located::Conflict(t);
                }
                from = (tt.n[3] & 3) as usize;
                t = tt.n[3] >> 2;
                continue;
            }
            let q = [
                self.pt(tt.v[0]),
                self.pt(tt.v[1]),
                self.pt(tt.v[2]),
                self.pt(tt.v[3]),
            ];
            let r = self.next_rand() as usize;
            let mut moved = false;
            for k in 0..4 {
                let i = (r + k) & 3;
                if i == from {
                    continue;
                }
                let l = TET_FACES[i];
                if orient3d(q[l[0]], q[l[1]], q[l[2]], p) == Sign::Positive {
                    from = (tt.n[i] & 3) as usize;
                    t = tt.n[i] >> 2;
                    moved = true;
                    break;
                }
            }
            if !moved {
                for k in 0..4 {
                    if q[k] == p {
                        return Located::Duplicate(tt.v[k]);
                    }
                }
                return Located::Conflict(t);
            }
        }
    }

    /// In-sphere conflict of the finite tet `u` (possibly flagged) with vertex `vi` at `p`,
    /// decided with Simulation of Simplicity by public vertex number.
    #[inline(always)]
    fn finite_conflict(&self, u: u32, vi: u32, p: [f64; 3]) -> bool {
        let mut v = self.tets[u as usize].v;
        v[0] &= !FLAG;
        let q = [self.pt(v[0]), self.pt(v[1]), self.pt(v[2]), self.pt(v[3])];
        match insphere_filter(q[0], q[1], q[2], q[3], p) {
            Some(s) => s == Sign::Positive,
            None => self.finite_conflict_exact(v, vi, p),
        }
    }

    #[inline(never)]
    fn finite_conflict_exact(&self, v: [u32; 4], vi: u32, p: [f64; 3]) -> bool {
        let q = [
            self.pt(v[0]),
            self.pt(v[1]),
            self.pt(v[2]),
            self.pt(v[3]),
            p,
        ];
        let ids = [
            self.ids[v[0] as usize],
            self.ids[v[1] as usize],
            self.ids[v[2] as usize],
            self.ids[v[3] as usize],
            self.ids[vi as usize],
        ];
        insphere_sos(q, ids) == Sign::Positive
    }

    /// Conflict of the (unflagged) tet `u` with vertex `vi` at `p`.
    ///
    /// A ghost `(a, b, c, ∞)` conflicts when `p` is strictly on the outer side of its hull face;
    /// when `p` is on the face's plane it conflicts exactly when the finite tet across the hull
    /// face does: both are the perturbed in-circle test of `p` against the circle of `abc`, the
    /// limit of the in-sphere test of the ghost as its fourth vertex goes to infinity (see the
    /// module docs of [`super`]).
    #[inline(always)]
    fn conflict(&self, u: u32, vi: u32, p: [f64; 3]) -> bool {
        let t = &self.tets[u as usize];
        if t.v[3] == INF {
            let (a, b, c) = (self.pt(t.v[0]), self.pt(t.v[2]), self.pt(t.v[1]));
            match orient3d(a, b, c, p) {
                Sign::Negative => true,
                Sign::Positive => false,
                Sign::Zero => self.finite_conflict(t.n[3] >> 2, vi, p),
            }
        } else {
            self.finite_conflict(u, vi, p)
        }
    }

    /// Grow the cavity of vertex `vi` from the conflicting tet `start`: fills `self.cavity` with
    /// the conflicting tets (flagged) and `self.bnd` with the cavity's boundary faces.
    #[inline(never)]
    pub(crate) fn find_cavity(&mut self, vi: u32, p: [f64; 3], start: u32) {
        self.cavity.clear();
        self.bnd.clear();
        self.tets[start as usize].v[0] |= FLAG;
        self.cavity.push(start);
        self.prefetch_neighbors(start);
        // Breadth-first: the cavity list is the queue, which leaves time for the prefetches.
        let mut next = 0;
        while next < self.cavity.len() {
            let t = self.cavity[next];
            next += 1;
            let tt = self.tets[t as usize];
            for f in 0..4 {
                let link = tt.n[f];
                let u = link >> 2;
                if self.tets[u as usize].v[0] & FLAG != 0 {
                    continue;
                }
                if self.conflict(u, vi, p) {
                    self.tets[u as usize].v[0] |= FLAG;
                    self.cavity.push(u);
                    self.prefetch_neighbors(u);
                } else {
                    let mut v = tt.v;
                    v[0] &= !FLAG;
                    v[f] = vi;
                    self.bnd.push(Boundary {
                        v,
                        outer: link,
                        f: f as u32,
                    });
                }
            }
        }
    }

    /// Ask the memory system for the records of the four neighbours of `t`.
    #[inline(always)]
    fn prefetch_neighbors(&self, t: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            let n = self.tets[t as usize].n;
            for l in n {
                let ptr = self.tets.as_ptr().wrapping_add((l >> 2) as usize);
                // SAFETY: prefetching never faults, whatever the address.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(ptr.cast::<i8>()) };
            }
        }
    }

    /// Undo the cavity marks (when the insertion is abandoned).
    pub(crate) fn unflag_cavity(&mut self) {
        for &t in &self.cavity {
            self.tets[t as usize].v[0] &= !FLAG;
        }
    }

    /// Take a tet slot: the free list first, then a new one at the end.
    #[inline]
    fn alloc(&mut self) -> u32 {
        if self.free != NONE {
            let t = self.free;
            self.free = self.tets[t as usize].n[0];
            self.n_free -= 1;
            t
        } else {
            let t = self.tets.len() as u32;
            self.tets.push(Tet::default());
            t
        }
    }

    /// Room for `extra` more tet slots without the doubling growth of `Vec` (which would waste
    /// up to half the largest array of the program): grow by an eighth at a time.
    pub(crate) fn reserve_tets(&mut self, extra: usize) {
        let need = self.tets.len() + extra;
        if need > self.tets.capacity() {
            let grow = (self.tets.capacity() / 8).max(extra).max(1024);
            self.tets.reserve_exact(grow);
        }
    }

    /// Replace the cavity by the star of new tets around `vi`. `self.cavity` and `self.bnd` come
    /// from [`Delaunay::find_cavity`].
    #[inline(never)]
    pub(crate) fn fill_cavity(&mut self) {
        let nb = self.bnd.len();
        let nc = self.cavity.len();
        if nb > nc {
            self.reserve_tets(nb - nc);
        }
        // Pairing table: load at most 1/2 (each boundary edge is stored once).
        let need = (3 * nb).next_power_of_two().max(64);
        if self.edges.len() < need {
            self.edges.resize(need, EdgeSlot::default());
        }
        let mask = need - 1;
        let shift = 32 - need.trailing_zeros();
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.edges.fill(EdgeSlot::default());
            self.stamp = 1;
        }
        let stamp = self.stamp;
        let mut last = NONE;
        for k in 0..nb {
            let b = self.bnd[k];
            let nt = if k < nc { self.cavity[k] } else { self.alloc() };
            let f = b.f as usize;
            {
                let t = &mut self.tets[nt as usize];
                t.v = b.v;
                t.n[f] = b.outer;
            }
            self.tets[(b.outer >> 2) as usize].n[(b.outer & 3) as usize] = nt << 2 | b.f;
            if b.v[3] != INF {
                last = nt;
            }
            for j in 0..4 {
                if j == f {
                    continue;
                }
                let (ea, eb) = EDGE[f][j];
                let (x, y) = (b.v[ea], b.v[eb]);
                let mut h = ((x.wrapping_add(y)).wrapping_mul(0x9E37_79B1) >> shift) as usize;
                loop {
                    let e = &mut self.edges[h];
                    if e.stamp != stamp {
                        *e = EdgeSlot {
                            a: x,
                            b: y,
                            link: nt << 2 | j as u32,
                            stamp,
                        };
                        break;
                    }
                    if e.a == y && e.b == x {
                        let other = e.link;
                        self.tets[nt as usize].n[j] = other;
                        self.tets[(other >> 2) as usize].n[(other & 3) as usize] =
                            nt << 2 | j as u32;
                        break;
                    }
                    h = (h + 1) & mask;
                }
            }
        }
        for k in nb..nc {
            let t = self.cavity[k];
            let r = &mut self.tets[t as usize];
            r.v = [FLAG; 4];
            r.n[0] = self.free;
            self.free = t;
            self.n_free += 1;
        }
        if last == NONE {
            last = if nc > 0 { self.cavity[0] } else { self.last };
        }
        self.last = last;
    }

    /// Insert the point with internal id `vi` (its coordinates are already in `pts`).
    pub(crate) fn insert_internal(&mut self, vi: u32) -> Inserted {
        let p = self.pts[vi as usize];
        let start = match self.locate(p) {
            Located::Conflict(t) => t,
            Located::Duplicate(v) => return Inserted::Duplicate(v),
        };
        self.find_cavity(vi, p, start);
        let (nb, nc) = (self.bnd.len(), self.cavity.len());
        if nb > nc + self.n_free && self.tets.len() + (nb - nc - self.n_free) > MAX_TETS {
            self.unflag_cavity();
            return Inserted::Full;
        }
        self.fill_cavity();
        Inserted::Done
    }
}
