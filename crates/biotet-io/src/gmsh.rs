//! Gmsh `.msh`: tet meshes in format 4.1 (ASCII and binary) and 2.2 (ASCII).
//!
//! Reading: `$MeshFormat`, `$PhysicalNames`, `$Entities`, `$Nodes` and `$Elements` are read;
//! other sections are skipped. Nodes are put in increasing tag order (tags need not be
//! contiguous) and tets (element type 4) in increasing element tag order. A tet's label is its
//! 3D physical tag — from the entity's first physical tag in 4.1, from the first element tag in
//! 2.2 — or, when the physical group is named `region_<n>`, that `n` (this is how label 0
//! survives a round trip); without a physical tag it is the elementary entity tag (2.2 with no
//! tags at all: 1). Other volume elements (hexahedra, prisms, pyramids, quadratic tets, ...)
//! are counted in [`TetRead::skipped_elements`]; points, lines and surface elements are ignored
//! silently. Gmsh 2.2 binary and 4.0 files are rejected with a clear error.
//!
//! Writing ([`write_tet`] ASCII, [`write_tet_binary`] binary, both 4.1):
//! - one volume entity per region label (tags 1, 2, ... in increasing label order), in a 3D
//!   physical group named `region_<label>` whose tag is the label (for label 0, which Gmsh
//!   cannot use as a tag: the largest label + 1);
//! - one surface entity and 2D physical group per boundary (`boundary_<a>_0`) or interface
//!   (`interface_<a>_<b>`, `a < b`) between labels, in the order and with the numbering of the
//!   Medit triangle refs (see [`crate::medit`]); each volume lists its bounding surfaces, with a
//!   minus sign for interfaces it does not own; triangles are oriented outward from the smaller
//!   label;
//! - node tags are point index + 1; every node is classified on the first surface entity
//!   that uses it, else on the volume of its first tet; tet element tags are tet index + 1,
//!   triangle element tags follow, so a read-back restores the order of points and tets.

use std::collections::HashMap;
use std::io::Write;

use biotet::TetMesh;

use crate::TetRead;
use crate::common::{check_tet, face_groups, label_of, orient_tets, read_all};
use crate::error::{Error, Result};
use crate::text::{Lexer, Out, reserve_cap, show};

/// Number of nodes of a Gmsh element type, for the types Gmsh documents.
fn nodes_of(ty: i64) -> Option<usize> {
    Some(match ty {
        1 => 2,
        2 => 3,
        3 => 4,
        4 => 4,
        5 => 8,
        6 => 6,
        7 => 5,
        8 => 3,
        9 => 6,
        10 => 9,
        11 => 10,
        12 => 27,
        13 => 18,
        14 => 14,
        15 => 1,
        16 => 8,
        17 => 20,
        18 => 15,
        19 => 13,
        20 => 9,
        21 => 10,
        22 => 12,
        23 => 15,
        24 => 15,
        25 => 21,
        26 => 4,
        27 => 5,
        28 => 6,
        29 => 20,
        30 => 35,
        31 => 56,
        92 => 64,
        93 => 125,
        _ => return None,
    })
}

/// Whether a Gmsh element type is a volume element.
fn is_volume(ty: i64) -> bool {
    matches!(ty, 4..=7 | 11..=14 | 17..=19 | 29..=31 | 92 | 93)
}

/// Binary reader over the data of a section.
struct Bin<'a> {
    d: &'a [u8],
    pos: usize,
    le: bool,
    size_t: usize,
    file: &'a str,
    section: &'static str,
}

impl Bin<'_> {
    #[inline]
    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        if self.d.len() - self.pos < N {
            return Err(Error::truncated(
                self.file,
                format!("binary data ends inside ${}", self.section),
            ));
        }
        let mut b = [0u8; N];
        b.copy_from_slice(&self.d[self.pos..self.pos + N]);
        if !self.le {
            b.reverse();
        }
        self.pos += N;
        Ok(b)
    }

    #[inline]
    fn i32(&mut self) -> Result<i32> {
        Ok(i32::from_le_bytes(self.take::<4>()?))
    }

    #[inline]
    fn size(&mut self) -> Result<u64> {
        if self.size_t == 4 {
            Ok(u32::from_le_bytes(self.take::<4>()?) as u64)
        } else {
            Ok(u64::from_le_bytes(self.take::<8>()?))
        }
    }

    #[inline]
    fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_le_bytes(self.take::<8>()?))
    }

    fn left(&self) -> usize {
        self.d.len() - self.pos
    }
}

#[derive(Default)]
struct Raw {
    /// 2 for 2.2, 4 for 4.1.
    major: u32,
    binary: bool,
    le: bool,
    size_t: usize,
    names: HashMap<(i64, i64), String>,
    /// Volume entity tag → physical tags.
    vol_phys: HashMap<i64, Vec<i64>>,
    node_tags: Vec<u64>,
    coords: Vec<[f64; 3]>,
    tet_tags: Vec<u64>,
    tet_nodes: Vec<[u64; 4]>,
    /// 4.1: (entity tag, 0); 2.2: (physical tag, elementary tag).
    tet_src: Vec<(i64, i64)>,
    skipped: usize,
    has_nodes: bool,
    has_elements: bool,
}

/// Read a Gmsh tet mesh (4.1 ASCII/binary, 2.2 ASCII) from a stream.
pub fn read_tet<R: std::io::Read>(r: R, file: &str) -> Result<TetRead> {
    parse_tet(&read_all(r, file)?, file)
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// Parse a Gmsh tet mesh held in memory.
pub fn parse_tet(data: &[u8], file: &str) -> Result<TetRead> {
    let mut lx = Lexer::new(data, file, None);
    let mut raw = Raw {
        le: true,
        size_t: 8,
        ..Raw::default()
    };
    let mut toks = Vec::new();
    while let Some(t) = lx.next_token() {
        if t.first() != Some(&b'$') {
            return Err(lx.err(format!("expected a $Section, got '{}'", show(t))));
        }
        let name = &t[1..];
        match name {
            b"MeshFormat" => mesh_format(&mut lx, &mut raw)?,
            b"PhysicalNames" => physical_names(&mut lx, &mut raw)?,
            b"Entities" if raw.major == 4 => entities(&mut lx, &mut raw)?,
            b"Nodes" => {
                if raw.major == 0 {
                    return Err(lx.err("$Nodes before $MeshFormat"));
                }
                nodes(&mut lx, &mut raw)?;
                raw.has_nodes = true;
            }
            b"Elements" => {
                if !raw.has_nodes {
                    return Err(lx.err("$Elements before $Nodes"));
                }
                elements(&mut lx, &mut raw, &mut toks)?;
                raw.has_elements = true;
            }
            _ => {
                // Skip an unknown section (or $Entities of 2.2, which has none).
                let mut end = b"$End".to_vec();
                end.extend_from_slice(name);
                match find(&data[lx.pos..], &end) {
                    Some(i) => {
                        lx.line += data[lx.pos..lx.pos + i]
                            .iter()
                            .filter(|&&c| c == b'\n')
                            .count();
                        lx.pos += i + end.len();
                    }
                    None => {
                        return Err(Error::truncated(
                            file,
                            format!("no ${} closing ${}", show(&end[1..]), show(name)),
                        ));
                    }
                }
                continue;
            }
        }
        let mut end = b"$End".to_vec();
        end.extend_from_slice(name);
        match lx.next_token() {
            Some(e) if e == &end[..] => {}
            Some(e) => {
                return Err(lx.err(format!("expected ${}, got '{}'", show(&end[1..]), show(e))));
            }
            None => {
                return Err(Error::truncated(
                    file,
                    format!("missing ${}", show(&end[1..])),
                ));
            }
        }
    }
    if raw.major == 0 {
        return Err(Error::format(
            file,
            "no $MeshFormat section: not a Gmsh file",
        ));
    }
    if !raw.has_nodes {
        return Err(Error::format(file, "no $Nodes section"));
    }
    if !raw.has_elements {
        return Err(Error::format(file, "no $Elements section"));
    }
    build(raw, file)
}

fn mesh_format(lx: &mut Lexer, raw: &mut Raw) -> Result<()> {
    let v = lx.expect("version")?;
    let ver = lx.tok_f64(v, "version")?;
    let ft = lx.u64("file type")?;
    let ds = lx.u64("data size")?;
    raw.binary = ft == 1;
    if (4.05..5.0).contains(&ver) {
        raw.major = 4;
    } else if (2.0..3.0).contains(&ver) {
        raw.major = 2;
        if raw.binary {
            return Err(lx.err("Gmsh 2.2 binary files are not supported (use 4.1, or 2.2 ASCII)"));
        }
    } else if (4.0..4.05).contains(&ver) {
        return Err(lx.err("Gmsh 4.0 files are not supported (use 4.1 or 2.2)"));
    } else {
        return Err(lx.err(format!("unsupported Gmsh version {}", show(v))));
    }
    if ft > 1 {
        return Err(lx.err(format!("file type {ft}, expected 0 (ASCII) or 1 (binary)")));
    }
    if raw.binary {
        if ds != 4 && ds != 8 {
            return Err(lx.err(format!("data size {ds}, expected 4 or 8")));
        }
        raw.size_t = ds as usize;
        lx.skip_line();
        let d = lx.data;
        if d.len() - lx.pos < 4 {
            return Err(Error::truncated(
                lx.file,
                "binary $MeshFormat lacks its endianness check",
            ));
        }
        let b = [d[lx.pos], d[lx.pos + 1], d[lx.pos + 2], d[lx.pos + 3]];
        raw.le = if i32::from_le_bytes(b) == 1 {
            true
        } else if i32::from_be_bytes(b) == 1 {
            false
        } else {
            return Err(lx.err("bad endianness check in binary $MeshFormat"));
        };
        lx.pos += 4;
    }
    Ok(())
}

fn physical_names(lx: &mut Lexer, raw: &mut Raw) -> Result<()> {
    let (n, _) = lx.count("number of physical names", 6)?;
    for _ in 0..n {
        let dim = lx.i64("dimension")?;
        let tag = lx.i64("physical tag")?;
        let rest = lx.raw_line().trim_ascii();
        let name = if rest.first() == Some(&b'"') {
            let inner = &rest[1..];
            let end = inner.iter().position(|&c| c == b'"').unwrap_or(inner.len());
            &inner[..end]
        } else {
            rest
        };
        raw.names
            .insert((dim, tag), String::from_utf8_lossy(name).into_owned());
    }
    Ok(())
}

fn entities(lx: &mut Lexer, raw: &mut Raw) -> Result<()> {
    let mut counts = [0u64; 4];
    if raw.binary {
        let mut b = bin(lx, raw, "Entities");
        for c in &mut counts {
            *c = b.size()?;
        }
        for (dim, &n) in counts.iter().enumerate() {
            for _ in 0..n {
                let tag = b.i32()? as i64;
                for _ in 0..if dim == 0 { 3 } else { 6 } {
                    b.f64()?;
                }
                let np = b.size()?;
                if np > b.left() as u64 / 4 {
                    return Err(Error::truncated(
                        lx.file,
                        "binary data ends inside $Entities",
                    ));
                }
                let mut phys = Vec::with_capacity(np as usize);
                for _ in 0..np {
                    phys.push(b.i32()? as i64);
                }
                if dim > 0 {
                    let nb = b.size()?;
                    if nb > b.left() as u64 / 4 {
                        return Err(Error::truncated(
                            lx.file,
                            "binary data ends inside $Entities",
                        ));
                    }
                    for _ in 0..nb {
                        b.i32()?;
                    }
                }
                if dim == 3 {
                    raw.vol_phys.insert(tag, phys);
                }
            }
        }
        lx.pos = b.pos;
        return Ok(());
    }
    for c in &mut counts {
        *c = lx.u64("entity count")?;
    }
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let tag = lx.i64("entity tag")?;
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                lx.f64("bounding box coordinate")?;
            }
            let np = lx.u64("number of physical tags")?;
            let mut phys = Vec::new();
            for _ in 0..np {
                phys.push(lx.i64("physical tag")?);
            }
            if dim > 0 {
                let nb = lx.u64("number of bounding entities")?;
                for _ in 0..nb {
                    lx.i64("bounding entity tag")?;
                }
            }
            if dim == 3 {
                raw.vol_phys.insert(tag, phys);
            }
        }
    }
    Ok(())
}

fn bin<'a>(lx: &Lexer<'a>, raw: &Raw, section: &'static str) -> Bin<'a> {
    // Binary data starts right after the section header line.
    let mut pos = lx.pos;
    if lx.data.get(pos) == Some(&b'\r') {
        pos += 1;
    }
    if lx.data.get(pos) == Some(&b'\n') {
        pos += 1;
    }
    Bin {
        d: lx.data,
        pos,
        le: raw.le,
        size_t: raw.size_t,
        file: lx.file,
        section,
    }
}

fn nodes(lx: &mut Lexer, raw: &mut Raw) -> Result<()> {
    if raw.major == 2 {
        let (n, cap) = lx.count("number of nodes", 8)?;
        raw.node_tags.reserve(cap);
        raw.coords.reserve(cap);
        for _ in 0..n {
            raw.node_tags.push(lx.u64("node tag")?);
            let mut p = [0.0; 3];
            for x in &mut p {
                *x = lx.f64("coordinate")?;
            }
            raw.coords.push(p);
        }
        return Ok(());
    }
    if raw.binary {
        let mut b = bin(lx, raw, "Nodes");
        let nblocks = b.size()?;
        let total = b.size()?;
        b.size()?;
        b.size()?;
        let cap = reserve_cap(total as usize, b.left(), 32);
        raw.node_tags.reserve(cap);
        raw.coords.reserve(cap);
        for _ in 0..nblocks {
            let dim = b.i32()?;
            b.i32()?;
            let param = b.i32()?;
            let n = b.size()?;
            let extra = if param != 0 {
                dim.clamp(0, 3) as usize
            } else {
                0
            };
            if n > (b.left() / (raw.size_t + 24)) as u64 {
                return Err(Error::truncated(lx.file, "binary data ends inside $Nodes"));
            }
            for _ in 0..n {
                raw.node_tags.push(b.size()?);
            }
            for i in 0..n {
                let mut p = [0.0; 3];
                for x in &mut p {
                    *x = b.f64()?;
                }
                if p.iter().any(|x| !x.is_finite()) {
                    return Err(Error::element(
                        lx.file,
                        "node",
                        raw.coords.len(),
                        format!("non-finite coordinate {p:?} (block node {i})"),
                    ));
                }
                for _ in 0..extra {
                    b.f64()?;
                }
                raw.coords.push(p);
            }
        }
        lx.pos = b.pos;
        return Ok(());
    }
    let nblocks = lx.u64("number of node blocks")?;
    let (total, cap) = lx.count("number of nodes", 8)?;
    let _ = total;
    lx.u64("min node tag")?;
    lx.u64("max node tag")?;
    raw.node_tags.reserve(cap);
    raw.coords.reserve(cap);
    for _ in 0..nblocks {
        let dim = lx.i64("entity dimension")?;
        lx.i64("entity tag")?;
        let param = lx.u64("parametric flag")?;
        let n = lx.u64("number of nodes in block")?;
        let extra = if param != 0 {
            dim.clamp(0, 3) as usize
        } else {
            0
        };
        let start = raw.node_tags.len();
        for _ in 0..n {
            raw.node_tags.push(lx.u64("node tag")?);
        }
        for _ in start..raw.node_tags.len() {
            let mut p = [0.0; 3];
            for x in &mut p {
                *x = lx.f64("coordinate")?;
            }
            for _ in 0..extra {
                lx.f64("parametric coordinate")?;
            }
            raw.coords.push(p);
        }
    }
    Ok(())
}

fn elements<'a>(lx: &mut Lexer<'a>, raw: &mut Raw, toks: &mut Vec<&'a [u8]>) -> Result<()> {
    if raw.major == 2 {
        let (n, cap) = lx.count("number of elements", 8)?;
        raw.tet_tags.reserve(cap);
        for _ in 0..n {
            if !lx.line_tokens(toks) {
                return Err(Error::truncated(lx.file, "$Elements ends early"));
            }
            if toks.len() < 3 {
                return Err(lx.err(format!("element line with {} numbers", toks.len())));
            }
            let tag = lx.tok_u64(toks[0], "element tag")?;
            let ty = lx.tok_i64(toks[1], "element type")?;
            let nt = lx.tok_u64(toks[2], "number of tags")?.min(1 << 20) as usize;
            if ty != 4 {
                if is_volume(ty) {
                    raw.skipped += 1;
                }
                continue;
            }
            if toks.len() != 3 + nt + 4 {
                return Err(lx.err(format!(
                    "tet line with {} numbers, expected {} (3 + {nt} tags + 4 nodes)",
                    toks.len(),
                    7 + nt
                )));
            }
            let phys = if nt >= 1 {
                lx.tok_i64(toks[3], "physical tag")?
            } else {
                0
            };
            let elem = if nt >= 2 {
                lx.tok_i64(toks[4], "elementary tag")?
            } else {
                -1
            };
            let mut v = [0u64; 4];
            for (x, t) in v.iter_mut().zip(&toks[3 + nt..]) {
                *x = lx.tok_u64(t, "node tag")?;
            }
            raw.tet_tags.push(tag);
            raw.tet_nodes.push(v);
            raw.tet_src.push((phys, elem));
        }
        return Ok(());
    }
    if raw.binary {
        let mut b = bin(lx, raw, "Elements");
        let nblocks = b.size()?;
        let total = b.size()?;
        b.size()?;
        b.size()?;
        let cap = reserve_cap(total as usize, b.left(), 5 * raw.size_t);
        raw.tet_tags.reserve(cap);
        for bi in 0..nblocks {
            b.i32()?;
            let etag = b.i32()? as i64;
            let ty = b.i32()? as i64;
            let n = b.size()?;
            let nn = nodes_of(ty).ok_or_else(|| {
                Error::element(
                    lx.file,
                    "element block",
                    bi as usize,
                    format!("unknown element type {ty}"),
                )
            })?;
            if n > (b.left() / ((nn + 1) * raw.size_t)) as u64 {
                return Err(Error::truncated(
                    lx.file,
                    "binary data ends inside $Elements",
                ));
            }
            if ty != 4 {
                if is_volume(ty) {
                    raw.skipped += n as usize;
                }
                b.pos += n as usize * (nn + 1) * raw.size_t;
                continue;
            }
            for _ in 0..n {
                raw.tet_tags.push(b.size()?);
                let mut v = [0u64; 4];
                for x in &mut v {
                    *x = b.size()?;
                }
                raw.tet_nodes.push(v);
                raw.tet_src.push((etag, 0));
            }
        }
        lx.pos = b.pos;
        return Ok(());
    }
    let nblocks = lx.u64("number of element blocks")?;
    let (_, cap) = lx.count("number of elements", 8)?;
    lx.u64("min element tag")?;
    lx.u64("max element tag")?;
    raw.tet_tags.reserve(cap);
    for _ in 0..nblocks {
        lx.i64("entity dimension")?;
        let etag = lx.i64("entity tag")?;
        let ty = lx.i64("element type")?;
        let n = lx.u64("number of elements in block")?;
        for _ in 0..n {
            if !lx.line_tokens(toks) {
                return Err(Error::truncated(lx.file, "$Elements ends early"));
            }
            if ty != 4 {
                if let Some(nn) = nodes_of(ty)
                    && toks.len() != nn + 1
                {
                    return Err(lx.err(format!(
                        "element of type {ty} with {} numbers, expected {}",
                        toks.len(),
                        nn + 1
                    )));
                }
                if is_volume(ty) {
                    raw.skipped += 1;
                }
                continue;
            }
            if toks.len() != 5 {
                return Err(lx.err(format!(
                    "tet with {} numbers, expected 5 (tag and 4 nodes)",
                    toks.len()
                )));
            }
            raw.tet_tags.push(lx.tok_u64(toks[0], "element tag")?);
            let mut v = [0u64; 4];
            for (x, t) in v.iter_mut().zip(&toks[1..]) {
                *x = lx.tok_u64(t, "node tag")?;
            }
            raw.tet_nodes.push(v);
            raw.tet_src.push((etag, 0));
        }
    }
    Ok(())
}

fn build(raw: Raw, file: &str) -> Result<TetRead> {
    let n = raw.node_tags.len();
    if n > u32::MAX as usize {
        return Err(Error::format(file, "too many nodes for 32-bit indices"));
    }
    if raw.coords.len() != n {
        return Err(Error::truncated(file, "$Nodes ends early"));
    }
    for (i, p) in raw.coords.iter().enumerate() {
        if p.iter().any(|x| !x.is_finite()) {
            return Err(Error::element(
                file,
                "node",
                i,
                format!("non-finite coordinate {p:?}"),
            ));
        }
    }
    // Points in increasing tag order.
    let sorted = raw.node_tags.windows(2).all(|w| w[0] < w[1]);
    let (tags, points): (Vec<u64>, Vec<[f64; 3]>) = if sorted {
        (raw.node_tags, raw.coords)
    } else {
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_unstable_by_key(|&i| raw.node_tags[i as usize]);
        let tags: Vec<u64> = order.iter().map(|&i| raw.node_tags[i as usize]).collect();
        if let Some(w) = tags.windows(2).find(|w| w[0] == w[1]) {
            return Err(Error::format(
                file,
                format!("node tag {} appears twice", w[0]),
            ));
        }
        (
            tags,
            order.iter().map(|&i| raw.coords[i as usize]).collect(),
        )
    };
    let max_tag = tags.last().copied().unwrap_or(0);
    let dense: Option<Vec<u32>> = (max_tag <= 2 * n as u64 + 1024).then(|| {
        let mut d = vec![u32::MAX; max_tag as usize + 1];
        for (i, &t) in tags.iter().enumerate() {
            d[t as usize] = i as u32;
        }
        d
    });
    let lookup = |t: u64| -> Option<u32> {
        match &dense {
            Some(d) => d.get(t as usize).copied().filter(|&i| i != u32::MAX),
            None => tags.binary_search(&t).ok().map(|i| i as u32),
        }
    };
    // Tets in increasing element tag order.
    let m = raw.tet_tags.len();
    let order: Option<Vec<u32>> = (!raw.tet_tags.windows(2).all(|w| w[0] <= w[1])).then(|| {
        let mut o: Vec<u32> = (0..m as u32).collect();
        o.sort_by_key(|&i| raw.tet_tags[i as usize]);
        o
    });
    let phys_label = |tag: i64| -> std::result::Result<u32, String> {
        if let Some(name) = raw.names.get(&(3, tag))
            && let Some(l) = name
                .strip_prefix("region_")
                .and_then(|s| s.parse::<u32>().ok())
        {
            return Ok(l);
        }
        label_of(tag)
    };
    let mut tets = Vec::with_capacity(m);
    let mut labels = Vec::with_capacity(m);
    for k in 0..m {
        let i = order.as_ref().map_or(k, |o| o[k] as usize);
        let mut t = [0u32; 4];
        for (x, &tag) in t.iter_mut().zip(&raw.tet_nodes[i]) {
            *x = lookup(tag).ok_or_else(|| {
                Error::element(
                    file,
                    "tet",
                    i,
                    format!(
                        "node tag {tag} not in $Nodes (element tag {})",
                        raw.tet_tags[i]
                    ),
                )
            })?;
        }
        let (a, b) = raw.tet_src[i];
        let label = if raw.major == 4 {
            match raw.vol_phys.get(&a).and_then(|p| p.first()) {
                Some(&p) => phys_label(p),
                None => label_of(a),
            }
        } else if a != 0 {
            phys_label(a)
        } else if b >= 0 {
            label_of(b)
        } else {
            Ok(1)
        };
        labels.push(label.map_err(|e| Error::element(file, "tet", i, e))?);
        tets.push(t);
    }
    let (flipped, degenerate) = orient_tets(&points, &mut tets);
    Ok(TetRead {
        mesh: TetMesh::new(points, tets, labels),
        flipped,
        degenerate,
        skipped_elements: raw.skipped,
    })
}

/// ASCII or binary output of the 4.1 format's numbers.
struct G<W: Write> {
    out: Out<W>,
    bin: bool,
}

impl<W: Write> G<W> {
    #[inline]
    fn i(&mut self, x: i64) {
        if self.bin {
            self.out.bytes(&(x as i32).to_le_bytes());
        } else {
            self.out.int(x);
            self.out.c(b' ');
        }
    }
    #[inline]
    fn z(&mut self, x: u64) {
        if self.bin {
            self.out.bytes(&x.to_le_bytes());
        } else {
            self.out.int(x);
            self.out.c(b' ');
        }
    }
    #[inline]
    fn f(&mut self, x: f64) {
        if self.bin {
            self.out.bytes(&x.to_le_bytes());
        } else {
            self.out.f64(x);
            self.out.c(b' ');
        }
    }
    /// End of a text line (drops the trailing space).
    #[inline]
    fn nl(&mut self) {
        if !self.bin {
            if self.out.buf.last() == Some(&b' ') {
                self.out.buf.pop();
            }
            self.out.c(b'\n');
        }
    }
    /// Close a section: binary data is followed by a newline before `$End...`.
    fn end(&mut self, name: &str) {
        if self.bin {
            self.out.c(b'\n');
        }
        self.out.s("$End");
        self.out.s(name);
        self.out.c(b'\n');
    }
    fn check(&mut self, file: &str) -> Result<()> {
        self.out.check().map_err(|e| Error::io(file, e))
    }
}

/// Write a tet mesh as Gmsh 4.1 ASCII.
pub fn write_tet<W: Write>(w: W, mesh: &TetMesh, file: &str) -> Result<()> {
    write41(w, mesh, file, false)
}

/// Write a tet mesh as Gmsh 4.1 binary (little endian, 8-byte `size_t`).
pub fn write_tet_binary<W: Write>(w: W, mesh: &TetMesh, file: &str) -> Result<()> {
    write41(w, mesh, file, true)
}

fn bbox(b: &mut [f64; 6], p: [f64; 3]) {
    for k in 0..3 {
        b[k] = b[k].min(p[k]);
        b[k + 3] = b[k + 3].max(p[k]);
    }
}

fn write41<W: Write>(w: W, mesh: &TetMesh, file: &str, bin: bool) -> Result<()> {
    check_tet(mesh, file)?;
    let npts = mesh.points.len();
    let nt = mesh.tets.len();
    let groups = face_groups(mesh);
    let ns = groups.groups.len();
    let mut regions = mesh.regions();
    let named_volumes = !regions.is_empty();
    if regions.is_empty() {
        // A volume entity to hold the nodes of a mesh without tets.
        regions.push(0);
    }
    let nv = regions.len();
    if nv > i32::MAX as usize || ns > i32::MAX as usize {
        return Err(Error::invalid(
            file,
            "too many regions for Gmsh entity tags",
        ));
    }
    let max_label = *regions.last().unwrap_or(&0);
    let phys_of = |label: u32| -> Result<i64> {
        let p = if label > 0 {
            label as i64
        } else {
            max_label as i64 + 1
        };
        if p > i32::MAX as i64 {
            return Err(Error::invalid(
                file,
                format!("label {label} does not fit a Gmsh physical tag"),
            ));
        }
        Ok(p)
    };
    let vol_of_tet: Vec<u32> = mesh
        .labels
        .iter()
        .map(|l| regions.binary_search(l).unwrap_or(0) as u32)
        .collect();
    // Node classification: entity index (surfaces 0..ns, volumes ns..ns+nv).
    let mut ent = vec![u32::MAX; npts];
    for (f, &g) in groups.faces.iter().zip(&groups.group_of) {
        for &v in f {
            if ent[v as usize] == u32::MAX {
                ent[v as usize] = g;
            }
        }
    }
    for (t, &vi) in mesh.tets.iter().zip(&vol_of_tet) {
        for &v in t {
            if ent[v as usize] == u32::MAX {
                ent[v as usize] = ns as u32 + vi;
            }
        }
    }
    let ne = ns + nv;
    let mut node_count = vec![0usize; ne];
    for e in &mut ent {
        if *e == u32::MAX {
            *e = ns as u32; // orphan points: first volume
        }
        node_count[*e as usize] += 1;
    }
    // Bounding boxes.
    let mut boxes = vec![
        [
            f64::INFINITY,
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY
        ];
        ne
    ];
    for (f, &g) in groups.faces.iter().zip(&groups.group_of) {
        for &v in f {
            bbox(&mut boxes[g as usize], mesh.points[v as usize]);
        }
    }
    for (t, &vi) in mesh.tets.iter().zip(&vol_of_tet) {
        for &v in t {
            bbox(&mut boxes[ns + vi as usize], mesh.points[v as usize]);
        }
    }
    for (p, &e) in mesh.points.iter().zip(&ent) {
        bbox(&mut boxes[e as usize], *p);
    }
    for b in &mut boxes {
        if b[0] > b[3] {
            *b = [0.0; 6];
        }
    }

    let mut g = G {
        out: Out::new(w),
        bin,
    };
    g.out.s(if bin {
        "$MeshFormat\n4.1 1 8\n"
    } else {
        "$MeshFormat\n4.1 0 8\n"
    });
    if bin {
        g.out.bytes(&1i32.to_le_bytes());
    }
    g.end("MeshFormat");

    // $PhysicalNames (always text).
    g.out.s("$PhysicalNames\n");
    g.out.int(if named_volumes { nv } else { 0 } + ns);
    g.out.c(b'\n');
    if named_volumes {
        for &l in &regions {
            g.out.s("3 ");
            g.out.int(phys_of(l)?);
            g.out.s(" \"region_");
            g.out.int(l);
            g.out.s("\"\n");
        }
    }
    for (k, grp) in groups.groups.iter().enumerate() {
        g.out.s("2 ");
        g.out.int(k + 1);
        g.out.s(" \"");
        g.out.s(&grp.name());
        g.out.s("\"\n");
    }
    g.out.s("$EndPhysicalNames\n");

    // $Entities.
    g.out.s("$Entities\n");
    if !bin {
        g.out.s("0 0 ");
        g.out.int(ns);
        g.out.c(b' ');
        g.out.int(nv);
        g.out.c(b'\n');
    } else {
        for c in [0, 0, ns as u64, nv as u64] {
            g.z(c);
        }
    }
    for (k, b) in boxes.iter().enumerate().take(ns) {
        g.i(k as i64 + 1);
        for &x in b {
            g.f(x);
        }
        g.z(1);
        g.i(k as i64 + 1);
        g.z(0);
        g.nl();
    }
    for (vi, &l) in regions.iter().enumerate() {
        g.i(vi as i64 + 1);
        for &x in &boxes[ns + vi] {
            g.f(x);
        }
        if named_volumes {
            g.z(1);
            g.i(phys_of(l)?);
        } else {
            g.z(0);
        }
        let bounding: Vec<i64> = groups
            .groups
            .iter()
            .enumerate()
            .filter_map(|(k, grp)| {
                if grp.a == l {
                    Some(k as i64 + 1)
                } else if grp.interface && grp.b == l {
                    Some(-(k as i64 + 1))
                } else {
                    None
                }
            })
            .collect();
        g.z(bounding.len() as u64);
        for s in bounding {
            g.i(s);
        }
        g.nl();
    }
    g.end("Entities");

    // $Nodes: one block per entity with nodes.
    let mut by_ent: Vec<Vec<u32>> = node_count.iter().map(|&c| Vec::with_capacity(c)).collect();
    for (i, &e) in ent.iter().enumerate() {
        by_ent[e as usize].push(i as u32);
    }
    let blocks = by_ent.iter().filter(|b| !b.is_empty()).count();
    g.out.s("$Nodes\n");
    g.z(blocks as u64);
    g.z(npts as u64);
    g.z(if npts > 0 { 1 } else { 0 });
    g.z(npts as u64);
    g.nl();
    for (e, nodes) in by_ent.iter().enumerate() {
        if nodes.is_empty() {
            continue;
        }
        let (dim, tag) = if e < ns { (2, e + 1) } else { (3, e - ns + 1) };
        g.i(dim);
        g.i(tag as i64);
        g.i(0);
        g.z(nodes.len() as u64);
        g.nl();
        for &v in nodes {
            g.z(v as u64 + 1);
            g.nl();
            g.check(file)?;
        }
        for &v in nodes {
            for x in mesh.points[v as usize] {
                g.f(x);
            }
            g.nl();
            g.check(file)?;
        }
    }
    g.end("Nodes");

    // $Elements: tets per volume, then triangles per surface.
    let mut tets_by_vol: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (t, &vi) in vol_of_tet.iter().enumerate() {
        tets_by_vol[vi as usize].push(t as u32);
    }
    let mut face_start = vec![0usize; ns + 1];
    for &gi in &groups.group_of {
        face_start[gi as usize + 1] += 1;
    }
    for k in 0..ns {
        face_start[k + 1] += face_start[k];
    }
    let nf = groups.faces.len();
    let blocks = tets_by_vol.iter().filter(|b| !b.is_empty()).count()
        + (0..ns)
            .filter(|&k| face_start[k + 1] > face_start[k])
            .count();
    g.out.s("$Elements\n");
    g.z(blocks as u64);
    g.z((nt + nf) as u64);
    g.z(if nt + nf > 0 { 1 } else { 0 });
    g.z((nt + nf) as u64);
    g.nl();
    for (vi, tets) in tets_by_vol.iter().enumerate() {
        if tets.is_empty() {
            continue;
        }
        g.i(3);
        g.i(vi as i64 + 1);
        g.i(4);
        g.z(tets.len() as u64);
        g.nl();
        for &t in tets {
            g.z(t as u64 + 1);
            for v in mesh.tets[t as usize] {
                g.z(v as u64 + 1);
            }
            g.nl();
            g.check(file)?;
        }
    }
    for k in 0..ns {
        let (a, b) = (face_start[k], face_start[k + 1]);
        if a == b {
            continue;
        }
        g.i(2);
        g.i(k as i64 + 1);
        g.i(2);
        g.z((b - a) as u64);
        g.nl();
        for f in a..b {
            g.z((nt + f + 1) as u64);
            for v in groups.faces[f] {
                g.z(v as u64 + 1);
            }
            g.nl();
            g.check(file)?;
        }
    }
    g.end("Elements");
    g.out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}
