//! Sources of laps: every way a policy's reward is obtained implements [`Evaluator`] — the
//! simulator ([`simulator`]), an external command such as a real car's lap timer
//! ([`command`]) — and reports an [`Outcome`], which a study records.

pub mod command;
pub mod simulator;
pub mod torcs;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Drives one lap with given policy weights.
pub trait Evaluator {
    /// The outcome of a lap with `weights`. An error means no lap could be attempted (the
    /// setup is broken), not that the lap failed: a failed lap is an [`Outcome::Failed`].
    fn evaluate(&mut self, weights: &[f64]) -> Result<Outcome>;
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
