//! The insertion kernel: point location by a remembering stochastic walk, the Bowyer–Watson
//! cavity by a breadth-first search over conflicting tets, and the star of new tets that fills it.
//!
//! Storage is one flat array of [`Tet`] records (4 vertices + 4 neighbour links, 32 bytes). A
//! neighbour link is `tet << 2 | face`: the tet across the face and the index of that face in it,
//! so no search is needed to go back. Ghost tets have the infinite vertex [`INF`] in slot 3.
//!
//! A new tet is `[p, x, y, z]`: the new vertex `p` in slot 0 and a cavity-boundary face `xyz`
//! (counter-clockwise seen from outside the cavity, rotated so that `INF`, if there, comes last —
//! which keeps ghosts' `INF` in slot 3). Its face 0 is the boundary face; its faces 1, 2, 3 hold
//! `p` and the boundary edges `zy`, `xz`, `yx` (directed as seen from `p`), and the new tet
//! across each has the same edge reversed. The boundary vertices get small local numbers (a
//! byte per vertex, reset by the insertion that uses it), and a 64×64 table indexed by local
//! numbers pairs the faces: one write and one read per face, no search, no branch. Cavities
//! with more than about 60 boundary vertices (rare: very degenerate input) pair their faces
//! through a stamped open-addressing hash table instead.
//!
//! Marks need no clearing: a tet in the current cavity carries [`FLAG`] in `v[0]`; every cavity
//! tet is then either overwritten by a new tet or put on the free list, where it stays flagged.

use super::Delaunay;
use crate::geom::filter::{
    Grid, insphere_certified, insphere_decide, insphere_det, insphere_det_fma, insphere_sos_slow,
    orient3d_on,
};
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
/// Side of the local face-pairing table (local vertex numbers `0..LOCAL`, 0 for `INF`).
pub(crate) const LOCAL: usize = 64;

/// One tet: vertices (internal ids, positively oriented; ghosts have [`INF`] in slot 3) and the
/// links `neighbor << 2 | face in neighbor` across the face opposite each vertex.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[repr(C, align(32))]
pub(crate) struct Tet {
    pub v: [u32; 4],
    pub n: [u32; 4],
}

/// A face of the cavity boundary: the new tet is `[p, v[0], v[1], v[2]]` (`INF`, if present, is
/// `v[2]`), and `outer` links to the tet outside.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Boundary {
    pub v: [u32; 3],
    pub outer: u32,
}

/// Face `f` of a tet as local vertex indices: a cyclic rotation of `TET_FACES[f]` (so the same
/// orientation) that puts slot 3 last whenever the face contains it.
const FACE_ROT: [[usize; 3]; 4] = [[1, 2, 3], [2, 0, 3], [0, 1, 3], [0, 2, 1]];

const _: () = {
    // FACE_ROT[f] is TET_FACES[f] rotated.
    let mut f = 0;
    while f < 4 {
        let (r, t) = (FACE_ROT[f], TET_FACES[f]);
        let mut k = 0;
        while t[k] != r[0] {
            k += 1;
        }
        assert!(t[(k + 1) % 3] == r[1] && t[(k + 2) % 3] == r[2]);
        f += 1;
    }
};

/// An entry of the fallback hash table that pairs the new tets' faces: the directed
/// cavity-boundary edge `(a, b)` and the link of the face that holds it.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct EdgeSlot {
    /// `a << 32 | b`.
    pub key: u64,
    pub link: u32,
    pub stamp: u32,
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

/// What [`locate`] found.
pub(crate) enum Located {
    /// A tet in conflict with the point (contains it, or a ghost that sees it).
    Conflict(u32),
    /// The point is exactly this existing vertex (internal id).
    Duplicate(u32),
}

/// `pts[v]`, unchecked in release builds.
///
/// Safety: `v < pts.len()` — true of every vertex of a live tet except [`INF`], which callers
/// never look up.
#[inline(always)]
unsafe fn pt(pts: &[[f64; 3]], v: u32) -> [f64; 3] {
    debug_assert!((v as usize) < pts.len());
    // SAFETY: the caller guarantees the bound.
    unsafe { *pts.get_unchecked(v as usize) }
}

/// `&tets[t]`, unchecked in release builds.
///
/// Safety: `t < tets.len()` — true of every link stored in a live tet (the array never shrinks).
#[inline(always)]
unsafe fn rec(tets: &[Tet], t: u32) -> &Tet {
    debug_assert!((t as usize) < tets.len());
    // SAFETY: the caller guarantees the bound.
    unsafe { tets.get_unchecked(t as usize) }
}

/// `&mut tets[t]`, unchecked in release builds (same contract as [`rec`]).
#[inline(always)]
unsafe fn rec_mut(tets: &mut [Tet], t: u32) -> &mut Tet {
    debug_assert!((t as usize) < tets.len());
    // SAFETY: the caller guarantees the bound.
    unsafe { tets.get_unchecked_mut(t as usize) }
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
#[inline(always)]
fn locate(
    tets: &[Tet],
    pts: &[[f64; 3]],
    grid: Grid,
    start: u32,
    p: [f64; 3],
    rng: &mut u32,
) -> Located {
    let mut t = start;
    let mut from = 4usize;
    loop {
        // SAFETY (this loop): `t` is `start` (a live tet) or a link of a live tet; vertices are
        // looked up only when finite.
        let tt = *unsafe { rec(tets, t) };
        if tt.v[3] == INF {
            // Ghost: its finite face 3 = (v0, v2, v1) faces the hull's interior.
            let (a, b, c) = unsafe { (pt(pts, tt.v[0]), pt(pts, tt.v[2]), pt(pts, tt.v[1])) };
            if orient3d_on(a, b, c, p, grid) == Sign::Negative {
                return Located::Conflict(t);
            }
            from = (tt.n[3] & 3) as usize;
            t = tt.n[3] >> 2;
            continue;
        }
        // (Built element by element: a `map` goes through a stack copy that stalls the loads.)
        let q = unsafe {
            [
                pt(pts, tt.v[0]),
                pt(pts, tt.v[1]),
                pt(pts, tt.v[2]),
                pt(pts, tt.v[3]),
            ]
        };
        let r = xorshift(rng) as usize;
        let mut moved = false;
        for k in 0..4 {
            let i = (r + k) & 3;
            if i == from {
                continue;
            }
            let l = TET_FACES[i];
            if orient3d_on(q[l[0]], q[l[1]], q[l[2]], p, grid) == Sign::Positive {
                from = (tt.n[i] & 3) as usize;
                t = tt.n[i] >> 2;
                moved = true;
                break;
            }
        }
        if !moved {
            if let Some(k) = q.iter().position(|&x| x == p) {
                return Located::Duplicate(tt.v[k]);
            }
            return Located::Conflict(t);
        }
    }
}

/// What the conflict tests of one insertion need besides the tets.
#[derive(Clone, Copy)]
struct Kernel<'a> {
    pts: &'a [[f64; 3]],
    ids: &'a [u32],
    grid: Grid,
    /// Use the fused multiply-add filter (only true in kernels compiled with FMA).
    fma: bool,
    /// The new vertex and its coordinates.
    vi: u32,
    p: [f64; 3],
}

/// In-sphere conflict of the finite tet with vertices `v` (flag cleared) with vertex `vi` at
/// `p`, decided with Simulation of Simplicity by public vertex number.
#[inline(always)]
fn finite_conflict(k: &Kernel, v: [u32; 4]) -> bool {
    // SAFETY: the vertices of a finite tet index `pts`.
    let (a, b, c, d) = unsafe {
        (
            pt(k.pts, v[0]),
            pt(k.pts, v[1]),
            pt(k.pts, v[2]),
            pt(k.pts, v[3]),
        )
    };
    let [det, m] = if k.fma {
        insphere_det_fma(a, b, c, d, k.p)
    } else {
        insphere_det(a, b, c, d, k.p)
    };
    // The usual case: a certified sign, returned as data (no branch on it: conflicts are
    // unpredictable, and the cavity search consumes the answer without branching).
    if insphere_certified(det, m) {
        return det < 0.0;
    }
    finite_conflict_uncertain(k, v, det, m)
}

#[inline(never)]
fn finite_conflict_uncertain(k: &Kernel, v: [u32; 4], det: f64, m: f64) -> bool {
    match insphere_decide(det, m, k.grid) {
        Some(Sign::Positive) => true,
        Some(Sign::Negative) => false,
        // Exactly cospherical (certified by the grid): the perturbation decides.
        Some(Sign::Zero) => cospherical_conflict(k, v),
        None => finite_conflict_exact(k, v),
    }
}

#[inline(never)]
fn finite_conflict_exact(k: &Kernel, v: [u32; 4]) -> bool {
    let q = v.map(|x| k.pts[x as usize]);
    let id = v.map(|x| k.ids[x as usize]);
    let pid = k.ids[k.vi as usize];
    let s = insphere_sos_slow(
        [q[0], q[1], q[2], q[3], k.p],
        [id[0], id[1], id[2], id[3], pid],
        k.grid,
    );
    s == Sign::Positive
}

/// Conflict of the finite tet `v` (positively oriented) with `p` when the five points are
/// exactly cospherical: the cofactors of `insphere_sos` (see `predicates::insphere_sos`),
/// largest vertex number first. The cofactor of p's lift is the orientation of the tet itself,
/// positive: when p has the largest number it is pushed out of the sphere.
#[inline(always)]
fn cospherical_conflict(k: &Kernel, v: [u32; 4]) -> bool {
    // SAFETY: the vertices of a finite tet index `pts` and `ids` (which have the same length).
    let (q, id) = unsafe {
        (
            [
                pt(k.pts, v[0]),
                pt(k.pts, v[1]),
                pt(k.pts, v[2]),
                pt(k.pts, v[3]),
            ],
            v.map(|x| *k.ids.get_unchecked(x as usize)),
        )
    };
    let pid = k.ids[k.vi as usize];
    let mut left = [true; 4];
    loop {
        let mut best = 4;
        let mut best_id = pid;
        for s in 0..4 {
            if left[s] && id[s] > best_id {
                best = s;
                best_id = id[s];
            }
        }
        // The other four points in slot order: q without slot `best`, then p.
        let (a, b, c) = match best {
            0 => (q[1], q[2], q[3]),
            1 => (q[0], q[2], q[3]),
            2 => (q[0], q[1], q[3]),
            3 => (q[0], q[1], q[2]),
            _ => return false,
        };
        left[best] = false;
        let o = orient3d_on(a, b, c, k.p, k.grid);
        if o != Sign::Zero {
            return o.times(best % 2 == 1) == Sign::Positive;
        }
    }
}

/// Conflict of the live, unflagged tet `t` (record `r`) with vertex `vi` at `p`.
///
/// A ghost `(a, b, c, ∞)` conflicts when `p` is strictly on the outer side of its hull face;
/// when `p` is on the face's plane it conflicts exactly when the finite tet across the hull
/// face does: both are the perturbed in-circle test of `p` against the circle of `abc`, the
/// limit of the in-sphere test of the ghost as its fourth vertex goes to infinity (see the
/// module docs of [`super`]).
#[inline(always)]
fn conflict(tets: &[Tet], k: &Kernel, r: &Tet) -> bool {
    if r.v[3] == INF {
        ghost_conflict(tets, k, r)
    } else {
        finite_conflict(k, r.v)
    }
}

#[inline(never)]
fn ghost_conflict(tets: &[Tet], k: &Kernel, r: &Tet) -> bool {
    let (a, b, c) = (
        k.pts[r.v[0] as usize],
        k.pts[r.v[2] as usize],
        k.pts[r.v[1] as usize],
    );
    match orient3d_on(a, b, c, k.p, k.grid) {
        Sign::Negative => true,
        Sign::Positive => false,
        Sign::Zero => {
            let mut v = tets[(r.n[3] >> 2) as usize].v;
            v[0] &= !FLAG;
            // (This cold function is compiled for the baseline target: no fused multiply-add.)
            let plain = Kernel { fma: false, ..*k };
            finite_conflict(&plain, v)
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

/// Grow the cavity of vertex `k.vi` from the conflicting tet `start`: fills `cavity` with the
/// conflicting tets (flagged) and `bnd` with the cavity's boundary faces.
#[inline(always)]
fn find_cavity(
    tets: &mut [Tet],
    k: &Kernel,
    start: u32,
    cavity: &mut Vec<u32>,
    bnd: &mut Vec<Boundary>,
    local: &mut [u8],
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
        // SAFETY: cavity tets are live.
        let mut tt = *unsafe { rec(tets, t) };
        tt.v[0] &= !FLAG;
        visit_face::<0>(tets, k, &tt, cavity, bnd, local);
        visit_face::<1>(tets, k, &tt, cavity, bnd, local);
        visit_face::<2>(tets, k, &tt, cavity, bnd, local);
        visit_face::<3>(tets, k, &tt, cavity, bnd, local);
    }
}

/// The neighbour of cavity tet `tt` (flag cleared) across face `F`: skipped when already in the
/// cavity, added to it when in conflict, its face recorded as cavity boundary otherwise (and
/// the local numbers of its vertices reset, for [`pair_local`]).
#[inline(always)]
fn visit_face<const F: usize>(
    tets: &mut [Tet],
    k: &Kernel,
    tt: &Tet,
    cavity: &mut Vec<u32>,
    bnd: &mut Vec<Boundary>,
    local: &mut [u8],
) {
    let link = tt.n[F];
    let u = link >> 2;
    // SAFETY: links of live tets index live tets.
    let r = *unsafe { rec(tets, u) };
    if r.v[0] & FLAG != 0 {
        return;
    }
    // Both outcomes are written, and the lengths advanced by the answer: no unpredictable
    // branch. (Every vertex of a cavity tet is on the cavity boundary, so resetting the local
    // numbers of the face's vertices is right either way.)
    let hit = conflict(tets, k, &r);
    let l = FACE_ROT[F];
    let v = [tt.v[l[0]], tt.v[l[1]], tt.v[l[2]]];
    cavity.reserve(1);
    bnd.reserve(1);
    // SAFETY: `u` is live; one free element was reserved in each list; finite vertex ids
    // index `local` (sized like `pts`).
    unsafe {
        rec_mut(tets, u).v[0] |= FLAG * u32::from(hit);
        let (nc, nb) = (cavity.len(), bnd.len());
        cavity.as_mut_ptr().add(nc).write(u);
        cavity.set_len(nc + usize::from(hit));
        bnd.as_mut_ptr().add(nb).write(Boundary { v, outer: link });
        bnd.set_len(nb + usize::from(!hit));
        for x in v {
            if x != INF {
                *local.get_unchecked_mut(x as usize) = u8::MAX;
            }
        }
    }
    prefetch_neighbors(tets, &r);
}

/// `tets[t].n[i] = link`, unchecked in release builds.
///
/// Safety: `t < tets.len()` and `i < 4`; links stored in live tets always satisfy this.
#[inline(always)]
unsafe fn set_link(tets: &mut [Tet], t: u32, i: u32, link: u32) {
    debug_assert!((t as usize) < tets.len() && i < 4);
    // SAFETY: the caller guarantees the bounds.
    unsafe {
        *tets
            .get_unchecked_mut(t as usize)
            .n
            .get_unchecked_mut(i as usize) = link
    };
}

/// Scratch space of [`fill_star`], reused by every insertion.
#[derive(Debug, Clone, Default)]
pub(crate) struct StarScratch {
    /// Local number of each vertex (by internal id); only meaningful for the boundary vertices
    /// of the current insertion, which reset theirs first.
    pub local: Vec<u8>,
    /// Local numbers of the boundary faces' vertices.
    pub lids: Vec<[u8; 3]>,
    /// `LOCAL × LOCAL` table: the link of the new face holding a directed edge.
    pub map: Vec<u32>,
    /// Fallback hash table and its stamp.
    pub edges: Vec<EdgeSlot>,
    pub stamp: u32,
    /// Always use the fallback (for tests).
    pub force_hash: bool,
}

/// Build the star of new tets around vertex `p`: `bnd[k]` becomes `[p, bnd[k].v]` in slot
/// `slots[k]`, linked to its outer tet and to its three neighbours in the star. Returns a new
/// finite tet.
#[inline(always)]
fn fill_star(
    tets: &mut [Tet],
    sc: &mut StarScratch,
    bnd: &[Boundary],
    slots: &[u32],
    p: u32,
) -> u32 {
    assert!(slots.len() >= bnd.len());
    assert!(slots.iter().all(|&t| (t as usize) < tets.len()));
    if sc.force_hash || !pair_local(tets, sc, bnd, slots, p) {
        pair_hashed(tets, sc, bnd, slots, p);
    }
    let mut last = NONE;
    for (b, &nt) in bnd.iter().zip(slots) {
        if b.v[2] != INF {
            last = nt;
            break;
        }
    }
    last
}

/// Pair the star's faces through local vertex numbers and write the new tets; false (no tet
/// written) when the cavity boundary has more vertices than local numbers fit (about 60). The
/// boundary vertices' local numbers were reset to `u8::MAX` by [`find_cavity`].
#[inline(always)]
fn pair_local(
    tets: &mut [Tet],
    sc: &mut StarScratch,
    bnd: &[Boundary],
    slots: &[u32],
    p: u32,
) -> bool {
    let local = &mut sc.local[..];
    let map = &mut sc.map[..LOCAL * LOCAL];
    // Local numbers are below LOCAL, so every index is in the table.
    let at = |a: u8, b: u8| a as usize * LOCAL + b as usize;
    sc.lids.clear();
    let mut count = 1u8;
    for (b, &nt) in bnd.iter().zip(slots) {
        // Room for three new numbers below LOCAL (a predictable branch, kept out of the loop).
        if count as usize > LOCAL - 3 {
            return false;
        }
        let mut l = [0u8; 3];
        for (li, &v) in l.iter_mut().zip(&b.v) {
            if v != INF {
                // SAFETY: finite vertex ids index `local` (sized like `pts`).
                let x = unsafe { local.get_unchecked_mut(v as usize) };
                // First sight of the vertex (reset to u8::MAX by `find_cavity`): the next number.
                // Branch-free, as first sights are unpredictable.
                let fresh = *x == u8::MAX;
                let id = if fresh { count } else { *x };
                *x = id;
                count += u8::from(fresh);
                *li = id;
            }
        }
        let [x, y, z] = l;
        // SAFETY: local numbers are below LOCAL.
        unsafe {
            *map.get_unchecked_mut(at(z, y)) = nt << 2 | 1;
            *map.get_unchecked_mut(at(x, z)) = nt << 2 | 2;
            *map.get_unchecked_mut(at(y, x)) = nt << 2 | 3;
        }
        sc.lids.push(l);
    }
    for ((b, l), &nt) in bnd.iter().zip(&sc.lids).zip(slots) {
        let [x, y, z] = *l;
        // SAFETY: local numbers are below LOCAL; `outer` is the link of a live tet; every slot
        // was checked by `fill_star`.
        unsafe {
            let r = Tet {
                v: [p, b.v[0], b.v[1], b.v[2]],
                n: [
                    b.outer,
                    *map.get_unchecked(at(y, z)),
                    *map.get_unchecked(at(z, x)),
                    *map.get_unchecked(at(x, y)),
                ],
            };
            set_link(tets, b.outer >> 2, b.outer & 3, nt << 2);
            *tets.get_unchecked_mut(nt as usize) = r;
        }
    }
    true
}

/// Pair the star's faces through a hash table keyed by the directed boundary edges (for
/// cavities too large for [`pair_local`]).
fn pair_hashed(tets: &mut [Tet], sc: &mut StarScratch, bnd: &[Boundary], slots: &[u32], p: u32) {
    let need = (6 * bnd.len()).next_power_of_two().max(128);
    if sc.edges.len() < need {
        sc.edges.resize(need, EdgeSlot::default());
    }
    sc.stamp = sc.stamp.wrapping_add(1);
    if sc.stamp == 0 {
        sc.edges.fill(EdgeSlot::default());
        sc.stamp = 1;
    }
    let stamp = sc.stamp;
    let edges = &mut sc.edges[..need];
    let mask = need - 1;
    let shift = 32 - need.trailing_zeros();
    for (b, &nt) in bnd.iter().zip(slots) {
        let [x, y, z] = b.v;
        let mut n = [b.outer, 0, 0, 0];
        tets[(b.outer >> 2) as usize].n[(b.outer & 3) as usize] = nt << 2;
        for (j, (a, c)) in [(z, y), (x, z), (y, x)].into_iter().enumerate() {
            let j = j + 1;
            let key = u64::from(a) << 32 | u64::from(c);
            let rev = u64::from(c) << 32 | u64::from(a);
            let mut h = (a.wrapping_add(c).wrapping_mul(0x9E37_79B1) >> shift) as usize;
            loop {
                let e = &mut edges[h & mask];
                if e.stamp != stamp {
                    *e = EdgeSlot {
                        key,
                        link: nt << 2 | j as u32,
                        stamp,
                    };
                    break;
                }
                if e.key == rev {
                    n[j] = e.link;
                    tets[(e.link >> 2) as usize].n[(e.link & 3) as usize] = nt << 2 | j as u32;
                    break;
                }
                h += 1;
            }
        }
        // Faces paired later are written into this record by their partner.
        tets[nt as usize] = Tet { v: [p, x, y, z], n };
    }
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

    /// Replace the cavity (`self.cavity`, `self.bnd`) by the star of new tets around vertex
    /// `vi`: cavity slots are reused first, then the free list, then new slots.
    fn fill_cavity(&mut self, vi: u32) {
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
        let last = kernels::fill_star(
            self.isa,
            &mut self.tets,
            &mut self.star,
            &self.bnd,
            &self.slots,
            vi,
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
        if self.star.local.len() < self.pts.len() {
            self.star.local.resize(self.pts.len(), 0);
        }
        let grid = self.grid;
        let start = match kernels::locate(
            self.isa,
            &self.tets,
            &self.pts,
            grid,
            self.last,
            p,
            &mut self.walk_rng,
        ) {
            Located::Conflict(t) => t,
            Located::Duplicate(v) => return Inserted::Duplicate(v),
        };
        #[cfg(target_arch = "x86_64")]
        let fma = self.isa == Isa::V4;
        #[cfg(not(target_arch = "x86_64"))]
        let fma = false;
        let k = Kernel {
            pts: &self.pts,
            ids: &self.ids,
            grid,
            fma,
            vi,
            p,
        };
        kernels::find_cavity(
            self.isa,
            &mut self.tets,
            &k,
            start,
            &mut self.cavity,
            &mut self.bnd,
            &mut self.star.local,
        );
        let (nb, nc) = (self.bnd.len(), self.cavity.len());
        if nb > nc + self.n_free && self.tets.len() + (nb - nc - self.n_free) > MAX_TETS {
            self.unflag_cavity();
            return Inserted::Full;
        }
        self.fill_cavity(vi);
        Inserted::Done
    }
}

/// The instruction set the hot kernels run with, detected once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Isa {
    /// Whatever the target was compiled for.
    Baseline,
    /// x86-64-v4 (AVX-512 F/BW/CD/DQ/VL on top of AVX2, FMA, BMI): the same code compiled for
    /// it, about 10% faster (mostly thanks to 32 vector registers: the filters spill less).
    #[cfg(target_arch = "x86_64")]
    V4,
}

impl Isa {
    /// The best instruction set of this CPU.
    pub(crate) fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            use std::is_x86_feature_detected as has;
            if has!("avx2")
                && has!("fma")
                && has!("bmi1")
                && has!("bmi2")
                && has!("lzcnt")
                && has!("popcnt")
                && has!("avx512f")
                && has!("avx512dq")
                && has!("avx512vl")
                && has!("avx512bw")
                && has!("avx512cd")
            {
                return Isa::V4;
            }
        }
        Isa::Baseline
    }
}

/// Each hot kernel twice: compiled for the baseline target and for x86-64-v4, chosen at run time
/// by [`Isa`]. The v4 kernels run the insphere filter with fused multiply-adds (different float
/// values, the same certified signs), so both make exactly the same decisions and the same
/// triangulation. They stay separate functions: inlining them all into one made the whole slower.
mod kernels {
    use super::*;

    macro_rules! dispatch {
        ($(fn $name:ident($($arg:ident: $ty:ty),*) -> $ret:ty;)*) => {
            $(
                pub(super) fn $name(isa: Isa, $($arg: $ty),*) -> $ret {
                    match isa {
                        Isa::Baseline => base::$name($($arg),*),
                        // SAFETY: `Isa::V4` is only ever detected on CPUs with these features.
                        #[cfg(target_arch = "x86_64")]
                        Isa::V4 => unsafe { v4::$name($($arg),*) },
                    }
                }
            )*
            mod base {
                use super::*;
                $(
                    #[inline(never)]
                    pub(super) fn $name($($arg: $ty),*) -> $ret {
                        super::super::$name($($arg),*)
                    }
                )*
            }
            #[cfg(target_arch = "x86_64")]
            mod v4 {
                use super::*;
                $(
                    #[target_feature(
                        enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,popcnt,avx512f,avx512dq,avx512vl,avx512bw,avx512cd"
                    )]
                    pub(super) unsafe fn $name($($arg: $ty),*) -> $ret {
                        super::super::$name($($arg),*)
                    }
                )*
            }
        };
    }

    dispatch! {
        fn locate(
            tets: &[Tet], pts: &[[f64; 3]], grid: Grid, start: u32, p: [f64; 3], rng: &mut u32
        ) -> Located;
        fn find_cavity(
            tets: &mut [Tet],
            k: &Kernel,
            start: u32,
            cavity: &mut Vec<u32>,
            bnd: &mut Vec<Boundary>,
            local: &mut [u8]
        ) -> ();
        fn fill_star(
            tets: &mut [Tet], sc: &mut StarScratch, bnd: &[Boundary], slots: &[u32], p: u32
        ) -> u32;
    }
}
