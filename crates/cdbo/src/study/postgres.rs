//! The PostgreSQL back end: any number of studies by name in one database, driven by workers
//! on many machines at once. Tables `cdbo_meta` (the schema version, [`SCHEMA_VERSION`], the
//! same as SQLite's), `cdbo_studies` (settings and optimiser state per study) and
//! `cdbo_trials` (the same columns as an SQLite study's `trials`, keyed by study and id); the
//! experiment grids spread over workers keep `cdbo_grids`, `cdbo_grid_runs` and
//! `cdbo_grid_sessions` ([`crate::experiment::shared`]).
//! Numbers are `DOUBLE PRECISION`, read and written in binary: bit for bit.
//!
//! Every write transaction first takes the study's row lock (`SELECT … FOR UPDATE` on
//! `cdbo_studies`), the equivalent of SQLite's `BEGIN IMMEDIATE` for one study: claims and
//! tells of one study are serialised, those of different studies run side by side. A trial is
//! thus handed out once, and a new suggestion is made knowing every lap in flight (the
//! fantasy of [`super::claim`]); `SKIP LOCKED` would let a claim skip a trial another worker
//! is renewing and count too few in flight. The pending trials are read `FOR UPDATE` too, so
//! that a claim sees a heartbeat that committed while it waited.

use std::path::Path;
use std::time::Duration;

use postgres::{Client, NoTls};

use super::rows::TRIALS;
use super::rows::postgres::{PgRows, PgRowsTransaction};
use super::storage::{Dump, Row, Storage, Told, Transaction};
use super::{SCHEMA_VERSION, Trial, claim::Claim};
use crate::error::{Error, Result};

/// How long connecting may take before the database counts as unreachable.
pub const CONNECT_TIMEOUT: Duration = Duration::from_secs(10);

/// The tables, created together on a database's first study.
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

/// The trial columns [`to_trial`] reads, in its order.
const TRIAL_COLUMNS: &str = "id, weights, reward, lap_time_s, failure, x_fail";

/// A study in a PostgreSQL database.
pub struct Postgres {
    rows: PgRows,
}

impl Postgres {
    /// Creates study `study` holding `dump` in the database at `url` (and the tables, on the
    /// database's first study); refuses an existing study, or a database of a newer schema,
    /// writing nothing.
    pub fn create(url: &str, study: &str, label: &Path, dump: &Dump) -> Result<()> {
        let err = |e| pg_error(label, e);
        let mut client = connect(url, label)?;
        let mut tx = client.transaction().map_err(err)?;
        ensure_schema(&mut tx, label, super::check_version)?;
        let added = tx
            .execute(
                "INSERT INTO cdbo_studies (name, config, optimizer_state) VALUES ($1, $2, $3) ON CONFLICT (name) DO NOTHING",
                &[&study, &dump.config, &dump.optimizer],
            )
            .map_err(err)?;
        if added == 0 {
            return Err(Error::AlreadyExists {
                path: label.to_owned(),
            });
        }
        for row in &dump.trials {
            let t = &row.trial;
            tx.execute(
                "INSERT INTO cdbo_trials (study, id, weights, reward, lap_time_s, failure, x_fail, asked_unix_s, told_unix_s, owner, lease_until_unix_s)
                 VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11)",
                &[
                    &study,
                    &t.id,
                    &super::weights_json(&t.weights)?,
                    &t.reward,
                    &t.lap_time_s,
                    &t.failure,
                    &t.x_fail,
                    &row.asked_unix_s,
                    &row.told_unix_s,
                    &row.owner,
                    &row.lease_until_unix_s,
                ],
            )
            .map_err(err)?;
        }
        tx.commit().map_err(err)
    }

    /// Opens study `study` in the database at `url` and reads its settings (JSON); read-only,
    /// the session refuses every write.
    pub fn open(
        url: &str,
        study: &str,
        label: &Path,
        writable: bool,
    ) -> Result<(Postgres, String)> {
        let err = |e| pg_error(label, e);
        let mut client = connect(url, label)?;
        if !writable {
            client
                .batch_execute("SET SESSION CHARACTERISTICS AS TRANSACTION READ ONLY")
                .map_err(err)?;
        }
        let mut tx = client.transaction().map_err(err)?;
        let no_study = || Error::NoStudy {
            path: label.to_owned(),
        };
        let version = schema_version(&mut tx, label)?.ok_or_else(no_study)?;
        super::check_version(label, version)?;
        let config: String = tx
            .query_opt("SELECT config FROM cdbo_studies WHERE name = $1", &[&study])
            .map_err(err)?
            .ok_or_else(no_study)?
            .try_get(0)
            .map_err(err)?;
        tx.commit().map_err(err)?;
        Ok((
            Postgres {
                rows: PgRows::new(label, study, client, &TRIALS),
            },
            config,
        ))
    }

    fn rows(&mut self) -> Result<Vec<Row>> {
        let sql = format!(
            "SELECT {TRIAL_COLUMNS}, asked_unix_s, told_unix_s, owner, lease_until_unix_s FROM cdbo_trials WHERE study = $1 ORDER BY id"
        );
        let rows = self.rows.with(|c, study| c.query(&sql, &[&study]))?;
        let label = self.rows.label();
        let err = |e| pg_error(label, e);
        rows.iter()
            .map(|r| {
                Ok(Row {
                    trial: to_trial(r, label)?,
                    asked_unix_s: r.try_get(6).map_err(err)?,
                    told_unix_s: r.try_get(7).map_err(err)?,
                    owner: r.try_get(8).map_err(err)?,
                    lease_until_unix_s: r.try_get(9).map_err(err)?,
                })
            })
            .collect()
    }
}

impl Storage for Postgres {
    fn label(&self) -> &Path {
        self.rows.label()
    }

    fn begin(&mut self) -> Result<Box<dyn Transaction + '_>> {
        Ok(Box::new(PostgresTransaction {
            rows: self.rows.begin()?,
        }))
    }

    fn heartbeat(&mut self, id: i64, owner: &str, until: f64) -> Result<bool> {
        self.rows.heartbeat(id, owner, until)
    }

    fn told(&mut self) -> Result<usize> {
        self.rows.count(true)
    }

    fn history(&mut self) -> Result<Vec<Trial>> {
        Ok(self.rows()?.into_iter().map(|r| r.trial).collect())
    }

    fn dump(&mut self) -> Result<Dump> {
        let (config, optimizer) = self.rows.with(|c, study| {
            let row = c.query_one(
                "SELECT config, optimizer_state FROM cdbo_studies WHERE name = $1",
                &[&study],
            )?;
            Ok((row.try_get(0)?, row.try_get(1)?))
        })?;
        Ok(Dump {
            config,
            optimizer,
            trials: self.rows()?,
        })
    }
}

/// A write transaction on a PostgreSQL study, holding its row lock.
struct PostgresTransaction<'a> {
    rows: PgRowsTransaction<'a>,
}

impl Transaction for PostgresTransaction<'_> {
    fn pending(&mut self) -> Result<Vec<(Trial, Claim)>> {
        let sql = format!(
            "SELECT {TRIAL_COLUMNS}, owner, lease_until_unix_s FROM cdbo_trials WHERE study = $1 AND reward IS NULL ORDER BY id FOR UPDATE"
        );
        let rows = self.rows.with(|tx, study| tx.query(&sql, &[&study]))?;
        let label = self.rows.label();
        let err = |e| pg_error(label, e);
        rows.iter()
            .map(|r| {
                let t = to_trial(r, label)?;
                let c = Claim {
                    trial: t.id,
                    owner: r.try_get(6).map_err(err)?,
                    lease_until: r.try_get(7).map_err(err)?,
                };
                Ok((t, c))
            })
            .collect()
    }

    fn told(&mut self) -> Result<usize> {
        self.rows.count(true)
    }

    fn told_rewards(&mut self) -> Result<Vec<f64>> {
        self.rows.with(|tx, study| {
            tx.query(
                "SELECT reward FROM cdbo_trials WHERE study = $1 AND reward IS NOT NULL ORDER BY id",
                &[&study],
            )?
            .iter()
            .map(|r| r.try_get(0))
            .collect()
        })
    }

    fn trial(&mut self, id: i64) -> Result<Option<Trial>> {
        let sql = format!(
            "SELECT {TRIAL_COLUMNS} FROM cdbo_trials WHERE study = $1 AND id = $2 FOR UPDATE"
        );
        let row = self
            .rows
            .with(|tx, study| tx.query_opt(&sql, &[&study, &id]))?;
        row.map(|r| to_trial(&r, self.rows.label())).transpose()
    }

    fn optimizer_state(&mut self) -> Result<String> {
        self.rows.with(|tx, study| {
            tx.query_one(
                "SELECT optimizer_state FROM cdbo_studies WHERE name = $1",
                &[&study],
            )?
            .try_get(0)
        })
    }

    fn add_trial(
        &mut self,
        weights: &str,
        asked_unix_s: f64,
        claim: Option<(&str, f64)>,
    ) -> Result<i64> {
        let (owner, until) = claim.unzip();
        self.rows.with(|tx, study| {
            tx.query_one(
                "INSERT INTO cdbo_trials (study, id, weights, asked_unix_s, owner, lease_until_unix_s)
                 SELECT $1, COALESCE(MAX(id), 0) + 1, $2, $3, $4, $5 FROM cdbo_trials WHERE study = $1
                 RETURNING id",
                &[&study, &weights, &asked_unix_s, &owner, &until],
            )?
            .try_get(0)
        })
    }

    fn set_claim(&mut self, id: i64, owner: &str, until: f64) -> Result<()> {
        self.rows.set_claim(id, owner, until)
    }

    fn record(&mut self, id: i64, told: &Told, optimizer_state: &str) -> Result<()> {
        self.rows.with(|tx, study| {
            tx.execute(
                "UPDATE cdbo_trials SET reward = $1, lap_time_s = $2, failure = $3, x_fail = $4, told_unix_s = $5 WHERE study = $6 AND id = $7",
                &[
                    &told.reward,
                    &told.lap_time_s,
                    &told.failure,
                    &told.x_fail,
                    &told.told_unix_s,
                    &study,
                    &id,
                ],
            )?;
            tx.execute(
                "UPDATE cdbo_studies SET optimizer_state = $1 WHERE name = $2",
                &[&optimizer_state, &study],
            )
        })?;
        Ok(())
    }

    fn commit(self: Box<Self>) -> Result<()> {
        self.rows.commit()
    }
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
    super::check_version(label, version)?;
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
/// `check_version`'s error, having written nothing.
pub(crate) fn ensure_schema(
    tx: &mut postgres::Transaction<'_>,
    label: &Path,
    check_version: fn(&Path, i64) -> Result<()>,
) -> Result<()> {
    let err = |e| pg_error(label, e);
    tx.execute("SELECT pg_advisory_xact_lock($1)", &[&SCHEMA_LOCK])
        .map_err(err)?;
    if let Some(version) = schema_version(tx, label)? {
        check_version(label, version)?;
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
pub(crate) fn connect(url: &str, label: &Path) -> Result<Client> {
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
        .batch_execute(&format!(
            "SET lock_timeout = {}",
            super::BUSY_TIMEOUT.as_millis()
        ))
        .map_err(|e| pg_error(label, e))?;
    Ok(client)
}

/// The database's study schema version; `None` if it holds no cdbo tables.
pub(crate) fn schema_version(
    tx: &mut postgres::Transaction<'_>,
    label: &Path,
) -> Result<Option<i64>> {
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

fn to_trial(r: &postgres::Row, label: &Path) -> Result<Trial> {
    let err = |e| pg_error(label, e);
    let json: String = r.try_get(1).map_err(err)?;
    let weights: Vec<f64> = serde_json::from_str(&json).map_err(|e| Error::Json {
        what: format!("{}: trial weights", label.display()),
        source: e,
    })?;
    Ok(Trial {
        id: r.try_get(0).map_err(err)?,
        weights,
        reward: r.try_get(2).map_err(err)?,
        lap_time_s: r.try_get(3).map_err(err)?,
        failure: r.try_get(4).map_err(err)?,
        x_fail: r.try_get(5).map_err(err)?,
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
