//! Grids in a PostgreSQL database, by name, beside its studies: tables `cdbo_grids`,
//! `cdbo_grid_runs` (one row per cell) and `cdbo_grid_sessions`, created with the studies'
//! under the one schema version ([`crate::study::postgres`]). Every write transaction first
//! takes the grid's advisory lock (a key hashed from its name), so that the claims of one grid
//! are serialised, as SQLite's write lock does, and workers that start at once on a grid not
//! stored yet store it once.

use std::path::Path;

use postgres::GenericClient;

use super::{GridStorage, GridTransaction, check_version};
use crate::error::{Error, Result};
use crate::study::claim::Claim;
use crate::study::postgres::{connect, ensure_schema, pg_error, schema_version};
use crate::study::rows::CELLS;
use crate::study::rows::postgres::{PgRows, PgRowsTransaction, Sql};

/// A grid in a PostgreSQL database.
pub struct PostgresGrid {
    rows: PgRows,
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
            rows: PgRows::new(label, name, client, &CELLS),
        })
    }

    /// The first column of the rows `sql` selects for this grid (`$1`).
    fn strings(&mut self, sql: &str) -> Result<Vec<String>> {
        self.rows.with(|c, name| {
            c.query(sql, &[&name])?
                .iter()
                .map(|r| r.try_get(0))
                .collect()
        })
    }
}

/// The grid as stored (TOML), if the database holds grid `name`.
fn stored_grid(client: &mut impl GenericClient, name: &str) -> Sql<Option<String>> {
    client
        .query_opt("SELECT grid FROM cdbo_grids WHERE name = $1", &[&name])?
        .map(|r| r.try_get(0))
        .transpose()
}

impl GridStorage for PostgresGrid {
    fn label(&self) -> &Path {
        self.rows.label()
    }

    fn begin(&mut self) -> Result<Box<dyn GridTransaction + '_>> {
        Ok(Box::new(PostgresGridTransaction {
            rows: self.rows.begin()?,
        }))
    }

    fn heartbeat(&mut self, id: i64, owner: &str, until: f64) -> Result<bool> {
        self.rows.heartbeat(id, owner, until)
    }

    fn grid(&mut self) -> Result<Option<String>> {
        self.rows.with(stored_grid)
    }

    fn records(&mut self) -> Result<Vec<String>> {
        self.strings(
            "SELECT record FROM cdbo_grid_runs WHERE grid = $1 AND record IS NOT NULL ORDER BY id",
        )
    }

    fn unfinished_count(&mut self) -> Result<usize> {
        self.rows.count(false)
    }

    fn sessions(&mut self) -> Result<Vec<String>> {
        self.strings("SELECT session FROM cdbo_grid_sessions WHERE grid = $1 ORDER BY id")
    }

    fn add_session(&mut self, session: &str) -> Result<()> {
        self.rows.with(|c, name| {
            c.execute(
                "INSERT INTO cdbo_grid_sessions (grid, session) VALUES ($1, $2)",
                &[&name, &session],
            )
        })?;
        Ok(())
    }
}

/// A write transaction on a PostgreSQL grid, holding its advisory lock.
struct PostgresGridTransaction<'a> {
    rows: PgRowsTransaction<'a>,
}

impl GridTransaction for PostgresGridTransaction<'_> {
    fn grid(&mut self) -> Result<Option<String>> {
        self.rows.with(stored_grid)
    }

    fn create(&mut self, grid: &str, runs: &[String]) -> Result<()> {
        let ids: Vec<i64> = (1..=runs.len() as i64).collect();
        self.rows.with(|tx, name| {
            tx.execute(
                "INSERT INTO cdbo_grids (name, grid) VALUES ($1, $2)",
                &[&name, &grid],
            )?;
            tx.execute(
                "INSERT INTO cdbo_grid_runs (grid, id, run) SELECT $1, * FROM UNNEST($2::BIGINT[], $3::TEXT[])",
                &[&name, &ids, &runs],
            )
        })?;
        Ok(())
    }

    fn unfinished(&mut self) -> Result<Vec<Claim>> {
        self.rows.with(|tx, name| {
            tx.query(
                "SELECT id, owner, lease_until_unix_s FROM cdbo_grid_runs WHERE grid = $1 AND record IS NULL ORDER BY id",
                &[&name],
            )?
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

    fn finished(&mut self) -> Result<usize> {
        self.rows.count(true)
    }

    fn set_claim(&mut self, id: i64, owner: &str, until: f64) -> Result<()> {
        self.rows.set_claim(id, owner, until)
    }

    fn finish(&mut self, id: i64, record: &str, now: f64) -> Result<bool> {
        let n = self.rows.with(|tx, name| {
            tx.execute(
                "UPDATE cdbo_grid_runs SET record = $1, finished_unix_s = $2 WHERE grid = $3 AND id = $4 AND record IS NULL",
                &[&record, &now, &name, &id],
            )
        })?;
        Ok(n == 1)
    }

    fn commit(self: Box<Self>) -> Result<()> {
        self.rows.commit()
    }
}
