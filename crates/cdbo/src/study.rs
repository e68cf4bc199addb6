//! Persistent ask/tell studies for optimising a real car one lap at a time: one SQLite file per
//! study (WAL journal, synchronous commits), so that a told result is on disk before `tell`
//! returns, and a study survives crashes, `kill -9` and restarts, continuing with exactly the
//! suggestion an uninterrupted run would make.
//!
//! The file holds the settings, every trial (asked weights, then the told outcome) and the
//! optimiser's [`Saved`] state after the last tell. `ask` returns the pending trial if there is
//! one; otherwise it asks the optimiser and records a pending trial. `tell` records the outcome
//! and the optimiser's new state in one transaction. Writers take SQLite's write lock for the
//! whole transaction; a second process waits up to [`BUSY_TIMEOUT`] and then gets a clear
//! "busy" error.

use std::path::{Path, PathBuf};
use std::time::Duration;

use rusqlite::{Connection, OpenFlags, OptionalExtension, TransactionBehavior, params};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
pub use crate::evaluator::Outcome;
use crate::optimizers::{Optimizer, Saved, Settings, by_name};

/// The schema this version writes and reads (SQLite's `user_version`).
pub const SCHEMA_VERSION: i64 = 1;

/// How long a process waits for another one's transaction before reporting "busy".
pub const BUSY_TIMEOUT: Duration = Duration::from_secs(10);

/// A study's settings, fixed at creation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudyConfig {
    /// Optimiser (`cdbo` by default).
    pub method: String,
    /// Policy kernels M.
    pub kernels: usize,
    /// Policy kernel length-scale.
    pub lengthscale: f64,
    /// Seed of every random choice.
    pub seed: u64,
    /// UCB β.
    pub beta: f64,
    /// The initial weights w₀.
    pub w0: Vec<f64>,
}

/// One trial of a study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trial {
    /// Trial id, 1, 2, 3, … in asking order.
    pub id: i64,
    /// The policy weights to drive.
    pub weights: Vec<f64>,
    /// The reward, once told.
    pub reward: Option<f64>,
    /// Lap time (s) of a completed lap, if told.
    pub lap_time_s: Option<f64>,
    /// Why the lap failed, for a failed lap.
    pub failure: Option<String>,
    /// Where the lap failed (fraction), if told.
    pub x_fail: Option<f64>,
}

/// An open study.
pub struct Study {
    path: PathBuf,
    conn: Connection,
    config: StudyConfig,
    /// The optimiser and the number of told trials it has seen.
    optimizer: Option<(Box<dyn Optimizer + Send>, usize)>,
}

fn sql_error(path: &Path, e: rusqlite::Error) -> Error {
    let text = e.to_string();
    if text.contains("not a database") {
        return Error::Domain(format!(
            "{}: not a cdbo study (the file is not an SQLite database)",
            path.display()
        ));
    }
    if text.contains("locked") || text.contains("busy") {
        return Error::Domain(format!(
            "{}: busy: another process is using the study; try again",
            path.display()
        ));
    }
    Error::Domain(format!("{}: {text}", path.display()))
}

impl Study {
    /// Creates a study file; refuses to overwrite one.
    pub fn create(path: &Path, config: StudyConfig) -> Result<Study> {
        if path.exists() {
            return Err(Error::Domain(format!(
                "{}: already exists; open it, or choose another name",
                path.display()
            )));
        }
        if config.w0.len() != config.kernels {
            return Err(Error::Domain(format!(
                "the initial policy has {} weights but the study has {} kernels",
                config.w0.len(),
                config.kernels
            )));
        }
        // Fails on a bad method or w₀ before anything is written.
        let optimizer = by_name(
            &config.method,
            config.w0.clone(),
            &Settings::race(config.seed, config.beta),
        )?;
        let state =
            serde_json::to_string(&optimizer.save()).map_err(|e| Error::Domain(e.to_string()))?;
        // Built under a temporary name and renamed into place once complete, so that a
        // create killed half-way leaves no half-made study behind.
        let building = path.with_file_name(format!(
            ".{}.creating-{}",
            path.file_name()
                .map_or("study".into(), |n| n.to_string_lossy()),
            std::process::id()
        ));
        let err = |e| sql_error(path, e);
        let mut conn = Connection::open(&building).map_err(err)?;
        configure(&conn).map_err(err)?;
        let tx = conn.transaction().map_err(err)?;
        tx.execute_batch(
            "CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
             CREATE TABLE trials (
                 id INTEGER PRIMARY KEY,
                 weights TEXT NOT NULL,
                 reward REAL,
                 lap_time_s REAL,
                 failure TEXT,
                 x_fail REAL,
                 asked_unix_s REAL NOT NULL,
                 told_unix_s REAL);
             CREATE TABLE optimizer (id INTEGER PRIMARY KEY CHECK (id = 1), state TEXT NOT NULL);",
        )
        .map_err(err)?;
        let config_json =
            serde_json::to_string(&config).map_err(|e| Error::Domain(e.to_string()))?;
        tx.execute(
            "INSERT INTO meta (key, value) VALUES ('config', ?1)",
            params![config_json],
        )
        .map_err(err)?;
        tx.execute(
            "INSERT INTO optimizer (id, state) VALUES (1, ?1)",
            params![state],
        )
        .map_err(err)?;
        tx.pragma_update(None, "user_version", SCHEMA_VERSION)
            .map_err(err)?;
        tx.commit().map_err(err)?;
        // Closing the only connection checkpoints the WAL into the file.
        conn.close().map_err(|(_, e)| err(e))?;
        // A hard link never replaces a study another process created meanwhile.
        let placed = match std::fs::hard_link(&building, path) {
            Ok(()) => std::fs::remove_file(&building),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let _ = std::fs::remove_file(&building);
                return Err(Error::Domain(format!(
                    "{}: already exists; open it, or choose another name",
                    path.display()
                )));
            }
            Err(_) => std::fs::rename(&building, path),
        };
        placed.map_err(|e| Error::Io {
            path: path.to_owned(),
            source: e,
        })?;
        let mut study = Study::open(path)?;
        study.optimizer = Some((optimizer, 0));
        Ok(study)
    }

    /// Opens an existing study.
    pub fn open(path: &Path) -> Result<Study> {
        if !path.is_file() {
            return Err(Error::NotFound(format!(
                "{}: no such study (create it with `cdbo study create`)",
                path.display()
            )));
        }
        let err = |e| sql_error(path, e);
        let conn =
            Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_WRITE).map_err(err)?;
        configure(&conn).map_err(err)?;
        let version: i64 = conn
            .pragma_query_value(None, "user_version", |r| r.get(0))
            .map_err(err)?;
        if version > SCHEMA_VERSION {
            return Err(Error::Domain(format!(
                "{}: written by a newer cdbo (study schema {version}, this version reads {SCHEMA_VERSION}); upgrade cdbo",
                path.display()
            )));
        }
        let config_json: Option<String> = if version == SCHEMA_VERSION {
            conn.query_row("SELECT value FROM meta WHERE key = 'config'", [], |r| {
                r.get(0)
            })
            .optional()
            .map_err(err)?
        } else {
            None
        };
        let config_json = config_json.ok_or_else(|| {
            Error::Domain(format!(
                "{}: an SQLite database but not a cdbo study",
                path.display()
            ))
        })?;
        let config: StudyConfig = serde_json::from_str(&config_json).map_err(|e| {
            Error::Domain(format!("{}: corrupt study settings: {e}", path.display()))
        })?;
        Ok(Study {
            path: path.to_owned(),
            conn,
            config,
            optimizer: None,
        })
    }

    /// The study's settings.
    pub fn config(&self) -> &StudyConfig {
        &self.config
    }

    /// The study file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The trial to drive next: the pending one if any, else a new suggestion.
    pub fn ask(&mut self) -> Result<Trial> {
        let path = self.path.clone();
        let err = |e| sql_error(&path, e);
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(err)?;
        if let Some(t) = pending(&tx).map_err(err)? {
            return Ok(t);
        }
        let told = told_count(&tx).map_err(err)?;
        let optimizer = load_optimizer(&tx, &path, &mut self.optimizer, told)?;
        let weights = optimizer.ask()?;
        let json = serde_json::to_string(&weights).map_err(|e| Error::Domain(e.to_string()))?;
        tx.execute(
            "INSERT INTO trials (weights, asked_unix_s) VALUES (?1, ?2)",
            params![json, unix_now()],
        )
        .map_err(err)?;
        let id = tx.last_insert_rowid();
        tx.commit().map_err(err)?;
        Ok(Trial {
            id,
            weights,
            reward: None,
            lap_time_s: None,
            failure: None,
            x_fail: None,
        })
    }

    /// Records the outcome of pending trial `id`; returns the reward. Durable on return.
    pub fn tell(&mut self, id: i64, outcome: &Outcome) -> Result<f64> {
        let reward = outcome.reward()?;
        let path = self.path.clone();
        let err = |e| sql_error(&path, e);
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(err)?;
        let trial = trial(&tx, id).map_err(err)?.ok_or_else(|| {
            Error::NotFound(format!("{}: no trial {id} in this study", path.display()))
        })?;
        if trial.reward.is_some() {
            return Err(Error::Conflict(format!(
                "{}: trial {id} was already told (reward {}); ask for the next trial",
                path.display(),
                trial.reward.unwrap_or_default()
            )));
        }
        let told = told_count(&tx).map_err(err)?;
        let (lap_time, failure, x_fail) = match outcome {
            Outcome::Reward(_) => (None, None, None),
            Outcome::Lap { time_s, .. } => (Some(*time_s), None, None),
            Outcome::Failed { at, reason } => (
                None,
                Some(reason.clone().unwrap_or_else(|| "failed".into())),
                *at,
            ),
        };
        let optimizer = load_optimizer(&tx, &path, &mut self.optimizer, told)?;
        let saved = (|| -> Result<()> {
            // Re-establish the optimiser's pending suggestion (the trial's), then tell it.
            optimizer.ask()?;
            optimizer.tell_lap(&trial.weights, reward, x_fail)?;
            let state = serde_json::to_string(&optimizer.save())
                .map_err(|e| Error::Domain(e.to_string()))?;
            tx.execute(
                "UPDATE trials SET reward = ?1, lap_time_s = ?2, failure = ?3, x_fail = ?4, told_unix_s = ?5 WHERE id = ?6",
                params![reward, lap_time, failure, x_fail, unix_now(), id],
            )
            .map_err(err)?;
            tx.execute(
                "UPDATE optimizer SET state = ?1 WHERE id = 1",
                params![state],
            )
            .map_err(err)?;
            tx.commit().map_err(err)
        })();
        match saved {
            Ok(()) => {
                if let Some(c) = self.optimizer.as_mut() {
                    c.1 = told + 1;
                }
                Ok(reward)
            }
            Err(e) => {
                // Nothing was written: forget the told optimiser, reload it next time.
                self.optimizer = None;
                Err(e)
            }
        }
    }

    /// Number of told trials.
    pub fn told(&self) -> Result<usize> {
        told_count(&self.conn).map_err(|e| sql_error(&self.path, e))
    }

    /// Every trial, in order.
    pub fn history(&self) -> Result<Vec<Trial>> {
        let err = |e| sql_error(&self.path, e);
        let mut stmt = self
            .conn
            .prepare(
                "SELECT id, weights, reward, lap_time_s, failure, x_fail FROM trials ORDER BY id",
            )
            .map_err(err)?;
        let rows = stmt.query_map([], row_to_trial).map_err(err)?;
        rows.collect::<rusqlite::Result<Vec<_>>>().map_err(err)
    }

    /// The told trial with the highest reward (the first on ties).
    pub fn best(&self) -> Result<Option<Trial>> {
        Ok(self
            .history()?
            .into_iter()
            .filter(|t| t.reward.is_some())
            .fold(None, |best: Option<Trial>, t| match &best {
                Some(b) if b.reward >= t.reward => best,
                _ => Some(t),
            }))
    }
}

/// WAL journal, full synchronous commits, a busy timeout.
fn configure(conn: &Connection) -> rusqlite::Result<()> {
    conn.busy_timeout(BUSY_TIMEOUT)?;
    conn.pragma_update(None, "journal_mode", "WAL")?;
    conn.pragma_update(None, "synchronous", "FULL")?;
    Ok(())
}

fn unix_now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
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

fn pending(conn: &Connection) -> rusqlite::Result<Option<Trial>> {
    conn.query_row(
        "SELECT id, weights, reward, lap_time_s, failure, x_fail FROM trials WHERE reward IS NULL ORDER BY id LIMIT 1",
        [],
        row_to_trial,
    )
    .optional()
}

fn trial(conn: &Connection, id: i64) -> rusqlite::Result<Option<Trial>> {
    conn.query_row(
        "SELECT id, weights, reward, lap_time_s, failure, x_fail FROM trials WHERE id = ?1",
        params![id],
        row_to_trial,
    )
    .optional()
}

fn told_count(conn: &Connection) -> rusqlite::Result<usize> {
    conn.query_row(
        "SELECT COUNT(*) FROM trials WHERE reward IS NOT NULL",
        [],
        |r| r.get::<_, i64>(0),
    )
    .map(|n| n as usize)
}

/// The optimiser as of `told` told trials: the one in memory if it is current (no other
/// process told a trial since), else resumed from the saved state.
fn load_optimizer<'a>(
    conn: &Connection,
    path: &Path,
    cache: &'a mut Option<(Box<dyn Optimizer + Send>, usize)>,
    told: usize,
) -> Result<&'a mut Box<dyn Optimizer + Send>> {
    if cache.as_ref().is_none_or(|c| c.1 != told) {
        let state: String = conn
            .query_row("SELECT state FROM optimizer WHERE id = 1", [], |r| r.get(0))
            .map_err(|e| sql_error(path, e))?;
        let saved: Saved = serde_json::from_str(&state).map_err(|e| {
            Error::Domain(format!("{}: corrupt optimiser state: {e}", path.display()))
        })?;
        *cache = Some((saved.resume()?, told));
    }
    match cache {
        Some((opt, _)) => Ok(opt),
        None => Err(Error::Domain("the optimiser could not be loaded".into())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config() -> StudyConfig {
        StudyConfig {
            method: "cdbo".into(),
            kernels: 3,
            lengthscale: 0.5,
            seed: 1,
            beta: 1.0,
            w0: vec![0.1, 0.2, 0.3],
        }
    }

    fn temp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("cdbo-study-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir.join("s.db")
    }

    #[test]
    fn ask_is_idempotent_and_tell_is_checked() {
        let path = temp("ask");
        let mut s = Study::create(&path, config()).unwrap();
        let a = s.ask().unwrap();
        assert_eq!(a.id, 1);
        assert_eq!(a.weights, config().w0);
        assert_eq!(s.ask().unwrap(), a);
        assert!(s.tell(2, &Outcome::Reward(1.0)).is_err());
        assert!(s.tell(1, &Outcome::Reward(f64::NAN)).is_err());
        assert!(
            s.tell(
                1,
                &Outcome::Lap {
                    time_s: -3.0,
                    length_m: 100.0
                }
            )
            .is_err()
        );
        assert_eq!(
            s.tell(
                1,
                &Outcome::Lap {
                    time_s: 4.0,
                    length_m: 100.0
                }
            )
            .unwrap(),
            25.0
        );
        assert!(s.tell(1, &Outcome::Reward(3.0)).is_err());
        let b = s.ask().unwrap();
        assert_eq!(b.id, 2);
        drop(s);
        // Reopened: the same pending trial, the same history.
        let mut s = Study::open(&path).unwrap();
        assert_eq!(s.ask().unwrap(), b);
        assert_eq!(s.history().unwrap().len(), 2);
        assert_eq!(s.best().unwrap().unwrap().reward, Some(25.0));
        assert!(Study::create(&path, config()).is_err());
    }

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
    }
}
