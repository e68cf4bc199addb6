//! The paper's policy (eq. 2–7): π_w(x) = clamp(wᵀφ(x), −1, 1), with φᵢ(x) = k(x, x̂ᵢ) a
//! Matérn-3/2 kernel, k(x, x′) = (1 + √3|x − x′|/l)·exp(−√3|x − x′|/l), at M regularly spaced
//! inducing points x̂ᵢ = i/(M − 1) on [0, 1].
//!
//! The initial weights fit a demonstration's (xⱼ, aⱼ) by ridge regression (eq. 8–9):
//! w₀ = [ΦᵀΦ + λI]⁻¹Φᵀa, Φⱼᵢ = φᵢ(xⱼ).
//!
//! The same block wᵀφ(x), unclamped, is a policy's line d(x) ([`super::actions`]).

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use serde::{Deserialize, Serialize};

use crate::drive::{Observation, Pedal};
use crate::error::{Error, Result};
use crate::gp::kernel::exp_nonpositive;

/// Default ridge factor λ.
pub const DEFAULT_RIDGE: f64 = 1e-3;

/// A policy in the RKHS of the Matérn-3/2 kernel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RkhsPolicy {
    /// Kernel length-scale l on the lap fraction x.
    pub lengthscale: f64,
    /// Weights w, one per inducing point.
    pub weights: Vec<f64>,
}

/// The paper's default length-scale: the spacing of the inducing points, 1/(M − 1).
pub fn default_lengthscale(kernels: usize) -> f64 {
    1.0 / (kernels.max(2) - 1) as f64
}

impl RkhsPolicy {
    /// A policy with given weights (M = weights.len() ≥ 2) and length-scale.
    pub fn new(weights: Vec<f64>, lengthscale: f64) -> Result<RkhsPolicy> {
        check_shape(weights.len(), lengthscale)?;
        if let Some(i) = weights.iter().position(|w| !w.is_finite()) {
            return Err(Error::invalid_value(
                format!("policy weight {i}"),
                weights[i],
                "finite",
            ));
        }
        Ok(RkhsPolicy {
            lengthscale,
            weights,
        })
    }

    /// Fits w₀ to a demonstration by ridge regression (paper eq. 9).
    pub fn fit(
        demo: &[(f64, f64)],
        kernels: usize,
        lengthscale: f64,
        ridge: f64,
    ) -> Result<RkhsPolicy> {
        check_shape(kernels, lengthscale)?;
        if demo.is_empty() {
            return Err(Error::too_small("demonstration (x, a) pairs", 0, 1));
        }
        if let Some((x, a)) = demo.iter().find(|(x, a)| !x.is_finite() || !a.is_finite()) {
            return Err(Error::invalid_value(
                "a demonstration pair",
                format!("(x {x}, a {a})"),
                "finite",
            ));
        }
        if !(ridge.is_finite() && ridge > 0.0) {
            return Err(Error::invalid_value("the ridge factor", ridge, "positive"));
        }
        let mut phi = vec![0.0; kernels];
        let mut gram = Mat::<f64>::zeros(kernels, kernels);
        let mut rhs = Mat::<f64>::zeros(kernels, 1);
        for &(x, a) in demo {
            features_into(x, lengthscale, &mut phi);
            for i in 0..kernels {
                rhs[(i, 0)] += phi[i] * a;
                for j in 0..=i {
                    gram[(i, j)] += phi[i] * phi[j];
                }
            }
        }
        for i in 0..kernels {
            gram[(i, i)] += ridge;
            for j in 0..i {
                gram[(j, i)] = gram[(i, j)];
            }
        }
        let llt = gram
            .llt(Side::Lower)
            .map_err(|e| Error::Numerical(format!("the ridge system is singular: {e:?}")))?;
        let w = llt.solve(&rhs);
        RkhsPolicy::new((0..kernels).map(|i| w[(i, 0)]).collect(), lengthscale)
    }

    /// Number of kernels M.
    pub fn kernels(&self) -> usize {
        self.weights.len()
    }

    /// wᵀφ(x), before clamping: the sum over all M kernels.
    pub fn raw(&self, x: f64) -> f64 {
        let h = 1.0 / (self.weights.len() - 1) as f64;
        self.weights
            .iter()
            .enumerate()
            .map(|(i, w)| w * matern32((x - i as f64 * h).abs() / self.lengthscale))
            .sum()
    }

    /// π(x) = clamp(wᵀφ(x), −1, 1).
    pub fn action(&self, x: f64) -> f64 {
        self.raw(x).clamp(-1.0, 1.0)
    }

    /// The policy prepared for driving: π(x) in O(1) per driver step ([`RkhsPedal`]).
    pub fn pedal(&self) -> RkhsPedal {
        RkhsPedal::new(self)
    }

    /// The (x, a) table at `points` evenly spaced x in [0, 1].
    pub fn table(&self, points: usize) -> Vec<(f64, f64)> {
        let n = points.max(2);
        (0..n)
            .map(|i| i as f64 / (n - 1) as f64)
            .map(|x| (x, self.action(x)))
            .collect()
    }
}

/// An [`RkhsPolicy`] prepared for driving: wᵀφ(x) exactly, whatever M, from two
/// exponentials.
///
/// With a = √3/l, h = 1/(M − 1) and x in the segment [x̂ₖ, x̂ₖ₊₁], t = x − x̂ₖ, s = x̂ₖ₊₁ − x,
/// the kernels left of x sum to e^(−at)·(Pₖ + at·Qₖ) and those right of it to
/// e^(−as)·(Uₖ₊₁ + as·Vₖ₊₁), where, with ρ = e^(−ah),
///
/// - Qₖ = wₖ + ρ·Qₖ₋₁,  Pₖ = wₖ + ρ·(Pₖ₋₁ + ah·Qₖ₋₁)  (from the left, P₀ = Q₀ = w₀),
/// - Vₖ = wₖ + ρ·Vₖ₊₁,  Uₖ = wₖ + ρ·(Uₖ₊₁ + ah·Vₖ₊₁)  (from the right),
///
/// since (1 + a(d + t))·e^(−a(d + t)) = e^(−at)·[(1 + ad)·e^(−ad) + at·e^(−ad)] for a kernel
/// at distance d from x̂ₖ. Both recursions shrink by ρ < 1, so they are stable. Outside
/// [0, 1] every kernel lies on one side: e^(−as)·(U₀ + as·V₀) with s = −x below 0, and
/// e^(−at)·(P_{M−1} + at·Q_{M−1}) with t = x − 1 above 1.
#[derive(Debug, Clone, PartialEq)]
pub struct RkhsPedal {
    /// a = √3/l.
    a: f64,
    /// Spacing h of the inducing points.
    h: f64,
    /// (Pₖ, Qₖ, Uₖ, Vₖ) per inducing point.
    sums: Vec<[f64; 4]>,
}

impl RkhsPedal {
    fn new(policy: &RkhsPolicy) -> RkhsPedal {
        let w = &policy.weights;
        let m = w.len();
        let h = 1.0 / (m - 1) as f64;
        let a = SQRT_3 / policy.lengthscale;
        let (rho, ah) = ((-a * h).exp(), a * h);
        let mut sums = vec![[0.0; 4]; m];
        let (mut p, mut q) = (0.0, 0.0);
        for (k, wk) in w.iter().enumerate() {
            (p, q) = (wk + rho * (p + ah * q), wk + rho * q);
            sums[k][0] = p;
            sums[k][1] = q;
        }
        let (mut u, mut v) = (0.0, 0.0);
        for (k, wk) in w.iter().enumerate().rev() {
            (u, v) = (wk + rho * (u + ah * v), wk + rho * v);
            sums[k][2] = u;
            sums[k][3] = v;
        }
        RkhsPedal { a, h, sums }
    }

    /// wᵀφ(x), before clamping.
    pub fn raw(&self, x: f64) -> f64 {
        let left = |t: f64, [p, q, ..]: [f64; 4]| exp_nonpositive(-t) * (p + t * q);
        let right = |s: f64, [.., u, v]: [f64; 4]| exp_nonpositive(-s) * (u + s * v);
        let last = self.sums.len() - 1;
        if x < 0.0 {
            return right(-self.a * x, self.sums[0]);
        }
        if x > 1.0 {
            return left(self.a * (x - 1.0), self.sums[last]);
        }
        let k = ((x / self.h) as usize).min(last - 1);
        let t = self.a * (x - k as f64 * self.h);
        let s = self.a * ((k + 1) as f64 * self.h - x);
        left(t, self.sums[k]) + right(s, self.sums[k + 1])
    }

    /// π(x) = clamp(wᵀφ(x), −1, 1).
    pub fn action(&self, x: f64) -> f64 {
        self.raw(x).clamp(-1.0, 1.0)
    }
}

impl Pedal for RkhsPedal {
    fn pedal(&mut self, obs: &Observation) -> f64 {
        self.action(obs.x)
    }
}

/// √3.
const SQRT_3: f64 = 1.732_050_807_568_877_2;

/// The Matérn-3/2 shape (1 + √3 u)·e^(−√3 u) of u = |x − x′|/l.
fn matern32(u: f64) -> f64 {
    let a = SQRT_3 * u;
    (1.0 + a) * (-a).exp()
}

/// φ(x) into `out` (length M).
pub fn features_into(x: f64, lengthscale: f64, out: &mut [f64]) {
    let m = out.len();
    for (i, o) in out.iter_mut().enumerate() {
        *o = matern32((x - i as f64 / (m - 1) as f64).abs() / lengthscale);
    }
}

/// The narrowest policy kernel (a fraction of the lap): a millionth, millimetres on any track.
/// Far narrower ones overflow: |x − xᵢ|/ℓ is infinite for a length-scale of 1e-308, and the
/// kernel (1 + √3·r)·e^(−√3·r) then NaN.
pub const MIN_LENGTHSCALE: f64 = 1e-6;

/// Refuses fewer than 2 kernels (or more than the size bound) and a length-scale that is not
/// finite or below [`MIN_LENGTHSCALE`].
pub(crate) fn check_shape(kernels: usize, lengthscale: f64) -> Result<()> {
    if kernels < 2 {
        return Err(Error::too_small("policy kernels", kernels, 2));
    }
    crate::sizes::KERNELS.checked(kernels)?;
    if !(lengthscale.is_finite() && lengthscale >= MIN_LENGTHSCALE) {
        return Err(Error::invalid_value(
            "the policy length-scale",
            format!("{lengthscale:?}"),
            format!("finite and at least {MIN_LENGTHSCALE:?} of the lap"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn features_peak_at_their_inducing_points() {
        let mut phi = vec![0.0; 11];
        features_into(0.3, 0.1, &mut phi);
        assert!((phi[3] - 1.0).abs() < 1e-15);
        assert!(phi[2] < 1.0 && (phi[2] - phi[4]).abs() < 1e-12);
    }

    #[test]
    fn ridge_fit_solves_the_normal_equations() {
        let demo: Vec<(f64, f64)> = (0..500)
            .map(|i| i as f64 / 499.0)
            .map(|x| (x, (6.0 * x).sin() * 0.8))
            .collect();
        let (m, l, lambda) = (12, default_lengthscale(12), 1e-3);
        let p = RkhsPolicy::fit(&demo, m, l, lambda).unwrap();
        // Gradient of ‖a − Φw‖² + λ‖w‖² vanishes: Φᵀ(Φw − a) + λw = 0.
        let mut grad = vec![0.0; m];
        let mut phi = vec![0.0; m];
        for &(x, a) in &demo {
            features_into(x, l, &mut phi);
            let r: f64 = phi.iter().zip(&p.weights).map(|(f, w)| f * w).sum::<f64>() - a;
            for (g, f) in grad.iter_mut().zip(&phi) {
                *g += f * r;
            }
        }
        for (i, (g, w)) in grad.iter().zip(&p.weights).enumerate() {
            assert!((g + lambda * w).abs() < 1e-8, "{i}: {}", g + lambda * w);
        }
        // And it fits: a smooth demonstration is reproduced closely.
        for &(x, a) in demo.iter().step_by(37) {
            assert!(
                (p.action(x) - a).abs() < 0.05,
                "x {x}: {} vs {a}",
                p.action(x)
            );
        }
        // wᵀφ(x) is the sum of the features.
        for x in [0.0, 0.123, 0.5, 0.999, 1.0] {
            features_into(x, l, &mut phi);
            let full: f64 = phi.iter().zip(&p.weights).map(|(f, w)| f * w).sum();
            assert!((p.raw(x) - full).abs() < 1e-14);
        }
    }

    /// The pedal's two-exponential form equals the direct sum over all kernels, for short
    /// and long length-scales, at the inducing points, between them and at the ends.
    #[test]
    fn pedal_equals_the_direct_sum() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for (m, l) in [
            (2, 0.5),
            (10, 1.0 / 9.0),
            (100, 1.0 / 99.0),
            (50, 0.3),
            (30, 0.002),
        ] {
            let weights = (0..m).map(|_| rng.random_range(-2.0..2.0)).collect();
            let policy = RkhsPolicy::new(weights, l).unwrap();
            let pedal = policy.pedal();
            let h = 1.0 / (m - 1) as f64;
            let xs = (0..=4000)
                .map(|i| i as f64 / 4000.0)
                .chain((0..m).map(|i| i as f64 * h))
                .chain([-0.05, -0.001, 1.001, 1.05]);
            for x in xs {
                let (fast, direct) = (pedal.raw(x), policy.raw(x));
                assert!(
                    (fast - direct).abs() < 1e-13,
                    "M {m}, l {l}, x {x}: {fast} vs {direct}"
                );
                assert_eq!(pedal.action(x), fast.clamp(-1.0, 1.0));
            }
        }
    }

    #[test]
    fn bad_input_is_refused() {
        assert!(RkhsPolicy::fit(&[], 10, 0.1, 1e-3).is_err());
        assert!(RkhsPolicy::fit(&[(0.5, 0.1)], 1, 0.1, 1e-3).is_err());
        assert!(RkhsPolicy::fit(&[(f64::NAN, 0.1)], 10, 0.1, 1e-3).is_err());
        assert!(RkhsPolicy::fit(&[(0.5, 0.1)], 10, -1.0, 1e-3).is_err());
        assert!(RkhsPolicy::new(vec![0.0, f64::INFINITY], 0.5).is_err());
        // A length-scale so small that |x − xᵢ|/ℓ overflows (the fuzzer's 9e-319) is refused,
        // naming the bound; the narrowest allowed gives finite actions everywhere.
        let e = RkhsPolicy::new(vec![0.1, 0.0], 9e-319)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("length-scale") && e.contains("at least 1e-6") && e.contains("9e-319"),
            "{e}"
        );
        let narrow = RkhsPolicy::new(vec![0.1, 0.0], MIN_LENGTHSCALE).unwrap();
        assert!(
            [0.0, 0.37, 1.0]
                .iter()
                .all(|&x| narrow.action(x).is_finite())
        );
    }
}
