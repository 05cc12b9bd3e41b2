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
//! [`SEED_BELOW_DEG`] (half of it where the cavity holds a flat tet, under [`FLAT_DEG`]) and above
//! the cavity's worst. Cavities of two seeds never share a tet; every accepted cone replaces its
//! cavity at once. Boundary and interface faces are never crossed, so they stay faces.
//!
//! The choice of points is floating point, as node placement is; every tet made is checked
//! positive exactly. Sequential, in tet order: the same mesh on any number of threads.

use rayon::prelude::*;

use crate::geom::vec3::{norm2, sub};
use crate::mesh::cavity;
use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::{NO_NEIGHBOR, TetMesh};
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
    let seeds = choose(mesh, ns, surface);
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

/// The seeds of the module docs, in the order of the tets that gave them: each poor tet not in
/// an earlier seed's cavity tries its candidates in turn, the first that passes its seed.
fn choose(mesh: &TetMesh, ns: usize, surface: &SurfaceMesh) -> Vec<Seed> {
    let on_surface = |t: u32| mesh.tets[t as usize].iter().all(|&x| (x as usize) < ns);
    let corners = |t: u32| mesh.tets[t as usize].map(|x| mesh.points[x as usize]);
    let bad: Vec<u32> = (0..mesh.tets.len() as u32)
        .into_par_iter()
        .filter(|&t| on_surface(t) && min_dihedral_deg_by_chord(&corners(t)) < SEED_BELOW_DEG)
        .collect();
    if bad.is_empty() {
        return Vec::new();
    }
    let bvh = Bvh::of_surface(surface);
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
            .find_map(|u| candidate(mesh, &bvh, u, &claimed))
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
