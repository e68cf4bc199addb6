//! TuRBO-1, trust-region Bayesian optimisation (Eriksson et al. 2019), in the search box
//! mapped to the unit cube u = (w − w₀ + r)/(2r).
//!
//! - A trust region of base side L (initially L_init, TuRBO's 0.8, the method's main knob) is centred on the best point of the current
//!   restart; its side along axis i is L·λᵢ/(∏λⱼ)^(1/D), with λ the GP's ARD length-scales,
//!   clipped to the cube.
//! - Each lap is the maximiser of one Thompson sample ([`crate::acquisition::thompson`]) of a
//!   Matérn-5/2 ARD GP over `candidates` points that copy the centre and redraw each
//!   coordinate uniformly in the region with probability min(20/D, 1) (at least one).
//! - A lap beating the restart's best by 1e-3·|best| is a success. After 3 successes in a row
//!   L doubles (at most 2·L_init); after max(4, D) failures in a row it halves; below
//!   L_init·0.5⁷/0.8 the run restarts: a fresh GP and initial design. (TuRBO's bounds 1.6 and
//!   0.5⁷ at its L_init 0.8, kept relative to L_init so that a smaller region halves and
//!   doubles as often before a restart.)
//! - The initial design of each restart is w₀ (the paper informs every method with it) and
//!   a Latin hypercube in the initial region around it, `initial_samples` points in all.
//!
//! Deviations, for a lap budget of a few hundred: the GP's hyperparameters are re-fitted every
//! `refit_every` laps (TuRBO: every batch), and at most `candidates` = min(100·D, 1000) points
//! are sampled (TuRBO: min(100·D, 5000)), since the joint draw costs O(candidates³).

use rand::Rng;
use rand::seq::SliceRandom;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

use super::ask_tell::{AskTell, Lap, Proposal, Proposer, SavedAs, Told};
use super::{SearchBox, rng_for};
use crate::acquisition::thompson;
use crate::error::{Error, Result};
use crate::gp::likelihood::{Bounds, fit};
use crate::gp::{GaussianProcess, Hyper, Kernel, Mean};

/// The method's name, and the kind of its saved state.
pub const NAME: &str = "turbo";

/// TuRBO's initial base side of the trust region (the default L_init).
pub const LENGTH_INIT: f64 = 0.8;
/// TuRBO's largest base side, at L_init 0.8; the largest L_init taken.
pub const LENGTH_MAX: f64 = 1.6;
/// Below this base side TuRBO restarts, at L_init 0.8.
pub const LENGTH_MIN: f64 = 0.0078125;
/// Successes in a row that double the side.
pub const SUCCESS_TOLERANCE: usize = 3;

/// Settings of a TuRBO-1 run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TurboConfig {
    /// Seed of every random choice.
    pub seed: u64,
    /// Half-width r of the search box around w₀.
    pub box_radius: f64,
    /// Initial base side L_init of the trust region, a fraction of the box's side 2r (the
    /// unit cube's); TuRBO's 0.8.
    #[serde(default = "default_length_init")]
    pub length_init: f64,
    /// Points of each restart's initial design, w₀ (first restart) included.
    pub initial_samples: usize,
    /// Candidates per Thompson sample (0: min(100·D, 1000)).
    pub candidates: usize,
    /// Re-fit the hyperparameters every this many laps.
    pub refit_every: usize,
    /// Adam iterations per fit.
    pub fit_iterations: usize,
}

fn default_length_init() -> f64 {
    LENGTH_INIT
}

impl Default for TurboConfig {
    fn default() -> Self {
        TurboConfig {
            seed: 0,
            box_radius: super::DEFAULT_BOX_RADIUS,
            length_init: LENGTH_INIT,
            initial_samples: 10,
            candidates: 0,
            refit_every: 5,
            fit_iterations: 30,
        }
    }
}

/// Everything needed to resume a run: the rest follows from replaying the told laps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TurboState {
    /// Settings.
    pub config: TurboConfig,
    /// The demonstration's weights.
    pub w0: Vec<f64>,
    /// Told (weights, reward), in order.
    pub observations: Vec<(Vec<f64>, f64)>,
}

/// The trust region's counters.
#[derive(Debug, Clone, PartialEq)]
struct Region {
    length: f64,
    successes: usize,
    failures: usize,
    /// Index of the restart (0 for the first).
    restart: u64,
    /// Points told since the restart began.
    told: usize,
    /// The best reward and its point (unit cube) since the restart began.
    best: Option<(Vec<f64>, f64)>,
}

impl Region {
    fn fresh(restart: u64, length_init: f64) -> Region {
        Region {
            length: length_init,
            successes: 0,
            failures: 0,
            restart,
            told: 0,
            best: None,
        }
    }
}

/// TuRBO's proposer: w₀, then each restart's Latin-hypercube design, then
/// the maximiser of a Thompson sample in the trust region; each told lap is added to the GP
/// and resizes or restarts the region (module doc).
#[derive(Debug, Clone)]
pub struct TurboProposer {
    state: TurboState,
    bounds: SearchBox,
    gp: GaussianProcess,
    region: Region,
}

fn initial_hyper(dim: usize) -> Hyper {
    Hyper {
        kernel: Kernel::Matern52,
        lengthscales: vec![0.5; dim],
        signal_var: 1.0,
        noise_var: 0.0,
        mean: Mean::Constant,
    }
}

/// A TuRBO-1 run.
pub type Turbo = AskTell<TurboProposer>;

impl Turbo {
    /// A new run from the demonstration's weights.
    pub fn new(w0: Vec<f64>, config: TurboConfig) -> Result<Turbo> {
        Turbo::resume(TurboState {
            config,
            w0,
            observations: Vec::new(),
        })
    }

    /// Rebuilds a run by replaying its told laps.
    pub fn resume(saved: TurboState) -> Result<Turbo> {
        let dim = saved.w0.len();
        if dim == 0 || saved.w0.iter().any(|w| !w.is_finite()) {
            return Err(Error::invalid_value(
                "TuRBO's start point",
                format!("{:?}", saved.w0),
                "finite, of at least one weight",
            ));
        }
        if saved.config.initial_samples == 0 {
            return Err(Error::too_small("TuRBO's initial design points", 0, 1));
        }
        let length_init = saved.config.length_init;
        if !(length_init > 0.0 && length_init <= LENGTH_MAX) {
            return Err(Error::invalid_value(
                "TuRBO's initial trust-region side L_init",
                length_init,
                format!("in (0, {LENGTH_MAX}]"),
            ));
        }
        let run = TurboProposer {
            bounds: SearchBox::around(&saved.w0, saved.config.box_radius)?,
            gp: GaussianProcess::new(dim, initial_hyper(dim))?,
            region: Region::fresh(0, length_init),
            state: TurboState {
                observations: Vec::new(),
                ..saved.clone()
            },
        };
        AskTell::replayed(run, &saved.observations)
    }
}

impl TurboProposer {
    /// The state to save.
    pub fn state(&self) -> &TurboState {
        &self.state
    }

    /// The trust region's current base side L.
    pub fn length(&self) -> f64 {
        self.region.length
    }

    fn unit_point(&self, w: &[f64]) -> Vec<f64> {
        let width = 2.0 * self.state.config.box_radius;
        w.iter()
            .zip(&self.bounds.lower)
            .map(|(w, lo)| ((w - lo) / width).clamp(0.0, 1.0))
            .collect()
    }

    fn weights_at(&self, u: &[f64]) -> Vec<f64> {
        let width = 2.0 * self.state.config.box_radius;
        u.iter()
            .zip(&self.bounds.lower)
            .map(|(u, lo)| lo + u * width)
            .collect()
    }

    /// The region's per-axis half-sides around `centre`, clipped to the cube: (lower, upper).
    fn region_box(&self, centre: &[f64], length: f64) -> (Vec<f64>, Vec<f64>) {
        let ls = &self.gp.hyper().lengthscales;
        let dim = centre.len();
        let log_mean = ls.iter().map(|l| l.ln()).sum::<f64>() / ls.len() as f64;
        (0..dim)
            .map(|i| {
                let l = if ls.len() == dim { ls[i] } else { ls[0] };
                let half = 0.5 * length * (l.ln() - log_mean).exp();
                ((centre[i] - half).max(0.0), (centre[i] + half).min(1.0))
            })
            .unzip()
    }

    /// Point k of the restart's Latin-hypercube design in the initial region around w₀.
    fn design_point(&self, k: usize) -> Vec<f64> {
        let dim = self.dim();
        let n = self.state.config.initial_samples;
        let mut rng = rng_for(self.state.config.seed, (1 << 40) + self.region.restart);
        let centre = self.unit_point(&self.state.w0);
        let side = self.state.config.length_init;
        let (lo, hi) = (
            centre.iter().map(|c| (c - 0.5 * side).max(0.0)),
            centre.iter().map(|c| (c + 0.5 * side).min(1.0)),
        );
        let mut u = Vec::with_capacity(dim);
        for (lo, hi) in lo.zip(hi) {
            let mut strata: Vec<usize> = (0..n).collect();
            strata.shuffle(&mut rng);
            let jitter: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
            u.push(lo + (hi - lo) * (strata[k] as f64 + jitter[k]) / n as f64);
        }
        self.weights_at(&u)
    }

    /// The maximiser of a Thompson sample over candidates in the trust region.
    fn thompson_point(&self) -> Result<Vec<f64>> {
        let dim = self.dim();
        let (centre, _) = self.region.best.clone().unwrap_or_else(|| {
            let w0 = self.unit_point(&self.state.w0);
            (w0, 0.0)
        });
        let (lo, hi) = self.region_box(&centre, self.region.length);
        let count = match self.state.config.candidates {
            0 => (100 * dim).min(1000),
            c => c,
        };
        let p = (20.0 / dim as f64).min(1.0);
        let mut rng = rng_for(self.state.config.seed, self.state.observations.len() as u64);
        let mut candidates = Vec::with_capacity(count * dim);
        for _ in 0..count {
            let forced = rng.random_range(0..dim);
            for i in 0..dim {
                let perturb = rng.random::<f64>() < p || i == forced;
                let t = rng.random::<f64>();
                candidates.push(if perturb {
                    lo[i] + (hi[i] - lo[i]) * t
                } else {
                    centre[i]
                });
            }
        }
        let (means, cov) = self.gp.predict_joint(&candidates);
        let sample = thompson::draw(&means, &cov, self.gp.hyper().signal_var, &mut rng)?;
        let k = crate::acquisition::argmax(&sample);
        Ok(self.weights_at(&candidates[k * dim..(k + 1) * dim]))
    }

    /// Counts a lap of the current restart against its best, resizes or restarts the region.
    fn update_region(&mut self, u: Vec<f64>, reward: f64) -> Result<()> {
        let (dim, initial) = (self.dim(), self.state.config.initial_samples);
        let length_init = self.state.config.length_init;
        let scale = length_init / LENGTH_INIT;
        let region = &mut self.region;
        region.told += 1;
        let previous = region.best.as_ref().map(|b| b.1);
        if previous.is_none_or(|b| reward > b) {
            region.best = Some((u, reward));
        }
        if region.told <= initial {
            return Ok(());
        }
        let previous = previous.unwrap_or(f64::NEG_INFINITY);
        if reward > previous + 1e-3 * previous.abs() {
            region.successes += 1;
            region.failures = 0;
        } else {
            region.successes = 0;
            region.failures += 1;
        }
        if region.successes == SUCCESS_TOLERANCE {
            region.length = (2.0 * region.length).min(LENGTH_MAX * scale);
            region.successes = 0;
        }
        if region.failures >= dim.max(4) {
            region.length *= 0.5;
            region.failures = 0;
        }
        if region.length < LENGTH_MIN * scale {
            self.region = Region::fresh(region.restart + 1, length_init);
            self.gp = GaussianProcess::new(dim, initial_hyper(dim))?;
        }
        Ok(())
    }

    /// Refits the hyperparameters when due; the signal variance is bounded relative to the
    /// rewards' variance (TuRBO standardises the rewards instead).
    fn maybe_refit(&mut self) -> Result<()> {
        let n = self.gp.len();
        let every = self.state.config.refit_every.max(1);
        if n < 2 || n % every != 0 {
            return Ok(());
        }
        let ys = self.gp.values();
        let mean = ys.iter().sum::<f64>() / n as f64;
        let var = (ys.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / n as f64).max(1e-6);
        let bounds = Bounds {
            lengthscale: (0.005, 2.0),
            signal_var: (0.05 * var, 20.0 * var),
            noise_var: None,
        };
        fit(&mut self.gp, &bounds, self.state.config.fit_iterations)?;
        Ok(())
    }
}

impl Proposer for TurboProposer {
    type Note = ();
    type State = TurboState;
    const SAVED_AS: SavedAs = SavedAs::Laps(NAME);

    fn propose(&mut self, _: &Told) -> Result<Proposal<()>> {
        let w = if self.state.observations.is_empty() {
            self.state.w0.clone()
        } else if self.region.told < self.state.config.initial_samples {
            self.design_point(self.region.told)
        } else {
            self.thompson_point()?
        };
        Ok(Proposal::plain(w))
    }

    fn observe(&mut self, lap: &Lap<'_>, _: Option<&Proposal<()>>, _: &Told) -> Result<()> {
        let u = self.unit_point(lap.weights);
        self.gp.add(&u, lap.reward)?;
        self.state
            .observations
            .push((lap.weights.to_vec(), lap.reward));
        self.update_region(u, lap.reward)?;
        self.maybe_refit()
    }

    fn dim(&self) -> usize {
        self.state.w0.len()
    }

    fn state(&self) -> Cow<'_, TurboState> {
        Cow::Borrowed(&self.state)
    }
}
