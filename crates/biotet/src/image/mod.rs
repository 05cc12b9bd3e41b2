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
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
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
    /// map into an axis-aligned *frame* and a frame → world map: sets `voxel_to_world` to
    /// `diag(±spacing)` (no offset; x negated when the map reverses orientation) and returns
    /// the map `M` with `world = M · frame`, whose linear part has positive
    /// determinant (a rotation when the voxel axes are orthogonal). `None` when the map is
    /// already axis-aligned.
    ///
    /// Why: the grid corners of one voxel face are exactly coplanar in an axis-aligned frame
    /// (they share one coordinate), but not after a rotation in floating point, where the
    /// staircase surface's flat parts become slightly folded and a mesher may fill the fold with
    /// a flat tet. Meshing in the frame and mapping the mesh to world at the end keeps flat
    /// parts flat and, the map being a rotation, every angle.
    pub fn to_frame(&mut self) -> Option<[[f64; 4]; 4]> {
        let m = self.voxel_to_world;
        let aligned = (0..3).all(|c| (0..3).filter(|&r| m[r][c] != 0.0).count() == 1);
        if aligned {
            return None;
        }
        let s = self.spacing();
        let sign = if self.determinant() < 0.0 { -1.0 } else { 1.0 };
        let scale = [sign * s[0], s[1], s[2]];
        let mut f = [[0.0; 4]; 4];
        let mut to_world = [[0.0; 4]; 4];
        for r in 0..3 {
            f[r][r] = scale[r];
            for c in 0..3 {
                to_world[r][c] = m[r][c] / scale[c];
            }
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
}
