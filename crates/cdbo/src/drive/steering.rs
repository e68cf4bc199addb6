//! The steering controller: a PI controller on the heading error towards a look-ahead point
//! of the centre line (the paper's PI steering, with look-ahead).
//!
//! The target is the centre-line point d = max(d_min, t_la·v) ahead of the car's station.
//! With e the angle between the car's heading and the line to the target,
//! δ = clamp(K_p·e + K_i·∫e dt, −δ_max, δ_max), with K_p = 2L/d (the small-angle gain of
//! pure pursuit for wheelbase L, so the loop's bandwidth is independent of speed) and
//! K_i = [`KI`]. The integral term removes the steady offset that tyre slip leaves in long
//! corners; it is frozen while the output saturates.

use crate::sim::vehicle::State;
use crate::track::{Projection, Track};

/// Look-ahead time (s).
pub const LOOKAHEAD_TIME: f64 = 0.8;
/// Shortest look-ahead distance (m).
pub const LOOKAHEAD_MIN: f64 = 12.0;
/// Integral gain (1/s).
pub const KI: f64 = 0.1;

/// The steering controller: its gains and its memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Steering {
    /// Look-ahead time t_la (s).
    pub lookahead_time: f64,
    /// Shortest look-ahead distance d_min (m).
    pub lookahead_min: f64,
    /// Integral gain K_i (1/s).
    pub ki: f64,
    integral: f64,
}

impl Default for Steering {
    fn default() -> Self {
        Steering {
            lookahead_time: LOOKAHEAD_TIME,
            lookahead_min: LOOKAHEAD_MIN,
            ki: KI,
            integral: 0.0,
        }
    }
}

impl Steering {
    /// A fresh controller with the documented gains.
    pub fn new() -> Steering {
        Steering::default()
    }

    /// The road-wheel angle (rad) for the car in `state` at `proj`, after `dt` seconds.
    pub fn update(
        &mut self,
        track: &Track,
        wheelbase: f64,
        steer_lock: f64,
        state: &State,
        proj: &Projection,
        dt: f64,
    ) -> f64 {
        let d = (self.lookahead_time * state.speed()).max(self.lookahead_min);
        let (tx, ty) = track.point_at(proj.s + d);
        // The angle from the car's heading (cos ψ, sin ψ) to the target, in (−π, π].
        let (dx, dy) = (tx - state.x, ty - state.y);
        let (sy, cy) = state.yaw_sin_cos;
        let e = (cy * dy - sy * dx).atan2(cy * dx + sy * dy);
        let kp = 2.0 * wheelbase / d;
        let raw = kp * e + self.ki * (self.integral + e * dt);
        if raw.abs() < steer_lock {
            self.integral += e * dt;
        }
        (kp * e + self.ki * self.integral).clamp(-steer_lock, steer_lock)
    }
}

/// An angle wrapped into (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    let t = (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    if t == -std::f64::consts::PI {
        std::f64::consts::PI
    } else {
        t
    }
}
