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

/// e^x for x ≤ 0, branch-light so that loops over many kernel values vectorise: with
/// x = k·ln 2 + r, |r| ≤ ln 2 / 2, e^x = 2^k·Σ_{i≤12} rⁱ/i! (truncation below 2e-16, about one
/// ulp); 0 below −708.
#[inline(always)]
pub fn exp_nonpositive(x: f64) -> f64 {
    const LN2_HI: f64 = 0.693_147_180_369_123_8;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    const LOG2_E: f64 = std::f64::consts::LOG2_E;
    let x = x.max(-708.0);
    // Round to nearest by the 1.5·2⁵² trick (no libm call without SSE4.1).
    const ROUNDER: f64 = 6_755_399_441_055_744.0;
    let t = x * LOG2_E + ROUNDER;
    let k = t - ROUNDER;
    let r = (x - k * LN2_HI) - k * LN2_LO;
    // Estrin's scheme on the Taylor coefficients cᵢ = 1/i!: pairs cᵢ + cᵢ₊₁r, joined by r²,
    // r⁴ and r⁸, a dependency chain of four steps instead of Horner's twelve.
    let c = &EXP_TAYLOR;
    let (r2, pair) = (r * r, |i: usize| c[i] + c[i + 1] * r);
    let r4 = r2 * r2;
    let low = (pair(0) + pair(2) * r2) + (pair(4) + pair(6) * r2) * r4;
    let high = (pair(8) + pair(10) * r2) + c[12] * r4;
    let p = low + high * (r4 * r4);
    // 2^k from the integer k held in t's low mantissa bits: (bits + 1023) << 52 keeps
    // (k + 1023) mod 2¹² as the exponent field, without a float-to-integer conversion.
    p * f64::from_bits(t.to_bits().wrapping_add(1023) << 52)
}

/// 1/i! for i = 0, 1, …, 12.
const EXP_TAYLOR: [f64; 13] = [
    1.0,
    1.0,
    1.0 / 2.0,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5040.0,
    1.0 / 40_320.0,
    1.0 / 362_880.0,
    1.0 / 3_628_800.0,
    1.0 / 39_916_800.0,
    1.0 / 479_001_600.0,
];

const SQRT3: f64 = 1.732_050_807_568_877_2;
const SQRT5: f64 = 2.236_067_977_499_79;

impl Kernel {
    /// κ as a function of the squared scaled distance r² (avoids a square root for the SE kernel).
    #[inline]
    pub fn of_r2(self, r2: f64) -> f64 {
        match self {
            Kernel::Exponential => exp_nonpositive(-r2.sqrt()),
            Kernel::Matern32 => {
                let a = SQRT3 * r2.sqrt();
                (1.0 + a) * exp_nonpositive(-a)
            }
            Kernel::Matern52 => {
                let a = SQRT5 * r2.sqrt();
                (1.0 + a + a * a / 3.0) * exp_nonpositive(-a)
            }
            Kernel::SquaredExponential => exp_nonpositive(-0.5 * r2),
        }
    }

    /// Replaces each squared scaled distance r² in `values` by σ_f²·κ(r²), one kernel shape
    /// per call so that the loop vectorises (four wide with AVX2, see `crate::simd`).
    pub fn apply_in_place(self, values: &mut [f64], signal_var: f64) {
        crate::simd::wide(
            #[inline(always)]
            || self.apply_in_place_baseline(values, signal_var),
        )
    }

    #[inline(always)]
    fn apply_in_place_baseline(self, values: &mut [f64], signal_var: f64) {
        match self {
            Kernel::Exponential => values
                .iter_mut()
                .for_each(|v| *v = signal_var * exp_nonpositive(-v.max(0.0).sqrt())),
            Kernel::Matern32 => values.iter_mut().for_each(|v| {
                let a = SQRT3 * v.max(0.0).sqrt();
                *v = signal_var * (1.0 + a) * exp_nonpositive(-a);
            }),
            Kernel::Matern52 => values.iter_mut().for_each(|v| {
                let a = SQRT5 * v.max(0.0).sqrt();
                *v = signal_var * (1.0 + a + a * a / 3.0) * exp_nonpositive(-a);
            }),
            Kernel::SquaredExponential => values
                .iter_mut()
                .for_each(|v| *v = signal_var * exp_nonpositive(-0.5 * v.max(0.0))),
        }
    }

    /// For each squared scaled distance r² in `r2`, the kernel value σ_f²·κ(r²) into `values`
    /// and its slope σ_f²·dκ/d(r²) into `slopes` (for length-scale gradients), vectorised
    /// like [`Kernel::apply_in_place`]. Slopes: exponential −e^(−r)/(2r), unbounded at r = 0
    /// where every term it multiplies vanishes (0 is returned there); Matérn-3/2
    /// −(3/2)e^(−√3r); Matérn-5/2 −(5/6)(1 + √5r)e^(−√5r); squared exponential −½e^(−r²/2).
    pub fn values_and_slopes(
        self,
        r2: &[f64],
        signal_var: f64,
        values: &mut [f64],
        slopes: &mut [f64],
    ) {
        let out = values.iter_mut().zip(slopes.iter_mut()).zip(r2);
        crate::simd::wide(
            #[inline(always)]
            || match self {
                Kernel::Exponential => out.for_each(|((k, dk), v)| {
                    let r = v.max(0.0).sqrt();
                    let e = signal_var * exp_nonpositive(-r);
                    *k = e;
                    *dk = if r > 0.0 { -e / (2.0 * r) } else { 0.0 };
                }),
                Kernel::Matern32 => out.for_each(|((k, dk), v)| {
                    let a = SQRT3 * v.max(0.0).sqrt();
                    let e = signal_var * exp_nonpositive(-a);
                    *k = (1.0 + a) * e;
                    *dk = -1.5 * e;
                }),
                Kernel::Matern52 => out.for_each(|((k, dk), v)| {
                    let a = SQRT5 * v.max(0.0).sqrt();
                    let e = signal_var * exp_nonpositive(-a);
                    *k = (1.0 + a + a * a / 3.0) * e;
                    *dk = -(5.0 / 6.0) * (1.0 + a) * e;
                }),
                Kernel::SquaredExponential => out.for_each(|((k, dk), v)| {
                    let e = signal_var * exp_nonpositive(-0.5 * v.max(0.0));
                    *k = e;
                    *dk = -0.5 * e;
                }),
            },
        )
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
    fn the_exponential_is_accurate_to_an_ulp_or_two() {
        let mut worst: f64 = 0.0;
        for i in 0..200_000 {
            let x = -(i as f64) * 3.5e-3;
            let (a, b) = (exp_nonpositive(x), x.exp());
            if b > 1e-300 {
                worst = worst.max((a - b).abs() / b);
            }
        }
        assert!(worst < 5e-16, "worst relative error {worst:e}");
        assert_eq!(exp_nonpositive(0.0), 1.0);
        assert_eq!(exp_nonpositive(-1e6), 0.0f64.max(exp_nonpositive(-708.0)));
    }

    #[test]
    fn derivatives_in_r2_match_finite_differences() {
        for k in [
            Kernel::Exponential,
            Kernel::Matern32,
            Kernel::Matern52,
            Kernel::SquaredExponential,
        ] {
            let r2 = [0.01, 0.3, 1.0, 2.5];
            let (mut values, mut slopes) = ([0.0; 4], [0.0; 4]);
            k.values_and_slopes(&r2, 2.0, &mut values, &mut slopes);
            for ((r2, v), dk) in r2.iter().zip(values).zip(slopes) {
                let h = 1e-7;
                let fd = 2.0 * (k.of_r2(r2 + h) - k.of_r2(r2 - h)) / (2.0 * h);
                assert!((v - 2.0 * k.of_r2(*r2)).abs() < 1e-14);
                assert!((fd - dk).abs() < 1e-6, "{k:?} at {r2}: {fd} vs {dk}");
            }
        }
    }
}
