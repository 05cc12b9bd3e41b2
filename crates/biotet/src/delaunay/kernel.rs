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
use crate::geom::filter::{insphere_filter, insphere_sos_slow, orient3d};
use crate::geom::predicates::Sign;
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
    /// `a << 32 | b`.
    pub key: u64,
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

#[inline(always)]
fn xorshift(x: &mut u32) -> u32 {
    *x ^= *x << 13;
    *x ^= *x >> 17;
    *x ^= *x << 5;
    *x
}

/// Remembering stochastic walk from `start` to a tet in conflict with `p`: a finite tet whose
/// closure contains `p` (then `p` is strictly inside its circumsphere unless it is a vertex), or
/// a ghost whose hull face `p` is strictly outside of.
fn locate(tets: &[Tet], pts: &[[f64; 3]], start: u32, p: [f64; 3], rng: &mut u32) -> Located {
    let mut t = start;
    let mut from = 4usize;
    loop {
        let tt = tets[t as usize];
        if tt.v[3] == INF {
            // Ghost: its finite face 3 = (v0, v2, v1) faces the hull's interior.
            let (a, b, c) = (
                pts[tt.v[0] as usize],
                pts[tt.v[2] as usize],
                pts[tt.v[1] as usize],
            );
            if orient3d(a, b, c, p) == Sign::Negative {
                return Located::Conflict(t);
            }
            from = (tt.n[3] & 3) as usize;
            t = tt.n[3] >> 2;
            continue;
        }
        let q = tt.v.map(|v| pts[v as usize]);
        let r = xorshift(rng) as usize;
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

/// In-sphere conflict of the finite tet with vertices `v` (flag cleared) with vertex `vi` at
/// `p`, decided with Simulation of Simplicity by public vertex number.
#[inline(always)]
fn finite_conflict(pts: &[[f64; 3]], ids: &[u32], v: [u32; 4], vi: u32, p: [f64; 3]) -> bool {
    let q = v.map(|x| pts[x as usize]);
    match insphere_filter(q[0], q[1], q[2], q[3], p) {
        Some(s) => s == Sign::Positive,
        None => finite_conflict_exact(pts, ids, v, vi, p),
    }
}

#[inline(never)]
fn finite_conflict_exact(pts: &[[f64; 3]], ids: &[u32], v: [u32; 4], vi: u32, p: [f64; 3]) -> bool {
    let q = v.map(|x| pts[x as usize]);
    let id = v.map(|x| ids[x as usize]);
    insphere_sos_slow(
        [q[0], q[1], q[2], q[3], p],
        [id[0], id[1], id[2], id[3], ids[vi as usize]],
    ) == Sign::Positive
}

/// Conflict of the live, unflagged tet `t` (record `r`) with vertex `vi` at `p`.
///
/// A ghost `(a, b, c, ∞)` conflicts when `p` is strictly on the outer side of its hull face;
/// when `p` is on the face's plane it conflicts exactly when the finite tet across the hull
/// face does: both are the perturbed in-circle test of `p` against the circle of `abc`, the
/// limit of the in-sphere test of the ghost as its fourth vertex goes to infinity (see the
/// module docs of [`super`]).
#[inline(always)]
fn conflict(tets: &[Tet], pts: &[[f64; 3]], ids: &[u32], r: &Tet, vi: u32, p: [f64; 3]) -> bool {
    if r.v[3] == INF {
        ghost_conflict(tets, pts, ids, r, vi, p)
    } else {
        finite_conflict(pts, ids, r.v, vi, p)
    }
}

#[inline(never)]
fn ghost_conflict(tets: &[Tet], pts: &[[f64; 3]], ids: &[u32], r: &Tet, vi: u32, p: [f64; 3]) -> bool {
    let (a, b, c) = (
        pts[r.v[0] as usize],
        pts[r.v[2] as usize],
        pts[r.v[1] as usize],
    );
    match orient3d(a, b, c, p) {
        Sign::Negative => true,
        Sign::Positive => false,
        Sign::Zero => {
            let mut v = tets[(r.n[3] >> 2) as usize].v;
            v[0] &= !FLAG;
            finite_conflict(pts, ids, v, vi, p)
        }
    }
}

/// Ask the memory system for the records of the four neighbours of `r`.
#[inline(always)]
fn prefetch_neighbors(tets: &[Tet], r: &Tet) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        for l in r.n {
            let ptr = tets.as_ptr().wrapping_add((l >> 2) as usize);
            // SAFETY: a prefetch never faults, whatever the address.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(ptr.cast::<i8>()) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (tets, r);
}

/// Grow the cavity of vertex `vi` at `p` from the conflicting tet `start`: fills `cavity` with
/// the conflicting tets (flagged) and `bnd` with the cavity's boundary faces.
#[allow(clippy::too_many_arguments)]
fn find_cavity(
    tets: &mut [Tet],
    pts: &[[f64; 3]],
    ids: &[u32],
    vi: u32,
    p: [f64; 3],
    start: u32,
    cavity: &mut Vec<u32>,
    bnd: &mut Vec<Boundary>,
) {
    cavity.clear();
    bnd.clear();
    tets[start as usize].v[0] |= FLAG;
    cavity.push(start);
    prefetch_neighbors(tets, &tets[start as usize]);
    // Breadth-first: the cavity list is the queue, which leaves time for the prefetches.
    let mut next = 0;
    while next < cavity.len() {
        let t = cavity[next];
        next += 1;
        let tt = tets[t as usize];
        for f in 0..4 {
            let link = tt.n[f];
            let u = (link >> 2) as usize;
            let r = tets[u];
            if r.v[0] & FLAG != 0 {
                continue;
            }
            if conflict(tets, pts, ids, &r, vi, p) {
                tets[u].v[0] |= FLAG;
                cavity.push(u as u32);
                prefetch_neighbors(tets, &r);
            } else {
                let mut v = tt.v;
                v[0] &= !FLAG;
                v[f] = vi;
                bnd.push(Boundary {
                    v,
                    outer: link,
                    f: f as u32,
                });
            }
        }
    }
}

/// Pair the three faces of new tet `nt` (record being built in `n`, new vertex in slot `F`)
/// around the new vertex with faces of the star built before, or leave them in the table for
/// the faces built after.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn pair_faces<const F: usize>(
    tets: &mut [Tet],
    edges: &mut [EdgeSlot],
    v: &[u32; 4],
    nt: u32,
    n: &mut [u32; 4],
    stamp: u32,
    shift: u32,
    mask: usize,
) {
    for j in 0..4 {
        if j == F {
            continue;
        }
        let (ea, eb) = EDGE[F][j];
        let (x, y) = (v[ea], v[eb]);
        let key = u64::from(x) << 32 | u64::from(y);
        let rev = u64::from(y) << 32 | u64::from(x);
        let mut h = ((x.wrapping_add(y)).wrapping_mul(0x9E37_79B1) >> shift) as usize;
        loop {
            let e = &mut edges[h];
            if e.stamp != stamp {
                *e = EdgeSlot {
                    key,
                    link: nt << 2 | j as u32,
                    stamp,
                };
                break;
            }
            if e.key == rev {
                let other = e.link;
                n[j] = other;
                tets[(other >> 2) as usize].n[(other & 3) as usize] = nt << 2 | j as u32;
                break;
            }
            h = (h + 1) & mask;
        }
    }
}

/// Build the star of new tets: `bnd[k]` goes to slot `slots[k]`. Faces around the new vertex are
/// paired through `edges`, keyed by their directed cavity-boundary edge (entries of other stamps
/// count as empty). Returns a new finite tet, or `NONE`.
fn fill_star(
    tets: &mut [Tet],
    edges: &mut [EdgeSlot],
    bnd: &[Boundary],
    slots: &[u32],
    stamp: u32,
) -> u32 {
    let mask = edges.len() - 1;
    let shift = 32 - edges.len().trailing_zeros();
    let mut last = NONE;
    for (b, &nt) in bnd.iter().zip(slots) {
        let f = b.f as usize;
        let mut n = [0u32; 4];
        n[f] = b.outer;
        tets[(b.outer >> 2) as usize].n[(b.outer & 3) as usize] = nt << 2 | b.f;
        if b.v[3] != INF {
            last = nt;
        }
        match f {
            0 => pair_faces::<0>(tets, edges, &b.v, nt, &mut n, stamp, shift, mask),
            1 => pair_faces::<1>(tets, edges, &b.v, nt, &mut n, stamp, shift, mask),
            2 => pair_faces::<2>(tets, edges, &b.v, nt, &mut n, stamp, shift, mask),
            _ => pair_faces::<3>(tets, edges, &b.v, nt, &mut n, stamp, shift, mask),
        }
        // Faces paired later are written into this record by their partner.
        tets[nt as usize] = Tet { v: b.v, n };
    }
    last
}

impl Delaunay {
    /// Undo the cavity marks (when the insertion is abandoned).
    fn unflag_cavity(&mut self) {
        for &t in &self.cavity {
            self.tets[t as usize].v[0] &= !FLAG;
        }
    }

    /// Room for `extra` more tet slots without the doubling growth of `Vec` (which would waste
    /// up to half the largest array of the program): grow by an eighth at a time.
    fn reserve_tets(&mut self, extra: usize) {
        let need = self.tets.len() + extra;
        if need > self.tets.capacity() {
            let grow = (self.tets.capacity() / 8).max(extra).max(1024);
            self.tets.reserve_exact(grow);
        }
    }

    /// Replace the cavity (`self.cavity`, `self.bnd`) by the star of new tets around the new
    /// vertex: cavity slots are reused first, then the free list, then new slots.
    fn fill_cavity(&mut self) {
        let nb = self.bnd.len();
        let nc = self.cavity.len();
        self.slots.clear();
        self.slots.extend_from_slice(&self.cavity[..nb.min(nc)]);
        while self.slots.len() < nb && self.free != NONE {
            let t = self.free;
            self.free = self.tets[t as usize].n[0];
            self.n_free -= 1;
            self.slots.push(t);
        }
        if self.slots.len() < nb {
            let extra = nb - self.slots.len();
            self.reserve_tets(extra);
            let first = self.tets.len() as u32;
            self.tets.resize(self.tets.len() + extra, Tet::default());
            self.slots.extend(first..first + extra as u32);
        }
        for k in nb..nc {
            let t = self.cavity[k];
            let r = &mut self.tets[t as usize];
            r.v = [FLAG; 4];
            r.n[0] = self.free;
            self.free = t;
            self.n_free += 1;
        }
        // Pairing table: load at most 1/4 (each boundary edge is stored once, 3·nb/2 of them).
        let need = (6 * nb).next_power_of_two().max(128);
        if self.edges.len() < need {
            self.edges.resize(need, EdgeSlot::default());
        }
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.edges.fill(EdgeSlot::default());
            self.stamp = 1;
        }
        let last = fill_star(
            &mut self.tets,
            &mut self.edges[..need],
            &self.bnd,
            &self.slots,
            self.stamp,
        );
        if last != NONE {
            self.last = last;
        } else if nb > 0 {
            self.last = self.slots[0];
        }
    }

    /// Insert the point with internal id `vi` (its coordinates are already in `pts`).
    pub(crate) fn insert_internal(&mut self, vi: u32) -> Inserted {
        let p = self.pts[vi as usize];
        let start = match locate(&self.tets, &self.pts, self.last, p, &mut self.walk_rng) {
            Located::Conflict(t) => t,
            Located::Duplicate(v) => return Inserted::Duplicate(v),
        };
        find_cavity(
            &mut self.tets,
            &self.pts,
            &self.ids,
            vi,
            p,
            start,
            &mut self.cavity,
            &mut self.bnd,
        );
        let (nb, nc) = (self.bnd.len(), self.cavity.len());
        if nb > nc + self.n_free && self.tets.len() + (nb - nc - self.n_free) > MAX_TETS {
            self.unflag_cavity();
            return Inserted::Full;
        }
        self.fill_cavity();
        Inserted::Done
    }
}
