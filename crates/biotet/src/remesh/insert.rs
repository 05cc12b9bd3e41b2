//! Inserting a closed surface (a lesion, an electrode) into a tet mesh in place.
//!
//! The surface must lie inside one region: every decision that says so is exact. Each mesh face
//! on the outer boundary or on an interface whose box overlaps the surface's is tested against
//! the surface's triangles ([`triangles_meet`], closed sets, so touching counts); any contact is
//! refused with the triangle, the face and a point of their contact. An interface or boundary
//! piece entirely inside the surface (the surface enclosing the white matter, say) is found by
//! locating the faces' corners in the surface ([`RegionLocator`]) and refused too.
//!
//! Then the carved tets are every tet whose closed set meets the closed solid the surface
//! bounds: a face meeting a surface triangle, a corner inside or on the surface, or (a surface
//! inside one tet) a shell's first point inside the tet; plus, by floating point (the zone is
//! the user's choice), the tets with a corner within the margin of the surface. So no kept tet
//! and no shell face touches the surface, and the cavity of the surface's region, its shell plus
//! the surface (outside the region's label, inside the new label), is a valid labelled surface
//! for the pipeline, checked again exactly before meshing. Tets of other regions within the
//! margin are refilled with their own labels, as the box and sphere zones do.

use super::cavity::{Inner, cavities, replace};
use super::{P3, RemeshError, RemeshReport};
use crate::geom::intersect::{SegTri, seg_tri, triangles_meet};
use crate::geom::predicates::{Sign, orient3d};
use crate::geom::vec3::bbox;
use crate::geom::vec3::{add, cross, dot, scale, sub};
use crate::mesh::dsu::Dsu;
use crate::mesh::inside::{Location, RegionLocator};
use crate::mesh::surface::SurfaceMesh;
use crate::mesh::tet::{NO_NEIGHBOR, TET_FACES, TetMesh};
use crate::mesh::validate::{ValidateOptions, validate_surface};
use crate::pipeline::PipelineOptions;
use crate::sizing::{Sizing, SizingError};
use crate::surface::bvh::Bvh;
use crate::surface::grid::Grid;
use std::time::Instant;

/// Embed the closed surface `surface` into `mesh` (see the module docs): the tets meeting it,
/// and those with a corner within `margin` of it, are carved out per region and refilled; the
/// inside of the surface gets `label`, everything else keeps its label; every other tet and
/// point stays bit for bit. `sizing` builds the size function on each cavity's surface (for
/// the surface's region: its shell plus the inserted surface).
pub fn insert(
    mesh: &TetMesh,
    surface: &SurfaceMesh,
    label: u32,
    margin: f64,
    sizing: &dyn Fn(&SurfaceMesh) -> Result<Sizing, SizingError>,
    opts: &PipelineOptions,
    progress: &mut dyn FnMut(&str),
) -> Result<(TetMesh, RemeshReport), RemeshError> {
    let start = Instant::now();
    if label == 0 {
        return Err(RemeshError::Label {
            label,
            reason: "0 is the outside",
        });
    }
    progress("checking the surface against the mesh");
    let s = closed_surface(surface)?;
    let index = SurfaceIndex::new(&s);
    refuse_contacts(mesh, &s, &index)?;

    progress("carving");
    let margin = if margin > 0.0 { margin } else { 0.0 };
    let (mut carved, region) = carve(mesh, &s, &index, margin)?;
    if region == label {
        return Err(RemeshError::Label {
            label,
            reason: "it is the region around the inserted surface already",
        });
    }
    let (cavities, grown) = cavities(mesh, &mut carved)?;
    let inner = Inner {
        region,
        surface: &s,
        label,
    };
    replace(
        mesh,
        &carved,
        cavities,
        Some(&inner),
        sizing,
        opts,
        progress,
        start,
        grown,
    )
}

/// The surface with only its used points, one region (label 1), validated (so closed,
/// manifold, outward and not self-intersecting).
fn closed_surface(surface: &SurfaceMesh) -> Result<SurfaceMesh, RemeshError> {
    let mut new_index = vec![u32::MAX; surface.points.len()];
    let mut points = Vec::new();
    let mut triangles = Vec::with_capacity(surface.triangles.len());
    for t in &surface.triangles {
        let mut out = [0u32; 3];
        for (o, &v) in out.iter_mut().zip(t) {
            let Some(slot) = new_index.get_mut(v as usize) else {
                // An index out of range: let validation name it on the uncompacted surface.
                let mut s =
                    SurfaceMesh::closed(surface.points.clone(), surface.triangles.clone(), 1);
                return Err(RemeshError::Surface(
                    validate_surface(&mut s, &ValidateOptions::default())
                        .err()
                        .unwrap_or(crate::mesh::validate::SurfaceError::Empty),
                ));
            };
            if *slot == u32::MAX {
                *slot = points.len() as u32;
                points.push(surface.points[v as usize]);
            }
            *o = *slot;
        }
        triangles.push(out);
    }
    let mut s = SurfaceMesh::closed(points, triangles, 1);
    validate_surface(&mut s, &ValidateOptions::default()).map_err(RemeshError::Surface)?;
    Ok(s)
}

/// The surface's triangles on a grid and in a BVH, its box, and one point per shell.
struct SurfaceIndex<'a> {
    grid: Grid,
    bvh: Bvh,
    lo: P3,
    hi: P3,
    locator: RegionLocator<'a>,
    /// The first point of each vertex-connected component, by index.
    seeds: Vec<(usize, P3)>,
}

impl<'a> SurfaceIndex<'a> {
    fn new(s: &'a SurfaceMesh) -> SurfaceIndex<'a> {
        let nt = s.triangles.len();
        let (lo, hi) = crate::geom::vec3::points_bbox(&s.points);
        let mut edges = 0.0;
        for t in 0..nt {
            let c = s.corners(t);
            for k in 0..3 {
                edges += crate::geom::vec3::norm(sub(c[(k + 1) % 3], c[k]));
            }
        }
        let h = edges / (3 * nt.max(1)) as f64;
        let mut grid = Grid::new(if h > 0.0 && h.is_finite() { h } else { 1.0 });
        let tris: Vec<[P3; 3]> = (0..nt).map(|t| s.corners(t)).collect();
        for (t, c) in tris.iter().enumerate() {
            grid.insert(t as u32, c);
        }
        let bvh = Bvh::new(tris, (0..nt as u32).collect());
        // Components through shared points (union-find on points).
        let mut parent = Dsu::new(s.points.len());
        for t in &s.triangles {
            parent.union(t[0], t[1]);
            parent.union(t[0], t[2]);
        }
        let seeds = (0..s.points.len() as u32)
            .filter(|&v| parent.find(v) == v)
            .map(|v| (v as usize, s.points[v as usize]))
            .collect();
        SurfaceIndex {
            grid,
            bvh,
            lo,
            hi,
            locator: RegionLocator::new(s),
            seeds,
        }
    }

    /// Whether the closed box `lo..hi` overlaps the surface's box (exact comparisons).
    fn overlaps(&self, lo: P3, hi: P3) -> bool {
        (0..3).all(|k| lo[k] <= self.hi[k] && hi[k] >= self.lo[k])
    }

    /// The surface triangles meeting the closed triangle `f`, in increasing order.
    fn meeting(&self, s: &SurfaceMesh, f: &[P3; 3], out: &mut Vec<u32>) {
        let (lo, hi) = bbox(f);
        if !self.overlaps(lo, hi) {
            out.clear();
            return;
        }
        // Every surface triangle's box is inside the surface's box: clamp the query to it.
        let lo = [0, 1, 2].map(|k| lo[k].max(self.lo[k]));
        let hi = [0, 1, 2].map(|k| hi[k].min(self.hi[k]));
        self.grid.query(lo, hi, out);
        out.retain(|&t| triangles_meet(f, &s.corners(t as usize)));
    }
}

/// What a boundary or interface face separates, for messages.
fn separates(a: u32, b: Option<u32>) -> String {
    match b {
        None => format!("the outer boundary of region {a}"),
        Some(b) => format!(
            "the interface between regions {} and {}",
            a.min(b),
            a.max(b)
        ),
    }
}

/// Refuse a surface meeting the mesh's outer boundary or an interface, or enclosing a piece of
/// either.
fn refuse_contacts(
    mesh: &TetMesh,
    s: &SurfaceMesh,
    index: &SurfaceIndex,
) -> Result<(), RemeshError> {
    let mut hits = Vec::new();
    for (t, nb) in mesh.neighbors.iter().enumerate() {
        let own = mesh.labels[t];
        for (i, &n) in nb.iter().enumerate() {
            let other = (n != NO_NEIGHBOR).then(|| mesh.labels[n as usize]);
            // Each interface face once, from its lower-numbered tet.
            if other == Some(own) || (other.is_some() && (n as usize) < t) {
                continue;
            }
            let face = mesh.face(t, i);
            let f = face.map(|v| mesh.points[v as usize]);
            let (lo, hi) = bbox(&f);
            if !index.overlaps(lo, hi) {
                continue;
            }
            index.meeting(s, &f, &mut hits);
            if let Some(&k) = hits.first() {
                let (point, proper) = contact(&s.corners(k as usize), &f);
                return Err(RemeshError::Crossing {
                    triangle: k as usize,
                    how: if proper { "crosses" } else { "meets" },
                    what: separates(own, other),
                    face,
                    point,
                });
            }
            for &v in &face {
                if index.locator.locate(mesh.points[v as usize]) != Location::Region(0) {
                    return Err(RemeshError::Encloses {
                        what: separates(own, other),
                        point: v,
                        at: mesh.points[v as usize],
                    });
                }
            }
        }
    }
    Ok(())
}

/// A point where the meeting triangles `t` and `u` meet (rounded, for the message) and whether
/// an edge of one crosses the other's interior.
fn contact(t: &[P3; 3], u: &[P3; 3]) -> (P3, bool) {
    let mut found = None;
    let mut proper = false;
    for (a, b) in [(t, u), (u, t)] {
        for k in 0..3 {
            let (p, q) = (a[k], a[(k + 1) % 3]);
            let r = seg_tri(p, q, b);
            if r == SegTri::Disjoint {
                continue;
            }
            proper |= r == SegTri::Proper;
            if found.is_none() || r == SegTri::Proper {
                let n = cross(sub(b[1], b[0]), sub(b[2], b[0]));
                let (dp, dq) = (dot(n, sub(p, b[0])), dot(n, sub(q, b[0])));
                found = Some(if dp != dq {
                    add(p, scale(sub(q, p), dp / (dp - dq)))
                } else {
                    p
                });
            }
        }
    }
    (found.unwrap_or(t[0]), proper)
}

/// Whether `p` lies in the closed tet `c` (positively oriented), exactly.
fn in_closed_tet(c: &[P3; 4], p: P3) -> bool {
    TET_FACES
        .iter()
        .all(|f| orient3d(c[f[0]], c[f[2]], c[f[1]], p) != Sign::Negative)
}

/// The tets to carve and the region of the surface: every tet meeting the closed solid (exact)
/// or with a corner within `margin` of the surface.
fn carve(
    mesh: &TetMesh,
    s: &SurfaceMesh,
    index: &SurfaceIndex,
    margin: f64,
) -> Result<(Vec<bool>, u32), RemeshError> {
    let mut carved = vec![false; mesh.tets.len()];
    // Per point: 0 unknown, 1 outside beyond the margin, 2 within the margin, 3 inside or on.
    let mut state = vec![0u8; mesh.points.len()];
    let mut region: Option<u32> = None;
    let mut hits = Vec::new();
    let mut seed_found = vec![false; index.seeds.len()];
    let (lo, hi) = (index.lo.map(|x| x - margin), index.hi.map(|x| x + margin));
    for (t, slot) in carved.iter_mut().enumerate() {
        let c = mesh.corners(t);
        let (tlo, thi) = crate::geom::vec3::bbox(&c);
        if !(0..3).all(|k| tlo[k] <= hi[k] && thi[k] >= lo[k]) {
            continue;
        }
        let mut meets = false;
        let mut near = false;
        for (&v, &p) in mesh.tets[t].iter().zip(&c) {
            let st = &mut state[v as usize];
            if *st == 0 {
                *st = match index.locator.locate(p) {
                    Location::Region(0) => {
                        if margin > 0.0 && index.bvh.any_within(p, margin * margin) {
                            2
                        } else {
                            1
                        }
                    }
                    _ => 3,
                };
            }
            meets |= *st == 3;
            near |= *st == 2;
        }
        for (found, &(_, p)) in seed_found.iter_mut().zip(&index.seeds) {
            if (0..3).all(|k| tlo[k] <= p[k] && p[k] <= thi[k]) && in_closed_tet(&c, p) {
                *found = true;
                meets = true;
            }
        }
        if !meets && index.overlaps(tlo, thi) {
            meets = TET_FACES.iter().any(|f| {
                index.meeting(s, &f.map(|k| c[k]), &mut hits);
                !hits.is_empty()
            });
        }
        if meets {
            let l = mesh.labels[t];
            match region {
                None => region = Some(l),
                Some(r) if r != l => return Err(RemeshError::Regions(r.min(l), r.max(l))),
                _ => {}
            }
        }
        *slot = meets || near;
    }
    // A shell with no tet around its first point is outside the mesh (it meets no boundary).
    if let Some(k) = seed_found.iter().position(|f| !f) {
        let (point, at) = index.seeds[k];
        return Err(RemeshError::Outside { point, at });
    }
    let Some(region) = region else {
        return Err(RemeshError::Outside {
            point: 0,
            at: s.points[0],
        });
    };
    Ok((carved, region))
}
