//! numpy arrays to the library's types and back. Inputs are read through read-only views and
//! checked (shape, indices, labels) with messages naming the array; outputs move the library's
//! vectors into numpy without a copy.

use biotet::mesh::shells::Part;
use biotet::sizing_grid::ScalarGrid;
use biotet::{SurfaceMesh, TetMesh};
use numpy::ndarray::Array2;
use numpy::{
    Element, IntoPyArray, PyArray2, PyReadonlyArray, PyReadonlyArray2, PyReadonlyArray3,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A surface as given: closed shells with optional labels (assembled as `biotet mesh` does),
/// or triangles with the region on each side.
pub enum Surface {
    Parts(Vec<Part>, String),
    Sided(SurfaceMesh, String),
}

impl Surface {
    pub fn name(&self) -> &str {
        match self {
            Surface::Parts(_, n) | Surface::Sided(_, n) => n,
        }
    }
}

fn shape_error(what: &str, want: usize, shape: &[usize]) -> PyErr {
    PyValueError::new_err(format!(
        "{what} must be an array of shape (n, {want}), not {shape:?}"
    ))
}

/// Points from an (n, 3) float64 array.
pub fn points_from(a: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<[f64; 3]>> {
    let v = a.as_array();
    if v.ncols() != 3 {
        return Err(shape_error("points", 3, v.shape()));
    }
    Ok(v.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect())
}

/// Integer arrays as numpy holds them: int32 (what biotet returns) or int64 (numpy's default
/// elsewhere), read in place either way.
macro_rules! int_array {
    ($name:ident, $dim:ty, $what:literal) => {
        #[doc = $what]
        #[derive(FromPyObject)]
        pub enum $name<'py> {
            I32(PyReadonlyArray<'py, i32, $dim>),
            I64(PyReadonlyArray<'py, i64, $dim>),
        }

        impl $name<'_> {
            fn shape(&self) -> &[usize] {
                match self {
                    $name::I32(a) => a.shape(),
                    $name::I64(a) => a.shape(),
                }
            }

            /// Every value, in logical order, as i64.
            fn values(&self) -> Box<dyn Iterator<Item = i64> + '_> {
                match self {
                    $name::I32(a) => Box::new(a.as_array().into_iter().map(|&x| x as i64)),
                    $name::I64(a) => Box::new(a.as_array().into_iter().copied()),
                }
            }
        }
    };
}

int_array!(Ints2, numpy::Ix2, "An (n, k) int32 or int64 array.");
int_array!(Ints1, numpy::Ix1, "An (n,) int32 or int64 array.");

/// Index rows of width `N`, each in `0..n_points`.
fn indices_from<const N: usize>(
    what: &str,
    a: &Ints2<'_>,
    n_points: usize,
) -> PyResult<Vec<[u32; N]>> {
    let shape = a.shape();
    if shape[1] != N {
        return Err(shape_error(what, N, shape));
    }
    let mut out = Vec::with_capacity(shape[0]);
    let mut row = [0u32; N];
    for (at, x) in a.values().enumerate() {
        if x < 0 || x as u64 >= n_points as u64 {
            return Err(PyValueError::new_err(format!(
                "{what}[{}] refers to point {x}, outside 0..{n_points}",
                at / N
            )));
        }
        row[at % N] = x as u32;
        if at % N == N - 1 {
            out.push(row);
        }
    }
    Ok(out)
}

/// Labels, each in `0..2³²`.
fn labels_from(what: &str, a: impl Iterator<Item = i64>) -> PyResult<Vec<u32>> {
    a.enumerate()
        .map(|(i, l)| {
            biotet_io::checked_label(l.into()).ok_or_else(|| {
                PyValueError::new_err(format!("{what}[{i}] = {l} is not a label in 0..2**31"))
            })
        })
        .collect()
}

/// A surface from points, triangles and either shell labels or side labels.
pub fn surface_from(
    points: &PyReadonlyArray2<'_, f64>,
    triangles: &Ints2<'_>,
    shell_labels: Option<Vec<u32>>,
    side_labels: Option<&Ints2<'_>>,
    name: String,
) -> PyResult<Surface> {
    let pts = points_from(points)?;
    let tris = indices_from::<3>("triangles", triangles, pts.len())?;
    let n = tris.len();
    match side_labels {
        Some(sides) => {
            if sides.shape() != [n, 2] {
                return Err(PyValueError::new_err(format!(
                    "side_labels must have shape ({n}, 2), not {:?}",
                    sides.shape()
                )));
            }
            let l = labels_from("side_labels", sides.values())?;
            let mut s = SurfaceMesh::closed(pts, tris, 1);
            s.sides = l.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
            Ok(Surface::Sided(s, name))
        }
        None => Ok(Surface::Parts(
            vec![Part {
                surface: SurfaceMesh::closed(pts, tris, 1),
                labels: shell_labels,
            }],
            name,
        )),
    }
}

/// The values of a 3D array `a[i, j, k]` with `i` fastest (the order of `LabelImage` and
/// `ScalarGrid`) and its shape: one copy, a `memcpy` when the array is Fortran-ordered (as
/// nibabel's are).
pub fn volume_from<T: Element + Copy>(a: &PyReadonlyArray3<'_, T>) -> (Vec<T>, [usize; 3]) {
    let v = a.as_array();
    let dims = [v.shape()[0], v.shape()[1], v.shape()[2]];
    // Axes reversed, the logical order is `i` fastest; contiguous when `a` is Fortran-ordered.
    let t = v.reversed_axes();
    let values = match t.as_slice() {
        Some(s) => s.to_vec(),
        None => t.iter().copied().collect(),
    };
    (values, dims)
}

/// A size field from samples `values[i, j, k]` at `affine · (i, j, k, 1)`: the affine's columns
/// give each grid axis's direction and spacing.
pub fn grid_from(
    values: &PyReadonlyArray3<'_, f64>,
    affine: &[[f64; 4]; 4],
) -> PyResult<ScalarGrid> {
    let (values, dims) = volume_from(values);
    let spacing: [f64; 3] = std::array::from_fn(|c| {
        (0..3)
            .map(|r| affine[r][c] * affine[r][c])
            .sum::<f64>()
            .sqrt()
    });
    let direction: [[f64; 3]; 3] =
        std::array::from_fn(|r| std::array::from_fn(|c| affine[r][c] / spacing[c]));
    let origin = [affine[0][3], affine[1][3], affine[2][3]];
    ScalarGrid::new(dims, origin, spacing, direction, values)
        .map_err(|e| PyValueError::new_err(format!("size_field: {e}")))
}

/// A tet mesh from points, tets and labels (adjacency rebuilt). Tets stored the other way
/// round throughout are turned, as the file readers do ([`biotet_io::orient_tets`]).
pub fn mesh_from(
    points: &PyReadonlyArray2<'_, f64>,
    tets: &Ints2<'_>,
    labels: &Ints1<'_>,
) -> PyResult<TetMesh> {
    let pts = points_from(points)?;
    // As the file readers refuse them: no measure or move means anything at such a point.
    if let Some(i) = pts.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(PyValueError::new_err(format!(
            "points: point {i} has a non-finite coordinate {:?}",
            pts[i]
        )));
    }
    let mut t = indices_from::<4>("tets", tets, pts.len())?;
    biotet_io::orient_tets(&pts, &mut t);
    let n = labels.shape()[0];
    if n != t.len() {
        return Err(PyValueError::new_err(format!(
            "labels has {n} entries for {} tets",
            t.len()
        )));
    }
    Ok(TetMesh::new(
        pts,
        t,
        labels_from("labels", labels.values())?,
    ))
}

/// Reinterpret indices as int32 (numpy's default index type) without a copy: every index is
/// below 2³¹ since the library numbers points in u32 and no mesh has 2³¹ points.
fn as_i32(v: Vec<u32>) -> Vec<i32> {
    if v.iter().any(|&x| x > i32::MAX as u32) {
        return v.into_iter().map(|x| x as i32).collect();
    }
    let mut v = std::mem::ManuallyDrop::new(v);
    // SAFETY: u32 and i32 have the same size and alignment, every value fits, and the
    // allocation is handed over whole (pointer, length, capacity).
    unsafe { Vec::from_raw_parts(v.as_mut_ptr() as *mut i32, v.len(), v.capacity()) }
}

fn rows<T: numpy::Element>(py: Python<'_>, flat: Vec<T>, width: usize) -> Bound<'_, PyArray2<T>> {
    let n = flat.len() / width;
    Array2::from_shape_vec((n, width), flat)
        .expect("rows of equal width")
        .into_pyarray(py)
}

/// Points, tets and labels moved into numpy, with the report text.
pub fn mesh_out(py: Python<'_>, mesh: TetMesh, report: String) -> crate::MeshOut<'_> {
    let TetMesh {
        points,
        tets,
        labels,
        ..
    } = mesh;
    (
        rows(py, points.into_flattened(), 3),
        rows(py, as_i32(tets.into_flattened()), 4),
        as_i32(labels).into_pyarray(py),
        report,
    )
}

/// A surface's points, triangles and side labels moved into numpy.
pub fn surface_out(py: Python<'_>, s: SurfaceMesh) -> crate::SurfaceOut<'_> {
    (
        rows(py, s.points.into_flattened(), 3),
        rows(py, as_i32(s.triangles.into_flattened()), 3),
        rows(py, as_i32(s.sides.into_flattened()), 2),
    )
}
