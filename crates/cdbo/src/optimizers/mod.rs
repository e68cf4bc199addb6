//! Optimisers behind one ask/tell face: ask for the weights of the next lap, tell its reward.
//!
//! Every method starts from the demonstration's weights w₀ (the paper: "all methods are
//! informed with this initial solution"), counts one lap per evaluation, takes every random
//! choice from its seed, and treats a failed lap (reward 0) as an ordinary observation.

pub mod ask_tell;
pub mod bo;
pub mod cmaes;
pub mod cmaes_ascent;
pub mod coordinate_ascent;
pub mod linebo;
pub mod random;
pub mod rembo;
pub mod turbo;

pub use crate::rng::rng_for;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;

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

    /// [`tell`](Optimizer::tell) with where and how a failed lap failed (for a failed lap whose
    /// place is known): all a car's lap timer and driver give besides the time. Methods that
    /// read it override this; the others are told the reward.
    fn tell_lap(&mut self, weights: &[f64], reward: f64, failure: Option<FailedLap>) -> Result<()> {
        let _ = failure;
        self.tell(weights, reward)
    }

    /// Whether [`tell`](Optimizer::tell) takes any weights, not only those of the last ask:
    /// what a study needs to hand several workers distinct laps at once (it tells a copy of
    /// the optimiser each lap in flight with a made-up reward, then asks the copy).
    fn tells_any_weights(&self) -> bool {
        true
    }

    /// The best weights told so far and their reward.
    fn best(&self) -> Option<(&[f64], f64)>;

    /// Number of rewards told.
    fn evaluations(&self) -> usize;

    /// The whole state, to resume the run later with [`crate::method::resume`] exactly where it is.
    fn save(&self) -> Saved;
}

/// What a car's timer and driver tell of a failed lap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FailedLap {
    /// Where it failed, a lap fraction in [0, 1].
    pub at: f64,
    /// Whether the car was too slow there (it stalled or ran out of time) rather than too fast
    /// (it left the road, spun or turned round).
    pub too_slow: bool,
}

impl FailedLap {
    /// A lap that failed at `at` for being too fast, the usual failure of a faster policy.
    pub fn too_fast(at: f64) -> FailedLap {
        FailedLap {
            at,
            too_slow: false,
        }
    }
}

/// The saved state of an optimiser of any method: its kind and its state as JSON, exactly as
/// written (`{"kind": "bo", "state": {…}}`). [`crate::method::resume`] continues it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Saved {
    kind: String,
    state: Box<RawValue>,
}

impl Saved {
    /// The state of an optimiser of `kind`.
    pub fn new(kind: &str, state: &impl Serialize) -> Saved {
        Saved {
            kind: kind.to_owned(),
            state: serde_json::value::to_raw_value(state)
                .expect("an optimiser's state is plain data that serialises to JSON"),
        }
    }

    /// The kind of optimiser it is the state of (`bo`, `cmaes`, `pattern-search`, …).
    pub fn kind(&self) -> &str {
        &self.kind
    }

    /// The state, read as `T` (the state of the optimiser of [`kind`](Saved::kind)); a state
    /// that does not read is refused naming `method`.
    pub fn state<T: DeserializeOwned>(&self, method: &'static str) -> Result<T> {
        serde_json::from_str(self.state.get()).map_err(|e| Error::CorruptState {
            method,
            reason: e.to_string(),
        })
    }
}

/// Two saved states are equal when they are of the same kind and their JSON is the same.
impl PartialEq for Saved {
    fn eq(&self, other: &Saved) -> bool {
        self.kind == other.kind && self.state.get() == other.state.get()
    }
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

/// The largest half-width r of a search box. A policy's weights act through
/// clamp(wᵀφ(x), −1, 1) with 0 ≤ φ ≤ 1, so they saturate within a few units, and the test
/// functions' domains (Ackley's ±32.768) fit well inside; a larger box only dilutes the
/// search, and far larger ones (1e308) overflow its arithmetic.
pub const MAX_BOX_RADIUS: f64 = 1000.0;

impl SearchBox {
    /// [w₀ − r, w₀ + r].
    pub fn around(w0: &[f64], radius: f64) -> Result<SearchBox> {
        if !(radius.is_finite() && radius > 0.0 && radius <= MAX_BOX_RADIUS) {
            return Err(Error::invalid_value(
                "the search-box radius",
                radius,
                format!("in (0, {MAX_BOX_RADIUS}]"),
            ));
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
pub(crate) struct Best(Option<(Vec<f64>, f64)>);

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
pub(crate) fn check_tell(dim: usize, weights: &[f64], reward: f64) -> Result<()> {
    if weights.len() != dim {
        return Err(Error::dimension("weights", dim, weights.len()));
    }
    if let Some(i) = weights.iter().position(|w| !w.is_finite()) {
        return Err(Error::invalid_value(
            format!("weight {i}"),
            weights[i],
            "finite",
        ));
    }
    if !reward.is_finite() {
        return Err(Error::invalid_value(
            "the reward",
            reward,
            "finite (0 for a failed lap)",
        ));
    }
    Ok(())
}

/// [`check_tell`] with the place a failed lap failed at, a lap fraction in [0, 1] when known.
pub(crate) fn check_tell_lap(
    dim: usize,
    weights: &[f64],
    reward: f64,
    failure: Option<FailedLap>,
) -> Result<()> {
    check_tell(dim, weights, reward)?;
    match failure.map(|f| f.at) {
        Some(x) if !(x.is_finite() && (0.0..=1.0).contains(&x)) => Err(Error::invalid_value(
            "the failure place",
            x,
            "a lap fraction in [0, 1]",
        )),
        _ => Ok(()),
    }
}
