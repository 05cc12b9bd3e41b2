//! FreeSurfer triangle surfaces (`lh.pial`, `rh.white`, `lh.smoothwm`, …: the binary files of a
//! subject's `surf/` directory, named without a format extension).
//!
//! Layout (big endian): the three bytes `FF FF FE` (the triangle file magic), a creator line
//! ending in two newlines, the counts of vertices and faces (`int32`), the vertices (three
//! `float32` each, surface RAS as stored: FreeSurfer's "tkregister" space, not scanner RAS), the
//! faces (three `int32` vertex indices each). What may follow (the volume geometry a recent
//! FreeSurfer appends) is ignored. Files starting `FF FF FF` (curvature files, the older
//! quadrangle surfaces) are refused, saying so. Surfaces are recognised by their first bytes,
//! whatever their name ([`is_freesurfer`]), or by the extension `.surf`.
//!
//! Written with the creator line `created by biotet`; coordinates are stored as `float32`, so a
//! surface written and read back has its points rounded to single precision.

use std::io::Write;

use biotet::SurfaceMesh;

use crate::SurfaceRead;
use crate::common::{check_surface, plain_surface};
use crate::error::{Error, Result};
use crate::limits;

/// The triangle file's first three bytes.
const MAGIC: [u8; 3] = [0xFF, 0xFF, 0xFE];
/// The first bytes of the older quadrangle surfaces and of curvature files (`lh.thickness`):
/// neither is read.
const QUAD_MAGIC: [u8; 3] = [0xFF, 0xFF, 0xFF];
/// The creator line is read up to this many bytes.
const MAX_CREATOR: usize = 4096;

/// Whether `head` (a file's first bytes) starts a FreeSurfer triangle surface.
pub fn is_freesurfer(head: &[u8]) -> bool {
    head.starts_with(&MAGIC)
}

/// Parse a FreeSurfer triangle surface held in memory.
pub fn parse(data: &[u8], file: &str) -> Result<SurfaceRead> {
    if data.starts_with(&QUAD_MAGIC) {
        return Err(Error::format(
            file,
            "starts with FF FF FF: a FreeSurfer curvature file (lh.thickness, lh.curv) or an old \
             quadrangle surface, not a triangle surface (mris_convert makes one)",
        ));
    }
    if !data.starts_with(&MAGIC) {
        return Err(Error::format(
            file,
            "not a FreeSurfer triangle surface (it does not start with FF FF FE)",
        ));
    }
    let rest = &data[3..];
    let end = rest[..rest.len().min(MAX_CREATOR)]
        .windows(2)
        .position(|w| w == b"\n\n")
        .ok_or_else(|| {
            Error::format(
                file,
                "the creator line does not end in two newlines within its first 4,096 bytes",
            )
        })?;
    let mut at = 3 + end + 2;
    let int = |at: &mut usize, what: &str| -> Result<i32> {
        let b = data.get(*at..*at + 4).ok_or_else(|| {
            Error::format(file, format!("the file ends inside {what} (byte {at})"))
        })?;
        *at += 4;
        Ok(i32::from_be_bytes([b[0], b[1], b[2], b[3]]))
    };
    let nv = int(&mut at, "the vertex count")?;
    let nf = int(&mut at, "the face count")?;
    if nv < 0 || nf < 0 {
        return Err(Error::format(
            file,
            format!("negative counts: {nv} vertices, {nf} faces"),
        ));
    }
    let (nv, nf) = (nv as usize, nf as usize);
    // The counts must fit the bytes left: a hostile header cannot make us allocate.
    let need = 12u64 * (nv as u64 + nf as u64);
    let left = (data.len() - at) as u64;
    if need > left {
        return Err(Error::format(
            file,
            format!("{nv} vertices and {nf} faces need {need} bytes, {left} are left in the file"),
        ));
    }
    limits::reserve(file, "the surface", need.saturating_mul(2))?;
    let f32_at = |i: usize| {
        let b = &data[at + 4 * i..at + 4 * i + 4];
        f32::from_be_bytes([b[0], b[1], b[2], b[3]]) as f64
    };
    let points: Vec<[f64; 3]> = (0..nv)
        .map(|v| [f32_at(3 * v), f32_at(3 * v + 1), f32_at(3 * v + 2)])
        .collect();
    at += 12 * nv;
    let mut triangles = Vec::with_capacity(nf);
    for f in 0..nf {
        let mut t = [0u32; 3];
        for (k, c) in t.iter_mut().enumerate() {
            let b = &data[at + 12 * f + 4 * k..at + 12 * f + 4 * k + 4];
            let i = i32::from_be_bytes([b[0], b[1], b[2], b[3]]);
            if i < 0 || i as usize >= nv {
                return Err(Error::invalid(
                    file,
                    format!("face {f}: vertex {i} out of range (the surface has {nv})"),
                ));
            }
            *c = i as u32;
        }
        triangles.push(t);
    }
    plain_surface(points, triangles, file)
}

/// Write a FreeSurfer triangle surface (coordinates rounded to `float32`; side labels are not
/// stored).
pub fn write<W: Write>(mut w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    check_surface(mesh, file)?;
    let too_many = |what: &str, n: usize| {
        Error::invalid(
            file,
            format!("{n} {what}: a FreeSurfer surface holds at most 2^31 - 1"),
        )
    };
    let nv = i32::try_from(mesh.points.len()).map_err(|_| too_many("points", mesh.points.len()))?;
    let nf = i32::try_from(mesh.triangles.len())
        .map_err(|_| too_many("triangles", mesh.triangles.len()))?;
    let mut out = Vec::with_capacity(32 + 12 * (mesh.points.len() + mesh.triangles.len()));
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(b"created by biotet\n\n");
    out.extend_from_slice(&nv.to_be_bytes());
    out.extend_from_slice(&nf.to_be_bytes());
    for p in &mesh.points {
        for c in p {
            out.extend_from_slice(&(*c as f32).to_be_bytes());
        }
    }
    for t in &mesh.triangles {
        for &v in t {
            out.extend_from_slice(&(v as i32).to_be_bytes());
        }
    }
    w.write_all(&out).map_err(|e| Error::io(file, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_surface_reads_back_in_single_precision() {
        let s = SurfaceMesh::icosphere(1.5, 1);
        let mut buf = Vec::new();
        write(&mut buf, &s, "lh.test").unwrap();
        assert!(is_freesurfer(&buf));
        let r = parse(&buf, "lh.test").unwrap();
        assert_eq!(r.mesh.triangles, s.triangles);
        for (a, b) in r.mesh.points.iter().zip(&s.points) {
            for k in 0..3 {
                assert_eq!(a[k], b[k] as f32 as f64);
            }
        }
        // A volume-geometry tail is ignored.
        let mut tail = buf.clone();
        tail.extend_from_slice(b"\0\0\0\x14valid = 1  # volume info valid\n");
        assert_eq!(parse(&tail, "lh.test").unwrap().mesh, r.mesh);
    }

    #[test]
    fn hostile_headers_are_refused_naming_the_file() {
        let s = SurfaceMesh::icosphere(1.0, 0);
        let mut good = Vec::new();
        write(&mut good, &s, "f").unwrap();
        // Every truncation, and a few byte flips, without a panic.
        for n in 0..good.len() {
            let e = parse(&good[..n], "rh.white").unwrap_err().to_string();
            assert!(e.contains("rh.white"), "{n}: {e}");
        }
        for k in 0..good.len() {
            let mut bad = good.clone();
            bad[k] ^= 0xA5;
            if let Err(e) = parse(&bad, "rh.white") {
                assert!(e.to_string().contains("rh.white"));
            }
        }
        let mut huge = good.clone();
        let at = 3 + "created by biotet\n\n".len();
        huge[at..at + 4].copy_from_slice(&i32::MAX.to_be_bytes());
        let e = parse(&huge, "rh.white").unwrap_err().to_string();
        assert!(e.contains("bytes"), "{e}");
        let mut quad = good.clone();
        quad[2] = 0xFF;
        let e = parse(&quad, "rh.white").unwrap_err().to_string();
        assert!(e.contains("curvature") && e.contains("rh.white"), "{e}");
    }
}
