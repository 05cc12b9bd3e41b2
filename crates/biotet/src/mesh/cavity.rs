//! Carving and refilling a cavity in a tet mesh with adjacency: its shell, and the stitching of
//! the tets that replace it. Shared by sliver removal and polishing, which keep tombstoned slots
//! of their own.

use rustc_hash::FxHashMap;

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
