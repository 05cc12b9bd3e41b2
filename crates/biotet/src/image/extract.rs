//! The surface of a label image: every face between two voxels of different labels (the image
//! padded with the outside, label 0) becomes two triangles whose sides are the two labels — a
//! multi-label *cuberille* surface.
//!
//! # Why it is valid
//!
//! - **Conforming.** A face between labels `a` and `b` is emitted once, with sides `[a, b]`, so
//!   each interface is one sheet shared by its two regions; points are the grid corners (one
//!   point per corner), so triple lines and quadruple points are shared edges and points.
//! - **Closed and oriented per region.** Every region is a union of closed voxels, whose
//!   boundary faces close up around every grid edge; faces are oriented by the axis they are
//!   normal to (and the sides swapped when the voxel-to-world map reverses orientation).
//! - **Manifold per region.** The union of one label's closed voxels is a 2-manifold at a grid
//!   corner exactly when, among the 8 voxels around the corner, the label's voxels and the
//!   others are both connected through shared faces (the corner's link is the octahedron's
//!   sphere; a set of its triangles is a disk iff it and its complement are connected).
//!   This also covers grid edges (a label on two diagonal voxels around an edge fails at both
//!   ends). Images break it — two voxels of one label touching only along an edge or a corner.
//!   [`make_manifold`] repairs them first by relabelling voxels, always to a label of higher
//!   *rank* (rank = the label value, the outside 0 lowest): a label non-manifold at a corner
//!   either is the highest label there and grows over the corner's other voxels until it is
//!   manifold, or gives its voxels there to the highest label (one voxel when one is enough,
//!   in both cases). Every change raises a voxel's
//!   rank, so the repair ends after at most (labels − 1) changes per voxel; it is counted in
//!   [`ExtractReport::relabelled`]. Regions of different labels may touch at an edge or a
//!   corner: `validate` and `check` accept that, as long as the outside is not pinched
//!   there too — `check` reads a tet mesh's boundary as one surface whose pieces meeting only at
//!   a point or an edge are separate; so, at every corner, each set of non-zero voxels joined
//!   through faces must leave the other voxels connected, else its highest label grows over
//!   the corner's outside voxels (again a rise in rank).
//! - **Embedded.** Faces of the grid meet only in grid edges and corners, which are edges and
//!   points of the triangulation.
//! - **Volume.** Each region's surface encloses exactly its voxels' volume (after the repair).
//!
//! Points are in the image's world coordinates. For an oblique image (a rotated voxel grid) the
//! corners of one flat face are then coplanar only up to rounding; to mesh, extract in the
//! image's axis-aligned frame ([`LabelImage::to_frame`]) and map the mesh to world at the end
//! ([`super::map_points`]), as `biotet mesh IMAGE` does.
//!
//! The surface is staircase-shaped; its smoothing belongs to the surface stage (issue 20:
//! `surface::improve` within a tolerance, by default [`LabelImage::default_surface_tolerance`],
//! half the smallest voxel spacing), which takes this [`SurfaceMesh`] as it takes any labelled
//! surface.

use rustc_hash::FxHashMap;

use super::LabelImage;
use crate::SurfaceMesh;

/// What [`extract`] did.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct ExtractReport {
    /// Voxels relabelled by [`make_manifold`]: `(from, to, voxels)`, sorted.
    pub relabelled: Vec<(u32, u32, usize)>,
    /// Points of the surface.
    pub n_points: usize,
    /// Triangles of the surface (two per voxel face).
    pub n_triangles: usize,
}

/// `true` for the masks of the 8 voxels around a grid corner (bit `dx + 2·dy + 4·dz`) whose set
/// and complement are both connected through faces (or empty): the manifold configurations.
fn manifold_table() -> [bool; 256] {
    fn connected(m: u32) -> bool {
        if m == 0 {
            return true;
        }
        let start = m.trailing_zeros();
        let mut seen = 1u32 << start;
        let mut stack = vec![start];
        while let Some(c) = stack.pop() {
            for bit in [1, 2, 4] {
                let n = c ^ bit;
                if m & (1 << n) != 0 && seen & (1 << n) == 0 {
                    seen |= 1 << n;
                    stack.push(n);
                }
            }
        }
        seen == m
    }
    std::array::from_fn(|m| connected(m as u32) && connected(!(m as u32) & 0xff))
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

/// The outside (label 0) must be manifold too, as `check` reads a tet mesh's boundary: at a
/// corner, each connected set of non-zero voxels (regions joined through faces) must leave the
/// rest connected. Returns the highest label of the first set that does not, and the set's
/// mask; growing that label over the corner's outside voxels repairs it.
fn outside_pinch(l: &[u32; 8], ok: &[bool; 256]) -> Option<(u32, usize)> {
    let mut done = 0usize;
    for s in 0..8 {
        if l[s] == 0 || done & (1 << s) != 0 {
            continue;
        }
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
        done |= m;
        if !ok[m] {
            let top = (0..8).filter(|&n| m & (1 << n) != 0).map(|n| l[n]).max();
            return top.map(|t| (t, m));
        }
    }
    None
}

/// Relabel voxels until every non-zero label is manifold at every grid corner (see the
/// [module documentation](self)). Returns `(from, to, voxels)` for the changes, sorted.
pub fn make_manifold(img: &mut LabelImage) -> Vec<(u32, u32, usize)> {
    let ok = manifold_table();
    let [nx, ny, nz] = img.dims;
    let (cx, cy) = (nx + 1, ny + 1);
    let corners = cx * cy * (nz + 1);
    let mut queued = vec![true; corners];
    let mut queue: std::collections::VecDeque<usize> = (0..corners).collect();
    let mut changes: FxHashMap<(u32, u32), usize> = FxHashMap::default();
    while let Some(q) = queue.pop_front() {
        queued[q] = false;
        let (a, b, c) = (q % cx, (q / cx) % cy, q / (cx * cy));
        let (l, idx) = block(img, a, b, c);
        if l.iter().all(|&x| x == l[0]) {
            continue;
        }
        let top = *l.iter().max().expect("8 labels");
        // The first non-manifold non-zero label, if any.
        let mut bad = None;
        for &lab in &l {
            if lab == 0 {
                continue;
            }
            let m = (0..8).fold(0usize, |m, n| m | (((l[n] == lab) as usize) << n));
            if !ok[m] {
                bad = Some((lab, m));
                break;
            }
        }
        let Some((lab, m)) = bad.or_else(|| outside_pinch(&l, &ok)) else {
            continue;
        };
        let mut set = |n: usize, to: u32, img: &mut LabelImage| {
            let v = idx[n];
            *changes.entry((img.labels[v], to)).or_default() += 1;
            img.labels[v] = to;
            // Re-examine the 8 corners of the changed voxel.
            let (i, j, k) = (v % nx, (v / nx) % ny, v / (nx * ny));
            for dz in 0..2 {
                for dy in 0..2 {
                    for dx in 0..2 {
                        let w = (i + dx) + cx * ((j + dy) + cy * (k + dz));
                        if !queued[w] {
                            queued[w] = true;
                            queue.push_back(w);
                        }
                    }
                }
            }
        };
        // A pinched outside grows the pinching set's top label over outside voxels only.
        let pinch = bad.is_none();
        let top = if pinch { lab } else { top };
        if lab == top {
            // Grow over lower labels: the first single in-image voxel whose change makes the
            // set manifold, else all of the corner's in-image voxels it may take.
            let may = |n: usize| m & (1 << n) == 0 && idx[n] != usize::MAX && (!pinch || l[n] == 0);
            match (0..8).find(|&n| may(n) && ok[m | (1 << n)]) {
                Some(n) => set(n, lab, img),
                None => {
                    for n in (0..8).filter(|&n| may(n)) {
                        set(n, lab, img);
                    }
                }
            }
        } else {
            // Give voxels to the highest label: the first single one that makes the label
            // manifold here, else all of its voxels at the corner.
            let mine = |n: usize| m & (1 << n) != 0;
            match (0..8).find(|&n| mine(n) && ok[m & !(1 << n)]) {
                Some(n) => set(n, top, img),
                None => {
                    for n in (0..8).filter(|&n| mine(n)) {
                        set(n, top, img);
                    }
                }
            }
        }
        // The corner itself may need more work.
        if !queued[q] {
            queued[q] = true;
            queue.push_back(q);
        }
    }
    let mut v: Vec<(u32, u32, usize)> = changes.into_iter().map(|((f, t), n)| (f, t, n)).collect();
    v.sort_unstable();
    v
}

/// The multi-label surface of an image (the image is first made manifold per label by
/// [`make_manifold`], in place). Points in world coordinates.
pub fn extract(img: &mut LabelImage) -> (SurfaceMesh, ExtractReport) {
    let relabelled = make_manifold(img);
    let mesh = faces(img);
    let report = ExtractReport {
        relabelled,
        n_points: mesh.points.len(),
        n_triangles: mesh.triangles.len(),
    };
    (mesh, report)
}

/// The voxel-face surface, without any repair: valid when every label is manifold at every
/// corner (as after [`make_manifold`]).
pub fn faces(img: &LabelImage) -> SurfaceMesh {
    let [nx, ny, nz] = img.dims;
    let (cx, cy) = (nx + 1, ny + 1);
    let label = |i: isize, j: isize, k: isize| -> u32 {
        if i < 0 || j < 0 || k < 0 || i >= nx as isize || j >= ny as isize || k >= nz as isize {
            0
        } else {
            img.get(i as usize, j as usize, k as usize)
        }
    };
    let flip = img.determinant() < 0.0;
    let mut point_of: FxHashMap<usize, u32> = FxHashMap::default();
    let mut mesh = SurfaceMesh::default();
    let mut corner = |a: usize, b: usize, c: usize, mesh: &mut SurfaceMesh| -> u32 {
        let key = a + cx * (b + cy * c);
        *point_of.entry(key).or_insert_with(|| {
            mesh.points
                .push(img.world([a as f64 - 0.5, b as f64 - 0.5, c as f64 - 0.5]));
            (mesh.points.len() - 1) as u32
        })
    };
    // Corner offsets of the quad normal to each axis, counter-clockwise seen from +axis.
    const QUADS: [[[usize; 3]; 4]; 3] = [
        [[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]],
        [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]],
        [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
    ];
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let (ii, jj, kk) = (i as isize, j as isize, k as isize);
                let here = label(ii, jj, kk);
                let behind = [
                    label(ii - 1, jj, kk),
                    label(ii, jj - 1, kk),
                    label(ii, jj, kk - 1),
                ];
                for (axis, &back) in behind.iter().enumerate() {
                    if back == here {
                        continue;
                    }
                    // The face lies on the plane of corner (i, j, k) normal to `axis` and
                    // must stay inside the padded grid along the other axes.
                    let lim = [nx, ny, nz];
                    if (0..3).any(|a| a != axis && [i, j, k][a] >= lim[a]) {
                        continue;
                    }
                    let q = QUADS[axis].map(|o| corner(i + o[0], j + o[1], k + o[2], &mut mesh));
                    let sides = if flip { [here, back] } else { [back, here] };
                    // The diagonal away from the corner of highest index: the one the
                    // Delaunay's symbolic perturbation picks for four cocircular points (the
                    // highest index is perturbed most), so fewer triangles need recovery.
                    let top = (0..4).max_by_key(|&c| q[c]).expect("4 corners");
                    if top % 2 == 0 {
                        mesh.triangles.push([q[0], q[1], q[3]]);
                        mesh.triangles.push([q[1], q[2], q[3]]);
                    } else {
                        mesh.triangles.push([q[0], q[1], q[2]]);
                        mesh.triangles.push([q[0], q[2], q[3]]);
                    }
                    mesh.sides.push(sides);
                    mesh.sides.push(sides);
                }
            }
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_counts() {
        let t = manifold_table();
        assert!(t[0] && t[255] && t[1] && t[3] && t[0x0f]);
        assert!(!t[0b1001] && !t[0b1000_0001]); // diagonal along a face, through the block
    }

    #[test]
    fn single_voxel_is_a_cube() {
        let img = LabelImage::axis_aligned([1, 1, 1], [2.0; 3], [0.0; 3], vec![3]).unwrap();
        let s = faces(&img);
        assert_eq!(s.triangles.len(), 12);
        assert_eq!(s.points.len(), 8);
        assert!(s.sides.iter().all(|&x| x == [3, 0] || x == [0, 3]));
        let r = validate(s);
        assert_eq!(r.regions.len(), 1);
        assert!((r.regions[0].volume - 8.0).abs() < 1e-12);
        assert!(!r.flipped_inward);
    }

    fn validate(mut s: SurfaceMesh) -> crate::mesh::validate::ValidationReport {
        crate::mesh::validate::validate_surface(&mut s, &Default::default()).unwrap()
    }

    #[test]
    fn mirrored_image_keeps_orientation() {
        let mut img = LabelImage::axis_aligned([2, 1, 1], [1.0; 3], [0.0; 3], vec![1, 2]).unwrap();
        img.voxel_to_world[0][0] = -1.0;
        let r = validate(faces(&img));
        assert!(!r.flipped_inward);
        assert_eq!(r.regions.len(), 2);
    }

    #[test]
    fn diagonal_pair_is_repaired() {
        let mut img =
            LabelImage::axis_aligned([2, 2, 1], [1.0; 3], [0.0; 3], vec![1, 0, 0, 1]).unwrap();
        let r = make_manifold(&mut img);
        assert_eq!(r.iter().map(|x| x.2).sum::<usize>(), 1);
        assert_eq!(img.labels.iter().filter(|&&l| l == 1).count(), 3);
        validate(faces(&img));
    }
}
