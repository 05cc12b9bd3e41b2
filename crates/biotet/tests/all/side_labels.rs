//! Side labels given with a surface (as a file gives them) checked against its cells.

use crate::common::cube_surface;
use biotet::SurfaceMesh;
use biotet::mesh::shells::{Part, assemble};
use biotet::mesh::side_labels::{FROM_GEOMETRY, SideLabelError, resolve};
use biotet::mesh::validate::{ValidateOptions, validate_surface};

/// Two unit cubes touching along x = 1 (regions 2 and 3) inside the box [-1, 3] x [-1, 2]²
/// (region 1): one non-manifold surface whose shared square's edges are triple lines.
fn three_regions() -> SurfaceMesh {
    let a = cube_surface([0.0; 3], 1.0);
    let b = cube_surface([1.0, 0.0, 0.0], 1.0);
    let mut c = cube_surface([-1.0, -1.0, -1.0], 1.0);
    for p in &mut c.points {
        p[0] = if p[0] > -1.0 { 3.0 } else { -1.0 };
        p[1] = if p[1] > -1.0 { 2.0 } else { -1.0 };
        p[2] = if p[2] > -1.0 { 2.0 } else { -1.0 };
    }
    let part = |surface, l| Part {
        surface,
        labels: Some(vec![l]),
    };
    let (mut s, _) = assemble(vec![part(a, 2), part(b, 3), part(c, 1)]).unwrap();
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    s
}

/// Index of a triangle with these sides.
fn with_sides(s: &SurfaceMesh, sides: [u32; 2]) -> usize {
    s.sides.iter().position(|&x| x == sides).unwrap()
}

#[test]
fn labels_that_fit_the_cells_are_kept_and_fronts_come_from_the_geometry() {
    let s = three_regions();
    // Three regions meet along the edges of the shared square (three triangles per edge).
    assert!(s.sides.contains(&[2, 3]) || s.sides.contains(&[3, 2]));
    let r = resolve(&s).unwrap();
    assert_eq!(r.surface.sides, s.sides);
    assert_eq!(r.n_from_geometry, 0);
    let mut labels: Vec<u32> = r.shells.iter().map(|sh| sh.label).collect();
    labels.sort_unstable();
    assert_eq!(labels, vec![1, 2, 3]);
    // Only the back labels (a Medit file written once per triangle): the fronts are found.
    let mut back_only = s.clone();
    for x in &mut back_only.sides {
        x[1] = FROM_GEOMETRY;
    }
    let r = resolve(&back_only).unwrap();
    assert_eq!(r.surface.sides, s.sides);
    assert_eq!(r.n_from_geometry, s.triangles.len());
}

#[test]
fn a_wrong_label_is_named_with_its_triangle_and_side() {
    let mut s = three_regions();
    let t = with_sides(&s, [2, 1]);
    s.sides[t] = [3, 1];
    let e = resolve(&s).unwrap_err();
    assert!(
        matches!(e, SideLabelError::Conflict { triangle, side: "back", label: 3, expected: 2, .. } if triangle == t),
        "{e}"
    );
    assert!(e.to_string().contains(&format!("triangle {t}:")), "{e}");
}

#[test]
fn a_triangle_facing_the_wrong_way_is_named() {
    let mut s = three_regions();
    let t = with_sides(&s, [3, 1]);
    s.triangles[t].swap(1, 2); // labels kept: they now contradict the normal
    let e = resolve(&s).unwrap_err();
    assert!(
        matches!(e, SideLabelError::Flipped { triangle, back: 3, front: 1 } if triangle == t),
        "{e}"
    );
    assert!(e.to_string().contains("faces the wrong way"), "{e}");
}

#[test]
fn the_unbounded_side_must_be_the_outside() {
    let mut s = three_regions();
    let t = with_sides(&s, [1, 0]);
    s.sides[t] = [1, 4];
    let e = resolve(&s).unwrap_err();
    assert!(
        matches!(e, SideLabelError::Outside { triangle, side: "front", label: 4 } if triangle == t),
        "{e}"
    );
}

#[test]
fn an_open_region_and_crossing_shells_are_refused_by_validation() {
    // Region 2 open: a triangle of its boundary removed.
    let mut s = three_regions();
    let t = with_sides(&s, [2, 1]);
    s.triangles.remove(t);
    s.sides.remove(t);
    let e = validate_surface(&mut s, &ValidateOptions::default()).unwrap_err();
    assert!(e.to_string().contains("not closed"), "{e}");
    // Two cubes that cross (neither shares a triangle with the other): labelled 1 and 2.
    let mut a = cube_surface([0.0; 3], 1.0);
    let mut b = cube_surface([0.5, 0.5, 0.5], 1.0);
    b.sides = vec![[2, 0]; b.triangles.len()];
    a.append(&b);
    let e = validate_surface(&mut a, &ValidateOptions::default()).unwrap_err();
    assert!(e.to_string().contains("intersect"), "{e}");
}
