//! Stationary covariance functions k(w, w′) = σ_f²·κ(r) of the scaled distance
//! r = √(Σ_d (w_d − w′_d)² / l_d²) (ARD: one length-scale per dimension; isotropic: one for all).
//!
//! | kernel | κ(r) |
//! | --- | --- |
//! | exponential (Matérn-1/2, the paper's reward kernel) | e^(−r) |
//! | Matérn-3/2 | (1 + √3 r) e^(−√3 r) |
//! | Matérn-5/2 | (1 + √5 r + 5r²/3) e^(−√5 r) |
//! | squared exponential | e^(−r²/2) |

use serde::{Deserialize, Serialize};

/// The shape κ of a stationary kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Kernel {
    /// Matérn-1/2, κ(r) = e^(−r): the paper's choice for the reward GP.
    Exponential,
    /// Matérn-3/2.
    Matern32,
    /// Matérn-5/2.
    Matern52,
    /// Squared exponential (RBF).
    SquaredExponential,
}

const SQRT3: f64 = 1.732_050_807_568_877_2;
const SQRT5: f64 = 2.236_067_977_499_79;

impl Kernel {
    /// κ as a function of the squared scaled distance r² (avoids a square root for the SE kernel).
    #[inline]
    pub fn of_r2(self, r2: f64) -> f64 {
        match self {
            Kernel::Exponential => (-r2.sqrt()).exp(),
            Kernel::Matern32 => {
                let a = SQRT3 * r2.sqrt();
                (1.0 + a) * (-a).exp()
            }
            Kernel::Matern52 => {
                let a = SQRT5 * r2.sqrt();
                (1.0 + a + a * a / 3.0) * (-a).exp()
            }
            Kernel::SquaredExponential => (-0.5 * r2).exp(),
        }
    }

    /// dκ/d(r²) as a function of r², used for length-scale gradients. For the exponential
    /// kernel it is −e^(−r)/(2r), unbounded at r = 0 where every term it multiplies vanishes;
    /// 0 is returned there.
    #[inline]
    pub fn d_of_r2(self, r2: f64) -> f64 {
        match self {
            Kernel::Exponential => {
                if r2 <= 0.0 {
                    0.0
                } else {
                    let r = r2.sqrt();
                    -(-r).exp() / (2.0 * r)
                }
            }
            Kernel::Matern32 => -1.5 * (-SQRT3 * r2.sqrt()).exp(),
            Kernel::Matern52 => {
                let a = SQRT5 * r2.sqrt();
                -(5.0 / 6.0) * (1.0 + a) * (-a).exp()
            }
            Kernel::SquaredExponential => -0.5 * (-0.5 * r2).exp(),
        }
    }

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Exponential => "exponential",
            Kernel::Matern32 => "matern32",
            Kernel::Matern52 => "matern52",
            Kernel::SquaredExponential => "squared-exponential",
        }
    }
}

/// Σ_d (a_d − b_d)²·s_d with s_d = 1/l_d² (one entry: isotropic).
#[inline]
pub fn scaled_sq_dist(a: &[f64], b: &[f64], inv_l2: &[f64]) -> f64 {
    if inv_l2.len() == 1 {
        let s: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
        return s * inv_l2[0];
    }
    a.iter()
        .zip(b)
        .zip(inv_l2)
        .map(|((x, y), s)| (x - y) * (x - y) * s)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernels_are_one_at_zero_and_decay() {
        for k in [
            Kernel::Exponential,
            Kernel::Matern32,
            Kernel::Matern52,
            Kernel::SquaredExponential,
        ] {
            assert!((k.of_r2(0.0) - 1.0).abs() < 1e-15);
            assert!(k.of_r2(1.0) < 1.0 && k.of_r2(4.0) < k.of_r2(1.0));
        }
        assert!((Kernel::Exponential.of_r2(4.0) - (-2.0f64).exp()).abs() < 1e-15);
        let r = 0.7f64;
        assert!(
            (Kernel::Matern32.of_r2(r * r) - (1.0 + SQRT3 * r) * (-SQRT3 * r).exp()).abs() < 1e-15
        );
    }

    #[test]
    fn derivatives_in_r2_match_finite_differences() {
        for k in [
            Kernel::Exponential,
            Kernel::Matern32,
            Kernel::Matern52,
            Kernel::SquaredExponential,
        ] {
            for r2 in [0.01, 0.3, 1.0, 2.5] {
                let h = 1e-7;
                let fd = (k.of_r2(r2 + h) - k.of_r2(r2 - h)) / (2.0 * h);
                assert!(
                    (fd - k.d_of_r2(r2)).abs() < 1e-6,
                    "{k:?} at {r2}: {fd} vs {}",
                    k.d_of_r2(r2)
                );
            }
        }
    }
}
