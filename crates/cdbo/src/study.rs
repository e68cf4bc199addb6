//! Persistent ask/tell studies for optimising a real car one lap at a time: every trial
//! (asked weights, then the told outcome), the settings and the optimiser's [`Saved`] state
//! after the last tell, kept in the claimed-row store ([`crate::store`]) — an SQLite file (the
//! embedded default) or a PostgreSQL database, named by a [`Location`] — so
//! that a told result is durable before `tell` returns, and a study survives crashes,
//! `kill -9` and restarts, continuing with exactly the suggestion an uninterrupted run would
//! make.
//!
//! `ask` returns the pending trial if there is one; otherwise it asks the optimiser and
//! records a pending trial. `tell` records the outcome and the optimiser's new state in one
//! transaction, under the study's write lock.
//!
//! Several workers drive one study through [`Study::claim`]: each trial handed out is claimed
//! by its worker with a lease the worker renews while it drives ([`Study::heartbeat`]), so
//! that every trial is driven once, and a trial whose worker died is handed out again; the
//! rules are in [`claim`], apart from the storage. Reading commands open a study with
//! [`Study::open_read_only`], which writes nothing.

pub use crate::store::claim;
#[cfg(feature = "postgres")]
mod postgres;
pub mod run;
mod sqlite;
mod storage;

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::drive::steering::SteeringLaw;
use crate::error::{Error, Result};
pub use crate::evaluator::Outcome;
use crate::line::BaseLine;
use crate::method::{Method, Spec, resume};
use crate::optimizers::{Optimizer, Saved};
use crate::policy::RacedPolicy;
use crate::policy::{Block, PolicyShape};
use claim::{Handout, Worker};
use storage::{Dump, Storage, Told, Transaction};

use crate::store::unix_now;
pub use crate::store::{Location, SCHEMA_VERSION};

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

/// A study's settings, fixed at creation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudyConfig {
    /// Optimiser (`cdbo` by default).
    pub method: Method,
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
    /// The track the laps are driven on, where the user or the evaluator named it (absent
    /// in studies made before it was recorded, and left out of the stored settings then).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub track: Option<String>,
    /// The lap's length (m), where the user told it (the pattern search's push repairs over
    /// road then; absent in studies made before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub track_length: Option<f64>,
    /// The method's main knob ([`Method::knob`]), where the user set it; absent: its race
    /// value (and in studies made before it could be set).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub knob: Option<f64>,
    /// Failed laps allowed ([`Spec::max_failed_laps`]), where the user set it; absent: no
    /// budget (the safe pattern search's own, [`crate::learner::safe_search::BUDGET`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_failed_laps: Option<usize>,
    /// Half-width r of the box [w₀ − r, w₀ + r] the method searches ([`Spec::box_radius`]),
    /// where the user set it; absent: [`DEFAULT_BOX_RADIUS`](crate::optimizers::DEFAULT_BOX_RADIUS)
    /// (and in studies made before it could be set).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub box_radius: Option<f64>,
    /// The policy file w₀ was read from when the study is warm-started from a learned policy
    /// (the pattern search then does not push it: [`Spec::warm_started`]); absent: w₀ is a
    /// demonstration's fit or initial weights, and in studies made before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub warm_start: Option<String>,
    /// Kernels of a learned line d(x) ([`crate::policy::actions`]) at the paper's length-scale
    /// 1/(M_d − 1): the weights are then [w_a, w_d], w₀ and every trial, as `cdbo race --line
    /// learn` races them; absent: the pedal only (and in studies made before it could be set).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_kernels: Option<usize>,
    /// The line the car holds where the policy has none, and from which a learned line's
    /// offsets are measured ([`BaseLine`]); absent: the centre line.
    #[serde(default, skip_serializing_if = "BaseLine::is_centre")]
    pub base_line: BaseLine,
    /// The steering the car drives with, written into each lap's policy file
    /// ([`RacedPolicy`]) and used in the game; absent: the paper's PI.
    #[serde(default, skip_serializing_if = "SteeringLaw::is_pi")]
    pub steering: SteeringLaw,
}

impl StudyConfig {
    /// The shape of the study's policies: M pedal kernels of its length-scale and, with a
    /// learned line, M_d line kernels at 1/(M_d − 1).
    pub fn shape(&self) -> Result<PolicyShape> {
        let pedal = PolicyShape::pedal(Block::new(self.kernels, self.lengthscale)?);
        Ok(match self.line_kernels {
            Some(m) => pedal.with_line(Block::paper(m)?),
            None => pedal,
        })
    }

    /// The policy a trial's weights are, with the study's base line ([`RacedPolicy`]).
    pub fn policy(&self, weights: &[f64]) -> Result<RacedPolicy> {
        Ok(RacedPolicy {
            policy: self.shape()?.policy(weights)?,
            base_line: self.base_line,
            steering: self.steering,
        })
    }

    /// The study's specification of its method, for the weights of its lap policy (with a
    /// learned line, the pedal's block first, as a race's).
    pub fn spec(&self) -> Result<Spec> {
        let mut spec =
            Spec::told(self.method, self.seed, self.beta, self.knob)?.policy(self.lengthscale)?;
        if self.line_kernels.is_some() {
            spec = spec.pedal_kernels(self.kernels);
        }
        if let Some(max) = self.max_failed_laps {
            spec = spec.max_failed_laps(max);
        }
        if let Some(radius) = self.box_radius {
            spec = spec.box_radius(radius)?;
        }
        if self.warm_start.is_some() {
            spec = spec.warm_started();
        }
        self.track_length
            .map_or(Ok(spec), |length| spec.track_length(length))
    }
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

impl Trial {
    /// A trial just asked: `weights` to drive, nothing told yet.
    fn asked(id: i64, weights: Vec<f64>) -> Trial {
        Trial {
            id,
            weights,
            reward: None,
            lap_time_s: None,
            failure: None,
            x_fail: None,
        }
    }
}

/// An open study.
pub struct Study {
    location: Location,
    label: PathBuf,
    /// Behind a cell so that reading and renewing a claim take `&self`, as on one connection.
    storage: RefCell<Box<dyn Storage>>,
    config: StudyConfig,
    /// The optimiser and the number of told trials it has seen.
    optimizer: Option<(Box<dyn Optimizer + Send>, usize)>,
}

impl Study {
    /// Creates a study file; refuses to overwrite one.
    pub fn create(path: &Path, config: StudyConfig) -> Result<Study> {
        Study::create_at(&Location::Sqlite(path.to_owned()), config)
    }

    /// Creates a study at `location`; refuses to overwrite one.
    pub fn create_at(location: &Location, config: StudyConfig) -> Result<Study> {
        let dims = config.shape()?.dims();
        if config.w0.len() != dims {
            return Err(Error::dimension(
                "initial weights (one per kernel, the line's after the pedal's)",
                dims,
                config.w0.len(),
            ));
        }
        // Fails on a bad method, w₀ or lap length before anything is written.
        let optimizer = config.spec()?.optimizer(config.w0.clone())?;
        let dump = Dump {
            config: serde_json::to_string(&config).map_err(|e| Error::json("study settings", e))?,
            optimizer: serde_json::to_string(&optimizer.save())
                .map_err(|e| Error::json("optimiser state", e))?,
            trials: Vec::new(),
        };
        create_from(location, &dump)?;
        let mut study = Study::open_at(location)?;
        study.optimizer = Some((optimizer, 0));
        Ok(study)
    }

    /// Copies the study at `from` to a new study at `to` (another back end, or the same),
    /// row for row: settings, trials with their times and claims, and the optimiser's state,
    /// so that the copy continues exactly as the original would. Refuses to overwrite.
    pub fn copy(from: &Location, to: &Location) -> Result<Study> {
        let dump = Study::open_read_only_at(from)?.storage.get_mut().dump()?;
        create_from(to, &dump)?;
        Study::open_at(to)
    }

    /// Opens an existing study file to ask and tell; a study of an older schema is upgraded.
    pub fn open(path: &Path) -> Result<Study> {
        Study::open_at(&Location::Sqlite(path.to_owned()))
    }

    /// Opens an existing study file to read it: writes nothing, and works where the file or
    /// its folder is read-only (then as an immutable file, if SQLite cannot share it).
    pub fn open_read_only(path: &Path) -> Result<Study> {
        Study::open_read_only_at(&Location::Sqlite(path.to_owned()))
    }

    /// Opens the study file at `path`, or creates it with `config` if there is none; see
    /// [`Study::open_or_create_at`].
    pub fn open_or_create(path: &Path, config: StudyConfig) -> Result<(Study, bool)> {
        Study::open_or_create_at(&Location::Sqlite(path.to_owned()), config)
    }

    /// Opens the study at `location` to ask and tell; an older schema is upgraded.
    pub fn open_at(location: &Location) -> Result<Study> {
        Study::open_with(location, true)
    }

    /// Opens the study at `location` to read it: writes nothing.
    pub fn open_read_only_at(location: &Location) -> Result<Study> {
        Study::open_with(location, false)
    }

    /// Opens the study at `location`, or creates it with `config` if there is none: workers
    /// started at once on a study that does not exist yet all join the one created first.
    /// Returns whether this call created it.
    pub fn open_or_create_at(location: &Location, config: StudyConfig) -> Result<(Study, bool)> {
        match Study::open_at(location) {
            Err(Error::NoStudy { .. }) => {}
            opened => return opened.map(|s| (s, false)),
        }
        match Study::create_at(location, config) {
            Ok(s) => Ok((s, true)),
            Err(Error::AlreadyExists { .. }) => Ok((Study::open_at(location)?, false)),
            Err(e) => Err(e),
        }
    }

    fn open_with(location: &Location, writable: bool) -> Result<Study> {
        let (storage, config_json): (Box<dyn Storage>, String) = match location {
            Location::Sqlite(path) => {
                let (s, c) = sqlite::open(path, writable)?;
                (Box::new(s), c)
            }
            #[cfg(feature = "postgres")]
            Location::Postgres { url, study } => {
                let (s, c) = postgres::open(url, study, &location.label(), writable)?;
                (Box::new(s), c)
            }
            #[cfg(not(feature = "postgres"))]
            Location::Postgres { .. } => return Err(location.without_postgres()),
        };
        let label = storage.label().to_owned();
        let config: StudyConfig =
            serde_json::from_str(&config_json).map_err(|e| Error::NotAStudy {
                path: label.clone(),
                reason: format!("corrupt study settings: {e}"),
            })?;
        Ok(Study {
            location: location.clone(),
            label,
            storage: RefCell::new(storage),
            config,
            optimizer: None,
        })
    }

    /// The study's settings.
    pub fn config(&self) -> &StudyConfig {
        &self.config
    }

    /// Where the study lives, for messages: the file, or the database URL and study name.
    pub fn path(&self) -> &Path {
        &self.label
    }

    /// Where the study lives, to open it again (another connection, another process).
    pub fn location(&self) -> &Location {
        &self.location
    }

    /// The trial to drive next: the pending one if any, else a new suggestion.
    pub fn ask(&mut self) -> Result<Trial> {
        let storage = self.storage.get_mut();
        let mut tx = storage.begin()?;
        if let Some((t, _)) = tx.pending()?.into_iter().next() {
            return Ok(t);
        }
        let told = tx.told()?;
        let optimizer = load_optimizer(tx.as_mut(), &self.label, &mut self.optimizer, told)?;
        let weights = optimizer.ask()?;
        let id = tx.add_trial(&weights_json(&weights)?, unix_now())?;
        tx.commit()?;
        Ok(Trial::asked(id, weights))
    }

    /// The trial `worker` is to drive next, claimed for it until its lease runs out (renew it
    /// with [`Study::heartbeat`] while driving), or whether to wait or stop: the rules of
    /// [`claim::hand_out`], with `total` told trials as the goal (`None`: no limit). A new
    /// trial beside laps in flight is the optimiser's suggestion once it is told each of them
    /// with [`claim::lie`], on a copy: a distinct point, never the same weights; a method
    /// that cannot be told laps out of order ([`Optimizer::tells_any_weights`]) waits instead.
    /// A single worker gets exactly the trials [`Study::ask`] would give.
    pub fn claim(&mut self, worker: &Worker, total: Option<usize>) -> Result<Next> {
        let storage = self.storage.get_mut();
        let mut tx = storage.begin()?;
        let now = unix_now();
        let pending = tx.pending()?;
        let told = tx.told()?;
        let claims: Vec<_> = pending.iter().map(|(_, c)| c.clone()).collect();
        let lease_until = now + worker.lease.as_secs_f64();
        let trial = match claim::hand_out(&claims, told, total, worker, now) {
            Handout::Done => return Ok(Next::Done),
            Handout::Wait => return Ok(Next::Wait),
            Handout::Pending(id) => {
                tx.set_claim(id, &worker.id, lease_until)?;
                pending
                    .into_iter()
                    .map(|(t, _)| t)
                    .find(|t| t.id == id)
                    .ok_or_else(|| Error::NoTrial {
                        path: self.label.clone(),
                        trial: id,
                    })?
            }
            Handout::New => {
                let in_flight: Vec<Trial> = pending.into_iter().map(|(t, _)| t).collect();
                let lie = if in_flight.is_empty() {
                    0.0
                } else {
                    claim::lie(tx.told_rewards()?)
                };
                let optimizer =
                    load_optimizer(tx.as_mut(), &self.label, &mut self.optimizer, told)?;
                let weights = if in_flight.is_empty() {
                    optimizer.ask()?
                } else {
                    match beside(optimizer.as_ref(), &in_flight, lie)? {
                        Some(w) => w,
                        None => return Ok(Next::Wait),
                    }
                };
                let id = tx.add_trial(&weights_json(&weights)?, now)?;
                tx.set_claim(id, &worker.id, lease_until)?;
                Trial::asked(id, weights)
            }
        };
        tx.commit()?;
        Ok(Next::Drive(trial))
    }

    /// Renews `worker`'s claim on pending trial `id` for another lease; false if the claim is
    /// no longer the worker's (its lease ran out and another worker took the trial) or the
    /// trial was told.
    pub fn heartbeat(&self, id: i64, worker: &Worker) -> Result<bool> {
        let until = unix_now() + worker.lease.as_secs_f64();
        self.storage.borrow_mut().heartbeat(id, &worker.id, until)
    }

    /// Records the outcome of pending trial `id`; returns the reward. Durable on return.
    pub fn tell(&mut self, id: i64, outcome: &Outcome) -> Result<f64> {
        let reward = outcome.reward()?;
        let label = &self.label;
        let storage = self.storage.get_mut();
        let mut tx = storage.begin()?;
        let trial = tx.trial(id)?.ok_or_else(|| Error::NoTrial {
            path: label.clone(),
            trial: id,
        })?;
        if let Some(told) = trial.reward {
            return Err(Error::Conflict {
                path: label.clone(),
                trial: id,
                reason: format!("was already told (reward {told}); ask for the next trial"),
            });
        }
        let told = tx.told()?;
        let (lap_time_s, failure, x_fail) = match outcome {
            Outcome::Reward(_) => (None, None, None),
            Outcome::Lap { time_s, .. } => (Some(*time_s), None, None),
            Outcome::Failed { at, reason } => (
                None,
                Some(bounded_reason(reason.as_deref().unwrap_or("failed"))),
                *at,
            ),
        };
        let record = Told {
            reward,
            lap_time_s,
            failure,
            x_fail,
            told_unix_s: unix_now(),
        };
        let saved = (|| -> Result<()> {
            let optimizer = load_optimizer(tx.as_mut(), label, &mut self.optimizer, told)?;
            // Re-establish the optimiser's pending suggestion (the trial's), then tell it.
            optimizer.ask()?;
            optimizer.tell_lap(&trial.weights, reward, outcome.failed_lap())?;
            let state = serde_json::to_string(&optimizer.save())
                .map_err(|e| Error::json("optimiser state", e))?;
            tx.record(id, &record, &state)?;
            tx.commit()
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
        self.storage.borrow_mut().told()
    }

    /// Every trial, in order.
    pub fn history(&self) -> Result<Vec<Trial>> {
        self.storage.borrow_mut().history()
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

/// Creates a study holding `dump` at `location`, in the back end the location names.
fn create_from(location: &Location, dump: &Dump) -> Result<()> {
    match location {
        Location::Sqlite(path) => sqlite::create(path, dump),
        #[cfg(feature = "postgres")]
        Location::Postgres { url, study } => postgres::create(url, study, &location.label(), dump),
        #[cfg(not(feature = "postgres"))]
        Location::Postgres { .. } => Err(location.without_postgres()),
    }
}

/// A trial's weights as stored: JSON, whose numbers read back bit for bit.
fn weights_json(weights: &[f64]) -> Result<String> {
    serde_json::to_string(weights).map_err(|e| Error::json("trial weights", e))
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
    let mut fantasy = resume(optimizer.save())?;
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

/// The optimiser as of `told` told trials: the one in memory if it is current (no other
/// process told a trial since), else resumed from the saved state.
fn load_optimizer<'a>(
    tx: &mut dyn Transaction,
    label: &Path,
    cache: &'a mut Option<(Box<dyn Optimizer + Send>, usize)>,
    told: usize,
) -> Result<&'a mut Box<dyn Optimizer + Send>> {
    let current = match cache.take().filter(|c| c.1 == told) {
        Some(c) => c,
        None => {
            let state = tx.optimizer_state()?;
            let saved: Saved = serde_json::from_str(&state).map_err(|e| Error::Json {
                what: format!("{}: the optimiser state", label.display()),
                source: e,
            })?;
            (resume(saved)?, told)
        }
    };
    Ok(&mut cache.insert(current).0)
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn config() -> StudyConfig {
        StudyConfig {
            method: Method::Cdbo,
            kernels: 3,
            lengthscale: 0.5,
            seed: 1,
            beta: 1.0,
            w0: vec![0.1, 0.2, 0.3],
            track: None,
            track_length: None,
            knob: None,
            max_failed_laps: None,
            box_radius: None,
            warm_start: None,
            line_kernels: None,
            base_line: Default::default(),
            steering: Default::default(),
        }
    }

    pub(crate) fn temp(name: &str) -> PathBuf {
        crate::scratch::dir(&format!("study-{name}")).join("s.db")
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

    /// A lap length that is not a positive number of metres is refused, whatever the method,
    /// and nothing is written.
    #[test]
    fn a_bad_lap_length_is_refused_before_anything_is_written() {
        for (k, length) in [0.0, -3.0, f64::NAN, f64::INFINITY].into_iter().enumerate() {
            let path = temp(&format!("length-{k}"));
            let bad = StudyConfig {
                track_length: Some(length),
                ..config()
            };
            let Err(e) = Study::create(&path, bad).map(|_| ()) else {
                panic!("{length}: created");
            };
            let e = e.to_string();
            assert!(e.contains("lap's length"), "{length}: {e}");
            assert!(!path.exists(), "{length}: a file was written");
        }
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
}
