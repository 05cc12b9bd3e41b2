//! A hashed uniform grid of the triangles being remeshed, updated as they change: the
//! candidates for the exact intersection test of every new triangle. Each triangle is listed in
//! every cell its bounding box overlaps; the box cells are remembered so removal does not need
//! the (possibly moved) coordinates. Each cell's entry carries the triangle's first cell, so a
//! query lists a triangle only in the first cell of its box within the query's (no repeats to
//! sort away).

use crate::geom::vec3::bbox;
use rustc_hash::FxHashMap;

type P3 = [f64; 3];
type Cells = ([i32; 3], [i32; 3]);

/// The grid.
#[derive(Debug, Clone, Default)]
pub struct Grid {
    h: f64,
    cells: FxHashMap<[i32; 3], Vec<(u32, [i32; 3])>>,
    of: Vec<Option<Cells>>,
}

impl Grid {
    /// An empty grid of cell size `h`.
    pub fn new(h: f64) -> Grid {
        Grid {
            h,
            ..Default::default()
        }
    }

    fn range(&self, lo: P3, hi: P3) -> Cells {
        (
            lo.map(|c| (c / self.h).floor() as i32),
            hi.map(|c| (c / self.h).floor() as i32),
        )
    }

    /// List triangle `t` with corners `c`.
    pub fn insert(&mut self, t: u32, c: &[P3; 3]) {
        let (lo, hi) = bbox(c);
        self.insert_box(t, lo, hi);
    }

    /// List item `t` over the box `lo..hi`.
    pub fn insert_box(&mut self, t: u32, lo: P3, hi: P3) {
        let r = self.range(lo, hi);
        if self.of.len() <= t as usize {
            self.of.resize(t as usize + 1, None);
        }
        debug_assert!(self.of[t as usize].is_none());
        self.of[t as usize] = Some(r);
        for i in r.0[0]..=r.1[0] {
            for j in r.0[1]..=r.1[1] {
                for k in r.0[2]..=r.1[2] {
                    self.cells.entry([i, j, k]).or_default().push((t, r.0));
                }
            }
        }
    }

    /// List triangle `t` again with its corners now at `c`: where its box keeps its cells, its
    /// entries stand as they are (a cell's order is not part of any answer).
    pub fn update(&mut self, t: u32, c: &[P3; 3]) {
        let (lo, hi) = bbox(c);
        if self.of.get(t as usize).copied().flatten() == Some(self.range(lo, hi)) {
            return;
        }
        self.remove(t);
        self.insert_box(t, lo, hi);
    }

    /// Unlist everything.
    pub fn clear(&mut self) {
        self.cells.clear();
        self.of.clear();
    }

    /// Unlist triangle `t`.
    pub fn remove(&mut self, t: u32) {
        let Some(r) = self.of.get_mut(t as usize).and_then(|x| x.take()) else {
            return;
        };
        for i in r.0[0]..=r.1[0] {
            for j in r.0[1]..=r.1[1] {
                for k in r.0[2]..=r.1[2] {
                    if let Some(v) = self.cells.get_mut(&[i, j, k])
                        && let Some(p) = v.iter().position(|&x| x.0 == t)
                    {
                        v.swap_remove(p);
                    }
                }
            }
        }
    }

    /// The triangles whose boxes' cells overlap the box `lo..hi`, sorted, without repeats.
    pub fn query(&self, lo: P3, hi: P3, out: &mut Vec<u32>) {
        out.clear();
        self.any(lo, hi, |t| {
            out.push(t);
            false
        });
        out.sort_unstable();
    }

    /// Whether `f` is true for one of the triangles [`Self::query`] lists, each offered once,
    /// in no particular order (stops at the first).
    #[inline]
    pub fn any(&self, lo: P3, hi: P3, mut f: impl FnMut(u32) -> bool) -> bool {
        let r = self.range(lo, hi);
        for i in r.0[0]..=r.1[0] {
            for j in r.0[1]..=r.1[1] {
                for k in r.0[2]..=r.1[2] {
                    let Some(v) = self.cells.get(&[i, j, k]) else {
                        continue;
                    };
                    for &(t, first) in v {
                        // The first cell of the triangle's box within the query's.
                        if i == first[0].max(r.0[0])
                            && j == first[1].max(r.0[1])
                            && k == first[2].max(r.0[2])
                            && f(t)
                        {
                            return true;
                        }
                    }
                }
            }
        }
        false
    }
}
