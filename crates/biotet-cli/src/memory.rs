//! Handing freed memory back to the system between the stages of a run.
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
