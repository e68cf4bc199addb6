//! Gaussian random search around the best point so far: w ~ N(w*, σ²I), clamped to the box.
//! The floor every model-based method must beat.

use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use super::{Best, Optimizer, Saved, SearchBox, check_tell, rng_for};
use crate::error::{Error, Result};

/// The method's name, and the kind of its saved state.
pub const NAME: &str = "random";
const SAVED_KIND: &str = NAME;

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

/// Everything needed to resume a search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RandomState {
    /// Settings.
    pub config: RandomConfig,
    /// The start point.
    pub start: Vec<f64>,
    /// Rewards told.
    pub evaluations: usize,
    /// The best (weights, reward) told.
    pub(crate) best: Best,
}

/// Random search.
#[derive(Debug, Clone)]
pub struct RandomSearch {
    state: RandomState,
    bounds: SearchBox,
    pending: Option<Vec<f64>>,
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
        RandomSearch::resume(RandomState {
            config,
            start,
            evaluations: 0,
            best: Best::default(),
        })
    }

    /// Rebuilds a search from its state.
    pub fn resume(state: RandomState) -> Result<RandomSearch> {
        Ok(RandomSearch {
            bounds: SearchBox::around(&state.start, state.config.box_radius)?,
            state,
            pending: None,
        })
    }

    /// The state to save.
    pub fn state(&self) -> &RandomState {
        &self.state
    }
}

impl Optimizer for RandomSearch {
    fn name(&self) -> &'static str {
        NAME
    }

    fn dim(&self) -> usize {
        self.state.start.len()
    }

    fn ask(&mut self) -> Result<Vec<f64>> {
        if let Some(p) = &self.pending {
            return Ok(p.clone());
        }
        let s = &self.state;
        let centre = s.best.get().map_or(&s.start[..], |b| b.0);
        let w = if s.evaluations == 0 {
            s.start.clone()
        } else {
            let normal = Normal::new(0.0, s.config.sigma)
                .map_err(|_| Error::invalid_value("σ", s.config.sigma, "positive"))?;
            let mut rng = rng_for(s.config.seed, s.evaluations as u64);
            let mut w: Vec<f64> = centre.iter().map(|c| c + normal.sample(&mut rng)).collect();
            self.bounds.clamp(&mut w);
            w
        };
        self.pending = Some(w.clone());
        Ok(w)
    }

    fn tell(&mut self, weights: &[f64], reward: f64) -> Result<()> {
        check_tell(self.dim(), weights, reward)?;
        self.state.evaluations += 1;
        self.state.best.offer(weights, reward);
        self.pending = None;
        Ok(())
    }

    fn best(&self) -> Option<(&[f64], f64)> {
        self.state.best.get()
    }

    fn evaluations(&self) -> usize {
        self.state.evaluations
    }

    fn save(&self) -> Saved {
        Saved::new(SAVED_KIND, &self.state)
    }
}
