//! MetaImage label images (ITK): `.mha` (header and data in one file) and `.mhd` (header, data
//! in `ElementDataFile`).
//!
//! Read: `NDims` 3, `DimSize`, `ElementType` (`MET_CHAR` … `MET_ULONG_LONG`, `MET_FLOAT`,
//! `MET_DOUBLE`), `ElementNumberOfChannels` 1, `ElementSpacing` (or `ElementSize`; default 1),
//! `Offset` (or `Origin`, `Position`; default 0), `TransformMatrix` (or `Rotation`,
//! `Orientation`; default identity), `BinaryDataByteOrderMSB`/`ElementByteOrderMSB`,
//! `CompressedData` (zlib), `HeaderSize` (bytes to skip in the data; −1: the data are the
//! last bytes), and `ElementDataFile` last: `LOCAL` (data follow the header line) or a file
//! name beside the header. Lists of files are refused.
//!
//! The matrix is written as ITK writes it: column `c` (the direction of index axis `c`) is
//! numbers `3c … 3c + 2`. Voxel `(i, j, k)` is at `Offset + M · diag(spacing) · (i, j, k)`.
//! World space: ITK's LPS, converted to RAS+ (x and y negated).

use std::path::Path;

use biotet::image::LabelImage;

use super::Scalar;
use crate::error::{Error, Result};

fn scalar(t: &str) -> Option<Scalar> {
    Some(match t {
        "MET_CHAR" => Scalar::I8,
        "MET_UCHAR" => Scalar::U8,
        "MET_SHORT" => Scalar::I16,
        "MET_USHORT" => Scalar::U16,
        "MET_INT" | "MET_LONG" => Scalar::I32,
        "MET_UINT" | "MET_ULONG" => Scalar::U32,
        "MET_LONG_LONG" => Scalar::I64,
        "MET_ULONG_LONG" => Scalar::U64,
        "MET_FLOAT" => Scalar::F32,
        "MET_DOUBLE" => Scalar::F64,
        _ => return None,
    })
}

/// Parse a MetaImage header (and its data, attached or in `dir`) held in memory.
pub fn parse(data: &[u8], file: &str, dir: Option<&Path>) -> Result<LabelImage> {
    let mut fields: Vec<(String, String)> = Vec::new();
    let mut pos = 0;
    let mut data_at = None;
    while pos < data.len() {
        let end = data[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(data.len(), |e| pos + e);
        let line = std::str::from_utf8(&data[pos..end])
            .map_err(|_| Error::format(file, "MetaImage header is not text"))?
            .trim();
        pos = (end + 1).min(data.len());
        if line.is_empty() {
            continue;
        }
        let Some((k, v)) = line.split_once('=') else {
            return Err(Error::format(
                file,
                format!("MetaImage header line '{line}' is not 'Key = Value'"),
            ));
        };
        let k = k.trim().to_string();
        let last = k == "ElementDataFile";
        fields.push((k, v.trim().to_string()));
        if last {
            data_at = Some(pos);
            break;
        }
    }
    let Some(data_at) = data_at else {
        return Err(Error::format(
            file,
            "MetaImage header has no ElementDataFile",
        ));
    };
    let get = |k: &str| fields.iter().find(|f| f.0 == k).map(|f| f.1.as_str());
    let get_any = |ks: &[&str]| ks.iter().find_map(|k| get(k));
    let nums = |k: &str, v: &str, n: usize| {
        super::numbers(v).filter(|x| x.len() == n).ok_or_else(|| {
            Error::format(file, format!("MetaImage {k} '{v}': expected {n} numbers"))
        })
    };
    if let Some(o) = get("ObjectType")
        && !o.eq_ignore_ascii_case("image")
    {
        return Err(Error::format(file, format!("MetaImage ObjectType '{o}'")));
    }
    if get("NDims") != Some("3") {
        return Err(Error::format(
            file,
            format!(
                "MetaImage NDims {}: a label image is 3D",
                get("NDims").unwrap_or("missing")
            ),
        ));
    }
    if let Some(c) = get("ElementNumberOfChannels")
        && c != "1"
    {
        return Err(Error::format(
            file,
            format!("{c} channels: labels have one"),
        ));
    }
    let ds = get("DimSize").ok_or_else(|| Error::format(file, "MetaImage without DimSize"))?;
    let d: Vec<usize> = ds
        .split_whitespace()
        .map(|t| t.parse::<usize>().ok().filter(|&x| x > 0))
        .collect::<Option<Vec<_>>>()
        .filter(|v| v.len() == 3)
        .ok_or_else(|| Error::format(file, format!("MetaImage DimSize '{ds}'")))?;
    let dims = [d[0], d[1], d[2]];
    let n = super::voxel_count(dims, file)?;
    let et = get("ElementType").unwrap_or("missing");
    let ty = scalar(et).ok_or_else(|| {
        Error::format(file, format!("MetaImage ElementType '{et}' not supported"))
    })?;
    let spacing = match get_any(&["ElementSpacing", "ElementSize"]) {
        Some(v) => nums("ElementSpacing", v, 3)?,
        None => vec![1.0; 3],
    };
    let offset = match get_any(&["Offset", "Origin", "Position"]) {
        Some(v) => nums("Offset", v, 3)?,
        None => vec![0.0; 3],
    };
    let m = match get_any(&["TransformMatrix", "Rotation", "Orientation"]) {
        Some(v) => nums("TransformMatrix", v, 9)?,
        None => vec![1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
    };
    let mut affine = [[0.0; 4]; 3];
    for r in 0..3 {
        for c in 0..3 {
            affine[r][c] = m[3 * c + r] * spacing[c];
        }
        affine[r][3] = offset[r];
    }
    let yes = |v: Option<&str>| v.is_some_and(|s| s.eq_ignore_ascii_case("true"));
    let big = yes(get_any(&["BinaryDataByteOrderMSB", "ElementByteOrderMSB"]));
    let compressed = yes(get("CompressedData"));
    if get("BinaryData").is_some_and(|s| s.eq_ignore_ascii_case("false")) {
        return Err(Error::format(
            file,
            "MetaImage ascii data (BinaryData = False) not supported",
        ));
    }
    let edf = get("ElementDataFile").unwrap_or_default();
    let detached;
    let mut body: &[u8] = if edf.eq_ignore_ascii_case("LOCAL") {
        &data[data_at..]
    } else {
        if edf.starts_with("LIST") || edf.contains('%') {
            return Err(Error::format(
                file,
                format!("ElementDataFile '{edf}': only a single data file is read"),
            ));
        }
        detached = super::read_sibling(dir, edf, file)?;
        &detached
    };
    let nbytes = n.saturating_mul(ty.size());
    let skip: i64 = get("HeaderSize").and_then(|s| s.parse().ok()).unwrap_or(0);
    if skip == -1 {
        body = &body[body.len().saturating_sub(nbytes)..];
    } else if skip > 0 {
        body = body.get(skip as usize..).unwrap_or(&[]);
    }
    let inflated;
    if compressed {
        inflated = super::inflate(body, true, nbytes, file)?;
        body = &inflated;
    }
    let labels = super::decode(body, ty, big, n, file)?;
    super::build(file, dims, affine, labels, super::LPS)
}
