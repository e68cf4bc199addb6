//! Bayesian optimisation of lap rewards (paper Alg. 2): Coordinate Descent Bayesian
//! Optimisation when the acquisition is maximised by coordinate ascent, standard BO-CMA-ES
//! when it is maximised by CMA-ES.
//!
//! 1. Drive w₀, then S laps with w ~ N(w₀, σ₀²I) clamped to the search box; while every lap
//!    has scored the same (every one failed, say), go on drawing them.
//! 2. Then, each lap: fit the GP's hyperparameters by maximum likelihood when due, choose
//!    w = argmax h from the best weights so far, by stochastic coordinate ascent
//!    ([`super::coordinate_ascent`], paper Alg. 1) or by CMA-ES ([`super::cmaes_ascent`]),
//!    drive it, add (w, R) to the GP.
//!
//! The length-scales' upper bound adapts as in REMBO (Wang et al. 2016), applied by the paper
//! to every BO method: when the chosen point's posterior standard deviation falls below
//! [`LOW_UNCERTAINTY`]·σ_f, the upper bound is halved (never below twice the lower bound), so
//! that the next fit must explain the data with shorter length-scales and the acquisition
//! finds uncertainty again.
//!
//! Hyperparameter fits are due at the first BO step and then every `refit_every` laps. The
//! first is fitted at once; each later one starts from the data at its lap on a thread of its
//! own (`FitInFlight`) and is installed when the next is due, `refit_every` laps later, so
//! that the laps between hide its O(n³) cost. The schedule depends on the lap count alone:
//! the result is the same whether the thread finished early or is waited for.
//!
//! A coordinate ascent that ends on an observation (posterior variance at most
//! [`REPEAT_VARIANCE`]·σ_f² plus twice the jitter) is run again with the observations scoring
//! −∞: with noise 0 a repeated lap teaches nothing, and every later ascent would end there.

use std::borrow::Cow;

use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use super::ask_tell::{AskTell, Lap, Proposal, Proposer, SavedAs, Told};
use super::cmaes_ascent::CmaesSearch;
use super::coordinate_ascent::{Ascent, AxisSearch, GpAcquisition};
use super::{SearchBox, rng_for};
use crate::acquisition::Acquisition;
use crate::acquisition::ucb::DEFAULT_BETA;
use crate::error::{Error, Result};
use crate::gp::fit_in_flight::FitInFlight;
use crate::gp::likelihood::{Bounds, fit};
use crate::gp::{GaussianProcess, Hyper, Kernel, Mean};

/// The paper's CDBO: the acquisition maximised by randomised coordinate ascent.
pub const CDBO: &str = "cdbo";
/// BO-CMA-ES: the acquisition maximised by CMA-ES.
pub const BO_CMAES: &str = "bo-cmaes";
/// The kind of the saved state of either.
const SAVED_KIND: &str = "bo";

/// Hyperparameter fits are fitted at once below this many observations, where they are
/// cheap, and on their own thread from it on.
pub const BACKGROUND_FITS_FROM: usize = 100;

/// σ(w_next) below this fraction of σ_f shrinks the length-scale upper bound.
pub const LOW_UNCERTAINTY: f64 = 0.05;

/// A posterior variance at most this fraction of σ_f² (plus twice the jitter) marks a point
/// already observed.
pub const REPEAT_VARIANCE: f64 = 1e-8;

/// How the acquisition is maximised.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum Maximiser {
    /// Stochastic coordinate ascent (CDBO, paper Alg. 1).
    CoordinateAscent(AxisSearch),
    /// Active CMA-ES in all coordinates at once (BO-CMA-ES).
    Cmaes(CmaesSearch),
}

/// Settings of a BO run; the default is the paper's CDBO.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BoConfig {
    /// Seed of every random choice.
    pub seed: u64,
    /// Acquisition (UCB with β = 1 by default).
    pub acquisition: Acquisition,
    /// Initial random laps S (the paper: 10).
    pub initial_samples: usize,
    /// Standard deviation σ₀ of the initial samples around w₀. The paper gives no value; 0.03
    /// keeps most initial laps alive on Forza (with 0.1 all ten stall: the demonstration's
    /// policy cruises at a ≈ 0.01, so larger perturbations brake the car to a stop).
    pub initial_sigma: f64,
    /// Half-width of the search box around w₀.
    pub box_radius: f64,
    /// Kernel of the reward GP (the paper: exponential, ARD).
    pub kernel: Kernel,
    /// One length-scale per weight (ARD) or one for all.
    pub ard: bool,
    /// Prior mean. The paper's GP has a zero mean; the default here is the average reward
    /// (as limbo's `mean::Data`): with rewards far above 0, a zero prior mean makes every
    /// step away from the data look like a crash, and the search creeps (measured in
    /// docs/results/design.md).
    pub mean: Mean,
    /// Observation noise variance (the paper: 0).
    pub noise_var: f64,
    /// Re-fit the hyperparameters every this many observations (0: never after the first).
    pub refit_every: usize,
    /// Adam iterations per fit.
    pub fit_iterations: usize,
    /// How the acquisition is maximised.
    pub maximiser: Maximiser,
}

impl Default for BoConfig {
    fn default() -> Self {
        BoConfig {
            seed: 0,
            acquisition: Acquisition::Ucb { beta: DEFAULT_BETA },
            initial_samples: 10,
            initial_sigma: 0.03,
            box_radius: super::DEFAULT_BOX_RADIUS,
            kernel: Kernel::Exponential,
            ard: true,
            mean: Mean::Constant,
            noise_var: 0.0,
            refit_every: 5,
            fit_iterations: 30,
            maximiser: Maximiser::CoordinateAscent(AxisSearch::default()),
        }
    }
}

/// Everything needed to resume a run: settings, w₀ and what was told.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BoState {
    /// Settings.
    pub config: BoConfig,
    /// The demonstration's weights.
    pub w0: Vec<f64>,
    /// Told (weights, reward), in order.
    pub observations: Vec<(Vec<f64>, f64)>,
    /// Current hyperparameters.
    pub hyper: Hyper,
    /// Current upper bound of the length-scales.
    pub lengthscale_max: f64,
    /// The length-scale upper bound in force when each told point was suggested, so that a
    /// resumed run replays the same hyperparameter fits bit for bit.
    pub bounds_used: Vec<f64>,
}

/// BO's proposer: w₀, then the initial design, then w = argmax h from the best weights so far,
/// each noted with the length-scale bound it was chosen under; each told lap is added to the
/// GP (module doc).
#[derive(Debug, Clone)]
pub struct BoProposer {
    state: BoState,
    bounds: SearchBox,
    gp: GaussianProcess,
    last_fit_at: usize,
    /// The fit started at `last_fit_at`, installed when the next is due.
    fit_in_flight: Option<FitInFlight>,
    /// Acquisition evaluations of the last suggestion.
    pub last_af_evaluations: usize,
    /// Seconds this run's thread spent fitting hyperparameters or waiting for a fit, in total.
    pub fit_seconds: f64,
}

/// The hyperparameters a run starts from: length-scales half the box width, σ_f² = 1.
fn initial_hyper(config: &BoConfig, dim: usize) -> Hyper {
    Hyper {
        kernel: config.kernel,
        lengthscales: vec![config.box_radius; if config.ard { dim } else { 1 }],
        signal_var: 1.0,
        noise_var: config.noise_var,
        mean: config.mean,
    }
}

/// Smallest length-scale searched, relative to the box width.
const LENGTHSCALE_MIN_FRACTION: f64 = 0.01;
/// Largest length-scale searched at the start, relative to the box width.
const LENGTHSCALE_MAX_FRACTION: f64 = 10.0;

/// A BO run (CDBO or BO-CMA-ES).
pub type Bo = AskTell<BoProposer>;

impl Bo {
    /// A new run from the demonstration's weights.
    pub fn new(w0: Vec<f64>, config: BoConfig) -> Result<Bo> {
        if w0.is_empty() {
            return Err(Error::too_small("Bayesian optimisation's weights", 0, 1));
        }
        if let Some(i) = w0.iter().position(|w| !w.is_finite()) {
            return Err(Error::invalid_value(
                format!("initial weight {i}"),
                w0[i],
                "finite",
            ));
        }
        if !(config.initial_sigma.is_finite() && config.initial_sigma >= 0.0) {
            return Err(Error::invalid_value(
                "σ₀",
                config.initial_sigma,
                "non-negative",
            ));
        }
        let hyper = initial_hyper(&config, w0.len());
        let lengthscale_max = LENGTHSCALE_MAX_FRACTION * 2.0 * config.box_radius;
        let state = BoState {
            w0,
            observations: Vec::new(),
            hyper,
            lengthscale_max,
            bounds_used: Vec::new(),
            config,
        };
        Bo::resume(state)
    }

    /// Rebuilds a run from its state by replaying its observations and hyperparameter fits,
    /// so that it continues exactly as the uninterrupted run would.
    pub fn resume(saved: BoState) -> Result<Bo> {
        let proposer = BoProposer::resume(saved)?;
        let told = Told::of(proposer.state.observations.iter().map(|(w, r)| (w, *r)));
        Ok(AskTell::resumed(proposer, told))
    }

    /// Fits the GP's hyperparameters by maximum likelihood within the current bounds now.
    pub fn fit_hyperparameters(&mut self) -> Result<()> {
        self.proposer_mut().fit_hyperparameters()
    }
}

impl BoProposer {
    fn resume(saved: BoState) -> Result<BoProposer> {
        if saved.bounds_used.len() != saved.observations.len() {
            return Err(Error::CorruptState {
                method: "BO",
                reason: format!(
                    "{} observations but {} recorded bounds",
                    saved.observations.len(),
                    saved.bounds_used.len()
                ),
            });
        }
        let dim = saved.w0.len();
        let mut state = BoState {
            observations: Vec::new(),
            bounds_used: Vec::new(),
            hyper: initial_hyper(&saved.config, dim),
            ..saved.clone()
        };
        state.lengthscale_max = LENGTHSCALE_MAX_FRACTION * 2.0 * saved.config.box_radius;
        let bounds = SearchBox::around(&state.w0, state.config.box_radius)?;
        let gp = GaussianProcess::new(dim, state.hyper.clone())?;
        let mut run = BoProposer {
            state,
            bounds,
            gp,
            last_fit_at: 0,
            fit_in_flight: None,
            last_af_evaluations: 0,
            fit_seconds: 0.0,
        };
        for ((w, r), bound) in saved.observations.iter().zip(&saved.bounds_used) {
            run.state.lengthscale_max = *bound;
            if run.gp.len() > run.state.config.initial_samples {
                run.prepare_gp()?;
            }
            run.add(w, *r, *bound)?;
        }
        run.state.lengthscale_max = saved.lengthscale_max;
        Ok(run)
    }

    /// The state to save.
    pub fn state(&self) -> &BoState {
        &self.state
    }

    /// The search box.
    pub fn search_box(&self) -> &SearchBox {
        &self.bounds
    }

    /// The reward GP.
    pub fn gp(&self) -> &GaussianProcess {
        &self.gp
    }

    fn hyper_bounds(&self) -> Bounds {
        let width = 2.0 * self.state.config.box_radius;
        let ys = self.gp.values();
        let n = ys.len().max(1) as f64;
        let mean_sq = ys.iter().map(|y| y * y).sum::<f64>() / n;
        let scale = mean_sq.max(1e-6);
        Bounds {
            lengthscale: (LENGTHSCALE_MIN_FRACTION * width, self.state.lengthscale_max),
            signal_var: (1e-3 * scale, 1e2 * scale),
            noise_var: None,
        }
    }

    /// Readies the GP for a suggestion. When a fit is due (the first BO step, then every
    /// `refit_every`): fits at once the first time; later, installs the fit started when the
    /// last was due and starts the next. Length-scales above the current upper bound (halved
    /// since, or fitted under an older bound) are brought down to it at once.
    fn prepare_gp(&mut self) -> Result<()> {
        let n = self.gp.len();
        let every = self.state.config.refit_every;
        let first = n == self.state.config.initial_samples + 1;
        let due = n >= 2 && (first || (every > 0 && n >= self.last_fit_at + every));
        if due && (first || n < BACKGROUND_FITS_FROM) {
            return self.fit_hyperparameters();
        }
        let start = std::time::Instant::now();
        if let Some(fit) = self.fit_in_flight.take_if(|_| due) {
            self.gp.set_hyper(fit.finish()?)?;
        }
        let max = self.state.lengthscale_max;
        if self.gp.hyper().lengthscales.iter().any(|l| *l > max) {
            let mut hyper = self.gp.hyper().clone();
            hyper.lengthscales.iter_mut().for_each(|l| *l = l.min(max));
            self.gp.set_hyper(hyper)?;
        }
        self.state.hyper = self.gp.hyper().clone();
        if due {
            let iterations = self.state.config.fit_iterations;
            self.fit_in_flight = Some(FitInFlight::start(
                &self.gp,
                self.hyper_bounds(),
                iterations,
            ));
            self.last_fit_at = n;
        }
        self.fit_seconds += start.elapsed().as_secs_f64();
        Ok(())
    }

    /// Fits the GP's hyperparameters by maximum likelihood within the current bounds now.
    fn fit_hyperparameters(&mut self) -> Result<()> {
        let start = std::time::Instant::now();
        let bounds = self.hyper_bounds();
        fit(&mut self.gp, &bounds, self.state.config.fit_iterations)?;
        self.state.hyper = self.gp.hyper().clone();
        self.last_fit_at = self.gp.len();
        self.fit_seconds += start.elapsed().as_secs_f64();
        Ok(())
    }

    /// The best, by the acquisition, of `start` and `count` uniform points of the box.
    fn best_random_start(
        &self,
        start: Vec<f64>,
        count: usize,
        rng: &mut impl rand::Rng,
    ) -> Vec<f64> {
        if count == 0 {
            return start;
        }
        let mut points = start.clone();
        for _ in 0..count {
            points.extend(
                self.bounds
                    .lower
                    .iter()
                    .zip(&self.bounds.upper)
                    .map(|(lo, hi)| lo + (hi - lo) * rng.random::<f64>()),
            );
        }
        let acquisition = self.state.config.acquisition;
        let incumbent = self.gp.best_value();
        let scores: Vec<f64> = self
            .gp
            .predict_batch(&points)
            .into_iter()
            .map(|(m, v)| acquisition.value(m, v, incumbent))
            .collect();
        let d = start.len();
        let i = crate::acquisition::argmax(&scores);
        points[i * d..(i + 1) * d].to_vec()
    }

    /// Adds a told lap to the GP, with the length-scale bound in force when it was chosen.
    fn add(&mut self, weights: &[f64], reward: f64, bound: f64) -> Result<()> {
        self.gp.add(weights, reward)?;
        self.state.observations.push((weights.to_vec(), reward));
        self.state.bounds_used.push(bound);
        self.state.hyper = self.gp.hyper().clone();
        Ok(())
    }

    fn choose(&mut self, told: &Told) -> Result<Vec<f64>> {
        let n = self.state.observations.len();
        let mut rng = rng_for(self.state.config.seed, n as u64);
        if n == 0 {
            return Ok(self.state.w0.clone());
        }
        let initial = self.state.config.initial_samples;
        let flat = self.gp.values().iter().all(|y| *y == self.gp.values()[0]);
        if n <= initial || flat {
            // While every lap has scored the same (all failed, say), the GP carries no
            // direction: the initial design goes on.
            let sigma = self.state.config.initial_sigma;
            let normal = Normal::new(0.0, sigma)
                .map_err(|_| Error::invalid_value("σ₀", sigma, "non-negative"))?;
            let mut w: Vec<f64> = self
                .state
                .w0
                .iter()
                .map(|w| w + normal.sample(&mut rng))
                .collect();
            self.bounds.clamp(&mut w);
            return Ok(w);
        }
        self.prepare_gp()?;
        let start = told.best_or(&self.state.w0).to_vec();
        let acquisition = self.state.config.acquisition;
        let ascent = match &self.state.config.maximiser {
            Maximiser::CoordinateAscent(search) => {
                let start = self.best_random_start(start, search.random_starts, &mut rng);
                let objective = GpAcquisition::new(&self.gp, acquisition, &start);
                let mut ascend = |mut objective: GpAcquisition<'_>| {
                    super::coordinate_ascent::maximise(
                        &mut objective,
                        &self.bounds,
                        &start,
                        search,
                        &mut rng,
                    )
                };
                let ascent = ascend(objective);
                // An ascent that ends on an observation would re-drive a known lap and teach
                // the GP nothing (noise 0: every later ascent would end there too); it is run
                // again with the observations excluded.
                let floor = REPEAT_VARIANCE * self.gp.hyper().signal_var + 2.0 * self.gp.jitter();
                if ascent.var <= floor {
                    let objective = GpAcquisition::new(&self.gp, acquisition, &start);
                    let again = ascend(objective.excluding_observed(floor));
                    Ascent {
                        evaluations: ascent.evaluations + again.evaluations,
                        ..again
                    }
                } else {
                    ascent
                }
            }
            Maximiser::Cmaes(search) => super::cmaes_ascent::maximise(
                &self.gp,
                acquisition,
                &self.bounds,
                &start,
                search,
                rand::Rng::random(&mut rng),
            )?,
        };
        self.last_af_evaluations = ascent.evaluations;
        // Wang & de Freitas: too little uncertainty at the chosen point shrinks the bound.
        if ascent.var.sqrt() < LOW_UNCERTAINTY * self.gp.hyper().signal_var.sqrt() {
            let floor = 2.0 * LENGTHSCALE_MIN_FRACTION * 2.0 * self.state.config.box_radius;
            self.state.lengthscale_max = (0.5 * self.state.lengthscale_max).max(floor);
        }
        Ok(ascent.point)
    }
}

impl Proposer for BoProposer {
    type Note = f64;
    type State = BoState;
    const SAVED_AS: SavedAs = SavedAs::Laps(SAVED_KIND);

    fn name(&self) -> &'static str {
        match self.state.config.maximiser {
            Maximiser::CoordinateAscent(_) => CDBO,
            Maximiser::Cmaes(_) => BO_CMAES,
        }
    }

    fn propose(&mut self, told: &Told) -> Result<Proposal<f64>> {
        let note = self.state.lengthscale_max;
        let weights = self.choose(told)?;
        Ok(Proposal { weights, note })
    }

    fn observe(&mut self, lap: &Lap<'_>, asked: Option<&Proposal<f64>>, _: &Told) -> Result<()> {
        let bound = asked.map_or(self.state.lengthscale_max, |p| p.note);
        self.add(lap.weights, lap.reward, bound)
    }

    fn dim(&self) -> usize {
        self.state.w0.len()
    }

    fn state(&self) -> Cow<'_, BoState> {
        Cow::Borrowed(&self.state)
    }
}
