//! Every seed (`fuzz/seeds/<target>/`) and every input that once failed
//! (`fuzz/regressions/<target>/`, each named after what it caught) through its target, under the
//! fuzz binary's allocation cap: none may panic or abort.

use std::path::{Path, PathBuf};

#[global_allocator]
static ALLOC: biotet_fuzz::CappedAlloc = biotet_fuzz::CappedAlloc;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz")
}

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

fn replay(kind: &str) -> usize {
    let mut n = 0;
    for dir in files(&root().join(kind)) {
        let target = dir.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            biotet_fuzz::TARGETS.contains(&target.as_str()),
            "{}: no target of that name",
            dir.display()
        );
        for f in files(&dir) {
            let data = std::fs::read(&f).unwrap();
            eprintln!("{}", f.display());
            biotet_fuzz::run(&target, &data);
            n += 1;
        }
    }
    n
}

#[test]
fn seeds() {
    let n = replay("seeds");
    // Every target has seeds.
    for t in biotet_fuzz::TARGETS {
        assert!(
            !files(&root().join("seeds").join(t)).is_empty(),
            "no seeds for target {t}"
        );
    }
    assert!(n >= biotet_fuzz::TARGETS.len());
}

#[test]
fn regressions() {
    replay("regressions");
}

/// The pipeline seeds are meshed, not refused on the way (else the target tests nothing).
#[test]
fn pipeline_seeds_mesh() {
    for f in files(&root().join("seeds/pipeline")) {
        let r = biotet_fuzz::pipeline(&std::fs::read(&f).unwrap());
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        eprintln!("{name}: {r:?}");
        if name != "ico_huge" {
            assert!(matches!(r, Ok(n) if n > 0), "{name}: {r:?}");
        }
    }
}
