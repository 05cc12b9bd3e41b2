//! NIfTI-1 and NIfTI-2 label images (`.nii`, `.nii.gz`): the header, voxel types, scaling and
//! world mapping of [`crate::grid`]'s NIfTI reader (sform if `sform_code` > 0, else qform if
//! `qform_code` > 0, else `diag(pixdim)`; `value = scl_slope · stored + scl_inter` when
//! `scl_slope` is finite and non-zero). World space: RAS+, as the file gives it.

use biotet::image::LabelImage;

use crate::error::{Error, Result};
use crate::grid::{gunzip_nifti, nifti_affine, nifti_header, nifti_layout, nifti_values};

/// Parse a NIfTI file held in memory (gzip recognised by its magic bytes).
pub fn parse(data: &[u8], file: &str) -> Result<LabelImage> {
    let gz;
    let data: &[u8] = if data.starts_with(&[0x1f, 0x8b]) {
        gz = gunzip_nifti(data, file)?;
        &gz
    } else {
        data
    };
    let h = nifti_header(data, file)?;
    let l = nifti_layout(&h, file)?;
    let end = l.offset + l.nbytes;
    if data.len() < end {
        return Err(Error::truncated(
            file,
            format!(
                "header announces {} bytes of voxels from byte {}, the file has {} bytes",
                l.nbytes,
                l.offset,
                data.len()
            ),
        ));
    }
    let affine = nifti_affine(&h, file)?;
    let values = nifti_values(&h, &l, &data[l.offset..end]);
    let labels = values
        .iter()
        .enumerate()
        .map(|(at, &x)| super::float_label(x, at, file))
        .collect::<Result<Vec<u32>>>()?;
    super::build(file, l.dims, affine, labels, [false; 3])
}
