//! The demonstrator: a PI speed controller holding a target speed (the paper's initial
//! example, 15 m/s by default).
//!
//! a = clamp(K_p·e + K_i·∫e dt, −1, 1), e = v_target − v, with the integral frozen while the
//! output saturates (anti-windup).

use super::{Observation, Pedal, pi_control};

/// The paper's demonstration speed (m/s).
pub const DEFAULT_TARGET_SPEED: f64 = 15.0;
/// Proportional gain (per m/s).
pub const KP: f64 = 0.5;
/// Integral gain (per m).
pub const KI: f64 = 0.1;

/// A PI controller holding `target` m/s.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedHold {
    /// Target speed (m/s).
    pub target: f64,
    integral: f64,
    last_time: Option<f64>,
}

impl SpeedHold {
    /// A controller for `target` m/s.
    pub fn new(target: f64) -> SpeedHold {
        SpeedHold {
            target,
            integral: 0.0,
            last_time: None,
        }
    }
}

impl Pedal for SpeedHold {
    fn pedal(&mut self, obs: &Observation) -> f64 {
        let dt = obs.time - self.last_time.unwrap_or(obs.time);
        self.last_time = Some(obs.time);
        pi_control(KP, KI, 1.0, &mut self.integral, self.target - obs.speed, dt)
    }
}
