//! Shared machinery for text formats: a tokenizer that tracks line numbers, number parsing, and
//! a buffered writer with fast shortest-round-trip float formatting (`ryu`) and integer
//! formatting (`itoa`).

use std::io::{self, Write};

use crate::error::{Error, Result};

/// Whitespace as every supported text format understands it.
#[inline]
pub(crate) fn is_ws(c: u8) -> bool {
    matches!(c, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

/// A short printable excerpt of a token for error messages.
pub(crate) fn show(tok: &[u8]) -> String {
    let t = &tok[..tok.len().min(40)];
    let s = String::from_utf8_lossy(t).into_owned();
    if tok.len() > 40 { format!("{s}...") } else { s }
}

/// Parse an unsigned decimal integer (an optional leading `+` is accepted).
#[inline]
pub(crate) fn parse_u64(tok: &[u8]) -> Option<u64> {
    let d = match tok.first()? {
        b'+' => &tok[1..],
        _ => tok,
    };
    if d.is_empty() || d.len() > 20 {
        return None;
    }
    let mut v: u64 = 0;
    for &c in d {
        let x = c.wrapping_sub(b'0');
        if x > 9 {
            return None;
        }
        v = v.checked_mul(10)?.checked_add(x as u64)?;
    }
    Some(v)
}

/// Parse a signed decimal integer.
#[inline]
pub(crate) fn parse_i64(tok: &[u8]) -> Option<i64> {
    match tok.first()? {
        b'-' => {
            let v = parse_u64(&tok[1..])?;
            if tok.get(1) == Some(&b'+') {
                return None;
            }
            if v <= i64::MAX as u64 + 1 {
                Some((v as i64).wrapping_neg())
            } else {
                None
            }
        }
        _ => i64::try_from(parse_u64(tok)?).ok(),
    }
}

/// Parse a float (any form Rust's `f64::from_str` accepts, which includes C's `%g` output).
/// Non-finite values parse; callers reject them.
#[inline]
pub(crate) fn parse_f64(tok: &[u8]) -> Option<f64> {
    std::str::from_utf8(tok).ok()?.parse::<f64>().ok()
}

/// Tokenizer over a whole file in memory, tracking 1-based line numbers.
pub(crate) struct Lexer<'a> {
    pub data: &'a [u8],
    pub pos: usize,
    /// Line number at `pos`.
    pub line: usize,
    /// Line of the last token or line returned (for error messages).
    pub tok_line: usize,
    /// Comment character (to end of line), 0 for none.
    comment: u8,
    pub file: &'a str,
}

impl<'a> Lexer<'a> {
    pub fn new(data: &'a [u8], file: &'a str, comment: Option<u8>) -> Lexer<'a> {
        Lexer {
            data,
            pos: 0,
            line: 1,
            tok_line: 1,
            comment: comment.unwrap_or(0),
            file,
        }
    }

    /// Skip whitespace (counting newlines) and comments.
    #[inline]
    pub fn skip_ws(&mut self) {
        let d = self.data;
        while self.pos < d.len() {
            let c = d[self.pos];
            if c == b'\n' {
                self.line += 1;
                self.pos += 1;
            } else if is_ws(c) {
                self.pos += 1;
            } else if c == self.comment && c != 0 {
                while self.pos < d.len() && d[self.pos] != b'\n' {
                    self.pos += 1;
                }
            } else {
                break;
            }
        }
    }

    /// The next token, or `None` at the end of the data.
    #[inline]
    pub fn next_token(&mut self) -> Option<&'a [u8]> {
        self.skip_ws();
        let d = self.data;
        if self.pos >= d.len() {
            self.tok_line = self.line;
            return None;
        }
        let start = self.pos;
        while self.pos < d.len()
            && !is_ws(d[self.pos])
            && (d[self.pos] != self.comment || self.comment == 0)
        {
            self.pos += 1;
        }
        self.tok_line = self.line;
        Some(&d[start..self.pos])
    }

    /// The next token; an error naming `what` at the end of the data.
    #[inline]
    pub fn expect(&mut self, what: &str) -> Result<&'a [u8]> {
        match self.next_token() {
            Some(t) => Ok(t),
            None => Err(self.err(format!("unexpected end of file, expected {what}"))),
        }
    }

    /// An error at the line of the last token.
    pub fn err(&self, msg: impl Into<String>) -> Error {
        Error::line(self.file, self.tok_line, msg)
    }

    /// A finite float.
    #[inline]
    pub fn f64(&mut self, what: &str) -> Result<f64> {
        let t = self.expect(what)?;
        self.tok_f64(t, what)
    }

    /// Interpret a token as a finite float.
    #[inline]
    pub fn tok_f64(&self, t: &[u8], what: &str) -> Result<f64> {
        match parse_f64(t) {
            Some(v) if v.is_finite() => Ok(v),
            Some(_) => Err(self.err(format!("non-finite {what} '{}'", show(t)))),
            None => Err(self.err(format!("expected {what}, got '{}'", show(t)))),
        }
    }

    /// An unsigned integer.
    #[inline]
    pub fn u64(&mut self, what: &str) -> Result<u64> {
        let t = self.expect(what)?;
        self.tok_u64(t, what)
    }

    /// Interpret a token as an unsigned integer.
    #[inline]
    pub fn tok_u64(&self, t: &[u8], what: &str) -> Result<u64> {
        parse_u64(t).ok_or_else(|| {
            self.err(format!(
                "expected {what} (a non-negative integer), got '{}'",
                show(t)
            ))
        })
    }

    /// A signed integer.
    #[inline]
    pub fn i64(&mut self, what: &str) -> Result<i64> {
        let t = self.expect(what)?;
        self.tok_i64(t, what)
    }

    /// Interpret a token as a signed integer.
    #[inline]
    pub fn tok_i64(&self, t: &[u8], what: &str) -> Result<i64> {
        parse_i64(t)
            .ok_or_else(|| self.err(format!("expected {what} (an integer), got '{}'", show(t))))
    }

    /// A count used to size arrays: an unsigned integer, capped for pre-allocation by the bytes
    /// left (each record needs at least `min_bytes`), so that a garbage count cannot make us
    /// allocate absurd amounts before failing.
    pub fn count(&mut self, what: &str, min_bytes: usize) -> Result<(usize, usize)> {
        let n = self.u64(what)?;
        let n = usize::try_from(n).map_err(|_| self.err(format!("{what} {n} too large")))?;
        Ok((n, reserve_cap(n, self.data.len() - self.pos, min_bytes)))
    }

    /// Tokens of the rest of the current line (stops before the newline or a comment).
    #[inline]
    pub fn rest_of_line(&mut self, out: &mut Vec<&'a [u8]>) {
        out.clear();
        let d = self.data;
        loop {
            while self.pos < d.len() && matches!(d[self.pos], b' ' | b'\t' | b'\r' | 0x0b | 0x0c) {
                self.pos += 1;
            }
            if self.pos >= d.len()
                || d[self.pos] == b'\n'
                || (d[self.pos] == self.comment && self.comment != 0)
            {
                return;
            }
            let start = self.pos;
            while self.pos < d.len()
                && !is_ws(d[self.pos])
                && (d[self.pos] != self.comment || self.comment == 0)
            {
                self.pos += 1;
            }
            out.push(&d[start..self.pos]);
        }
    }

    /// The tokens of the next non-blank line; `false` at the end of the data.
    #[inline]
    pub fn line_tokens(&mut self, out: &mut Vec<&'a [u8]>) -> bool {
        self.skip_ws();
        self.tok_line = self.line;
        if self.pos >= self.data.len() {
            out.clear();
            return false;
        }
        self.rest_of_line(out);
        true
    }

    /// Skip to the start of the next line.
    pub fn skip_line(&mut self) {
        let d = self.data;
        while self.pos < d.len() && d[self.pos] != b'\n' {
            self.pos += 1;
        }
        if self.pos < d.len() {
            self.pos += 1;
            self.line += 1;
        }
    }

    /// The raw rest of the current line (without the newline), consumed.
    pub fn raw_line(&mut self) -> &'a [u8] {
        let d = self.data;
        let start = self.pos;
        while self.pos < d.len() && d[self.pos] != b'\n' {
            self.pos += 1;
        }
        let mut end = self.pos;
        if end > start && d[end - 1] == b'\r' {
            end -= 1;
        }
        if self.pos < d.len() {
            self.pos += 1;
            self.line += 1;
        }
        &d[start..end]
    }
}

/// How many records to reserve room for: `n`, but no more than the remaining bytes could hold.
#[inline]
pub(crate) fn reserve_cap(n: usize, bytes_left: usize, min_bytes: usize) -> usize {
    n.min(bytes_left / min_bytes.max(1) + 1)
}

/// Buffered text output with fast number formatting. Write errors surface at [`Out::check`]
/// and [`Out::finish`].
pub(crate) struct Out<W: Write> {
    w: W,
    pub buf: Vec<u8>,
}

const CHUNK: usize = 1 << 16;

impl<W: Write> Out<W> {
    pub fn new(w: W) -> Out<W> {
        Out {
            w,
            buf: Vec::with_capacity(CHUNK + 1024),
        }
    }

    /// Shortest representation that parses back to the same `f64`.
    #[inline]
    pub fn f64(&mut self, x: f64) {
        let mut b = ryu::Buffer::new();
        self.buf.extend_from_slice(b.format(x).as_bytes());
    }

    /// An integer.
    #[inline]
    pub fn int<I: itoa::Integer>(&mut self, x: I) {
        let mut b = itoa::Buffer::new();
        self.buf.extend_from_slice(b.format(x).as_bytes());
    }

    /// Numbers separated by single spaces (no line end).
    pub fn f64s(&mut self, xs: &[f64]) {
        for (i, &x) in xs.iter().enumerate() {
            if i > 0 {
                self.c(b' ');
            }
            self.f64(x);
        }
    }

    /// Integers separated by single spaces (no line end).
    pub fn ints<I: itoa::Integer + Copy>(&mut self, xs: &[I]) {
        for (i, &x) in xs.iter().enumerate() {
            if i > 0 {
                self.c(b' ');
            }
            self.int(x);
        }
    }

    /// Text.
    #[inline]
    pub fn s(&mut self, s: &str) {
        self.buf.extend_from_slice(s.as_bytes());
    }

    /// One byte.
    #[inline]
    pub fn c(&mut self, c: u8) {
        self.buf.push(c);
    }

    /// Raw bytes.
    #[inline]
    pub fn bytes(&mut self, b: &[u8]) {
        self.buf.extend_from_slice(b);
    }

    /// Flush the buffer to the writer when it is full.
    #[inline]
    pub fn check(&mut self) -> io::Result<()> {
        if self.buf.len() >= CHUNK {
            self.w.write_all(&self.buf)?;
            self.buf.clear();
        }
        Ok(())
    }

    /// Write everything out and flush.
    pub fn finish(mut self) -> io::Result<W> {
        self.w.write_all(&self.buf)?;
        self.buf.clear();
        self.w.flush()?;
        Ok(self.w)
    }
}

/// The body shared by OFF and ASCII PLY: one `x y z` line per point, then one `3 a b c` line per
/// triangle (followed by its two side labels with `sides`); finishes the output.
pub(crate) fn write_points_and_counted_triangles<W: Write>(
    mut out: Out<W>,
    mesh: &biotet::SurfaceMesh,
    file: &str,
    sides: bool,
) -> Result<()> {
    for p in &mesh.points {
        out.f64s(p);
        out.c(b'\n');
        out.check().map_err(|e| Error::io(file, e))?;
    }
    for (i, t) in mesh.triangles.iter().enumerate() {
        out.c(b'3');
        let labels = if sides { &mesh.sides[i][..] } else { &[] };
        for &v in t.iter().chain(labels) {
            out.c(b' ');
            out.int(v);
        }
        out.c(b'\n');
        out.check().map_err(|e| Error::io(file, e))?;
    }
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}
