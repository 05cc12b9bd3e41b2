//! Labelled 3D images (segmentations) and the surface of their labels.
//!
//! A [`LabelImage`] holds one integer label per voxel and the affine map from voxel indices to
//! world coordinates. Voxel `(i, j, k)` is the box `[i − ½, i + ½] × [j − ½, j + ½] × [k − ½, k + ½]`
//! in index space, its centre at `voxel_to_world · (i, j, k, 1)` (the convention of NIfTI, MGH,
//! NRRD's cell-less samples and ITK). The readers in `biotet-io::image` give world coordinates
//! in RAS+ millimetres (see there).
//!
//! - [`labels`]: which labels are regions (`--labels`, `--merge`, `--outside`), 6-connected
//!   components, small islands merged into their surroundings.
//! - [`extract`]: the voxel-face surface of all label interfaces, one conforming labelled
//!   [`crate::SurfaceMesh`], each region closed and manifold.
//! - [`repair`]: voxels relabelled so that every label is manifold at every grid corner,
//!   keeping each region's connected components.
//! - [`surface`]: both, on an image, with the summary the reports print (shared by the CLI and
//!   the Python package).

use crate::geom::vec3::det3;

pub mod extract;
pub mod labels;
pub mod repair;
pub mod surface;

/// Apply an affine map (the last row `[0, 0, 0, 1]`) to points in place.
pub fn map_points(m: &[[f64; 4]; 4], points: &mut [[f64; 3]]) {
    for p in points.iter_mut() {
        *p = std::array::from_fn(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3]);
    }
}

/// A labelled 3D image: `labels[i + dims[0]·(j + dims[1]·k)]` is the label of voxel `(i, j, k)`.
#[derive(Debug, Clone, PartialEq)]
pub struct LabelImage {
    /// Voxels along each index axis.
    pub dims: [usize; 3],
    /// Voxel index `(i, j, k, 1)` → world (the last row is `[0, 0, 0, 1]`).
    pub voxel_to_world: [[f64; 4]; 4],
    /// One label per voxel, `i` fastest.
    pub labels: Vec<u32>,
}

/// Why a label image cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImageError {
    /// `labels.len()` is not `dims[0]·dims[1]·dims[2]`, or a dimension is zero.
    #[error("image of {dims:?} voxels holds {len} labels")]
    Size {
        /// The dimensions.
        dims: [usize; 3],
        /// The number of labels.
        len: usize,
    },
    /// The affine is not finite, not affine, or singular.
    #[error("voxel-to-world matrix {0:?} is not a finite invertible affine map")]
    Affine(Box<[[f64; 4]; 4]>),
}

impl LabelImage {
    /// A checked image.
    pub fn new(
        dims: [usize; 3],
        voxel_to_world: [[f64; 4]; 4],
        labels: Vec<u32>,
    ) -> Result<LabelImage, ImageError> {
        let n = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
        if dims.contains(&0) || n != Some(labels.len()) {
            return Err(ImageError::Size {
                dims,
                len: labels.len(),
            });
        }
        let img = LabelImage {
            dims,
            voxel_to_world,
            labels,
        };
        let m = &img.voxel_to_world;
        let finite = m.iter().flatten().all(|x| x.is_finite());
        let det = img.determinant();
        if !finite || m[3] != [0.0, 0.0, 0.0, 1.0] || det == 0.0 || !det.is_finite() {
            return Err(ImageError::Affine(Box::new(img.voxel_to_world)));
        }
        Ok(img)
    }

    /// An axis-aligned image with the given spacing and the centre of voxel 0 at `origin`.
    pub fn axis_aligned(
        dims: [usize; 3],
        spacing: [f64; 3],
        origin: [f64; 3],
        labels: Vec<u32>,
    ) -> Result<LabelImage, ImageError> {
        let mut m = [[0.0; 4]; 4];
        for a in 0..3 {
            m[a][a] = spacing[a];
            m[a][3] = origin[a];
        }
        m[3][3] = 1.0;
        LabelImage::new(dims, m, labels)
    }

    /// Number of voxels.
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    /// Whether the image has no voxels (never, for a checked image).
    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    /// Linear index of voxel `(i, j, k)`.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// The label of voxel `(i, j, k)`.
    #[inline]
    pub fn get(&self, i: usize, j: usize, k: usize) -> u32 {
        self.labels[self.index(i, j, k)]
    }

    /// World coordinates of a point given in (fractional) voxel indices.
    pub fn world(&self, p: [f64; 3]) -> [f64; 3] {
        let m = &self.voxel_to_world;
        std::array::from_fn(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3])
    }

    /// Determinant of the linear part: the volume of one voxel, signed (negative when the
    /// index axes are left-handed in world space).
    pub fn determinant(&self) -> f64 {
        let m = &self.voxel_to_world;
        det3(&std::array::from_fn(|r| [m[r][0], m[r][1], m[r][2]]))
    }

    /// Whether the voxel-to-world map is a scaled permutation (each voxel axis along a world
    /// axis): no frame is needed ([`Self::to_frame`]).
    pub fn is_scaled_permutation(&self) -> bool {
        let m = &self.voxel_to_world;
        (0..3).all(|c| (0..3).filter(|&r| m[r][c] != 0.0).count() == 1)
    }

    /// The volume of one voxel (world units cubed).
    pub fn voxel_volume(&self) -> f64 {
        self.determinant().abs()
    }

    /// The length of each index axis in world units (the voxel spacings).
    pub fn spacing(&self) -> [f64; 3] {
        let m = &self.voxel_to_world;
        std::array::from_fn(|c| (0..3).map(|r| m[r][c] * m[r][c]).sum::<f64>().sqrt())
    }

    /// The default surface tolerance of issue 20's surface stage for this image: half the
    /// smallest voxel spacing.
    pub fn default_surface_tolerance(&self) -> f64 {
        0.5 * self.spacing().into_iter().fold(f64::INFINITY, f64::min)
    }

    /// For an oblique image (a voxel-to-world map that is not a scaled permutation), split the
    /// map into a *frame* and a frame → world map `M` (returned) with `world = M · frame`, whose
    /// linear part is a rotation (to rounding), so that angles and distances measured in the
    /// frame are the world's. `None` when the map is already axis-aligned.
    ///
    /// - Orthogonal voxel axes (a rotated grid): the frame is axis-aligned, `voxel_to_world`
    ///   becomes `diag(±spacing)` (no offset; x negated when the map reverses orientation).
    ///   Why: the grid corners of one voxel face are exactly coplanar there (they share one
    ///   coordinate), but not after a rotation in floating point, where the staircase
    ///   surface's flat parts become slightly folded and a mesher may fill the fold with a flat
    ///   tet.
    /// - Sheared voxel axes (a CT gantry tilt, say): no frame is both axis-aligned and
    ///   isometric to world, and an axis-aligned one would shear the mesh made in it on the way
    ///   out (its angles, and the surface stage's distances, measured in the wrong metric). The
    ///   frame is the symmetric factor `P` of the polar decomposition `A = R·P` of the map's
    ///   linear part (`R` a rotation; with x negated first when `A` reverses orientation), and
    ///   `M` is `R` with the offset.
    ///
    /// Axes count as orthogonal when every pair's cosine is under 1e-6: a map stored in single
    /// precision (NIfTI's) is orthogonal to about 1e-7.
    pub fn to_frame(&mut self) -> Option<[[f64; 4]; 4]> {
        if self.is_scaled_permutation() {
            return None;
        }
        let m = self.voxel_to_world;
        let s = self.spacing();
        let sign = if self.determinant() < 0.0 { -1.0 } else { 1.0 };
        let orthogonal = (0..3).all(|a| {
            let b = (a + 1) % 3;
            let d: f64 = (0..3).map(|r| m[r][a] * m[r][b]).sum();
            d.abs() < 1e-6 * s[a] * s[b]
        });
        let mut f = [[0.0; 4]; 4];
        let mut to_world = [[0.0; 4]; 4];
        if orthogonal {
            let scale = [sign * s[0], s[1], s[2]];
            for r in 0..3 {
                f[r][r] = scale[r];
                for c in 0..3 {
                    to_world[r][c] = m[r][c] / scale[c];
                }
            }
        } else {
            // The rotation of the map with x turned to positive determinant; the frame is what
            // it leaves, Rᵀ·A (symmetric but for the sign of its first column).
            let a: [[f64; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|c| m[r][c]));
            let turned = std::array::from_fn(|r| {
                std::array::from_fn(|c| if c == 0 { sign * a[r][0] } else { a[r][c] })
            });
            let rot = polar_rotation(turned);
            for r in 0..3 {
                for c in 0..3 {
                    to_world[r][c] = rot[r][c];
                    f[r][c] = (0..3).map(|k| rot[k][r] * a[k][c]).sum();
                }
            }
        }
        for r in 0..3 {
            to_world[r][3] = m[r][3];
        }
        f[3][3] = 1.0;
        to_world[3][3] = 1.0;
        self.voxel_to_world = f;
        Some(to_world)
    }

    /// Voxels per label, sorted by label.
    pub fn counts(&self) -> Vec<(u32, usize)> {
        let mut m: rustc_hash::FxHashMap<u32, usize> = Default::default();
        for &l in &self.labels {
            *m.entry(l).or_default() += 1;
        }
        let mut v: Vec<(u32, usize)> = m.into_iter().collect();
        v.sort_unstable();
        v
    }
}

/// The rotation `R` of the polar decomposition `A = R·P` (`P` symmetric positive definite) of
/// an invertible 3×3 matrix with positive determinant: Newton's iteration `X ← (γX + X⁻ᵀ/γ)/2`
/// with determinant scaling (`γ = |det X|^(−1/3)`), which converges quadratically; stopped when
/// a step changes no entry by more than 1e-15 of the matrix's size.
fn polar_rotation(a: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut x = a;
    for _ in 0..100 {
        let det = det3(&x);
        // X⁻ᵀ is the cofactor matrix over the determinant.
        let cof = |r: usize, c: usize| {
            let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
            let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
            x[r1][c1] * x[r2][c2] - x[r1][c2] * x[r2][c1]
        };
        let g = det.abs().powf(-1.0 / 3.0);
        let next: [[f64; 3]; 3] = std::array::from_fn(|r| {
            std::array::from_fn(|c| 0.5 * (g * x[r][c] + cof(r, c) / (g * det)))
        });
        let size = next.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let step = (0..9).fold(0.0f64, |m, k| {
            m.max((next[k / 3][k % 3] - x[k / 3][k % 3]).abs())
        });
        x = next;
        if step <= 1e-15 * size {
            break;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_then_world_is_the_image_map() {
        let (c, s) = (0.6f64.cos(), 0.6f64.sin());
        let m = [
            [-c, -s * 1.5, 0.0, 10.0],
            [-s, c * 1.5, 0.0, -3.0],
            [0.0, 0.0, 0.75, 2.0],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let mut img = LabelImage::new([2, 2, 2], m, vec![1; 8]).unwrap();
        let orig = img.clone();
        let to_world = img.to_frame().unwrap();
        let mut p = vec![img.world([0.5, -0.5, 1.5])];
        map_points(&to_world, &mut p);
        let want = orig.world([0.5, -0.5, 1.5]);
        for r in 0..3 {
            assert!((p[0][r] - want[r]).abs() < 1e-12);
        }
        assert!(img.determinant() < 0.0); // the frame keeps the orientation; M is a rotation
        let lin = LabelImage::new([1, 1, 1], to_world, vec![0]).unwrap();
        assert!((lin.determinant() - 1.0).abs() < 1e-12);
        assert!(img.clone().to_frame().is_none());
    }

    /// Thick sheared slices (0.5 × 0.5 × 3 voxels, slices tilted 25°, the grid turned): the
    /// polar factor is a rotation and what it leaves is symmetric positive definite.
    #[test]
    fn polar_rotation_of_a_thick_tilted_grid() {
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let t = 25f64.to_radians().tan() * 3.0;
        let a0 = [[0.5, 0.0, 0.0], [0.0, 0.5, t], [0.0, 0.0, 3.0]];
        let turn = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        let a: [[f64; 3]; 3] = std::array::from_fn(|r| {
            std::array::from_fn(|k| (0..3).map(|j| turn[r][j] * a0[j][k]).sum())
        });
        let rot = polar_rotation(a);
        let p: [[f64; 3]; 3] = std::array::from_fn(|r| {
            std::array::from_fn(|k| (0..3).map(|j| rot[j][r] * a[j][k]).sum())
        });
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|r| rot[r][i] * rot[r][j]).sum();
                assert!(
                    (d - f64::from(u8::from(i == j))).abs() < 1e-14,
                    "RᵀR {i}{j}: {d}"
                );
                assert!((p[i][j] - p[j][i]).abs() < 1e-13, "P {p:?}");
            }
            assert!(p[i][i] > 0.0);
        }
    }
}
