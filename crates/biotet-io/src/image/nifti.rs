//! NIfTI-1 and NIfTI-2 label images (`.nii`, `.nii.gz`): the header, voxel types, scaling and
//! world mapping of [`crate::grid`]'s NIfTI reader (sform if `sform_code` > 0, else qform if
//! `qform_code` > 0, else `diag(pixdim)`; `value = scl_slope · stored + scl_inter` when
//! `scl_slope` is finite and non-zero). World space: RAS+, as the file gives it.

use biotet::image::LabelImage;

use crate::error::Result;
use crate::grid::{nifti_affine, nifti_voxels};

/// Parse a NIfTI file held in memory (gzip recognised by its magic bytes).
pub fn parse(data: &[u8], file: &str) -> Result<LabelImage> {
    let (h, l, values) = nifti_voxels(data, file)?;
    let affine = nifti_affine(&h, file)?;
    let labels = values
        .iter()
        .enumerate()
        .map(|(at, &x)| super::float_label(x, at, file))
        .collect::<Result<Vec<u32>>>()?;
    super::build(file, l.dims, affine, labels, [false; 3])
}
