//! A study in an SQLite file (one study per file; [`crate::store::sqlite`]): tables `meta`
//! (the settings), `trials` (one claimed row per trial) and `optimizer` (its state after the
//! last tell).

use std::path::Path;

use rusqlite::{Connection, OptionalExtension, params};

use super::Trial;
use super::claim::Claim;
use super::storage::{Dump, Row, Storage, Told, Transaction, Trials};
use crate::error::{Error, Result};
use crate::store::sqlite::{SqliteRows, SqliteTransaction, sql_error, user_version};

/// A study in an SQLite file.
pub(crate) type Sqlite = SqliteRows<Trials>;

/// The trial columns [`row_to_trial`] reads, in its order.
const TRIAL_COLUMNS: &str = "id, weights, reward, lap_time_s, failure, x_fail";

/// The tables of a new study file.
const SCHEMA: &str = "CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
     CREATE TABLE trials (
         id INTEGER PRIMARY KEY,
         weights TEXT NOT NULL,
         reward REAL,
         lap_time_s REAL,
         failure TEXT,
         x_fail REAL,
         asked_unix_s REAL NOT NULL,
         told_unix_s REAL,
         owner TEXT,
         lease_until_unix_s REAL);
     CREATE TABLE optimizer (id INTEGER PRIMARY KEY CHECK (id = 1), state TEXT NOT NULL);";

/// Creates the study file holding `dump`; refuses to overwrite one.
pub(crate) fn create(path: &Path, dump: &Dump) -> Result<()> {
    Sqlite::create(path, |tx| {
        let err = |e| sql_error::<Trials>(path, e);
        tx.execute_batch(SCHEMA).map_err(err)?;
        tx.execute(
            "INSERT INTO meta (key, value) VALUES ('config', ?1)",
            params![dump.config],
        )
        .map_err(err)?;
        tx.execute(
            "INSERT INTO optimizer (id, state) VALUES (1, ?1)",
            params![dump.optimizer],
        )
        .map_err(err)?;
        for row in &dump.trials {
            let t = &row.trial;
            let weights = super::weights_json(&t.weights)?;
            tx.execute(
                "INSERT INTO trials (id, weights, reward, lap_time_s, failure, x_fail, asked_unix_s, told_unix_s, owner, lease_until_unix_s)
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
                params![
                    t.id,
                    weights,
                    t.reward,
                    t.lap_time_s,
                    t.failure,
                    t.x_fail,
                    row.asked_unix_s,
                    row.told_unix_s,
                    row.owner,
                    row.lease_until_unix_s
                ],
            )
            .map_err(err)?;
        }
        Ok(())
    })
}

/// Opens the study file at `path` and reads its settings (JSON). Writable, a study of an
/// older schema is upgraded; read-only, nothing is written.
pub(crate) fn open(path: &Path, writable: bool) -> Result<(Sqlite, String)> {
    Sqlite::open(path, writable, |conn, version| {
        let config: Option<String> = if version >= 1 {
            conn.query_row("SELECT value FROM meta WHERE key = 'config'", [], |r| {
                r.get(0)
            })
            .optional()
            .map_err(|e| sql_error::<Trials>(path, e))?
        } else {
            None
        };
        config.ok_or_else(|| Error::NotAStudy {
            path: path.to_owned(),
            reason: "an SQLite database without a study in it".into(),
        })
    })
}

impl Storage for Sqlite {
    fn begin(&mut self) -> Result<Box<dyn Transaction + '_>> {
        Ok(Box::new(Sqlite::begin(self)?))
    }

    fn settings_and_state(&mut self) -> Result<(String, String)> {
        let conn = self.conn();
        let config = conn.query_row("SELECT value FROM meta WHERE key = 'config'", [], |r| {
            r.get(0)
        });
        let state = config.and_then(|c| Ok((c, optimizer_state(conn)?)));
        state.map_err(self.err())
    }

    fn rows(&mut self) -> Result<Vec<Row>> {
        select_rows(self.conn(), "ORDER BY id").map_err(self.err())
    }
}

/// The trials with their times and claims that `filter` (`WHERE …`, `ORDER BY …`) selects.
fn select_rows(conn: &Connection, filter: &str) -> rusqlite::Result<Vec<Row>> {
    // A schema-1 study opened read-only is read as it is: it has no claim columns.
    let claims = if user_version(conn)? >= 2 {
        "owner, lease_until_unix_s"
    } else {
        "NULL, NULL"
    };
    let mut stmt = conn.prepare(&format!(
        "SELECT {TRIAL_COLUMNS}, asked_unix_s, told_unix_s, {claims} FROM trials {filter}"
    ))?;
    let rows = stmt.query_map([], |r| {
        Ok(Row {
            trial: row_to_trial(r)?,
            asked_unix_s: r.get(6)?,
            told_unix_s: r.get(7)?,
            owner: r.get(8)?,
            lease_until_unix_s: r.get(9)?,
        })
    })?;
    rows.collect()
}

impl Transaction for SqliteTransaction<'_, Trials> {
    fn pending(&mut self) -> Result<Vec<(Trial, Claim)>> {
        let rows =
            select_rows(self.tx(), "WHERE reward IS NULL ORDER BY id").map_err(self.err())?;
        Ok(rows.into_iter().map(Row::pending).collect())
    }

    fn told_rewards(&mut self) -> Result<Vec<f64>> {
        let mut stmt = self
            .tx()
            .prepare("SELECT reward FROM trials WHERE reward IS NOT NULL")
            .map_err(self.err())?;
        let rows = stmt.query_map([], |r| r.get(0)).map_err(self.err())?;
        rows.collect::<rusqlite::Result<Vec<_>>>()
            .map_err(self.err())
    }

    fn trial(&mut self, id: i64) -> Result<Option<Trial>> {
        self.tx()
            .query_row(
                &format!("SELECT {TRIAL_COLUMNS} FROM trials WHERE id = ?1"),
                params![id],
                row_to_trial,
            )
            .optional()
            .map_err(self.err())
    }

    fn optimizer_state(&mut self) -> Result<String> {
        optimizer_state(self.tx()).map_err(self.err())
    }

    fn add_trial(&mut self, weights: &str, asked_unix_s: f64) -> Result<i64> {
        self.tx()
            .execute(
                "INSERT INTO trials (weights, asked_unix_s) VALUES (?1, ?2)",
                params![weights, asked_unix_s],
            )
            .map_err(self.err())?;
        Ok(self.tx().last_insert_rowid())
    }

    fn record(&mut self, id: i64, told: &Told, optimizer_state: &str) -> Result<()> {
        self.tx()
            .execute(
                "UPDATE trials SET reward = ?1, lap_time_s = ?2, failure = ?3, x_fail = ?4, told_unix_s = ?5 WHERE id = ?6",
                params![
                    told.reward,
                    told.lap_time_s,
                    told.failure,
                    told.x_fail,
                    told.told_unix_s,
                    id
                ],
            )
            .map_err(self.err())?;
        self.tx()
            .execute(
                "UPDATE optimizer SET state = ?1 WHERE id = 1",
                params![optimizer_state],
            )
            .map_err(self.err())?;
        Ok(())
    }
}

fn row_to_trial(r: &rusqlite::Row<'_>) -> rusqlite::Result<Trial> {
    let json: String = r.get(1)?;
    let weights: Vec<f64> = serde_json::from_str(&json).map_err(|e| {
        rusqlite::Error::FromSqlConversionFailure(1, rusqlite::types::Type::Text, Box::new(e))
    })?;
    Ok(Trial {
        id: r.get(0)?,
        weights,
        reward: r.get(2)?,
        lap_time_s: r.get(3)?,
        failure: r.get(4)?,
        x_fail: r.get(5)?,
    })
}

fn optimizer_state(conn: &Connection) -> rusqlite::Result<String> {
    conn.query_row("SELECT state FROM optimizer WHERE id = 1", [], |r| r.get(0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::tests::{config, temp};
    use crate::study::{Location, Study};

    #[test]
    fn foreign_and_newer_files_are_refused() {
        let path = temp("foreign");
        std::fs::write(&path, "x,a\n0,1\n").unwrap();
        let e = Study::open(&path).err().unwrap().to_string();
        assert!(e.contains("not an SQLite database"), "{e}");
        let path = temp("newer");
        drop(Study::create(&path, config()).unwrap());
        let conn = Connection::open(&path).unwrap();
        conn.pragma_update(None, "user_version", 99).unwrap();
        drop(conn);
        let e = Study::open(&path).err().unwrap().to_string();
        assert!(e.contains("newer cdbo"), "{e}");
        let e = Study::open(&path.with_extension("missing"))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("no such study"), "{e}");
        let e = Study::open_at(&Location::Sqlite(path.with_extension("missing")))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("no such study"), "{e}");
    }
}
