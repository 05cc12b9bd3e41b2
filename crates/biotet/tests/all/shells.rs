//! Several closed surfaces to one labelled surface (nesting, touching, cavities).

use crate::common::{cube_surface, load_stl};
use biotet::SurfaceMesh;
use biotet::mesh::shells::{AssembleError, Part, assemble, touching};
use biotet::mesh::validate::{ValidateOptions, validate_surface};
use biotet::pipeline::{PipelineOptions, mesh_surface};
use biotet::quality::tet::volume;
use biotet::sizing::Sizing;

fn part(s: SurfaceMesh, labels: Option<Vec<u32>>) -> Part {
    Part { surface: s, labels }
}

fn inward(mut s: SurfaceMesh) -> SurfaceMesh {
    for t in &mut s.triangles {
        t.swap(1, 2);
    }
    s
}

fn sides_of(s: &SurfaceMesh) -> Vec<[u32; 2]> {
    let mut v = s.sides.clone();
    v.sort_unstable();
    v.dedup();
    v
}

#[test]
fn nested_cubes_make_two_regions_innermost_first() {
    // The inner cube given first and inside out: order and orientation do not matter.
    let outer = cube_surface([0.0; 3], 4.0);
    let inner = inward(cube_surface([1.0; 3], 2.0));
    let (mut s, shells) = assemble(vec![part(inner, None), part(outer, None)]).unwrap();
    assert_eq!(shells.len(), 2);
    assert!(shells[0].flipped && !shells[1].flipped);
    assert_eq!(shells[0].parent, Some(1));
    assert_eq!(shells[1].parent, None);
    // Inner shell: region 1 inside, region 2 around it; outer: region 2 inside, outside 0.
    assert_eq!(sides_of(&s), vec![[1, 2], [2, 0]]);
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
}

#[test]
fn forty_loose_cubes_are_forty_regions() {
    // A scan of loose parts: each shell its own region, more than the seed's one-byte template
    // held (31 labels).
    let parts: Vec<Part> = (0..40)
        .map(|i| {
            part(
                cube_surface([3.0 * (i % 8) as f64, 3.0 * (i / 8) as f64, 0.0], 1.0),
                None,
            )
        })
        .collect();
    let (mut s, shells) = assemble(parts).unwrap();
    assert_eq!(shells.len(), 40);
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    let sizing = Sizing::uniform(0.5).unwrap();
    let (mesh, _) = mesh_surface(&s, &sizing, &PipelineOptions::default(), &mut |_| {}).unwrap();
    let c = biotet::check::check(&mesh, Some(&s));
    assert!(c.valid, "{c}");
    let mut labels = mesh.labels.clone();
    labels.sort_unstable();
    labels.dedup();
    assert_eq!(labels, (1..=40).collect::<Vec<u32>>());
    for l in 1..=40 {
        let v: f64 = (0..mesh.tets.len())
            .filter(|&t| mesh.labels[t] == l)
            .map(|t| volume(&mesh.corners(t)))
            .sum();
        assert!((v - 1.0).abs() < 1e-9, "region {l}: volume {v}");
    }
}

#[test]
fn explicit_labels_and_cavities() {
    let outer = cube_surface([0.0; 3], 4.0);
    let inner = cube_surface([1.0; 3], 2.0);
    let (s, _) = assemble(vec![
        part(outer.clone(), Some(vec![7])),
        part(inner.clone(), Some(vec![0])),
    ])
    .unwrap();
    assert_eq!(sides_of(&s), vec![[0, 7], [7, 0]]);
    // Wrong number of labels, and a shell labelled like the one around it, are refused.
    let e = assemble(vec![part(outer.clone(), Some(vec![1, 2]))]).unwrap_err();
    assert!(matches!(e, AssembleError::Labels { .. }), "{e}");
    let e = assemble(vec![part(outer, Some(vec![3])), part(inner, Some(vec![3]))]).unwrap_err();
    assert!(matches!(e, AssembleError::SameAsParent { .. }), "{e}");
}

#[test]
fn touching_cubes_share_an_interface() {
    // [0,1]^3 and [1,2]x[0,1]^2 share the face x = 1. Split the shared quad the same way in
    // both: the left cube's x = 1 face uses the diagonal through (1,0,0)-(1,1,1).
    let left = cube_surface([0.0; 3], 1.0);
    let right = cube_surface([1.0, 0.0, 0.0], 1.0);
    let (mut s, shells) = assemble(vec![part(left, None), part(right, None)]).unwrap();
    assert_eq!(shells.len(), 2);
    // Both cubes split the shared quad along (1,0,0)–(1,1,1): two interface triangles, one copy
    // each, between regions 1 and 2.
    assert_eq!(s.triangles.len(), 22);
    let interface: Vec<_> = s.sides.iter().filter(|x| x[1] != 0).collect();
    assert_eq!(interface, vec![&[1, 2], &[1, 2]]);
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
}

#[test]
fn nested_brain_and_white_matter_mesh_into_two_regions() {
    let s = load_stl("nested_brain_wm_20k.stl");
    let (mut s, shells) = assemble(vec![part(s, None)]).unwrap();
    assert_eq!(shells.len(), 2);
    assert_eq!(shells[1].parent, Some(0));
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    let sizing = crate::common::default_sizing(&s);
    let (mesh, _) =
        mesh_surface(&s, &sizing, &PipelineOptions::deploy_only(), &mut |_| {}).unwrap();
    let vol = region_volumes(&mesh);
    // Region 2 is the white matter (552,267 mm³), region 1 the rest of the brain (1,659,213 −
    // 552,267); before boundary recovery the split follows the centroids, within 3%.
    assert_eq!(vol[0], 0.0);
    let (grey, white) = (1_659_213.0 - 552_267.0, 552_267.0);
    assert!((vol[1] - grey).abs() / grey < 0.03, "{vol:?}");
    assert!((vol[2] - white).abs() / white < 0.03, "{vol:?}");
}

#[test]
fn three_materials_with_a_triple_line_mesh_conformingly() {
    // Two unit cubes touching along x = 1 (regions 1 and 2) inside a box (region 3): the three
    // regions meet along the edges of the shared square, a triple line.
    let a = cube_surface([0.0; 3], 1.0);
    let b = cube_surface([1.0, 0.0, 0.0], 1.0);
    let mut c = cube_surface([-1.0, -1.0, -1.0], 1.0);
    for p in &mut c.points {
        // Stretch to the box [-1, 3] x [-1, 2] x [-1, 2].
        p[0] = if p[0] > -1.0 { 3.0 } else { -1.0 };
        p[1] = if p[1] > -1.0 { 2.0 } else { -1.0 };
        p[2] = if p[2] > -1.0 { 2.0 } else { -1.0 };
    }
    let (mut s, shells) = assemble(vec![
        part(a, Some(vec![1])),
        part(b, Some(vec![2])),
        part(c, Some(vec![3])),
    ])
    .unwrap();
    assert_eq!(shells[0].parent, Some(2));
    assert_eq!(shells[1].parent, Some(2));
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    let sizing = Sizing::uniform(0.4).unwrap();
    let (mesh, report) =
        mesh_surface(&s, &sizing, &PipelineOptions::default(), &mut |_| {}).unwrap();
    let r = report.recover.as_ref().unwrap();
    assert_eq!(r.missing_after, 0, "{r:?}");
    let c = biotet::check::check(&mesh, Some(&s));
    assert!(c.valid, "{c}");
    let conf = c.surface.as_ref().unwrap();
    assert_eq!(conf.n_found, s.triangles.len());
    for i in &conf.interfaces {
        assert_eq!(i.found, i.expected, "{:?}", i.labels);
    }
    // Region volumes are the volumes their surfaces enclose.
    let mut vol = [0.0f64; 4];
    for t in 0..mesh.tets.len() {
        vol[mesh.labels[t] as usize] += volume(&mesh.corners(t));
    }
    for (l, v) in [(1, 1.0), (2, 1.0), (3, 36.0 - 2.0)] {
        assert!(
            (vol[l] - v).abs() < 1e-9 * 36.0,
            "region {l}: {} vs {v}",
            vol[l]
        );
    }
}

#[test]
fn a_non_manifold_surface_is_labelled_from_its_cells() {
    // Two unit cubes sharing the face x = 1, given as one surface with that face once: the
    // edges of the shared square carry three triangles each.
    let a = cube_surface([0.0; 3], 1.0);
    let b = cube_surface([1.0, 0.0, 0.0], 1.0);
    let mut s = a.clone();
    let base = s.points.len() as u32;
    s.points.extend(&b.points);
    for t in &b.triangles {
        let on_shared = t.iter().all(|&v| b.points[v as usize][0] == 1.0);
        if !on_shared {
            s.triangles.push(t.map(|v| v + base));
            s.sides.push([1, 0]);
        }
    }
    s.weld_exact();
    let (mut s, shells) = assemble(vec![part(s, None)]).unwrap();
    assert_eq!(shells.len(), 2);
    // Every triangle has the outside or the other cube on its front; the shared square is the
    // interface between regions 1 and 2.
    assert_eq!(s.sides.iter().filter(|x| x[0] != 0 && x[1] != 0).count(), 2);
    assert_eq!(s.sides.iter().filter(|x| x.contains(&0)).count(), 20);
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    let sizing = Sizing::uniform(0.3).unwrap();
    let (mesh, _) = mesh_surface(&s, &sizing, &PipelineOptions::default(), &mut |_| {}).unwrap();
    let c = biotet::check::check(&mesh, Some(&s));
    assert!(c.valid, "{c}");
    let vol = region_volumes(&mesh);
    assert!(
        (vol[1] - 1.0).abs() < 1e-12 && (vol[2] - 1.0).abs() < 1e-12,
        "{vol:?}"
    );
}

/// Volume of each region (by label) of `mesh`.
fn region_volumes(mesh: &biotet::TetMesh) -> [f64; 3] {
    let mut vol = [0.0f64; 3];
    for t in 0..mesh.tets.len() {
        vol[mesh.labels[t] as usize] += volume(&mesh.corners(t));
    }
    vol
}

#[test]
fn shells_touching_along_an_edge_or_at_a_vertex_mesh_as_two_regions() {
    // One surface of two unit cubes: [1,2]x[1,2]x[0,1] shares the edge (1,1,0)-(1,1,1) with
    // [0,1]^3; [1,2]^3 shares its vertex (1,1,1).
    for (b, edge) in [([1.0, 1.0, 0.0], true), ([1.0, 1.0, 1.0], false)] {
        let mut s = cube_surface([0.0; 3], 1.0);
        s.append(&cube_surface(b, 1.0));
        s.weld_exact();
        let (mut s, shells) = assemble(vec![part(s, None)]).unwrap();
        assert_eq!(shells.len(), 2, "{b:?}");
        validate_surface(&mut s, &ValidateOptions::default()).unwrap();
        let at = |p: [f64; 3]| s.points.iter().position(|q| *q == p).unwrap() as u32;
        let (lo, hi) = (at([1.0, 1.0, 0.0]), at([1.0, 1.0, 1.0]));
        let t = touching(&s);
        if edge {
            assert_eq!(t.edges, vec![([lo.min(hi), lo.max(hi)], vec![1, 2])]);
            assert!(t.vertices.is_empty(), "{t:?}");
        } else {
            assert!(t.edges.is_empty(), "{t:?}");
            assert_eq!(t.vertices, vec![(hi, vec![1, 2])]);
        }
        let sizing = Sizing::uniform(0.4).unwrap();
        let (mesh, report) =
            mesh_surface(&s, &sizing, &PipelineOptions::default(), &mut |_| {}).unwrap();
        assert_eq!(report.recover.as_ref().unwrap().missing_after, 0);
        let c = biotet::check::check(&mesh, Some(&s));
        assert!(c.valid, "{b:?}: {c}");
        assert_eq!(c.n_touching_vertices, if edge { 2 } else { 1 }, "{c}");
        let found: Vec<_> = c
            .surface
            .as_ref()
            .unwrap()
            .interfaces
            .iter()
            .map(|i| (i.labels, i.expected, i.found))
            .collect();
        assert_eq!(found, vec![([0, 1], 12, 12), ([0, 2], 12, 12)], "{c}");
        assert_eq!(mesh.regions(), vec![1, 2]);
        // The shared edge (or vertex) is in the mesh, in tets of both regions.
        let mp = |p: [f64; 3]| mesh.points.iter().position(|q| *q == p).unwrap() as u32;
        let (lo, hi) = (mp([1.0, 1.0, 0.0]), mp([1.0, 1.0, 1.0]));
        for label in [1, 2] {
            assert!(
                (0..mesh.tets.len()).any(|t| mesh.labels[t] == label
                    && mesh.tets[t].contains(&hi)
                    && (!edge || mesh.tets[t].contains(&lo))),
                "{b:?}: no tet of region {label} at the shared edge or vertex"
            );
        }
        let vol = region_volumes(&mesh);
        assert!(
            (vol[1] - 1.0).abs() < 1e-12 && (vol[2] - 1.0).abs() < 1e-12,
            "{vol:?}"
        );
    }
}

#[test]
fn one_shell_pinched_at_an_edge_stays_invalid() {
    // A bow-tie: two tets sharing only the edge (0,0,0)-(0,0,1), given as one region.
    let pts = vec![
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    let mut tris = Vec::new();
    for tet in [[0u32, 1, 2, 3], [0, 1, 4, 5]] {
        for k in 0..4 {
            let f = [tet[(k + 1) % 4], tet[(k + 2) % 4], tet[(k + 3) % 4]];
            tris.push(f);
        }
    }
    let mut s = SurfaceMesh::closed(pts, tris, 1);
    let e = validate_surface(&mut s, &ValidateOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("non-manifold edges") && msg.contains("(0, 0, 0)–(0, 0, 1) in 4 triangles"),
        "{msg}"
    );
    // Given without labels, its two cells are two regions that share the edge.
    let (mut s, shells) = assemble(vec![part(s, None)]).unwrap();
    assert_eq!(shells.len(), 2);
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    assert_eq!(touching(&s).edges, vec![([0, 1], vec![1, 2])]);
    // Labelled as one region, it is refused again.
    let (mut one, _) = assemble(vec![part(s, Some(vec![1, 1]))]).unwrap();
    let e = validate_surface(&mut one, &ValidateOptions::default()).unwrap_err();
    assert!(e.to_string().contains("(0, 0, 0)–(0, 0, 1)"), "{e}");
}

/// `s` as a triangle soup: every triangle on three points of its own (as a PLY or OBJ written
/// without merging points, or an STL read as it is).
fn soup(s: &SurfaceMesh) -> SurfaceMesh {
    let mut out = SurfaceMesh {
        points: Vec::new(),
        triangles: Vec::new(),
        sides: Vec::new(),
    };
    for (t, side) in s.triangles.iter().zip(&s.sides) {
        let base = out.points.len() as u32;
        out.points.extend(t.map(|v| s.points[v as usize]));
        out.triangles.push([base, base + 1, base + 2]);
        out.sides.push(*side);
    }
    out
}

#[test]
fn a_triangle_soup_assembles_as_its_welded_surface() {
    // Nested cubes, each a soup, and two cubes touching along an edge in one soup: the shells
    // (and the arrangement's regions) are those of the welded surfaces, not one per triangle.
    let outer = cube_surface([0.0; 3], 4.0);
    let inner = cube_surface([1.0; 3], 2.0);
    let welded = assemble(vec![part(inner.clone(), None), part(outer.clone(), None)]).unwrap();
    let soups = assemble(vec![part(soup(&inner), None), part(soup(&outer), None)]).unwrap();
    assert_eq!(soups.1.len(), 2);
    assert_eq!(soups.0.points.len(), 16);
    // The same triangles, corner for corner, and sides (the points numbered as they come).
    let corners = |s: &SurfaceMesh| -> Vec<[[f64; 3]; 3]> {
        (0..s.triangles.len()).map(|t| s.corners(t)).collect()
    };
    assert_eq!(corners(&soups.0), corners(&welded.0));
    assert_eq!(soups.0.sides, welded.0.sides);
    let mut pair = cube_surface([0.0; 3], 1.0);
    pair.append(&cube_surface([1.0, 1.0, 0.0], 1.0));
    let (mut s, shells) = assemble(vec![part(soup(&pair), None)]).unwrap();
    assert_eq!(shells.len(), 2);
    assert_eq!(s.points.len(), 14);
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    assert_eq!(touching(&s).edges.len(), 1);
    // Two cubes sharing a face in one part, each on its own copies of the shared points (each
    // closed in the file's numbering): two shells and one interface, as before any welding.
    let mut pair = cube_surface([0.0; 3], 1.0);
    pair.append(&cube_surface([1.0, 0.0, 0.0], 1.0));
    let (mut s, shells) = assemble(vec![part(pair.clone(), None)]).unwrap();
    assert_eq!(shells.len(), 2);
    assert_eq!(s.sides.iter().filter(|x| x[0] != 0 && x[1] != 0).count(), 2);
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    // The same two cubes as a soup, and welded (as an STL of the assembly is read): the shared
    // face comes twice, once in each cube's boundary with opposite orientations; it is one
    // interface between two regions (this was refused as overlapping triangles).
    let mut welded = pair.clone();
    welded.weld_exact();
    for given in [soup(&pair), welded] {
        let (mut s, shells) = assemble(vec![part(given, None)]).unwrap();
        assert_eq!(shells.len(), 2);
        assert_eq!(s.triangles.len(), 22);
        let mut inter: Vec<[u32; 2]> = s
            .sides
            .iter()
            .filter(|x| x[0] != 0 && x[1] != 0)
            .copied()
            .collect();
        inter.dedup();
        assert_eq!(inter.len(), 1, "{:?}", s.sides);
        assert_eq!(s.sides.iter().filter(|x| x[0] != 0 && x[1] != 0).count(), 2);
        validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    }
    // A soup whose points collapse (two corners of a triangle at one position) is left to the
    // validation, which names the triangle.
    let mut flat = soup(&outer);
    flat.points[1] = flat.points[0];
    let (mut s, _) = assemble(vec![part(flat, None)]).unwrap();
    let e = validate_surface(&mut s, &ValidateOptions::default()).unwrap_err();
    assert!(e.to_string().contains("degenerate"), "{e}");
}

#[test]
fn triangles_turned_against_their_neighbours_are_turned_back() {
    // A cube with one triangle turned, one with five (the minority), and nested cubes whose
    // inner one has half its triangles turned: each shell comes out as the consistent cube's.
    let cube = cube_surface([0.0; 3], 4.0);
    let (good, _) = assemble(vec![part(cube.clone(), None)]).unwrap();
    for turned in [&[3usize][..], &[0, 3, 5, 8, 11]] {
        let mut s = cube.clone();
        for &k in turned {
            s.triangles[k].swap(1, 2);
        }
        let (mut out, shells) = assemble(vec![part(s, None)]).unwrap();
        assert_eq!(shells[0].reoriented, turned.len());
        assert!(!shells[0].flipped);
        assert_eq!(out.triangles, good.triangles);
        validate_surface(&mut out, &ValidateOptions::default()).unwrap();
    }
    let mut inner = cube_surface([1.0; 3], 2.0);
    for k in (0..inner.triangles.len()).step_by(2) {
        inner.triangles[k].swap(1, 2);
    }
    let (mut s, shells) = assemble(vec![part(inner, None), part(cube.clone(), None)]).unwrap();
    assert_eq!(shells[0].reoriented, 6);
    assert_eq!(shells[0].parent, Some(1));
    assert_eq!(sides_of(&s), vec![[1, 2], [2, 0]]);
    validate_surface(&mut s, &ValidateOptions::default()).unwrap();
    // An open shell is turned the same way, and the validation still refuses it for its hole.
    let mut open = cube.clone();
    open.triangles.pop();
    open.sides.pop();
    open.triangles[0].swap(1, 2);
    let (mut s, shells) = assemble(vec![part(open, None)]).unwrap();
    assert_eq!(shells[0].reoriented, 1);
    assert!(validate_surface(&mut s, &ValidateOptions::default()).is_err());
}
