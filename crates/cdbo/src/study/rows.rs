//! Claimed rows: the one table shape a study's trials and a grid's cells share. Each row is a
//! trial or a cell, keyed by `id` (and, in PostgreSQL, by the study or grid it belongs to),
//! with its claim (`owner`, `lease_until_unix_s`) and a column that stays NULL until the row is
//! done (a trial's reward, a cell's record). What both do alike is written here once per back
//! end ([`sqlite`], [`postgres`]): a write transaction under the lock, renewing a claim (the
//! heartbeat), setting one, counting the rows done and not done, and naming the database in
//! every error. What each stores beside is its own ([`super::sqlite`], [`super::postgres`],
//! [`crate::experiment::shared`]).

#[cfg(feature = "postgres")]
pub(crate) mod postgres;
pub(crate) mod sqlite;

use std::path::PathBuf;

use crate::error::Error;

/// A table of claimed rows, by its names in each back end.
#[cfg_attr(not(feature = "postgres"), allow(dead_code))]
pub(crate) struct ClaimedRows {
    /// The table in an SQLite file (one study or grid per file).
    pub sqlite: &'static str,
    /// The table in a PostgreSQL database (any number of studies or grids).
    pub postgres: &'static str,
    /// In PostgreSQL, the column naming the study or grid a row belongs to.
    pub parent: &'static str,
    /// The column that is NULL until the row is done.
    pub done: &'static str,
    /// In PostgreSQL, the statement that takes the study's or grid's write lock (its name is
    /// `$1`); it returns no row where there is nothing to lock.
    pub lock: &'static str,
    /// The error for a study or grid whose lock finds nothing.
    pub missing: fn(PathBuf) -> Error,
}

/// A study's trials: done once told. PostgreSQL's lock is the study's row
/// (`SELECT … FOR UPDATE`), the equivalent of SQLite's `BEGIN IMMEDIATE` for one study.
pub(crate) const TRIALS: ClaimedRows = ClaimedRows {
    sqlite: "trials",
    postgres: "cdbo_trials",
    parent: "study",
    done: "reward",
    lock: "SELECT 1 FROM cdbo_studies WHERE name = $1 FOR UPDATE",
    missing: |path| Error::NoStudy { path },
};

/// A grid's cells: done once their run's record is stored. PostgreSQL's lock is an advisory
/// lock keyed by the grid's name, so that workers starting at once on a grid not stored yet
/// store it once.
pub(crate) const CELLS: ClaimedRows = ClaimedRows {
    sqlite: "runs",
    postgres: "cdbo_grid_runs",
    parent: "grid",
    done: "record",
    lock: "SELECT pg_advisory_xact_lock(hashtextextended('cdbo grid ' || $1, 0))",
    missing: |path| Error::NoGrid { path },
};
