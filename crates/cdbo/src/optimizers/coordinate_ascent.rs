//! Stochastic coordinate ascent of the acquisition (paper Alg. 1).
//!
//! From w = w*, the axes are shuffled and h is maximised along one axis at a time with the
//! others fixed, inside the search box. Along axis i only one term of each squared distance to
//! the n observations changes, r²ⱼ(v) = r²ⱼ − sᵢ(wᵢ − Xⱼᵢ)² + sᵢ(v − Xⱼᵢ)² (sᵢ = 1/lᵢ²), so a
//! candidate costs O(n) kernel values plus one triangular solve. Each axis gets a coarse scan of
//! `scan` evenly spaced values (one batched solve), then a COBYLA polish from the best of them
//! and the current value (the paper's per-axis optimiser), stopping at the evaluation budget.
//! Every axis is polished, not only those whose scan improved: skipping the others saves
//! little time and loses lap speed (docs/results/design.md).

use rand::seq::SliceRandom;

use super::SearchBox;
use crate::acquisition::Acquisition;
use crate::gp::GaussianProcess;

/// Settings of the coordinate ascent.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AxisSearch {
    /// Passes over all axes (default 1).
    pub sweeps: usize,
    /// Evenly spaced values scanned per axis before the polish.
    pub scan: usize,
    /// COBYLA evaluations per axis, its first (the start, already scanned) included.
    pub polish: usize,
    /// Acquisition evaluations per suggestion, at most (the paper's 50,000).
    pub budget: usize,
    /// Uniform random points of the box scored (one batch) before the ascent, which starts
    /// from the best of them and the best observation: a global first look for acquisitions
    /// whose maxima lie far from the best point (REMBO's expected improvement). 0 in CDBO.
    #[serde(default)]
    pub random_starts: usize,
}

impl Default for AxisSearch {
    fn default() -> Self {
        AxisSearch {
            sweeps: 1,
            scan: 12,
            polish: 6,
            budget: 50_000,
            random_starts: 0,
        }
    }
}

/// The result of one ascent.
#[derive(Debug, Clone, PartialEq)]
pub struct Ascent {
    /// The maximiser found.
    pub point: Vec<f64>,
    /// Its acquisition value.
    pub value: f64,
    /// Its posterior variance.
    pub var: f64,
    /// Acquisition evaluations spent.
    pub evaluations: usize,
}

/// A function maximised one axis at a time: scores candidate values of one coordinate with the
/// others fixed at `point`, as (value, posterior variance).
pub trait AxisObjective {
    /// Scores of `values` for coordinate `axis` of `point`.
    fn along(&self, point: &[f64], axis: usize, values: &[f64]) -> Vec<(f64, f64)>;

    /// Called when coordinate `axis` of the point moves from `from` to `to` (for caches).
    fn moved(&mut self, _axis: usize, _from: f64, _to: f64) {}
}

/// The acquisition of a GP as an [`AxisObjective`], caching the squared distances r²ⱼ of the
/// current point to every observation, and the observations by axis (column d holds every
/// observation's coordinate d, so that a scan along d reads contiguous memory).
pub struct GpAcquisition<'a> {
    gp: &'a GaussianProcess,
    acq: Acquisition,
    best: f64,
    r2: Vec<f64>,
    columns: Vec<f64>,
    variance_floor: f64,
}

impl<'a> GpAcquisition<'a> {
    /// The acquisition at `point` (its distances are computed once here).
    pub fn new(gp: &'a GaussianProcess, acq: Acquisition, point: &[f64]) -> GpAcquisition<'a> {
        let best = gp.best_value();
        let r2 = (0..gp.len())
            .map(|j| crate::gp::scaled_sq_dist(point, gp.input(j), gp.inv_l2()))
            .collect();
        GpAcquisition {
            gp,
            acq,
            best,
            r2,
            columns: gp.inputs_by_dim(),
            variance_floor: f64::NEG_INFINITY,
        }
    }

    /// Scores −∞ wherever the posterior variance is at most `floor`: at an observation of a
    /// noise-free GP, where a lap would only repeat a known one.
    pub fn excluding_observed(self, floor: f64) -> GpAcquisition<'a> {
        GpAcquisition {
            variance_floor: floor,
            ..self
        }
    }

    fn column(&self, axis: usize) -> &[f64] {
        let n = self.gp.len();
        &self.columns[axis * n..(axis + 1) * n]
    }

    fn scale(&self, axis: usize) -> f64 {
        let s = self.gp.inv_l2();
        if s.len() == 1 { s[0] } else { s[axis] }
    }
}

impl AxisObjective for GpAcquisition<'_> {
    fn along(&self, point: &[f64], axis: usize, values: &[f64]) -> Vec<(f64, f64)> {
        let gp = self.gp;
        let n = gp.len();
        let h = gp.hyper();
        let (current, scale) = (point[axis], self.scale(axis));
        // Column-major n × B buffer of r², turned into kernel values in one vectorised pass.
        // rest_j = r²ⱼ − sᵢ(wᵢ − Xⱼᵢ)², the part of r²ⱼ that the candidates share.
        let xs = self.column(axis);
        let rest: Vec<f64> = self
            .r2
            .iter()
            .zip(xs)
            .map(|(r2, xj)| r2 - scale * (current - xj) * (current - xj))
            .collect();
        let mut buf = vec![0.0; n * values.len()];
        for (col, v) in buf.chunks_exact_mut(n).zip(values) {
            for ((out, rest), xj) in col.iter_mut().zip(&rest).zip(xs) {
                *out = rest + scale * (v - xj) * (v - xj);
            }
        }
        h.kernel.apply_in_place(&mut buf, h.signal_var);
        gp.predict_from_k(&mut buf)
            .into_iter()
            .map(|(m, v)| {
                let h = if v > self.variance_floor {
                    self.acq.value(m, v, self.best)
                } else {
                    f64::NEG_INFINITY
                };
                (h, v)
            })
            .collect()
    }

    fn moved(&mut self, axis: usize, from: f64, to: f64) {
        let s = self.scale(axis);
        let n = self.gp.len();
        let xs = &self.columns[axis * n..(axis + 1) * n];
        for (r, xj) in self.r2.iter_mut().zip(xs) {
            *r = (*r - s * (from - xj) * (from - xj) + s * (to - xj) * (to - xj)).max(0.0);
        }
    }
}

/// Maximises `objective` over the box by stochastic coordinate ascent from `start`.
pub fn maximise(
    objective: &mut impl AxisObjective,
    bounds: &SearchBox,
    start: &[f64],
    settings: &AxisSearch,
    rng: &mut impl rand::Rng,
) -> Ascent {
    let dim = start.len();
    let mut point = start.to_vec();
    bounds.clamp(&mut point);
    let (mut value, mut var) = objective.along(&point, 0, &[point[0]])[0];
    let mut evaluations = 1;
    let mut order: Vec<usize> = (0..dim).collect();
    'sweeps: for _ in 0..settings.sweeps.max(1) {
        order.shuffle(rng);
        for &i in &order {
            if evaluations >= settings.budget {
                break 'sweeps;
            }
            let (lo, hi) = (bounds.lower[i], bounds.upper[i]);
            // Coarse scan: one batched evaluation.
            let scan = settings
                .scan
                .max(2)
                .min(settings.budget - evaluations)
                .max(1);
            let grid: Vec<f64> = (0..scan)
                .map(|k| lo + (hi - lo) * k as f64 / (scan - 1).max(1) as f64)
                .collect();
            let scores = objective.along(&point, i, &grid);
            evaluations += grid.len();
            let (mut best_v, mut best_h, mut best_var) = (point[i], value, var);
            for (v, (hv, vv)) in grid.iter().zip(&scores) {
                if *hv > best_h {
                    (best_v, best_h, best_var) = (*v, *hv, *vv);
                }
            }
            // COBYLA polish from the best value (minimising −h).
            let polish = settings
                .polish
                .min(settings.budget.saturating_sub(evaluations));
            if polish >= 3 {
                // Every new point COBYLA tries is scored once; the best of them is kept. Its
                // first point is the start, whose score the scan already has.
                let tried = std::cell::Cell::new((0usize, best_v, best_h, best_var));
                let obj = &*objective;
                let p = &point;
                let start = (best_v, best_h);
                let f = |x: &[f64], _: &mut ()| {
                    let v = x[0].clamp(lo, hi);
                    if v == start.0 {
                        return (-start.1).min(f64::MAX);
                    }
                    let (hv, vv) = obj.along(p, i, &[v])[0];
                    let (count, bv, bh, bvar) = tried.get();
                    tried.set(if hv > bh {
                        (count + 1, v, hv, vv)
                    } else {
                        (count + 1, bv, bh, bvar)
                    });
                    (-hv).min(f64::MAX)
                };
                let step = (hi - lo) / (2.0 * (scan - 1).max(1) as f64);
                let cons: Vec<&dyn cobyla::Func<()>> = vec![];
                // Its own answer is among the points it tried, so only `tried` is read.
                let _ = cobyla::minimize(
                    f,
                    &[best_v],
                    &[(lo, hi)],
                    &cons,
                    (),
                    polish,
                    cobyla::RhoBeg::All(step),
                    None,
                );
                let count;
                (count, best_v, best_h, best_var) = tried.get();
                evaluations += count;
            }
            if best_v != point[i] {
                objective.moved(i, point[i], best_v);
                point[i] = best_v;
                (value, var) = (best_h, best_var);
            }
        }
    }
    Ascent {
        point,
        value,
        var,
        evaluations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// h(w) = −Σ cᵢ(wᵢ − tᵢ)², separable and concave, maximum 0 at t.
    struct Bowl {
        target: Vec<f64>,
        curvature: Vec<f64>,
    }

    impl AxisObjective for Bowl {
        fn along(&self, point: &[f64], axis: usize, values: &[f64]) -> Vec<(f64, f64)> {
            let rest: f64 = (0..point.len())
                .filter(|&d| d != axis)
                .map(|d| self.curvature[d] * (point[d] - self.target[d]).powi(2))
                .sum();
            values
                .iter()
                .map(|v| {
                    (
                        -(rest + self.curvature[axis] * (v - self.target[axis]).powi(2)),
                        0.0,
                    )
                })
                .collect()
        }
    }

    #[test]
    fn finds_the_exact_maximum_of_separable_concave_functions() {
        let dim = 30;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let target: Vec<f64> = (0..dim)
            .map(|d| ((d * 37 % 11) as f64 / 11.0 - 0.5) * 1.7)
            .collect();
        let mut bowl = Bowl {
            target: target.clone(),
            curvature: (0..dim).map(|d| 0.5 + d as f64).collect(),
        };
        let bounds = SearchBox {
            lower: vec![-1.0; dim],
            upper: vec![1.0; dim],
        };
        let a = maximise(
            &mut bowl,
            &bounds,
            &vec![0.0; dim],
            &AxisSearch {
                polish: 30,
                ..AxisSearch::default()
            },
            &mut rng,
        );
        for (d, (got, want)) in a.point.iter().zip(&target).enumerate() {
            assert!((got - want).abs() < 1e-4, "axis {d}: {got} vs {want}");
        }
        assert!(a.value > -1e-6 && a.evaluations <= 50_000);
        // A target outside the box ends on the box.
        let mut outside = Bowl {
            target: vec![3.0; dim],
            curvature: vec![1.0; dim],
        };
        let a = maximise(
            &mut outside,
            &bounds,
            &vec![0.0; dim],
            &AxisSearch::default(),
            &mut rng,
        );
        assert!(a.point.iter().all(|v| (*v - 1.0).abs() < 1e-12));
    }

    #[test]
    fn respects_the_evaluation_budget() {
        let dim = 50;
        let mut bowl = Bowl {
            target: vec![0.3; dim],
            curvature: vec![1.0; dim],
        };
        let bounds = SearchBox {
            lower: vec![-1.0; dim],
            upper: vec![1.0; dim],
        };
        let settings = AxisSearch {
            budget: 200,
            ..AxisSearch::default()
        };
        let a = maximise(
            &mut bowl,
            &bounds,
            &vec![0.0; dim],
            &settings,
            &mut rand_chacha::ChaCha8Rng::seed_from_u64(1),
        );
        assert!(
            a.evaluations <= 200 + settings.scan + settings.polish + 1,
            "{}",
            a.evaluations
        );
    }
}
