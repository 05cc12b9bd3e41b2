//! Label images (segmentations): one reader per format, all giving a
//! [`biotet::image::LabelImage`] whose world coordinates are **RAS+** (x to the right, y to the
//! front, z up), in the file's units (millimetres in practice).
//!
//! | format | extensions | world space in the file | conversion |
//! |---|---|---|---|
//! | NIfTI-1/2 ([`nifti`]) | `.nii`, `.nii.gz` | RAS+ (sform, else qform, else pixdim) | none |
//! | FreeSurfer MGH ([`mgh`]) | `.mgh`, `.mgz` | RAS+ (vox2ras from direction cosines, spacing, c_ras) | none |
//! | NRRD ([`nrrd`]) | `.nrrd`, `.nhdr` (+ detached data) | the `space` field: RAS, LAS or LPS (ITK and Slicer write LPS) | x (and y) negated for LAS (LPS) |
//! | MetaImage ([`metaimage`]) | `.mha`, `.mhd` (+ `ElementDataFile`) | LPS (ITK's convention) | x and y negated |
//! | VTK ImageData ([`vti`]) | `.vti` | none stated | taken as RAS+ |
//!
//! Labels are unsigned integers; float voxel types must hold integral values, and negative
//! values are refused, each with an error naming the first offending voxel. Images of more than
//! [`crate::grid::MAX_GRID_SAMPLES`] voxels are refused before anything is allocated.
//! Every reader returns an error, never panics, on truncated or garbage input.

use std::path::Path;

use biotet::image::LabelImage;

use crate::common::{MAX_LABEL, checked_label};
use crate::error::{Error, Result};

pub mod metaimage;
pub mod mgh;
pub mod nifti;
pub mod nrrd;
pub mod vti;

/// Supported label image extensions, for messages.
pub const IMAGE_EXTENSIONS: &str = ".nii, .nii.gz, .mgh, .mgz, .nrrd, .nhdr, .mha, .mhd, .vti";

/// Label image formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ImageFormat {
    /// NIfTI-1 or NIfTI-2, optionally gzipped.
    Nifti,
    /// FreeSurfer MGH, optionally gzipped (`.mgz`).
    Mgh,
    /// NRRD, attached (`.nrrd`) or detached (`.nhdr`).
    Nrrd,
    /// MetaImage, `.mha` (one file) or `.mhd` (+ data file).
    MetaImage,
    /// VTK XML ImageData.
    Vti,
}

impl ImageFormat {
    /// The format named by a path's extension (case-insensitive), if it is a label image.
    pub fn detect(path: &Path) -> Option<ImageFormat> {
        let n = path
            .file_name()
            .map(|n| n.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let ends = |e: &str| n.ends_with(e);
        Some(if ends(".nii") || ends(".nii.gz") {
            ImageFormat::Nifti
        } else if ends(".mgh") || ends(".mgz") || ends(".mgh.gz") {
            ImageFormat::Mgh
        } else if ends(".nrrd") || ends(".nhdr") {
            ImageFormat::Nrrd
        } else if ends(".mha") || ends(".mhd") {
            ImageFormat::MetaImage
        } else if ends(".vti") {
            ImageFormat::Vti
        } else {
            return None;
        })
    }
}

/// Whether a path names a label image (by extension).
pub fn is_label_image(path: &Path) -> bool {
    ImageFormat::detect(path).is_some()
}

/// Read a label image, choosing the format by extension.
pub fn read_label_image(path: &Path) -> Result<LabelImage> {
    let n = crate::name(path);
    let format = ImageFormat::detect(path).ok_or_else(|| Error::UnknownExtension {
        path: n.clone(),
        kind: "label image",
        supported: IMAGE_EXTENSIONS,
    })?;
    let data = crate::atomic::read_file(path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    match format {
        ImageFormat::Nifti => nifti::parse(&data, &n),
        ImageFormat::Mgh => mgh::parse(&data, &n),
        ImageFormat::Nrrd => nrrd::parse(&data, &n, Some(dir)),
        ImageFormat::MetaImage => metaimage::parse(&data, &n, Some(dir)),
        ImageFormat::Vti => vti::parse(&data, &n),
    }
}

/// Voxel types of the binary formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scalar {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    U64,
    I64,
    F32,
    F64,
}

impl Scalar {
    pub(crate) fn size(self) -> usize {
        match self {
            Scalar::U8 | Scalar::I8 => 1,
            Scalar::U16 | Scalar::I16 => 2,
            Scalar::U32 | Scalar::I32 | Scalar::F32 => 4,
            Scalar::U64 | Scalar::I64 | Scalar::F64 => 8,
        }
    }
}

/// The number of voxels, refused above the limit or when the voxels' values and labels (12
/// bytes a voxel) exceed the memory budget.
pub(crate) fn voxel_count(dims: [usize; 3], file: &str) -> Result<usize> {
    let n = crate::grid::sample_count(dims, file)?;
    crate::limits::reserve(
        file,
        &format!("an image of {}×{}×{} voxels", dims[0], dims[1], dims[2]),
        n as u64 * 12,
    )?;
    Ok(n)
}

/// A label from a float value: finite, integral, in `0..=MAX_LABEL`.
pub(crate) fn float_label(x: f64, at: usize, file: &str) -> Result<u32> {
    if x.is_finite() && x.fract() == 0.0 && (0.0..=f64::from(MAX_LABEL)).contains(&x) {
        Ok(x as u32)
    } else {
        Err(not_a_label(x, at, file))
    }
}

fn int_label(x: i128, at: usize, file: &str) -> Result<u32> {
    checked_label(x).ok_or_else(|| not_a_label(x, at, file))
}

fn not_a_label(x: impl std::fmt::Display, at: usize, file: &str) -> Error {
    Error::format(
        file,
        format!("voxel {at} holds {x}: labels must be whole numbers from 0 to {MAX_LABEL}"),
    )
}

/// Decode `n` voxels of type `ty` from `bytes` (at least `n·size` long) to labels.
pub(crate) fn decode(
    bytes: &[u8],
    ty: Scalar,
    big_endian: bool,
    n: usize,
    file: &str,
) -> Result<Vec<u32>> {
    let size = ty.size();
    if bytes.len() / size < n {
        return Err(Error::truncated(
            file,
            format!(
                "{} bytes of voxel data, {} voxels need {}",
                bytes.len(),
                n,
                n.saturating_mul(size)
            ),
        ));
    }
    let mut out = Vec::with_capacity(n);
    for (at, c) in bytes.chunks_exact(size).take(n).enumerate() {
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(c);
        if big_endian {
            b[..size].reverse();
        }
        let l = match ty {
            Scalar::U8 => b[0] as u32,
            Scalar::I8 => int_label(b[0] as i8 as i128, at, file)?,
            Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as u32,
            Scalar::I16 => int_label(i16::from_le_bytes([b[0], b[1]]) as i128, at, file)?,
            Scalar::U32 => int_label(
                u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i128,
                at,
                file,
            )?,
            Scalar::I32 => int_label(
                i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i128,
                at,
                file,
            )?,
            Scalar::U64 => int_label(u64::from_le_bytes(b) as i128, at, file)?,
            Scalar::I64 => int_label(i64::from_le_bytes(b) as i128, at, file)?,
            Scalar::F32 => float_label(
                f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                at,
                file,
            )?,
            Scalar::F64 => float_label(f64::from_le_bytes(b), at, file)?,
        };
        out.push(l);
    }
    Ok(out)
}

/// Inflate gzip (or zlib, when `zlib`) data, reading at most `limit` bytes of output.
pub(crate) fn inflate(data: &[u8], zlib: bool, limit: usize, file: &str) -> Result<Vec<u8>> {
    use std::io::Read;
    let mut out = Vec::with_capacity(limit.min(data.len().saturating_mul(64)));
    let r = if zlib {
        flate2::read::ZlibDecoder::new(data)
            .take(limit as u64)
            .read_to_end(&mut out)
    } else {
        flate2::read::MultiGzDecoder::new(data)
            .take(limit as u64)
            .read_to_end(&mut out)
    };
    r.map_err(|e| Error::format(file, format!("{}: {e}", if zlib { "zlib" } else { "gzip" })))?;
    Ok(out)
}

/// A checked image, errors naming the file. `lps` converts LPS world coordinates to RAS.
pub(crate) fn build(
    file: &str,
    dims: [usize; 3],
    affine: [[f64; 4]; 3],
    labels: Vec<u32>,
    negate_rows: [bool; 3],
) -> Result<LabelImage> {
    let mut m = [[0.0; 4]; 4];
    for r in 0..3 {
        let s = if negate_rows[r] { -1.0 } else { 1.0 };
        for c in 0..4 {
            m[r][c] = s * affine[r][c];
        }
    }
    m[3][3] = 1.0;
    LabelImage::new(dims, m, labels).map_err(|e| Error::format(file, e.to_string()))
}

/// Rows to negate for a world space named by a NRRD `space` or similar: LPS → x, y; LAS → x.
pub(crate) const LPS: [bool; 3] = [true, true, false];

/// Header text helpers shared by the text-header formats.
pub(crate) fn numbers(s: &str) -> Option<Vec<f64>> {
    s.split(|c: char| c.is_whitespace() || c == ',' || c == '(' || c == ')')
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect()
}

/// A sibling data file named in a header, read whole; refused if the header was given without
/// a directory (parsing from memory).
pub(crate) fn read_sibling(dir: Option<&Path>, name: &str, file: &str) -> Result<Vec<u8>> {
    let Some(dir) = dir else {
        return Err(Error::format(
            file,
            format!("data in the separate file '{name}', but no directory to read it from"),
        ));
    };
    let p = dir.join(name);
    crate::atomic::read_file(&p)
}
