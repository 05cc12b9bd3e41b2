//! The LAST RESORT search (Algorithm 3.1 of the seed, section 3.3.1): fill a closed cavity shell
//! with tets whose corners are cavity points only.
//!
//! # What is searched
//! The *front* starts as the shell: oriented triangles whose right-hand normals point into the
//! region to fill (a triangle may appear with both orientations: a "fin" inside the region, such
//! as a recovered surface triangle that the rest of the shell does not close off). A candidate of
//! an active face `abc` is a tet `abcp` whose fourth point `p` is a cavity point with
//! 1. `orient3d(a, b, c, p) > 0` (exact);
//! 2. quality `q` (eq. 4.9) above the threshold ηe and, optionally, smallest dihedral angle
//!    above a floor and largest below a cap (floating point: ranking only; with ηe ≤ 0, no
//!    floor and no cap no float test is made at all);
//! 3. no other live cavity point in the closed tet (exact, orient3d);
//! 4. no improper contact with any other active face: for every active face and every face of
//!    the tet, the exact triangle–triangle test ([`tri_tri`]) reports disjoint, a shared vertex
//!    or a shared edge, or the two are the same triangle.
//!
//! Given 3 for both tets, 4 is exactly "the tet lies in the closure of the unfilled region and
//! meets its boundary only in shared vertices, edges and faces": if an active face met the open
//! tet, its corners being outside it, some pair of faces would meet improperly. The unfilled
//! region only shrinks, so a candidate once invalid stays invalid down the tree: a checked
//! candidate is only *filtered* when a tet is added (the same pairwise test against the new
//! tet), and filtering is undone on backtracking.
//!
//! Conditions 1–2 are tested when a face joins the front; 3–4 lazily, against the current front:
//! a face's candidates are checked only while its count could still be the smallest (module
//! docs of `Searcher::dfs`), which leaves the search tree exactly as with eager checking.
//! Orientations are cached per triangle for the whole call (the points never move).
//!
//! # How
//! Every fill has exactly one tet on each active face, so branching over the candidates of one
//! face is exhaustive. The face with the fewest live candidates is expanded (a face with none
//! prunes the branch at once, fig. 3.5); candidates are tried best quality first; a dead end
//! returns to the previous level (fig. 3.6). This is the seed's search made complete: the seed
//! tries the best tet of successive faces, which can miss fills.
//!
//! With [`SearchOptions::improve`] the search goes on after the first fill, branch and bound on
//! the worst quality so far (candidates not better than the best fill's worst tet are pruned),
//! until the tree is exhausted or the extra node budget is spent.
//!
//! # Limits
//! Exponential in the worst case (the seed's eq. 3.3); [`SearchOptions::max_nodes`] bounds the
//! work and [`SearchError::Budget`] reports it. A shell without a fill (the Schönhardt
//! polyhedron) is proved fillless only when the tree is exhausted within the budget
//! ([`SearchError::NoFill`]).

use crate::geom::filter::orient3d;
use crate::geom::intersect::{TriTri, is_degenerate, seg_tri, tri_tri};
use crate::geom::predicates::{Sign, in_exact_range};
pub(super) use crate::geom::vec3::bbox;
use crate::geom::vec3::{cross, norm, norm2, sub};
use crate::quality::tet::{max_dihedral_chord2, min_dihedral_chord2, q_measure, volume};
use rustc_hash::FxHashMap;
use std::cell::Cell;
use thiserror::Error;

type P3 = [f64; 3];

/// Options of [`fill`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchOptions {
    /// ηe: candidates need quality q (eq. 4.9) strictly above it. At or below 0, every
    /// positively oriented tet qualifies (decided exactly, no float test).
    pub min_quality: f64,
    /// Candidates need their smallest dihedral angle strictly above this many degrees (at or
    /// below 0: no floor). Sliver removal sets it to the cavity's worst angle, so every fill
    /// found is an improvement and no search is spent on refills that would be rejected.
    pub min_dihedral: f64,
    /// Candidates need their largest dihedral angle strictly below this many degrees (at or
    /// above 180: no cap). Polish's obtuse step sets it, so a fill never brings back the
    /// obtuse tet it replaces.
    pub max_dihedral: f64,
    /// Node budget for the first fill.
    pub max_nodes: u64,
    /// After the first fill, look for fills with a better worst tet for at most this many more
    /// nodes (branch and bound). `None`: stop at the first fill.
    pub improve: Option<u64>,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            min_quality: 0.0,
            min_dihedral: 0.0,
            max_dihedral: 180.0,
            max_nodes: 100_000,
            improve: None,
        }
    }
}

/// A fill found by [`fill`].
#[derive(Debug, Clone, PartialEq)]
pub struct Fill {
    /// The tets, positively oriented, as indices into the caller's point array.
    pub tets: Vec<[u32; 4]>,
    /// The smallest quality q among them.
    pub worst_q: f64,
    /// Search nodes visited (tets tried).
    pub nodes_visited: u64,
    /// With [`SearchOptions::improve`]: true when the whole tree was searched, so no fill has a
    /// better worst tet (among tets above ηe).
    pub optimal: bool,
}

/// Why [`fill`] found no fill.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum SearchError {
    /// The shell has no triangles.
    #[error("the shell is empty")]
    Empty,
    /// A shell or inner point index is out of range.
    #[error("point index {index} is out of range ({n} points)")]
    IndexOutOfRange {
        /// The index.
        index: u32,
        /// Number of points.
        n: usize,
    },
    /// A point used by the shell is not finite or outside the predicates' exact range.
    #[error("point {index} is not finite or outside the exact range of the predicates")]
    BadCoordinate {
        /// The point.
        index: u32,
    },
    /// Two distinct indices have the same coordinates.
    #[error("points {a} and {b} have the same coordinates")]
    DuplicatePoint {
        /// First index.
        a: u32,
        /// Second index.
        b: u32,
    },
    /// A shell triangle has collinear or repeated corners.
    #[error("shell triangle {face} is degenerate")]
    DegenerateFace {
        /// Index in the shell.
        face: usize,
    },
    /// Some directed edge `a → b` is used more often than `b → a`: the shell is not closed and
    /// consistently oriented.
    #[error("the shell is not closed: edge {a}->{b} is unmatched")]
    NotClosed {
        /// Edge start.
        a: u32,
        /// Edge end.
        b: u32,
    },
    /// The whole tree was searched: no fill with these points and threshold exists.
    #[error("no fill exists (search exhausted after {nodes_visited} nodes)")]
    NoFill {
        /// Nodes visited.
        nodes_visited: u64,
    },
    /// The node budget ran out before a fill was found.
    #[error("node budget exhausted after {nodes_visited} nodes")]
    Budget {
        /// Nodes visited.
        nodes_visited: u64,
    },
}

/// Fill the closed shell `shell` (triangles of indices into `points`, normals pointing into the
/// region) plus the isolated points `inner` with tets (see the module docs).
///
/// Every point of `inner` strictly inside the region ends up as a tet corner (a fill may not
/// contain a cavity point); points outside it are simply not used.
pub fn fill(
    points: &[P3],
    shell: &[[u32; 3]],
    inner: &[u32],
    opts: &SearchOptions,
) -> Result<Fill, SearchError> {
    Searcher::default().fill(points, shell, inner, opts)
}

/// An active face of the front.
#[derive(Debug, Clone, Copy)]
struct Face {
    v: [u32; 3],
    alive: bool,
    /// Candidate range in `Searcher::cands`.
    c0: u32,
    c1: u32,
    /// Candidates not known invalid (an upper bound on the count).
    live: u32,
    /// Candidates checked valid.
    valid: u32,
    /// Its plane, oriented like `v`.
    plane: Plane,
    /// Its bounding box.
    lo: P3,
    hi: P3,
}

/// A candidate tet `face + p`.
#[derive(Debug, Clone, Copy)]
struct Cand {
    p: u32,
    /// q³ ([`q_cubed`]): candidates are ranked and bounded by it.
    q: f64,
    lo: P3,
    hi: P3,
    /// The planes of its three new faces once validated (row `u32::MAX` before): a valid
    /// candidate is filtered against every tet added, and the row look-ups were a fifth of that.
    planes: [Plane; 3],
}

/// The plane of [`Cand::planes`] not yet looked up.
const NO_PLANE: Plane = Plane {
    row: u32::MAX,
    even: true,
};

/// Undo record of one search level.
#[derive(Debug, Clone, Copy)]
struct Level {
    faces_len: u32,
    cands_len: u32,
    kill_len: u32,
    removed_len: u32,
    tet: [u32; 4],
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Flow {
    Continue,
    Done,
    Abort,
}

/// The search with its buffers, reusable across calls (no allocation once warm).
#[derive(Debug, Default)]
pub struct Searcher {
    pts: Vec<P3>,
    global: Vec<u32>,
    faces: Vec<Face>,
    cands: Vec<Cand>,
    /// Each candidate's state, [`UNCHECKED`], [`VALID`] or [`DEAD`] (apart from `cands`: the
    /// filter of every added tet scans them).
    state: Vec<u8>,
    map: FxHashMap<[u32; 3], u32>,
    /// Candidate state changes (candidate, its face, previous state), undone on backtracking.
    kill_log: Vec<(u32, u32, u8)>,
    /// The alive faces, in no particular order (dead ones are most of `faces` deep down).
    front: Vec<u32>,
    /// The bounding boxes of the faces of `front`, in its order (scanned contiguously).
    front_box: Vec<(P3, P3)>,
    /// Position of each face in `front` (kept after its death, for the undo).
    front_pos: Vec<u32>,
    removed_log: Vec<u32>,
    front_deg: Vec<u32>,
    uses: Vec<u32>,
    levels: Vec<Level>,
    worst: Vec<f64>,
    best: Vec<[u32; 4]>,
    /// The best fill's worst q³, and the bound (q³) candidates must beat.
    best_worst: f64,
    have_best: bool,
    bound: f64,
    nodes: u64,
    budget: u64,
    eta: f64,
    /// ηe³.
    eta3: f64,
    /// The dihedral floor as [`min_dihedral_chord2`] of it; `None` for no floor.
    floor: Option<f64>,
    /// The dihedral cap as the chord² of the largest angle (`max_dihedral_chord2`); `None` for
    /// no cap.
    cap: Option<f64>,
    improve: Option<u64>,
    /// Whether this search left out an apex in front of its face for ηe alone (see
    /// [`Searcher::cut_by_quality`]).
    eta_cut: bool,
    scratch: Vec<[u32; 3]>,
    edges: Vec<(u32, u32)>,
    /// Local point ids sorted by coordinates (the duplicate check).
    order: Vec<u32>,
    /// Local id of each caller point (`u32::MAX`: not loaded) when the caller's array is small
    /// next to the shell (`dense`): cheaper than sorting and binary searches.
    local_of: Vec<u32>,
    dense: bool,
    /// Whether the last [`Self::load`] succeeded (for [`Self::refill`]).
    loaded: bool,
    /// The local points by x (large searches only, else empty): [`Self::contains_point`]
    /// visits only those in the candidate's x range.
    by_x: Vec<(P3, u32)>,
    /// The root's faces by shape, poorest first.
    root_order: Vec<(f64, u32)>,
    /// Rows of `orient`: one per triangle met (sorted corners), for the whole call: the points
    /// never move, so an orientation once computed holds for every face, candidate and level.
    rows: FxHashMap<[u32; 3], u32>,
    /// Cached orientations of every point against each row's sorted triangle, row-major
    /// ([`UNKNOWN`] until computed).
    orient: Vec<Cell<i8>>,
    /// The sorted triangle of each row.
    row_keys: Vec<[u32; 3]>,
    /// Per edge of the face whose candidates are computed: the apex of the one other front face
    /// across it, and that face, when the region's wedge there is convex.
    wedge: [Option<u32>; 3],
}

/// Searches with more points than this index them by x for [`Searcher::contains_point`].
const BY_X_MIN_POINTS: usize = 48;

/// Marks a not yet computed entry of `Searcher::orient`.
const UNKNOWN: i8 = 2;

/// Candidate states: conditions 1–2 hold, 3–4 not yet checked against the current front.
const UNCHECKED: u8 = 0;
/// All four conditions hold (checked, then filtered against every tet added since).
const VALID: u8 = 1;
/// Not a candidate (any more).
const DEAD: u8 = 2;

/// The plane of an oriented triangle: its row of cached orientations, and whether the triangle
/// is an even permutation of the row's sorted corners (else every sign flips).
#[derive(Debug, Clone, Copy)]
struct Plane {
    row: u32,
    even: bool,
}

impl Plane {
    /// The same plane, opposite orientation.
    #[inline]
    fn flip(self) -> Plane {
        Plane {
            row: self.row,
            even: !self.even,
        }
    }
}

/// Empty `m` for a search expected to need about `want` entries: clearing a hash map costs its
/// capacity, and one large search would otherwise make every later small one pay for it.
fn reset_map<K, V>(m: &mut FxHashMap<K, V>, want: usize) {
    if m.capacity() > 4 * want {
        *m = FxHashMap::default();
    } else {
        m.clear();
    }
}

/// Area over the sum of squared edges (up to a constant): small for a thin triangle.
fn tri_shape(c: &[P3; 3]) -> f64 {
    let (u, v, w) = (sub(c[1], c[0]), sub(c[2], c[0]), sub(c[2], c[1]));
    norm(cross(u, v)) / (norm2(u) + norm2(v) + norm2(w))
}

/// q³ (eq. 4.9 cubed) of the tet `c` of volume `v`: the same order as q without its cube root,
/// for ranking candidates.
#[inline]
fn q_cubed(v: f64, c: &[P3; 4]) -> f64 {
    let l2: f64 = crate::mesh::tet::TET_EDGES
        .iter()
        .map(|&[i, j]| norm2(sub(c[i], c[j])))
        .sum();
    if l2 == 0.0 {
        return 0.0;
    }
    let w = 3.0 * v;
    v.signum() * 1728.0 * w * w / (l2 * l2 * l2)
}

/// Is [`min_dihedral_chord2`] of the tet above `floor`? For a floor below a right angle, on the
/// unnormalised face normals without a square root: the chord² at the edge of faces k, l is
/// 2 + 2·cos(n_k, n_l), so it is at most the floor when n_k·n_l ≤ c·|n_k||n_l| with
/// c = floor/2 − 1 < 0.
#[inline]
fn dihedrals_above(c: &[P3; 4], floor: f64) -> bool {
    let k = 0.5 * floor - 1.0;
    if k >= 0.0 {
        return min_dihedral_chord2(c) > floor;
    }
    let n = [0, 1, 2, 3].map(|i| {
        let l = crate::mesh::tet::TET_FACES[i];
        cross(sub(c[l[1]], c[l[0]]), sub(c[l[2]], c[l[0]]))
    });
    let m = n.map(norm2);
    if m.contains(&0.0) {
        return false;
    }
    let k2 = k * k;
    crate::mesh::tet::TET_EDGES.iter().all(|&[i, j]| {
        let d = n[i][0] * n[j][0] + n[i][1] * n[j][1] + n[i][2] * n[j][2];
        d >= 0.0 || d * d < k2 * m[i] * m[j]
    })
}

/// Sorted corners and whether `f` is an even permutation of them.
#[inline]
fn sort3(f: [u32; 3]) -> ([u32; 3], bool) {
    let [mut a, mut b, mut c] = f;
    let mut even = true;
    if a > b {
        std::mem::swap(&mut a, &mut b);
        even = !even;
    }
    if b > c {
        std::mem::swap(&mut b, &mut c);
        even = !even;
    }
    if a > b {
        std::mem::swap(&mut a, &mut b);
        even = !even;
    }
    ([a, b, c], even)
}

/// Canonical rotation of an oriented triangle (smallest index first).
#[inline]
fn canon(f: [u32; 3]) -> [u32; 3] {
    if f[0] < f[1] && f[0] < f[2] {
        f
    } else if f[1] < f[2] {
        [f[1], f[2], f[0]]
    } else {
        [f[2], f[0], f[1]]
    }
}

#[inline]
fn same_set(a: [u32; 3], b: [u32; 3]) -> bool {
    a.iter().all(|x| b.contains(x))
}

#[inline]
pub(super) fn boxes_apart(alo: P3, ahi: P3, blo: P3, bhi: P3) -> bool {
    // Without short circuits: no branch per axis in the loops over the front.
    (ahi[0] < blo[0])
        | (bhi[0] < alo[0])
        | (ahi[1] < blo[1])
        | (bhi[1] < alo[1])
        | (ahi[2] < blo[2])
        | (bhi[2] < alo[2])
}

/// The four outward faces of tet `t` (the face table of [`crate::TET_FACES`]).
#[inline]
fn tet_faces(t: [u32; 4]) -> [[u32; 3]; 4] {
    [
        [t[1], t[2], t[3]],
        [t[0], t[3], t[2]],
        [t[0], t[1], t[3]],
        [t[0], t[2], t[1]],
    ]
}

impl Searcher {
    /// A searcher with empty buffers.
    pub fn new() -> Searcher {
        Searcher::default()
    }

    /// [`fill`], reusing this searcher's buffers.
    pub fn fill(
        &mut self,
        points: &[P3],
        shell: &[[u32; 3]],
        inner: &[u32],
        opts: &SearchOptions,
    ) -> Result<Fill, SearchError> {
        self.load(points, shell, inner, false)?;
        self.run(opts)
    }

    /// [`Self::fill`] for a shell carved from a valid mesh: the caller vouches that the points are
    /// distinct and in range and that the shell is closed, consistently oriented and without
    /// degenerate triangles, so those checks (a fifth of a small search) run in debug builds only.
    pub(crate) fn fill_carved(
        &mut self,
        points: &[P3],
        shell: &[[u32; 3]],
        inner: &[u32],
        opts: &SearchOptions,
    ) -> Result<Fill, SearchError> {
        self.load(points, shell, inner, !cfg!(debug_assertions))?;
        self.run(opts)
    }

    /// [`Self::fill`] again on the shell, points and inner points of the last call, which
    /// loaded successfully, with other options. Every search undoes its levels before it
    /// returns, so the front is the loaded shell again, as a new load would make it; the
    /// orientations cached so far are kept (the points are the same).
    pub(crate) fn refill(&mut self, opts: &SearchOptions) -> Result<Fill, SearchError> {
        debug_assert!(self.loaded && self.levels.is_empty());
        self.cands.clear();
        self.state.clear();
        self.kill_log.clear();
        self.removed_log.clear();
        for f in &mut self.faces {
            f.c0 = 0;
            f.c1 = 0;
            f.live = 0;
            f.valid = 0;
        }
        self.run(opts)
    }

    /// The search proper, on a loaded shell.
    fn run(&mut self, opts: &SearchOptions) -> Result<Fill, SearchError> {
        self.eta = opts.min_quality;
        self.eta3 = opts.min_quality.powi(3);
        self.floor = (opts.min_dihedral > 0.0).then(|| {
            let s = (opts.min_dihedral.to_radians() / 2.0).sin();
            4.0 * s * s
        });
        self.cap = (opts.max_dihedral < 180.0).then(|| {
            let s = (opts.max_dihedral.to_radians() / 2.0).sin();
            4.0 * s * s
        });
        self.improve = opts.improve;
        self.eta_cut = false;
        self.budget = opts.max_nodes;
        self.nodes = 0;
        self.have_best = false;
        self.best.clear();
        self.best_worst = f64::NEG_INFINITY;
        self.bound = f64::NEG_INFINITY;
        self.levels.clear();
        self.worst.clear();
        self.worst.push(f64::INFINITY);
        // Poorest faces first: a face with no candidate is most likely a poor one (a tet on a
        // thin triangle has a small q), and the root prunes at once when one has none (fig.
        // 3.5), without the other faces' candidates. Most cavities of sliver removal end here
        // (nested_brain_wm_20k: 6,982 of 9,990), so the order matters; the result does not
        // depend on it.
        let mut root = std::mem::take(&mut self.root_order);
        root.clear();
        root.extend((0..self.faces.len() as u32).map(|f| {
            let c = self.faces[f as usize].v.map(|x| self.pts[x as usize]);
            (tri_shape(&c), f)
        }));
        root.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let empty = root.iter().any(|&(_, f)| {
            self.gen_candidates(f as usize);
            self.faces[f as usize].live == 0
        });
        self.root_order = root;
        if empty {
            return Err(SearchError::NoFill { nodes_visited: 1 });
        }
        let flow = self.dfs();
        if self.have_best {
            let tets = self
                .best
                .iter()
                .map(|t| t.map(|v| self.global[v as usize]))
                .collect();
            // q itself, exactly as `q_measure` gives it (the search ranked by q³).
            let worst_q = self
                .best
                .iter()
                .map(|t| q_measure(&t.map(|v| self.pts[v as usize])))
                .fold(f64::INFINITY, f64::min);
            return Ok(Fill {
                tets,
                worst_q,
                nodes_visited: self.nodes,
                optimal: flow == Flow::Continue,
            });
        }
        match flow {
            Flow::Abort => Err(SearchError::Budget {
                nodes_visited: self.nodes,
            }),
            _ => Err(SearchError::NoFill {
                nodes_visited: self.nodes,
            }),
        }
    }

    /// Validate the input (unless `trusted`) and set up local points and the initial front.
    fn load(
        &mut self,
        points: &[P3],
        shell: &[[u32; 3]],
        inner: &[u32],
        trusted: bool,
    ) -> Result<(), SearchError> {
        self.loaded = false;
        if shell.is_empty() {
            return Err(SearchError::Empty);
        }
        let n = points.len();
        self.global.clear();
        // A cavity's own point array (recovery): mark the used points and number them in
        // order, the same local ids as sorting them.
        self.dense = n <= 4 * (3 * shell.len() + inner.len()) + 64;
        if self.dense {
            self.local_of.clear();
            self.local_of.resize(n, u32::MAX);
            for &i in shell.iter().flatten().chain(inner) {
                if i as usize >= n {
                    return Err(SearchError::IndexOutOfRange { index: i, n });
                }
                self.local_of[i as usize] = 0;
            }
            for (g, l) in self.local_of.iter_mut().enumerate() {
                if *l != u32::MAX {
                    *l = self.global.len() as u32;
                    self.global.push(g as u32);
                }
            }
        } else {
            for &i in shell.iter().flatten().chain(inner) {
                if i as usize >= n {
                    return Err(SearchError::IndexOutOfRange { index: i, n });
                }
                self.global.push(i);
            }
            self.global.sort_unstable();
            self.global.dedup();
        }
        self.pts.clear();
        for &g in &self.global {
            let p = points[g as usize];
            if !trusted && !p.iter().all(|&c| in_exact_range(c)) {
                return Err(SearchError::BadCoordinate { index: g });
            }
            self.pts.push(p);
        }
        self.scratch.clear();
        if trusted {
            let mut scratch = std::mem::take(&mut self.scratch);
            scratch.extend(shell.iter().map(|f| f.map(|g| self.local(g))));
            self.scratch = scratch;
        } else {
            self.check(shell)?;
        }
        let np = self.pts.len();
        self.front_deg.clear();
        self.front_deg.resize(np, 0);
        self.uses.clear();
        self.uses.resize(np, 0);
        let want = 8 * shell.len() + 64;
        reset_map(&mut self.rows, want);
        self.orient.clear();
        self.row_keys.clear();
        self.faces.clear();
        self.cands.clear();
        self.state.clear();
        reset_map(&mut self.map, want);
        self.kill_log.clear();
        self.removed_log.clear();
        self.front.clear();
        self.front_box.clear();
        self.front_pos.clear();
        let scratch = std::mem::take(&mut self.scratch);
        for &f in &scratch {
            if self.map.contains_key(&canon(f)) {
                // The same oriented triangle twice: the region would be on one side twice.
                return Err(SearchError::NotClosed {
                    a: self.global[f[0] as usize],
                    b: self.global[f[1] as usize],
                });
            }
            self.push_face(f);
        }
        self.scratch = scratch;
        self.by_x.clear();
        if np > BY_X_MIN_POINTS {
            self.by_x
                .extend(self.pts.iter().enumerate().map(|(i, p)| (*p, i as u32)));
            self.by_x
                .sort_unstable_by(|a, b| a.0[0].total_cmp(&b.0[0]).then(a.1.cmp(&b.1)));
        }
        self.loaded = true;
        Ok(())
    }

    /// Caller point → local id, for a loaded caller point.
    #[inline]
    fn local(&self, g: u32) -> u32 {
        if self.dense {
            self.local_of[g as usize]
        } else {
            self.global.binary_search(&g).unwrap_or(0) as u32
        }
    }

    /// The checks [`Self::fill_carved`] skips: distinct points, non-degenerate shell triangles
    /// (mapped to local ids into `scratch`), a closed consistently oriented shell.
    fn check(&mut self, shell: &[[u32; 3]]) -> Result<(), SearchError> {
        // Duplicates: sort local ids by coordinates.
        let order = &mut self.order;
        order.clear();
        order.extend(0..self.pts.len() as u32);
        let key = crate::mesh::coord_key;
        order.sort_unstable_by_key(|&i| key(&self.pts[i as usize]));
        for w in self.order.windows(2) {
            if key(&self.pts[w[0] as usize]) == key(&self.pts[w[1] as usize]) {
                return Err(SearchError::DuplicatePoint {
                    a: self.global[w[0] as usize],
                    b: self.global[w[1] as usize],
                });
            }
        }
        let mut scratch = std::mem::take(&mut self.scratch);
        for (i, f) in shell.iter().enumerate() {
            let l = f.map(|g| self.local(g));
            let c = l.map(|v| self.pts[v as usize]);
            if l[0] == l[1] || l[1] == l[2] || l[0] == l[2] || is_degenerate(&c) {
                self.scratch = scratch;
                return Err(SearchError::DegenerateFace { face: i });
            }
            scratch.push(l);
        }
        self.scratch = scratch;
        // Closed: every directed edge matched by its reverse.
        self.edges.clear();
        for f in &self.scratch {
            for k in 0..3 {
                self.edges.push((f[k], f[(k + 1) % 3]));
            }
        }
        self.edges.sort_unstable();
        let count = |e: &[(u32, u32)], x: (u32, u32)| {
            let lo = e.partition_point(|y| *y < x);
            e[lo..].iter().take_while(|y| **y == x).count()
        };
        for &(a, b) in &self.edges {
            if count(&self.edges, (a, b)) != count(&self.edges, (b, a)) {
                return Err(SearchError::NotClosed {
                    a: self.global[a as usize],
                    b: self.global[b as usize],
                });
            }
        }
        Ok(())
    }

    fn push_face(&mut self, v: [u32; 3]) {
        let id = self.faces.len() as u32;
        let c = self.cands.len() as u32;
        let plane = self.plane(v);
        let (lo, hi) = bbox(&v.map(|x| self.pts[x as usize]));
        self.front_pos.push(self.front.len() as u32);
        self.front.push(id);
        self.front_box.push((lo, hi));
        self.faces.push(Face {
            v,
            alive: true,
            c0: c,
            c1: c,
            live: 0,
            valid: 0,
            plane,
            lo,
            hi,
        });
        self.map.insert(canon(v), id);
        for &x in &v {
            self.front_deg[x as usize] += 1;
        }
    }

    /// The plane of the oriented triangle `v` (a row of the cache, made on first use).
    fn plane(&mut self, v: [u32; 3]) -> Plane {
        let (key, even) = sort3(v);
        let next = self.rows.len() as u32;
        let row = *self.rows.entry(key).or_insert(next);
        if row == next {
            self.row_keys.push(key);
            let np = self.pts.len();
            self.orient
                .resize(self.orient.len() + np, Cell::new(UNKNOWN));
        }
        Plane { row, even }
    }

    fn kill_face(&mut self, f: u32) {
        let face = &mut self.faces[f as usize];
        face.alive = false;
        let v = face.v;
        self.map.remove(&canon(v));
        for &x in &v {
            self.front_deg[x as usize] -= 1;
        }
        self.removed_log.push(f);
        let i = self.front_pos[f as usize] as usize;
        let last_box = self.front_box.pop();
        if let Some(last) = self.front.pop()
            && last != f
            && let Some(b) = last_box
        {
            self.front[i] = last;
            self.front_box[i] = b;
            self.front_pos[last as usize] = i as u32;
        }
    }

    /// Undo [`Self::kill_face`] (in exact reverse order of the kills since).
    fn revive_face(&mut self, f: u32) {
        let face = &mut self.faces[f as usize];
        face.alive = true;
        let v = face.v;
        self.map.insert(canon(v), f);
        for &x in &v {
            self.front_deg[x as usize] += 1;
        }
        let b = (face.lo, face.hi);
        let i = self.front_pos[f as usize] as usize;
        let n = self.front.len();
        if i < n {
            let moved = self.front[i];
            self.front_pos[moved as usize] = n as u32;
            self.front.push(moved);
            self.front_box.push(self.front_box[i]);
            self.front[i] = f;
            self.front_box[i] = b;
        } else {
            self.front.push(f);
            self.front_box.push(b);
        }
    }

    #[inline]
    fn usable(&self, p: u32) -> bool {
        self.front_deg[p as usize] > 0 || self.uses[p as usize] == 0
    }

    /// Exact orientation of point `d` against the plane of `abc`, zero at once when `d` is one
    /// of `a, b, c` (no adaptive stage for the exact zero).
    #[inline]
    fn o(&self, a: u32, b: u32, c: u32, d: u32) -> Sign {
        if d == a || d == b || d == c {
            return Sign::Zero;
        }
        let p = &self.pts;
        orient3d(p[a as usize], p[b as usize], p[c as usize], p[d as usize])
    }

    /// [`Self::o`] against the plane of face `f` (cached).
    #[inline]
    fn side(&self, f: u32, x: u32) -> Sign {
        self.outer(self.faces[f as usize].plane, x)
    }

    /// Orientation of `x` against the oriented plane `pl` (cached): for a face of a candidate
    /// tet, positive outside the tet.
    #[inline]
    fn outer(&self, pl: Plane, x: u32) -> Sign {
        let np = self.pts.len();
        let cell = &self.orient[pl.row as usize * np + x as usize];
        let s = match cell.get() {
            1 => Sign::Positive,
            -1 => Sign::Negative,
            0 => Sign::Zero,
            _ => {
                let s = self.o_row(pl.row, x);
                cell.set(s.as_i32() as i8);
                s
            }
        };
        s.times(pl.even)
    }

    /// Orientation of `x` against the sorted triangle of row `row` (uncached).
    #[inline(never)]
    fn o_row(&self, row: u32, x: u32) -> Sign {
        let v = self.row_keys[row as usize];
        self.o(v[0], v[1], v[2], x)
    }

    /// Is `other` on the closed outer side of plane `pl` (face `fv`), touching it only at
    /// corners of `fv`? Then the two meet at most in shared corners of that face.
    #[inline]
    fn separates(&self, pl: Plane, fv: [u32; 3], other: &[u32]) -> bool {
        other.iter().all(|&x| match self.outer(pl, x) {
            Sign::Positive => true,
            Sign::Zero => fv.contains(&x),
            Sign::Negative => false,
        })
    }

    /// Do the triangles `f` (plane `fpl`) and `g` (plane `gpl`), distinct vertex sets, meet
    /// other than in shared corners or a shared edge? Exact. Plane tests (cached orientations)
    /// settle the common cases; triangles without a shared corner are decided by their edges
    /// (for triangles in different planes, they meet iff an edge of one meets the other);
    /// coplanar pairs and pairs with one shared corner go to [`tri_tri`].
    fn tri_conflict(&self, f: [u32; 3], fpl: Plane, g: [u32; 3], gpl: Plane) -> bool {
        let sg = g.map(|x| {
            if f.contains(&x) {
                Sign::Zero
            } else {
                self.outer(fpl, x)
            }
        });
        let sf = f.map(|x| {
            if g.contains(&x) {
                Sign::Zero
            } else {
                self.outer(gpl, x)
            }
        });
        let one_side = |s: &[Sign; 3], v: [u32; 3], other: [u32; 3]| {
            let mut pos = false;
            let mut neg = false;
            for k in 0..3 {
                if other.contains(&v[k]) {
                    continue;
                }
                match s[k] {
                    Sign::Positive => pos = true,
                    Sign::Negative => neg = true,
                    Sign::Zero => return false,
                }
            }
            !(pos && neg)
        };
        if one_side(&sg, g, f) || one_side(&sf, f, g) {
            return false;
        }
        let shared = g.iter().filter(|x| f.contains(x)).count();
        let coplanar = sg.iter().all(|&x| x == Sign::Zero);
        if shared == 0 && !coplanar {
            // Both directions need the orientation of each edge of f against each edge of g
            // (orient3d(a, b, c, d) = orient3d(c, d, a, b)): each is computed once.
            let memo = [const { Cell::new(UNKNOWN) }; 9];
            let edges = |k: usize, i: usize| {
                let m = &memo[3 * k + i];
                if m.get() == UNKNOWN {
                    let s = self.o4(f[k], f[(k + 1) % 3], g[i], g[(i + 1) % 3]);
                    m.set(s.as_i32() as i8);
                }
                match m.get() {
                    1 => Sign::Positive,
                    -1 => Sign::Negative,
                    _ => Sign::Zero,
                }
            };
            return (0..3).any(|k| {
                let (k1, s) = ((k + 1) % 3, (sf[k], sf[(k + 1) % 3]));
                self.seg_meets(f[k], f[k1], s, g, |i| edges(k, i))
            }) || (0..3).any(|k| {
                let (k1, s) = ((k + 1) % 3, (sg[k], sg[(k + 1) % 3]));
                self.seg_meets(g[k], g[k1], s, f, |j| edges(j, k))
            });
        }
        let fp = f.map(|x| self.pts[x as usize]);
        let gp = g.map(|x| self.pts[x as usize]);
        tri_tri(&fp, &gp) == TriTri::Improper
    }

    /// Does segment `xy` meet the closed triangle `t` (no corner shared)? `sx`, `sy`: the exact
    /// orientations of `x`, `y` against `t` in its own orientation (every plane passed to
    /// [`Self::tri_conflict`] is oriented like its triangle); `edge(i)`: orient3d(x, y, t[i],
    /// t[i + 1]).
    fn seg_meets(
        &self,
        x: u32,
        y: u32,
        (sx, sy): (Sign, Sign),
        t: [u32; 3],
        edge: impl Fn(usize) -> Sign,
    ) -> bool {
        if sx != Sign::Zero && sx == sy {
            return false;
        }
        if sx == Sign::Zero && sy == Sign::Zero {
            let p = &self.pts;
            let tp = t.map(|i| p[i as usize]);
            return seg_tri(p[x as usize], p[y as usize], &tp).meets();
        }
        // The line crosses the plane at one point; its barycentric signs are the orientations
        // of the line against the triangle's edges, times the sign of its direction · normal.
        let dn_positive = sy == Sign::Positive || sx == Sign::Negative;
        [1, 2, 0]
            .iter()
            .all(|&i| edge(i).times(dn_positive) != Sign::Negative)
    }

    /// Plain exact orientation of four distinct points.
    #[inline]
    fn o4(&self, a: u32, b: u32, c: u32, d: u32) -> Sign {
        let p = &self.pts;
        orient3d(p[a as usize], p[b as usize], p[c as usize], p[d as usize])
    }

    /// The outward faces of candidate `k` of face `f` and their planes (looked up once per
    /// candidate).
    #[inline]
    fn cand_planes(&mut self, f: u32, k: u32) -> ([[u32; 3]; 4], [Plane; 4]) {
        let face = &self.faces[f as usize];
        let (v, base) = (face.v, face.plane.flip());
        let c = self.cands[k as usize];
        let tf = tet_faces([v[0], v[1], v[2], c.p]);
        let pl = if c.planes[0].row == u32::MAX {
            let pl = [self.plane(tf[0]), self.plane(tf[1]), self.plane(tf[2])];
            self.cands[k as usize].planes = pl;
            pl
        } else {
            c.planes
        };
        (tf, [pl[0], pl[1], pl[2], base])
    }

    /// Compute the candidates of face `f` (its range is the end of `cands`).
    fn gen_candidates(&mut self, f: usize) {
        let v = self.faces[f].v;
        let [a, b, c] = v.map(|x| self.pts[x as usize]);
        let start = self.cands.len();
        self.find_wedges(f as u32);
        let wedge = self.wedge;
        // The tests are a conjunction, so their order is free: with a float threshold the float
        // tests run first (they reject most apexes, the point behind the face included, and
        // cost less than a first exact orientation); without one, the exact test first.
        let floats_first = self.eta > 0.0
            || self.floor.is_some()
            || self.cap.is_some()
            || self.bound > f64::NEG_INFINITY;
        'apex: for p in 0..self.pts.len() as u32 {
            if v.contains(&p) || !self.usable(p) {
                continue;
            }
            if !floats_first && self.side(f as u32, p) != Sign::Positive {
                continue;
            }
            let d = self.pts[p as usize];
            let corners = [a, b, c, d];
            let vol = volume(&corners);
            // q³ ≤ 0 is at most ηe³ when ηe > 0: `above_eta` would refuse it.
            if self.eta > 0.0 && vol <= 0.0 {
                self.note_eta_cut(f as u32, p);
                continue;
            }
            let q = q_cubed(vol, &corners);
            if self.eta > 0.0 && !self.above_eta(q, &corners) {
                self.note_eta_cut(f as u32, p);
                continue;
            }
            if q <= self.bound
                || self.floor.is_some_and(|f| !dihedrals_above(&corners, f))
                || self.cap.is_some_and(|c| max_dihedral_chord2(&corners) >= c)
            {
                continue;
            }
            if floats_first && self.side(f as u32, p) != Sign::Positive {
                continue;
            }
            // Convex wedge at an edge: the apex must be in front of the face across it (or be
            // its apex): else the tet leaves the region next to that edge.
            for h in wedge.iter().flatten() {
                let hv = self.faces[*h as usize].v;
                if !hv.contains(&p) && self.side(*h, p) != Sign::Positive {
                    continue 'apex;
                }
            }
            let (lo, hi) = bbox(&corners);
            self.cands.push(Cand {
                p,
                q,
                lo,
                hi,
                planes: [NO_PLANE; 3],
            });
        }
        self.cands[start..].sort_by(|x, y| y.q.total_cmp(&x.q).then(x.p.cmp(&y.p)));
        self.state.resize(self.cands.len(), UNCHECKED);
        let face = &mut self.faces[f];
        face.c0 = start as u32;
        face.c1 = self.cands.len() as u32;
        face.live = face.c1 - face.c0;
        face.valid = 0;
    }

    /// Record an apex refused for ηe alone that a search without ηe could take (in front of
    /// face `f`, exact; the other tests are not checked, so the record may be needless).
    fn note_eta_cut(&mut self, f: u32, p: u32) {
        if !self.eta_cut && self.side(f, p) == Sign::Positive {
            self.eta_cut = true;
        }
    }

    /// Whether the last search refused an apex for its [`SearchOptions::min_quality`] alone
    /// (conservatively). When it did not and found no fill (within its budget), a search with
    /// the same options but a lower `min_quality` (and no smaller budget) has the same
    /// candidates at every node, so it finds no fill either.
    pub(crate) fn cut_by_quality(&self) -> bool {
        self.eta_cut
    }

    /// Is the tet's q strictly above ηe? Decided on q³ unless the two are too close to call,
    /// then on q itself, so the threshold means what [`SearchOptions::min_quality`] says.
    #[inline]
    fn above_eta(&self, q3: f64, corners: &[P3; 4]) -> bool {
        if q3 > self.eta3 * (1.0 + 1e-9) {
            return true;
        }
        if q3 < self.eta3 * (1.0 - 1e-9) {
            return false;
        }
        q_measure(corners).partial_cmp(&self.eta) == Some(std::cmp::Ordering::Greater)
    }

    /// Check conditions 3–4 of candidate `k` of face `f` against the current front; records
    /// the outcome. Valid against the current front means valid: the region only shrinks.
    fn validate(&mut self, f: u32, k: u32) -> bool {
        let c = self.cands[k as usize];
        let v = self.faces[f as usize].v;
        let t = [v[0], v[1], v[2], c.p];
        let (tf, planes) = self.cand_planes(f, k);
        let ok = !(self.contains_point(t, &planes, c.lo, c.hi)
            || self.hits_front(t, &tf, &planes, f, c.lo, c.hi));
        self.set_state(f, k, if ok { VALID } else { DEAD });
        ok
    }

    /// Set the state of candidate `k` of face `f`, logged for [`Self::undo`].
    fn set_state(&mut self, f: u32, k: u32, new: u8) {
        let old = self.state[k as usize];
        self.kill_log.push((k, f, old));
        self.restate(f, k, new);
    }

    /// Set a candidate's state and keep its face's counts.
    fn restate(&mut self, f: u32, k: u32, new: u8) {
        let state = &mut self.state[k as usize];
        let face = &mut self.faces[f as usize];
        match *state {
            VALID => face.valid -= 1,
            DEAD => face.live += 1,
            _ => {}
        }
        match new {
            VALID => face.valid += 1,
            DEAD => face.live -= 1,
            _ => {}
        }
        *state = new;
    }

    /// The number of candidates of face `f` with quality above the bound, exact when below
    /// `limit` (else some number at least `limit`): unchecked ones are checked, best first,
    /// only until `limit` valid ones are found.
    fn count_upto(&mut self, f: u32, limit: u32) -> u32 {
        let face = self.faces[f as usize];
        if self.bound == f64::NEG_INFINITY
            && (face.live == 0 || face.valid >= limit || face.valid == face.live)
        {
            return face.valid;
        }
        let mut n = 0;
        for k in face.c0..face.c1 {
            let c = self.cands[k as usize];
            if c.q <= self.bound {
                break;
            }
            n += match self.state[k as usize] {
                VALID => 1,
                UNCHECKED => self.validate(f, k) as u32,
                _ => 0,
            };
            if n >= limit {
                break;
            }
        }
        n
    }

    /// For each edge of face `f`, the other front face across it when it is the only one and the
    /// region's wedge between the two is convex (at most flat).
    fn find_wedges(&mut self, f: u32) {
        let v = self.faces[f as usize].v;
        let mut w = [None; 3];
        let mut count = [0u8; 3];
        for &h in &self.front {
            if h == f {
                continue;
            }
            let hv = self.faces[h as usize].v;
            // A face across an edge shares two corners; most share none.
            if hv.iter().filter(|x| v.contains(x)).count() < 2 {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                // The face across runs the edge backwards.
                if (0..3).any(|i| hv[i] == b && hv[(i + 1) % 3] == a) {
                    count[k] += 1;
                    w[k] = Some(h);
                }
                if (0..3).any(|i| hv[i] == a && hv[(i + 1) % 3] == b) {
                    count[k] += 2;
                }
            }
        }
        for k in 0..3 {
            self.wedge[k] = None;
            if count[k] != 1 {
                continue;
            }
            if let Some(h) = w[k] {
                let hv = self.faces[h as usize].v;
                let Some(&apex) = hv.iter().find(|&&x| !v.contains(&x)) else {
                    continue;
                };
                if self.side(f, apex) != Sign::Negative {
                    self.wedge[k] = Some(h);
                }
            }
        }
    }

    /// Does the closed tet `t` contain a usable point other than its corners?
    fn contains_point(&self, t: [u32; 4], planes: &[Plane; 4], lo: P3, hi: P3) -> bool {
        // Whether any point is inside: the order of the visits does not matter.
        let test = |r: u32, x: P3| {
            if (0..3).any(|k| x[k] < lo[k] || x[k] > hi[k]) || t.contains(&r) || !self.usable(r) {
                return false;
            }
            // The base plane first: cached.
            planes
                .iter()
                .rev()
                .all(|&pl| self.outer(pl, r) != Sign::Positive)
        };
        if self.by_x.is_empty() {
            return (0..self.pts.len() as u32).any(|r| test(r, self.pts[r as usize]));
        }
        let a = self.by_x.partition_point(|e| e.0[0] < lo[0]);
        self.by_x[a..]
            .iter()
            .take_while(|e| e.0[0] <= hi[0])
            .any(|&(x, r)| test(r, x))
    }

    /// Does the candidate tet `t` (built on alive face `base`) meet another active face
    /// improperly?
    fn hits_front(
        &self,
        t: [u32; 4],
        tf: &[[u32; 3]; 4],
        planes: &[Plane; 4],
        base: u32,
        lo: P3,
        hi: P3,
    ) -> bool {
        for (&g, &(glo, ghi)) in self.front.iter().zip(&self.front_box).rev() {
            if g == base || boxes_apart(lo, hi, glo, ghi) {
                continue;
            }
            if self.face_conflicts(t, tf, planes, g) {
                return true;
            }
        }
        false
    }

    /// Exact: does front face `gid` meet the candidate tet (corners `t`, outward faces `tf` with
    /// planes `planes`, the last one its base) other than in shared vertices, edges or whole
    /// faces?
    fn face_conflicts(
        &self,
        t: [u32; 4],
        tf: &[[u32; 3]; 4],
        planes: &[Plane; 4],
        gid: u32,
    ) -> bool {
        let g = self.faces[gid as usize].v;
        // All three corners in the tet: g is one of its faces.
        if g.iter().all(|x| t.contains(x)) {
            return false;
        }
        // g's plane (cached) with the tet on one closed side, touching only at corners of g.
        let mut pos = false;
        let mut neg = false;
        let mut cut = false;
        for &x in &t {
            match self.side(gid, x) {
                Sign::Positive => pos = true,
                Sign::Negative => neg = true,
                Sign::Zero => cut |= !g.contains(&x),
            }
        }
        if !cut && (!pos || !neg) {
            return false;
        }
        // A face plane of the tet with g on its closed outer side.
        for k in (0..4).rev() {
            if self.separates(planes[k], tf[k], &g) {
                return false;
            }
        }
        let gpl = self.faces[gid as usize].plane;
        (0..3).any(|k| self.tri_conflict(tf[k], planes[k], g, gpl))
    }

    /// Do the candidate tet `c` (outward faces `cf`, planes `cp`) and the new tet (faces `tf`,
    /// planes `tp`) overlap or meet improperly?
    #[allow(clippy::too_many_arguments)]
    fn tets_conflict(
        &self,
        c: [u32; 4],
        cf: &[[u32; 3]; 4],
        cp: &[Plane; 4],
        t: [u32; 4],
        tf: &[[u32; 3]; 4],
        tp: &[Plane; 4],
    ) -> bool {
        if t.iter().all(|x| c.contains(x)) {
            return true;
        }
        if (0..4).any(|k| self.separates(tp[k], tf[k], &c))
            || (0..4).rev().any(|k| self.separates(cp[k], cf[k], &t))
        {
            return false;
        }
        for (i, f) in cf.iter().enumerate() {
            for (k, g) in tf.iter().enumerate() {
                if !same_set(*f, *g) && self.tri_conflict(*f, cp[i], *g, tp[k]) {
                    return true;
                }
            }
        }
        false
    }

    /// Add the tet of candidate `ci` on face `fi`.
    fn apply(&mut self, fi: u32, ci: u32) {
        let face = self.faces[fi as usize];
        let cand = self.cands[ci as usize];
        let t = [face.v[0], face.v[1], face.v[2], cand.p];
        self.levels.push(Level {
            faces_len: self.faces.len() as u32,
            cands_len: self.cands.len() as u32,
            kill_len: self.kill_log.len() as u32,
            removed_len: self.removed_log.len() as u32,
            tet: t,
        });
        let w = *self.worst.last().unwrap_or(&f64::INFINITY);
        self.worst.push(w.min(cand.q));
        self.kill_face(fi);
        for &x in &t {
            self.uses[x as usize] += 1;
        }
        let tf = tet_faces(t);
        let mut tp = [face.plane.flip(); 4];
        let first_new = self.faces.len();
        // Kills before pushes: the undo pops new faces off the end of `front`.
        let mut new = [false; 3];
        for k in 0..3 {
            let g = tf[k];
            let rev = [g[0], g[2], g[1]];
            if let Some(&h) = self.map.get(&canon(rev)) {
                self.kill_face(h);
                tp[k] = self.faces[h as usize].plane.flip();
            } else {
                new[k] = true;
            }
        }
        for k in 0..3 {
            if new[k] {
                self.push_face(tf[k]);
                tp[k] = self.faces[self.faces.len() - 1].plane;
            }
        }
        // Filter the candidates of the other live faces against the new tet.
        let (tlo, thi) = (cand.lo, cand.hi);
        // Only checked ones: unchecked ones are checked against the front when needed.
        for i in 0..self.front.len() {
            let f = self.front[i] as usize;
            let fr = self.faces[f];
            if f >= first_new || fr.valid == 0 {
                continue;
            }
            // Its valid candidates, counted: the rest of its range need not be read (the valid
            // ones, checked best first, come early in it).
            let mut left = fr.valid;
            for k in fr.c0..fr.c1 {
                if left == 0 {
                    break;
                }
                if self.state[k as usize] != VALID {
                    continue;
                }
                left -= 1;
                let c = &self.cands[k as usize];
                if boxes_apart(c.lo, c.hi, tlo, thi) {
                    continue;
                }
                let p = c.p;
                let ct = [fr.v[0], fr.v[1], fr.v[2], p];
                let (cf, cp) = self.cand_planes(f as u32, k);
                if self.tets_conflict(ct, &cf, &cp, t, &tf, &tp) {
                    self.set_state(f as u32, k, DEAD);
                }
            }
        }
        for f in first_new..self.faces.len() {
            self.gen_candidates(f);
        }
    }

    fn undo(&mut self) {
        let Some(l) = self.levels.pop() else {
            return;
        };
        self.worst.pop();
        // States first: the log may name candidates of faces added at this level.
        while self.kill_log.len() > l.kill_len as usize {
            if let Some((k, f, old)) = self.kill_log.pop() {
                self.restate(f, k, old);
            }
        }
        while self.faces.len() > l.faces_len as usize {
            if let Some(f) = self.faces.pop() {
                self.map.remove(&canon(f.v));
                for &x in &f.v {
                    self.front_deg[x as usize] -= 1;
                }
                self.front.pop();
                self.front_box.pop();
                self.front_pos.pop();
            }
        }
        self.cands.truncate(l.cands_len as usize);
        self.state.truncate(l.cands_len as usize);
        while self.removed_log.len() > l.removed_len as usize {
            if let Some(f) = self.removed_log.pop() {
                self.revive_face(f);
            }
        }
        for &x in &l.tet {
            self.uses[x as usize] -= 1;
        }
    }

    fn dfs(&mut self) -> Flow {
        self.nodes += 1;
        if self.nodes > self.budget {
            return Flow::Abort;
        }
        // The face with the fewest candidates, the first such in face order (or the first found
        // with one); a face without any prunes. Candidates are checked lazily: a face is first guessed by its upper bound,
        // then every other face is checked only until it cannot win.
        let mut pick = None;
        let mut fewest = u32::MAX;
        let guess = self
            .front
            .iter()
            .min_by_key(|&&f| (self.faces[f as usize].live, f))
            .map(|&f| f as usize);
        if let Some(g) = guess {
            let n = self.count_upto(g as u32, u32::MAX);
            if n == 0 {
                return Flow::Continue;
            }
            fewest = n;
            pick = Some(g);
        }
        for i in 0..self.front.len() {
            let Some(p) = pick else { break };
            let f = self.front[i] as usize;
            if f == p {
                continue;
            }
            // Beats the pick with fewer candidates, or as many and an earlier index.
            let limit = if f < p { fewest + 1 } else { fewest };
            let n = self.count_upto(f as u32, limit);
            if n == 0 {
                return Flow::Continue;
            }
            if n < limit {
                fewest = n;
                pick = Some(f);
            }
            // A face with one candidate is a forced move: take it without checking the rest (a
            // face without any is then found one level down; 5–10% less search on brain_20k).
            if fewest == 1 {
                break;
            }
        }
        let Some(f) = pick else {
            // The front is empty: a fill.
            let w = *self.worst.last().unwrap_or(&f64::INFINITY);
            if !self.have_best || w > self.best_worst {
                self.best.clear();
                self.best.extend(self.levels.iter().map(|l| l.tet));
                self.best_worst = w;
                if !self.have_best {
                    self.have_best = true;
                    match self.improve {
                        None => return Flow::Done,
                        Some(extra) => self.budget = self.nodes.saturating_add(extra),
                    }
                }
                self.bound = w;
            }
            return Flow::Continue;
        };
        let face = self.faces[f];
        for k in face.c0..face.c1 {
            let c = self.cands[k as usize];
            if c.q <= self.bound {
                break;
            }
            let st = self.state[k as usize];
            if st == DEAD || (st == UNCHECKED && !self.validate(f as u32, k)) {
                continue;
            }
            self.apply(f as u32, k);
            let r = self.dfs();
            self.undo();
            if r != Flow::Continue {
                return r;
            }
        }
        Flow::Continue
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plane-and-edge triangle test agrees with the exact [`tri_tri`] on lattice triangles,
    /// shared corners included.
    #[test]
    fn tri_conflict_matches_tri_tri() {
        // All points of a small lattice, indexed.
        let mut pts = Vec::new();
        for x in -1..=1 {
            for y in -1..=1 {
                for z in -1..=1 {
                    pts.push([x as f64, y as f64, z as f64 * 0.5 + (x * y) as f64 * 0.25]);
                }
            }
        }
        let mut s = Searcher::new();
        s.pts = pts.clone();
        let n = pts.len() as u64;
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) % n) as u32
        };
        let mut checked = 0;
        while checked < 20000 {
            let f = [next(), next(), next()];
            let g = [next(), next(), next()];
            let fp = f.map(|i| pts[i as usize]);
            let gp = g.map(|i| pts[i as usize]);
            if f[0] == f[1] || f[1] == f[2] || f[0] == f[2] || g[0] == g[1] || g[1] == g[2] {
                continue;
            }
            if g[0] == g[2] || is_degenerate(&fp) || is_degenerate(&gp) || same_set(f, g) {
                continue;
            }
            let (fpl, gpl) = (s.plane(f), s.plane(g));
            let got = s.tri_conflict(f, fpl, g, gpl);
            assert_eq!(got, tri_tri(&fp, &gp) == TriTri::Improper, "{f:?} {g:?}");
            checked += 1;
        }
    }
}
