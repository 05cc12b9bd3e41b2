//! GIfTI surfaces (`.gii`, `.surf.gii`: what fMRIPrep, the HCP pipelines, FreeSurfer's
//! `mris_convert` and nibabel write).
//!
//! A GIfTI file is XML: `DataArray` elements, each with an `Intent`, a `DataType`, its
//! dimensions (`Dim0`, `Dim1`), `ArrayIndexingOrder`, `Encoding` and `Endian`, and its values in
//! a `Data` element. The surface is the `NIFTI_INTENT_POINTSET` array (`Dim1` = 3, float) and the
//! `NIFTI_INTENT_TRIANGLE` array (`Dim1` = 3, integer indices from 0); every other array
//! (shape, labels, time series) is skipped. Encodings: `ASCII`, `Base64Binary`,
//! `GZipBase64Binary` (zlib-compressed, as the standard specifies); `ExternalFileBinary` is
//! refused by name. Coordinates are taken as stored (the coordinate-system matrix is not
//! applied). Written with both arrays `GZipBase64Binary`, points as `float64`.

use std::io::Read;

use biotet::SurfaceMesh;

use crate::SurfaceRead;
use crate::b64;
use crate::common::{check_surface, plain_surface};
use crate::error::{Error, Result};
use crate::limits;
use crate::text::{parse_f64, parse_i64, show};
use crate::vtkxml::{Ctx, Tag, find};

/// One decoded array: its values (floats or integers) and its two dimensions.
struct Array {
    values: Vec<f64>,
    rows: usize,
    cols: usize,
}

/// Parse a GIfTI surface held in memory.
pub fn parse(data: &[u8], file: &str) -> Result<SurfaceRead> {
    let (ctx, _) = Ctx::new(data, file)?;
    let mut pos = 0;
    let mut points = None;
    let mut triangles = None;
    let mut seen_root = false;
    while let Some(tag) = ctx.next_tag(data, &mut pos)? {
        if tag.closing {
            continue;
        }
        if tag.name == b"GIFTI" {
            seen_root = true;
        }
        if tag.name != b"DataArray" {
            continue;
        }
        let intent = tag.attr("Intent").unwrap_or(b"");
        let want = match intent {
            b"NIFTI_INTENT_POINTSET" => &mut points,
            b"NIFTI_INTENT_TRIANGLE" => &mut triangles,
            _ => continue,
        };
        if want.is_some() {
            return Err(ctx.err_at(tag.start, format!("a second {} array", show(intent))));
        }
        *want = Some((array(&ctx, data, &tag, &mut pos)?, tag.start));
    }
    if !seen_root {
        return Err(Error::format(file, "not a GIfTI file (no GIFTI element)"));
    }
    let (Some((p, pat)), Some((t, tat))) = (points, triangles) else {
        return Err(Error::format(
            file,
            "a GIfTI file without a surface: it needs a NIFTI_INTENT_POINTSET and a \
             NIFTI_INTENT_TRIANGLE array (a shape, label or time-series file holds neither)",
        ));
    };
    if p.cols != 3 {
        return Err(ctx.err_at(pat, format!("points have {} columns, not 3", p.cols)));
    }
    if t.cols != 3 {
        return Err(ctx.err_at(tat, format!("triangles have {} columns, not 3", t.cols)));
    }
    let n = p.rows;
    let pts: Vec<[f64; 3]> = p
        .values
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let mut tris = Vec::with_capacity(t.rows);
    for (k, c) in t.values.chunks_exact(3).enumerate() {
        let mut tri = [0u32; 3];
        for (j, &v) in c.iter().enumerate() {
            if !(v >= 0.0 && v < n as f64 && v.fract() == 0.0) {
                return Err(ctx.err_at(
                    tat,
                    format!("triangle {k}: vertex {v} out of range (the surface has {n})"),
                ));
            }
            tri[j] = v as u32;
        }
        tris.push(tri);
    }
    plain_surface(pts, tris, file)
}

/// Write a GIfTI surface: a `NIFTI_INTENT_POINTSET` array (`float64`) and a
/// `NIFTI_INTENT_TRIANGLE` array (`int32`), both zlib-compressed base64 (side labels are not
/// stored).
pub fn write<W: std::io::Write>(mut w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    use std::io::Write;
    check_surface(mesh, file)?;
    if mesh.points.len() > i32::MAX as usize {
        return Err(Error::invalid(
            file,
            "more points than GIfTI's int32 indices hold",
        ));
    }
    let packed = |bytes: Vec<u8>| -> Result<Vec<u8>> {
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(&bytes).map_err(|e| Error::io(file, e))?;
        let mut out = Vec::new();
        b64::encode(&z.finish().map_err(|e| Error::io(file, e))?, &mut out);
        Ok(out)
    };
    let p = packed(
        mesh.points
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect(),
    )?;
    let t = packed(
        mesh.triangles
            .iter()
            .flatten()
            .flat_map(|&v| (v as i32).to_le_bytes())
            .collect(),
    )?;
    let head = |intent: &str, ty: &str, n: usize| {
        format!(
            " <DataArray Intent=\"{intent}\" DataType=\"{ty}\" ArrayIndexingOrder=\"RowMajorOrder\" \
             Dimensionality=\"2\" Dim0=\"{n}\" Dim1=\"3\" Encoding=\"GZipBase64Binary\" \
             Endian=\"LittleEndian\" ExternalFileName=\"\" ExternalFileOffset=\"\">\n  <Data>"
        )
    };
    let mut out = Vec::with_capacity(p.len() + t.len() + 1024);
    out.extend_from_slice(
        b"<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
          <!DOCTYPE GIFTI SYSTEM \"http://www.nitrc.org/frs/download.php/115/gifti.dtd\">\n\
          <GIFTI Version=\"1.0\" NumberOfDataArrays=\"2\">\n <MetaData/>\n <LabelTable/>\n",
    );
    out.extend_from_slice(
        head(
            "NIFTI_INTENT_POINTSET",
            "NIFTI_TYPE_FLOAT64",
            mesh.points.len(),
        )
        .as_bytes(),
    );
    out.extend_from_slice(&p);
    out.extend_from_slice(b"</Data>\n </DataArray>\n");
    out.extend_from_slice(
        head(
            "NIFTI_INTENT_TRIANGLE",
            "NIFTI_TYPE_INT32",
            mesh.triangles.len(),
        )
        .as_bytes(),
    );
    out.extend_from_slice(&t);
    out.extend_from_slice(b"</Data>\n </DataArray>\n</GIFTI>\n");
    w.write_all(&out).map_err(|e| Error::io(file, e))
}

/// The values of the `DataArray` whose start tag is `tag`, `pos` moved past its `Data`.
fn array(ctx: &Ctx, data: &[u8], tag: &Tag, pos: &mut usize) -> Result<Array> {
    let at = tag.start;
    let attr = |k: &str| {
        tag.attr(k)
            .ok_or_else(|| ctx.err_at(at, format!("DataArray without {k}")))
    };
    let dim = |k: &str| -> Result<usize> {
        match tag.attr(k) {
            None => Ok(1),
            Some(v) => parse_i64(v)
                .and_then(|x| usize::try_from(x).ok())
                .ok_or_else(|| ctx.err_at(at, format!("{k}=\"{}\" is not a count", show(v)))),
        }
    };
    let dims = dim("Dimensionality")?;
    if !(1..=2).contains(&dims) {
        return Err(ctx.err_at(
            at,
            format!("Dimensionality {dims}: a surface array has 1 or 2"),
        ));
    }
    let rows = dim("Dim0")?;
    let cols = if dims == 2 { dim("Dim1")? } else { 1 };
    let (size, float) = match attr("DataType")? {
        b"NIFTI_TYPE_FLOAT32" => (4, true),
        b"NIFTI_TYPE_FLOAT64" => (8, true),
        b"NIFTI_TYPE_INT32" => (4, false),
        b"NIFTI_TYPE_UINT32" => (4, false),
        b"NIFTI_TYPE_INT64" => (8, false),
        b"NIFTI_TYPE_UINT8" => (1, false),
        t => return Err(ctx.err_at(at, format!("DataType {} not read", show(t)))),
    };
    let unsigned = matches!(
        attr("DataType")?,
        b"NIFTI_TYPE_UINT32" | b"NIFTI_TYPE_UINT8"
    );
    let count = rows
        .checked_mul(cols)
        .ok_or_else(|| ctx.err_at(at, "Dim0 × Dim1 overflows"))?;
    let be = tag.attr("Endian") == Some(b"BigEndian");
    let column_major = tag.attr("ArrayIndexingOrder") == Some(b"ColumnMajorOrder");
    // The Data element's text.
    let open = loop {
        let t = ctx
            .next_tag(data, pos)?
            .ok_or_else(|| ctx.err_at(at, "DataArray without Data"))?;
        if t.name == b"Data" && !t.closing {
            break t;
        }
        if t.name == b"DataArray" && t.closing {
            return Err(ctx.err_at(at, "DataArray without Data"));
        }
    };
    let text: &[u8] = if open.self_closing {
        b""
    } else {
        let end = find(data, open.end, b"</Data>")
            .ok_or_else(|| ctx.err_at(open.start, "unterminated Data element"))?;
        *pos = end + 7;
        &data[open.end..end]
    };
    let nbytes = count
        .checked_mul(size)
        .ok_or_else(|| ctx.err_at(at, "the array's size overflows"))?;
    let mut values = match attr("Encoding")? {
        b"ASCII" => {
            // At least one byte a value: a hostile count cannot make us allocate.
            if count > text.len() / 2 + 1 {
                return Err(ctx.err_at(at, format!("{count} values announced, fewer given")));
            }
            let v: Vec<f64> = text
                .split(|c| c.is_ascii_whitespace())
                .filter(|w| !w.is_empty())
                .map(|w| {
                    parse_f64(w)
                        .ok_or_else(|| ctx.err_at(at, format!("'{}' is not a number", show(w))))
                })
                .collect::<Result<_>>()?;
            v
        }
        enc @ (b"Base64Binary" | b"GZipBase64Binary") => {
            let raw =
                b64::decode(text).ok_or_else(|| ctx.err_at(open.start, "malformed base64 data"))?;
            let bytes = if enc == b"GZipBase64Binary" {
                limits::reserve(ctx.file, "a GIfTI array", nbytes as u64)?;
                let mut out = Vec::with_capacity(nbytes.min(1 << 26));
                flate2::read::ZlibDecoder::new(&raw[..])
                    .take(nbytes as u64 + 1)
                    .read_to_end(&mut out)
                    .map_err(|e| ctx.err_at(open.start, format!("bad zlib data: {e}")))?;
                out
            } else {
                raw
            };
            if bytes.len() != nbytes {
                return Err(ctx.err_at(
                    open.start,
                    format!("{} bytes of data, {nbytes} expected", bytes.len()),
                ));
            }
            bytes
                .chunks_exact(size)
                .map(|c| decode(c, size, float, unsigned, be))
                .collect()
        }
        b"ExternalFileBinary" => {
            return Err(ctx.err_at(
                at,
                "data in an external file (ExternalFileBinary) is not read",
            ));
        }
        e => return Err(ctx.err_at(at, format!("Encoding {} not read", show(e)))),
    };
    if values.len() != count {
        return Err(ctx.err_at(
            at,
            format!("{} values, Dim0 × Dim1 = {count} announced", values.len()),
        ));
    }
    if column_major && cols > 1 {
        values = (0..count)
            .map(|i| values[(i % cols) * rows + i / cols])
            .collect();
    }
    Ok(Array { values, rows, cols })
}

/// One binary value as a float (integers below 2^53 exactly).
fn decode(c: &[u8], size: usize, float: bool, unsigned: bool, be: bool) -> f64 {
    let mut b = [0u8; 8];
    b[..size].copy_from_slice(c);
    if be {
        b[..size].reverse();
    }
    match (size, float, unsigned) {
        (4, true, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        (8, true, _) => f64::from_le_bytes(b),
        (4, false, false) => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        (4, false, true) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        (8, false, _) => i64::from_le_bytes(b) as f64,
        _ => b[0] as f64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A GIfTI file of `points` and `triangles` arrays in the given encoding.
    fn gifti(encoding: &str, p: &[f32], t: &[i32], column_major: bool) -> Vec<u8> {
        let enc = |bytes: Vec<u8>| -> String {
            let mut out = Vec::new();
            match encoding {
                "GZipBase64Binary" => {
                    use std::io::Write;
                    let mut z =
                        flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
                    z.write_all(&bytes).unwrap();
                    b64::encode(&z.finish().unwrap(), &mut out);
                }
                _ => b64::encode(&bytes, &mut out),
            }
            String::from_utf8(out).unwrap()
        };
        let (pd, td) = if encoding == "ASCII" {
            let j = |v: Vec<String>| v.join(" ");
            (
                j(p.iter().map(|x| x.to_string()).collect()),
                j(t.iter().map(|x| x.to_string()).collect()),
            )
        } else {
            (
                enc(p.iter().flat_map(|x| x.to_le_bytes()).collect()),
                enc(t.iter().flat_map(|x| x.to_le_bytes()).collect()),
            )
        };
        let order = if column_major {
            "ColumnMajorOrder"
        } else {
            "RowMajorOrder"
        };
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE GIFTI SYSTEM "http://www.nitrc.org/frs/download.php/115/gifti.dtd">
<GIFTI Version="1.0" NumberOfDataArrays="3">
 <MetaData/><LabelTable/>
 <DataArray Intent="NIFTI_INTENT_SHAPE" DataType="NIFTI_TYPE_FLOAT32" ArrayIndexingOrder="RowMajorOrder" Dimensionality="1" Dim0="2" Encoding="ASCII" Endian="LittleEndian" ExternalFileName="" ExternalFileOffset=""><Data>1 2</Data></DataArray>
 <DataArray Intent="NIFTI_INTENT_POINTSET" DataType="NIFTI_TYPE_FLOAT32" ArrayIndexingOrder="{order}" Dimensionality="2" Dim0="{}" Dim1="3" Encoding="{encoding}" Endian="LittleEndian" ExternalFileName="" ExternalFileOffset="">
  <MetaData><MD><Name><![CDATA[AnatomicalStructurePrimary]]></Name><Value><![CDATA[CortexLeft]]></Value></MD></MetaData>
  <CoordinateSystemTransformMatrix><DataSpace><![CDATA[NIFTI_XFORM_TALAIRACH]]></DataSpace><TransformedSpace><![CDATA[NIFTI_XFORM_TALAIRACH]]></TransformedSpace><MatrixData>1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</MatrixData></CoordinateSystemTransformMatrix>
  <Data>{pd}</Data>
 </DataArray>
 <DataArray Intent="NIFTI_INTENT_TRIANGLE" DataType="NIFTI_TYPE_INT32" ArrayIndexingOrder="{order}" Dimensionality="2" Dim0="{}" Dim1="3" Encoding="{encoding}" Endian="LittleEndian" ExternalFileName="" ExternalFileOffset=""><Data>{td}</Data></DataArray>
</GIFTI>
"#,
            p.len() / 3,
            t.len() / 3
        )
        .into_bytes()
    }

    fn tetra() -> (Vec<f32>, Vec<i32>) {
        (
            vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.5],
            vec![0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3],
        )
    }

    #[test]
    fn every_encoding_reads_the_same_surface() {
        let (p, t) = tetra();
        for enc in ["ASCII", "Base64Binary", "GZipBase64Binary"] {
            let r = parse(&gifti(enc, &p, &t, false), "s.surf.gii").unwrap();
            assert_eq!(r.mesh.points[3], [0.0, 0.0, 1.5], "{enc}");
            assert_eq!(r.mesh.triangles[1], [0, 1, 3], "{enc}");
        }
        // Column-major: the same arrays stored column by column.
        let cm = |v: &[f32]| -> Vec<f32> {
            (0..3)
                .flat_map(|c| v.iter().skip(c).step_by(3).copied())
                .collect()
        };
        let cmi = |v: &[i32]| -> Vec<i32> {
            (0..3)
                .flat_map(|c| v.iter().skip(c).step_by(3).copied())
                .collect()
        };
        let r = parse(&gifti("Base64Binary", &cm(&p), &cmi(&t), true), "c.gii").unwrap();
        assert_eq!(r.mesh.points[3], [0.0, 0.0, 1.5]);
        assert_eq!(r.mesh.triangles[1], [0, 1, 3]);
    }

    #[test]
    fn a_written_surface_reads_back_exactly() {
        let s = SurfaceMesh::icosphere(1.5, 1);
        let mut buf = Vec::new();
        write(&mut buf, &s, "w.surf.gii").unwrap();
        let r = parse(&buf, "w.surf.gii").unwrap();
        assert_eq!(r.mesh.points, s.points);
        assert_eq!(r.mesh.triangles, s.triangles);
    }

    #[test]
    fn files_without_a_surface_or_with_bad_arrays_are_refused_naming_the_file() {
        let (p, t) = tetra();
        let good = gifti("GZipBase64Binary", &p, &t, false);
        let text = String::from_utf8(good.clone()).unwrap();
        for (from, to, want) in [
            (
                "NIFTI_INTENT_TRIANGLE",
                "NIFTI_INTENT_LABEL",
                "without a surface",
            ),
            (
                "Encoding=\"GZipBase64Binary\"",
                "Encoding=\"ExternalFileBinary\"",
                "external",
            ),
            ("Dim0=\"4\"", "Dim0=\"400000000000\"", "s.gii"),
            ("<GIFTI ", "<NOTGIFTI ", "not a GIfTI"),
        ] {
            let bad = text.replacen(from, to, 1);
            let e = parse(bad.as_bytes(), "s.gii").unwrap_err().to_string();
            assert!(e.contains(want) && e.contains("s.gii"), "{from}: {e}");
        }
        let bad_index: Vec<i32> = t.iter().map(|&x| if x == 3 { 7 } else { x }).collect();
        let e = parse(&gifti("ASCII", &p, &bad_index, false), "s.gii")
            .unwrap_err()
            .to_string();
        assert!(e.contains("out of range"), "{e}");
        // Every truncation, and byte flips, without a panic.
        for n in (0..good.len()).step_by(7) {
            let _ = parse(&good[..n], "s.gii");
        }
        for k in (0..good.len()).step_by(3) {
            let mut b = good.clone();
            b[k] ^= 0x5A;
            let _ = parse(&b, "s.gii");
        }
    }
}
