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
//!
//! Several workers drive one study through [`Study::claim`]: each trial handed out is claimed
//! by its worker with a lease the worker renews while it drives ([`Study::heartbeat`]), so
//! that every trial is driven once, and a trial whose worker died is handed out again; the
//! rules are in [`claim`], apart from the storage. Reading commands open a study with
//! [`Study::open_read_only`], which writes nothing and works where the file or its folder is
//! read-only.

pub mod claim;

use std::path::{Path, PathBuf};
use std::time::Duration;

use rusqlite::{Connection, OpenFlags, OptionalExtension, TransactionBehavior, params};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
pub use crate::evaluator::Outcome;
use crate::optimizers::{Optimizer, Saved, Settings, by_name};
use claim::{Claim, Handout, Worker};

/// The schema this version writes and reads (SQLite's `user_version`): 2 added the claims
/// (`owner`, `lease_until_unix_s`); a version-1 study is upgraded when opened for writing.
pub const SCHEMA_VERSION: i64 = 2;

/// The first 16 bytes of every SQLite database file.
const SQLITE_HEADER: &[u8; 16] = b"SQLite format 3\0";

/// What a worker is to do next, from [`Study::claim`].
#[derive(Debug, Clone, PartialEq)]
pub enum Next {
    /// Drive this trial (claimed for the worker), then tell it.
    Drive(Trial),
    /// Every remaining trial is out with another live worker: wait, then claim again.
    Wait,
    /// The study has told the worker's total.
    Done,
}

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

/// Sorts an SQLite error by its code: busy or locked, not a database, or another failure.
fn sql_error(path: &Path, source: rusqlite::Error) -> Error {
    use rusqlite::ErrorCode;
    let path = path.to_owned();
    match source.sqlite_error_code() {
        Some(ErrorCode::DatabaseBusy | ErrorCode::DatabaseLocked) => Error::Busy { path },
        Some(ErrorCode::NotADatabase) => Error::NotAStudy {
            path,
            reason: "the file is not an SQLite database".into(),
        },
        _ => Error::Sql { path, source },
    }
}

impl Study {
    /// Creates a study file; refuses to overwrite one.
    pub fn create(path: &Path, config: StudyConfig) -> Result<Study> {
        if path.exists() {
            return Err(Error::AlreadyExists {
                path: path.to_owned(),
            });
        }
        if config.w0.len() != config.kernels {
            return Err(Error::dimension(
                "initial weights (one per kernel)",
                config.kernels,
                config.w0.len(),
            ));
        }
        // Fails on a bad method or w₀ before anything is written.
        let optimizer = by_name(
            &config.method,
            config.w0.clone(),
            &Settings::race(config.seed, config.beta),
        )?;
        let state = serde_json::to_string(&optimizer.save())
            .map_err(|e| Error::json("optimiser state", e))?;
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
                 told_unix_s REAL,
                 owner TEXT,
                 lease_until_unix_s REAL);
             CREATE TABLE optimizer (id INTEGER PRIMARY KEY CHECK (id = 1), state TEXT NOT NULL);",
        )
        .map_err(err)?;
        let config_json =
            serde_json::to_string(&config).map_err(|e| Error::json("study settings", e))?;
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
                return Err(Error::AlreadyExists {
                    path: path.to_owned(),
                });
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

    /// Opens an existing study to ask and tell; a study of an older schema is upgraded.
    pub fn open(path: &Path) -> Result<Study> {
        Study::open_with(path, true)
    }

    /// Opens an existing study to read it: writes nothing, and works where the file or its
    /// folder is read-only (then as an immutable file, if SQLite cannot share it).
    pub fn open_read_only(path: &Path) -> Result<Study> {
        Study::open_with(path, false)
    }

    /// Opens the study at `path`, or creates it with `config` if there is none: workers
    /// started at once on a study that does not exist yet all join the one created first.
    /// Returns whether this call created it.
    pub fn open_or_create(path: &Path, config: StudyConfig) -> Result<(Study, bool)> {
        if path.exists() {
            return Ok((Study::open(path)?, false));
        }
        match Study::create(path, config) {
            Ok(s) => Ok((s, true)),
            Err(Error::AlreadyExists { .. }) => Ok((Study::open(path)?, false)),
            Err(e) => Err(e),
        }
    }

    fn open_with(path: &Path, writable: bool) -> Result<Study> {
        if !path.is_file() {
            return Err(Error::NoStudy {
                path: path.to_owned(),
            });
        }
        check_header(path)?;
        let err = |e| sql_error(path, e);
        let (conn, version) = if writable {
            let conn = Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_WRITE)
                .map_err(err)?;
            conn.busy_timeout(BUSY_TIMEOUT).map_err(err)?;
            let version = user_version(&conn).map_err(err)?;
            (conn, version)
        } else {
            read_only_connection(path)?
        };
        if version > SCHEMA_VERSION {
            return Err(Error::NotAStudy {
                path: path.to_owned(),
                reason: format!(
                    "written by a newer cdbo (study schema {version}, this version reads {SCHEMA_VERSION}); upgrade cdbo"
                ),
            });
        }
        // Read before anything is written: a foreign database is left as it was.
        let config_json: Option<String> = if version >= 1 {
            conn.query_row("SELECT value FROM meta WHERE key = 'config'", [], |r| {
                r.get(0)
            })
            .optional()
            .map_err(err)?
        } else {
            None
        };
        let config_json = config_json.ok_or_else(|| Error::NotAStudy {
            path: path.to_owned(),
            reason: "an SQLite database without a study in it".into(),
        })?;
        let config: StudyConfig =
            serde_json::from_str(&config_json).map_err(|e| Error::NotAStudy {
                path: path.to_owned(),
                reason: format!("corrupt study settings: {e}"),
            })?;
        if writable {
            configure(&conn).map_err(err)?;
            if version < SCHEMA_VERSION {
                upgrade(&conn).map_err(err)?;
            }
        }
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
        let json = serde_json::to_string(&weights).map_err(|e| Error::json("trial weights", e))?;
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

    /// The trial `worker` is to drive next, claimed for it until its lease runs out (renew it
    /// with [`Study::heartbeat`] while driving), or whether to wait or stop: the rules of
    /// [`claim::hand_out`], with `total` told trials as the goal (`None`: no limit). A new
    /// trial beside laps in flight is the optimiser's suggestion once it is told each of them
    /// with [`claim::lie`], on a copy: a distinct point, never the same weights; a method
    /// that cannot be told laps out of order ([`Optimizer::tells_any_weights`]) waits instead.
    /// A single worker gets exactly the trials [`Study::ask`] would give.
    pub fn claim(&mut self, worker: &Worker, total: Option<usize>) -> Result<Next> {
        let path = self.path.clone();
        let err = |e| sql_error(&path, e);
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(err)?;
        let now = unix_now();
        let pending = pending_claims(&tx).map_err(err)?;
        let told = told_count(&tx).map_err(err)?;
        let claims: Vec<Claim> = pending.iter().map(|(_, c)| c.clone()).collect();
        let lease_until = now + worker.lease.as_secs_f64();
        let trial = match claim::hand_out(&claims, told, total, worker, now) {
            Handout::Done => return Ok(Next::Done),
            Handout::Wait => return Ok(Next::Wait),
            Handout::Pending(id) => {
                tx.execute(
                    "UPDATE trials SET owner = ?1, lease_until_unix_s = ?2 WHERE id = ?3",
                    params![worker.id, lease_until, id],
                )
                .map_err(err)?;
                pending
                    .into_iter()
                    .map(|(t, _)| t)
                    .find(|t| t.id == id)
                    .ok_or_else(|| Error::NoTrial {
                        path: path.clone(),
                        trial: id,
                    })?
            }
            Handout::New => {
                let in_flight: Vec<Trial> = pending.into_iter().map(|(t, _)| t).collect();
                let optimizer = load_optimizer(&tx, &path, &mut self.optimizer, told)?;
                let weights = if in_flight.is_empty() {
                    optimizer.ask()?
                } else {
                    let lie = claim::lie(told_rewards(&tx).map_err(err)?);
                    match beside(optimizer.as_ref(), &in_flight, lie)? {
                        Some(w) => w,
                        None => return Ok(Next::Wait),
                    }
                };
                let json =
                    serde_json::to_string(&weights).map_err(|e| Error::json("trial weights", e))?;
                tx.execute(
                    "INSERT INTO trials (weights, asked_unix_s, owner, lease_until_unix_s) VALUES (?1, ?2, ?3, ?4)",
                    params![json, now, worker.id, lease_until],
                )
                .map_err(err)?;
                Trial {
                    id: tx.last_insert_rowid(),
                    weights,
                    reward: None,
                    lap_time_s: None,
                    failure: None,
                    x_fail: None,
                }
            }
        };
        tx.commit().map_err(err)?;
        Ok(Next::Drive(trial))
    }

    /// Renews `worker`'s claim on pending trial `id` for another lease; false if the claim is
    /// no longer the worker's (its lease ran out and another worker took the trial) or the
    /// trial was told.
    pub fn heartbeat(&self, id: i64, worker: &Worker) -> Result<bool> {
        let until = unix_now() + worker.lease.as_secs_f64();
        let n = self
            .conn
            .execute(
                "UPDATE trials SET lease_until_unix_s = ?1 WHERE id = ?2 AND owner = ?3 AND reward IS NULL",
                params![until, id, worker.id],
            )
            .map_err(|e| sql_error(&self.path, e))?;
        Ok(n == 1)
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
        let trial = trial(&tx, id).map_err(err)?.ok_or_else(|| Error::NoTrial {
            path: path.clone(),
            trial: id,
        })?;
        if trial.reward.is_some() {
            return Err(Error::Conflict {
                path: path.clone(),
                trial: id,
                reason: format!(
                    "was already told (reward {}); ask for the next trial",
                    trial.reward.unwrap_or_default()
                ),
            });
        }
        let told = told_count(&tx).map_err(err)?;
        let (lap_time, failure, x_fail) = match outcome {
            Outcome::Reward(_) => (None, None, None),
            Outcome::Lap { time_s, .. } => (Some(*time_s), None, None),
            Outcome::Failed { at, reason } => (
                None,
                Some(bounded_reason(reason.as_deref().unwrap_or("failed"))),
                *at,
            ),
        };
        let optimizer = load_optimizer(&tx, &path, &mut self.optimizer, told)?;
        let saved = (|| -> Result<()> {
            // Re-establish the optimiser's pending suggestion (the trial's), then tell it.
            optimizer.ask()?;
            optimizer.tell_lap(&trial.weights, reward, x_fail)?;
            let state = serde_json::to_string(&optimizer.save())
                .map_err(|e| Error::json("optimiser state", e))?;
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

/// The most of a failure reason a study keeps: an evaluator that prints megabytes fills the
/// database with them otherwise.
pub const MAX_REASON_BYTES: usize = 4096;

/// `reason` as stored: whole up to [`MAX_REASON_BYTES`], else its last bytes up to that bound,
/// cut at a character boundary and saying so (the end of an output says why a
/// command failed; its start is usually progress).
pub fn bounded_reason(reason: &str) -> String {
    if reason.len() <= MAX_REASON_BYTES {
        return reason.to_owned();
    }
    let note = format!(
        "[{} bytes of output, cut to their last {MAX_REASON_BYTES}; the full output was not kept] ",
        reason.len()
    );
    let mut start = reason.len() - MAX_REASON_BYTES + note.len();
    while !reason.is_char_boundary(start) {
        start += 1;
    }
    format!("{note}{}", &reason[start..])
}

/// Refuses a file that is not an SQLite database before SQLite touches it (opened read-write,
/// SQLite would write its header into an empty file).
fn check_header(path: &Path) -> Result<()> {
    use std::io::Read;
    let mut head = Vec::with_capacity(16);
    std::fs::File::open(path)
        .and_then(|f| f.take(16).read_to_end(&mut head))
        .map_err(|e| Error::Io {
            path: path.to_owned(),
            source: e,
        })?;
    if head.is_empty() {
        return Err(Error::NotAStudy {
            path: path.to_owned(),
            reason: "the file is empty".into(),
        });
    }
    if head != SQLITE_HEADER {
        return Err(Error::NotAStudy {
            path: path.to_owned(),
            reason: "the file is not an SQLite database".into(),
        });
    }
    Ok(())
}

fn user_version(conn: &Connection) -> rusqlite::Result<i64> {
    conn.pragma_query_value(None, "user_version", |r| r.get(0))
}

/// A read-only connection and the schema version. SQLite shares a WAL database through a
/// `-shm` file beside it; where that cannot be made (a read-only folder), the file is opened
/// as immutable, which is right while no writer has the study open.
fn read_only_connection(path: &Path) -> Result<(Connection, i64)> {
    let err = |e| sql_error(path, e);
    let shared =
        Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_ONLY).and_then(|c| {
            c.busy_timeout(BUSY_TIMEOUT)?;
            let v = user_version(&c)?;
            Ok((c, v))
        });
    if let Ok(opened) = shared {
        return Ok(opened);
    }
    let uri = format!("file:{}?immutable=1", uri_path(path));
    let conn = Connection::open_with_flags(
        uri,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_URI,
    )
    .map_err(err)?;
    let v = user_version(&conn).map_err(err)?;
    Ok((conn, v))
}

/// A path as the path of an SQLite `file:` URI.
fn uri_path(path: &Path) -> String {
    let text = path.to_string_lossy();
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '%' => out.push_str("%25"),
            '?' => out.push_str("%3f"),
            '#' => out.push_str("%23"),
            c => out.push(c),
        }
    }
    out
}

/// Schema 1 → 2: the claims' columns.
fn upgrade(conn: &Connection) -> rusqlite::Result<()> {
    conn.execute_batch(&format!(
        "BEGIN IMMEDIATE;
         ALTER TABLE trials ADD COLUMN owner TEXT;
         ALTER TABLE trials ADD COLUMN lease_until_unix_s REAL;
         PRAGMA user_version = {SCHEMA_VERSION};
         COMMIT;"
    ))
}

/// A new suggestion beside the laps in flight: a copy of the optimiser is told each of them
/// with reward `lie`, then asked; `None` if the method cannot be told laps out of order, or
/// keeps suggesting a lap in flight.
fn beside(
    optimizer: &(dyn Optimizer + Send),
    in_flight: &[Trial],
    lie: f64,
) -> Result<Option<Vec<f64>>> {
    if !optimizer.tells_any_weights() {
        return Ok(None);
    }
    let mut fantasy = optimizer.save().resume()?;
    for t in in_flight {
        fantasy.ask()?;
        fantasy.tell(&t.weights, lie)?;
    }
    for _ in 0..4 {
        let w = fantasy.ask()?;
        if in_flight.iter().all(|t| t.weights != w) {
            return Ok(Some(w));
        }
        fantasy.tell(&w, lie)?;
    }
    Ok(None)
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

/// The pending trials in order, with their claims.
fn pending_claims(conn: &Connection) -> rusqlite::Result<Vec<(Trial, Claim)>> {
    let mut stmt = conn.prepare(
        "SELECT id, weights, reward, lap_time_s, failure, x_fail, owner, lease_until_unix_s FROM trials WHERE reward IS NULL ORDER BY id",
    )?;
    let rows = stmt.query_map([], |r| {
        let t = row_to_trial(r)?;
        let c = Claim {
            trial: t.id,
            owner: r.get(6)?,
            lease_until: r.get(7)?,
        };
        Ok((t, c))
    })?;
    rows.collect()
}

fn told_rewards(conn: &Connection) -> rusqlite::Result<Vec<f64>> {
    let mut stmt = conn.prepare("SELECT reward FROM trials WHERE reward IS NOT NULL")?;
    let rows = stmt.query_map([], |r| r.get(0))?;
    rows.collect()
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
    let current = match cache.take().filter(|c| c.1 == told) {
        Some(c) => c,
        None => {
            let state: String = conn
                .query_row("SELECT state FROM optimizer WHERE id = 1", [], |r| r.get(0))
                .map_err(|e| sql_error(path, e))?;
            let saved: Saved = serde_json::from_str(&state).map_err(|e| Error::Json {
                what: format!("{}: the optimiser state", path.display()),
                source: e,
            })?;
            (saved.resume()?, told)
        }
    };
    Ok(&mut cache.insert(current).0)
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
    fn long_reasons_keep_a_bounded_tail_cut_at_a_character() {
        assert_eq!(bounded_reason("spun at turn 3"), "spun at turn 3");
        let long = "é".repeat(10_000) + "the end";
        let kept = bounded_reason(&long);
        assert!(kept.len() <= MAX_REASON_BYTES, "{}", kept.len());
        assert!(
            kept.starts_with("[20007 bytes of output, cut to their last 4096"),
            "{kept}"
        );
        assert!(kept.ends_with("éthe end"));
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
