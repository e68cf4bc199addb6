//! The profile start of the safe pattern search: a demonstration that holds a share of the
//! limit's speed profile on the line the race drives, and a policy that learns the speed to
//! hold from it ([`crate::policy::target`]).
//!
//! The paper's demonstrator holds 15 m/s: on a 5 km circuit whose limit lap averages 32–42 m/s
//! the learner then has to climb from under half the limit within its budget of failed laps,
//! and spends it on the way (measured with the recommended stack on TUMFTM's 13 circuits: 72 %
//! of the centre-line limit). The profile start demonstrates near the limit instead:
//!
//! - **The profile.** v_g(s), the crest-aware QSS limit's speeds on the raced line
//!   ([`crate::ceiling::profile`]) braking at no more than [`DECEL`]: v_g(sᵢ) =
//!   min(v_lim(sᵢ), √(v_g(sᵢ₊₁)² + 2·[`DECEL`]·h)) from the finish back, h the stations'
//!   spacing. Braking at [`DECEL`] spreads each brake over 100–300 m, which the policy's M
//!   kernels, 120–200 m apart on a 5 km circuit, can shape.
//! - **The scale.** The largest k in (0, 1] whose hold of k·v_g
//!   ([`crate::drive::profile::ProfileHold`]) completes is found by [`BISECTIONS`] halvings
//!   (each a lap of the demonstrator, not counted among the race's laps, as the paper's
//!   demonstration is not); the race demonstrates at k₀ = [`SCALE`]·k.
//! - **The policy.** Its action asks for the speed (k₀ + s·a(x))·v_g(x)
//!   ([`SpeedTarget`], s = [`SPAN`]), so w₀ = 0 is the
//!   demonstration itself, repaired where its lap fails ([`super::start::complete_start`]; a
//!   slower demonstration there is a smaller k, a lower a).
//!
//! A demonstration's speed, as the start reports and slows it, is k times the profile's
//! reward (the crest-aware limit's L/T).
//!
//! Measured with the recommended stack at a9d677b (seeds 0–2, cdbo's simulator;
//! docs/results/any-track.md): TUMFTM's 13 circuits 72.7 → 84.2 % of the centre-line limit,
//! TORCS's 21 road tracks with car1-trb1 89.4 → 94.5 %. On the 13 circuits, seed 0:
//! [`DECEL`] 3 against 4 m/s², and [`SCALE`] 0.8 against 0.75 and 0.85, gave 84.0 against
//! 82.7, 82.1 and 81.5 %.

use crate::car::Car;
use crate::error::Result;
use crate::line::RacingLine;
use crate::policy::target::{SPAN, SpeedTarget};
use crate::track::Track;
use crate::venue::Venue;

use super::start::Demonstration;

/// The profile's braking deceleration (m/s²), about a third of a road car's on dry tarmac.
pub const DECEL: f64 = 3.0;
/// Halvings of [0, 1] searching the largest k whose profile hold completes.
pub const BISECTIONS: usize = 6;
/// The demonstration holds this share of the largest k that completed.
pub const SCALE: f64 = 0.8;

/// The demonstrator of the profile start on one venue: a hold of k·v_g.
#[derive(Debug, Clone)]
pub struct ProfileDemonstrator {
    /// v_g at the track's stations, spaced evenly from the start line to the finish (m/s).
    pub speed: Vec<f64>,
    /// The reward of the crest-aware limit v_g brakes from (m/s): a demonstration at k is said
    /// to hold k times it.
    pub reference_mps: f64,
}

/// What the profile start chose.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ProfileChoice {
    /// The largest scale k whose hold completed.
    pub largest_k: f64,
    /// The scale demonstrated, [`SCALE`] times it.
    pub k: f64,
    /// The speed that stands for (m/s): k times the profile's reward.
    pub speed_mps: f64,
    /// Demonstration laps the search drove, the chosen one's included.
    pub laps: usize,
}

impl ProfileChoice {
    /// One line saying what was demonstrated and what the policy learns.
    pub fn sentence(&self) -> String {
        format!(
            "demonstrating with a hold of {:.2} times the limit's speed profile on the line \
             (braking at {DECEL} m/s²; {SCALE} of the largest scale that completed, {:.3}, in \
             a search of {} laps); the policy learns the speed to hold, {:.2} ± {SPAN} times \
             the profile",
            self.k, self.largest_k, self.laps, self.k
        )
    }
}

impl ProfileDemonstrator {
    /// The demonstrator for `car` on `track`, on `line` if the race holds one.
    pub fn new(track: &Track, car: &Car, line: Option<&RacingLine>) -> ProfileDemonstrator {
        let limit = crate::ceiling::profile(track, car, line);
        ProfileDemonstrator {
            speed: braking_gently(&limit.speed, track.length, DECEL),
            reference_mps: limit.reward_mps,
        }
    }

    /// The target a policy learning from this demonstrator's hold at scale `k` asks for on
    /// `track`: (k + s·a(x))·v_g(x), s = [`SPAN`].
    pub fn target(&self, track: &Track, k: f64) -> Result<SpeedTarget> {
        SpeedTarget::new(self.speed.clone(), track.length, k, SPAN)
    }

    /// The demonstration on `venue` said to hold `speed` m/s: the hold of k·v_g, k =
    /// `speed` / the reference.
    pub fn demonstrate(&self, venue: &Venue, speed: f64) -> Result<Demonstration> {
        venue.demonstrate_profile(&self.speed, speed / self.reference_mps)
    }

    /// The start's demonstration on `venue` and what was chosen: the hold at [`SCALE`] times
    /// the largest completing k, or that k's own lap where the smaller one fails; `None` if no
    /// k tried completed.
    pub fn choose(&self, venue: &Venue) -> Result<Option<(Demonstration, ProfileChoice)>> {
        let mut laps = 0;
        let found = largest_completing(|k| {
            laps += 1;
            self.demonstrate(venue, k * self.reference_mps)
        })?;
        let Some((largest_k, top)) = found else {
            return Ok(None);
        };
        let k = SCALE * largest_k;
        let demo = self.demonstrate(venue, k * self.reference_mps)?;
        laps += 1;
        let (demo, k) = if demo.0.completed {
            (demo, k)
        } else {
            (top, largest_k)
        };
        let choice = ProfileChoice {
            largest_k,
            k,
            speed_mps: k * self.reference_mps,
            laps,
        };
        Ok(Some((demo, choice)))
    }
}

/// The largest k in (0, 1] (to [`BISECTIONS`] halvings) whose profile hold, driven by `hold`,
/// completes, and its lap; `None` if no k tried completed.
pub fn largest_completing(
    mut hold: impl FnMut(f64) -> Result<Demonstration>,
) -> Result<Option<(f64, Demonstration)>> {
    let top = hold(1.0)?;
    if top.0.completed {
        return Ok(Some((1.0, top)));
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    let mut best = None;
    for _ in 0..BISECTIONS {
        let k = 0.5 * (lo + hi);
        let demo = hold(k)?;
        if demo.0.completed {
            lo = k;
            best = Some((k, demo));
        } else {
            hi = k;
        }
    }
    Ok(best)
}

/// `profile` (m/s at stations spaced evenly over a lap of `length` m) braking at no more than
/// `decel` m/s²: v(sᵢ) = min(v_lim(sᵢ), √(v(sᵢ₊₁)² + 2·decel·h)), h the stations' spacing,
/// from the finish back.
pub fn braking_gently(profile: &[f64], length: f64, decel: f64) -> Vec<f64> {
    let mut v = profile.to_vec();
    let h = length / (v.len().max(2) - 1) as f64;
    for i in (0..v.len().saturating_sub(1)).rev() {
        v[i] = v[i].min((v[i + 1] * v[i + 1] + 2.0 * decel * h).sqrt());
    }
    v
}

#[cfg(test)]
mod tests {
    use super::super::start::demonstrator_up_to;
    use super::*;

    /// Before a corner the profile falls no faster than the deceleration allows, and where the
    /// limit falls slower, or rises, it is the limit.
    #[test]
    fn the_profile_brakes_at_the_deceleration() {
        // 25 stations 10 m apart: 40 m/s, a corner at 10 m/s, then 30 m/s.
        let mut limit = vec![40.0; 12];
        limit.push(10.0);
        limit.extend([30.0; 12]);
        let gentle = braking_gently(&limit, 240.0, 3.0);
        assert_eq!(gentle[12], 10.0);
        for (i, v) in gentle[..12].iter().enumerate() {
            let most = (10.0f64.powi(2) + 2.0 * 3.0 * 10.0 * (12 - i) as f64).sqrt();
            assert!((v - most.min(40.0)).abs() < 1e-12, "{i}: {v}");
        }
        assert_eq!(&gentle[13..], &limit[13..]);
    }

    /// The whole profile is tried first; below it the bisection keeps the largest k that
    /// completed, to 1/64; where none does, nothing is chosen.
    #[test]
    fn the_search_keeps_the_largest_completing_scale() {
        let mut tried = Vec::new();
        let (k, demo) = largest_completing(demonstrator_up_to(2.0, &mut tried))
            .unwrap()
            .unwrap();
        assert_eq!((k, tried.len()), (1.0, 1));
        assert!(demo.0.completed);
        let mut tried = Vec::new();
        let (k, demo) = largest_completing(demonstrator_up_to(0.7, &mut tried))
            .unwrap()
            .unwrap();
        assert_eq!(tried.len(), 1 + BISECTIONS);
        assert!(k <= 0.7 && k > 0.7 - 1.0 / 64.0, "{k}");
        assert_eq!(demo.0.reward_mps, k);
        let mut tried = Vec::new();
        assert!(
            largest_completing(demonstrator_up_to(0.001, &mut tried))
                .unwrap()
                .is_none()
        );
    }
}
