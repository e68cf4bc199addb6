//! A grid in an SQLite file (one grid per file; [`crate::store::sqlite`]), for workers on one
//! machine or a shared folder: tables `grid` (the grid's TOML), `runs` (one claimed row per
//! cell) and `sessions`, made by the first worker.

use std::path::Path;

use rusqlite::{Connection, OptionalExtension, params};

use super::storage::{Cells, GridStorage, GridTransaction};
use crate::error::{Error, Result};
use crate::store::sqlite::{SqliteRows, SqliteTransaction, sql_error};

/// A grid in an SQLite file.
type SqliteGrid = SqliteRows<Cells>;

/// Opens the grid file at `path`: to write, creating the file and its tables where missing
/// (an empty file counts as missing: another worker may have just made it); to read, an
/// existing grid file only. Refuses a file that is not SQLite, a database without a grid (a
/// study, say) and a newer schema, writing nothing.
pub(super) fn open(path: &Path, writable: bool) -> Result<SqliteGrid> {
    let (grid, ()) = SqliteGrid::open(path, writable, |conn, _| {
        let tables: Vec<String> =
            strings(conn, "SELECT name FROM sqlite_master WHERE type = 'table'")
                .map_err(|e| sql_error::<Cells>(path, e))?;
        if !tables.is_empty() && !tables.iter().any(|t| t == "runs") {
            return Err(Error::NotAGrid {
                path: path.to_owned(),
                reason: "an SQLite database without a grid in it".into(),
            });
        }
        if !writable && tables.is_empty() {
            return Err(Error::NoGrid {
                path: path.to_owned(),
            });
        }
        Ok(())
    })?;
    Ok(grid)
}

fn stored_grid(conn: &Connection) -> rusqlite::Result<Option<String>> {
    conn.query_row("SELECT grid FROM grid WHERE id = 1", [], |r| r.get(0))
        .optional()
}

fn strings(conn: &Connection, sql: &str) -> rusqlite::Result<Vec<String>> {
    let mut stmt = conn.prepare(sql)?;
    stmt.query_map([], |r| r.get(0))?.collect()
}

impl GridStorage for SqliteGrid {
    fn begin(&mut self) -> Result<Box<dyn GridTransaction + '_>> {
        Ok(Box::new(SqliteGrid::begin(self)?))
    }

    fn grid(&mut self) -> Result<Option<String>> {
        stored_grid(self.conn()).map_err(self.err())
    }

    fn records(&mut self) -> Result<Vec<String>> {
        strings(
            self.conn(),
            "SELECT record FROM runs WHERE record IS NOT NULL ORDER BY id",
        )
        .map_err(self.err())
    }

    fn sessions(&mut self) -> Result<Vec<String>> {
        strings(self.conn(), "SELECT session FROM sessions ORDER BY id").map_err(self.err())
    }

    fn add_session(&mut self, session: &str) -> Result<()> {
        self.conn()
            .execute(
                "INSERT INTO sessions (session) VALUES (?1)",
                params![session],
            )
            .map_err(self.err())?;
        Ok(())
    }
}

impl GridTransaction for SqliteTransaction<'_, Cells> {
    fn grid(&mut self) -> Result<Option<String>> {
        stored_grid(self.tx()).map_err(self.err())
    }

    fn create(&mut self, grid: &str, runs: &[String]) -> Result<()> {
        let (tx, err) = (self.tx(), self.err());
        tx.execute("INSERT INTO grid (id, grid) VALUES (1, ?1)", params![grid])
            .map_err(&err)?;
        for (k, run) in runs.iter().enumerate() {
            tx.execute(
                "INSERT INTO runs (id, run) VALUES (?1, ?2)",
                params![k as i64 + 1, run],
            )
            .map_err(&err)?;
        }
        Ok(())
    }

    fn finish(&mut self, id: i64, record: &str, now: f64) -> Result<bool> {
        let n = self
            .tx()
            .execute(
                "UPDATE runs SET record = ?1, finished_unix_s = ?2 WHERE id = ?3 AND record IS NULL",
                params![record, now, id],
            )
            .map_err(self.err())?;
        Ok(n == 1)
    }
}
