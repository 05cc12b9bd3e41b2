//! A scalar field sampled on a regular 3D grid and interpolated anywhere: the representation of
//! a user-supplied mesh sizing function (a desired edge length per point of space).
//!
//! The grid is the one of medical images and VTK `ImageData`: sample `(i, j, k)` sits at
//!
//! ```text
//! world(i, j, k) = origin + direction · (spacing[0]·i, spacing[1]·j, spacing[2]·k)
//! ```
//!
//! where the columns of `direction` are the directions of the grid's axes in world space
//! (usually orthonormal, but any invertible matrix is accepted). [`ScalarGrid::value_at`]
//! interpolates trilinearly between the eight surrounding samples, and clamps points outside the
//! grid to it (see there).

use thiserror::Error;

use crate::geom::vec3::det3;

/// Why a [`ScalarGrid`] cannot be built from the given parts.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GridError {
    /// A dimension is zero.
    #[error(
        "grid dimensions {dims:?}: axis {axis} has no samples (each dimension must be at least 1)"
    )]
    EmptyAxis {
        /// The dimensions.
        dims: [usize; 3],
        /// The first axis (0, 1 or 2) with dimension 0.
        axis: usize,
    },
    /// The number of samples does not fit `usize`.
    #[error("grid dimensions {dims:?}: too many samples")]
    TooLarge {
        /// The dimensions.
        dims: [usize; 3],
    },
    /// `values` does not hold one value per sample.
    #[error(
        "{got} values for a {}×{}×{} grid, expected {expected}",
        .dims[0], .dims[1], .dims[2]
    )]
    ValueCount {
        /// The dimensions.
        dims: [usize; 3],
        /// `dims[0]·dims[1]·dims[2]`.
        expected: usize,
        /// `values.len()`.
        got: usize,
    },
    /// A spacing is zero, negative, NaN or infinite.
    #[error("spacing {spacing:?}: axis {axis} is not a finite positive number")]
    BadSpacing {
        /// The spacing.
        spacing: [f64; 3],
        /// The first offending axis.
        axis: usize,
    },
    /// The origin has a NaN or infinite coordinate.
    #[error("origin {0:?} is not finite")]
    NonFiniteOrigin([f64; 3]),
    /// The direction matrix has a NaN or infinite entry.
    #[error("direction matrix {0:?} is not finite")]
    NonFiniteDirection([[f64; 3]; 3]),
    /// The direction matrix is singular (or so close to it that the grid's axes are
    /// numerically coplanar).
    #[error("direction matrix {0:?} is singular: the grid axes do not span 3D space")]
    SingularDirection([[f64; 3]; 3]),
    /// A grid corner lies at an infinite world position (huge spacing or origin).
    #[error("the grid's extent overflows: a corner has an infinite world coordinate")]
    NonFiniteExtent,
    /// A value is NaN or infinite.
    #[error("value {index} (sample {ijk:?}) is {value}, not a finite number")]
    NonFiniteValue {
        /// Index of the value in `values`.
        index: usize,
        /// The sample `(i, j, k)` it belongs to.
        ijk: [usize; 3],
        /// The value.
        value: f64,
    },
}

/// The identity matrix, the default `direction`.
pub const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A scalar field sampled on a regular 3D grid:
/// `world(i,j,k) = origin + direction · (spacing ∘ (i,j,k))`.
///
/// Build it with [`ScalarGrid::new`], which validates the parts. The fields are public for
/// reading; [`ScalarGrid::value_at`] relies on a transform cached by `new`, so a grid whose
/// `dims`, `origin`, `spacing` or `direction` have been changed must be rebuilt with `new`
/// (changing `values` in place is fine as long as they stay finite and keep their length).
#[derive(Debug, Clone, PartialEq)]
pub struct ScalarGrid {
    /// Number of samples along each grid axis (each ≥ 1).
    pub dims: [usize; 3],
    /// World position of sample `(0, 0, 0)`.
    pub origin: [f64; 3],
    /// Distance between neighbouring samples along each grid axis (finite, > 0).
    pub spacing: [f64; 3],
    /// Rows of the matrix whose columns are the grid axes' world directions ([`IDENTITY`] for
    /// an axis-aligned grid). Finite and invertible.
    pub direction: [[f64; 3]; 3],
    /// The samples, x fastest: the value at `(i, j, k)` is
    /// `values[i + dims[0] * (j + dims[1] * k)]`. All finite.
    pub values: Vec<f64>,
    /// Inverse of `direction · diag(spacing)`: world offsets from `origin` to continuous grid
    /// indices.
    inv: [[f64; 3]; 3],
}

/// The inverse of `m` by cofactors, `None` when singular or not finite.
fn inverse3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let d = det3(m);
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    let c =
        |r0: usize, c0: usize, r1: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    let adj = [
        [c(1, 1, 2, 2), -c(0, 1, 2, 2), c(0, 1, 1, 2)],
        [-c(1, 0, 2, 2), c(0, 0, 2, 2), -c(0, 0, 1, 2)],
        [c(1, 0, 2, 1), -c(0, 0, 2, 1), c(0, 0, 1, 1)],
    ];
    let inv = adj.map(|row| row.map(|x| x / d));
    inv.iter().flatten().all(|x| x.is_finite()).then_some(inv)
}

impl ScalarGrid {
    /// A grid from its parts, validated: every dimension ≥ 1, one value per sample, spacings
    /// finite and positive, origin finite, direction finite and invertible (its normalised
    /// columns must not be nearly coplanar: `|det| > 1e-9` after scaling each column to unit
    /// length), a finite world extent, and finite values.
    pub fn new(
        dims: [usize; 3],
        origin: [f64; 3],
        spacing: [f64; 3],
        direction: [[f64; 3]; 3],
        values: Vec<f64>,
    ) -> Result<ScalarGrid, GridError> {
        if let Some(axis) = dims.iter().position(|&n| n == 0) {
            return Err(GridError::EmptyAxis { dims, axis });
        }
        let expected = dims[0]
            .checked_mul(dims[1])
            .and_then(|x| x.checked_mul(dims[2]))
            .ok_or(GridError::TooLarge { dims })?;
        if values.len() != expected {
            return Err(GridError::ValueCount {
                dims,
                expected,
                got: values.len(),
            });
        }
        if let Some(axis) = spacing.iter().position(|&s| !(s.is_finite() && s > 0.0)) {
            return Err(GridError::BadSpacing { spacing, axis });
        }
        if origin.iter().any(|x| !x.is_finite()) {
            return Err(GridError::NonFiniteOrigin(origin));
        }
        if direction.iter().flatten().any(|x| !x.is_finite()) {
            return Err(GridError::NonFiniteDirection(direction));
        }
        // Singularity test on the direction with unit columns: scale-free, so a direction given
        // in any unit is judged by the angles between the axes alone.
        let mut unit = direction;
        for c in 0..3 {
            let norm = (0..3)
                .map(|r| direction[r][c] * direction[r][c])
                .sum::<f64>()
                .sqrt();
            if !(norm > 0.0 && norm.is_finite()) {
                return Err(GridError::SingularDirection(direction));
            }
            for row in unit.iter_mut() {
                row[c] /= norm;
            }
        }
        if det3(&unit).abs() <= 1e-9 {
            return Err(GridError::SingularDirection(direction));
        }
        let m: [[f64; 3]; 3] =
            std::array::from_fn(|r| std::array::from_fn(|c| direction[r][c] * spacing[c]));
        let inv = inverse3(&m).ok_or(GridError::SingularDirection(direction))?;
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            let i = index % dims[0];
            let j = index / dims[0] % dims[1];
            let k = index / dims[0] / dims[1];
            return Err(GridError::NonFiniteValue {
                index,
                ijk: [i, j, k],
                value: values[index],
            });
        }
        let grid = ScalarGrid {
            dims,
            origin,
            spacing,
            direction,
            values,
            inv,
        };
        let b = grid.bounds();
        if b.iter().flatten().any(|x| !x.is_finite()) {
            return Err(GridError::NonFiniteExtent);
        }
        Ok(grid)
    }

    /// An axis-aligned grid (`direction` = [`IDENTITY`]); see [`ScalarGrid::new`].
    pub fn axis_aligned(
        dims: [usize; 3],
        origin: [f64; 3],
        spacing: [f64; 3],
        values: Vec<f64>,
    ) -> Result<ScalarGrid, GridError> {
        ScalarGrid::new(dims, origin, spacing, IDENTITY, values)
    }

    /// Number of samples, `dims[0]·dims[1]·dims[2]`.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Always `false`: a grid has at least one sample. (For symmetry with [`ScalarGrid::len`].)
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The value of sample `(i, j, k)` (panics when out of range).
    pub fn get(&self, i: usize, j: usize, k: usize) -> f64 {
        assert!(i < self.dims[0] && j < self.dims[1] && k < self.dims[2]);
        self.values[i + self.dims[0] * (j + self.dims[1] * k)]
    }

    /// World position of sample `(i, j, k)` (any indices, also fractional or outside the grid).
    pub fn world(&self, ijk: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|r| {
            self.origin[r]
                + (0..3)
                    .map(|c| self.direction[r][c] * self.spacing[c] * ijk[c])
                    .sum::<f64>()
        })
    }

    /// Continuous grid indices of a world point: the inverse of [`ScalarGrid::world`].
    pub fn index_of(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [
            p[0] - self.origin[0],
            p[1] - self.origin[1],
            p[2] - self.origin[2],
        ];
        self.inv
            .map(|row| row[0] * d[0] + row[1] * d[1] + row[2] * d[2])
    }

    /// The field at world point `p`, by trilinear interpolation of the eight samples around it.
    ///
    /// Outside the grid the field is clamped: each continuous grid index is clamped to
    /// `[0, dims - 1]` separately, so a point beyond a face takes the value at its projection
    /// onto that face along the grid axis, and a point beyond a corner takes the corner's value
    /// (for a rotated grid the clamping is along the grid's own axes, not the world axes). An
    /// axis with a single sample is constant along it. Trilinear interpolation reproduces
    /// fields linear in the world coordinates exactly (up to rounding) inside the grid. The
    /// result lies between [`ScalarGrid::min_value`] and [`ScalarGrid::max_value`] (up to
    /// rounding); a point with
    /// a NaN coordinate gives NaN (infinite coordinates give a boundary value or NaN). Never
    /// panics.
    #[inline]
    pub fn value_at(&self, p: [f64; 3]) -> f64 {
        let u = self.index_of(p);
        let strides = [1, self.dims[0], self.dims[0] * self.dims[1]];
        let mut base = 0usize;
        let mut step = [0usize; 3];
        let mut t = [0.0f64; 3];
        for a in 0..3 {
            let n = self.dims[a];
            if n == 1 {
                // NaN stays NaN through the interpolation below.
                t[a] = if u[a].is_nan() { f64::NAN } else { 0.0 };
                continue;
            }
            let hi = (n - 1) as f64;
            let x = u[a].clamp(0.0, hi); // NaN stays NaN
            // `as usize` saturates (NaN → 0), and `min` keeps one cell to the right.
            let i0 = (x.floor() as usize).min(n - 2);
            t[a] = x - i0 as f64;
            base += i0 * strides[a];
            step[a] = strides[a];
        }
        let v = |di: usize, dj: usize, dk: usize| {
            self.values[base + di * step[0] + dj * step[1] + dk * step[2]]
        };
        let lerp = |a: f64, b: f64, t: f64| a + t * (b - a);
        let c00 = lerp(v(0, 0, 0), v(1, 0, 0), t[0]);
        let c10 = lerp(v(0, 1, 0), v(1, 1, 0), t[0]);
        let c01 = lerp(v(0, 0, 1), v(1, 0, 1), t[0]);
        let c11 = lerp(v(0, 1, 1), v(1, 1, 1), t[0]);
        let c0 = lerp(c00, c10, t[1]);
        let c1 = lerp(c01, c11, t[1]);
        lerp(c0, c1, t[2])
    }

    /// The smallest sample value.
    pub fn min_value(&self) -> f64 {
        self.values.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// The largest sample value.
    pub fn max_value(&self) -> f64 {
        self.values
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// The world-space axis-aligned bounding box `[min, max]` of the grid's eight corner
    /// samples (for a rotated grid, a box containing the rotated grid).
    pub fn bounds(&self) -> [[f64; 3]; 2] {
        let mut b = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
        for corner in 0..8 {
            let ijk: [f64; 3] = std::array::from_fn(|a| {
                if corner >> a & 1 == 1 {
                    (self.dims[a] - 1) as f64
                } else {
                    0.0
                }
            });
            let w = self.world(ijk);
            for a in 0..3 {
                b[0][a] = b[0][a].min(w[a]);
                b[1][a] = b[1][a].max(w[a]);
            }
        }
        b
    }
}
