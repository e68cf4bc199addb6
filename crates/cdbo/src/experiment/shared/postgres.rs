//! Grids in a PostgreSQL database, by name, beside its studies: tables `cdbo_grids`,
//! `cdbo_grid_runs` (one row per cell) and `cdbo_grid_sessions`, created with the studies'
//! under the one schema version ([`crate::study::postgres`]). Every write transaction first
//! takes the grid's advisory lock (a key hashed from its name), so that the claims of one grid
//! are serialised, as SQLite's write lock does, and workers that start at once on a grid not
//! stored yet store it once.

use std::path::{Path, PathBuf};

use postgres::Client;

use super::{GridStorage, GridTransaction, check_version};
use crate::error::{Error, Result};
use crate::study::claim::Claim;
use crate::study::postgres::{connect, ensure_schema, pg_error, schema_version};

/// A grid in a PostgreSQL database.
pub struct PostgresGrid {
    label: PathBuf,
    name: String,
    client: Client,
}

impl PostgresGrid {
    /// Connects to the database at `url` for grid `name`: to write, creating the tables where
    /// the database has none; to read, in read-only transactions. Refuses a database of a
    /// newer schema, writing nothing.
    pub fn open(url: &str, name: &str, label: &Path, writable: bool) -> Result<PostgresGrid> {
        let err = |e| pg_error(label, e);
        let mut client = connect(url, label)?;
        if writable {
            let mut tx = client.transaction().map_err(err)?;
            ensure_schema(&mut tx, label, check_version)?;
            tx.commit().map_err(err)?;
        } else {
            client
                .batch_execute("SET SESSION CHARACTERISTICS AS TRANSACTION READ ONLY")
                .map_err(err)?;
            let mut tx = client.transaction().map_err(err)?;
            let version = schema_version(&mut tx, label)?.ok_or_else(|| Error::NoGrid {
                path: label.to_owned(),
            })?;
            check_version(label, version)?;
            tx.commit().map_err(err)?;
        }
        Ok(PostgresGrid {
            label: label.to_owned(),
            name: name.to_owned(),
            client,
        })
    }

    fn strings(&mut self, sql: &str) -> Result<Vec<String>> {
        let rows = self
            .client
            .query(sql, &[&self.name])
            .map_err(|e| pg_error(&self.label, e))?;
        rows.iter()
            .map(|r| r.try_get(0).map_err(|e| pg_error(&self.label, e)))
            .collect()
    }
}

fn stored_grid(
    client: &mut impl postgres::GenericClient,
    name: &str,
    label: &Path,
) -> Result<Option<String>> {
    client
        .query_opt("SELECT grid FROM cdbo_grids WHERE name = $1", &[&name])
        .map_err(|e| pg_error(label, e))?
        .map(|r| r.try_get(0).map_err(|e| pg_error(label, e)))
        .transpose()
}

impl GridStorage for PostgresGrid {
    fn label(&self) -> &Path {
        &self.label
    }

    fn begin(&mut self) -> Result<Box<dyn GridTransaction + '_>> {
        let label = &self.label;
        let mut tx = self.client.transaction().map_err(|e| pg_error(label, e))?;
        tx.execute(
            "SELECT pg_advisory_xact_lock(hashtextextended('cdbo grid ' || $1, 0))",
            &[&self.name],
        )
        .map_err(|e| pg_error(label, e))?;
        Ok(Box::new(PostgresGridTransaction {
            label,
            name: &self.name,
            tx,
        }))
    }

    fn heartbeat(&mut self, id: i64, owner: &str, until: f64) -> Result<bool> {
        let n = self
            .client
            .execute(
                "UPDATE cdbo_grid_runs SET lease_until_unix_s = $1 WHERE grid = $2 AND id = $3 AND owner = $4 AND record IS NULL",
                &[&until, &self.name, &id, &owner],
            )
            .map_err(|e| pg_error(&self.label, e))?;
        Ok(n == 1)
    }

    fn grid(&mut self) -> Result<Option<String>> {
        stored_grid(&mut self.client, &self.name, &self.label)
    }

    fn records(&mut self) -> Result<Vec<String>> {
        self.strings(
            "SELECT record FROM cdbo_grid_runs WHERE grid = $1 AND record IS NOT NULL ORDER BY id",
        )
    }

    fn unfinished_count(&mut self) -> Result<usize> {
        let row = self
            .client
            .query_one(
                "SELECT COUNT(*) FROM cdbo_grid_runs WHERE grid = $1 AND record IS NULL",
                &[&self.name],
            )
            .map_err(|e| pg_error(&self.label, e))?;
        let n: i64 = row.try_get(0).map_err(|e| pg_error(&self.label, e))?;
        Ok(n as usize)
    }

    fn sessions(&mut self) -> Result<Vec<String>> {
        self.strings("SELECT session FROM cdbo_grid_sessions WHERE grid = $1 ORDER BY id")
    }

    fn add_session(&mut self, session: &str) -> Result<()> {
        self.client
            .execute(
                "INSERT INTO cdbo_grid_sessions (grid, session) VALUES ($1, $2)",
                &[&self.name, &session],
            )
            .map_err(|e| pg_error(&self.label, e))?;
        Ok(())
    }
}

/// A write transaction on a PostgreSQL grid, holding its advisory lock.
struct PostgresGridTransaction<'a> {
    label: &'a Path,
    name: &'a str,
    tx: postgres::Transaction<'a>,
}

impl PostgresGridTransaction<'_> {
    fn err(&self) -> impl Fn(postgres::Error) -> Error + '_ {
        |e| pg_error(self.label, e)
    }
}

impl GridTransaction for PostgresGridTransaction<'_> {
    fn grid(&mut self) -> Result<Option<String>> {
        stored_grid(&mut self.tx, self.name, self.label)
    }

    fn create(&mut self, grid: &str, runs: &[String]) -> Result<()> {
        self.tx
            .execute(
                "INSERT INTO cdbo_grids (name, grid) VALUES ($1, $2)",
                &[&self.name, &grid],
            )
            .map_err(self.err())?;
        let ids: Vec<i64> = (1..=runs.len() as i64).collect();
        self.tx
            .execute(
                "INSERT INTO cdbo_grid_runs (grid, id, run) SELECT $1, * FROM UNNEST($2::BIGINT[], $3::TEXT[])",
                &[&self.name, &ids, &runs],
            )
            .map_err(self.err())?;
        Ok(())
    }

    fn unfinished(&mut self) -> Result<Vec<Claim>> {
        let rows = self
            .tx
            .query(
                "SELECT id, owner, lease_until_unix_s FROM cdbo_grid_runs WHERE grid = $1 AND record IS NULL ORDER BY id",
                &[&self.name],
            )
            .map_err(self.err())?;
        rows.iter()
            .map(|r| {
                Ok(Claim {
                    trial: r.try_get(0).map_err(self.err())?,
                    owner: r.try_get(1).map_err(self.err())?,
                    lease_until: r.try_get(2).map_err(self.err())?,
                })
            })
            .collect()
    }

    fn finished(&mut self) -> Result<usize> {
        let n: i64 = self
            .tx
            .query_one(
                "SELECT COUNT(*) FROM cdbo_grid_runs WHERE grid = $1 AND record IS NOT NULL",
                &[&self.name],
            )
            .and_then(|r| r.try_get(0))
            .map_err(self.err())?;
        Ok(n as usize)
    }

    fn set_claim(&mut self, id: i64, owner: &str, until: f64) -> Result<()> {
        self.tx
            .execute(
                "UPDATE cdbo_grid_runs SET owner = $1, lease_until_unix_s = $2 WHERE grid = $3 AND id = $4",
                &[&owner, &until, &self.name, &id],
            )
            .map_err(self.err())?;
        Ok(())
    }

    fn finish(&mut self, id: i64, record: &str, now: f64) -> Result<bool> {
        let n = self
            .tx
            .execute(
                "UPDATE cdbo_grid_runs SET record = $1, finished_unix_s = $2 WHERE grid = $3 AND id = $4 AND record IS NULL",
                &[&record, &now, &self.name, &id],
            )
            .map_err(self.err())?;
        Ok(n == 1)
    }

    fn commit(self: Box<Self>) -> Result<()> {
        let label = self.label;
        self.tx.commit().map_err(|e| pg_error(label, e))
    }
}
