//! One error type for everything that reads user input: files, units, dimensions, rewards.
//!
//! Every variant says *where* the problem is (file, element, line) and *what* was wrong, so
//! that the command line can print one clear line and exit non-zero.

use std::path::PathBuf;

/// Errors raised by the cdbo library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A file was read but its content is invalid.
    #[error("{file}{}: {element}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Invalid {
        /// The file (or a built-in resource name).
        file: String,
        /// The 1-based line, when known.
        line: Option<u32>,
        /// The element, section or field (e.g. `Main Track/Track Segments/curve 1/arc`).
        element: String,
        /// What was wrong, with the offending value.
        message: String,
    },
    /// A named thing (track, car) could not be found.
    #[error("{0}")]
    NotFound(String),
    /// A value given through the API or the command line is out of its domain.
    #[error("{0}")]
    Domain(String),
    /// Something another process already did (a study's trial told twice).
    #[error("{0}")]
    Conflict(String),
}

impl Error {
    /// An [`Error::Invalid`] without a line number.
    pub fn invalid(
        file: impl Into<String>,
        element: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Error::Invalid {
            file: file.into(),
            line: None,
            element: element.into(),
            message: message.into(),
        }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
