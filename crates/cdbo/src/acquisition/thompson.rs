//! Thompson sampling: one draw f ~ N(μ, Σ) of the joint posterior over a set of candidates,
//! f = μ + L_Σ z with L_Σ L_Σᵀ = Σ + εI and z ~ N(0, I); the candidate where the draw is
//! largest is the next point (TuRBO's acquisition). The jitter ε is the smallest of 0,
//! 1e-10·s̄, 1e-9·s̄, …, 1e-3·s̄ (s̄ the mean posterior variance on the diagonal) that factors
//! Σ, then of 1e-10·σ², …, 1e-3·σ² with σ² the prior variance: where every candidate lies close
//! to observed points (a small trust region) the posterior variances are far below the
//! rounding error of Σ = K** − K*ᵀK⁻¹K*, which is relative to σ².

use faer::{Mat, Side};
use rand_distr::{Distribution, StandardNormal};

use crate::error::{Error, Result};

/// One joint draw at the candidates from their posterior means and covariance, and the GP's
/// prior variance σ².
pub fn draw(
    means: &[f64],
    cov: &Mat<f64>,
    prior_var: f64,
    rng: &mut impl rand::Rng,
) -> Result<Vec<f64>> {
    let b = means.len();
    let scale = (0..b).map(|i| cov[(i, i)].abs()).sum::<f64>() / b.max(1) as f64;
    let ladder = [1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3];
    let jitters = std::iter::once(0.0)
        .chain(ladder.map(|j| j * scale.max(1e-300)))
        .chain(
            ladder
                .map(|j| j * prior_var)
                .into_iter()
                .filter(|&j| j > 1e-3 * scale),
        );
    for add in jitters {
        let k = Mat::from_fn(b, b, |i, j| cov[(i, j)] + if i == j { add } else { 0.0 });
        let Ok(llt) = k.llt(Side::Lower) else {
            continue;
        };
        let l = llt.L();
        let z: Vec<f64> = (0..b).map(|_| StandardNormal.sample(rng)).collect();
        return Ok((0..b)
            .map(|i| means[i] + (0..=i).map(|j| l[(i, j)] * z[j]).sum::<f64>())
            .collect());
    }
    Err(Error::Numerical(format!(
        "the posterior covariance of {b} candidates is not positive semi-definite even with jitter"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The draws' sample mean and covariance converge to μ and Σ.
    #[test]
    fn draws_have_the_given_mean_and_covariance() {
        let means = [1.0, -2.0];
        let cov = Mat::from_fn(2, 2, |i, j| [[2.0, 0.6], [0.6, 0.5]][i][j]);
        let mut rng = crate::rng::rng_for(3, 0);
        let n = 40_000;
        let draws: Vec<Vec<f64>> = (0..n)
            .map(|_| draw(&means, &cov, 1.0, &mut rng).unwrap())
            .collect();
        let m: Vec<f64> = (0..2)
            .map(|i| draws.iter().map(|d| d[i]).sum::<f64>() / n as f64)
            .collect();
        let c01 = draws
            .iter()
            .map(|d| (d[0] - m[0]) * (d[1] - m[1]))
            .sum::<f64>()
            / n as f64;
        let c11 = draws.iter().map(|d| (d[1] - m[1]).powi(2)).sum::<f64>() / n as f64;
        assert!(
            (m[0] - 1.0).abs() < 0.03 && (m[1] + 2.0).abs() < 0.02,
            "{m:?}"
        );
        assert!(
            (c01 - 0.6).abs() < 0.03 && (c11 - 0.5).abs() < 0.02,
            "{c01} {c11}"
        );
    }

    /// A singular covariance (two identical candidates) still factors, with jitter.
    #[test]
    fn singular_covariance_is_jittered() {
        let cov = Mat::from_fn(2, 2, |_, _| 1.0);
        let mut rng = crate::rng::rng_for(1, 0);
        let d = draw(&[0.0, 0.0], &cov, 1.0, &mut rng).unwrap();
        assert!((d[0] - d[1]).abs() < 1e-3);
    }

    /// Posterior variances far below the prior's rounding error (a matrix off positive
    /// definite by −1e-14 where its diagonal is 1e-16) factor with the prior's jitter.
    #[test]
    fn rounding_error_of_the_prior_is_jittered() {
        let cov = Mat::from_fn(2, 2, |i, j| if i == j { 1e-16 } else { 1e-14 });
        let mut rng = crate::rng::rng_for(1, 0);
        assert!(draw(&[0.0, 0.0], &cov, 1e-16, &mut rng).is_err());
        let d = draw(&[0.0, 0.0], &cov, 1.0, &mut rng).unwrap();
        assert!(d.iter().all(|x| x.abs() < 1e-3), "{d:?}");
    }
}
