//! Gaussian-process regression of the reward over policy weights (paper eq. 3–7).
//!
//! With K = k(W, W) + (σ_n² + jitter)·I = LLᵀ and α = K⁻¹(z − m):
//! μ(w*) = m + k(w*, W)·α and σ²(w*) = k(w*, w*) − vᵀv with v = L⁻¹k(W, w*).
//! Observations are added in O(n²) by extending L with one row, in place (no refactorisation,
//! no copy of L); the jitter is the smallest of 0, 1e-10, 1e-9, … that keeps L finite, raised only when needed
//! and reported by [`GaussianProcess::jitter`].

pub(crate) mod fit_in_flight;
pub mod kernel;
pub mod likelihood;

use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::{Mat, MatMut, Par, Side};
use serde::{Deserialize, Serialize};

pub use kernel::{Kernel, scaled_sq_dist};

use crate::error::{Error, Result};
use crate::simd::TriangularRows;

/// The prior mean.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Mean {
    /// m = 0 (the paper).
    Zero,
    /// m = the average of the observed values.
    Constant,
}

/// Hyperparameters: kernel shape, length-scales, signal and noise variance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Hyper {
    /// Kernel shape.
    pub kernel: Kernel,
    /// Length-scales: one (isotropic) or one per dimension (ARD).
    pub lengthscales: Vec<f64>,
    /// Signal variance σ_f².
    pub signal_var: f64,
    /// Observation noise variance σ_n² (the paper: 0, the simulator is deterministic).
    pub noise_var: f64,
    /// Prior mean.
    pub mean: Mean,
}

impl Hyper {
    /// 1/l_d² for each length-scale.
    pub fn inv_l2(&self) -> Vec<f64> {
        self.lengthscales.iter().map(|l| 1.0 / (l * l)).collect()
    }
}

/// Jitter levels tried in turn when the factor would not be positive definite.
const JITTERS: [f64; 8] = [0.0, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4];

/// A GP with its Cholesky factor kept up to date.
#[derive(Debug, Clone)]
pub struct GaussianProcess {
    dim: usize,
    hyper: Hyper,
    inv_l2: Vec<f64>,
    /// Inputs, row-major n × dim.
    x: Vec<f64>,
    y: Vec<f64>,
    mean: f64,
    /// Lower Cholesky factor of K, by columns, for faer's blocked solves (several points, α,
    /// the likelihood). Its capacity doubles as it fills, so a new observation writes one row
    /// in place.
    chol: Mat<f64>,
    /// The same factor by rows, for one-point solves (the coordinate ascent's inner loop); a
    /// new observation appends a row. Both layouts are kept: L by rows alone makes a
    /// suggestion slower and changes faer's order of summation for α (docs/results/design.md).
    rows: TriangularRows,
    alpha: Vec<f64>,
    jitter: f64,
}

impl GaussianProcess {
    /// An empty GP over `dim`-dimensional inputs.
    pub fn new(dim: usize, hyper: Hyper) -> Result<GaussianProcess> {
        check_hyper(dim, &hyper)?;
        Ok(GaussianProcess {
            dim,
            inv_l2: hyper.inv_l2(),
            hyper,
            x: Vec::new(),
            y: Vec::new(),
            mean: 0.0,
            chol: Mat::zeros(0, 0),
            rows: TriangularRows::default(),
            alpha: Vec::new(),
            jitter: 0.0,
        })
    }

    /// Input dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of observations.
    pub fn len(&self) -> usize {
        self.y.len()
    }

    /// Whether there are no observations.
    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }

    /// The hyperparameters.
    pub fn hyper(&self) -> &Hyper {
        &self.hyper
    }

    /// 1/l_d² of the current length-scales.
    pub fn inv_l2(&self) -> &[f64] {
        &self.inv_l2
    }

    /// The jitter added to the diagonal (0 unless needed for a finite factor).
    pub fn jitter(&self) -> f64 {
        self.jitter
    }

    /// The prior mean in use.
    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// The i-th input.
    pub fn input(&self, i: usize) -> &[f64] {
        &self.x[i * self.dim..(i + 1) * self.dim]
    }

    /// All inputs, row-major.
    pub fn inputs(&self) -> &[f64] {
        &self.x
    }

    /// The observed values.
    pub fn values(&self) -> &[f64] {
        &self.y
    }

    /// The largest observed value (−∞ with no observations): the incumbent of EI.
    pub fn best_value(&self) -> f64 {
        self.y.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    /// α = K⁻¹(z − m).
    pub fn alpha(&self) -> &[f64] {
        &self.alpha
    }

    /// The lower Cholesky factor L of K.
    pub(crate) fn cholesky(&self) -> faer::MatRef<'_, f64> {
        self.chol.as_ref()
    }

    /// k(a, b) = σ_f²·κ(r²).
    #[inline]
    pub fn k(&self, a: &[f64], b: &[f64]) -> f64 {
        self.hyper.signal_var * self.hyper.kernel.of_r2(scaled_sq_dist(a, b, &self.inv_l2))
    }

    /// Adds one observation in O(n²): L gains the row [lᵀ, d] with Ll = k(W, w) and
    /// d = √(k(w, w) + σ_n² + jitter − lᵀl).
    pub fn add(&mut self, w: &[f64], z: f64) -> Result<()> {
        self.check_point(w)?;
        if !z.is_finite() {
            return Err(Error::invalid_value("the observed value", z, "finite"));
        }
        let n = self.len();
        let mut l: Vec<f64> = (0..n).map(|i| self.k(self.input(i), w)).collect();
        let ll = self.forward_substitute_norm2(&mut l);
        let d2 = self.hyper.signal_var + self.hyper.noise_var + self.jitter - ll;
        self.x.extend_from_slice(w);
        self.y.push(z);
        if d2 > 1e-12 * self.hyper.signal_var && d2.is_finite() {
            let d = d2.sqrt();
            let capacity = (n + 1).next_power_of_two();
            self.chol.reserve(capacity, capacity);
            self.chol.resize_with(n + 1, n + 1, |_, _| 0.0);
            for (j, lj) in l.iter().enumerate() {
                self.chol[(n, j)] = *lj;
            }
            self.chol[(n, n)] = d;
            l.push(d);
            self.rows.push_row(&l);
            self.update_alpha();
            Ok(())
        } else {
            // The new point nearly duplicates an old one: refactor with more jitter.
            self.refactor().or_else(|e| {
                self.x.truncate(n * self.dim);
                self.y.pop();
                self.refactor()?;
                Err(e)
            })
        }
    }

    /// Replaces the hyperparameters and refactors (O(n³)).
    pub fn set_hyper(&mut self, hyper: Hyper) -> Result<()> {
        check_hyper(self.dim, &hyper)?;
        self.inv_l2 = hyper.inv_l2();
        self.hyper = hyper;
        self.jitter = 0.0;
        self.refactor()
    }

    /// The covariance matrix of the observations, without noise or jitter.
    pub fn gram(&self) -> Mat<f64> {
        let n = self.len();
        let columns = self.inputs_by_dim();
        let mut k = Mat::zeros(n, n);
        let mut row = vec![0.0; n];
        for i in 0..n {
            let row = &mut row[..=i];
            self.sq_dists_to_earlier(&columns, i, &mut row[..i]);
            row[i] = 0.0;
            self.hyper.kernel.apply_in_place(row, self.hyper.signal_var);
            for (j, v) in row.iter().enumerate() {
                k[(i, j)] = *v;
                k[(j, i)] = *v;
            }
        }
        k
    }

    /// The inputs by dimension: entry d·n + j is coordinate d of observation j.
    pub(crate) fn inputs_by_dim(&self) -> Vec<f64> {
        let n = self.len();
        (0..self.dim)
            .flat_map(|d| (0..n).map(move |j| self.x[j * self.dim + d]))
            .collect()
    }

    /// The scaled squared distances of observation i to observations 0..i, into `out`
    /// (length i): each summed over the dimensions in order, as [`scaled_sq_dist`] does, and
    /// vectorised across the observations (`columns` from [`Self::inputs_by_dim`]).
    pub(crate) fn sq_dists_to_earlier(&self, columns: &[f64], i: usize, out: &mut [f64]) {
        let n = self.len();
        let xi = self.input(i);
        out.fill(0.0);
        crate::simd::wide(
            #[inline(always)]
            || {
                for (d, (&xid, col)) in xi.iter().zip(columns.chunks_exact(n)).enumerate() {
                    let col = &col[..out.len()];
                    if self.inv_l2.len() == 1 {
                        for (o, x) in out.iter_mut().zip(col) {
                            *o += (xid - x) * (xid - x);
                        }
                    } else {
                        let s = self.inv_l2[d];
                        for (o, x) in out.iter_mut().zip(col) {
                            *o += (xid - x) * (xid - x) * s;
                        }
                    }
                }
                if let [s] = self.inv_l2[..] {
                    out.iter_mut().for_each(|o| *o *= s);
                }
            },
        )
    }

    /// Factors K from scratch, raising the jitter until it succeeds.
    fn refactor(&mut self) -> Result<()> {
        let n = self.len();
        let gram = self.gram();
        let start = JITTERS
            .iter()
            .position(|&j| j >= self.jitter)
            .unwrap_or(JITTERS.len() - 1);
        for &jitter in &JITTERS[start..] {
            let add = self.hyper.noise_var + jitter * self.hyper.signal_var;
            let k = Mat::from_fn(n, n, |i, j| gram[(i, j)] + if i == j { add } else { 0.0 });
            if let Ok(llt) = k.llt(Side::Lower) {
                let l = llt.L().to_owned();
                if (0..n).all(|i| l[(i, i)].is_finite() && l[(i, i)] > 0.0) {
                    self.rows = TriangularRows::from_fn(n, |i, j| l[(i, j)]);
                    self.chol = l;
                    self.jitter = jitter * self.hyper.signal_var;
                    self.update_alpha();
                    return Ok(());
                }
            }
        }
        Err(Error::Numerical(format!(
            "the GP covariance of {n} points is not positive definite even with jitter 1e-4·σ_f²"
        )))
    }

    fn update_alpha(&mut self) {
        let n = self.len();
        self.mean = match self.hyper.mean {
            Mean::Zero => 0.0,
            Mean::Constant => self.y.iter().sum::<f64>() / n.max(1) as f64,
        };
        let mut a = Mat::from_fn(n, 1, |i, _| self.y[i] - self.mean);
        solve_lower_triangular_in_place(self.cholesky(), a.as_mut(), Par::Seq);
        faer::linalg::triangular_solve::solve_upper_triangular_in_place(
            self.cholesky().transpose(),
            a.as_mut(),
            Par::Seq,
        );
        self.alpha = (0..n).map(|i| a[(i, 0)]).collect();
    }

    /// Posterior mean and variance at one point.
    pub fn predict(&self, w: &[f64]) -> (f64, f64) {
        let mut k: Vec<f64> = (0..self.len()).map(|i| self.k(self.input(i), w)).collect();
        self.predict_from_k(&mut k)[0]
    }

    /// Posterior mean and variance at many points (row-major, `dim` columns each).
    pub fn predict_batch(&self, points: &[f64]) -> Vec<(f64, f64)> {
        let mut k: Vec<f64> = points
            .chunks_exact(self.dim)
            .flat_map(|p| (0..self.len()).map(move |i| self.k(self.input(i), p)))
            .collect();
        self.predict_from_k(&mut k)
    }

    /// The joint posterior at many points (row-major, `dim` columns each): the means and the
    /// covariance k(P, P) − VᵀV with V = L⁻¹k(W, P). Kernel matrices come from one matrix
    /// product each, r² = ‖a‖² + ‖b‖² − 2a·b in scaled coordinates (rounding of order
    /// 1e-16·‖a‖², harmless for sampling).
    pub fn predict_joint(&self, points: &[f64]) -> (Vec<f64>, Mat<f64>) {
        let (n, b) = (self.len(), points.len() / self.dim);
        let mut v = self.cov_by_product(&self.x, points);
        let means = (0..b)
            .map(|j| self.mean + (0..n).map(|i| v[(i, j)] * self.alpha[i]).sum::<f64>())
            .collect();
        if n > 0 {
            solve_lower_triangular_in_place(self.cholesky(), v.as_mut(), Par::Seq);
        }
        let mut cov = self.cov_by_product(points, points);
        faer::linalg::matmul::matmul(
            cov.as_mut(),
            faer::Accum::Add,
            v.transpose(),
            v.as_ref(),
            -1.0,
            Par::Seq,
        );
        (means, cov)
    }

    /// k(A, B) for row-major point sets, by one matrix product of the scaled coordinates.
    fn cov_by_product(&self, a: &[f64], b: &[f64]) -> Mat<f64> {
        let d = self.dim;
        let scale: Vec<f64> = (0..d)
            .map(|k| self.inv_l2[if self.inv_l2.len() == 1 { 0 } else { k }].sqrt())
            .collect();
        let scaled = |p: &[f64]| Mat::from_fn(p.len() / d, d, |i, k| p[i * d + k] * scale[k]);
        let (sa, sb) = (scaled(a), scaled(b));
        let norms = |m: &Mat<f64>| -> Vec<f64> {
            (0..m.nrows())
                .map(|i| (0..d).map(|k| m[(i, k)] * m[(i, k)]).sum())
                .collect()
        };
        let (na, nb) = (norms(&sa), norms(&sb));
        let dot = &sa * sb.transpose();
        let (ra, rb) = (na.len(), nb.len());
        let mut r2: Vec<f64> = (0..ra * rb)
            .map(|idx| {
                let (i, j) = (idx % ra, idx / ra);
                na[i] + nb[j] - 2.0 * dot[(i, j)]
            })
            .collect();
        self.hyper
            .kernel
            .apply_in_place(&mut r2, self.hyper.signal_var);
        Mat::from_fn(ra, rb, |i, j| r2[j * ra + i])
    }

    /// Posterior means and variances from cross-covariances k(W, w*), one column of n = len()
    /// values per point, stored one after another (overwritten by L⁻¹k):
    /// μ = m + kᵀα, σ² = σ_f² − ‖L⁻¹k‖².
    pub(crate) fn predict_from_k(&self, k: &mut [f64]) -> Vec<(f64, f64)> {
        let n = self.len();
        if n == 0 {
            let points = k.len().max(1);
            return vec![(self.mean, self.hyper.signal_var); points];
        }
        let means: Vec<f64> = k
            .chunks_exact(n)
            .map(|col| self.mean + crate::simd::dot(col, &self.alpha))
            .collect();
        let norms = if k.len() == n {
            vec![self.forward_substitute_norm2(k)]
        } else {
            // Several columns: faer's blocked triangular solve is faster here.
            let points = k.len() / n;
            let kv = MatMut::from_column_major_slice_mut(k, n, points);
            solve_lower_triangular_in_place(self.cholesky(), kv, Par::Seq);
            k.chunks_exact(n).map(|x| crate::simd::dot(x, x)).collect()
        };
        means
            .into_iter()
            .zip(norms)
            .map(|(m, vv)| (m, (self.hyper.signal_var - vv).max(0.0)))
            .collect()
    }

    /// Overwrites k (len() values) by x = L⁻¹k and returns ‖x‖² (see
    /// [`TriangularRows::forward_substitute`]).
    fn forward_substitute_norm2(&self, k: &mut [f64]) -> f64 {
        self.rows.forward_substitute(k)
    }

    fn check_point(&self, w: &[f64]) -> Result<()> {
        if w.len() != self.dim {
            return Err(Error::dimension("weights", self.dim, w.len()));
        }
        if let Some(i) = w.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid_value(format!("weight {i}"), w[i], "finite"));
        }
        Ok(())
    }
}

fn check_hyper(dim: usize, h: &Hyper) -> Result<()> {
    if dim == 0 {
        return Err(Error::too_small("GP input dimensions", 0, 1));
    }
    if h.lengthscales.len() != 1 && h.lengthscales.len() != dim {
        return Err(Error::invalid_value(
            format!("the number of length-scales for {dim} dimensions"),
            h.lengthscales.len(),
            format!("1 or {dim}"),
        ));
    }
    if h.lengthscales.iter().any(|l| !(l.is_finite() && *l > 0.0))
        || !(h.signal_var.is_finite() && h.signal_var > 0.0)
        || !(h.noise_var.is_finite() && h.noise_var >= 0.0)
    {
        return Err(Error::invalid_value(
            "the GP hyperparameters",
            format!("{h:?}"),
            "positive and finite",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn random_gp(
        n: usize,
        dim: usize,
        kernel: Kernel,
        ard: bool,
        seed: u64,
    ) -> (GaussianProcess, rand_chacha::ChaCha8Rng) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let lengthscales = if ard {
            (0..dim).map(|_| rng.random_range(0.5..2.0)).collect()
        } else {
            vec![1.3]
        };
        let hyper = Hyper {
            kernel,
            lengthscales,
            signal_var: 2.0,
            noise_var: 0.01,
            mean: Mean::Constant,
        };
        let mut gp = GaussianProcess::new(dim, hyper).unwrap();
        for _ in 0..n {
            let w: Vec<f64> = (0..dim).map(|_| rng.random_range(-2.0..2.0)).collect();
            let z = w.iter().map(|v| v.sin()).sum::<f64>() + 5.0;
            gp.add(&w, z).unwrap();
        }
        (gp, rng)
    }

    /// Naive O(n³) reference: explicit inverse of K by Gauss–Jordan elimination.
    fn naive_predict(gp: &GaussianProcess, w: &[f64]) -> (f64, f64) {
        let n = gp.len();
        let mut k = gp.gram();
        for i in 0..n {
            k[(i, i)] += gp.hyper().noise_var + gp.jitter();
        }
        let mut inv = Mat::<f64>::identity(n, n);
        for c in 0..n {
            let p = (c..n)
                .max_by(|&a, &b| k[(a, c)].abs().total_cmp(&k[(b, c)].abs()))
                .unwrap();
            for j in 0..n {
                let (t, u) = (k[(c, j)], inv[(c, j)]);
                k[(c, j)] = k[(p, j)];
                k[(p, j)] = t;
                inv[(c, j)] = inv[(p, j)];
                inv[(p, j)] = u;
            }
            let d = k[(c, c)];
            for j in 0..n {
                k[(c, j)] /= d;
                inv[(c, j)] /= d;
            }
            for r in 0..n {
                if r != c {
                    let f = k[(r, c)];
                    for j in 0..n {
                        k[(r, j)] -= f * k[(c, j)];
                        inv[(r, j)] -= f * inv[(c, j)];
                    }
                }
            }
        }
        let ks: Vec<f64> = (0..n).map(|i| gp.k(gp.input(i), w)).collect();
        let m = gp.mean();
        let mu = m
            + (0..n)
                .map(|i| {
                    (0..n)
                        .map(|j| ks[i] * inv[(i, j)] * (gp.values()[j] - m))
                        .sum::<f64>()
                })
                .sum::<f64>();
        let var = gp.hyper().signal_var
            - (0..n)
                .map(|i| (0..n).map(|j| ks[i] * inv[(i, j)] * ks[j]).sum::<f64>())
                .sum::<f64>();
        (mu, var)
    }

    #[test]
    fn predictions_equal_the_naive_reference() {
        for (kernel, ard) in [
            (Kernel::Exponential, true),
            (Kernel::Matern52, false),
            (Kernel::SquaredExponential, true),
        ] {
            let (gp, mut rng) = random_gp(40, 5, kernel, ard, 7);
            for _ in 0..10 {
                let w: Vec<f64> = (0..5).map(|_| rng.random_range(-2.0..2.0)).collect();
                let (mu, var) = gp.predict(&w);
                let (rm, rv) = naive_predict(&gp, &w);
                assert!(
                    (mu - rm).abs() <= 1e-9 * rm.abs().max(1.0),
                    "{kernel:?} mean {mu} vs {rm}"
                );
                assert!(
                    (var - rv).abs() <= 1e-9 * gp.hyper().signal_var,
                    "{kernel:?} var {var} vs {rv}"
                );
            }
            let batch: Vec<f64> = (0..15).map(|i| i as f64 * 0.1 - 0.7).collect();
            let b = gp.predict_batch(&batch);
            for j in 0..3 {
                let one = gp.predict(&batch[j * 5..(j + 1) * 5]);
                assert!((b[j].0 - one.0).abs() < 1e-12 && (b[j].1 - one.1).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn the_grown_factor_equals_a_fresh_one() {
        let (mut gp, _) = random_gp(60, 4, Kernel::Exponential, true, 3);
        let grown = gp.cholesky().to_owned();
        gp.set_hyper(gp.hyper().clone()).unwrap();
        let fresh = gp.cholesky();
        for i in 0..60 {
            for j in 0..=i {
                assert!((grown[(i, j)] - fresh[(i, j)]).abs() < 1e-10, "L[{i},{j}]");
            }
        }
    }

    #[test]
    fn noiseless_duplicates_get_jitter_and_interpolation_holds() {
        let hyper = Hyper {
            kernel: Kernel::Exponential,
            lengthscales: vec![1.0],
            signal_var: 1.0,
            noise_var: 0.0,
            mean: Mean::Zero,
        };
        let mut gp = GaussianProcess::new(2, hyper).unwrap();
        gp.add(&[0.0, 0.0], 1.0).unwrap();
        gp.add(&[1.0, 0.5], 2.0).unwrap();
        let (mu, var) = gp.predict(&[1.0, 0.5]);
        assert!(
            (mu - 2.0).abs() < 1e-9 && var < 1e-9,
            "noise-free interpolation: {mu} {var}"
        );
        assert_eq!(gp.jitter(), 0.0);
        gp.add(&[1.0, 0.5], 2.0).unwrap();
        assert!(gp.jitter() > 0.0 && gp.jitter() <= 1e-4);
    }

    #[test]
    fn bad_input_is_refused_and_changes_nothing() {
        let (mut gp, _) = random_gp(5, 3, Kernel::Matern32, false, 1);
        let before = gp.alpha().to_vec();
        assert!(gp.add(&[0.0, 1.0], 1.0).is_err());
        assert!(gp.add(&[0.0, 1.0, f64::NAN], 1.0).is_err());
        assert!(gp.add(&[0.0, 1.0, 2.0], f64::INFINITY).is_err());
        assert_eq!(gp.len(), 5);
        assert_eq!(gp.alpha(), &before[..]);
    }
}
