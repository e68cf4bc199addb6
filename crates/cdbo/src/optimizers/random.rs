//! Gaussian random search around the best point so far: w ~ N(w*, σ²I), clamped to the box.
//! The floor every model-based method must beat.

use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use std::borrow::Cow;

use super::ask_tell::{AskTell, Lap, Proposal, Proposer, Recorded, SavedAs, Told};
use super::{SearchBox, rng_for};
use crate::error::{Error, Result};

/// The method's name, and the kind of its saved state.
pub const NAME: &str = "random";

/// Settings of a random search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RandomConfig {
    /// Seed of every random choice.
    pub seed: u64,
    /// Standard deviation σ of the perturbations.
    pub sigma: f64,
    /// Half-width of the search box around the start.
    pub box_radius: f64,
}

impl Default for RandomConfig {
    fn default() -> Self {
        RandomConfig {
            seed: 0,
            sigma: 0.1,
            box_radius: super::DEFAULT_BOX_RADIUS,
        }
    }
}

/// The search's own state: its settings and start.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RandomProgress {
    /// Settings.
    pub config: RandomConfig,
    /// The start point.
    pub start: Vec<f64>,
}

/// Everything needed to resume a search: its state and the laps' record.
pub type RandomState = Recorded<RandomProgress>;

/// Random search's proposer: the start first, then w ~ N(w*, σ²I) clamped to the box, w* the
/// best weights told, drawn from stream n (n laps told) of the seed.
#[derive(Debug, Clone)]
pub struct RandomProposer {
    state: RandomProgress,
    bounds: SearchBox,
}

/// Random search.
pub type RandomSearch = AskTell<RandomProposer>;

impl RandomProposer {
    fn resume(state: RandomProgress) -> Result<RandomProposer> {
        Ok(RandomProposer {
            bounds: SearchBox::around(&state.start, state.config.box_radius)?,
            state,
        })
    }
}

impl RandomSearch {
    /// A search from `start` (asked first, unperturbed).
    pub fn new(start: Vec<f64>, config: RandomConfig) -> Result<RandomSearch> {
        if start.is_empty() || start.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid_value(
                "random search's start point",
                format!("{start:?}"),
                "finite, of at least one weight",
            ));
        }
        if !(config.sigma.is_finite() && config.sigma > 0.0) {
            return Err(Error::invalid_value("σ", config.sigma, "positive"));
        }
        let proposer = RandomProposer::resume(RandomProgress { config, start })?;
        Ok(AskTell::resumed(proposer, Told::default()))
    }

    /// Rebuilds a search from its state.
    pub fn resume(state: RandomState) -> Result<RandomSearch> {
        let (state, told) = state.into_parts();
        Ok(AskTell::resumed(RandomProposer::resume(state)?, told))
    }
}

impl Proposer for RandomProposer {
    type Note = ();
    type State = RandomProgress;
    const SAVED_AS: SavedAs = SavedAs::WithRecord(NAME);

    fn propose(&mut self, told: &Told) -> Result<Proposal<()>> {
        let s = &self.state;
        if told.evaluations() == 0 {
            return Ok(Proposal::plain(s.start.clone()));
        }
        let normal = Normal::new(0.0, s.config.sigma)
            .map_err(|_| Error::invalid_value("σ", s.config.sigma, "positive"))?;
        let mut rng = rng_for(s.config.seed, told.evaluations() as u64);
        let centre = told.best_or(&s.start);
        let mut w: Vec<f64> = centre.iter().map(|c| c + normal.sample(&mut rng)).collect();
        self.bounds.clamp(&mut w);
        Ok(Proposal::plain(w))
    }

    fn observe(&mut self, _: &Lap<'_>, _: Option<&Proposal<()>>, _: &Told) -> Result<()> {
        Ok(())
    }

    fn dim(&self) -> usize {
        self.state.start.len()
    }

    fn state(&self) -> Cow<'_, RandomProgress> {
        Cow::Borrowed(&self.state)
    }
}
