//! A study in a PostgreSQL database, by name ([`crate::store::postgres`]): its settings and
//! optimiser state in a row of `cdbo_studies`, its trials in `cdbo_trials` (the same columns
//! as an SQLite study's `trials`, keyed by study and id).
//!
//! Every write transaction first takes the study's row lock (`SELECT … FOR UPDATE` on
//! `cdbo_studies`), the equivalent of SQLite's `BEGIN IMMEDIATE` for one study: claims and
//! tells of one study are serialised, those of different studies run side by side. A trial is
//! thus handed out once, and a new suggestion is made knowing every lap in flight (the
//! fantasy of [`super::claim`]); `SKIP LOCKED` would let a claim skip a trial another worker
//! is renewing and count too few in flight. The pending trials are read `FOR UPDATE` too, so
//! that a claim sees a heartbeat that committed while it waited.

use std::path::Path;

use super::storage::{Dump, Row, Storage, Told, Transaction, Trials};
use super::{Trial, claim::Claim};
use crate::error::{Error, Result};
use crate::store::Rows;
use crate::store::postgres::{PgRows, PgTransaction, pg_error};

/// A study in a PostgreSQL database.
pub(crate) type Postgres = PgRows<Trials>;

/// The trial columns [`to_trial`] reads, in its order.
const TRIAL_COLUMNS: &str = "id, weights, reward, lap_time_s, failure, x_fail";

/// Creates study `study` holding `dump` in the database at `url` (and the tables, on the
/// database's first study); refuses an existing study, or a database of a newer schema,
/// writing nothing.
pub(crate) fn create(url: &str, study: &str, label: &Path, dump: &Dump) -> Result<()> {
    Postgres::create(url, study, label, |tx| {
        let added = tx.with(|tx, study| {
            tx.execute(
                "INSERT INTO cdbo_studies (name, config, optimizer_state) VALUES ($1, $2, $3) ON CONFLICT (name) DO NOTHING",
                &[&study, &dump.config, &dump.optimizer],
            )
        })?;
        if added == 0 {
            return Err(Error::AlreadyExists {
                path: label.to_owned(),
            });
        }
        for row in &dump.trials {
            let t = &row.trial;
            let weights = super::weights_json(&t.weights)?;
            tx.with(|tx, study| {
                tx.execute(
                    "INSERT INTO cdbo_trials (study, id, weights, reward, lap_time_s, failure, x_fail, asked_unix_s, told_unix_s, owner, lease_until_unix_s)
                     VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11)",
                    &[
                        &study,
                        &t.id,
                        &weights,
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
            })?;
        }
        Ok(())
    })
}

/// Opens study `study` in the database at `url` and reads its settings (JSON); read-only,
/// the session refuses every write.
pub(crate) fn open(
    url: &str,
    study: &str,
    label: &Path,
    writable: bool,
) -> Result<(Postgres, String)> {
    let mut rows = Postgres::open(url, study, label, writable)?;
    let config = rows
        .with(|c, study| {
            c.query_opt("SELECT config FROM cdbo_studies WHERE name = $1", &[&study])?
                .map(|r| r.try_get(0))
                .transpose()
        })?
        .ok_or_else(|| Error::NoStudy {
            path: label.to_owned(),
        })?;
    Ok((rows, config))
}

/// The statement that selects the study's (`$1`) trials with their times and claims, as
/// `filter` (`AND …`, `ORDER BY …`) says.
fn select_rows(filter: &str) -> String {
    format!(
        "SELECT {TRIAL_COLUMNS}, asked_unix_s, told_unix_s, owner, lease_until_unix_s FROM cdbo_trials WHERE study = $1 {filter}"
    )
}

/// The trials with their times and claims, as [`select_rows`] reads them.
fn to_rows(rows: &[postgres::Row], label: &Path) -> Result<Vec<Row>> {
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

impl Storage for Postgres {
    fn begin(&mut self) -> Result<Box<dyn Transaction + '_>> {
        Ok(Box::new(Postgres::begin(self)?))
    }

    fn settings_and_state(&mut self) -> Result<(String, String)> {
        self.with(|c, study| {
            let row = c.query_one(
                "SELECT config, optimizer_state FROM cdbo_studies WHERE name = $1",
                &[&study],
            )?;
            Ok((row.try_get(0)?, row.try_get(1)?))
        })
    }

    fn rows(&mut self) -> Result<Vec<Row>> {
        let sql = select_rows("ORDER BY id");
        let rows = self.with(|c, study| c.query(&sql, &[&study]))?;
        to_rows(&rows, self.label())
    }
}

impl Transaction for PgTransaction<'_, Trials> {
    fn pending(&mut self) -> Result<Vec<(Trial, Claim)>> {
        let sql = select_rows("AND reward IS NULL ORDER BY id FOR UPDATE");
        let rows = self.with(|tx, study| tx.query(&sql, &[&study]))?;
        Ok(to_rows(&rows, self.label())?
            .into_iter()
            .map(Row::pending)
            .collect())
    }

    fn told_rewards(&mut self) -> Result<Vec<f64>> {
        self.with(|tx, study| {
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
        let row = self.with(|tx, study| tx.query_opt(&sql, &[&study, &id]))?;
        row.map(|r| to_trial(&r, self.label())).transpose()
    }

    fn optimizer_state(&mut self) -> Result<String> {
        self.with(|tx, study| {
            tx.query_one(
                "SELECT optimizer_state FROM cdbo_studies WHERE name = $1",
                &[&study],
            )?
            .try_get(0)
        })
    }

    fn add_trial(&mut self, weights: &str, asked_unix_s: f64) -> Result<i64> {
        self.with(|tx, study| {
            tx.query_one(
                "INSERT INTO cdbo_trials (study, id, weights, asked_unix_s)
                 SELECT $1, COALESCE(MAX(id), 0) + 1, $2, $3 FROM cdbo_trials WHERE study = $1
                 RETURNING id",
                &[&study, &weights, &asked_unix_s],
            )?
            .try_get(0)
        })
    }

    fn record(&mut self, id: i64, told: &Told, optimizer_state: &str) -> Result<()> {
        self.with(|tx, study| {
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
