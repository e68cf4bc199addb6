//! Sources of laps: every way a policy's reward is obtained implements [`Evaluator`] — the
//! simulator ([`simulator`]), an external command such as a real car's lap timer
//! ([`command`]) — and reports an [`Outcome`], which a study records.

pub mod command;
pub mod simulator;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::sim::LapResult;

/// Drives one lap with given policy weights.
pub trait Evaluator {
    /// The outcome of trial `trial`'s lap with `weights` (the trial's number names what the
    /// evaluator keeps per lap, such as the command evaluator's policy file). An error means
    /// no lap could be attempted (the setup is broken), not that the lap failed: a failed lap
    /// is an [`Outcome::Failed`].
    fn evaluate(&mut self, trial: i64, weights: &[f64]) -> Result<Outcome>;

    /// Removes what laps of processes killed mid-lap left behind (files of theirs); returns
    /// each file removed and its process. Called before a worker's first lap.
    fn remove_leftovers(&mut self) -> Vec<(std::path::PathBuf, u32)> {
        Vec::new()
    }
}

/// A boxed evaluator is one (a [`crate::venue::Venue`]'s, say).
impl<E: Evaluator + ?Sized> Evaluator for Box<E> {
    fn evaluate(&mut self, trial: i64, weights: &[f64]) -> Result<Outcome> {
        (**self).evaluate(trial, weights)
    }

    fn remove_leftovers(&mut self) -> Vec<(std::path::PathBuf, u32)> {
        (**self).remove_leftovers()
    }
}

/// What a lap produced, as told to a study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Outcome {
    /// A reward (m/s for laps; any finite number for other tasks).
    Reward(f64),
    /// A completed lap: reward = length / time.
    Lap {
        /// Lap time (s), positive.
        time_s: f64,
        /// Lap length (m), positive.
        length_m: f64,
    },
    /// A failed lap (reward 0), where and why if known.
    Failed {
        /// Fraction of the lap where it failed.
        at: Option<f64>,
        /// Why.
        reason: Option<String>,
    },
}

impl Outcome {
    /// The outcome of a lap driven on a track `length_m` long: its time, or where and why it
    /// failed.
    pub fn of_lap(lap: &LapResult, length_m: f64) -> Outcome {
        match (lap.lap_time_s, lap.failure) {
            (Some(time_s), None) => Outcome::Lap { time_s, length_m },
            (_, failure) => Outcome::Failed {
                at: failure.map(|f| f.x),
                reason: failure.map(|f| f.reason.name().to_owned()),
            },
        }
    }

    /// Where a failed lap failed and whether it was too slow there (a reason that names a stall
    /// or the time limit), if its place is known.
    pub fn failed_lap(&self) -> Option<crate::optimizers::FailedLap> {
        match self {
            Outcome::Failed {
                at: Some(at),
                reason,
            } => Some(crate::optimizers::FailedLap {
                at: *at,
                too_slow: reason
                    .as_deref()
                    .and_then(crate::sim::lap::FailureReason::from_name)
                    .is_some_and(crate::sim::lap::FailureReason::too_slow),
            }),
            _ => None,
        }
    }

    /// Where a failed lap failed (lap fraction), if known.
    pub fn failed_at(&self) -> Option<f64> {
        match self {
            Outcome::Failed { at, .. } => *at,
            _ => None,
        }
    }

    /// The reward, after checking the numbers.
    pub fn reward(&self) -> Result<f64> {
        match self {
            Outcome::Reward(r) if r.is_finite() => Ok(*r),
            Outcome::Reward(r) => Err(Error::invalid_value("the reward", r, "a finite number")),
            Outcome::Lap { time_s, length_m } => {
                if !(time_s.is_finite() && *time_s > 0.0) {
                    return Err(Error::invalid_value(
                        "the lap time",
                        time_s,
                        "a positive number of seconds",
                    ));
                }
                if !(length_m.is_finite() && *length_m > 0.0) {
                    return Err(Error::invalid_value(
                        "the lap length",
                        length_m,
                        "a positive number of metres",
                    ));
                }
                Ok(length_m / time_s)
            }
            Outcome::Failed { at, .. } => match at {
                Some(x) if !(x.is_finite() && (0.0..=1.0).contains(x)) => Err(
                    Error::invalid_value("where the lap failed", x, "a lap fraction in [0, 1]"),
                ),
                _ => Ok(0.0),
            },
        }
    }
}
