//! Several closed surfaces to one labelled surface: each closed shell encloses a region, and the
//! region of a point is the label of the innermost shell containing it.
//!
//! Shells are the connected components of the input triangles (through shared edges); a part
//! with an edge open in its own numbering (a triangle soup) is first welded (exactly equal
//! coordinates are one point), so a soup is the surface it describes. Within each shell,
//! triangles turned against their neighbours are turned back (the minority orientation). Each is
//! oriented outward on its own (by its signed volume), then nested by exact point location
//! ([`RegionLocator`]). A shell's triangles get `sides = [own label, label of the shell around
//! it]` (0 when none). Two sibling shells that share triangles (touching tissues) keep one copy
//! of each shared triangle, an interface `[label A, label B]`. A shell labelled 0 is a cavity: its
//! inside is not meshed.
//!
//! A part whose triangles meet more than two at an edge (a non-manifold surface, as a
//! multi-material marching cubes writes: three regions along an edge) is labelled from its
//! arrangement instead ([`label_arrangement`]): the triangles, taken on both sides, split space
//! into cells by their exact angular order around every edge; nested cells are resolved by exact
//! point location; each bounded region gets a label. Solids that share a face, each given with
//! its whole boundary in one welded file (an assembly saved as one STL), have that face twice
//! with opposite orientations: one copy is kept, and the arrangement labels its two sides (the
//! face triangulated alike by both; split along different diagonals, the copies overlap and are
//! refused).
//!
//! Shells touching only along an edge (no shared triangle) make their part non-manifold: it is
//! labelled from its arrangement, each shell its own region, the edge shared by them; shells
//! touching only at a vertex are separate components, each its own region. [`touching`] lists
//! such edges and vertices. Limits: a shell sharing triangles with the shell around it is
//! refused; a non-manifold part must be the only part.
//! [`crate::mesh::validate`] checks the result (closed regions, no intersections).

use crate::mesh::dsu::Dsu;
use rustc_hash::FxHashMap;

use crate::geom::vec3::volume6;
use crate::mesh::coord_key;
use crate::mesh::inside::{Location, RegionLocator};
use crate::mesh::surface::{SurfaceMesh, same_turn};

/// One shell of an assembled surface.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Shell {
    /// Which input part it came from.
    pub part: usize,
    /// Its label (the region it encloses; 0 = a cavity).
    pub label: u32,
    /// Triangles.
    pub n_triangles: usize,
    /// Index of the innermost shell around it.
    pub parent: Option<usize>,
    /// Whether it was reversed to face outward.
    pub flipped: bool,
    /// Triangles turned to agree with their neighbours before that (the shell's minority
    /// orientation; see [`assemble`]).
    pub reoriented: usize,
}

/// Why the shells cannot be assembled.
#[derive(Debug, thiserror::Error)]
pub enum AssembleError {
    /// Fewer labels than shells in an input part.
    #[error("part {part} has {shells} closed shells but {labels} labels were given")]
    Labels {
        /// The part.
        part: usize,
        /// Its shells.
        shells: usize,
        /// Labels given.
        labels: usize,
    },
    /// A shell has the same label as the shell around it.
    #[error("shell {shell} (part {part}) has label {label}, the same as the shell around it")]
    SameAsParent {
        /// Shell index.
        shell: usize,
        /// Its part.
        part: usize,
        /// The label.
        label: u32,
    },
    /// A non-manifold part given with other parts.
    #[error("a non-manifold surface (more than two triangles at an edge) must be given alone")]
    NonManifoldWithOthers,
    /// The triangles do not split space into consistent cells: the edge where they do not,
    /// by its points' indices (the part's numbering, welded for a soup) and coordinates.
    #[error(
        "the triangles around edge ({a}, {b}) {}–{} do not bound consistent regions (crossing \
         or overlapping triangles)",
        crate::text::point(&at[0]),
        crate::text::point(&at[1])
    )]
    Arrangement {
        /// One end's point index.
        a: u32,
        /// The other end's.
        b: u32,
        /// Their coordinates.
        at: [[f64; 3]; 2],
    },
    /// A shell shares triangles with the shell around it.
    #[error(
        "shell {inner} shares triangles with shell {outer} around it (a region touching the \
         boundary of the region that contains it is not supported yet)"
    )]
    SharedWithParent {
        /// Inner shell.
        inner: usize,
        /// Outer shell.
        outer: usize,
    },
}

/// An input part: a surface and optional labels for its shells in order (default: the next
/// unused labels 1, 2, … in order of parts and shells).
pub struct Part {
    /// The triangles (any orientation per shell; within a shell, the minority orientation is
    /// turned to the majority's).
    pub surface: SurfaceMesh,
    /// Labels of its shells in order of first triangle.
    pub labels: Option<Vec<u32>>,
}

/// Connected components of triangles through shared edges: component of each triangle, count.
fn components(tris: &[[u32; 3]]) -> (Vec<u32>, usize) {
    let mut parent = Dsu::new(tris.len());
    let mut first: FxHashMap<(u32, u32), u32> = Default::default();
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let e = (a.min(b), a.max(b));
            match first.get(&e) {
                Some(&u) => parent.union(u, t as u32),
                None => {
                    first.insert(e, t as u32);
                }
            }
        }
    }
    let mut id = vec![u32::MAX; tris.len()];
    let mut comp = vec![0u32; tris.len()];
    let mut n = 0;
    for (t, c) in comp.iter_mut().enumerate() {
        let r = parent.find(t as u32) as usize;
        if id[r] == u32::MAX {
            id[r] = n;
            n += 1;
        }
        *c = id[r];
    }
    (comp, n as usize)
}

/// Turn the triangles of one shell (connected through edges, at most two triangles an edge) that
/// disagree with their neighbours: each edge then traversed once each way. The orientation of
/// the shell's first triangle spreads through shared edges, and the smaller class is turned (on
/// a tie, those disagreeing with the first triangle); the number turned. A shell where the
/// spread meets itself turned (not orientable, or an edge of more than two triangles) is left as
/// given: 0.
fn orient_consistently(tris: &mut [[u32; 3]]) -> usize {
    let n = tris.len();
    // The (at most two) triangles of each edge.
    let mut by_edge: FxHashMap<(u32, u32), [u32; 2]> = Default::default();
    by_edge.reserve(3 * n / 2);
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let e = by_edge.entry((a.min(b), a.max(b))).or_insert([u32::MAX; 2]);
            if e[0] == u32::MAX {
                e[0] = t as u32;
            } else if e[1] == u32::MAX {
                e[1] = t as u32;
            } else {
                return 0;
            }
        }
    }
    // Whether triangle `t` runs a -> b as given.
    let forward =
        |tri: &[u32; 3], a: u32, b: u32| (0..3).any(|k| tri[k] == a && tri[(k + 1) % 3] == b);
    let mut turn: Vec<Option<bool>> = vec![None; n];
    let mut stack = Vec::new();
    for start in 0..n {
        if turn[start].is_some() {
            continue;
        }
        turn[start] = Some(false);
        stack.push(start as u32);
        while let Some(t) = stack.pop() {
            let tri = tris[t as usize];
            let tt = turn[t as usize] == Some(true);
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                for u in by_edge[&(a.min(b), a.max(b))] {
                    if u == t || u == u32::MAX {
                        continue;
                    }
                    // t runs a -> b (turned or not); u must run b -> a.
                    let want = forward(&tris[u as usize], a, b) != tt;
                    match turn[u as usize] {
                        None => {
                            turn[u as usize] = Some(want);
                            stack.push(u);
                        }
                        Some(x) if x != want => return 0,
                        Some(_) => {}
                    }
                }
            }
        }
    }
    let turned = turn.iter().filter(|x| **x == Some(true)).count();
    let flip_turned = 2 * turned <= n;
    let mut count = 0;
    for (tri, t) in tris.iter_mut().zip(&turn) {
        if (*t == Some(true)) == flip_turned {
            tri.swap(1, 2);
            count += 1;
        }
    }
    count
}

/// The closed surface `tris` alone, on its own points only (region 1 inside), for locating
/// points against one shell.
fn alone(points: &[[f64; 3]], tris: &[[u32; 3]]) -> SurfaceMesh {
    let mut local: FxHashMap<u32, u32> = Default::default();
    let mut pts = Vec::new();
    let tris = tris
        .iter()
        .map(|t| {
            t.map(|v| {
                *local.entry(v).or_insert_with(|| {
                    pts.push(points[v as usize]);
                    (pts.len() - 1) as u32
                })
            })
        })
        .collect();
    SurfaceMesh::closed(pts, tris, 1)
}

/// Whether some edge has only one triangle (open) and whether some has more than two
/// (non-manifold).
fn edge_uses(tris: &[[u32; 3]]) -> (bool, bool) {
    let mut count: FxHashMap<(u32, u32), u32> = Default::default();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    (
        count.values().any(|&c| c == 1),
        count.values().any(|&c| c > 2),
    )
}

/// One copy of each triangle given twice with opposite orientations on the same corners: solids
/// that share a face, each given with its whole boundary in one welded file (an assembly saved
/// as one STL), have that face once in each; the arrangement needs it once, and labels its two
/// sides. The first copy is kept; other repeats are left for the arrangement to refuse.
fn merge_opposite_copies(mut s: SurfaceMesh) -> SurfaceMesh {
    // Corners sorted -> the first copy, while it is unpaired.
    let mut open: FxHashMap<[u32; 3], usize> = Default::default();
    let mut drop = vec![false; s.triangles.len()];
    for (t, tri) in s.triangles.iter().enumerate() {
        let mut key = *tri;
        key.sort_unstable();
        if let Some(&f) = open.get(&key) {
            if !same_turn(s.triangles[f], *tri) {
                drop[t] = true;
                open.remove(&key);
            }
        } else {
            open.insert(key, t);
        }
    }
    if drop.contains(&true) {
        let mut keep = drop.iter().map(|&d| !d);
        s.triangles.retain(|_| keep.next().unwrap_or(true));
        let mut keep = drop.iter().map(|&d| !d);
        s.sides.retain(|_| keep.next().unwrap_or(true));
    }
    s
}

/// Label a (possibly non-manifold) surface from the cells its triangles bound: every bounded
/// region gets a label, 1, 2, … in order of its first triangle, or `labels[k]` for the k-th.
/// Triangle orientations are kept; `sides` are set.
pub fn label_arrangement(
    s: &SurfaceMesh,
    labels: Option<&[u32]>,
) -> Result<(SurfaceMesh, Vec<Shell>), AssembleError> {
    let nt = s.triangles.len();
    // Half-face 2t faces the triangle's front (its normal points into that cell), 2t+1 its back.
    let mut half = Vec::with_capacity(2 * nt);
    for t in &s.triangles {
        half.push(*t);
        half.push([t[0], t[2], t[1]]);
    }
    let mut cell = Vec::new();
    let n = crate::lastresort::cells::Cells::default()
        .split(&s.points, &half, &mut cell)
        .map_err(|(a, b)| AssembleError::Arrangement {
            a,
            b,
            at: [a, b].map(|v| s.points[v as usize]),
        })?;
    // Each cell is a closed surface with normals into it: negative outward volume means it
    // bounds a finite region from outside; positive, that it is the outer side of a solid (a
    // hole in the region around it, or the boundary of the unbounded region).
    let mut vol = vec![0.0f64; n];
    let o = s.points.first().copied().unwrap_or([0.0; 3]);
    for (h, f) in half.iter().enumerate() {
        let [a, b, c] = f.map(|v| s.points[v as usize]);
        vol[cell[h] as usize] += volume6(o, a, b, c);
    }
    let outer: Vec<usize> = (0..n).filter(|&c| vol[c] < 0.0).collect();
    let mut region = vec![0u32; n];
    for (k, &c) in outer.iter().enumerate() {
        region[c] = match labels {
            Some(l) if k < l.len() => l[k],
            Some(l) => {
                return Err(AssembleError::Labels {
                    part: 0,
                    shells: outer.len(),
                    labels: l.len(),
                });
            }
            None => k as u32 + 1,
        };
    }
    if let Some(l) = labels
        && l.len() != outer.len()
    {
        return Err(AssembleError::Labels {
            part: 0,
            shells: outer.len(),
            labels: l.len(),
        });
    }
    // A positive cell belongs to the innermost finite region around it, by point location
    // against each negative cell's own triangles.
    let tris_of = |c: usize| -> Vec<[u32; 3]> {
        half.iter()
            .zip(&cell)
            .filter(|&(_, &k)| k as usize == c)
            .map(|(f, _)| [f[0], f[2], f[1]]) // outward for the region inside
            .collect()
    };
    let positive: Vec<usize> = (0..n).filter(|&c| vol[c] >= 0.0).collect();
    if !positive.is_empty() && !outer.is_empty() {
        let mut best: Vec<Option<(usize, f64)>> = vec![None; n];
        for &c in &outer {
            let tris = tris_of(c);
            let on: rustc_hash::FxHashSet<u32> = tris.iter().flatten().copied().collect();
            let shell = alone(&s.points, &tris);
            let loc = RegionLocator::new(&shell);
            for &p in &positive {
                let Some(&v) = half
                    .iter()
                    .zip(&cell)
                    .filter(|&(_, &k)| k as usize == p)
                    .flat_map(|(f, _)| f.iter())
                    .find(|v| !on.contains(v))
                else {
                    continue;
                };
                if loc.locate(s.points[v as usize]) == Location::Region(1) {
                    // The innermost container has the smallest volume.
                    let size = -vol[c];
                    if best[p].is_none_or(|(_, b)| size < b) {
                        best[p] = Some((c, size));
                    }
                }
            }
        }
        for &p in &positive {
            region[p] = best[p].map_or(0, |(c, _)| region[c]);
        }
    }
    let sides = (0..nt)
        .map(|t| {
            [
                region[cell[2 * t + 1] as usize],
                region[cell[2 * t] as usize],
            ]
        })
        .collect();
    let shells = outer
        .iter()
        .map(|&c| Shell {
            part: 0,
            label: region[c],
            n_triangles: cell.iter().filter(|&&k| k as usize == c).count(),
            parent: None,
            flipped: false,
            reoriented: 0,
        })
        .collect();
    Ok((
        SurfaceMesh {
            points: s.points.clone(),
            triangles: s.triangles.clone(),
            sides,
        },
        shells,
    ))
}

/// Assemble parts into one surface with region labels; returns it and its shells (see the
/// module docs: soups welded, shells nested, turned triangles turned back, shared triangles one
/// interface).
pub fn assemble(parts: Vec<Part>) -> Result<(SurfaceMesh, Vec<Shell>), AssembleError> {
    // One welded point set for the geometry.
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut index: FxHashMap<[u64; 3], u32> = Default::default();
    let welded: Vec<Vec<[u32; 3]>> = parts
        .iter()
        .map(|part| {
            let map: Vec<u32> = part
                .surface
                .points
                .iter()
                .map(|p| {
                    *index.entry(coord_key(p)).or_insert_with(|| {
                        points.push(*p);
                        (points.len() - 1) as u32
                    })
                })
                .collect();
            let tris = &part.surface.triangles;
            tris.iter().map(|t| t.map(|v| map[v as usize])).collect()
        })
        .collect();
    // The topology a part's shells are found in: its own indices when they close every edge
    // (shells that touch, each with its own copies of the shared points, stay apart and share
    // an interface); the welded indices when some edge is open in its own (a triangle soup, as
    // a PLY or OBJ written without merging points, where each triangle would be a shell).
    let own: Vec<(bool, bool)> = parts
        .iter()
        .map(|p| edge_uses(&p.surface.triangles))
        .collect();
    let joined: Vec<bool> = own.iter().map(|u| u.0).collect();
    let topo = |k: usize| -> &[[u32; 3]] {
        if joined[k] {
            &welded[k]
        } else {
            &parts[k].surface.triangles
        }
    };
    // A triangle whose corners welded together (distinct points in the file at one position)
    // is left to the validation, which names it; the arrangement would only see bad edges.
    let collapsed = |tris: &[[u32; 3]]| {
        tris.iter()
            .any(|t| t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
    };
    let non_manifold = |k: usize| {
        let over = if joined[k] {
            edge_uses(&welded[k]).1
        } else {
            own[k].1
        };
        over && !collapsed(topo(k))
    };
    if let Some(k) = (0..parts.len()).find(|&k| non_manifold(k)) {
        if parts.len() > 1 {
            return Err(AssembleError::NonManifoldWithOthers);
        }
        let s = if joined[k] {
            SurfaceMesh {
                points,
                triangles: welded[k].clone(),
                sides: parts[k].surface.sides.clone(),
            }
        } else {
            parts[k].surface.clone()
        };
        return label_arrangement(&merge_opposite_copies(s), parts[k].labels.as_deref());
    }
    // Shell triangles, per shell, mapped to the welded points.
    let mut shell_tris: Vec<Vec<[u32; 3]>> = Vec::new();
    let mut shells: Vec<Shell> = Vec::new();
    let mut next_label = 1u32;
    for (pi, (part, tris)) in parts.iter().zip(&welded).enumerate() {
        let (comp, n) = components(topo(pi));
        if let Some(l) = &part.labels
            && l.len() != n
        {
            return Err(AssembleError::Labels {
                part: pi,
                shells: n,
                labels: l.len(),
            });
        }
        let base = shell_tris.len();
        for c in 0..n {
            let label = match &part.labels {
                Some(l) => l[c],
                None => next_label,
            };
            next_label = next_label.max(label + 1);
            shells.push(Shell {
                part: pi,
                label,
                n_triangles: 0,
                parent: None,
                flipped: false,
                reoriented: 0,
            });
            shell_tris.push(Vec::new());
        }
        for (t, tri) in tris.iter().enumerate() {
            shell_tris[base + comp[t] as usize].push(*tri);
        }
    }
    // A shell's triangles turned against their neighbours (a few reversed by an exporter): the
    // minority turned, as the validation would ask. Orientation means nothing yet (the regions
    // come from the nesting), so this is no guess; a shell that cannot be oriented is left for
    // the validation to refuse.
    for (s, tris) in shell_tris.iter_mut().enumerate() {
        shells[s].reoriented = orient_consistently(tris);
    }
    // Orient each shell outward by its signed volume (a sign on a closed embedded shell; the
    // validation that follows confirms the shell is one).
    for (s, tris) in shell_tris.iter_mut().enumerate() {
        let o = points[tris[0][0] as usize];
        let vol: f64 = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| points[v as usize]);
                volume6(o, a, b, c)
            })
            .sum();
        if vol < 0.0 {
            for t in tris.iter_mut() {
                t.swap(1, 2);
            }
            shells[s].flipped = true;
        }
        shells[s].n_triangles = tris.len();
    }
    // Shared triangles between shells (by vertex set).
    let sorted = |t: &[u32; 3]| {
        let mut k = *t;
        k.sort_unstable();
        k
    };
    let mut owner: FxHashMap<[u32; 3], (usize, usize)> = Default::default();
    let mut shared: Vec<(usize, usize, usize, usize)> = Vec::new(); // (shell a, tri a, shell b, tri b)
    for (s, tris) in shell_tris.iter().enumerate() {
        for (t, tri) in tris.iter().enumerate() {
            match owner.get(&sorted(tri)) {
                Some(&(s0, t0)) if s0 != s => shared.push((s0, t0, s, t)),
                _ => {
                    owner.insert(sorted(tri), (s, t));
                }
            }
        }
    }
    // Nesting: shell a inside shell b when a point of a not on b is inside b.
    let n = shells.len();
    let mut inside = vec![vec![false; n]; n];
    if n > 1 {
        let on_shell: Vec<rustc_hash::FxHashSet<u32>> = shell_tris
            .iter()
            .map(|tris| tris.iter().flatten().copied().collect())
            .collect();
        for b in 0..n {
            let sb = alone(&points, &shell_tris[b]);
            let loc = RegionLocator::new(&sb);
            for a in 0..n {
                if a == b {
                    continue;
                }
                // A vertex of a off b; shells that share every vertex are siblings or equal.
                if let Some(&v) = on_shell[a]
                    .iter()
                    .filter(|v| !on_shell[b].contains(v))
                    .min()
                {
                    inside[a][b] = loc.locate(points[v as usize]) == Location::Region(1);
                }
            }
        }
    }
    for a in 0..n {
        let depth = |x: usize| (0..n).filter(|&b| inside[x][b]).count();
        let d = depth(a);
        shells[a].parent = (0..n).find(|&b| inside[a][b] && depth(b) + 1 == d);
    }
    for &(a, _, b, _) in &shared {
        if inside[a][b] {
            return Err(AssembleError::SharedWithParent { inner: a, outer: b });
        }
        if inside[b][a] {
            return Err(AssembleError::SharedWithParent { inner: b, outer: a });
        }
    }
    for (s, sh) in shells.iter().enumerate() {
        if let Some(p) = sh.parent
            && shells[p].label == sh.label
        {
            return Err(AssembleError::SameAsParent {
                shell: s,
                part: sh.part,
                label: sh.label,
            });
        }
    }
    let outside = |s: usize| shells[s].parent.map_or(0, |p| shells[p].label);
    let mut skip: rustc_hash::FxHashSet<(usize, usize)> = Default::default();
    let mut interface: FxHashMap<(usize, usize), u32> = Default::default();
    for &(a, ta, b, tb) in &shared {
        skip.insert((b, tb));
        interface.insert((a, ta), shells[b].label);
    }
    let mut triangles = Vec::new();
    let mut sides = Vec::new();
    for (s, tris) in shell_tris.iter().enumerate() {
        for (t, tri) in tris.iter().enumerate() {
            if skip.contains(&(s, t)) {
                continue;
            }
            let front = interface
                .get(&(s, t))
                .copied()
                .unwrap_or_else(|| outside(s));
            triangles.push(*tri);
            sides.push([shells[s].label, front]);
        }
    }
    Ok((
        SurfaceMesh {
            points,
            triangles,
            sides,
        },
        shells,
    ))
}

/// Where the regions of a labelled surface touch only along an edge or at a vertex: the outer
/// boundary of the union of the regions (the triangles with the outside, label 0, on one side)
/// is not a manifold there, though each region's boundary is. See [`touching`].
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct Touching {
    /// Edges in more than two outer triangles, with the regions that meet there.
    pub edges: Vec<([u32; 2], Vec<u32>)>,
    /// Vertices (not on such an edge) where the outer triangles form more than one fan, with
    /// the regions that meet there.
    pub vertices: Vec<(u32, Vec<u32>)>,
}

/// The edges and vertices where regions of `s` touch (combinatorial: by vertex indices). On a
/// surface that passes [`crate::mesh::validate::validate_surface`] each region is a manifold on
/// its own, so every sheet meeting there belongs to a different region.
pub fn touching(s: &SurfaceMesh) -> Touching {
    let outer: Vec<usize> = (0..s.triangles.len())
        .filter(|&t| s.sides.get(t).is_some_and(|x| x.contains(&0)))
        .collect();
    let mut at_edge: FxHashMap<[u32; 2], Vec<usize>> = Default::default();
    for &t in &outer {
        let v = s.triangles[t];
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            at_edge.entry([a.min(b), a.max(b)]).or_default().push(t);
        }
    }
    let regions = |ts: &mut dyn Iterator<Item = usize>| {
        let mut r: Vec<u32> = ts.flat_map(|t| s.sides[t]).filter(|&l| l != 0).collect();
        r.sort_unstable();
        r.dedup();
        r
    };
    let mut out = Touching::default();
    let mut on_edge: rustc_hash::FxHashSet<u32> = Default::default();
    // Fans: corners (3t + k) of outer triangles joined across edges with two outer triangles.
    let mut parent = Dsu::new(3 * s.triangles.len());
    let corner =
        |t: usize, v: u32| 3 * t + s.triangles[t].iter().position(|&x| x == v).unwrap_or(0);
    let mut edges: Vec<_> = at_edge.into_iter().collect();
    edges.sort_unstable();
    for (e, ts) in &edges {
        match ts.len() {
            2 => {
                for v in e {
                    parent.union(corner(ts[0], *v) as u32, corner(ts[1], *v) as u32);
                }
            }
            n if n > 2 => {
                out.edges.push((*e, regions(&mut ts.iter().copied())));
                on_edge.extend(e);
            }
            _ => {}
        }
    }
    let mut fans: Vec<(u32, usize, usize)> = Vec::new(); // (vertex, fan, triangle)
    for &t in &outer {
        for v in s.triangles[t] {
            fans.push((v, parent.find(corner(t, v) as u32) as usize, t));
        }
    }
    fans.sort_unstable();
    for run in fans.chunk_by(|a, b| a.0 == b.0) {
        let v = run[0].0;
        if on_edge.contains(&v) || run.windows(2).all(|w| w[0].1 == w[1].1) {
            continue;
        }
        out.vertices
            .push((v, regions(&mut run.iter().map(|x| x.2))));
    }
    out
}
