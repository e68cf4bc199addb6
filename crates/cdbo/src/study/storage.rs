//! What a study stores, the same in both back ends: its trials as claimed rows ([`Trials`]),
//! the [`Storage`] and [`Transaction`] that an SQLite file ([`super::sqlite`]) and a
//! PostgreSQL database ([`super::postgres`]) implement beside the claims of
//! [`crate::store`], and the rows a copy carries ([`Dump`]). What to store — asking, claiming,
//! telling the optimiser — is [`super::Study`]'s and [`super::claim`]'s, the same for both.

use crate::error::Result;
use crate::store::{Kind, Parent, Rows, RowsTransaction, Table};

use super::Trial;
use super::claim::Claim;

/// A study's trials: done once told. PostgreSQL's lock is the study's row
/// (`SELECT … FOR UPDATE`), the equivalent of SQLite's `BEGIN IMMEDIATE` for one study.
pub(crate) enum Trials {}

impl Kind for Trials {
    const TABLE: Table = Table {
        sqlite: "trials",
        // Schema 1 → 2: the claims' columns.
        sqlite_upgrade: "ALTER TABLE trials ADD COLUMN owner TEXT;
                         ALTER TABLE trials ADD COLUMN lease_until_unix_s REAL;",
        postgres: "cdbo_trials",
        done: "reward",
        lock: "SELECT 1 FROM cdbo_studies WHERE name = $1 FOR UPDATE",
        parent: Parent::Study,
    };
}

/// Everything a study holds, row for row: what [`Storage::dump`] reads and a back end's
/// `create` writes, so that a study copied between back ends is the same bit for bit.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Dump {
    /// The settings as stored (JSON of [`super::StudyConfig`]).
    pub config: String,
    /// The optimiser's state after the last tell (JSON of [`crate::optimizers::Saved`]).
    pub optimizer: String,
    /// Every trial, in id order.
    pub trials: Vec<Row>,
}

/// One trial as stored, with its times and claim.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Row {
    /// The trial (weights and, once told, its outcome).
    pub trial: Trial,
    /// Unix time (s) it was asked.
    pub asked_unix_s: f64,
    /// Unix time (s) it was told.
    pub told_unix_s: Option<f64>,
    /// Its claim (owner and lease), if a worker claimed it.
    pub owner: Option<String>,
    /// Unix time (s) until which the claim holds.
    pub lease_until_unix_s: Option<f64>,
}

impl Row {
    /// The pending trial and its claim.
    pub(crate) fn pending(self) -> (Trial, Claim) {
        let claim = Claim {
            trial: self.trial.id,
            owner: self.owner,
            lease_until: self.lease_until_unix_s,
        };
        (self.trial, claim)
    }
}

/// A told outcome as stored.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Told {
    /// The reward.
    pub reward: f64,
    /// Lap time (s) of a completed lap.
    pub lap_time_s: Option<f64>,
    /// Why the lap failed (bounded by [`super::bounded_reason`]).
    pub failure: Option<String>,
    /// Where the lap failed (fraction).
    pub x_fail: Option<f64>,
    /// Unix time (s) it was told.
    pub told_unix_s: f64,
}

/// A study's storage: its rows, and a write lock that makes each [`Transaction`] see and
/// change the study alone.
pub(crate) trait Storage: Rows {
    /// Starts a transaction holding the study's write lock (SQLite's `BEGIN IMMEDIATE`,
    /// PostgreSQL's `SELECT … FOR UPDATE` of the study's row) until it commits or is dropped
    /// (rolled back).
    fn begin(&mut self) -> Result<Box<dyn Transaction + '_>>;
    /// Number of told trials.
    fn told(&mut self) -> Result<usize> {
        self.count(true)
    }
    /// The settings and the optimiser's state, as stored (JSON).
    fn settings_and_state(&mut self) -> Result<(String, String)>;
    /// Every trial with its times and claim, in id order.
    fn rows(&mut self) -> Result<Vec<Row>>;
    /// Every trial, in id order.
    fn history(&mut self) -> Result<Vec<Trial>> {
        Ok(self.rows()?.into_iter().map(|r| r.trial).collect())
    }
    /// Everything the study holds, for a copy.
    fn dump(&mut self) -> Result<Dump> {
        let (config, optimizer) = self.settings_and_state()?;
        Ok(Dump {
            config,
            optimizer,
            trials: self.rows()?,
        })
    }
}

/// One write transaction on a study, under its write lock.
pub(crate) trait Transaction: RowsTransaction {
    /// The pending (untold) trials in id order, with their claims.
    fn pending(&mut self) -> Result<Vec<(Trial, Claim)>>;
    /// Number of told trials.
    fn told(&mut self) -> Result<usize> {
        self.count(true)
    }
    /// The rewards told so far.
    fn told_rewards(&mut self) -> Result<Vec<f64>>;
    /// Trial `id`, if the study has it.
    fn trial(&mut self, id: i64) -> Result<Option<Trial>>;
    /// The optimiser's saved state (JSON).
    fn optimizer_state(&mut self) -> Result<String>;
    /// Adds a pending trial with `weights` (JSON), asked at `asked_unix_s`, unclaimed; returns
    /// its id (one more than the last).
    fn add_trial(&mut self, weights: &str, asked_unix_s: f64) -> Result<i64>;
    /// Records trial `id`'s outcome and the optimiser's new state.
    fn record(&mut self, id: i64, told: &Told, optimizer_state: &str) -> Result<()>;
}
