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
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        const M_MMAP_THRESHOLD: std::ffi::c_int = -3;
        unsafe extern "C" {
            fn mallopt(param: std::ffi::c_int, value: std::ffi::c_int) -> std::ffi::c_int;
        }
        // SAFETY: mallopt takes no pointer; it is called first thing in main, before any thread.
        unsafe {
            mallopt(M_MMAP_THRESHOLD, 1 << 20);
        }
    }
}
