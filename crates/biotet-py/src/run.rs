//! Running library code for Python: the GIL released, panics caught, a thread pool of the
//! requested size, and failures turned into `CoreError(kind, message, triangles)`.

use crate::CoreError;
use biotet::mesh::validate::SurfaceError;
use pyo3::prelude::*;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// What went wrong, for the Python layer to choose the exception class.
#[derive(Debug, Clone, Copy)]
pub enum Kind {
    /// The surface is not a valid closed surface (`InvalidSurfaceError`, a `ValueError`).
    InvalidSurface,
    /// Meshing could not finish (`MeshingError`).
    Meshing,
    /// A bad argument value (`ValueError`).
    Value,
    /// A file could not be found (`FileNotFoundError`).
    NotFound,
    /// A file could not be read for permissions (`PermissionError`).
    Permission,
    /// Any other file problem: unreadable, malformed, unknown format (`BiotetFileError`, an
    /// `OSError`).
    File,
    /// A bug: a panic caught at the boundary (`MeshingError` saying so).
    Panic,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::InvalidSurface => "invalid_surface",
            Kind::Meshing => "meshing",
            Kind::Value => "value",
            Kind::NotFound => "not_found",
            Kind::Permission => "permission",
            Kind::File => "file",
            Kind::Panic => "panic",
        }
    }
}

/// A failure with the CLI's message and, where it names them, the offending triangles.
#[derive(Debug)]
pub struct Failure {
    pub kind: Kind,
    pub message: String,
    pub triangles: Vec<u32>,
}

impl Failure {
    pub fn new(kind: Kind, message: String) -> Failure {
        Failure {
            kind,
            message,
            triangles: Vec::new(),
        }
    }

    /// An invalid surface, with the message `biotet validate` prints.
    pub fn invalid(name: &str, e: &SurfaceError) -> Failure {
        Failure {
            kind: Kind::InvalidSurface,
            message: format!("{name}: invalid surface: {e}"),
            triangles: e.triangles(),
        }
    }

    /// A reader's or writer's error (its message names the file).
    pub fn io(e: biotet_io::Error) -> Failure {
        let kind = match &e {
            biotet_io::Error::Io { error, .. } => match error.kind() {
                std::io::ErrorKind::NotFound => Kind::NotFound,
                std::io::ErrorKind::PermissionDenied => Kind::Permission,
                _ => Kind::File,
            },
            _ => Kind::File,
        };
        Failure::new(kind, e.to_string())
    }
}

/// Run `f` without the GIL, on a pool of `threads` threads when given (at most four a core;
/// else the global pool, one thread per core), catching panics. Results do not depend on the thread count.
pub fn guarded<T: Send>(
    py: Python<'_>,
    threads: Option<usize>,
    f: impl FnOnce() -> Result<T, Failure> + Send,
) -> PyResult<T> {
    let out = py.detach(move || {
        let run = move || catch_unwind(AssertUnwindSafe(f));
        match threads.filter(|&n| n > 0).map(biotet::usable_threads) {
            Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
                Ok(pool) => pool.install(run),
                Err(e) => Ok(Err(Failure::new(
                    Kind::Value,
                    format!("cannot start {n} threads: {e}"),
                ))),
            },
            None => run(),
        }
    });
    let failure = match out {
        Ok(Ok(v)) => return Ok(v),
        Ok(Err(f)) => f,
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Failure::new(
                Kind::Panic,
                format!("internal error (a bug in biotet, please report it): {what}"),
            )
        }
    };
    Err(CoreError::new_err((
        failure.kind.name(),
        failure.message,
        failure.triangles,
    )))
}

/// Hand a stage name to the Python progress callable, if any (the GIL taken for the call).
/// Errors raised by the callable are ignored: progress must not stop meshing.
pub fn report_progress(progress: Option<&Py<PyAny>>, stage: &str) {
    if let Some(cb) = progress {
        Python::attach(|py| {
            let _ = cb.call1(py, (stage,));
        });
    }
}
