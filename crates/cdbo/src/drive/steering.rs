//! The steering controllers: [`Steering`] is the one a lap drives with — the paper's PI
//! steering with look-ahead ([`PiSteering`], the default, below) or the path tracker
//! ([`super::tracker::PathTracker`]: feed-forward, previewed feedback, yaw-rate damping).
//!
//! The PI steering is a PI controller on the heading error towards a look-ahead point.
//! The target is the point of the line the driver holds (the centre line unless its
//! [`Pedal::line`](super::Pedal::line) names another, [`Track::point_off`]) d = max(d_min,
//! t_la·v) ahead of the car's station.
//! With e the angle between the car's heading and the line to the target,
//! δ = clamp(K_p·e + K_i·∫e dt, −δ_max, δ_max), with K_p = 2L/d (the small-angle gain of
//! pure pursuit for wheelbase L, so the loop's bandwidth is independent of speed) and
//! K_i = [`KI`]. The integral term removes the steady offset that tyre slip leaves in long
//! corners; it is frozen while the output saturates.
//!
//! The look-ahead, the [`bearing`] and the [`steering_law`] are pure functions so that the
//! TORCS robot's `torcs-robot/drive.hpp`, which finds its target on the game's track, can be
//! checked against them (`tests/robot_drive.rs`).

use super::pi_control;
use super::tracker::PathTracker;
use crate::geometry::bearing;
use crate::track::{Projection, Track};
use crate::vehicle::{State, Vehicle};

/// Look-ahead time (s).
pub const LOOKAHEAD_TIME: f64 = 0.8;
/// Shortest look-ahead distance (m).
pub const LOOKAHEAD_MIN: f64 = 12.0;
/// Integral gain (1/s).
pub const KI: f64 = 0.1;

/// The steering a lap drives with.
#[derive(Debug, Clone, PartialEq)]
pub enum Steering {
    /// The paper's PI steering with look-ahead (the default).
    Pi(PiSteering),
    /// The path tracker.
    Tracker(PathTracker),
}

impl Default for Steering {
    fn default() -> Self {
        Steering::Pi(PiSteering::new())
    }
}

impl Steering {
    /// The road-wheel angle (rad) for the car in `state` at `proj` holding the line `line(s)`
    /// metres left of the centre line at station s, after `dt` seconds.
    pub fn update(
        &mut self,
        track: &Track,
        vehicle: &Vehicle,
        state: &State,
        proj: &Projection,
        line: &dyn Fn(f64) -> f64,
        dt: f64,
    ) -> f64 {
        match self {
            Steering::Pi(pi) => pi.update(track, vehicle, state, proj, line, dt),
            Steering::Tracker(tracker) => tracker.update(track, vehicle, state, proj, line),
        }
    }
}

/// A steering law by name, with its documented gains: what a grid's `steering = "tracker"`
/// names (`cdbo race --steering` likewise).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SteeringLaw {
    /// The paper's PI steering with look-ahead ([`PiSteering`], the default).
    #[default]
    Pi,
    /// The path tracker ([`PathTracker`]).
    Tracker,
}

impl SteeringLaw {
    /// Every law, the default first.
    pub const ALL: [SteeringLaw; 2] = [SteeringLaw::Pi, SteeringLaw::Tracker];

    /// The controller, fresh.
    pub fn steering(self) -> Steering {
        match self {
            SteeringLaw::Pi => Steering::default(),
            SteeringLaw::Tracker => Steering::Tracker(PathTracker::new()),
        }
    }

    /// Whether this is the default, the paper's PI steering.
    pub fn is_pi(&self) -> bool {
        *self == SteeringLaw::Pi
    }

    /// Its name, as `--steering` and a grid's `steering` take it: `pi` or `tracker`
    /// (and [`str::parse`]).
    pub fn name(&self) -> &'static str {
        match self {
            SteeringLaw::Pi => "pi",
            SteeringLaw::Tracker => "tracker",
        }
    }

    /// One line on what it does, as `--steering`'s help lists it.
    pub fn description(self) -> &'static str {
        match self {
            SteeringLaw::Pi => {
                "The paper's PI steering on a look-ahead point of the line (the default)"
            }
            SteeringLaw::Tracker => {
                "The path tracker: feed-forward from the path's curvature and the car's understeer \
                 gradient, feedback on the previewed lateral error, yaw-rate damping"
            }
        }
    }
}

impl std::fmt::Display for SteeringLaw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for SteeringLaw {
    type Err = crate::error::Error;
    fn from_str(s: &str) -> crate::error::Result<SteeringLaw> {
        SteeringLaw::ALL
            .into_iter()
            .find(|law| law.name() == s)
            .ok_or_else(|| {
                crate::error::Error::invalid_value(
                    "the steering",
                    format!("{s:?}"),
                    "pi or tracker",
                )
            })
    }
}

/// The PI steering controller: its gains and its memory.
#[derive(Debug, Clone, PartialEq)]
pub struct PiSteering {
    /// Look-ahead time t_la (s).
    pub lookahead_time: f64,
    /// Shortest look-ahead distance d_min (m).
    pub lookahead_min: f64,
    /// Integral gain K_i (1/s).
    pub ki: f64,
    integral: f64,
}

impl Default for PiSteering {
    fn default() -> Self {
        PiSteering {
            lookahead_time: LOOKAHEAD_TIME,
            lookahead_min: LOOKAHEAD_MIN,
            ki: KI,
            integral: 0.0,
        }
    }
}

impl PiSteering {
    /// A fresh controller with the documented gains.
    pub fn new() -> PiSteering {
        PiSteering::default()
    }

    /// The road-wheel angle (rad) for the car in `state` at `proj`, after `dt` seconds: the
    /// [`steering_law`] on the [`bearing`] of the line's point [`Self::lookahead`] metres ahead
    /// of the car's station, the line `line(s)` metres left of the centre line at station s.
    pub fn update(
        &mut self,
        track: &Track,
        vehicle: &Vehicle,
        state: &State,
        proj: &Projection,
        line: &dyn Fn(f64) -> f64,
        dt: f64,
    ) -> f64 {
        let d = self.lookahead(state.speed());
        let s = proj.s + d;
        let (tx, ty) = track.point_off(s, line(track.wrap(s)));
        let e = bearing(tx - state.x, ty - state.y, state.yaw_sin_cos);
        let car = &vehicle.car;
        steering_law(
            e,
            d,
            car.wheelbase,
            self.ki,
            car.steer_lock,
            &mut self.integral,
            dt,
        )
    }

    /// The look-ahead distance d = max(d_min, t_la·v) (m) at speed v (m/s).
    #[inline]
    pub fn lookahead(&self, speed: f64) -> f64 {
        (self.lookahead_time * speed).max(self.lookahead_min)
    }
}

/// The PI law on the bearing e (rad) of a target d metres ahead: δ = [`pi_control`] with
/// K_p = 2L/d (L the wheelbase), K_i = `ki` and the limit ±`steer_lock`; updates the
/// `integral` of e over `dt` seconds.
#[inline]
pub fn steering_law(
    e: f64,
    d: f64,
    wheelbase: f64,
    ki: f64,
    steer_lock: f64,
    integral: &mut f64,
    dt: f64,
) -> f64 {
    pi_control(2.0 * wheelbase / d, ki, steer_lock, integral, e, dt)
}
