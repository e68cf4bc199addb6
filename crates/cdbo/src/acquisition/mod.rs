//! Acquisition functions h(w) scoring where to run the next lap, from the GP posterior
//! mean μ(w) and standard deviation σ(w).

pub mod ei;
pub mod ucb;

use serde::{Deserialize, Serialize};

/// An acquisition function.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum Acquisition {
    /// Upper confidence bound μ + βσ (the paper's choice).
    Ucb {
        /// Exploration weight β.
        beta: f64,
    },
    /// Expected improvement over the best observation (REMBO's choice).
    Ei {
        /// Margin ξ subtracted from the improvement.
        xi: f64,
    },
}

impl Acquisition {
    /// h for a posterior mean, variance and the best value observed so far.
    #[inline]
    pub fn value(&self, mean: f64, var: f64, best: f64) -> f64 {
        match *self {
            Acquisition::Ucb { beta } => ucb::ucb(mean, var, beta),
            Acquisition::Ei { xi } => ei::expected_improvement(mean, var, best, xi),
        }
    }
}
