//! The `biotet` command-line tool.
//!
//! Conventions shared by every command: `biotet <command> INPUT... [-o OUT]`, `--help`
//! everywhere, `--quiet` silences everything but errors, `--json` prints one JSON object on
//! stdout for scripts, a progress spinner on a terminal, errors as one message without a
//! backtrace, outputs written to a temporary file and renamed, `--threads N` for the parallel
//! stages (all cores by default; no result depends on it).

mod cmd;
mod memory;
mod output;
mod plot;
mod progress;
mod view;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// biotet: tetrahedral meshes from closed triangulated surfaces, keeping the surface exactly.
#[derive(Parser)]
#[command(name = "biotet", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Worker threads for the parallel stages (sliver removal's cavity searches, smoothing
    /// sweeps, surface validation); 0 or absent: one per core; at most four a core. Results do
    /// not depend on it.
    #[arg(long, global = true, value_name = "N")]
    threads: Option<usize>,
    /// Memory limit (bytes, or with a unit: 512M, 8G): images, grids and compressed data larger,
    /// and meshing estimated larger, are refused before the work starts. Default: three
    /// quarters of the machine's memory.
    #[arg(long, global = true, value_name = "BYTES", value_parser = memory::parse_bytes)]
    max_memory: Option<u64>,
}

/// Options every command takes.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct Common {
    /// Print nothing but errors (and the JSON object with --json).
    #[arg(short, long, global = true)]
    pub quiet: bool,
    /// Print one JSON object on stdout instead of text.
    #[arg(long, global = true)]
    pub json: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Report the quality of a tet (or 2D triangle) mesh: angles, q, radius ratio, histograms.
    Quality(cmd::quality::Args),
    /// Check that a tet mesh is valid and, with --surface, that it contains every surface
    /// triangle. Exits 0 only when valid.
    Check(cmd::check::Args),
    /// Convert a mesh between formats (chosen by extension).
    Convert(cmd::convert::Args),
    /// The 3D Delaunay tetrahedralization of a point cloud (exact, degenerate-proof).
    Delaunay(cmd::delaunay::Args),
    /// Mesh the volume inside closed surfaces (or a 2D PSLG): template node deployment,
    /// Delaunay, outside removal, boundary recovery, sliver removal, smoothing, polishing.
    /// Without a surface, meshes the bundled brain example.
    Mesh(cmd::mesh::Args),
    /// Raise the smallest solid angles of a tet mesh by moving nodes (surface fixed or sliding).
    Smooth(cmd::smooth::Args),
    /// Make every triangle of a surface a face of a tet mesh (LAST RESORT), without new points
    /// on the surface.
    Recover(cmd::recover::Args),
    /// Remove slivers by refilling their cavities (LAST RESORT); points and surface untouched.
    Improve(cmd::improve::Args),
    /// Remesh part of a tet mesh in place: one region, or the tets meeting a box or a sphere,
    /// at a new size; every other tet kept exactly.
    Remesh(cmd::remesh::Args),
    /// Surfaces: `surface IMAGE -o OUT` extracts the labelled surface of a label image;
    /// `surface improve` remeshes a surface within a distance bound.
    Surface(cmd::surface::Args),
    /// Validate closed surfaces: closed, manifold, no self-intersection (duplicate points
    /// welded, turned triangles turned back, both reported).
    Validate(cmd::validate::Args),
    /// Draw a tet mesh as SVG or PNG: the tets a plane cuts, coloured by region or by
    /// quality, or the boundary seen from one viewpoint.
    View(cmd::view::Args),
    /// The former name of `surface IMAGE` (kept for scripts).
    #[command(hide = true)]
    SurfaceExtract(cmd::extract::Args),
}

/// Exit status when the input was read and judged invalid (a mesh that fails `check`, a surface
/// that `validate` refuses).
pub const EXIT_INVALID: u8 = 1;
/// Exit status when the command could not do its job (unreadable file, bad option, I/O error).
pub const EXIT_ERROR: u8 = 2;

fn main() -> ExitCode {
    memory::map_large_blocks();
    // A closed stderr (`biotet mesh 2>&1 | head`) makes eprintln! panic: end quietly instead, as
    // for a closed stdout; any other panic keeps the default report.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.starts_with("failed printing to stderr") {
            std::process::exit(EXIT_ERROR as i32);
        }
        default_hook(info);
    }));
    let cli = Cli::parse();
    // The documentation test parses every command line of the docs without running it.
    if std::env::var_os("BIOTET_PARSE_ONLY").is_some() {
        return ExitCode::SUCCESS;
    }
    if let Some(asked) = cli.threads.filter(|&n| n > 0) {
        let n = biotet::usable_threads(asked);
        if n < asked && !std::env::args().any(|a| a == "--quiet" || a == "-q") {
            eprintln!("note: --threads {asked}: using {n}, four for each of this machine's cores");
        }
        if let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
        {
            eprintln!("error: --threads {n}: {e}");
            return ExitCode::from(EXIT_ERROR);
        }
    }
    biotet_io::limits::set_max_memory(
        cli.max_memory
            .unwrap_or_else(biotet_io::limits::default_max_memory),
    );
    let json = std::env::args().any(|a| a == "--json");
    let result = match cli.command {
        Command::Quality(a) => cmd::quality::run(a),
        Command::Check(a) => cmd::check::run(a),
        Command::Convert(a) => cmd::convert::run(a),
        Command::Validate(a) => cmd::validate::run(a),
        Command::Delaunay(a) => cmd::delaunay::run(a),
        Command::Mesh(a) => cmd::mesh::run(a),
        Command::Recover(a) => cmd::recover::run(a),
        Command::Improve(a) => cmd::improve::run(a),
        Command::Remesh(a) => cmd::remesh::run(a),
        Command::Smooth(a) => cmd::smooth::run(a),
        Command::SurfaceExtract(a) => cmd::extract::run(a),
        Command::Surface(a) => cmd::surface::run(a),
        Command::View(a) => cmd::view::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            let msg = format!("{e:#}");
            eprintln!("error: {msg}");
            if json {
                emit(&serde_json::json!({ "error": msg }).to_string());
            }
            // A surface refused by validation is an invalid input, not a failure to run.
            let refused = e
                .downcast_ref::<biotet::mesh::validate::SurfaceError>()
                .is_some()
                || e.downcast_ref::<biotet::mesh::side_labels::SideLabelError>()
                    .is_some()
                || matches!(
                    e.downcast_ref::<biotet::surface::SurfaceError>(),
                    Some(biotet::surface::SurfaceError::Crossings(_))
                );
            ExitCode::from(if refused { EXIT_INVALID } else { EXIT_ERROR })
        }
    }
}

/// Print a line on stdout. A closed pipe (`biotet quality m.vtu | head`) ends the program
/// quietly, as for any Unix filter, instead of panicking.
pub fn emit(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let r = writeln!(out, "{}", text.trim_end_matches('\n')).and_then(|_| out.flush());
    if let Err(e) = r {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: writing to stdout: {e}");
        std::process::exit(EXIT_ERROR as i32);
    }
}
