//! The hostile inputs issue 25 names, each refused with a clear error before the memory its
//! header announces is allocated: the allocator here counts the peak of live bytes.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to System, counting sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let now = LIVE.fetch_add(l.size(), Ordering::Relaxed) + l.size();
        PEAK.fetch_max(now, Ordering::Relaxed);
        // SAFETY: forwarded.
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        LIVE.fetch_sub(l.size(), Ordering::Relaxed);
        // SAFETY: forwarded.
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static A: Counting = Counting;

// One case at a time: the peak and the reader budget are process-wide.
static ONE: Mutex<()> = Mutex::new(());

/// Run `f` alone; the peak of live bytes above the start.
fn peak_of<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let start = LIVE.load(Ordering::Relaxed);
    PEAK.store(start, Ordering::Relaxed);
    let r = f();
    (r, PEAK.load(Ordering::Relaxed) - start)
}

fn err<T: std::fmt::Debug>(r: biotet_io::Result<T>) -> String {
    let m = r.unwrap_err().to_string();
    assert!(!m.contains('\n'));
    eprintln!("{m}");
    m
}

#[test]
fn binary_stl_claiming_a_billion_triangles_in_84_bytes() {
    let _g = ONE.lock().unwrap();
    let mut data = vec![0u8; 84];
    data[80..84].copy_from_slice(&1_000_000_000u32.to_le_bytes());
    let (r, peak) = peak_of(|| biotet_io::stl::parse(&data, "a.stl"));
    let m = err(r);
    assert!(m.starts_with("a.stl: truncated file"), "{m}");
    assert!(m.contains("1000000000 triangles"), "{m}");
    assert!(peak < 1 << 20, "{peak} bytes allocated");
}

fn seed(target: &str, name: &str) -> Vec<u8> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/seeds")
        .join(target)
        .join(name);
    std::fs::read(p).unwrap()
}

#[test]
fn vtu_with_2_to_the_62_points() {
    let _g = ONE.lock().unwrap();
    for name in ["cube_ascii.vtu", "cube_base64_zlib.vtu", "cube_raw.vtu"] {
        let text = seed("vtu_tet", name);
        let at = text
            .windows(16)
            .position(|w| w == b"NumberOfPoints=\"")
            .unwrap()
            + 16;
        let end = at + text[at..].iter().position(|&b| b == b'"').unwrap();
        let data = [&text[..at], b"4611686018427387904", &text[end..]].concat();
        let (r, peak) = peak_of(|| biotet_io::vtu::parse_tet(&data, "m.vtu"));
        let m = err(r);
        assert!(m.starts_with("m.vtu: "), "{m}");
        assert!(peak < 1 << 20, "{name}: {peak} bytes allocated: {m}");
    }
}

/// A NIfTI-1 header of `dims` 16-bit voxels, followed by `zeros` zero bytes, gzipped.
fn nifti_gz(dims: [u16; 3], zeros: usize) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    for (i, d) in [3u16, dims[0], dims[1], dims[2], 1, 1, 1, 1]
        .iter()
        .enumerate()
    {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&4i16.to_le_bytes()); // int16
    h[72..74].copy_from_slice(&16i16.to_le_bytes());
    for i in 0..4 {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&1f32.to_le_bytes()); // pixdim
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes()); // vox_offset
    h[344..348].copy_from_slice(b"n+1\0");
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(&h).unwrap();
    let block = vec![0u8; 1 << 20];
    let mut left = zeros;
    while left > 0 {
        let n = left.min(block.len());
        gz.write_all(&block[..n]).unwrap();
        left -= n;
    }
    gz.finish().unwrap()
}

#[test]
fn gzip_bomb_is_refused_before_inflating() {
    let _g = ONE.lock().unwrap();
    // 1024×1024×64 16-bit voxels: 128 MiB of data in about 130 kB.
    let bomb = nifti_gz([1024, 1024, 64], 128 << 20);
    assert!(bomb.len() < 1 << 20);
    biotet_io::limits::set_max_memory(256 << 20);
    for parse in [
        |d: &[u8]| biotet_io::image::nifti::parse(d, "bomb.nii.gz").map(|_| ()),
        |d: &[u8]| biotet_io::grid::parse_nifti(d, "bomb.nii.gz").map(|_| ()),
    ] {
        let (r, peak) = peak_of(|| parse(&bomb));
        let m = err(r);
        biotet_io::limits::set_max_memory(0);
        assert!(m.starts_with("bomb.nii.gz: "), "{m}");
        assert!(m.contains("--max-memory"), "{m}");
        assert!(peak < 4 << 20, "{peak} bytes allocated: {m}");
        biotet_io::limits::set_max_memory(256 << 20);
    }
    biotet_io::limits::set_max_memory(0);
}

#[test]
fn gzip_stream_longer_than_its_header_is_inflated_only_as_far_as_needed() {
    let _g = ONE.lock().unwrap();
    // 4×4×4 voxels announced, 64 MiB of zeros in the stream: the image is read, the rest left.
    let data = nifti_gz([4, 4, 4], 64 << 20);
    let (r, peak) = peak_of(|| biotet_io::image::nifti::parse(&data, "long.nii.gz"));
    let img = r.unwrap();
    assert_eq!(img.labels, vec![0; 64]);
    assert!(peak < 4 << 20, "{peak} bytes allocated");
}

#[test]
fn vtu_zlib_block_announcing_more_than_the_budget() {
    let _g = ONE.lock().unwrap();
    // One zlib block announced as 1 GiB in a raw appended VTU: refused before inflating (by the
    // array's expected size here; by the 1100:1 bound and the budget for arrays of no known
    // size).
    let text = seed("vtu_tet", "cube_raw_zlib.vtu");
    let tag = text
        .windows(13)
        .position(|w| w == b"<AppendedData")
        .unwrap();
    let app = tag + text[tag..].iter().position(|&b| b == b'_').unwrap() + 1;
    let mut data = text.clone();
    // The first array's header: blocks, block size, last block size (32-bit by default).
    let hs = if text.windows(19).any(|w| w == b"header_type=\"UInt64") {
        8
    } else {
        4
    };
    let big = (1u64 << 30).to_le_bytes();
    data[app + hs..app + 2 * hs].copy_from_slice(&big[..hs]);
    data[app + 2 * hs..app + 3 * hs].copy_from_slice(&big[..hs]);
    biotet_io::limits::set_max_memory(64 << 20);
    let (r, peak) = peak_of(|| biotet_io::vtu::parse_tet(&data, "z.vtu"));
    biotet_io::limits::set_max_memory(0);
    let m = err(r);
    assert!(m.starts_with("z.vtu: "), "{m}");
    assert!(peak < 4 << 20, "{peak} bytes allocated: {m}");
    assert!(m.contains("announces 1073741824 bytes"), "{m}");
}
