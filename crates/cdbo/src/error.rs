//! One error type for the library, with variants a caller can match.
//!
//! Every variant says *what* was wrong and *where* (file, line, element, value), so that the
//! command line can print one clear line and exit non-zero. Library messages name no
//! command-line flag: the CLI adds those where a value came from one.

use std::path::PathBuf;

/// Errors raised by the cdbo library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// An input (a file, a program's output) larger than the bound of its kind, refused after
    /// reading the bound and one byte.
    #[error("{input}: the {what} is larger than its bound of {}", show_bytes(*bound))]
    InputTooLarge {
        /// The file, or the program and which of its outputs.
        input: String,
        /// What the input is (`policy file`).
        what: &'static str,
        /// The bound, bytes.
        bound: u64,
    },
    /// A file was read but its content is invalid.
    #[error("{file}{}: {element}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Parse {
        /// The file (or a built-in resource name).
        file: String,
        /// The 1-based line, when known.
        line: Option<u32>,
        /// The element, section or field (e.g. `Main Track/Track Segments/curve 1/arc`).
        element: String,
        /// What was wrong, with the offending value.
        message: String,
    },
    /// JSON that could not be written or read back.
    #[error("{what}: {source}")]
    Json {
        /// What was being read or written (a file, or a named piece of state).
        what: String,
        /// The serde_json error (with its line and column when reading).
        source: serde_json::Error,
    },
    /// A named thing (track, car, method) does not exist.
    #[error("unknown {what} {name}: {detail}")]
    NotFound {
        /// The kind of thing: `track`, `car`, `method`.
        what: &'static str,
        /// The name as given (quoted where it is text).
        name: String,
        /// Where it was looked for, or what exists.
        detail: String,
    },
    /// An SQLite error on a study file (other than [`Error::Busy`] and [`Error::NotAStudy`]).
    #[error("{}: {source}", path.display())]
    Sql {
        /// The study file.
        path: PathBuf,
        /// The SQLite error.
        source: rusqlite::Error,
    },
    /// A PostgreSQL error on a study's database: unreachable, credentials refused, or a
    /// statement that failed.
    #[cfg(feature = "postgres")]
    #[error("{}: {}", path.display(), postgres_message(source))]
    Postgres {
        /// The database URL (without its password) and study name.
        path: PathBuf,
        /// The client's error.
        source: postgres::Error,
    },
    /// Another process holds the study's write lock beyond the busy timeout
    /// (SQLite's `DatabaseBusy` / `DatabaseLocked`).
    #[error("{}: busy: another process is using the study; try again", path.display())]
    Busy {
        /// The study file.
        path: PathBuf,
    },
    /// A file that is not a study this version can read.
    #[error("{}: not a cdbo study: {reason}", path.display())]
    NotAStudy {
        /// The file.
        path: PathBuf,
        /// Why (not SQLite, no settings, a newer schema, corrupt settings).
        reason: String,
    },
    /// A study file that does not exist.
    #[error("{}: no such study (create it first)", path.display())]
    NoStudy {
        /// The file.
        path: PathBuf,
    },
    /// A study has no trial of this id.
    #[error("{}: no trial {trial} in this study", path.display())]
    NoTrial {
        /// The study file.
        path: PathBuf,
        /// The trial id asked for.
        trial: i64,
    },
    /// A file that must not be overwritten already exists.
    #[error("{}: already exists; open it, or choose another name", path.display())]
    AlreadyExists {
        /// The file.
        path: PathBuf,
    },
    /// Something another process already did: a study's trial told twice.
    #[error("{}: trial {trial} {reason}", path.display())]
    Conflict {
        /// The study file.
        path: PathBuf,
        /// The trial id.
        trial: i64,
        /// What had already happened.
        reason: String,
    },
    /// An experiment folder that already holds a different grid.
    #[error("{}: this folder holds a different grid", path.display())]
    DifferentGrid {
        /// The folder's grid file.
        path: PathBuf,
    },
    /// A database or file that holds no experiment grid this version can read.
    #[error("{}: not a cdbo grid: {reason}", path.display())]
    NotAGrid {
        /// The file, or the database URL (without its password) and grid name.
        path: PathBuf,
        /// Why (not SQLite, a study, a newer schema, a stored grid that does not parse).
        reason: String,
    },
    /// A grid that does not exist in its database.
    #[error("{}: no such grid (run `cdbo experiment GRID --storage ...` first)", path.display())]
    NoGrid {
        /// The file, or the database URL (without its password) and grid name.
        path: PathBuf,
    },
    /// A value out of its domain.
    #[error("{what} must be {expected}, got {value}")]
    InvalidValue {
        /// The quantity (e.g. `the ridge factor`, `policy weight 3`).
        what: String,
        /// The value given.
        value: String,
        /// What it must be (e.g. `positive`, `a lap fraction in [0, 1]`).
        expected: String,
    },
    /// A vector or list of the wrong length.
    #[error("expected {expected} {what}, got {got}")]
    DimensionMismatch {
        /// What is counted (e.g. `weights`).
        what: String,
        /// The length required.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A count below its minimum (no laps, an empty demonstration, one kernel).
    #[error("{what} {value}: must be at least {min}")]
    TooSmall {
        /// What is counted.
        what: String,
        /// The count given.
        value: u64,
        /// The minimum.
        min: u64,
    },
    /// A size beyond its bound (kernels, laps, a file, a line).
    #[error("{what} {value}: must be at most {max} ({why})")]
    TooLarge {
        /// What is measured.
        what: String,
        /// The size given.
        value: u64,
        /// The bound.
        max: u64,
        /// Why the bound is there.
        why: String,
    },
    /// A saved optimiser state whose parts do not fit together.
    #[error("corrupt {method} state: {reason}")]
    CorruptState {
        /// The method whose state it is.
        method: &'static str,
        /// What does not fit.
        reason: String,
    },
    /// An optimiser told the reward of weights it did not ask for.
    #[error("{method} can only be told the reward of the weights it asked for last")]
    NotAsked {
        /// The method.
        method: &'static str,
    },
    /// The demonstrator cannot complete the track at the requested speed.
    #[error(
        "the {speed} m/s demonstration does not complete {track} ({failure}): choose a slower demonstration speed"
    )]
    DemoFailed {
        /// The demonstrator's target speed, m/s.
        speed: f64,
        /// The track's name.
        track: String,
        /// How the lap failed.
        failure: String,
    },
    /// An external lap command could not be started or waited for.
    #[error("`sh -c {line}`: {source}")]
    Command {
        /// The command line.
        line: String,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// An external program cdbo relies on (TORCS, its headers, a C++ compiler) is missing or
    /// not set up; the message says how to get it.
    #[error("{0}")]
    Setup(String),
    /// An external program (the TORCS robot) reported an error or wrote something unreadable.
    #[error("{program}: {message}")]
    External {
        /// The program.
        program: String,
        /// What it reported.
        message: String,
    },
    /// A numerical failure: a matrix not positive definite even with jitter, a singular system.
    #[error("{0}")]
    Numerical(String),
    /// A background thread (a hyperparameter fit) panicked.
    #[error("the {0} thread panicked")]
    Panicked(&'static str),
}

impl Error {
    /// An [`Error::Parse`] without a line number.
    pub fn parse(
        file: impl Into<String>,
        element: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Error::Parse {
            file: file.into(),
            line: None,
            element: element.into(),
            message: message.into(),
        }
    }

    /// An [`Error::InvalidValue`].
    pub fn invalid_value(
        what: impl Into<String>,
        value: impl ToString,
        expected: impl Into<String>,
    ) -> Self {
        Error::InvalidValue {
            what: what.into(),
            value: value.to_string(),
            expected: expected.into(),
        }
    }

    /// An [`Error::TooSmall`] for a count.
    pub fn too_small(what: impl Into<String>, value: usize, min: usize) -> Self {
        Error::TooSmall {
            what: what.into(),
            value: value as u64,
            min: min as u64,
        }
    }

    /// An [`Error::DimensionMismatch`].
    pub fn dimension(what: impl Into<String>, expected: usize, got: usize) -> Self {
        Error::DimensionMismatch {
            what: what.into(),
            expected,
            got,
        }
    }

    /// An [`Error::Json`] about `what`.
    pub fn json(what: impl Into<String>, source: serde_json::Error) -> Self {
        Error::Json {
            what: what.into(),
            source,
        }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// A PostgreSQL error on one line: the server's severity and message, or what failed on the
/// way to it and why (the client's own `Display` leaves the cause out).
#[cfg(feature = "postgres")]
fn postgres_message(e: &postgres::Error) -> String {
    if let Some(db) = e.as_db_error() {
        return format!("{}: {}", db.severity(), db.message());
    }
    match std::error::Error::source(e) {
        Some(cause) => format!("{e}: {cause}"),
        None => e.to_string(),
    }
}

/// `bytes` as the refusals say them: `16 MiB`, `4 KiB`, or a count of bytes.
pub(crate) fn show_bytes(bytes: u64) -> String {
    match bytes {
        b if b >= MIB && b % MIB == 0 => format!("{} MiB", b / MIB),
        b if b >= 1024 && b % 1024 == 0 => format!("{} KiB", b / 1024),
        b => format!("{b} bytes"),
    }
}

/// A mebibyte.
pub(crate) const MIB: u64 = 1 << 20;
