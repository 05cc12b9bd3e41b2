//! The boundary surface of a tet mesh seen from one viewpoint, shaded, drawn back to front
//! (a painter's algorithm: enough for a closed surface seen from outside, where the nearer
//! triangle always covers the farther one it overlaps).

use super::palette::{label_color, label_key, shade};
use super::{Polygon, Scene};
use biotet::mesh::tet::{NO_NEIGHBOR, TET_FACES, TetMesh};

/// The direction to the eye, the usual isometric one: from +x, −y, +z looking at the centre,
/// z up.
const EYE: [f64; 3] = [1.0, -1.0, 1.0];
/// The light comes from over the viewer's left shoulder.
const LIGHT: [f64; 3] = [0.3, -0.9, 1.0];

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    if l > 0.0 { a.map(|x| x / l) } else { a }
}

/// The boundary faces of `mesh` (faces with no tet across), coloured by their tet's region,
/// shaded by the angle to the light, the faces turned away from the eye left out.
pub fn boundary(mesh: &TetMesh) -> (Scene, usize) {
    let regions = mesh.regions();
    let eye = unit(EYE);
    let light = unit(LIGHT);
    // Screen axes: x across, y up (world z projected).
    let up = [0.0, 0.0, 1.0];
    let sx = unit(cross(up, eye));
    let sy = cross(eye, sx);
    let mut faces: Vec<(f64, Polygon)> = Vec::new();
    let mut shown = vec![false; regions.len()];
    for (t, tet) in mesh.tets.iter().enumerate() {
        for (f, face) in TET_FACES.iter().enumerate() {
            if mesh.neighbors.get(t).is_some_and(|n| n[f] != NO_NEIGHBOR) {
                continue;
            }
            let c = face.map(|k| mesh.points[tet[k] as usize]);
            // Outward normal (the face is counter-clockwise from outside its tet).
            let n = unit(cross(sub(c[1], c[0]), sub(c[2], c[0])));
            if dot(n, eye) <= 0.0 {
                continue;
            }
            let r = regions.binary_search(&mesh.labels[t]).unwrap_or(0);
            shown[r] = true;
            let lit = 0.35 + 0.65 * dot(n, light).max(0.0);
            let fill = shade(label_color(r), lit);
            let depth = c.iter().map(|&p| dot(p, eye)).sum::<f64>();
            faces.push((
                depth,
                Polygon {
                    points: c.iter().map(|&p| [dot(p, sx), dot(p, sy)]).collect(),
                    fill,
                    stroke: Some(shade(fill, 0.85)),
                },
            ));
        }
    }
    // Farthest first (smallest depth along the eye's direction is farthest from the eye,
    // which looks along −eye); ties in input order, so the output is deterministic.
    faces.sort_by(|a, b| a.0.total_cmp(&b.0));
    let n = faces.len();
    let key = label_key(&regions, &shown);
    (
        Scene {
            polygons: faces.into_iter().map(|(_, p)| p).collect(),
            segments: Vec::new(),
            key,
            title: String::new(),
        },
        n,
    )
}
