//! The claimed-row store behind studies and shared experiment grids. A study's trials and a
//! grid's cells are both claimed rows: keyed by `id` (and, in PostgreSQL, by the study or grid
//! they belong to), each with its claim (`owner`, `lease_until_unix_s`) and a column that stays
//! NULL until the row is done (a trial's reward, a cell's record).
//!
//! One back end per database holds what both do alike: the connection, the schema version and
//! its upgrade, the write transaction under the study's or grid's lock, the claim and its
//! renewal (the heartbeat), counting the rows done and not done, and every error naming the
//! database ([`sqlite`], [`postgres`]). A study or a grid says only what its rows are: a
//! `Kind`, and the statements of what it stores beside the claims ([`crate::study`],
//! [`crate::experiment::shared`]). Which row a worker gets is decided by the rules of
//! [`claim`], apart from any database; [`Location`] is where a user names one.

pub mod claim;
mod location;
#[cfg(feature = "postgres")]
pub mod postgres;
pub mod sqlite;

use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::error::{Error, Result};
use claim::Claim;
pub use location::{Location, redact};

/// The schema this version writes and reads, the same for every back end and for studies and
/// grids (SQLite's `user_version`): 2 added the claims (`owner`, `lease_until_unix_s`); a
/// version-1 study is upgraded when opened for writing.
pub const SCHEMA_VERSION: i64 = 2;

/// How long a process waits for another one's write lock on a study or grid before reporting
/// "busy" (SQLite's busy timeout, PostgreSQL's `lock_timeout`).
pub const BUSY_TIMEOUT: Duration = Duration::from_secs(10);

/// What one kind of claimed rows is, in each back end.
#[cfg_attr(not(feature = "postgres"), allow(dead_code))]
pub(crate) struct Table {
    /// The table in an SQLite file (one study or grid per file).
    pub sqlite: &'static str,
    /// The statements that bring an SQLite file of an older schema to [`SCHEMA_VERSION`], in
    /// the write transaction that sets its `user_version`.
    pub sqlite_upgrade: &'static str,
    /// The table in a PostgreSQL database (any number of studies or grids).
    pub postgres: &'static str,
    /// The column that is NULL until the row is done.
    pub done: &'static str,
    /// In PostgreSQL, the statement that takes the study's or grid's write lock (its name is
    /// `$1`); it returns no row where there is nothing to lock.
    pub lock: &'static str,
    /// What the rows belong to.
    pub parent: Parent,
}

/// What claimed rows belong to: it names them in messages, and decides who makes them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Parent {
    /// A study's trials.
    Study,
    /// A grid's cells.
    Grid,
}

impl Parent {
    /// In PostgreSQL, the column naming the study or grid a row belongs to.
    #[cfg_attr(not(feature = "postgres"), allow(dead_code))]
    pub(crate) fn column(self) -> &'static str {
        match self {
            Parent::Study => "study",
            Parent::Grid => "grid",
        }
    }

    /// Whether opening to write makes what is missing (the SQLite file, the PostgreSQL
    /// tables): for a grid, which any worker may store first; a study is made by its own
    /// `create` only.
    pub(crate) fn made_on_open(self) -> bool {
        self == Parent::Grid
    }

    /// The error for a study or grid that does not exist.
    pub(crate) fn missing(self, path: PathBuf) -> Error {
        match self {
            Parent::Study => Error::NoStudy { path },
            Parent::Grid => Error::NoGrid { path },
        }
    }

    /// The error for a file or database that holds no study or grid this version reads, and
    /// why.
    pub(crate) fn foreign(self, path: PathBuf, reason: String) -> Error {
        match self {
            Parent::Study => Error::NotAStudy { path, reason },
            Parent::Grid => Error::NotAGrid { path, reason },
        }
    }
}

/// A kind of claimed rows (a study's trials, a grid's cells): the type that ties a back end's
/// rows to what their owner stores beside them.
pub(crate) trait Kind: Send + 'static {
    /// The table, by its names in each back end.
    const TABLE: Table;
}

/// The claimed rows of one study or grid in one back end, and the connection to them.
pub(crate) trait Rows: Send {
    /// Where they live, for messages (never with a password).
    fn label(&self) -> &Path;
    /// Renews `owner`'s claim on row `id`, not done yet, until `until`; false if the row is
    /// done or no longer `owner`'s.
    fn heartbeat(&mut self, id: i64, owner: &str, until: f64) -> Result<bool>;
    /// Number of rows done (or, `done` false, not done yet), read without the write lock.
    fn count(&mut self, done: bool) -> Result<usize>;
}

/// A write transaction on one study's or grid's claimed rows, under its write lock.
pub(crate) trait RowsTransaction {
    /// Number of rows done (or, `done` false, not done yet).
    fn count(&mut self, done: bool) -> Result<usize>;
    /// The claims of the rows not done yet, in id order.
    fn claims(&mut self) -> Result<Vec<Claim>>;
    /// Claims row `id` for `owner` until `until`.
    fn set_claim(&mut self, id: i64, owner: &str, until: f64) -> Result<()>;
    /// Makes every change durable, then releases the lock.
    fn commit(self: Box<Self>) -> Result<()>;
}

/// Refuses a file or database written with a newer schema than this version reads, as not
/// holding a study or grid of `parent`'s kind.
pub(crate) fn check_version(label: &Path, version: i64, parent: Parent) -> Result<()> {
    if version > SCHEMA_VERSION {
        return Err(parent.foreign(
            label.to_owned(),
            format!(
                "written by a newer cdbo (study schema {version}, this version reads {SCHEMA_VERSION}); upgrade cdbo"
            ),
        ));
    }
    Ok(())
}

/// Unix time now (s).
pub(crate) fn unix_now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}
