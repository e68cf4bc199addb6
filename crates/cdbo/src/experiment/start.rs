//! The start of a race on any circuit: a demonstration that completes under the rule the laps
//! are learned by, and a first policy π(w₀) that completes before any method learns from it.
//!
//! **The demonstration.** The paper's PI holds 15 m/s ([`crate::drive::demo`]); where that lap
//! leaves the road (a tight chicane on a circuit whose laps keep a reserve of the road), and
//! the speed was not asked for, a short search finds the fastest constant speed that completes:
//! the speed falls by [`SLOWDOWN`] until a lap completes (no slower than [`SLOWEST`]), then
//! [`BISECTIONS`] halvings of the interval between the slowest failing and the fastest
//! completing speed. Each is one lap of the demonstrator, not counted among the race's laps
//! (as the paper's demonstration is not). Where 15 m/s completes nothing changes. The safe
//! pattern search demonstrates near the limit instead ([`super::profile_start`]), unless a
//! speed was asked for.
//!
//! **The first policy.** w₀, the demonstration's fit, is a smoothed copy of the demonstrator's
//! pedal, and can be faster than the demonstrator where the fit spreads its launch or rounds
//! its brake: where its lap leaves the road its pedal is lowered before the place (to half the
//! demonstrator's throttle at most, to full braking where the demonstrator brakes), where it
//! stalls raised just before it (up to full throttle), by a step that halves where a repair
//! overshot, and where lowering does not help it is fitted again to a slower demonstration,
//! the repairs made so far kept, until its lap completes ([`complete_start`]). These laps are
//! the race's first laps and count among its failed ones; the method then starts from the
//! policy whose lap completed (its first lap, which it does not drive again; where a method
//! does not ask for its start first, as CMA-ES does not, that lap is recorded before its own),
//! and the safe pattern search remembers those too fast ([`Start::departures`],
//! [`crate::learner::safe_search::SafeSearch::after_failures`]).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::evaluator::{Evaluator, Outcome};
use crate::learner::pattern_search::push::REPAIR_DISTANCE;
use crate::optimizers::FailedLap;
use crate::policy::repair::REPAIR_SPACINGS;
use crate::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use crate::policy::{Policy, RkhsPolicy};
use crate::sim::{Failure, LapResult};

/// Each speed the demonstration search tries is this share of the last that failed.
pub const SLOWDOWN: f64 = 0.8;
/// The slowest demonstration the search tries (m/s).
pub const SLOWEST: f64 = 2.0;
/// Halvings of the interval between the last failing and the first completing speed.
pub const BISECTIONS: usize = 3;
/// Where lowering its pedal cannot help a first policy's lap too fast, it is fitted again to a
/// demonstration this much slower.
pub const START_SLOWDOWN: f64 = 0.9;
/// How much a first policy's pedal is lowered before where its lap was too fast.
pub const START_STEP: f64 = 0.1;

/// A demonstration as the race drove it: its lap and the (x, a) pairs of every driver step.
pub type Demonstration = (LapResult, Vec<(f64, f64)>);

/// What the demonstration search chose where the asked speed's lap failed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DemoChoice {
    /// The speed asked for (m/s).
    pub asked_mps: f64,
    /// How its lap failed.
    pub failure: Failure,
    /// The fastest speed found to complete (m/s).
    pub chosen_mps: f64,
    /// Demonstration laps the search drove, the asked speed's included.
    pub laps: usize,
}

impl DemoChoice {
    /// One line saying what was chosen and why.
    pub fn sentence(&self, track: &str) -> String {
        format!(
            "the {} m/s demonstration does not complete {track} ({} at {:.0} % of the lap); \
             demonstrating at {:.2} m/s instead, the fastest constant speed that completed in a \
             search of {} laps",
            self.asked_mps,
            self.failure.reason.name(),
            100.0 * self.failure.x,
            self.chosen_mps,
            self.laps
        )
    }
}

/// The demonstration at `speed` (m/s) by `demonstrate`; where its lap fails and the speed is
/// not `fixed`, the fastest constant speed whose lap completes (see the [module](self)), and
/// what was chosen. A fixed speed's failed lap is returned as it is (the race refuses it).
pub fn demonstration(
    speed: f64,
    fixed: bool,
    mut demonstrate: impl FnMut(f64) -> Result<Demonstration>,
) -> Result<(Demonstration, Option<DemoChoice>)> {
    let first = demonstrate(speed)?;
    let Some(failure) = first.0.failure.filter(|_| !first.0.completed && !fixed) else {
        return Ok((first, None));
    };
    let mut laps = 1;
    let (mut failing, mut completing) = (speed, None);
    while completing.is_none() {
        let v = SLOWDOWN * failing;
        if v < SLOWEST {
            return Ok((first, None));
        }
        let demo = demonstrate(v)?;
        laps += 1;
        if demo.0.completed {
            completing = Some((v, demo));
        } else {
            failing = v;
        }
    }
    let Some((mut v, mut best)) = completing else {
        return Ok((first, None));
    };
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (v + failing);
        let demo = demonstrate(mid)?;
        laps += 1;
        if demo.0.completed {
            (v, best) = (mid, demo);
        } else {
            failing = mid;
        }
    }
    let choice = DemoChoice {
        asked_mps: speed,
        failure,
        chosen_mps: v,
        laps,
    };
    Ok((best, Some(choice)))
}

/// The first policy of a race, driven until its lap completes.
#[derive(Debug, Clone)]
pub struct Start {
    /// The policy the method starts from: w₀, repaired where its laps failed.
    pub policy: Policy,
    /// The outcome of each lap driven, in order: failed ones, then the completed one, if any.
    pub laps: Vec<(Outcome, f64)>,
    /// The weights of each lap driven, in the order of `laps`.
    pub driven: Vec<Vec<f64>>,
    /// The speed (m/s) of the demonstration the policy was last fitted to.
    pub speed_mps: f64,
}

impl Start {
    /// Laps that failed.
    pub fn failed(&self) -> usize {
        self.laps
            .iter()
            .filter(|(o, _)| matches!(o, Outcome::Failed { .. }))
            .count()
    }

    /// The failed laps too fast (the car left the road) whose venue said where: their weights
    /// and where each failed (what a car's timer tells). A stall of the start is a repair's
    /// overshoot (a brake lowered too far, raised on the next lap): remembered by the safe
    /// search, it held back the push's own repairs before the same corner (measured, seeds
    /// 0–2: the 13 circuits 86.1 against 86.2 %, and 94.8 against 95.1 % on TORCS's 21 road
    /// tracks, seed 0; docs/results/any-track.md).
    pub fn departures(&self) -> Vec<(Vec<f64>, FailedLap)> {
        self.driven
            .iter()
            .zip(&self.laps)
            .filter_map(|(w, (outcome, _))| outcome.failed_lap().map(|f| (w.clone(), f)))
            .filter(|(_, f)| !f.too_slow)
            .collect()
    }

    /// Whether the last lap completed.
    pub fn completed(&self) -> bool {
        self.laps
            .last()
            .is_some_and(|(o, _)| !matches!(o, Outcome::Failed { .. }))
    }
}

/// Drives `initial` (its pedal w₀ fitted to the demonstration `targets`, held at `speed` m/s)
/// with `evaluator` until its lap completes, at most `max_failed` laps failing. After a lap too
/// fast (off the road, spun, backwards), the fit's targets over the [`REPAIR_DISTANCE`] metres
/// (at least two kernel spacings) before the failure are lowered by a step δ, but none
/// below its floor: half the demonstrator's throttle where it presses, full braking where
/// it brakes; after a lap too slow (stalled, time limit), they are
/// raised by δ over the kernel spacing before the stall, up to full throttle, however often it
/// stalls there (a slower demonstration cannot help a car that stops; raised over more road,
/// a 30-kernel pedal on Spring's 22 km, 760 m a spacing, reached the corner before the hill
/// too fast). δ starts at [`START_STEP`], halves where a lap fails where the last repair
/// moved the pedal the other way (it overshot), and is [`START_STEP`] again once a failure
/// lies further on. Where lowering cannot help — a lap
/// too fast failed within a kernel spacing of where one failed since the last fit to a
/// demonstration, or the targets are at their floor already — or where raising cannot (full
/// throttle already), or the venue did not say where, w₀ is fitted again to a demonstration
/// [`START_SLOWDOWN`] as fast, by `demonstrate`, its targets moved as the repairs so far moved
/// the last one's (a corner lowered stays lowered, rather than failing again on
/// the slower fit). Each lap's weights, outcome and the seconds it took are kept.
pub fn complete_start(
    evaluator: &mut dyn Evaluator,
    initial: Policy,
    (targets, speed): (&[(f64, f64)], f64),
    demonstrate: &mut dyn FnMut(f64) -> Result<Demonstration>,
    track_length: f64,
    max_failed: usize,
) -> Result<Start> {
    let kernels = initial.pedal.kernels();
    let lengthscale = default_lengthscale(kernels);
    let window = (REPAIR_DISTANCE / track_length).max(REPAIR_SPACINGS * lengthscale);
    let mut demo = targets.to_vec();
    let mut targets = demo.clone();
    let mut speed = speed;
    // Where laps too fast failed since the last fit to a demonstration.
    let mut places: Vec<f64> = Vec::new();
    // The repair's step, and the last repair's place and whether it raised the pedal.
    let mut step = START_STEP;
    let mut last: Option<(f64, bool)> = None;
    let mut start = Start {
        policy: initial,
        laps: Vec::new(),
        driven: Vec::new(),
        speed_mps: speed,
    };
    loop {
        let t0 = std::time::Instant::now();
        let weights = start.policy.weights();
        let outcome = evaluator.evaluate(start.laps.len() as i64 + 1, &weights)?;
        start
            .laps
            .push((outcome.clone(), t0.elapsed().as_secs_f64()));
        start.driven.push(weights);
        if !matches!(outcome, Outcome::Failed { .. }) || start.failed() >= max_failed {
            return Ok(start);
        }
        let failed = outcome.failed_lap();
        if let Some(f) = failed {
            step = match last {
                // The last repair moved the pedal here the other way: it overshot; halve.
                Some((x, raised))
                    if raised != f.too_slow && (x - window..=x + lengthscale).contains(&f.at) =>
                {
                    0.5 * step
                }
                Some((x, _)) if f.at <= x + lengthscale => step,
                _ => START_STEP,
            };
            last = Some((f.at, f.too_slow));
        }
        let again = failed
            .is_some_and(|f| !f.too_slow && places.iter().any(|x| (f.at - x).abs() < lengthscale));
        places.extend(failed.filter(|f| !f.too_slow).map(|f| f.at));
        let repaired = match failed {
            Some(f) if f.too_slow => shift(&mut targets, &demo, f.at - lengthscale, f.at, step),
            Some(_) if again => false,
            Some(f) => shift(&mut targets, &demo, f.at - window, f.at, -step),
            None => false,
        };
        if !repaired {
            loop {
                speed *= START_SLOWDOWN;
                if speed < SLOWEST {
                    return Ok(start);
                }
                let (lap, pairs) = demonstrate(speed)?;
                if lap.completed {
                    targets = carried(&demo, &targets, &pairs);
                    demo = pairs;
                    places.clear();
                    (step, last) = (START_STEP, None);
                    start.speed_mps = speed;
                    break;
                }
            }
        }
        start.policy.pedal = RkhsPolicy::fit(&targets, kernels, lengthscale, DEFAULT_RIDGE)
            .map_err(|e| Error::Numerical(format!("refitting the first policy: {e}")))?;
    }
}

/// The targets of a new demonstration `pairs` moved as `targets` moved from `demo` (the
/// repairs so far, kept): each pair's a₀ plus the move d at the nearest place of `demo` at or
/// before it, no lower than the [`floor`] and no higher than full throttle.
fn carried(demo: &[(f64, f64)], targets: &[(f64, f64)], pairs: &[(f64, f64)]) -> Vec<(f64, f64)> {
    pairs
        .iter()
        .map(|&(x, a0)| {
            let i = demo.partition_point(|p| p.0 <= x).saturating_sub(1);
            let d = match (demo.get(i), targets.get(i)) {
                (Some(p), Some(t)) => t.1 - p.1,
                _ => 0.0,
            };
            let a = if d < 0.0 {
                (a0 + d).max(floor(a0).min(a0))
            } else {
                (a0 + d).min(1.0).max(a0)
            };
            (x, a)
        })
        .collect()
}

/// The lowest a target whose demonstration pedal is a₀ is lowered to: half a₀ where the
/// demonstrator presses the throttle (a cruising pedal braked, or only coasting, over the
/// repair's stretch stops the car), full braking where it brakes (the fit rounds the
/// demonstrator's brake, 100–300 m long, into a lift with kernels 120–200 m apart, and the
/// fitted car reaches the corner too fast however little throttle is left before the brake).
fn floor(a0: f64) -> f64 {
    if a0 > 0.0 { 0.5 * a0 } else { -1.0 }
}

/// Moves the targets (x, a) with x in [from, to] by `step`, a lowered one no further than its
/// [`floor`] (`demo`: the targets and the demonstration are the same pairs, moved); whether
/// any moved.
fn shift(targets: &mut [(f64, f64)], demo: &[(f64, f64)], from: f64, to: f64, step: f64) -> bool {
    let mut moved = false;
    for ((x, a), (_, a0)) in targets.iter_mut().zip(demo) {
        if (from..=to).contains(x) {
            let next = if step < 0.0 {
                (*a + step).max(floor(*a0).min(*a))
            } else {
                (*a + step).min(1.0).max(*a)
            };
            moved |= next != *a;
            *a = next;
        }
    }
    moved
}

/// An evaluator that has already driven one lap: the first evaluation of those weights is
/// that lap's outcome, not driven again; every other lap is `inner`'s.
pub struct DrivenOnce<'a> {
    inner: &'a mut dyn Evaluator,
    lap: Option<(Vec<f64>, Outcome)>,
}

impl<'a> DrivenOnce<'a> {
    /// `inner`, with the lap of `weights` already driven to `outcome`.
    pub fn new(inner: &'a mut dyn Evaluator, lap: Option<(Vec<f64>, Outcome)>) -> DrivenOnce<'a> {
        DrivenOnce { inner, lap }
    }
}

impl Evaluator for DrivenOnce<'_> {
    fn evaluate(&mut self, trial: i64, weights: &[f64]) -> Result<Outcome> {
        match self.lap.take() {
            Some((w, outcome)) if w == weights => Ok(outcome),
            _ => self.inner.evaluate(trial, weights),
        }
    }

    fn remove_leftovers(&mut self) -> Vec<(std::path::PathBuf, u32)> {
        self.inner.remove_leftovers()
    }
}

/// A demonstrator for tests: its lap at v (a speed or a profile's scale) completes at a
/// reward of v while v ≤ `limit`, and leaves the road at x = 0.17 above it; each v is pushed
/// onto `asked`.
#[cfg(test)]
pub(super) fn demonstrator_up_to(
    limit: f64,
    asked: &mut Vec<f64>,
) -> impl FnMut(f64) -> Result<Demonstration> + '_ {
    move |v| {
        asked.push(v);
        let completed = v <= limit;
        let lap = LapResult {
            completed,
            lap_time_s: completed.then_some(100.0 / v),
            reward_mps: if completed { v } else { 0.0 },
            failure: (!completed).then_some(Failure {
                reason: crate::sim::FailureReason::OffTrack,
                x: 0.17,
                distance_m: 10.0,
                time_s: 1.0,
            }),
            simulated_s: 1.0,
            standing_lap_s: None,
            trace: Vec::new(),
        };
        Ok((lap, vec![(0.0, v)]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A venue whose lap fails at `at` for `reason` while the pedal at `probe` is outside `ok`.
    struct Gate {
        probe: f64,
        ok: std::ops::RangeInclusive<f64>,
        at: f64,
        reason: &'static str,
    }

    impl Evaluator for Gate {
        fn evaluate(&mut self, _trial: i64, weights: &[f64]) -> Result<Outcome> {
            let lengthscale = default_lengthscale(weights.len());
            let pedal = RkhsPolicy::new(weights.to_vec(), lengthscale)?;
            Ok(if self.ok.contains(&pedal.action(self.probe)) {
                Outcome::Lap {
                    time_s: 100.0,
                    length_m: 1000.0,
                }
            } else {
                Outcome::Failed {
                    at: Some(self.at),
                    reason: Some(self.reason.into()),
                }
            })
        }
    }

    /// A hill: the lap stalls at x = 0.3 while the pedal at x = 0.29 is below `needed`.
    fn hill(needed: f64) -> Gate {
        Gate {
            probe: 0.29,
            ok: needed..=f64::INFINITY,
            at: 0.3,
            reason: "stalled",
        }
    }

    /// A brake: the lap leaves the road at x = 0.5 while the pedal at x = 0.45, inside the
    /// demonstrator's brake, is above `most`.
    fn brake(most: f64) -> Gate {
        Gate {
            probe: 0.45,
            ok: f64::NEG_INFINITY..=most,
            at: 0.5,
            reason: "off_track",
        }
    }

    /// The 30-kernel fit of `targets` (the 15 m/s demonstration's pairs).
    fn fit(targets: &[(f64, f64)]) -> RkhsPolicy {
        let kernels = 30;
        RkhsPolicy::fit(
            targets,
            kernels,
            default_lengthscale(kernels),
            DEFAULT_RIDGE,
        )
        .unwrap()
    }

    /// The start from `pedal`, the fit of `targets`, on `venue`, with the speeds of the slower
    /// demonstrations it asked for (every one completes).
    fn start_on(venue: &mut Gate, pedal: RkhsPolicy, targets: &[(f64, f64)]) -> (Start, Vec<f64>) {
        let mut asked = Vec::new();
        let mut demonstrate = |v: f64| {
            asked.push(v);
            demonstrator_up_to(f64::INFINITY, &mut Vec::new())(v)
        };
        let start = complete_start(
            venue,
            pedal.into(),
            (targets, 15.0),
            &mut demonstrate,
            1000.0,
            30,
        )
        .unwrap();
        (start, asked)
    }

    /// A first policy that stalls again and again at one place is raised there until its lap
    /// completes: a slower demonstration cannot help a car that stops, so none is asked for.
    #[test]
    fn a_stalling_first_policy_is_raised_not_slowed() {
        let targets: Vec<(f64, f64)> = (0..100).map(|i| (i as f64 / 100.0, 0.2)).collect();
        let (start, asked) = start_on(&mut hill(0.55), fit(&targets), &targets);
        assert!(start.completed(), "{:?}", start.laps);
        // 0.2 raised by 0.1 a lap: 0.3, 0.4, 0.5 stall (the fit sits a little below its
        // targets), 0.6 completes.
        assert!((3..=5).contains(&start.failed()), "{:?}", start.laps);
        assert!(
            asked.is_empty(),
            "slower demonstrations asked for: {asked:?}"
        );
        assert_eq!(start.speed_mps, 15.0);
        // Stalls are the repair's to undo, not departures the learner remembers.
        assert!(start.departures().is_empty());
    }

    /// A first policy too fast where the demonstrator brakes (its brake fills the whole
    /// stretch a repair lowers) brakes harder there until its lap completes: no slower
    /// demonstration is asked for (with the brake held at the demonstrator's, nothing could
    /// be lowered and every repair was a slower demonstration).
    #[test]
    fn a_first_policy_too_fast_in_a_brake_brakes_harder() {
        let targets: Vec<(f64, f64)> = (0..100)
            .map(|i| {
                let x = i as f64 / 100.0;
                (x, if (0.2..=0.5).contains(&x) { -0.2 } else { 0.4 })
            })
            .collect();
        let pedal = fit(&targets);
        // The fit brakes at 0.45 about as the demonstrator does; the venue asks 0.05 more.
        let mut venue = brake(pedal.action(0.45) - 0.05);
        let (start, asked) = start_on(&mut venue, pedal, &targets);
        assert!(start.completed(), "{:?}", start.laps);
        assert_eq!(start.failed(), 1, "{:?}", start.laps);
        assert!(
            asked.is_empty(),
            "slower demonstrations asked for: {asked:?}"
        );
        assert_eq!(start.departures().len(), start.failed());
        assert!(
            start
                .departures()
                .iter()
                .all(|(_, f)| f.at == 0.5 && !f.too_slow)
        );
        assert_eq!(start.driven.last(), Some(&start.policy.weights()));
    }

    /// A slower demonstration keeps the repairs made on the last: its pedal moves by the
    /// last targets' move at the nearest place before, a lowering no further than the floor.
    #[test]
    fn a_slower_demonstration_keeps_the_repairs() {
        let demo = [(0.0, 0.5), (0.5, 0.5), (0.8, -0.2)];
        let targets = [(0.0, 0.5), (0.5, 0.3), (0.8, -0.4)];
        let slower = [(0.1, 0.4), (0.6, 0.3), (0.7, 0.4), (0.9, -0.1)];
        let moved = carried(&demo, &targets, &slower);
        let expected = [(0.1, 0.4), (0.6, 0.15), (0.7, 0.2), (0.9, -0.3)];
        for ((x, a), (ex, ea)) in moved.iter().zip(expected) {
            assert_eq!(*x, ex);
            assert!((a - ea).abs() < 1e-12, "{moved:?}");
        }
    }

    /// Where the asked speed completes, it is the only lap; where it fails, the search slows
    /// by a fifth until a lap completes, then halves the gap three times, and keeps the
    /// fastest that completed; a fixed speed is never searched.
    #[test]
    fn the_search_finds_the_fastest_speed_that_completes() {
        let mut speeds = Vec::new();
        let (demo, choice) =
            demonstration(15.0, false, demonstrator_up_to(20.0, &mut speeds)).unwrap();
        assert!(demo.0.completed && choice.is_none());
        assert_eq!(speeds, vec![15.0]);
        let mut speeds = Vec::new();
        let (demo, choice) =
            demonstration(15.0, false, demonstrator_up_to(10.0, &mut speeds)).unwrap();
        let choice = choice.unwrap();
        // 15 and 12 fail, 9.6 completes; 10.8 fails, 10.2 fails, 9.9 completes.
        assert_eq!(speeds.len(), 6, "{speeds:?}");
        assert!((choice.chosen_mps - 9.9).abs() < 1e-9, "{choice:?}");
        assert_eq!(demo.0.reward_mps, choice.chosen_mps);
        assert_eq!(choice.laps, 6);
        assert!(choice.sentence("Monza").contains("off_track at 17 %"));
        let mut speeds = Vec::new();
        let (demo, choice) =
            demonstration(15.0, true, demonstrator_up_to(10.0, &mut speeds)).unwrap();
        assert!(!demo.0.completed && choice.is_none() && speeds == vec![15.0]);
    }
}
