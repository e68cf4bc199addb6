//! Pattern search with failure repair: an adaptive coordinate search around the best lap that
//! reads where a failed lap failed.
//!
//! The weights are a policy's kernels in lap order (weight i acts around x̂ᵢ = i/(M − 1)), and
//! a lap is causal: the pedal at x changes nothing before x. Each weight i has a signed step
//! sᵢ, first +σ₀ (more pedal). A trial moves one weight from the best point w*:
//! w = clamp(w* + sᵢeᵢ) (Rosenbrock's method on the coordinate axes):
//! - a faster lap is accepted and the step grows, sᵢ ← 2sᵢ, on the same weight;
//! - a lap that **fails at x_f past the moved kernel** was too fast for what follows: the
//!   **repair** w* + sᵢeᵢ − sᵢeⱼ gives the step back at the kernel j = ⌊x_f(M − 1)⌋ − 1 just
//!   before the failure (brake earlier for the corner the car could not take); if it is
//!   faster, both are accepted and sᵢ doubles;
//! - otherwise (slower, or failed again) the step reverses and halves, sᵢ ← −sᵢ/2, and the
//!   search moves to the next weight.
//!
//! The weights are visited in a fresh random order each sweep; a step that has shrunk below
//! σ₀/16 starts the next sweep at ±σ₀ again. Only the lap's reward and where it failed are
//! used: what a car's lap timer gives.

use rand::seq::SliceRandom;
use serde::{Deserialize, Serialize};

use super::{Best, Optimizer, SearchBox, check_tell, rng_for};
use crate::error::{Error, Result};

/// Settings of a pattern search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatternSearchConfig {
    /// Seed of every random choice (the sweeps' orders).
    pub seed: u64,
    /// The first step σ₀ of every weight.
    pub sigma0: f64,
    /// Half-width of the search box around the start.
    pub box_radius: f64,
    /// Repair failed laps where they failed.
    pub repair: bool,
}

impl Default for PatternSearchConfig {
    fn default() -> Self {
        PatternSearchConfig {
            seed: 0,
            sigma0: 0.03,
            box_radius: super::DEFAULT_BOX_RADIUS,
            repair: true,
        }
    }
}

/// What the pending trial is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Trial {
    /// The start point.
    Start,
    /// w* + sᵢeᵢ.
    Step {
        /// The moved weight i.
        weight: usize,
    },
    /// w* + sᵢeᵢ − sᵢeⱼ.
    Repair {
        /// The moved weight i.
        weight: usize,
        /// The weight j before the failure.
        before: usize,
    },
}

/// Everything needed to resume a search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatternSearchState {
    /// Settings.
    pub config: PatternSearchConfig,
    /// The start point.
    pub start: Vec<f64>,
    /// The signed step of every weight.
    pub steps: Vec<f64>,
    /// This sweep's order of the weights.
    pub order: Vec<usize>,
    /// Position in `order`.
    pub cursor: usize,
    /// Sweeps begun.
    pub sweeps: u64,
    /// The next trial.
    pub next: Trial,
    /// Rewards told.
    pub evaluations: usize,
    /// The best (weights, reward) told.
    pub(crate) best: Best,
}

/// Pattern search with failure repair.
#[derive(Debug, Clone)]
pub struct PatternSearch {
    state: PatternSearchState,
    bounds: SearchBox,
}

impl PatternSearch {
    /// A search from `start` (driven first, unmoved).
    pub fn new(start: Vec<f64>, config: PatternSearchConfig) -> Result<PatternSearch> {
        if start.is_empty() || start.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid_value(
                "pattern search's start point",
                format!("{start:?}"),
                "finite, of at least one weight",
            ));
        }
        if !(config.sigma0.is_finite() && config.sigma0 > 0.0) {
            return Err(Error::invalid_value("σ₀", config.sigma0, "positive"));
        }
        let n = start.len();
        PatternSearch::resume(PatternSearchState {
            steps: vec![config.sigma0; n],
            order: Vec::new(),
            cursor: 0,
            sweeps: 0,
            next: Trial::Start,
            evaluations: 0,
            best: Best::default(),
            config,
            start,
        })
    }

    /// Rebuilds a search from its state.
    pub fn resume(state: PatternSearchState) -> Result<PatternSearch> {
        let n = state.start.len();
        if state.steps.len() != n || state.order.iter().any(|&i| i >= n) {
            return Err(Error::CorruptState {
                method: "pattern search",
                reason: format!(
                    "{n} weights but {} steps and order {:?}",
                    state.steps.len(),
                    state.order
                ),
            });
        }
        Ok(PatternSearch {
            bounds: SearchBox::around(&state.start, state.config.box_radius)?,
            state,
        })
    }

    /// The weight the search is on, beginning a new sweep when the last one is done.
    fn current_weight(&mut self) -> usize {
        let s = &mut self.state;
        if s.cursor >= s.order.len() {
            s.order = (0..s.start.len()).collect();
            s.order.shuffle(&mut rng_for(s.config.seed, s.sweeps));
            s.sweeps += 1;
            s.cursor = 0;
            let floor = s.config.sigma0 / 16.0;
            for step in &mut s.steps {
                if step.abs() < floor {
                    *step = s.config.sigma0.copysign(*step);
                }
            }
        }
        s.order[s.cursor]
    }

    /// The kernel just before a failure at lap fraction `at`, if it lies past `weight`.
    fn before_failure(&self, weight: usize, at: f64) -> Option<usize> {
        let last = self.state.start.len() - 1;
        let at_kernel = (at.clamp(0.0, 1.0) * last as f64).floor() as usize;
        let j = at_kernel.checked_sub(1)?;
        (j > weight).then_some(j)
    }

    /// The step on `weight` failed: reverse and halve it, move to the next weight.
    fn give_up(&mut self, weight: usize) {
        self.state.steps[weight] *= -0.5;
        self.state.cursor += 1;
        self.state.next = Trial::Step {
            weight: self.current_weight(),
        };
    }
}

impl Optimizer for PatternSearch {
    fn name(&self) -> &'static str {
        "pattern-search"
    }

    fn dim(&self) -> usize {
        self.state.start.len()
    }

    fn ask(&mut self) -> Result<Vec<f64>> {
        let s = &self.state;
        let centre = s.best.get().map_or(&s.start[..], |b| b.0);
        let mut w = centre.to_vec();
        match s.next {
            Trial::Start => return Ok(s.start.clone()),
            Trial::Step { weight } => w[weight] += s.steps[weight],
            Trial::Repair { weight, before } => {
                w[weight] += s.steps[weight];
                w[before] -= s.steps[weight];
            }
        }
        self.bounds.clamp(&mut w);
        Ok(w)
    }

    fn tell(&mut self, weights: &[f64], reward: f64) -> Result<()> {
        self.tell_lap(weights, reward, None)
    }

    /// Its tell reads the reward as the outcome of its last step.
    fn tells_any_weights(&self) -> bool {
        false
    }

    fn tell_lap(&mut self, weights: &[f64], reward: f64, failed_at: Option<f64>) -> Result<()> {
        check_tell(self.dim(), weights, reward)?;
        if let Some(at) = failed_at.filter(|x| !(x.is_finite() && (0.0..=1.0).contains(x))) {
            return Err(Error::invalid_value(
                "the failure place",
                at,
                "a lap fraction in [0, 1]",
            ));
        }
        self.state.evaluations += 1;
        let better = self.state.best.offer(weights, reward);
        match self.state.next {
            Trial::Start => {
                let weight = self.current_weight();
                self.state.next = Trial::Step { weight };
            }
            Trial::Step { weight } | Trial::Repair { weight, .. } if better => {
                self.state.steps[weight] *= 2.0;
                self.state.next = Trial::Step { weight };
            }
            Trial::Step { weight } => {
                let repair = failed_at
                    .filter(|_| self.state.config.repair)
                    .and_then(|at| self.before_failure(weight, at));
                match repair {
                    Some(before) => self.state.next = Trial::Repair { weight, before },
                    None => self.give_up(weight),
                }
            }
            Trial::Repair { weight, .. } => self.give_up(weight),
        }
        Ok(())
    }

    fn best(&self) -> Option<(&[f64], f64)> {
        self.state.best.get()
    }

    fn evaluations(&self) -> usize {
        self.state.evaluations
    }

    fn save(&self) -> super::Saved {
        super::Saved::PatternSearch(Box::new(self.state.clone()))
    }
}
