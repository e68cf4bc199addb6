//! A budget of failed laps around any method, a hard cap: the method proposes laps as
//! usual until `max_failed` of them have failed; from then on only the best completed lap is
//! driven again. In a deterministic simulator that lap completes again, so a run fails at most
//! `max_failed` laps; on a real car it is the lap the learner is most certain of.
//!
//! A lap failed when its reward is 0 or its failure was told ([`FailedLap`]). A lap can be
//! driven again only once one has completed, or where the start is known to complete
//! ([`FailureBudget::falling_back_to`]: a race drives its start until it does,
//! [`crate::experiment::start`]): then the cap holds from the first lap. Otherwise the method
//! goes on proposing until a lap completes.

use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::optimizers::{FailedLap, Optimizer, Saved, check_tell_lap};

/// The kind of a budgeted method's saved state.
pub const SAVED_KIND: &str = "failure-budget";

/// What a budget keeps besides its method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BudgetState {
    /// The method's own state.
    pub inner: Saved,
    /// Failed laps allowed.
    pub max_failed: usize,
    /// Failed laps told.
    pub failed: usize,
    /// Laps driven again after the budget was spent (not told to the method).
    pub repeats: usize,
    /// A start known to complete, driven again once the budget is spent while no lap of the
    /// method has completed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<Vec<f64>>,
}

/// A method that fails at most `max_failed` laps.
pub struct FailureBudget {
    inner: Box<dyn Optimizer + Send>,
    max_failed: usize,
    failed: usize,
    repeats: usize,
    fallback: Option<Vec<f64>>,
}

impl FailureBudget {
    /// `inner` within a budget of `max_failed` failed laps.
    pub fn new(inner: Box<dyn Optimizer + Send>, max_failed: usize) -> FailureBudget {
        FailureBudget {
            inner,
            max_failed,
            failed: 0,
            repeats: 0,
            fallback: None,
        }
    }

    /// This budget with `start` known to complete: once the budget is spent, `start` is driven
    /// again while no lap of the method has completed.
    pub fn falling_back_to(self, start: Vec<f64>) -> FailureBudget {
        FailureBudget {
            fallback: Some(start),
            ..self
        }
    }

    /// A budget continuing exactly where `state` was saved, its method by `resume`.
    pub fn resume(
        state: BudgetState,
        resume: impl FnOnce(Saved) -> Result<Box<dyn Optimizer + Send>>,
    ) -> Result<FailureBudget> {
        Ok(FailureBudget {
            inner: resume(state.inner)?,
            max_failed: state.max_failed,
            failed: state.failed,
            repeats: state.repeats,
            fallback: state.fallback,
        })
    }

    /// Whether the budget is spent: only the best completed lap is driven from now on.
    pub fn spent(&self) -> bool {
        self.failed >= self.max_failed
    }

    /// The lap driven again once the budget is spent: the best completed one, else the start
    /// known to complete.
    fn safest(&self) -> Option<Vec<f64>> {
        self.inner
            .best()
            .filter(|(_, reward)| *reward > 0.0)
            .map(|(w, _)| w.to_vec())
            .or_else(|| self.fallback.clone())
    }
}

impl Optimizer for FailureBudget {
    fn name(&self) -> &'static str {
        self.inner.name()
    }

    fn dim(&self) -> usize {
        self.inner.dim()
    }

    fn ask(&mut self) -> Result<Vec<f64>> {
        if self.spent()
            && let Some(w) = self.safest()
        {
            return Ok(w);
        }
        self.inner.ask()
    }

    fn tell(&mut self, weights: &[f64], reward: f64) -> Result<()> {
        self.tell_lap(weights, reward, None)
    }

    fn tell_lap(&mut self, weights: &[f64], reward: f64, failure: Option<FailedLap>) -> Result<()> {
        check_tell_lap(self.dim(), weights, reward, failure)?;
        let failed = reward == 0.0 || failure.is_some();
        if self.spent() && self.safest().is_some() {
            self.repeats += 1;
        } else {
            self.inner.tell_lap(weights, reward, failure)?;
        }
        self.failed += usize::from(failed);
        Ok(())
    }

    fn tells_any_weights(&self) -> bool {
        self.inner.tells_any_weights()
    }

    fn best(&self) -> Option<(&[f64], f64)> {
        self.inner.best()
    }

    fn evaluations(&self) -> usize {
        self.inner.evaluations() + self.repeats
    }

    fn save(&self) -> Saved {
        Saved::new(
            SAVED_KIND,
            &BudgetState {
                inner: self.inner.save(),
                max_failed: self.max_failed,
                failed: self.failed,
                repeats: self.repeats,
                fallback: self.fallback.clone(),
            },
        )
    }
}
