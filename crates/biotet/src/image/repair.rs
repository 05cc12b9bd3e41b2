//! Voxels relabelled so that every label is a 2-manifold at every grid corner (what the
//! voxel-face surface of [`super::extract`] needs), keeping each region's connected components
//! wherever one voxel's change can.
//!
//! # When a corner needs work
//! The union of one label's closed voxels is a 2-manifold at a grid corner exactly when, among
//! the 8 voxels around the corner, the label's voxels and the others are both connected through
//! shared faces. The outside must not be pinched either (`check` reads a mesh's boundary as one
//! surface): each set of non-zero voxels joined through faces must leave the other voxels of the
//! corner connected. A corner's *problems* are its non-manifold non-zero labels, plus one if the
//! outside is pinched; its *defect* counts how far it is from manifold (each label's pieces and
//! its complement's beyond one, plus the pinching sets), zero exactly when it needs no work.
//!
//! # The rule
//! 1. **A safe change first.** One voxel of the corner takes the label of one of its face
//!    neighbours in the corner's block, such that the corner's defect falls and no
//!    region's connected components change:
//!    - *nothing is split*: the voxel's face neighbours of its old label stay connected through
//!      that label inside the voxel's 3×3×3 block (a voxel with none is a whole component, and
//!      stays);
//!    - *nothing is merged*: its face neighbours of the new label all belong to one component of
//!      the image (the components are labelled once; a safe change keeps the labelling true).
//!
//!    A voxel takes at most [`SAFE_CHANGES`] safe changes.
//! 2. **Else by rank** (rank = the label value, the outside 0 lowest): a label non-manifold at
//!    the corner either is the highest label there and grows over the corner's other voxels
//!    until it is manifold, or gives its voxels there to the highest label (one voxel when one is
//!    enough, in both cases); a pinched outside is repaired by growing the pinching set's
//!    highest label over the corner's outside voxels. These may split or merge components; the
//!    image summary reports every region whose count changed.
//!
//! Safe changes are bounded per voxel and every other change raises a voxel's rank, so the
//! repair ends. Why safe changes matter: on the MNI brain, grey matter touches itself diagonally
//! across white matter at 1,542 corners; the rank rule alone gave those voxels to white matter
//! and cut grey matter (one component in the image) into five.

use std::collections::VecDeque;

use rustc_hash::FxHashMap;

use super::LabelImage;
use super::labels::{Components, face_neighbours, on_border};

/// How many safe changes one voxel may take (bounds the repair: safe changes may lower a rank).
pub const SAFE_CHANGES: u8 = 2;

/// The number of face-connected pieces of each mask of the 8 voxels around a grid corner (bit
/// `dx + 2·dy + 4·dz`).
fn pieces_table() -> [u8; 256] {
    let mut t = [0u8; 256];
    for (m, count) in t.iter_mut().enumerate() {
        let mut left = m as u32;
        while left != 0 {
            *count += 1;
            let start = left.trailing_zeros();
            left &= !(1 << start);
            let mut stack = vec![start];
            while let Some(c) = stack.pop() {
                for bit in [1, 2, 4] {
                    let n = c ^ bit;
                    if left & (1 << n) != 0 {
                        left &= !(1 << n);
                        stack.push(n);
                    }
                }
            }
        }
    }
    t
}

/// `true` for the masks whose set and complement are both connected through faces (or empty):
/// the manifold configurations.
fn manifold_table(pieces: &[u8; 256]) -> [bool; 256] {
    std::array::from_fn(|m| pieces[m] <= 1 && pieces[!m & 0xff] <= 1)
}

/// The labels of the 8 voxels around grid corner `(a, b, c)` (corner `(a, b, c)` lies between
/// voxels `a − 1` and `a` along x, and so on); voxels outside the image are 0. Also returns
/// their linear indices (`usize::MAX` outside).
fn block(img: &LabelImage, a: usize, b: usize, c: usize) -> ([u32; 8], [usize; 8]) {
    let mut l = [0u32; 8];
    let mut idx = [usize::MAX; 8];
    for n in 0..8 {
        let (dx, dy, dz) = (n & 1, (n >> 1) & 1, (n >> 2) & 1);
        let (i, j, k) = (a + dx, b + dy, c + dz);
        if i == 0 || j == 0 || k == 0 || i > img.dims[0] || j > img.dims[1] || k > img.dims[2] {
            continue;
        }
        let v = img.index(i - 1, j - 1, k - 1);
        l[n] = img.labels[v];
        idx[n] = v;
    }
    (l, idx)
}

/// The mask of the voxels of label `lab` among a corner's 8.
fn mask_of(l: &[u32; 8], lab: u32) -> usize {
    (0..8).fold(0usize, |m, n| m | (((l[n] == lab) as usize) << n))
}

/// At a corner, each connected set of non-zero voxels (regions joined through faces) must leave
/// the rest connected. Returns the highest label of the first set that does not, and the set's
/// mask; growing that label over the corner's outside voxels repairs it.
fn outside_pinch(l: &[u32; 8], ok: &[bool; 256]) -> Option<(u32, usize)> {
    let m = nonzero_sets(l).find(|&m| !ok[m])?;
    let top = (0..8).filter(|&n| m & (1 << n) != 0).map(|n| l[n]).max();
    top.map(|t| (t, m))
}

/// The number of connected sets of non-zero voxels of a corner that pinch the outside.
fn pinches(l: &[u32; 8], ok: &[bool; 256]) -> usize {
    nonzero_sets(l).filter(|&m| !ok[m]).count()
}

/// The masks of a corner's connected sets of non-zero voxels, in order of their first voxel.
fn nonzero_sets(l: &[u32; 8]) -> impl Iterator<Item = usize> + '_ {
    let mut done = 0usize;
    (0..8).filter_map(move |s| {
        if l[s] == 0 || done & (1 << s) != 0 {
            return None;
        }
        let m = nonzero_set(l, s);
        done |= m;
        Some(m)
    })
}

/// The connected set of non-zero voxels of a corner that holds voxel `s`.
fn nonzero_set(l: &[u32; 8], s: usize) -> usize {
    let mut m = 1usize << s;
    let mut stack = vec![s];
    while let Some(c) = stack.pop() {
        for bit in [1, 2, 4] {
            let n = c ^ bit;
            if l[n] != 0 && m & (1 << n) == 0 {
                m |= 1 << n;
                stack.push(n);
            }
        }
    }
    m
}

/// The first non-manifold non-zero label of a corner and its mask.
fn first_bad(l: &[u32; 8], ok: &[bool; 256]) -> Option<(u32, usize)> {
    l.iter()
        .filter(|&&lab| lab != 0)
        .map(|&lab| (lab, mask_of(l, lab)))
        .find(|&(_, m)| !ok[m])
}

/// How far a corner is from manifold: for each non-zero label, its pieces and its complement's
/// beyond one, plus the non-zero sets that pinch the outside. Zero exactly when the corner needs
/// no work; a safe change must lower it.
fn defect(l: &[u32; 8], ok: &[bool; 256], pieces: &[u8; 256]) -> usize {
    let mut seen = [0u32; 8];
    let mut n = 0;
    let mut d = 0;
    for &lab in l {
        if lab == 0 || seen[..n].contains(&lab) {
            continue;
        }
        seen[n] = lab;
        n += 1;
        let m = mask_of(l, lab);
        d += pieces[m].saturating_sub(1) as usize + pieces[!m & 0xff].saturating_sub(1) as usize;
    }
    d + pinches(l, ok)
}

/// Component keys of voxels, for the "nothing is merged" test: the image's 6-connected
/// components, the outside's components on the image border being one (the padding joins them).
struct Keys {
    of_voxel: Vec<u32>,
}

/// The key of the padding around the image.
const PADDING: u32 = u32::MAX;

impl Keys {
    fn of(img: &LabelImage) -> Keys {
        let c = Components::of(img);
        let mut of_voxel = c.of_voxel;
        for k in of_voxel.iter_mut() {
            let comp = &c.list[*k as usize];
            if comp.label == 0 && comp.border {
                *k = PADDING;
            }
        }
        Keys { of_voxel }
    }
}

/// The repair's state: the image, the manifold table, component keys and safe changes so far.
struct Repair<'a> {
    img: &'a mut LabelImage,
    ok: [bool; 256],
    pieces: [u8; 256],
    keys: Keys,
    safe_taken: FxHashMap<usize, u8>,
    /// Corners to examine (every corner at first, then those of changed voxels).
    queued: Vec<bool>,
    queue: VecDeque<usize>,
    /// `(from, to)` → voxels.
    changes: FxHashMap<(u32, u32), usize>,
}

impl Repair<'_> {
    /// Give voxel `v` label `to` and component key `key`, and queue its 8 corners.
    fn set(&mut self, v: usize, to: u32, key: u32) {
        *self.changes.entry((self.img.labels[v], to)).or_default() += 1;
        self.img.labels[v] = to;
        self.keys.of_voxel[v] = key;
        let [nx, ny, _] = self.img.dims;
        let (cx, cy) = (nx + 1, ny + 1);
        let (i, j, k) = (v % nx, (v / nx) % ny, v / (nx * ny));
        for dz in 0..2 {
            for dy in 0..2 {
                for dx in 0..2 {
                    let w = (i + dx) + cx * ((j + dy) + cy * (k + dz));
                    if !self.queued[w] {
                        self.queued[w] = true;
                        self.queue.push_back(w);
                    }
                }
            }
        }
    }

    /// The label at voxel `(i, j, k)` given as signed indices (0 outside the image).
    fn label_at(&self, i: isize, j: isize, k: isize) -> u32 {
        let [nx, ny, nz] = self.img.dims;
        if i < 0 || j < 0 || k < 0 || i >= nx as isize || j >= ny as isize || k >= nz as isize {
            0
        } else {
            self.img.labels[self.img.index(i as usize, j as usize, k as usize)]
        }
    }

    /// Can voxel `v` leave its label without splitting a component? Its face neighbours of that
    /// label must exist and be connected through that label inside its 3×3×3 block, `v` itself
    /// left out.
    fn leaves_connected(&self, v: usize) -> bool {
        let [nx, ny, _] = self.img.dims;
        let (i, j, k) = (
            (v % nx) as isize,
            ((v / nx) % ny) as isize,
            (v / (nx * ny)) as isize,
        );
        let lab = self.img.labels[v];
        // The block's cells of the label, bit `(dx+1) + 3(dy+1) + 9(dz+1)`; the centre left out.
        let mut cells = 0u32;
        for c in 0..27 {
            if c == 13 {
                continue;
            }
            let (dx, dy, dz) = (c % 3 - 1, (c / 3) % 3 - 1, c / 9 - 1);
            if self.label_at(i + dx as isize, j + dy as isize, k + dz as isize) == lab {
                cells |= 1 << c;
            }
        }
        const FACES: [u32; 6] = [12, 14, 10, 16, 4, 22];
        let want = FACES.iter().fold(0u32, |m, &c| m | (cells & (1 << c)));
        if want == 0 {
            return false;
        }
        let start = want.trailing_zeros();
        let mut seen = 1u32 << start;
        let mut stack = vec![start];
        while let Some(c) = stack.pop() {
            let (x, y, z) = (c % 3, (c / 3) % 3, c / 9);
            let mut visit = |n: u32| {
                if cells & (1 << n) != 0 && seen & (1 << n) == 0 {
                    seen |= 1 << n;
                    stack.push(n);
                }
            };
            if x > 0 {
                visit(c - 1);
            }
            if x < 2 {
                visit(c + 1);
            }
            if y > 0 {
                visit(c - 3);
            }
            if y < 2 {
                visit(c + 3);
            }
            if z > 0 {
                visit(c - 9);
            }
            if z < 2 {
                visit(c + 9);
            }
        }
        seen & want == want
    }

    /// The one component key of voxel `v`'s face neighbours of label `to`, or `None` when it
    /// has none or they lie in more than one component.
    fn joins_one(&self, v: usize, to: u32) -> Option<u32> {
        let mut key = None;
        let mut one = true;
        let mut see = |k: u32| match key {
            None => key = Some(k),
            Some(x) => one &= x == k,
        };
        face_neighbours(self.img.dims, v, |w| {
            if self.img.labels[w] == to {
                see(self.keys.of_voxel[w]);
            }
        });
        // The padding around the image is outside, one component.
        if to == 0 && on_border(self.img.dims, v) {
            see(PADDING);
        }
        key.filter(|_| one)
    }

    /// Voxel `v`'s component key if giving it label `to` is safe (splits and merges nothing)
    /// and it may take another safe change.
    fn safe(&self, v: usize, to: u32) -> Option<u32> {
        if v == usize::MAX || self.safe_taken.get(&v).copied().unwrap_or(0) >= SAFE_CHANGES {
            return None;
        }
        self.joins_one(v, to).filter(|_| self.leaves_connected(v))
    }

    /// The first safe changes at a corner (labels `l`, voxels `idx`) that lower its defect: one
    /// voxel if one is enough, else two (a voxel of one component touching another at two
    /// points needs both cut). `(corner voxel, new label, its component key)`, in order.
    fn safe_changes(&mut self, l: &[u32; 8], idx: &[usize; 8]) -> Vec<(usize, u32, u32)> {
        let before = defect(l, &self.ok, &self.pieces);
        // A voxel of the corner takes the label of a face neighbour there.
        let options = |l: &[u32; 8]| {
            (0..8)
                .flat_map(|n| [1, 2, 4].map(|bit| (n, l[n ^ bit])))
                .filter(|&(n, to)| to != l[n])
                .collect::<Vec<_>>()
        };
        let lowers = |l: &[u32; 8], n: usize, to: u32| {
            let mut after = *l;
            after[n] = to;
            (defect(&after, &self.ok, &self.pieces) < before).then_some(after)
        };
        for &(n, to) in &options(l) {
            if lowers(l, n, to).is_some()
                && let Some(key) = self.safe(idx[n], to)
            {
                return vec![(n, to, key)];
            }
        }
        for (n, to) in options(l) {
            let Some(key) = self.safe(idx[n], to) else {
                continue;
            };
            // Tentatively made, so the second change is judged on the image after the first.
            let v = idx[n];
            let (old, old_key) = (self.img.labels[v], self.keys.of_voxel[v]);
            self.img.labels[v] = to;
            self.keys.of_voxel[v] = key;
            let mut l1 = *l;
            l1[n] = to;
            let second = options(&l1).into_iter().find_map(|(m, to2)| {
                if m == n {
                    return None;
                }
                let after = {
                    let mut a = l1;
                    a[m] = to2;
                    a
                };
                (defect(&after, &self.ok, &self.pieces) < before)
                    .then(|| self.safe(idx[m], to2).map(|k| (m, to2, k)))
                    .flatten()
            });
            self.img.labels[v] = old;
            self.keys.of_voxel[v] = old_key;
            if let Some(c) = second {
                return vec![(n, to, key), c];
            }
        }
        Vec::new()
    }
}

/// Relabel voxels until every non-zero label is manifold at every grid corner and the outside is
/// pinched nowhere (see the [module documentation](self)). Returns `(from, to, voxels)` for the
/// changes, sorted.
pub fn make_manifold(img: &mut LabelImage) -> Vec<(u32, u32, usize)> {
    let [nx, ny, nz] = img.dims;
    let (cx, cy) = (nx + 1, ny + 1);
    let corners = cx * cy * (nz + 1);
    let keys = Keys::of(img);
    let pieces = pieces_table();
    let mut r = Repair {
        img,
        ok: manifold_table(&pieces),
        pieces,
        keys,
        safe_taken: FxHashMap::default(),
        queued: vec![true; corners],
        queue: (0..corners).collect(),
        changes: FxHashMap::default(),
    };
    while let Some(q) = r.queue.pop_front() {
        r.queued[q] = false;
        let (a, b, c) = (q % cx, (q / cx) % cy, q / (cx * cy));
        let (l, idx) = block(r.img, a, b, c);
        if l.iter().all(|&x| x == l[0]) {
            continue;
        }
        let bad = first_bad(&l, &r.ok);
        let Some((lab, m)) = bad.or_else(|| outside_pinch(&l, &r.ok)) else {
            continue;
        };
        let safe = r.safe_changes(&l, &idx);
        if !safe.is_empty() {
            for (n, to, key) in safe {
                *r.safe_taken.entry(idx[n]).or_insert(0) += 1;
                r.set(idx[n], to, key);
            }
        } else {
            // By rank. A voxel's key after such a change: a component of its new label it
            // touches, else one of its own (a new component).
            let key_for = |r: &Repair, v: usize, to: u32| {
                r.joins_one(v, to).unwrap_or(u32::MAX - 1 - v as u32)
            };
            let top = *l.iter().max().expect("8 labels");
            // A pinched outside grows the pinching set's top label over outside voxels only.
            let pinch = bad.is_none();
            let top = if pinch { lab } else { top };
            let mut todo: Vec<(usize, u32)> = Vec::new();
            if lab == top {
                // Grow over lower labels: the first single in-image voxel whose change makes
                // the set manifold, else all of the corner's in-image voxels it may take.
                let may =
                    |n: usize| m & (1 << n) == 0 && idx[n] != usize::MAX && (!pinch || l[n] == 0);
                match (0..8).find(|&n| may(n) && r.ok[m | (1 << n)]) {
                    Some(n) => todo.push((idx[n], lab)),
                    None => todo.extend((0..8).filter(|&n| may(n)).map(|n| (idx[n], lab))),
                }
            } else {
                // Give voxels to the highest label: the first single one that makes the label
                // manifold here, else all of its voxels at the corner.
                let mine = |n: usize| m & (1 << n) != 0;
                match (0..8).find(|&n| mine(n) && r.ok[m & !(1 << n)]) {
                    Some(n) => todo.push((idx[n], top)),
                    None => todo.extend((0..8).filter(|&n| mine(n)).map(|n| (idx[n], top))),
                }
            }
            for (v, to) in todo {
                let key = key_for(&r, v, to);
                r.set(v, to, key);
            }
        }
        // The corner itself may need more work.
        if !r.queued[q] {
            r.queued[q] = true;
            r.queue.push_back(q);
        }
    }
    let mut v: Vec<(u32, u32, usize)> =
        r.changes.into_iter().map(|((f, t), n)| (f, t, n)).collect();
    v.sort_unstable();
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_counts() {
        let t = manifold_table(&pieces_table());
        assert!(t[0] && t[255] && t[1] && t[3] && t[0x0f]);
        assert!(!t[0b1001] && !t[0b1000_0001]); // diagonal along a face, through the block
    }
}
