//! The profile hold: a speed controller following k times a speed profile v(s) given at
//! stations spaced evenly over the lap, linear in between, previewed over the next τ seconds
//! (the calibration's fast probe, [`crate::calibrate`]):
//!
//! a = clamp(K_p·(max(k·min_{u₀ ≤ u ≤ u₁} v(u), v_min) − v), −1, 1),
//!
//! u₀ = n·clamp(x, 0, 1) and u₁ = n·clamp(x + v·τ/L, 0, 1) in units of the profile's n
//! intervals, x the lap fraction, L the lap's length, v the speed, v(u) linear between the
//! profile's n + 1 values; the minimum is over v(u₀), v(u₁) and the values at the stations
//! strictly between. K_p, τ and the floor v_min are the ceiling's profile tracker's
//! ([`TRACKER_GAIN`], [`PREVIEW_S`],
//! [`TRACKER_FLOOR_MPS`]); unlike it, which reads the profile at the nearest
//! station, the target is continuous in x and v, so that the pedal is too: the tracker's
//! target steps down by k·Δv at each station of a braking curve, and its pedal follows in a
//! saw-tooth whose teeth move with the smallest change of the car, noise in a calibration's
//! residuals. The TORCS robot's `drive::profile_hold` (`torcs-robot/drive.hpp`) is the same
//! arithmetic, checked by `tests/robot_drive.rs`.

use super::{Observation, Pedal};

/// Proportional gain of the profile tracker (per m/s): full pedal at 1 m/s off the target.
pub const TRACKER_GAIN: f64 = 1.0;
/// Preview time τ of the profile tracker (s).
pub const PREVIEW_S: f64 = 0.3;
/// The floor v_min of the tracker's target (m/s): below the demonstrator's 15 m/s, which
/// every track of the paper completes.
pub const TRACKER_FLOOR_MPS: f64 = 10.0;

/// A speed controller holding k times a speed profile (module documentation).
#[derive(Debug, Clone, Copy)]
pub struct ProfileHold<'a> {
    /// The profile's speeds (m/s) at n + 1 ≥ 2 stations spaced evenly from the start line to
    /// the finish.
    pub profile: &'a [f64],
    /// The lap's length L (m).
    pub length: f64,
    /// The scale k.
    pub k: f64,
}

impl ProfileHold<'_> {
    /// v(u): the profile linear between its stations, u in station intervals, in [0, n].
    fn at(&self, u: f64) -> f64 {
        let p = self.profile;
        let n = p.len() - 1;
        let j = (u.floor() as usize).min(n - 1);
        p[j] + (p[j + 1] - p[j]) * (u - j as f64)
    }

    /// The previewed target max(k·min v(u) over [u₀, u₁], v_min) (m/s) at lap fraction `x`
    /// and `speed`.
    pub fn target(&self, x: f64, speed: f64) -> f64 {
        let n = (self.profile.len() - 1) as f64;
        let u0 = x.clamp(0.0, 1.0) * n;
        let u1 = (x + speed * PREVIEW_S / self.length).clamp(0.0, 1.0) * n;
        let mut v = self.at(u0).min(self.at(u1));
        // The stations strictly inside (u₀, u₁).
        let mut i = u0.floor() as usize + 1;
        while (i as f64) < u1 {
            v = v.min(self.profile[i]);
            i += 1;
        }
        (self.k * v).max(TRACKER_FLOOR_MPS)
    }
}

impl Pedal for ProfileHold<'_> {
    fn pedal(&mut self, obs: &Observation) -> f64 {
        (TRACKER_GAIN * (self.target(obs.x, obs.speed) - obs.speed)).clamp(-1.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_is_the_previewed_minimum_of_the_linear_profile() {
        // 4 intervals over a 100 m lap: stations every 25 m.
        let profile = [20.0, 40.0, 30.0, 50.0, 60.0];
        let hold = ProfileHold {
            profile: &profile,
            length: 100.0,
            k: 0.5,
        };
        // At x = 0.1 (u = 0.4) with a preview of 30 m/s · 0.3 s = 9 m (u₁ = 0.76): rising,
        // the minimum at u₀, v = 28.
        assert!((hold.target(0.1, 30.0) - 14.0).abs() < 1e-12);
        // At x = 0.4 (u = 1.6) to u₁ = 1.96: falling from 34 to 30.4, k·30.4 = 15.2.
        assert!((hold.target(0.4, 30.0) - 15.2).abs() < 1e-12);
        // Spanning station 2 (30 m/s): x = 0.45 (u = 1.8) to u₁ = 2.16.
        assert_eq!(hold.target(0.45, 30.0), 15.0);
        // The floor, and the finish held.
        assert_eq!(hold.target(0.0, 0.0), TRACKER_FLOOR_MPS);
        assert_eq!(hold.target(1.0, 40.0), 30.0);
        let mut hold = hold;
        let mut pedal = |x: f64, speed: f64| {
            hold.pedal(&Observation {
                x,
                speed,
                time: 1.0,
            })
        };
        assert_eq!(pedal(0.0, 9.5), 0.5);
        assert_eq!(pedal(0.45, 30.0), -1.0);
    }
}
