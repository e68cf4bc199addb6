//! The driver: the environment's controllers and the pedal command they follow.
//!
//! A lap is driven by a [`Pedal`] (the optimised policy, the demonstrator or a constant), which
//! maps the observation — chiefly x, the fraction of the lap — to a ∈ [−1, 1] (throttle > 0,
//! brake < 0), and may name a line d(x) to hold (the centre line unless it does). Steering is
//! the environment's [`steering::Steering`] controller, which holds that line.

pub mod demo;
pub mod profile;
pub mod steering;
pub mod tracker;

/// What the driver sees at each driver step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Position along the centre line as a fraction of the lap, x ∈ [0, 1].
    pub x: f64,
    /// Speed over ground (m/s).
    pub speed: f64,
    /// Time since the start (s).
    pub time: f64,
}

/// What drives a lap: the throttle/brake command, and the line to hold.
pub trait Pedal {
    /// The command a ∈ [−1, 1] for this observation.
    fn pedal(&mut self, obs: &Observation) -> f64;

    /// The line d(x) at lap fraction x: the offset (m, positive left) from the centre line
    /// the steering holds, before the lap bounds it to the road; 0, the centre line, unless
    /// the driver has a line of its own (a [`crate::policy::Policy`] with a line).
    fn line(&self, _x: f64) -> f64 {
        0.0
    }
}

/// The same command everywhere (`cdbo lap --throttle A`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantPedal(pub f64);

impl Pedal for ConstantPedal {
    fn pedal(&mut self, _: &Observation) -> f64 {
        self.0.clamp(-1.0, 1.0)
    }
}

/// Any function of the lap fraction x is a pedal (e.g. a policy π(x)).
#[derive(Debug, Clone, Copy)]
pub struct PolicyPedal<F: Fn(f64) -> f64>(pub F);

impl<F: Fn(f64) -> f64> Pedal for PolicyPedal<F> {
    fn pedal(&mut self, obs: &Observation) -> f64 {
        (self.0)(obs.x).clamp(-1.0, 1.0)
    }
}

/// The pedal command a driver step applies for a pedal's value `a`: held in [−1, 1], NaN
/// taken as 0 (coasting). The TORCS robot's `drive::pedal_command` is the same.
#[inline]
pub fn pedal_command(a: f64) -> f64 {
    let a = a.clamp(-1.0, 1.0);
    if a.is_nan() { 0.0 } else { a }
}

/// The speed (m/s) a flying lap's run-up keeps at least ([`run_up_pedal`]): the profile
/// tracker's floor, below the demonstrator's 15 m/s.
pub const RUN_UP_FLOOR_MPS: f64 = profile::TRACKER_FLOOR_MPS;

/// The pedal command on a flying lap's run-up, the standing lap before the timed one
/// ([`crate::sim::LapConfig::flying`]): the policy's command `a`, but never below the
/// floor's, a = max(a, clamp(v_min − v, −1, 1)) with v_min = [`RUN_UP_FLOOR_MPS`]. A
/// policy over the lap fraction brakes where the flying lap must, also on the run-up,
/// where the car comes to that place from a standstill far slower: without the floor it
/// stops there. Above v_min + 1 m/s it is the policy's command. The TORCS robot's
/// `drive::run_up_pedal` is the same.
#[inline]
pub fn run_up_pedal(a: f64, speed: f64) -> f64 {
    a.max((RUN_UP_FLOOR_MPS - speed).clamp(-1.0, 1.0))
}

/// One step of a PI controller with anti-windup, the law of the demonstrator's speed hold
/// ([`demo`]) and of the steering ([`steering`]): for the error e over `dt` seconds,
/// u = clamp(K_p·e + K_i·I, −u_max, u_max), where the integral I += e·dt only while the
/// unclamped output with the new integral, K_p·e + K_i·(I + e·dt), lies strictly inside
/// ±u_max (it is frozen while the output saturates). Updates `integral` and returns u.
///
/// The TORCS robot's `drive::pi_control` (`torcs-robot/drive.hpp`) is the same arithmetic,
/// checked against this by `tests/robot_drive.rs`.
#[inline]
pub fn pi_control(kp: f64, ki: f64, limit: f64, integral: &mut f64, e: f64, dt: f64) -> f64 {
    let raw = kp * e + ki * (*integral + e * dt);
    if raw.abs() < limit {
        *integral += e * dt;
    }
    (kp * e + ki * *integral).clamp(-limit, limit)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The run-up's floor: full throttle from a standstill, no braking below the floor, the
    /// policy's command once the car is a metre per second past it.
    #[test]
    fn the_run_up_keeps_its_floor_speed() {
        assert_eq!(run_up_pedal(-1.0, 0.0), 1.0);
        assert_eq!(run_up_pedal(0.2, 9.5), 0.5);
        assert_eq!(run_up_pedal(-1.0, RUN_UP_FLOOR_MPS), 0.0);
        assert_eq!(run_up_pedal(-0.3, 10.5), -0.3);
        assert_eq!(run_up_pedal(-1.0, 30.0), -1.0);
        assert_eq!(run_up_pedal(0.7, 0.0), 1.0);
    }
}
