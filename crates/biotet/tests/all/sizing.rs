//! Sizing functions: the surface-derived graded field, clamps and region overrides.

use crate::common::octahedron;
use biotet::sizing::{SizeSpec, Sizing, SizingOptions};

#[test]
fn surface_field_is_the_graded_cone_minimum() {
    let s = octahedron(10.0);
    let mut o = SizingOptions::new(SizeSpec::FromSurface { grading: 0.5 });
    o.min_size = Some(1.0);
    let z = Sizing::new(&s, o).unwrap();
    let h = 200f64.sqrt(); // every edge of the octahedron
    assert!((z.at([10.0, 0.0, 0.0], 1) - h).abs() < 1e-12);
    // At the centre every node is 10 away: h + 0.5 * 10.
    assert!((z.at([0.0, 0.0, 0.0], 1) - (h + 5.0)).abs() < 1e-12);
    assert!((z.min_size() - h).abs() < 1e-12);
}

#[test]
fn clamps_and_region_overrides() {
    let s = octahedron(10.0);
    let mut o = SizingOptions::new(SizeSpec::FromSurface { grading: 1.0 });
    o.max_size = Some(15.0);
    o.region_sizes = vec![(2, 3.0)];
    let z = Sizing::new(&s, o).unwrap();
    assert_eq!(z.at([0.0, 0.0, 0.0], 1), 15.0);
    assert_eq!(z.at([0.0, 0.0, 0.0], 2), 3.0);
    assert_eq!(z.min_size(), 3.0);
    assert!(Sizing::uniform(0.0).is_err());
    assert!(Sizing::uniform(f64::NAN).is_err());
    assert_eq!(Sizing::uniform(2.0).unwrap().at([1e9, 0.0, 0.0], 0), 2.0);
}
