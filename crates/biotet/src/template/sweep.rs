//! The inward sweep (section 2.3.1, eq. 2.8): a breadth-first front over the inside voxels,
//! starting at the boundary buffer. Each unprocessed voxel the front reaches becomes an interior
//! node and claims its buffer zone. All distances are in voxels, integers only.
//!
//! The front is a ring buffer, so besides the template it holds only the current layer (a
//! surface's worth of voxels, not a volume's).

use std::collections::VecDeque;

use super::voxels::{INTERIOR_NODE, QUEUED, Template, UNPROCESSED, Zone};

/// Run the sweep; `radius(point, region)` gives the zone radius in voxels at a voxel centre.
/// Returns the number of interior nodes placed.
pub fn sweep(t: &mut Template, zone: Zone, radius: &dyn Fn([f64; 3], u32) -> usize) -> usize {
    let [nx, ny, nz] = t.n;
    let mut front: VecDeque<u32> = VecDeque::new();
    // Whether an inside voxel lies on the grid's border (only with a zero margin): else every
    // inside voxel has all six neighbours, found by index steps without its (i, j, k).
    let mut on_border = false;
    // Seeds: inside voxels already claimed by the boundary buffer, or touching the outside.
    for k in 0..nz {
        for j in 0..ny {
            let row = t.index(0, j, k);
            for i in 0..nx {
                let idx = row + i;
                if t.region(idx) == 0 {
                    continue;
                }
                on_border |=
                    i == 0 || j == 0 || k == 0 || i + 1 == nx || j + 1 == ny || k + 1 == nz;
                let seed = t.state(idx) != UNPROCESSED
                    || neighbours(t, i, j, k, idx).any(|m| t.region(m) == 0);
                if seed {
                    t.cells[idx] |= QUEUED;
                    front.push_back(idx as u32);
                }
            }
        }
    }
    let mut placed = 0;
    let (sy, sz) = (nx, nx * ny);
    while let Some(idx) = front.pop_front() {
        let idx = idx as usize;
        if t.state(idx) == UNPROCESSED {
            let c = t.ijk(idx);
            t.set_state(idx, INTERIOR_NODE);
            placed += 1;
            let r = radius(t.point(c), t.region(idx));
            t.mark_zone(c, r, zone);
        }
        // The same six neighbours in the same order either way.
        let mut next = [usize::MAX; 6];
        if on_border {
            let [i, j, k] = t.ijk(idx);
            for (s, m) in neighbours(t, i, j, k, idx).enumerate() {
                next[s] = m;
            }
        } else {
            next = [idx - 1, idx + 1, idx - sy, idx + sy, idx - sz, idx + sz];
        }
        for m in next {
            if m != usize::MAX && t.region(m) != 0 && t.cells[m] & QUEUED == 0 {
                t.cells[m] |= QUEUED;
                front.push_back(m as u32);
            }
        }
    }
    placed
}

/// Linear indices of the (up to six) face neighbours of voxel `(i, j, k)`.
#[inline]
fn neighbours(
    t: &Template,
    i: usize,
    j: usize,
    k: usize,
    idx: usize,
) -> impl Iterator<Item = usize> {
    let [nx, ny, nz] = t.n;
    let sx = 1;
    let sy = nx;
    let sz = nx * ny;
    [
        (i > 0).then(|| idx - sx),
        (i + 1 < nx).then(|| idx + sx),
        (j > 0).then(|| idx - sy),
        (j + 1 < ny).then(|| idx + sy),
        (k > 0).then(|| idx - sz),
        (k + 1 < nz).then(|| idx + sz),
    ]
    .into_iter()
    .flatten()
}
