//! The path tracker: steering that holds any line d(x) at racing speed — feed-forward from
//! the path's curvature and the car's understeer gradient, feedback on the lateral error
//! previewed ahead, and yaw-rate feedback (the feed-forward and the previewed error after
//! Kapania & Gerdes, *Design of a feedback-feedforward steering controller for accurate path
//! tracking and stability at the limits of handling*, 2015).
//!
//! The path is the line P(s) = c(s) + d(s)·n(s), d metres left of the centre line at station
//! s. With v the speed, e the car's lateral offset from the path, Δψ = ψ − θ_P its heading
//! error and r its yaw rate, the tracker demands the curvature
//!
//! κ_d = κ_f − (2/x_p²)·(e + x_p·(Δψ − Δψ_ss))
//!
//! and steers δ = G·(κ_d + c·(κ_d − r/v)), clamped to ±δ_max, where
//! - κ_f is the path's curvature t_f·v ahead (the car's yaw lags its steering);
//! - x_p = max(x_min, t_p·v) is the preview distance: e + x_p·Δψ is the lateral error x_p
//!   ahead, and the gain 2/x_p² makes it obey ë = −(2/t_p²)·e − (2/t_p)·ė on the kinematic
//!   car, damped at ζ = 1/√2 whatever the speed;
//! - Δψ_ss = κ_f·(m·a·v²/(L·C_r) − b) is the linear single-track car's steady-state heading
//!   error (minus its body slip angle) on curvature κ_f, so that a steady corner is no error
//!   (a, b the distances of the axles from the centre of gravity, C_r the rear axle's
//!   cornering stiffness at this speed, [`Vehicle::cornering_stiffness`]);
//! - G = max(L + K·v², L/4), with K = (m/L)·(b/C_f − a/C_r) the understeer gradient, is the
//!   steering per unit of curvature in a steady corner (the floor keeps the sign of an
//!   oversteering car's gain below its critical speed √(−L/K));
//! - c·(κ_d − r/v) is the yaw-rate feedback: the steering grows while the car yaws less than
//!   demanded, v·κ_d, and shrinks while it yaws more (a slide), with a gain c·G/v that shrinks
//!   with speed as the car's yaw response v/G grows. The law acts once per driver step
//!   (20 ms), and at low speed the car's yaw settles within a step: the loop is then the
//!   map r ← −c·r, which rings at half the driver's rate once c > 1 (discrete-time loop,
//!   time constant τ of the yaw ∝ v: stable while c < (1 + e^(−T/τ))/(1 − e^(−T/τ))). So
//!   c = min(c_max, v/v_y): 4 from 24 m/s, 2.5 at 15 m/s, 1.7 at 10 m/s.
//! - At speed the yaw no longer settles within a step, and the loop's gain over one step is
//!   the car's own: a steering change Δδ turns the front axle's force by C_f·Δδ and the yaw
//!   rate, one step T later, by a·C_f·Δδ·T/I_z, which the law answers with
//!   −(c·G/v)·a·C_f·T/I_z·Δδ. That one-step gain g₁ = c·G·a·C_f·T/(v·I_z) rings at half the
//!   driver's rate once it passes 1 and grows once it passes 2: it falls with speed on an
//!   oversteering, soft-tyred car (the Spirit 300's reaches 1.59 with c = min(c_max, v/v_y), at
//!   20 m/s) and rises on an understeering, stiff one (car1-trb1's reached 1.9–2.8 from
//!   20 m/s up, and its steering alternated step by step in cdbo's simulator and in the game
//!   alike). So c = min(c_max, v/v_y, g*·v·I_z/(G·a·C_f·T)), g* = [`YAW_STEP_GAIN`].
//!
//! On a circle of curvature κ the linear single-track car settles with e = 0, Δψ = Δψ_ss and
//! r = v·κ, steering δ = (L + K·v²)·κ: there κ_d = κ, the feed-forward is the whole steady
//! steering and the feedback's error vanishes (a car held at offset e turns on curvature
//! κ/(1 − κe) and would need e·[κ² + (2/x_p²)·(1 + x_p·κ²·(m·a·v²/(L·C_r) − b))] = 0). The test
//! `the_tracker_holds_an_offset_on_a_circle` checks this steady state on the simulator's car.

use crate::car::Car;
use crate::geometry::bearing;
use crate::track::{Projection, Track};
use crate::vehicle::{State, Vehicle};

/// Preview time t_p (s). The gains were chosen by the ceiling (`cdbo ceiling --steering
/// tracker`, the tracked profile's share of the limit, averaged over Ridgeway, Forza, Allondaz
/// and E-Track 2) over t_p 0.2–0.9 s, x_min 3–10 m, t_f 0–0.2 s and c 0–8: 92.3 % at these
/// gains, within 2.5 % of it for t_p 0.2–0.4 s, t_f 0.1–0.2 s and c 2–4; without the yaw-rate
/// feedback (c = 0) 74–76 %, and from c = 8 E-Track 2 spins (64–76 %).
pub const PREVIEW_TIME: f64 = 0.4;
/// Shortest preview distance x_min (m).
pub const PREVIEW_MIN: f64 = 10.0;
/// Feed-forward preview time t_f (s).
pub const FEEDFORWARD_TIME: f64 = 0.15;
/// Yaw-rate gain c_max (dimensionless: the steering per unit of curvature error in yaw).
pub const YAW_RATE_GAIN: f64 = 4.0;
/// The yaw-rate loop's largest one-step gain g* (see the module): c ≤ g*·v·I_z/(G·a·C_f·T).
/// Chosen by measurement: the Spirit 300's laps reach at most 1.59 with c = min(c_max, v/v_y)
/// and do not ring (0.003 rad a step), car1-trb1's reached 1.9–2.8 with c_max = 4 and rang at
/// 0.09–0.17 rad a step from 20 m/s up, in cdbo's simulator and in the game alike
/// (docs/results/torcs.md, "The path tracker's one-step bound"); at a flat c = 2.5 (one-step gains up to 1.75)
/// they rang at 0.0003–0.002 rad.
pub const YAW_STEP_GAIN: f64 = 1.6;
/// The driver step T (s) the law acts at, in cdbo's simulator and in the game (TORCS's robots
/// are called every 20 ms).
pub const DRIVER_STEP: f64 = 0.02;
/// The speed v_y (m/s) per unit of yaw-rate gain below c_max: c = min(c_max, v/v_y). With
/// c_max at every speed the Spirit 300's steering rang at 25 Hz below some 17 m/s
/// (Ridgeway's 15 m/s demonstration: 0.028 rad of steering change per driver step against
/// the PI's 0.00005, and 15 % more pedal for the same speed; at 10 m/s 0.15 rad), so that
/// the demonstration's fitted policy stalled on the climb; with v_y = 6 m/s 0.00014, and the
/// ceiling on the minimum-curvature line (Ridgeway, Forza, Allondaz, E-Track 2) 96.2 / 106.5 /
/// 111.6 / 104.4 % of the centre-line limit against 95.8 / 106.3 / 111.5 / 104.3 (v_y = 5:
/// 96.8 / 106.5 / 110.6 / 104.6).
pub const YAW_RATE_SPEED: f64 = 6.0;
/// Half the spacing of the path points the heading and curvature are read from (m): one
/// station of a racing line ([`crate::line::SPACING`]). A line is linear between its stations,
/// so its curvature sits in kinks there; three points a station apart read each kink's share
/// evenly wherever the car is, where points 2 m apart read a kink whole or not at all as the
/// car moves 1.2 m a driver step past 3 m stations. With 2 m the feed-forward rang on
/// E-Track 2's minimum-curvature line at speed (car1-trb1, a learned lap above 40 m/s: the
/// steering's second difference 0.070 rad a step, 0.0007 on the centre line; with 3 m
/// 0.0006). The pattern search's best lap there (50 kernels, 3 seeds, in cdbo's simulator)
/// 127.67 s with 2 m, 125.25 s with 3 m; in the game (`cdbo --simulator torcs race --track
/// e-track-2 --kernels 50 --steering tracker --line min-curvature`) 132.70 s and 128.39 s.
pub const PATH_STEP: f64 = crate::line::SPACING;
/// The speed below which the gains are those of this speed (m/s): the standing start.
pub const MIN_SPEED: f64 = 1.0;

/// The path tracker's gains (it keeps no memory between steps).
#[derive(Debug, Clone, PartialEq)]
pub struct PathTracker {
    /// Preview time t_p (s).
    pub preview_time: f64,
    /// Shortest preview distance x_min (m).
    pub preview_min: f64,
    /// Feed-forward preview time t_f (s).
    pub feedforward_time: f64,
    /// Yaw-rate gain c_max.
    pub yaw_rate_gain: f64,
    /// Speed per unit of yaw-rate gain below c_max, v_y (m/s).
    pub yaw_rate_speed: f64,
    /// The yaw-rate loop's largest one-step gain g*.
    pub yaw_step_gain: f64,
}

impl Default for PathTracker {
    fn default() -> Self {
        PathTracker {
            preview_time: PREVIEW_TIME,
            preview_min: PREVIEW_MIN,
            feedforward_time: FEEDFORWARD_TIME,
            yaw_rate_gain: YAW_RATE_GAIN,
            yaw_rate_speed: YAW_RATE_SPEED,
            yaw_step_gain: YAW_STEP_GAIN,
        }
    }
}

/// The car as the tracker's law reads it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerCar {
    /// Mass m (kg).
    pub mass: f64,
    /// Wheelbase L (m).
    pub wheelbase: f64,
    /// Distance a of the front axle from the centre of gravity (m).
    pub cg_to_front: f64,
    /// Distance b of the rear axle from the centre of gravity (m).
    pub cg_to_rear: f64,
    /// Largest road-wheel angle δ_max (rad).
    pub steer_lock: f64,
    /// Yaw inertia I_z (kg·m²).
    pub yaw_inertia: f64,
}

impl TrackerCar {
    /// What the law reads of `car`.
    pub fn of(car: &Car) -> TrackerCar {
        TrackerCar {
            mass: car.mass,
            wheelbase: car.wheelbase,
            cg_to_front: car.cg_to_front(),
            cg_to_rear: car.cg_to_rear(),
            steer_lock: car.steer_lock,
            yaw_inertia: car.yaw_inertia(),
        }
    }
}

/// The car's state against the path, all the tracker's law reads of a driver step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerInput {
    /// Lateral error e (m, positive left of the path).
    pub lateral_error: f64,
    /// Heading error Δψ = ψ − θ_P (rad).
    pub heading_error: f64,
    /// The path's curvature κ_f at the feed-forward station (1/m).
    pub curvature: f64,
    /// Speed v (m/s), at least [`MIN_SPEED`] ([`tracker_speed`]).
    pub speed: f64,
    /// Yaw rate r (rad/s).
    pub yaw_rate: f64,
    /// The front and rear axle's cornering stiffness C_f, C_r at this speed (N/rad).
    pub cornering_stiffness: [f64; 2],
}

impl PathTracker {
    /// A tracker with the documented gains.
    pub fn new() -> PathTracker {
        PathTracker::default()
    }

    /// The road-wheel angle (rad) for the car in `state` at `proj` holding the line `line(s)`
    /// metres left of the centre line at station s (the [module](self)'s law): the path's
    /// points [`PATH_STEP`] either side of the car's station give its heading, three points
    /// around the station t_f·v ahead its [`curvature`], and [`Self::law`] steers.
    pub fn update(
        &self,
        track: &Track,
        vehicle: &Vehicle,
        state: &State,
        proj: &Projection,
        line: &dyn Fn(f64) -> f64,
    ) -> f64 {
        let v = tracker_speed(state.speed());
        let path = |s: f64| track.point_off(s, line(track.wrap(s)));
        let s = proj.s;
        let (behind, ahead) = (path(s - PATH_STEP), path(s + PATH_STEP));
        // Δψ = ψ − θ_P: minus the bearing of the path's tangent from the car's heading.
        let heading_error = -bearing(ahead.0 - behind.0, ahead.1 - behind.1, state.yaw_sin_cos);
        let sf = s + self.feedforward_time * v;
        let input = TrackerInput {
            lateral_error: proj.lateral - line(s),
            heading_error,
            curvature: curvature(path(sf - PATH_STEP), path(sf), path(sf + PATH_STEP)),
            speed: v,
            yaw_rate: state.yaw_rate,
            cornering_stiffness: vehicle.cornering_stiffness(v, track.frame(proj.index).friction),
        };
        self.law(&TrackerCar::of(&vehicle.car), &input)
    }

    /// The road-wheel angle (rad) δ = clamp(G·(κ_d + c·(κ_d − r/v)), −δ_max, δ_max), with
    /// c = min(c_max, v/v_y, g*·v·I_z/(G·a·C_f·T)), κ_d = κ_f − (2/x_p²)·(e + x_p·(Δψ − Δψ_ss)),
    /// x_p = max(t_p·v, x_min), Δψ_ss = κ_f·(m·a·v²/(L·C_r) − b), G = max(L + K·v², L/4),
    /// K = (m/L)·(b/C_f − a/C_r)
    /// (the [module](self)'s law, a pure function of numbers so that the TORCS robot's
    /// `torcs-robot/drive.hpp` can be checked against it, `tests/robot_drive.rs`).
    pub fn law(&self, car: &TrackerCar, input: &TrackerInput) -> f64 {
        let (l, a, b, m) = (car.wheelbase, car.cg_to_front, car.cg_to_rear, car.mass);
        let (e, heading_error, kappa, v) = (
            input.lateral_error,
            input.heading_error,
            input.curvature,
            input.speed,
        );
        let [cf, cr] = input.cornering_stiffness;
        let understeer = m / l * (b / cf - a / cr);
        let steady_heading_error = kappa * (m * a * v * v / (l * cr) - b);
        let x_p = (self.preview_time * v).max(self.preview_min);
        let kappa_d =
            kappa - 2.0 / (x_p * x_p) * (e + x_p * (heading_error - steady_heading_error));
        let gain = (l + understeer * v * v).max(0.25 * l);
        let one_step = self.yaw_step_gain * v * car.yaw_inertia / (gain * a * cf * DRIVER_STEP);
        let c = self
            .yaw_rate_gain
            .min(v / self.yaw_rate_speed)
            .min(one_step);
        let delta = gain * (kappa_d + c * (kappa_d - input.yaw_rate / v));
        delta.clamp(-car.steer_lock, car.steer_lock)
    }
}

/// The speed (m/s) the tracker's gains are taken at: max(v, [`MIN_SPEED`]).
#[inline]
pub fn tracker_speed(speed: f64) -> f64 {
    speed.max(MIN_SPEED)
}

/// The signed curvature (1/m, positive turning left) of the circle through three points:
/// 2·((p₁ − p₀) × (p₂ − p₁)) / (|p₁ − p₀|·|p₂ − p₁|·|p₂ − p₀|).
pub fn curvature(p0: (f64, f64), p1: (f64, f64), p2: (f64, f64)) -> f64 {
    let (ax, ay) = (p1.0 - p0.0, p1.1 - p0.1);
    let (bx, by) = (p2.0 - p1.0, p2.1 - p1.1);
    let (cx, cy) = (p2.0 - p0.0, p2.1 - p0.1);
    let norms = (ax.hypot(ay) * bx.hypot(by) * cx.hypot(cy)).max(f64::MIN_POSITIVE);
    2.0 * (ax * by - ay * bx) / norms
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three points on a circle of radius R give 1/R, signed by the turn.
    #[test]
    fn three_points_give_the_circles_curvature() {
        let r = 37.0;
        let p = |t: f64| (r * t.cos(), r * t.sin());
        let k = curvature(p(0.1), p(0.15), p(0.2));
        assert!((k - 1.0 / r).abs() < 1e-12, "{k}");
        assert!((curvature(p(0.2), p(0.15), p(0.1)) + 1.0 / r).abs() < 1e-12);
        assert_eq!(curvature((0.0, 0.0), (1.0, 0.0), (2.0, 0.0)), 0.0);
    }
}
