//! Where a tet sits relative to the input surface, and whether the input forces it to be poor.
//!
//! Marching-cubes surfaces carry triangles with angles of 0.01° and folds where two triangles
//! meet at a tiny interior angle. Any mesh that keeps the surface must then contain a tet with a
//! tiny solid (and usually dihedral) angle there, whatever the fill: such a tet is *forced*. A tet
//! is forced when
//! - one of its faces is an input triangle whose smallest angle is below the threshold (unless
//!   the tet is far flatter than that triangle: see [`face_forces`]), or
//! - one of its edges is an input edge at which the surface, seen from the tet's region, folds
//!   to an interior dihedral angle below the threshold.
//!
//! Quality reports split forced from unforced tets: the unforced ones are what a mesher can fix.
//! Surface triangles are matched to mesh faces by exact point coordinates.

use serde::Serialize;

use crate::geom::vec3::{cross, dot, norm, sub};
use crate::mesh::match_points;
use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::{TET_EDGES, TET_FACES, TetMesh};
use crate::quality::tet::{TetMeasures, dihedral_angles};
use crate::quality::tri::min_angle_3d_deg;

/// A tet whose smallest dihedral angle is below this fraction of its poor input face's smallest
/// angle is flatter than the face forces: a tet on a needle of angle α can have its angles near
/// α (its edge from the needle's tip square to the needle), and a flat one on a planar quad of a
/// needle and its neighbour (a lattice's joint kept one at 3e-15° on a 2.75° needle, TetGen
/// 0.09° there) is the mesher's to fix.
pub const FLAT_BELOW_FACE: f64 = 1e-3;

/// Whether an input face whose smallest angle is `face_deg` forces a tet on it whose smallest
/// dihedral angle is `tet_deg` (degrees) to be poor against `threshold_deg`.
pub fn face_forces(face_deg: f64, tet_deg: f64, threshold_deg: f64) -> bool {
    face_deg < threshold_deg && tet_deg >= FLAT_BELOW_FACE * face_deg
}

/// Where a tet touches the input surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Placement {
    /// One of its faces is an input triangle.
    Face,
    /// It has a surface point but no input triangle as a face.
    Vertex,
    /// No surface point.
    Interior,
}

/// Per-tet placement and forcing.
#[derive(Debug, Clone)]
pub struct Forcing {
    /// Placement of each tet.
    pub placement: Vec<Placement>,
    /// Whether each tet is forced poor by the input.
    pub forced: Vec<bool>,
    /// Per mesh point: a corner of an input triangle with an angle below the threshold.
    pub poor_corner: Vec<bool>,
    /// The edges (mesh points, smaller first, sorted) of input triangles with an angle below
    /// the threshold.
    pub poor_edges: Vec<[u32; 2]>,
}

impl Forcing {
    /// Why an unforced tet with corners `tet` and its smallest dihedral angle at local edge `e`
    /// may still be poor: 0 when the opposite edge (the short edge of a wedge) is an edge of a
    /// poor input triangle, 1 when a corner is on one, 2 otherwise.
    pub fn cause(&self, tet: [u32; 4], e: usize) -> usize {
        let [i, j] = TET_EDGES[5 - e];
        let (a, b) = (tet[i], tet[j]);
        if self.poor_edges.binary_search(&[a.min(b), a.max(b)]).is_ok() {
            0
        } else if tet.iter().any(|&v| self.poor_corner[v as usize]) {
            1
        } else {
            2
        }
    }
}

/// Counts of [`classify`], with the quality of the unforced tets.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ForcingSummary {
    /// The angle threshold used (degrees).
    pub threshold_deg: f64,
    /// Tets with an input triangle as a face.
    pub n_face: usize,
    /// Tets touching the surface at a point only.
    pub n_vertex: usize,
    /// Tets away from the surface.
    pub n_interior: usize,
    /// Forced tets.
    pub n_forced: usize,
    /// Forced tets whose smallest dihedral angle is below 10°.
    pub n_forced_dihedral_lt_10: usize,
    /// Unforced tets whose smallest dihedral angle is below 5°.
    pub n_unforced_dihedral_lt_5: usize,
    /// Unforced tets whose smallest dihedral angle is below 10°.
    pub n_unforced_dihedral_lt_10: usize,
    /// Unforced tets whose smallest dihedral angle is below 20°.
    pub n_unforced_dihedral_lt_20: usize,
    /// Smallest dihedral angle of an unforced tet.
    pub unforced_min_dihedral_deg: Option<f64>,
    /// Tets below 10° by placement: `[face, vertex, interior]`.
    pub dihedral_lt_10_by_placement: [usize; 3],
    /// Unforced tets below 10° by what bounds them (see [`Forcing::cause`]): `[the edge opposite
    /// their smallest angle is an edge of a poor input triangle, a corner is on a poor input
    /// triangle, neither]`.
    pub unforced_lt_10_by_cause: [usize; 3],
}

impl ForcingSummary {
    /// The unforced tets under 10° by cause, for a report line: `"109 opposite an edge of a
    /// poor input triangle, 48 with a corner on one, 1 neither"`.
    pub fn cause_text(&self) -> String {
        let [e, c, o] = self.unforced_lt_10_by_cause;
        format!(
            "{e} opposite an edge of a poor input triangle, {c} with a corner on one, {o} neither"
        )
    }
}

#[inline]
fn sorted3(mut a: [u32; 3]) -> [u32; 3] {
    a.sort_unstable();
    a
}

/// Classify every tet of `mesh` against `surface` with the angle `threshold_deg`.
pub fn classify(mesh: &TetMesh, surface: &SurfaceMesh, threshold_deg: f64) -> Forcing {
    // Mesh point -> surface point.
    let surf_of = match_points(&mesh.points, &surface.points);
    // Input triangles and half-edges as indices sorted by their vertex sets: 4 bytes each, where
    // hash maps (with a list per edge) took several times the mesh's size on brain_20k.
    let tri_key = |t: u32| sorted3(surface.triangles[t as usize]);
    let mut triangles: Vec<u32> = (0..surface.triangles.len() as u32).collect();
    triangles.sort_unstable_by(|&a, &b| tri_key(a).cmp(&tri_key(b)).then(a.cmp(&b)));
    let face_deg: Vec<f64> = (0..surface.triangles.len())
        .map(|t| min_angle_3d_deg(&surface.corners(t)))
        .collect();
    let poor: Vec<bool> = face_deg.iter().map(|&a| a < threshold_deg).collect();
    // Half-edge 3t+k runs from corner k of triangle t to corner k+1; its use of the edge is
    // (triangle t, opposite corner k+2).
    let edge_key = |h: u32| {
        let tri = surface.triangles[h as usize / 3];
        let k = h as usize % 3;
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        [a.min(b), a.max(b)]
    };
    let mut edges: Vec<u32> = (0..3 * surface.triangles.len() as u32).collect();
    edges.sort_unstable_by(|&a, &b| edge_key(a).cmp(&edge_key(b)).then(a.cmp(&b)));
    let opposite = |h: u32| surface.triangles[h as usize / 3][(h as usize % 3 + 2) % 3];
    let mut placement = Vec::with_capacity(mesh.tets.len());
    let mut forced = Vec::with_capacity(mesh.tets.len());
    for (t, tet) in mesh.tets.iter().enumerate() {
        let s = tet.map(|v| surf_of[v as usize]);
        let n_surf = s.iter().filter(|&&x| x != u32::MAX).count();
        let mut place = if n_surf > 0 {
            Placement::Vertex
        } else {
            Placement::Interior
        };
        let mut is_forced = false;
        let mut tet_deg = None;
        if n_surf >= 3 {
            for f in TET_FACES {
                let k = [s[f[0]], s[f[1]], s[f[2]]];
                if k.contains(&u32::MAX) {
                    continue;
                }
                let k = sorted3(k);
                // Of repeated triangles, the last (as a map's last insert).
                let n = triangles.partition_point(|&i| tri_key(i) <= k);
                if n > 0 && tri_key(triangles[n - 1]) == k {
                    place = Placement::Face;
                    let f = triangles[n - 1] as usize;
                    if poor[f] && !is_forced {
                        let d = *tet_deg.get_or_insert_with(|| {
                            let a = dihedral_angles(&mesh.corners(t));
                            a.iter().fold(f64::INFINITY, |m, &x| m.min(x)).to_degrees()
                        });
                        is_forced = face_forces(face_deg[f], d, threshold_deg);
                    }
                }
            }
        }
        if n_surf >= 2 && !is_forced {
            // An input edge of the tet at which the surface folds sharply on the tet's side: the
            // tet lies inside the wedge, so its own dihedral angle there is at most the wedge's.
            let c = mesh.corners(t);
            let angles = dihedral_angles(&c);
            for (e, &[i, j]) in TET_EDGES.iter().enumerate() {
                let (a, b) = (s[i], s[j]);
                if a == u32::MAX || b == u32::MAX {
                    continue;
                }
                let k = [a.min(b), a.max(b)];
                let lo = edges.partition_point(|&h| edge_key(h) < k);
                let hi = lo + edges[lo..].partition_point(|&h| edge_key(h) == k);
                let uses = &edges[lo..hi];
                if uses.len() >= 2 && angles[e].to_degrees() < threshold_deg {
                    // The tet's own angle at an input edge is below the threshold; it is forced
                    // when the surface's wedge there (on the tet's side) is below it too.
                    let opp = uses.iter().map(|&h| opposite(h));
                    if wedge_below(surface, opp, &c, i, j, threshold_deg) {
                        is_forced = true;
                        break;
                    }
                }
            }
        }
        placement.push(place);
        forced.push(is_forced);
    }
    let mut poor_corner = vec![false; mesh.points.len()];
    let mut poor_edges = Vec::new();
    let mesh_of = {
        let mut m = vec![u32::MAX; surface.points.len()];
        for (v, &sv) in surf_of.iter().enumerate() {
            if sv != u32::MAX {
                m[sv as usize] = v as u32;
            }
        }
        m
    };
    for (t, tri) in surface.triangles.iter().enumerate() {
        if !poor[t] {
            continue;
        }
        let v = tri.map(|x| mesh_of[x as usize]);
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            if a != u32::MAX {
                poor_corner[a as usize] = true;
            }
            if a != u32::MAX && b != u32::MAX {
                poor_edges.push([a.min(b), a.max(b)]);
            }
        }
    }
    poor_edges.sort_unstable();
    poor_edges.dedup();
    Forcing {
        placement,
        forced,
        poor_corner,
        poor_edges,
    }
}

/// Whether the surface triangles at an edge `(c[i], c[j])` form, around the tet, a wedge whose
/// angle is below the threshold: the two triangles nearest the tet on either side enclose it.
fn wedge_below(
    surface: &SurfaceMesh,
    opposite: impl Iterator<Item = u32>,
    c: &[[f64; 3]; 4],
    i: usize,
    j: usize,
    threshold_deg: f64,
) -> bool {
    let (a, b) = (c[i], c[j]);
    let axis = sub(b, a);
    let len = norm(axis);
    if len == 0.0 {
        return false;
    }
    let axis = axis.map(|x| x / len);
    // Angle around the edge of a point, from a reference direction.
    let perp = |p: [f64; 3]| {
        let d = sub(p, a);
        let along = dot(d, axis);
        sub(d, axis.map(|x| x * along))
    };
    let others: Vec<usize> = (0..4).filter(|&k| k != i && k != j).collect();
    let mid = {
        let (p, q) = (c[others[0]], c[others[1]]);
        perp([0, 1, 2].map(|k| (p[k] + q[k]) / 2.0))
    };
    let r0 = mid;
    let r1 = cross(axis, r0);
    let angle = |p: [f64; 3]| {
        let d = perp(p);
        dot(d, r1).atan2(dot(d, r0))
    };
    // The tet's middle direction is angle 0; the nearest triangle on each side bounds the wedge.
    let mut lo = -std::f64::consts::PI;
    let mut hi = std::f64::consts::PI;
    for opp in opposite {
        let th = angle(surface.points[opp as usize]);
        if th < 0.0 {
            lo = lo.max(th);
        } else {
            hi = hi.min(th);
        }
    }
    (hi - lo).to_degrees() < threshold_deg
}

/// Summarise a classification with the tets' smallest dihedral angles.
pub fn summarise(mesh: &TetMesh, f: &Forcing, threshold_deg: f64) -> ForcingSummary {
    let mut s = ForcingSummary {
        threshold_deg,
        ..ForcingSummary::default()
    };
    for t in 0..mesh.tets.len() {
        let angles = dihedral_angles(&mesh.corners(t));
        let (e, m) =
            angles.iter().enumerate().fold(
                (0, f64::INFINITY),
                |b, (e, &a)| if a < b.1 { (e, a) } else { b },
            );
        let m = m.to_degrees();
        let slot = match f.placement[t] {
            Placement::Face => {
                s.n_face += 1;
                0
            }
            Placement::Vertex => {
                s.n_vertex += 1;
                1
            }
            Placement::Interior => {
                s.n_interior += 1;
                2
            }
        };
        if m < 10.0 {
            s.dihedral_lt_10_by_placement[slot] += 1;
        }
        if f.forced[t] {
            s.n_forced += 1;
            s.n_forced_dihedral_lt_10 += usize::from(m < 10.0);
        } else {
            s.n_unforced_dihedral_lt_5 += usize::from(m < 5.0);
            s.n_unforced_dihedral_lt_10 += usize::from(m < 10.0);
            if m < 10.0 {
                s.unforced_lt_10_by_cause[f.cause(mesh.tets[t], e)] += 1;
            }
            s.n_unforced_dihedral_lt_20 += usize::from(m < 20.0);
            s.unforced_min_dihedral_deg = Some(s.unforced_min_dihedral_deg.map_or(m, |x| x.min(m)));
        }
    }
    s
}

/// Quality of the tets of one [`Placement`] class.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ClassQuality {
    /// Tets in the class.
    pub n_tets: usize,
    /// Forced tets in the class.
    pub n_forced: usize,
    /// Smallest dihedral angle (degrees; `None` for an empty class).
    pub min_dihedral_deg: Option<f64>,
    /// Largest dihedral angle (degrees).
    pub max_dihedral_deg: Option<f64>,
    /// Smallest solid angle (steradians).
    pub min_solid_angle_sr: Option<f64>,
    /// Mean q (eq. 4.9).
    pub mean_q: Option<f64>,
    /// Tets whose smallest dihedral angle is below 5°.
    pub n_dihedral_lt_5: usize,
    /// Tets whose smallest dihedral angle is below 10°.
    pub n_dihedral_lt_10: usize,
    /// Tets whose smallest dihedral angle is below 20°.
    pub n_dihedral_lt_20: usize,
}

/// Quality split by [`Placement`]: tets with an input triangle as a face, touching the surface
/// at points only, and away from it.
#[derive(Debug, Clone, Default, Serialize)]
pub struct PlacementQuality {
    /// Tets with an input triangle as a face.
    pub face: ClassQuality,
    /// Tets touching the surface at a point only.
    pub vertex: ClassQuality,
    /// Tets away from the surface.
    pub interior: ClassQuality,
}

/// The quality of each placement class of a classification.
pub fn placement_quality(mesh: &TetMesh, f: &Forcing) -> PlacementQuality {
    let mut out = PlacementQuality::default();
    let mut sum_q = [0.0f64; 3];
    for t in 0..mesh.tets.len() {
        let m = TetMeasures::of(&mesh.corners(t));
        let (slot, c) = match f.placement[t] {
            Placement::Face => (0, &mut out.face),
            Placement::Vertex => (1, &mut out.vertex),
            Placement::Interior => (2, &mut out.interior),
        };
        let (lo, hi) = (m.min_dihedral(), m.max_dihedral());
        c.n_tets += 1;
        c.n_forced += usize::from(f.forced[t]);
        c.min_dihedral_deg = Some(c.min_dihedral_deg.map_or(lo, |x| x.min(lo)));
        c.max_dihedral_deg = Some(c.max_dihedral_deg.map_or(hi, |x| x.max(hi)));
        let s = m.min_solid();
        c.min_solid_angle_sr = Some(c.min_solid_angle_sr.map_or(s, |x| x.min(s)));
        c.n_dihedral_lt_5 += usize::from(lo < 5.0);
        c.n_dihedral_lt_10 += usize::from(lo < 10.0);
        c.n_dihedral_lt_20 += usize::from(lo < 20.0);
        sum_q[slot] += m.q;
    }
    for (c, s) in [&mut out.face, &mut out.vertex, &mut out.interior]
        .into_iter()
        .zip(sum_q)
    {
        if c.n_tets > 0 {
            c.mean_q = Some(s / c.n_tets as f64);
        }
    }
    out
}
