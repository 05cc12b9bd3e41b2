//! Remeshing in place: a region, a sphere and a box replaced, every other tet kept exactly.

use biotet::check::check;
use biotet::mesh::shells::{Part, assemble};
use biotet::mesh::validate::{ValidateOptions, validate_surface};
use biotet::pipeline::{PipelineOptions, mesh_surface};
use biotet::quality::QualityReport;
use biotet::remesh::{Zone, remesh};
use biotet::sizing::{SizeSpec, Sizing, SizingOptions};
use biotet::{SurfaceMesh, TetMesh};
use std::collections::BTreeSet;

/// A ball of radius 4 with a ball of radius 1.5 inside (regions 2 inside, 1 around), meshed at
/// size 0.6.
fn nested() -> (SurfaceMesh, TetMesh) {
    let parts = vec![
        Part {
            surface: SurfaceMesh::icosphere(4.0, 3),
            labels: None,
        },
        Part {
            surface: SurfaceMesh::icosphere(1.5, 2),
            labels: None,
        },
    ];
    let (mut s, _) = assemble(parts).unwrap();
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    let (m, _) = mesh_surface(
        &s,
        Sizing::uniform(0.6).unwrap(),
        &PipelineOptions::default(),
        &mut |_| {},
    )
    .unwrap();
    (s, m)
}

/// Tets as sets of corner coordinates (bit patterns), with their labels.
fn tet_set(m: &TetMesh, range: std::ops::Range<usize>) -> BTreeSet<([[u64; 3]; 4], u32)> {
    range
        .map(|t| {
            let mut c = m.tets[t].map(|v| m.points[v as usize].map(f64::to_bits));
            c.sort();
            (c, m.labels[t])
        })
        .collect()
}

fn region_volumes(m: &TetMesh) -> Vec<(u32, f64)> {
    QualityReport::of(m)
        .regions
        .iter()
        .map(|r| (r.label, r.volume))
        .collect()
}

fn run(m: &TetMesh, zone: Zone, h: f64) -> (TetMesh, biotet::remesh::RemeshReport) {
    let sizing = |s: &SurfaceMesh| Sizing::new(s, SizingOptions::new(SizeSpec::Uniform(h)));
    remesh(m, &zone, &sizing, &PipelineOptions::default(), &mut |_| {}).unwrap()
}

/// The output is valid against the input surface, the kept tets are the input's untouched
/// tets (as coordinate sets, with labels), and the region volumes are unchanged.
fn assert_in_place(
    s: &SurfaceMesh,
    before: &TetMesh,
    after: &TetMesh,
    kept: usize,
    changed: usize,
) {
    let c = check(after, Some(s));
    assert!(c.valid, "{:?}", c.problems);
    assert_eq!(after.tets.len() - kept, changed);
    let old = tet_set(before, 0..before.tets.len());
    let kept_set = tet_set(after, 0..kept);
    assert!(kept_set.is_subset(&old));
    assert_eq!(kept_set.len(), kept);
    // No new tet is an old one's copy in disguise only if something changed; the new ones are
    // not among the kept.
    let new_set = tet_set(after, kept..after.tets.len());
    assert!(new_set.is_disjoint(&kept_set));
    for ((l0, v0), (l1, v1)) in region_volumes(before)
        .into_iter()
        .zip(region_volumes(after))
    {
        assert_eq!(l0, l1);
        assert!((v0 - v1).abs() <= 1e-9 * v0, "region {l0}: {v0} → {v1}");
    }
}

#[test]
fn remeshing_a_region_keeps_the_others_and_its_boundary() {
    let (s, m) = nested();
    let inner_before = m.labels.iter().filter(|&&l| l == 2).count();
    let (fine, r) = run(&m, Zone::Region(2), 0.3);
    assert_eq!(r.tets_kept, m.tets.len() - inner_before);
    assert_eq!(r.cavities.len(), 1);
    let added = r.cavities[0].tets_added;
    assert!(added > 4 * inner_before, "{added} vs {inner_before}");
    assert_in_place(&s, &m, &fine, r.tets_kept, added);
    // Only region 2 changed: every new tet is labelled 2.
    assert!(fine.labels[r.tets_kept..].iter().all(|&l| l == 2));
    // Coarser works too (the shell's own triangles bound how coarse).
    let (coarse, r) = run(&m, Zone::Region(2), 1.5);
    assert!(r.cavities[0].tets_added < added);
    assert_in_place(&s, &m, &coarse, r.tets_kept, r.cavities[0].tets_added);
}

#[test]
fn remeshing_a_sphere_and_a_box_across_the_interface() {
    let (s, m) = nested();
    // Both zones straddle the inner ball's boundary: two cavities, one per region, meeting on
    // interface triangles recovered in both.
    for zone in [
        Zone::Sphere {
            centre: [1.5, 0.0, 0.0],
            radius: 0.6,
        },
        Zone::Box {
            lo: [1.1, -0.4, -0.3],
            hi: [1.9, 0.3, 0.5],
        },
    ] {
        let (out, r) = run(&m, zone, 0.3);
        assert_eq!(r.cavities.len(), 2, "{zone:?}");
        let changed: usize = r.cavities.iter().map(|c| c.tets_added).sum();
        assert_in_place(&s, &m, &out, r.tets_kept, changed);
        assert!(
            r.tets_kept > m.tets.len() / 2,
            "{zone:?}: kept {}",
            r.tets_kept
        );
    }
}

#[test]
fn a_zone_with_no_tet_is_refused() {
    let (_, m) = nested();
    let sizing = |s: &SurfaceMesh| Sizing::new(s, SizingOptions::new(SizeSpec::Uniform(1.0)));
    let e = remesh(
        &m,
        &Zone::Sphere {
            centre: [10.0; 3],
            radius: 1.0,
        },
        &sizing,
        &PipelineOptions::default(),
        &mut |_| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("no tet"), "{e}");
}
