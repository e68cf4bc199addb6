//! Bounded Levenberg–Marquardt on a residual vector, its Jacobian by forward differences.
//!
//! Minimises C(x) = |r(x)|² over the box lo ≤ x ≤ hi. At x, with J the forward-difference
//! Jacobian (J_ik = (r_i(x + h·e_k) − r_i(x)) / h, the step −h where +h would leave the box),
//! the step δ solves Marquardt's damped normal equations
//!
//!   (JᵀJ + λ·diag(JᵀJ)) δ = −Jᵀr,
//!
//! and x + δ, projected onto the box, is taken if it lowers C (λ ← λ/3), else λ ← 4λ and the
//! step is solved again. Gauss–Newton's curvature JᵀJ follows a long, narrow valley (two
//! parameters trading against each other) in a few steps where a method that models the cost
//! alone, such as COBYLA's linear models, zigzags across it; the damping falls back to
//! gradient steps, scaled per parameter, far from the minimum.

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};

/// The settings of [`minimize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// The first forward-difference step h (in x's units).
    pub h: f64,
    /// The smallest: h halves each time the search stalls (no step lowers the cost, or one
    /// moves less than `x_tol`), down to this.
    pub h_min: f64,
    /// Residual evaluations at most.
    pub max_evaluations: usize,
    /// Stop when a taken step moves no coordinate by more than this.
    pub x_tol: f64,
}

/// What [`minimize`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Minimum {
    /// The best point evaluated.
    pub x: Vec<f64>,
    /// C there.
    pub cost: f64,
    /// Residual evaluations made.
    pub evaluations: usize,
}

/// The initial damping λ, relative to JᵀJ's diagonal.
const LAMBDA_START: f64 = 1e-2;
/// Past this damping no step lowers the cost: the search stops.
const LAMBDA_MAX: f64 = 1e8;

/// Minimises |r(x)|² over the box `bounds` from `x0` (module documentation). `r` returns
/// residual vectors of one length; a non-finite cost counts as infinitely bad.
pub fn minimize(
    r: impl Fn(&[f64]) -> Vec<f64>,
    x0: &[f64],
    bounds: &[(f64, f64)],
    settings: &Settings,
) -> Minimum {
    let n = x0.len();
    let cost_of = |res: &[f64]| {
        let c: f64 = res.iter().map(|v| v * v).sum();
        if c.is_finite() { c } else { f64::INFINITY }
    };
    let clamp = |x: &mut [f64]| {
        for (v, &(lo, hi)) in x.iter_mut().zip(bounds) {
            *v = v.clamp(lo, hi);
        }
    };
    let mut x = x0.to_vec();
    clamp(&mut x);
    let mut res = r(&x);
    let mut cost = cost_of(&res);
    let mut evaluations = 1;
    let mut best = (x.clone(), cost);
    let mut lambda = LAMBDA_START;
    let mut h = settings.h;
    'outer: while evaluations + n < settings.max_evaluations {
        // The Jacobian, one column per coordinate.
        let mut jac = Mat::<f64>::zeros(res.len(), n);
        for k in 0..n {
            let mut xk = x.clone();
            let step = if x[k] + h <= bounds[k].1 { h } else { -h };
            xk[k] += step;
            let rk = r(&xk);
            evaluations += 1;
            for (i, (a, b)) in rk.iter().zip(&res).enumerate() {
                jac[(i, k)] = (a - b) / step;
            }
            // A difference step that happens to be better is kept, as any point evaluated.
            let ck = cost_of(&rk);
            if ck < best.1 {
                best = (xk, ck);
            }
        }
        let mut jtj = Mat::<f64>::zeros(n, n);
        let mut jtr = Mat::<f64>::zeros(n, 1);
        for i in 0..res.len() {
            for a in 0..n {
                jtr[(a, 0)] -= jac[(i, a)] * res[i];
                for b in 0..=a {
                    jtj[(a, b)] += jac[(i, a)] * jac[(i, b)];
                }
            }
        }
        let scale: Vec<f64> = {
            let top = (0..n).map(|a| jtj[(a, a)]).fold(0.0, f64::max);
            (0..n)
                .map(|a| jtj[(a, a)].max(1e-12 * top + 1e-300))
                .collect()
        };
        // Damped steps until one lowers the cost (the next Jacobian) or the search stalls at
        // this resolution (no step helps, or the one taken moved less than x_tol).
        let stalled = loop {
            if evaluations >= settings.max_evaluations {
                break 'outer;
            }
            if lambda > LAMBDA_MAX {
                break true;
            }
            let damped = Mat::<f64>::from_fn(n, n, |a, b| {
                let (i, j) = if a >= b { (a, b) } else { (b, a) };
                jtj[(i, j)] + if a == b { lambda * scale[a] } else { 0.0 }
            });
            let Ok(llt) = damped.llt(Side::Lower) else {
                lambda *= 4.0;
                continue;
            };
            let delta = llt.solve(&jtr);
            let mut trial: Vec<f64> = (0..n).map(|k| x[k] + delta[(k, 0)]).collect();
            clamp(&mut trial);
            let moved = trial
                .iter()
                .zip(&x)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            if moved == 0.0 {
                break true;
            }
            let trial_res = r(&trial);
            evaluations += 1;
            let trial_cost = cost_of(&trial_res);
            if trial_cost < cost {
                if trial_cost < best.1 {
                    best = (trial.clone(), trial_cost);
                }
                (x, res, cost) = (trial, trial_res, trial_cost);
                lambda = (lambda / 3.0).max(1e-9);
                break moved < settings.x_tol;
            }
            lambda *= 4.0;
        };
        if stalled {
            // A finer difference step, else the end.
            if h / 2.0 < settings.h_min {
                break;
            }
            h /= 2.0;
            lambda = LAMBDA_START;
        }
    }
    Minimum {
        x: best.0,
        cost: best.1,
        evaluations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SETTINGS: Settings = Settings {
        h: 1e-6,
        h_min: 1e-6,
        max_evaluations: 2000,
        x_tol: 1e-9,
    };

    /// Rosenbrock's banana as residuals (10(y − x²), 1 − x): its curved valley is the case the
    /// method is for; from the classic start (−1.2, 1) it reaches the minimum (1, 1).
    #[test]
    fn it_follows_rosenbrocks_valley_to_its_minimum() {
        let r = |x: &[f64]| vec![10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]];
        let m = minimize(r, &[-1.2, 1.0], &[(-2.0, 2.0), (-2.0, 2.0)], &SETTINGS);
        assert!(
            (m.x[0] - 1.0).abs() < 1e-5 && (m.x[1] - 1.0).abs() < 1e-5,
            "{m:?}"
        );
        assert!(m.cost < 1e-10, "{m:?}");
    }

    /// A linear least-squares problem is solved in one Gauss–Newton step (λ small): the
    /// answer is the normal equations' (closed form for the line through three points).
    #[test]
    fn a_linear_fit_is_the_normal_equations() {
        // y = a + b t through (0, 1), (1, 2), (2, 4): b = 1.5, a = 5/6.
        let data = [(0.0, 1.0), (1.0, 2.0), (2.0, 4.0)];
        let r = |x: &[f64]| data.iter().map(|(t, y)| x[0] + x[1] * t - y).collect();
        let m = minimize(r, &[0.0, 0.0], &[(-10.0, 10.0), (-10.0, 10.0)], &SETTINGS);
        assert!((m.x[0] - 5.0 / 6.0).abs() < 1e-4, "{m:?}");
        assert!((m.x[1] - 1.5).abs() < 1e-4, "{m:?}");
    }

    /// The box holds: the unconstrained minimum at x = 3 lies outside [−1, 2], the answer is
    /// its edge 2.
    #[test]
    fn the_box_holds() {
        let r = |x: &[f64]| vec![x[0] - 3.0];
        let m = minimize(r, &[0.0], &[(-1.0, 2.0)], &SETTINGS);
        assert_eq!(m.x, vec![2.0]);
        assert!((m.cost - 1.0).abs() < 1e-12);
    }
}
