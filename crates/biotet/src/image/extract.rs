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
//!   [`make_manifold`] (module [`super::repair`]) repairs them first by relabelling voxels,
//!   keeping every region's connected components where one voxel's change can. Regions of
//!   different labels may touch at an edge or a corner: `validate` and `check` accept that, as
//!   long as the outside is not pinched there too — `check` reads a tet mesh's boundary as one
//!   surface whose pieces meeting only at a point or an edge are separate; the repair sees to
//!   that as well.
//! - **Embedded.** Faces of the grid meet only in grid edges and corners, which are edges and
//!   points of the triangulation.
//! - **Volume.** Each region's surface encloses exactly its voxels' volume (after the repair).
//!
//! Points are in the image's world coordinates. For an oblique image (a rotated voxel grid) the
//! corners of one flat face are then coplanar only up to rounding; to mesh, extract in the
//! image's frame ([`LabelImage::to_frame`]: axis-aligned unless the grid is sheared) and map the
//! mesh to world at the end ([`super::map_points`]), as `biotet mesh IMAGE` does. A sheared
//! grid's faces are parallelograms, split along their shorter diagonals.
//!
//! The surface is staircase-shaped; its smoothing belongs to the surface stage (issue 20:
//! `surface::improve` within a tolerance, by default [`LabelImage::default_surface_tolerance`],
//! half the smallest voxel spacing), which takes this [`SurfaceMesh`] as it takes any labelled
//! surface.

use rustc_hash::FxHashMap;

use super::LabelImage;
pub use super::repair::make_manifold;
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
    // Not a scaled permutation: the frame of a sheared grid ([`LabelImage::to_frame`]).
    let sheared = !img.is_scaled_permutation();
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
                    // A sheared grid's face is a parallelogram: its shorter diagonal is the
                    // Delaunay one (the angles facing it are the acute ones).
                    let even = if sheared {
                        let p = q.map(|x| mesh.points[x as usize]);
                        let d = |a: usize, b: usize| {
                            (0..3).map(|k| (p[a][k] - p[b][k]).powi(2)).sum::<f64>()
                        };
                        let (d02, d13) = (d(0, 2), d(1, 3));
                        if d02 == d13 { top % 2 == 0 } else { d13 < d02 }
                    } else {
                        top % 2 == 0
                    };
                    if even {
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
