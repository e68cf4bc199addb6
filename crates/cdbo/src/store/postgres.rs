//! The PostgreSQL back end: any number of studies and grids by name in one database, driven
//! by workers on many machines at once. Table `cdbo_meta` holds the schema version
//! ([`SCHEMA_VERSION`], the same as SQLite's); the studies keep `cdbo_studies` and
//! `cdbo_trials` (the same columns as an SQLite study's `trials`, keyed by study and id), the
//! grids `cdbo_grids`, `cdbo_grid_runs` and `cdbo_grid_sessions`, all created together.
//! Numbers are `DOUBLE PRECISION`, read and written in binary: bit for bit.
//!
//! Every write transaction first takes its study's or grid's lock (the `lock` statement of its
//! kind's table), so that the claims of one study or grid are serialised as SQLite's write
//! lock serialises a file's, while those of others run side by side.

use std::marker::PhantomData;
use std::path::{Path, PathBuf};
use std::time::Duration;

use postgres::{Client, GenericClient, NoTls};

use super::claim::Claim;
use super::{BUSY_TIMEOUT, Kind, Parent, Rows, RowsTransaction, SCHEMA_VERSION, check_version};
use crate::error::{Error, Result};

/// How long connecting may take before the database counts as unreachable.
pub const CONNECT_TIMEOUT: Duration = Duration::from_secs(10);

/// The tables of studies and grids: one schema, one version for the whole database, created
/// together on its first study or grid.
const SCHEMA: &str = "
    CREATE TABLE IF NOT EXISTS cdbo_meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
    CREATE TABLE IF NOT EXISTS cdbo_studies (
        name TEXT PRIMARY KEY,
        config TEXT NOT NULL,
        optimizer_state TEXT NOT NULL);
    CREATE TABLE IF NOT EXISTS cdbo_trials (
        study TEXT NOT NULL REFERENCES cdbo_studies (name) ON DELETE CASCADE,
        id BIGINT NOT NULL,
        weights TEXT NOT NULL,
        reward DOUBLE PRECISION,
        lap_time_s DOUBLE PRECISION,
        failure TEXT,
        x_fail DOUBLE PRECISION,
        asked_unix_s DOUBLE PRECISION NOT NULL,
        told_unix_s DOUBLE PRECISION,
        owner TEXT,
        lease_until_unix_s DOUBLE PRECISION,
        PRIMARY KEY (study, id));
    CREATE TABLE IF NOT EXISTS cdbo_grids (name TEXT PRIMARY KEY, grid TEXT NOT NULL);
    CREATE TABLE IF NOT EXISTS cdbo_grid_runs (
        grid TEXT NOT NULL REFERENCES cdbo_grids (name) ON DELETE CASCADE,
        id BIGINT NOT NULL,
        run TEXT NOT NULL,
        record TEXT,
        owner TEXT,
        lease_until_unix_s DOUBLE PRECISION,
        finished_unix_s DOUBLE PRECISION,
        PRIMARY KEY (grid, id));
    CREATE TABLE IF NOT EXISTS cdbo_grid_sessions (
        grid TEXT NOT NULL REFERENCES cdbo_grids (name) ON DELETE CASCADE,
        id BIGSERIAL PRIMARY KEY,
        session TEXT NOT NULL);";

/// The advisory lock key under which a database's tables are created (`cdbo` in ASCII).
const SCHEMA_LOCK: i64 = 0x6364_626f;

/// What a statement returns, before its error names the database.
pub(crate) type Sql<T> = std::result::Result<T, postgres::Error>;

/// The claimed rows of kind `K` that belong to one study or grid in a PostgreSQL database, and
/// the connection to it.
pub(crate) struct PgRows<K> {
    label: PathBuf,
    parent: String,
    client: Client,
    kind: PhantomData<K>,
}

impl<K: Kind> PgRows<K> {
    /// Connects to the database at `url` for the study or grid `name` (`label` names it in
    /// messages): to write, creating the tables where the database has none if the kind is
    /// [`Table::made_on_open`]; to read, in a session that refuses every write. Refuses a
    /// database without cdbo tables (where they are not made) or of a newer schema, writing
    /// nothing.
    pub(crate) fn open(url: &str, name: &str, label: &Path, writable: bool) -> Result<PgRows<K>> {
        let table = &K::TABLE;
        let err = |e| pg_error(label, e);
        let mut client = connect(url, label)?;
        if !writable {
            client
                .batch_execute("SET SESSION CHARACTERISTICS AS TRANSACTION READ ONLY")
                .map_err(err)?;
        }
        let mut tx = client.transaction().map_err(err)?;
        if writable && table.parent.made_on_open() {
            ensure_schema(&mut tx, label, table.parent)?;
        } else {
            let version = schema_version(&mut tx, label)?
                .ok_or_else(|| table.parent.missing(label.to_owned()))?;
            check_version(label, version, table.parent)?;
        }
        tx.commit().map_err(err)?;
        Ok(PgRows {
            label: label.to_owned(),
            parent: name.to_owned(),
            client,
            kind: PhantomData,
        })
    }

    /// Stores the study or grid `name` in the database at `url` (and the tables, on the
    /// database's first study or grid) with what `fill` writes, in one transaction; refuses a
    /// database of a newer schema, writing nothing.
    pub(crate) fn create(
        url: &str,
        name: &str,
        label: &Path,
        fill: impl FnOnce(&mut PgTransaction<'_, K>) -> Result<()>,
    ) -> Result<()> {
        let err = |e| pg_error(label, e);
        let mut client = connect(url, label)?;
        let mut tx = client.transaction().map_err(err)?;
        ensure_schema(&mut tx, label, K::TABLE.parent)?;
        let mut tx = PgTransaction {
            label,
            parent: name,
            tx,
            kind: PhantomData,
        };
        fill(&mut tx)?;
        Box::new(tx).commit()
    }

    /// Runs `f` on the connection, outside a transaction's lock, with the study's or grid's
    /// name; its error names the database.
    pub(crate) fn with<T>(&mut self, f: impl FnOnce(&mut Client, &str) -> Sql<T>) -> Result<T> {
        f(&mut self.client, &self.parent).map_err(|e| pg_error(&self.label, e))
    }

    /// Starts a transaction holding the study's or grid's write lock until it commits or is
    /// dropped (rolled back); refuses a study or grid that has nothing to lock.
    pub(crate) fn begin(&mut self) -> Result<PgTransaction<'_, K>> {
        let label = &self.label;
        let err = |e| pg_error(label, e);
        let mut tx = self.client.transaction().map_err(err)?;
        let locked = tx.query_opt(K::TABLE.lock, &[&self.parent]).map_err(err)?;
        if locked.is_none() {
            return Err(K::TABLE.parent.missing(label.clone()));
        }
        Ok(PgTransaction {
            label,
            parent: &self.parent,
            tx,
            kind: PhantomData,
        })
    }
}

impl<K: Kind> Rows for PgRows<K> {
    fn label(&self) -> &Path {
        &self.label
    }

    fn heartbeat(&mut self, id: i64, owner: &str, until: f64) -> Result<bool> {
        let sql = format!(
            "UPDATE {} SET lease_until_unix_s = $2 WHERE {} AND id = $3 AND owner = $4",
            K::TABLE.postgres,
            rows_of::<K>(false),
        );
        let n = self.with(|c, name| c.execute(&sql, &[&name, &until, &id, &owner]))?;
        Ok(n == 1)
    }

    fn count(&mut self, done: bool) -> Result<usize> {
        self.with(|c, name| count::<K>(c, name, done))
    }
}

/// A write transaction on one study's or grid's claimed rows, holding its lock.
pub(crate) struct PgTransaction<'a, K> {
    label: &'a Path,
    parent: &'a str,
    tx: postgres::Transaction<'a>,
    kind: PhantomData<K>,
}

impl<'a, K: Kind> PgTransaction<'a, K> {
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
}

impl<K: Kind> RowsTransaction for PgTransaction<'_, K> {
    fn count(&mut self, done: bool) -> Result<usize> {
        self.with(|tx, name| count::<K>(tx, name, done))
    }

    fn claims(&mut self) -> Result<Vec<Claim>> {
        let sql = format!(
            "SELECT id, owner, lease_until_unix_s FROM {} WHERE {} ORDER BY id",
            K::TABLE.postgres,
            rows_of::<K>(false),
        );
        self.with(|tx, name| {
            tx.query(&sql, &[&name])?
                .iter()
                .map(|r| {
                    Ok(Claim {
                        trial: r.try_get(0)?,
                        owner: r.try_get(1)?,
                        lease_until: r.try_get(2)?,
                    })
                })
                .collect()
        })
    }

    fn set_claim(&mut self, id: i64, owner: &str, until: f64) -> Result<()> {
        let sql = format!(
            "UPDATE {} SET owner = $2, lease_until_unix_s = $3 WHERE {} = $1 AND id = $4",
            K::TABLE.postgres,
            K::TABLE.parent.column(),
        );
        self.with(|tx, name| tx.execute(&sql, &[&name, &owner, &until, &id]))?;
        Ok(())
    }

    fn commit(self: Box<Self>) -> Result<()> {
        let label = self.label;
        self.tx.commit().map_err(|e| pg_error(label, e))
    }
}

/// Number of `name`'s rows done (or, `done` false, not done yet).
fn count<K: Kind>(client: &mut impl GenericClient, name: &str, done: bool) -> Sql<usize> {
    let sql = format!(
        "SELECT COUNT(*) FROM {} WHERE {}",
        K::TABLE.postgres,
        rows_of::<K>(done)
    );
    let n: i64 = client.query_one(&sql, &[&name])?.try_get(0)?;
    Ok(n as usize)
}

/// The condition that picks the rows of the study or grid named `$1` that are done (or,
/// `done` false, not done yet).
fn rows_of<K: Kind>(done: bool) -> String {
    let is = if done { "IS NOT NULL" } else { "IS NULL" };
    format!(
        "{} = $1 AND {} {is}",
        K::TABLE.parent.column(),
        K::TABLE.done
    )
}

/// The studies and the grids the database at `url` holds, by name, in a read-only session
/// (none of either where it has no cdbo tables); refuses a database of a newer schema.
pub fn names(url: &str, label: &Path) -> Result<(Vec<String>, Vec<String>)> {
    let err = |e| pg_error(label, e);
    let mut client = connect(url, label)?;
    client
        .batch_execute("SET SESSION CHARACTERISTICS AS TRANSACTION READ ONLY")
        .map_err(err)?;
    let mut tx = client.transaction().map_err(err)?;
    let Some(version) = schema_version(&mut tx, label)? else {
        return Ok((Vec::new(), Vec::new()));
    };
    check_version(label, version, Parent::Study)?;
    let mut listed = Vec::new();
    for table in ["cdbo_studies", "cdbo_grids"] {
        let exists: bool = tx
            .query_one("SELECT to_regclass($1) IS NOT NULL", &[&table])
            .and_then(|r| r.try_get(0))
            .map_err(err)?;
        let names = if exists {
            tx.query(&format!("SELECT name FROM {table} ORDER BY name"), &[])
                .map_err(err)?
                .iter()
                .map(|r| r.try_get(0).map_err(err))
                .collect::<Result<Vec<String>>>()?
        } else {
            Vec::new()
        };
        listed.push(names);
    }
    let grids = listed.pop().unwrap_or_default();
    let studies = listed.pop().unwrap_or_default();
    Ok((studies, grids))
}

/// Creates the tables where the database has none yet, under the schema lock (workers that
/// start at once create them once); first refuses a database of a newer schema with
/// `parent`'s error, having written nothing.
fn ensure_schema(tx: &mut postgres::Transaction<'_>, label: &Path, parent: Parent) -> Result<()> {
    let err = |e| pg_error(label, e);
    tx.execute("SELECT pg_advisory_xact_lock($1)", &[&SCHEMA_LOCK])
        .map_err(err)?;
    if let Some(version) = schema_version(tx, label)? {
        check_version(label, version, parent)?;
    }
    tx.batch_execute(SCHEMA).map_err(err)?;
    tx.execute(
        "INSERT INTO cdbo_meta (key, value) VALUES ('schema_version', $1) ON CONFLICT (key) DO NOTHING",
        &[&SCHEMA_VERSION.to_string()],
    )
    .map_err(err)?;
    Ok(())
}

/// A connection to the database at `url`: an unreachable server or refused credentials are
/// one line naming the database.
fn connect(url: &str, label: &Path) -> Result<Client> {
    let mut config: postgres::Config = url.parse().map_err(|e| pg_error(label, e))?;
    if config.get_connect_timeout().is_none() {
        config.connect_timeout(CONNECT_TIMEOUT);
    }
    let mut client = config
        .application_name("cdbo")
        .connect(NoTls)
        .map_err(|e| pg_error(label, e))?;
    // A study locked longer than SQLite's busy timeout is "busy", as an SQLite study is.
    client
        .batch_execute(&format!("SET lock_timeout = {}", BUSY_TIMEOUT.as_millis()))
        .map_err(|e| pg_error(label, e))?;
    Ok(client)
}

/// The database's study schema version; `None` if it holds no cdbo tables.
fn schema_version(tx: &mut postgres::Transaction<'_>, label: &Path) -> Result<Option<i64>> {
    let err = |e| pg_error(label, e);
    let has_tables: bool = tx
        .query_one("SELECT to_regclass('cdbo_meta') IS NOT NULL", &[])
        .and_then(|r| r.try_get(0))
        .map_err(err)?;
    if !has_tables {
        return Ok(None);
    }
    let value: Option<String> = tx
        .query_opt(
            "SELECT value FROM cdbo_meta WHERE key = 'schema_version'",
            &[],
        )
        .map_err(err)?
        .map(|r| r.try_get(0))
        .transpose()
        .map_err(err)?;
    let value = value.ok_or_else(|| Error::NotAStudy {
        path: label.to_owned(),
        reason: "a cdbo_meta table without a schema version".into(),
    })?;
    value.parse().map(Some).map_err(|_| Error::NotAStudy {
        path: label.to_owned(),
        reason: format!("schema version {value:?} is not a number"),
    })
}

/// Sorts a PostgreSQL error: a lock not had within the lock timeout is "busy", as in SQLite.
pub(crate) fn pg_error(label: &Path, source: postgres::Error) -> Error {
    if source.code() == Some(&postgres::error::SqlState::LOCK_NOT_AVAILABLE) {
        return Error::Busy {
            path: label.to_owned(),
        };
    }
    Error::Postgres {
        path: label.to_owned(),
        source,
    }
}
