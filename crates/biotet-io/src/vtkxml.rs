//! The VTK XML file structure shared by the `.vtu` and `.vti` readers: a minimal XML tag
//! scanner, the `VTKFile` attributes (byte order, header type, compressor), and the decoding of
//! `DataArray`s in every format VTK writes (ascii, inline base64, appended raw or base64, with
//! or without zlib compression).

use std::io::Read;

use crate::b64;
use crate::error::{Error, Result};
use crate::text::{parse_f64, parse_i64, show};

/// A `DataArray`'s number type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Ty {
    pub(crate) fn parse(s: &[u8]) -> Option<Ty> {
        Some(match s {
            b"Int8" | b"Char" => Ty::I8,
            b"UInt8" | b"UChar" => Ty::U8,
            b"Int16" => Ty::I16,
            b"UInt16" => Ty::U16,
            b"Int32" => Ty::I32,
            b"UInt32" => Ty::U32,
            b"Int64" => Ty::I64,
            b"UInt64" => Ty::U64,
            b"Float32" => Ty::F32,
            b"Float64" => Ty::F64,
            _ => return None,
        })
    }

    pub(crate) fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::I64 | Ty::U64 | Ty::F64 => 8,
        }
    }

    pub(crate) fn is_float(self) -> bool {
        matches!(self, Ty::F32 | Ty::F64)
    }
}

/// Decoded array values: floats, or integers kept exact.
pub(crate) enum Values {
    F(Vec<f64>),
    I(Vec<i64>),
}

impl Values {
    pub(crate) fn len(&self) -> usize {
        match self {
            Values::F(v) => v.len(),
            Values::I(v) => v.len(),
        }
    }
}

/// Where and how a `DataArray`'s values are stored.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Format {
    Ascii,
    Binary,
    Appended,
}

/// A `DataArray` as found in the XML, not decoded yet.
#[derive(Debug)]
pub(crate) struct ArrayRef<'a> {
    pub(crate) name: &'a [u8],
    pub(crate) ty: Ty,
    pub(crate) ncomp: usize,
    pub(crate) format: Format,
    pub(crate) offset: usize,
    /// Inline content (ascii or base64).
    pub(crate) content: &'a [u8],
    /// Byte position of the tag (for line numbers in errors).
    pub(crate) at: usize,
}

/// The reading state of one VTK XML file (from [`Ctx::new`] and [`Ctx::root`]).
pub(crate) struct Ctx<'a> {
    pub(crate) data: &'a [u8],
    pub(crate) file: &'a str,
    pub(crate) be: bool,
    pub(crate) header64: bool,
    pub(crate) zlib: bool,
    /// Start of appended data (after `_`), and whether it is base64.
    pub(crate) app: Option<(usize, bool)>,
    pub(crate) app_end: usize,
    /// Sorted offsets of all appended arrays (to delimit base64 appended arrays).
    pub(crate) app_offsets: Vec<usize>,
}

/// The first occurrence of `needle` in `hay` at or after `from`.
pub(crate) fn find(hay: &[u8], from: usize, needle: &[u8]) -> Option<usize> {
    if from > hay.len() {
        return None;
    }
    let first = needle[0];
    let mut i = from;
    while i + needle.len() <= hay.len() {
        match hay[i..].iter().position(|&c| c == first) {
            Some(k) => {
                i += k;
                if i + needle.len() <= hay.len() && &hay[i..i + needle.len()] == needle {
                    return Some(i);
                }
                i += 1;
            }
            None => return None,
        }
    }
    None
}

/// An XML start, end or empty-element tag.
pub(crate) struct Tag<'a> {
    pub(crate) name: &'a [u8],
    pub(crate) attrs: Vec<(&'a [u8], &'a [u8])>,
    pub(crate) closing: bool,
    pub(crate) self_closing: bool,
    pub(crate) start: usize,
    pub(crate) end: usize,
}

impl<'a> Tag<'a> {
    pub(crate) fn attr(&self, k: &str) -> Option<&'a [u8]> {
        self.attrs
            .iter()
            .find(|(n, _)| *n == k.as_bytes())
            .map(|(_, v)| *v)
    }
}

impl<'a> Ctx<'a> {
    pub(crate) fn line_at(&self, pos: usize) -> usize {
        1 + self.data[..pos.min(self.data.len())]
            .iter()
            .filter(|&&c| c == b'\n')
            .count()
    }

    pub(crate) fn err_at(&self, pos: usize, msg: impl Into<String>) -> Error {
        Error::line(self.file, self.line_at(pos), msg)
    }

    /// The next tag in `xml` from `*pos`, skipping declarations and comments.
    pub(crate) fn next_tag(&self, xml: &'a [u8], pos: &mut usize) -> Result<Option<Tag<'a>>> {
        loop {
            let Some(lt) = find(xml, *pos, b"<") else {
                return Ok(None);
            };
            let rest = &xml[lt..];
            if rest.starts_with(b"<!--") {
                *pos = find(xml, lt, b"-->")
                    .ok_or_else(|| self.err_at(lt, "unterminated XML comment"))?
                    + 3;
                continue;
            }
            if rest.starts_with(b"<?") || rest.starts_with(b"<!") {
                *pos = find(xml, lt, b">")
                    .ok_or_else(|| self.err_at(lt, "unterminated XML declaration"))?
                    + 1;
                continue;
            }
            let mut i = lt + 1;
            let closing = xml.get(i) == Some(&b'/');
            if closing {
                i += 1;
            }
            let ns = i;
            while i < xml.len() && !xml[i].is_ascii_whitespace() && xml[i] != b'>' && xml[i] != b'/'
            {
                i += 1;
            }
            let name = &xml[ns..i];
            let mut attrs = Vec::new();
            loop {
                while i < xml.len() && xml[i].is_ascii_whitespace() {
                    i += 1;
                }
                match xml.get(i) {
                    None => return Err(self.err_at(lt, "unterminated XML tag")),
                    Some(b'>') => {
                        *pos = i + 1;
                        return Ok(Some(Tag {
                            name,
                            attrs,
                            closing,
                            self_closing: false,
                            start: lt,
                            end: i + 1,
                        }));
                    }
                    Some(b'/') if xml.get(i + 1) == Some(&b'>') => {
                        *pos = i + 2;
                        return Ok(Some(Tag {
                            name,
                            attrs,
                            closing,
                            self_closing: true,
                            start: lt,
                            end: i + 2,
                        }));
                    }
                    _ => {}
                }
                let ks = i;
                while i < xml.len()
                    && xml[i] != b'='
                    && !xml[i].is_ascii_whitespace()
                    && xml[i] != b'>'
                {
                    i += 1;
                }
                let key = &xml[ks..i];
                while i < xml.len() && xml[i].is_ascii_whitespace() {
                    i += 1;
                }
                if xml.get(i) != Some(&b'=') {
                    return Err(self.err_at(lt, format!("malformed XML attribute '{}'", show(key))));
                }
                i += 1;
                while i < xml.len() && xml[i].is_ascii_whitespace() {
                    i += 1;
                }
                let q = match xml.get(i) {
                    Some(&q @ (b'"' | b'\'')) => q,
                    _ => {
                        return Err(
                            self.err_at(lt, format!("unquoted XML attribute '{}'", show(key)))
                        );
                    }
                };
                let vs = i + 1;
                let ve = xml[vs..]
                    .iter()
                    .position(|&c| c == q)
                    .map(|k| vs + k)
                    .ok_or_else(|| self.err_at(lt, "unterminated XML attribute value"))?;
                attrs.push((key, &xml[vs..ve]));
                i = ve + 1;
            }
        }
    }

    pub(crate) fn header_int(&self, b: &[u8]) -> u64 {
        let mut x = [0u8; 8];
        let n = if self.header64 { 8 } else { 4 };
        x[..n].copy_from_slice(&b[..n]);
        if self.be {
            x[..n].reverse();
        }
        u64::from_le_bytes(x)
    }

    /// Decode a binary block (header + data) starting at `bytes[0]`. `max` bounds the decoded
    /// size; `name` names the array in errors.
    pub(crate) fn unblock(&self, bytes: &[u8], name: &str, max: usize) -> Result<Vec<u8>> {
        let hs = if self.header64 { 8 } else { 4 };
        let trunc = || Error::truncated(self.file, format!("data of array '{name}' is incomplete"));
        if bytes.len() < hs {
            return Err(trunc());
        }
        if !self.zlib {
            let n = self.header_int(bytes);
            if n > (bytes.len() - hs) as u64 {
                return Err(trunc());
            }
            return Ok(bytes[hs..hs + n as usize].to_vec());
        }
        if bytes.len() < 3 * hs {
            return Err(trunc());
        }
        let nb = self.header_int(bytes);
        let bs = self.header_int(&bytes[hs..]);
        let last = self.header_int(&bytes[2 * hs..]);
        if nb > ((bytes.len() - 3 * hs) / hs) as u64 {
            return Err(trunc());
        }
        let nb = nb as usize;
        let total = if nb == 0 {
            0
        } else {
            (nb as u64 - 1)
                .saturating_mul(bs)
                .saturating_add(if last == 0 { bs } else { last })
        };
        // zlib expands at most ~1032:1, so more than that is a lie (and must not be allocated).
        if total > max as u64 || total > (bytes.len() as u64).saturating_mul(1100) {
            return Err(Error::format(
                self.file,
                format!(
                    "array '{name}': compressed header announces {total} bytes, more than the {max} expected"
                ),
            ));
        }
        crate::limits::reserve(
            self.file,
            &format!("array '{name}' ({total} bytes decompressed)"),
            total,
        )?;
        let mut out = Vec::with_capacity(total as usize);
        let mut pos = 3 * hs + nb * hs;
        for k in 0..nb {
            let cs = self.header_int(&bytes[3 * hs + k * hs..]);
            if cs > (bytes.len() - pos) as u64 {
                return Err(trunc());
            }
            let want = if k + 1 == nb && last != 0 { last } else { bs };
            let before = out.len();
            let mut dec = flate2::read::ZlibDecoder::new(&bytes[pos..pos + cs as usize]).take(want);
            dec.read_to_end(&mut out).map_err(|e| {
                Error::format(self.file, format!("array '{name}': zlib block {k}: {e}"))
            })?;
            if (out.len() - before) as u64 != want {
                return Err(Error::format(
                    self.file,
                    format!(
                        "array '{name}': zlib block {k} decompresses to {} bytes, expected {want}",
                        out.len() - before
                    ),
                ));
            }
            pos += cs as usize;
        }
        Ok(out)
    }

    /// The values of an array: `count` of them (components included) when given, else all.
    pub(crate) fn values(&self, a: &ArrayRef, count: Option<usize>) -> Result<Values> {
        let name = String::from_utf8_lossy(a.name).into_owned();
        let size = a.ty.size();
        // Bound for decoded sizes: what the file could plausibly hold.
        let max = match count {
            Some(c) => c.saturating_mul(size),
            None => self.data.len().saturating_mul(1100),
        };
        let bytes = match a.format {
            Format::Ascii => return self.ascii(a, &name, count),
            Format::Binary => {
                let raw = b64::decode(a.content).ok_or_else(|| {
                    self.err_at(a.at, format!("array '{name}': invalid base64 data"))
                })?;
                self.unblock(&raw, &name, max)?
            }
            Format::Appended => {
                let (start, base64) = self.app.ok_or_else(|| {
                    self.err_at(
                        a.at,
                        format!("array '{name}' is appended but there is no AppendedData"),
                    )
                })?;
                let s = start.saturating_add(a.offset);
                if s > self.data.len() {
                    return Err(Error::truncated(
                        self.file,
                        format!("appended data of array '{name}' is missing"),
                    ));
                }
                if base64 {
                    let end = self
                        .app_offsets
                        .iter()
                        .find(|&&o| o > a.offset)
                        .map_or(self.app_end, |&o| (start + o).min(self.app_end));
                    let raw = b64::decode(&self.data[s..end.max(s)]).ok_or_else(|| {
                        self.err_at(a.at, format!("array '{name}': invalid base64 data"))
                    })?;
                    self.unblock(&raw, &name, max)?
                } else {
                    self.unblock(&self.data[s..], &name, max)?
                }
            }
        };
        let n = bytes.len() / size;
        let n = match count {
            Some(c) if c > n => {
                return Err(Error::truncated(
                    self.file,
                    format!("array '{name}' has {n} values, expected {c}"),
                ));
            }
            Some(c) => c,
            None => n,
        };
        let mut x = [0u8; 8];
        let mut get = |i: usize| -> [u8; 8] {
            x = [0; 8];
            x[..size].copy_from_slice(&bytes[i * size..(i + 1) * size]);
            if self.be {
                x[..size].reverse();
            }
            x
        };
        Ok(match a.ty {
            Ty::F32 => Values::F(
                (0..n)
                    .map(|i| {
                        let b = get(i);
                        f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64
                    })
                    .collect(),
            ),
            Ty::F64 => Values::F((0..n).map(|i| f64::from_le_bytes(get(i))).collect()),
            ty => Values::I(
                (0..n)
                    .map(|i| {
                        let b = get(i);
                        match ty {
                            Ty::I8 => b[0] as i8 as i64,
                            Ty::U8 => b[0] as i64,
                            Ty::I16 => i16::from_le_bytes([b[0], b[1]]) as i64,
                            Ty::U16 => u16::from_le_bytes([b[0], b[1]]) as i64,
                            Ty::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i64,
                            Ty::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i64,
                            Ty::I64 => i64::from_le_bytes(b),
                            // Values above i64::MAX become negative and are rejected as indices.
                            _ => u64::from_le_bytes(b) as i64,
                        }
                    })
                    .collect(),
            ),
        })
    }

    pub(crate) fn ascii(&self, a: &ArrayRef, name: &str, count: Option<usize>) -> Result<Values> {
        let toks = a
            .content
            .split(|c| c.is_ascii_whitespace())
            .filter(|t| !t.is_empty());
        let toks = toks.take(count.unwrap_or(usize::MAX));
        let bad = |t: &[u8]| self.err_at(a.at, format!("array '{name}': bad number '{}'", show(t)));
        let v = if a.ty.is_float() {
            let mut v = Vec::new();
            for t in toks {
                v.push(parse_f64(t).ok_or_else(|| bad(t))?);
            }
            Values::F(v)
        } else {
            let mut v = Vec::new();
            for t in toks {
                v.push(parse_i64(t).ok_or_else(|| bad(t))?);
            }
            Values::I(v)
        };
        if let Some(c) = count
            && v.len() < c
        {
            return Err(Error::truncated(
                self.file,
                format!("array '{name}' has {} values, expected {c}", v.len()),
            ));
        }
        Ok(v)
    }

    pub(crate) fn ints(&self, a: &ArrayRef, count: Option<usize>) -> Result<Vec<i64>> {
        match self.values(a, count)? {
            Values::I(v) => Ok(v),
            Values::F(v) => {
                let mut out = Vec::with_capacity(v.len());
                for (i, x) in v.into_iter().enumerate() {
                    if x.fract() != 0.0 || !(i64::MIN as f64..=i64::MAX as f64).contains(&x) {
                        return Err(Error::element(
                            self.file,
                            "value",
                            i,
                            format!("array '{}': {x} is not an integer", show(a.name)),
                        ));
                    }
                    out.push(x as i64);
                }
                Ok(out)
            }
        }
    }
}

impl<'a> Ctx<'a> {
    /// A reading context for `data`: finds the `AppendedData` block, if any. Returns the
    /// context and the end of the XML part (where the appended data starts).
    pub(crate) fn new(data: &'a [u8], file: &'a str) -> Result<(Ctx<'a>, usize)> {
        let mut ctx = Ctx {
            data,
            file,
            be: false,
            header64: false,
            zlib: false,
            app: None,
            app_end: data.len(),
            app_offsets: Vec::new(),
        };
        let xml_end = match find(data, 0, b"<AppendedData") {
            Some(p) => {
                let mut q = p;
                let tag = ctx
                    .next_tag(data, &mut q)?
                    .ok_or_else(|| ctx.err_at(p, "malformed AppendedData tag"))?;
                let base64 = match tag.attr("encoding") {
                    Some(b"raw") => false,
                    Some(b"base64") => true,
                    Some(e) => {
                        return Err(
                            ctx.err_at(p, format!("unknown AppendedData encoding '{}'", show(e)))
                        );
                    }
                    None => return Err(ctx.err_at(p, "AppendedData without an encoding")),
                };
                let us = data[tag.end..]
                    .iter()
                    .position(|&c| c == b'_')
                    .ok_or_else(|| ctx.err_at(p, "AppendedData without the '_' marker"))?;
                let start = tag.end + us + 1;
                ctx.app = Some((start, base64));
                if base64 {
                    ctx.app_end = find(data, start, b"</AppendedData").unwrap_or(data.len());
                }
                p
            }
            None => data.len(),
        };
        Ok((ctx, xml_end))
    }

    /// Check the `VTKFile` element's type (`kind`, e.g. "UnstructuredGrid", read from `ext`
    /// files) and take its byte order, header type and compressor.
    pub(crate) fn root(&mut self, tag: &Tag, kind: &str, ext: &str) -> Result<()> {
        match tag.attr("type") {
            Some(t) if t == kind.as_bytes() => {}
            Some(t) => {
                return Err(self.err_at(
                    tag.start,
                    format!("VTK file type '{}': only {kind} ({ext}) is read", show(t)),
                ));
            }
            None => return Err(self.err_at(tag.start, "VTKFile without a type")),
        }
        self.be = match tag.attr("byte_order") {
            Some(b"BigEndian") => true,
            Some(b"LittleEndian") | None => false,
            Some(o) => {
                return Err(self.err_at(tag.start, format!("unknown byte_order '{}'", show(o))));
            }
        };
        self.header64 = match tag.attr("header_type") {
            Some(b"UInt64") => true,
            Some(b"UInt32") | None => false,
            Some(h) => {
                return Err(
                    self.err_at(tag.start, format!("unsupported header_type '{}'", show(h)))
                );
            }
        };
        self.zlib = match tag.attr("compressor") {
            None | Some(b"") => false,
            Some(b"vtkZLibDataCompressor") => true,
            Some(c) => {
                return Err(self.err_at(
                    tag.start,
                    format!(
                        "unsupported compressor '{}' (only vtkZLibDataCompressor)",
                        show(c)
                    ),
                ));
            }
        };
        Ok(())
    }

    /// The array described by a `DataArray` start tag; moves `pos` to its end tag.
    pub(crate) fn data_array(
        &mut self,
        tag: &Tag<'a>,
        xml: &'a [u8],
        pos: &mut usize,
    ) -> Result<ArrayRef<'a>> {
        let ty_s = tag
            .attr("type")
            .ok_or_else(|| self.err_at(tag.start, "DataArray without a type"))?;
        let ty = Ty::parse(ty_s).ok_or_else(|| {
            self.err_at(
                tag.start,
                format!("unsupported DataArray type '{}'", show(ty_s)),
            )
        })?;
        let ncomp = match tag.attr("NumberOfComponents") {
            Some(v) => crate::text::parse_u64(v)
                .filter(|&n| (1..=1024).contains(&n))
                .ok_or_else(|| {
                    self.err_at(tag.start, format!("bad NumberOfComponents '{}'", show(v)))
                })? as usize,
            None => 1,
        };
        let format = match tag.attr("format") {
            Some(b"ascii") => Format::Ascii,
            Some(b"binary") => Format::Binary,
            Some(b"appended") => Format::Appended,
            Some(f) => {
                return Err(
                    self.err_at(tag.start, format!("unknown DataArray format '{}'", show(f)))
                );
            }
            None => Format::Ascii,
        };
        let offset = match tag.attr("offset") {
            Some(v) => crate::text::parse_u64(v)
                .and_then(|x| usize::try_from(x).ok())
                .ok_or_else(|| self.err_at(tag.start, format!("bad offset '{}'", show(v))))?,
            None => 0,
        };
        let content: &[u8] = if tag.self_closing {
            b""
        } else {
            let end = find(xml, tag.end, b"</DataArray")
                .ok_or_else(|| self.err_at(tag.start, "DataArray without </DataArray>"))?;
            *pos = end;
            // The data is the text before any child element (VTK adds
            // <InformationKey> elements after it).
            let text_end = find(&xml[..end], tag.end, b"<").unwrap_or(end);
            &xml[tag.end..text_end]
        };
        if format == Format::Appended {
            self.app_offsets.push(offset);
        }
        Ok(ArrayRef {
            name: tag.attr("Name").unwrap_or(b""),
            ty,
            ncomp,
            format,
            offset,
            content,
            at: tag.start,
        })
    }

    /// To call once every `DataArray` has been seen: prepares reading base64 appended arrays.
    pub(crate) fn end_of_xml(&mut self) {
        self.app_offsets.sort_unstable();
        self.app_offsets.dedup();
    }
}

/// Walk the pieces of a VTK XML file of type `kind` (`ext` for messages). `open` makes a piece
/// from its `Piece` tag's numbers (`num(name, required)`: an attribute absent and not required
/// is 0); `array` files each `DataArray` of a piece under the element of `sections` it sits in
/// (`Points`, `Cells`, `CellData`, …; empty outside them). Returns the context to decode the
/// arrays with, and the pieces in file order.
pub(crate) fn read_pieces<'a, P>(
    data: &'a [u8],
    file: &'a str,
    (kind, ext): (&str, &str),
    sections: &[&[u8]],
    open: impl Fn(&dyn Fn(&str, bool) -> Result<usize>) -> Result<P>,
    array: impl Fn(&mut P, &[u8], ArrayRef<'a>),
) -> Result<(Ctx<'a>, Vec<P>)> {
    let (mut ctx, xml_end) = Ctx::new(data, file)?;
    let xml = &data[..xml_end];
    let mut pos = 0;
    let mut pieces: Vec<P> = Vec::new();
    let mut cur: Option<P> = None;
    let mut section: &[u8] = b"";
    let mut seen_root = false;
    while let Some(tag) = ctx.next_tag(xml, &mut pos)? {
        match tag.name {
            b"VTKFile" if !tag.closing => {
                seen_root = true;
                ctx.root(&tag, kind, ext)?;
            }
            b"Piece" if !tag.closing => {
                if !seen_root {
                    return Err(ctx.err_at(tag.start, "Piece outside VTKFile"));
                }
                let num = |k: &str, required: bool| -> Result<usize> {
                    match tag.attr(k) {
                        None if !required => Ok(0),
                        None => Err(ctx.err_at(tag.start, format!("Piece without {k}"))),
                        Some(v) => crate::text::parse_u64(v)
                            .and_then(|x| usize::try_from(x).ok())
                            .ok_or_else(|| ctx.err_at(tag.start, format!("bad {k} '{}'", show(v)))),
                    }
                };
                let p = open(&num)?;
                if tag.self_closing {
                    pieces.push(p);
                } else {
                    cur = Some(p);
                }
            }
            b"Piece" => {
                if let Some(p) = cur.take() {
                    pieces.push(p);
                }
            }
            name if sections.contains(&name) => {
                section = if tag.closing || tag.self_closing {
                    b""
                } else {
                    name
                };
            }
            b"DataArray" if !tag.closing => {
                let a = ctx.data_array(&tag, xml, &mut pos)?;
                if let Some(p) = cur.as_mut() {
                    array(p, section, a);
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
    if let Some(p) = cur.take() {
        pieces.push(p);
    }
    ctx.end_of_xml();
    Ok((ctx, pieces))
}
