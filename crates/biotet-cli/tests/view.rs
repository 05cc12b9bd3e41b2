//! `biotet view`: a cut of a small two-region cube against its expected SVG text, the PNG's
//! pixels, the iso view, and the errors.

mod support;
use std::fmt::Write as _;
use std::path::Path;
use support::*;

/// `cubes` Kuhn cubes of side 2 stacked along z (points shared between them), as Medit text:
/// each cube's six tets around the diagonal from its lowest corner, positively oriented,
/// labelled by `label(path start)` (the axis bit, 1, 2 or 4, its path leaves that corner along).
fn kuhn_cubes(cubes: usize, label: impl Fn(usize) -> u32) -> String {
    // Corner b (bits x, y, z) of cube i: layer i + (b >> 2), index b & 3 in it.
    let layer_point = |b: usize, layer: usize| {
        [
            (b & 1) as f64 * 2.0,
            (b >> 1 & 1) as f64 * 2.0,
            layer as f64 * 2.0,
        ]
    };
    let mut s = format!(
        "MeshVersionFormatted 2\nDimension 3\nVertices\n{}\n",
        4 * (cubes + 1)
    );
    for layer in 0..=cubes {
        for b in 0..4 {
            let q = layer_point(b, layer);
            writeln!(s, "{} {} {} 0", q[0], q[1], q[2]).unwrap();
        }
    }
    writeln!(s, "Tetrahedra\n{}", 6 * cubes).unwrap();
    for cube in 0..cubes {
        for (a, b) in [(1, 2), (1, 4), (2, 1), (2, 4), (4, 1), (4, 2)] {
            let mut t = [0usize, a, a | b, 7];
            let c = t.map(|b| layer_point(b & 3, cube + (b >> 2)));
            let d = |i: usize| [0, 1, 2].map(|k| c[i][k] - c[0][k]);
            let (u, v, w) = (d(1), d(2), d(3));
            let det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                + u[2] * (v[0] * w[1] - v[1] * w[0]);
            if det < 0.0 {
                t.swap(1, 2);
            }
            let t = t.map(|b| (cube + (b >> 2)) * 4 + (b & 3) + 1);
            writeln!(s, "{} {} {} {} {}", t[0], t[1], t[2], t[3], label(a)).unwrap();
        }
    }
    s.push_str("End\n");
    s
}

/// The cube [0, 2]³ as its six Kuhn tets (around the diagonal from the origin), the three
/// whose path leaves the origin along x in region 1 and the others in region 7, as Medit text.
fn kuhn_cube() -> String {
    kuhn_cubes(1, |a| if a == 1 { 1 } else { 7 })
}

fn cube_file(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("cube.mesh");
    std::fs::write(&path, kuhn_cube()).unwrap();
    assert!(
        biotet(&["check", s(&path), "--quiet"]).status.success(),
        "the cube is a valid mesh"
    );
    path
}

/// A plane through faces shared by tets on both sides (z = 2 between the stacked cubes) shows
/// those faces: the cut covers the whole 2 × 2 square, drawn once.
#[test]
fn a_cut_through_a_layer_of_faces_has_no_holes() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("stack.mesh");
    std::fs::write(&mesh, kuhn_cubes(2, |_| 1)).unwrap();
    assert!(biotet(&["check", s(&mesh), "--quiet"]).status.success());
    let out = dir.path().join("cut.svg");
    let r = json_of(&biotet(&[
        "view",
        s(&mesh),
        "--cut",
        "z=2",
        "-o",
        s(&out),
        "--json",
    ]));
    // The upper cube's two tets with a face on z = 2 (the lower cube's are not drawn again).
    assert_eq!(r["counts"]["tets_cut"], 2, "{r}");
}

#[test]
fn a_cut_matches_its_expected_svg_and_counts() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = cube_file(dir.path());
    let out = dir.path().join("cut.svg");
    let r = json_of(&biotet(&[
        "view",
        s(&mesh),
        "--cut",
        "z=1",
        "--width",
        "300",
        "-o",
        s(&out),
        "--json",
    ]));
    // Every Kuhn tet spans z from 0 to 2.
    assert_eq!(r["counts"]["tets_cut"], 6);
    // The four side squares, two triangles each, and the interfaces between the two regions.
    assert!(r["counts"]["trace_segments"].as_u64().unwrap() >= 8);
    let svg = std::fs::read_to_string(&out).unwrap();
    assert_eq!(svg.matches("<polygon").count(), 6);
    assert!(
        svg.contains(">1</text>") && svg.contains(">7</text>"),
        "both labels in the legend"
    );
    let expected = root().join("tests/data/view/kuhn_cube_z1.svg");
    if std::env::var_os("BIOTET_BLESS").is_some() {
        std::fs::write(&expected, &svg).unwrap();
    }
    let want = std::fs::read_to_string(&expected).unwrap();
    // The title names the temporary file: compare the drawing after it.
    let body = |t: &str| t.split_once("</text>").map(|(_, b)| b.to_string()).unwrap();
    assert_eq!(
        body(&svg),
        body(&want),
        "the drawing changed (BIOTET_BLESS=1 to accept)"
    );
}

#[test]
fn a_png_has_the_region_colours_where_the_cube_is_and_white_around() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = cube_file(dir.path());
    let out = dir.path().join("cut.png");
    let r = json_of(&biotet(&[
        "view",
        s(&mesh),
        "--cut",
        "z=1.5",
        "--width",
        "240",
        "-o",
        s(&out),
        "--json",
    ]));
    let (w, h) = (
        r["width"].as_u64().unwrap() as usize,
        r["height"].as_u64().unwrap() as usize,
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&out).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width as usize, info.height as usize), (w, h));
    let px = |x: usize, y: usize| {
        let i = (y * w + x) * 3;
        [buf[i], buf[i + 1], buf[i + 2]]
    };
    assert_eq!(px(1, h - 2), [255, 255, 255], "background");
    // The 2 × 2 square is drawn 88 pixels wide (240 less the margins and the key) from
    // (16, 44): its pixels are not white, and both regions' colours appear.
    let mut colours = std::collections::BTreeSet::new();
    for y in (50..128).step_by(7) {
        for x in (22..100).step_by(7) {
            let c = px(x, y);
            assert_ne!(c, [255, 255, 255], "inside the cut at ({x}, {y})");
            colours.insert(c);
        }
    }
    assert!(
        colours.contains(&[68, 119, 170]) && colours.contains(&[238, 102, 119]),
        "{colours:?}"
    );
    // The same bytes again, on any thread count.
    let again = dir.path().join("again.png");
    let _ = json_of(&biotet(&[
        "view",
        s(&mesh),
        "--cut",
        "z=1.5",
        "--width",
        "240",
        "-o",
        s(&again),
        "--json",
        "--threads",
        "1",
    ]));
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
}

#[test]
fn the_iso_view_draws_the_faces_that_face_the_eye() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = cube_file(dir.path());
    let out = dir.path().join("iso.svg");
    let r = json_of(&biotet(&[
        "view",
        s(&mesh),
        "--view",
        "iso",
        "-o",
        s(&out),
        "--json",
    ]));
    // Seen from (1, −1, 1): the faces x = 2, y = 0 and z = 2, two triangles each.
    assert_eq!(r["faces_drawn"], 6);
    let svg = std::fs::read_to_string(&out).unwrap();
    assert_eq!(svg.matches("<polygon").count(), 6);
}

#[test]
fn bad_options_fail_with_one_line_and_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = cube_file(dir.path());
    for (args, want) in [
        (vec!["--cut", "w=1"], "the axis must be x, y or z"),
        (vec!["--cut", "z"], "expected AXIS=VALUE"),
        (vec!["--cut-normal", "0,0,0"], "must not be zero"),
        (vec!["--cut-normal", "1,2"], "expected 3 finite numbers"),
    ] {
        let out = dir.path().join("x.svg");
        let mut a = vec!["view", s(&mesh), "-o", s(&out)];
        a.extend(args);
        let r = biotet(&a);
        assert_eq!(r.status.code(), Some(2), "{a:?}");
        assert!(stderr(&r).contains(want), "{a:?}: {}", stderr(&r));
        assert!(!out.exists());
    }
    let r = biotet(&["view", s(&mesh), "-o", s(&dir.path().join("x.jpg"))]);
    assert!(stderr(&r).contains("must be .svg or .png"));
}
