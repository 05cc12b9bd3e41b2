//! Write the seed corpora `fuzz/seeds/<target>/`: small meshes written by biotet's own writers
//! in every format and encoding, the small files of the test data, and byte strings for the
//! generated-surface targets. Run by `scripts/fuzz.sh seeds`; the output is committed.

use std::fs;
use std::path::{Path, PathBuf};

use biotet::SurfaceMesh;
use biotet::delaunay::Delaunay;
use biotet::mesh::pslg::Pslg;
use biotet_io::{SurfaceFormat, TetFormat, TriFormat};

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = root.join("fuzz/seeds");
    let _ = fs::remove_dir_all(&out);
    let tmp = tempdir(&root);
    let put = |target: &str, name: &str, data: &[u8]| {
        let d = out.join(target);
        fs::create_dir_all(&d).unwrap();
        fs::write(d.join(name), data).unwrap();
    };

    // Surfaces: a tetrahedron and a cube (two-label sides on the cube, for PLY/VTU/Medit).
    let tet4 = SurfaceMesh::icosphere(1.0, 0);
    let mut cube = biotet_io::off::parse(
        &fs::read(root.join("tests/data/shapes/tm_box.off")).unwrap(),
        "tm_box.off",
    )
    .unwrap()
    .mesh;
    cube.sides = vec![[2, 0]; cube.triangles.len()];
    for (ext, f, target) in [
        ("stl", SurfaceFormat::Stl, "stl"),
        ("stl", SurfaceFormat::StlAscii, "stl"),
        ("obj", SurfaceFormat::Obj, "obj"),
        ("off", SurfaceFormat::Off, "off"),
        ("ply", SurfaceFormat::Ply, "ply"),
        ("ply", SurfaceFormat::PlyAscii, "ply"),
        ("mesh", SurfaceFormat::Medit, "medit_surface"),
        ("vtu", SurfaceFormat::Vtu, "vtu_surface"),
        ("vtp", SurfaceFormat::Vtp, "vtp_surface"),
        ("vtk", SurfaceFormat::Vtk, "vtk_surface"),
        ("surf", SurfaceFormat::FreeSurfer, "freesurfer_surface"),
        ("gii", SurfaceFormat::Gifti, "gifti_surface"),
    ] {
        for (name, m) in [("ico", &tet4), ("cube", &cube)] {
            let p = tmp.join(format!("{name}_{f:?}.{ext}"));
            biotet_io::write_surface_as(&p, m, f).unwrap();
            put(
                target,
                &format!("{name}_{f:?}.{ext}"),
                &fs::read(&p).unwrap(),
            );
        }
    }
    for f in [
        "gen_tetrahedron.off",
        "invalid_open_box.off",
        "gen_schonhardt.off",
    ] {
        put(
            "off",
            f,
            &fs::read(root.join("tests/data/shapes").join(f)).unwrap(),
        );
    }

    // Tet meshes: the Delaunay of a cube's corners and centre, labelled 1 and 2.
    let mut pts = vec![[0.5, 0.5, 0.5]];
    for i in 0..8 {
        pts.push([(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]);
    }
    let mut tm = Delaunay::new(&pts).unwrap().to_tet_mesh();
    for (i, l) in tm.labels.iter_mut().enumerate() {
        *l = 1 + (i % 2) as u32;
    }
    for (ext, f, target) in [
        ("vtu", TetFormat::Vtu, "vtu_tet"),
        ("mesh", TetFormat::Medit, "medit_tet"),
        ("msh", TetFormat::Gmsh, "gmsh_tet"),
        ("msh", TetFormat::GmshBinary, "gmsh_tet"),
        ("vtk", TetFormat::Vtk, "vtk_tet"),
    ] {
        let p = tmp.join(format!("cube_{f:?}.{ext}"));
        biotet_io::write_tet_mesh_as(&p, &tm, f).unwrap();
        put(target, &format!("cube_{f:?}.{ext}"), &fs::read(&p).unwrap());
    }
    for (enc, name) in [
        (biotet_io::VtuEncoding::Ascii, "ascii"),
        (biotet_io::VtuEncoding::Raw, "raw"),
        (biotet_io::VtuEncoding::RawZlib, "raw_zlib"),
        (biotet_io::VtuEncoding::Base64, "base64"),
        (biotet_io::VtuEncoding::Base64Zlib, "base64_zlib"),
    ] {
        let mut v = Vec::new();
        biotet_io::vtu::write_tet_with(&mut v, &tm, "x.vtu", enc).unwrap();
        put("vtu_tet", &format!("cube_{name}.vtu"), &v);
    }
    // Legacy VTK as VTK 9 writes it in ASCII (the 5.1 layout): one tet and a triangle.
    let ascii51 = "# vtk DataFile Version 5.1\nvtk output\nASCII\nDATASET UNSTRUCTURED_GRID\n\
                   POINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 3 7\nOFFSETS vtktypeint64\n0 4 7\n\
                   CONNECTIVITY vtktypeint64\n0 1 2 3 0 2 1\nCELL_TYPES 2\n10\n5\n\
                   CELL_DATA 2\nSCALARS region int 1\nLOOKUP_TABLE default\n3 0\n";
    put("vtk_tet", "one_tet_51.vtk", ascii51.as_bytes());
    put("vtk_surface", "one_tet_51.vtk", ascii51.as_bytes());
    let p = tmp.join("cube.node");
    let written = biotet_io::write_tet_mesh_as(&p, &tm, TetFormat::TetGen).unwrap();
    let node = fs::read(&written[0]).unwrap();
    let ele = fs::read(&written[1]).unwrap();
    put(
        "tetgen_tet",
        "cube.node_ele",
        &[&node[..], b"\0", &ele[..]].concat(),
    );
    put("peek", "cube.node", &node);
    let td = root.join("crates/biotet-io/tests/data");
    for f in [
        "gmsh_two_boxes_22.msh",
        "gmsh_two_boxes_41.msh",
        "gmsh_two_boxes_41_binary.msh",
    ] {
        put("gmsh_tet", f, &fs::read(td.join(f)).unwrap());
    }
    put(
        "medit_tet",
        "gmsh_two_boxes.mesh",
        &fs::read(td.join("gmsh_two_boxes.mesh")).unwrap(),
    );
    for f in [
        "vtk_appended_base64_uint32.vtu",
        "vtk_appended_raw_bigendian_zlib.vtu",
        "vtk_ascii.vtu",
        "vtk_inline_base64_zlib.vtu",
    ] {
        put("vtu_tet", f, &fs::read(td.join(f)).unwrap());
        put("peek", f, &fs::read(td.join(f)).unwrap());
    }

    // 2D: a square with a hole as a PSLG, meshed.
    let g = Pslg {
        points: vec![
            [0.0, 0.0],
            [4.0, 0.0],
            [4.0, 4.0],
            [0.0, 4.0],
            [1.0, 1.0],
            [3.0, 1.0],
            [2.0, 3.0],
        ],
        segments: vec![[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 4]],
        segment_markers: vec![1, 1, 1, 1, 2, 2, 2],
        holes: vec![[2.0, 2.0]],
        regions: Vec::new(),
    };
    let mut poly = Vec::new();
    biotet_io::poly::write_poly(&mut poly, &g, "x.poly").unwrap();
    put("poly", "square_hole.poly", &poly);
    let (tri, _) = biotet::pipeline2d::triangulate_pslg(&g, &[]).unwrap();
    for (ext, f, target) in [
        ("mesh", TriFormat::Medit, "medit_tri"),
        ("node", TriFormat::Triangle, "triangle_tri"),
    ] {
        let p = tmp.join(format!("square.{ext}"));
        let w = biotet_io::write_tri_mesh_as(&p, &tri, f).unwrap();
        if w.len() == 1 {
            put(target, &format!("square.{ext}"), &fs::read(&w[0]).unwrap());
            put("peek", &format!("square.{ext}"), &fs::read(&w[0]).unwrap());
        } else {
            let node = fs::read(&w[0]).unwrap();
            let ele = fs::read(&w[1]).unwrap();
            put(
                target,
                "square.node_ele",
                &[&node[..], b"\0", &ele[..]].concat(),
            );
            let edge = b"3 1\n0 0 1 1\n1 1 2 1\n2 2 0 1\n";
            put(
                "node_edge",
                "square.node_edge",
                &[&node[..], b"\0", &edge[..]].concat(),
            );
        }
    }
    put(
        "xyz",
        "points.xyz",
        b"0 0 0\n1 0 0\n0 1 0\n# c\n0 0 1.5e3\n",
    );

    // Size fields and label images: the test data.
    for (f, targets) in [
        (
            "vtk_image_ascii.vti",
            &["grid_vti", "image_vti", "peek"][..],
        ),
        ("vtk_image_binary_uint32.vti", &["grid_vti", "image_vti"]),
        (
            "vtk_image_appended_raw_zlib.vti",
            &["grid_vti", "image_vti"],
        ),
        ("label_ascii.vti", &["grid_vti", "image_vti"]),
        ("nibabel_int16_sform.nii.gz", &["grid_nifti", "image_nifti"]),
        (
            "nibabel_nifti2_bigendian.nii",
            &["grid_nifti", "image_nifti"],
        ),
        ("nibabel_qform_flipped.nii", &["grid_nifti", "image_nifti"]),
        ("label_fractional.nii", &["grid_nifti", "image_nifti"]),
        ("label_nifti1_int16.nii.gz", &["grid_nifti", "image_nifti"]),
        (
            "label_nifti2_float32_qform.nii",
            &["grid_nifti", "image_nifti"],
        ),
        ("label_uint8.mgz", &["image_mgh"]),
        ("label_lps_gzip.nrrd", &["image_nrrd"]),
        ("label_ras_detached.nhdr", &["image_nrrd"]),
        ("label_uint8.mha", &["image_metaimage"]),
        ("label_int32.mhd", &["image_metaimage"]),
    ] {
        for t in targets {
            put(t, f, &fs::read(td.join(f)).unwrap());
        }
    }
    // An uncompressed MGH: the .mgz inflated.
    let mgz = fs::read(td.join("label_uint8.mgz")).unwrap();
    let mut mgh = Vec::new();
    flate2_inflate(&mgz, &mut mgh);
    put("image_mgh", "label_uint8.mgh", &mgh);

    // Generated surfaces: a tetrahedron as a triangle soup (4 points, 4 outward triangles),
    // and spheres at several scales for the pipeline.
    let soup = [
        0u8, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3,
    ];
    put("validate", "tetrahedron", &soup);
    put("validate", "tetrahedron_nudged", &{
        let mut s = soup;
        s[4] |= 0x80;
        s
    });
    put(
        "pipeline",
        "soup_tetrahedron",
        &[&[3u8][..], &soup].concat(),
    );
    for (name, bytes) in [
        (
            "ico",
            vec![
                0u8, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 100, 0, 0, 0, 1,
            ],
        ),
        (
            "ico_bumpy",
            vec![
                0, 10, 200, 30, 90, 64, 64, 5, 64, 250, 64, 64, 64, 100, 0, 0, 0, 0,
            ],
        ),
        (
            "ico_tiny",
            vec![
                0, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 0, 0, 0, 0, 2,
            ],
        ),
        (
            "ico_far",
            vec![
                0, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 100, 255, 120, 0, 3,
            ],
        ),
        (
            "ico_grid",
            vec![
                0, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 100, 0, 0, 0x82, 0,
            ],
        ),
        (
            "ico_huge",
            vec![
                0, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 206, 0, 0, 0, 0,
            ],
        ),
    ] {
        put("pipeline", name, &bytes);
    }
    let _ = fs::remove_dir_all(&tmp);
    println!("seeds written to {}", out.display());
}

fn flate2_inflate(gz: &[u8], out: &mut Vec<u8>) {
    use std::io::Read;
    flate2::read::MultiGzDecoder::new(gz)
        .read_to_end(out)
        .unwrap();
}

fn tempdir(root: &Path) -> PathBuf {
    let d = root.join("target/fuzz-seeds-tmp");
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}
