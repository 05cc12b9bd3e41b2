//! The documentation cannot drift from the tool: every `biotet` command line in a `sh` block of
//! the README and of docs/*.md must be accepted by the argument parser as written (every
//! command, option and value exists), every line of those blocks runs as written (but the few
//! listed in [`NOT_RUN`], with why), and every command's `--help` ends with examples.

mod support;
use std::path::{Path, PathBuf};
use std::process::Command;
use support::*;

/// Lines of the docs' `sh` blocks that [`every_documented_shell_line_runs`] does not run, by
/// prefix, with why. Each prefix must still match a line (the list cannot rot); every other
/// line of every `sh` block is run.
const NOT_RUN: &[(&str, &str)] = &[
    ("scripts/test.sh", "the test suite this test is part of"),
    (
        "cargo install ",
        "a second release build of the binary this test runs",
    ),
    (
        "cargo build --release",
        "cargo test built the binary this test runs",
    ),
    (
        "pip install ",
        "scripts/test.sh installs the Python package and its pytest suite runs",
    ),
    (
        "(cd crates/biotet-py && maturin build",
        "scripts/test.sh builds and installs the Python package",
    ),
    (
        "python examples/cohort_dask.py",
        "run by the Python suite (crates/biotet-py/tests/test_docs.py), which has Dask",
    ),
    (
        "python3 scripts/compare.py",
        "a benchmark: needs TetGen, Gmsh, CGAL, fTetWild and MMG, and minutes",
    ),
    (
        "python3 scripts/bench_",
        "a benchmark beside anchors (TetGen, MMG, pytetwild) CI does not install",
    ),
];

/// The lines of the `sh` blocks of `text`, trimmed, `\` continuations joined and `cargo run
/// --release -p biotet-cli --` read as `biotet`, with their line numbers.
fn sh_lines(text: &str) -> Vec<(usize, String)> {
    let mut out: Vec<(usize, String)> = Vec::new();
    let mut in_sh = false;
    let mut open = false;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if t.starts_with("```") {
            in_sh = !in_sh && t.trim_start_matches('`').trim() == "sh";
            open = false;
            continue;
        }
        if !in_sh {
            continue;
        }
        let (body, cont) = match line.trim_end().strip_suffix('\\') {
            Some(b) => (b.to_string(), true),
            None => (line.to_string(), false),
        };
        match out.last_mut() {
            Some(last) if open => last.1.push_str(&body),
            _ => out.push((i + 1, body)),
        }
        open = cont;
    }
    for (_, l) in &mut out {
        let t = l.trim();
        *l = t
            .strip_prefix("cargo run --release -p biotet-cli -- ")
            .map_or(t.to_string(), |r| format!("biotet {r}"));
    }
    out
}

/// Why a documented line is not run, if it is one of [`NOT_RUN`].
fn not_run(line: &str) -> Option<&'static str> {
    let t = line.trim_start();
    NOT_RUN
        .iter()
        .find(|(p, _)| t.starts_with(p))
        .map(|&(_, why)| why)
}

/// The `biotet` command lines of the `sh` blocks of `text` ([`sh_lines`]), with their line
/// numbers: comments and redirections cut.
fn command_lines(text: &str) -> Vec<(usize, Vec<String>)> {
    sh_lines(text)
        .into_iter()
        .filter_map(|(n, t)| {
            let rest = t.strip_prefix("biotet ")?;
            let rest = rest.split(" #").next().unwrap_or("");
            let rest = rest.split(" > ").next().unwrap_or("");
            Some((n, words(rest)))
        })
        .collect()
}

/// Split on spaces, keeping double-quoted words whole.
fn words(s: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    for c in s.chars() {
        match c {
            '"' => quoted = !quoted,
            ' ' if !quoted => {
                if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
            _ => cur.push(c),
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// The README and docs/*.md, in that order (docs sorted by name).
fn doc_files() -> Vec<PathBuf> {
    let root = root();
    let mut docs: Vec<_> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    let mut files = vec![root.join("README.md")];
    files.extend(docs);
    files
}

#[test]
fn every_documented_command_line_parses() {
    let files = doc_files();
    let mut checked = 0;
    let mut bad = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for (line, args) in command_lines(&text) {
            let out = Command::new(env!("CARGO_BIN_EXE_biotet"))
                .args(&args)
                .env("BIOTET_PARSE_ONLY", "1")
                .output()
                .unwrap();
            checked += 1;
            if !out.status.success() {
                bad.push(format!(
                    "{}:{line}: biotet {}: {}",
                    f.display(),
                    args.join(" "),
                    stderr(&out)
                ));
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    // The README's quick start alone has seven.
    assert!(checked >= 15, "only {checked} command lines found");
}

#[test]
fn every_command_help_ends_with_examples() {
    let help = String::from_utf8(biotet(&["--help"]).stdout).unwrap();
    let commands: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        // A command's name is indented by two; its wrapped description by more.
        .filter(|l| !l[2..].starts_with(' '))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.len() >= 12, "{commands:?}");
    for c in commands {
        let h = String::from_utf8(biotet(&[c, "--help"]).stdout).unwrap();
        let tail = h.rsplit("Examples:").next().unwrap_or("");
        assert!(
            h.contains("Examples:") && tail.contains(&format!("biotet {c}")),
            "biotet {c} --help has no examples"
        );
        // Each example parses as written.
        let lines = tail
            .lines()
            .flat_map(|l| l.split(" && "))
            .map(str::trim_start);
        for line in lines.filter_map(|l| l.strip_prefix("biotet ")) {
            let line = line
                .split(" (")
                .next()
                .unwrap_or("")
                .split(" > ")
                .next()
                .unwrap_or("");
            let out = Command::new(env!("CARGO_BIN_EXE_biotet"))
                .args(words(line))
                .env("BIOTET_PARSE_ONLY", "1")
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "biotet {c} --help: biotet {line}: {}",
                stderr(&out)
            );
        }
    }
}

/// A scratch directory that sees the repository's `tests/` and `examples/` (the paths the docs
/// use), with the inputs the cohort script of docs/cohorts.md expects.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("biotet-docs-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("subjects")).unwrap();
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    let root = root().canonicalize().unwrap();
    for d in ["tests", "examples"] {
        std::os::unix::fs::symlink(root.join(d), dir.join(d)).unwrap();
    }
    std::os::unix::fs::symlink(
        root.join("tests/data/brain_20k.stl"),
        dir.join("subjects/brain_20k.stl"),
    )
    .unwrap();
    dir
}

/// The `-o` output of a documented `biotet` line, if it writes a mesh.
fn mesh_output(line: &str) -> Option<String> {
    let w = words(line.split(" #").next().unwrap_or(""));
    let command = w.get(1)?.as_str();
    if !matches!(
        command,
        "mesh" | "remesh" | "smooth" | "recover" | "improve"
    ) {
        return None;
    }
    let i = w.iter().position(|x| x == "-o" || x == "--output")?;
    let o = w.get(i + 1)?;
    // A 2D mesh (from a PSLG) written as .vtu is written only: `check` refuses to read it.
    let planar = w.iter().any(|x| x.ends_with(".poly"));
    let skip = o.contains('$') || (planar && o.ends_with(".vtu"));
    (!skip).then(|| o.clone())
}

/// Every line of the `sh` blocks of the README and of docs/*.md runs as written, in document
/// order (README first, so the docs' later lines find the meshes it wrote), in one scratch
/// directory, `biotet` being the binary under test (`cargo run --release -p biotet-cli --` read
/// as `biotet`); each mesh a line writes passes `biotet check`.
#[test]
fn every_documented_shell_line_runs() {
    let files = doc_files();
    let dir = scratch("run");
    let bin = Path::new(env!("CARGO_BIN_EXE_biotet"));
    let path = format!(
        "{}:{}",
        bin.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut used = vec![false; NOT_RUN.len()];
    let mut ran = 0;
    let mut failed = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        // One shell for a file's lines, so a block's variables carry to its next lines.
        let mut script = String::from("set -e -o pipefail\n");
        let mut lines = Vec::new();
        for (n, line) in sh_lines(&text) {
            let t = line.trim();
            if t.is_empty() || t.starts_with('#') {
                continue;
            }
            if let Some(why) = not_run(t) {
                let k = NOT_RUN.iter().position(|(_, w)| *w == why).unwrap();
                used[k] = true;
                continue;
            }
            script.push_str(&format!("echo '>> {name}:{n}' >&2\n{t}\n"));
            lines.push((n, t.to_string()));
        }
        if lines.is_empty() {
            continue;
        }
        let out = Command::new("bash")
            .arg("-c")
            .arg(&script)
            .current_dir(&dir)
            .env("PATH", &path)
            .env("SLURM_ARRAY_TASK_ID", "0")
            .output()
            .unwrap();
        ran += lines.len();
        if !out.status.success() {
            let err = stderr(&out);
            let at = err.rsplit(">> ").next().unwrap_or("").to_string();
            failed.push(format!("{name}: stopped at {at}"));
            continue;
        }
        for (n, t) in &lines {
            let Some(o) = mesh_output(t) else { continue };
            let check = Command::new(bin)
                .args(["check", &o])
                .current_dir(&dir)
                .output()
                .unwrap();
            if !check.status.success() {
                failed.push(format!(
                    "{name}:{n}: {o} fails `biotet check`: {}",
                    String::from_utf8_lossy(&check.stdout)
                ));
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(failed.is_empty(), "{}", failed.join("\n"));
    for (k, (p, _)) in NOT_RUN.iter().enumerate() {
        assert!(
            used[k],
            "NOT_RUN lists `{p}`, which no documented line starts with any more"
        );
    }
    // The README's main job and quick start, the view and 2D examples, the Slurm job line.
    assert!(ran >= 15, "only {ran} documented lines ran");
}

/// Every fenced block of the README and docs/*.md names its language, so no command hides from
/// the tests above in an untagged block (one in docs/benchmarks.md did).
#[test]
fn every_code_block_names_its_language() {
    let files = doc_files();
    let mut bad = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let mut open = false;
        for (i, line) in text.lines().enumerate() {
            let Some(rest) = line.trim_start().strip_prefix("```") else {
                continue;
            };
            if !open && rest.trim().is_empty() {
                bad.push(format!("{}:{}", f.display(), i + 1));
            }
            open = !open;
        }
    }
    assert!(bad.is_empty(), "untagged code blocks: {}", bad.join(", "));
}
