//! Running library code for Python: the GIL released, panics caught, a thread pool of the
//! requested size, and failures turned into `CoreError(kind, message, triangles)`.

use crate::CoreError;
use biotet::mesh::validate::SurfaceError;
use pyo3::prelude::*;
use std::cell::RefCell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::Duration;

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

    /// An invalid surface, with the message `biotet validate` prints; with `hint` the way out
    /// of crossing triangles said (the surface stage untangles them) where they are the reason.
    pub fn refused(name: &str, e: &SurfaceError, hint: bool) -> Failure {
        Failure {
            kind: Kind::InvalidSurface,
            message: if hint && matches!(e, SurfaceError::SelfIntersection { .. }) {
                // As the CLI says it.
                let hint = biotet::surface::untangle::HINT;
                format!("{name}: invalid surface: {hint}: {e}")
            } else {
                format!("{name}: invalid surface: {e}")
            },
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

/// A call's cancellation: requested by the waiting Python thread when a signal handler raised
/// (Ctrl-C), or by the progress callable's own exception, which is then raised in the call's
/// place.
#[derive(Default)]
struct Cancel {
    requested: AtomicBool,
    error: Mutex<Option<PyErr>>,
}

impl Cancel {
    fn request(&self, e: PyErr) {
        let mut slot = self.error.lock().unwrap_or_else(|p| p.into_inner());
        if slot.is_none() {
            *slot = Some(e);
        }
        self.requested.store(true, Ordering::SeqCst);
    }
}

thread_local! {
    /// The cancellation of the call running on this thread (set by [`guarded`]).
    static CURRENT: RefCell<Option<Arc<Cancel>>> = const { RefCell::new(None) };
}

/// The unwinding payload that stops a cancelled call at a progress point (raised with
/// `resume_unwind`, so no panic message is printed).
struct Interrupted;

/// How often the waiting thread looks at Python's signals.
const SIGNAL_POLL: Duration = Duration::from_millis(100);

/// The worker thread's stack (the main thread's usual size).
const STACK: usize = 8 << 20;

/// Run `f` without the GIL, on a pool of `threads` threads when given (at most four a core;
/// else the global pool, one thread per core), catching panics. Results do not depend on the thread count.
///
/// `f` runs on a thread of its own while the calling thread waits, looking at Python's signals
/// every 100 ms: a signal handler that raises (Ctrl-C's `KeyboardInterrupt`) stops the call
/// at its next progress point, as does an exception from the progress callable; that
/// exception is raised in the call's place.
pub fn guarded<T: Send>(
    py: Python<'_>,
    threads: Option<usize>,
    f: impl FnOnce() -> Result<T, Failure> + Send,
) -> PyResult<T> {
    let cancel = Arc::new(Cancel::default());
    let out = py.detach(|| {
        let (done, wait) = mpsc::channel::<()>();
        std::thread::scope(|scope| {
            let mine = cancel.clone();
            let worker = std::thread::Builder::new()
                .name("biotet".into())
                .stack_size(STACK)
                .spawn_scoped(scope, move || {
                    let run = move || {
                        CURRENT.with(|c| *c.borrow_mut() = Some(mine));
                        let r = catch_unwind(AssertUnwindSafe(f));
                        CURRENT.with(|c| *c.borrow_mut() = None);
                        r
                    };
                    let r = match threads.filter(|&n| n > 0).map(biotet::usable_threads) {
                        Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
                            Ok(pool) => pool.install(run),
                            Err(e) => Ok(Err(Failure::new(
                                Kind::Value,
                                format!("cannot start {n} threads: {e}"),
                            ))),
                        },
                        None => run(),
                    };
                    let _ = done.send(());
                    r
                });
            let worker = match worker {
                Ok(w) => w,
                Err(e) => {
                    return Ok(Err(Failure::new(
                        Kind::Meshing,
                        format!("cannot start a thread: {e}"),
                    )));
                }
            };
            while let Err(RecvTimeoutError::Timeout) = wait.recv_timeout(SIGNAL_POLL) {
                if !cancel.requested.load(Ordering::SeqCst)
                    && let Err(e) = Python::attach(|py| py.check_signals())
                {
                    cancel.request(e);
                }
            }
            worker.join().unwrap_or_else(Err)
        })
    });
    let failure = match out {
        Ok(Ok(v)) => return Ok(v),
        Ok(Err(f)) => f,
        Err(panic) if panic.is::<Interrupted>() => {
            let e = cancel
                .error
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .take();
            return Err(e.unwrap_or_else(|| {
                pyo3::exceptions::PyKeyboardInterrupt::new_err("biotet: interrupted")
            }));
        }
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
/// A cancelled call stops here, and an exception from the callable cancels it (on the thread
/// [`guarded`] runs the call on; elsewhere it is ignored).
pub fn report_progress(progress: Option<&Py<PyAny>>, stage: &str) {
    let cancel = CURRENT.with(|c| c.borrow().clone());
    if cancel
        .as_ref()
        .is_some_and(|c| c.requested.load(Ordering::SeqCst))
    {
        std::panic::resume_unwind(Box::new(Interrupted));
    }
    if let Some(cb) = progress
        && let Err(e) = Python::attach(|py| cb.call1(py, (stage,)).map(|_| ()))
        && let Some(c) = cancel
    {
        c.request(e);
        std::panic::resume_unwind(Box::new(Interrupted));
    }
}
