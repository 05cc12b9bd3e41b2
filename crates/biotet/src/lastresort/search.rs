//! The LAST RESORT search (Algorithm 3.1 of the seed, section 3.3.1): fill a closed cavity shell
//! with tets whose corners are cavity points only.
//!
//! # What is searched
//! The *front* starts as the shell: oriented triangles whose right-hand normals point into the
//! region to fill (a triangle may appear with both orientations: a "fin" inside the region, such
//! as a recovered surface triangle that the rest of the shell does not close off). A candidate of
//! an active face `abc` is a tet `abcp` whose fourth point `p` is a cavity point with
//! 1. `orient3d(a, b, c, p) > 0` (exact);
//! 2. quality `q` (eq. 4.9) above the threshold ηe (floating point: ranking only; with ηe ≤ 0
//!    no float test is made at all);
//! 3. no other live cavity point in the closed tet (exact, orient3d);
//! 4. no improper contact with any other active face: for every active face and every face of
//!    the tet, the exact triangle–triangle test ([`tri_tri`]) reports disjoint, a shared vertex
//!    or a shared edge, or the two are the same triangle.
//!
//! Given 3 for both tets, 4 is exactly "the tet lies in the closure of the unfilled region and
//! meets its boundary only in shared vertices, edges and faces": if an active face met the open
//! tet, its corners being outside it, some pair of faces would meet improperly. The unfilled
//! region only shrinks, so a candidate once invalid stays invalid down the tree: candidates are
//! computed once per face and only *filtered* when a tet is added (the same pairwise test against
//! the new tet), and filtering is undone on backtracking.
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
use crate::geom::intersect::{TriTri, is_degenerate, tri_tri};
use crate::geom::predicates::{Sign, in_exact_range};
use crate::quality::tet::q_measure;
use rustc_hash::FxHashMap;
use thiserror::Error;

type P3 = [f64; 3];

/// Options of [`fill`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchOptions {
    /// ηe: candidates need quality q (eq. 4.9) strictly above it. At or below 0, every
    /// positively oriented tet qualifies (decided exactly, no float test).
    pub min_quality: f64,
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
    /// Live candidates.
    live: u32,
}

/// A candidate tet `face + p`.
#[derive(Debug, Clone, Copy)]
struct Cand {
    p: u32,
    q: f64,
    dead: bool,
    lo: P3,
    hi: P3,
}

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
    map: FxHashMap<[u32; 3], u32>,
    kill_log: Vec<u32>,
    removed_log: Vec<u32>,
    front_deg: Vec<u32>,
    uses: Vec<u32>,
    levels: Vec<Level>,
    worst: Vec<f64>,
    best: Vec<[u32; 4]>,
    best_worst: f64,
    have_best: bool,
    bound: f64,
    nodes: u64,
    budget: u64,
    eta: f64,
    improve: Option<u64>,
    scratch: Vec<[u32; 3]>,
    edges: Vec<(u32, u32)>,
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
fn bbox4(c: &[P3; 4]) -> (P3, P3) {
    let mut lo = c[0];
    let mut hi = c[0];
    for p in &c[1..] {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

#[inline]
fn boxes_apart(alo: P3, ahi: P3, blo: P3, bhi: P3) -> bool {
    (0..3).any(|k| ahi[k] < blo[k] || bhi[k] < alo[k])
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
        self.load(points, shell, inner)?;
        self.eta = opts.min_quality;
        self.improve = opts.improve;
        self.budget = opts.max_nodes;
        self.nodes = 0;
        self.have_best = false;
        self.best.clear();
        self.best_worst = f64::NEG_INFINITY;
        self.bound = f64::NEG_INFINITY;
        self.levels.clear();
        self.worst.clear();
        self.worst.push(f64::INFINITY);
        for f in 0..self.faces.len() {
            self.gen_candidates(f);
        }
        let flow = self.dfs();
        if self.have_best {
            let tets = self
                .best
                .iter()
                .map(|t| t.map(|v| self.global[v as usize]))
                .collect();
            return Ok(Fill {
                tets,
                worst_q: self.best_worst,
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

    /// Validate the input and set up local points and the initial front.
    fn load(
        &mut self,
        points: &[P3],
        shell: &[[u32; 3]],
        inner: &[u32],
    ) -> Result<(), SearchError> {
        if shell.is_empty() {
            return Err(SearchError::Empty);
        }
        let n = points.len();
        self.global.clear();
        for &i in shell.iter().flatten().chain(inner) {
            if i as usize >= n {
                return Err(SearchError::IndexOutOfRange { index: i, n });
            }
            self.global.push(i);
        }
        self.global.sort_unstable();
        self.global.dedup();
        self.pts.clear();
        for &g in &self.global {
            let p = points[g as usize];
            if !p.iter().all(|&c| in_exact_range(c)) {
                return Err(SearchError::BadCoordinate { index: g });
            }
            self.pts.push(p);
        }
        // Duplicates: sort local ids by coordinates.
        let mut order: Vec<u32> = (0..self.pts.len() as u32).collect();
        let key = |p: &P3| p.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
        order.sort_unstable_by_key(|&i| key(&self.pts[i as usize]));
        for w in order.windows(2) {
            if key(&self.pts[w[0] as usize]) == key(&self.pts[w[1] as usize]) {
                return Err(SearchError::DuplicatePoint {
                    a: self.global[w[0] as usize],
                    b: self.global[w[1] as usize],
                });
            }
        }
        let local = |g: u32, global: &[u32]| global.binary_search(&g).unwrap_or(0) as u32;
        self.scratch.clear();
        for (i, f) in shell.iter().enumerate() {
            let l = f.map(|g| local(g, &self.global));
            let c = l.map(|v| self.pts[v as usize]);
            if l[0] == l[1] || l[1] == l[2] || l[0] == l[2] || is_degenerate(&c) {
                return Err(SearchError::DegenerateFace { face: i });
            }
            self.scratch.push(l);
        }
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
        let np = self.pts.len();
        self.front_deg.clear();
        self.front_deg.resize(np, 0);
        self.uses.clear();
        self.uses.resize(np, 0);
        self.faces.clear();
        self.cands.clear();
        self.map.clear();
        self.kill_log.clear();
        self.removed_log.clear();
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
        Ok(())
    }

    fn push_face(&mut self, v: [u32; 3]) {
        let id = self.faces.len() as u32;
        let c = self.cands.len() as u32;
        self.faces.push(Face {
            v,
            alive: true,
            c0: c,
            c1: c,
            live: 0,
        });
        self.map.insert(canon(v), id);
        for &x in &v {
            self.front_deg[x as usize] += 1;
        }
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
    }

    #[inline]
    fn usable(&self, p: u32) -> bool {
        self.front_deg[p as usize] > 0 || self.uses[p as usize] == 0
    }

    /// Compute the candidates of face `f` (its range is the end of `cands`).
    fn gen_candidates(&mut self, f: usize) {
        let v = self.faces[f].v;
        let [a, b, c] = v.map(|x| self.pts[x as usize]);
        let start = self.cands.len();
        for p in 0..self.pts.len() as u32 {
            if v.contains(&p) || !self.usable(p) {
                continue;
            }
            let d = self.pts[p as usize];
            if orient3d(a, b, c, d) != Sign::Positive {
                continue;
            }
            let corners = [a, b, c, d];
            let q = q_measure(&corners);
            if (self.eta > 0.0 && !(q > self.eta)) || q <= self.bound {
                continue;
            }
            let t = [v[0], v[1], v[2], p];
            let (lo, hi) = bbox4(&corners);
            if self.contains_point(t, &corners, lo, hi) || self.hits_front(t, f as u32, lo, hi) {
                continue;
            }
            self.cands.push(Cand {
                p,
                q,
                dead: false,
                lo,
                hi,
            });
        }
        self.cands[start..].sort_by(|x, y| y.q.total_cmp(&x.q).then(x.p.cmp(&y.p)));
        let face = &mut self.faces[f];
        face.c0 = start as u32;
        face.c1 = self.cands.len() as u32;
        face.live = face.c1 - face.c0;
    }

    /// Does the closed tet `t` contain a usable point other than its corners?
    fn contains_point(&self, t: [u32; 4], c: &[P3; 4], lo: P3, hi: P3) -> bool {
        let faces = tet_faces([0, 1, 2, 3]);
        for r in 0..self.pts.len() as u32 {
            if t.contains(&r) || !self.usable(r) {
                continue;
            }
            let x = self.pts[r as usize];
            if (0..3).any(|k| x[k] < lo[k] || x[k] > hi[k]) {
                continue;
            }
            let inside = faces.iter().all(|fl| {
                orient3d(c[fl[0] as usize], c[fl[1] as usize], c[fl[2] as usize], x)
                    != Sign::Positive
            });
            if inside {
                return true;
            }
        }
        false
    }

    /// Does the tet `t` (built on alive face `base`) meet another active face improperly?
    fn hits_front(&self, t: [u32; 4], base: u32, lo: P3, hi: P3) -> bool {
        let tf = tet_faces(t);
        for (g, face) in self.faces.iter().enumerate() {
            if !face.alive || g as u32 == base {
                continue;
            }
            if self.face_conflicts(&tf, t, face.v, lo, hi, Some(3)) {
                return true;
            }
        }
        false
    }

    /// Exact: does triangle `g` meet the tet with faces `tf` (corners `t`) other than in shared
    /// vertices, edges or whole faces? Faces of the tet equal to `g` (as vertex sets) are
    /// skipped; so is face `skip` of the tet (the base, already on the front).
    fn face_conflicts(
        &self,
        tf: &[[u32; 3]; 4],
        t: [u32; 4],
        g: [u32; 3],
        lo: P3,
        hi: P3,
        skip: Option<usize>,
    ) -> bool {
        let gp = g.map(|x| self.pts[x as usize]);
        let mut glo = gp[0];
        let mut ghi = gp[0];
        for p in &gp[1..] {
            for k in 0..3 {
                glo[k] = glo[k].min(p[k]);
                ghi[k] = ghi[k].max(p[k]);
            }
        }
        if boxes_apart(lo, hi, glo, ghi) {
            return false;
        }
        if tf.iter().any(|f| same_set(*f, g)) {
            return false;
        }
        // A face plane of the tet with g on its closed outer side, touching only at corners of
        // that face: contact within shared corners only.
        for f in tf {
            let fp = f.map(|x| self.pts[x as usize]);
            let ok = (0..3).all(|k| match orient3d(fp[0], fp[1], fp[2], gp[k]) {
                Sign::Positive => true,
                Sign::Zero => f.contains(&g[k]),
                Sign::Negative => false,
            });
            if ok {
                return false;
            }
        }
        // g's plane with the tet on one closed side, touching only at corners of g.
        let mut side = Sign::Zero;
        let mut sep = true;
        for &x in &t {
            let s = orient3d(gp[0], gp[1], gp[2], self.pts[x as usize]);
            match s {
                Sign::Zero => {
                    if !g.contains(&x) {
                        sep = false;
                        break;
                    }
                }
                _ => {
                    if side == Sign::Zero {
                        side = s;
                    } else if side != s {
                        sep = false;
                        break;
                    }
                }
            }
        }
        if sep {
            return false;
        }
        for (k, f) in tf.iter().enumerate() {
            if Some(k) == skip {
                continue;
            }
            let fp = f.map(|x| self.pts[x as usize]);
            if tri_tri(&fp, &gp) == TriTri::Improper {
                return true;
            }
        }
        false
    }

    /// Do the candidate tet `c` and the new tet `t` overlap or meet improperly?
    fn tets_conflict(&self, c: [u32; 4], clo: P3, chi: P3, t: [u32; 4], tlo: P3, thi: P3) -> bool {
        if boxes_apart(clo, chi, tlo, thi) {
            return false;
        }
        if t.iter().all(|x| c.contains(x)) {
            return true;
        }
        let cf = tet_faces(c);
        let tf = tet_faces(t);
        // Separating face planes (contact at shared corners of that face only).
        let separated = |faces: &[[u32; 3]; 4], other: [u32; 4]| {
            faces.iter().any(|f| {
                let fp = f.map(|x| self.pts[x as usize]);
                other.iter().all(
                    |&x| match orient3d(fp[0], fp[1], fp[2], self.pts[x as usize]) {
                        Sign::Positive => true,
                        Sign::Zero => f.contains(&x),
                        Sign::Negative => false,
                    },
                )
            })
        };
        if separated(&tf, c) || separated(&cf, t) {
            return false;
        }
        for f in &cf {
            let fp = f.map(|x| self.pts[x as usize]);
            for g in &tf {
                if same_set(*f, *g) {
                    continue;
                }
                let gp = g.map(|x| self.pts[x as usize]);
                if tri_tri(&fp, &gp) == TriTri::Improper {
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
        let mut fresh = [[0u32; 3]; 3];
        let mut n_fresh = 0;
        for g in &tet_faces(t)[..3] {
            let rev = [g[0], g[2], g[1]];
            if let Some(&h) = self.map.get(&canon(rev)) {
                self.kill_face(h);
            } else {
                fresh[n_fresh] = *g;
                n_fresh += 1;
            }
        }
        // Filter the candidates of the other live faces against the new tet.
        let (tlo, thi) = (cand.lo, cand.hi);
        for f in 0..self.faces.len() {
            let fr = self.faces[f];
            if !fr.alive || fr.live == 0 {
                continue;
            }
            for k in fr.c0..fr.c1 {
                let c = self.cands[k as usize];
                if c.dead {
                    continue;
                }
                let ct = [fr.v[0], fr.v[1], fr.v[2], c.p];
                if self.tets_conflict(ct, c.lo, c.hi, t, tlo, thi) {
                    self.cands[k as usize].dead = true;
                    self.faces[f].live -= 1;
                    self.kill_log.push(k);
                }
            }
        }
        let first_new = self.faces.len();
        for g in &fresh[..n_fresh] {
            self.push_face(*g);
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
        while self.faces.len() > l.faces_len as usize {
            if let Some(f) = self.faces.pop() {
                self.map.remove(&canon(f.v));
                for &x in &f.v {
                    self.front_deg[x as usize] -= 1;
                }
            }
        }
        self.cands.truncate(l.cands_len as usize);
        while self.kill_log.len() > l.kill_len as usize {
            if let Some(k) = self.kill_log.pop() {
                self.cands[k as usize].dead = false;
                // Find the owning face: the one whose range holds k (alive ones only were
                // filtered).
                if let Some(f) = self.owner(k) {
                    self.faces[f].live += 1;
                }
            }
        }
        while self.removed_log.len() > l.removed_len as usize {
            if let Some(f) = self.removed_log.pop() {
                let face = &mut self.faces[f as usize];
                face.alive = true;
                let v = face.v;
                self.map.insert(canon(v), f);
                for &x in &v {
                    self.front_deg[x as usize] += 1;
                }
            }
        }
        for &x in &l.tet {
            self.uses[x as usize] -= 1;
        }
    }

    /// The face whose candidate range holds candidate `k` (ranges are disjoint and increasing).
    fn owner(&self, k: u32) -> Option<usize> {
        let i = self.faces.partition_point(|f| f.c1 <= k);
        (i < self.faces.len() && self.faces[i].c0 <= k).then_some(i)
    }

    fn dfs(&mut self) -> Flow {
        self.nodes += 1;
        if self.nodes > self.budget {
            return Flow::Abort;
        }
        let mut pick = None;
        let mut fewest = u32::MAX;
        for (f, face) in self.faces.iter().enumerate() {
            if !face.alive {
                continue;
            }
            let n = if self.bound > f64::NEG_INFINITY {
                (face.c0..face.c1)
                    .filter(|&k| {
                        let c = &self.cands[k as usize];
                        !c.dead && c.q > self.bound
                    })
                    .count() as u32
            } else {
                face.live
            };
            if n == 0 {
                return Flow::Continue;
            }
            if n < fewest {
                fewest = n;
                pick = Some(f);
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
            if c.dead {
                continue;
            }
            if c.q <= self.bound {
                break;
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
