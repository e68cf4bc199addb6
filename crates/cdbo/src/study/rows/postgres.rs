//! Claimed rows in a PostgreSQL database, keyed by the study or grid they belong to. Every
//! write transaction first takes that study's or grid's lock ([`ClaimedRows::lock`]), so that
//! its claims are serialised as SQLite's write lock serialises a file's, while those of other
//! studies and grids run side by side.

use std::path::{Path, PathBuf};

use postgres::{Client, GenericClient};

use super::ClaimedRows;
use crate::error::Result;
use crate::study::postgres::pg_error;

/// What a statement returns, before its error names the database.
pub(crate) type Sql<T> = std::result::Result<T, postgres::Error>;

/// The claimed rows of one study or grid in a PostgreSQL database, and the connection to it.
pub(crate) struct PgRows {
    label: PathBuf,
    parent: String,
    client: Client,
    table: &'static ClaimedRows,
}

impl PgRows {
    /// The rows of `table` that belong to `parent` (the study's or grid's name), reached by
    /// `client`; `label` names them in messages.
    pub(crate) fn new(
        label: &Path,
        parent: &str,
        client: Client,
        table: &'static ClaimedRows,
    ) -> PgRows {
        PgRows {
            label: label.to_owned(),
            parent: parent.to_owned(),
            client,
            table,
        }
    }

    /// Where they live, for messages (never with a password).
    pub(crate) fn label(&self) -> &Path {
        &self.label
    }

    /// Runs `f` on the connection, outside a transaction's lock, with the study's or grid's
    /// name; its error names the database.
    pub(crate) fn with<T>(&mut self, f: impl FnOnce(&mut Client, &str) -> Sql<T>) -> Result<T> {
        f(&mut self.client, &self.parent).map_err(|e| pg_error(&self.label, e))
    }

    /// Starts a transaction holding the study's or grid's write lock until it commits or is
    /// dropped (rolled back); refuses a study or grid that has nothing to lock.
    pub(crate) fn begin(&mut self) -> Result<PgRowsTransaction<'_>> {
        let label = &self.label;
        let err = |e| pg_error(label, e);
        let mut tx = self.client.transaction().map_err(err)?;
        let locked = tx
            .query_opt(self.table.lock, &[&self.parent])
            .map_err(err)?;
        if locked.is_none() {
            return Err((self.table.missing)(label.clone()));
        }
        Ok(PgRowsTransaction {
            label,
            parent: &self.parent,
            tx,
            table: self.table,
        })
    }

    /// Renews `owner`'s claim on row `id`, not done yet, until `until`; false if the row is
    /// done or no longer `owner`'s.
    pub(crate) fn heartbeat(&mut self, id: i64, owner: &str, until: f64) -> Result<bool> {
        let ClaimedRows {
            postgres,
            parent,
            done,
            ..
        } = self.table;
        let sql = format!(
            "UPDATE {postgres} SET lease_until_unix_s = $1 WHERE {parent} = $2 AND id = $3 AND owner = $4 AND {done} IS NULL"
        );
        let n = self.with(|c, name| c.execute(&sql, &[&until, &name, &id, &owner]))?;
        Ok(n == 1)
    }

    /// Number of rows done (or, `done` false, not done yet).
    pub(crate) fn count(&mut self, done: bool) -> Result<usize> {
        let table = self.table;
        self.with(|c, name| count(c, table, name, done))
    }
}

/// A write transaction on one study's or grid's claimed rows, holding its lock.
pub(crate) struct PgRowsTransaction<'a> {
    label: &'a Path,
    parent: &'a str,
    tx: postgres::Transaction<'a>,
    table: &'static ClaimedRows,
}

impl<'a> PgRowsTransaction<'a> {
    /// Where the rows live, for messages.
    pub(crate) fn label(&self) -> &'a Path {
        self.label
    }

    /// Runs `f` in the transaction with the study's or grid's name; its error names the
    /// database.
    pub(crate) fn with<T>(
        &mut self,
        f: impl FnOnce(&mut postgres::Transaction<'a>, &str) -> Sql<T>,
    ) -> Result<T> {
        f(&mut self.tx, self.parent).map_err(|e| pg_error(self.label, e))
    }

    /// Number of rows done (or, `done` false, not done yet).
    pub(crate) fn count(&mut self, done: bool) -> Result<usize> {
        let table = self.table;
        self.with(|tx, name| count(tx, table, name, done))
    }

    /// Claims row `id` for `owner` until `until`.
    pub(crate) fn set_claim(&mut self, id: i64, owner: &str, until: f64) -> Result<()> {
        let ClaimedRows {
            postgres, parent, ..
        } = self.table;
        let sql = format!(
            "UPDATE {postgres} SET owner = $1, lease_until_unix_s = $2 WHERE {parent} = $3 AND id = $4"
        );
        self.with(|tx, name| tx.execute(&sql, &[&owner, &until, &name, &id]))?;
        Ok(())
    }

    /// Makes every change durable, then releases the lock.
    pub(crate) fn commit(self) -> Result<()> {
        let label = self.label;
        self.tx.commit().map_err(|e| pg_error(label, e))
    }
}

/// Number of `name`'s rows done (or, `done` false, not done yet).
fn count(
    client: &mut impl GenericClient,
    table: &ClaimedRows,
    name: &str,
    done: bool,
) -> Sql<usize> {
    let ClaimedRows {
        postgres,
        parent,
        done: column,
        ..
    } = table;
    let is = if done { "IS NOT NULL" } else { "IS NULL" };
    let sql = format!("SELECT COUNT(*) FROM {postgres} WHERE {parent} = $1 AND {column} {is}");
    let n: i64 = client.query_one(&sql, &[&name])?.try_get(0)?;
    Ok(n as usize)
}
