//! Learning to race one track (paper Sec. V): drive the demonstration, fit w₀, then optimise
//! the policy weights for a number of laps, one lap per evaluation. The safe pattern search
//! starts from the profile start instead ([`super::profile_start`]): its policy's action asks
//! for a speed ([`crate::policy::target`]), and w₀ = 0 is the demonstration.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::car::Car;
use crate::error::{Error, Result};
use crate::evaluator::{Evaluator, Outcome};
use crate::limit::{Limit, limit_lap};
use crate::line::RacingLine;
use crate::method::{Method, Spec};
use crate::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use crate::policy::{Block, Policy, PolicyShape, RkhsPolicy, SpeedTarget};
use crate::sim::{FailureReason, LapResult};
use crate::study::run::{Event, InMemory, run};
use crate::track::Track;
use crate::venue::Venue;

use super::profile_start::{ProfileChoice, ProfileDemonstrator};
use super::start::{DemoChoice, Demonstration, DrivenOnce, Start, complete_start, demonstration};

pub use crate::line::BaseLine;

/// Settings of a race.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RaceConfig {
    /// Optimiser.
    pub method: Method,
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
    /// Whether the demonstration holds exactly [`demo_speed`](Self::demo_speed) (a speed the
    /// user asked for); otherwise, where its lap fails, the fastest constant speed that
    /// completes ([`super::start::demonstration`]).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub fixed_demo_speed: bool,
    /// The method's main knob ([`Method::knob`]: σ₀, TuRBO's L_init, LineBO's step, REMBO's
    /// box); `None`: its race value. Older configs name it `sigma0`.
    #[serde(default, alias = "sigma0", skip_serializing_if = "Option::is_none")]
    pub knob: Option<f64>,
    /// Failed laps allowed ([`crate::learner::budget`]); `None`: no budget.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_failed_laps: Option<usize>,
    /// Kernels of a learned line d(x) ([`crate::policy::actions`]), starting at the base line
    /// (d = 0) and optimised with the pedal; `None`: the base line, fixed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_kernels: Option<usize>,
    /// The policy the race starts from instead of the demonstration's fitted w₀ (a warm start:
    /// say, a policy learned in cdbo's simulator, continued in the game). Its shape must be the
    /// race's ([`check_warm_start`]); the search box is centred on it, and the pattern search
    /// skips its push and repairs it where its first lap fails ([`Spec::warm_started`]); where
    /// its action asks for a speed ([`crate::policy::target`]) the race's policies ask for the
    /// same. `None`: the fitted w₀, as the paper does.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub warm_start: Option<Policy>,
    /// The base line d₀(s): the line the car holds, the demonstration's included, and from
    /// which a learned line's offsets are measured (the car holds d₀(s) + d(s/L)).
    #[serde(default, skip_serializing_if = "BaseLine::is_centre")]
    pub base_line: BaseLine,
    /// Half-width r of the search box [w₀ − r, w₀ + r] every method searches; `None`:
    /// [`DEFAULT_BOX_RADIUS`](crate::optimizers::DEFAULT_BOX_RADIUS).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub box_radius: Option<f64>,
    /// Learn on the flying lap ([`crate::sim::LapConfig::flying`]: the second of two laps
    /// from the standing start, timed line to line), the lap a race is made of; the
    /// demonstration stays a standing lap.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub flying: bool,
}

impl RaceConfig {
    /// The race's specification of its method.
    pub fn spec(&self) -> Result<Spec> {
        let mut spec = Spec::told(self.method, self.seed, self.beta, self.knob)?;
        if self.line_kernels.is_some() {
            spec = spec.pedal_kernels(self.kernels);
        }
        if self.warm_start.is_some() {
            spec = spec.warm_started();
        }
        if let Some(radius) = self.box_radius {
            spec = spec.box_radius(radius)?;
        }
        Ok(match self.max_failed_laps {
            Some(max) => spec.max_failed_laps(max),
            None => spec,
        })
    }

    /// The shape of the race's policies: M pedal kernels and, with a learned line, M_d line
    /// kernels, each at the paper's length-scale 1/(M − 1).
    pub fn shape(&self) -> Result<PolicyShape> {
        let pedal = PolicyShape::pedal(Block::paper(self.kernels)?);
        Ok(match self.line_kernels {
            Some(m) => pedal.with_line(Block::paper(m)?),
            None => pedal,
        })
    }
}

impl Default for RaceConfig {
    fn default() -> Self {
        RaceConfig {
            method: Method::Cdbo,
            kernels: 30,
            laps: 300,
            seed: 0,
            beta: crate::acquisition::ucb::DEFAULT_BETA,
            demo_speed: 15.0,
            fixed_demo_speed: false,
            knob: None,
            max_failed_laps: None,
            line_kernels: None,
            warm_start: None,
            base_line: BaseLine::Centre,
            box_radius: None,
            flying: false,
        }
    }
}

/// Refuses a warm start whose shape is not a race's of `kernels` kernels: the paper's pedal
/// (`kernels` kernels of length-scale [`default_lengthscale`]`(kernels)`), no line. The error
/// gives both shapes.
pub fn check_warm_start(policy: &Policy, kernels: usize) -> Result<()> {
    let race = PolicyShape::pedal(Block::paper(kernels)?);
    let shape = policy.shape();
    let same_lengthscale =
        (shape.pedal.lengthscale - race.pedal.lengthscale).abs() <= 1e-9 * race.pedal.lengthscale;
    if shape.line.is_none() && shape.pedal.kernels == kernels && same_lengthscale {
        return Ok(());
    }
    let line = shape.line.map_or(String::new(), |l| {
        format!(" and a line of {} kernels", l.kernels)
    });
    Err(Error::invalid_value(
        "the warm start's policy",
        format!(
            "{} kernels of length-scale {:.6}{line}",
            shape.pedal.kernels, shape.pedal.lengthscale
        ),
        format!(
            "the race's {kernels} kernels of length-scale {:.6}, no line (race with --kernels {})",
            race.pedal.lengthscale, shape.pedal.kernels
        ),
    ))
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
    /// What the demonstration search chose where the asked speed's lap failed.
    pub demo_choice: Option<DemoChoice>,
    /// The profile start's demonstration, where the race began with one
    /// ([`super::profile_start`]).
    pub profile_choice: Option<ProfileChoice>,
    /// Laps of the first policy that failed before one completed
    /// ([`super::start::complete_start`]): the race's first laps, among its failed ones.
    pub start_failed_laps: usize,
    /// The demonstration's (x, a) pairs.
    pub demo_pairs: Vec<(f64, f64)>,
    /// The policy the race started from: the demonstration's fit (repaired where its laps
    /// failed, [`super::start::complete_start`]), or the warm start.
    pub initial: Policy,
    /// The best policy found.
    pub best: Policy,
    /// Its reward.
    pub best_reward_mps: f64,
    /// Every optimisation lap.
    pub laps: Vec<LapRecord>,
    /// The limit lap.
    pub limit: Limit,
    /// The base line the laps were driven on ([`RaceConfig::base_line`]); `None`: the centre
    /// line. Drive a policy again on it with [`Venue::on_line`].
    pub line: Option<Arc<RacingLine>>,
}

impl RaceOutcome {
    /// This outcome with its policies asking for `target`'s speeds (the race's evaluator
    /// drove them so).
    fn targeting(self, target: Option<SpeedTarget>) -> RaceOutcome {
        RaceOutcome {
            initial: self.initial.targeting(target.clone()),
            best: self.best.targeting(target),
            ..self
        }
    }

    /// The time (s) of the first lap that reached the best reward, if one completed.
    pub fn best_lap_time_s(&self) -> Option<f64> {
        self.laps
            .iter()
            .filter(|l| l.reward_mps == self.best_reward_mps)
            .find_map(|l| l.lap_time_s)
    }
}

/// Runs a race where `venue` drives its laps, on `track` with `car` (cdbo's reading of them,
/// for the limit and the base line), the demonstration and every lap on the config's base line;
/// `progress` is called after every lap.
pub fn race(
    venue: &Venue,
    track: &Track,
    car: &Car,
    config: &RaceConfig,
    progress: impl FnMut(&LapRecord),
) -> Result<RaceOutcome> {
    let limit = limit_lap(track, car);
    let line = config.base_line.line(track, car)?;
    let on_line;
    let venue = match &line {
        Some(l) => {
            on_line = venue.clone().on_line(l.clone());
            &on_line
        }
        None => venue,
    };
    // The safe pattern search starts near the limit (its budget of failed laps cannot pay
    // for the climb from 15 m/s on a long circuit) and learns a target speed; a speed asked
    // for is held as asked.
    let profiled = config.method == Method::SafePatternSearch
        && !config.fixed_demo_speed
        && config.warm_start.is_none();
    let profile = profiled.then(|| ProfileDemonstrator::new(track, car, line.as_deref()));
    let chosen = match &profile {
        Some(p) => p.choose(venue)?,
        None => None,
    };
    // The laps' evaluator, the pedal's action asking for `target`'s speeds if given.
    let evaluator = |target: Option<SpeedTarget>| {
        if config.flying {
            venue.clone().flying().evaluator(config.shape()?, target)
        } else {
            venue.evaluator(config.shape()?, target)
        }
    };
    let mut outcome = match (chosen, &profile) {
        (Some(((lap, pairs), choice)), Some(profile)) => {
            // The demonstration is a = 0 of a target at its scale; a slower one, a lower a.
            let target = profile.target(track, choice.k)?;
            let at = |k: f64, pairs: Vec<(f64, f64)>| {
                let a = target.action_holding(k);
                pairs.into_iter().map(|(x, _)| (x, a)).collect::<Vec<_>>()
            };
            let pairs = at(choice.k, pairs);
            let mut outcome = race_with(
                &track.name,
                ((lap, pairs), choice.speed_mps),
                limit,
                config,
                (evaluator(Some(target.clone()))?.as_mut(), &mut |v| {
                    let (lap, pairs) = profile.demonstrate(venue, v)?;
                    Ok((lap, at(v / profile.reference_mps, pairs)))
                }),
                progress,
            )?;
            outcome.profile_choice = Some(choice);
            outcome.targeting(Some(target))
        }
        _ => {
            let (demo, choice) = demonstration(config.demo_speed, config.fixed_demo_speed, |v| {
                venue.demonstrate(v)
            })?;
            let speed = choice.as_ref().map_or(config.demo_speed, |c| c.chosen_mps);
            // A warm start asking for a speed goes on asking for it.
            let target = config.warm_start.as_ref().and_then(|p| p.target.clone());
            let mut outcome = race_with(
                &track.name,
                (demo, speed),
                limit,
                config,
                (evaluator(target.clone())?.as_mut(), &mut |v| {
                    venue.demonstrate(v)
                }),
                progress,
            )?;
            outcome.demo_choice = choice;
            outcome.targeting(target)
        }
    };
    outcome.line = line;
    Ok(outcome)
}

/// Runs a race whose laps `evaluator` drives with policies of length-scale
/// [`default_lengthscale`]`(config.kernels)`, from a demonstration already driven there (its
/// lap and (x, a) pairs, and the speed it held), slower ones by `demonstrate` where the first
/// policy needs one ([`complete_start`]); `progress` is called after every lap. The laps go through the one
/// lap loop ([`crate::study::run`]) with an in-memory trial source.
fn race_with(
    track_name: &str,
    ((demo, demo_pairs), demo_speed): (Demonstration, f64),
    limit: Limit,
    config: &RaceConfig,
    (evaluator, demonstrate): (
        &mut dyn Evaluator,
        &mut dyn FnMut(f64) -> Result<Demonstration>,
    ),
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
    // w₀: the warm start, or the pedal fitted to the demonstration and a line at the base line
    // (d = 0).
    let shape = config.shape()?;
    let mut initial = match &config.warm_start {
        Some(_) if shape.line.is_some() => {
            return Err(Error::invalid_value(
                "a warm start with a learned line",
                "--warm-start and --line learn",
                "one of them (a warm start is a pedal-only policy)",
            ));
        }
        Some(policy) => {
            check_warm_start(policy, config.kernels)?;
            policy.clone()
        }
        None => Policy {
            pedal: RkhsPolicy::fit(&demo_pairs, config.kernels, lengthscale, DEFAULT_RIDGE)?,
            line: match shape.line {
                Some(line) => Some(RkhsPolicy::new(vec![0.0; line.kernels], line.lengthscale)?),
                None => None,
            },
            target: None,
        },
    };
    // The first policy driven, and repaired where it fails, until its lap completes; a warm
    // start is the method's to repair.
    let budget = match config.max_failed_laps {
        Some(max) => Some(max),
        None if config.method == Method::SafePatternSearch => {
            Some(crate::learner::safe_search::BUDGET)
        }
        None => None,
    };
    let start_cap = budget.unwrap_or(config.laps).min(config.laps);
    let start = if config.warm_start.is_some() {
        None
    } else {
        Some(complete_start(
            evaluator,
            initial.clone(),
            (&demo_pairs, demo_speed),
            demonstrate,
            limit.track_length,
            start_cap,
        )?)
    };
    let start_failed = start.as_ref().map_or(0, Start::failed);
    let mut laps = Vec::with_capacity(config.laps);
    let mut best = (initial.weights(), 0.0);
    for (i, (outcome, seconds)) in start.iter().flat_map(|s| &s.laps).enumerate() {
        if matches!(outcome, Outcome::Failed { .. }) {
            let record = lap_record(i + 1, outcome, (0.0, 0.0), (0.0, *seconds));
            progress(&record);
            laps.push(record);
        }
    }
    let (first, remembered) = match &start {
        Some(s) if !s.completed() => {
            return Ok(RaceOutcome {
                demo,
                demo_pairs,
                demo_choice: None,
                profile_choice: None,
                start_failed_laps: start_failed,
                best: s.policy.clone(),
                initial,
                best_reward_mps: 0.0,
                laps,
                limit,
                line: None,
            });
        }
        Some(s) => {
            initial = s.policy.clone();
            let (outcome, seconds) = s.laps.last().cloned().unzip();
            let lap = outcome.map(|o| (s.policy.weights(), o));
            (s.policy.weights(), (lap, seconds.unwrap_or(0.0)))
        }
        None => (initial.weights(), (None, 0.0)),
    };
    let mut spec = config.spec()?;
    if let Some(max) = budget.filter(|_| start_failed > 0) {
        spec = spec.max_failed_laps(max - start_failed);
    }
    if start.is_some() {
        spec = spec.start_completed();
    }
    let mut optimizer = spec
        .policy(lengthscale)?
        .track_length(limit.track_length)?
        .optimizer_after(
            first,
            &start.as_ref().map(Start::departures).unwrap_or_default(),
        )?;
    let (mut lap, mut start_s) = remembered;
    // The start's completed lap is the method's first where the method asks for the start
    // first; otherwise (CMA-ES samples around it) it is the race's own lap, recorded and
    // counted in the best, and the method has one lap fewer.
    let mut recorded = start_failed;
    let asks_start = match &lap {
        Some((weights, _)) => optimizer.ask()? == *weights,
        None => true,
    };
    if !asks_start && let Some((weights, outcome)) = lap.take() {
        let reward = outcome.reward()?;
        let seconds = (0.0, std::mem::take(&mut start_s));
        let record = lap_record(start_failed + 1, &outcome, (reward, reward), seconds);
        progress(&record);
        laps.push(record);
        best = (weights, reward);
        recorded += 1;
    }
    let mut source = InMemory::new(optimizer, config.laps.saturating_sub(recorded));
    let mut evaluator = DrivenOnce::new(evaluator, lap);
    run(&mut source, &mut evaluator, &mut |event| {
        let Event::Told {
            trial,
            outcome,
            reward,
            timing,
        } = event
        else {
            return;
        };
        if reward > best.1 {
            best = (trial.weights.clone(), reward);
        }
        let seconds = (
            timing.ask_s + timing.tell_s,
            timing.evaluate_s + std::mem::take(&mut start_s),
        );
        let record = lap_record(
            recorded + trial.id as usize,
            outcome,
            (reward, best.1),
            seconds,
        );
        progress(&record);
        laps.push(record);
    })?;
    Ok(RaceOutcome {
        demo,
        demo_pairs,
        demo_choice: None,
        profile_choice: None,
        start_failed_laps: start_failed,
        initial,
        best: shape.policy(&best.0)?,
        best_reward_mps: best.1,
        laps,
        limit,
        line: None,
    })
}

/// The record of the race's `lap`-th lap: its `outcome`, its reward and the best so far
/// (m/s), and the seconds the optimiser and the simulator took for it.
fn lap_record(
    lap: usize,
    outcome: &Outcome,
    (reward_mps, best_mps): (f64, f64),
    (optimizer_s, simulator_s): (f64, f64),
) -> LapRecord {
    LapRecord {
        lap,
        reward_mps,
        best_mps,
        lap_time_s: match outcome {
            Outcome::Lap { time_s, .. } => Some(*time_s),
            _ => None,
        },
        failure: match outcome {
            Outcome::Failed { reason, .. } => Some(failure_reason(reason.as_deref())),
            _ => None,
        },
        x_fail: outcome.failed_at(),
        optimizer_s,
        simulator_s,
    }
}

/// A failed lap's reason as the race records it: the simulator's (and the game robot's)
/// reasons by name; any other (a game that drove no lap) counts as the time limit.
fn failure_reason(reason: Option<&str>) -> FailureReason {
    reason
        .and_then(FailureReason::from_name)
        .unwrap_or(FailureReason::TimeLimit)
}
