//! The tets a plane cuts, drawn as their cross-sections (the dissertation's figures 2.12,
//! 2.13 and 3.12 are such cuts), with the boundary and interfaces traced.
//!
//! Floating point throughout: this draws, it decides nothing about the mesh.

use super::palette::{label_color, label_key, ramp, shade};
use super::{Key, Polygon, Rgb, Scene, Segment};
use biotet::mesh::surface::SurfaceMesh;
use biotet::mesh::tet::{NO_NEIGHBOR, TET_EDGES, TET_FACES, TetMesh};
use biotet::quality::tet::min_dihedral_deg;

/// A cutting plane `n·x = d` with a frame `(u, v)` in it for the drawing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub n: [f64; 3],
    /// Offset along the normal.
    pub d: f64,
    /// Drawing x axis (unit, in the plane).
    pub u: [f64; 3],
    /// Drawing y axis (unit, in the plane).
    pub v: [f64; 3],
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(a: [f64; 3]) -> Option<[f64; 3]> {
    let l = dot(a, a).sqrt();
    (l > 0.0 && l.is_finite()).then(|| a.map(|x| x / l))
}

impl Plane {
    /// The plane `x[axis] = c`, drawn with the other two axes in their usual orientation
    /// (x = c: y right, z up; y = c: x right, z up; z = c: x right, y up).
    pub fn axis(axis: usize, c: f64) -> Plane {
        let e = |k: usize| {
            let mut a = [0.0; 3];
            a[k] = 1.0;
            a
        };
        let (u, v) = match axis {
            0 => (e(1), e(2)),
            1 => (e(0), e(2)),
            _ => (e(0), e(1)),
        };
        Plane {
            n: e(axis.min(2)),
            d: c,
            u,
            v,
        }
    }

    /// The plane through `p` with normal `n` (any length but zero); the drawing's y axis is
    /// world z projected on the plane (world y when the plane is horizontal).
    pub fn through(p: [f64; 3], n: [f64; 3]) -> Option<Plane> {
        let n = unit(n)?;
        let up = if n[2].abs() > 0.9 {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        let k = dot(up, n);
        let v = unit([0, 1, 2].map(|i| up[i] - k * n[i]))?;
        let u = cross(v, n);
        Some(Plane {
            n,
            d: dot(n, p),
            u,
            v,
        })
    }

    fn side(&self, p: [f64; 3]) -> f64 {
        dot(self.n, p) - self.d
    }

    fn project(&self, p: [f64; 3]) -> [f64; 2] {
        [dot(self.u, p), dot(self.v, p)]
    }
}

/// How the cut tets are coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Coloring {
    /// By region label (a qualitative palette, with a legend).
    Label,
    /// By the tet's smallest dihedral angle (a colour bar from 0° to 70.5°).
    Quality,
}

/// The largest smallest dihedral angle a tet has (the regular tet's, arccos 1/3).
const REGULAR_DEG: f64 = 70.528_779_365_509_31;

const TRACE: Rgb = [30, 30, 30];
const SURFACE: Rgb = [255, 0, 200];

/// Where the segment `a`–`b` meets the plane, given the sides `sa`, `sb` of different signs.
fn crossing(a: [f64; 3], b: [f64; 3], sa: f64, sb: f64) -> [f64; 3] {
    let t = sa / (sa - sb);
    [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]))
}

/// The points where the plane meets the simplex with corners `c` and edges `edges`: corners on
/// the plane and edge crossings.
fn cut_points(plane: &Plane, c: &[[f64; 3]], s: &[f64], edges: &[[usize; 2]]) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(4);
    for (k, &p) in c.iter().enumerate() {
        if s[k] == 0.0 {
            out.push(plane.project(p));
        }
    }
    for &[i, j] in edges {
        if (s[i] < 0.0 && s[j] > 0.0) || (s[i] > 0.0 && s[j] < 0.0) {
            out.push(plane.project(crossing(c[i], c[j], s[i], s[j])));
        }
    }
    out
}

/// The corners of a convex polygon in counter-clockwise order around their centroid.
fn order_convex(mut pts: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    let n = pts.len() as f64;
    let cx = pts.iter().map(|p| p[0]).sum::<f64>() / n;
    let cy = pts.iter().map(|p| p[1]).sum::<f64>() / n;
    pts.sort_by(|a, b| {
        let ta = (a[1] - cy).atan2(a[0] - cx);
        let tb = (b[1] - cy).atan2(b[0] - cx);
        ta.total_cmp(&tb)
    });
    pts
}

/// What [`cut`] drew, for the command's report.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct CutCounts {
    /// Tets whose cross-section is a polygon.
    pub tets_cut: usize,
    /// Boundary and interface segments traced.
    pub trace_segments: usize,
    /// Segments of the given surface's trace.
    pub surface_segments: usize,
    /// The smallest dihedral angle among the cut tets (degrees), if any.
    pub min_dihedral_cut: Option<f64>,
}

/// The scene of `mesh` cut by `plane`, coloured by `coloring`, with the trace of `surface`
/// on the plane if given.
pub fn cut(
    mesh: &TetMesh,
    plane: &Plane,
    coloring: Coloring,
    surface: Option<&SurfaceMesh>,
) -> (Scene, CutCounts) {
    let regions = mesh.regions();
    let rank = |l: u32| regions.binary_search(&l).unwrap_or(0);
    let mut polygons = Vec::new();
    let mut segments = Vec::new();
    let mut worst = f64::INFINITY;
    let mut shown = vec![false; regions.len()];
    for (t, tet) in mesh.tets.iter().enumerate() {
        let c = tet.map(|x| mesh.points[x as usize]);
        let s = c.map(|p| plane.side(p));
        let (neg, pos) = (s.iter().any(|&x| x < 0.0), s.iter().any(|&x| x > 0.0));
        // A tet with a face in the plane shows that face, drawn once: by the tet on the plane's
        // positive side (a plane through a grid of faces, x = 20 on a 1 mm image's mesh, would
        // otherwise leave holes).
        let on = s.iter().filter(|&&x| x == 0.0).count();
        if !(pos && (neg || on == 3)) {
            continue;
        }
        let pts = cut_points(plane, &c, &s, &TET_EDGES);
        if pts.len() < 3 {
            continue;
        }
        let r = rank(mesh.labels[t]);
        let fill = match coloring {
            Coloring::Label => {
                shown[r] = true;
                label_color(r)
            }
            Coloring::Quality => {
                let a = min_dihedral_deg(&c);
                worst = worst.min(a);
                ramp(a / REGULAR_DEG)
            }
        };
        polygons.push(Polygon {
            points: order_convex(pts),
            fill,
            stroke: Some(shade(fill, 0.7)),
        });
        if coloring == Coloring::Label {
            let a = min_dihedral_deg(&c);
            worst = worst.min(a);
        }
        // The boundary faces and interfaces (each interface once, from its lower tet).
        for (f, face) in TET_FACES.iter().enumerate() {
            let nb = mesh.neighbors.get(t).map_or(NO_NEIGHBOR, |n| n[f]);
            let traced = nb == NO_NEIGHBOR
                || (mesh.labels[nb as usize] != mesh.labels[t] && (nb as usize) > t);
            if !traced {
                continue;
            }
            let fc = face.map(|k| c[k]);
            let fs = face.map(|k| s[k]);
            let seg = cut_points(plane, &fc, &fs, &[[0, 1], [1, 2], [2, 0]]);
            if seg.len() == 2 {
                segments.push(Segment {
                    ends: [seg[0], seg[1]],
                    color: TRACE,
                    width: 1.5,
                });
            }
        }
    }
    let trace_segments = segments.len();
    let mut surface_segments = 0;
    if let Some(sm) = surface {
        for tri in &sm.triangles {
            let c = tri.map(|x| sm.points[x as usize]);
            let s = c.map(|p| plane.side(p));
            let seg = cut_points(plane, &c, &s, &[[0, 1], [1, 2], [2, 0]]);
            if seg.len() == 2 {
                surface_segments += 1;
                segments.push(Segment {
                    ends: [seg[0], seg[1]],
                    color: SURFACE,
                    width: 1.0,
                });
            }
        }
    }
    let key = match coloring {
        Coloring::Label => label_key(&regions, &shown),
        Coloring::Quality => Key::Bar {
            range: [0.0, REGULAR_DEG],
            ticks: vec![0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0],
            title: "min dihedral °".into(),
        },
    };
    let counts = CutCounts {
        tets_cut: polygons.len(),
        trace_segments,
        surface_segments,
        min_dihedral_cut: worst.is_finite().then_some(worst),
    };
    (
        Scene {
            polygons,
            segments,
            key,
            title: String::new(),
        },
        counts,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tet_cut_through_its_middle_is_a_triangle_or_a_quadrilateral() {
        let mesh = TetMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            vec![[0, 1, 2, 3]],
            vec![4],
        );
        let (scene, counts) = cut(&mesh, &Plane::axis(2, 0.5), Coloring::Label, None);
        assert_eq!(counts.tets_cut, 1);
        assert_eq!(scene.polygons[0].points.len(), 3);
        // The section of the corner tet at z = 1/2 is the triangle (0,0),(1/2,0),(0,1/2).
        let area: f64 = {
            let p = &scene.polygons[0].points;
            0.5 * (0..3)
                .map(|i| p[i][0] * p[(i + 1) % 3][1] - p[(i + 1) % 3][0] * p[i][1])
                .sum::<f64>()
        };
        assert!((area - 0.125).abs() < 1e-12, "{area}");
        // Three boundary faces cross the plane.
        assert_eq!(counts.trace_segments, 3);
        let (_, c2) = cut(&mesh, &Plane::axis(0, 0.25), Coloring::Quality, None);
        assert_eq!(c2.tets_cut, 1);
        let (_, c3) = cut(&mesh, &Plane::axis(2, 2.0), Coloring::Label, None);
        assert_eq!(c3.tets_cut, 0);
    }

    #[test]
    fn an_oblique_plane_has_an_orthonormal_frame() {
        let p = Plane::through([1.0, 2.0, 3.0], [1.0, 1.0, 1.0]).unwrap();
        for (a, b) in [(p.n, p.u), (p.n, p.v), (p.u, p.v)] {
            assert!(dot(a, b).abs() < 1e-12);
        }
        assert!((dot(p.u, p.u) - 1.0).abs() < 1e-12);
        assert!((p.side([1.0, 2.0, 3.0])).abs() < 1e-12);
        assert!(Plane::through([0.0; 3], [0.0; 3]).is_none());
    }
}
