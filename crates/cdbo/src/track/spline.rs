//! Periodic cubic splines, used to turn a closed polyline into a smooth closed curve.
//!
//! For knots tᵢ with spacing hᵢ = tᵢ₊₁ − tᵢ and values yᵢ (indices mod n), the second
//! derivatives Mᵢ solve the cyclic tridiagonal system
//! hᵢ₋₁Mᵢ₋₁ + 2(hᵢ₋₁ + hᵢ)Mᵢ + hᵢMᵢ₊₁ = 6[(yᵢ₊₁ − yᵢ)/hᵢ − (yᵢ − yᵢ₋₁)/hᵢ₋₁],
//! solved exactly with the Sherman–Morrison correction of the Thomas algorithm.

/// A closed cubic spline y(t), t ∈ [t₀, t₀ + period).
#[derive(Debug, Clone)]
pub struct PeriodicSpline {
    t: Vec<f64>,
    y: Vec<f64>,
    m: Vec<f64>,
    period: f64,
}

impl PeriodicSpline {
    /// Fits a spline through (tᵢ, yᵢ); `period` is t of the knot after the last (where y wraps
    /// to y₀). Needs at least 3 knots with strictly increasing t.
    pub fn new(t: &[f64], y: &[f64], period: f64) -> PeriodicSpline {
        let n = t.len();
        assert!(n >= 3 && y.len() == n, "a periodic spline needs >= 3 knots");
        let h = |i: usize| {
            if i + 1 < n {
                t[i + 1] - t[i]
            } else {
                period - t[n - 1] + t[0]
            }
        };
        let yy = |i: usize| y[i % n];
        let mut sub = vec![0.0; n];
        let mut diag = vec![0.0; n];
        let mut sup = vec![0.0; n];
        let mut rhs = vec![0.0; n];
        for i in 0..n {
            let hp = h((i + n - 1) % n);
            let hi = h(i);
            sub[i] = hp;
            diag[i] = 2.0 * (hp + hi);
            sup[i] = hi;
            rhs[i] = 6.0 * ((yy(i + 1) - y[i]) / hi - (y[i] - yy(i + n - 1)) / hp);
        }
        let m = solve_cyclic(&sub, &diag, &sup, &rhs);
        PeriodicSpline {
            t: t.to_vec(),
            y: y.to_vec(),
            m,
            period,
        }
    }

    /// Value, first and second derivative at t (wrapped into the period).
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        let n = self.t.len();
        let t = self.t[0] + (t - self.t[0]).rem_euclid(self.period);
        let i = match self.t.binary_search_by(|v| v.total_cmp(&t)) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        let (t0, t1) = (
            self.t[i],
            if i + 1 < n {
                self.t[i + 1]
            } else {
                self.t[0] + self.period
            },
        );
        let (y0, y1) = (self.y[i], self.y[(i + 1) % n]);
        let (m0, m1) = (self.m[i], self.m[(i + 1) % n]);
        let h = t1 - t0;
        let (a, b) = (t1 - t, t - t0);
        let c0 = y0 / h - m0 * h / 6.0;
        let c1 = y1 / h - m1 * h / 6.0;
        let v = m0 * a * a * a / (6.0 * h) + m1 * b * b * b / (6.0 * h) + c0 * a + c1 * b;
        let d1 = -m0 * a * a / (2.0 * h) + m1 * b * b / (2.0 * h) - c0 + c1;
        let d2 = (m0 * a + m1 * b) / h;
        (v, d1, d2)
    }
}

/// Solves a cyclic tridiagonal system: row i is sub[i]·x[i−1] + diag[i]·x[i] + sup[i]·x[i+1],
/// indices mod n (n ≥ 3).
fn solve_cyclic(sub: &[f64], diag: &[f64], sup: &[f64], rhs: &[f64]) -> Vec<f64> {
    let n = diag.len();
    // A = T + u vᵀ with u = (γ, 0, …, 0, sub₀·…), Sherman–Morrison.
    let gamma = -diag[0];
    let mut d = diag.to_vec();
    d[0] -= gamma;
    d[n - 1] -= sup[n - 1] * sub[0] / gamma;
    let x = solve_tridiagonal(sub, &d, sup, rhs);
    let mut u = vec![0.0; n];
    u[0] = gamma;
    u[n - 1] = sup[n - 1];
    let z = solve_tridiagonal(sub, &d, sup, &u);
    let fact = (x[0] + sub[0] * x[n - 1] / gamma) / (1.0 + z[0] + sub[0] * z[n - 1] / gamma);
    x.iter().zip(&z).map(|(xi, zi)| xi - fact * zi).collect()
}

/// Thomas algorithm for a plain tridiagonal system (sub[0] and sup[n−1] unused).
fn solve_tridiagonal(sub: &[f64], diag: &[f64], sup: &[f64], rhs: &[f64]) -> Vec<f64> {
    let n = diag.len();
    let mut c = vec![0.0; n];
    let mut x = vec![0.0; n];
    c[0] = sup[0] / diag[0];
    x[0] = rhs[0] / diag[0];
    for i in 1..n {
        let den = diag[i] - sub[i] * c[i - 1];
        c[i] = sup[i] / den;
        x[i] = (rhs[i] - sub[i] * x[i - 1]) / den;
    }
    for i in (0..n - 1).rev() {
        x[i] -= c[i] * x[i + 1];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn reproduces_a_periodic_function_and_its_derivatives() {
        let n = 64;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * TAU / n as f64).collect();
        let y: Vec<f64> = t.iter().map(|t| t.sin()).collect();
        let s = PeriodicSpline::new(&t, &y, TAU);
        for k in 0..200 {
            let x = k as f64 * 0.0731 - 3.0;
            let (v, d1, d2) = s.eval(x);
            assert!((v - x.sin()).abs() < 1e-5, "value at {x}");
            assert!((d1 - x.cos()).abs() < 1e-3, "slope at {x}");
            assert!((d2 + x.sin()).abs() < 2e-2, "curvature at {x}");
        }
    }

    #[test]
    fn interpolates_its_knots_with_uneven_spacing() {
        let t = [0.0, 0.5, 2.0, 2.5, 4.0];
        let y = [1.0, -2.0, 0.5, 3.0, 0.0];
        let s = PeriodicSpline::new(&t, &y, 5.0);
        for (ti, yi) in t.iter().zip(y) {
            assert!((s.eval(*ti).0 - yi).abs() < 1e-12);
        }
        // Continuity of the value and slope across the wrap.
        let (a, da, _) = s.eval(5.0 - 1e-9);
        let (b, db, _) = s.eval(0.0);
        assert!((a - b).abs() < 1e-7 && (da - db).abs() < 1e-6);
    }
}
