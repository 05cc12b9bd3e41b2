//! Keeping the allocator's resident memory close to what is in use: large blocks mapped on their
//! own, and freed memory handed back to the system between the stages of a run.
//!
//! glibc's allocator keeps freed blocks for reuse, in the main heap and in one arena per worker
//! thread, so after a stage that built and dropped large temporaries the resident size stays
//! near that stage's peak, and the next stage's temporaries come on top of it (on the 1.1M-tet
//! brain, 50 MB sat free in the arenas by the end of meshing). Trimming between stages returns
//! those pages; it takes milliseconds.

/// Return the allocator's free pages to the system (glibc's `malloc_trim`); a no-op elsewhere.
pub fn release_free_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        unsafe extern "C" {
            fn malloc_trim(pad: usize) -> std::ffi::c_int;
        }
        // SAFETY: malloc_trim takes no pointer and may be called at any time from any thread.
        unsafe {
            malloc_trim(0);
        }
    }
}

/// Serve every block of 1 MiB or more from its own mapping (glibc's `mallopt(M_MMAP_THRESHOLD)`);
/// a no-op elsewhere. glibc's default threshold rises to the size of any mapped block freed (up
/// to 32 MB), after which the mesh-sized arrays of the later stages come from the heap, grow by
/// copying, and leave holes there when freed; mapped, they are returned to the system when freed
/// and grow in place (`mremap`). On the 1.1M-tet brain this takes the peak from 108 to 101 MB
/// above the starting RSS, and 10 MB off the absolute peak.
pub fn map_large_blocks() {
    set_mmap_threshold(1 << 20);
}

/// Serve every block of 128 KiB or more from its own mapping, for meshing (`biotet mesh` calls it
/// once the input is read and the starting RSS taken, so that figure means what it did). The
/// per-tet arrays of a mesh of 100k tets (1 to 8 bytes a tet) are below 1 MiB: from the heap,
/// each stage's copies and regrown arrays left holes that kept its peak resident; mapped, they
/// grow in place and go back to the system when freed. On brain_20k this takes 0.3 to 0.5 MB
/// off the peaks of recovery, sliver removal and smoothing, at no measurable cost in time.
pub fn map_mesh_sized_blocks() {
    set_mmap_threshold(128 << 10);
}

fn set_mmap_threshold(bytes: std::ffi::c_int) {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        const M_MMAP_THRESHOLD: std::ffi::c_int = -3;
        unsafe extern "C" {
            fn mallopt(param: std::ffi::c_int, value: std::ffi::c_int) -> std::ffi::c_int;
        }
        // SAFETY: mallopt takes no pointer and is thread-safe (it takes the arena locks).
        unsafe {
            mallopt(M_MMAP_THRESHOLD, bytes);
        }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    let _ = bytes;
}

/// The peak resident memory of each stage of a run (Linux; empty elsewhere). [`next`] closes
/// the running stage with the peak since it started and restarts the kernel's count
/// (`/proc/self/clear_refs`), so the largest stage peak is the run's peak.
///
/// [`next`]: StagePeaks::next
#[derive(Debug, Default)]
pub struct StagePeaks {
    running: Option<String>,
    /// Stage name and peak RSS in kB, in order.
    pub peaks: Vec<(String, u64)>,
    /// `/proc/self/status` and `/proc/self/clear_refs`, opened once: opening them for every
    /// stage was half the cost of a count (about 25 µs a stage, a hundredth of a small run).
    status: Option<std::fs::File>,
    clear_refs: Option<std::fs::File>,
    buf: Vec<u8>,
}

impl StagePeaks {
    /// Start counting with stage `first`.
    pub fn start(first: &str) -> StagePeaks {
        let mut p = StagePeaks {
            status: std::fs::File::open("/proc/self/status").ok(),
            clear_refs: std::fs::OpenOptions::new()
                .write(true)
                .open("/proc/self/clear_refs")
                .ok(),
            ..StagePeaks::default()
        };
        p.next(Some(first));
        p
    }

    /// Close the running stage and start `stage` (`None`: stop counting).
    pub fn next(&mut self, stage: Option<&str>) {
        if let Some(name) = self.running.take()
            && let Some(kb) = self.peak_kb()
        {
            self.peaks.push((name, kb));
        }
        if let Some(f) = &mut self.clear_refs {
            use std::io::Write;
            let _ = f.write_all(b"5");
        }
        self.running = stage.map(str::to_string);
    }

    /// `VmHWM` of `/proc/self/status`, read again from its start.
    fn peak_kb(&mut self) -> Option<u64> {
        use std::io::{Read, Seek};
        let f = self.status.as_mut()?;
        f.rewind().ok()?;
        self.buf.clear();
        f.read_to_end(&mut self.buf).ok()?;
        let text = std::str::from_utf8(&self.buf).ok()?;
        crate::cmd::delaunay::status_field(text, "VmHWM:")
    }

    /// The largest peak so far.
    pub fn max(&self) -> Option<u64> {
        self.peaks.iter().map(|p| p.1).max()
    }
}

/// Parse a `--max-memory` value: bytes, or a number with a unit `K`, `M`, `G` or `T` (powers of
/// 1024; `KB`, `MiB` and the like accepted too).
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let x: f64 = num
        .parse()
        .map_err(|_| format!("'{s}' is not a size (e.g. 8G, 512M, 1000000)"))?;
    let shift = match unit.trim().to_ascii_uppercase().as_str() {
        "" | "B" => 0,
        "K" | "KB" | "KIB" => 10,
        "M" | "MB" | "MIB" => 20,
        "G" | "GB" | "GIB" => 30,
        "T" | "TB" | "TIB" => 40,
        u => return Err(format!("'{s}': unknown unit '{u}' (K, M, G or T)")),
    };
    let b = x * (1u64 << shift) as f64;
    if !(b >= 1.0 && b < u64::MAX as f64) {
        return Err(format!("'{s}' is not a positive size"));
    }
    Ok(b as u64)
}

/// Resident bytes per tet while meshing, measured: 160 on the unit cube at size 0.05 (39k tets),
/// 100 on the 1.1M-tet brain; the larger is used.
const BYTES_PER_TET: f64 = 160.0;
/// Tets per node of a template mesh (5.7 on the unit cube).
const TETS_PER_NODE: f64 = 6.0;
/// Bytes per template voxel (two bytes of state and region, and the classification's rows).
const BYTES_PER_VOXEL: f64 = 3.0;

/// What meshing `surface` at `sizing` will take, estimated before any work: the template's
/// voxels (as `template::deploy` counts them) and the nodes (the inside volume at the sizes
/// sampled on a 32³ grid over the bounding box, one node per h³, 0.86 measured).
#[derive(Debug, Clone, Copy)]
pub struct MeshEstimate {
    /// Template voxels.
    pub voxels: f64,
    /// Nodes of the mesh.
    pub nodes: f64,
    /// Bytes at the peak.
    pub bytes: f64,
}

/// The estimate of meshing `surface` (see [`MeshEstimate`]) when it exceeds `limit` bytes, else
/// `None`. The sizes are sampled only when the bound with the smallest size everywhere exceeds
/// the limit (on a small surface the samples would cost more than the meshing).
pub fn over_limit(
    surface: &biotet::SurfaceMesh,
    sizing: &biotet::sizing::Sizing,
    deploy: &biotet::template::DeployOptions,
    limit: f64,
) -> Option<MeshEstimate> {
    let (volume, lo, ext, voxels) = extent(surface, sizing, deploy);
    let most = nodes_bytes(voxels, 0.86 * volume / sizing.min_size().powi(3));
    if most <= limit {
        return None;
    }
    let e = sampled(sizing, volume, lo, ext, voxels);
    (e.bytes > limit).then_some(e)
}

/// The inside volume (absolute), the bounding box's corner and extent, and the template voxels.
fn extent(
    surface: &biotet::SurfaceMesh,
    sizing: &biotet::sizing::Sizing,
    deploy: &biotet::template::DeployOptions,
) -> (f64, [f64; 3], [f64; 3], f64) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    // The inside volume: triangles with the outside on one side only (interfaces add nothing).
    // Cones from a corner of the surface, not the origin: far from it (coordinates of 1e9) the
    // terms would cancel to noise larger than the volume.
    let o = surface
        .triangles
        .first()
        .map_or([0.0; 3], |t| surface.points[t[0] as usize]);
    let mut volume = 0.0;
    for (t, s) in surface.triangles.iter().zip(&surface.sides) {
        let [a, b, c] = t.map(|v| surface.points[v as usize]);
        for p in [a, b, c] {
            for i in 0..3 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        let det = biotet::geom::vec3::volume6(o, a, b, c);
        let sign = match (s[0] != 0, s[1] != 0) {
            (true, false) => 1.0,
            (false, true) => -1.0,
            _ => 0.0,
        };
        volume += sign * det / 6.0;
    }
    let ext = [0, 1, 2].map(|i| (hi[i] - lo[i]).max(0.0));
    let dx = sizing.min_size() / deploy.resolution;
    let m = 2.0 * deploy.margin as f64 + 2.0;
    let voxels = ext.iter().map(|e| e / dx + m).product::<f64>();
    (volume.abs(), lo, ext, voxels)
}

/// Peak bytes of `voxels` template voxels and `nodes` nodes.
fn nodes_bytes(voxels: f64, nodes: f64) -> f64 {
    let bytes = voxels * BYTES_PER_VOXEL + nodes * TETS_PER_NODE * BYTES_PER_TET;
    if bytes.is_nan() { f64::INFINITY } else { bytes }
}

/// The estimate with the sizes sampled on a 32³ grid over the bounding box.
fn sampled(
    sizing: &biotet::sizing::Sizing,
    volume: f64,
    lo: [f64; 3],
    ext: [f64; 3],
    voxels: f64,
) -> MeshEstimate {
    const N: usize = 32;
    let cell = ext.map(|e| e / N as f64);
    let mut per_volume = 0.0;
    for i in 0..N {
        for j in 0..N {
            for k in 0..N {
                let p = [
                    lo[0] + (i as f64 + 0.5) * cell[0],
                    lo[1] + (j as f64 + 0.5) * cell[1],
                    lo[2] + (k as f64 + 0.5) * cell[2],
                ];
                per_volume += 1.0 / sizing.at(p, 1).powi(3);
            }
        }
    }
    let nodes = 0.86 * volume * per_volume / (N * N * N) as f64;
    MeshEstimate {
        voxels,
        nodes,
        bytes: nodes_bytes(voxels, nodes),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_bytes("1000"), Ok(1000));
        assert_eq!(parse_bytes("512M"), Ok(512 << 20));
        assert_eq!(parse_bytes("1.5G"), Ok(3 << 29));
        assert_eq!(parse_bytes("2GiB"), Ok(2 << 30));
        assert!(parse_bytes("0").is_err());
        assert!(parse_bytes("12X").is_err());
        assert!(parse_bytes("G").is_err());
    }

    #[test]
    fn ball_estimate_counts_its_nodes_and_voxels() {
        let mut s = biotet::SurfaceMesh::icosphere(1.0, 3);
        s.sides = vec![[1, 0]; s.triangles.len()];
        let sizing = biotet::sizing::Sizing::uniform(0.1).unwrap();
        // Any estimate is over a zero limit.
        let e = over_limit(&s, &sizing, &Default::default(), 0.0).unwrap();
        // The ball's volume is about 4.19 (a little less, inscribed): about 3600 nodes at 0.1.
        assert!(e.nodes > 3000.0 && e.nodes < 3700.0, "{e:?}");
        // 2.2 / 0.1 + 6 margin voxels a side.
        assert!(e.voxels > 8.0e4 && e.voxels < 1.2e5, "{e:?}");
        // Under a limit above it: none, whether or not the sizes were sampled.
        let d = Default::default();
        assert!(over_limit(&s, &sizing, &d, 1.01 * e.bytes).is_none());
        assert!(over_limit(&s, &sizing, &d, 0.99 * e.bytes).is_some());
    }
}
