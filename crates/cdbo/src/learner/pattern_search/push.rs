//! The push: the whole pedal raised at once, then repaired where its laps fail.
//!
//! Steps of one kernel climb a lap's speed one place at a time, and most of them fail at the
//! corner just after the moved kernel. A push moves every place at once: pedal targets
//! a(xₖ) = π_{w*}(xₖ) + U at G evenly spaced xₖ (π_{w*} the best lap's pedal), fitted by
//! ridge regression with the policy's M kernels (paper eq. 9). The pushed lap is too fast for
//! most corners; while it fails at x_f, the targets over the [`REPAIR_DISTANCE`] metres of road
//! before x_f (two kernel spacings when the lap's length is not told) move by ±δ (down where
//! the car was too fast, up where it stalled) and are fitted again: the ceiling's repair
//! ([`PedalRepair`]), which walks the failure round the lap corner by corner. The first lap
//! that completes ends the push, kept if it is faster than the best lap; each push is
//! followed by one of half the size, up to [`PUSHES`] pushes. A later push **holds** the
//! targets that a kept push had to lower (the car was at its limit there): it raises the
//! others only.
//!
//! The repair's stretch is road, not kernels: a car brakes for a corner over a distance set by
//! its speed and grip, whatever the policy's resolution. Two spacings are 124–219 m on the
//! training panels; measured there (docs/results/beyond), 200 / 250 / 275 / 300 m of road gave
//! 34.09 / 35.56 / 35.61 / 35.53 m/s against 34.86 for two spacings, and holding the lowered
//! targets kept 35.62 m/s with 11 fewer failed laps a run.
//!
//! **Not through the corner before.** Where corners come close, 275 m before a failure reach
//! back over the previous corner and the straight between, and lower a pedal the car needed
//! there. The stretch before a failure at x_f is therefore
//! min([`REPAIR_DISTANCE`], max(2/(M − 1), ½·(x_f − x_p))) with x_p the nearest place before
//! x_f, by more than [`SAME_PLACE`], where the pushes failed (the start line if none): at most half
//! the road back to the last corner the car was too fast for, but never less than the pedal's
//! own resolution, two kernel spacings. Measured (car1-trb1, tracker on the minimum-curvature
//! line, 50 kernels, seeds 0–2, cdbo's simulator): Aalborg 85.80 → 79.05 s, E-Track 2 128.06 →
//! 126.96 s, Forza 96.48 → 96.26 s, Forza with 100 kernels 98.44 → 98.55 s; on the training
//! panels (PI on the centre line, seeds 100–105) Ridgeway-30 37.37 → 37.16 m/s and Forza-50
//! 40.25 → 39.50 m/s, the 30-kernel ones unchanged (their two spacings exceed 275 m).
//!
//! A push gives up when its repairs oscillate at one place (δ below [`GIVE_UP`]·δ₀: the car
//! stalls there with less pedal and spins with more), when it is **stuck**
//! ([`PatternSearchConfig::push_patience`] laps in a row fail short of the furthest place its
//! laps reached: two places, each repair undoing the other, e.g. a corner the car spins in
//! followed within the repair's reach by a climb it stalls on, are farther apart than the
//! reversal's one spacing), or after [`LAPS`] laps. Its size is drawn
//! around U₀ from the seed (±[`JITTER`]): where a failure lands moves from corner to corner
//! with U, so runs with different seeds try different pushes and their mean measures the
//! method rather than one push.
//!
//! **After a push not kept.** A push whose first complete lap is slower than the best (its
//! repairs left the pedal too low somewhere), or that gave up, is followed by the next push,
//! half its size, begun afresh from the best lap: it holds nothing and remembers no failure
//! ([`PatternSearchConfig::push_after_unkept`]). Before, the pushes ended there and the sweeps
//! had the rest of the laps. Measured (300 laps, mean best reward): the training panels (PI on
//! the centre line, seeds 100–105) 34.95 → 35.17 m/s; the spirit-300 with the line learned
//! (tracker, seeds 0–5) Allondaz-30 31.56 → 31.94 and E-Track 2-30 32.02 → 32.44 m/s, Forza-50
//! unchanged. Holding what the unkept push or the kept ones lowered gave 35.10 and 35.07 m/s
//! on the training panels.

use rand::Rng;
use serde::{Deserialize, Serialize};

use super::PatternSearchConfig;
use crate::error::Result;
use crate::optimizers::{FailedLap, SearchBox, rng_for};
use crate::policy::RkhsPolicy;
#[cfg(test)]
use crate::policy::repair::REPAIR_STEP;
use crate::policy::repair::{PedalRepair, REPAIR_SPACINGS};
use crate::policy::rkhs::DEFAULT_RIDGE;

/// The first push's size U₀ (pedal units), chosen by a sweep on the training panels and
/// checked again with repairs over road (0.25 / 0.3 / 0.35 / 0.4 / 0.45: 34.22 / 35.01 /
/// 35.68 / 34.96 / 35.13 m/s; docs/results/beyond).
pub const SIZE: f64 = 0.35;
/// Failures closer than this (lap fraction) to a later one are at the same place: the
/// stretch a repair moves stops half-way back to the nearest *other* place the pushes failed.
pub const SAME_PLACE: f64 = 0.01;
/// Pushes at most: U₀, then U₀/2, U₀/4, U₀/8, each after a kept one (chosen on the training
/// panels: 2, 3, 4, 6 pushes gave 34.54, 34.81, 34.86, 34.86 m/s; with repairs over road, 1,
/// 2, 3, 4 gave 34.41, 35.31, 35.51, 35.61).
pub const PUSHES: u32 = 4;
/// The relative spread of a push's size around its nominal value, drawn from the seed.
pub const JITTER: f64 = 0.1;
/// Laps of one push at most.
pub const LAPS: usize = 60;
/// Failed laps in a row short of the furthest place a push's laps reached after which it
/// gives up (chosen by measurement: the spirit-300 on Allondaz, 30 kernels, seed 1 of the
/// tracker on the line, spun at 0.285 and stalled at 0.340 of the lap in turn for 58 laps;
/// 8 and 12 give the same best laps there, 8 the fewer failed ones).
pub const PATIENCE: usize = 8;
/// A push gives up once its repair step δ falls below this fraction of δ₀.
pub const GIVE_UP: f64 = 0.3;
/// The road (m) before a failure over which a repair moves the targets, when the lap's length
/// is told (chosen on the training panels; docs/results/beyond).
pub const REPAIR_DISTANCE: f64 = 275.0;
/// Policies of more kernels are not pushed: each lap's fit costs O(G·M²), G ≥ 10(M − 1).
pub const MAX_KERNELS: usize = 200;
/// Pedal targets per push at least (more for fine policies: ten per kernel spacing).
const MIN_TARGETS: usize = 601;

/// A push under way.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Push {
    /// Which push this is: 1 for the first (size U₀), n for the n-th (U₀/2ⁿ⁻¹).
    pub number: u32,
    /// The pedal targets a(xₖ) at xₖ = k/(G − 1).
    pub targets: Vec<f64>,
    /// The repairs' step δ and last failure.
    pub repair: PedalRepair,
    /// Laps driven in this push.
    pub laps: usize,
    /// The net move of every target by the repairs of this push and of the kept pushes before
    /// it; a later push holds the targets moved down (empty in pushes saved before it existed).
    #[serde(default)]
    pub repaired: Vec<f64>,
    /// The weights the targets move, when this is the repair of a start rather than a push
    /// ([`Push::repairing`]): the targets are then offsets to its pedal, and a lap's weights
    /// are these plus the offsets' fit, the start kept exactly where no repair moved it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<Vec<f64>>,
    /// The places (lap fractions) where this push's laps and the kept pushes' before it failed,
    /// in the order they failed: a repair's stretch stops half-way back to the nearest other
    /// one before the failure (empty in pushes saved before it existed).
    #[serde(default)]
    pub failures: Vec<f64>,
}

impl Push {
    /// Push `number` of a search set by `config` from the best weights `best` of a policy
    /// with length-scale ℓ, after the kept push `previous`: the best pedal raised by
    /// U = U₀/2^(number − 1)·(1 + J·(2u − 1)), u uniform from (seed, `number`), except at the
    /// targets that `previous` and the pushes before it moved down, which stay.
    pub fn begin(
        number: u32,
        best: &[f64],
        lengthscale: f64,
        config: &PatternSearchConfig,
        previous: Option<&Push>,
    ) -> Result<Push> {
        let u: f64 = rng_for(config.seed, u64::MAX - u64::from(number)).random();
        let size = config.push / f64::from(1u32 << (number - 1).min(31))
            * (1.0 + JITTER * (2.0 * u - 1.0));
        Push::sized(number, size, best, lengthscale, config, previous)
    }

    /// Push `number` of size `size`.
    fn sized(
        number: u32,
        size: f64,
        best: &[f64],
        lengthscale: f64,
        config: &PatternSearchConfig,
        previous: Option<&Push>,
    ) -> Result<Push> {
        let policy = RkhsPolicy::new(best.to_vec(), lengthscale)?;
        let g = targets_for(best.len());
        let repaired = previous
            .map(|p| p.repaired.clone())
            .filter(|r| r.len() == g)
            .unwrap_or_else(|| vec![0.0; g]);
        let failures = previous.map(|p| p.failures.clone()).unwrap_or_default();
        let repair = PedalRepair::new(best.len()).starting_at(config.repair_step);
        Ok(Push {
            number,
            targets: (0..g)
                .map(|k| policy.action(x_of(k, g)) + if repaired[k] < 0.0 { 0.0 } else { size })
                .collect(),
            repair: match config.track_length {
                Some(length) => repair.over(REPAIR_DISTANCE / length),
                None => repair,
            },
            laps: 0,
            repaired,
            base: None,
            failures,
        })
    }

    /// The repair of the start `start` of a search set by `config` (a policy learned
    /// elsewhere, whose lap here failed): a push of size 0 whose targets are offsets to the
    /// start's pedal, all 0 until a repair moves them. Refitting the start's pedal itself
    /// would smooth away its sharp braking points (measured: a 112.5 s lap became 137 s).
    pub fn repairing(start: &[f64], config: &PatternSearchConfig) -> Push {
        let g = targets_for(start.len());
        let repair = PedalRepair::new(start.len()).starting_at(config.repair_step);
        Push {
            number: 0,
            targets: vec![0.0; g],
            repair: match config.track_length {
                Some(length) => repair.over(REPAIR_DISTANCE / length),
                None => repair,
            },
            laps: 0,
            repaired: vec![0.0; g],
            base: Some(start.to_vec()),
            failures: Vec::new(),
        }
    }

    /// Whether a saved push is one this code could have made for an M-kernel policy: a push
    /// number in 1..=[`PUSHES`] (0 for the repair of a start, [`Push::repairing`]),
    /// [`targets_for`]`(M)` finite targets and net repairs, a positive finite repair step and
    /// window at the policy's kernel spacing, at most [`LAPS`] laps.
    pub fn is_sound(&self, kernels: usize) -> bool {
        let finite = |v: &[f64]| v.iter().all(|a| a.is_finite());
        (u32::from(self.base.is_none())..=PUSHES).contains(&self.number)
            && self.targets.len() == targets_for(kernels)
            && self.repaired.len() == self.targets.len()
            && finite(&self.targets)
            && finite(&self.repaired)
            && self.repair.window().is_finite()
            && self.repair.window() > 0.0
            && self.repair.step.is_finite()
            && self.repair.step > 0.0
            && self.repair.first.is_finite()
            && self.repair.first > 0.0
            && self.repair.spacing == PedalRepair::new(kernels).spacing
            && self
                .repair
                .last
                .is_none_or(|(x, d)| x.is_finite() && d.is_finite())
            && self.laps <= LAPS
            && self.failures.len() <= (PUSHES as usize + 1) * LAPS
            && self.failures.iter().all(|x| (0.0..=1.0).contains(x))
            && self
                .base
                .as_ref()
                .is_none_or(|b| b.len() == kernels && finite(b))
    }

    /// The weights of the push's next lap: its targets fitted by ridge regression, in the box.
    pub fn weights(&self, lengthscale: f64, bounds: &SearchBox) -> Result<Vec<f64>> {
        let mut w = RkhsPolicy::fit(
            &self.pairs(),
            bounds.lower.len(),
            lengthscale,
            DEFAULT_RIDGE,
        )?
        .weights;
        if let Some(base) = &self.base {
            w.iter_mut().zip(base).for_each(|(w, b)| *w += b);
        }
        bounds.clamp(&mut w);
        Ok(w)
    }

    /// Repairs the targets for a lap that failed as `failure` says; false if the push gives up
    /// instead (its repairs oscillate, it is stuck, or it has driven [`LAPS`] laps).
    pub fn repair(&mut self, failure: FailedLap, config: &PatternSearchConfig) -> bool {
        if self.laps >= LAPS || self.repair.step < GIVE_UP * self.repair.first {
            return false;
        }
        let mut pairs = self.pairs();
        let stretch = self.stretch(failure.at, config.stop_half_way);
        self.failures.push(failure.at.clamp(0.0, 1.0));
        if config.push_patience > 0 && self.short_of_furthest() >= config.push_patience {
            return false;
        }
        self.repair
            .repair_over(&mut pairs, failure.at, failure.too_slow, stretch);
        for ((target, net), (_, a)) in self.targets.iter_mut().zip(&mut self.repaired).zip(pairs) {
            *net += a - *target;
            *target = a;
        }
        true
    }

    /// How many of this push's failed laps in a row, to the last, fell short of the furthest
    /// place its laps reached (the places before this push's own laps were carried from the
    /// kept pushes before it).
    fn short_of_furthest(&self) -> usize {
        let own = &self.failures[self.failures.len().saturating_sub(self.laps)..];
        let furthest = own
            .iter()
            .enumerate()
            .fold(0, |best, (i, &x)| if x > own[best] { i } else { best });
        own.len().saturating_sub(furthest + 1)
    }

    /// The stretch (lap fraction) a repair moves before a failure at `at`: the repair's window;
    /// with `stop_half_way`, not further back than half-way to the nearest other place
    /// before it where the pushes failed (the start line if none), nor less than two kernel
    /// spacings (the module's "Not through the corner before").
    fn stretch(&self, at: f64, stop_half_way: bool) -> f64 {
        if !stop_half_way {
            return self.repair.window();
        }
        let last_other = self
            .failures
            .iter()
            .copied()
            .filter(|&x| x < at - SAME_PLACE)
            .fold(0.0, f64::max);
        let half_way = 0.5 * (at - last_other);
        self.repair
            .window()
            .min(half_way.max(REPAIR_SPACINGS * self.repair.spacing))
    }

    /// The targets as (xₖ, a(xₖ)) pairs.
    fn pairs(&self) -> Vec<(f64, f64)> {
        let g = self.targets.len();
        self.targets
            .iter()
            .enumerate()
            .map(|(k, &a)| (x_of(k, g), a))
            .collect()
    }
}

/// The number G of pedal targets of an M-kernel policy.
pub fn targets_for(kernels: usize) -> usize {
    MIN_TARGETS.max(10 * kernels.saturating_sub(1) + 1)
}

/// The place xₖ = k/(G − 1) of target k.
fn x_of(k: usize, g: usize) -> f64 {
    k as f64 / (g - 1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::policy::rkhs::default_lengthscale;

    fn best_and_lengthscale() -> (Vec<f64>, f64) {
        (
            (0..11).map(|i| 0.3 * (i as f64).sin()).collect(),
            default_lengthscale(11),
        )
    }

    /// The default search's settings with this seed (U₀ = [`SIZE`], no lap length).
    fn seeded(seed: u64) -> PatternSearchConfig {
        PatternSearchConfig {
            seed,
            ..PatternSearchConfig::default()
        }
    }

    /// A push raises the best lap's pedal by one size everywhere, within its jitter around U₀
    /// (the second around U₀/2), and its fitted weights drive that pedal.
    #[test]
    fn a_push_raises_the_best_pedal_by_its_size_everywhere() {
        let (best, l) = best_and_lengthscale();
        let policy = RkhsPolicy::new(best.clone(), l).unwrap();
        for (number, nominal) in [(1, SIZE), (2, SIZE / 2.0)] {
            let push = Push::begin(number, &best, l, &seeded(7), None).unwrap();
            let g = push.targets.len();
            assert_eq!(g, MIN_TARGETS);
            let size = push.targets[0] - policy.action(0.0);
            assert!(
                (size - nominal).abs() <= JITTER * nominal && size != nominal,
                "{size}"
            );
            for (k, a) in push.targets.iter().enumerate() {
                assert!((a - policy.action(x_of(k, g)) - size).abs() < 1e-12);
            }
            let w = push
                .weights(l, &SearchBox::around(&best, 10.0).unwrap())
                .unwrap();
            let fitted = RkhsPolicy::new(w, l).unwrap();
            for x in [0.1, 0.33, 0.5, 0.77, 0.9] {
                let target = policy.action(x) + size;
                assert!(
                    (fitted.raw(x) - target).abs() < 0.02,
                    "x {x}: {} against {target}",
                    fitted.raw(x)
                );
            }
        }
        // Other seeds, other sizes.
        let other = Push::begin(1, &best, l, &seeded(8), None).unwrap();
        assert_ne!(
            other.targets[0],
            Push::begin(1, &best, l, &seeded(7), None).unwrap().targets[0]
        );
    }

    /// A repair lowers the targets over two spacings before a failure of a too-fast car and
    /// nowhere else; the push gives up once its step has halved below GIVE_UP·δ₀ (a stall and a
    /// spin in turn at one place) or after LAPS laps.
    #[test]
    fn a_push_repairs_before_the_failure_and_gives_up_when_it_oscillates() {
        let (best, l) = best_and_lengthscale();
        let config = seeded(7);
        let mut push = Push::begin(1, &best, l, &config, None).unwrap();
        let before = push.targets.clone();
        let g = before.len();
        assert!(push.repair(FailedLap::too_fast(0.5), &config));
        for (k, (a, b)) in push.targets.iter().zip(&before).enumerate() {
            let moved = (0.3 - 1e-9..=0.5).contains(&x_of(k, g));
            assert!(
                (a - b - if moved { -REPAIR_STEP } else { 0.0 }).abs() < 1e-12,
                "k {k}"
            );
        }
        let stall = FailedLap {
            at: 0.51,
            too_slow: true,
        };
        assert!(push.repair(stall, &config)); // δ halves to 0.05
        assert!(push.repair(FailedLap::too_fast(0.5), &config)); // and to 0.025
        assert!(push.repair.step < GIVE_UP * REPAIR_STEP);
        assert!(!push.repair(stall, &config));
        let mut fresh = Push::begin(1, &best, l, &config, None).unwrap();
        fresh.laps = LAPS;
        assert!(!fresh.repair(FailedLap::too_fast(0.5), &config));
    }

    /// A push gives up once PATIENCE of its laps in a row fail short of the furthest place its
    /// own laps reached (not the places carried from the kept push before it); a lap that
    /// fails further on starts the count again; patience 0 never gives up.
    #[test]
    fn a_stuck_push_gives_up() {
        let (best, l) = best_and_lengthscale();
        let config = seeded(7);
        let fail = |push: &mut Push, at: f64, config: &PatternSearchConfig| {
            push.laps += 1;
            push.repair(FailedLap::too_fast(at), config)
        };
        let mut kept = Push::begin(1, &best, l, &config, None).unwrap();
        assert!(fail(&mut kept, 0.9, &config));
        let mut push = Push::begin(2, &best, l, &config, Some(&kept)).unwrap();
        assert_eq!(push.failures, [0.9]);
        assert!(fail(&mut push, 0.6, &config));
        for _ in 0..PATIENCE - 1 {
            assert!(fail(&mut push, 0.2, &config));
        }
        assert!(fail(&mut push, 0.61, &config));
        for _ in 0..PATIENCE - 1 {
            assert!(fail(&mut push, 0.2, &config));
        }
        let mut patient = push.clone();
        assert!(!fail(&mut push, 0.2, &config));
        let never = PatternSearchConfig {
            push_patience: 0,
            ..config
        };
        assert!(fail(&mut patient, 0.2, &never));
        assert!(fail(&mut patient, 0.2, &never));
    }

    /// With the lap's length told, a repair moves the targets over REPAIR_DISTANCE metres of
    /// road before the failure; the next push holds the targets a kept push moved down and
    /// raises the rest by its own size.
    #[test]
    fn a_push_repairs_over_road_and_the_next_holds_what_it_lowered() {
        let (best, l) = best_and_lengthscale();
        let policy = RkhsPolicy::new(best.clone(), l).unwrap();
        let config = PatternSearchConfig {
            track_length: Some(8.0 * REPAIR_DISTANCE),
            ..seeded(7)
        };
        let mut first = Push::begin(1, &best, l, &config, None).unwrap();
        let before = first.targets.clone();
        let g = before.len();
        assert!(first.repair(FailedLap::too_fast(0.5), &config));
        let lowered = |k: usize| (0.375..=0.5).contains(&x_of(k, g));
        let moves = first.targets.iter().zip(&before).zip(&first.repaired);
        for (k, ((a, b), net)) in moves.enumerate() {
            let moved = if lowered(k) { -REPAIR_STEP } else { 0.0 };
            assert!((a - b - moved).abs() < 1e-12, "k {k}");
            assert!((net - moved).abs() < 1e-12, "k {k}");
        }
        let second = Push::begin(2, &best, l, &config, Some(&first)).unwrap();
        let size = second.targets[0] - policy.action(0.0);
        assert!((size - SIZE / 2.0).abs() <= JITTER * SIZE / 2.0, "{size}");
        for (k, a) in second.targets.iter().enumerate() {
            let raised = if lowered(k) { 0.0 } else { size };
            assert!(
                (a - policy.action(x_of(k, g)) - raised).abs() < 1e-12,
                "k {k}"
            );
        }
        assert_eq!(second.repaired, first.repaired);
        assert!(second.is_sound(best.len()));
    }

    /// A repair's stretch stops half-way back to the nearest other place the pushes failed
    /// before it (the start line at first), never below two kernel spacings nor above the
    /// window; failures within SAME_PLACE of each other are one place, and the next push
    /// remembers them.
    #[test]
    fn a_repair_does_not_reach_through_the_corner_before() {
        let (best, l) = best_and_lengthscale();
        // 11 kernels: spacing 0.1, two spacings 0.2; the window 0.25 of the lap.
        let config = PatternSearchConfig {
            track_length: Some(4.0 * REPAIR_DISTANCE),
            ..seeded(7)
        };
        let mut push = Push::begin(1, &best, l, &config, None).unwrap();
        let g = push.targets.len();
        let lowered_over = |push: &mut Push, at: f64, config: &PatternSearchConfig| {
            let before = push.targets.clone();
            assert!(push.repair(FailedLap::too_fast(at), config));
            let moved: Vec<f64> = (0..g)
                .filter(|&k| push.targets[k] < before[k] - 1e-12)
                .map(|k| x_of(k, g))
                .collect();
            (moved[0], *moved.last().unwrap())
        };
        let close =
            |(a, b): (f64, f64), (c, d): (f64, f64)| (a - c).abs() < 2e-3 && (b - d).abs() < 2e-3;
        // Half-way to the start line is past the window: the window, 0.25.
        let s = lowered_over(&mut push, 0.7, &config);
        assert!(close(s, (0.45, 0.7)), "{s:?}");
        // 0.005 further on is the same place: the window again.
        let s = lowered_over(&mut push, 0.705, &config);
        assert!(close(s, (0.455, 0.705)), "{s:?}");
        // Half-way back to 0.705 is 0.1475, less than two spacings: 0.2.
        let s = lowered_over(&mut push, 1.0, &config);
        assert!(close(s, (0.8, 1.0)), "{s:?}");
        // The next push keeps the places. Before 0.45 there is none: half-way to the start
        // line, 0.225, lies between two spacings and the window.
        let mut next = Push::begin(2, &best, l, &config, Some(&push)).unwrap();
        assert_eq!(next.failures, vec![0.7, 0.705, 1.0]);
        let s = lowered_over(&mut next, 0.45, &config);
        assert!(close(s, (0.225, 0.45)), "{s:?}");
        // Before 0.6 the nearest is 0.45, half-way 0.075: two spacings.
        let s = lowered_over(&mut next, 0.6, &config);
        assert!(close(s, (0.4, 0.6)), "{s:?}");
        assert!(next.is_sound(best.len()));
        // A push that does not stop half-way moves the whole window.
        let whole = PatternSearchConfig {
            stop_half_way: false,
            ..config.clone()
        };
        let s = lowered_over(&mut next, 0.6, &whole);
        assert!(close(s, (0.35, 0.6)), "{s:?}");
        let mut unsound = next.clone();
        unsound.failures.push(f64::NAN);
        assert!(!unsound.is_sound(best.len()));
    }
}
