//! Streaming VTU output: every `DataArray` is produced in chunks of tuples and encoded straight
//! into the output, so a writer never holds a whole array, let alone all of them. The appended raw
//! layout needs only each array's length up front (for the offsets); base64 carries at most two
//! bytes between chunks. Compressed encodings hold the compressed blocks (of every array for
//! appended data, whose offsets depend on them; of one array at a time inline), never the raw
//! bytes.

use std::io::Write;
use std::ops::Range;

use crate::b64;
use crate::error::{Error, Result};
use crate::text::Out;
use crate::vtu::VtuEncoding;

/// Tuples per chunk when writing files: small beside any mesh worth streaming (a chunk of
/// points and its bytes take 0.8 MB; at 2^16 tuples they took 3 MB, most of the writer's peak on
/// brain_20k), large enough that the per-chunk work (a parallel quality pass) is not dominated
/// by thread start-up.
pub(crate) const CHUNK: usize = 1 << 14;
/// Bytes per zlib block (VTK's layout: independently compressed blocks of this size).
const ZBLOCK: usize = 1 << 16;

/// Value type of an array.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Ty {
    F64,
    I32,
    I64,
    U8,
}

impl Ty {
    fn name(self) -> &'static str {
        match self {
            Ty::F64 => "Float64",
            Ty::I32 => "Int32",
            Ty::I64 => "Int64",
            Ty::U8 => "UInt8",
        }
    }

    fn size(self) -> usize {
        match self {
            Ty::F64 | Ty::I64 => 8,
            Ty::I32 => 4,
            Ty::U8 => 1,
        }
    }
}

/// The values of one chunk of an array.
pub(crate) enum Data {
    F64(Vec<f64>),
    I32(Vec<i32>),
    I64(Vec<i64>),
    U8(Vec<u8>),
}

impl Data {
    /// Append the values' little-endian bytes to `out`.
    fn le_bytes(&self, out: &mut Vec<u8>) {
        match self {
            Data::F64(v) => v
                .iter()
                .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
            Data::I32(v) => v
                .iter()
                .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
            Data::I64(v) => v
                .iter()
                .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
            Data::U8(v) => out.extend_from_slice(v),
        }
    }
}

/// Makes the values of the tuples in a range (`ncomp` values per tuple, of the array's type).
pub(crate) type Fill<'a> = Box<dyn Fn(Range<usize>) -> Data + 'a>;

/// One `DataArray`, produced on demand.
pub(crate) struct Array<'a> {
    pub name: &'static str,
    pub ncomp: usize,
    pub ty: Ty,
    /// Number of tuples.
    pub n: usize,
    pub fill: Fill<'a>,
}

impl<'a> Array<'a> {
    /// An array of `n` tuples of `ncomp` values of type `ty`, made by `fill`.
    pub fn new(
        name: &'static str,
        ncomp: usize,
        ty: Ty,
        n: usize,
        fill: impl Fn(Range<usize>) -> Data + 'a,
    ) -> Array<'a> {
        Array {
            name,
            ncomp,
            ty,
            n,
            fill: Box::new(fill),
        }
    }

    fn nbytes(&self) -> usize {
        self.n * self.ncomp * self.ty.size()
    }

    /// The array's values, `chunk` tuples at a time.
    fn chunks(&self, chunk: usize) -> impl Iterator<Item = Data> + '_ {
        let n = self.n;
        (0..n)
            .step_by(chunk.max(1))
            .map(move |lo| (self.fill)(lo..(lo + chunk).min(n)))
    }

    /// The array's bytes, a piece at a time, through `f` (the scratch buffer is reused).
    fn for_each_bytes(&self, chunk: usize, mut f: impl FnMut(&[u8]) -> Result<()>) -> Result<()> {
        let mut bytes = Vec::new();
        for d in self.chunks(chunk) {
            bytes.clear();
            d.le_bytes(&mut bytes);
            f(&bytes)?;
        }
        Ok(())
    }
}

/// `f(i)` for every `i` in `r`, on `threads` scoped threads (at least 4096 values each).
pub(crate) fn par_map(r: Range<usize>, threads: usize, f: &(dyn Fn(usize) -> f64 + Sync)) -> Data {
    let mut out = vec![0.0; r.len()];
    let per = r.len().div_ceil(threads.max(1)).max(4096);
    if per >= r.len() {
        // One part: no thread to start.
        for (x, i) in out.iter_mut().zip(r) {
            *x = f(i);
        }
        return Data::F64(out);
    }
    std::thread::scope(|s| {
        for (k, part) in out.chunks_mut(per).enumerate() {
            let lo = r.start + k * per;
            s.spawn(move || {
                for (i, x) in part.iter_mut().enumerate() {
                    *x = f(lo + i);
                }
            });
        }
    });
    Data::F64(out)
}

/// Threads for the per-tet quality arrays: one per core, at most 16.
pub(crate) fn threads() -> usize {
    std::thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(16)
}

/// Base64 of a byte stream fed in pieces: the same text as encoding the concatenation at once.
#[derive(Default)]
struct B64Stream {
    carry: [u8; 3],
    n: usize,
}

impl B64Stream {
    fn push(&mut self, mut data: &[u8], out: &mut Vec<u8>) {
        if self.n > 0 {
            let take = (3 - self.n).min(data.len());
            self.carry[self.n..self.n + take].copy_from_slice(&data[..take]);
            self.n += take;
            data = &data[take..];
            if self.n < 3 {
                return;
            }
            b64::encode(&self.carry, out);
            self.n = 0;
        }
        let whole = data.len() / 3 * 3;
        b64::encode(&data[..whole], out);
        self.n = data.len() - whole;
        self.carry[..self.n].copy_from_slice(&data[whole..]);
    }

    fn finish(self, out: &mut Vec<u8>) {
        b64::encode(&self.carry[..self.n], out);
    }
}

/// VTK's zlib layout of an array: header `[nblocks, blocksize, lastsize, csize...]` and the
/// compressed blocks, made from the array's chunks without holding its raw bytes.
fn compress(a: &Array, chunk: usize, file: &str) -> Result<(Vec<u8>, Vec<u8>)> {
    let nbytes = a.nbytes();
    let mut header = Vec::new();
    for x in [nbytes.div_ceil(ZBLOCK), ZBLOCK, nbytes % ZBLOCK] {
        header.extend_from_slice(&(x as u64).to_le_bytes());
    }
    let mut payload = Vec::new();
    let mut block = |b: &[u8]| -> Result<()> {
        let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
        e.write_all(b).map_err(|e| Error::io(file, e))?;
        let z = e.finish().map_err(|e| Error::io(file, e))?;
        header.extend_from_slice(&(z.len() as u64).to_le_bytes());
        payload.extend_from_slice(&z);
        Ok(())
    };
    let mut stage = Vec::new();
    for d in a.chunks(chunk) {
        d.le_bytes(&mut stage);
        let full = stage.len() / ZBLOCK * ZBLOCK;
        for b in stage[..full].chunks(ZBLOCK) {
            block(b)?;
        }
        stage.drain(..full);
    }
    if !stage.is_empty() {
        block(&stage)?;
    }
    Ok((header, payload))
}

/// The kind of VTK XML grid [`write_grid`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Grid {
    /// `UnstructuredGrid` (`.vtu`): cells as connectivity, offsets and types.
    Unstructured,
    /// `PolyData` (`.vtp`): polygons as connectivity and offsets.
    Poly,
}

/// Write a grid of `sizes = (points, cells)` from its arrays: `Points`, the cell arrays (three
/// for [`Grid::Unstructured`], two polygon arrays for [`Grid::Poly`]), then cell data from index
/// `first_cell_array` on, `scalars` the active one. Arrays are made and encoded `chunk` tuples at
/// a time.
#[allow(clippy::too_many_arguments)]
pub(crate) fn write_grid<W: Write>(
    w: W,
    grid: Grid,
    sizes: (usize, usize),
    arrays: &[Array],
    (first_cell_array, scalars): (usize, &str),
    file: &str,
    enc: VtuEncoding,
    chunk: usize,
) -> Result<()> {
    let zlib = matches!(enc, VtuEncoding::RawZlib | VtuEncoding::Base64Zlib);
    let io = |e| Error::io(file, e);
    let mut out = Out::new(w);
    let (kind, cells_attr, section) = match grid {
        Grid::Unstructured => ("UnstructuredGrid", "NumberOfCells", "Cells"),
        Grid::Poly => ("PolyData", "NumberOfPolys", "Polys"),
    };
    out.s("<?xml version=\"1.0\"?>\n<VTKFile type=\"");
    out.s(kind);
    out.s("\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"");
    if zlib {
        out.s(" compressor=\"vtkZLibDataCompressor\"");
    }
    out.s(">\n  <");
    out.s(kind);
    out.s(">\n    <Piece NumberOfPoints=\"");
    out.int(sizes.0);
    out.s("\" ");
    out.s(cells_attr);
    out.s("=\"");
    out.int(sizes.1);
    out.s("\">\n");
    // Compressed appended blocks are made up front: the offsets depend on their sizes.
    let zblocks = match enc {
        VtuEncoding::RawZlib => arrays
            .iter()
            .map(|a| compress(a, chunk, file))
            .collect::<Result<Vec<_>>>()?,
        _ => Vec::new(),
    };
    let mut offset = 0usize;
    for (k, a) in arrays.iter().enumerate() {
        match k {
            0 => out.s("      <Points>\n"),
            1 => {
                out.s("      <");
                out.s(section);
                out.s(">\n");
            }
            _ if k == first_cell_array => {
                out.s("      <CellData Scalars=\"");
                out.s(scalars);
                out.s("\">\n");
            }
            _ => {}
        }
        out.s("        <DataArray type=\"");
        out.s(a.ty.name());
        out.s("\" Name=\"");
        out.s(a.name);
        out.s("\"");
        if a.ncomp != 1 {
            out.s(" NumberOfComponents=\"");
            out.int(a.ncomp);
            out.s("\"");
        }
        match enc {
            VtuEncoding::Raw | VtuEncoding::RawZlib => {
                out.s(" format=\"appended\" offset=\"");
                out.int(offset);
                out.s("\"/>\n");
                offset += match zblocks.get(k) {
                    Some((h, p)) => h.len() + p.len(),
                    None => 8 + a.nbytes(),
                };
            }
            VtuEncoding::Base64 => {
                out.s(" format=\"binary\">\n");
                let mut b = B64Stream::default();
                b.push(&(a.nbytes() as u64).to_le_bytes(), &mut out.buf);
                a.for_each_bytes(chunk, |bytes| {
                    for piece in bytes.chunks(3 << 14) {
                        b.push(piece, &mut out.buf);
                        out.check().map_err(io)?;
                    }
                    Ok(())
                })?;
                b.finish(&mut out.buf);
                out.s("\n        </DataArray>\n");
            }
            VtuEncoding::Base64Zlib => {
                out.s(" format=\"binary\">\n");
                let (h, p) = compress(a, chunk, file)?;
                b64::encode(&h, &mut out.buf);
                // Pieces of a multiple of 3 bytes encode to the text of the whole.
                for piece in p.chunks(3 << 14) {
                    b64::encode(piece, &mut out.buf);
                    out.check().map_err(io)?;
                }
                out.s("\n        </DataArray>\n");
            }
            VtuEncoding::Ascii => {
                out.s(" format=\"ascii\">\n");
                let mut i = 0usize;
                macro_rules! nums {
                    ($v:expr, $f:ident) => {
                        for x in $v {
                            out.$f(*x);
                            out.c(if i % 12 == 11 { b'\n' } else { b' ' });
                            out.check().map_err(io)?;
                            i += 1;
                        }
                    };
                }
                for d in a.chunks(chunk) {
                    match &d {
                        Data::F64(v) => nums!(v, f64),
                        Data::I32(v) => nums!(v, int),
                        Data::I64(v) => nums!(v, int),
                        Data::U8(v) => nums!(v, int),
                    }
                }
                out.s("\n        </DataArray>\n");
            }
        }
        out.check().map_err(io)?;
        if k == 0 {
            out.s("      </Points>\n");
        } else if k + 1 == first_cell_array {
            out.s("      </");
            out.s(section);
            out.s(">\n");
        }
    }
    if arrays.len() > first_cell_array {
        out.s("      </CellData>\n");
    }
    out.s("    </Piece>\n  </");
    out.s(kind);
    out.s(">\n");
    if matches!(enc, VtuEncoding::Raw | VtuEncoding::RawZlib) {
        out.s("  <AppendedData encoding=\"raw\">\n   _");
        for (k, a) in arrays.iter().enumerate() {
            if let Some((h, p)) = zblocks.get(k) {
                out.bytes(h);
                for piece in p.chunks(1 << 16) {
                    out.check().map_err(io)?;
                    out.bytes(piece);
                }
            } else {
                out.bytes(&(a.nbytes() as u64).to_le_bytes());
                a.for_each_bytes(chunk, |bytes| {
                    for piece in bytes.chunks(1 << 16) {
                        out.check().map_err(io)?;
                        out.bytes(piece);
                    }
                    Ok(())
                })?;
            }
            out.check().map_err(io)?;
        }
        out.s("\n  </AppendedData>\n");
    }
    out.s("</VTKFile>\n");
    out.finish().map_err(io)?;
    Ok(())
}
