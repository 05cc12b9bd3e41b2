//! The README's library example runs as written: the lines between the markers below, with the
//! `use` line, are the README's Rust block (checked), run from the repository root where the
//! README's paths start.

use biotet::{check::check, quality::QualityReport};
use std::path::Path;

const BEGIN: &str = "// README block begins";
const END: &str = "// README block ends";

#[test]
fn the_readme_library_example_runs() -> Result<(), Box<dyn std::error::Error>> {
    std::env::set_current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))?;
    // README block begins
    let mesh = biotet_io::read_tet_mesh("examples/brain_tetgen.node".as_ref())?.mesh;
    let surface = biotet_io::read_surface("tests/data/brain_20k.stl".as_ref())?.mesh;
    assert!(check(&mesh, Some(&surface)).valid);
    println!("{}", QualityReport::of(&mesh));
    // README block ends
    assert_eq!(mesh.tets.len(), 95_654, "TetGen's mesh, examples/README.md");
    Ok(())
}

#[test]
fn the_readme_rust_block_is_the_example_above() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../README.md"))
            .unwrap();
    let block: Vec<&str> = readme
        .split("```rust\n")
        .nth(1)
        .expect("the README has a Rust block")
        .split("```")
        .next()
        .unwrap()
        .lines()
        .map(str::trim)
        .collect();
    let this = include_str!("readme_library.rs");
    let body = this.split(BEGIN).nth(2).unwrap().split(END).next().unwrap();
    let mut expected = vec!["use biotet::{check::check, quality::QualityReport};"];
    expected.extend(body.lines().map(str::trim).filter(|l| !l.is_empty()));
    assert_eq!(block, expected);
}
