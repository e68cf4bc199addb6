//! Optimisers behind one ask/tell face: ask for the weights of the next lap, tell its reward.
//!
//! Every method starts from the demonstration's weights w₀ (the paper: "all methods are
//! informed with this initial solution"), counts one lap per evaluation, takes every random
//! choice from its seed, and treats a failed lap (reward 0) as an ordinary observation.

pub mod cdbo;
pub mod cmaes;
pub mod coordinate_ascent;
pub mod random;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// An ask/tell optimiser of lap rewards over policy weights.
pub trait Optimizer {
    /// The method's name on the command line.
    fn name(&self) -> &'static str;

    /// Number of weights.
    fn dim(&self) -> usize;

    /// The weights of the next lap to drive. Asking again before telling returns the same.
    fn ask(&mut self) -> Result<Vec<f64>>;

    /// The reward of a lap driven with `weights` (0 for a failed lap). Bad input — wrong
    /// dimension, non-finite weights or reward — is refused and changes nothing.
    fn tell(&mut self, weights: &[f64], reward: f64) -> Result<()>;

    /// The best weights told so far and their reward.
    fn best(&self) -> Option<(&[f64], f64)>;

    /// Number of rewards told.
    fn evaluations(&self) -> usize;
}

/// The methods [`by_name`] knows.
pub const METHODS: &[&str] = &["cdbo", "cmaes", "random"];

/// An optimiser by its command-line name, from w₀, a seed, the UCB β (used by the BO methods)
/// and the half-width r of the search box around w₀; the evolution strategies start with
/// σ = r/15 (0.1 for the policy box).
pub fn by_name(
    name: &str,
    w0: Vec<f64>,
    seed: u64,
    beta: f64,
    box_radius: f64,
) -> Result<Box<dyn Optimizer>> {
    Ok(match name {
        "cdbo" => {
            let config = cdbo::CdboConfig {
                seed,
                acquisition: crate::acquisition::Acquisition::Ucb { beta },
                box_radius,
                ..cdbo::CdboConfig::default()
            };
            Box::new(cdbo::Cdbo::new(w0, config)?)
        }
        "cmaes" => {
            let config = cmaes::CmaesConfig {
                seed,
                sigma0: box_radius / 15.0,
                box_radius: Some(box_radius),
                ..cmaes::CmaesConfig::default()
            };
            Box::new(cmaes::Cmaes::new(w0, config)?)
        }
        "random" => Box::new(random::RandomSearch::new(
            w0,
            random::RandomConfig {
                seed,
                sigma: box_radius / 15.0,
                box_radius,
            },
        )?),
        other => {
            return Err(Error::Domain(format!(
                "unknown method {other:?} (available: {})",
                METHODS.join(", ")
            )));
        }
    })
}

/// The box the weights are searched in: [w₀ − r, w₀ + r] in every coordinate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SearchBox {
    /// Lower corner.
    pub lower: Vec<f64>,
    /// Upper corner.
    pub upper: Vec<f64>,
}

/// The default half-width r of the search box around w₀.
pub const DEFAULT_BOX_RADIUS: f64 = 1.5;

impl SearchBox {
    /// [w₀ − r, w₀ + r].
    pub fn around(w0: &[f64], radius: f64) -> Result<SearchBox> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::Domain(format!(
                "the search-box radius must be positive, got {radius}"
            )));
        }
        Ok(SearchBox {
            lower: w0.iter().map(|w| w - radius).collect(),
            upper: w0.iter().map(|w| w + radius).collect(),
        })
    }

    /// The point clamped into the box.
    pub fn clamp(&self, w: &mut [f64]) {
        for ((v, lo), hi) in w.iter_mut().zip(&self.lower).zip(&self.upper) {
            *v = v.clamp(*lo, *hi);
        }
    }
}

/// The best (weights, reward) told so far.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Best(Option<(Vec<f64>, f64)>);

impl Best {
    /// Records (weights, reward) if it beats the best; returns whether it did.
    pub fn offer(&mut self, weights: &[f64], reward: f64) -> bool {
        let better = self.0.as_ref().is_none_or(|b| reward > b.1);
        if better {
            self.0 = Some((weights.to_vec(), reward));
        }
        better
    }

    /// The best weights and reward.
    pub fn get(&self) -> Option<(&[f64], f64)> {
        self.0.as_ref().map(|(w, r)| (w.as_slice(), *r))
    }
}

/// Checks a told (weights, reward) pair against the dimension.
pub fn check_tell(dim: usize, weights: &[f64], reward: f64) -> Result<()> {
    if weights.len() != dim {
        return Err(Error::Domain(format!(
            "expected {dim} weights, got {}",
            weights.len()
        )));
    }
    if let Some(i) = weights.iter().position(|w| !w.is_finite()) {
        return Err(Error::Domain(format!("weight {i} is {}", weights[i])));
    }
    if !reward.is_finite() {
        return Err(Error::Domain(format!(
            "the reward must be finite (0 for a failed lap), got {reward}"
        )));
    }
    Ok(())
}

/// A generator for draw number `stream` of a run seeded with `seed`: every random choice is a
/// pure function of (seed, stream), so a resumed run makes the same choices.
pub fn rng_for(seed: u64, stream: u64) -> rand_chacha::ChaCha8Rng {
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream);
    rng
}
