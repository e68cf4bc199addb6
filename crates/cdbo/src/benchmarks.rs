//! Standard test functions for the optimisers, written as rewards to maximise
//! (the negated function), on the box [lower, upper] of each.

/// Hartmann-6 on [0, 1]⁶, minimum −3.32237 at (0.20169, 0.150011, 0.476874, 0.275332,
/// 0.311652, 0.6573); returned negated (maximum 3.32237).
pub fn hartmann6(x: &[f64]) -> f64 {
    const ALPHA: [f64; 4] = [1.0, 1.2, 3.0, 3.2];
    const A: [[f64; 6]; 4] = [
        [10.0, 3.0, 17.0, 3.5, 1.7, 8.0],
        [0.05, 10.0, 17.0, 0.1, 8.0, 14.0],
        [3.0, 3.5, 1.7, 10.0, 17.0, 8.0],
        [17.0, 8.0, 0.05, 10.0, 0.1, 14.0],
    ];
    const P: [[f64; 6]; 4] = [
        [0.1312, 0.1696, 0.5569, 0.0124, 0.8283, 0.5886],
        [0.2329, 0.4135, 0.8307, 0.3736, 0.1004, 0.9991],
        [0.2348, 0.1451, 0.3522, 0.2883, 0.3047, 0.6650],
        [0.4047, 0.8828, 0.8732, 0.5743, 0.1091, 0.0381],
    ];
    (0..4)
        .map(|i| {
            ALPHA[i]
                * (-(0..6)
                    .map(|j| A[i][j] * (x[j] - P[i][j]).powi(2))
                    .sum::<f64>())
                .exp()
        })
        .sum()
}

/// Branin on [0, 1]² (rescaled from x₁ ∈ [−5, 10], x₂ ∈ [0, 15]), minimum 0.397887 at three
/// points, e.g. (π, 2.275) → (0.542773, 0.151667); returned negated.
pub fn branin(u: &[f64]) -> f64 {
    use std::f64::consts::PI;
    let (x1, x2) = (15.0 * u[0] - 5.0, 15.0 * u[1]);
    let b = 5.1 / (4.0 * PI * PI);
    let c = 5.0 / PI;
    let t = 1.0 / (8.0 * PI);
    -((x2 - b * x1 * x1 + c * x1 - 6.0).powi(2) + 10.0 * (1.0 - t) * x1.cos() + 10.0)
}

/// Rosenbrock in any dimension, Σ 100(x_{i+1} − x_i²)² + (1 − x_i)², minimum 0 at (1, …, 1);
/// returned negated.
pub fn rosenbrock(x: &[f64]) -> f64 {
    -x.windows(2)
        .map(|w| 100.0 * (w[1] - w[0] * w[0]).powi(2) + (1.0 - w[0]).powi(2))
        .sum::<f64>()
}

/// Ackley in any dimension, minimum 0 at the origin; returned negated.
pub fn ackley(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let sq = x.iter().map(|v| v * v).sum::<f64>() / n;
    let cos = x
        .iter()
        .map(|v| (std::f64::consts::TAU * v).cos())
        .sum::<f64>()
        / n;
    -(-20.0 * (-0.2 * sq.sqrt()).exp() - cos.exp() + 20.0 + std::f64::consts::E)
}

/// A test problem as the optimisers meet it: a reward to maximise over a box around a start.
#[derive(Debug, Clone)]
pub struct Problem {
    /// Name.
    pub name: String,
    /// The start point w₀ (the box's centre).
    pub start: Vec<f64>,
    /// Half-width of the box.
    pub radius: f64,
    /// Dimensions that matter (for functions embedded in more dimensions).
    effective: Vec<usize>,
    reward: Reward,
}

/// A reward function of the effective coordinates.
type Reward = fn(&[f64]) -> f64;

/// The problems [`Problem::by_name`] knows.
pub const PROBLEMS: &[&str] = &["hartmann6", "branin", "rosenbrock", "ackley"];

impl Problem {
    /// `hartmann6` and `branin` (embedded in `dims` ≥ 6 or 2 dimensions on [0, 1], start 0.5),
    /// `rosenbrock` and `ackley` (on [start − 2, start + 2], starts −0.5 and 1.2).
    pub fn by_name(name: &str, dims: usize) -> Option<Problem> {
        let all: Vec<usize> = (0..dims).collect();
        let (start, radius, reward, effective) = match name {
            "hartmann6" if dims >= 6 => (
                0.5,
                0.5,
                hartmann6 as Reward,
                (0..6).map(|k| k * dims / 6 + (dims / 12)).collect(),
            ),
            "branin" if dims >= 2 => (0.5, 0.5, branin as Reward, vec![dims / 3, (2 * dims) / 3]),
            "rosenbrock" if dims >= 2 => (-0.5, 2.0, rosenbrock as Reward, all),
            "ackley" if dims >= 1 => (1.2, 2.0, ackley as Reward, all),
            _ => return None,
        };
        Some(Problem {
            name: name.to_owned(),
            start: vec![start; dims],
            radius,
            effective,
            reward,
        })
    }

    /// The reward at w.
    pub fn reward(&self, w: &[f64]) -> f64 {
        let x: Vec<f64> = self.effective.iter().map(|&d| w[d]).collect();
        (self.reward)(&x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn optima_have_their_published_values() {
        let h = hartmann6(&[0.20169, 0.150011, 0.476874, 0.275332, 0.311652, 0.6573]);
        assert!((h - 3.32237).abs() < 1e-4, "{h}");
        let b = branin(&[(std::f64::consts::PI + 5.0) / 15.0, 2.275 / 15.0]);
        assert!((b + 0.397887).abs() < 1e-6, "{b}");
        assert_eq!(rosenbrock(&[1.0; 20]), 0.0);
        assert!(ackley(&[0.0; 20]).abs() < 1e-12);
        assert!(rosenbrock(&[0.0; 20]) < -18.0 && ackley(&[1.0; 20]) < -3.0);
    }
}
