//! The output contract: a run that exits non-zero never creates or replaces a requested output
//! path. A complete result is written with its side outputs (SVGs) all together; an incomplete
//! one is written only with `--keep-failed`, and then beside the output as `OUT.failed.EXT`.

use anyhow::Result;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Where `--keep-failed` writes the partial result of a run asked to write `out`: `.failed`
/// before the extension (`brain.vtu` → `brain.failed.vtu`; the TetGen base `brain.node` →
/// `brain.failed.node`, so `brain.failed.node/.ele/.face`).
pub fn failed_path(out: &Path) -> PathBuf {
    match (out.file_stem(), out.extension()) {
        (Some(stem), Some(ext)) => {
            let mut name = stem.to_os_string();
            name.push(".failed.");
            name.push(ext);
            out.with_file_name(name)
        }
        _ => {
            let mut s = out.as_os_str().to_os_string();
            s.push(".failed");
            PathBuf::from(s)
        }
    }
}

/// Paths as one comma-separated list for messages.
pub fn list<P: AsRef<Path>>(paths: &[P]) -> String {
    joined(paths, ", ")
}

/// Paths joined by `sep`.
fn joined<P: AsRef<Path>>(paths: &[P], sep: &str) -> String {
    paths
        .iter()
        .map(|p| p.as_ref().display().to_string())
        .collect::<Vec<_>>()
        .join(sep)
}

/// Write a complete result: `main` writes the main output (or nothing) and returns its files,
/// each `(path, text)` of `sides` is a rendered side output. Each side output is first written
/// to a temporary file beside its target, then the main output is written (atomically), and only
/// then are the side outputs renamed into place: an error anywhere before leaves none written.
/// Returns every file written, the main output's first.
pub fn write_all(
    main: impl FnOnce() -> biotet_io::Result<Vec<PathBuf>>,
    sides: &[(&Path, String)],
) -> Result<Vec<PathBuf>> {
    fn nest(
        sides: &[(&Path, String)],
        main: Box<dyn FnOnce() -> biotet_io::Result<Vec<PathBuf>> + '_>,
    ) -> biotet_io::Result<Vec<PathBuf>> {
        let Some(((path, text), rest)) = sides.split_first() else {
            return main();
        };
        let mut written = Vec::new();
        biotet_io::atomic::write_atomic(path, |w| {
            // Into the temporary file now, so a full disk shows before the main output is written.
            w.write_all(text.as_bytes())
                .and_then(|_| w.flush())
                .map_err(|e| biotet_io::Error::io(&path.display().to_string(), e))?;
            written = nest(rest, main)?;
            Ok(())
        })?;
        written.push(path.to_path_buf());
        Ok(written)
    }
    Ok(nest(sides, Box::new(main))?)
}

/// What a failed run does with its partial result. Nothing is written at the requested paths
/// (`requested`: the output and any side output); with `keep_failed`, `write` writes the partial
/// result to [`failed_path`] of `out`. Returns the files written and a sentence for the error
/// message naming them, or saying what was not written and how to keep it.
pub fn on_failure(
    what: &str,
    out: Option<&Path>,
    requested: &[&Path],
    keep_failed: bool,
    write: impl FnOnce(&Path) -> biotet_io::Result<Vec<PathBuf>>,
) -> (Vec<PathBuf>, String) {
    let not_written = match requested {
        [] => String::new(),
        [one] => format!("{} was not written", one.display()),
        many => format!("{} were not written", joined(many, " and ")),
    };
    let Some(out) = out else {
        return (Vec::new(), not_written);
    };
    let failed = failed_path(out);
    if !keep_failed {
        return (
            Vec::new(),
            format!(
                "{not_written} (--keep-failed writes the {what} to {})",
                failed.display()
            ),
        );
    }
    match write(&failed) {
        Ok(files) => {
            let text = format!("{not_written}; the {what} was written to {}", list(&files));
            (files, text)
        }
        Err(e) => (
            Vec::new(),
            format!("{not_written}, nor could the {what} be: {e}"),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_names_sit_beside_the_output() {
        let f = |s: &str| failed_path(Path::new(s)).display().to_string();
        assert_eq!(f("brain.vtu"), "brain.failed.vtu");
        assert_eq!(f("out/brain.msh"), "out/brain.failed.msh");
        assert_eq!(f("brain.1.node"), "brain.1.failed.node");
        assert_eq!(f("a.b/brain"), "a.b/brain.failed");
        // TetGen: the three files of the failed base.
        let t = biotet_io::tetgen::files(&failed_path(Path::new("d/brain.ele")));
        assert_eq!(t.node, Path::new("d/brain.failed.node"));
        assert_eq!(t.face, Path::new("d/brain.failed.face"));
    }

    #[test]
    fn side_outputs_are_not_written_when_the_main_one_fails() {
        let dir = tempfile::tempdir().unwrap();
        let svg = dir.path().join("q.svg");
        std::fs::write(&svg, "old").unwrap();
        let r = write_all(
            || Err(biotet_io::Error::io("m.vtu", std::io::Error::other("boom"))),
            &[(svg.as_path(), "new".into())],
        );
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&svg).unwrap(), "old");
        // A side output whose directory does not exist fails before the main output is written.
        let main = dir.path().join("m.txt");
        let r = write_all(
            || {
                std::fs::write(&main, "x").unwrap();
                Ok(vec![main.clone()])
            },
            &[(dir.path().join("no/q.svg").as_path(), "new".into())],
        );
        assert!(r.is_err());
        assert!(!main.exists());
        let written = write_all(
            || {
                std::fs::write(&main, "x").unwrap();
                Ok(vec![main.clone()])
            },
            &[(svg.as_path(), "new".into())],
        )
        .unwrap();
        assert_eq!(written, vec![main.clone(), svg.clone()]);
        assert_eq!(std::fs::read_to_string(&svg).unwrap(), "new");
    }
}
