//! Star-shaped regions coned from one interior point: a fallback of recovery that cannot fail
//! where it applies.
//!
//! A closed region every one of whose boundary triangles sees a point `k` strictly from the
//! region's side (exact `orient3d`) is star-shaped from `k`, and the tets joining each boundary
//! triangle to `k` tile it: seen from `k` the boundary covers the sphere of directions once.
//! Every triangle is then a face as given, at the cost of one interior point. The cone of a
//! convex CAD part is a valid mesh even where recovery finds no fill (a cube whose faces are cut
//! into long strips fanned over collinear points: 499 triangles left after every other fallback,
//! none this way).
//!
//! The cones only join surface points to `k`, so the interior nodes of node deployment are put
//! back into them, each into the tets of its region whose circumspheres hold it (reached through
//! faces, never across the surface) when coning that cavity to it is valid
//! ([`cavity::cone_valid`]), in passes while one puts a node back: a constrained
//! tetrahedralization, as TetGen makes its boundary first and refines after. A node no valid
//! cavity takes is left out, and the mesh is coarser there than asked: splitting the thin cone
//! tet holding it instead (always valid) made flat tets (the strip cube at `--size 0.05`:
//! 22,023 of 34,573 tets under 10°, 340 s; leaving them out, 1,303 of 12,765 in 4.7 s).
//!
//! The kernel point is chosen in floating point (the region's centroid, then the mean of its
//! boundary points); the exact test decides. Sequential and in a fixed order: the same mesh on
//! any number of threads.

use crate::geom::predicates::{Sign, orient3d};
use crate::geom::vec3::{add, cross, dot, scale, sub};
use crate::mesh::cavity;
use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::TetMesh;

type P3 = [f64; 3];

/// Largest circumsphere cavity a node may take, in tets (past it, the tet holding it).
const MAX_CAVITY: usize = 256;

/// Passes over the nodes not yet put back, at most.
const PASSES: usize = 4;

/// Steps of the walk that locates a node before the scan of every tet.
const WALK_STEPS: usize = 256;

/// What [`coned`] did.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct StarReport {
    /// Regions coned (each from one kernel point, an interior Steiner point).
    pub regions: usize,
    /// Interior nodes put back into the cones.
    pub nodes_inserted: usize,
    /// Interior nodes left out: no valid cavity among the cone's thin tets (the mesh is
    /// coarser there than asked).
    pub nodes_left_out: usize,
    /// Triangles recovery had left, all faces now.
    pub triangles_left_by_recovery: usize,
    /// Whether the mesh is the cones: they are set aside for recovery's other fallbacks when
    /// they leave out more nodes than they put back, and used only if those leave triangles
    /// too.
    pub kept: bool,
}

/// The regions of `surface` (labels other than 0, in increasing order), each with its boundary
/// triangles turned so the region is on the side of their normal: `[a, b, c]` with
/// `orient3d(a, b, c, x) > 0` for `x` in the region just beyond it. (Keyed by label, not indexed
/// by it: a label image's labels may be large.)
fn region_faces(surface: &SurfaceMesh) -> Vec<(u32, Vec<[u32; 3]>)> {
    let mut out: std::collections::BTreeMap<u32, Vec<[u32; 3]>> = Default::default();
    for (t, &[back, front]) in surface.triangles.iter().zip(&surface.sides) {
        // The normal (b - a) x (c - a) points to the front.
        if front != 0 {
            out.entry(front).or_default().push(*t);
        }
        if back != 0 {
            out.entry(back).or_default().push([t[0], t[2], t[1]]);
        }
    }
    out.into_iter().collect()
}

/// A point strictly inside the kernel of the region bounded by `faces` (turned as
/// [`region_faces`] gives them), if one of the candidates is.
fn kernel_point(points: &[P3], faces: &[[u32; 3]]) -> Option<P3> {
    if faces.is_empty() {
        return None;
    }
    let corners = |f: &[u32; 3]| f.map(|v| points[v as usize]);
    // Centroid of the solid: the cone of each face from the first corner, weighted by volume;
    // the faces point inward, so the signed volumes are negated.
    let o = corners(&faces[0])[0];
    let mut vol = 0.0;
    let mut acc = [0.0; 3];
    for f in faces {
        let [a, b, c] = corners(f);
        let v = -dot(sub(a, o), cross(sub(b, o), sub(c, o)));
        vol += v;
        acc = add(acc, scale(add(add(a, b), add(c, o)), v / 4.0));
    }
    let mut mean = [0.0; 3];
    let mut used: Vec<u32> = faces.iter().flatten().copied().collect();
    used.sort_unstable();
    used.dedup();
    for &v in &used {
        mean = add(mean, points[v as usize]);
    }
    let mean = scale(mean, 1.0 / used.len() as f64);
    let candidates = [(vol > 0.0).then(|| scale(acc, 1.0 / vol)), Some(mean)];
    candidates.into_iter().flatten().find(|&k| {
        k.iter().all(|x| x.is_finite())
            && faces.iter().all(|f| {
                let [a, b, c] = corners(f);
                orient3d(a, b, c, k) == Sign::Positive
            })
    })
}

/// A kernel point per region of `surface` (label and point, labels in increasing order), if
/// every region has one among the candidates and a connected boundary (two shells of one label
/// have no single cone). Linear in the triangles: cheap enough to ask before recovery.
pub fn kernels(surface: &SurfaceMesh) -> Option<Vec<(u32, P3)>> {
    let k: Vec<(u32, P3)> = region_faces(surface)
        .iter()
        .map(|(label, f)| {
            connected(f)
                .then(|| kernel_point(&surface.points, f))
                .flatten()
                .map(|k| (*label, k))
        })
        .collect::<Option<_>>()?;
    (!k.is_empty()).then_some(k)
}

/// Every region of `surface` coned from its kernel point ([`kernels`]), then the interior nodes
/// `points[ns..]` (region `regions[i - ns]`) put back (see the module docs); `points[..ns]` are
/// the surface's points.
pub fn coned(
    surface: &SurfaceMesh,
    kernels: &[(u32, P3)],
    points: &[P3],
    regions: &[u32],
    ns: usize,
) -> (TetMesh, StarReport) {
    let faces = region_faces(surface);
    let mut mesh = TetMesh {
        points: points[..ns].to_vec(),
        tets: Vec::new(),
        neighbors: Vec::new(),
        labels: Vec::new(),
    };
    let mut report = StarReport::default();
    for ((label, f), &(_, k)) in faces.iter().zip(kernels) {
        let apex = mesh.points.len() as u32;
        mesh.points.push(k);
        for t in f {
            mesh.tets.push([t[0], t[1], t[2], apex]);
            mesh.labels.push(*label);
        }
        report.regions += 1;
    }
    mesh.rebuild_neighbors();
    // Nodes in a spatial order (short walks), ties by index.
    let mut order: Vec<usize> = (ns..points.len()).collect();
    let key = grid_keys(&points[ns..]);
    order.sort_by_key(|&i| (key[i - ns], i));
    let mut dead = Vec::new();
    let mut last = 0u32;
    // Passes while one puts a node back: a node whose cavity fails among the cone's thin tets
    // may find a valid one once the nodes around it are in.
    for _ in 0..PASSES {
        let mut left = Vec::new();
        for &i in &order {
            let (x, label) = (points[i], regions[i - ns]);
            let Some((s, _)) = locate(&mesh, last, x, label) else {
                left.push(i);
                continue;
            };
            let same = |n: u32| mesh.labels[n as usize] == label;
            let corners = |t: u32| mesh.tets[t as usize].map(|v| mesh.points[v as usize]);
            let cav = cavity::circumsphere_cavity(s, x, MAX_CAVITY, &mesh.neighbors, corners, same)
                .filter(|c| {
                    let inside = |t: u32| c.binary_search(&t).is_ok();
                    let (shell, _) = cavity::shell(c, &mesh.tets, &mesh.neighbors, inside);
                    cavity::cone_valid(&mesh, c, &shell, x)
                });
            let Some(cav) = cav else {
                left.push(i);
                continue;
            };
            let before = dead.len();
            cavity::cone_in(&mut mesh, x, &cav, &mut dead);
            // Slots left over keep their old corners until dropped: out of every region, so
            // the scan of `locate` cannot land in one.
            for &t in &dead[before..] {
                mesh.labels[t as usize] = u32::MAX;
            }
            last = cav[0];
            report.nodes_inserted += 1;
        }
        let progress = left.len() < order.len();
        order = left;
        if !progress {
            break;
        }
    }
    report.nodes_left_out = order.len();
    // Slots left over by cones with fewer tets than their cavities.
    cavity::drop_dead(&mut mesh, &dead);
    (mesh, report)
}

/// Whether the triangles `faces` are connected through shared edges.
fn connected(faces: &[[u32; 3]]) -> bool {
    let mut by_edge: rustc_hash::FxHashMap<(u32, u32), Vec<u32>> = Default::default();
    for (i, f) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            by_edge
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(i as u32);
        }
    }
    let mut seen = vec![false; faces.len()];
    let mut stack = vec![0u32];
    seen[0] = true;
    let mut n = 1;
    while let Some(i) = stack.pop() {
        let f = faces[i as usize];
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            for &j in &by_edge[&(a.min(b), a.max(b))] {
                if !seen[j as usize] {
                    seen[j as usize] = true;
                    n += 1;
                    stack.push(j);
                }
            }
        }
    }
    n == faces.len()
}

/// A key per point ordering them cell by cell of a grid of about one point a cell, the cells
/// in x-major order, so consecutive points are mostly near each other.
fn grid_keys(points: &[P3]) -> Vec<u64> {
    if points.is_empty() {
        return Vec::new();
    }
    let (lo, hi) = crate::geom::vec3::points_bbox(points.iter());
    let cells = (points.len() as f64).cbrt().ceil().max(1.0);
    let cell = |p: P3, k: usize| {
        let w = hi[k] - lo[k];
        if w > 0.0 {
            (((p[k] - lo[k]) / w * cells) as u64).min(cells as u64 - 1)
        } else {
            0
        }
    };
    let n = cells as u64;
    points
        .iter()
        .map(|&p| {
            let (x, y, z) = (cell(p, 0), cell(p, 1), cell(p, 2));
            // Serpentine: alternate directions keep the last cell of a row beside the next.
            let y = if x % 2 == 1 { n - 1 - y } else { y };
            let z = if (x * n + y) % 2 == 1 { n - 1 - z } else { z };
            (x * n + y) * n + z
        })
        .collect()
}

/// The tet of region `label` holding `x`, and whether strictly inside (else on its boundary): a
/// walk from `start` ([`cavity::walk`]), then, if it leaves the region or stalls, a scan of every
/// tet of the region.
fn locate(mesh: &TetMesh, start: u32, x: P3, label: u32) -> Option<(u32, bool)> {
    let walked = ((start as usize) < mesh.tets.len() && mesh.labels[start as usize] == label)
        .then(|| cavity::walk(mesh, start, x, WALK_STEPS))
        .flatten();
    // The scan: a region need not be convex, so the walk may leave it.
    walked.or_else(|| {
        (0..mesh.tets.len() as u32)
            .filter(|&t| mesh.labels[t as usize] == label)
            .find_map(|t| cavity::where_in(mesh, t, x).ok().map(|inside| (t, inside)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::check;

    /// A sphere coned from its centre with nodes put back: every triangle a face, every node
    /// in, and the mesh valid against the surface.
    #[test]
    fn a_sphere_cones_from_its_centre_with_its_nodes() {
        let mut s = SurfaceMesh::icosphere(1.0, 2);
        // A label image's label: regions are keyed by label, not indexed by it.
        s.sides.iter_mut().for_each(|x| *x = [70_000, 0]);
        let ns = s.points.len();
        let mut points = s.points.clone();
        let mut regions = Vec::new();
        for i in 0..20 {
            let a = i as f64 * 0.7;
            points.push([
                0.5 * a.cos() * (0.3 * a).sin(),
                0.5 * a.sin(),
                0.4 * (0.5 * a).cos(),
            ]);
            regions.push(70_000);
        }
        let k = kernels(&s).expect("a sphere is star-shaped");
        let (mesh, report) = coned(&s, &k, &points, &regions, ns);
        assert!(mesh.labels.iter().all(|&l| l == 70_000));
        assert_eq!(report.regions, 1);
        assert_eq!(report.nodes_inserted + report.nodes_left_out, 20);
        assert_eq!(report.nodes_left_out, 0);
        assert_eq!(crate::pipeline::missing_triangles(&mesh, &s), 0);
        let c = check(&mesh, Some(&s));
        assert!(c.valid, "{c:?}");
        assert_eq!(mesh.points.len(), ns + 21);
    }

    /// A torus has no kernel (its hole hides part of it from every point), and two spheres of
    /// one label have no single cone: neither is coned.
    #[test]
    fn a_torus_or_two_shells_of_one_label_have_no_cone() {
        let (r0, r1, n, m) = (1.0f64, 0.3f64, 24u32, 12u32);
        let mut t = SurfaceMesh::default();
        for i in 0..n {
            for j in 0..m {
                let (u, v) = (
                    i as f64 / n as f64 * std::f64::consts::TAU,
                    j as f64 / m as f64 * std::f64::consts::TAU,
                );
                let r = r0 + r1 * v.cos();
                t.points.push([r * u.cos(), r * u.sin(), r1 * v.sin()]);
            }
        }
        let id = |i: u32, j: u32| (i % n) * m + (j % m);
        for i in 0..n {
            for j in 0..m {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                t.triangles.push([a, b, c]);
                t.triangles.push([a, c, d]);
                t.sides.push([1, 0]);
                t.sides.push([1, 0]);
            }
        }
        assert!(kernels(&t).is_none());
        let s = SurfaceMesh::icosphere(1.0, 1);
        assert!(kernels(&s).is_some());
        let mut two = s.clone();
        let k = two.points.len() as u32;
        two.points
            .extend(s.points.iter().map(|p| [p[0] + 3.0, p[1], p[2]]));
        two.triangles
            .extend(s.triangles.iter().map(|f| f.map(|v| v + k)));
        two.sides.extend(s.sides.iter().copied());
        assert!(kernels(&two).is_none());
    }

    /// Two boxes sharing a face, two regions: each coned from its own centre, the shared face a
    /// face of both cones, the mesh valid with both labels.
    #[test]
    fn two_boxes_sharing_a_face_cone_each_from_its_own_centre() {
        let mut s = SurfaceMesh::default();
        let id = |x: usize, y: usize, z: usize| (x * 4 + y * 2 + z) as u32;
        for x in 0..3 {
            for y in 0..2 {
                for z in 0..2 {
                    s.points.push([x as f64, y as f64, z as f64]);
                }
            }
        }
        // A quad split in two, turned so its normal is `n`, with sides [back, front].
        let mut quad = |q: [u32; 4], n: [f64; 3], sides: [u32; 2]| {
            for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                let c = t.map(|v| s.points[v as usize]);
                let m = cross(sub(c[1], c[0]), sub(c[2], c[0]));
                s.triangles.push(if dot(m, n) > 0.0 {
                    t
                } else {
                    [t[0], t[2], t[1]]
                });
                s.sides.push(sides);
            }
        };
        // The sides y = 0, y = 1, z = 0, z = 1 of each box, in that order.
        for (r, x0) in [(1u32, 0usize), (2, 1)] {
            let x1 = x0 + 1;
            for (axis, w) in [(1, 0), (1, 1), (2, 0), (2, 1)] {
                // Corner (x, u) of the face: u runs along the other of y and z.
                let at = |x: usize, u: usize| if axis == 1 { id(x, w, u) } else { id(x, u, w) };
                let mut n = [0.0; 3];
                n[axis] = if w == 0 { -1.0 } else { 1.0 };
                quad([at(x0, 0), at(x1, 0), at(x1, 1), at(x0, 1)], n, [r, 0]);
            }
        }
        quad(
            [id(0, 0, 0), id(0, 1, 0), id(0, 1, 1), id(0, 0, 1)],
            [-1.0, 0.0, 0.0],
            [1, 0],
        );
        quad(
            [id(2, 0, 0), id(2, 1, 0), id(2, 1, 1), id(2, 0, 1)],
            [1.0, 0.0, 0.0],
            [2, 0],
        );
        quad(
            [id(1, 0, 0), id(1, 1, 0), id(1, 1, 1), id(1, 0, 1)],
            [1.0, 0.0, 0.0],
            [1, 2],
        );
        let k = kernels(&s).expect("boxes are star-shaped");
        assert_eq!(k, vec![(1, [0.5, 0.5, 0.5]), (2, [1.5, 0.5, 0.5])]);
        let ns = s.points.len();
        let (mesh, report) = coned(&s, &k, &s.points, &[], ns);
        assert_eq!(report.regions, 2);
        assert_eq!(mesh.tets.len(), 24);
        assert_eq!(crate::pipeline::missing_triangles(&mesh, &s), 0);
        let c = check(&mesh, Some(&s));
        assert!(c.valid, "{c:?}");
        assert_eq!(mesh.labels.iter().filter(|&&l| l == 2).count(), 12);
    }
}
