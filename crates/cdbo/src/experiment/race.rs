//! Learning to race one track (paper Sec. V): drive the demonstration, fit w₀, then optimise
//! the policy weights for a number of laps, one lap per evaluation.

use serde::{Deserialize, Serialize};

use crate::car::Car;
use crate::drive::demo::SpeedHold;
use crate::error::{Error, Result};
use crate::limit::{Limit, limit_lap};
use crate::policy::RkhsPolicy;
use crate::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use crate::sim::{FailureReason, LapResult, Simulator};
use crate::track::Track;

/// Settings of a race.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RaceConfig {
    /// Optimiser name (`cdbo`).
    pub method: String,
    /// Policy kernels M.
    pub kernels: usize,
    /// Laps (evaluations), the demonstration's fitted policy included.
    pub laps: usize,
    /// Seed of every random choice.
    pub seed: u64,
    /// UCB β.
    pub beta: f64,
    /// Demonstration speed (m/s).
    pub demo_speed: f64,
    /// The exploration scale σ₀ of every method ([`Settings::sigma0`]); `None`: the race
    /// default, 0.03.
    ///
    /// [`Settings::sigma0`]: crate::optimizers::Settings::sigma0
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma0: Option<f64>,
}

impl Default for RaceConfig {
    fn default() -> Self {
        RaceConfig {
            method: "cdbo".into(),
            kernels: 30,
            laps: 300,
            seed: 0,
            beta: crate::acquisition::ucb::DEFAULT_BETA,
            demo_speed: 15.0,
            sigma0: None,
        }
    }
}

/// One lap of the optimisation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LapRecord {
    /// 1-based lap number.
    pub lap: usize,
    /// Reward L/T (0 on failure).
    pub reward_mps: f64,
    /// Best reward so far.
    pub best_mps: f64,
    /// Lap time, if completed.
    pub lap_time_s: Option<f64>,
    /// Failure reason, if any.
    pub failure: Option<FailureReason>,
    /// Lap fraction where it failed.
    pub x_fail: Option<f64>,
    /// Seconds the optimiser spent choosing this lap's weights.
    pub optimizer_s: f64,
    /// Seconds the simulator spent on this lap.
    pub simulator_s: f64,
}

/// What a race produced.
#[derive(Debug, Clone)]
pub struct RaceOutcome {
    /// The demonstration lap.
    pub demo: LapResult,
    /// The demonstration's (x, a) pairs.
    pub demo_pairs: Vec<(f64, f64)>,
    /// The fitted initial policy.
    pub initial: RkhsPolicy,
    /// The best policy found.
    pub best: RkhsPolicy,
    /// Its reward.
    pub best_reward_mps: f64,
    /// Every optimisation lap.
    pub laps: Vec<LapRecord>,
    /// The limit lap.
    pub limit: Limit,
}

/// Drives the demonstration and records its (x, a) pairs at every driver step.
pub fn demonstrate(sim: &Simulator, speed: f64) -> (LapResult, Vec<(f64, f64)>) {
    let mut s = sim.clone();
    s.config.trace = true;
    let lap = s.lap(&mut SpeedHold::new(speed));
    let pairs = lap.trace.iter().map(|p| (p.x, p.pedal)).collect();
    (lap, pairs)
}

/// Runs a race; `progress` is called after every lap.
pub fn race(
    track: Track,
    car: &Car,
    config: &RaceConfig,
    progress: impl FnMut(&LapRecord),
) -> Result<RaceOutcome> {
    let limit = limit_lap(&track, car);
    let sim = Simulator::new(track, car);
    let (demo, demo_pairs) = demonstrate(&sim, config.demo_speed);
    race_with(
        &sim.track.name,
        (demo, demo_pairs),
        limit,
        config,
        |policy| Ok(sim.lap(&mut policy.pedal())),
        progress,
    )
}

/// Runs a race whose laps `drive` drives (cdbo's simulator, the game TORCS, ...), from a
/// demonstration already driven there (its lap and (x, a) pairs); `progress` is called after
/// every lap.
pub fn race_with(
    track_name: &str,
    (demo, demo_pairs): (LapResult, Vec<(f64, f64)>),
    limit: Limit,
    config: &RaceConfig,
    mut drive: impl FnMut(&RkhsPolicy) -> Result<LapResult>,
    mut progress: impl FnMut(&LapRecord),
) -> Result<RaceOutcome> {
    crate::sizes::KERNELS.checked(config.kernels)?;
    crate::sizes::LAPS.checked(config.laps)?;
    if !(config.demo_speed.is_finite() && config.demo_speed > 0.0) {
        return Err(Error::invalid_value(
            "the demonstration speed",
            config.demo_speed,
            "a positive number of m/s",
        ));
    }
    if !demo.completed {
        let why = demo.failure.map_or("it did not finish".into(), |f| {
            format!("{} at {:.0} % of the lap", f.reason.name(), 100.0 * f.x)
        });
        return Err(Error::DemoFailed {
            speed: config.demo_speed,
            track: track_name.to_string(),
            failure: why,
        });
    }
    let lengthscale = default_lengthscale(config.kernels);
    let initial = RkhsPolicy::fit(&demo_pairs, config.kernels, lengthscale, DEFAULT_RIDGE)?;
    let mut settings = crate::optimizers::Settings::race(config.seed, config.beta);
    if let Some(sigma0) = config.sigma0 {
        if !(sigma0.is_finite() && sigma0 > 0.0) {
            return Err(Error::invalid_value("σ₀", sigma0, "positive"));
        }
        settings.sigma0 = sigma0;
    }
    let mut optimizer =
        crate::optimizers::by_name(&config.method, initial.weights.clone(), &settings)?;
    let mut laps = Vec::with_capacity(config.laps);
    let mut best = (initial.clone(), 0.0);
    for lap in 1..=config.laps {
        let t0 = std::time::Instant::now();
        let weights = optimizer.ask()?;
        let optimizer_s = t0.elapsed().as_secs_f64();
        let policy = RkhsPolicy::new(weights.clone(), lengthscale)?;
        let t1 = std::time::Instant::now();
        let result = drive(&policy)?;
        let simulator_s = t1.elapsed().as_secs_f64();
        let t2 = std::time::Instant::now();
        optimizer.tell_lap(&weights, result.reward_mps, result.failure.map(|f| f.x))?;
        let optimizer_s = optimizer_s + t2.elapsed().as_secs_f64();
        if result.reward_mps > best.1 {
            best = (policy, result.reward_mps);
        }
        let record = LapRecord {
            lap,
            reward_mps: result.reward_mps,
            best_mps: best.1,
            lap_time_s: result.lap_time_s,
            failure: result.failure.map(|f| f.reason),
            x_fail: result.failure.map(|f| f.x),
            optimizer_s,
            simulator_s,
        };
        progress(&record);
        laps.push(record);
    }
    Ok(RaceOutcome {
        demo,
        demo_pairs,
        initial,
        best: best.0,
        best_reward_mps: best.1,
        laps,
        limit,
    })
}
