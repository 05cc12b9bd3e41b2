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
}

impl StagePeaks {
    /// Start counting with stage `first`.
    pub fn start(first: &str) -> StagePeaks {
        let mut p = StagePeaks::default();
        p.next(Some(first));
        p
    }

    /// Close the running stage and start `stage` (`None`: stop counting).
    pub fn next(&mut self, stage: Option<&str>) {
        if let Some(name) = self.running.take()
            && let (Some(kb), _) = crate::cmd::delaunay::memory_kb()
        {
            self.peaks.push((name, kb));
        }
        let _ = std::fs::write("/proc/self/clear_refs", "5");
        self.running = stage.map(str::to_string);
    }

    /// The largest peak so far.
    pub fn max(&self) -> Option<u64> {
        self.peaks.iter().map(|p| p.1).max()
    }
}
