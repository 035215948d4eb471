//! The library's one error type.
//!
//! Every message names the file (when there is one), the place in it (line, element,
//! byte offset) and what was expected, so that a user can act on it.

use std::path::PathBuf;

/// Everything that can go wrong in crease.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The operating system refused to open, read or write a file.
    ///
    /// The message already holds the operating system's words, so the underlying error is not
    /// also chained as a `source` (a chain printer would say it twice).
    #[error("{path}: {error}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying error.
        error: std::io::Error,
    },
    /// The file's content does not follow its format.
    #[error("{path}: {message}")]
    Format {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong and where (line / element / byte), and what was expected.
        message: String,
    },
    /// The file extension names no format crease knows.
    #[error("{path}: unknown file format {ext:?}; known extensions: {known}")]
    UnknownFormat {
        /// The file concerned.
        path: PathBuf,
        /// The extension found (empty if none).
        ext: String,
        /// The extensions crease reads or writes.
        known: &'static str,
    },
    /// The format is known but this operation is not supported for it (e.g. writing E57).
    #[error("{path}: {message}")]
    Unsupported {
        /// The file concerned.
        path: PathBuf,
        /// What is not supported.
        message: String,
    },
    /// The input is well formed but unusable by the algorithm (too few points, NaN, ...).
    #[error("{0}")]
    InvalidInput(String),
    /// A caller passed inconsistent arguments (e.g. attribute length differs from point count).
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
}

impl Error {
    /// A format error for `path` with `message`.
    pub fn format(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Format {
            path: path.into(),
            message: message.into(),
        }
    }

    /// An I/O error for `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            error: source,
        }
    }
}

/// A piece of input quoted in an error message, at most 40 characters (with the total length
/// when cut): a corrupt file must not turn into an error message megabytes long.
pub(crate) fn excerpt(text: &str) -> String {
    const MAX: usize = 40;
    match text.char_indices().nth(MAX) {
        None => format!("{text:?}"),
        Some((cut, _)) => format!("{:?}… ({} bytes)", &text[..cut], text.len()),
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
