//! Open-loop replay: a logged lap's own commands driven through cdbo's car, window by window,
//! to say where the model and the car that drove the lap part.
//!
//! A closed-loop comparison (the same policy in both, [`crate::torcs`]'s `compare`) mixes the
//! vehicle with the driver: a car a little faster here steers a little differently there, and
//! the two laps part for reasons far from where they show. The replay takes the driver out.
//! Every `every_s` along the log, at a sample moving at least [`MIN_SPEED`], cdbo's car is
//! set to the logged state and driven for `window_s` by the logged steering and pedal, each
//! held until the next sample (its gear too, where the log names it); then
//!
//! - the yaw-rate error e_r = √(mean_k (r_k − r̂_k)²) over the window's samples,
//! - the lateral and speed errors at its end, d − d̂ and v − v̂ (cdbo's minus the log's).
//!
//! Each window is classed by what the logged car did in it ([`Regime`]): past the road's edge,
//! sliding, braking or driving on the road; the means are given per class too
//! ([`Replay::by_regime`]), since a model that agrees on the road may part in slides and off
//! it, where a learned policy that runs at the limit spends its decisive seconds.
//!
//! The logged state at sample i: the position at (sᵢ, dᵢ) off the centre line; the yaw
//! ψ = θ(sᵢ) + atan((∂d/∂s)/(1 − κd)) − β, the direction of travel against the centre line's
//! heading θ from the offset's slope (central differences over the neighbouring samples) less
//! the body's slip angle β (0 where the log has none); vₓ = v·cos β, v_y = v·sin β, the logged
//! yaw rate, and the tyres' longitudinal force per unit mass that gives the slope of vₓ
//! against the drag, the rolling resistance, the grade and v_y·r ([`Vehicle::tyres_accel`],
//! [`Vehicle::under_way`]; from the speed's slope alone, it was some 2 m/s² off in a slide),
//! and a shift still under way where the logged gear changed less than the car's shift time
//! before. Nothing is fitted: replayed, cdbo's own lap of Ridgeway comes back within
//! 0.0012 rad/s of yaw rate and 4 mm of offset after a second, in every regime within
//! 0.01 m/s of speed, so what remains against another car is the model's (or a state the log
//! does not hold: a wheel's spin, the body's roll).

use serde::Serialize;

use super::LapConfig;
use crate::car::Car;
use crate::error::{Error, Result};
use crate::sim::log::{LoggedLap, Sample};
use crate::track::Track;
use crate::vehicle::Vehicle;

/// Windows start only where the logged car moves at least this fast (m/s).
pub const MIN_SPEED: f64 = 5.0;

/// How long each window drives and how often one starts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReplayConfig {
    /// Length of a window (s).
    pub window_s: f64,
    /// Time between windows' starts (s).
    pub every_s: f64,
}

impl Default for ReplayConfig {
    fn default() -> Self {
        ReplayConfig {
            window_s: 1.0,
            every_s: 0.5,
        }
    }
}

/// One window of the replay.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Window {
    /// Where it starts along the centre line (m).
    pub start_m: f64,
    /// When it starts (s, the log's clock).
    pub start_s: f64,
    /// The logged speed there (m/s).
    pub speed_mps: f64,
    /// Root-mean-square yaw-rate error over its samples (rad/s).
    pub yaw_rate_rms: f64,
    /// Lateral offset at its end, cdbo's minus the log's (m).
    pub lateral_error_m: f64,
    /// Speed at its end, cdbo's minus the log's (m/s).
    pub speed_error_mps: f64,
    /// What the logged car did over it.
    pub regime: Regime,
}

/// The body's slip angle past which a logged car is sliding (rad, about 4.6°).
pub const SLIDE_ANGLE: f64 = 0.08;

/// What a logged car did over a window, in the order of precedence: its centre past the
/// road's edge at some sample; else its body's slip angle past [`SLIDE_ANGLE`] at some sample
/// (where the log has it); else braking, the mean pedal below 0; else driving.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Regime {
    /// On the road, the mean pedal at 0 or above, not sliding.
    Driving,
    /// On the road, the mean pedal below 0, not sliding.
    Braking,
    /// On the road, sliding.
    Sliding,
    /// Past the road's edge.
    PastTheEdge,
}

impl Regime {
    /// Every regime, in order.
    pub const ALL: [Regime; 4] = [
        Regime::Driving,
        Regime::Braking,
        Regime::Sliding,
        Regime::PastTheEdge,
    ];

    /// The regime of a window's logged samples on `track`.
    pub fn of(track: &Track, samples: &[Sample]) -> Regime {
        let past_edge =
            |q: &Sample| q.lateral.abs() > track.frame(track.index_at(q.distance_m)).half_width;
        if samples.iter().any(past_edge) {
            Regime::PastTheEdge
        } else if samples
            .iter()
            .any(|q| q.slip_angle.is_some_and(|b| b.abs() > SLIDE_ANGLE))
        {
            Regime::Sliding
        } else if samples.iter().map(|q| q.pedal).sum::<f64>() < 0.0 {
            Regime::Braking
        } else {
            Regime::Driving
        }
    }

    /// Its name in a report.
    pub fn name(self) -> &'static str {
        match self {
            Regime::Driving => "driving",
            Regime::Braking => "braking",
            Regime::Sliding => "sliding",
            Regime::PastTheEdge => "past the edge",
        }
    }
}

/// The windows' errors summed up.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Summary {
    /// How many windows.
    pub count: usize,
    /// √(mean of the windows' squared yaw-rate errors) (rad/s).
    pub yaw_rate_rms: f64,
    /// Mean |lateral error| at the windows' ends (m).
    pub mean_abs_lateral_m: f64,
    /// Mean speed error at the windows' ends (m/s): positive where cdbo's car is faster.
    pub mean_speed_error_mps: f64,
}

impl Summary {
    /// The summary of `windows`; `None` for none.
    pub fn of<'a>(windows: impl IntoIterator<Item = &'a Window>) -> Option<Summary> {
        let (mut n, mut yaw, mut lateral, mut speed) = (0usize, 0.0, 0.0, 0.0);
        for w in windows {
            n += 1;
            yaw += w.yaw_rate_rms.powi(2);
            lateral += w.lateral_error_m.abs();
            speed += w.speed_error_mps;
        }
        (n > 0).then(|| {
            let k = n as f64;
            Summary {
                count: n,
                yaw_rate_rms: (yaw / k).sqrt(),
                mean_abs_lateral_m: lateral / k,
                mean_speed_error_mps: speed / k,
            }
        })
    }
}

/// A window class's summary.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RegimeSummary {
    /// The class.
    pub regime: Regime,
    /// Its windows' errors.
    #[serde(flatten)]
    pub summary: Summary,
}

/// A lap's replay: every window and their means, over all and per [`Regime`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Replay {
    /// The windows, in the log's order.
    pub windows: Vec<Window>,
    /// All the windows' errors.
    #[serde(flatten)]
    pub all: Summary,
    /// Each regime's, for those with windows, in [`Regime::ALL`]'s order.
    pub by_regime: Vec<RegimeSummary>,
}

/// Replays `lap`, logged on `track` by `car`, window by window (module documentation).
/// `file` names the log in errors: a log without `t_s` or `steer_rad`, with time that does
/// not increase, or too short for one window.
pub fn replay(
    track: &Track,
    car: &Car,
    lap: &LoggedLap,
    config: &ReplayConfig,
    file: &str,
) -> Result<Replay> {
    let refuse = |message: String| Error::parse(file, format!("lap {}", lap.lap), message);
    for (what, value) in [
        ("the replay window (s)", config.window_s),
        ("the replay windows' spacing (s)", config.every_s),
    ] {
        if !(value > 0.0 && value.is_finite()) {
            return Err(Error::invalid_value(what, value, "positive"));
        }
    }
    let samples = &lap.samples;
    let mut times = Vec::with_capacity(samples.len());
    let mut steers = Vec::with_capacity(samples.len());
    for (k, p) in samples.iter().enumerate() {
        let (Some(t), Some(steer)) = (p.t, p.steer) else {
            return Err(refuse(
                "a replay needs the columns t_s and steer_rad (the commands applied, and when)"
                    .into(),
            ));
        };
        if k > 0 && t <= times[k - 1] {
            return Err(refuse(format!(
                "time runs back or stands at row {} ({t} s after {} s)",
                lap.line + k,
                times[k - 1]
            )));
        }
        times.push(t);
        steers.push(steer);
    }
    let vehicle = Vehicle::new(car);
    let dt = LapConfig::default().dt;
    let mut windows = Vec::new();
    let mut next_start = f64::NEG_INFINITY;
    for i in 1..samples.len().saturating_sub(1) {
        let p = &samples[i];
        if times[i] < next_start || p.speed < MIN_SPEED || p.distance_m < 0.0 {
            continue;
        }
        // The window's last sample; skip where the log ends before the window does.
        let Some(end) = (i..samples.len()).find(|&k| times[k] >= times[i] + config.window_s) else {
            break;
        };
        next_start = times[i] + config.every_s;
        let velocity = body_velocity(p);
        let dvx_dt = (body_velocity(&samples[i + 1]).0 - body_velocity(&samples[i - 1]).0)
            / (times[i + 1] - times[i - 1]);
        let frame = track.frame(track.index_at(p.distance_m));
        let mut state = vehicle.under_way(
            pose(track, &samples[i - 1], p, &samples[i + 1]),
            velocity,
            vehicle.tyres_accel(velocity, dvx_dt, frame),
            gear_index(p).unwrap_or(0),
        );
        if let Some(speeds) = p.wheel_speeds {
            vehicle.set_wheel_speeds(&mut state, speeds);
        }
        // A shift the log shows under way: the last change of gear at a sample j ≤ i less than
        // the shift's time before, which leaves shift_time − (tᵢ − t_j) of it.
        let changed = |j: usize| {
            gear_index(&samples[j]).is_some_and(|g| Some(g) != gear_index(&samples[j - 1]))
        };
        if let Some(j) = (1..=i)
            .rev()
            .take_while(|&j| times[i] - times[j] < car.shift_time)
            .find(|&j| changed(j))
        {
            state.gearbox.shifting = car.shift_time - (times[i] - times[j]);
        }
        let mut proj = track.project(state.x, state.y, track.index_at(p.distance_m));
        let mut squared = 0.0;
        for k in i..end {
            let q = &samples[k];
            let brake = vehicle.driver_brake(&state, (-q.pedal).max(0.0));
            let controls = vehicle.controls(steers[k], q.pedal.max(0.0), brake);
            match gear_index(q) {
                // A logged change of gear starts a shift, as cdbo's gearbox does.
                Some(g) => {
                    if k > i && state.gearbox.gear != g {
                        state.gearbox.shifting = car.shift_time;
                    }
                    state.gearbox.gear = g;
                    state.yaw_sin_cos = state.yaw.sin_cos();
                }
                None => vehicle.shift(&mut state, controls.throttle()),
            }
            let span = times[k + 1] - times[k];
            let steps = (span / dt).round().max(1.0);
            for _ in 0..steps as usize {
                vehicle.step(&mut state, &controls, track.frame(proj.index), span / steps);
                proj = track.project(state.x, state.y, proj.index);
            }
            squared += (state.yaw_rate - samples[k + 1].yaw_rate).powi(2);
        }
        let last = &samples[end];
        windows.push(Window {
            start_m: p.distance_m,
            start_s: times[i],
            speed_mps: p.speed,
            yaw_rate_rms: (squared / (end - i) as f64).sqrt(),
            lateral_error_m: proj.lateral - last.lateral,
            speed_error_mps: state.speed() - last.speed,
            regime: Regime::of(track, &samples[i..=end]),
        });
    }
    let Some(all) = Summary::of(&windows) else {
        return Err(refuse(format!(
            "no window of {} s where the car moves at {MIN_SPEED} m/s or more",
            config.window_s
        )));
    };
    let by_regime = Regime::ALL
        .into_iter()
        .filter_map(|regime| {
            Summary::of(windows.iter().filter(|w| w.regime == regime))
                .map(|summary| RegimeSummary { regime, summary })
        })
        .collect();
    Ok(Replay {
        windows,
        all,
        by_regime,
    })
}

/// A sample's body velocities and yaw rate (vₓ, v_y, r): vₓ = v·cos β, v_y = v·sin β, β its
/// slip angle (0 where the log has none).
fn body_velocity(p: &Sample) -> (f64, f64, f64) {
    let beta = p.slip_angle.unwrap_or(0.0);
    (p.speed * beta.cos(), p.speed * beta.sin(), p.yaw_rate)
}

/// The 0-based gear a sample names (none for neutral or an unlogged gear).
fn gear_index(p: &Sample) -> Option<usize> {
    p.gear.filter(|&g| g > 0).map(|g| usize::from(g) - 1)
}

/// Position and yaw at sample `p` from its offset off the centre line and the offset's slope
/// between its neighbours `before` and `after` (module documentation).
fn pose(track: &Track, before: &Sample, p: &Sample, after: &Sample) -> (f64, f64, f64) {
    let (x, y) = track.point_off(p.distance_m, p.lateral);
    let (sin, cos) = track.heading_sin_cos(p.distance_m);
    let curvature = track.frame(track.index_at(p.distance_m)).curvature;
    let slope = (after.lateral - before.lateral) / (after.distance_m - before.distance_m);
    let travel = (slope / (1.0 - curvature * p.lateral)).atan();
    let yaw = sin.atan2(cos) + travel - p.slip_angle.unwrap_or(0.0);
    (x, y, yaw)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::Simulator;

    /// cdbo's own lap of Ridgeway at a 20 m/s speed hold, as a log.
    fn own_lap(car: &Car) -> (Track, LoggedLap) {
        let track = crate::track::builtin::load("ridgeway").unwrap().unwrap();
        let (lap, _) = Simulator::new(track.clone(), car).demonstrate(20.0);
        assert!(lap.completed);
        let samples = lap.trace.iter().map(Sample::of).collect();
        (
            track,
            LoggedLap {
                lap: 0,
                line: 2,
                samples,
            },
        )
    }

    #[test]
    fn cdbos_own_lap_replays_to_itself_and_another_car_parts_from_it() {
        let car = Car::spirit_300();
        let (track, lap) = own_lap(&car);
        let config = ReplayConfig::default();
        let own = replay(&track, &car, &lap, &config, "own.csv").unwrap();
        // A window every 0.5 s over the lap, each picked up from the log alone.
        let lap_time = lap.samples.last().unwrap().t.unwrap();
        assert!(
            own.windows.len() as f64 > 1.6 * lap_time,
            "{}",
            own.windows.len()
        );
        assert!(own.all.yaw_rate_rms < 0.003, "{}", own.all.yaw_rate_rms);
        assert!(
            own.all.mean_abs_lateral_m < 0.01,
            "{}",
            own.all.mean_abs_lateral_m
        );
        assert!(
            own.all.mean_speed_error_mps.abs() < 0.01,
            "{}",
            own.all.mean_speed_error_mps
        );

        // The same commands through a car with half as much drag again, 20 % less grip and a
        // yaw inertia half as large again: slower, wider, turning later.
        let mut other = car.clone();
        other.cx *= 1.5;
        other.yaw_inertia_factor *= 1.5;
        other.front_tyre.mu *= 0.8;
        other.rear_tyre.mu *= 0.8;
        let apart = replay(&track, &other, &lap, &config, "own.csv").unwrap();
        assert!(
            apart.all.mean_speed_error_mps < -0.03,
            "{}",
            apart.all.mean_speed_error_mps
        );
        assert!(
            apart.all.yaw_rate_rms > 3.0 * own.all.yaw_rate_rms,
            "{}",
            apart.all.yaw_rate_rms
        );
        assert!(apart.all.mean_abs_lateral_m > 4.0 * own.all.mean_abs_lateral_m);
    }

    /// A window is classed by what the logged car did: past the road's edge before sliding,
    /// sliding before braking; the classes' windows add up to all of them.
    #[test]
    fn a_window_is_classed_by_what_the_logged_car_did() {
        let car = Car::spirit_300();
        let (track, lap) = own_lap(&car);
        let window = &lap.samples[100..150];
        let with = |change: &dyn Fn(&mut Sample)| {
            let mut w = window.to_vec();
            change(&mut w[20]);
            Regime::of(&track, &w)
        };
        let braking = |w: &[Sample]| w.iter().map(|q| q.pedal).sum::<f64>() < 0.0;
        let plain = if braking(window) {
            Regime::Braking
        } else {
            Regime::Driving
        };
        assert_eq!(Regime::of(&track, window), plain);
        let edge = track
            .frame(track.index_at(window[20].distance_m))
            .half_width;
        assert_eq!(with(&|q| q.slip_angle = Some(-0.09)), Regime::Sliding);
        assert_eq!(with(&|q| q.slip_angle = Some(0.07)), plain);
        assert_eq!(with(&|q| q.lateral = -(edge + 0.01)), Regime::PastTheEdge);
        assert_eq!(with(&|q| q.lateral = edge - 0.01), plain);
        let mut off_and_sliding = window.to_vec();
        off_and_sliding[3].slip_angle = Some(0.2);
        off_and_sliding[40].lateral = edge + 1.0;
        assert_eq!(Regime::of(&track, &off_and_sliding), Regime::PastTheEdge);
        let mut hard = window.to_vec();
        hard.iter_mut().for_each(|q| q.pedal = -0.5);
        assert_eq!(Regime::of(&track, &hard), Regime::Braking);

        let own = replay(&track, &car, &lap, &ReplayConfig::default(), "own.csv").unwrap();
        let counted: usize = own.by_regime.iter().map(|r| r.summary.count).sum();
        assert_eq!(counted, own.windows.len());
        // Driving and braking, and the replay gives both back: braking too, where windows
        // start with a shift under way (0.11 m/s short at a window's end when the pick-up
        // took none, and the tyres' force as the speed's slope).
        assert_eq!(
            own.by_regime.iter().map(|r| r.regime).collect::<Vec<_>>(),
            [Regime::Driving, Regime::Braking]
        );
        for r in &own.by_regime {
            assert!(r.summary.mean_speed_error_mps.abs() < 0.01, "{r:?}");
        }
    }

    #[test]
    fn a_log_without_the_commands_or_its_clock_is_refused_in_one_line() {
        let car = Car::spirit_300();
        let (track, mut lap) = own_lap(&car);
        let config = ReplayConfig::default();
        let mut no_steer = lap.clone();
        no_steer.samples[3].steer = None;
        assert_eq!(
            replay(&track, &car, &no_steer, &config, "l.csv")
                .unwrap_err()
                .to_string(),
            "l.csv: lap 0: a replay needs the columns t_s and steer_rad (the commands applied, and when)"
        );
        lap.samples[5].t = lap.samples[4].t;
        assert!(
            replay(&track, &car, &lap, &config, "l.csv")
                .unwrap_err()
                .to_string()
                .starts_with("l.csv: lap 0: time runs back or stands at row 7")
        );
        let zero = ReplayConfig {
            window_s: 0.0,
            ..config
        };
        assert!(replay(&track, &car, &lap, &zero, "l.csv").is_err());
    }
}
