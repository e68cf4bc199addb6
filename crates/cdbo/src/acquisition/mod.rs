//! Acquisition functions h(w) scoring where to run the next lap, from the GP posterior
//! mean μ(w) and standard deviation σ(w).

pub mod ei;
pub mod thompson;
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

/// The index of the largest value (the first on ties).
pub fn argmax(values: &[f64]) -> usize {
    values
        .iter()
        .enumerate()
        .fold((0, f64::NEG_INFINITY), |(bi, bv), (i, &v)| {
            if v > bv { (i, v) } else { (bi, bv) }
        })
        .0
}

#[cfg(test)]
mod tests {
    #[test]
    fn argmax_takes_the_first_largest() {
        assert_eq!(super::argmax(&[1.0, 3.0, 3.0, -1.0]), 1);
        assert_eq!(super::argmax(&[f64::NAN, -1.0]), 1);
    }
}
