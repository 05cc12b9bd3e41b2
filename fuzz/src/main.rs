//! libFuzzer over one biotet-fuzz target, named by the environment variable
//! `BIOTET_FUZZ_TARGET` (one binary for every target: one instrumented link, not 25).
#![no_main]

use std::sync::OnceLock;

#[global_allocator]
static ALLOC: biotet_fuzz::CappedAlloc = biotet_fuzz::CappedAlloc;

fn target() -> &'static str {
    static T: OnceLock<String> = OnceLock::new();
    T.get_or_init(|| {
        let t = std::env::var("BIOTET_FUZZ_TARGET").unwrap_or_default();
        if !biotet_fuzz::TARGETS.contains(&t.as_str()) {
            eprintln!(
                "BIOTET_FUZZ_TARGET must be one of: {}",
                biotet_fuzz::TARGETS.join(" ")
            );
            std::process::exit(2);
        }
        t
    })
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    biotet_fuzz::run(target(), data);
});
