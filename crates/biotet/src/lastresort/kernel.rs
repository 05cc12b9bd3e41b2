//! A point strictly inside the kernel of a closed cell: the fallback of boundary recovery when
//! no fill of a cell with its own points exists (a Schönhardt polyhedron, a cube whose face
//! diagonals twist).
//!
//! A cell is a closed polyhedron given by oriented triangles whose right-hand normals point
//! into it. Its kernel is the set of points that see every face from inside, the intersection
//! of the faces' inner half-spaces. From a point strictly inside the kernel, the cone over the
//! faces (one tet per face) is a valid fill: every tet is positively oriented, and since every
//! ray from the point leaves the cell exactly once, the tets do not overlap.
//!
//! The point is searched in floating point (maximise the smallest distance to the face planes,
//! the Chebyshev centre of the kernel, by min-norm ascent, the direction smoothing uses), then
//! decided exactly: it is returned only if `orient3d` puts it strictly on the inner side of
//! every face. Of the first such point on the way and the deepest, the one whose cone has fewer
//! tets under 10° (then the larger smallest dihedral angle) is returned. Where the ascent finds
//! no point (it is first-order and stalls in a thin kernel of a long cell), the caller may ask
//! for the Chebyshev centre by linear program, decided exactly the same way. A cell whose kernel
//! is empty, or too thin for floating point, gives `None`.

use crate::geom::filter::orient3d;
use crate::geom::predicates::{Sign, in_exact_range};
use crate::geom::vec3::{add, cross, dot, norm2, scale, sub};
use crate::quality::tet::min_dihedral_deg;
use crate::smooth::ascent::{MAX_ACTIVE, min_norm_point};

type P3 = [f64; 3];

/// Ascent iterations at most (each is linear in the number of faces).
const MAX_STEPS: usize = 200;

/// A point strictly inside the kernel of the cell bounded by `faces` (indices into `points`,
/// normals into the cell), or `None`. Exact: every returned point passes `orient3d > 0` against
/// every face.
/// With `exact_lp`, where the ascent finds no point the linear program is solved too (see
/// [`chebyshev_centre`]).
pub(crate) fn kernel_point(points: &[P3], faces: &[[u32; 3]], exact_lp: bool) -> Option<P3> {
    if faces.len() < 4 {
        return None;
    }
    // Unit inward normals and offsets, in coordinates centred on the cell (conditioning).
    let mut centre = [0.0; 3];
    let mut n = 0.0;
    for f in faces {
        for &x in f {
            centre = add(centre, points[x as usize]);
            n += 1.0;
        }
    }
    centre = scale(centre, 1.0 / n);
    let mut planes: Vec<(P3, f64)> = Vec::with_capacity(faces.len());
    let mut diameter2: f64 = 0.0;
    for f in faces {
        let [a, b, c] = f.map(|x| sub(points[x as usize], centre));
        diameter2 = diameter2.max(norm2(a));
        let nrm = cross(sub(b, a), sub(c, a));
        let len = norm2(nrm).sqrt();
        if len == 0.0 || !len.is_finite() {
            return None;
        }
        let u = scale(nrm, 1.0 / len);
        planes.push((u, dot(u, a)));
    }
    let exact_ok = |x: P3| {
        let p = add(x, centre);
        p.iter().all(|&c| in_exact_range(c))
            && faces.iter().all(|f| {
                let [a, b, c] = f.map(|i| points[i as usize]);
                orient3d(a, b, c, p) == Sign::Positive
            })
    };
    // Smallest signed distance to the planes, positive inside.
    let depth = |x: P3| {
        planes
            .iter()
            .map(|&(u, d)| dot(u, x) - d)
            .fold(f64::INFINITY, f64::min)
    };
    let mut x = [0.0; 3];
    let mut fx = depth(x);
    let mut step = diameter2.sqrt().max(f64::MIN_POSITIVE);
    let mut active: Vec<(f64, usize)> = Vec::with_capacity(planes.len());
    let mut grads: Vec<P3> = Vec::with_capacity(MAX_ACTIVE);
    // Two candidates: the first exactly inside point on the way and the deepest one (the last
    // exactly inside). Neither is always better: the deeper point keeps away from every face,
    // the first one stays nearer the cell's centroid.
    let mut first: Option<P3> = None;
    let mut last: Option<P3> = None;
    for _ in 0..MAX_STEPS {
        if fx > 0.0 && exact_ok(x) {
            first.get_or_insert(x);
            last = Some(x);
        }
        // The planes nearly tied for the smallest distance, nearest first.
        let tol = 1e-3 * step;
        active.clear();
        active.extend(
            planes
                .iter()
                .enumerate()
                .map(|(i, &(u, d))| (dot(u, x) - d, i))
                .filter(|&(v, _)| v <= fx + tol),
        );
        active.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        grads.clear();
        grads.extend(active.iter().take(MAX_ACTIVE).map(|&(_, i)| planes[i].0));
        let d = min_norm_point(&grads);
        let dn = norm2(d).sqrt();
        if dn < 1e-12 {
            // Stationary: the kernel is empty, or its depth is what `fx` says.
            break;
        }
        let d = scale(d, 1.0 / dn);
        // Backtracking: the longest step (halving from the current scale) that raises depth.
        let mut moved = false;
        let mut s = step * 2.0;
        for _ in 0..60 {
            let y = add(x, scale(d, s));
            let fy = depth(y);
            if fy > fx {
                x = y;
                fx = fy;
                step = s;
                moved = true;
                break;
            }
            s *= 0.5;
        }
        if !moved {
            break;
        }
    }
    if fx > 0.0 && exact_ok(x) {
        first.get_or_insert(x);
        last = Some(x);
    }
    // Score: the cone's tets under 10°, then its smallest dihedral angle.
    let score = |x: P3| {
        let p = add(x, centre);
        faces.iter().fold((0usize, f64::INFINITY), |(n, m), f| {
            let [a, b, c] = f.map(|i| points[i as usize]);
            let d = min_dihedral_deg(&[a, b, c, p]);
            (n + usize::from(d < 10.0), m.min(d))
        })
    };
    let best = match (first, last) {
        (Some(a), Some(b)) => {
            let (sa, sb) = (score(a), score(b));
            if sb.0 < sa.0 || (sb.0 == sa.0 && sb.1 > sa.1) {
                b
            } else {
                a
            }
        }
        // The ascent is first-order and stalls where the kernel is a thin sliver of a long
        // cell (a cell reaching the enclosing box's corners, its kernel 10⁻⁴ of its size deep:
        // tm_extrude_holes with a 300-tet first cavity bound). The linear program finds the
        // deepest point wherever the kernel has an interior that floating point can resolve.
        _ if exact_lp => chebyshev_centre(&planes, diameter2.sqrt()).filter(|&x| exact_ok(x))?,
        _ => return None,
    };
    Some(add(best, centre))
}

/// The Chebyshev centre of the kernel (the point deepest inside every plane `u·x ≥ d`, `u`
/// unit), by the simplex method on the dual: maximise `d·y` over `y ≥ 0`, `Σ y = 1`,
/// `Σ y u = 0`, whose optimal basis names the four planes the centre is equally deep in
/// (Bland's rule: no cycling, so it terminates). `None` when the kernel has no interior (or
/// the normals do not enclose it). Floating point; the caller decides exactly.
fn chebyshev_centre(planes: &[(P3, f64)], scale: f64) -> Option<P3> {
    let m = planes.len();
    // (NaN fails `is_finite`.)
    if m < 4 || scale <= 0.0 || !scale.is_finite() {
        return None;
    }
    // Rows: Σ y u_k = 0 (k < 3), Σ y = 1; columns: y (m), then 4 artificials, then the
    // right-hand side. Offsets in units of the cell's size (conditioning).
    let cols = m + 4;
    let mut tab = vec![[0.0f64; 4]; cols + 1];
    for (j, &(u, _)) in planes.iter().enumerate() {
        tab[j] = [u[0], u[1], u[2], 1.0];
    }
    for r in 0..4 {
        tab[m + r][r] = 1.0;
    }
    tab[cols][3] = 1.0;
    let cost: Vec<f64> = planes.iter().map(|&(_, d)| d / scale).collect();
    let mut basis = [m, m + 1, m + 2, m + 3];
    const EPS: f64 = 1e-12;
    // Two phases: first drive the artificials out (maximise minus their sum), then maximise
    // d·y. Column-major tableau, pivoting on rows.
    for phase in 0..2 {
        let obj = |j: usize| -> f64 {
            if phase == 0 {
                if j >= m { -1.0 } else { 0.0 }
            } else if j >= m {
                f64::NEG_INFINITY
            } else {
                cost[j]
            }
        };
        for _ in 0..50 * cols {
            // Reduced costs c_j - c_B·(column j in the current basis).
            let cb = basis.map(&obj);
            let entering = (0..cols).find(|&j| {
                !basis.contains(&j) && {
                    let c = obj(j);
                    c.is_finite() && c - (0..4).map(|r| cb[r] * tab[j][r]).sum::<f64>() > EPS
                }
            });
            let Some(e) = entering else { break };
            // Ratio test (Bland: the smallest basis index among ties).
            let mut leave: Option<(f64, usize)> = None;
            for r in 0..4 {
                let a = tab[e][r];
                if a > EPS {
                    let q = tab[cols][r] / a;
                    let better = leave.is_none_or(|(lq, lr)| {
                        q < lq - EPS || (q <= lq + EPS && basis[r] < basis[lr])
                    });
                    if better {
                        leave = Some((q, r));
                    }
                }
            }
            let (_, r) = leave?;
            let piv = tab[e][r];
            for col in tab.iter_mut() {
                col[r] /= piv;
            }
            let pc = tab[e];
            for col in tab.iter_mut() {
                let f = col[r];
                for k in 0..4 {
                    if k != r {
                        col[k] -= pc[k] * f;
                    }
                }
            }
            basis[r] = e;
        }
        if phase == 0 && basis.iter().any(|&j| j >= m) {
            // An artificial left in the basis: the origin is not a positive combination of
            // the normals that spans space (no bounded kernel to centre).
            return None;
        }
    }
    // The centre and its depth t: u_j·x − t = d_j for the four basic planes.
    let mut a = [[0.0f64; 5]; 4];
    for (r, &j) in basis.iter().enumerate() {
        let (u, d) = planes[j];
        a[r] = [u[0], u[1], u[2], -1.0, d];
    }
    for c in 0..4 {
        let p = (c..4).max_by(|&i, &k| a[i][c].abs().total_cmp(&a[k][c].abs()))?;
        a.swap(c, p);
        if a[c][c].abs() < EPS {
            return None;
        }
        for i in 0..4 {
            if i != c {
                let f = a[i][c] / a[c][c];
                let pivot_row = a[c];
                for (x, &y) in a[i].iter_mut().zip(pivot_row.iter()).skip(c) {
                    *x -= f * y;
                }
            }
        }
    }
    let z = [0, 1, 2, 3].map(|i| a[i][4] / a[i][i]);
    (z[3] > 0.0 && z.iter().all(|v| v.is_finite())).then_some([z[0], z[1], z[2]])
}

/// The cone from point `p` (index `apex`) over `faces`: one positively oriented tet per face
/// when `p` is strictly inside the kernel.
pub(crate) fn cone(faces: &[[u32; 3]], apex: u32) -> impl Iterator<Item = [u32; 4]> + '_ {
    faces.iter().map(move |f| [f[0], f[1], f[2], apex])
}

/// Insert point `x` into the tets `tets` (indices into `points`) by splitting every tet whose
/// closure holds it: each face of such a tet that `x` sees strictly from inside becomes a tet
/// with `x` (four for a point inside, six for one on a face shared by two tets, two per tet
/// around an edge). Exact. Returns whether `x` was in some tet; a point equal to a corner is
/// left alone (`false`).
pub(crate) fn split_insert(points: &[P3], tets: &mut Vec<[u32; 4]>, x: u32) -> bool {
    use crate::mesh::tet::TET_FACES;
    let p = points[x as usize];
    let mut found = false;
    let mut i = 0;
    while i < tets.len() {
        let t = tets[i];
        let c = t.map(|v| points[v as usize]);
        let signs = TET_FACES.map(|f| orient3d(c[f[0]], c[f[1]], c[f[2]], p));
        // Faces point outward: inside is Negative for every face.
        if signs.contains(&Sign::Positive) || t.contains(&x) {
            i += 1;
            continue;
        }
        if signs.iter().filter(|&&s| s == Sign::Zero).count() >= 3 {
            // `p` is a corner's position (distinct points make this a corner itself).
            i += 1;
            continue;
        }
        found = true;
        tets.swap_remove(i);
        for (k, s) in signs.iter().enumerate() {
            if *s == Sign::Negative {
                let mut n = t;
                n[k] = x;
                tets.push(n);
            }
        }
        // The pushed tets hold `x` and are skipped; `i` now holds an unvisited tet.
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cell a thousand times longer than its kernel is deep (a corner of the enclosing box
    /// far out, as in tm_extrude_holes's cavities): the linear program finds the kernel's
    /// centre, and the point is exactly inside every face.
    #[test]
    fn a_long_thin_cell_has_its_kernel_point() {
        // The tet (0,0,0), (1,0,0), (0,1,0), far apex; faces inward.
        let pts = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-640.0, -640.0, 640.5],
        ];
        let faces = [[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]];
        for f in &faces {
            let [a, b, c] = f.map(|i| pts[i as usize]);
            let inner = [0, 1, 2, 3].into_iter().find(|x| !f.contains(x)).unwrap();
            assert_eq!(orient3d(a, b, c, pts[inner as usize]), Sign::Positive);
        }
        let p = kernel_point(&pts, &faces, true).expect("a kernel point");
        for f in &faces {
            let [a, b, c] = f.map(|i| pts[i as usize]);
            assert_eq!(orient3d(a, b, c, p), Sign::Positive);
        }
        // The centre alone: equally deep in its four planes (the inradius).
        let planes: Vec<(P3, f64)> = faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| pts[i as usize]);
                let n = cross(sub(b, a), sub(c, a));
                let u = scale(n, 1.0 / norm2(n).sqrt());
                (u, dot(u, a))
            })
            .collect();
        let x = chebyshev_centre(&planes, 1000.0).expect("a centre");
        let depths: Vec<f64> = planes.iter().map(|&(u, d)| dot(u, x) - d).collect();
        let lo = depths.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = depths.iter().copied().fold(0.0, f64::max);
        assert!(lo > 0.0 && hi - lo < 1e-9 * hi, "{depths:?}");
        // No kernel: the tet's faces turned outward.
        let out: Vec<(P3, f64)> = planes.iter().map(|&(u, d)| (scale(u, -1.0), -d)).collect();
        assert!(chebyshev_centre(&out, 1000.0).is_none());
    }
}
