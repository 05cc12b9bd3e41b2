//! The documentation cannot drift from the tool: every `biotet` command line in a `sh` block of
//! the README and of docs/*.md must be accepted by the argument parser as written (every
//! command, option and value exists), and every command's `--help` ends with examples.

mod support;
use std::process::Command;
use support::*;

/// The `biotet` command lines of the `sh` blocks of `text`, with their line numbers:
/// comments and redirections cut, `cargo run … --` read as `biotet`.
fn command_lines(text: &str) -> Vec<(usize, Vec<String>)> {
    let mut out = Vec::new();
    let mut in_sh = false;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if t.starts_with("```") {
            in_sh = !in_sh && t.trim_start_matches('`').trim() == "sh";
            continue;
        }
        if !in_sh {
            continue;
        }
        let t = t
            .strip_prefix("cargo run --release -p biotet-cli -- ")
            .map_or(t.to_string(), |r| format!("biotet {r}"));
        let Some(rest) = t.strip_prefix("biotet ") else {
            continue;
        };
        let rest = rest.split(" #").next().unwrap_or("");
        let rest = rest.split(" > ").next().unwrap_or("");
        out.push((i + 1, words(rest)));
    }
    out
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

#[test]
fn every_documented_command_line_parses() {
    let root = root();
    let mut files = vec![root.join("README.md")];
    let mut docs: Vec<_> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
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
