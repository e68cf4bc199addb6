//! REMBO, Bayesian optimisation in a random embedding (Wang et al. 2016).
//!
//! A matrix A ∈ ℝ^{D×d} with N(0, 1) entries, drawn from the seed, embeds the low-dimensional
//! box Y = [−b, b]^d (REMBO's b = √d; b is the method's main knob) in the weights: w(y) = w₀ + r·P(Ay), with P the projection onto
//! [−1, 1]^D (REMBO's map into its normalised box X = [−1, 1]^D, here the search box
//! [w₀ − r, w₀ + r]) and y = 0 giving the demonstration. After y = 0 and S initial samples
//! that move w by σ₀ as CDBO's do, a GP (Matérn-5/2 ARD as in REMBO, CDBO's hyperparameter scheme)
//! models the reward over y; the next y maximises expected improvement (REMBO's
//! acquisition) by coordinate ascent with three sweeps, cheap in d dimensions, started from
//! the best of the best observation and 1,000 uniform points of Y (REMBO maximises EI
//! globally).

use std::borrow::Cow;

use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use super::ask_tell::{AskTell, Lap, Proposal, Proposer, SavedAs, Told};
use super::bo::{Bo, BoConfig, BoState, Maximiser};
use super::coordinate_ascent::AxisSearch;
use super::{Optimizer, rng_for};
use crate::acquisition::Acquisition;
use crate::error::{Error, Result};
use crate::gp::Kernel;

/// REMBO in a 5-dimensional embedding.
pub const NAME_5D: &str = "rembo-5d";
/// REMBO in a 10-dimensional embedding.
pub const NAME_10D: &str = "rembo-10d";
/// The kind of the saved state of any REMBO.
const SAVED_KIND: &str = "rembo";

/// Settings of a REMBO run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RemboConfig {
    /// Seed of the embedding and of every other random choice.
    pub seed: u64,
    /// Dimension d of the embedding.
    pub embedding_dim: usize,
    /// Half-width r of the search box around w₀.
    pub box_radius: f64,
    /// The exploration scale σ₀ around w₀ in the weights: the initial samples are
    /// y ~ N(0, σ_y²I) with σ_y = σ₀/(r√d), since each wᵢ − w₀ᵢ = r·Σⱼ Aᵢⱼyⱼ then has
    /// standard deviation σ₀ (before the projection).
    pub sigma0: f64,
    /// Half-width b of the embedding's box Y = [−b, b]^d; `None`: REMBO's √d.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub embedding_box: Option<f64>,
}

/// Everything needed to resume a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RemboState {
    /// Settings.
    pub config: RemboConfig,
    /// The demonstration's weights.
    pub w0: Vec<f64>,
    /// The BO run in the embedding.
    pub inner: BoState,
}

/// REMBO's proposer: w(y) for the y the BO run in the embedding asks, noted with that y; a
/// told lap tells its y to the BO run.
#[derive(Debug, Clone)]
pub struct RemboProposer {
    config: RemboConfig,
    w0: Vec<f64>,
    /// A, row-major D × d.
    embedding: Vec<f64>,
    inner: Bo,
}

/// A REMBO run.
pub type Rembo = AskTell<RemboProposer>;

/// Uniform points of Y scored before each ascent of the expected improvement: REMBO
/// maximises it globally (with DIRECT in the paper), and its maxima often lie far from the
/// best point in a space of only d dimensions.
const RANDOM_STARTS: usize = 1000;

/// The stream of the embedding's draws (the inner BO run uses streams 0, 1, 2, …).
const EMBEDDING_STREAM: u64 = u64::MAX;

impl Rembo {
    /// A new run from the demonstration's weights.
    pub fn new(w0: Vec<f64>, config: RemboConfig) -> Result<Rembo> {
        let d = config.embedding_dim;
        if d == 0 || w0.is_empty() {
            return Err(Error::too_small(
                "REMBO's weights and embedding dimension",
                d.min(w0.len()),
                1,
            ));
        }
        let half_width = config.embedding_box.unwrap_or((d as f64).sqrt());
        if !(half_width.is_finite() && half_width > 0.0) {
            return Err(Error::invalid_value(
                "REMBO's box half-width b",
                half_width,
                "a finite positive number",
            ));
        }
        let inner = BoConfig {
            seed: config.seed,
            acquisition: Acquisition::Ei { xi: 0.0 },
            initial_sigma: config.sigma0 / (config.box_radius * (d as f64).sqrt()),
            kernel: Kernel::Matern52,
            box_radius: half_width,
            // In d ≤ 10 dimensions a thorough ascent costs little: three sweeps, a finer scan
            // and a longer polish than CDBO's in 100 (Branin-100D: 9 of 10 seeds within 0.5 of
            // the optimum in 150 evaluations, against 7 with CDBO's settings).
            maximiser: Maximiser::CoordinateAscent(AxisSearch {
                sweeps: 3,
                scan: 24,
                polish: 16,
                random_starts: RANDOM_STARTS,
                ..AxisSearch::default()
            }),
            ..BoConfig::default()
        };
        let state = RemboState {
            inner: Bo::new(vec![0.0; d], inner)?.state().clone(),
            w0,
            config,
        };
        Rembo::resume(state)
    }

    /// Rebuilds a run from its state.
    pub fn resume(state: RemboState) -> Result<Rembo> {
        let (dim, d) = (state.w0.len(), state.config.embedding_dim);
        if state.inner.w0.len() != d {
            return Err(Error::CorruptState {
                method: "REMBO",
                reason: format!(
                    "an embedding of dimension {d} but a {}-dimensional GP",
                    state.inner.w0.len()
                ),
            });
        }
        let mut rng = rng_for(state.config.seed, EMBEDDING_STREAM);
        let embedding = (0..dim * d)
            .map(|_| StandardNormal.sample(&mut rng))
            .collect();
        let inner = Bo::resume(state.inner)?;
        let proposer = RemboProposer {
            config: state.config,
            w0: state.w0,
            embedding,
            inner,
        };
        let laps = proposer.inner.state().observations.iter();
        let told = Told::of(laps.map(|(y, r)| (proposer.weights(y), *r)));
        Ok(AskTell::resumed(proposer, told))
    }
}

impl RemboProposer {
    /// w(y) = w₀ + r·P(Ay).
    pub fn weights(&self, y: &[f64]) -> Vec<f64> {
        let d = y.len();
        let r = self.config.box_radius;
        self.w0
            .iter()
            .enumerate()
            .map(|(i, w)| {
                let ay: f64 = self.embedding[i * d..(i + 1) * d]
                    .iter()
                    .zip(y)
                    .map(|(a, y)| a * y)
                    .sum();
                w + r * ay.clamp(-1.0, 1.0)
            })
            .collect()
    }
}

impl Proposer for RemboProposer {
    type Note = Vec<f64>;
    type State = RemboState;
    const SAVED_AS: SavedAs = SavedAs::Laps(SAVED_KIND);

    fn name(&self) -> &'static str {
        match self.config.embedding_dim {
            5 => NAME_5D,
            10 => NAME_10D,
            _ => SAVED_KIND,
        }
    }

    fn propose(&mut self, _: &Told) -> Result<Proposal<Vec<f64>>> {
        let y = self.inner.ask()?;
        Ok(Proposal {
            weights: self.weights(&y),
            note: y,
        })
    }

    /// Only the asked weights can be told: the GP lives in the embedding, and weights outside
    /// its image have no point there.
    fn observe(
        &mut self,
        lap: &Lap<'_>,
        asked: Option<&Proposal<Vec<f64>>>,
        _: &Told,
    ) -> Result<()> {
        match asked {
            Some(p) if p.weights.as_slice() == lap.weights => self.inner.tell(&p.note, lap.reward),
            _ => Err(Error::NotAsked { method: "REMBO" }),
        }
    }

    /// Its tell needs the embedded point of its last ask.
    fn takes_any_weights(&self) -> bool {
        false
    }

    fn dim(&self) -> usize {
        self.w0.len()
    }

    fn state(&self) -> Cow<'_, RemboState> {
        Cow::Owned(RemboState {
            config: self.config.clone(),
            w0: self.w0.clone(),
            inner: self.inner.state().clone(),
        })
    }
}
