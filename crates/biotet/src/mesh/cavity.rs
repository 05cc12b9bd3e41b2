//! Carving and refilling a cavity in a tet mesh with adjacency: its shell, and the stitching of
//! the tets that replace it. Shared by sliver removal and polishing, which keep tombstoned slots
//! of their own.

use rustc_hash::{FxHashMap, FxHashSet};

use crate::geom::predicates::{Sign, orient3d};
use crate::geom::vec3::{norm2, sub};
use crate::quality::tet::circumcentre;

use super::tet::{NO_NEIGHBOR, TET_FACES, TetMesh, retain_tets};

/// The shell of the tets `cavity` (`inside(t)`: `t` is one of them): each face with no cavity
/// tet across, turned to point into the cavity, with the tet across it and that tet's local face
/// (`(NO_NEIGHBOR, 0)` on the mesh boundary).
pub fn shell(
    cavity: &[u32],
    tets: &[[u32; 4]],
    nb: &[[u32; 4]],
    inside: impl Fn(u32) -> bool,
) -> (Vec<[u32; 3]>, Vec<(u32, u8)>) {
    let mut faces = Vec::new();
    let mut outer = Vec::new();
    for &t in cavity {
        let v = tets[t as usize];
        for (i, l) in TET_FACES.iter().enumerate() {
            let n = nb[t as usize][i];
            if n != NO_NEIGHBOR && inside(n) {
                continue;
            }
            // Outward face reversed: the normal points into the cavity.
            faces.push([v[l[0]], v[l[2]], v[l[1]]]);
            let j = if n == NO_NEIGHBOR {
                0
            } else {
                nb[n as usize].iter().position(|&x| x == t).unwrap_or(0) as u8
            };
            outer.push((n, j));
        }
    }
    (faces, outer)
}

/// Stitch the adjacency of the new tets `ids` (which fill the cavity of `shell`/`outer`, as
/// [`shell`] gives them) among themselves and to the tets outside.
pub fn stitch(
    tets: &[[u32; 4]],
    nb: &mut [[u32; 4]],
    ids: &[u32],
    shell: &[[u32; 3]],
    outer: &[(u32, u8)],
) {
    let key = |mut k: [u32; 3]| {
        k.sort_unstable();
        k
    };
    let outside: FxHashMap<[u32; 3], (u32, u8)> = shell
        .iter()
        .zip(outer)
        .map(|(f, &o)| (key(*f), o))
        .collect();
    let mut open: FxHashMap<[u32; 3], (u32, u8)> = Default::default();
    for &t in ids {
        let tv = tets[t as usize];
        for (i, l) in TET_FACES.iter().enumerate() {
            let k = key([tv[l[0]], tv[l[1]], tv[l[2]]]);
            if let Some(&(n, j)) = outside.get(&k) {
                nb[t as usize][i] = n;
                if n != NO_NEIGHBOR {
                    nb[n as usize][j as usize] = t;
                }
            } else if let Some((u, j)) = open.remove(&k) {
                nb[t as usize][i] = u;
                nb[u as usize][j as usize] = t;
            } else {
                open.insert(k, (t, i as u8));
            }
        }
    }
    debug_assert!(open.is_empty(), "the new tets do not fill the cavity");
}

/// `start` and the tets whose circumspheres strictly hold `x` and that `admit` (asked only of
/// those), reached from it through faces (never across [`NO_NEIGHBOR`]), sorted: Delaunay
/// refinement's cavity for a point at `x`. `None` past `max` tets. Floating point: it chooses a cavity, whose use the
/// caller decides exactly.
pub fn circumsphere_cavity(
    start: u32,
    x: [f64; 3],
    max: usize,
    nb: &[[u32; 4]],
    corners: impl Fn(u32) -> [[f64; 3]; 4],
    admit: impl Fn(u32) -> bool,
) -> Option<Vec<u32>> {
    let mut out = vec![start];
    let mut seen: FxHashSet<u32> = FxHashSet::default();
    seen.insert(start);
    let mut i = 0;
    while i < out.len() {
        let s = out[i];
        i += 1;
        for n in nb[s as usize] {
            if n == NO_NEIGHBOR || !seen.insert(n) {
                continue;
            }
            let c = corners(n);
            if circumcentre(&c).is_some_and(|o| norm2(sub(x, o)) < norm2(sub(c[0], o))) && admit(n)
            {
                out.push(n);
                if out.len() > max {
                    return None;
                }
            }
        }
    }
    out.sort_unstable();
    Some(out)
}

/// Whether coning the tets `cavity` (sorted; `faces` their [`shell`]) to `x` makes a
/// triangulation of it: every cone tet strictly positive (exact), the shell a sphere (a shell
/// wrapped twice around `x` passes the first test too), and every cavity point on it.
pub fn cone_valid(mesh: &TetMesh, cavity: &[u32], faces: &[[u32; 3]], x: [f64; 3]) -> bool {
    let positive = faces.iter().all(|f| {
        let w = f.map(|v| mesh.points[v as usize]);
        orient3d(w[0], w[1], w[2], x) == Sign::Positive
    });
    if !positive {
        return false;
    }
    // A sphere: every edge on two faces, and V - E + F = 2 (the shell is embedded and closed,
    // so connected).
    let mut edges: Vec<[u32; 2]> = faces
        .iter()
        .flat_map(|f| [(f[0], f[1]), (f[1], f[2]), (f[0], f[2])])
        .map(|(a, b)| [a.min(b), a.max(b)])
        .collect();
    edges.sort_unstable();
    let manifold = edges.chunks(2).all(|e| e.len() == 2 && e[0] == e[1])
        && edges.windows(3).all(|w| !(w[0] == w[1] && w[1] == w[2]));
    let mut on_shell: Vec<u32> = faces.iter().flatten().copied().collect();
    on_shell.sort_unstable();
    on_shell.dedup();
    let sphere = manifold && on_shell.len() + faces.len() == edges.len() / 2 + 2;
    sphere
        && cavity
            .iter()
            .flat_map(|&t| mesh.tets[t as usize])
            .all(|v| on_shell.binary_search(&v).is_ok())
}

/// Add point `x` and replace the tets `cavity` (sorted) by the cone of their shell to it,
/// adjacency kept: the cone's tets take the cavity's slots in order, then new ones; slots left
/// over are added to `dead` (for [`super::tet::retain_tets`]). The caller has checked the cone
/// ([`cone_valid`]).
pub fn cone_in(mesh: &mut TetMesh, x: [f64; 3], cavity: &[u32], dead: &mut Vec<u32>) {
    let p = mesh.points.len() as u32;
    mesh.points.push(x);
    let inside = |t: u32| cavity.binary_search(&t).is_ok();
    let (faces, outer) = shell(cavity, &mesh.tets, &mesh.neighbors, inside);
    // The shell's faces point into the cavity, at x.
    let cone: Vec<[u32; 4]> = faces.iter().map(|f| [f[0], f[1], f[2], p]).collect();
    fill_slots(mesh, cavity, &cone, &faces, &outer);
    dead.extend(cavity.iter().skip(faces.len()));
}

/// Put `made` (filling the space of the tets `cavity`, sorted, whose shell is `faces` with the
/// faces `outer` across, as [`shell`] gives them) into the mesh, adjacency kept: the cavity's slots in order, then new
/// ones; returns the slots of `made`. Slots left over keep their old tets (the caller drops them).
pub fn fill_slots(
    mesh: &mut TetMesh,
    cavity: &[u32],
    made: &[[u32; 4]],
    faces: &[[u32; 3]],
    outer: &[(u32, u8)],
) -> Vec<u32> {
    let label = mesh.labels[cavity[0] as usize];
    let mut ids = Vec::with_capacity(made.len());
    for (j, &tet) in made.iter().enumerate() {
        match cavity.get(j) {
            Some(&s) => {
                mesh.tets[s as usize] = tet;
                ids.push(s);
            }
            None => {
                ids.push(mesh.tets.len() as u32);
                mesh.tets.push(tet);
                mesh.labels.push(label);
                mesh.neighbors.push([NO_NEIGHBOR; 4]);
            }
        }
    }
    stitch(&mesh.tets, &mut mesh.neighbors, &ids, faces, outer);
    ids
}

/// Where `x` lies against tet `t`: `Ok(true)` strictly inside, `Ok(false)` on its boundary,
/// `Err(k)` strictly beyond the face opposite corner `k` (exact).
pub fn where_in(mesh: &TetMesh, t: u32, x: [f64; 3]) -> Result<bool, usize> {
    let v = mesh.tets[t as usize].map(|i| mesh.points[i as usize]);
    let mut on_face = false;
    for k in 0..4 {
        // x in place of corner k: negative when x lies beyond the face opposite it.
        let mut w = v;
        w[k] = x;
        match orient3d(w[0], w[1], w[2], w[3]) {
            Sign::Negative => return Err(k),
            Sign::Zero => on_face = true,
            Sign::Positive => {}
        }
    }
    Ok(!on_face)
}

/// The tet of `start`'s region holding `x` and whether strictly inside ([`where_in`]), walking
/// from `start` through faces `x` lies strictly beyond; `None` if the walk would leave the
/// region or takes more than `steps`.
pub fn walk(mesh: &TetMesh, start: u32, x: [f64; 3], steps: usize) -> Option<(u32, bool)> {
    let label = mesh.labels[start as usize];
    let mut s = start;
    for _ in 0..steps {
        match where_in(mesh, s, x) {
            Ok(inside) => return Some((s, inside)),
            Err(k) => {
                let n = mesh.neighbors[s as usize][k];
                if n == NO_NEIGHBOR || mesh.labels[n as usize] != label {
                    return None;
                }
                s = n;
            }
        }
    }
    None
}

/// Drop the tets `dead` (the slots [`cone_in`] left over), adjacency kept.
pub fn drop_dead(mesh: &mut TetMesh, dead: &[u32]) {
    if dead.is_empty() {
        return;
    }
    let mut keep = vec![true; mesh.tets.len()];
    for &t in dead {
        keep[t as usize] = false;
    }
    let TetMesh {
        tets,
        neighbors,
        labels,
        ..
    } = mesh;
    retain_tets(tets, neighbors, labels, &keep);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::delaunay::Delaunay;

    /// Carving the star of a point and putting the same tets back under new ids: the shell and
    /// the stitch give back exactly the adjacency a full rebuild gives.
    #[test]
    fn stitch_restores_the_adjacency_of_a_refilled_star() {
        let mut pts = Vec::new();
        let mut s = 7u64;
        for _ in 0..300 {
            let mut c = [0.0; 3];
            for x in &mut c {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                *x = (s >> 11) as f64 / (1u64 << 53) as f64;
            }
            pts.push(c);
        }
        let mesh = Delaunay::new(&pts).unwrap().to_tet_mesh();
        let (mut tets, mut nb) = (mesh.tets.clone(), mesh.neighbors.clone());
        // The star of the first corner of tet 0.
        let v = tets[0][0];
        let star: Vec<u32> = (0..tets.len() as u32)
            .filter(|&t| tets[t as usize].contains(&v))
            .collect();
        assert!(star.len() > 4);
        let (shell_faces, outer) = shell(&star, &tets, &nb, |t| star.contains(&t));
        assert!(outer.iter().any(|&(n, _)| n != NO_NEIGHBOR));
        // The same tets back at the end of the arrays, the old slots dead.
        let ids: Vec<u32> = star
            .iter()
            .map(|&t| {
                tets.push(tets[t as usize]);
                nb.push([NO_NEIGHBOR; 4]);
                (tets.len() - 1) as u32
            })
            .collect();
        stitch(&tets, &mut nb, &ids, &shell_faces, &outer);
        let live: Vec<u32> = (0..tets.len() as u32)
            .filter(|t| !star.contains(t))
            .collect();
        let mut index = vec![NO_NEIGHBOR; tets.len()];
        for (k, &t) in live.iter().enumerate() {
            index[t as usize] = k as u32;
        }
        let kept: Vec<[u32; 4]> = live.iter().map(|&t| tets[t as usize]).collect();
        let got: Vec<[u32; 4]> = live
            .iter()
            .map(|&t| {
                nb[t as usize].map(|n| {
                    if n == NO_NEIGHBOR {
                        n
                    } else {
                        index[n as usize]
                    }
                })
            })
            .collect();
        let (want, _) = crate::mesh::tet::face_adjacency(&kept);
        assert_eq!(got, want);
    }
}
