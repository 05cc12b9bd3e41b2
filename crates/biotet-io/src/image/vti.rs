//! VTK XML ImageData label images (`.vti`): the geometry and encodings of [`crate::grid`]'s
//! `.vti` reader (`Origin`, `Spacing`, `Direction`; ascii, base64 and raw appended data, zlib
//! compression). The active point scalars (else the first single-component point array, else
//! a cell array at the cell centres) are the labels. VTK states no anatomical space: the
//! coordinates are taken as RAS+.

use biotet::image::LabelImage;

use crate::error::Result;

/// Parse a `.vti` file held in memory.
pub fn parse(data: &[u8], file: &str) -> Result<LabelImage> {
    let g = crate::grid::parse_vti(data, file, None)?;
    let affine: [[f64; 4]; 3] = std::array::from_fn(|r| {
        let d = g.direction[r];
        [
            d[0] * g.spacing[0],
            d[1] * g.spacing[1],
            d[2] * g.spacing[2],
            g.origin[r],
        ]
    });
    let labels = g
        .values
        .iter()
        .enumerate()
        .map(|(at, &x)| super::float_label(x, at, file))
        .collect::<Result<Vec<u32>>>()?;
    super::build(file, g.dims, affine, labels, [false; 3])
}
