//! Carving and refilling a cavity in a tet mesh with adjacency: its shell, and the stitching of
//! the tets that replace it. Shared by sliver removal and polishing, which keep tombstoned slots
//! of their own.

use rustc_hash::{FxHashMap, FxHashSet};

use crate::geom::vec3::{norm2, sub};
use crate::quality::tet::circumcentre;

use super::tet::{NO_NEIGHBOR, TET_FACES};

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
