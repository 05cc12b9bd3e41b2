//! Atomic file output: write to temporary files next to the targets, then rename.
//!
//! A reader of the output path sees either the old file or the complete new one, never a
//! partial write; if anything fails (a write error, or an error returned by the format writer)
//! the temporaries are deleted and the targets are left untouched. For formats made of several
//! files (TetGen), every file is written to its temporary first and only then are all renamed,
//! so an error while writing any of them leaves none behind. (The renames themselves are done one
//! after the other; a failure between two renames — rare, as all temporaries are on the target
//! file systems already — can leave a mix of old and new files.) A process killed before the
//! rename leaves the previous file (or none) and a `.<name>.<random>.tmp` beside it.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

use crate::error::{Error, Result};

/// The writer handed to format writers: a large buffer over the temporary file.
pub type AtomicWriter = BufWriter<NamedTempFile>;

// Large enough that writes are few, small beside the mesh being written.
const BUF: usize = 1 << 18;

fn temp_for(path: &Path) -> Result<NamedTempFile> {
    let name = path.display().to_string();
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let stem = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let prefix = format!(".{stem}.");
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // Like File::create: 0o666 minus the umask, instead of tempfile's private 0o600.
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    b.tempfile_in(&dir).map_err(|e| Error::io(&name, e))
}

/// Write one file atomically: `f` gets a buffered writer on a temporary file in the same
/// directory, which is renamed to `path` when `f` succeeds.
pub fn write_atomic<F>(path: &Path, f: F) -> Result<()>
where
    F: FnOnce(&mut AtomicWriter) -> Result<()>,
{
    write_atomic_many(&[path.to_path_buf()], |ws| f(&mut ws[0]))
}

/// Write several files atomically as a group: all are written to temporaries, then all renamed.
pub fn write_atomic_many<F>(paths: &[PathBuf], f: F) -> Result<()>
where
    F: FnOnce(&mut [AtomicWriter]) -> Result<()>,
{
    let mut ws = Vec::with_capacity(paths.len());
    for p in paths {
        ws.push(BufWriter::with_capacity(BUF, temp_for(p)?));
    }
    f(&mut ws)?;
    let mut temps = Vec::with_capacity(ws.len());
    for (w, p) in ws.into_iter().zip(paths) {
        let name = p.display().to_string();
        let mut tmp = w
            .into_inner()
            .map_err(|e| Error::io(&name, e.into_error()))?;
        tmp.flush().map_err(|e| Error::io(&name, e))?;
        // On disk before the rename, so a crash never leaves a renamed but empty file.
        tmp.as_file().sync_all().map_err(|e| Error::io(&name, e))?;
        temps.push(tmp);
    }
    pause_before_rename();
    for (tmp, p) in temps.into_iter().zip(paths) {
        tmp.persist(p)
            .map_err(|e| Error::io(&p.display().to_string(), e.error))?;
    }
    Ok(())
}

/// The fault tests' hook: with `BIOTET_TEST_PAUSE_BEFORE_RENAME` naming a file, that file is
/// created once every temporary is complete and synced, and the process waits there (for the
/// test's SIGKILL) instead of renaming.
fn pause_before_rename() {
    if let Some(marker) = std::env::var_os("BIOTET_TEST_PAUSE_BEFORE_RENAME") {
        let _ = std::fs::write(marker, b"");
        loop {
            std::thread::sleep(std::time::Duration::from_secs(1));
        }
    }
}

/// Read a whole file, naming it in the error.
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| Error::io(&path.display().to_string(), e))
}

/// Open a file for buffered streaming (used by format detection).
pub(crate) fn open(path: &Path) -> Result<std::io::BufReader<File>> {
    File::open(path)
        .map(std::io::BufReader::new)
        .map_err(|e| Error::io(&path.display().to_string(), e))
}
