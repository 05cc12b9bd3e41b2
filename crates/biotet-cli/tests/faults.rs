//! Faults while writing: a full disk, a read-only directory, the process killed between the
//! temporary file and the rename. Each time the output path holds the complete previous file
//! (or nothing), never a partial one, and a failure's message names the file and the cause.
//!
//! The full disk is a 512 KiB tmpfs and the read-only directory a tmpfs remounted read-only when
//! the tests may mount (root, as here and in CI); otherwise the file size limit (RLIMIT_FSIZE,
//! `ulimit -f`) stands in for the full disk and a mode-0555 directory for the read-only one (as
//! root, permissions do not stop a write). Each test prints which it used.

mod support;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use support::*;

/// The previous output: a small valid mesh.
fn previous() -> PathBuf {
    root().join("fuzz/seeds/vtu_tet/cube_ascii.vtu")
}

/// The new output's input: a 5 MB VTU once converted.
fn large() -> PathBuf {
    root().join("examples/brain_tetgen.node")
}

/// A tmpfs mounted at a fresh directory, unmounted on drop; `None` when mounting is not allowed.
struct Tmpfs {
    dir: tempfile::TempDir,
}

impl Tmpfs {
    fn mount(opts: &str) -> Option<Tmpfs> {
        let dir = tempfile::tempdir().unwrap();
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", opts, "tmpfs", s(dir.path())])
            .output()
            .is_ok_and(|o| o.status.success());
        ok.then_some(Tmpfs { dir })
    }
    fn path(&self) -> &Path {
        self.dir.path()
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(self.dir.path()).output();
    }
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Put the previous output at `out` (converted, so it is biotet's own writing) and check it.
fn write_previous(out: &Path) -> Vec<u8> {
    let o = biotet(&["convert", s(&previous()), "-o", s(out), "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let check = biotet(&["check", s(out), "--quiet"]);
    assert!(check.status.success(), "{}", stderr(&check));
    std::fs::read(out).unwrap()
}

fn convert_large(out: &Path) -> Output {
    biotet(&["convert", s(&large()), "-o", s(out), "--quiet"])
}

#[test]
fn full_disk_leaves_the_previous_file() {
    if let Some(fs) = Tmpfs::mount("size=512k") {
        eprintln!("full disk: a 512 KiB tmpfs");
        let out = fs.path().join("out.vtu");
        let before = write_previous(&out);
        let o = convert_large(&out);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let msg = stderr(&o);
        eprintln!("{msg}");
        assert!(msg.contains("out.vtu"), "{msg}");
        assert!(msg.contains("No space left on device"), "{msg}");
        assert_eq!(std::fs::read(&out).unwrap(), before);
        // The temporary is gone, and so nothing but the previous file is there.
        assert_eq!(entries(fs.path()), ["out.vtu"]);
    } else {
        eprintln!("full disk: no mount allowed, RLIMIT_FSIZE of 512 KiB instead");
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.vtu");
        let before = write_previous(&out);
        // SIGXFSZ ignored (inherited through exec), so the write fails with EFBIG instead.
        let o = Command::new("bash")
            .args(["-c", "trap '' XFSZ; ulimit -f 512; exec \"$@\"", "bash"])
            .arg(env!("CARGO_BIN_EXE_biotet"))
            .args(["convert", s(&large()), "-o", s(&out), "--quiet"])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let msg = stderr(&o);
        eprintln!("{msg}");
        assert!(msg.contains("out.vtu"), "{msg}");
        assert!(msg.contains("File too large"), "{msg}");
        assert_eq!(std::fs::read(&out).unwrap(), before);
        assert_eq!(entries(dir.path()), ["out.vtu"]);
    }
}

#[test]
fn read_only_directory_leaves_the_previous_file() {
    let (guard, dir);
    let tmpfs = Tmpfs::mount("size=1m");
    if let Some(fs) = &tmpfs {
        dir = fs.path().to_path_buf();
        guard = None;
    } else {
        let d = tempfile::tempdir().unwrap();
        dir = d.path().to_path_buf();
        guard = Some(d);
    }
    let out = dir.join("out.vtu");
    let before = write_previous(&out);
    let expect = if tmpfs.is_some() {
        eprintln!("read-only directory: a tmpfs remounted read-only");
        let o = Command::new("mount")
            .args(["-o", "remount,ro", s(&dir)])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        "Read-only file system"
    } else {
        eprintln!("read-only directory: mode 0555");
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o555)).unwrap();
        "Permission denied"
    };
    let o = convert_large(&out);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let msg = stderr(&o);
    eprintln!("{msg}");
    assert!(msg.contains("out.vtu"), "{msg}");
    assert!(msg.contains(expect), "{msg}");
    assert_eq!(std::fs::read(&out).unwrap(), before);
    assert_eq!(entries(&dir), ["out.vtu"]);
    if guard.is_some() {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
}

/// Run `convert` to `out` until it has written and synced its temporary, then SIGKILL it.
fn kill_before_rename(out: &Path, marker: &Path) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_biotet"))
        .args(["convert", s(&large()), "-o", s(out), "--quiet"])
        .env("BIOTET_TEST_PAUSE_BEFORE_RENAME", marker)
        .spawn()
        .unwrap();
    // No timing: wait for the marker, or for the process to end (a failure).
    while !marker.exists() {
        if let Some(status) = child.try_wait().unwrap() {
            panic!("convert ended before the rename: {status}");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap(); // SIGKILL
    let status = child.wait().unwrap();
    use std::os::unix::process::ExitStatusExt;
    assert_eq!(status.signal(), Some(9));
}

#[test]
fn killed_between_temporary_and_rename() {
    let dir = tempfile::tempdir().unwrap();
    let marker_dir = tempfile::tempdir().unwrap();
    // What the complete new file is.
    let reference = dir.path().join("reference.vtu");
    let o = convert_large(&reference);
    assert!(o.status.success(), "{}", stderr(&o));
    let check = biotet(&["check", s(&reference), "--quiet"]);
    assert!(check.status.success(), "{}", stderr(&check));
    let new = std::fs::read(&reference).unwrap();
    std::fs::remove_file(&reference).unwrap();

    // No previous file: the path stays absent.
    let out = dir.path().join("out.vtu");
    kill_before_rename(&out, &marker_dir.path().join("first"));
    assert!(!out.exists());
    let left = entries(dir.path());
    eprintln!("left after the kill: {left:?}");
    assert_eq!(left.len(), 1);
    assert!(left[0].starts_with(".out.vtu.") && left[0].ends_with(".tmp"));
    // The temporary was complete (synced before the rename would have been).
    assert_eq!(std::fs::read(dir.path().join(&left[0])).unwrap(), new);
    std::fs::remove_file(dir.path().join(&left[0])).unwrap();

    // A previous file: it stays, whole.
    let before = write_previous(&out);
    kill_before_rename(&out, &marker_dir.path().join("second"));
    assert_eq!(std::fs::read(&out).unwrap(), before);
    assert_eq!(entries(dir.path()).len(), 2);
}
