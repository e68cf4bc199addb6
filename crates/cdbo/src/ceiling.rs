//! The ceiling: the best lap this drive stack (the steering controller, the PI by default, and
//! a pedal over the lap fraction) reaches, as opposed to the physical [limit](crate::limit).
//!
//! 1. **Profile tracking**: a speed controller follows k·v_lim(s), the QSS limit's speed
//!    profile scaled by k, previewed over the next τ seconds:
//!    a = clamp(K_p·(max(k·min_{s ≤ s′ ≤ s + v·τ} v_lim(s′), v_min) − v), −1, 1), where the
//!    floor v_min lets the car leave the standing start (the profile begins at 0).
//!    The profile is the *crest-aware* limit's ([`profile`], [`LimitOptions::CRESTS`]): the
//!    crest-blind one asks for speeds at which the car takes off over a crest, so its largest
//!    k measured the crests, not the drive stack. Every share of "the limit" stays of the
//!    crest-blind [`limit_lap`](crate::limit::limit_lap) ([`Ceiling::limit_mps`]).
//!    The largest k whose lap completes is found by bisection (completion is not strictly
//!    monotone in k; the bisection keeps a completed k as its lower end, so it ends on a
//!    completed lap), and the ceiling is the fastest completed lap of the bisection's and of
//!    [`SCAN_STEPS`] more below its k, [`SCAN_STEP`] apart: past some k a lap can still
//!    complete yet be slower, the car over-driven into the corners and sliding out of them
//!    (the two-track Spirit 300 on Ridgeway's min-curvature line with the tracker: 43.18 m/s
//!    at k = 1, the bisection's top, against 45.95 m/s at k = 0.96).
//!
//!    One corner the drive stack cannot take at the profile's speed holds that k down over
//!    the whole lap. So the profile is also **lowered only where it fails**
//!    ([`lowered_where_it_fails`]): scaled by k + [`LOWERING_HEADROOM`] (at most 1), then,
//!    at each failure at s_f, lowered by [`LOWERING_STEP`] over [s_f − 150 m, s_f + 25 m]
//!    (the braking zone before it), never below k, until its lap completes. Where that lap
//!    is faster than the uniform one, the policy below is fitted to its pedal (car1-trb1 on
//!    E-Track 3, tracker and minimum-curvature line: 39.45 m/s at k = 0.796, 43.85 m/s
//!    lowered from 0.896). The uniform lap stays the ceiling learners are measured against.
//! 2. **The policy class**: the pedal of that lap (or of the lowered one), a(x), fitted by
//!    ridge regression with M kernels (paper eq. 9), then **repaired where it fails**
//!    ([`PedalRepair`]): while the fitted policy's lap fails at x_f, the fit's targets over the
//!    [`REPAIR_SPACINGS`] kernel spacings before it, x ∈ [x_f − 2/(M − 1), x_f], move by δ,
//!    down where the car was too fast (off the road, spun, backwards) and up where it was too
//!    slow (stalled, past the time limit), and the policy is fitted again. δ starts at δ₀ =
//!    [`REPAIR_STEP`], halves when the next failure lies within one spacing of the last and
//!    asks for the other direction (a bisection of the pedal there), and returns to δ₀ once a
//!    failure lies further on. The first completed lap (within [`REPAIR_LAPS`] laps) gives the
//!    fitted policy, a lower bound of the M-kernel policies' best. Where none completes, the
//!    repairs start again from the tracked lap's pedal, braking earlier for a corner that fails
//!    again ([`PedalRepair::braking_earlier`]): lowered only in the corner, the pedal brakes
//!    the car while it turns, and at the limit it spins or stops there. car1-trb1's flying laps
//!    on E-Track 2, where the car reaches the first corners at speed, fitted with 100 and 200
//!    kernels: no plain repair completes in 150 laps; braking earlier, 41.6 and 43.7 m/s after
//!    15 and 25 (docs/results/torcs.md).
//!
//!    Why a plain fit is not enough: the fitted pedal drives open loop. The tracker brakes
//!    for about a second at −0.5…−1 and then holds its speed with a small pedal; M kernels
//!    (116 m apart on Forza with 50) smooth that brake into a lift, so the car reaches the
//!    corner several m/s faster than the tracked lap and spins or leaves the road; and since
//!    the gearbox shifts at the current throttle (6574efe), a pedal near 0 goes up to top gear
//!    and loses the engine brake the tracker had in a low gear. Since then no plain fit (nor
//!    one of the pedal scaled by 1.5 or 2, of 16 slower laps down to 0.55 k) completed Forza,
//!    Allondaz or E-Track 2.
//!
//! Their rewards beside the limit's show how much of the gap to the limit is the steering's
//! (limit → tracked profile) and the policy class's (tracked profile → fitted policy), and
//! what is left to an optimiser.
//!
//! [`REPAIR_SPACINGS`]: crate::policy::repair::REPAIR_SPACINGS
//! [`REPAIR_STEP`]: crate::policy::repair::REPAIR_STEP

use serde::Serialize;

use crate::car::Car;
use crate::drive::profile::{PREVIEW_S, TRACKER_FLOOR_MPS, TRACKER_GAIN};
use crate::drive::{Observation, Pedal};
use crate::error::{Error, Result};
use crate::limit::{Limit, LimitOptions};
use crate::line::RacingLine;
use crate::policy::RkhsPolicy;
use crate::policy::repair::PedalRepair;
use crate::policy::rkhs::DEFAULT_RIDGE;
use crate::sim::Simulator;
use crate::track::Track;

/// Bisection steps on k.
pub const BISECTION_STEPS: usize = 14;
/// Laps below the bisection's k searched for a faster completed lap.
pub const SCAN_STEPS: usize = 16;
/// Their spacing in k: the scan reaches [`SCAN_STEPS`]·[`SCAN_STEP`] = 0.08 below.
pub const SCAN_STEP: f64 = 0.005;
/// Laps of fitted policies driven at most by one kind of repair (the first fit and its
/// repairs).
pub const REPAIR_LAPS: usize = 150;
/// Laps of fitted policies driven at most: the plain repairs', then those braking earlier.
pub const MOST_REPAIR_LAPS: usize = 2 * REPAIR_LAPS;

/// The speed profile the ceiling tracks for `car` on `track`: the crest-aware QSS limit
/// ([`LimitOptions::CRESTS`]) on the centre line, or, where the car holds `line`, that line's
/// read at the centre line's stations
/// ([`line_limit_on_centre_with`](crate::limit::line_limit_on_centre_with)).
pub fn profile(track: &Track, car: &Car, line: Option<&RacingLine>) -> Limit {
    profile_with(track, car, line, LimitOptions::CRESTS)
}

/// The speed profile a flying lap tracks ([`profile`] of a flying lap,
/// [`LimitOptions::flying`]): the car crosses the line at the speed the lap ends with, and
/// brakes before the line for the next lap's first corner.
pub fn flying_profile(track: &Track, car: &Car, line: Option<&RacingLine>) -> Limit {
    profile_with(track, car, line, LimitOptions::CRESTS.flying())
}

/// The limit's profile under `options`, on `line` read at the centre line's stations, or on
/// the centre line.
fn profile_with(
    track: &Track,
    car: &Car,
    line: Option<&RacingLine>,
    options: LimitOptions,
) -> Limit {
    match line {
        Some(line) => crate::limit::line_limit_on_centre_with(track, line, car, options),
        None => crate::limit::limit_lap_with(track, car, options),
    }
}

/// A speed controller following k times the limit's speed profile.
#[derive(Debug, Clone)]
pub struct ProfileTracker<'a> {
    /// The limit's speed at each track sample (m/s), plus the finish.
    pub profile: &'a [f64],
    /// The track's length (m).
    pub length: f64,
    /// The scale k.
    pub k: f64,
    /// The profile is a flying lap's: the preview past the finish reads the next lap's start.
    pub flying: bool,
}

impl<'a> ProfileTracker<'a> {
    /// A tracker of k times `limit`'s profile on a track of `length` metres.
    pub fn new(limit: &Limit, length: f64, k: f64) -> ProfileTracker<'_> {
        ProfileTracker {
            profile: &limit.speed,
            length,
            k,
            flying: limit.flying,
        }
    }

    /// A tracker of the speeds `speed` at `limit`'s stations (a profile lowered from it,
    /// [`lowered_where_it_fails`]) on a track of `length` metres.
    pub fn of_speeds(limit: &Limit, speed: &'a [f64], length: f64) -> ProfileTracker<'a> {
        ProfileTracker {
            profile: speed,
            length,
            k: 1.0,
            flying: limit.flying,
        }
    }

    /// The previewed target k·min v_lim over [s, s + v·τ] (m/s); on a flying profile the
    /// window past the finish goes on from the start.
    pub fn target(&self, x: f64, speed: f64) -> f64 {
        let n = self.profile.len() - 1;
        let at = |x: f64| ((x.clamp(0.0, 1.0) * n as f64).round() as usize).min(n);
        let ahead = x + speed * PREVIEW_S / self.length;
        let lowest = |i: usize, j: usize| {
            self.profile[i..=j]
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min)
        };
        let mut v = lowest(at(x), at(ahead));
        if self.flying && ahead > 1.0 {
            v = v.min(lowest(0, at(ahead - 1.0)));
        }
        (self.k * v).max(TRACKER_FLOOR_MPS)
    }
}

impl Pedal for ProfileTracker<'_> {
    fn pedal(&mut self, obs: &Observation) -> f64 {
        (TRACKER_GAIN * (self.target(obs.x, obs.speed) - obs.speed)).clamp(-1.0, 1.0)
    }
}

/// The ceiling of a car on a track. The tracked profile's lap is the ceiling the learners are
/// measured against; the fitted policy is a lower bound of the M-kernel policies' best (a
/// least-squares fit of a bang-bang pedal, not an optimum).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Ceiling {
    /// The physical limit's reward (m/s): the yardstick of the shares, crest-blind.
    pub limit_mps: f64,
    /// The reward of the limit whose profile was tracked (m/s), crest-aware ([`profile`]).
    pub profile_mps: f64,
    /// The profile scale k of the fastest completed lap ([`tracked_profile`]).
    pub k: f64,
    /// The reward of the tracked profile's lap (m/s).
    pub tracked_mps: f64,
    /// The lap of the profile lowered only where it fails ([`lowered_where_it_fails`]), where
    /// it completes faster than the uniform scale's (m/s): the fit then targets its pedal.
    pub lowered_mps: Option<f64>,
    /// Policy kernels M.
    pub kernels: usize,
    /// The completed lap of the M-kernel policy fitted to the tracked lap's pedal and repaired
    /// where it failed (m/s); 0 if none completed within [`MOST_REPAIR_LAPS`] laps.
    pub policy_mps: f64,
    /// That policy.
    pub policy: Option<RkhsPolicy>,
    /// Repairs before it completed, the plain ones' [`REPAIR_LAPS`] included where the
    /// repairs braking earlier made it ([`MOST_REPAIR_LAPS`] if none did).
    pub repairs: usize,
}

/// The scale k of `limit`'s speed profile whose tracked lap is the fastest completed one,
/// and that lap's reward (m/s): step 1 of the ceiling, whose profile is [`profile`]'s. The
/// largest completing k by bisection, then [`SCAN_STEPS`] laps below it (the module's
/// step 1); of equally fast laps the largest k.
pub fn tracked_profile(sim: &Simulator, limit: &Limit) -> Result<(f64, f64)> {
    let (top, mut best) = largest_completing_scale(sim, limit)?;
    for i in 1..=SCAN_STEPS {
        let k = top - i as f64 * SCAN_STEP;
        if k <= 0.0 {
            break;
        }
        let lap = sim.lap(&mut ProfileTracker::new(limit, sim.track.length, k));
        if lap.completed && lap.reward_mps > best.1 {
            best = (k, lap.reward_mps);
        }
    }
    Ok(best)
}

/// The largest scale k of `limit`'s speed profile whose tracked lap completes, by bisection,
/// and the fastest completed lap of the bisection's, (k, reward).
fn largest_completing_scale(sim: &Simulator, limit: &Limit) -> Result<(f64, (f64, f64))> {
    let (mut lo, mut hi) = (0.0, 1.0);
    let mut best = (0.0, 0.0);
    for _ in 0..BISECTION_STEPS {
        let k = 0.5 * (lo + hi);
        let lap = sim.lap(&mut ProfileTracker::new(limit, sim.track.length, k));
        if lap.completed {
            lo = k;
            if lap.reward_mps >= best.1 {
                best = (k, lap.reward_mps);
            }
        } else {
            hi = k;
        }
    }
    if best.1 == 0.0 {
        return Err(Error::Numerical(format!(
            "no scale of the limit's speed profile completes {}",
            sim.track.name
        )));
    }
    Ok((lo, best))
}

/// Laps of the locally lowered profile at most ([`lowered_where_it_fails`]).
pub const LOWERING_LAPS: usize = 100;
/// How far above the uniform scale k the locally lowered profile starts.
pub const LOWERING_HEADROOM: f64 = 0.1;
/// The scale the lowered profile starts from: k + [`LOWERING_HEADROOM`], at most 1.
pub fn lowering_from(k: f64) -> f64 {
    (k + LOWERING_HEADROOM).min(1.0)
}

/// How much a failure lowers the scale before it.
pub const LOWERING_STEP: f64 = 0.02;
/// How far before a failure the scale is lowered (m): a braking zone of a fast car.
pub const LOWERING_BEFORE_M: f64 = 150.0;
/// How far past it (m).
pub const LOWERING_AFTER_M: f64 = 25.0;

/// The profile scaled by k + [`LOWERING_HEADROOM`] (at most 1) and lowered only where its
/// tracked lap fails: each failure at s_f lowers the scale over [s_f − 150 m, s_f + 25 m] by
/// [`LOWERING_STEP`], never below k, until a lap completes (within [`LOWERING_LAPS`]). The
/// lowered speeds at the profile's stations and their lap's reward; `None` if none completed
/// or a lap failed too slow.
pub fn lowered_where_it_fails(sim: &Simulator, profile: &Limit, k: f64) -> Option<(Vec<f64>, f64)> {
    let length = sim.track.length;
    let n = profile.speed.len() - 1;
    let mut scale = vec![lowering_from(k); n + 1];
    for _ in 0..LOWERING_LAPS {
        let scaled: Vec<f64> = (profile.speed.iter().zip(&scale))
            .map(|(v, s)| v * s)
            .collect();
        let lap = sim.lap(&mut ProfileTracker::of_speeds(profile, &scaled, length));
        let Some(failure) = lap.failure else {
            return Some((scaled, lap.reward_mps));
        };
        if failure.reason.too_slow() {
            return None;
        }
        let at = failure.distance_m % length;
        let station = |s: f64| ((s / length).clamp(0.0, 1.0) * n as f64).round() as usize;
        let window = station(at - LOWERING_BEFORE_M)..=station(at + LOWERING_AFTER_M).min(n);
        if scale[window.clone()].iter().all(|&s| s <= k) {
            return None;
        }
        for s in &mut scale[window] {
            *s = (*s - LOWERING_STEP).max(k);
        }
    }
    None
}

/// The ceiling of `kernels`-kernel policies in `sim` (its track, car and steering) tracking
/// `profile`'s speeds ([`profile`]), its shares of `limit`'s reward (the crest-blind limit).
pub fn ceiling_with(
    sim: &Simulator,
    limit: &Limit,
    profile: &Limit,
    kernels: usize,
) -> Result<Ceiling> {
    let tracked = TrackedLap::of(sim, profile)?;
    ceiling_from(sim, limit, &tracked, kernels)
}

/// Step 1 of the ceiling, whatever the kernels: the uniform scale's lap and the locally
/// lowered one's, and the pedal the fits target.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackedLap {
    /// The reward of the limit whose profile was tracked (m/s).
    pub profile_mps: f64,
    /// The profile scale k of the fastest completed uniform lap ([`tracked_profile`]).
    pub k: f64,
    /// Its reward (m/s).
    pub tracked_mps: f64,
    /// The lowered lap's reward where it is faster ([`lowered_where_it_fails`]).
    pub lowered_mps: Option<f64>,
    /// The pedal of the faster of the two, (x, a) at each driver step of the timed lap.
    pub pedal: Vec<(f64, f64)>,
}

impl TrackedLap {
    /// The tracked laps of `profile` in `sim`.
    pub fn of(sim: &Simulator, profile: &Limit) -> Result<TrackedLap> {
        let (k, tracked_mps) = tracked_profile(sim, profile)?;
        // The fit's pedal: the uniform scale's lap, or the locally lowered one's where faster.
        let lowered =
            lowered_where_it_fails(sim, profile, k).filter(|(_, reward)| *reward > tracked_mps);
        let length = sim.track.length;
        let mut tracker = match &lowered {
            Some((scaled, _)) => ProfileTracker::of_speeds(profile, scaled, length),
            None => ProfileTracker::new(profile, length, k),
        };
        let mut traced = sim.clone();
        traced.config.trace = true;
        let lap = traced.lap(&mut tracker);
        // A flying lap's policy is fitted to the timed lap's pedal; the run-up keeps its speed.
        let timed_from = if sim.config.flying {
            sim.track.length
        } else {
            f64::NEG_INFINITY
        };
        let pedal = lap
            .trace
            .iter()
            .filter(|p| p.distance_m >= timed_from)
            .map(|p| (p.x, p.pedal))
            .collect();
        Ok(TrackedLap {
            profile_mps: profile.reward_mps,
            k,
            tracked_mps,
            lowered_mps: lowered.map(|(_, reward)| reward),
            pedal,
        })
    }
}

/// The ceiling of `kernels`-kernel policies fitted to `tracked`'s pedal (step 2), `tracked`
/// being [`TrackedLap::of`] a profile in `sim`: one tracked lap serves every kernel count.
pub fn ceiling_from(
    sim: &Simulator,
    limit: &Limit,
    tracked: &TrackedLap,
    kernels: usize,
) -> Result<Ceiling> {
    let mut ceiling = Ceiling {
        limit_mps: limit.reward_mps,
        profile_mps: tracked.profile_mps,
        k: tracked.k,
        tracked_mps: tracked.tracked_mps,
        lowered_mps: tracked.lowered_mps,
        kernels,
        policy_mps: 0.0,
        policy: None,
        repairs: MOST_REPAIR_LAPS,
    };
    // The plain repairs first; where none completes, from the tracked lap's pedal again,
    // braking earlier for a corner that fails again.
    for (tries, repair) in [
        PedalRepair::new(kernels),
        PedalRepair::new(kernels).braking_earlier(),
    ]
    .into_iter()
    .enumerate()
    {
        if let Some((policy, reward, repairs)) =
            repaired(sim, tracked.pedal.clone(), kernels, repair)?
        {
            ceiling.policy_mps = reward;
            ceiling.policy = Some(policy);
            ceiling.repairs = tries * REPAIR_LAPS + repairs;
            break;
        }
    }
    Ok(ceiling)
}

/// The policy fitted to `targets` and repaired by `repair` where its laps fail in `sim`, its
/// reward and the repairs before it completed; `None` if none did within [`REPAIR_LAPS`] laps.
fn repaired(
    sim: &Simulator,
    mut targets: Vec<(f64, f64)>,
    kernels: usize,
    mut repair: PedalRepair,
) -> Result<Option<(RkhsPolicy, f64, usize)>> {
    for repairs in 0..REPAIR_LAPS {
        let policy = RkhsPolicy::fit(&targets, kernels, repair.spacing, DEFAULT_RIDGE)?;
        let lap = sim.lap(&mut policy.pedal());
        match lap.failure {
            None => return Ok(Some((policy, lap.reward_mps, repairs))),
            Some(failure) => repair.repair(&mut targets, failure.x, failure.reason.too_slow()),
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::car::Car;
    use crate::limit::limit_lap;

    /// The simulator on the built-in Ridgeway with the Spirit 300, and its limit lap.
    fn ridgeway() -> (Simulator, Limit) {
        let track = crate::track::builtin::load("ridgeway").unwrap().unwrap();
        let car = Car::spirit_300();
        let limit = limit_lap(&track, &car);
        (Simulator::new(track, &car), limit)
    }

    /// On Ridgeway the tracked profile completes above the demonstrator (15 m/s) and below
    /// the limit, the failed upper end of the bisection, one step above its k, does fail, and
    /// the tracked lap is at least as fast as the bisection's and drives its reward again.
    #[test]
    fn the_tracked_profile_is_the_fastest_completing_scale() {
        let (sim, limit) = ridgeway();
        let (k, reward) = tracked_profile(&sim, &limit).unwrap();
        assert!(
            reward > 15.0 && reward < limit.reward_mps,
            "{reward} {}",
            limit.reward_mps
        );
        let lap = |k: f64| sim.lap(&mut ProfileTracker::new(&limit, sim.track.length, k));
        assert_eq!(lap(k).reward_mps, reward);
        let (top, (_, bisected)) = largest_completing_scale(&sim, &limit).unwrap();
        assert!(
            k <= top && reward >= bisected,
            "{k} {reward}, {top} {bisected}"
        );
        let above = top + 0.5f64.powi(BISECTION_STEPS as i32);
        assert!(!lap(above).completed, "k = {above} completed");
    }

    /// Past some scale a lap can complete and yet be slower: on Ridgeway's minimum-curvature
    /// line, with the path tracker, the two-track Spirit 300 completes the whole profile
    /// (k = 1, the bisection's top) sliding out of the hairpins, slower than its lap a few
    /// hundredths below, which the ceiling takes: above 95 % of the centre line's limit.
    #[test]
    fn an_over_driven_lap_is_not_the_ceiling() {
        use crate::drive::steering::Steering;
        use crate::drive::tracker::PathTracker;
        let (mut sim, centre) = ridgeway();
        let car = Car::spirit_300();
        let line = crate::line::BaseLine::MinCurvature
            .line(&sim.track, &car)
            .unwrap();
        let limit = profile(&sim.track, &car, line.as_deref());
        sim.config.steering = Steering::Tracker(PathTracker::new());
        sim.config.line = line;
        let (top, _) = largest_completing_scale(&sim, &limit).unwrap();
        let over = sim.lap(&mut ProfileTracker::new(&limit, sim.track.length, top));
        let (k, reward) = tracked_profile(&sim, &limit).unwrap();
        assert!(
            over.completed && k < top && reward > over.reward_mps + 1.0,
            "k {k} {reward} m/s, k {top} {} m/s",
            over.reward_mps
        );
        assert!(
            reward > 0.95 * centre.reward_mps,
            "{reward} m/s against {}",
            centre.reward_mps
        );
    }

    /// One corner holds the uniform scale down: on Ridgeway with the PI steering the
    /// crest-aware profile lowered only where it fails completes faster than the uniform
    /// scale's lap (38.3 against 34.7 m/s), each station between k and k + 0.1 times the
    /// profile, lowered at some and not at others; the ceiling fits its pedal, and the
    /// uniform lap stays the ceiling.
    #[test]
    fn lowering_only_where_it_fails_beats_the_uniform_scale() {
        let (sim, crest_blind) = ridgeway();
        let limit = profile(&sim.track, &Car::spirit_300(), None);
        let (k, uniform) = tracked_profile(&sim, &limit).unwrap();
        let (scaled, reward) = lowered_where_it_fails(&sim, &limit, k).unwrap();
        assert!(reward > uniform + 2.0, "{reward} against {uniform} m/s");
        let top = lowering_from(k);
        let scales: Vec<f64> = (scaled.iter().zip(&limit.speed))
            .filter(|(_, v)| **v > 0.0)
            .map(|(s, v)| s / v)
            .collect();
        let eps = 1e-12;
        assert!(
            scales.iter().all(|&s| s > k - eps && s < top + eps),
            "scales outside [{k}, {top}]"
        );
        assert!(scales.iter().any(|&s| s < top - 1e-6) && scales.iter().any(|&s| s > top - eps));
        let lap = sim.lap(&mut ProfileTracker::of_speeds(
            &limit,
            &scaled,
            sim.track.length,
        ));
        assert_eq!(lap.reward_mps, reward);
        let c = ceiling_with(&sim, &crest_blind, &limit, 30).unwrap();
        assert_eq!((c.tracked_mps, c.lowered_mps), (uniform, Some(reward)));
    }

    /// On Ridgeway the plain 30-kernel fit of the tracked lap's pedal fails, and the repaired
    /// fit completes: the ceiling's policy drives its reward again, between the demonstrator
    /// and the limit.
    #[test]
    fn the_repaired_fit_completes_where_the_plain_fit_fails() {
        let (sim, limit) = ridgeway();
        let c = ceiling_with(&sim, &limit, &limit, 30).unwrap();
        assert!(c.repairs > 0, "the plain fit completed");
        let policy = c.policy.clone().expect("no repaired fit completed");
        let lap = sim.lap(&mut policy.pedal());
        assert!(lap.completed);
        assert_eq!(lap.reward_mps, c.policy_mps);
        assert!(c.policy_mps > 15.0 && c.policy_mps < c.limit_mps, "{c:?}");
    }

    /// The path tracker lifts the ceiling: on Ridgeway it tracks a profile scale at least 0.15
    /// above the PI steering's (0.965 against 0.770), and that lap keeps the car's centre
    /// within the road, |lateral| below half the road's width less half the car's.
    #[test]
    fn the_tracker_lifts_the_ceiling_within_the_road() {
        use crate::drive::steering::Steering;
        use crate::drive::tracker::PathTracker;
        let (pi, limit) = ridgeway();
        let mut tracker = pi.clone();
        tracker.config.steering = Steering::Tracker(PathTracker::new());
        let (k_pi, reward_pi) = tracked_profile(&pi, &limit).unwrap();
        let (k, reward) = tracked_profile(&tracker, &limit).unwrap();
        assert!(
            k > k_pi + 0.15 && reward > reward_pi,
            "k {k} against {k_pi}"
        );
        tracker.config.trace = true;
        let lap = tracker.lap(&mut ProfileTracker::new(&limit, tracker.track.length, k));
        let widest = lap
            .trace
            .iter()
            .map(|p| p.lateral.abs())
            .fold(0.0, f64::max);
        let road = tracker.track.samples[0].width / 2.0 - tracker.vehicle.car.width / 2.0;
        assert!(
            lap.completed && widest < road,
            "{widest} m off the centre line"
        );
    }

    /// A flying profile's preview past the finish reads the next lap's start; a standing
    /// one's stops at the finish.
    #[test]
    fn a_flying_trackers_preview_wraps_past_the_line() {
        let mut limit = Limit {
            lap_time_s: 2.0,
            reward_mps: 50.0,
            flying: true,
            speed: vec![20.0, 50.0, 50.0, 50.0, 50.0],
            track_length: 100.0,
        };
        // At x = 0.99 and 40 m/s the 0.3 s preview reaches x = 1.11: station 0's 20 m/s.
        let target = |limit: &Limit| ProfileTracker::new(limit, 100.0, 0.9).target(0.99, 40.0);
        assert_eq!(target(&limit), 18.0);
        limit.flying = false;
        assert_eq!(target(&limit), 45.0);
    }
}
