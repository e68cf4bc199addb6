//! What a grid stores, the same in both back ends: its cells as claimed rows ([`Cells`]), and
//! the [`GridStorage`] and [`GridTransaction`] that an SQLite file ([`super::sqlite`]) and a
//! PostgreSQL database ([`super::postgres`]) implement beside the claims of [`crate::store`].

use crate::error::Result;
use crate::store::{Kind, Parent, Rows, RowsTransaction, Table};

/// A grid's cells: done once their run's record is stored. PostgreSQL's lock is an advisory
/// lock keyed by the grid's name, so that workers starting at once on a grid not stored yet
/// store it once; a worker opening a grid to write makes the file or the tables where missing.
pub(crate) enum Cells {}

impl Kind for Cells {
    const TABLE: Table = Table {
        sqlite: "runs",
        // The tables, created together by the first worker.
        sqlite_upgrade: "
            CREATE TABLE IF NOT EXISTS grid (id INTEGER PRIMARY KEY CHECK (id = 1), grid TEXT NOT NULL);
            CREATE TABLE IF NOT EXISTS runs (
                id INTEGER PRIMARY KEY,
                run TEXT NOT NULL,
                record TEXT,
                owner TEXT,
                lease_until_unix_s REAL,
                finished_unix_s REAL);
            CREATE TABLE IF NOT EXISTS sessions (id INTEGER PRIMARY KEY, session TEXT NOT NULL);",
        postgres: "cdbo_grid_runs",
        done: "record",
        lock: "SELECT pg_advisory_xact_lock(hashtextextended('cdbo grid ' || $1, 0))",
        parent: Parent::Grid,
    };
}

/// A grid's rows in a database, with a lock that makes each [`GridTransaction`] see and change
/// the grid alone.
pub(crate) trait GridStorage: Rows {
    /// Starts a transaction holding the grid's write lock until it commits or is dropped.
    fn begin(&mut self) -> Result<Box<dyn GridTransaction + '_>>;
    /// The grid as stored (TOML), if the database holds it.
    fn grid(&mut self) -> Result<Option<String>>;
    /// The finished cells' records (JSON), in cell order.
    fn records(&mut self) -> Result<Vec<String>>;
    /// The sessions logged (JSON of [`crate::experiment::folder::Session`]), in order.
    fn sessions(&mut self) -> Result<Vec<String>>;
    /// Logs a session.
    fn add_session(&mut self, session: &str) -> Result<()>;
}

/// One write transaction on a grid, under its write lock.
pub(crate) trait GridTransaction: RowsTransaction {
    /// The grid as stored (TOML), if the database holds it.
    fn grid(&mut self) -> Result<Option<String>>;
    /// Stores the grid and one unclaimed cell per run (ids 1, 2, 3, … named `runs`).
    fn create(&mut self, grid: &str, runs: &[String]) -> Result<()>;
    /// Stores cell `id`'s record (JSON), finished at `now`; false if it had one already.
    fn finish(&mut self, id: i64, record: &str, now: f64) -> Result<bool>;
}
