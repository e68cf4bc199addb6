//! The acquisition maximised by CMA-ES: the inner loop of standard BO as the paper ran it
//! (BO-CMA-ES). The search starts at the best weights so far with step size `sigma0` (the
//! exploration scale every method gets, 0.03 in races: started with a fifth of the box
//! instead, CMA-ES only meets the flat far field of UCB and hands back its start point, so
//! that BO-CMA-ES drives the same lap again and again), keeps to the search box, and scores
//! each population as one batched
//! GP query. It stops at the evaluation budget (the paper's 50,000), or when the best value
//! has not improved by more than 1e-6 relative in 10 + ⌈30n/λ⌉ generations (pycma's
//! `tolflatfitness`-like stagnation rule), or when σ·max√λ(C) falls below 1e-9·r.

use serde::{Deserialize, Serialize};

use super::cmaes::{Cmaes, CmaesConfig};
use super::coordinate_ascent::Ascent;
use super::{Optimizer, SearchBox};
use crate::acquisition::Acquisition;
use crate::error::Result;
use crate::gp::GaussianProcess;

/// Settings of the CMA-ES acquisition search.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CmaesSearch {
    /// Acquisition evaluations per suggestion, at most (the paper's 50,000).
    pub budget: usize,
    /// Initial step size σ₀.
    pub sigma0: f64,
}

impl Default for CmaesSearch {
    fn default() -> Self {
        CmaesSearch {
            budget: 50_000,
            sigma0: 0.03,
        }
    }
}

/// Maximises the acquisition `acq` of `gp` over the box from `start` with active CMA-ES
/// seeded by `seed`.
pub fn maximise(
    gp: &GaussianProcess,
    acq: Acquisition,
    bounds: &SearchBox,
    start: &[f64],
    settings: &CmaesSearch,
    seed: u64,
) -> Result<Ascent> {
    let dim = start.len();
    let radius = 0.5 * (bounds.upper[0] - bounds.lower[0]);
    let best_y = gp.best_value();
    let mut es = Cmaes::new(
        start.to_vec(),
        CmaesConfig {
            seed,
            sigma0: settings.sigma0,
            population: 0,
            bounds: Some(bounds.clone()),
            lazy_eigen: true,
        },
    )?;
    let (m0, v0) = gp.predict(start);
    let mut best = Ascent {
        point: start.to_vec(),
        value: acq.value(m0, v0, best_y),
        var: v0,
        evaluations: 1,
    };
    let mut flat_generations = 0usize;
    while best.evaluations < settings.budget {
        let population = es.untold();
        let lambda = population.len();
        let patience = 10 + (30 * dim).div_ceil(lambda.max(1));
        let flat: Vec<f64> = population.iter().flatten().copied().collect();
        let scores = gp.predict_batch(&flat);
        best.evaluations += lambda;
        let before = best.value;
        for (w, (m, v)) in population.iter().zip(scores) {
            let h = acq.value(m, v, best_y);
            if h > best.value {
                best.point.clone_from(w);
                (best.value, best.var) = (h, v);
            }
            es.tell(w, h)?;
        }
        let improved = best.value - before > 1e-6 * before.abs().max(1e-12);
        flat_generations = if improved { 0 } else { flat_generations + 1 };
        if flat_generations > patience || es.sigma() * es.max_axis() < 1e-9 * radius {
            break;
        }
    }
    Ok(best)
}
