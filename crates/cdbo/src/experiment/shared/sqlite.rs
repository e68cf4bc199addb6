//! A grid in an SQLite file (one grid per file), for workers on one machine or a shared
//! folder: tables `grid` (the grid's TOML), `runs` (one row per cell) and `sessions`, the
//! schema version in `user_version` as a study's. Writers take SQLite's write lock for the
//! whole transaction (`BEGIN IMMEDIATE`), as a study's do.

use std::path::Path;

use rusqlite::{Connection, OpenFlags, OptionalExtension, params};

use super::{GridStorage, GridTransaction, check_version};
use crate::error::{Error, Result};
use crate::study::SCHEMA_VERSION;
use crate::study::claim::Claim;
use crate::study::rows::CELLS;
use crate::study::rows::sqlite::{SqliteRows, SqliteRowsTransaction};
use crate::study::sqlite::{
    check_header, configure, read_only_connection, sql_error, user_version,
};

/// The tables, created together by the first worker.
const SCHEMA: &str = "
    CREATE TABLE IF NOT EXISTS grid (id INTEGER PRIMARY KEY CHECK (id = 1), grid TEXT NOT NULL);
    CREATE TABLE IF NOT EXISTS runs (
        id INTEGER PRIMARY KEY,
        run TEXT NOT NULL,
        record TEXT,
        owner TEXT,
        lease_until_unix_s REAL,
        finished_unix_s REAL);
    CREATE TABLE IF NOT EXISTS sessions (id INTEGER PRIMARY KEY, session TEXT NOT NULL);";

/// A grid in an SQLite file.
pub struct SqliteGrid {
    rows: SqliteRows,
}

impl SqliteGrid {
    /// Opens the grid file at `path`: to write, creating the file and its tables where
    /// missing (an empty file counts as missing: another worker may have just made it); to
    /// read, an existing grid file only. Refuses a file that is not SQLite, a database
    /// without a grid (a study, say) and a newer schema, writing nothing.
    pub fn open(path: &Path, writable: bool) -> Result<SqliteGrid> {
        let err = |e| sql_error(path, e);
        let empty = std::fs::metadata(path).map_or(true, |m| m.len() == 0);
        if !empty {
            check_header(path).map_err(as_grid)?;
        } else if !writable {
            return Err(Error::NoGrid {
                path: path.to_owned(),
            });
        }
        let conn = if writable {
            Connection::open_with_flags(
                path,
                OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_CREATE,
            )
            .map_err(err)?
        } else {
            read_only_connection(path).map_err(as_grid)?.0
        };
        conn.busy_timeout(crate::study::BUSY_TIMEOUT).map_err(err)?;
        // Read before anything is written: a foreign database is left as it was.
        check_version(path, user_version(&conn).map_err(err)?)?;
        let tables: Vec<String> = conn
            .prepare("SELECT name FROM sqlite_master WHERE type = 'table'")
            .and_then(|mut s| s.query_map([], |r| r.get(0))?.collect())
            .map_err(err)?;
        if !tables.is_empty() && !tables.iter().any(|t| t == "runs") {
            return Err(Error::NotAGrid {
                path: path.to_owned(),
                reason: "an SQLite database without a grid in it".into(),
            });
        }
        if writable {
            configure(&conn).map_err(err)?;
            conn.execute_batch(&format!(
                "BEGIN IMMEDIATE; {SCHEMA} PRAGMA user_version = {SCHEMA_VERSION}; COMMIT;"
            ))
            .map_err(err)?;
        } else if tables.is_empty() {
            return Err(Error::NoGrid {
                path: path.to_owned(),
            });
        }
        Ok(SqliteGrid {
            rows: SqliteRows::new(path, conn, &CELLS),
        })
    }
}

/// A study's "not a cdbo study" as a grid's.
fn as_grid(e: Error) -> Error {
    match e {
        Error::NotAStudy { path, reason } => Error::NotAGrid { path, reason },
        e => e,
    }
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
    fn label(&self) -> &Path {
        self.rows.path()
    }

    fn begin(&mut self) -> Result<Box<dyn GridTransaction + '_>> {
        Ok(Box::new(SqliteGridTransaction {
            rows: self.rows.begin()?,
        }))
    }

    fn heartbeat(&mut self, id: i64, owner: &str, until: f64) -> Result<bool> {
        self.rows.heartbeat(id, owner, until)
    }

    fn grid(&mut self) -> Result<Option<String>> {
        stored_grid(self.rows.conn()).map_err(self.rows.err())
    }

    fn records(&mut self) -> Result<Vec<String>> {
        strings(
            self.rows.conn(),
            "SELECT record FROM runs WHERE record IS NOT NULL ORDER BY id",
        )
        .map_err(self.rows.err())
    }

    fn unfinished_count(&mut self) -> Result<usize> {
        self.rows.count(false)
    }

    fn sessions(&mut self) -> Result<Vec<String>> {
        strings(self.rows.conn(), "SELECT session FROM sessions ORDER BY id")
            .map_err(self.rows.err())
    }

    fn add_session(&mut self, session: &str) -> Result<()> {
        self.rows
            .conn()
            .execute(
                "INSERT INTO sessions (session) VALUES (?1)",
                params![session],
            )
            .map_err(self.rows.err())?;
        Ok(())
    }
}

/// A write transaction on an SQLite grid.
struct SqliteGridTransaction<'a> {
    rows: SqliteRowsTransaction<'a>,
}

impl GridTransaction for SqliteGridTransaction<'_> {
    fn grid(&mut self) -> Result<Option<String>> {
        stored_grid(self.rows.tx()).map_err(self.rows.err())
    }

    fn create(&mut self, grid: &str, runs: &[String]) -> Result<()> {
        let (tx, err) = (self.rows.tx(), self.rows.err());
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

    fn unfinished(&mut self) -> Result<Vec<Claim>> {
        let err = self.rows.err();
        let mut stmt = self
            .rows
            .tx()
            .prepare(
                "SELECT id, owner, lease_until_unix_s FROM runs WHERE record IS NULL ORDER BY id",
            )
            .map_err(&err)?;
        let rows = stmt
            .query_map([], |r| {
                Ok(Claim {
                    trial: r.get(0)?,
                    owner: r.get(1)?,
                    lease_until: r.get(2)?,
                })
            })
            .map_err(&err)?;
        rows.collect::<rusqlite::Result<Vec<_>>>().map_err(err)
    }

    fn finished(&mut self) -> Result<usize> {
        self.rows.count(true)
    }

    fn set_claim(&mut self, id: i64, owner: &str, until: f64) -> Result<()> {
        self.rows.set_claim(id, owner, until)
    }

    fn finish(&mut self, id: i64, record: &str, now: f64) -> Result<bool> {
        let n = self
            .rows
            .tx()
            .execute(
                "UPDATE runs SET record = ?1, finished_unix_s = ?2 WHERE id = ?3 AND record IS NULL",
                params![record, now, id],
            )
            .map_err(self.rows.err())?;
        Ok(n == 1)
    }

    fn commit(self: Box<Self>) -> Result<()> {
        self.rows.commit()
    }
}
