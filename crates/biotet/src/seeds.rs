//! Interior seeds where node deployment placed none: the circumcentres of the poor tets that
//! join surface points across a thin section, each inserted by coning its cavity.
//!
//! The template keeps its nodes a sealing distance from the surface, so a section thinner than that
//! (a square-section ring tube, a thin bar) gets no interior node, and every tet there joins
//! surface points from wall to wall. Where such a tet is poor, the circumcentre of it or of a
//! neighbour of the same kind (a flat tet on a planar quad has none of its own) is the point
//! Delaunay refinement would add (TetGen's `q` puts one in each segment of a square-section ring
//! tube). It becomes a seed when it lies strictly inside the region, clear of the surface and of
//! the points around it, and the tets whose circumspheres hold it, reached through faces of the
//! region (with the poor tets beside them when that passes, else alone: a flat tet on a planar quad
//! has no circumsphere to hold it), form a cavity whose every shell face sees it strictly inside
//! (exact `orient3d`), with no point lost, and whose cone's worst dihedral angle is above
//! [`SEED_BELOW_DEG`] (half of it where the cavity holds a flat tet, under `FLAT_DEG`) and above
//! the cavity's worst. Cavities of two seeds never share a tet; every accepted cone replaces its
//! cavity at once. Boundary and interface faces are never crossed, so they stay faces.
//!
//! Recovery can leave tets that span two or three segments of a tube (a twisted prism's six
//! corners are cospherical, so the Delaunay there is a tie), whose circumcentres lie outside it or
//! too near its walls: those segments get no seed. A second pass flips the poor tets the first
//! left towards Delaunay (Lawson 2-3 and 3-2 flips of faces between two tets of surface points,
//! one of them poor, exact `insphere`) as a trial, undone from a log of the slots it changed;
//! the groups of flips that a seed's cavity there takes are made again, and the poor tets they
//! made give seeds as above. The other flips are dropped: they only trade one poor tet for
//! another.
//!
//! The choice of points is floating point, as node placement is; every tet made is checked
//! positive exactly. Sequential, in tet order: the same mesh on any number of threads.

use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};

use crate::geom::predicates::{Sign, insphere, orient3d};
use crate::geom::vec3::{norm2, sub};
use crate::mesh::cavity;
use crate::mesh::dsu::Dsu;
use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::{NO_NEIGHBOR, TET_FACES, TetMesh};
use crate::quality::tet::{circumcentre, min_dihedral_deg_by_chord};
use crate::surface::bvh::Bvh;

type P3 = [f64; 3];

/// Tets of surface points below this smallest dihedral angle (degrees) give candidates, and a
/// seed's cone must be above it.
pub const SEED_BELOW_DEG: f64 = 10.0;

/// A seed's clearance from the surface and from the points around it, as a fraction of its
/// tet's circumradius: the centre of a segment of a ring tube is 0.38 of it from the walls for a
/// square section, 0.27 for a triangular one (whose cones stay above 10°); the cone's own test
/// is what keeps the seeds that would make slivers out.
const SEED_CLEARANCE: f64 = 0.2;

/// A cavity whose worst tet is below this (degrees; polish's flat, a thousandth of 10°) holds a
/// flat tet: its seed's cone may be below [`SEED_BELOW_DEG`], down to half of it. (At 1°, pyvista's
/// sphere got six more seeds near its poles and twice the sliver removal's time, for nothing.)
const FLAT_DEG: f64 = 0.01;

/// Steps of the walk that locates a circumcentre.
const WALK_STEPS: usize = 64;

/// Largest cavity a seed may take, in tets.
const MAX_CAVITY: usize = 64;

/// Insert the seeds into `mesh`, whose first `ns` points are the surface's (`surface` its
/// boundary); returns how many. Adjacency is kept.
pub fn insert_seeds(mesh: &mut TetMesh, ns: usize, surface: &SurfaceMesh) -> usize {
    let bad = poor_surface_tets(mesh, ns);
    if bad.is_empty() {
        return 0;
    }
    let bvh = Bvh::of_surface(surface);
    let mut n = seed_pass(mesh, ns, &bvh, bad);
    let left = poor_surface_tets(mesh, ns);
    if !left.is_empty() {
        n += flip_and_seed(mesh, ns, &bvh, &left);
    }
    n
}

/// The seeds [`choose`] takes from the poor tets `bad`, each cavity coned to its seed; how many.
fn seed_pass(mesh: &mut TetMesh, ns: usize, bvh: &Bvh, bad: Vec<u32>) -> usize {
    let seeds = choose(mesh, ns, bvh, bad);
    let n = seeds.len();
    // A cone may have fewer tets than its cavity: the slots left over go at the end.
    let mut dead: Vec<u32> = Vec::new();
    for (x, cavity) in seeds {
        cavity::cone_in(mesh, x, &cavity, &mut dead);
    }
    cavity::drop_dead(mesh, &dead);
    n
}

/// A seed: its point and its cavity's tets (sorted).
type Seed = (P3, Vec<u32>);

/// The tets of surface points below [`SEED_BELOW_DEG`], in order.
fn poor_surface_tets(mesh: &TetMesh, ns: usize) -> Vec<u32> {
    let on_surface = |t: u32| mesh.tets[t as usize].iter().all(|&x| (x as usize) < ns);
    let corners = |t: u32| mesh.tets[t as usize].map(|x| mesh.points[x as usize]);
    (0..mesh.tets.len() as u32)
        .into_par_iter()
        .filter(|&t| on_surface(t) && min_dihedral_deg_by_chord(&corners(t)) < SEED_BELOW_DEG)
        .collect()
}

/// The seeds of the module docs, in the order of the poor tets `bad` that gave them: each not in
/// an earlier seed's cavity tries its candidates in turn, the first that passes its seed.
fn choose(mesh: &TetMesh, ns: usize, bvh: &Bvh, bad: Vec<u32>) -> Vec<Seed> {
    let on_surface = |t: u32| mesh.tets[t as usize].iter().all(|&x| (x as usize) < ns);
    let mut claimed = vec![false; mesh.tets.len()];
    let mut seeds: Vec<Seed> = Vec::new();
    for t in bad {
        if claimed[t as usize] {
            continue;
        }
        // Its own circumcentre, then its surface-only neighbours' (a flat tet on a planar quad
        // has none of its own).
        let tries = std::iter::once(t).chain(
            mesh.neighbors[t as usize]
                .into_iter()
                .filter(|&n| n != NO_NEIGHBOR && on_surface(n)),
        );
        if let Some(seed) = tries
            .into_iter()
            .find_map(|u| candidate(mesh, bvh, u, &claimed))
        {
            for &x in &seed.1 {
                claimed[x as usize] = true;
            }
            seeds.push(seed);
        }
    }
    seeds
}

/// The seed at the circumcentre of tet `u`, if it passes every test of the module docs with
/// the tets `claimed` by earlier seeds left alone.
fn candidate(mesh: &TetMesh, bvh: &Bvh, u: u32, claimed: &[bool]) -> Option<Seed> {
    let c = mesh.tets[u as usize].map(|x| mesh.points[x as usize]);
    let o = circumcentre(&c)?;
    let clear2 = SEED_CLEARANCE * SEED_CLEARANCE * norm2(sub(c[0], o));
    let s = locate(mesh, u, o)?;
    let near_point = std::iter::once(s)
        .chain(mesh.neighbors[s as usize])
        .filter(|&n| n != NO_NEIGHBOR)
        .flat_map(|n| mesh.tets[n as usize])
        .any(|x| norm2(sub(mesh.points[x as usize], o)) < clear2);
    if near_point || bvh.any_within(o, clear2) {
        return None;
    }
    Some((o, cone(mesh, s, o, claimed)?))
}

/// The cavity of `x` from `s` (the tets of `s`'s region whose circumspheres hold `x`, reached
/// through faces; at most [`MAX_CAVITY`]), with the poor tets beside it or else alone, sorted,
/// when [`cone_ok`] passes it and no tet of it is `claimed` by an earlier seed.
fn cone(mesh: &TetMesh, s: u32, x: P3, claimed: &[bool]) -> Option<Vec<u32>> {
    let label = mesh.labels[s as usize];
    let corners = |t: u32| mesh.tets[t as usize].map(|v| mesh.points[v as usize]);
    let same = |n: u32| mesh.labels[n as usize] == label;
    let cavity = cavity::circumsphere_cavity(s, x, MAX_CAVITY, &mesh.neighbors, corners, same)?;
    // Another seed's cavity: two cones never share a tet.
    if cavity.iter().any(|&t| claimed[t as usize]) {
        return None;
    }
    // The poor tets beside it first: a flat tet on a planar quad of the wall has no
    // circumsphere to hold x, and a cone that leaves it is no better than the good tets it
    // replaces (the triangular ring tube's segments).
    let grown = with_poor_neighbours(mesh, &cavity, |n| same(n) && !claimed[n as usize]);
    if grown.len() > cavity.len() && grown.len() <= MAX_CAVITY && cone_ok(mesh, &grown, x) {
        return Some(grown);
    }
    cone_ok(mesh, &cavity, x).then_some(cavity)
}

/// `cavity` and, repeatedly, the tets beside it that `admit` lets in and whose smallest
/// dihedral angle is below [`SEED_BELOW_DEG`]; sorted.
fn with_poor_neighbours(mesh: &TetMesh, cavity: &[u32], admit: impl Fn(u32) -> bool) -> Vec<u32> {
    let corners = |t: u32| mesh.tets[t as usize].map(|v| mesh.points[v as usize]);
    let mut out = cavity.to_vec();
    let mut i = 0;
    while i < out.len() && out.len() <= MAX_CAVITY {
        let t = out[i];
        i += 1;
        for n in mesh.neighbors[t as usize] {
            if n != NO_NEIGHBOR
                && !out.contains(&n)
                && admit(n)
                && min_dihedral_deg_by_chord(&corners(n)) < SEED_BELOW_DEG
            {
                out.push(n);
            }
        }
    }
    out.sort_unstable();
    out
}

/// Whether coning `cavity`'s shell to `x` is valid ([`cavity::cone_valid`]) and better (the cone's worst dihedral angle
/// above [`SEED_BELOW_DEG`], or half of it for a cavity holding a flat tet, and above the
/// cavity's worst).
fn cone_ok(mesh: &TetMesh, cavity: &[u32], x: P3) -> bool {
    let corners = |t: u32| mesh.tets[t as usize].map(|v| mesh.points[v as usize]);
    let inside = |t: u32| cavity.binary_search(&t).is_ok();
    let (faces, _) = cavity::shell(cavity, &mesh.tets, &mesh.neighbors, inside);
    let old = cavity
        .iter()
        .map(|&t| min_dihedral_deg_by_chord(&corners(t)))
        .fold(180.0, f64::min);
    // A flat tet (a cap on a planar quad of a thin fin, volume 1e-19) goes for a cone
    // above half the floor: a revolved zigzag's fins had cones at 5°–9.8° refused and kept 0°
    // tets, which a solver cannot use.
    let floor = if old < FLAT_DEG {
        0.5 * SEED_BELOW_DEG
    } else {
        SEED_BELOW_DEG
    };
    // The cone's tets, the first one below the floor ending the test (most candidates end so).
    let mut new = 180.0f64;
    for f in &faces {
        let w = [f[0], f[1], f[2]].map(|v| mesh.points[v as usize]);
        new = new.min(min_dihedral_deg_by_chord(&[w[0], w[1], w[2], x]));
        if new < floor {
            return false;
        }
    }
    new > old && cavity::cone_valid(mesh, cavity, &faces, x)
}

/// The tet of `t`'s region holding `x` strictly inside ([`cavity::walk`]); `None` if the walk
/// would leave the region, lands on a face or stalls.
fn locate(mesh: &TetMesh, t: u32, x: P3) -> Option<u32> {
    cavity::walk(mesh, t, x, WALK_STEPS).and_then(|(s, inside)| inside.then_some(s))
}

/// A second pass over the poor tets `left` by the first, after the flips of
/// [`flip_towards_delaunay`] from them that give a seed its cavity; how many seeds.
///
/// Recovery can leave tets that span several segments of a tube (a twisted prism's, whose six
/// corners are cospherical), with circumcentres outside it or too large for the clearance: the
/// segments between get no seed. The flips are tried and undone ([`Undo`]), and only the groups
/// of flips (sharing tets) that a seed's cavity there takes are made again: elsewhere a flip
/// trades one poor tet for another, and the stages after fared worse with them.
fn flip_and_seed(mesh: &mut TetMesh, ns: usize, bvh: &Bvh, left: &[u32]) -> usize {
    // The trial flips are made on `mesh` itself and undone before the replay: the slots they
    // touched are saved first (a copy of the mesh was a third of the stage's peak memory on
    // brain_20k at --size 1).
    let mut undo = Undo::new(mesh);
    let (flips, alive) = flip_towards_delaunay(mesh, ns, left, &mut undo);
    if flips.is_empty() {
        undo.restore(mesh);
        return 0;
    }
    let trial = &*mesh;
    // Flips sharing a tet form a group; the group's last flip in a slot owns it.
    let mut groups = Dsu::new(flips.len());
    let mut owner = vec![u32::MAX; trial.tets.len()];
    for (f, flip) in flips.iter().enumerate() {
        for &s in &flip.old {
            if owner[s as usize] != u32::MAX {
                groups.union(f as u32, owner[s as usize]);
            }
        }
        for &s in &flip.ids {
            owner[s as usize] = f as u32;
        }
    }
    // Only the poor tets the flips made: the others had their chance in the first pass.
    let bad = poor_surface_tets(trial, ns)
        .into_iter()
        .filter(|&t| alive[t as usize] && owner[t as usize] != u32::MAX)
        .collect();
    let seeds = choose(trial, ns, bvh, bad);
    let mut used = vec![false; flips.len()];
    for &t in seeds.iter().flat_map(|s| &s.1) {
        if owner[t as usize] != u32::MAX {
            used[groups.find(owner[t as usize]) as usize] = true;
        }
    }
    let mut slot: Vec<u32> = (0..trial.tets.len() as u32).collect();
    undo.restore(mesh);
    // The used groups' flips again, in order, on the restored mesh (its slots mapped from the
    // trial's).
    let mut dead = Vec::new();
    let mut made = FxHashSet::default();
    for (f, flip) in flips.iter().enumerate() {
        if !used[groups.find(f as u32) as usize] {
            continue;
        }
        made.extend(flip.made.iter().map(|&t| sorted(t)));
        let old = flip.old.iter().map(|&s| slot[s as usize]).collect();
        let (old, ids) = replace(mesh, old, &flip.made, None);
        for (&t, &r) in flip.ids.iter().zip(&ids) {
            slot[t as usize] = r;
        }
        dead.extend(old.into_iter().filter(|s| !ids.contains(s)));
    }
    if made.is_empty() {
        return 0;
    }
    cavity::drop_dead(mesh, &dead);
    let bad = poor_surface_tets(mesh, ns)
        .into_iter()
        .filter(|&t| made.contains(&sorted(mesh.tets[t as usize])))
        .collect();
    seed_pass(mesh, ns, bvh, bad)
}

fn sorted(mut t: [u32; 4]) -> [u32; 4] {
    t.sort_unstable();
    t
}

/// A flip: the slots of its old tets (sorted), its new tets and their slots.
struct Flip {
    old: Vec<u32>,
    made: Vec<[u32; 4]>,
    ids: Vec<u32>,
}

/// Lawson flips (2-3 and 3-2, exact `insphere`/`orient3d`) of the faces between two tets of
/// surface points of one label, one of them below [`SEED_BELOW_DEG`], whose circumsphere
/// strictly holds the other's far corner; from the tets `start`, then the new ones (sequential).
/// The flips in order, and which slots hold a tet (the others are left for [`cavity::drop_dead`]).
/// Adjacency is kept.
fn flip_towards_delaunay(
    mesh: &mut TetMesh,
    ns: usize,
    start: &[u32],
    undo: &mut Undo,
) -> (Vec<Flip>, Vec<bool>) {
    let mut alive = vec![true; mesh.tets.len()];
    let mut stack: Vec<u32> = start.iter().rev().copied().collect();
    let mut flips = Vec::new();
    while let Some(t) = stack.pop() {
        if !alive[t as usize] {
            continue;
        }
        if let Some(flip) = (0..4).find_map(|i| flip_face(mesh, ns, t, i, undo)) {
            alive.resize(mesh.tets.len(), true);
            for &s in &flip.old {
                if !flip.ids.contains(&s) {
                    alive[s as usize] = false;
                }
            }
            stack.extend(flip.ids.iter().rev());
            flips.push(flip);
        }
    }
    (flips, alive)
}

/// Flip the face of `t` opposite its corner `i` when the rule of [`flip_towards_delaunay`] asks
/// for it and a 2-3 or 3-2 flip is valid.
fn flip_face(mesh: &mut TetMesh, ns: usize, t: u32, i: usize, undo: &mut Undo) -> Option<Flip> {
    let n = mesh.neighbors[t as usize][i];
    if n == NO_NEIGHBOR || mesh.labels[n as usize] != mesh.labels[t as usize] {
        return None;
    }
    let tv = mesh.tets[t as usize];
    let nv = mesh.tets[n as usize];
    let surface_only = |v: &[u32; 4]| v.iter().all(|&x| (x as usize) < ns);
    if !surface_only(&tv) || !surface_only(&nv) {
        return None;
    }
    let p = |v: u32| mesh.points[v as usize];
    let poor = |v: &[u32; 4]| min_dihedral_deg_by_chord(&v.map(p)) < SEED_BELOW_DEG;
    if !poor(&tv) && !poor(&nv) {
        return None;
    }
    let d = tv[i];
    let e = *nv.iter().find(|v| !tv.contains(v))?;
    if insphere(p(tv[0]), p(tv[1]), p(tv[2]), p(tv[3]), p(e)) != Sign::Positive {
        return None;
    }
    let f = TET_FACES[i].map(|k| tv[k]);
    // 2-3: the edge de crosses the face inside, the three tets around it all positive.
    let ring = [[f[0], f[1]], [f[1], f[2]], [f[2], f[0]]];
    let signs = ring.map(|[x, y]| orient3d(p(d), p(e), p(x), p(y)));
    if signs.iter().all(|&s| s == signs[0]) && signs[0] != Sign::Zero {
        let made: Vec<[u32; 4]> = ring
            .iter()
            .map(|&[x, y]| {
                if signs[0] == Sign::Positive {
                    [d, e, x, y]
                } else {
                    [d, e, y, x]
                }
            })
            .collect();
        let (old, ids) = replace(mesh, vec![t, n], &made, Some(undo));
        return Some(Flip { old, made, ids });
    }
    // 3-2: an edge xy of the face has just these two tets and one more, {x, y, d, e}, around it
    // and crosses the triangle dez inside.
    for k in 0..3 {
        let (x, y, z) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
        let across = |s: u32, sv: [u32; 4]| {
            let j = sv.iter().position(|&v| v == z).unwrap();
            mesh.neighbors[s as usize][j]
        };
        let m = across(t, tv);
        if m == NO_NEIGHBOR
            || m != across(n, nv)
            || mesh.labels[m as usize] != mesh.labels[t as usize]
        {
            continue;
        }
        let sx = orient3d(p(d), p(e), p(z), p(x));
        let sy = orient3d(p(d), p(e), p(z), p(y));
        if sx == Sign::Zero || sy == Sign::Zero || sx == sy {
            continue;
        }
        let orient = |w: u32, s: Sign| {
            if s == Sign::Positive {
                [d, e, z, w]
            } else {
                [e, d, z, w]
            }
        };
        let made = vec![orient(x, sx), orient(y, sy)];
        let (old, ids) = replace(mesh, vec![t, n, m], &made, Some(undo));
        return Some(Flip { old, made, ids });
    }
    None
}

/// Replace the tets `old` by `made` (filling the same space), adjacency kept: the old slots in
/// order, then new ones; returns the old tets and the slots of the new. With `undo`, the slots
/// it changes are saved there first.
fn replace(
    mesh: &mut TetMesh,
    mut old: Vec<u32>,
    made: &[[u32; 4]],
    undo: Option<&mut Undo>,
) -> (Vec<u32>, Vec<u32>) {
    old.sort_unstable();
    let inside = |s: u32| old.binary_search(&s).is_ok();
    let (faces, outer) = cavity::shell(&old, &mesh.tets, &mesh.neighbors, inside);
    if let Some(undo) = undo {
        // The cavity's slots are refilled, and the stitch rewrites the outer tets' adjacency.
        for &s in old.iter().chain(outer.iter().map(|(n, _)| n)) {
            undo.save(mesh, s);
        }
    }
    let ids = cavity::fill_slots(mesh, &old, made, &faces, &outer);
    (old, ids)
}

/// What trial changes to a mesh overwrote: the tets and adjacency of the slots that existed
/// before them, each as it was when first changed, and how many tets there were. New slots are
/// dropped on restoring; labels and points are never changed by [`replace`].
struct Undo {
    tets: usize,
    saved: FxHashMap<u32, ([u32; 4], [u32; 4])>,
}

impl Undo {
    fn new(mesh: &TetMesh) -> Undo {
        Undo {
            tets: mesh.tets.len(),
            saved: FxHashMap::default(),
        }
    }

    /// Save slot `s` unless it is new or already saved.
    fn save(&mut self, mesh: &TetMesh, s: u32) {
        if s != NO_NEIGHBOR && (s as usize) < self.tets {
            self.saved
                .entry(s)
                .or_insert_with(|| (mesh.tets[s as usize], mesh.neighbors[s as usize]));
        }
    }

    /// Put `mesh` back as it was when this was made.
    fn restore(self, mesh: &mut TetMesh) {
        for (s, (t, n)) in self.saved {
            mesh.tets[s as usize] = t;
            mesh.neighbors[s as usize] = n;
        }
        mesh.tets.truncate(self.tets);
        mesh.neighbors.truncate(self.tets);
        mesh.labels.truncate(self.tets);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::{PipelineOptions, mesh_surface};
    use crate::sizing::{SizeSpec, Sizing, SizingOptions};

    /// trimesh's ring tube of triangular section (`torus(1, 0.01, 200, 3)`) from the shape
    /// corpus (an OFF file of triangles).
    fn triangular_ring() -> SurfaceMesh {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tests/data/shapes/tm_tri_torus.off"
        );
        let text = std::fs::read_to_string(path).expect("shape corpus");
        let mut words = text.split_whitespace().skip(1);
        let mut next = || words.next().expect("OFF");
        let nv: usize = next().parse().unwrap();
        let nf: usize = next().parse().unwrap();
        next();
        let points = (0..nv)
            .map(|_| [0; 3].map(|_| next().parse::<f64>().unwrap()))
            .collect();
        let triangles = (0..nf)
            .map(|_| {
                assert_eq!(next(), "3");
                [0; 3].map(|_| next().parse::<u32>().unwrap())
            })
            .collect();
        SurfaceMesh::closed(points, triangles, 1)
    }

    /// The second pass's trial flips, undone from their log, leave the mesh as it was to the bit
    /// (tets, adjacency, labels, and no slot left over), on the ring tube whose recovered tets
    /// span segments (where the flips happen).
    #[test]
    fn trial_flips_are_undone_to_the_bit() {
        let s = triangular_ring();
        let sizing = Sizing::new(
            &s,
            SizingOptions::new(SizeSpec::FromSurface { grading: 0.3 }),
        )
        .unwrap();
        let opts = PipelineOptions {
            seeds: false,
            improve: None,
            smooth: None,
            polish: None,
            ..PipelineOptions::default()
        };
        let (mut mesh, report) = mesh_surface(&s, &sizing, &opts, &mut |_| {}).unwrap();
        let ns = report.n_surface_points;
        let bvh = Bvh::of_surface(&s);
        let bad = poor_surface_tets(&mesh, ns);
        seed_pass(&mut mesh, ns, &bvh, bad);
        let left = poor_surface_tets(&mesh, ns);
        let before = mesh.clone();
        let mut undo = Undo::new(&mesh);
        let (flips, _) = flip_towards_delaunay(&mut mesh, ns, &left, &mut undo);
        assert!(!flips.is_empty(), "no trial flip on the ring tube");
        assert!(
            flips.iter().any(|f| f.ids.len() > f.old.len()),
            "no 2-3 flip"
        );
        assert_ne!(mesh, before);
        undo.restore(&mut mesh);
        assert_eq!(mesh, before);
    }
}
