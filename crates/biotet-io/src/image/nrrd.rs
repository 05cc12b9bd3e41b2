//! NRRD label images: `.nrrd` (header and data in one file) and `.nhdr` (header, data in the
//! file named by `data file`).
//!
//! Read: `dimension` 3 (or 4 with a first axis of size 1, such as a one-component `kinds`
//! axis), `sizes`, `type` (every integer type and `float`/`double`, under all their NRRD
//! spellings), `encoding` `raw`, `gzip`/`gz` or `ascii`/`text`/`txt` (`bzip2` and `hex` are
//! refused), `endian`, `byte skip` (−1: the data are the file's last bytes, raw only),
//! `line skip` (detached ascii and raw), `space directions` (one vector per axis; `none` for
//! the size-1 axis), `space origin`, `space` (`right-anterior-superior`/`RAS`,
//! `left-anterior-superior`/`LAS`, `left-posterior-superior`/`LPS`, or a `scanner-xyz`/`3D-*`
//! space taken as RAS); without `space directions`, `spacings` (default 1) on the index axes.
//! Sample `(i, j, k)` is at `origin + Σ i·dir_i`: samples are voxel centres. World space:
//! RAS+, converted from the file's `space` (LPS: x and y negated; LAS: x negated).

use std::path::Path;

use biotet::image::LabelImage;

use super::Scalar;
use crate::error::{Error, Result};

fn scalar(t: &str) -> Option<Scalar> {
    Some(match t {
        "signed char" | "int8" | "int8_t" => Scalar::I8,
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => Scalar::U8,
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
            Scalar::I16
        }
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => Scalar::U16,
        "int" | "signed int" | "int32" | "int32_t" => Scalar::I32,
        "uint" | "unsigned int" | "uint32" | "uint32_t" => Scalar::U32,
        "longlong"
        | "long long"
        | "long long int"
        | "signed long long"
        | "signed long long int"
        | "int64"
        | "int64_t" => Scalar::I64,
        "ulonglong" | "unsigned long long" | "unsigned long long int" | "uint64" | "uint64_t" => {
            Scalar::U64
        }
        "float" => Scalar::F32,
        "double" => Scalar::F64,
        _ => return None,
    })
}

/// Parse a NRRD header (and its data, attached or in `dir`) held in memory.
pub fn parse(data: &[u8], file: &str, dir: Option<&Path>) -> Result<LabelImage> {
    if !data.starts_with(b"NRRD000") {
        return Err(Error::format(file, "no 'NRRD000' magic: not a NRRD file"));
    }
    // The header ends at the first empty line (or the end of a detached header).
    let (head_len, data_at) = match find(data, b"\n\n") {
        Some(p) => (p, p + 2),
        None => match find(data, b"\r\n\r\n") {
            Some(p) => (p, p + 4),
            None => (data.len(), data.len()),
        },
    };
    let head = std::str::from_utf8(&data[..head_len])
        .map_err(|_| Error::format(file, "NRRD header is not text"))?;
    let mut fields: Vec<(String, String)> = Vec::new();
    for line in head.lines().skip(1) {
        let line = line.trim_end_matches('\r');
        if line.starts_with('#') || line.contains(":=") || line.trim().is_empty() {
            continue;
        }
        let Some((k, v)) = line.split_once(": ") else {
            return Err(Error::format(
                file,
                format!("NRRD header line '{line}' is not 'field: value'"),
            ));
        };
        fields.push((k.trim().to_ascii_lowercase(), v.trim().to_string()));
    }
    let get = |k: &str| fields.iter().find(|f| f.0 == k).map(|f| f.1.as_str());
    let need = |k: &'static str| {
        get(k).ok_or_else(|| Error::format(file, format!("NRRD header has no '{k}' field")))
    };
    let ty_name = need("type")?;
    let ty = scalar(ty_name)
        .ok_or_else(|| Error::format(file, format!("NRRD type '{ty_name}' not supported")))?;
    let ndim: usize = need("dimension")?
        .parse()
        .map_err(|_| Error::format(file, "NRRD dimension is not a whole number"))?;
    let sizes: Vec<usize> = need("sizes")?
        .split_whitespace()
        .map(|t| t.parse::<usize>().ok().filter(|&s| s > 0))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| Error::format(file, "NRRD sizes must be positive whole numbers"))?;
    if sizes.len() != ndim {
        return Err(Error::format(
            file,
            format!("NRRD dimension {ndim} but {} sizes", sizes.len()),
        ));
    }
    // The three spatial axes.
    let skip_first = match (ndim, sizes.first()) {
        (3, _) => false,
        (4, Some(1)) => true,
        _ => {
            return Err(Error::format(
                file,
                format!("NRRD of sizes {sizes:?}: a label image is one 3D volume"),
            ));
        }
    };
    let s3 = &sizes[skip_first as usize..];
    let dims = [s3[0], s3[1], s3[2]];
    let n = super::voxel_count(dims, file)?;
    let encoding = need("encoding")?.to_ascii_lowercase();
    let big = match get("endian") {
        Some("big") => true,
        Some("little") | None => false,
        Some(e) => return Err(Error::format(file, format!("NRRD endian '{e}'"))),
    };

    // Geometry.
    let mut affine = [[0.0; 4]; 3];
    if let Some(sd) = get("space directions") {
        let vecs: Vec<&str> = sd.split_whitespace().filter(|t| *t != "none").collect();
        let joined = vecs.join(" ");
        let nums = super::numbers(&joined)
            .ok_or_else(|| Error::format(file, format!("NRRD space directions '{sd}'")))?;
        if nums.len() != 9 {
            return Err(Error::format(
                file,
                format!("NRRD space directions '{sd}': expected three 3D vectors"),
            ));
        }
        for c in 0..3 {
            for r in 0..3 {
                affine[r][c] = nums[3 * c + r];
            }
        }
    } else {
        let sp = match get("spacings") {
            Some(s) => s
                .split_whitespace()
                .map(|t| t.parse::<f64>().ok())
                .collect::<Option<Vec<f64>>>()
                .filter(|v| v.len() == ndim)
                .ok_or_else(|| Error::format(file, format!("NRRD spacings '{s}'")))?,
            None => vec![1.0; ndim],
        };
        let sp = &sp[skip_first as usize..];
        for c in 0..3 {
            affine[c][c] = if sp[c].is_finite() { sp[c] } else { 1.0 };
        }
    }
    if let Some(o) = get("space origin") {
        let v = super::numbers(o)
            .filter(|v| v.len() == 3)
            .ok_or_else(|| Error::format(file, format!("NRRD space origin '{o}'")))?;
        for r in 0..3 {
            affine[r][3] = v[r];
        }
    }
    let negate = match get("space").map(|s| s.to_ascii_lowercase()) {
        Some(s) if s == "left-posterior-superior" || s == "lps" => super::LPS,
        Some(s) if s == "left-anterior-superior" || s == "las" => [true, false, false],
        Some(s)
            if s == "right-anterior-superior"
                || s == "ras"
                || s == "scanner-xyz"
                || s.starts_with("3d-") =>
        {
            [false; 3]
        }
        None => [false; 3],
        Some(s) => {
            return Err(Error::format(
                file,
                format!("NRRD space '{s}' not supported (RAS, LAS or LPS)"),
            ));
        }
    };

    // Data.
    let detached;
    let mut body: &[u8] = match get("data file").or(get("datafile")) {
        Some(name) => {
            if name.starts_with("LIST") || name.contains(' ') && name.contains('%') {
                return Err(Error::format(
                    file,
                    format!("NRRD data file '{name}': only a single data file is read"),
                ));
            }
            detached = super::read_sibling(dir, name, file)?;
            &detached
        }
        None => &data[data_at..],
    };
    let line_skip: usize = get("line skip").and_then(|s| s.parse().ok()).unwrap_or(0);
    for _ in 0..line_skip {
        match find(body, b"\n") {
            Some(p) => body = &body[p + 1..],
            None => return Err(Error::truncated(file, "NRRD line skip past the data")),
        }
    }
    let nbytes = n.saturating_mul(ty.size());
    let byte_skip: i64 = get("byte skip").and_then(|s| s.parse().ok()).unwrap_or(0);
    let inflated;
    let labels = match encoding.as_str() {
        "raw" => {
            if byte_skip == -1 {
                body = &body[body.len().saturating_sub(nbytes)..];
            } else {
                let s = usize::try_from(byte_skip)
                    .map_err(|_| Error::format(file, format!("NRRD byte skip {byte_skip}")))?;
                body = body.get(s..).unwrap_or(&[]);
            }
            super::decode(body, ty, big, n, file)?
        }
        "gzip" | "gz" => {
            inflated = super::inflate(body, false, nbytes, file)?;
            let s = usize::try_from(byte_skip.max(0)).unwrap_or(0);
            super::decode(inflated.get(s..).unwrap_or(&[]), ty, big, n, file)?
        }
        "ascii" | "text" | "txt" => {
            let text = std::str::from_utf8(body)
                .map_err(|_| Error::format(file, "NRRD ascii data is not text"))?;
            let mut out = Vec::with_capacity(n.min(body.len()));
            for (at, t) in text.split_whitespace().take(n).enumerate() {
                let x: f64 = t
                    .parse()
                    .map_err(|_| Error::format(file, format!("NRRD ascii value '{t}'")))?;
                out.push(super::float_label(x, at, file)?);
            }
            if out.len() < n {
                return Err(Error::truncated(
                    file,
                    format!("{} ascii values, {n} expected", out.len()),
                ));
            }
            out
        }
        e => {
            return Err(Error::format(
                file,
                format!("NRRD encoding '{e}' not supported (raw, gzip, ascii)"),
            ));
        }
    };
    super::build(file, dims, affine, labels, negate)
}

fn find(h: &[u8], needle: &[u8]) -> Option<usize> {
    h.windows(needle.len()).position(|w| w == needle)
}
