//! Label images to labelled surfaces (`image::extract`): synthetic multi-label volumes validate,
//! mesh, pass `check`, and every region's mesh volume is its voxel volume.

use biotet::image::LabelImage;
use biotet::image::extract::{extract, make_manifold};
use biotet::image::labels::{Components, LabelOptions, apply};
use biotet::mesh::validate::{ValidateOptions, validate_surface};
use biotet::pipeline::{PipelineOptions, mesh_surface};
use biotet::quality::tet::volume;
use biotet::sizing::Sizing;

/// An image from a function of the voxel index, with an anisotropic rotated affine.
fn image(dims: [usize; 3], f: impl Fn(i64, i64, i64) -> u32) -> LabelImage {
    let mut labels = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                labels.push(f(i as i64, j as i64, k as i64));
            }
        }
    }
    let (c, s) = (0.6f64.cos(), 0.6f64.sin());
    // Rotation about z, spacings 1, 1.5, 0.75, an x flip (negative determinant), an offset.
    let m = [
        [-c * 1.0, -s * 1.5, 0.0, 10.0],
        [-s * 1.0, c * 1.5, 0.0, -3.0],
        [0.0, 0.0, 0.75, 2.0],
        [0.0, 0.0, 0.0, 1.0],
    ];
    LabelImage::new(dims, m, labels).unwrap()
}

/// Extract, validate, mesh with the full pipeline, check, and compare region volumes with the
/// voxel volumes (after the manifold repair).
/// Returns the voxels relabelled by the manifold repair and the surface triangles missing from
/// the Delaunay before recovery.
fn extract_and_mesh(mut img: LabelImage, size: f64) -> (usize, usize) {
    // Mesh in the image's axis-aligned frame (voxel faces exactly flat), map to world after.
    let to_world = img.to_frame();
    let (mut s, rep) = extract(&mut img);
    let v = validate_surface(&mut s, &ValidateOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(!v.flipped_inward);
    let vox = img.voxel_volume();
    for (l, n) in img.counts() {
        if l == 0 {
            continue;
        }
        let r = v.regions.iter().find(|r| r.label == l).unwrap();
        assert!(
            (r.volume - n as f64 * vox).abs() < 1e-9 * r.volume,
            "surface of {l}: {} vs {}",
            r.volume,
            n as f64 * vox
        );
    }
    let sizing = Sizing::uniform(size).unwrap();
    let (mut mesh, report) =
        mesh_surface(&s, &sizing, &PipelineOptions::default(), &mut |_| {}).unwrap();
    assert_eq!(report.recover.as_ref().unwrap().missing_after, 0);
    if let Some(m) = &to_world {
        biotet::image::map_points(m, &mut mesh.points);
        biotet::image::map_points(m, &mut s.points);
    }
    let q = biotet::quality::QualityReport::of(&mesh);
    let min = q.min_dihedral_deg.unwrap();
    assert!(min > 5.0, "min dihedral {min}");
    let c = biotet::check::check(&mesh, Some(&s));
    assert!(
        c.valid,
        "{c}\n{:?}\n{:?}\n{:?}",
        c.problems, c.boundary_problem, c.surface
    );
    let mut vol: std::collections::BTreeMap<u32, f64> = Default::default();
    for t in 0..mesh.tets.len() {
        *vol.entry(mesh.labels[t]).or_default() += volume(&mesh.corners(t));
    }
    for (l, n) in img.counts() {
        if l == 0 {
            continue;
        }
        let want = n as f64 * vox;
        assert!(
            (vol[&l] - want).abs() < 1e-9 * want,
            "region {l}: mesh {} vs voxels {want}",
            vol[&l]
        );
    }
    (
        rep.relabelled.iter().map(|r| r.2).sum(),
        report.recover.as_ref().unwrap().missing_before,
    )
}

#[test]
fn ball_in_a_ball() {
    let img = image([10, 10, 10], |i, j, k| {
        let d = (i - 5).pow(2) + (j - 5).pow(2) + (k - 5).pow(2);
        if d <= 4 {
            2
        } else if d <= 14 {
            1
        } else {
            0
        }
    });
    // The quad diagonals are the Delaunay's own: nothing to recover.
    assert_eq!(extract_and_mesh(img, 1.5), (0, 0));
}

#[test]
fn three_labels_meet_at_a_line() {
    // Labels 3, 7 and 12 in three wedges around the line i = j = 3 (the 17 of FreeSurfer stays
    // 17: mesh labels are the image's values).
    let img = image([7, 7, 3], |i, j, _| {
        if i < 3 {
            3
        } else if j < 3 {
            7
        } else {
            12
        }
    });
    assert_eq!(extract_and_mesh(img, 1.5).0, 0);
}

#[test]
fn forty_eight_labels_each_keep_their_region() {
    // 48 labels in 2-voxel blocks, each touching its neighbours (interfaces, triple lines,
    // corners where eight meet): more regions than the seed's one-byte template held (31).
    let img = image([14, 10, 5], |i, j, k| {
        if i == 0 || j == 0 || i == 13 || j == 9 || k == 4 {
            return 0;
        }
        (1 + (i - 1) / 2 + 6 * ((j - 1) / 2) + 24 * (k / 2)) as u32
    });
    assert_eq!(img.counts().len(), 49);
    extract_and_mesh(img, 1.0);
}

#[test]
fn one_voxel_thick_layer() {
    // A slab of label 2, one voxel thick, between two blocks of 1 and 3; and a one-voxel shell
    // of 4 around everything.
    let img = image([7, 7, 7], |i, j, k| {
        if i == 0 || j == 0 || k == 0 || i == 6 || j == 6 || k == 6 {
            4
        } else if k < 3 {
            1
        } else if k == 3 {
            2
        } else {
            3
        }
    });
    assert_eq!(extract_and_mesh(img, 1.5).0, 0);
}

#[test]
fn different_labels_touching_diagonally_stay() {
    // Two labels touching along an edge and a third at a corner only: regions of different
    // labels may touch there, no repair.
    let img = image([4, 4, 4], |i, j, k| match (i, j, k) {
        (1, 1, 1) => 1,
        (2, 2, 1) => 2,
        (2, 2, 2) => 5,
        _ => 0,
    });
    let mut img2 = img.clone();
    assert!(make_manifold(&mut img2).is_empty());
    assert_eq!(extract_and_mesh(img, 1.0).0, 0);
}

#[test]
fn one_label_touching_itself_diagonally_is_repaired() {
    // A checkerboard of 1 and 2 inside 0, and two voxels of 3 meeting at a corner.
    let img = image([6, 6, 6], |i, j, k| {
        if (1..=3).contains(&i) && (1..=3).contains(&j) && k == 1 {
            1 + ((i + j) % 2) as u32
        } else if (i, j, k) == (1, 1, 3) || (i, j, k) == (2, 2, 4) {
            3
        } else {
            0
        }
    });
    assert!(extract_and_mesh(img, 1.0).0 > 0);
}

/// Connected components per non-zero label, sorted by label.
fn components(img: &LabelImage) -> Vec<(u32, usize)> {
    let mut v: Vec<(u32, usize)> = Vec::new();
    for c in Components::of(img).list.iter().filter(|c| c.label != 0) {
        match v.iter_mut().find(|x| x.0 == c.label) {
            Some(x) => x.1 += 1,
            None => v.push((c.label, 1)),
        }
    }
    v.sort_unstable();
    v
}

#[test]
fn a_repair_keeps_each_regions_components() {
    // A ring of grey matter (1) closed by a diagonal step, in white matter (2) that also has an
    // enclosed column. By rank alone the repair gave the step's grey voxel to white matter and
    // joined the column to the rest (2 components to 1); a safe change gives an outer white
    // voxel to grey matter instead, and every count stays.
    const RING: [[u32; 5]; 5] = [
        [2, 2, 2, 2, 2],
        [2, 1, 1, 1, 2],
        [2, 1, 2, 1, 2],
        [2, 1, 1, 2, 2],
        [2, 2, 2, 2, 2],
    ];
    let img = image([5, 5, 2], |i, j, _| RING[4 - j as usize][i as usize]);
    let before = components(&img);
    assert_eq!(before, vec![(1, 1), (2, 2)]);
    let mut repaired = img.clone();
    let changed = make_manifold(&mut repaired);
    assert!(!changed.is_empty());
    assert_eq!(components(&repaired), before);
    assert_eq!(
        extract_and_mesh(img, 1.0).0,
        changed.iter().map(|c| c.2).sum()
    );
}

#[test]
fn labels_then_extract() {
    // --merge 2,41=1 and an island of 9 merged away: one region 1 and a region 5.
    let mut img = image([6, 6, 6], |i, j, k| {
        if (1..5).contains(&i) && (1..5).contains(&j) && (1..5).contains(&k) {
            if (i, j, k) == (2, 2, 2) {
                9
            } else if i < 3 {
                2
            } else if j < 3 {
                41
            } else {
                5
            }
        } else {
            0
        }
    });
    let r = apply(
        &mut img,
        &LabelOptions {
            merge: vec![(vec![2, 41], 1)],
            min_component_voxels: 2,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(r.islands.len(), 1);
    assert_eq!(
        r.regions.iter().map(|x| x.0).collect::<Vec<_>>(),
        vec![1, 5]
    );
    extract_and_mesh(img, 1.5);
}

#[test]
fn random_label_noise_always_validates() {
    // Salt-and-pepper images of 0..=3 (the worst case for manifoldness): the repaired surface
    // validates, encloses the voxel volumes, and a few of them mesh and check.
    let mut state = 7u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for round in 0..40 {
        let n = 3 + (round % 5);
        let dense = (next() % 1000) as f64 / 1000.0;
        let labels: Vec<u32> = (0..n * n * n)
            .map(|_| {
                if ((next() % 1000) as f64) < dense * 1000.0 {
                    1 + (next() % 3) as u32
                } else {
                    0
                }
            })
            .collect();
        let mut img = image([n, n, n], |_, _, _| 0);
        img.labels = labels;
        if img.labels.iter().all(|&l| l == 0) {
            continue;
        }
        if round % 8 == 0 {
            extract_and_mesh(img, 1.0);
            continue;
        }
        let (mut s, _) = extract(&mut img);
        let v = validate_surface(&mut s, &ValidateOptions::default())
            .unwrap_or_else(|e| panic!("round {round}: {e}"));
        for r in &v.regions {
            let n = img.labels.iter().filter(|&&l| l == r.label).count();
            assert!((r.volume - n as f64 * img.voxel_volume()).abs() < 1e-9 * r.volume);
        }
    }
}

/// A sheared voxel-to-world map (x += 0.5 y): the regions' voxel volumes are world volumes
/// (the map's determinant, 1 here), not the product of the axes' lengths (1.118), which the
/// image's axis-aligned frame has.
#[test]
fn a_sheared_image_reports_world_voxel_volumes() {
    let labels = (0..5 * 5 * 5)
        .map(|i| {
            let (x, y, z) = (i % 5, (i / 5) % 5, i / 25);
            u32::from((1..4).contains(&x) && (1..4).contains(&y) && (1..4).contains(&z))
        })
        .collect();
    let m = [
        [1.0, 0.5, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let img = LabelImage::new([5, 5, 5], m, labels).unwrap();
    let (_, summary) = biotet::image::surface::labelled_surface(
        img,
        &LabelOptions::default(),
        "sheared",
        &mut |_| {},
    )
    .unwrap();
    assert!(summary.frame_to_world.is_some());
    assert_eq!(summary.regions.len(), 1);
    assert!(
        (summary.regions[0].voxel_volume - 27.0).abs() < 1e-12,
        "{:?}",
        summary.regions
    );
    assert!((summary.voxel_volume - 1.0).abs() < 1e-15);
}

/// A grid sheared in two directions (a CT gantry tilt: each slice shifted along y and x) with
/// an x flip: the frame is the polar decomposition's symmetric factor, so the frame → world map
/// is a rotation and the mesh's angles are the world's. Its voxel faces are parallelograms,
/// split along their shorter diagonals (the Delaunay's, but for a few): little to recover. The
/// old frame was
/// axis-aligned and sheared the mesh on the way out.
#[test]
fn a_sheared_grid_is_meshed_in_a_frame_isometric_to_world() {
    let labels = (0..12 * 12 * 10)
        .map(|n| {
            let (i, j, k) = (n % 12, (n / 12) % 12, n / 144);
            let d = (i - 6) * (i - 6) + (j - 6) * (j - 6) + (k - 5) * (k - 5);
            if d <= 6 { 2 } else { u32::from(d <= 20) }
        })
        .collect();
    let m = [
        [-1.0, 0.0, 0.35, 4.0],
        [0.0, 0.9, 0.5, -2.0],
        [0.0, 0.0, 1.6, 7.0],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let mut img = LabelImage::new([12, 12, 10], m, labels).unwrap();
    let orig = img.clone();
    let to_world = img.to_frame().expect("oblique");
    // A rotation: orthonormal columns, determinant 1.
    for a in 0..3 {
        for b in 0..3 {
            let d: f64 = (0..3).map(|r| to_world[r][a] * to_world[r][b]).sum();
            let want = if a == b { 1.0 } else { 0.0 };
            assert!((d - want).abs() < 1e-12, "columns {a}, {b}: {d}");
        }
    }
    // Frame then world is the image's map.
    let mut p = vec![img.world([2.5, -0.5, 7.5])];
    biotet::image::map_points(&to_world, &mut p);
    let want = orig.world([2.5, -0.5, 7.5]);
    assert!(
        (0..3).all(|r| (p[0][r] - want[r]).abs() < 1e-12),
        "{p:?} vs {want:?}"
    );
    assert_eq!(img.determinant().signum(), orig.determinant().signum());
    let (s, _) = extract(&mut img);
    let mut s = s;
    validate_surface(&mut s, &ValidateOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let sizing = Sizing::uniform(1.5).unwrap();
    let (mut mesh, report) =
        mesh_surface(&s, &sizing, &PipelineOptions::default(), &mut |_| {}).unwrap();
    let rec = report.recover.as_ref().unwrap();
    // (The longer diagonals: 466 of the 1,080 triangles missing, 9 Steiner points.)
    assert!(
        rec.missing_before <= 4 && rec.steiner_points == 0,
        "{rec:?}"
    );
    let in_frame = biotet::quality::QualityReport::of(&mesh);
    biotet::image::map_points(&to_world, &mut mesh.points);
    biotet::image::map_points(&to_world, &mut s.points);
    let in_world = biotet::quality::QualityReport::of(&mesh);
    let (a, b) = (
        in_frame.min_dihedral_deg.unwrap(),
        in_world.min_dihedral_deg.unwrap(),
    );
    assert!((a - b).abs() < 1e-6 && b >= 10.0, "frame {a}°, world {b}°");
    let c = biotet::check::check(&mesh, Some(&s));
    assert!(c.valid, "{c}");
    // Each region's mesh volume is its world voxel volume.
    let mut vol: std::collections::BTreeMap<u32, f64> = Default::default();
    for t in 0..mesh.tets.len() {
        *vol.entry(mesh.labels[t]).or_default() += volume(&mesh.corners(t));
    }
    for (l, n) in img.counts() {
        if l != 0 {
            let want = n as f64 * orig.voxel_volume();
            assert!(
                (vol[&l] - want).abs() < 1e-9 * want,
                "region {l}: {}",
                vol[&l]
            );
        }
    }
}

/// A 12³ crop of the MNI ridge in 0.5 × 0.5 × 3 mm voxels (`tests/data/ridge_aniso_crop.nii.gz`,
/// grey and white matter meeting the crop's border), meshed as `biotet mesh IMAGE` does: the
/// triple lines and rims there are staircases of 3 mm steps against a target edge of 0.5, and
/// the stage keeps them. Whole, they bounded the triangles near them (3.1°) and the tets (41
/// under 10°, 2.93°); cut to the target before the rounds, their pieces still kept, every tet
/// is within 10°–165°.
#[test]
fn thick_slices_mesh_within_the_range() {
    use biotet::quality::tet::dihedral_angles;
    use biotet::surface::{SurfaceOptions, improve};
    let (voxels, summary) = crate::common::image_surface("ridge_aniso_crop.nii.gz");
    assert!(summary.orient_sheets());
    let opts = SurfaceOptions {
        tolerance: summary.default_surface_tolerance,
        orient_sheets: true,
        ..Default::default()
    };
    let (s, report) = improve(&voxels, &opts).expect("improves");
    assert!(report.min_angle_out > 20.0, "{}°", report.min_angle_out);
    let sizing = crate::common::default_sizing(&s);
    let (m, _) =
        mesh_surface(&s, sizing, &PipelineOptions::default(), &mut |_| {}).expect("meshes");
    for t in 0..m.tets.len() {
        let a = dihedral_angles(&m.corners(t)).map(f64::to_degrees);
        let lo = a.iter().copied().fold(180.0, f64::min);
        let hi = a.iter().copied().fold(0.0, f64::max);
        assert!(lo >= 10.0 && hi <= 165.0, "tet {t}: {lo}°, {hi}°");
    }
    let c = biotet::check::check(&m, Some(&s));
    assert!(c.valid, "{c}");
}
