//! The validity checker: is a [`TetMesh`] a conforming, positively oriented tetrahedralization,
//! and does it contain every triangle of a given surface?
//!
//! Every decision is exact: orientation by [`orient3d`], surface matching by exact coordinates.
//! Every test that makes a mesh runs this on it; `biotet check` prints its report.

use crate::geom::predicates::{Sign, in_exact_range, orient3d};
use crate::mesh::coord_key;
use crate::mesh::dsu::Dsu;
use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::{NO_NEIGHBOR, TET_FACES, TetMesh, sorted3};
use crate::mesh::validate::{
    SurfaceError, TriangleInfo, ValidateOptions, check_self_intersections, validate_surface,
};
use rustc_hash::FxHashMap;
use serde::Serialize;
use std::fmt;

/// How many offending items of each kind are listed by name in [`CheckReport::problems`].
const LIST_FIRST: usize = 5;

/// The result of [`check`]: counts of each kind of defect and the first offenders of each.
#[derive(Debug, Clone, Default, Serialize)]
pub struct CheckReport {
    /// True when no defect was found.
    pub valid: bool,
    /// Points in the mesh.
    pub n_points: usize,
    /// Tets in the mesh.
    pub n_tets: usize,
    /// Boundary faces (faces of exactly one tet).
    pub n_boundary_faces: usize,
    /// Tets with a vertex index out of range or a repeated vertex.
    pub n_bad_tets: usize,
    /// Tets that are not strictly positively oriented (exact orient3d ≤ 0).
    pub n_nonpositive: usize,
    /// Faces found in more than two tets.
    pub n_overshared_faces: usize,
    /// Interior faces whose two tets give them the same orientation (the tets overlap).
    pub n_misoriented_faces: usize,
    /// Entries of the adjacency array that disagree with the faces.
    pub n_adjacency_errors: usize,
    /// Points used by no tet.
    pub n_unused_points: usize,
    /// Points with exactly the same coordinates as an earlier point.
    pub n_duplicate_points: usize,
    /// Non-finite coordinates, or coordinates outside the exact range of the predicates (0 or a
    /// magnitude between 2⁻¹⁵⁰ and 1e50), where no sign could be trusted.
    pub n_nonfinite_points: usize,
    /// Label array length differs from the tet count (0 or 1).
    pub n_label_errors: usize,
    /// Why the mesh's boundary faces do not form a closed, embedded, outward surface (`None`
    /// when they do). Together with positive tets and conforming faces this proves that the
    /// tets cover their domain exactly once: no overlap, no fold.
    pub boundary_problem: Option<String>,
    /// Boundary vertices where the mesh touches itself (its boundary is not a manifold there:
    /// two shells meet only at that vertex or along an edge through it) and every sheet belongs
    /// to different regions: regions touching, not a region pinched. Legitimate; informational.
    pub n_touching_vertices: usize,
    /// Surface conformity, when a surface was given.
    pub surface: Option<SurfaceConformity>,
    /// Per region label (by increasing label): tets, volume, worst angles and, with a surface,
    /// the volume its triangles enclose. Informational: validity does not depend on it.
    pub regions: Vec<RegionCheck>,
    /// Human-readable descriptions of the first offenders of each kind.
    pub problems: Vec<String>,
}

/// How a [`TetMesh`] conforms to a [`SurfaceMesh`].
#[derive(Debug, Clone, Default, Serialize)]
pub struct SurfaceConformity {
    /// Surface triangles.
    pub n_triangles: usize,
    /// Surface triangles present as mesh faces with the right neighbours and labels.
    pub n_found: usize,
    /// Surface triangles with a corner that is not a mesh point.
    pub n_points_missing: usize,
    /// Surface triangles whose three corners are mesh points but that are no mesh face.
    pub n_missing: usize,
    /// Outer triangles (one side labelled 0) present as faces but not on the mesh boundary.
    pub n_outer_not_boundary: usize,
    /// Interface triangles present as faces but not between tets of their two labels.
    pub n_interface_wrong: usize,
    /// Triangles whose adjacent tet labels contradict the triangle's side labels.
    pub n_label_mismatch: usize,
    /// Mesh boundary faces that are no outer surface triangle.
    pub n_extra_boundary_faces: usize,
    /// Per pair of side labels (sorted, 0 = outside): expected and found triangles.
    pub interfaces: Vec<InterfaceConformity>,
}

/// Expected and found triangles of one boundary or interface (a pair of region labels).
#[derive(Debug, Clone, Default, Serialize, PartialEq, Eq)]
pub struct InterfaceConformity {
    /// The two region labels, smaller first (0 = outside, so `[0, r]` is region r's boundary).
    pub labels: [u32; 2],
    /// Triangles of the surface with these side labels.
    pub expected: usize,
    /// Of those, present in the mesh as required.
    pub found: usize,
}

/// One region of a checked mesh: what its tets measure, and what its surface encloses.
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct RegionCheck {
    /// The label.
    pub label: u32,
    /// Its tets.
    pub n_tets: usize,
    /// The sum of their signed volumes.
    pub volume: f64,
    /// Their smallest dihedral angle (degrees).
    pub min_dihedral_deg: f64,
    /// Their largest dihedral angle (degrees).
    pub max_dihedral_deg: f64,
    /// Their smallest solid angle (steradians).
    pub min_solid_angle_sr: f64,
    /// With a surface: the volume enclosed by the triangles with this label on one side, each
    /// taken with the region behind it (floating point; equal to `volume` up to rounding when
    /// the mesh conforms).
    pub enclosed_volume: Option<f64>,
}

/// [`RegionCheck`] of every label of `mesh` (tets with an index out of range are skipped), and
/// of every label of `surface` that has no tets.
fn region_checks(mesh: &TetMesh, surface: Option<&SurfaceMesh>) -> Vec<RegionCheck> {
    let mut by_label: std::collections::BTreeMap<u32, RegionCheck> = Default::default();
    let np = mesh.points.len();
    for (t, tet) in mesh.tets.iter().enumerate() {
        if tet.iter().any(|&v| v as usize >= np) {
            continue;
        }
        let label = mesh.labels.get(t).copied().unwrap_or(0);
        let m = crate::quality::tet::TetMeasures::of(&mesh.corners(t));
        let r = by_label.entry(label).or_insert_with(|| RegionCheck {
            label,
            min_dihedral_deg: f64::INFINITY,
            max_dihedral_deg: f64::NEG_INFINITY,
            min_solid_angle_sr: f64::INFINITY,
            ..Default::default()
        });
        r.n_tets += 1;
        r.volume += m.volume;
        r.min_dihedral_deg = r.min_dihedral_deg.min(m.min_dihedral());
        r.max_dihedral_deg = r.max_dihedral_deg.max(m.max_dihedral());
        r.min_solid_angle_sr = r.min_solid_angle_sr.min(m.min_solid());
    }
    if let Some(s) = surface {
        let o = s.points.first().copied().unwrap_or([0.0; 3]);
        let mut enclosed: std::collections::BTreeMap<u32, f64> = Default::default();
        for (t, sides) in s.sides.iter().enumerate().take(s.triangles.len()) {
            if s.triangles[t].iter().any(|&v| v as usize >= s.points.len()) {
                continue;
            }
            let [a, b, c] = s.corners(t);
            let v = crate::geom::vec3::volume6(o, a, b, c) / 6.0;
            for (k, &l) in sides.iter().enumerate() {
                if l != 0 {
                    *enclosed.entry(l).or_insert(0.0) += if k == 0 { v } else { -v };
                }
            }
        }
        for (label, v) in enclosed {
            by_label
                .entry(label)
                .or_insert_with(|| RegionCheck {
                    label,
                    min_dihedral_deg: f64::NAN,
                    max_dihedral_deg: f64::NAN,
                    min_solid_angle_sr: f64::NAN,
                    ..Default::default()
                })
                .enclosed_volume = Some(v);
        }
    }
    by_label.into_values().collect()
}

impl CheckReport {
    fn note(&mut self, count: usize, msg: impl FnOnce() -> String) {
        if count <= LIST_FIRST {
            self.problems.push(msg());
        }
    }
}

/// Check `mesh`, and if `surface` is given, that every surface triangle is a face of it.
///
/// Mesh checks: indices in range and distinct, every tet strictly positive (exact), no face in
/// more than two tets, the two tets of an interior face see it with opposite orientations, the
/// adjacency array matches the faces, every point used, no duplicate or non-finite points, one
/// label per tet. Surface checks (points matched by exact coordinates): every triangle is a mesh
/// face; triangles with an outside side (label 0) are boundary faces and, when the mesh has
/// several regions, the tet behind them carries the inside label; interface triangles lie
/// between tets of their two labels, each on its side; no other boundary faces exist.
pub fn check(mesh: &TetMesh, surface: Option<&SurfaceMesh>) -> CheckReport {
    let mut r = CheckReport {
        n_points: mesh.points.len(),
        n_tets: mesh.tets.len(),
        ..Default::default()
    };
    let np = mesh.points.len();

    if mesh.tets.is_empty() {
        r.problems.push("the mesh has no tets".to_string());
    }
    if mesh.tets.len() >= 1 << 30 {
        r.n_bad_tets += 1;
        r.problems.push(format!(
            "{} tets: more than 2^30 are not supported",
            mesh.tets.len()
        ));
        return r;
    }
    if mesh.labels.len() != mesh.tets.len() {
        r.n_label_errors = 1;
        r.problems.push(format!(
            "{} labels for {} tets",
            mesh.labels.len(),
            mesh.tets.len()
        ));
    }
    for (i, p) in mesh.points.iter().enumerate() {
        if !p.iter().all(|&c| in_exact_range(c)) {
            r.n_nonfinite_points += 1;
            r.note(r.n_nonfinite_points, || {
                format!("point {i} is not finite or outside the exact range: {p:?}")
            });
        }
    }

    // Tets: indices and orientation.
    let mut ok_tet = vec![true; mesh.tets.len()];
    let mut used = vec![false; np];
    for (t, v) in mesh.tets.iter().enumerate() {
        let in_range = v.iter().all(|&i| (i as usize) < np);
        let distinct = v[0] != v[1] && v[0] != v[2] && v[0] != v[3] && v[1] != v[2];
        let distinct = distinct && v[1] != v[3] && v[2] != v[3];
        if !in_range || !distinct {
            ok_tet[t] = false;
            r.n_bad_tets += 1;
            r.note(r.n_bad_tets, || {
                format!("tet {t} {v:?}: vertex index out of range ({np} points) or repeated")
            });
            continue;
        }
        for &i in v {
            used[i as usize] = true;
        }
        let c = mesh.corners(t);
        if orient3d(c[0], c[1], c[2], c[3]) != Sign::Positive {
            r.n_nonpositive += 1;
            r.note(r.n_nonpositive, || {
                format!("tet {t} {v:?} is not positively oriented: corners {c:?}")
            });
        }
    }
    for (i, u) in used.iter().enumerate() {
        if !u {
            r.n_unused_points += 1;
            r.note(r.n_unused_points, || {
                format!("point {i} {:?} is used by no tet", mesh.points[i])
            });
        }
    }
    let mut first_at: FxHashMap<[u64; 3], usize> = FxHashMap::default();
    first_at.reserve(np);
    for (i, p) in mesh.points.iter().enumerate() {
        if let Some(&j) = first_at.get(&coord_key(p)) {
            r.n_duplicate_points += 1;
            r.note(r.n_duplicate_points, || {
                format!("point {i} duplicates point {j} at {p:?}")
            });
        } else {
            first_at.insert(coord_key(p), i);
        }
    }

    // Faces: sort (key, tet*4 + face) and walk the runs.
    let mut keys: Vec<([u32; 3], u32)> = Vec::with_capacity(mesh.tets.len() * 4);
    for (t, v) in mesh.tets.iter().enumerate() {
        if !ok_tet[t] {
            continue;
        }
        for (f, l) in TET_FACES.iter().enumerate() {
            keys.push((
                sorted3([v[l[0]], v[l[1]], v[l[2]]]),
                (t as u32) << 2 | f as u32,
            ));
        }
    }
    keys.sort_unstable();
    let mut expect_nb = vec![[NO_NEIGHBOR; 4]; mesh.tets.len()];
    let mut boundary: FxHashMap<[u32; 3], (u32, u32)> = FxHashMap::default();
    let mut i = 0;
    while i < keys.len() {
        let mut j = i + 1;
        while j < keys.len() && keys[j].0 == keys[i].0 {
            j += 1;
        }
        let key = keys[i].0;
        match j - i {
            1 => {
                let (t, f) = (keys[i].1 >> 2, keys[i].1 & 3);
                boundary.insert(key, (t, f));
            }
            2 => {
                let (a, b) = (keys[i].1, keys[i + 1].1);
                let (ta, fa) = ((a >> 2) as usize, (a & 3) as usize);
                let (tb, fb) = ((b >> 2) as usize, (b & 3) as usize);
                expect_nb[ta][fa] = tb as u32;
                expect_nb[tb][fb] = ta as u32;
                if same_cyclic_order(mesh.face(ta, fa), mesh.face(tb, fb)) {
                    r.n_misoriented_faces += 1;
                    r.note(r.n_misoriented_faces, || {
                        format!("face {key:?} has the same orientation in tets {ta} and {tb}: they overlap")
                    });
                }
            }
            n => {
                r.n_overshared_faces += 1;
                let tets: Vec<u32> = keys[i..j].iter().map(|k| k.1 >> 2).collect();
                r.note(r.n_overshared_faces, || {
                    format!("face {key:?} is in {n} tets {tets:?}")
                });
            }
        }
        i = j;
    }
    r.n_boundary_faces = boundary.len();

    // Adjacency.
    if mesh.neighbors.len() != mesh.tets.len() {
        r.n_adjacency_errors += 1;
        r.problems.push(format!(
            "adjacency has {} entries for {} tets",
            mesh.neighbors.len(),
            mesh.tets.len()
        ));
    } else {
        for (t, nb) in mesh.neighbors.iter().enumerate() {
            if !ok_tet[t] {
                continue;
            }
            for f in 0..4 {
                if nb[f] != expect_nb[t][f] {
                    r.n_adjacency_errors += 1;
                    r.note(r.n_adjacency_errors, || {
                        format!(
                            "tet {t} face {f}: adjacency says {}, faces say {}",
                            show_nb(nb[f]),
                            show_nb(expect_nb[t][f])
                        )
                    });
                }
            }
        }
    }

    let locally_ok = r.n_bad_tets == 0
        && r.n_nonpositive == 0
        && r.n_overshared_faces == 0
        && r.n_misoriented_faces == 0
        && r.n_nonfinite_points == 0;
    if locally_ok && !mesh.tets.is_empty() {
        let (problem, touching) = boundary_embedding(mesh, &boundary, &keys);
        r.boundary_problem = problem;
        r.n_touching_vertices = touching;
        if let Some(p) = &r.boundary_problem {
            r.problems.push(format!("boundary surface: {p}"));
        }
    }

    if let Some(s) = surface {
        r.surface = Some(check_surface(
            mesh,
            s,
            &first_at,
            &keys,
            &boundary,
            &mut r.problems,
        ));
    }

    r.regions = region_checks(mesh, surface);
    let s_ok = r.surface.as_ref().is_none_or(|s| {
        s.n_found == s.n_triangles && s.n_extra_boundary_faces == 0 && s.n_label_mismatch == 0
    });
    r.valid = s_ok
        && !mesh.tets.is_empty()
        && r.boundary_problem.is_none()
        && r.n_bad_tets == 0
        && r.n_nonpositive == 0
        && r.n_overshared_faces == 0
        && r.n_misoriented_faces == 0
        && r.n_adjacency_errors == 0
        && r.n_unused_points == 0
        && r.n_duplicate_points == 0
        && r.n_nonfinite_points == 0
        && r.n_label_errors == 0;
    r
}

/// Validate the boundary faces as one closed surface (outward, as tet faces are): closed,
/// manifold, consistently oriented, not self-intersecting, and no shell inside out. Positive tets
/// with conforming faces cover each point a number of times equal to the winding number of
/// their boundary around it, so an embedded outward boundary means every point of the domain is
/// covered exactly once: this finds tets that overlap without sharing a face.
///
/// Regions may touch: two shells meeting only along an edge or at a vertex make the boundary
/// non-manifold there, which is legitimate when the tets on the two sheets belong to different
/// regions, and a region pinched when they share one ([`touching_boundary`]). Returns the
/// problem, if any, and the number of boundary vertices where regions touch.
fn boundary_embedding(
    mesh: &TetMesh,
    boundary: &FxHashMap<[u32; 3], (u32, u32)>,
    face_keys: &[([u32; 3], u32)],
) -> (Option<String>, usize) {
    let mut faces: Vec<(u32, u32)> = boundary.values().copied().collect();
    faces.sort_unstable();
    let triangles: Vec<[u32; 3]> = faces
        .iter()
        .map(|&(t, f)| mesh.face(t as usize, f as usize))
        .collect();
    let mut surface = SurfaceMesh::closed(mesh.points.clone(), triangles, 1);
    let opts = ValidateOptions {
        fix_inward: false,
        ..ValidateOptions::default()
    };
    let show =
        |e: SurfaceError| format!("{e} (triangle indices are boundary faces in (tet, face) order)");
    match validate_surface(&mut surface, &opts) {
        Ok(_) => (None, 0),
        Err(SurfaceError::NonManifoldEdge { .. } | SurfaceError::NonManifoldVertex { .. }) => {
            let (problem, touching) = touching_boundary(mesh, &faces, &surface, face_keys);
            (problem.map(show), touching)
        }
        Err(e) => (Some(show(e)), 0),
    }
}

/// [`boundary_embedding`] for a boundary that is not a manifold (`surface`: the boundary
/// `faces` as one closed surface). At each vertex the tets around it fall into classes, tets
/// joined through their shared faces at the vertex; classes that share a region label are one
/// group (a region is one piece there). Where a vertex has several groups, the regions of each
/// group touch the others only at that vertex (or along an edge through it), and each group gets
/// its own copy of the vertex: the boundary, so unpinched, must then pass every check of
/// [`validate_surface`] but self-intersection, which is checked on the boundary as it is
/// (sheets that touch share their vertices there). A region pinched at an edge or a vertex keeps
/// its sheets on one copy and fails as a non-manifold edge or vertex, with the mesh's indices.
fn touching_boundary(
    mesh: &TetMesh,
    faces: &[(u32, u32)],
    surface: &SurfaceMesh,
    face_keys: &[([u32; 3], u32)],
) -> (Option<SurfaceError>, usize) {
    let nt = mesh.tets.len();
    let np = mesh.points.len();
    let corner = |t: usize, v: u32| mesh.tets[t].iter().position(|&x| x == v).unwrap_or(0);
    // Tet corners 4t + i joined across interior faces at each of the face's vertices.
    let mut dsu = Dsu::new(4 * nt);
    for w in face_keys.windows(2) {
        if w[0].0 != w[1].0 {
            continue;
        }
        let (ta, tb) = ((w[0].1 >> 2) as usize, (w[1].1 >> 2) as usize);
        for v in w[0].0 {
            dsu.union(
                (4 * ta + corner(ta, v)) as u32,
                (4 * tb + corner(tb, v)) as u32,
            );
        }
    }
    // (vertex, class, label) of every corner; per vertex, classes sharing a label merged.
    let mut at: Vec<(u32, u32, u32)> = (0..4 * nt)
        .map(|c| {
            let t = c / 4;
            let label = mesh.labels.get(t).copied().unwrap_or(0);
            (mesh.tets[t][c % 4], dsu.find(c as u32), label)
        })
        .collect();
    at.sort_unstable();
    at.dedup();
    let mut points = mesh.points.clone();
    let mut copy_of: FxHashMap<u32, u32> = FxHashMap::default(); // class -> vertex copy
    let mut original: Vec<u32> = (0..np as u32).collect();
    let mut touching = vec![false; np];
    let mut n_touching = 0;
    let mut i = 0;
    while i < at.len() {
        let v = at[i].0;
        let mut j = i + 1;
        while j < at.len() && at[j].0 == v {
            j += 1;
        }
        let mut classes: Vec<u32> = at[i..j].iter().map(|x| x.1).collect();
        classes.dedup();
        if classes.len() > 1 {
            // Union of classes through labels (few: a vertex's classes).
            let mut group: Vec<usize> = (0..classes.len()).collect();
            let root = |g: &[usize], mut k: usize| {
                while g[k] != k {
                    k = g[k];
                }
                k
            };
            for a in i..j {
                for b in a + 1..j {
                    if at[a].2 == at[b].2 {
                        let ka = classes.binary_search(&at[a].1).unwrap_or(0);
                        let kb = classes.binary_search(&at[b].1).unwrap_or(0);
                        let (ra, rb) = (root(&group, ka), root(&group, kb));
                        group[ra.max(rb)] = ra.min(rb);
                    }
                }
            }
            let roots: Vec<usize> = (0..classes.len()).map(|k| root(&group, k)).collect();
            if roots.iter().any(|&r| r != 0) {
                n_touching += 1;
                touching[v as usize] = true;
                let mut index_of: FxHashMap<usize, u32> = FxHashMap::default();
                for (k, &r) in roots.iter().enumerate() {
                    let idx = *index_of.entry(r).or_insert_with(|| {
                        if r == 0 {
                            v
                        } else {
                            points.push(mesh.points[v as usize]);
                            original.push(v);
                            (points.len() - 1) as u32
                        }
                    });
                    copy_of.insert(classes[k], idx);
                }
            }
        }
        i = j;
    }
    touching.resize(points.len(), true);
    // The unpinched boundary. Nesting is judged from each shell's lowest triangle's first
    // corner, which must lie on no other shell: put a corner where nothing touches first, and
    // triangles without one last.
    let mut tris: Vec<(bool, usize, [u32; 3])> = faces
        .iter()
        .enumerate()
        .map(|(k, &(t, f))| {
            let t = t as usize;
            let mut tri = mesh.face(t, f as usize).map(|v| {
                let class = dsu.find((4 * t + corner(t, v)) as u32);
                copy_of.get(&class).copied().unwrap_or(v)
            });
            if let Some(r) = (0..3).find(|&r| !touching[tri[r] as usize]) {
                tri.rotate_left(r);
            }
            (touching[tri[0] as usize], k, tri)
        })
        .collect();
    tris.sort_by_key(|x| (x.0, x.1));
    let order: Vec<u32> = tris.iter().map(|x| x.1 as u32).collect();
    let mut split = SurfaceMesh::closed(points, tris.iter().map(|x| x.2).collect(), 1);
    let opts = ValidateOptions {
        self_intersections: false,
        fix_inward: false,
        ..ValidateOptions::default()
    };
    if let Err(mut e) = validate_surface(&mut split, &opts) {
        restore_indices(&mut e, &original, &order, surface);
        return (Some(e), n_touching);
    }
    (
        check_self_intersections(surface, opts.max_examples).err(),
        n_touching,
    )
}

/// Give an error about the unpinched boundary of [`touching_boundary`] the boundary's own
/// indices: vertex copies as their `original`, triangle `k` as `order[k]`.
fn restore_indices(e: &mut SurfaceError, original: &[u32], order: &[u32], s: &SurfaceMesh) {
    let v = |x: u32| original.get(x as usize).copied().unwrap_or(x);
    let t = |x: u32| order.get(x as usize).copied().unwrap_or(x);
    let tri = |x: &mut TriangleInfo| {
        x.index = t(x.index);
        x.vertices = s.triangles[x.index as usize];
        x.corners = s.corners(x.index as usize);
    };
    match e {
        SurfaceError::NotClosed { first, .. } | SurfaceError::NonManifoldEdge { first, .. } => {
            for x in first {
                let [a, b] = x.edge.map(v);
                x.edge = [a.min(b), a.max(b)];
                x.triangles.iter_mut().for_each(tri);
            }
        }
        SurfaceError::NonManifoldVertex { first, .. } => {
            for x in first {
                x.vertex = v(x.vertex);
                x.triangles.iter_mut().for_each(|k| *k = t(*k));
            }
        }
        SurfaceError::Degenerate { first, .. } | SurfaceError::NonOrientable { first, .. } => {
            first.iter_mut().for_each(tri);
        }
        SurfaceError::Flipped { first, to_flip, .. } => {
            first.iter_mut().for_each(tri);
            to_flip.iter_mut().for_each(|k| *k = t(*k));
            to_flip.sort_unstable();
        }
        SurfaceError::Duplicate { first, .. } | SurfaceError::SelfIntersection { first, .. } => {
            for p in first {
                tri(&mut p.0);
                tri(&mut p.1);
            }
        }
        SurfaceError::Inward { first, .. }
        | SurfaceError::LabelsContradictGeometry { first, .. } => {
            for x in first {
                tri(&mut x.triangle);
            }
        }
        _ => {}
    }
}

fn show_nb(n: u32) -> String {
    if n == NO_NEIGHBOR {
        "none".to_string()
    } else {
        format!("tet {n}")
    }
}

/// True when `a` and `b` list the same three vertices in the same cyclic order.
fn same_cyclic_order(a: [u32; 3], b: [u32; 3]) -> bool {
    let rot = |x: [u32; 3]| {
        let m = (0..3).min_by_key(|&k| x[k]).unwrap_or(0);
        [x[m], x[(m + 1) % 3], x[(m + 2) % 3]]
    };
    rot(a) == rot(b)
}

fn check_surface(
    mesh: &TetMesh,
    s: &SurfaceMesh,
    point_of: &FxHashMap<[u64; 3], usize>,
    face_keys: &[([u32; 3], u32)],
    boundary: &FxHashMap<[u32; 3], (u32, u32)>,
    problems: &mut Vec<String>,
) -> SurfaceConformity {
    let mut c = SurfaceConformity {
        n_triangles: s.triangles.len(),
        ..Default::default()
    };
    let multi_region = mesh.regions().len() > 1;
    let mut per_pair: FxHashMap<[u32; 2], (usize, usize)> = FxHashMap::default();
    let mut outer_matched: Vec<[u32; 3]> = Vec::new();
    let mut listed = 0usize;
    let mut list = |problems: &mut Vec<String>, msg: String| {
        listed += 1;
        if listed <= 2 * LIST_FIRST {
            problems.push(msg);
        }
    };
    // Surface point -> mesh point.
    let map: Vec<Option<u32>> = s
        .points
        .iter()
        .map(|p| point_of.get(&coord_key(p)).map(|&i| i as u32))
        .collect();

    for (t, tri) in s.triangles.iter().enumerate() {
        let sides = s.sides.get(t).copied().unwrap_or([1, 0]);
        let pair = [sides[0].min(sides[1]), sides[0].max(sides[1])];
        per_pair.entry(pair).or_default().0 += 1;
        let corners = s.corners(t);
        let Some(v) = tri
            .iter()
            .map(|&i| map.get(i as usize).copied().flatten())
            .collect::<Option<Vec<u32>>>()
        else {
            c.n_points_missing += 1;
            list(
                problems,
                format!(
                    "surface triangle {t} {tri:?}: a corner of {corners:?} is not a mesh point"
                ),
            );
            continue;
        };
        let fv = [v[0], v[1], v[2]];
        let key = sorted3(fv);
        let lo = face_keys.partition_point(|k| k.0 < key);
        let hits: Vec<(usize, usize)> = face_keys[lo..]
            .iter()
            .take_while(|k| k.0 == key)
            .map(|k| ((k.1 >> 2) as usize, (k.1 & 3) as usize))
            .collect();
        if hits.is_empty() {
            c.n_missing += 1;
            list(
                problems,
                format!("surface triangle {t} {tri:?} at {corners:?} is missing from the mesh"),
            );
            continue;
        }
        // For each tet at this face: is it behind the triangle (same cyclic order as the
        // triangle, since tet faces are outward) or in front?
        let mut ok = true;
        let outer = sides[0] == 0 || sides[1] == 0;
        if outer && hits.len() == 1 {
            outer_matched.push(key);
        }
        if outer {
            if hits.len() != 1 {
                c.n_outer_not_boundary += 1;
                ok = false;
                list(
                    problems,
                    format!(
                        "surface triangle {t} {tri:?} (outer boundary) is an interior face of the mesh"
                    ),
                );
            }
        } else if hits.len() != 2 {
            c.n_interface_wrong += 1;
            ok = false;
            list(
                problems,
                format!(
                    "surface triangle {t} {tri:?} (interface {}|{}) is a boundary face of the mesh",
                    sides[0], sides[1]
                ),
            );
        }
        if ok && (multi_region || !outer) {
            for &(tet, f) in &hits {
                let behind = same_cyclic_order(mesh.face(tet, f), fv);
                let want = if behind { sides[0] } else { sides[1] };
                let got = mesh.labels.get(tet).copied().unwrap_or(u32::MAX);
                if got != want {
                    c.n_label_mismatch += 1;
                    ok = false;
                    list(
                        problems,
                        format!(
                            "surface triangle {t} {tri:?}: tet {tet} on its {} side has label {got}, expected {want}",
                            if behind { "back" } else { "front" }
                        ),
                    );
                    break;
                }
            }
        }
        if ok {
            c.n_found += 1;
            per_pair.entry(pair).or_default().1 += 1;
        }
    }
    // Boundary faces that are no outer triangle (whatever their labels).
    outer_matched.sort_unstable();
    outer_matched.dedup();
    c.n_extra_boundary_faces = boundary.len() - outer_matched.len();
    if c.n_extra_boundary_faces > 0 && c.n_found == c.n_triangles {
        problems.push(format!(
            "{} mesh boundary faces are not triangles of the surface",
            c.n_extra_boundary_faces
        ));
    }
    let mut pairs: Vec<_> = per_pair.into_iter().collect();
    pairs.sort_unstable();
    c.interfaces = pairs
        .into_iter()
        .map(|(labels, (expected, found))| InterfaceConformity {
            labels,
            expected,
            found,
        })
        .collect();
    c
}

impl fmt::Display for CheckReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{}: {} points, {} tets, {} boundary faces",
            if self.valid { "valid" } else { "INVALID" },
            self.n_points,
            self.n_tets,
            self.n_boundary_faces
        )?;
        let rows = [
            ("tets with bad or repeated vertex indices", self.n_bad_tets),
            ("tets not strictly positive", self.n_nonpositive),
            ("faces in more than two tets", self.n_overshared_faces),
            (
                "interior faces with equal orientations",
                self.n_misoriented_faces,
            ),
            ("adjacency entries wrong", self.n_adjacency_errors),
            ("unused points", self.n_unused_points),
            ("duplicate points", self.n_duplicate_points),
            ("non-finite points", self.n_nonfinite_points),
            ("label array errors", self.n_label_errors),
        ];
        for (what, n) in rows {
            if n > 0 {
                writeln!(f, "  {n} {what}")?;
            }
        }
        if self.n_touching_vertices > 0 {
            writeln!(
                f,
                "  different regions touch at {} boundary {} (a shared vertex or edge, not a face)",
                self.n_touching_vertices,
                if self.n_touching_vertices == 1 {
                    "vertex"
                } else {
                    "vertices"
                }
            )?;
        }
        if let Some(s) = &self.surface {
            writeln!(
                f,
                "surface: {} of {} triangles present",
                s.n_found, s.n_triangles
            )?;
            for i in &s.interfaces {
                let name = if i.labels[0] == 0 {
                    format!("boundary of region {}", i.labels[1])
                } else {
                    format!("interface {}|{}", i.labels[0], i.labels[1])
                };
                writeln!(f, "  {name}: {} of {} found", i.found, i.expected)?;
            }
            let rows = [
                (
                    "triangles with a corner that is no mesh point",
                    s.n_points_missing,
                ),
                ("triangles missing", s.n_missing),
                ("outer triangles inside the mesh", s.n_outer_not_boundary),
                (
                    "interface triangles on the mesh boundary",
                    s.n_interface_wrong,
                ),
                (
                    "triangles with wrong labels beside them",
                    s.n_label_mismatch,
                ),
                (
                    "boundary faces not on the surface",
                    s.n_extra_boundary_faces,
                ),
            ];
            for (what, n) in rows {
                if n > 0 {
                    writeln!(f, "  {n} {what}")?;
                }
            }
        }
        for g in &self.regions {
            write!(
                f,
                "region {}: {} tets, volume {:.6e}",
                g.label, g.n_tets, g.volume
            )?;
            if let Some(e) = g.enclosed_volume {
                write!(f, " (its surface encloses {e:.6e})")?;
            }
            if g.n_tets > 0 {
                write!(
                    f,
                    ", dihedral {:.2}°–{:.2}°, min solid angle {:.4} sr",
                    g.min_dihedral_deg, g.max_dihedral_deg, g.min_solid_angle_sr
                )?;
            }
            writeln!(f)?;
        }
        for p in &self.problems {
            writeln!(f, "  - {p}")?;
        }
        Ok(())
    }
}
