//! LineBO, Bayesian optimisation restricted to lines (Kirschner et al. 2019).
//!
//! One GP over all laps (Matérn-5/2 ARD, hyperparameters re-fitted every `refit_every` laps);
//! the search moves along one line at a time, ℓ(t) = w_line + t·d, through the best weights
//! when the line begins. Directions alternate between a random coordinate axis
//! (CoordinateLineBO) and a uniformly random unit vector (RandomLineBO). On a line, each lap
//! maximises UCB μ + βσ over `grid` evenly spaced t where ℓ(t) is inside the box and |t| is at
//! most the step s (one batched GP query); after `laps_per_line` laps a new line begins. The
//! first lap is w₀.
//!
//! The step s, the line's half-length, is the method's main knob: it sets how far a lap moves
//! from the best point (β only weighs the GP's uncertainty along the same segment, and where
//! every sample fails the GP is flat, so the UCB's choice is the segment's far end). Kirschner
//! et al. search the whole line in the domain: s = ∞, the default.

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

use super::ask_tell::{AskTell, Lap, Proposal, Proposer, SavedAs, Told};
use super::{SearchBox, rng_for};
use crate::acquisition::ucb::{DEFAULT_BETA, ucb};
use crate::error::{Error, Result};
use crate::gp::likelihood::{Bounds, fit};
use crate::gp::{GaussianProcess, Hyper, Kernel, Mean};

/// The method's name, and the kind of its saved state.
pub const NAME: &str = "linebo";

/// Settings of a LineBO run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LineBoConfig {
    /// Seed of every random choice.
    pub seed: u64,
    /// Half-width r of the search box around w₀.
    pub box_radius: f64,
    /// UCB exploration weight β.
    pub beta: f64,
    /// The step s, each line's half-length: a lap moves at most s from the line's origin;
    /// `None`: the whole line in the box (Kirschner et al.).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<f64>,
    /// Laps on each line.
    pub laps_per_line: usize,
    /// Values of t scored per lap.
    pub grid: usize,
    /// Re-fit the hyperparameters every this many laps.
    pub refit_every: usize,
    /// Adam iterations per fit.
    pub fit_iterations: usize,
}

impl Default for LineBoConfig {
    fn default() -> Self {
        LineBoConfig {
            seed: 0,
            box_radius: super::DEFAULT_BOX_RADIUS,
            beta: DEFAULT_BETA,
            step: None,
            laps_per_line: 4,
            grid: 200,
            refit_every: 5,
            fit_iterations: 30,
        }
    }
}

/// Everything needed to resume a run: the rest follows from replaying the told laps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LineBoState {
    /// Settings.
    pub config: LineBoConfig,
    /// The demonstration's weights.
    pub w0: Vec<f64>,
    /// Told (weights, reward), in order.
    pub observations: Vec<(Vec<f64>, f64)>,
}

/// The current line: origin, unit direction, its index and laps driven on it.
#[derive(Debug, Clone, PartialEq)]
struct Line {
    origin: Vec<f64>,
    direction: Vec<f64>,
    index: u64,
    laps: usize,
}

/// LineBO's proposer: w₀, then the UCB maximiser on the current line's grid;
/// each told lap is added to the GP, and after `laps_per_line` laps the next line begins through
/// the best weights (module doc).
#[derive(Debug, Clone)]
pub struct LineBoProposer {
    state: LineBoState,
    bounds: SearchBox,
    gp: GaussianProcess,
    line: Line,
}

/// A LineBO run.
pub type LineBo = AskTell<LineBoProposer>;

impl LineBo {
    /// A new run from the demonstration's weights.
    pub fn new(w0: Vec<f64>, config: LineBoConfig) -> Result<LineBo> {
        LineBo::resume(LineBoState {
            config,
            w0,
            observations: Vec::new(),
        })
    }

    /// Rebuilds a run by replaying its told laps.
    pub fn resume(saved: LineBoState) -> Result<LineBo> {
        let dim = saved.w0.len();
        if dim == 0 || saved.w0.iter().any(|w| !w.is_finite()) {
            return Err(Error::invalid_value(
                "LineBO's start point",
                format!("{:?}", saved.w0),
                "finite, of at least one weight",
            ));
        }
        if saved.config.laps_per_line == 0 || saved.config.grid < 2 {
            return Err(Error::invalid_value(
                "LineBO's laps per line and grid points",
                format!("{} and {}", saved.config.laps_per_line, saved.config.grid),
                "at least 1 and 2",
            ));
        }
        if let Some(step) = saved.config.step.filter(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(Error::invalid_value(
                "LineBO's step (the line's half-length)",
                step,
                "a finite positive number",
            ));
        }
        let r = saved.config.box_radius;
        let hyper = Hyper {
            kernel: Kernel::Matern52,
            lengthscales: vec![r; dim],
            signal_var: 1.0,
            noise_var: 0.0,
            mean: Mean::Constant,
        };
        let mut run = LineBoProposer {
            bounds: SearchBox::around(&saved.w0, r)?,
            gp: GaussianProcess::new(dim, hyper)?,
            line: Line {
                origin: saved.w0.clone(),
                direction: vec![0.0; dim],
                index: 0,
                laps: 0,
            },
            state: LineBoState {
                observations: Vec::new(),
                ..saved.clone()
            },
        };
        run.line = run.line_through(saved.w0.clone(), 0);
        AskTell::replayed(run, &saved.observations)
    }
}

impl LineBoProposer {
    /// The state to save.
    pub fn state(&self) -> &LineBoState {
        &self.state
    }

    /// Line `index` through `origin`: a coordinate axis for even indices, a random unit
    /// direction for odd ones.
    fn line_through(&self, origin: Vec<f64>, index: u64) -> Line {
        let dim = origin.len();
        let mut rng = rng_for(self.state.config.seed, (1 << 40) + index);
        let mut direction = vec![0.0; dim];
        if index % 2 == 0 {
            direction[rng.random_range(0..dim)] = 1.0;
        } else {
            for d in direction.iter_mut() {
                *d = StandardNormal.sample(&mut rng);
            }
            let norm = direction
                .iter()
                .map(|d| d * d)
                .sum::<f64>()
                .sqrt()
                .max(1e-300);
            direction.iter_mut().for_each(|d| *d /= norm);
        }
        Line {
            origin,
            direction,
            index,
            laps: 0,
        }
    }

    /// The range of t keeping origin + t·d inside the box, and |t| within the step.
    fn t_range(&self) -> (f64, f64) {
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for (i, d) in self.line.direction.iter().enumerate() {
            if d.abs() < 1e-15 {
                continue;
            }
            let a = (self.bounds.lower[i] - self.line.origin[i]) / d;
            let b = (self.bounds.upper[i] - self.line.origin[i]) / d;
            lo = lo.max(a.min(b));
            hi = hi.min(a.max(b));
        }
        if let Some(step) = self.state.config.step {
            (lo, hi) = (lo.max(-step), hi.min(step));
        }
        (lo.min(0.0), hi.max(0.0))
    }

    fn on_line(&self, t: f64) -> Vec<f64> {
        let mut w: Vec<f64> = self
            .line
            .origin
            .iter()
            .zip(&self.line.direction)
            .map(|(o, d)| o + t * d)
            .collect();
        self.bounds.clamp(&mut w);
        w
    }

    fn maybe_refit(&mut self) -> Result<()> {
        let n = self.gp.len();
        if n < 2 || n % self.state.config.refit_every.max(1) != 0 {
            return Ok(());
        }
        let ys = self.gp.values();
        let mean_sq = ys.iter().map(|y| y * y).sum::<f64>() / n as f64;
        let width = 2.0 * self.state.config.box_radius;
        let bounds = Bounds {
            lengthscale: (0.01 * width, 10.0 * width),
            signal_var: (1e-3 * mean_sq.max(1e-6), 1e2 * mean_sq.max(1e-6)),
            noise_var: None,
        };
        fit(&mut self.gp, &bounds, self.state.config.fit_iterations)?;
        Ok(())
    }
}

impl Proposer for LineBoProposer {
    type Note = ();
    type State = LineBoState;
    const SAVED_AS: SavedAs = SavedAs::Laps(NAME);

    fn propose(&mut self, _: &Told) -> Result<Proposal<()>> {
        if self.state.observations.is_empty() {
            return Ok(Proposal::plain(self.state.w0.clone()));
        }
        let (lo, hi) = self.t_range();
        let grid = self.state.config.grid;
        let ts: Vec<f64> = (0..grid)
            .map(|k| lo + (hi - lo) * k as f64 / (grid - 1) as f64)
            .collect();
        let points: Vec<f64> = ts.iter().flat_map(|&t| self.on_line(t)).collect();
        let beta = self.state.config.beta;
        let scores: Vec<f64> = self
            .gp
            .predict_batch(&points)
            .into_iter()
            .map(|(m, v)| ucb(m, v, beta))
            .collect();
        Ok(Proposal::plain(
            self.on_line(ts[crate::acquisition::argmax(&scores)]),
        ))
    }

    fn observe(&mut self, lap: &Lap<'_>, _: Option<&Proposal<()>>, told: &Told) -> Result<()> {
        self.gp.add(lap.weights, lap.reward)?;
        self.state
            .observations
            .push((lap.weights.to_vec(), lap.reward));
        self.line.laps += 1;
        if self.line.laps >= self.state.config.laps_per_line || self.state.observations.len() == 1 {
            let origin = told.best_or(&self.state.w0).to_vec();
            self.line = self.line_through(origin, self.line.index + 1);
        }
        self.maybe_refit()
    }

    fn dim(&self) -> usize {
        self.state.w0.len()
    }

    fn state(&self) -> Cow<'_, LineBoState> {
        Cow::Borrowed(&self.state)
    }
}
