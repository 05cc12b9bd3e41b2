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
    nested_with(&PipelineOptions::default())
}

/// [`nested`] meshed with `opts`.
fn nested_with(opts: &PipelineOptions) -> (SurfaceMesh, TetMesh) {
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
    let (m, _) = mesh_surface(&s, Sizing::uniform(0.6).unwrap(), opts, &mut |_| {}).unwrap();
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

/// The adjacency carried over by the splice is the one a full rebuild finds.
fn assert_adjacency(m: &TetMesh) {
    let mut rebuilt = m.clone();
    rebuilt.rebuild_neighbors();
    assert!(
        rebuilt.neighbors == m.neighbors,
        "adjacency differs from a rebuild"
    );
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
    assert_adjacency(after);
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

/// A ball refilled six times finer than its shell's triangles (coarse triangles around fine
/// nodes: recovery failed here with "the cavity grew too large" before the seal cleared caps
/// over large boundary triangles and wide rounds started from the crossed tets).
#[test]
fn a_ball_far_finer_than_its_shell() {
    let (s, m) = nested();
    let zone = Zone::Sphere {
        centre: [2.7, 0.0, 0.0],
        radius: 0.9,
    };
    let (out, r) = run(&m, zone, 0.1);
    let changed: usize = r.cavities.iter().map(|c| c.tets_added).sum();
    assert_in_place(&s, &m, &out, r.tets_kept, changed);
    let removed = m.tets.len() - r.tets_kept;
    assert!(changed > 20 * removed, "{removed} → {changed}");
}

/// `--allow-shell-changes`: sliver removal across the shell replaces some kept tets around the
/// zone, reports each by its input index, keeps every other kept tet and the volumes, and leaves
/// no more tets under 10° than the refill alone. The input is made without sliver removal,
/// smoothing or polishing, so the kept tets around the zone hold slivers to replace.
#[test]
fn sliver_removal_across_the_shell_reports_what_it_changed() {
    let (s, m) = nested_with(&PipelineOptions {
        improve: None,
        smooth: None,
        polish: None,
        ..PipelineOptions::default()
    });
    let zone = Zone::Sphere {
        centre: [2.7, 0.0, 0.0],
        radius: 0.9,
    };
    let (alone, r0) = run(&m, zone, 1.5);
    let mut r = r0.clone();
    let out =
        biotet::remesh::across_shell(&alone, &mut r, &PipelineOptions::default().improve.unwrap());
    let c = r.shell_changes.as_ref().unwrap();
    assert!(!c.kept_replaced.is_empty() && c.kept_replaced.len() <= c.kept_offered);
    assert!(c.improve.n_bad_after < c.improve.n_bad_before);
    assert_in_place(&s, &m, &out, r.tets_kept, out.tets.len() - r.tets_kept);
    assert_eq!(r.kept_input.len(), r.tets_kept);
    // The kept tets are the input's, index for index; the replaced ones are gone.
    let key = |mesh: &TetMesh, t: usize| {
        let mut c = mesh.tets[t].map(|v| mesh.points[v as usize].map(f64::to_bits));
        c.sort();
        (c, mesh.labels[t])
    };
    for (i, &t) in r.kept_input.iter().enumerate() {
        assert_eq!(key(&out, i), key(&m, t as usize));
    }
    let all = tet_set(&out, 0..out.tets.len());
    for &t in &c.kept_replaced {
        assert!(
            !all.contains(&key(&m, t as usize)),
            "kept tet {t} still there"
        );
    }
    let below = |mesh: &TetMesh| QualityReport::of(mesh).n_dihedral_lt_10;
    assert!(
        below(&out) <= below(&alone),
        "{} > {}",
        below(&out),
        below(&alone)
    );
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

/// An icosphere of radius `r` (3 levels) centred at `c`, scaled by `stretch` along x.
fn ball(c: [f64; 3], r: f64, stretch: f64) -> SurfaceMesh {
    let mut s = SurfaceMesh::icosphere(r, 3);
    for p in &mut s.points {
        *p = [c[0] + stretch * p[0], c[1] + p[1], c[2] + p[2]];
    }
    s
}

fn run_insert(
    m: &TetMesh,
    lesion: &SurfaceMesh,
    label: u32,
    margin: f64,
) -> Result<(TetMesh, biotet::remesh::RemeshReport), biotet::remesh::RemeshError> {
    let sizing = |s: &SurfaceMesh| Sizing::new(s, SizingOptions::new(SizeSpec::Uniform(0.3)));
    biotet::remesh::insert(
        m,
        lesion,
        label,
        margin,
        &sizing,
        &PipelineOptions::default(),
        &mut |_| {},
    )
}

/// The model's surface with the lesion added as the boundary between `label` and `around`.
fn with_lesion(s: &SurfaceMesh, lesion: &SurfaceMesh, label: u32, around: u32) -> SurfaceMesh {
    let mut all = s.clone();
    let mut l = lesion.clone();
    l.sides = vec![[label, around]; l.triangles.len()];
    all.append(&l);
    all
}

fn volume_of(m: &TetMesh, label: u32) -> f64 {
    region_volumes(m)
        .into_iter()
        .find(|r| r.0 == label)
        .map_or(0.0, |r| r.1)
}

#[test]
fn inserting_a_surface_inside_one_region_keeps_the_rest() {
    let (s, m) = nested();
    // In the outer shell (region 1, between radii 1.5 and 4), an ellipsoid; and one inside the
    // inner ball (region 2).
    for (lesion, around) in [
        (ball([2.7, 0.0, 0.3], 0.5, 1.4), 1),
        (ball([0.1, 0.2, 0.0], 0.6, 1.5), 2),
    ] {
        let (out, r) = run_insert(&m, &lesion, 3, 0.3).unwrap();
        // Kept tets are input tets, bit for bit, with their labels; new ones are not among them.
        let old = tet_set(&m, 0..m.tets.len());
        let kept = tet_set(&out, 0..r.tets_kept);
        assert_eq!(kept.len(), r.tets_kept);
        assert!(kept.is_subset(&old));
        assert!(tet_set(&out, r.tets_kept..out.tets.len()).is_disjoint(&kept));
        assert!(r.tets_kept > m.tets.len() / 2, "kept {}", r.tets_kept);
        // Valid against the model's surface plus the lesion between labels 3 and `around`.
        let c = check(&out, Some(&with_lesion(&s, &lesion, 3, around)));
        assert!(c.valid, "{:?}", c.problems);
        assert_adjacency(&out);
        // Region 3 holds exactly the lesion's volume, taken from the region around it.
        let v3 = volume_of(&out, 3);
        let mut lesion_mesh = lesion.clone();
        validate_surface(&mut lesion_mesh, &ValidateOptions::default()).unwrap();
        let enclosed: f64 = lesion_mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| lesion_mesh.points[v as usize]);
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum();
        assert!(
            (v3 - enclosed).abs() < 1e-9 * enclosed,
            "{v3} vs {enclosed}"
        );
        let before = volume_of(&m, around);
        let after = volume_of(&out, around) + v3;
        assert!(
            (before - after).abs() < 1e-9 * before,
            "{before} vs {after}"
        );
        let other = 3 - around;
        assert!(
            (volume_of(&m, other) - volume_of(&out, other)).abs() < 1e-9 * volume_of(&m, other)
        );
        // Only new tets carry the new label.
        assert!(out.labels[..r.tets_kept].iter().all(|&l| l != 3));
    }
}

#[test]
fn a_surface_inside_few_tets_and_no_margin() {
    let (s, m) = nested();
    // Smaller than the mesh size: it lies in a handful of tets, possibly inside one.
    let lesion = ball([2.71, 0.13, -0.07], 0.05, 1.0);
    let (out, r) = run_insert(&m, &lesion, 7, 0.0).unwrap();
    assert!(
        r.tets_before - r.tets_kept < 40,
        "{}",
        r.tets_before - r.tets_kept
    );
    let c = check(&out, Some(&with_lesion(&s, &lesion, 7, 1)));
    assert!(c.valid, "{:?}", c.problems);
}

#[test]
fn a_surface_meeting_an_interface_or_the_boundary_is_refused_naming_where() {
    let (_, m) = nested();
    let cases: [(SurfaceMesh, u32, &str); 6] = [
        (
            ball([1.5, 0.0, 0.0], 0.5, 1.0),
            3,
            "interface between regions 1 and 2",
        ),
        (
            ball([4.0, 0.0, 0.0], 0.5, 1.0),
            3,
            "outer boundary of region 1",
        ),
        (
            ball([0.0, 0.0, 0.0], 2.5, 1.0),
            3,
            "encloses part of the interface",
        ),
        (ball([10.0, 0.0, 0.0], 0.5, 1.0), 3, "outside the mesh"),
        (ball([2.7, 0.0, 0.0], 0.5, 1.0), 1, "region around"),
        (ball([2.7, 0.0, 0.0], 0.5, 1.0), 0, "outside"),
    ];
    for (lesion, label, what) in cases {
        let e = run_insert(&m, &lesion, label, 0.2).unwrap_err().to_string();
        assert!(e.contains(what), "{what}: {e}");
    }
    // The crossing message names the triangle and a point on both surfaces.
    let lesion = ball([1.5, 0.0, 0.0], 0.5, 1.0);
    match run_insert(&m, &lesion, 3, 0.2).unwrap_err() {
        biotet::remesh::RemeshError::Crossing {
            triangle, point, ..
        } => {
            assert!(triangle < lesion.triangles.len());
            let r = (point[0] * point[0] + point[1] * point[1] + point[2] * point[2]).sqrt();
            assert!(
                (r - 1.5).abs() < 0.1,
                "{point:?} is not on the inner sphere"
            );
            let d = ((point[0] - 1.5).powi(2) + point[1].powi(2) + point[2].powi(2)).sqrt();
            assert!((d - 0.5).abs() < 0.05, "{point:?} is not on the lesion");
        }
        e => panic!("{e}"),
    }
}

#[test]
fn a_surface_touching_the_interface_at_one_point_is_refused_exactly() {
    let (s, m) = nested();
    // The inner ball's first vertex w (an icosahedron vertex, radius 1.5), and a lesion outside
    // the inner ball whose vertex 3 (pointing at the origin) is put exactly on w: the two meet at
    // that point only.
    let w = s
        .points
        .iter()
        .copied()
        .find(|p| {
            let r2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
            (r2 - 2.25).abs() < 1e-9
        })
        .unwrap();
    let r = 1.5;
    let mut lesion = ball(
        [
            w[0] + 0.5 * w[0] / r,
            w[1] + 0.5 * w[1] / r,
            w[2] + 0.5 * w[2] / r,
        ],
        0.5,
        1.0,
    );
    let k = (0..lesion.points.len())
        .min_by(|&a, &b| {
            let d = |p: [f64; 3]| (0..3).map(|i| (p[i] - w[i]).powi(2)).sum::<f64>();
            d(lesion.points[a]).total_cmp(&d(lesion.points[b]))
        })
        .unwrap();
    lesion.points[k] = w;
    let e = run_insert(&m, &lesion, 3, 0.2).unwrap_err().to_string();
    assert!(
        e.contains("meets the interface between regions 1 and 2"),
        "{e}"
    );
    // Moved off w by a hair towards the lesion's centre, it is accepted.
    let c = [
        w[0] + 0.5 * w[0] / r,
        w[1] + 0.5 * w[1] / r,
        w[2] + 0.5 * w[2] / r,
    ];
    lesion.points[k] = [0, 1, 2].map(|i| w[i] + 1e-6 * (c[i] - w[i]));
    let (out, _) = run_insert(&m, &lesion, 3, 0.2).unwrap();
    let c = check(&out, Some(&with_lesion(&s, &lesion, 3, 1)));
    assert!(c.valid, "{:?}", c.problems);
}

#[test]
fn shells_in_two_regions_are_refused() {
    let (_, m) = nested();
    let mut two = ball([2.7, 0.0, 0.0], 0.4, 1.0);
    two.append(&ball([0.0, 0.0, 0.0], 0.5, 1.0));
    let e = run_insert(&m, &two, 3, 0.2).unwrap_err().to_string();
    assert!(e.contains("shells in regions 1 and 2"), "{e}");
}
