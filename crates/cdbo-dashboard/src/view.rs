//! What the page shows of a study or an experiment, as JSON: the best reward against laps per
//! method (for a grid, the mean over seeds with a band of ± one standard error), each lap's
//! reward and failure, and the policy curves π(x) = clamp(wᵀφ(x), −1, 1) (Eq. 1) of the best
//! and the latest trial.

use cdbo::Result;
use cdbo::experiment::record::RunRecord;
use cdbo::experiment::summary;
use cdbo::policy::RkhsPolicy;
use cdbo::study::{StudyConfig, Trial};
use serde::Serialize;

/// Points at which a policy curve is drawn, x = i / (POLICY_POINTS − 1).
pub const POLICY_POINTS: usize = 201;

/// A learning curve: the best reward after each lap, and its band.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurveView {
    /// The method (study) or the cell `track m{kernels} method` (experiment).
    pub label: String,
    /// The optimiser.
    pub method: String,
    /// Runs behind the curve (1 for a study).
    pub runs: usize,
    /// Mean best reward after lap k + 1 (m/s).
    pub mean: Vec<f64>,
    /// Lower edge of the band: mean − standard error (the mean for one run).
    pub lo: Vec<f64>,
    /// Upper edge of the band: mean + standard error.
    pub hi: Vec<f64>,
}

/// One lap.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LapView {
    /// 1-based lap (trial id for a study).
    pub lap: i64,
    /// Reward L/T (m/s), 0 for a failed lap.
    pub reward: f64,
    /// Lap time (s) of a completed lap.
    pub lap_time_s: Option<f64>,
    /// Why the lap failed.
    pub failure: Option<String>,
    /// Where it failed (lap fraction).
    pub x_fail: Option<f64>,
}

/// A policy curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PolicyView {
    /// Which policy (`best, trial 12, 31.20 m/s`).
    pub label: String,
    /// The trial (study) or run (experiment) it belongs to, for the map.
    pub key: String,
    /// Pedal a at x = i / (POLICY_POINTS − 1).
    pub pedal: Vec<f64>,
}

/// A run of a grid, to choose in the page.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunView {
    /// `forza-m50-cdbo-r0`.
    pub id: String,
    /// The best reward of the run (m/s).
    pub best: f64,
    /// Laps driven.
    pub laps: usize,
}

/// Everything the page draws for one source.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct View {
    /// Laps told (study) or driven by the finished runs (experiment).
    pub laps_total: usize,
    /// Best reward against laps, per method or cell.
    pub curves: Vec<CurveView>,
    /// The laps of the study, or of the chosen run of an experiment.
    pub laps: Vec<LapView>,
    /// The best and the latest policy.
    pub policies: Vec<PolicyView>,
    /// The runs of an experiment (empty for a study).
    pub runs: Vec<RunView>,
    /// The track a study's laps are driven on, if it recorded one (each run of an experiment
    /// names its own).
    pub track: Option<String>,
}

fn curve_of(pedal: &RkhsPolicy) -> Vec<f64> {
    (0..POLICY_POINTS)
        .map(|i| pedal.action(i as f64 / (POLICY_POINTS - 1) as f64))
        .collect()
}

fn policy_view(
    label: String,
    key: String,
    weights: &[f64],
    lengthscale: f64,
) -> Result<PolicyView> {
    let policy = RkhsPolicy::new(weights.to_vec(), lengthscale)?;
    Ok(PolicyView {
        label,
        key,
        pedal: curve_of(&policy),
    })
}

/// A study: its told laps in order, the best-so-far curve, the best and the latest told
/// trial's policy.
pub fn study(config: &StudyConfig, trials: &[Trial]) -> Result<View> {
    let told: Vec<&Trial> = trials.iter().filter(|t| t.reward.is_some()).collect();
    let laps: Vec<LapView> = told
        .iter()
        .map(|t| LapView {
            lap: t.id,
            reward: t.reward.unwrap_or(0.0),
            lap_time_s: t.lap_time_s,
            failure: t.failure.clone(),
            x_fail: t.x_fail,
        })
        .collect();
    let best_so_far: Vec<f64> = laps
        .iter()
        .scan(f64::NEG_INFINITY, |best, l| {
            *best = best.max(l.reward);
            Some(*best)
        })
        .collect();
    let curves = vec![CurveView {
        label: config.method.to_string(),
        method: config.method.to_string(),
        runs: 1,
        lo: best_so_far.clone(),
        hi: best_so_far.clone(),
        mean: best_so_far,
    }];
    let best = told
        .iter()
        .fold(None, |best: Option<&&Trial>, t| match best {
            Some(b) if b.reward >= t.reward => best,
            _ => Some(t),
        });
    let mut policies = Vec::new();
    for (what, trial) in [("best", best), ("latest", told.last())] {
        if let Some(t) = trial {
            let label = format!("{what}: trial {}, {:.2} m/s", t.id, t.reward.unwrap_or(0.0));
            // The pedal's block: with a learned line, the weights are [w_a, w_d].
            let pedal = config.policy(&t.weights)?.policy.pedal;
            policies.push(policy_view(
                label,
                t.id.to_string(),
                &pedal.weights,
                pedal.lengthscale,
            )?);
        }
    }
    Ok(View {
        laps_total: laps.len(),
        curves,
        laps,
        policies,
        runs: Vec::new(),
        track: config.track.clone(),
    })
}

/// An experiment: the mean best-so-far curve of each cell with a band of ± one standard error
/// over its seeds, the laps of the chosen run (the best run if none is chosen), and the best
/// policies of the best run and the chosen one.
pub fn experiment(records: &[RunRecord], chosen: Option<&str>) -> Result<View> {
    let curves = summary::curves(records)
        .into_iter()
        .map(|((track, kernels, method), c)| CurveView {
            label: format!("{track} m{kernels} {method}"),
            lo: c.mean.iter().zip(&c.se).map(|(m, s)| m - s).collect(),
            hi: c.mean.iter().zip(&c.se).map(|(m, s)| m + s).collect(),
            mean: c.mean,
            method,
            runs: c.runs,
        })
        .collect();
    let best = records
        .iter()
        .max_by(|a, b| a.best_reward_mps.total_cmp(&b.best_reward_mps));
    let shown = chosen
        .and_then(|id| records.iter().find(|r| r.spec.id() == id))
        .or(best);
    let laps = shown.map_or_else(Vec::new, |r| {
        r.laps
            .iter()
            .map(|l| LapView {
                lap: l.lap as i64,
                reward: l.reward_mps,
                lap_time_s: l.lap_time_s,
                failure: l.failure.map(|f| f.name().to_owned()),
                x_fail: l.x_fail,
            })
            .collect()
    });
    let mut policies = Vec::new();
    for (what, run) in [("best run", best), ("chosen run", shown)] {
        if let Some(r) = run {
            let label = format!("{what}: {}, {:.2} m/s", r.spec.id(), r.best_reward_mps);
            let pedal = r.best_policy()?.policy.pedal;
            policies.push(policy_view(
                label,
                r.spec.id(),
                &pedal.weights,
                pedal.lengthscale,
            )?);
        }
    }
    Ok(View {
        track: shown.map(|r| r.spec.track.clone()),
        laps_total: records.iter().map(|r| r.laps.len()).sum(),
        curves,
        laps,
        policies,
        runs: records
            .iter()
            .map(|r| RunView {
                id: r.spec.id(),
                best: r.best_reward_mps,
                laps: r.laps.len(),
            })
            .collect(),
    })
}
