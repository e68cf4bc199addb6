//! Where a study lives: the [`Storage`] trait that both back ends implement (an SQLite file,
//! [`super::sqlite`]; a PostgreSQL database, [`super::postgres`]), and the [`Location`] a
//! user names one by. The back ends store rows and hold a study's write lock; what to store —
//! asking, claiming, telling the optimiser — is [`super::Study`]'s and [`super::claim`]'s,
//! the same for both.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

use super::Trial;
use super::claim::Claim;

/// A study's place, parsed from what a user types: a file path or `sqlite://PATH` is an
/// SQLite file (one study per file); `postgresql://USER@HOST[:PORT]/DB#STUDY` (or
/// `postgres://`) is study `STUDY` of a PostgreSQL database, which holds any number.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Location {
    /// An SQLite file.
    Sqlite(PathBuf),
    /// Study `study` in a PostgreSQL database.
    Postgres {
        /// The connection URL, without the `#STUDY` (a password in it is never shown).
        url: String,
        /// The study's name in the database.
        study: String,
    },
}

/// The URL schemes [`Location::parse`] knows, for its error message.
const SCHEMES: &str = "a file path, sqlite://PATH or postgresql://USER@HOST[:PORT]/DB";

impl Location {
    /// The location `storage` names. A database URL names its study after a `#`, or else
    /// takes `study` (a database without a study name is an error). An unknown `scheme://`
    /// is refused.
    pub fn parse(storage: &str, study: Option<&str>) -> Result<Location> {
        let Some((scheme, rest)) = storage.split_once("://") else {
            return Ok(Location::Sqlite(PathBuf::from(storage)));
        };
        match scheme {
            "sqlite" if !rest.is_empty() => Ok(Location::Sqlite(PathBuf::from(rest))),
            "postgresql" | "postgres" => {
                let (url, named) = match storage.split_once('#') {
                    Some((url, name)) => (url, Some(name)),
                    None => (storage, study),
                };
                let study = named
                    .filter(|s| !s.is_empty())
                    .ok_or_else(|| Error::InvalidValue {
                        what: format!("the study or grid name of {}", redact(url)),
                        value: "none".into(),
                        expected:
                            "given (DATABASE-URL#NAME): a database holds many studies and grids"
                                .into(),
                    })?;
                Ok(Location::Postgres {
                    url: url.to_owned(),
                    study: study.to_owned(),
                })
            }
            _ => Err(Error::InvalidValue {
                what: "the storage".into(),
                value: redact(storage),
                expected: SCHEMES.into(),
            }),
        }
    }

    /// The error of a PostgreSQL location in a cdbo built without PostgreSQL (its `postgres`
    /// feature off, as in the fuzz build).
    #[cfg(not(feature = "postgres"))]
    pub(crate) fn without_postgres(&self) -> Error {
        Error::InvalidValue {
            what: "the storage".into(),
            value: self.label().display().to_string(),
            expected: "a file path or sqlite://PATH: this cdbo was built without PostgreSQL (cargo feature `postgres`)".into(),
        }
    }

    /// How messages name it: the file, or `URL#STUDY` with any password replaced by `***`.
    pub fn label(&self) -> PathBuf {
        match self {
            Location::Sqlite(path) => path.clone(),
            Location::Postgres { url, study } => PathBuf::from(format!("{}#{study}", redact(url))),
        }
    }
}

/// `url` with the password of its `user:password@` part replaced by `***`.
pub fn redact(url: &str) -> String {
    let Some((scheme, rest)) = url.split_once("://") else {
        return url.to_owned();
    };
    let authority_end = rest.find('/').unwrap_or(rest.len());
    match rest[..authority_end].rfind('@') {
        Some(at) => match rest[..at].split_once(':') {
            Some((user, _)) => format!("{scheme}://{user}:***{}", &rest[at..]),
            None => url.to_owned(),
        },
        None => url.to_owned(),
    }
}

/// Everything a study holds, row for row: what [`Storage::dump`] reads and a back end's
/// `create` writes, so that a study copied between back ends is the same bit for bit.
#[derive(Debug, Clone, PartialEq)]
pub struct Dump {
    /// The settings as stored (JSON of [`super::StudyConfig`]).
    pub config: String,
    /// The optimiser's state after the last tell (JSON of [`crate::optimizers::Saved`]).
    pub optimizer: String,
    /// Every trial, in id order.
    pub trials: Vec<Row>,
}

/// One trial as stored, with its times and claim.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
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

/// A told outcome as stored.
#[derive(Debug, Clone, PartialEq)]
pub struct Told {
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
pub trait Storage: Send {
    /// Where the study lives, for messages (never with a password).
    fn label(&self) -> &Path;
    /// Starts a transaction holding the study's write lock (SQLite's `BEGIN IMMEDIATE`,
    /// PostgreSQL's `SELECT … FOR UPDATE` of the study's row) until it commits or is dropped
    /// (rolled back).
    fn begin(&mut self) -> Result<Box<dyn Transaction + '_>>;
    /// Renews `owner`'s claim on pending trial `id` until `until`; false if the trial is
    /// told or no longer `owner`'s.
    fn heartbeat(&mut self, id: i64, owner: &str, until: f64) -> Result<bool>;
    /// Number of told trials.
    fn told(&mut self) -> Result<usize>;
    /// Every trial, in id order.
    fn history(&mut self) -> Result<Vec<Trial>>;
    /// Everything the study holds, for a copy.
    fn dump(&mut self) -> Result<Dump>;
}

/// One write transaction on a study, under its write lock.
pub trait Transaction {
    /// The pending (untold) trials in id order, with their claims.
    fn pending(&mut self) -> Result<Vec<(Trial, Claim)>>;
    /// Number of told trials.
    fn told(&mut self) -> Result<usize>;
    /// The rewards told so far.
    fn told_rewards(&mut self) -> Result<Vec<f64>>;
    /// Trial `id`, if the study has it.
    fn trial(&mut self, id: i64) -> Result<Option<Trial>>;
    /// The optimiser's saved state (JSON).
    fn optimizer_state(&mut self) -> Result<String>;
    /// Adds a pending trial with `weights` (JSON), asked at `asked_unix_s`, claimed by
    /// `claim` = (owner, lease until) if given; returns its id (one more than the last).
    fn add_trial(
        &mut self,
        weights: &str,
        asked_unix_s: f64,
        claim: Option<(&str, f64)>,
    ) -> Result<i64>;
    /// Claims pending trial `id` for `owner` until `until`.
    fn set_claim(&mut self, id: i64, owner: &str, until: f64) -> Result<()>;
    /// Records trial `id`'s outcome and the optimiser's new state.
    fn record(&mut self, id: i64, told: &Told, optimizer_state: &str) -> Result<()>;
    /// Makes every change durable, then releases the lock.
    fn commit(self: Box<Self>) -> Result<()>;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locations_by_scheme() {
        assert_eq!(
            Location::parse("a/s.db", None).unwrap(),
            Location::Sqlite("a/s.db".into())
        );
        assert_eq!(
            Location::parse("sqlite:///tmp/s.db", None).unwrap(),
            Location::Sqlite("/tmp/s.db".into())
        );
        let pg = Location::parse("postgresql://me:secret@db.lan:5433/laps", Some("kart")).unwrap();
        assert_eq!(
            pg.label(),
            PathBuf::from("postgresql://me:***@db.lan:5433/laps#kart")
        );
        assert_eq!(
            Location::parse("postgres://me@h/db#lap", Some("other")).unwrap(),
            Location::Postgres {
                url: "postgres://me@h/db".into(),
                study: "lap".into()
            }
        );
        let e = Location::parse("postgres://me@h/db", None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("study or grid name"), "{e}");
        let e = Location::parse("mysql://u:pw@h/db", Some("s"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("mysql://u:***@h/db") && e.contains("postgresql://"),
            "{e}"
        );
        assert!(!e.contains("pw"), "{e}");
        assert_eq!(redact("postgresql://me@h/db"), "postgresql://me@h/db");
    }
}
