//! Upper confidence bound, h(w) = μ(w) + β·σ(w) (paper Sec. IV; β in [0.5, 2] there).

/// The paper's default β.
pub const DEFAULT_BETA: f64 = 1.0;

/// μ + β√var.
#[inline]
pub fn ucb(mean: f64, var: f64, beta: f64) -> f64 {
    mean + beta * var.max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    #[test]
    fn is_mean_plus_beta_sigma() {
        assert_eq!(super::ucb(2.0, 4.0, 0.5), 3.0);
        assert_eq!(super::ucb(2.0, -1e-18, 3.0), 2.0);
    }
}
