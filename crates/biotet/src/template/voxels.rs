//! The voxel template: one [`Cell`] per voxel (dissertation section 2.3.1, Table 2.1).
//!
//! Bits 0–1 hold the state (unprocessed, buffer, surface node, interior node), bit 2 marks a
//! voxel already queued by the inward sweep, bits 3–15 the region containing the voxel centre
//! (0 = outside). The seed's byte held 31 regions; a FreeSurfer parcellation has over a hundred
//! labels and a scan of loose parts as many shells, so a voxel takes two bytes.

/// One voxel's bits.
pub type Cell = u16;

/// State: not yet claimed.
pub const UNPROCESSED: Cell = 0;
/// State: inside some node's buffer zone; no node may go here.
pub const BUFFER: Cell = 1;
/// State: the nearest voxel of a surface node.
pub const SURFACE_NODE: Cell = 2;
/// State: an interior node.
pub const INTERIOR_NODE: Cell = 3;
const STATE: Cell = 0b11;
/// Flag: queued by the sweep.
pub const QUEUED: Cell = 0b100;
const REGION_SHIFT: u32 = 3;
/// Largest region label the template can hold.
pub const MAX_REGION: u32 = (Cell::MAX >> REGION_SHIFT) as u32;

/// Shape of a buffer zone of radius `r` voxels around a node voxel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Zone {
    /// The seed's zone: every voxel whose offsets are all below `r` in magnitude (L∞ ball).
    Box,
    /// Every voxel at integer squared distance below `r²` (Euclidean ball).
    Euclidean,
}

/// The template grid.
pub struct Template {
    /// Voxels along x, y, z.
    pub n: [usize; 3],
    /// Centre of voxel (0, 0, 0).
    pub origin: [f64; 3],
    /// Spacing (eq. 2.1).
    pub dx: f64,
    /// One cell per voxel, x fastest.
    pub cells: Vec<Cell>,
    /// Per row `(j, k)` (index `j + n[1]·k`), its first and last inside voxel (first above last:
    /// none), kept by [`Template::set_region_span`]: sealing scans only that part of a row, since
    /// only inside voxels become nodes.
    pub inside_rows: Vec<[u32; 2]>,
}

impl Template {
    /// An unprocessed, all-outside template.
    pub fn new(n: [usize; 3], origin: [f64; 3], dx: f64) -> Template {
        Template {
            n,
            origin,
            dx,
            cells: vec![0; n[0] * n[1] * n[2]],
            inside_rows: vec![[u32::MAX, 0]; n[1] * n[2]],
        }
    }

    /// Linear index of voxel `(i, j, k)`.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.n[0] * (j + self.n[1] * k)
    }

    /// `(i, j, k)` of a linear index.
    #[inline]
    pub fn ijk(&self, idx: usize) -> [usize; 3] {
        [
            idx % self.n[0],
            (idx / self.n[0]) % self.n[1],
            idx / (self.n[0] * self.n[1]),
        ]
    }

    /// Coordinate of voxel index `i` along `axis` (eq. 2.9). Every use goes through here, so the
    /// exact inside test and the node coordinates agree to the last bit.
    #[inline]
    pub fn coord(&self, axis: usize, i: usize) -> f64 {
        self.origin[axis] + i as f64 * self.dx
    }

    /// Centre of voxel `(i, j, k)`.
    #[inline]
    pub fn point(&self, c: [usize; 3]) -> [f64; 3] {
        [
            self.coord(0, c[0]),
            self.coord(1, c[1]),
            self.coord(2, c[2]),
        ]
    }

    /// The voxel nearest to `p` (eq. 2.6), clamped to the grid.
    pub fn nearest(&self, p: [f64; 3]) -> [usize; 3] {
        [0, 1, 2].map(|a| {
            let f = ((p[a] - self.origin[a]) / self.dx).round();
            (f.max(0.0) as usize).min(self.n[a] - 1)
        })
    }

    /// State bits of a voxel.
    #[inline]
    pub fn state(&self, idx: usize) -> Cell {
        self.cells[idx] & STATE
    }

    /// Set the state bits, keeping the others.
    #[inline]
    pub fn set_state(&mut self, idx: usize, s: Cell) {
        self.cells[idx] = (self.cells[idx] & !STATE) | s;
    }

    /// Region of a voxel centre (0 = outside).
    #[inline]
    pub fn region(&self, idx: usize) -> u32 {
        (self.cells[idx] >> REGION_SHIFT) as u32
    }

    /// Set the region of voxels `lo..hi` of one row (they must still be region 0).
    #[inline]
    pub fn set_region_span(&mut self, row_start: usize, lo: usize, hi: usize, region: u32) {
        let bits = (region as Cell) << REGION_SHIFT;
        for c in &mut self.cells[row_start + lo..row_start + hi] {
            *c |= bits;
        }
        if region != 0 && lo < hi {
            let r = &mut self.inside_rows[row_start / self.n[0]];
            r[0] = r[0].min(lo as u32);
            r[1] = r[1].max((hi - 1) as u32);
        }
    }

    /// Mark every unprocessed voxel of the zone of radius `r` around `c` as buffer (eq. 2.8);
    /// nodes keep their state, so the denser requirement wins.
    pub fn mark_zone(&mut self, c: [usize; 3], r: usize, zone: Zone) {
        let r = r.max(1);
        let reach = (r - 1) as i64;
        let r2 = (r * r) as i64;
        let [nx, ny, nz] = self.n.map(|v| v as i64);
        let [ci, cj, ck] = c.map(|v| v as i64);
        for dk in -reach..=reach {
            let k = ck + dk;
            if k < 0 || k >= nz {
                continue;
            }
            for dj in -reach..=reach {
                let j = cj + dj;
                if j < 0 || j >= ny {
                    continue;
                }
                let span = match zone {
                    Zone::Box => reach,
                    Zone::Euclidean => {
                        let rest = r2 - dj * dj - dk * dk;
                        if rest <= 0 {
                            continue;
                        }
                        isqrt_below(rest)
                    }
                };
                let lo = (ci - span).max(0);
                let hi = (ci + span).min(nx - 1);
                let row = (nx * (j + ny * k)) as usize;
                for c in &mut self.cells[row + lo as usize..=row + hi as usize] {
                    if *c & STATE == UNPROCESSED {
                        *c |= BUFFER;
                    }
                }
            }
        }
    }

    /// Bytes held by the template.
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.cells.as_slice())
    }
}

/// The largest `d ≥ 0` with `d² < x` (for `x > 0`), in integers.
#[inline]
fn isqrt_below(x: i64) -> i64 {
    let mut d = ((x as f64).sqrt()) as i64;
    while d * d >= x {
        d -= 1;
    }
    while (d + 1) * (d + 1) < x {
        d += 1;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    fn count_buffer(t: &Template) -> usize {
        t.cells.iter().filter(|&&c| c & STATE == BUFFER).count()
    }

    #[test]
    fn zones_have_the_stated_shape() {
        let mut t = Template::new([11, 11, 11], [0.0; 3], 1.0);
        t.mark_zone([5, 5, 5], 3, Zone::Box);
        assert_eq!(count_buffer(&t), 125); // offsets -2..=2
        let mut t = Template::new([11, 11, 11], [0.0; 3], 1.0);
        t.mark_zone([5, 5, 5], 3, Zone::Euclidean);
        let mut expect = 0;
        for a in -2i64..=2 {
            for b in -2i64..=2 {
                for c in -2i64..=2 {
                    expect += usize::from(a * a + b * b + c * c < 9);
                }
            }
        }
        assert_eq!(count_buffer(&t), expect);
        // A node inside the zone stays a node.
        let mut t = Template::new([5, 5, 5], [0.0; 3], 1.0);
        let i = t.index(2, 2, 3);
        t.set_state(i, INTERIOR_NODE);
        t.mark_zone([2, 2, 2], 2, Zone::Box);
        assert_eq!(t.state(i), INTERIOR_NODE);
        assert_eq!(isqrt_below(9), 2);
        assert_eq!(isqrt_below(10), 3);
        assert_eq!(isqrt_below(1), 0);
    }
}
