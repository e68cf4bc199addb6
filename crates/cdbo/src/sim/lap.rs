//! One lap: the expensive evaluation of the paper, reward R = L/T, or 0 if the lap fails.
//!
//! The car starts standing on the start line, on the centre line, facing along it. Every
//! physics step (4 ms) the car is projected on the centre line; every driver step (20 ms) the
//! pedal and the steering controller update their commands, which are held in between. The
//! steering holds the driver's line ([`Pedal::line`]: the centre line unless the driver names
//! another), measured from the lap's own line d₀(s) if it has one ([`LapConfig::line`], e.g.
//! the minimum-curvature line) and bounded to the road: at station s the offset d₀(s) + d(s/L)
//! is clamped to ±max(0, w(s)/2 − w_car/2), the road's half-width less half the car's width.
//! The lap ends when the car has covered the track's length, or fails when:
//! - **off track**: the car's centre is more than width/2 + 1 m from the centre line;
//! - **hit the wall**: a corner of the body is past a barrier, where a TORCS track has them
//!   ([`crate::vehicle::barrier`]: the road, its border and its side; the game bounces the car off it);
//! - **spun**: the car faces more than 90° away from the track, or slides with a body slip
//!   angle above 60° at more than 3 m/s;
//! - **backwards**: the car has moved 10 m back from the farthest point it reached;
//! - **stalled**: slower than 1 m/s for 5 s ([`STALL_SPEED`]); a car that comes to rest off
//!   the road (its centre past the edge while it is that slow, in the gravel short of the
//!   off-track margin) left the road: it fails **off track**, too fast, not too slow;
//! - **time limit**: the lap takes longer than its limit.
//!
//! Nothing else ends a lap: whether these happen follows from speed, grip and steering.
//!
//! **A flying lap** ([`LapConfig::flying`]) is the lap a race is made of, the way the game
//! times a robot's best lap: the car drives two laps from the standing start with the same
//! policy (the pedal and line read at the lap fraction of the lap it is on), and the second,
//! which starts as the car crosses the line at speed, is timed line to line. Either lap can
//! fail, at its own lap fraction; the time limit is the two laps'. On the run-up, the first
//! lap, the pedal keeps the car above 10 m/s ([`run_up_pedal`]): a policy braking for a
//! corner the flying lap enters fast would otherwise stop the slower run-up there.

use std::sync::Arc;

use serde::Serialize;

use crate::car::Car;
use crate::drive::demo::SpeedHold;
use crate::drive::steering::Steering;
use crate::drive::{Observation, Pedal, pedal_command, run_up_pedal};
use crate::geometry::wrap_angle;
use crate::line::RacingLine;
use crate::sim::trace::TracePoint;
use crate::track::{Frame, Track};
use crate::vehicle::barrier::Body;
use crate::vehicle::{State, Vehicle};

/// Why a lap failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureReason {
    /// The car left the road.
    OffTrack,
    /// The car's body hit a barrier.
    HitWall,
    /// The car spun.
    Spun,
    /// The car drove backwards.
    Backwards,
    /// The car stopped.
    Stalled,
    /// The lap took too long.
    TimeLimit,
}

impl FailureReason {
    /// The name used in JSON and CSV output (`off_track`, `spun`, …).
    pub fn name(self) -> &'static str {
        match self {
            FailureReason::OffTrack => "off_track",
            FailureReason::HitWall => "hit_wall",
            FailureReason::Spun => "spun",
            FailureReason::Backwards => "backwards",
            FailureReason::Stalled => "stalled",
            FailureReason::TimeLimit => "time_limit",
        }
    }

    /// Whether the car failed for being too slow (it stalled or ran out of time) rather than
    /// too fast (it left the road, spun or turned round).
    pub fn too_slow(self) -> bool {
        matches!(self, FailureReason::Stalled | FailureReason::TimeLimit)
    }

    /// The reason named `name` ([`FailureReason::name`]), if it is one.
    pub fn from_name(name: &str) -> Option<FailureReason> {
        [
            FailureReason::OffTrack,
            FailureReason::HitWall,
            FailureReason::Spun,
            FailureReason::Backwards,
            FailureReason::Stalled,
            FailureReason::TimeLimit,
        ]
        .into_iter()
        .find(|r| r.name() == name)
    }
}

/// Where and when a lap failed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct Failure {
    /// Why.
    pub reason: FailureReason,
    /// Lap fraction of the car's station.
    pub x: f64,
    /// Distance covered (m).
    pub distance_m: f64,
    /// Time since the start (s).
    pub time_s: f64,
}

/// The outcome of a lap.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LapResult {
    /// Whether the car completed the lap.
    pub completed: bool,
    /// Lap time (s) when completed.
    pub lap_time_s: Option<f64>,
    /// Reward R = L/T (m/s), 0 when the lap failed.
    pub reward_mps: f64,
    /// Why and where the lap failed, if it did.
    pub failure: Option<Failure>,
    /// Simulated time (s).
    pub simulated_s: f64,
    /// Of a flying lap ([`LapConfig::flying`]), the standing lap before it (s), once the car
    /// completed it; `lap_time_s` is then the flying lap's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub standing_lap_s: Option<f64>,
    /// The driver steps, when asked for.
    #[serde(skip)]
    pub trace: Vec<TracePoint>,
}

/// Settings of a lap.
#[derive(Debug, Clone, PartialEq)]
pub struct LapConfig {
    /// Physics step (s): 4 ms, twice TORCS's 2 ms: lap times stay close to those of a much
    /// finer step at nearly twice the speed (measured in docs/results/design.md). The test
    /// `the_lap_time_converges_as_the_step_shrinks` checks the convergence.
    pub dt: f64,
    /// Physics steps per driver step: 5, i.e. the driver at 50 Hz.
    pub driver_every: usize,
    /// Extra distance beyond half the width before the car is off track (m): by default
    /// [`GAME_OFF_TRACK_MARGIN`], the game's rule.
    pub off_track_margin: f64,
    /// Time limit (s); `None`: 30 s + L / (4 m/s).
    pub time_limit: Option<f64>,
    /// Record a trace of every driver step.
    pub trace: bool,
    /// The steering controller (its gains; its memory starts empty each lap): the PI by
    /// default.
    pub steering: Steering,
    /// The line the car holds, part of the track as a driver's reference: offsets d₀(s) from
    /// the centre line ([`RacingLine::offset_at`]); a policy's own line d(x) is driven as an
    /// offset from it, d₀(s) + d(s/L), clamped to the road less half the car's width.
    /// `None`: the centre line (d₀ = 0).
    pub line: Option<Arc<RacingLine>>,
    /// What a learning lap keeps in reserve where the road's verges are known
    /// ([`Reserve`]); `None`: the lap fails only at [`LapConfig::off_track_margin`] and the
    /// barriers.
    pub reserve: Option<Reserve>,
    /// Time the flying lap, the second of two from the standing start (the [module](self)),
    /// rather than the standing lap.
    pub flying: bool,
}

/// What a policy learning in cdbo's simulator keeps in reserve of the road, so that the world it
/// is then driven in (the game, a car) does not take its lap away: the lap fails once
///
/// - a wheel's centre comes within [`Reserve::wheels_m`] of ground gripping less than
///   [`Reserve::SLIPPERY`] of the road (grass, sand, gravel past the edge; a flat kerb as
///   grippy as the road is not slippery): at the grass the tyres lose two thirds of their
///   grip, and there a few centimetres between cdbo's car and the game's decide whether the
///   car spins;
/// - a wheel's centre mounts a raised kerb, whose ramp cdbo's wheels do not climb;
/// - a corner of the body comes within [`Reserve::body_m`] of a barrier;
/// - the car's centre passes the road's edge, or, on a road whose verges the track does not
///   give (the built-in and CSV tracks), [`LapConfig::off_track_margin`] (by default
///   [`LEARNING_OFF_TRACK_MARGIN`], a metre inside it): nothing is known past that edge.
///
/// Measured on TORCS's 21 road tracks over seeds 0–2 (docs/results/torcs.md):
/// the pattern search's best policies complete in the game on 21, 19 and 21 of 21, against 19,
/// 20 and 20 with the car's centre a metre inside every edge, at 95.7 % of the transfer's
/// reference reward on average against 95.5 %.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Reserve {
    /// Distance every wheel's centre keeps from slippery ground (m).
    pub wheels_m: f64,
    /// Distance every corner of the body keeps from a barrier (m).
    pub body_m: f64,
}

impl Reserve {
    /// The reserve a policy learns with in cdbo's simulator: a quarter of a metre for the
    /// wheels (half a metre completed all 21 tracks on seed 0 too, for 0.5 % more of the reward;
    /// the metre on the car's centre left its wheels 0.16 m, where E-Track 3's spun), a metre
    /// for the body (without it the game's car struck the walls on Alpine 1 and 2).
    pub const LEARNING: Reserve = Reserve {
        wheels_m: 0.25,
        body_m: 1.0,
    };

    /// Ground gripping less than this share of the road's friction is slippery.
    pub const SLIPPERY: f64 = 0.8;
}

/// The game's rule for where a lap fails (m past the road's edge, [`LapConfig::off_track_margin`]):
/// the car's centre 1 m past the edge. A lap is judged by it unless told otherwise: `cdbo
/// lap`, the game's own laps, `cdbo torcs compare`.
pub const GAME_OFF_TRACK_MARGIN: f64 = 1.0;

/// Where a lap fails while a policy learns in cdbo's simulator on a road whose verges the track
/// does not give ([`Reserve`]; the built-in and CSV tracks): the car's centre 1 m *inside* the
/// road's edge, two metres short of the game's rule. A policy learned at the very edge the
/// simulator allows leaves the road wherever the world it is then driven in is a little
/// harsher; on TORCS's road tracks this metre, everywhere, was the robust learner's reserve
/// (docs/results/torcs.md). Learning in the game itself takes the
/// game's rule.
pub const LEARNING_OFF_TRACK_MARGIN: f64 = -1.0;

/// The off-track margins a lap takes (m, [`LapConfig::off_track_margin`]): from 3 m inside the
/// road's edge to 5 m past it.
pub const OFF_TRACK_MARGINS: std::ops::RangeInclusive<f64> = -3.0..=5.0;

/// `margin` if it is within [`OFF_TRACK_MARGINS`], else an error naming it.
pub fn checked_off_track_margin(margin: f64) -> crate::error::Result<f64> {
    if OFF_TRACK_MARGINS.contains(&margin) {
        Ok(margin)
    } else {
        Err(crate::error::Error::invalid_value(
            "the off-track margin (m)",
            margin,
            "within [-3, 5] m past the road's edge (negative: inside it)",
        ))
    }
}

impl Default for LapConfig {
    fn default() -> Self {
        LapConfig {
            dt: 0.004,
            driver_every: 5,
            off_track_margin: GAME_OFF_TRACK_MARGIN,
            time_limit: None,
            trace: false,
            steering: Steering::default(),
            line: None,
            reserve: None,
            flying: false,
        }
    }
}

impl LapConfig {
    /// Laps driven for one timed lap: 2 for a flying lap (the standing lap before it), else 1;
    /// the time limit is theirs.
    pub fn laps(&self) -> f64 {
        if self.flying { 2.0 } else { 1.0 }
    }

    /// Laps failing once the car's centre is `margin` metres past the road's edge (negative:
    /// inside the road), and at the barriers, nothing kept in reserve.
    pub fn fail_at(&mut self, margin: f64) {
        self.off_track_margin = margin;
        self.reserve = None;
    }

    /// Laps as a policy learns them in cdbo's simulator: failing `margin` metres past the
    /// road's edge if given ([`LapConfig::fail_at`]); else keeping [`Reserve::LEARNING`] (a
    /// reserve the world the policy is then driven in will not take away), with
    /// [`LEARNING_OFF_TRACK_MARGIN`] where the road's verges are not known.
    pub fn learn_with(&mut self, margin: Option<f64>) {
        match margin {
            Some(margin) => self.fail_at(margin),
            None => {
                self.off_track_margin = LEARNING_OFF_TRACK_MARGIN;
                self.reserve = Some(Reserve::LEARNING);
            }
        }
    }
}

/// 1 / tan(60°): a body slip angle above 60° means vₓ < |v_y| / tan 60°.
pub(crate) const INV_TAN_SPIN_SLIP_ANGLE: f64 = 0.577_350_269_189_625_8;
pub(crate) const SPIN_MIN_SPEED: f64 = 3.0;
pub(crate) const BACKWARDS_DISTANCE: f64 = 10.0;
/// Slower than this (m/s) for [`STALL_TIME`] the car has stopped racing. It was 0.5 m/s: in
/// the game (car1-trb1, Aalborg, the line learned, seed 1) a push's pedal braked the car to
/// 0.51–0.6 m/s in a slow corner for 10 s, a completed lap 12 s slower than the best that
/// ended the pushes; at 1 m/s it stalls, and the repair raises the pedal there (six seeds in
/// the game: 82.05 → 81.26 s with the line learned, 81.51 → 80.64 s fixed).
pub const STALL_SPEED: f64 = 1.0;
/// How long (s) below [`STALL_SPEED`] a car stalls.
pub const STALL_TIME: f64 = 5.0;

/// Whether the car faces more than 90° away from the road: cos(ψ − θ) < 0.
#[inline]
fn facing_away(state: &State, frame: &Frame) -> bool {
    let (sy, cy) = state.yaw_sin_cos;
    cy * frame.cos_heading + sy * frame.sin_heading < 0.0
}

/// The offset (m, positive left of the centre line) the car holds at centre-line station `s`:
/// the base line's d₀(s) (0 without one) plus the policy's d, clamped to the road less half the
/// car's width, |d₀ + d| ≤ max(w(s)/2 − `half_car`, 0). One definition for the lap and for
/// whatever draws the line a lap holds.
#[inline]
pub fn held_offset(track: &Track, half_car: f64, base: Option<&RacingLine>, d: f64, s: f64) -> f64 {
    let bound = (track.frame(track.index_at(s)).half_width - half_car).max(0.0);
    let d = match base {
        Some(base) => base.offset_at(s) + d,
        None => d,
    };
    d.clamp(-bound, bound)
}

/// A point of the line a lap holds ([`Simulator::held_line`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HeldPoint {
    /// Station on the centre line (m).
    pub s: f64,
    /// Offset from the centre line (m, positive left), within the road less half the car.
    pub offset: f64,
    /// Position (m).
    pub x: f64,
    /// Position (m).
    pub y: f64,
}

/// A track and a car, ready to run laps.
#[derive(Debug, Clone)]
pub struct Simulator {
    /// The track.
    pub track: Track,
    /// The car, prepared for simulation.
    pub vehicle: Vehicle,
    /// Lap settings.
    pub config: LapConfig,
}

impl Simulator {
    /// A simulator with the default settings.
    pub fn new(track: Track, car: &Car) -> Simulator {
        Simulator {
            track,
            vehicle: Vehicle::new(car),
            config: LapConfig::default(),
        }
    }

    /// The line a policy with line `d(x)` holds, as its laps steer it ([`held_offset`]): at
    /// every track sample sᵢ, the offset dᵢ (m, positive left) and the point cᵢ + dᵢ·nᵢ, nᵢ
    /// the centre line's left normal (−sin θᵢ, cos θᵢ).
    pub fn held_line(&self, d: impl Fn(f64) -> f64) -> Vec<HeldPoint> {
        let track = &self.track;
        let half_car = 0.5 * self.vehicle.car.width;
        track
            .samples
            .iter()
            .map(|p| {
                let offset = held_offset(
                    track,
                    half_car,
                    self.config.line.as_deref(),
                    d(p.s / track.length),
                    p.s,
                );
                let (sin, cos) = p.heading.sin_cos();
                HeldPoint {
                    s: p.s,
                    offset,
                    x: p.x - offset * sin,
                    y: p.y + offset * cos,
                }
            })
            .collect()
    }

    /// The time limit of a lap (s).
    pub fn time_limit(&self) -> f64 {
        self.config
            .time_limit
            .unwrap_or(30.0 + self.track.length / 4.0)
    }

    /// The demonstration (paper Sec. V): the lap of a speed hold at `speed` (m/s), traced, and
    /// its (x, a) pairs at every driver step, which w₀ is fitted to.
    pub fn demonstrate(&self, speed: f64) -> (LapResult, Vec<(f64, f64)>) {
        let mut traced = self.clone();
        traced.config.trace = true;
        let lap = traced.lap(&mut SpeedHold::new(speed));
        let pairs = lap.trace.iter().map(|p| (p.x, p.pedal)).collect();
        (lap, pairs)
    }

    /// Drives one lap with `pedal` and the steering controller.
    pub fn lap(&self, pedal: &mut dyn Pedal) -> LapResult {
        let track = &self.track;
        let cfg = &self.config;
        let half_car = 0.5 * self.vehicle.car.width;
        let body = Body::of(&self.vehicle.car);
        let start = track.sample(0);
        let mut state: State = self.vehicle.at_rest(start.x, start.y, start.heading);
        let mut steering = cfg.steering.clone();
        let mut controls = self.vehicle.controls(0.0, 0.0, 0.0);
        let mut proj = track.project(state.x, state.y, 0);
        let (mut distance, mut farthest, mut slow_for) = (0.0, 0.0, 0.0);
        // Whether the car has been off the road since it became slow.
        let mut slow_off_road = false;
        let mut trace = Vec::new();
        let limit = cfg.laps() * self.time_limit();
        // Where the timed lap starts: its distance (m) and time (s) at the line.
        let (mut lap_start, mut standing) = (0.0, None);
        let driver_dt = cfg.dt * cfg.driver_every as f64;
        let mut step = 0usize;
        let mut until_driver = 0usize;
        let half_length = 0.5 * track.length;
        // `distance` into the lap it failed on.
        let fail = |reason, distance: f64, t: f64, standing: Option<f64>| LapResult {
            completed: false,
            lap_time_s: None,
            reward_mps: 0.0,
            failure: Some(Failure {
                reason,
                x: (distance / track.length).clamp(0.0, 1.0),
                distance_m: distance,
                time_s: t,
            }),
            simulated_s: t,
            standing_lap_s: standing,
            trace: Vec::new(),
        };
        loop {
            if until_driver == 0 {
                until_driver = cfg.driver_every;
                let t = step as f64 * cfg.dt;
                let x = ((distance - lap_start) / track.length).clamp(0.0, 1.0);
                let mut a = pedal_command(pedal.pedal(&Observation {
                    x,
                    speed: state.speed(),
                    time: t,
                }));
                if cfg.flying && standing.is_none() {
                    a = run_up_pedal(a, state.speed());
                }
                let line = |s: f64| {
                    held_offset(
                        track,
                        half_car,
                        cfg.line.as_deref(),
                        pedal.line(s / track.length),
                        s,
                    )
                };
                let steer = steering.update(track, &self.vehicle, &state, &proj, &line, driver_dt);
                let brake = self.vehicle.driver_brake(&state, (-a).max(0.0));
                controls = self.vehicle.controls(steer, a.max(0.0), brake);
                self.vehicle.shift(&mut state, controls.throttle());
                self.vehicle
                    .clutch(&mut state, controls.throttle(), driver_dt);
                if cfg.trace {
                    trace.push(TracePoint {
                        t,
                        distance_m: distance,
                        x,
                        speed: state.speed(),
                        pedal: a,
                        steer: controls.steer(),
                        lateral: proj.lateral,
                        heading_error: wrap_angle(state.yaw - track.sample(proj.index).heading),
                        slip_angle: state.vy.atan2(state.vx.abs().max(1e-9)),
                        gear: state.gearbox.gear + 1,
                        rpm: state.engine_speed * 30.0 / std::f64::consts::PI,
                        pos_x: state.x,
                        pos_y: state.y,
                        yaw_rate: state.yaw_rate,
                        wheel_speeds: self.vehicle.wheel_speeds(&state),
                    });
                }
            }
            self.vehicle
                .step(&mut state, &controls, track.frame(proj.index), cfg.dt);
            step += 1;
            until_driver -= 1;
            let t = step as f64 * cfg.dt;
            let prev_s = proj.s;
            proj = track.project(state.x, state.y, proj.index);
            let mut ds = proj.s - prev_s;
            if ds > half_length {
                ds -= track.length;
            } else if ds < -half_length {
                ds += track.length;
            }
            let before = distance;
            distance += ds;
            if distance >= lap_start + track.length {
                // The time the car crossed the line, linear within the step.
                let crossed = t - cfg.dt + cfg.dt * (lap_start + track.length - before) / ds;
                if cfg.flying && standing.is_none() {
                    (lap_start, standing) = (track.length, Some(crossed));
                } else {
                    let lap_time = crossed - standing.unwrap_or(0.0);
                    return LapResult {
                        completed: true,
                        lap_time_s: Some(lap_time),
                        reward_mps: track.length / lap_time,
                        failure: None,
                        simulated_s: t,
                        standing_lap_s: standing,
                        trace,
                    };
                }
            }
            farthest = f64::max(farthest, distance);
            let road = track.frame(proj.index);
            let (edge, wheels, walls) = match cfg.reserve {
                Some(r) if road.has_verges => (0.0, Some(r.wheels_m), r.body_m),
                Some(r) => (cfg.off_track_margin, None, r.body_m),
                None => (cfg.off_track_margin, None, 0.0),
            };
            let failure = if proj.lateral.abs() > road.half_width + edge
                || wheels.is_some_and(|reserve| {
                    self.vehicle
                        .wheel_near_slippery(&state, road, reserve, Reserve::SLIPPERY)
                }) {
                Some(super::FailureReason::OffTrack)
            } else if body.near_barrier(&state, road, walls) {
                Some(super::FailureReason::HitWall)
            } else if facing_away(&state, road)
                || (state.vx < state.vy.abs() * INV_TAN_SPIN_SLIP_ANGLE
                    && state.speed() > SPIN_MIN_SPEED)
            {
                Some(super::FailureReason::Spun)
            } else if distance < farthest - BACKWARDS_DISTANCE {
                Some(super::FailureReason::Backwards)
            } else if t > limit {
                Some(super::FailureReason::TimeLimit)
            } else {
                let slow = state.vx.abs() < STALL_SPEED && state.speed() < STALL_SPEED;
                slow_for = if slow { slow_for + cfg.dt } else { 0.0 };
                slow_off_road = slow && (slow_off_road || proj.lateral.abs() > road.half_width);
                (slow_for > STALL_TIME).then_some(if slow_off_road {
                    super::FailureReason::OffTrack
                } else {
                    super::FailureReason::Stalled
                })
            };
            if let Some(reason) = failure {
                let mut r = fail(reason, (distance - lap_start).max(0.0), t, standing);
                r.trace = trace;
                return r;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::car::{Car, G};
    use crate::drive::demo::SpeedHold;
    use crate::drive::tracker::{
        PathTracker, TrackerCar, TrackerInput, YAW_RATE_GAIN, YAW_RATE_SPEED,
    };
    use crate::drive::{Observation, Pedal};
    use crate::track::{Piece, Track};
    use std::f64::consts::FRAC_PI_2;

    /// The demonstrator's speed hold on a line `offset` metres left of the centre line.
    struct OnLine {
        hold: SpeedHold,
        offset: f64,
    }

    impl Pedal for OnLine {
        fn pedal(&mut self, obs: &Observation) -> f64 {
            self.hold.pedal(obs)
        }

        fn line(&self, _: f64) -> f64 {
            self.offset
        }
    }

    /// The yaw-rate loop does not ring at low speed: the 15 m/s and 10 m/s demonstrations on
    /// Ridgeway change the steering by less than 1 mrad per driver step on average (with
    /// c = 4 at every speed, 28 and 150 mrad: the steering alternated step by step), and
    /// with the full gain from v = c_max·v_y on, the law is the same there (car1-trb1 at
    /// speed: `tests/shared_tracks.rs`).
    #[test]
    fn the_steering_does_not_ring_at_low_speed() {
        let track = crate::track::builtin::load("ridgeway").unwrap().unwrap();
        let mut sim = Simulator::new(track, &Car::spirit_300());
        sim.config.steering = Steering::Tracker(PathTracker::new());
        sim.config.trace = true;
        for speed in [10.0, 15.0] {
            let lap = sim.lap(&mut SpeedHold::new(speed));
            assert!(lap.completed, "{speed}: {:?}", lap.failure);
            let steps = lap.trace.windows(2);
            let n = steps.len() as f64;
            let change = steps.map(|w| (w[1].steer - w[0].steer).abs()).sum::<f64>() / n;
            assert!(change < 1e-3, "{speed} m/s: {change} rad per step");
        }
        let tracker = PathTracker::new();
        let car = TrackerCar::of(&Car::spirit_300());
        let fast = |yaw_rate_speed| PathTracker {
            yaw_rate_speed,
            ..tracker.clone()
        };
        let input = TrackerInput {
            lateral_error: 0.3,
            heading_error: 0.01,
            curvature: 0.01,
            speed: YAW_RATE_GAIN * YAW_RATE_SPEED,
            yaw_rate: 0.2,
            cornering_stiffness: [80_000.0, 90_000.0],
        };
        assert_eq!(tracker.law(&car, &input), fast(1e-9).law(&car, &input));
        let slow = TrackerInput {
            speed: 10.0,
            ..input
        };
        assert_ne!(tracker.law(&car, &slow), fast(1e-9).law(&car, &slow));
    }

    /// The closed-form steady state (see the module): on a circle of radius 100 m, with a line
    /// 3 m inside it (and outside it) at 15 m/s (0.23 g), the car settles on the line (e = 0
    /// within 5 mm) with the steering δ = (L + K·v²)·κ of the linear single-track car (within
    /// 0.5 %, as the front wheels' mean angle: the outer wheel steers by its Ackermann angle)
    /// and its heading error Δψ_ss = κ·(m·a·v²/(L·C_r) − b) − M_R/(L·C_r) (within 2.5 % of
    /// κ·b, the terms nearly cancelling at this speed; the drive force on the rear tyres'
    /// budget moves the rear slip a little), κ = 1/(R − d) the line's curvature; the rolling
    /// resistance's moment M_R = R·L/2 against the yaw (simuv2's) asks the front tyres for
    /// M_R/L more and the rear ones for M_R/L less, δ gaining M_R/L·(1/C_f + 1/C_r).
    #[test]
    fn the_tracker_holds_an_offset_on_a_circle() {
        let r = 100.0;
        let track = Track::from_pieces(
            "circle",
            "test",
            &[Piece::flat(std::f64::consts::TAU * r, 1.0 / r)],
            vec![],
        );
        let car = Car::spirit_300();
        let mut sim = Simulator::new(track, &car);
        sim.config.steering = Steering::Tracker(PathTracker::new());
        sim.config.trace = true;
        let (l, a, b, m) = (car.wheelbase, car.cg_to_front(), car.cg_to_rear(), car.mass);
        let start = sim.track.sample(0);
        let centre = (
            start.x - r * start.heading.sin(),
            start.y + r * start.heading.cos(),
        );
        for offset in [3.0, -3.0] {
            let mut driver = OnLine {
                hold: SpeedHold::new(15.0),
                offset,
            };
            let lap = sim.lap(&mut driver);
            assert!(lap.completed, "{:?}", lap.failure);
            // The last third of the lap, settled.
            let settled = &lap.trace[2 * lap.trace.len() / 3..];
            let n = settled.len() as f64;
            let mean =
                |f: &dyn Fn(&crate::sim::TracePoint) -> f64| settled.iter().map(f).sum::<f64>() / n;
            let v = mean(&|p| p.speed);
            let kappa = 1.0 / (r - offset);
            let [cf, cr] = sim.vehicle.cornering_stiffness(v, 1.0);
            let understeer = m / l * (b / cf - a / cr);
            let c_rr = 0.5 * (car.front_tyre.rolling_resistance + car.rear_tyre.rolling_resistance);
            let [df, dr] = car.downforce(v);
            let turning = 0.5 * c_rr * (m * G + df + dr) * l;
            let steer = (l + understeer * v * v) * kappa + turning / l * (1.0 / cf + 1.0 / cr);
            let heading = kappa * (m * a * v * v / (l * cr) - b) - turning / (l * cr);
            let lateral = mean(&|p| p.lateral);
            let heading_error = mean(&|p| {
                let proj = sim.track.project_global(p.pos_x, p.pos_y);
                let yaw = p.heading_error + sim.track.sample(proj.index).heading;
                let tangent = (p.pos_y - centre.1).atan2(p.pos_x - centre.0) + FRAC_PI_2;
                wrap_angle(yaw - tangent)
            });
            let delta = mean(&|p| p.steer);
            assert!((v - 15.0).abs() < 0.1, "speed {v}");
            assert!(
                (lateral - offset).abs() < 0.005,
                "d {offset}: lateral {lateral}"
            );
            assert!(
                (heading_error - heading).abs() < 0.025 * b * kappa,
                "d {offset}: Δψ {heading_error} against {heading}"
            );
            // The bicycle's steer is the mean of the front wheels' angles: the inner one's δ
            // and the outer one's Ackermann angle (`vehicle`); the lateral load transfer
            // leaves 0.3 % more.
            let track = car.axles.half_track[0] + car.axles.half_track[1];
            let outer = (l * delta.tan() / (l + track * delta.tan().abs())).atan();
            let mean = 0.5 * (delta + outer);
            assert!(
                (mean / steer - 1.0).abs() < 0.005,
                "d {offset}: δ {delta} (mean {mean}) against {steer}"
            );
        }
    }
}
