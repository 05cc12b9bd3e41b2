//! The error type of every reader and writer.
//!
//! Every message starts with the file name as given by the caller, then says where (a line
//! number for text formats, an element index for binary formats or whole-mesh checks) and why:
//!
//! - `x.off: line 5: expected 3 coordinates, got 2`
//! - `brain.stl: triangle 17: vertex index 99 out of range (12 vertices)`
//! - `a.stl: truncated file: header announces 200 triangles (10084 bytes), file has 3000 bytes`
//!
//! Element indices in messages are 0-based positions in the file's element order.

use std::io;

use thiserror::Error;

/// The result type of this crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Everything that can go wrong reading or writing a mesh file.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// The operating system refused to open, read, write or rename a file.
    // The OS error is part of the message, not a `source`, so error chains print it once.
    #[error("{file}: {error}")]
    Io {
        /// The file.
        file: String,
        /// The underlying error.
        error: io::Error,
    },
    /// Malformed text at a given line.
    #[error("{file}: line {line}: {msg}")]
    Line {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        msg: String,
    },
    /// A malformed element or record, identified by its position (binary formats, checks made
    /// after parsing).
    #[error("{file}: {what} {index}: {msg}")]
    Element {
        /// The file.
        file: String,
        /// The kind of record: "triangle", "tet", "vertex", "cell", ...
        what: &'static str,
        /// 0-based index of the record in the file.
        index: usize,
        /// What is wrong.
        msg: String,
    },
    /// The file ends before the data its header announces.
    #[error("{file}: truncated file: {msg}")]
    Truncated {
        /// The file.
        file: String,
        /// What was expected.
        msg: String,
    },
    /// A structural problem that is not tied to one line or record (missing section, unsupported
    /// variant of a format, ...).
    #[error("{file}: {msg}")]
    Format {
        /// The file.
        file: String,
        /// What is wrong.
        msg: String,
    },
    /// The file name's extension does not name a supported format.
    #[error("{path}: unknown {kind} file extension; supported: {supported}")]
    UnknownExtension {
        /// The path.
        path: String,
        /// "surface", "tet mesh", "triangle mesh" or "mesh".
        kind: &'static str,
        /// The supported extensions.
        supported: &'static str,
    },
    /// The mesh handed to a writer cannot be written (index out of range, non-finite
    /// coordinate, label not representable in the format, ...).
    #[error("{file}: cannot write: {msg}")]
    InvalidMesh {
        /// The file.
        file: String,
        /// What is wrong.
        msg: String,
    },
}

impl Error {
    /// An I/O error on `file`.
    pub fn io(file: &str, source: io::Error) -> Error {
        Error::Io {
            file: file.to_string(),
            error: source,
        }
    }

    pub(crate) fn line(file: &str, line: usize, msg: impl Into<String>) -> Error {
        Error::Line {
            file: file.to_string(),
            line,
            msg: one_line(msg.into()),
        }
    }

    pub(crate) fn element(
        file: &str,
        what: &'static str,
        index: usize,
        msg: impl Into<String>,
    ) -> Error {
        Error::Element {
            file: file.to_string(),
            what,
            index,
            msg: one_line(msg.into()),
        }
    }

    pub(crate) fn truncated(file: &str, msg: impl Into<String>) -> Error {
        Error::Truncated {
            file: file.to_string(),
            msg: one_line(msg.into()),
        }
    }

    pub(crate) fn format(file: &str, msg: impl Into<String>) -> Error {
        Error::Format {
            file: file.to_string(),
            msg: one_line(msg.into()),
        }
    }

    pub(crate) fn invalid(file: &str, msg: impl Into<String>) -> Error {
        Error::InvalidMesh {
            file: file.to_string(),
            msg: one_line(msg.into()),
        }
    }
}

/// Messages quote the file's own text (a magic number, an attribute value), which may hold line
/// breaks and other control characters: escaped, so that every error stays one line.
fn one_line(msg: String) -> String {
    if !msg.chars().any(char::is_control) {
        return msg;
    }
    let mut out = String::with_capacity(msg.len() + 8);
    for c in msg.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_one_line() {
        let e = Error::format("a.nii", "magic '\n\u{1}5' is not 'n+1'");
        assert_eq!(e.to_string(), "a.nii: magic '\\n\\u{1}5' is not 'n+1'");
        let e = Error::line("a.vtu", 2, "unknown byte_order 'Little\r\nEndian'");
        assert!(!e.to_string().contains(['\n', '\r']));
    }
}
