//! A pedal that asks for a speed: the policy's action a(x) scales a speed profile, and the
//! profile hold ([`ProfileHold`]) brakes and accelerates to it.
//!
//! The paper's action is the pedal itself, open loop: a(x) ∈ [−1, 1] is the throttle (> 0)
//! or the brake (< 0) at lap fraction x. With a target, the same action sets the speed to
//! hold,
//!
//! v*(x) = (k₀ + s·a(x))·v_g(x),
//!
//! v_g the profile (the profile start's gently braking limit,
//! [`crate::experiment::profile_start`]), k₀ the scale its demonstration held and s the
//! span, [`SPAN`]: a = 0 is the demonstration, a = ±1 holds k₀ ± s times the profile. The
//! hold's pedal is a = clamp(K_p·(v* − v), −1, 1) previewed over the next τ seconds, in cdbo's
//! simulator and in the game's robot alike (`GamePedal::Profile` with v* as its speeds).
//!
//! Why: an open-loop pedal fitted with M kernels, 100–200 m apart on a 5 km circuit, cannot
//! follow a corner's brake point, and a learner's step that adds speed in one place moves
//! every later corner's entry speed; a target speed is learned where it is held. Measured
//! with the recommended stack in cdbo's simulator (docs/results/any-track.md).

use serde::{Deserialize, Serialize};

use super::RkhsPolicy;
use crate::drive::profile::ProfileHold;
use crate::drive::{Observation, Pedal};
use crate::error::{Error, Result};

/// The span s: a = ±1 holds k₀ ± s times the profile.
pub const SPAN: f64 = 0.25;
/// The fastest speed a profile may give (m/s), past any car's.
pub const MAX_SPEED: f64 = 1000.0;
/// The largest scale k₀ and span s a target may have.
pub const MAX_SCALE: f64 = 10.0;

/// The speed a policy's action asks for, v*(x) = (k₀ + s·a(x))·v_g(x) (module
/// documentation), stored with the policy (`"target"` in its file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpeedTarget {
    /// v_g (m/s) at n + 1 ≥ 2 stations spaced evenly from the start line to the finish.
    pub profile: Vec<f64>,
    /// The lap's length L (m).
    pub length: f64,
    /// The scale k₀ that a = 0 holds.
    pub scale: f64,
    /// The span s.
    pub span: f64,
}

impl SpeedTarget {
    /// The target of scale `scale` and span `span` on `profile` over a lap of `length` m,
    /// refused unless the profile has at least two speeds, each in [0, [`MAX_SPEED`]] m/s (a
    /// standing start's is 0 at the line), the length is finite and positive, the scale in
    /// (0, [`MAX_SCALE`]] and the span in [0, [`MAX_SCALE`]].
    pub fn new(profile: Vec<f64>, length: f64, scale: f64, span: f64) -> Result<SpeedTarget> {
        SpeedTarget {
            profile,
            length,
            scale,
            span,
        }
        .checked()
    }

    /// This target, refused as [`SpeedTarget::new`] refuses one.
    pub fn checked(self) -> Result<SpeedTarget> {
        if self.profile.len() < 2 {
            return Err(Error::invalid_value(
                "the target's profile",
                format!("{} speeds", self.profile.len()),
                "at least 2 stations",
            ));
        }
        if let Some(i) = self
            .profile
            .iter()
            .position(|v| !(0.0..=MAX_SPEED).contains(v))
        {
            return Err(Error::invalid_value(
                format!("the target's profile speed {i}"),
                self.profile[i],
                format!("a speed in [0, {MAX_SPEED}] m/s"),
            ));
        }
        if !(self.length.is_finite() && self.length > 0.0) {
            return Err(Error::invalid_value(
                "the target's length",
                self.length,
                "a positive number of metres",
            ));
        }
        for (what, value, ok, range) in [
            (
                "the target's scale",
                self.scale,
                self.scale > 0.0 && self.scale <= MAX_SCALE,
                format!("in (0, {MAX_SCALE}]"),
            ),
            (
                "the target's span",
                self.span,
                (0.0..=MAX_SCALE).contains(&self.span),
                format!("in [0, {MAX_SCALE}]"),
            ),
        ] {
            if !ok {
                return Err(Error::invalid_value(what, value, range));
            }
        }
        Ok(self)
    }

    /// The action a = (k − k₀)/s that holds k times the profile (unclamped; k₀ for a span of
    /// 0).
    pub fn action_holding(&self, k: f64) -> f64 {
        if self.span > 0.0 {
            (k - self.scale) / self.span
        } else {
            0.0
        }
    }

    /// v*(xᵢ) = (k₀ + s·a(xᵢ))·v_g(xᵢ) at the profile's stations xᵢ = i/n, a the pedal's
    /// clamped action.
    pub fn speeds(&self, pedal: &RkhsPolicy) -> Vec<f64> {
        let n = (self.profile.len() - 1) as f64;
        self.profile
            .iter()
            .enumerate()
            .map(|(i, v)| (self.scale + self.span * pedal.action(i as f64 / n)) * v)
            .collect()
    }
}

/// The hold of a target's speeds v*(xᵢ) ([`SpeedTarget::speeds`]) on a lap of `length` m: a
/// [`ProfileHold`] of scale 1 that owns its profile.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetHold {
    /// v*(xᵢ) (m/s).
    pub speeds: Vec<f64>,
    /// The lap's length (m).
    pub length: f64,
}

impl Pedal for TargetHold {
    fn pedal(&mut self, obs: &Observation) -> f64 {
        ProfileHold {
            profile: &self.speeds,
            length: self.length,
            k: 1.0,
        }
        .pedal(obs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn target() -> SpeedTarget {
        SpeedTarget::new(vec![20.0, 40.0, 30.0, 50.0, 60.0], 100.0, 0.6, 0.25).unwrap()
    }

    /// v* is k₀ + s·a times the profile at each station, a clamped: at a = 0 the
    /// demonstration's k₀·v_g, and the action holding k gives k·v_g.
    #[test]
    fn the_target_is_the_scaled_profile() {
        let t = target();
        let zero = RkhsPolicy::new(vec![0.0; 4], 1.0 / 3.0).unwrap();
        let speeds = t.speeds(&zero);
        for (v, g) in speeds.iter().zip(&t.profile) {
            assert!((v - 0.6 * g).abs() < 1e-12);
        }
        let flat = |a: f64| RkhsPolicy::new(vec![a; 40], 0.05).unwrap();
        let a = t.action_holding(0.7);
        assert!((a - 0.4).abs() < 1e-12);
        // Any pedal: its a(x) read back at each station.
        let p = flat(0.1);
        for (i, (v, g)) in t.speeds(&p).iter().zip(&t.profile).enumerate() {
            let a = p.action(i as f64 / 4.0);
            assert!((v - (0.6 + 0.25 * a) * g).abs() < 1e-12, "{i}");
        }
        // Clamped: a large action holds k₀ + s, no more.
        let top = t.speeds(&flat(100.0));
        assert!((top[2] - 0.85 * 30.0).abs() < 1e-12, "{top:?}");
    }

    /// The hold of the speeds at a = 0 is the profile hold of k₀ times the profile.
    #[test]
    fn the_hold_at_zero_is_the_demonstrations() {
        let t = target();
        let zero = RkhsPolicy::new(vec![0.0; 4], 1.0 / 3.0).unwrap();
        let mut hold = TargetHold {
            speeds: t.speeds(&zero),
            length: t.length,
        };
        let mut demo = ProfileHold {
            profile: &t.profile,
            length: t.length,
            k: t.scale,
        };
        for (x, speed) in [(0.1, 12.0), (0.45, 25.0), (0.7, 40.0), (1.0, 20.0)] {
            let obs = Observation {
                x,
                speed,
                time: 1.0,
            };
            assert!((hold.pedal(&obs) - demo.pedal(&obs)).abs() < 1e-12, "{x}");
        }
    }

    #[test]
    fn bad_targets_are_refused() {
        for (profile, length, scale, span) in [
            (vec![20.0], 100.0, 0.6, 0.25),
            (vec![20.0, f64::NAN], 100.0, 0.6, 0.25),
            (vec![20.0, -1.0], 100.0, 0.6, 0.25),
            (vec![20.0, 30.0], 0.0, 0.6, 0.25),
            (vec![20.0, 30.0], 100.0, -0.6, 0.25),
            (vec![20.0, 30.0], 100.0, 0.6, -0.25),
            (vec![20.0, 1e300], 100.0, 0.6, 0.25),
            (vec![20.0, 30.0], 100.0, 0.6, f64::INFINITY),
        ] {
            let e = SpeedTarget::new(profile, length, scale, span).unwrap_err();
            assert!(e.to_string().contains("target"), "{e}");
        }
    }
}
