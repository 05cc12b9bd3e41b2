//! Base64 (standard alphabet, padded), as VTK's XML formats use it.

const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Append the base64 encoding of `data` to `out`.
pub(crate) fn encode(data: &[u8], out: &mut Vec<u8>) {
    out.reserve(data.len().div_ceil(3) * 4);
    let mut chunks = data.chunks_exact(3);
    for c in &mut chunks {
        let v = (c[0] as u32) << 16 | (c[1] as u32) << 8 | c[2] as u32;
        out.extend_from_slice(&[
            ALPHABET[(v >> 18) as usize & 63],
            ALPHABET[(v >> 12) as usize & 63],
            ALPHABET[(v >> 6) as usize & 63],
            ALPHABET[v as usize & 63],
        ]);
    }
    let r = chunks.remainder();
    if !r.is_empty() {
        let v = (r[0] as u32) << 16 | (r.get(1).copied().unwrap_or(0) as u32) << 8;
        out.push(ALPHABET[(v >> 18) as usize & 63]);
        out.push(ALPHABET[(v >> 12) as usize & 63]);
        out.push(if r.len() == 2 {
            ALPHABET[(v >> 6) as usize & 63]
        } else {
            b'='
        });
        out.push(b'=');
    }
}

const fn table() -> [u8; 256] {
    let mut t = [255u8; 256];
    let mut i = 0;
    while i < 64 {
        t[ALPHABET[i] as usize] = i as u8;
        i += 1;
    }
    t
}

static DECODE: [u8; 256] = table();

/// Decode base64, skipping whitespace. Padding ends a group and decoding continues after it, so
/// separately encoded pieces that were concatenated (VTK writes a header and the data as two
/// base64 strings) decode to the concatenation of their bytes. `None` on an invalid character.
pub(crate) fn decode(text: &[u8]) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 3);
    let mut acc: u32 = 0;
    let mut k = 0;
    let mut i = 0;
    while i < text.len() {
        let c = text[i];
        i += 1;
        if c == b'=' {
            // Flush the partial group.
            match k {
                2 => out.push((acc >> 4) as u8),
                3 => {
                    out.push((acc >> 10) as u8);
                    out.push((acc >> 2) as u8);
                }
                0 => {}
                _ => return None,
            }
            acc = 0;
            k = 0;
            continue;
        }
        let d = DECODE[c as usize];
        if d == 255 {
            if c.is_ascii_whitespace() {
                continue;
            }
            return None;
        }
        acc = acc << 6 | d as u32;
        k += 1;
        if k == 4 {
            out.push((acc >> 16) as u8);
            out.push((acc >> 8) as u8);
            out.push(acc as u8);
            acc = 0;
            k = 0;
        }
    }
    match k {
        0 => {}
        2 => out.push((acc >> 4) as u8),
        3 => {
            out.push((acc >> 10) as u8);
            out.push((acc >> 2) as u8);
        }
        _ => return None,
    }
    Some(out)
}
