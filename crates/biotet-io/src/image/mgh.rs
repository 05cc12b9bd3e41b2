//! FreeSurfer MGH label images (`.mgh`; gzipped `.mgz`).
//!
//! Big-endian header: `version` (1), `width`, `height`, `depth`, `nframes` (must be 1), `type`
//! (0 `uchar`, 1 `int32`, 3 `float32`, 4 `int16`, 10 `uint16`), `dof`, `goodRASFlag` (int16);
//! when the flag is set, the spacing (3 × float32), the direction cosines `Mdc` (the x, y and z
//! axis directions, 3 float32 each) and `c_ras` (the world position of the volume centre);
//! voxels start at byte 284, x fastest. Without the flag FreeSurfer's defaults hold (spacing 1,
//! axes −x, −z, +y: a coronal LIA volume, centre at 0).
//!
//! `vox2ras = [Mdc · diag(spacing) | c_ras − Mdc · diag(spacing) · (dims / 2.0)]`, as FreeSurfer
//! and nibabel compute it. World space: RAS+ (scanner RAS).

use biotet::image::LabelImage;

use super::Scalar;
use crate::error::{Error, Result};

const HEADER: usize = 284;

fn be_i32(b: &[u8], at: usize) -> i32 {
    i32::from_be_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}
fn be_f32(b: &[u8], at: usize) -> f64 {
    f32::from_be_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]) as f64
}

/// Parse an MGH file held in memory (gzip recognised by its magic bytes).
pub fn parse(data: &[u8], file: &str) -> Result<LabelImage> {
    let gz;
    let data: &[u8] = if data.starts_with(&[0x1f, 0x8b]) {
        let head = super::inflate(data, false, HEADER, file)?;
        let (dims, ty) = layout(&head, file)?;
        let n = super::voxel_count(dims, file)?;
        gz = super::inflate(data, false, HEADER + n * ty.size(), file)?;
        &gz
    } else {
        data
    };
    let (dims, ty) = layout(data, file)?;
    let n = super::voxel_count(dims, file)?;
    let labels = super::decode(&data[HEADER..], ty, true, n, file)?;
    let good = i16::from_be_bytes([data[28], data[29]]) != 0;
    let (spacing, mdc, c_ras) = if good {
        (
            [be_f32(data, 30), be_f32(data, 34), be_f32(data, 38)],
            std::array::from_fn::<[f64; 3], 3, _>(|a| {
                std::array::from_fn(|r| be_f32(data, 42 + 12 * a + 4 * r))
            }),
            [be_f32(data, 78), be_f32(data, 82), be_f32(data, 86)],
        )
    } else {
        (
            [1.0; 3],
            [[-1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]],
            [0.0; 3],
        )
    };
    let mut affine = [[0.0; 4]; 3];
    for r in 0..3 {
        for a in 0..3 {
            affine[r][a] = mdc[a][r] * spacing[a];
        }
        let centre: f64 = (0..3).map(|a| affine[r][a] * (dims[a] as f64 / 2.0)).sum();
        affine[r][3] = c_ras[r] - centre;
    }
    super::build(file, dims, affine, labels, [false; 3])
}

fn layout(h: &[u8], file: &str) -> Result<([usize; 3], Scalar)> {
    if h.len() < HEADER {
        return Err(Error::truncated(
            file,
            format!(
                "{} bytes, shorter than the {HEADER}-byte MGH header",
                h.len()
            ),
        ));
    }
    let version = be_i32(h, 0);
    if version != 1 {
        return Err(Error::format(
            file,
            format!("MGH version {version}, expected 1 (not an MGH file?)"),
        ));
    }
    let mut dims = [0usize; 3];
    for (a, d) in dims.iter_mut().enumerate() {
        let v = be_i32(h, 4 + 4 * a);
        if v < 1 {
            return Err(Error::format(file, format!("dimension {a} is {v}")));
        }
        *d = v as usize;
    }
    let frames = be_i32(h, 16);
    if frames != 1 {
        return Err(Error::format(
            file,
            format!("{frames} frames: a label image has one"),
        ));
    }
    let ty = match be_i32(h, 20) {
        0 => Scalar::U8,
        1 => Scalar::I32,
        3 => Scalar::F32,
        4 => Scalar::I16,
        10 => Scalar::U16,
        t => {
            return Err(Error::format(
                file,
                format!("MGH type {t} not supported (0 uchar, 1 int, 3 float, 4 short, 10 ushort)"),
            ));
        }
    };
    Ok((dims, ty))
}
