//! 3D Delaunay tetrahedralization: incremental Bowyer–Watson insertion with exact predicates and
//! Simulation of Simplicity, so that every input — lattices, cospherical and coplanar points
//! included — gives a valid triangulation.
//!
//! # Use
//! ```
//! use biotet::delaunay::Delaunay;
//! let pts = vec![
//!     [0.0, 0.0, 0.0],
//!     [1.0, 0.0, 0.0],
//!     [0.0, 1.0, 0.0],
//!     [0.0, 0.0, 1.0],
//!     [1.0, 1.0, 1.0],
//! ];
//! let mut dt = Delaunay::new(&pts).unwrap();
//! let v = dt.insert([0.25, 0.25, 0.25]).unwrap(); // vertex 5
//! assert_eq!(v, 5);
//! let mesh = dt.to_tet_mesh();
//! assert!(biotet::check::check(&mesh, None).valid);
//! ```
//!
//! # Vertex numbering and duplicates
//! Vertices are numbered in the order their points were given, exact duplicates removed: the
//! first occurrence of a coordinate triple (`-0.0 == 0.0`) becomes a vertex, later copies map to
//! it. [`Delaunay::vertex_of_input`] / [`Delaunay::vertex_map`] give the map from input index
//! (counting the points of [`Delaunay::new`] then every inserted point) to vertex number; without
//! duplicates it is the identity. [`Delaunay::to_tet_mesh`] numbers its points the same way.
//!
//! # Which triangulation
//! Degenerate configurations (five cospherical points, four coplanar points on the hull) have
//! several Delaunay triangulations; the one built is the unique triangulation of the
//! *perturbed* points of [`insphere_sos`](crate::geom::predicates::insphere_sos): point `i` is
//! lifted to `|p_i|² + ε_i` with `ε_i` infinitesimal and growing with the vertex number.
//! Equivalently, it is the regular triangulation of these lifted points, which are in general
//! position as far as in-sphere tests go. It depends only on the point set and the vertex
//! numbering, not on the insertion order: building from all points at once or from a part and
//! inserting the rest gives the same tets.
//!
//! # The infinite vertex and coplanar hull points
//! The triangulation is closed by one infinite vertex: each hull face `abc` carries a ghost tet
//! `(a, b, c, ∞)`, so the hull needs no special case. A ghost conflicts with a new point `p` when
//! `p` is strictly outside the plane of `abc`. When `p` is exactly on that plane, the ghost's
//! "circumsphere" (the limit of the sphere through `a, b, c` and a fourth point `q` going to
//! infinity on the outer side) meets the plane in the circumcircle of `abc`, so the test is the
//! in-circle test of `p` against `abc` — and it must be perturbed consistently with
//! `insphere_sos`. For any `q` off the plane, `insphere_sos(a, b, c, q, p)` expands (after the
//! exact determinant, which is the unperturbed in-circle test scaled by the distance of `q`) into
//! the cofactors of the lifts of the five points, largest vertex number first. The cofactor of
//! `q`'s lift is `±orient3d(a, b, c, p) = 0`, so `q` never decides; the cofactor of the lift of
//! each of `a, b, c, p` is `±orient3d(other three, q)`, which is the in-plane orientation of those
//! three times the side of `q`. So for every `q` on one side of the plane the answer is the same:
//! the 2D in-circle test with the same symbolic lifts, i.e. the in-circle test of the perturbed
//! points. Taking `q` = the fourth vertex `d` of the finite tet `(a, c, b, d)` across the hull
//! face (the same sphere family, seen from the positively oriented side) gives the rule used here:
//! **a ghost whose plane contains `p` conflicts with `p` exactly when the finite tet behind its
//! hull face does** (`insphere_sos` on that tet). Finite tets and ghosts thus answer from one
//! and the same perturbed lifting, which makes the conflict region of every point the visible
//! part of one lower convex hull: connected, star-shaped from `p`, and the result a valid
//! triangulation for any input.
//!
//! # Algorithm and performance
//! - Insertion order: exact duplicates removed, then BRIO rounds (sizes growing eightfold, as in
//!   CGAL: fewer rounds and a long final round in Hilbert order, about 6% faster than doubling;
//!   a fixed-seed SplitMix64 RNG) with a Hilbert curve order inside each round (one radix sort of 30-bit
//!   Hilbert keys). The points are copied in that order, so neighbours in space are neighbours in
//!   memory.
//! - Location: a remembering stochastic visibility walk from the last tet created.
//! - Cavity: a breadth-first search over conflicting tets (the cavity list is the queue; the
//!   neighbours of each new cavity tet are prefetched). The in-sphere answer is used as data, not
//!   branched on: each visited neighbour is written both to the cavity and to the boundary list,
//!   and the answer advances one of the two lengths (conflicts are unpredictable; this saves
//!   about 15% of the build). Marks are a bit in the tet record, set on
//!   cavity tets only, and disappear when the slot is reused or freed: nothing is ever cleared.
//! - New tets: `[p, boundary face]`, in the cavity's slots first, then a free list (linked
//!   through the dead records), then new slots. Their faces around `p` are paired with no search:
//!   boundary vertices get local numbers (one byte per vertex), and a 64×64 table of directed
//!   local edges gives each face its partner (a stamped hash table takes over for cavities with
//!   more than about 60 boundary vertices).
//! - Predicates: semi-static float filters in front of the exact adaptive predicates and the
//!   perturbation, plus exact `f64` evaluation for points on a common binary grid (lattices), see
//!   [`crate::geom::filter`]. The hot kernels are compiled twice, for the baseline target and for
//!   x86-64-v4 (AVX-512; the filter then uses fused multiply-adds), chosen at run time; both give
//!   the same triangulation.
//! - Storage: 32 bytes per tet (4 vertices + 4 links `tet << 2 | face`; about 6.75 tets per
//!   random point), 24 bytes per point plus 4 for its vertex number and 1 of scratch; the tet
//!   array grows by an eighth at a time (untouched capacity costs no memory). Buffers are reused:
//!   nothing is allocated per insertion.
//! - Limits: fewer than 2³¹ − 1 points and 2³⁰ tet slots ([`DelaunayError::TooLarge`]).

mod kernel;
pub(crate) mod order;

use crate::geom::filter::Grid;
use crate::geom::predicates::{Sign, orient2d, orient3d};
use crate::mesh::tet::{NO_NEIGHBOR, TET_FACES, TetMesh};
use kernel::{Boundary, FLAG, INF, Inserted, Isa, LOCAL, MAX_TETS, NONE, StarScratch, Tet};
use thiserror::Error;

/// The vertex number standing for the infinite vertex in [`Delaunay::tet`] (slot 3 of ghosts).
pub const INFINITE: u32 = u32::MAX;

/// Seed of the insertion-order RNG (the output is deterministic).
const SEED: u64 = 0x5EED_B107_E7DE_1A01;

/// Why a triangulation could not be built.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum DelaunayError {
    /// A coordinate is NaN or infinite.
    #[error("point {index} has a non-finite coordinate")]
    NonFinite {
        /// Index of the offending point in the input.
        index: usize,
    },
    /// A coordinate is larger than [`MAX_COORDINATE`] in magnitude, or non-zero and smaller
    /// than [`MIN_COORDINATE`]: exact arithmetic could overflow or underflow there.
    #[error(
        "point {index} has a coordinate outside the exact range (0, or magnitude between \
         7.0e-46 and 1e50, where exact arithmetic neither underflows nor overflows): rescale the input"
    )]
    OutOfRange {
        /// Index of the offending point in the input.
        index: usize,
    },
    /// Fewer than 4 distinct points.
    #[error("only {distinct} distinct points: a tetrahedralization needs at least 4")]
    TooFewPoints {
        /// Number of distinct points.
        distinct: usize,
    },
    /// All points lie on one line.
    #[error("all points are collinear: no tetrahedralization exists")]
    Collinear,
    /// All points lie in one plane.
    #[error("all points are coplanar: no tetrahedralization exists")]
    Coplanar,
    /// More points or tets than the 32-bit indices hold.
    #[error("too large: more than 2^31 - 2 points or 2^30 tets")]
    TooLarge,
}

/// A 3D Delaunay tetrahedralization (see the [module docs](self)).
///
/// Tets are addressed by slot ids `0..n_slots()`; a slot holds a finite tet, a ghost tet (one
/// vertex is [`INFINITE`]) or nothing (free). Vertices are addressed by vertex number (the input
/// order with duplicates removed).
#[derive(Debug, Clone)]
pub struct Delaunay {
    /// Point coordinates by internal id (insertion order).
    pts: Vec<[f64; 3]>,
    /// Vertex number of each internal id (also the Simulation-of-Simplicity index).
    ids: Vec<u32>,
    /// Tet records.
    tets: Vec<Tet>,
    /// Head of the free list of tet slots (linked through `n[0]`).
    free: u32,
    /// Length of the free list.
    n_free: usize,
    /// A recently created finite tet (walk start).
    last: u32,
    /// Number of vertices.
    n_vertices: usize,
    /// Number of input points seen (duplicates counted).
    n_inputs: usize,
    /// Input index -> vertex number; `None` while it is the identity.
    input_vertex: Option<Vec<u32>>,
    /// Grid certificate of all points (exact fast predicates on lattices).
    grid: Grid,
    /// Walk RNG state (xorshift32).
    walk_rng: u32,
    /// Instruction set of the hot kernels.
    isa: Isa,
    // Scratch buffers, reused by every insertion.
    cavity: Vec<u32>,
    slots: Vec<u32>,
    bnd: Vec<Boundary>,
    star: StarScratch,
}

/// True when `a`, `b`, `c` lie on one line (exact: all three axis projections are degenerate).
fn collinear(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    let xy = |p: [f64; 3]| [p[0], p[1]];
    let yz = |p: [f64; 3]| [p[1], p[2]];
    let zx = |p: [f64; 3]| [p[2], p[0]];
    orient2d(xy(a), xy(b), xy(c)) == Sign::Zero
        && orient2d(yz(a), yz(b), yz(c)) == Sign::Zero
        && orient2d(zx(a), zx(b), zx(c)) == Sign::Zero
}

/// Reorder `v` so that `v[k]` becomes the old `v[perm[k]]`; `perm` is a permutation of
/// `0..v.len()`. Follows the cycles with a bit per element.
fn permute_in_place<T: Copy>(v: &mut [T], perm: &[u32]) {
    debug_assert_eq!(v.len(), perm.len());
    let mut done = vec![0u64; v.len().div_ceil(64)];
    for start in 0..v.len() {
        if done[start / 64] >> (start % 64) & 1 == 1 {
            continue;
        }
        let first = v[start];
        let mut k = start;
        loop {
            done[k / 64] |= 1 << (k % 64);
            let src = perm[k] as usize;
            if src == start {
                v[k] = first;
                break;
            }
            v[k] = v[src];
            k = src;
        }
    }
}

// The accepted coordinate range is the predicates' exact range.
pub use crate::geom::predicates::{MAX_COORDINATE, MIN_COORDINATE};

/// Every coordinate finite and in the exact range of the predicates (0, or a magnitude between
/// [`MIN_COORDINATE`] and [`MAX_COORDINATE`]).
fn check_finite(points: &[[f64; 3]], offset: usize) -> Result<(), DelaunayError> {
    for (i, p) in points.iter().enumerate() {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(DelaunayError::NonFinite { index: offset + i });
        }
        if !p
            .iter()
            .all(|&c| crate::geom::predicates::in_exact_range(c))
        {
            return Err(DelaunayError::OutOfRange { index: offset + i });
        }
    }
    Ok(())
}

impl Delaunay {
    /// The Delaunay tetrahedralization of `points`.
    ///
    /// Exact duplicates are merged (see [`Delaunay::vertex_map`]). Fails on non-finite or
    /// too large coordinates (beyond [`MAX_COORDINATE`]), on fewer than 4 distinct points and on
    /// collinear or coplanar input.
    pub fn new(points: &[[f64; 3]]) -> Result<Delaunay, DelaunayError> {
        Delaunay::new_with_isa(points.to_vec(), Isa::detect())
    }

    /// [`Delaunay::new`] taking the points by value: they are reordered in place and kept as the
    /// triangulation's own copy, which saves 24 bytes per point at the peak.
    pub fn from_points(points: Vec<[f64; 3]>) -> Result<Delaunay, DelaunayError> {
        Delaunay::new_with_isa(points, Isa::detect())
    }

    /// [`Delaunay::from_points`] with the kernels of a given instruction set.
    fn new_with_isa(mut points: Vec<[f64; 3]>, isa: Isa) -> Result<Delaunay, DelaunayError> {
        check_finite(&points, 0)?;
        let n = points.len();
        if n >= INF as usize {
            return Err(DelaunayError::TooLarge);
        }
        let grid = Grid::of(&points);
        let order = order::insertion_order(&points, SEED);
        let mut seq = order.seq;
        let m = seq.len();
        if m < 4 {
            return Err(DelaunayError::TooFewPoints { distinct: m });
        }
        // Four points in general position, moved to the front of the order.
        let p = |k: usize| points[seq[k] as usize];
        let Some(k2) = (2..m).find(|&k| !collinear(p(0), p(1), p(k))) else {
            return Err(DelaunayError::Collinear);
        };
        let Some(k3) = (k2 + 1..m).find(|&k| orient3d(p(0), p(1), p(k2), p(k)) != Sign::Zero)
        else {
            return Err(DelaunayError::Coplanar);
        };
        // [s0, s1, .., s2 (at k2), .., s3 (at k3), ..] -> [s0, s1, s2, s3, the rest in order].
        seq[2..=k3].rotate_right(1);
        seq[3..=k2 + 1].rotate_right(1);
        seq.swap(2, 3);

        // Vertex numbers: input order with duplicates removed.
        let input_vertex = order.rep.as_ref().map(|rep| {
            let mut map = vec![0u32; rep.len()];
            let mut c = 0u32;
            for i in 0..rep.len() {
                if rep[i] as usize == i {
                    map[i] = c;
                    c += 1;
                } else {
                    map[i] = map[rep[i] as usize];
                }
            }
            map
        });
        // The points in insertion order, in place: complete `seq` into a permutation of all
        // inputs (duplicates last) and follow its cycles.
        if let Some(rep) = &order.rep {
            seq.extend((0..n as u32).filter(|&i| rep[i as usize] != i));
        }
        permute_in_place(&mut points, &seq);
        points.truncate(m);
        if m < n {
            points.shrink_to_fit();
        }
        seq.truncate(m);
        let ids: Vec<u32> = match &input_vertex {
            // Without duplicates the vertex number is the input index.
            None => seq,
            Some(map) => seq.iter().map(|&i| map[i as usize]).collect(),
        };
        let pts = points;

        let mut dt = Delaunay {
            pts,
            ids,
            tets: Vec::new(),
            free: NONE,
            n_free: 0,
            last: 0,
            n_vertices: m,
            n_inputs: n,
            input_vertex,
            grid,
            walk_rng: 0x9E37_79B9,
            isa,
            cavity: Vec::new(),
            slots: Vec::new(),
            bnd: Vec::new(),
            star: StarScratch {
                map: vec![0; LOCAL * LOCAL],
                ..StarScratch::default()
            },
        };
        // About 6.7 tets per point for random points; untouched capacity costs no memory.
        dt.tets.reserve_exact(m / 8 * 55 + 64);
        dt.init_tet();
        for vi in 4..m as u32 {
            match dt.insert_internal(vi) {
                Inserted::Done => {}
                // Duplicates were removed beforehand.
                Inserted::Duplicate(_) => unreachable!("duplicate after deduplication"),
                Inserted::Full => return Err(DelaunayError::TooLarge),
            }
        }
        Ok(dt)
    }

    /// The first tet (internal ids 0..4) and its four ghosts.
    fn init_tet(&mut self) {
        let mut v = [0u32, 1, 2, 3];
        let q = v.map(|i| self.pts[i as usize]);
        if orient3d(q[0], q[1], q[2], q[3]) == Sign::Negative {
            v.swap(2, 3);
        }
        let mut tets = vec![Tet { v, n: [NONE; 4] }];
        for l in TET_FACES {
            tets.push(Tet {
                v: [v[l[0]], v[l[1]], v[l[2]], INF],
                n: [NONE; 4],
            });
        }
        // Pair the faces (each face of these 5 tets is in exactly two of them).
        let key = |t: &Tet, i: usize| {
            let l = TET_FACES[i];
            let mut k = [t.v[l[0]], t.v[l[1]], t.v[l[2]]];
            k.sort_unstable();
            k
        };
        for a in 0..5 {
            for i in 0..4 {
                for b in 0..5 {
                    for j in 0..4 {
                        if a != b && key(&tets[a], i) == key(&tets[b], j) {
                            tets[a].n[i] = (b as u32) << 2 | j as u32;
                        }
                    }
                }
            }
        }
        self.tets.extend_from_slice(&tets);
        self.last = 0;
    }

    /// Insert one more point; returns its vertex number (the existing vertex's number when the
    /// point is an exact duplicate). The new vertex gets the next vertex number.
    pub fn insert(&mut self, p: [f64; 3]) -> Result<u32, DelaunayError> {
        check_finite(&[p], self.n_inputs)?;
        if self.pts.len() + 1 >= INF as usize {
            return Err(DelaunayError::TooLarge);
        }
        let vi = self.pts.len() as u32;
        let number = self.n_vertices as u32;
        self.grid = self.grid.with(p);
        self.pts.push(p);
        self.ids.push(number);
        let v = match self.insert_internal(vi) {
            Inserted::Done => {
                self.n_vertices += 1;
                number
            }
            Inserted::Duplicate(w) => {
                self.pts.pop();
                self.ids.pop();
                self.ids[w as usize]
            }
            Inserted::Full => {
                self.pts.pop();
                self.ids.pop();
                return Err(DelaunayError::TooLarge);
            }
        };
        self.push_input(v);
        Ok(v)
    }

    /// Record the vertex of the next input point.
    fn push_input(&mut self, v: u32) {
        let identity = self.input_vertex.is_none() && v as usize == self.n_inputs;
        if !identity {
            let n = self.n_inputs as u32;
            self.input_vertex
                .get_or_insert_with(|| (0..n).collect())
                .push(v);
        }
        self.n_inputs += 1;
    }

    /// Insert a batch of points (in BRIO + Hilbert order, which is much faster than one by one
    /// in a random order); returns the vertex number of each. New vertices are numbered in the
    /// order of `points`, duplicates (within the batch or of existing vertices) removed, exactly
    /// as if the points had been inserted one by one with [`Delaunay::insert`], and the
    /// triangulation is the same too.
    ///
    /// On [`DelaunayError::TooLarge`] the triangulation stays valid and holds part of the batch,
    /// which is not recorded as input (the vertex map does not grow).
    pub fn insert_points(&mut self, points: &[[f64; 3]]) -> Result<Vec<u32>, DelaunayError> {
        check_finite(points, self.n_inputs)?;
        if self.pts.len() + points.len() >= INF as usize {
            return Err(DelaunayError::TooLarge);
        }
        let base = self.n_vertices as u32;
        for p in points {
            self.grid = self.grid.with(*p);
        }
        // Duplicates inside the batch are removed first (the first occurrence stays), so that
        // every new vertex is created by its first occurrence.
        let order = order::insertion_order(points, SEED ^ self.n_inputs as u64);
        // Provisional numbers base + batch index: their order is the final order, so the
        // perturbation (which only compares numbers) is already the final one. Numbers of points
        // that turn out to be duplicates of existing vertices are squeezed out afterwards.
        let mut internal = vec![NONE; points.len()];
        let mut is_new = vec![false; points.len()];
        let mut failed = false;
        for &i in &order.seq {
            let vi = self.pts.len() as u32;
            self.pts.push(points[i as usize]);
            self.ids.push(base + i);
            match self.insert_internal(vi) {
                Inserted::Done => {
                    internal[i as usize] = vi;
                    is_new[i as usize] = true;
                }
                Inserted::Duplicate(w) => {
                    self.pts.pop();
                    self.ids.pop();
                    internal[i as usize] = w;
                }
                Inserted::Full => {
                    self.pts.pop();
                    self.ids.pop();
                    failed = true;
                    break;
                }
            }
        }
        // Final numbers of the new vertices: base + rank among new ones in batch order.
        let mut c = base;
        for i in 0..points.len() {
            if is_new[i] {
                self.ids[internal[i] as usize] = c;
                c += 1;
            }
        }
        self.n_vertices = c as usize;
        if failed {
            return Err(DelaunayError::TooLarge);
        }
        let result: Vec<u32> = (0..points.len())
            .map(|i| {
                let r = order.rep.as_ref().map_or(i, |r| r[i] as usize);
                self.ids[internal[r] as usize]
            })
            .collect();
        for &v in &result {
            self.push_input(v);
        }
        Ok(result)
    }

    /// Number of vertices (distinct points).
    pub fn n_vertices(&self) -> usize {
        self.n_vertices
    }

    /// Number of input points given so far (duplicates counted).
    pub fn n_input_points(&self) -> usize {
        self.n_inputs
    }

    /// The vertex number of input point `i` (see the [module docs](self)).
    pub fn vertex_of_input(&self, i: usize) -> u32 {
        match &self.input_vertex {
            None => i as u32,
            Some(m) => m[i],
        }
    }

    /// The vertex number of every input point so far.
    pub fn vertex_map(&self) -> Vec<u32> {
        match &self.input_vertex {
            None => (0..self.n_inputs as u32).collect(),
            Some(m) => m.clone(),
        }
    }

    /// The coordinates of every vertex, by vertex number.
    pub fn vertex_points(&self) -> Vec<[f64; 3]> {
        let mut out = vec![[0.0; 3]; self.n_vertices];
        for (i, &v) in self.ids.iter().enumerate() {
            out[v as usize] = self.pts[i];
        }
        out
    }

    /// The coordinates of every vertex by vertex number, consuming the triangulation: the
    /// points are reordered in place, so no second copy is made.
    pub fn into_vertex_points(self) -> Vec<[f64; 3]> {
        if self.pts.len() != self.n_vertices {
            return self.vertex_points();
        }
        let mut inv = vec![0u32; self.n_vertices];
        for (i, &v) in self.ids.iter().enumerate() {
            inv[v as usize] = i as u32;
        }
        let Delaunay { mut pts, tets, .. } = self;
        drop(tets);
        permute_in_place(&mut pts, &inv);
        pts
    }

    /// Number of tet slots; tet ids are `0..n_slots()`.
    pub fn n_slots(&self) -> usize {
        self.tets.len()
    }

    /// True when slot `t` holds no tet.
    pub fn is_free(&self, t: u32) -> bool {
        self.tets[t as usize].v[0] & FLAG != 0
    }

    /// True when slot `t` holds a ghost tet (a hull face and the infinite vertex).
    pub fn is_ghost(&self, t: u32) -> bool {
        !self.is_free(t) && self.tets[t as usize].v[3] == INF
    }

    /// True when slot `t` holds a finite tet.
    pub fn is_finite(&self, t: u32) -> bool {
        let r = &self.tets[t as usize];
        r.v[0] & FLAG == 0 && r.v[3] != INF
    }

    /// The vertex numbers of tet `t`, positively oriented; a ghost has [`INFINITE`] in slot 3 and
    /// its hull face `(v0, v1, v2)` counter-clockwise seen from outside the hull.
    pub fn tet(&self, t: u32) -> [u32; 4] {
        self.tets[t as usize].v.map(|v| {
            if v == INF {
                INFINITE
            } else {
                self.ids[v as usize]
            }
        })
    }

    /// The corner coordinates of finite tet `t`, in the order of [`tet`](Self::tet).
    pub fn tet_points(&self, t: u32) -> [[f64; 3]; 4] {
        self.tets[t as usize].v.map(|v| self.pts[v as usize])
    }

    /// The tets across the four faces of tet `t` (face `i` is opposite vertex `i`, see
    /// [`TET_FACES`]). Every face of a live tet has a neighbour (ghosts close the hull).
    pub fn adjacent(&self, t: u32) -> [u32; 4] {
        self.tets[t as usize].n.map(|l| l >> 2)
    }

    /// The tet across face `i` of tet `t` and the index of that face in it.
    pub fn adjacent_face(&self, t: u32, i: usize) -> (u32, usize) {
        let l = self.tets[t as usize].n[i];
        (l >> 2, (l & 3) as usize)
    }

    /// Ids of the finite tets.
    pub fn finite_tets(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.tets.len() as u32).filter(|&t| self.is_finite(t))
    }

    /// Number of finite tets.
    pub fn n_finite_tets(&self) -> usize {
        self.tets
            .iter()
            .filter(|r| r.v[0] & FLAG == 0 && r.v[3] != INF)
            .count()
    }

    /// Number of hull faces (ghost tets).
    pub fn n_hull_faces(&self) -> usize {
        self.tets
            .iter()
            .filter(|r| r.v[0] & FLAG == 0 && r.v[3] == INF)
            .count()
    }

    /// The finite tets as a [`TetMesh`]: points by vertex number, tets positively oriented with
    /// label 1, neighbours across hull faces [`NO_NEIGHBOR`]. Tets keep the order of their slots.
    pub fn to_tet_mesh(&self) -> TetMesh {
        let mut index = vec![NO_NEIGHBOR; self.tets.len()];
        let mut nt = 0u32;
        for (t, r) in self.tets.iter().enumerate() {
            if r.v[0] & FLAG == 0 && r.v[3] != INF {
                index[t] = nt;
                nt += 1;
            }
        }
        let mut tets = Vec::with_capacity(nt as usize);
        let mut neighbors = Vec::with_capacity(nt as usize);
        for (t, r) in self.tets.iter().enumerate() {
            if index[t] != NO_NEIGHBOR {
                tets.push(r.v.map(|v| self.ids[v as usize]));
                neighbors.push(r.n.map(|l| index[(l >> 2) as usize]));
            }
        }
        TetMesh {
            points: self.vertex_points(),
            tets,
            neighbors,
            labels: vec![1; nt as usize],
        }
    }

    /// Bytes held by the triangulation's arrays (capacity, not just length).
    pub fn heap_bytes(&self) -> usize {
        self.pts.capacity() * 24
            + self.ids.capacity() * 4
            + self.tets.capacity() * std::mem::size_of::<Tet>()
            + self.input_vertex.as_ref().map_or(0, |m| m.capacity() * 4)
            + self.cavity.capacity() * 4
            + self.slots.capacity() * 4
            + self.bnd.capacity() * std::mem::size_of::<Boundary>()
            + self.star.local.capacity()
            + self.star.lids.capacity() * 3
            + self.star.map.capacity() * 4
            + self.star.edges.capacity() * 16
    }
}

const _: () = assert!(MAX_TETS <= 1 << 30);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::check;

    /// The fallback pairing of the star's faces (hash table), used for cavities with more than
    /// 60 boundary vertices, forced on every insertion: the same triangulation.
    #[test]
    fn hashed_face_pairing_gives_the_same_triangulation() {
        let mut pts = Vec::new();
        for z in 0..6 {
            for y in 0..5 {
                for x in 0..7 {
                    pts.push([f64::from(x), f64::from(y), f64::from(z)]);
                }
            }
        }
        let mut seed = 3u64;
        for _ in 0..300 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            pts.push([(seed >> 11) as f64 / (1u64 << 53) as f64 * 6.0, 2.5, 3.0]);
        }
        let fast = Delaunay::new(&pts).unwrap().to_tet_mesh();
        let mut dt = Delaunay::new(&pts[..40]).unwrap();
        dt.star.force_hash = true;
        dt.insert_points(&pts[40..]).unwrap();
        let slow = dt.to_tet_mesh();
        assert!(check(&slow, None).valid);
        let key = |m: &TetMesh| {
            let mut t: Vec<[u32; 4]> = m
                .tets
                .iter()
                .map(|t| {
                    let mut s = *t;
                    s.sort_unstable();
                    s
                })
                .collect();
            t.sort_unstable();
            t
        };
        assert_eq!(key(&fast), key(&slow));
    }

    /// The baseline kernels and the ones compiled for this CPU give the same triangulation.
    #[test]
    fn instruction_sets_agree() {
        let mut seed = 9u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut pts: Vec<[f64; 3]> = (0..3000).map(|_| [next(), next(), next()]).collect();
        for i in 0..1000 {
            pts.push([
                f64::from(i % 10),
                f64::from(i / 10 % 10),
                f64::from(i / 100),
            ]);
        }
        let a = Delaunay::new_with_isa(pts.clone(), Isa::Baseline)
            .unwrap()
            .to_tet_mesh();
        let b = Delaunay::new_with_isa(pts.clone(), Isa::detect())
            .unwrap()
            .to_tet_mesh();
        assert!(check(&a, None).valid);
        assert_eq!(a, b);
    }

    /// Cavities with more than 60 boundary vertices take the fallback on their own: the centre
    /// of 1032 cospherical lattice points, inserted last, sees every tet.
    #[test]
    fn huge_cavity() {
        let r2 = 2966;
        let mut pts = Vec::new();
        for x in -55i32..=55 {
            for y in -55i32..=55 {
                let z2 = r2 - x * x - y * y;
                if z2 >= 0 {
                    let z = f64::from(z2).sqrt() as i32;
                    if z * z == z2 {
                        pts.push([f64::from(x), f64::from(y), f64::from(z)]);
                        if z != 0 {
                            pts.push([f64::from(x), f64::from(y), -f64::from(z)]);
                        }
                    }
                }
            }
        }
        assert_eq!(pts.len(), 1032);
        let mut dt = Delaunay::new(&pts).unwrap();
        dt.insert([0.0; 3]).unwrap();
        let mesh = dt.to_tet_mesh();
        assert!(check(&mesh, None).valid);
        // Every hull face is now a tet with the centre.
        assert_eq!(mesh.n_tets(), dt.n_hull_faces());
    }
}
