//! The memory budget of the readers: what a file's header announces (voxels of an image, samples
//! of a grid, bytes of decompressed data) is turned into bytes and refused before anything is
//! allocated when it exceeds the budget, with an error naming the file.
//!
//! Counts that a file's own length bounds (points of a text file, triangles of a binary STL) are
//! refused when the file is too short for them; compressed data is the one way a small file can
//! announce a large one (zlib expands up to ~1032:1), and this budget bounds it.
//!
//! The budget is process-wide (the CLI sets it from `--max-memory`); by default it is
//! [`default_max_memory`].

use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

// 0: not set, the default applies.
static MAX_MEMORY: AtomicU64 = AtomicU64::new(0);

/// Set the budget in bytes (0: back to the default).
pub fn set_max_memory(bytes: u64) {
    MAX_MEMORY.store(bytes, Ordering::Relaxed);
}

/// The budget in bytes.
pub fn max_memory() -> u64 {
    match MAX_MEMORY.load(Ordering::Relaxed) {
        0 => default_max_memory(),
        b => b,
    }
}

/// Three quarters of the machine's physical memory (`MemTotal` in `/proc/meminfo`), or 8 GiB
/// where that cannot be read.
pub fn default_max_memory() -> u64 {
    physical_memory().map_or(8 << 30, |b| b / 4 * 3)
}

/// The machine's physical memory in bytes (Linux), if known.
pub fn physical_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kb.checked_mul(1024)
}

/// Refuse `bytes` for `what` in `file` when above the budget.
pub(crate) fn reserve(file: &str, what: &str, bytes: u64) -> Result<()> {
    let max = max_memory();
    if bytes > max {
        return Err(Error::format(
            file,
            format!(
                "{what} needs {} of memory, more than the limit of {} (--max-memory)",
                human(bytes),
                human(max)
            ),
        ));
    }
    Ok(())
}

/// Bytes in MiB or GiB, for messages.
pub fn human(bytes: u64) -> String {
    if bytes >= 10 << 30 {
        format!("{:.0} GiB", bytes as f64 / (1u64 << 30) as f64)
    } else if bytes >= 1 << 30 {
        format!("{:.1} GiB", bytes as f64 / (1u64 << 30) as f64)
    } else {
        format!("{:.1} MiB", bytes as f64 / (1u64 << 20) as f64)
    }
}
