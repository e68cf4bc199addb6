//! Active CMA-ES (Hansen 2016, "The CMA Evolution Strategy: A Tutorial", with the negative
//! weights of active CMA, Jastrebski & Arnold 2006; libcmaes's default aCMA-ES, the paper's
//! baseline). Minimises f = −reward, one individual per lap.
//!
//! With λ = 4 + ⌊3 ln n⌋, μ = ⌊λ/2⌋, w′ᵢ = ln((λ+1)/2) − ln i and the tutorial's constants:
//! - sample yₖ = B·D·zₖ, xₖ = m + σyₖ (clamped into the box; the clamped step is used),
//! - m ← m + σ·Σᵢ≤μ wᵢ yᵢ:λ,
//! - p_σ ← (1 − c_σ)p_σ + √(c_σ(2 − c_σ)μ_eff)·C^(−1/2)⟨y⟩, σ ← σ·exp(c_σ/d_σ·(‖p_σ‖/E‖N(0,I)‖ − 1)),
//! - p_c ← (1 − c_c)p_c + h_σ√(c_c(2 − c_c)μ_eff)⟨y⟩,
//! - C ← (1 + c₁δ(h_σ) − c₁ − c_μΣwⱼ)C + c₁p_cp_cᵀ + c_μΣᵢ wᵢ° yᵢ:λ yᵢ:λᵀ, with
//!   wᵢ° = wᵢ·n/‖C^(−1/2)yᵢ:λ‖² for the negative weights.
//!
//! A failed lap told with its place x (`tell_lap`) ranks by it, f = 1 − x, behind every
//! completed lap.
//!
//! IPOP restarts (Auger & Hansen 2005): when the search has collapsed (σ·max√λ(C) below
//! 1e-12 of σ₀, a condition number of C above 1e14, or a non-finite state), it restarts from
//! the best point with σ₀ and twice the population.

use faer::{Mat, Side};
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use std::borrow::Cow;

use super::ask_tell::{AskTell, Lap, Proposal, Proposer, Recorded, SavedAs, Told};
use super::{SearchBox, rng_for};
use crate::error::{Error, Result};

/// The method's name, and the kind of its saved state.
pub const NAME: &str = "cmaes";

/// Settings of a CMA-ES run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CmaesConfig {
    /// Seed of every random choice.
    pub seed: u64,
    /// Initial step size σ₀.
    pub sigma0: f64,
    /// Population size λ (0: 4 + ⌊3 ln n⌋).
    pub population: usize,
    /// The box the search stays in (`None`: unbounded).
    pub bounds: Option<SearchBox>,
    /// Re-decompose C only every ⌈1/(10·n·(c₁ + c_μ))⌉ generations (Hansen's lazy update,
    /// O(n³) amortised away) instead of every generation. For an inner loop that is never
    /// saved: a resumed run decomposes its current C, so its samples would differ.
    pub lazy_eigen: bool,
}

impl Default for CmaesConfig {
    fn default() -> Self {
        CmaesConfig {
            seed: 0,
            sigma0: 0.3,
            population: 0,
            bounds: None,
            lazy_eigen: false,
        }
    }
}

/// The strategy parameters derived from n and λ.
#[derive(Debug, Clone, PartialEq)]
struct Params {
    lambda: usize,
    mu: usize,
    weights: Vec<f64>,
    mu_eff: f64,
    cc: f64,
    cs: f64,
    c1: f64,
    cmu: f64,
    damps: f64,
    chi_n: f64,
}

impl Params {
    fn new(n: usize, lambda: usize) -> Params {
        let nf = n as f64;
        let mu = lambda / 2;
        let raw: Vec<f64> = (1..=lambda)
            .map(|i| ((lambda as f64 + 1.0) / 2.0).ln() - (i as f64).ln())
            .collect();
        let pos_sum: f64 = raw[..mu].iter().sum();
        let pos_sq: f64 = raw[..mu].iter().map(|w| w * w).sum();
        let mu_eff = pos_sum * pos_sum / pos_sq;
        let neg_sum: f64 = raw[mu..].iter().map(|w| w.abs()).sum();
        let neg_sq: f64 = raw[mu..].iter().map(|w| w * w).sum();
        let mu_eff_neg = if neg_sq > 0.0 {
            neg_sum * neg_sum / neg_sq
        } else {
            0.0
        };
        let cc = (4.0 + mu_eff / nf) / (nf + 4.0 + 2.0 * mu_eff / nf);
        let cs = (mu_eff + 2.0) / (nf + mu_eff + 5.0);
        let c1 = 2.0 / ((nf + 1.3).powi(2) + mu_eff);
        let cmu =
            (1.0 - c1).min(2.0 * (mu_eff - 2.0 + 1.0 / mu_eff) / ((nf + 2.0).powi(2) + mu_eff));
        let damps = 1.0 + 2.0 * (((mu_eff - 1.0) / (nf + 1.0)).sqrt() - 1.0).max(0.0) + cs;
        let alpha_mu = 1.0 + c1 / cmu;
        let alpha_eff = 1.0 + 2.0 * mu_eff_neg / (mu_eff + 2.0);
        let alpha_posdef = (1.0 - c1 - cmu) / (nf * cmu);
        let neg_scale = alpha_mu.min(alpha_eff).min(alpha_posdef);
        let weights = raw
            .iter()
            .enumerate()
            .map(|(i, w)| {
                if i < mu {
                    w / pos_sum
                } else if neg_sum > 0.0 {
                    neg_scale * w / neg_sum
                } else {
                    0.0
                }
            })
            .collect();
        let chi_n = nf.sqrt() * (1.0 - 1.0 / (4.0 * nf) + 1.0 / (21.0 * nf * nf));
        Params {
            lambda,
            mu,
            weights,
            mu_eff,
            cc,
            cs,
            c1,
            cmu,
            damps,
            chi_n,
        }
    }
}

/// The search distribution and the current generation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CmaesProgress {
    /// Settings.
    pub config: CmaesConfig,
    /// The start point.
    pub start: Vec<f64>,
    /// Mean m.
    pub mean: Vec<f64>,
    /// Step size σ.
    pub sigma: f64,
    /// Covariance C, row-major n × n.
    pub cov: Vec<f64>,
    /// Evolution paths.
    pub ps: Vec<f64>,
    /// Evolution path of C.
    pub pc: Vec<f64>,
    /// Generations completed.
    pub generation: u64,
    /// The current generation's steps yₖ (sampled, then clamped).
    pub population: Vec<Vec<f64>>,
    /// Fitness (−reward) told for the current generation, in order.
    pub fitness: Vec<f64>,
    /// IPOP restarts so far (the population is λ·2^restarts).
    pub restarts: u32,
}

/// Everything needed to resume a run: its distribution and the laps' record.
pub type CmaesState = Recorded<CmaesProgress>;

/// Active CMA-ES's proposer: the current generation's next individual m + σyₖ, updated as the
/// module says once all λ are told.
#[derive(Debug, Clone)]
pub struct CmaesProposer {
    state: CmaesProgress,
    params: Params,
    bounds: SearchBox,
    /// Eigenvectors B (columns) and square roots of the eigenvalues D of C.
    b: Mat<f64>,
    d: Vec<f64>,
}

/// Active CMA-ES.
pub type Cmaes = AskTell<CmaesProposer>;

impl Cmaes {
    /// A run from `start` with step size σ₀.
    pub fn new(start: Vec<f64>, config: CmaesConfig) -> Result<Cmaes> {
        let n = start.len();
        if n == 0 || start.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid_value(
                "CMA-ES's start point",
                format!("{start:?}"),
                "finite, of at least one weight",
            ));
        }
        if !(config.sigma0.is_finite() && config.sigma0 > 0.0) {
            return Err(Error::invalid_value("σ₀", config.sigma0, "positive"));
        }
        let mut cov = vec![0.0; n * n];
        for i in 0..n {
            cov[i * n + i] = 1.0;
        }
        let state = CmaesProgress {
            mean: start.clone(),
            sigma: config.sigma0,
            cov,
            ps: vec![0.0; n],
            pc: vec![0.0; n],
            generation: 0,
            population: Vec::new(),
            fitness: Vec::new(),
            restarts: 0,
            start,
            config,
        };
        Ok(AskTell::resumed(
            CmaesProposer::resume(state)?,
            Told::default(),
        ))
    }

    /// Rebuilds a run from its state.
    pub fn resume(state: CmaesState) -> Result<Cmaes> {
        let (state, told) = state.into_parts();
        Ok(AskTell::resumed(CmaesProposer::resume(state)?, told))
    }
}

impl CmaesProposer {
    fn resume(state: CmaesProgress) -> Result<CmaesProposer> {
        let n = state.start.len();
        if state.cov.len() != n * n || state.mean.len() != n {
            return Err(Error::CorruptState {
                method: "CMA-ES",
                reason: "sizes do not match the dimension".into(),
            });
        }
        let base = if state.config.population > 0 {
            state.config.population
        } else {
            4 + (3.0 * (n as f64).ln()).floor() as usize
        };
        let lambda = base << state.restarts.min(16);
        let bounds = match &state.config.bounds {
            Some(b) if b.lower.len() == n && b.upper.len() == n => b.clone(),
            Some(_) => {
                return Err(Error::CorruptState {
                    method: "CMA-ES",
                    reason: "the box does not match the dimension".into(),
                });
            }
            None => SearchBox {
                lower: vec![f64::NEG_INFINITY; n],
                upper: vec![f64::INFINITY; n],
            },
        };
        let mut run = CmaesProposer {
            params: Params::new(n, lambda.max(2)),
            bounds,
            b: Mat::identity(n, n),
            d: vec![1.0; n],
            state,
        };
        run.decompose()?;
        if run.state.population.is_empty() {
            run.sample();
        }
        Ok(run)
    }

    /// Current step size σ.
    pub fn sigma(&self) -> f64 {
        self.state.sigma
    }

    fn decompose(&mut self) -> Result<()> {
        let n = self.state.mean.len();
        let c = Mat::from_fn(n, n, |i, j| self.state.cov[i * n + j]);
        let evd = c.self_adjoint_eigen(Side::Lower).map_err(|e| {
            Error::Numerical(format!(
                "CMA-ES covariance eigendecomposition failed: {e:?}"
            ))
        })?;
        self.b = evd.U().to_owned();
        let s = evd.S().column_vector();
        self.d = (0..n).map(|i| s[i].max(1e-300).sqrt()).collect();
        Ok(())
    }

    /// C^(−1/2)·y = B·(D⁻¹ ∘ Bᵀy).
    fn inv_sqrt(&self, y: &[f64]) -> Vec<f64> {
        let n = y.len();
        let bty: Vec<f64> = (0..n)
            .map(|k| (0..n).map(|i| self.b[(i, k)] * y[i]).sum::<f64>() / self.d[k])
            .collect();
        (0..n)
            .map(|i| (0..n).map(|k| self.b[(i, k)] * bty[k]).sum())
            .collect()
    }

    fn sample(&mut self) {
        let n = self.state.mean.len();
        let mut rng = rng_for(self.state.config.seed, self.state.generation);
        let sigma = self.state.sigma;
        let lambda = self.params.lambda;
        // Y = B·diag(D)·Z for the whole population in one matrix product.
        let mut z = Mat::<f64>::zeros(n, lambda);
        for k in 0..lambda {
            for i in 0..n {
                let g: f64 = StandardNormal.sample(&mut rng);
                z[(i, k)] = self.d[i] * g;
            }
        }
        let ys = &self.b * &z;
        self.state.population = (0..lambda)
            .map(|k| {
                let y: Vec<f64> = ys.col(k).iter().copied().collect();
                let mut x: Vec<f64> = self
                    .state
                    .mean
                    .iter()
                    .zip(&y)
                    .map(|(m, yi)| m + sigma * yi)
                    .collect();
                self.bounds.clamp(&mut x);
                x.iter()
                    .zip(&self.state.mean)
                    .map(|(xi, m)| (xi - m) / sigma)
                    .collect()
            })
            .collect();
        self.state.fitness.clear();
    }

    /// The largest axis √λ_max(C) of the search distribution, relative to σ.
    pub fn max_axis(&self) -> f64 {
        self.d.iter().fold(0.0, |a, &d| a.max(d))
    }

    /// The current generation's individuals not yet told, in the order `ask` gives them: a
    /// caller that scores a whole population in one batch tells them back in this order.
    pub fn untold(&self) -> Vec<Vec<f64>> {
        (self.state.fitness.len()..self.params.lambda)
            .map(|k| self.point(k))
            .collect()
    }

    fn point(&self, k: usize) -> Vec<f64> {
        self.state
            .mean
            .iter()
            .zip(&self.state.population[k])
            .map(|(m, y)| m + self.state.sigma * y)
            .collect()
    }

    /// Records a told individual with its fitness (minimised) and updates the generation
    /// once all λ are told.
    fn tell_ranked(&mut self, weights: &[f64], fitness: f64, told: &Told) -> Result<()> {
        let k = self.state.fitness.len();
        let mut w = weights.to_vec();
        self.bounds.clamp(&mut w);
        let y: Vec<f64> = w
            .iter()
            .zip(&self.state.mean)
            .map(|(wi, m)| (wi - m) / self.state.sigma)
            .collect();
        self.state.population[k] = y;
        self.state.fitness.push(fitness);
        if self.state.fitness.len() == self.params.lambda {
            self.update(told)?;
        }
        Ok(())
    }

    /// The generation's update, once all λ individuals are told.
    fn update(&mut self, told: &Told) -> Result<()> {
        let n = self.state.mean.len();
        let nf = n as f64;
        let p = self.params.clone();
        let mut order: Vec<usize> = (0..p.lambda).collect();
        order.sort_by(|&a, &b| self.state.fitness[a].total_cmp(&self.state.fitness[b]));
        let ys: Vec<Vec<f64>> = order
            .iter()
            .map(|&k| self.state.population[k].clone())
            .collect();
        let mut yw = vec![0.0; n];
        for (w, y) in p.weights[..p.mu].iter().zip(&ys) {
            for (acc, yi) in yw.iter_mut().zip(y) {
                *acc += w * yi;
            }
        }
        let s = &mut self.state;
        for (m, y) in s.mean.iter_mut().zip(&yw) {
            *m += s.sigma * y;
        }
        let cinv_yw = self.inv_sqrt(&yw);
        let s = &mut self.state;
        let a = (p.cs * (2.0 - p.cs) * p.mu_eff).sqrt();
        for (ps, c) in s.ps.iter_mut().zip(&cinv_yw) {
            *ps = (1.0 - p.cs) * *ps + a * c;
        }
        let ps_norm = s.ps.iter().map(|v| v * v).sum::<f64>().sqrt();
        let g = (s.generation + 1) as i32;
        let hsig =
            ps_norm / (1.0 - (1.0 - p.cs).powi(2 * g)).sqrt() < (1.4 + 2.0 / (nf + 1.0)) * p.chi_n;
        let hs = if hsig { 1.0 } else { 0.0 };
        let b = (p.cc * (2.0 - p.cc) * p.mu_eff).sqrt();
        for (pc, y) in s.pc.iter_mut().zip(&yw) {
            *pc = (1.0 - p.cc) * *pc + hs * b * y;
        }
        // Weights with the negative ones rescaled by n/‖C^(−1/2)y‖².
        let wo: Vec<f64> = p
            .weights
            .iter()
            .zip(&ys)
            .map(|(w, y)| {
                if *w >= 0.0 {
                    *w
                } else {
                    let c = self.inv_sqrt(y);
                    w * nf / c.iter().map(|v| v * v).sum::<f64>().max(1e-300)
                }
            })
            .collect();
        let s = &mut self.state;
        let sum_w: f64 = p.weights.iter().sum();
        let delta = (1.0 - hs) * p.cc * (2.0 - p.cc);
        let decay = 1.0 + p.c1 * delta - p.c1 - p.cmu * sum_w;
        // Σₖ wₖ° yₖyₖᵀ as one product of n × λ matrices.
        let weighted = Mat::from_fn(n, ys.len(), |i, k| wo[k] * ys[k][i]);
        let plain = Mat::from_fn(n, ys.len(), |i, k| ys[k][i]);
        let rank_mu = &weighted * plain.transpose();
        for i in 0..n {
            for j in 0..n {
                s.cov[i * n + j] =
                    decay * s.cov[i * n + j] + p.c1 * s.pc[i] * s.pc[j] + p.cmu * rank_mu[(i, j)];
            }
        }
        s.sigma *= ((p.cs / p.damps) * (ps_norm / p.chi_n - 1.0))
            .min(1.0)
            .exp();
        s.generation += 1;
        let lazy_period = (1.0 / (10.0 * nf * (p.c1 + p.cmu))).ceil().max(1.0) as u64;
        let due = !s.config.lazy_eigen || s.generation % lazy_period == 0;
        let decomposed = if due { self.decompose() } else { Ok(()) };
        let (dmin, dmax) = self.d.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), d| {
            (lo.min(*d), hi.max(*d))
        });
        let collapsed = decomposed.is_err()
            || !self.state.sigma.is_finite()
            || self.state.sigma * dmax < 1e-12 * self.state.config.sigma0
            || dmax * dmax > 1e14 * dmin * dmin;
        if collapsed {
            self.restart(told)?;
        }
        self.sample();
        Ok(())
    }

    /// IPOP restart from the best point with σ₀ and a doubled population.
    fn restart(&mut self, told: &Told) -> Result<()> {
        let n = self.state.mean.len();
        let s = &mut self.state;
        s.restarts += 1;
        s.mean = told.best_or(&s.start).to_vec();
        s.sigma = s.config.sigma0;
        s.cov = (0..n * n)
            .map(|k| if k % (n + 1) == 0 { 1.0 } else { 0.0 })
            .collect();
        s.ps = vec![0.0; n];
        s.pc = vec![0.0; n];
        let base = if s.config.population > 0 {
            s.config.population
        } else {
            4 + (3.0 * (n as f64).ln()).floor() as usize
        };
        self.params = Params::new(n, base << s.restarts.min(16));
        self.decompose()
    }
}

impl Proposer for CmaesProposer {
    type Note = ();
    type State = CmaesProgress;
    const SAVED_AS: SavedAs = SavedAs::WithRecord(NAME);

    fn propose(&mut self, _: &Told) -> Result<Proposal<()>> {
        Ok(Proposal::plain(self.point(self.state.fitness.len())))
    }

    /// Told weights other than the asked ones are injected: their step (w − m)/σ replaces the
    /// pending individual's. A lap that failed at x ranks by how far it got, f = 1 − x (behind
    /// every completed lap, f = −reward < 0): when a whole generation fails, a fitness of zeros
    /// everywhere steers nothing, while the failure places still point the mean towards laps
    /// that got further.
    fn observe(&mut self, lap: &Lap<'_>, _: Option<&Proposal<()>>, told: &Told) -> Result<()> {
        let fitness = lap.failure.map_or(-lap.reward, |f| 1.0 - f.at);
        self.tell_ranked(lap.weights, fitness, told)
    }

    fn dim(&self) -> usize {
        self.state.mean.len()
    }

    fn state(&self) -> Cow<'_, CmaesProgress> {
        Cow::Borrowed(&self.state)
    }
}
