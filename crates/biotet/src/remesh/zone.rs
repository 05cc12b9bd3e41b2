//! Which tets a box or a ball zone meets.

use super::Zone;
use crate::geom::vec3::{cross, dot, norm, sub};
use crate::mesh::tet::TET_FACES;
use crate::surface::bvh::closest_on_triangle;

type P3 = [f64; 3];

/// Does the tet with corners `c` meet the zone? Floating point: the zone is the user's choice
/// of what to replace, not a combinatorial decision of the mesh.
pub(super) fn meets(zone: &Zone, label: u32, c: &[P3; 4]) -> bool {
    // The tet's box first: most tets of a large mesh are far from a small zone.
    let (tlo, thi) = crate::geom::vec3::bbox(c);
    match *zone {
        Zone::Region(r) => label == r,
        Zone::Box { lo, hi } => {
            (0..3).all(|k| tlo[k] <= hi[k] && thi[k] >= lo[k]) && tet_meets_box(c, lo, hi)
        }
        Zone::Sphere { centre, radius } => {
            let gap: f64 = (0..3)
                .map(|k| {
                    (tlo[k] - centre[k])
                        .max(centre[k] - thi[k])
                        .max(0.0)
                        .powi(2)
                })
                .sum();
            gap <= radius * radius && tet_distance(c, centre) <= radius
        }
    }
}

/// Separating-axis test of a tet and an axis-aligned box (both closed).
fn tet_meets_box(c: &[P3; 4], lo: P3, hi: P3) -> bool {
    let box_corners: Vec<P3> = (0..8)
        .map(|i| {
            [
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ]
        })
        .collect();
    let separated = |axis: P3| {
        if dot(axis, axis) == 0.0 {
            return false;
        }
        let (a0, a1) = c
            .iter()
            .map(|p| dot(*p, axis))
            .fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)));
        let (b0, b1) = box_corners
            .iter()
            .map(|p| dot(*p, axis))
            .fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)));
        a1 < b0 || b1 < a0
    };
    let axes_box = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if axes_box.iter().any(|&a| separated(a)) {
        return false;
    }
    for f in TET_FACES {
        if separated(cross(sub(c[f[1]], c[f[0]]), sub(c[f[2]], c[f[0]]))) {
            return false;
        }
    }
    for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
        let e = sub(c[j], c[i]);
        if axes_box.iter().any(|&a| separated(cross(e, a))) {
            return false;
        }
    }
    true
}

/// Distance from `p` to the closed tet `c` (0 inside).
fn tet_distance(c: &[P3; 4], p: P3) -> f64 {
    let inside = TET_FACES.iter().all(|f| {
        let n = cross(sub(c[f[1]], c[f[0]]), sub(c[f[2]], c[f[0]]));
        dot(n, sub(p, c[f[0]])) <= 0.0
    });
    if inside {
        return 0.0;
    }
    TET_FACES
        .iter()
        .map(|f| norm(sub(p, closest_on_triangle(p, &[c[f[0]], c[f[1]], c[f[2]]]))))
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_and_sphere_tests_agree_with_simple_cases() {
        let c = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(tet_meets_box(&c, [0.2; 3], [0.3; 3]));
        assert!(!tet_meets_box(&c, [0.4; 3], [0.5; 3])); // beyond the slanted face
        assert!(tet_meets_box(&c, [-1.0; 3], [0.0; 3])); // touching at a corner
        assert!(!tet_meets_box(&c, [1.1, -1.0, -1.0], [2.0, 1.0, 1.0]));
        assert_eq!(tet_distance(&c, [0.1; 3]), 0.0);
        assert!((tet_distance(&c, [-1.0, 0.0, 0.0]) - 1.0).abs() < 1e-15);
        let d = tet_distance(&c, [1.0; 3]);
        assert!((d - (2.0 / 3f64.sqrt())).abs() < 1e-12, "{d}");
    }
}
