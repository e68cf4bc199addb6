//! Grids in a PostgreSQL database, by name, beside its studies ([`crate::store::postgres`]):
//! tables `cdbo_grids`, `cdbo_grid_runs` (one claimed row per cell) and `cdbo_grid_sessions`.
//! Every write transaction first takes the grid's advisory lock (a key hashed from its name),
//! so that the claims of one grid are serialised, as SQLite's write lock does, and workers
//! that start at once on a grid not stored yet store it once.

use postgres::GenericClient;

use super::storage::{Cells, GridStorage, GridTransaction};
use crate::error::Result;
use crate::store::postgres::{PgRows, PgTransaction, Sql};

/// A grid in a PostgreSQL database: opened to write, it makes the tables where the database
/// has none.
pub(super) type PostgresGrid = PgRows<Cells>;

/// The grid as stored (TOML), if the database holds grid `name`.
fn stored_grid(client: &mut impl GenericClient, name: &str) -> Sql<Option<String>> {
    client
        .query_opt("SELECT grid FROM cdbo_grids WHERE name = $1", &[&name])?
        .map(|r| r.try_get(0))
        .transpose()
}

/// The first column of the rows `sql` selects for grid `name` (`$1`).
fn strings(client: &mut impl GenericClient, sql: &str, name: &str) -> Sql<Vec<String>> {
    client
        .query(sql, &[&name])?
        .iter()
        .map(|r| r.try_get(0))
        .collect()
}

impl GridStorage for PostgresGrid {
    fn begin(&mut self) -> Result<Box<dyn GridTransaction + '_>> {
        Ok(Box::new(PostgresGrid::begin(self)?))
    }

    fn grid(&mut self) -> Result<Option<String>> {
        self.with(stored_grid)
    }

    fn records(&mut self) -> Result<Vec<String>> {
        self.with(|c, name| {
            strings(
                c,
                "SELECT record FROM cdbo_grid_runs WHERE grid = $1 AND record IS NOT NULL ORDER BY id",
                name,
            )
        })
    }

    fn sessions(&mut self) -> Result<Vec<String>> {
        self.with(|c, name| {
            strings(
                c,
                "SELECT session FROM cdbo_grid_sessions WHERE grid = $1 ORDER BY id",
                name,
            )
        })
    }

    fn add_session(&mut self, session: &str) -> Result<()> {
        self.with(|c, name| {
            c.execute(
                "INSERT INTO cdbo_grid_sessions (grid, session) VALUES ($1, $2)",
                &[&name, &session],
            )
        })?;
        Ok(())
    }
}

impl GridTransaction for PgTransaction<'_, Cells> {
    fn grid(&mut self) -> Result<Option<String>> {
        self.with(stored_grid)
    }

    fn create(&mut self, grid: &str, runs: &[String]) -> Result<()> {
        let ids: Vec<i64> = (1..=runs.len() as i64).collect();
        self.with(|tx, name| {
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

    fn finish(&mut self, id: i64, record: &str, now: f64) -> Result<bool> {
        let n = self.with(|tx, name| {
            tx.execute(
                "UPDATE cdbo_grid_runs SET record = $1, finished_unix_s = $2 WHERE grid = $3 AND id = $4 AND record IS NULL",
                &[&record, &now, &name, &id],
            )
        })?;
        Ok(n == 1)
    }
}
