//! Scalar grid readers: VTK ImageData (`.vti`) in every encoding and NIfTI-1/2 (`.nii`,
//! `.nii.gz`), written here byte by byte, plus files written by nibabel (tests/data).

use std::io::Write;
use std::path::{Path, PathBuf};

use biotet::sizing_grid::{IDENTITY, ScalarGrid};
use biotet_io::grid::{self, GridFormat, MAX_GRID_SAMPLES};
use biotet_io::{read_scalar_grid, read_scalar_grid_named};

fn linear(p: [f64; 3]) -> f64 {
    1.5 + 0.5 * p[0] - 0.25 * p[1] + 2.0 * p[2]
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

fn assert_close3(a: [f64; 3], b: [f64; 3], tol: f64, what: &str) {
    for i in 0..3 {
        assert!(close(a[i], b[i], tol), "{what}: {a:?} vs {b:?}");
    }
}

fn assert_close33(a: [[f64; 3]; 3], b: [[f64; 3]; 3], tol: f64, what: &str) {
    for r in 0..3 {
        assert_close3(a[r], b[r], tol, what);
    }
}

/// World position of index `ijk` for the given geometry (the definition, written out).
fn world(origin: [f64; 3], spacing: [f64; 3], dir: [[f64; 3]; 3], ijk: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| {
        origin[r] + (0..3).map(|c| dir[r][c] * spacing[c] * ijk[c]).sum::<f64>()
    })
}

/// Values of `f` at every point of a grid, x fastest.
fn sample(
    dims: [usize; 3],
    origin: [f64; 3],
    spacing: [f64; 3],
    dir: [[f64; 3]; 3],
    f: impl Fn([f64; 3]) -> f64,
) -> Vec<f64> {
    let mut v = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                v.push(f(world(
                    origin,
                    spacing,
                    dir,
                    [i as f64, j as f64, k as f64],
                )));
            }
        }
    }
    v
}

/// A rotation about `u` by `angle`, as rows.
fn rotation(u: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let n = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let [x, y, z] = u.map(|c| c / n);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

/// Check that `g` has this geometry and these values, and interpolates `f` (linear) inside.
fn check_grid(
    g: &ScalarGrid,
    dims: [usize; 3],
    origin: [f64; 3],
    spacing: [f64; 3],
    dir: [[f64; 3]; 3],
    values: &[f64],
    tol: f64,
) {
    assert_eq!(g.dims, dims);
    assert_close3(g.origin, origin, tol, "origin");
    assert_close3(g.spacing, spacing, tol, "spacing");
    assert_close33(g.direction, dir, tol, "direction");
    assert_eq!(g.values.len(), values.len());
    for (i, (a, b)) in g.values.iter().zip(values).enumerate() {
        assert!(close(*a, *b, tol), "value {i}: {a} vs {b}");
    }
}

// ---------------------------------------------------------------------------------------------
// A small VTK ImageData writer.

fn b64(data: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let v = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(v >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[derive(Clone, Copy, Debug)]
enum Enc {
    Ascii,
    /// Inline base64.
    Binary,
    AppendedRaw,
    AppendedB64,
}

#[derive(Clone, Copy, Debug)]
struct Opts {
    enc: Enc,
    zlib: bool,
    header64: bool,
    be: bool,
}

const ASCII: Opts = Opts {
    enc: Enc::Ascii,
    zlib: false,
    header64: false,
    be: false,
};

struct Arr<'a> {
    name: &'a str,
    ty: &'a str,
    ncomp: usize,
    cell: bool,
    values: Vec<f64>,
}

fn arr<'a>(name: &'a str, ty: &'a str, values: Vec<f64>) -> Arr<'a> {
    Arr {
        name,
        ty,
        ncomp: 1,
        cell: false,
        values,
    }
}

fn to_bytes(ty: &str, v: &[f64], be: bool) -> Vec<u8> {
    let mut out = Vec::new();
    for &x in v {
        let mut b = match ty {
            "Int8" => (x as i8).to_le_bytes().to_vec(),
            "UInt8" => (x as u8).to_le_bytes().to_vec(),
            "Int16" => (x as i16).to_le_bytes().to_vec(),
            "UInt16" => (x as u16).to_le_bytes().to_vec(),
            "Int32" => (x as i32).to_le_bytes().to_vec(),
            "UInt32" => (x as u32).to_le_bytes().to_vec(),
            "Int64" => (x as i64).to_le_bytes().to_vec(),
            "UInt64" => (x as u64).to_le_bytes().to_vec(),
            "Float32" => (x as f32).to_le_bytes().to_vec(),
            "Float64" => x.to_le_bytes().to_vec(),
            _ => panic!("type {ty}"),
        };
        if be {
            b.reverse();
        }
        out.extend(b);
    }
    out
}

/// Header + payload of a binary block, VTK's layout.
fn block(bytes: &[u8], o: Opts) -> (Vec<u8>, Vec<u8>) {
    let int = |x: usize| -> Vec<u8> {
        let mut b = if o.header64 {
            (x as u64).to_le_bytes().to_vec()
        } else {
            (x as u32).to_le_bytes().to_vec()
        };
        if o.be {
            b.reverse();
        }
        b
    };
    if !o.zlib {
        return (int(bytes.len()), bytes.to_vec());
    }
    // Small blocks, so that several are used.
    let bs = 64;
    let mut h = int(bytes.len().div_ceil(bs));
    h.extend(int(bs));
    h.extend(int(bytes.len() % bs));
    let mut p = Vec::new();
    for c in bytes.chunks(bs) {
        let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(c).unwrap();
        let z = e.finish().unwrap();
        h.extend(int(z.len()));
        p.extend(z);
    }
    (h, p)
}

fn ext_str(start: [i64; 3], dims: [usize; 3]) -> String {
    (0..3)
        .map(|a| format!("{} {}", start[a], start[a] + dims[a] as i64 - 1))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A one-piece `.vti` with point dims `dims` starting at extent index `start`.
fn vti(
    dims: [usize; 3],
    start: [i64; 3],
    origin: [f64; 3],
    spacing: [f64; 3],
    dir: Option<[[f64; 3]; 3]>,
    arrays: &[Arr],
    o: Opts,
) -> Vec<u8> {
    let mut s = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"{}\" header_type=\"{}\"{}>\n",
        if o.be { "BigEndian" } else { "LittleEndian" },
        if o.header64 { "UInt64" } else { "UInt32" },
        if o.zlib {
            " compressor=\"vtkZLibDataCompressor\""
        } else {
            ""
        }
    );
    let e = ext_str(start, dims);
    s += &format!(
        "  <ImageData WholeExtent=\"{e}\" Origin=\"{} {} {}\" Spacing=\"{} {} {}\"",
        origin[0], origin[1], origin[2], spacing[0], spacing[1], spacing[2]
    );
    if let Some(d) = dir {
        let t: Vec<String> = d.iter().flatten().map(|x| format!("{x:?}")).collect();
        s += &format!(" Direction=\"{}\"", t.join(" "));
    }
    s += &format!(">\n  <Piece Extent=\"{e}\">\n");
    let mut appended: Vec<u8> = Vec::new();
    for cell in [false, true] {
        let sec = if cell { "CellData" } else { "PointData" };
        s += &format!("    <{sec}>\n");
        for a in arrays.iter().filter(|a| a.cell == cell) {
            s += &format!(
                "      <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"",
                a.ty, a.name, a.ncomp
            );
            let bytes = to_bytes(a.ty, &a.values, o.be);
            match o.enc {
                Enc::Ascii => {
                    s += " format=\"ascii\">\n        ";
                    let t: Vec<String> = a.values.iter().map(|x| format!("{x}")).collect();
                    s += &t.join(" ");
                    s += "\n      </DataArray>\n";
                }
                Enc::Binary => {
                    let (h, p) = block(&bytes, o);
                    s += " format=\"binary\">\n        ";
                    if o.zlib {
                        // VTK encodes the header and the data separately.
                        s += &b64(&h);
                        s += &b64(&p);
                    } else {
                        s += &b64(&[h, p].concat());
                    }
                    s += "\n      </DataArray>\n";
                }
                Enc::AppendedRaw | Enc::AppendedB64 => {
                    let (h, p) = block(&bytes, o);
                    let off = appended.len();
                    s += &format!(" format=\"appended\" offset=\"{off}\"/>\n");
                    if matches!(o.enc, Enc::AppendedRaw) {
                        appended.extend(h);
                        appended.extend(p);
                    } else {
                        appended.extend(b64(&[h, p].concat()).into_bytes());
                    }
                }
            }
        }
        s += &format!("    </{sec}>\n");
    }
    s += "  </Piece>\n  </ImageData>\n";
    let mut out = s.into_bytes();
    if !appended.is_empty() {
        let enc = if matches!(o.enc, Enc::AppendedRaw) {
            "raw"
        } else {
            "base64"
        };
        out.extend(format!("  <AppendedData encoding=\"{enc}\">\n   _").into_bytes());
        out.extend(appended);
        out.extend(b"\n  </AppendedData>\n");
    }
    out.extend(b"</VTKFile>\n");
    out
}

fn parse_vti(data: &[u8]) -> biotet_io::Result<ScalarGrid> {
    grid::parse_vti(data, "size.vti", None)
}

fn err_vti(data: &[u8], array: Option<&str>) -> String {
    grid::parse_vti(data, "size.vti", array)
        .unwrap_err()
        .to_string()
}

// ---------------------------------------------------------------------------------------------
// VTK ImageData tests.

#[test]
fn vti_ascii_rotated_with_shifted_extent() {
    let dims = [4, 3, 5];
    let start = [2, -1, 0];
    let origin = [1.0, -2.0, 0.5];
    let spacing = [0.5, 0.25, 1.5];
    let r = rotation([0.3, -1.0, 2.0], 0.9);
    // The grid's first point is at extent index `start`.
    let g0 = world(origin, spacing, r, start.map(|x| x as f64));
    let values = sample(dims, g0, spacing, r, linear);
    let data = vti(
        dims,
        start,
        origin,
        spacing,
        Some(r),
        &[arr("size", "Float64", values.clone())],
        ASCII,
    );
    let g = parse_vti(&data).unwrap();
    check_grid(&g, dims, g0, spacing, r, &values, 1e-14);
    // Interpolation reproduces the linear field inside the rotated grid.
    let mut rng = crate::common::Rng(5);
    for _ in 0..200 {
        let ijk: [f64; 3] = std::array::from_fn(|a| (dims[a] - 1) as f64 * rng.f64());
        let p = world(g0, spacing, r, ijk);
        assert!(close(g.value_at(p), linear(p), 1e-12));
    }
}

#[test]
fn vti_binary_encodings() {
    let dims = [5, 4, 3];
    let (origin, spacing) = ([-1.0, 0.0, 2.0], [0.1, 0.2, 0.3]);
    let values = sample(dims, origin, spacing, IDENTITY, linear);
    for enc in [Enc::Binary, Enc::AppendedRaw, Enc::AppendedB64] {
        for zlib in [false, true] {
            for header64 in [false, true] {
                for be in [false, true] {
                    let o = Opts {
                        enc,
                        zlib,
                        header64,
                        be,
                    };
                    let arrays = [
                        // A first array, to check that appended offsets are followed.
                        Arr {
                            name: "vectors",
                            ty: "Float32",
                            ncomp: 3,
                            cell: false,
                            values: vec![1.0; 3 * values.len()],
                        },
                        arr("size", "Float64", values.clone()),
                        arr("other", "Int32", vec![7.0; values.len()]),
                    ];
                    let data = vti(dims, [0; 3], origin, spacing, None, &arrays, o);
                    let g = parse_vti(&data).unwrap_or_else(|e| panic!("{o:?}: {e}"));
                    check_grid(&g, dims, origin, spacing, IDENTITY, &values, 0.0);
                    let g = grid::parse_vti(&data, "size.vti", Some("other")).unwrap();
                    assert_eq!(g.values, vec![7.0; values.len()], "{o:?}");
                }
            }
        }
    }
}

#[test]
fn vti_number_types() {
    let dims = [3, 2, 2];
    let values: Vec<f64> = (0..12).map(|i| i as f64 * 3.0 + 1.0).collect();
    for ty in [
        "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "Int64", "UInt64", "Float32",
        "Float64",
    ] {
        for o in [
            ASCII,
            Opts {
                enc: Enc::Binary,
                zlib: true,
                header64: true,
                be: true,
            },
        ] {
            let data = vti(
                dims,
                [0; 3],
                [0.0; 3],
                [1.0; 3],
                None,
                &[arr("s", ty, values.clone())],
                o,
            );
            let g = parse_vti(&data).unwrap_or_else(|e| panic!("{ty}: {e}"));
            assert_eq!(g.values, values, "{ty}");
        }
    }
}

#[test]
fn vti_array_choice() {
    let dims = [2, 2, 2];
    let a = |name: &'static str, v: f64| arr(name, "Float64", vec![v; 8]);
    // The first single-component point-data array.
    let multi = Arr {
        name: "vec",
        ty: "Float64",
        ncomp: 3,
        cell: false,
        values: vec![0.0; 24],
    };
    let data = vti(
        dims,
        [0; 3],
        [0.0; 3],
        [1.0; 3],
        None,
        &[multi, a("first", 1.0), a("second", 2.0)],
        ASCII,
    );
    assert_eq!(parse_vti(&data).unwrap().values[0], 1.0);
    assert_eq!(
        grid::parse_vti(&data, "x", Some("second")).unwrap().values[0],
        2.0
    );
    let e = err_vti(&data, Some("vec"));
    assert!(
        e.contains("DataArray 'vec' has 3 components; a scalar grid needs 1"),
        "{e}"
    );
    let e = err_vti(&data, Some("nope"));
    assert_eq!(
        e,
        "size.vti: no data array named 'nope'; the file has 'vec' (point data), 'first' (point data), 'second' (point data)"
    );
    // The active scalars win over the first array.
    let text = String::from_utf8(data)
        .unwrap()
        .replace("<PointData>", "<PointData Scalars=\"second\">");
    assert_eq!(parse_vti(text.as_bytes()).unwrap().values[0], 2.0);
}

#[test]
fn vti_cell_data_at_cell_centres() {
    let dims = [4, 3, 1]; // a flat image: 3×2×1 cells
    let (origin, spacing) = ([10.0, 20.0, 30.0], [2.0, 1.0, 5.0]);
    let cdims = [3, 2, 1];
    let centres0 = [11.0, 20.5, 30.0];
    let values = sample(cdims, centres0, spacing, IDENTITY, linear);
    let cells = Arr {
        name: "h",
        ty: "Float64",
        ncomp: 1,
        cell: true,
        values: values.clone(),
    };
    let data = vti(dims, [0; 3], origin, spacing, None, &[cells], ASCII);
    let g = parse_vti(&data).unwrap();
    check_grid(&g, cdims, centres0, spacing, IDENTITY, &values, 1e-15);
    assert!(close(
        g.value_at([12.0, 21.0, 99.0]),
        linear([12.0, 21.0, 30.0]),
        1e-14
    ));
    // Point data is preferred to cell data.
    let cells = Arr {
        name: "h",
        ty: "Float64",
        ncomp: 1,
        cell: true,
        values: vec![0.0; 6],
    };
    let data = vti(
        dims,
        [0; 3],
        origin,
        spacing,
        None,
        &[cells, arr("p", "Float64", vec![4.0; 12])],
        ASCII,
    );
    assert_eq!(parse_vti(&data).unwrap().dims, dims);
    assert_eq!(grid::parse_vti(&data, "x", Some("h")).unwrap().dims, cdims);
}

#[test]
fn vti_several_pieces() {
    // Points 0..=3 along x in two overlapping pieces (VTK's pieces share their boundary).
    let text = r#"<VTKFile type="ImageData" version="0.1">
  <ImageData WholeExtent="0 3 0 1 0 0" Origin="0 0 0" Spacing="1 1 1">
    <Piece Extent="0 1 0 1 0 0">
      <PointData Scalars="s"><DataArray type="Float32" Name="s" format="ascii">0 1 10 11</DataArray></PointData>
    </Piece>
    <Piece Extent="1 3 0 1 0 0">
      <PointData Scalars="s"><DataArray type="Float32" Name="s" format="ascii">1 2 3 11 12 13</DataArray></PointData>
    </Piece>
    <Piece Extent="0 -1 0 -1 0 -1"/>
  </ImageData>
</VTKFile>"#;
    let g = parse_vti(text.as_bytes()).unwrap();
    assert_eq!(g.dims, [4, 2, 1]);
    assert_eq!(g.values, vec![0.0, 1.0, 2.0, 3.0, 10.0, 11.0, 12.0, 13.0]);
    // A gap between pieces.
    let gap = text
        .replace("Extent=\"1 3 0 1 0 0\"", "Extent=\"3 3 0 1 0 0\"")
        .replace("1 2 3 11 12 13", "3 13");
    let e = err_vti(gap.as_bytes(), None);
    assert_eq!(
        e,
        "size.vti: line 2: the pieces do not cover the WholeExtent: 6 point values for 8 = 4×2×1 points"
    );
    // Enough values, but overlapping pieces leave a gap.
    let first = &text[text.find("<Piece").unwrap()..text.find("</Piece>").unwrap() + 8];
    let gap = gap.replace("<Piece Extent=\"0 -1 0 -1 0 -1\"/>", first);
    let e = err_vti(gap.as_bytes(), None);
    assert_eq!(
        e,
        "size.vti: line 2: the pieces do not cover the WholeExtent: point [2, 0, 0] has no value"
    );
    // A piece outside the whole extent.
    let out = text.replace("Extent=\"1 3 0 1 0 0\"", "Extent=\"1 4 0 1 0 0\"");
    let e = err_vti(out.as_bytes(), None);
    assert!(
        e.contains("piece 1: Extent is not inside the WholeExtent (axis 0)"),
        "{e}"
    );
}

#[test]
fn vti_negative_spacing_flips_the_axis() {
    let data = vti(
        [3, 2, 2],
        [0; 3],
        [5.0, 0.0, 0.0],
        [-1.0, 1.0, 1.0],
        None,
        &[arr("s", "Float64", (0..12).map(f64::from).collect())],
        ASCII,
    );
    let g = parse_vti(&data).unwrap();
    assert_eq!(g.spacing, [1.0; 3]);
    assert_eq!(g.direction[0][0], -1.0);
    assert_eq!(g.bounds(), [[3.0, 0.0, 0.0], [5.0, 1.0, 1.0]]);
    assert_eq!(g.value_at([3.0, 0.0, 0.0]), 2.0);
}

#[test]
fn vti_errors() {
    let dims = [10, 10, 10];
    let full = vti(
        dims,
        [0; 3],
        [0.0; 3],
        [1.0; 3],
        None,
        &[arr("size", "Float64", vec![1.0; 1000])],
        ASCII,
    );
    let short = vti(
        dims,
        [0; 3],
        [0.0; 3],
        [1.0; 3],
        None,
        &[arr("size", "Float64", vec![1.0; 100])],
        ASCII,
    );
    assert_eq!(
        err_vti(&short, None),
        "size.vti: DataArray 'size' has 100 values, expected 1000 = 10×10×10"
    );
    let long = vti(
        dims,
        [0; 3],
        [0.0; 3],
        [1.0; 3],
        None,
        &[arr("size", "Float64", vec![1.0; 1001])],
        ASCII,
    );
    assert_eq!(
        err_vti(&long, None),
        "size.vti: DataArray 'size' has 1001 values, expected 1000 = 10×10×10"
    );
    let text = String::from_utf8(full.clone()).unwrap();
    let cases: Vec<(String, &str)> = vec![
        (
            text.replace("Spacing=\"1 1 1\"", "Spacing=\"1 0 1\""),
            "spacing [1.0, 0.0, 1.0]: axis 1 is not a finite positive number",
        ),
        (
            text.replace("Spacing=\"1 1 1\"", "Spacing=\"1 1\""),
            "ImageData Spacing '1 1': expected 3 finite numbers",
        ),
        (
            text.replace("Origin=\"0 0 0\"", "Origin=\"0 nan 0\""),
            "ImageData Origin '0 nan 0': expected 3 finite numbers",
        ),
        (
            text.replace(
                "WholeExtent=\"0 9 0 9 0 9\"",
                "WholeExtent=\"0 9 0 -1 0 9\"",
            ),
            "empty WholeExtent",
        ),
        (
            text.replace(" WholeExtent=\"0 9 0 9 0 9\"", ""),
            "ImageData without a WholeExtent",
        ),
        (
            text.replace("<ImageData ", "<ImageData Direction=\"1 0 0 1 0 0 0 0 1\" "),
            "is singular",
        ),
        (
            text.replace("type=\"ImageData\"", "type=\"UnstructuredGrid\""),
            "VTK file type 'UnstructuredGrid': only ImageData (.vti) is read",
        ),
        (
            text.replace("1 1 1 1", "1 1 nan 1"),
            "value 2 (sample [2, 0, 0]) is NaN, not a finite number",
        ),
        (
            text.replace("1 1 1 1", "1 1 x 1"),
            "array 'size': bad number 'x'",
        ),
        (
            text.replace("<DataArray", "<DataArray compressor=\"x\"")
                .replace("<VTKFile", "<VTKFile compressor=\"vtkLZ4DataCompressor\""),
            "unsupported compressor 'vtkLZ4DataCompressor'",
        ),
        (
            text.replace("<PointData>", "<PointData/>")
                .replace("</PointData>", ""),
            "no PointData or CellData array",
        ),
        ("just text".to_string(), "no VTKFile element"),
    ];
    for (data, msg) in cases {
        let e = err_vti(data.as_bytes(), None);
        assert!(
            e.starts_with("size.vti: ") && e.contains(msg),
            "{e}\nexpected: {msg}"
        );
    }
    // Truncated or corrupted binary files: errors, never panics.
    for enc in [Enc::Binary, Enc::AppendedRaw, Enc::AppendedB64] {
        for zlib in [false, true] {
            let o = Opts {
                enc,
                zlib,
                header64: false,
                be: false,
            };
            let data = vti(
                [3, 3, 3],
                [0; 3],
                [0.0; 3],
                [1.0; 3],
                None,
                &[arr("size", "Float64", vec![2.0; 27])],
                o,
            );
            parse_vti(&data).unwrap();
            for n in 0..data.len() {
                let _ = parse_vti(&data[..n]);
            }
            let mut rng = crate::common::Rng(9);
            for _ in 0..300 {
                let mut d = data.clone();
                let i = (rng.next_u64() % d.len() as u64) as usize;
                d[i] = rng.next_u64() as u8;
                let _ = parse_vti(&d);
            }
        }
    }
    let o = Opts {
        enc: Enc::AppendedRaw,
        zlib: false,
        header64: false,
        be: false,
    };
    let data = vti(
        [3, 3, 3],
        [0; 3],
        [0.0; 3],
        [1.0; 3],
        None,
        &[arr("size", "Float64", vec![2.0; 27])],
        o,
    );
    let e = parse_vti(&data[..data.len() - 40]).unwrap_err().to_string();
    assert_eq!(
        e,
        "size.vti: truncated file: data of array 'size' is incomplete"
    );
    // A large extent with little data fails before the grid is allocated.
    let big = text
        .replace(
            "WholeExtent=\"0 9 0 9 0 9\"",
            "WholeExtent=\"0 1023 0 1023 0 1023\"",
        )
        .replace("Extent=\"0 9 0 9 0 9\"", "Extent=\"0 1023 0 1023 0 1023\"");
    let e = err_vti(big.as_bytes(), None);
    assert_eq!(
        e,
        "size.vti: DataArray 'size' has 1000 values, expected 1073741824 = 1024×1024×1024"
    );
    // A huge extent is refused before allocating.
    let huge = text.replace(
        "WholeExtent=\"0 9 0 9 0 9\"",
        "WholeExtent=\"0 99999 0 99999 0 99999\"",
    );
    let e = err_vti(huge.as_bytes(), None);
    assert!(
        e.contains(&format!(
            "grid of 100000×100000×100000 samples: more than the {MAX_GRID_SAMPLES} supported"
        )),
        "{e}"
    );
}

// ---------------------------------------------------------------------------------------------
// A small NIfTI writer.

#[derive(Clone)]
struct Nii {
    v2: bool,
    be: bool,
    dim: Vec<i64>,
    datatype: i16,
    bitpix: i16,
    pixdim: [f64; 8],
    slope: f64,
    inter: f64,
    qform_code: i16,
    sform_code: i16,
    quatern: [f64; 3],
    qoffset: [f64; 3],
    srow: [[f64; 4]; 3],
    magic: Option<&'static [u8]>,
}

impl Nii {
    fn new(dims: [usize; 3], datatype: i16, bitpix: i16) -> Nii {
        Nii {
            v2: false,
            be: false,
            dim: dims.iter().map(|&d| d as i64).collect(),
            datatype,
            bitpix,
            pixdim: [1.0; 8],
            slope: 0.0,
            inter: 0.0,
            qform_code: 0,
            sform_code: 0,
            quatern: [0.0; 3],
            qoffset: [0.0; 3],
            srow: [[0.0; 4]; 3],
            magic: None,
        }
    }

    /// Header, 4 bytes of extension flag, then the data (`data` little-endian, swapped here).
    fn bytes(&self, data: &[u8], elem: usize) -> Vec<u8> {
        let size = if self.v2 { 540 } else { 348 };
        let mut h = vec![0u8; size + 4];
        let be = self.be;
        let put = |h: &mut Vec<u8>, at: usize, b: &[u8]| {
            let mut b = b.to_vec();
            if be {
                b.reverse();
            }
            h[at..at + b.len()].copy_from_slice(&b);
        };
        let mut dim = [1i64; 8];
        dim[0] = self.dim.len() as i64;
        dim[1..=self.dim.len()].copy_from_slice(&self.dim);
        put(&mut h, 0, &(size as i32).to_le_bytes());
        if !self.v2 {
            for (i, (d, p)) in dim.iter().zip(self.pixdim).enumerate() {
                put(&mut h, 40 + 2 * i, &(*d as i16).to_le_bytes());
                put(&mut h, 76 + 4 * i, &(p as f32).to_le_bytes());
            }
            put(&mut h, 70, &self.datatype.to_le_bytes());
            put(&mut h, 72, &self.bitpix.to_le_bytes());
            put(&mut h, 108, &((size + 4) as f32).to_le_bytes());
            put(&mut h, 112, &(self.slope as f32).to_le_bytes());
            put(&mut h, 116, &(self.inter as f32).to_le_bytes());
            put(&mut h, 252, &self.qform_code.to_le_bytes());
            put(&mut h, 254, &self.sform_code.to_le_bytes());
            for i in 0..3 {
                put(&mut h, 256 + 4 * i, &(self.quatern[i] as f32).to_le_bytes());
                put(&mut h, 268 + 4 * i, &(self.qoffset[i] as f32).to_le_bytes());
                for c in 0..4 {
                    put(
                        &mut h,
                        280 + 16 * i + 4 * c,
                        &(self.srow[i][c] as f32).to_le_bytes(),
                    );
                }
            }
            h[344..348].copy_from_slice(self.magic.unwrap_or(b"n+1\0"));
        } else {
            h[4..12].copy_from_slice(self.magic.unwrap_or(b"n+2\0\r\n\x1a\n"));
            put(&mut h, 12, &self.datatype.to_le_bytes());
            put(&mut h, 14, &self.bitpix.to_le_bytes());
            for (i, (d, p)) in dim.iter().zip(self.pixdim).enumerate() {
                put(&mut h, 16 + 8 * i, &d.to_le_bytes());
                put(&mut h, 104 + 8 * i, &p.to_le_bytes());
            }
            put(&mut h, 168, &((size + 4) as i64).to_le_bytes());
            put(&mut h, 176, &self.slope.to_le_bytes());
            put(&mut h, 184, &self.inter.to_le_bytes());
            put(&mut h, 344, &(self.qform_code as i32).to_le_bytes());
            put(&mut h, 348, &(self.sform_code as i32).to_le_bytes());
            for i in 0..3 {
                put(&mut h, 352 + 8 * i, &self.quatern[i].to_le_bytes());
                put(&mut h, 376 + 8 * i, &self.qoffset[i].to_le_bytes());
                for c in 0..4 {
                    put(&mut h, 400 + 32 * i + 8 * c, &self.srow[i][c].to_le_bytes());
                }
            }
        }
        for c in data.chunks(elem) {
            let mut c = c.to_vec();
            if be {
                c.reverse();
            }
            h.extend(c);
        }
        h
    }
}

fn f32_bytes(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|&x| (x as f32).to_le_bytes()).collect()
}

fn gz(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

fn parse_nii(data: &[u8]) -> biotet_io::Result<ScalarGrid> {
    grid::parse_nifti(data, "size.nii")
}

fn err_nii(data: &[u8]) -> String {
    parse_nii(data).unwrap_err().to_string()
}

// ---------------------------------------------------------------------------------------------
// NIfTI tests.

#[test]
fn nifti_float32_sform_with_rotation() {
    let dims = [4, 5, 3];
    let r = rotation([1.0, 1.0, 0.2], -0.6);
    let spacing = [0.5, 2.0, 1.25];
    let origin = [-10.0, 4.0, 7.5];
    // Values exactly representable in f32.
    let values: Vec<f64> = (0..60).map(|i| 0.25 * i as f64 - 3.0).collect();
    for v2 in [false, true] {
        for be in [false, true] {
            let mut n = Nii::new(dims, 16, 32);
            n.v2 = v2;
            n.be = be;
            n.sform_code = 2;
            // A qform that must be ignored in favour of the sform.
            n.qform_code = 1;
            n.quatern = [0.5, 0.5, 0.5];
            for row in 0..3 {
                for c in 0..3 {
                    n.srow[row][c] = r[row][c] * spacing[c];
                }
                n.srow[row][3] = origin[row];
            }
            let data = n.bytes(&f32_bytes(&values), 4);
            let g = parse_nii(&data).unwrap_or_else(|e| panic!("v2 {v2} be {be}: {e}"));
            let tol = if v2 { 1e-14 } else { 1e-6 };
            check_grid(&g, dims, origin, spacing, r, &values, tol);
            // gzip: the same grid.
            let g2 = parse_nii(&gz(&data)).unwrap();
            assert_eq!(g, g2);
        }
    }
}

#[test]
fn nifti_int16_with_scaling() {
    let dims = [3, 2, 2];
    let stored: Vec<i16> = vec![-5, 0, 1, 2, 3, 100, -100, 7, 8, 9, 10, 11];
    let bytes: Vec<u8> = stored.iter().flat_map(|x| x.to_le_bytes()).collect();
    for be in [false, true] {
        let mut n = Nii::new(dims, 4, 16);
        n.be = be;
        n.slope = 0.5;
        n.inter = 2.0;
        n.pixdim = [1.0, 0.75, 0.5, 2.0, 1.0, 1.0, 1.0, 1.0];
        let g = parse_nii(&n.bytes(&bytes, 2)).unwrap();
        let expected: Vec<f64> = stored.iter().map(|&x| 0.5 * x as f64 + 2.0).collect();
        // No sform, no qform: diag(pixdim), origin 0.
        check_grid(
            &g,
            dims,
            [0.0; 3],
            [0.75, 0.5, 2.0],
            IDENTITY,
            &expected,
            0.0,
        );
        // Slope 0: no scaling.
        n.slope = 0.0;
        let g = parse_nii(&n.bytes(&bytes, 2)).unwrap();
        assert_eq!(
            g.values,
            stored.iter().map(|&x| x as f64).collect::<Vec<_>>()
        );
    }
}

#[test]
fn nifti_voxel_types() {
    let values: Vec<f64> = vec![0.0, 1.0, 2.0, 100.0, 5.0, 6.0, 7.0, 120.0];
    type Encode = fn(f64) -> Vec<u8>;
    let cases: [(i16, usize, Encode); 10] = [
        (2, 1, |x| (x as u8).to_le_bytes().to_vec()),
        (256, 1, |x| (x as i8).to_le_bytes().to_vec()),
        (4, 2, |x| (x as i16).to_le_bytes().to_vec()),
        (512, 2, |x| (x as u16).to_le_bytes().to_vec()),
        (8, 4, |x| (x as i32).to_le_bytes().to_vec()),
        (768, 4, |x| (x as u32).to_le_bytes().to_vec()),
        (1024, 8, |x| (x as i64).to_le_bytes().to_vec()),
        (1280, 8, |x| (x as u64).to_le_bytes().to_vec()),
        (16, 4, |x| (x as f32).to_le_bytes().to_vec()),
        (64, 8, |x| x.to_le_bytes().to_vec()),
    ];
    for (code, size, enc) in cases {
        let bytes: Vec<u8> = values.iter().flat_map(|&x| enc(x)).collect();
        for be in [false, true] {
            let mut n = Nii::new([2, 2, 2], code, 8 * size as i16);
            n.be = be;
            let g = parse_nii(&n.bytes(&bytes, size)).unwrap_or_else(|e| panic!("{code}: {e}"));
            assert_eq!(g.values, values, "datatype {code}");
        }
    }
}

#[test]
fn nifti_qform_quaternion() {
    // A rotation of 90° about z: quaternion (a, b, c, d) = (cos 45°, 0, 0, sin 45°).
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let mut n = Nii::new([2, 3, 2], 64, 64);
    n.qform_code = 1;
    n.quatern = [0.0, 0.0, h];
    n.qoffset = [1.0, 2.0, 3.0];
    n.pixdim = [-1.0, 2.0, 3.0, 4.0, 1.0, 1.0, 1.0, 1.0]; // qfac = -1 flips k
    let bytes: Vec<u8> = (0..12).flat_map(|i| (i as f64).to_le_bytes()).collect();
    let g = parse_nii(&n.bytes(&bytes, 8)).unwrap();
    // i → +y, j → -x, k → -z.
    let dir = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]];
    check_grid(
        &g,
        [2, 3, 2],
        [1.0, 2.0, 3.0],
        [2.0, 3.0, 4.0],
        dir,
        &(0..12).map(f64::from).collect::<Vec<_>>(),
        1e-6,
    );
    assert!(close(g.value_at(g.world([1.0, 2.0, 1.0])), 11.0, 1e-9));
    // The qform needs positive voxel sizes.
    n.pixdim[2] = -3.0;
    let e = err_nii(&n.bytes(&bytes, 8));
    assert!(
        e.contains("pixdim[2] = -3: the voxel size must be finite and positive"),
        "{e}"
    );
}

#[test]
fn nifti_4d_with_one_volume_and_fewer_dims() {
    let mut n = Nii::new([2, 2, 2], 16, 32);
    n.dim = vec![2, 2, 2, 1];
    let vals: Vec<f64> = (0..8).map(f64::from).collect();
    assert_eq!(
        parse_nii(&n.bytes(&f32_bytes(&vals), 4)).unwrap().dims,
        [2, 2, 2]
    );
    // A 2D image: dims [3, 2, 1].
    n.dim = vec![3, 2];
    let vals: Vec<f64> = (0..6).map(f64::from).collect();
    assert_eq!(
        parse_nii(&n.bytes(&f32_bytes(&vals), 4)).unwrap().dims,
        [3, 2, 1]
    );
}

#[test]
fn nifti_errors() {
    let vals: Vec<f64> = (0..8).map(f64::from).collect();
    let bytes = f32_bytes(&vals);
    let base = Nii::new([2, 2, 2], 16, 32);
    let good = base.bytes(&bytes, 4);
    parse_nii(&good).unwrap();
    let with = |f: &dyn Fn(&mut Nii)| {
        let mut n = base.clone();
        f(&mut n);
        err_nii(&n.bytes(&bytes, 4))
    };
    let cases = [
        (
            with(&|n| n.dim = vec![2, 2, 2, 3]),
            "4D image with dim[4] = 3 (dim = [2, 2, 2, 3]): a scalar grid needs a single 3D volume",
        ),
        (
            with(&|n| n.dim = vec![2, -2, 2]),
            "dim[2] = -2: dimensions must be at least 1",
        ),
        (
            with(&|n| n.dim = vec![2, 0, 2]),
            "dim[2] = 0: dimensions must be at least 1",
        ),
        (
            with(&|n| n.dim = vec![30000, 30000, 30000]),
            "grid of 30000×30000×30000 samples: more than the 1073741824 supported",
        ),
        (
            with(&|n| n.datatype = 32),
            "datatype 32 (complex64) is not supported",
        ),
        (
            with(&|n| n.datatype = 128),
            "datatype 128 (RGB24) is not supported",
        ),
        (
            with(&|n| n.datatype = 999),
            "datatype 999 (unknown) is not supported",
        ),
        (
            with(&|n| n.magic = Some(b"ni1\0")),
            "NIfTI-1 header of a .hdr/.img pair (magic 'ni1'): only single-file .nii is read",
        ),
        (
            with(&|n| n.magic = Some(b"\0\0\0\0")),
            "is not 'n+1' (an Analyze 7.5 file?)",
        ),
        (
            with(&|n| n.pixdim[3] = 0.0),
            "pixdim[3] = 0: the voxel size must be finite and non-zero",
        ),
        (
            with(&|n| {
                n.sform_code = 1;
                n.srow = [
                    [1.0, 0.0, 0.0, 0.0],
                    [0.0, 0.0, 0.0, 0.0],
                    [0.0, 0.0, 1.0, 0.0],
                ];
            }),
            "sform column 1 is zero",
        ),
        (
            with(&|n| {
                n.sform_code = 1;
                n.srow = [
                    [1.0, 1.0, 0.0, 0.0],
                    [1.0, 1.0, 0.0, 0.0],
                    [0.0, 0.0, 1.0, 0.0],
                ];
            }),
            "is singular",
        ),
    ];
    for (e, msg) in cases {
        assert!(
            e.starts_with("size.nii: ") && e.contains(msg),
            "{e}\nexpected: {msg}"
        );
    }
    // NaN voxels.
    let mut nan = vals.clone();
    nan[5] = f64::NAN;
    let e = err_nii(&base.bytes(&f32_bytes(&nan), 4));
    assert_eq!(
        e,
        "size.nii: value 5 (sample [1, 0, 1]) is NaN, not a finite number"
    );
    // Not NIfTI at all.
    assert_eq!(
        err_nii(b"hello world"),
        "size.nii: header size 1819043176: not a NIfTI-1 (348) or NIfTI-2 (540) file"
    );
    // Truncated data, plain and gzipped.
    let e = err_nii(&good[..good.len() - 1]);
    assert_eq!(
        e,
        "size.nii: truncated file: header announces 2×2×2 float32 voxels (32 bytes) from byte 352, the file has 383 bytes"
    );
    let z = gz(&good[..good.len() - 1]);
    assert!(err_nii(&z).contains("truncated file"));
    // Every prefix and random corruptions: errors, never panics.
    let z = gz(&good);
    for data in [&good, &z] {
        for n in 0..data.len() {
            assert!(parse_nii(&data[..n]).is_err());
        }
        let mut rng = crate::common::Rng(11);
        for _ in 0..2000 {
            let mut d = data.clone();
            let i = (rng.next_u64() % d.len() as u64) as usize;
            d[i] = rng.next_u64() as u8;
            let _ = parse_nii(&d);
        }
    }
    // A gzip bomb-like header: huge announced data, tiny file.
    let mut n = base.clone();
    n.dim = vec![1024, 1024, 1024];
    let e = err_nii(&gz(&n.bytes(&bytes, 4)));
    assert!(
        e.contains("truncated file: header announces 1024×1024×1024 float32 voxels"),
        "{e}"
    );
}

// ---------------------------------------------------------------------------------------------
// Files and dispatch.

#[test]
fn read_by_extension() {
    let dir = tempfile::tempdir().unwrap();
    let vals: Vec<f64> = (0..8).map(f64::from).collect();
    let nii = Nii::new([2, 2, 2], 16, 32).bytes(&f32_bytes(&vals), 4);
    let vti_data = vti(
        [2, 2, 2],
        [0; 3],
        [0.0; 3],
        [1.0; 3],
        None,
        &[arr("size", "Float64", vals.clone())],
        ASCII,
    );
    let files: [(&str, Vec<u8>); 5] = [
        ("a.vti", vti_data.clone()),
        ("B.VTI", vti_data),
        ("c.nii", nii.clone()),
        ("d.nii.gz", gz(&nii)),
        ("E.NII.GZ", gz(&nii)),
    ];
    for (name, data) in files {
        let p = dir.path().join(name);
        std::fs::write(&p, data).unwrap();
        let g = read_scalar_grid(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(g.values, vals, "{name}");
    }
    assert_eq!(
        GridFormat::from_path(Path::new("x.nii.gz")).unwrap(),
        GridFormat::Nifti
    );
    assert_eq!(
        read_scalar_grid_named(&dir.path().join("a.vti"), Some("size"))
            .unwrap()
            .values,
        vals
    );
    let e = read_scalar_grid_named(&dir.path().join("c.nii"), Some("size"))
        .unwrap_err()
        .to_string();
    assert!(
        e.ends_with(
            "c.nii: array 'size' requested, but a NIfTI file holds a single unnamed volume"
        ),
        "{e}"
    );
    let e = read_scalar_grid(Path::new("x.gz")).unwrap_err().to_string();
    assert_eq!(
        e,
        "x.gz: unknown scalar grid file extension; supported: .vti, .nii, .nii.gz"
    );
    let e = read_scalar_grid(&dir.path().join("missing.vti"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.vti: "), "{e}");
}

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// Files written by nibabel (tests/data/nibabel_grids.py): the geometry and values nibabel reads
/// back (nibabel_expected.txt) are what we read.
#[test]
fn nibabel_written_files() {
    let expected = std::fs::read_to_string(data("nibabel_expected.txt")).unwrap();
    let lines: Vec<&str> = expected.lines().collect();
    assert_eq!(lines.len(), 9);
    for rec in lines.chunks(3) {
        let nums = |s: &str| -> Vec<f64> { s.split(' ').map(|t| t.parse().unwrap()).collect() };
        let (name, affine, values) = (rec[0], nums(rec[1]), nums(rec[2]));
        let g = read_scalar_grid(&data(name)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(g.dims, [5, 4, 3], "{name}");
        for (i, (a, b)) in g.values.iter().zip(&values).enumerate() {
            assert!(
                close(*a, *b, 1e-12),
                "{name}: value {i}: {a} vs nibabel {b}"
            );
        }
        // world(i, j, k) = affine · (i, j, k, 1), at every corner.
        for c in 0..8 {
            let ijk = [
                (c & 1) as f64 * 4.0,
                (c >> 1 & 1) as f64 * 3.0,
                (c >> 2 & 1) as f64 * 2.0,
            ];
            let w = g.world(ijk);
            for r in 0..3 {
                let e = (0..3).map(|k| affine[4 * r + k] * ijk[k]).sum::<f64>() + affine[4 * r + 3];
                assert!(
                    close(w[r], e, 1e-12),
                    "{name}: corner {ijk:?}: {w:?}, nibabel {e}"
                );
            }
        }
        // The field: 1 + i/2 - j/4 + 2k, up to int16 quantisation.
        let g0 = g.world([1.5, 2.25, 0.5]);
        assert!(
            close(g.value_at(g0), 1.0 + 0.75 - 0.5625 + 1.0, 1e-4),
            "{name}"
        );
    }
}

/// Files written by VTK 9.7 (tests/data/vtk_grids.py): a rotated image whose extent starts at
/// (1, -2, 0), with the field `1 + x/2 - y/4 + 2z` of the world coordinates VTK computed.
#[test]
fn vtk_written_files() {
    let f = |p: [f64; 3]| 1.0 + 0.5 * p[0] - 0.25 * p[1] + 2.0 * p[2];
    let d = [
        0.886326664612489,
        -0.3669073891114443,
        0.2824960378701332,
        0.40188379999990925,
        0.9125589727788377,
        -0.07566724851919487,
        -0.23003142153743583,
        0.18059648118458965,
        0.9562794863894188,
    ];
    let dir = [[d[0], d[1], d[2]], [d[3], d[4], d[5]], [d[6], d[7], d[8]]];
    let spacing = [0.8, 1.1, 2.5];
    let origin = world([-20.0, 5.5, 13.0], spacing, dir, [1.0, -2.0, 0.0]);
    for name in [
        "vtk_image_appended_raw_zlib.vti",
        "vtk_image_binary_uint32.vti",
        "vtk_image_ascii.vti",
    ] {
        let p = data(name);
        // The active scalars ("size"), not the first array ("other").
        let g = read_scalar_grid(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
        let values = sample([5, 4, 3], origin, spacing, dir, f);
        check_grid(&g, [5, 4, 3], origin, spacing, dir, &values, 1e-12);
        let g = read_scalar_grid_named(&p, Some("other")).unwrap();
        assert_eq!(g.values, vec![7.0; 60]);
        // Cell data (Float32) at the cell centres.
        let g = read_scalar_grid_named(&p, Some("cellsize")).unwrap();
        let centre0 = world(origin, spacing, dir, [0.5; 3]);
        let values = sample([4, 3, 2], centre0, spacing, dir, f);
        check_grid(&g, [4, 3, 2], centre0, spacing, dir, &values, 1e-6);
    }
}
