//! The mesh types shared by every stage: [`surface::SurfaceMesh`] (input boundaries and
//! interfaces), [`tet::TetMesh`] (volume meshes) and [`tri::TriMesh`] (2D meshes), plus surface
//! validation ([`validate`]).
//!
//! All three are flat arrays with `u32` indices, cheap to hand to numpy, VTK or a solver.

pub mod cavity;
pub(crate) mod dsu;
pub mod inside;
pub mod pslg;
pub mod shells;
pub mod side_labels;
pub mod surface;
pub mod tet;
pub mod tri;
pub mod validate;

/// Drop the points from index `from` on that no entry of `corners` names (the element
/// corners of a mesh, flattened), keeping the others' order, and renumber `corners`; returns how
/// many went. One pass to mark, one to move, one to renumber (skipped when nothing went): it runs
/// on whole meshes, in place.
pub fn drop_unused_points(points: &mut Vec<[f64; 3]>, corners: &mut [u32], from: usize) -> usize {
    let n = points.len();
    if from >= n {
        return 0;
    }
    // New indices of the points from `from` on (u32::MAX for the unused).
    let mut new_index = vec![u32::MAX; n - from];
    for &v in corners.iter() {
        if let Some(x) = (v as usize).checked_sub(from) {
            new_index[x] = 0;
        }
    }
    let mut k = from;
    for i in from..n {
        if new_index[i - from] != u32::MAX {
            new_index[i - from] = k as u32;
            points[k] = points[i];
            k += 1;
        }
    }
    if k == n {
        return 0;
    }
    points.truncate(k);
    for v in corners.iter_mut() {
        if let Some(x) = (*v as usize).checked_sub(from) {
            *v = new_index[x];
        }
    }
    n - k
}

/// The exact identity of a point's coordinates, for matching points across meshes (`-0.0` and
/// `0.0` are the same point).
#[inline]
pub fn coord_key(p: &[f64; 3]) -> [u64; 3] {
    p.map(|c| if c == 0.0 { 0 } else { c.to_bits() })
}

/// For each of `points`, the index of the point of `targets` with the same coordinates
/// ([`coord_key`]), `u32::MAX` for none; of repeated targets, the last. A sorted index (4 bytes
/// per target) rather than a hash map of keys: a fraction of the memory, for a report that runs
/// while the whole mesh is held.
pub fn match_points(points: &[[f64; 3]], targets: &[[f64; 3]]) -> Vec<u32> {
    let key = |i: u32| coord_key(&targets[i as usize]);
    let mut order: Vec<u32> = (0..targets.len() as u32).collect();
    order.sort_unstable_by(|&a, &b| key(a).cmp(&key(b)).then(a.cmp(&b)));
    points
        .iter()
        .map(|p| {
            let k = coord_key(p);
            // The last target whose key is at most k: the last of the equal ones, if any.
            match order.partition_point(|&i| key(i) <= k) {
                0 => u32::MAX,
                n if key(order[n - 1]) == k => order[n - 1],
                _ => u32::MAX,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn match_points_finds_the_last_equal_target() {
        let targets = [
            [1.0, 2.0, 3.0],
            [0.0, 0.0, 0.0],
            [1.0, 2.0, 3.0],
            [5.0, 5.0, 5.0],
        ];
        let points = [
            [-0.0, 0.0, 0.0],
            [1.0, 2.0, 3.0],
            [4.0, 4.0, 4.0],
            [5.0, 5.0, 5.0],
        ];
        assert_eq!(match_points(&points, &targets), [1, 2, u32::MAX, 3]);
        assert_eq!(match_points(&points, &[]), [u32::MAX; 4]);
    }
}
