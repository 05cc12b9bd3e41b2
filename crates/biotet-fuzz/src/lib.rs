//! The fuzz targets of biotet: every reader, surface validation, and the meshing pipeline on
//! small closed surfaces made from the fuzzer's bytes.
//!
//! [`run`] is the whole harness: `fuzz/` wraps it in libFuzzer (one binary, the target named by
//! `BIOTET_FUZZ_TARGET`), and this crate's tests replay the seed corpora and every input that
//! ever failed (`fuzz/regressions/<target>/`) through it. A target fails by panicking, so the
//! properties checked beyond "no panic" are assertions:
//! - a reader's error is one line starting with the file name;
//! - what a reader returns has every index in range;
//! - a surface that validation accepts and the pipeline meshes gives a mesh that `check` passes.
//!
//! Memory is bounded twice: [`biotet_io::limits`] is set to [`MEMORY_LIMIT`] so readers refuse
//! larger estimates, and [`CappedAlloc`] (the fuzz binary's and the replay test's allocator)
//! aborts on any single allocation above [`ALLOCATION_CAP`], which a count taken from a header
//! without a check against the file's size would make.

use std::alloc::{GlobalAlloc, Layout, System};

use biotet::SurfaceMesh;
use biotet::mesh::validate::{ValidateOptions, validate_surface};
use biotet::pipeline::{PipelineOptions, mesh_surface};
use biotet::sizing::Sizing;
use biotet_io::{Error, SurfaceRead, TetRead, TriRead};

/// Every target, by name.
pub const TARGETS: &[&str] = &[
    "stl",
    "obj",
    "off",
    "ply",
    "vtu_surface",
    "vtp_surface",
    "vtk_surface",
    "freesurfer_surface",
    "gifti_surface",
    "medit_surface",
    "vtu_tet",
    "vtk_tet",
    "medit_tet",
    "gmsh_tet",
    "tetgen_tet",
    "medit_tri",
    "triangle_tri",
    "poly",
    "node_edge",
    "xyz",
    "peek",
    "grid_vti",
    "grid_nifti",
    "image_nifti",
    "image_mgh",
    "image_nrrd",
    "image_metaimage",
    "image_vti",
    "validate",
    "pipeline",
];

/// The reader memory budget set by [`run`]: far above what a fuzz input of a few kilobytes can
/// hold, far below the machine.
pub const MEMORY_LIMIT: u64 = 256 << 20;

/// The largest single allocation [`CappedAlloc`] grants.
pub const ALLOCATION_CAP: usize = 512 << 20;

/// The system allocator, aborting the process on any allocation larger than [`ALLOCATION_CAP`]
/// (libFuzzer's own malloc limit needs a sanitizer runtime, which stable Rust has not).
pub struct CappedAlloc;

// SAFETY: every call is forwarded to `System` unchanged, or the process ends.
unsafe impl GlobalAlloc for CappedAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        cap(layout.size());
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        cap(layout.size());
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded with the caller's pointer and layout.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        cap(new_size);
        // SAFETY: forwarded with the caller's pointer, layout and size.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

fn cap(size: usize) {
    if size > ALLOCATION_CAP {
        // No allocation (and so no formatting) here: write a fixed message and abort.
        let msg = b"biotet-fuzz: allocation above the cap\n";
        // SAFETY: writing a static buffer to stderr.
        unsafe {
            write(2, msg.as_ptr(), msg.len());
        }
        std::process::abort();
    }
}

unsafe extern "C" {
    fn write(fd: i32, buf: *const u8, count: usize) -> isize;
}

/// Run target `target` on `data`; `false` when no target has that name. Panics when a
/// property fails.
pub fn run(target: &str, data: &[u8]) -> bool {
    biotet_io::limits::set_max_memory(MEMORY_LIMIT);
    match target {
        "stl" => surface(biotet_io::stl::parse(data, F), F),
        "obj" => surface(biotet_io::obj::parse(data, F), F),
        "off" => surface(biotet_io::off::parse(data, F), F),
        "ply" => surface(biotet_io::ply::parse(data, F), F),
        "vtu_surface" => surface(biotet_io::vtu::parse_surface(data, F), F),
        "vtp_surface" => surface(biotet_io::vtp::parse_surface(data, F), F),
        "freesurfer_surface" => surface(biotet_io::freesurfer::parse(data, F), F),
        "gifti_surface" => surface(biotet_io::gifti::parse(data, F), F),
        "vtk_surface" => surface(biotet_io::vtk::parse_surface(data, F), F),
        "medit_surface" => surface(biotet_io::medit::parse_surface(data, F), F),
        "vtu_tet" => tet(biotet_io::vtu::parse_tet(data, F), F),
        "vtk_tet" => tet(biotet_io::vtk::parse_tet(data, F), F),
        "medit_tet" => tet(biotet_io::medit::parse_tet(data, F), F),
        "gmsh_tet" => tet(biotet_io::gmsh::parse_tet(data, F), F),
        "tetgen_tet" => {
            let (a, b) = split(data);
            tet(biotet_io::tetgen::parse_tet(a, b, F), F)
        }
        "medit_tri" => tri(biotet_io::medit::parse_tri(data, F), F),
        "triangle_tri" => {
            let (a, b) = split(data);
            tri(biotet_io::tetgen::parse_tri(a, b, F), F)
        }
        "poly" => {
            let r = biotet_io::poly::parse_poly(data, F, None);
            if let Err(e) = r {
                error(&e, F);
            }
        }
        "node_edge" => {
            let (a, b) = split(data);
            if let Err(e) = biotet_io::poly::parse_node_edge(a, F, b, F) {
                error(&e, F);
            }
        }
        "xyz" => match biotet_io::points::parse_xyz(data, F) {
            Ok(p) => assert!(p.iter().flatten().all(|c| c.is_finite())),
            Err(e) => error(&e, F),
        },
        "peek" => {
            for r in [
                biotet_io::medit::peek_kind(data, F).map(|_| ()),
                biotet_io::vtu::peek_kind(data, F).map(|_| ()),
                biotet_io::vtk::peek_kind(data, F).map(|_| ()),
                biotet_io::tetgen::peek_dim(data, F).map(|_| ()),
            ] {
                if let Err(e) = r {
                    error(&e, F);
                }
            }
        }
        "grid_vti" => grid(biotet_io::grid::parse_vti(data, F, None)),
        "grid_nifti" => grid(biotet_io::grid::parse_nifti(data, F)),
        "image_nifti" => image(biotet_io::image::nifti::parse(data, F)),
        "image_mgh" => image(biotet_io::image::mgh::parse(data, F)),
        "image_nrrd" => image(biotet_io::image::nrrd::parse(data, F, None)),
        "image_metaimage" => image(biotet_io::image::metaimage::parse(data, F, None)),
        "image_vti" => image(biotet_io::image::vti::parse(data, F)),
        "validate" => {
            let mut s = soup(data);
            let _ = validate_surface(&mut s, &ValidateOptions::default());
        }
        "pipeline" => {
            let _ = pipeline(data);
        }
        _ => return false,
    }
    true
}

/// The file name readers are given.
const F: &str = "fuzz.in";

/// Two files from one input: split at the first NUL byte (text formats hold none).
fn split(data: &[u8]) -> (&[u8], &[u8]) {
    match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &[]),
    }
}

/// An error is one line that starts with the file name.
fn error(e: &Error, file: &str) {
    let m = e.to_string();
    assert!(m.starts_with(file), "error without the file name: {m}");
    assert!(!m.contains('\n'), "error of more than one line: {m:?}");
}

fn surface(r: biotet_io::Result<SurfaceRead>, file: &str) {
    match r {
        Ok(s) => {
            let n = s.mesh.points.len();
            assert!(s.mesh.triangles.iter().flatten().all(|&v| (v as usize) < n));
            assert_eq!(s.mesh.sides.len(), s.mesh.triangles.len());
            if let Some(l) = &s.side_labels {
                assert_eq!(l.len(), s.mesh.triangles.len());
            }
            if let Some(l) = &s.triangle_refs {
                assert_eq!(l.len(), s.mesh.triangles.len());
            }
        }
        Err(e) => error(&e, file),
    }
}

fn tet(r: biotet_io::Result<TetRead>, file: &str) {
    match r {
        Ok(t) => {
            let n = t.mesh.points.len();
            assert!(t.mesh.tets.iter().flatten().all(|&v| (v as usize) < n));
            assert_eq!(t.mesh.labels.len(), t.mesh.tets.len());
            // What a reader returns goes to the checker and the quality report next.
            let _ = biotet::check::check(&t.mesh, None);
        }
        Err(e) => error(&e, file),
    }
}

fn tri(r: biotet_io::Result<TriRead>, file: &str) {
    match r {
        Ok(t) => {
            let n = t.mesh.points.len();
            assert!(t.mesh.triangles.iter().flatten().all(|&v| (v as usize) < n));
            let _ = biotet::check2d::check_tri(&t.mesh, None);
        }
        Err(e) => error(&e, file),
    }
}

fn grid(r: biotet_io::Result<biotet::sizing_grid::ScalarGrid>) {
    match r {
        Ok(g) => {
            let _ = g.value_at([0.0; 3]);
        }
        Err(e) => error(&e, F),
    }
}

fn image(r: biotet_io::Result<biotet::image::LabelImage>) {
    match r {
        Ok(i) => assert_eq!(i.labels.len(), i.dims.iter().product::<usize>()),
        Err(e) => error(&e, F),
    }
}

/// A little-endian reader of the fuzzer's bytes that gives zeros once they run out.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        match self.0.split_first() {
            Some((&b, rest)) => {
                self.0 = rest;
                b
            }
            None => 0,
        }
    }
}

/// Points on a small integer grid (some nudged by 2⁻⁴⁰, near-degenerate) and triangles over
/// them, sides `[1, 0]`: mostly invalid surfaces, some closed ones.
fn soup(data: &[u8]) -> SurfaceMesh {
    let mut b = Bytes(data);
    let np = 4 + (b.u8() % 13) as usize;
    let mut points = Vec::with_capacity(np);
    for _ in 0..np {
        points.push(std::array::from_fn(|_| {
            let c = b.u8();
            (c % 8) as f64 + if c & 0x80 != 0 { 2f64.powi(-40) } else { 0.0 }
        }));
    }
    let mut triangles = Vec::new();
    while !b.0.is_empty() && triangles.len() < 64 {
        triangles.push(std::array::from_fn(|_| (b.u8() as usize % np) as u32));
    }
    SurfaceMesh {
        points,
        sides: vec![[1, 0]; triangles.len()],
        triangles,
    }
}

/// A closed surface from bytes: a sphere (icosahedron, once subdivided or not) with each
/// vertex moved along its ray (so never self-intersecting), or a triangle soup; then scaled by
/// 2^e (up to the ends of the double range), translated (cancellation) and rounded to a grid
/// (coplanar points) as the bytes say.
pub fn closed_surface(data: &[u8]) -> SurfaceMesh {
    let mut b = Bytes(data);
    let mode = b.u8();
    let mut s = if mode % 4 == 3 {
        soup(b.0)
    } else {
        let mut s = SurfaceMesh::icosphere(1.0, (mode % 2) as usize);
        for p in &mut s.points {
            let r = 0.25 + b.u8() as f64 / 64.0;
            *p = p.map(|c| c * r);
        }
        s
    };
    let e = match b.u8() {
        x @ 0..200 => (x as i32 - 100) / 4,
        x => [-1070, -1020, -600, -300, 300, 600, 1000, 1020][(x % 8) as usize],
    };
    let scale = 2f64.powi(e);
    let shift = b.u8() as f64 * 2f64.powi(b.u8() as i32 / 4);
    let grid = b.u8();
    for p in &mut s.points {
        for c in p.iter_mut() {
            *c = *c * scale + shift * scale;
            if grid & 0x80 != 0 {
                let q = scale * 2f64.powi(-((grid % 8) as i32));
                *c = (*c / q).round() * q;
            }
        }
    }
    s
}

/// Validate a surface made by [`closed_surface`]; mesh it coarsely when valid; the mesh must
/// then pass `check`, with every surface triangle a face unless the pipeline reported some
/// missing. Returns how far it got: `Err(stage)` with the stage that refused the input, or
/// `Ok(tets)`.
pub fn pipeline(data: &[u8]) -> Result<usize, &'static str> {
    let coarse = data.last().copied().unwrap_or(0);
    let mut s = closed_surface(data);
    if validate_surface(&mut s, &ValidateOptions::default()).is_err() {
        return Err("validate");
    }
    let (lo, hi) = bounds(&s.points);
    let diag = (0..3).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f64>().sqrt();
    let Ok(sizing) = Sizing::uniform(diag / (2.0 + (coarse % 4) as f64)) else {
        return Err("sizing");
    };
    let mut opts = PipelineOptions::default();
    opts.deploy.max_voxels = 1 << 18;
    let Ok((mesh, report)) = mesh_surface(&s, sizing, &opts, &mut |_| {}) else {
        return Err("mesh");
    };
    let c = biotet::check::check(&mesh, None);
    assert!(c.valid, "pipeline output fails check: {c:?}");
    if report.missing_triangles == 0 {
        let c = biotet::check::check(&mesh, Some(&s));
        assert!(c.valid, "pipeline output lacks surface triangles: {c:?}");
    }
    Ok(mesh.tets.len())
}

fn bounds(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    (lo, hi)
}
