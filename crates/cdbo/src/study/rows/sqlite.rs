//! Claimed rows in an SQLite file. Writers take SQLite's write lock for the whole transaction
//! (`BEGIN IMMEDIATE`); another process waits up to [`crate::study::BUSY_TIMEOUT`], then gets a
//! clear "busy" error ([`sql_error`]).

use std::path::{Path, PathBuf};

use rusqlite::{Connection, TransactionBehavior, params};

use super::ClaimedRows;
use crate::error::{Error, Result};
use crate::study::sqlite::sql_error;

/// A table of claimed rows in an SQLite file, and the connection to it.
pub(crate) struct SqliteRows {
    path: PathBuf,
    conn: Connection,
    table: &'static ClaimedRows,
}

impl SqliteRows {
    /// The rows of `table` in the file at `path`, opened as `conn`.
    pub(crate) fn new(path: &Path, conn: Connection, table: &'static ClaimedRows) -> SqliteRows {
        SqliteRows {
            path: path.to_owned(),
            conn,
            table,
        }
    }

    /// The file.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// The connection, to read without the write lock.
    pub(crate) fn conn(&self) -> &Connection {
        &self.conn
    }

    /// An SQLite error as this file's [`Error`].
    pub(crate) fn err(&self) -> impl Fn(rusqlite::Error) -> Error + '_ {
        |e| sql_error(&self.path, e)
    }

    /// Starts a transaction holding the file's write lock until it commits or is dropped.
    pub(crate) fn begin(&mut self) -> Result<SqliteRowsTransaction<'_>> {
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(|e| sql_error(&self.path, e))?;
        Ok(SqliteRowsTransaction {
            path: &self.path,
            tx,
            table: self.table,
        })
    }

    /// Renews `owner`'s claim on row `id`, not done yet, until `until`; false if the row is
    /// done or no longer `owner`'s.
    pub(crate) fn heartbeat(&mut self, id: i64, owner: &str, until: f64) -> Result<bool> {
        let ClaimedRows { sqlite, done, .. } = self.table;
        let n = self
            .conn
            .execute(
                &format!(
                    "UPDATE {sqlite} SET lease_until_unix_s = ?1 WHERE id = ?2 AND owner = ?3 AND {done} IS NULL"
                ),
                params![until, id, owner],
            )
            .map_err(self.err())?;
        Ok(n == 1)
    }

    /// Number of rows done (or, `done` false, not done yet).
    pub(crate) fn count(&self, done: bool) -> Result<usize> {
        count(&self.conn, self.table, done).map_err(self.err())
    }
}

/// A write transaction on claimed rows, under the file's write lock.
pub(crate) struct SqliteRowsTransaction<'a> {
    path: &'a Path,
    tx: rusqlite::Transaction<'a>,
    table: &'static ClaimedRows,
}

impl<'a> SqliteRowsTransaction<'a> {
    /// The transaction, for what the table's owner stores beside the claims.
    pub(crate) fn tx(&self) -> &rusqlite::Transaction<'a> {
        &self.tx
    }

    /// An SQLite error as this file's [`Error`].
    pub(crate) fn err(&self) -> impl Fn(rusqlite::Error) -> Error + 'a {
        let path = self.path;
        move |e| sql_error(path, e)
    }

    /// Number of rows done (or, `done` false, not done yet).
    pub(crate) fn count(&self, done: bool) -> Result<usize> {
        count(&self.tx, self.table, done).map_err(self.err())
    }

    /// Claims row `id` for `owner` until `until`.
    pub(crate) fn set_claim(&mut self, id: i64, owner: &str, until: f64) -> Result<()> {
        self.tx
            .execute(
                &format!(
                    "UPDATE {} SET owner = ?1, lease_until_unix_s = ?2 WHERE id = ?3",
                    self.table.sqlite
                ),
                params![owner, until, id],
            )
            .map_err(self.err())?;
        Ok(())
    }

    /// Makes every change durable, then releases the lock.
    pub(crate) fn commit(self) -> Result<()> {
        let err = self.err();
        self.tx.commit().map_err(err)
    }
}

fn count(conn: &Connection, table: &ClaimedRows, done: bool) -> rusqlite::Result<usize> {
    let ClaimedRows {
        sqlite,
        done: column,
        ..
    } = table;
    let is = if done { "IS NOT NULL" } else { "IS NULL" };
    conn.query_row(
        &format!("SELECT COUNT(*) FROM {sqlite} WHERE {column} {is}"),
        [],
        |r| r.get::<_, i64>(0),
    )
    .map(|n| n as usize)
}
