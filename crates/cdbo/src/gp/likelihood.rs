//! The log marginal likelihood, its gradient in the log hyperparameters, and maximum-
//! likelihood estimation within bounds.
//!
//! log p(z) = −½(z − m)ᵀα − Σᵢ log Lᵢᵢ − (n/2) log 2π, and for any hyperparameter θ
//! ∂ log p/∂θ = ½ tr((ααᵀ − K⁻¹) ∂K/∂θ), with, for the log hyperparameters,
//! ∂K/∂log σ_f² = K_f (the noise-free part), ∂K/∂log σ_n² = σ_n²I,
//! ∂Kᵢⱼ/∂log l_d = σ_f²·κ′(r²ᵢⱼ)·(−2(w_id − w_jd)²/l_d²).

use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::{Accum, Mat, Par};
use serde::{Deserialize, Serialize};

use super::{GaussianProcess, Hyper};
use crate::error::Result;

/// The log marginal likelihood of the GP's observations under its hyperparameters.
pub fn log_likelihood(gp: &GaussianProcess) -> f64 {
    let n = gp.len();
    let l = gp.cholesky();
    let m = gp.mean();
    let fit: f64 = gp
        .values()
        .iter()
        .zip(gp.alpha())
        .map(|(z, a)| (z - m) * a)
        .sum();
    let logdet: f64 = (0..n).map(|i| l[(i, i)].ln()).sum();
    -0.5 * fit - logdet - 0.5 * n as f64 * (2.0 * std::f64::consts::PI).ln()
}

/// The gradient of [`log_likelihood`] in (log l₁, …, log l_L, log σ_f², log σ_n²); the last
/// entry is present only when `with_noise`.
///
/// With W = ααᵀ − K⁻¹ and, for i ≠ j, cᵢⱼ = Wᵢⱼ·σ_f²κ′(r²ᵢⱼ): ∂/∂log σ_f² = ½ Σᵢⱼ Wᵢⱼ(K_f)ᵢⱼ,
/// and for the ARD length-scales ∂/∂log l_d = −s_d Σᵢⱼ cᵢⱼ(x_id − x_jd)²
/// = −2s_d [Σᵢ x_id² Σⱼ cᵢⱼ − Σᵢ x_id (CX)_id] (s_d = 1/l_d²), one matrix product for all d,
/// with X centred in each dimension (the differences are unchanged and cancel less).
pub fn log_likelihood_gradient(gp: &GaussianProcess, with_noise: bool) -> Vec<f64> {
    let n = gp.len();
    let dim = gp.dim();
    let h = gp.hyper();
    let inv_l2 = gp.inv_l2();
    // K⁻¹ = L⁻ᵀL⁻¹, its upper triangle only, from the triangular factors.
    let mut linv = Mat::<f64>::identity(n, n);
    solve_lower_triangular_in_place(gp.cholesky(), linv.as_mut(), Par::Seq);
    let mut kinv = Mat::<f64>::zeros(n, n);
    triangular::matmul(
        kinv.as_mut(),
        BlockStructure::TriangularUpper,
        Accum::Replace,
        linv.transpose(),
        BlockStructure::TriangularUpper,
        linv.as_ref(),
        BlockStructure::TriangularLower,
        1.0,
        Par::Seq,
    );
    let a = gp.alpha();
    let nl = h.lengthscales.len();
    let ard = nl > 1;
    let mut grad = vec![0.0; nl + 1 + usize::from(with_noise)];
    let columns = gp.inputs_by_dim();
    let mut c = Mat::<f64>::zeros(if ard { n } else { 0 }, if ard { n } else { 0 });
    let (mut r2, mut kf, mut dk) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut trace_w = 0.0;
    for i in 0..n {
        let m = i + 1;
        gp.sq_dists_to_earlier(&columns, i, &mut r2[..i]);
        r2[i] = 0.0;
        h.kernel
            .values_and_slopes(&r2[..m], h.signal_var, &mut kf[..m], &mut dk[..m]);
        // K⁻¹ is symmetric: row i up to the diagonal is column i's head (upper triangle).
        let kinv_i = &kinv.col_as_slice(i)[..m];
        for j in 0..m {
            let w = a[i] * a[j] - kinv_i[j];
            if i == j {
                grad[nl] += 0.5 * w * kf[j];
                trace_w += w;
                continue;
            }
            grad[nl] += w * kf[j];
            if ard {
                let cij = w * dk[j];
                c[(i, j)] = cij;
                c[(j, i)] = cij;
            } else {
                grad[0] += w * dk[j] * (-2.0 * r2[j]);
            }
        }
    }
    if ard {
        let means: Vec<f64> = columns
            .chunks_exact(n)
            .map(|col| col.iter().sum::<f64>() / n as f64)
            .collect();
        let x = Mat::from_fn(n, dim, |j, d| columns[d * n + j] - means[d]);
        let mut cx = Mat::<f64>::zeros(n, dim);
        faer::linalg::matmul::matmul(cx.as_mut(), Accum::Replace, &c, &x, 1.0, Par::Seq);
        let row_sums: Vec<f64> = (0..n).map(|i| c.col_as_slice(i).iter().sum()).collect();
        for (d, g) in grad[..dim].iter_mut().enumerate() {
            let (xd, cxd) = (x.col_as_slice(d), cx.col_as_slice(d));
            let t: f64 = (0..n).map(|i| xd[i] * (xd[i] * row_sums[i] - cxd[i])).sum();
            *g = -2.0 * inv_l2[d] * t;
        }
    }
    if with_noise {
        grad[nl + 1] = 0.5 * trace_w * h.noise_var;
    }
    grad
}

/// Box bounds of the hyperparameters searched by [`fit`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bounds {
    /// Smallest and largest length-scale.
    pub lengthscale: (f64, f64),
    /// Smallest and largest signal variance.
    pub signal_var: (f64, f64),
    /// Noise-variance bounds; `None` keeps σ_n² fixed.
    pub noise_var: Option<(f64, f64)>,
}

/// Maximises the log marginal likelihood from the GP's current hyperparameters by projected
/// gradient ascent with Adam steps in log space (step 0.1, `iterations` steps); keeps the best
/// point met. Returns the best log likelihood.
pub fn fit(gp: &mut GaussianProcess, bounds: &Bounds, iterations: usize) -> Result<f64> {
    if gp.len() < 2 {
        return Ok(log_likelihood(gp));
    }
    let with_noise = bounds.noise_var.is_some();
    let start = gp.hyper().clone();
    let to_theta = |h: &Hyper| {
        let mut t: Vec<f64> = h.lengthscales.iter().map(|l| l.ln()).collect();
        t.push(h.signal_var.ln());
        if with_noise {
            t.push(h.noise_var.max(1e-12).ln());
        }
        t
    };
    let nl = start.lengthscales.len();
    let lo: Vec<f64> = (0..nl)
        .map(|_| bounds.lengthscale.0.ln())
        .chain([bounds.signal_var.0.ln()])
        .chain(bounds.noise_var.map(|b| b.0.max(1e-12).ln()))
        .collect();
    let hi: Vec<f64> = (0..nl)
        .map(|_| bounds.lengthscale.1.ln())
        .chain([bounds.signal_var.1.ln()])
        .chain(bounds.noise_var.map(|b| b.1.ln()))
        .collect();
    let from_theta = |t: &[f64]| Hyper {
        lengthscales: t[..nl].iter().map(|v| v.exp()).collect(),
        signal_var: t[nl].exp(),
        noise_var: if with_noise {
            t[nl + 1].exp()
        } else {
            start.noise_var
        },
        ..start.clone()
    };
    let mut theta: Vec<f64> = to_theta(&start)
        .iter()
        .zip(lo.iter().zip(&hi))
        .map(|(t, (a, b))| t.clamp(*a, *b))
        .collect();
    gp.set_hyper(from_theta(&theta))?;
    let mut best = (log_likelihood(gp), theta.clone());
    let (mut m, mut v) = (vec![0.0; theta.len()], vec![0.0; theta.len()]);
    let (b1, b2, step) = (0.9f64, 0.999f64, 0.1);
    for it in 1..=iterations {
        let g = log_likelihood_gradient(gp, with_noise);
        for k in 0..theta.len() {
            m[k] = b1 * m[k] + (1.0 - b1) * g[k];
            v[k] = b2 * v[k] + (1.0 - b2) * g[k] * g[k];
            let mh = m[k] / (1.0 - b1.powi(it as i32));
            let vh = v[k] / (1.0 - b2.powi(it as i32));
            theta[k] = (theta[k] + step * mh / (vh.sqrt() + 1e-8)).clamp(lo[k], hi[k]);
        }
        gp.set_hyper(from_theta(&theta))?;
        let ll = log_likelihood(gp);
        if ll > best.0 {
            best = (ll, theta.clone());
        }
    }
    gp.set_hyper(from_theta(&best.1))?;
    Ok(best.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gp::{Kernel, Mean};
    use faer::linalg::solvers::Solve;
    use rand::{Rng, SeedableRng};

    fn gp_with(h: Hyper, seed: u64) -> GaussianProcess {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let dim = 3;
        let mut gp = GaussianProcess::new(dim, h).unwrap();
        for _ in 0..25 {
            let w: Vec<f64> = (0..dim).map(|_| rng.random_range(-2.0..2.0)).collect();
            gp.add(&w, (w[0] * 1.5).sin() + 0.3 * w[1]).unwrap();
        }
        gp
    }

    #[test]
    fn gradient_matches_finite_differences() {
        for (kernel, ard) in [
            (Kernel::Exponential, true),
            (Kernel::Matern52, true),
            (Kernel::SquaredExponential, false),
            (Kernel::Matern32, false),
        ] {
            let ls = if ard { vec![0.8, 1.3, 2.0] } else { vec![1.1] };
            let h = Hyper {
                kernel,
                lengthscales: ls,
                signal_var: 1.5,
                noise_var: 0.05,
                mean: Mean::Constant,
            };
            let gp = gp_with(h.clone(), 11);
            let g = log_likelihood_gradient(&gp, true);
            let nl = h.lengthscales.len();
            for (k, gk) in g.iter().enumerate() {
                let eps = 1e-6;
                let shifted = |delta: f64| {
                    let mut hh = h.clone();
                    match k {
                        k if k < nl => hh.lengthscales[k] *= delta.exp(),
                        k if k == nl => hh.signal_var *= delta.exp(),
                        _ => hh.noise_var *= delta.exp(),
                    }
                    let mut g2 = gp.clone();
                    g2.set_hyper(hh).unwrap();
                    log_likelihood(&g2)
                };
                let fd = (shifted(eps) - shifted(-eps)) / (2.0 * eps);
                assert!(
                    (fd - gk).abs() < 1e-5 * fd.abs().max(1.0),
                    "{kernel:?} θ{k}: {fd} vs {gk}"
                );
            }
        }
    }

    #[test]
    fn likelihood_equals_the_gaussian_density() {
        let h = Hyper {
            kernel: Kernel::Matern32,
            lengthscales: vec![1.0],
            signal_var: 1.0,
            noise_var: 0.1,
            mean: Mean::Zero,
        };
        let gp = gp_with(h, 5);
        // log N(z; 0, K) by the determinant and inverse of K computed independently.
        let n = gp.len();
        let mut k = gp.gram();
        for i in 0..n {
            k[(i, i)] += 0.1;
        }
        let llt = k.llt(faer::Side::Lower).unwrap();
        let z = Mat::from_fn(n, 1, |i, _| gp.values()[i]);
        let sol = llt.solve(&z);
        let quad: f64 = (0..n).map(|i| z[(i, 0)] * sol[(i, 0)]).sum();
        let logdet: f64 = (0..n).map(|i| 2.0 * llt.L()[(i, i)].ln()).sum();
        let expected =
            -0.5 * quad - 0.5 * logdet - 0.5 * n as f64 * (2.0 * std::f64::consts::PI).ln();
        assert!((log_likelihood(&gp) - expected).abs() < 1e-9 * expected.abs());
    }

    #[test]
    fn fitting_raises_the_likelihood_within_bounds() {
        let h = Hyper {
            kernel: Kernel::Exponential,
            lengthscales: vec![5.0, 5.0, 5.0],
            signal_var: 0.1,
            noise_var: 0.0,
            mean: Mean::Constant,
        };
        let mut gp = gp_with(h, 9);
        let before = log_likelihood(&gp);
        let bounds = Bounds {
            lengthscale: (0.1, 4.0),
            signal_var: (0.01, 10.0),
            noise_var: None,
        };
        let after = fit(&mut gp, &bounds, 60).unwrap();
        assert!(after > before + 1.0, "{before} -> {after}");
        assert!((log_likelihood(&gp) - after).abs() < 1e-9);
        assert!(
            gp.hyper()
                .lengthscales
                .iter()
                .all(|l| (0.1..=4.0 + 1e-9).contains(l))
        );
        // The irrelevant third input gets a longer length-scale than the first.
        assert!(gp.hyper().lengthscales[2] > gp.hyper().lengthscales[0]);
    }
}
