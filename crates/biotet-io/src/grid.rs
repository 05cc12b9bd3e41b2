//! Scalar fields on regular 3D grids ([`ScalarGrid`]), such as a mesh sizing function: VTK
//! ImageData `.vti` and NIfTI `.nii`/`.nii.gz`.
//!
//! [`read_scalar_grid`] chooses the format by extension (case-insensitive): `.vti` is VTK XML
//! ImageData; `.nii` and `.nii.gz` are NIfTI-1 or NIfTI-2 single files (gzip is recognised by
//! its magic bytes, whatever the extension). The result is a validated [`ScalarGrid`]: finite
//! values, positive spacings, an invertible direction. Grids of more than
//! [`MAX_GRID_SAMPLES`] samples are refused before anything is allocated.
//!
//! # VTK ImageData (`.vti`)
//!
//! - Geometry: `WholeExtent`, `Origin` (default 0), `Spacing` (default 1) and the optional
//!   `Direction` (9 numbers, row-major; default identity) of the `ImageData` element. Point
//!   `(i, j, k)` of the extent is at `Origin + Direction · (Spacing ∘ (i, j, k))`, so an extent
//!   that does not start at 0 shifts the grid. A negative spacing (old VTK files) is turned
//!   into a positive one with the matching direction column negated; a zero spacing is an
//!   error.
//! - Data: any number of `Piece`s, each with its `Extent` inside the whole extent; together
//!   they must cover it (overlaps are fine: later pieces win). The array is the point-data
//!   array named by the `array` argument of [`read_scalar_grid_named`] if given (it may also
//!   be a cell-data array), else the point data's active scalars (the `Scalars` attribute of
//!   `PointData`), else the first single-component point-data array.
//! - Cell data: a file whose only suitable array is cell data (or when a cell-data array is
//!   named) is read as a grid of the cell values at the cell centres: one sample fewer along
//!   each axis that has more than one point, the origin moved by half a cell. Interpolation
//!   then clamps to the cell centres, half a cell inside the image's edges.
//! - Encodings: everything the `.vtu` reader reads ([`crate::vtu`]): `ascii`, inline `binary`
//!   (base64), `appended` (`raw` or `base64`), optionally `vtkZLibDataCompressor`-compressed,
//!   `UInt32` or `UInt64` headers, either byte order; number types `Int8` to `UInt64`,
//!   `Float32` and `Float64` (`UInt64` values above 2^63 are misread; they make no sense as a
//!   size anyway). LZ4 and LZMA compression are refused. The array must have one component
//!   and exactly one value per grid point (or cell).
//!
//! # NIfTI (`.nii`, `.nii.gz`)
//!
//! - NIfTI-1 (348-byte header, magic `n+1`) and NIfTI-2 (540-byte header, magic `n+2`),
//!   either byte order (detected from `sizeof_hdr`), gzip-compressed or not. Header/image
//!   pairs (`.hdr`/`.img`, magic `ni1`/`ni2`) and Analyze 7.5 files are refused.
//! - Dimensions `dim[1..=3]`; missing ones (`dim[0]` < 3) are 1. Further dimensions must all
//!   be 1 (a time series or a vector field is refused).
//! - Voxel types: `uint8`, `int8`, `int16`, `uint16`, `int32`, `uint32`, `int64`, `uint64`,
//!   `float32`, `float64`; complex, RGB, binary and `float128` are refused.
//! - Scaling: `value = scl_slope · stored + scl_inter` when `scl_slope` is finite and non-zero
//!   (a non-finite `scl_inter` counts as 0), as nibabel does; otherwise stored values as they
//!   are.
//! - World mapping, in NIfTI's order of preference: the sform (`srow_x/y/z`) when
//!   `sform_code` > 0; else the qform (quaternion `b, c, d`, `qoffset`, `pixdim[1..=3]` and
//!   `qfac = pixdim[0]`, -1 flipping the third axis) when `qform_code` > 0; else
//!   `diag(pixdim[1..=3])` with the origin at 0. The affine's columns give the spacings (their
//!   lengths) and the direction (the normalised columns). Voxel sizes used by the qform must be
//!   finite and positive (as nibabel requires); the fallback accepts negative ones (flipping
//!   their axis) but not zero.
//! - Coordinates are taken as they are: NIfTI world space is RAS+ (x to the right, y to the
//!   front), usually in millimetres (`xyzt_units` is not applied). A surface in LPS
//!   coordinates (DICOM, ITK) needs x and y negated to match.

use std::io::Read;
use std::path::Path;

use biotet::sizing_grid::{IDENTITY, ScalarGrid};

use crate::error::{Error, Result};
use crate::text::{parse_f64, parse_i64, show};
use crate::vtkxml::{ArrayRef, Ctx, Tag, Values};

/// Supported scalar grid extensions, for messages.
pub const GRID_EXTENSIONS: &str = ".vti, .nii, .nii.gz";

/// The most samples a grid file may have (2^30, a 1024³ image: 8 GiB of `f64`). Larger headers
/// are refused as corrupt before anything is allocated.
pub const MAX_GRID_SAMPLES: usize = 1 << 30;

/// Scalar grid file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GridFormat {
    /// VTK XML ImageData `.vti`.
    Vti,
    /// NIfTI-1 or NIfTI-2 `.nii`, optionally gzipped (`.nii.gz`).
    Nifti,
}

impl GridFormat {
    /// The format named by a path's extension (`.vti`, `.nii`, `.nii.gz`; case-insensitive).
    pub fn from_path(path: &Path) -> Result<GridFormat> {
        let file_name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if file_name.ends_with(".vti") {
            Ok(GridFormat::Vti)
        } else if file_name.ends_with(".nii") || file_name.ends_with(".nii.gz") {
            Ok(GridFormat::Nifti)
        } else {
            Err(Error::UnknownExtension {
                path: crate::name(path),
                kind: "scalar grid",
                supported: GRID_EXTENSIONS,
            })
        }
    }
}

/// Read a scalar grid, choosing the format by extension; for `.vti`, the array is chosen as
/// described in the [module documentation](self).
pub fn read_scalar_grid(path: &Path) -> Result<ScalarGrid> {
    read_scalar_grid_named(path, None)
}

/// Read a scalar grid, choosing the format by extension; `array` names the `.vti` data array
/// to read (point or cell data). NIfTI files hold a single unnamed volume: naming an array for
/// one is an error.
pub fn read_scalar_grid_named(path: &Path, array: Option<&str>) -> Result<ScalarGrid> {
    let format = GridFormat::from_path(path)?;
    let data = crate::atomic::read_file(path)?;
    let n = crate::name(path);
    match format {
        GridFormat::Vti => parse_vti(&data, &n, array),
        GridFormat::Nifti => {
            if let Some(a) = array {
                return Err(Error::format(
                    &n,
                    format!(
                        "array '{a}' requested, but a NIfTI file holds a single unnamed volume"
                    ),
                ));
            }
            parse_nifti(&data, &n)
        }
    }
}

/// A grid from raw geometry as files give it: a negative spacing becomes positive with its
/// direction column negated; validation errors become format errors naming the file.
fn build(
    file: &str,
    dims: [usize; 3],
    origin: [f64; 3],
    mut spacing: [f64; 3],
    mut direction: [[f64; 3]; 3],
    values: Vec<f64>,
) -> Result<ScalarGrid> {
    for (c, s) in spacing.iter_mut().enumerate() {
        if *s < 0.0 {
            *s = -*s;
            for row in direction.iter_mut() {
                row[c] = -row[c];
            }
        }
    }
    ScalarGrid::new(dims, origin, spacing, direction, values)
        .map_err(|e| Error::format(file, e.to_string()))
}

/// `dims[0]·dims[1]·dims[2]`, refused above [`MAX_GRID_SAMPLES`] or when its values (`f64`)
/// exceed the memory budget ([`crate::limits`]).
pub(crate) fn sample_count(dims: [usize; 3], file: &str) -> Result<usize> {
    let n = checked_samples(dims, file)?;
    crate::limits::reserve(
        file,
        &format!("a grid of {}", dims_text(dims)),
        n as u64 * 8,
    )?;
    Ok(n)
}

fn checked_samples(dims: [usize; 3], file: &str) -> Result<usize> {
    dims[0]
        .checked_mul(dims[1])
        .and_then(|x| x.checked_mul(dims[2]))
        .filter(|&n| n <= MAX_GRID_SAMPLES)
        .ok_or_else(|| {
            Error::format(
                file,
                format!(
                    "grid of {}×{}×{} samples: more than the {MAX_GRID_SAMPLES} supported",
                    dims[0], dims[1], dims[2]
                ),
            )
        })
}

fn dims_text(d: [usize; 3]) -> String {
    format!("{}×{}×{}", d[0], d[1], d[2])
}

// ---------------------------------------------------------------------------------------------
// VTK ImageData.

/// Numbers of an attribute: exactly `N` of them, or an error naming the element and attribute.
fn attr_nums<const N: usize, T: Copy + Default>(
    ctx: &Ctx,
    tag: &Tag,
    key: &str,
    parse: fn(&[u8]) -> Option<T>,
    what: &str,
) -> Result<Option<[T; N]>> {
    let Some(v) = tag.attr(key) else {
        return Ok(None);
    };
    let toks: Vec<&[u8]> = v
        .split(|c| c.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
        .collect();
    let bad = || {
        ctx.err_at(
            tag.start,
            format!(
                "{} {key} '{}': expected {N} {what}",
                show(tag.name),
                show(v)
            ),
        )
    };
    if toks.len() != N {
        return Err(bad());
    }
    let mut out = [T::default(); N];
    for (o, t) in out.iter_mut().zip(toks) {
        *o = parse(t).ok_or_else(bad)?;
    }
    Ok(Some(out))
}

/// An extent `[x0, x1, y0, y1, z0, z1]` → per-axis (first index, number of points).
fn extent_dims(e: [i64; 6]) -> Option<[(i64, usize); 3]> {
    let mut out = [(0, 0); 3];
    for a in 0..3 {
        let (lo, hi) = (e[2 * a], e[2 * a + 1]);
        if hi < lo {
            return None;
        }
        let n = usize::try_from((hi as i128 - lo as i128 + 1).min(usize::MAX as i128)).ok()?;
        out[a] = (lo, n);
    }
    Some(out)
}

struct VtiPiece<'a> {
    extent: [(i64, usize); 3],
    /// The PointData's `Scalars` attribute.
    scalars: Option<&'a [u8]>,
    point_data: Vec<ArrayRef<'a>>,
    cell_data: Vec<ArrayRef<'a>>,
    /// Byte position of the Piece tag.
    at: usize,
}

/// Parse a VTK XML ImageData file held in memory; `array` names the data array to read (see
/// the [module documentation](self) for the default choice).
pub fn parse_vti(data: &[u8], file: &str, array: Option<&str>) -> Result<ScalarGrid> {
    let (mut ctx, xml_end) = Ctx::new(data, file)?;
    let xml = &data[..xml_end];
    let mut pos = 0;
    let mut seen_root = false;
    let mut whole: Option<([(i64, usize); 3], usize)> = None;
    let mut origin = [0.0; 3];
    let mut spacing = [1.0; 3];
    let mut direction = IDENTITY;
    let mut pieces: Vec<VtiPiece> = Vec::new();
    let mut in_piece = false;
    let mut section: &[u8] = b"";
    let f64s = |t: &[u8]| parse_f64(t).filter(|x| x.is_finite());
    while let Some(tag) = ctx.next_tag(xml, &mut pos)? {
        match tag.name {
            b"VTKFile" if !tag.closing => {
                seen_root = true;
                ctx.root(&tag, "ImageData", ".vti")?;
            }
            b"ImageData" if !tag.closing => {
                if !seen_root {
                    return Err(ctx.err_at(tag.start, "ImageData outside VTKFile"));
                }
                let e = attr_nums::<6, i64>(&ctx, &tag, "WholeExtent", parse_i64, "integers")?
                    .ok_or_else(|| ctx.err_at(tag.start, "ImageData without a WholeExtent"))?;
                let ext = extent_dims(e).ok_or_else(|| {
                    ctx.err_at(
                        tag.start,
                        format!("empty WholeExtent {e:?}: the image has no points"),
                    )
                })?;
                whole = Some((ext, tag.start));
                if let Some(o) = attr_nums::<3, f64>(&ctx, &tag, "Origin", f64s, "finite numbers")?
                {
                    origin = o;
                }
                if let Some(s) = attr_nums::<3, f64>(&ctx, &tag, "Spacing", f64s, "finite numbers")?
                {
                    spacing = s;
                }
                if let Some(d) =
                    attr_nums::<9, f64>(&ctx, &tag, "Direction", f64s, "finite numbers")?
                {
                    direction = [[d[0], d[1], d[2]], [d[3], d[4], d[5]], [d[6], d[7], d[8]]];
                }
            }
            b"Piece" if !tag.closing => {
                if whole.is_none() {
                    return Err(ctx.err_at(tag.start, "Piece outside ImageData"));
                }
                let e = attr_nums::<6, i64>(&ctx, &tag, "Extent", parse_i64, "integers")?
                    .ok_or_else(|| ctx.err_at(tag.start, "Piece without an Extent"))?;
                // An empty piece (VTK writes "0 -1 0 -1 0 -1") holds nothing.
                let Some(extent) = extent_dims(e) else {
                    continue;
                };
                pieces.push(VtiPiece {
                    extent,
                    scalars: None,
                    point_data: Vec::new(),
                    cell_data: Vec::new(),
                    at: tag.start,
                });
                in_piece = !tag.self_closing;
            }
            b"Piece" => in_piece = false,
            b"PointData" | b"CellData" | b"FieldData" => {
                section = if tag.closing || tag.self_closing {
                    b""
                } else {
                    tag.name
                };
                if tag.name == b"PointData"
                    && !tag.closing
                    && in_piece
                    && let Some(p) = pieces.last_mut()
                {
                    p.scalars = tag.attr("Scalars");
                }
            }
            b"DataArray" if !tag.closing => {
                let a = ctx.data_array(&tag, xml, &mut pos)?;
                if let (true, Some(p)) = (in_piece, pieces.last_mut()) {
                    match section {
                        b"PointData" => p.point_data.push(a),
                        b"CellData" => p.cell_data.push(a),
                        _ => {}
                    }
                }
            }
            _ => {}
        }
    }
    if !seen_root {
        return Err(Error::format(
            file,
            "no VTKFile element: not a VTK XML file",
        ));
    }
    ctx.end_of_xml();
    let Some((whole, whole_at)) = whole else {
        return Err(Error::format(file, "no ImageData element"));
    };
    let Some(first) = pieces.first() else {
        return Err(Error::format(
            file,
            "no non-empty Piece: the image holds no data",
        ));
    };

    // Choose the array (by name and section) in the first piece.
    let single = |v: &[ArrayRef]| v.iter().position(|a| a.ncomp == 1);
    let (cells, name): (bool, &[u8]) = if let Some(want) = array {
        let w = want.as_bytes();
        if first.point_data.iter().any(|a| a.name == w) {
            (false, w)
        } else if first.cell_data.iter().any(|a| a.name == w) {
            (true, w)
        } else {
            let names: Vec<String> = first
                .point_data
                .iter()
                .map(|a| format!("'{}' (point data)", show(a.name)))
                .chain(
                    first
                        .cell_data
                        .iter()
                        .map(|a| format!("'{}' (cell data)", show(a.name))),
                )
                .collect();
            return Err(Error::format(
                file,
                format!(
                    "no data array named '{want}'; the file has {}",
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                ),
            ));
        }
    } else if let Some(s) = first
        .scalars
        .filter(|s| first.point_data.iter().any(|a| a.name == *s))
    {
        (false, s)
    } else if let Some(i) = single(&first.point_data) {
        (false, first.point_data[i].name)
    } else if let Some(i) = single(&first.cell_data) {
        (true, first.cell_data[i].name)
    } else if first.point_data.is_empty() && first.cell_data.is_empty() {
        return Err(Error::format(file, "no PointData or CellData array"));
    } else {
        return Err(Error::format(
            file,
            "no single-component data array (a scalar grid needs one value per point)",
        ));
    };
    let shown = show(name);
    let data_kind = if cells { "cell" } else { "point" };

    // Grid of points, or of cell centres.
    let cdim = |n: usize| if n > 1 { n - 1 } else { 1 };
    let dims: [usize; 3] = std::array::from_fn(|a| {
        let n = whole[a].1;
        if cells { cdim(n) } else { n }
    });
    let total = sample_count(dims, file)?;
    let first_index: [f64; 3] = std::array::from_fn(|a| {
        let half = if cells && whole[a].1 > 1 { 0.5 } else { 0.0 };
        whole[a].0 as f64 + half
    });
    let grid_origin: [f64; 3] = std::array::from_fn(|r| {
        origin[r]
            + (0..3)
                .map(|c| direction[r][c] * spacing[c] * first_index[c])
                .sum::<f64>()
    });

    // Decode every piece first: the grid is allocated only once the data it needs exists (a
    // tiny file announcing a huge extent fails before that).
    let mut decoded: Vec<([usize; 3], [usize; 3], Vec<f64>)> = Vec::with_capacity(pieces.len());
    for (pi, p) in pieces.iter().enumerate() {
        let list = if cells { &p.cell_data } else { &p.point_data };
        let Some(a) = list.iter().find(|a| a.name == name) else {
            return Err(Error::format(
                file,
                format!("piece {pi} has no {data_kind}-data array '{shown}'"),
            ));
        };
        if a.ncomp != 1 {
            return Err(ctx.err_at(
                a.at,
                format!(
                    "DataArray '{shown}' has {} components; a scalar grid needs 1",
                    a.ncomp
                ),
            ));
        }
        // The piece's place in the grid.
        let mut start = [0usize; 3];
        let mut pdims = [0usize; 3];
        for ax in 0..3 {
            let (lo, n) = p.extent[ax];
            let (wlo, wn) = whole[ax];
            let off = lo as i128 - wlo as i128;
            if off < 0 || off + n as i128 > wn as i128 {
                return Err(ctx.err_at(
                    p.at,
                    format!("piece {pi}: Extent is not inside the WholeExtent (axis {ax})"),
                ));
            }
            start[ax] = off as usize;
            pdims[ax] = n;
            if cells {
                if (n == 1) != (wn == 1) {
                    return Err(ctx.err_at(
                        p.at,
                        format!(
                            "piece {pi}: Extent is flat along axis {ax} but the image is not \
                             (or the reverse): its cells do not match the image's"
                        ),
                    ));
                }
                pdims[ax] = cdim(n);
            }
        }
        let expected = pdims[0] * pdims[1] * pdims[2];
        let got = ctx.values(a, None)?;
        if got.len() != expected {
            return Err(Error::format(
                file,
                format!(
                    "DataArray '{shown}' has {} values, expected {expected} = {}{}",
                    got.len(),
                    dims_text(pdims),
                    if cells { " cells" } else { "" }
                ),
            ));
        }
        let got = match got {
            Values::F(v) => v,
            Values::I(v) => v.into_iter().map(|x| x as f64).collect(),
        };
        decoded.push((start, pdims, got));
    }
    if let [(_, pdims, _)] = decoded.as_slice()
        && *pdims == dims
    {
        let values = decoded.pop().expect("one piece").2;
        return build(file, dims, grid_origin, spacing, direction, values);
    }
    let supplied = decoded.iter().map(|d| d.2.len()).sum::<usize>();
    if supplied < total {
        return Err(ctx.err_at(
            whole_at,
            format!(
                "the pieces do not cover the WholeExtent: {supplied} {data_kind} values for \
                 {total} = {} {data_kind}s",
                dims_text(dims)
            ),
        ));
    }
    let mut values = vec![0.0f64; total];
    let mut covered = vec![false; values.len()];
    for (start, pdims, got) in &decoded {
        let mut src = got.iter();
        for k in 0..pdims[2] {
            for j in 0..pdims[1] {
                let row = start[0] + dims[0] * (start[1] + j + dims[1] * (start[2] + k));
                for (v, c) in values[row..row + pdims[0]]
                    .iter_mut()
                    .zip(&mut covered[row..row + pdims[0]])
                {
                    *v = *src.next().expect("count checked");
                    *c = true;
                }
            }
        }
    }
    if let Some(missing) = covered.iter().position(|&c| !c) {
        let ijk = [
            missing % dims[0],
            missing / dims[0] % dims[1],
            missing / dims[0] / dims[1],
        ];
        return Err(ctx.err_at(
            whole_at,
            format!("the pieces do not cover the WholeExtent: {data_kind} {ijk:?} has no value"),
        ));
    }
    build(file, dims, grid_origin, spacing, direction, values)
}

// ---------------------------------------------------------------------------------------------
// NIfTI.

/// The NIfTI header fields that matter here, from either version.
pub(crate) struct NiftiHeader {
    dim: [i64; 8],
    datatype: i16,
    pixdim: [f64; 8],
    vox_offset: f64,
    scl_slope: f64,
    scl_inter: f64,
    pub(crate) qform_code: i32,
    pub(crate) sform_code: i32,
    quatern: [f64; 3],
    qoffset: [f64; 3],
    srow: [[f64; 4]; 3],
    /// Header size (348 or 540).
    size: usize,
    be: bool,
}

/// Fixed-offset field access with a byte order.
struct Fields<'a> {
    b: &'a [u8],
    be: bool,
}

impl Fields<'_> {
    fn bytes<const N: usize>(&self, at: usize) -> [u8; N] {
        let mut x: [u8; N] = self.b[at..at + N].try_into().expect("N bytes");
        if self.be {
            x.reverse();
        }
        x
    }
    fn i16(&self, at: usize) -> i16 {
        i16::from_le_bytes(self.bytes(at))
    }
    fn i32(&self, at: usize) -> i32 {
        i32::from_le_bytes(self.bytes(at))
    }
    fn i64(&self, at: usize) -> i64 {
        i64::from_le_bytes(self.bytes(at))
    }
    fn f32(&self, at: usize) -> f64 {
        f32::from_le_bytes(self.bytes(at)) as f64
    }
    fn f64(&self, at: usize) -> f64 {
        f64::from_le_bytes(self.bytes(at))
    }
}

/// Parse a NIfTI-1 or NIfTI-2 header from the first bytes of a file.
pub(crate) fn nifti_header(h: &[u8], file: &str) -> Result<NiftiHeader> {
    if h.len() < 4 {
        return Err(Error::truncated(
            file,
            format!("{} bytes: not even a NIfTI header size", h.len()),
        ));
    }
    let sz = [h[0], h[1], h[2], h[3]];
    let (size, be) = match (i32::from_le_bytes(sz), i32::from_be_bytes(sz)) {
        (348, _) => (348, false),
        (_, 348) => (348, true),
        (540, _) => (540, false),
        (_, 540) => (540, true),
        (n, _) => {
            return Err(Error::format(
                file,
                format!("header size {n}: not a NIfTI-1 (348) or NIfTI-2 (540) file"),
            ));
        }
    };
    if h.len() < size {
        return Err(Error::truncated(
            file,
            format!(
                "{} bytes, shorter than the {size}-byte NIfTI header",
                h.len()
            ),
        ));
    }
    let f = Fields { b: h, be };
    if size == 348 {
        let magic = &h[344..348];
        match magic {
            b"n+1\0" => {}
            b"ni1\0" => {
                return Err(Error::format(
                    file,
                    "NIfTI-1 header of a .hdr/.img pair (magic 'ni1'): only single-file .nii is read",
                ));
            }
            _ => {
                return Err(Error::format(
                    file,
                    format!(
                        "NIfTI magic '{}' is not 'n+1' (an Analyze 7.5 file?)",
                        show(magic).trim_end_matches('\0')
                    ),
                ));
            }
        }
        Ok(NiftiHeader {
            dim: std::array::from_fn(|i| f.i16(40 + 2 * i) as i64),
            datatype: f.i16(70),
            pixdim: std::array::from_fn(|i| f.f32(76 + 4 * i)),
            vox_offset: f.f32(108),
            scl_slope: f.f32(112),
            scl_inter: f.f32(116),
            qform_code: f.i16(252) as i32,
            sform_code: f.i16(254) as i32,
            quatern: std::array::from_fn(|i| f.f32(256 + 4 * i)),
            qoffset: std::array::from_fn(|i| f.f32(268 + 4 * i)),
            srow: std::array::from_fn(|r| std::array::from_fn(|c| f.f32(280 + 16 * r + 4 * c))),
            size,
            be,
        })
    } else {
        let magic = &h[4..12];
        if &magic[..4] == b"ni2\0" {
            return Err(Error::format(
                file,
                "NIfTI-2 header of a .hdr/.img pair (magic 'ni2'): only single-file .nii is read",
            ));
        }
        if &magic[..4] != b"n+2\0" {
            return Err(Error::format(
                file,
                format!(
                    "NIfTI-2 magic '{}' is not 'n+2'",
                    show(&magic[..3]).trim_end_matches('\0')
                ),
            ));
        }
        Ok(NiftiHeader {
            dim: std::array::from_fn(|i| f.i64(16 + 8 * i)),
            datatype: f.i16(12),
            pixdim: std::array::from_fn(|i| f.f64(104 + 8 * i)),
            vox_offset: f.i64(168) as f64,
            scl_slope: f.f64(176),
            scl_inter: f.f64(184),
            qform_code: f.i32(344),
            sform_code: f.i32(348),
            quatern: std::array::from_fn(|i| f.f64(352 + 8 * i)),
            qoffset: std::array::from_fn(|i| f.f64(376 + 8 * i)),
            srow: std::array::from_fn(|r| std::array::from_fn(|c| f.f64(400 + 32 * r + 8 * c))),
            size,
            be,
        })
    }
}

/// NIfTI voxel types read: (name, bytes per voxel).
fn nifti_type(code: i16) -> std::result::Result<(&'static str, usize), &'static str> {
    Ok(match code {
        2 => ("uint8", 1),
        4 => ("int16", 2),
        8 => ("int32", 4),
        16 => ("float32", 4),
        64 => ("float64", 8),
        256 => ("int8", 1),
        512 => ("uint16", 2),
        768 => ("uint32", 4),
        1024 => ("int64", 8),
        1280 => ("uint64", 8),
        1 => return Err("binary (1 bit)"),
        32 => return Err("complex64"),
        128 => return Err("RGB24"),
        1536 => return Err("float128"),
        1792 => return Err("complex128"),
        2048 => return Err("complex256"),
        2304 => return Err("RGBA32"),
        _ => return Err("unknown"),
    })
}

/// What the header says about the voxels: grid dims, type, and where the data is.
pub(crate) struct NiftiLayout {
    pub(crate) dims: [usize; 3],
    pub(crate) ty: (&'static str, usize),
    pub(crate) offset: usize,
    pub(crate) nbytes: usize,
}

pub(crate) fn nifti_layout(h: &NiftiHeader, file: &str) -> Result<NiftiLayout> {
    let nd = h.dim[0];
    if !(1..=7).contains(&nd) {
        return Err(Error::format(
            file,
            format!("dim[0] = {nd}: the number of dimensions must be 1 to 7"),
        ));
    }
    let nd = nd as usize;
    let mut dims = [1usize; 3];
    for i in 1..=nd {
        let d = h.dim[i];
        if d < 1 {
            return Err(Error::format(
                file,
                format!("dim[{i}] = {d}: dimensions must be at least 1"),
            ));
        }
        if i <= 3 {
            dims[i - 1] = usize::try_from(d).unwrap_or(usize::MAX);
        } else if d != 1 {
            return Err(Error::format(
                file,
                format!(
                    "{nd}D image with dim[{i}] = {d} (dim = {:?}): a scalar grid needs a single 3D \
                     volume",
                    &h.dim[1..=nd]
                ),
            ));
        }
    }
    let ty = nifti_type(h.datatype).map_err(|what| {
        Error::format(
            file,
            format!(
                "datatype {} ({what}) is not supported: uint8, int8, int16, uint16, int32, \
                 uint32, int64, uint64, float32 or float64",
                h.datatype
            ),
        )
    })?;
    let n = sample_count(dims, file)?;
    let v = h.vox_offset;
    if !(v.is_finite() && v.fract() == 0.0 && v >= h.size as f64 && v <= u32::MAX as f64) {
        return Err(Error::format(
            file,
            format!(
                "vox_offset {v}: the data must start at a whole byte at or after the {}-byte header",
                h.size
            ),
        ));
    }
    let offset = v as usize;
    let nbytes = n
        .checked_mul(ty.1)
        .filter(|b| b.checked_add(offset).is_some())
        .ok_or_else(|| Error::format(file, "image too large for this platform"))?;
    Ok(NiftiLayout {
        dims,
        ty,
        offset,
        nbytes,
    })
}

/// The affine (3×4, voxel → world) the header describes.
pub(crate) fn nifti_affine(h: &NiftiHeader, file: &str) -> Result<[[f64; 4]; 3]> {
    if h.sform_code > 0 {
        return Ok(h.srow);
    }
    let qform = h.qform_code > 0;
    let mut zoom = [0.0; 3];
    for (a, zo) in zoom.iter_mut().enumerate() {
        let z = h.pixdim[a + 1];
        // The qform needs positive voxel sizes (nibabel refuses negative ones too); the
        // fallback flips an axis with a negative size.
        if !(z.is_finite() && (z > 0.0 || (z < 0.0 && !qform))) {
            return Err(Error::format(
                file,
                format!(
                    "pixdim[{}] = {z}: the voxel size must be finite and {} (no sform to give \
                     the geometry)",
                    a + 1,
                    if qform { "positive" } else { "non-zero" }
                ),
            ));
        }
        *zo = z;
    }
    if qform {
        // nifti_quatern_to_mat44 from nifti1_io.c.
        let [mut b, mut c, mut d] = h.quatern;
        let mut a = 1.0 - (b * b + c * c + d * d);
        if a < 1e-7 {
            let s = 1.0 / (b * b + c * c + d * d).sqrt();
            b *= s;
            c *= s;
            d *= s;
            a = 0.0;
        } else {
            a = a.sqrt();
        }
        let r = [
            [
                a * a + b * b - c * c - d * d,
                2.0 * (b * c - a * d),
                2.0 * (b * d + a * c),
            ],
            [
                2.0 * (b * c + a * d),
                a * a + c * c - b * b - d * d,
                2.0 * (c * d - a * b),
            ],
            [
                2.0 * (b * d - a * c),
                2.0 * (c * d + a * b),
                a * a + d * d - c * c - b * b,
            ],
        ];
        // qfac = pixdim[0]: -1 flips the third axis (0 counts as 1, as in nifti1_io.c).
        if h.pixdim[0] < 0.0 {
            zoom[2] = -zoom[2];
        }
        return Ok(std::array::from_fn(|row| {
            [
                r[row][0] * zoom[0],
                r[row][1] * zoom[1],
                r[row][2] * zoom[2],
                h.qoffset[row],
            ]
        }));
    }
    Ok([
        [zoom[0], 0.0, 0.0, 0.0],
        [0.0, zoom[1], 0.0, 0.0],
        [0.0, 0.0, zoom[2], 0.0],
    ])
}

/// The voxel values, scaled.
pub(crate) fn nifti_values(h: &NiftiHeader, l: &NiftiLayout, bytes: &[u8]) -> Vec<f64> {
    let size = l.ty.1;
    let (slope, inter) = if h.scl_slope.is_finite() && h.scl_slope != 0.0 {
        let i = if h.scl_inter.is_finite() {
            h.scl_inter
        } else {
            0.0
        };
        (h.scl_slope, i)
    } else {
        (1.0, 0.0)
    };
    let f = Fields { b: bytes, be: h.be };
    let read = |i: usize| -> f64 {
        let at = i * size;
        match h.datatype {
            2 => bytes[at] as f64,
            256 => bytes[at] as i8 as f64,
            4 => f.i16(at) as f64,
            512 => u16::from_le_bytes(f.bytes(at)) as f64,
            8 => f.i32(at) as f64,
            768 => u32::from_le_bytes(f.bytes(at)) as f64,
            1024 => f.i64(at) as f64,
            1280 => u64::from_le_bytes(f.bytes(at)) as f64,
            16 => f.f32(at),
            _ => f.f64(at),
        }
    };
    let n = l.nbytes / size;
    if (slope, inter) == (1.0, 0.0) {
        (0..n).map(read).collect()
    } else {
        (0..n).map(|i| slope * read(i) + inter).collect()
    }
}

/// A NIfTI-1 or NIfTI-2 single file (`.nii`) held in memory, gzip-compressed or not (detected
/// by the gzip magic bytes): its header, layout and voxel values (scaled), the voxel data
/// checked to be all there. Shared by the size-field and label-image readers.
pub(crate) fn nifti_voxels(
    data: &[u8],
    file: &str,
) -> Result<(NiftiHeader, NiftiLayout, Vec<f64>)> {
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
                "header announces {} {} voxels ({} bytes) from byte {}, the file has {} bytes",
                dims_text(l.dims),
                l.ty.0,
                l.nbytes,
                l.offset,
                data.len()
            ),
        ));
    }
    let values = nifti_values(&h, &l, &data[l.offset..end]);
    Ok((h, l, values))
}

/// Parse a NIfTI-1 or NIfTI-2 single file (`.nii`) held in memory, gzip-compressed or not
/// (detected by the gzip magic bytes).
pub fn parse_nifti(data: &[u8], file: &str) -> Result<ScalarGrid> {
    let (h, l, values) = nifti_voxels(data, file)?;
    let a = nifti_affine(&h, file)?;
    let mut spacing = [0.0; 3];
    let mut direction = [[0.0; 3]; 3];
    for c in 0..3 {
        let norm = (0..3).map(|r| a[r][c] * a[r][c]).sum::<f64>().sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(Error::format(
                file,
                format!(
                    "{} column {c} is {}: voxel axes must have a finite non-zero length",
                    if h.sform_code > 0 { "sform" } else { "qform" },
                    if norm == 0.0 { "zero" } else { "not finite" }
                ),
            ));
        }
        spacing[c] = norm;
        for r in 0..3 {
            direction[r][c] = a[r][c] / norm;
        }
    }
    let origin = [a[0][3], a[1][3], a[2][3]];
    build(file, l.dims, origin, spacing, direction, values)
}

/// Decompress a gzipped NIfTI file: the header first, then exactly the bytes it announces (so
/// a lying header or a compression bomb cannot make us allocate more than the data needs).
pub(crate) fn gunzip_nifti(data: &[u8], file: &str) -> Result<Vec<u8>> {
    let gz_err = |e: std::io::Error| Error::format(file, format!("gzip: {e}"));
    let mut dec = flate2::read::MultiGzDecoder::new(data);
    let mut out = Vec::new();
    (&mut dec).take(540).read_to_end(&mut out).map_err(gz_err)?;
    let h = nifti_header(&out, file)?;
    let l = nifti_layout(&h, file)?;
    let end = (l.offset + l.nbytes) as u64;
    out.reserve(((end as usize).saturating_sub(out.len())).min(data.len().saturating_mul(1100)));
    (&mut dec)
        .take(end.saturating_sub(out.len() as u64))
        .read_to_end(&mut out)
        .map_err(gz_err)?;
    Ok(out)
}
