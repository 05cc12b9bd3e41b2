//! Stanford PLY: ASCII, binary little endian and binary big endian.
//!
//! Reading: the `vertex` element must have scalar properties `x`, `y`, `z` (any numeric type;
//! other properties such as normals or colours are ignored). The `face` element must have a
//! list property `vertex_indices` or `vertex_index` (any integer count and index types); faces
//! with more than three corners are fan-triangulated and counted in
//! [`SurfaceRead::polygons_split`]. An integer scalar face property named `ref`, `label`,
//! `region` or `marker` becomes [`SurfaceRead::triangle_refs`]. Other elements are skipped.
//!
//! Two region labels per face, `[back, front]` as in [`SurfaceMesh::sides`] (the front is where
//! the right-hand normal of the corner order points; 0 = the outside), become
//! [`SurfaceRead::side_labels`]: integer scalar properties `label_back` and `label_front` (or
//! `region_back` and `region_front`), or a two-item integer list property `sides`,
//! `boundary_labels` or `BoundaryLabels` (back first). A polygon's fan triangles share its labels.
//!
//! Writing: [`write_binary`] (little endian, `double` coordinates, `uchar`/`int` face lists)
//! and [`write_ascii`] (shortest round-trip coordinates); a surface with some side other than
//! `[1, 0]` also gets `uint label_back` and `uint label_front` face properties.

use std::io::Write;

use biotet::SurfaceMesh;

use crate::SurfaceRead;
use crate::common::{check_surface, read_all};
use crate::error::{Error, Result};
use crate::text::{Lexer, Out, reserve_cap, show, write_points_and_counted_triangles};

/// Read a PLY surface from a stream; `file` names it in errors.
pub fn read<R: std::io::Read>(r: R, file: &str) -> Result<SurfaceRead> {
    parse(&read_all(r, file)?, file)
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(t: &[u8]) -> Option<Ty> {
        Some(match t {
            b"char" | b"int8" => Ty::I8,
            b"uchar" | b"uint8" => Ty::U8,
            b"short" | b"int16" => Ty::I16,
            b"ushort" | b"uint16" => Ty::U16,
            b"int" | b"int32" => Ty::I32,
            b"uint" | b"uint32" => Ty::U32,
            b"float" | b"float32" => Ty::F32,
            b"double" | b"float64" => Ty::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }

    fn is_int(self) -> bool {
        !matches!(self, Ty::F32 | Ty::F64)
    }
}

#[derive(Debug)]
struct Prop {
    name: Vec<u8>,
    /// `Some(count type)` for a list.
    list: Option<Ty>,
    ty: Ty,
}

#[derive(Debug)]
struct Element {
    name: Vec<u8>,
    count: usize,
    props: Vec<Prop>,
}

#[derive(Clone, Copy, PartialEq)]
enum Fmt {
    Ascii,
    Le,
    Be,
}

/// Reads values of one element record, from text tokens or binary bytes.
struct Src<'a> {
    fmt: Fmt,
    lx: Lexer<'a>,
    file: &'a str,
}

impl Src<'_> {
    fn value(&mut self, ty: Ty, what: &str, elem: &'static str, index: usize) -> Result<f64> {
        if self.fmt == Fmt::Ascii {
            let t = self.lx.next_token().ok_or_else(|| {
                Error::truncated(self.file, format!("data ends inside {elem} {index}"))
            })?;
            let v = self.lx.tok_f64(t, what)?;
            if ty.is_int() && v.fract() != 0.0 {
                return Err(self
                    .lx
                    .err(format!("expected an integer {what}, got '{}'", show(t))));
            }
            return Ok(v);
        }
        let n = ty.size();
        let d = self.lx.data;
        let p = self.lx.pos;
        if d.len() - p < n {
            return Err(Error::truncated(
                self.file,
                format!("binary data ends inside {elem} {index}"),
            ));
        }
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(&d[p..p + n]);
        if self.fmt == Fmt::Be {
            b[..n].reverse();
        }
        self.lx.pos += n;
        Ok(match ty {
            Ty::I8 => b[0] as i8 as f64,
            Ty::U8 => b[0] as f64,
            Ty::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Ty::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Ty::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Ty::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Ty::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Ty::F64 => f64::from_le_bytes(b),
        })
    }

    /// Error for record `index` of `elem`, with the line for ASCII data.
    fn err(&self, elem: &'static str, index: usize, msg: String) -> Error {
        if self.fmt == Fmt::Ascii {
            self.lx.err(msg)
        } else {
            Error::element(self.file, elem, index, msg)
        }
    }
}

/// Parse a PLY surface held in memory.
pub fn parse(data: &[u8], file: &str) -> Result<SurfaceRead> {
    let mut lx = Lexer::new(data, file, None);
    let first = lx.raw_line();
    if first.trim_ascii() != b"ply" {
        return Err(Error::line(
            file,
            1,
            "not a PLY file (first line is not 'ply')",
        ));
    }
    let mut fmt = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut toks: Vec<&[u8]> = Vec::new();
    loop {
        if lx.pos >= data.len() {
            return Err(Error::truncated(file, "PLY header without 'end_header'"));
        }
        let line_no = lx.line;
        let raw = lx.raw_line();
        let mut sub = Lexer::new(raw, file, None);
        sub.rest_of_line(&mut toks);
        let err = |m: String| Error::line(file, line_no, m);
        let Some(&kw) = toks.first() else { continue };
        match kw {
            b"end_header" => break,
            b"comment" | b"obj_info" => {}
            b"format" => {
                if toks.len() < 2 {
                    return Err(err("expected a format after 'format'".into()));
                }
                fmt = Some(match toks[1] {
                    b"ascii" => Fmt::Ascii,
                    b"binary_little_endian" => Fmt::Le,
                    b"binary_big_endian" => Fmt::Be,
                    f => return Err(err(format!("unknown PLY format '{}'", show(f)))),
                });
            }
            b"element" => {
                if toks.len() < 3 {
                    return Err(err("expected 'element <name> <count>'".into()));
                }
                let count = sub
                    .tok_u64(toks[2], "element count")
                    .map_err(|_| err(format!("bad element count '{}'", show(toks[2]))))?;
                let count =
                    usize::try_from(count).map_err(|_| err("element count too large".into()))?;
                // A second vertex or face element would mix two meshes' indices and labels.
                let name = toks[1];
                if (name == b"vertex" || name == b"face") && elements.iter().any(|e| e.name == name)
                {
                    return Err(err(format!("a second '{}' element", show(name))));
                }
                elements.push(Element {
                    name: toks[1].to_vec(),
                    count,
                    props: Vec::new(),
                });
            }
            b"property" => {
                let Some(el) = elements.last_mut() else {
                    return Err(err("'property' before any 'element'".into()));
                };
                let bad = |t: &[u8]| err(format!("unknown property type '{}'", show(t)));
                if toks.get(1) == Some(&&b"list"[..]) {
                    if toks.len() < 5 {
                        return Err(err(
                            "expected 'property list <count type> <item type> <name>'".into(),
                        ));
                    }
                    let ct = Ty::parse(toks[2]).ok_or_else(|| bad(toks[2]))?;
                    if !ct.is_int() {
                        return Err(err("list count type must be an integer type".into()));
                    }
                    let ty = Ty::parse(toks[3]).ok_or_else(|| bad(toks[3]))?;
                    el.props.push(Prop {
                        name: toks[4].to_vec(),
                        list: Some(ct),
                        ty,
                    });
                } else {
                    if toks.len() < 3 {
                        return Err(err("expected 'property <type> <name>'".into()));
                    }
                    let ty = Ty::parse(toks[1]).ok_or_else(|| bad(toks[1]))?;
                    el.props.push(Prop {
                        name: toks[2].to_vec(),
                        list: None,
                        ty,
                    });
                }
            }
            _ => return Err(err(format!("unknown PLY header line '{}'", show(kw)))),
        }
    }
    let fmt = fmt.ok_or_else(|| Error::format(file, "PLY header has no 'format' line"))?;
    let mut src = Src {
        fmt,
        lx: Lexer::new(data, file, None),
        file,
    };
    src.lx.pos = lx.pos;
    src.lx.line = lx.line;

    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut refs: Vec<i32> = Vec::new();
    let mut has_refs = false;
    // The face properties holding the two side labels, and the labels of each triangle.
    let mut side_props: Option<SideProps> = None;
    let mut sides: Vec<[u32; 2]> = Vec::new();
    let mut have_vertices = false;
    let mut split = 0;
    let mut corners: Vec<u32> = Vec::new();
    for el in &elements {
        let left = data.len() - src.lx.pos;
        let is_vertex = el.name == b"vertex";
        let is_face = el.name == b"face";
        let (xyz, idx_prop, ref_prop) = if is_vertex {
            let find = |n: &[u8]| {
                el.props
                    .iter()
                    .position(|p| p.name == n && p.list.is_none())
            };
            let (Some(x), Some(y), Some(z)) = (find(b"x"), find(b"y"), find(b"z")) else {
                return Err(Error::format(
                    file,
                    "PLY vertex element lacks scalar x, y, z properties",
                ));
            };
            points.reserve(reserve_cap(el.count, left, 3));
            have_vertices = true;
            ([x, y, z], None, None)
        } else if is_face {
            let li = el
                .props
                .iter()
                .position(|p| {
                    p.list.is_some() && (p.name == b"vertex_indices" || p.name == b"vertex_index")
                })
                .ok_or_else(|| {
                    Error::format(file, "PLY face element lacks a 'vertex_indices' list")
                })?;
            if !el.props[li].ty.is_int() {
                return Err(Error::format(
                    file,
                    "PLY vertex_indices must have an integer type",
                ));
            }
            let ri = el.props.iter().position(|p| {
                p.list.is_none()
                    && p.ty.is_int()
                    && matches!(&p.name[..], b"ref" | b"label" | b"region" | b"marker")
            });
            has_refs = ri.is_some();
            side_props = side_label_props(&el.props, li);
            triangles.reserve(reserve_cap(el.count, left, 4));
            ([usize::MAX; 3], Some(li), ri)
        } else {
            ([usize::MAX; 3], None, None)
        };
        let what: &'static str = if is_vertex {
            "vertex"
        } else if is_face {
            "face"
        } else {
            "element"
        };
        if el.props.is_empty() {
            continue;
        }
        for r in 0..el.count {
            let mut p = [0.0; 3];
            let mut refv = 0i32;
            let mut side = [0u32; 2];
            for (pi, prop) in el.props.iter().enumerate() {
                if let Some(ct) = prop.list {
                    let n = src.value(ct, "list length", what, r)?;
                    if n < 0.0 {
                        return Err(src.err(what, r, format!("negative list length {n}")));
                    }
                    let n = n as usize;
                    if Some(pi) == idx_prop {
                        if n < 3 {
                            return Err(src.err(
                                what,
                                r,
                                format!("face with {n} corners, need at least 3"),
                            ));
                        }
                        if !have_vertices {
                            return Err(Error::format(
                                file,
                                "PLY face element before the vertex element",
                            ));
                        }
                        corners.clear();
                        for _ in 0..n {
                            let v = src.value(prop.ty, "vertex index", what, r)?;
                            if v < 0.0 || v >= points.len() as f64 {
                                return Err(src.err(
                                    what,
                                    r,
                                    format!(
                                        "vertex index {v} out of range ({} vertices)",
                                        points.len()
                                    ),
                                ));
                            }
                            corners.push(v as u32);
                        }
                    } else if is_face && side_props == Some(SideProps::List(pi)) {
                        if n != 2 {
                            return Err(src.err(
                                what,
                                r,
                                format!(
                                    "list '{}' has {n} items, expected 2 (back and front labels)",
                                    show(&prop.name)
                                ),
                            ));
                        }
                        for x in &mut side {
                            let v = src.value(prop.ty, "side label", what, r)?;
                            *x = ply_side_label(v, prop, &src, what, r)?;
                        }
                    } else {
                        if fmt != Fmt::Ascii
                            && n.saturating_mul(prop.ty.size()) > data.len() - src.lx.pos
                        {
                            return Err(Error::truncated(
                                file,
                                format!("binary data ends inside {what} {r}"),
                            ));
                        }
                        for _ in 0..n {
                            src.value(prop.ty, "list item", what, r)?;
                        }
                    }
                } else {
                    let v = src.value(prop.ty, "property value", what, r)?;
                    if let Some(k) = xyz.iter().position(|&i| i == pi) {
                        if !v.is_finite() {
                            return Err(src.err(what, r, format!("non-finite coordinate {v}")));
                        }
                        p[k] = v;
                    } else if Some(pi) == ref_prop {
                        refv = i32::try_from(v as i64).map_err(|_| {
                            src.err(what, r, format!("ref {v} does not fit a 32-bit integer"))
                        })?;
                    } else if let Some(SideProps::Pair(b, f)) = side_props
                        && is_face
                        && (pi == b || pi == f)
                    {
                        side[usize::from(pi == f)] = ply_side_label(v, prop, &src, what, r)?;
                    }
                }
            }
            if is_vertex {
                if points.len() >= u32::MAX as usize {
                    return Err(Error::format(file, "too many vertices for 32-bit indices"));
                }
                points.push(p);
            } else if is_face {
                for t in crate::common::fan(&corners, &mut split) {
                    triangles.push(t);
                    if has_refs {
                        refs.push(refv);
                    }
                    if side_props.is_some() {
                        sides.push(side);
                    }
                }
            }
        }
    }
    Ok(SurfaceRead {
        mesh: SurfaceMesh::closed(points, triangles, 1),
        triangle_refs: has_refs.then_some(refs),
        side_labels: side_props.is_some().then_some(sides),
        welded: 0,
        polygons_split: split,
    })
}

/// Where a face element keeps its two side labels.
#[derive(Debug, Clone, Copy, PartialEq)]
enum SideProps {
    /// Two integer scalar properties: back, front.
    Pair(usize, usize),
    /// An integer list property of two items: back, front.
    List(usize),
}

/// Names of the scalar property pairs holding the side labels, `(back, front)`.
const SIDE_PAIRS: [(&[u8], &[u8]); 2] = [
    (b"label_back", b"label_front"),
    (b"region_back", b"region_front"),
];
/// Names of the two-item list properties holding the side labels (back first).
const SIDE_LISTS: [&[u8]; 3] = [b"sides", b"boundary_labels", b"BoundaryLabels"];

/// The side-label properties of a face element whose corner list is property `corners`.
fn side_label_props(props: &[Prop], corners: usize) -> Option<SideProps> {
    let scalar = |n: &[u8]| {
        props
            .iter()
            .position(|p| p.list.is_none() && p.ty.is_int() && p.name == n)
    };
    for (b, f) in SIDE_PAIRS {
        if let (Some(b), Some(f)) = (scalar(b), scalar(f)) {
            return Some(SideProps::Pair(b, f));
        }
    }
    SIDE_LISTS.iter().find_map(|n| {
        props
            .iter()
            .enumerate()
            .position(|(i, p)| i != corners && p.list.is_some() && p.ty.is_int() && p.name == *n)
            .map(SideProps::List)
    })
}

/// A side label read as `v` from `prop`.
fn ply_side_label(v: f64, prop: &Prop, src: &Src, what: &'static str, r: usize) -> Result<u32> {
    crate::common::side_label_of(v as i64)
        .map_err(|e| src.err(what, r, format!("property '{}': {e}", show(&prop.name))))
}

/// Whether a surface carries labels worth writing (any side other than `[1, 0]`).
fn labelled(mesh: &SurfaceMesh) -> bool {
    mesh.sides.len() == mesh.triangles.len() && mesh.sides.iter().any(|s| *s != [1, 0])
}

fn header<W: Write>(out: &mut Out<W>, fmt: &str, mesh: &SurfaceMesh) {
    out.s("ply\nformat ");
    out.s(fmt);
    out.s(" 1.0\ncomment written by biotet\nelement vertex ");
    out.int(mesh.points.len());
    out.s("\nproperty double x\nproperty double y\nproperty double z\nelement face ");
    out.int(mesh.triangles.len());
    out.s("\nproperty list uchar ");
    out.s(if mesh.points.len() <= i32::MAX as usize {
        "int"
    } else {
        "uint"
    });
    out.s(" vertex_indices\n");
    if labelled(mesh) {
        out.s("property uint label_back\nproperty uint label_front\n");
    }
    out.s("end_header\n");
}

/// Write a binary little-endian PLY surface (with `label_back`, `label_front` face properties
/// when some side is not `[1, 0]`).
pub fn write_binary<W: Write>(w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    check_surface(mesh, file)?;
    let labels = labelled(mesh);
    let mut out = Out::new(w);
    header(&mut out, "binary_little_endian", mesh);
    for p in &mesh.points {
        for &x in p {
            out.bytes(&x.to_le_bytes());
        }
        out.check().map_err(|e| Error::io(file, e))?;
    }
    for (i, t) in mesh.triangles.iter().enumerate() {
        out.c(3);
        for &v in t {
            out.bytes(&v.to_le_bytes());
        }
        if labels {
            for l in mesh.sides[i] {
                out.bytes(&l.to_le_bytes());
            }
        }
        out.check().map_err(|e| Error::io(file, e))?;
    }
    out.finish().map_err(|e| Error::io(file, e))?;
    Ok(())
}

/// Write an ASCII PLY surface (labels as in [`write_binary`]).
pub fn write_ascii<W: Write>(w: W, mesh: &SurfaceMesh, file: &str) -> Result<()> {
    check_surface(mesh, file)?;
    let mut out = Out::new(w);
    header(&mut out, "ascii", mesh);
    write_points_and_counted_triangles(out, mesh, file, labelled(mesh))
}
