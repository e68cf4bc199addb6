//! Calibration: fit a car's uncertain parameters ([`Scales`]) so that cdbo's simulator drives
//! the laps the game (or a real car) drove.
//!
//! 1. **Probes** ([`probes`]): a small set of laps, each chosen so that some scale shows in
//!    it. The PI speed hold at 10, 15 and 20 m/s: the pedal it needs to hold a speed is the
//!    resistance at that speed (rolling at 10, drag at 20), and each pulls away from standing
//!    (launch); each kept where its lap completes with the stock car and with [`FAST_MARGIN`]'s
//!    (E-Track 2's 20 m/s hold slides wide in its hairpin, at the limit there, and a scale a
//!    percent off moved its cost by a whole lap's). A launch-and-brake table: full throttle from the start line to the first
//!    braking point of the QSS limit or [`LAUNCH_M`], full brake for [`BRAKE_M`], then
//!    coasting, compared over [`COAST_M`] of it: the pull-away (launch), the speed at the end of
//!    the straight (drag), an ABS stop at the tyre's longitudinal limit (grip and its peak
//!    slip, where ABS works), and the coast-down (rolling resistance and drag); the pedal
//!    ramps over [`RAMP_M`] between its levels, so that where a driver step falls on a ramp
//!    moves the lap a little, not by a whole step of the pedal. A fast lap, closed loop: the
//!    profile hold ([`ProfileHold`](crate::drive::profile::ProfileHold)) following k times the
//!    stock car's crest-aware limit profile v(s) ([`crate::ceiling::profile`]),
//!    a = clamp(K_p·(max(k·min_{s ≤ s′ ≤ s + v·τ} v(s′), v_min) − v), −1, 1) with the
//!    ceiling's K_p = 1 per m/s, τ = 0.3 s and v_min = 10 m/s, v(s) linear between the
//!    profile's 1 m stations; k the first of [`FAST_PROFILE`] (0.8, 0.75, …) whose lap
//!    completes with the stock car and with [`FAST_MARGIN`]'s less grippy one. The corners
//!    near the grip limit: the steering's lateral offset and the yaw rate show the tyre's grip,
//!    its shape and the downforce at speed, and the pedal the car needs to hold the profile
//!    its drag. The same law drives every car, the game's robot too (`pedal profile`,
//!    `torcs-robot/drive.hpp`), so that a car with more drag or less grip still completes the
//!    lap, slower: an open-loop replay of the stock car's pedal stalls or leaves the road
//!    instead, a cliff in the cost.
//! 2. **Residuals** ([`compare`]): at stations every [`STATION_M`] m along the lap, up to the
//!    probe's window, the differences in speed, lateral offset, yaw rate and (for the closed-
//!    loop probes, the speed holds and the profile hold; a table's pedal is the same in both)
//!    pedal between the observed lap and cdbo's lap of the same probe, each the mean over the
//!    [`STATION_M`] before the station (the samples linear in distance in between: a pedal
//!    that moves within a driver step, read at a station, would change with where the steps
//!    fall) and divided by its scale ([`SIGMA`]); a station that only one of the two laps
//!    reached (the other failed or stopped earlier; a completed lap reached every station to
//!    the finish) counts as the speed there of the lap that reached it, in σ, at most
//!    [`MISSING`]: bounded, so that a lap that leaves the road does not swamp the rest, growing
//!    with the distance the two laps disagree over, and small where the other lap was about to
//!    stop too. A lap's cost is the mean square over its stations; the total is the mean over
//!    laps.
//! 3. **Fit** ([`fit`]): first a coarse scan, one free scale at a time over [`SCAN_POINTS`]
//!    log-spaced values of its bounds (a scale can be masked near 1: a launch torque scale
//!    changes nothing while traction control caps the drive), then least squares on the
//!    logarithms of the free scales ([`least_squares`]: Levenberg–Marquardt on the stacked
//!    residual vector, whose |r|² is the total cost, its Jacobian by forward differences of
//!    [`FitConfig::difference_step`], halved down to an eighth where the search stalls: the
//!    lap's driver steps make the cost piecewise flat at small scales), bounded by
//!    [`Scales::BOUNDS`], from the scan's best; the best point evaluated is kept.
//!    Deterministic: every lap is deterministic and the residuals are stacked in a fixed
//!    order.

pub mod least_squares;

use serde::Serialize;

use crate::car::{Car, Scales};
use crate::drive::demo::SpeedHold;
use crate::error::{Error, Result};
use crate::policy::PolicyTable;
use crate::sim::Simulator;
use crate::sim::lap::LapResult;
pub use crate::sim::log::{LoggedLap, Sample};
use crate::track::Track;

/// Distance between the stations the residuals are taken at (m).
pub const STATION_M: f64 = 10.0;

/// The scale each residual is divided by: speed 1 m/s, lateral offset 0.5 m, yaw rate
/// 0.05 rad/s, pedal 0.1 — about what separates a good match from a poor one in each.
pub const SIGMA: Sigma = Sigma {
    speed: 1.0,
    lateral: 0.5,
    yaw_rate: 0.05,
    pedal: 0.1,
};

/// Values of each scale the coarse scan tries, log-spaced over its bounds.
pub const SCAN_POINTS: usize = 7;

/// Residual scales.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sigma {
    /// Speed (m/s).
    pub speed: f64,
    /// Lateral offset (m).
    pub lateral: f64,
    /// Yaw rate (rad/s).
    pub yaw_rate: f64,
    /// Pedal command.
    pub pedal: f64,
}

/// The speeds of the speed-hold probes (m/s), each kept where its lap completes in cdbo's
/// simulator with the stock car and with [`FAST_MARGIN`]'s.
pub const DEMO_SPEEDS: [f64; 3] = [10.0, 15.0, 20.0];

/// The speed-profile fraction of the fast probe, and the lower ones tried while its lap fails
/// in cdbo's simulator with the stock car or with [`FAST_MARGIN`]'s.
pub const FAST_PROFILE: [f64; 5] = [0.8, 0.75, 0.7, 0.65, 0.6];

/// The scales of the car the fast probe must complete with besides the stock one: a car this
/// much less grippy (than the base) still finishes the lap, so that the fit meets no cliff
/// near the truth.
pub const FAST_MARGIN: Scales = Scales {
    grip: 0.85,
    downforce: 0.7,
    ..Scales::ONE
};

/// The launch-and-brake probe's full throttle ends at the limit's first braking point or
/// after this distance (m), whichever comes first: early enough that the car stays on the
/// road in both simulators.
pub const LAUNCH_M: f64 = 400.0;
/// ... and its full brake lasts this distance (m): under a second at the grip limit (car1-trb1
/// stops from 60 m/s within 100 m), short of a stop (at a crawl ABS releases the brakes, and
/// cdbo's car creeps on where the game's stands).
pub const BRAKE_M: f64 = 50.0;
/// ... and it is compared up to this distance (m) past the end of the brake: the coast-down.
pub const COAST_M: f64 = 300.0;
/// The largest residual (in σ of speed) of a station only one of the two laps reached.
pub const MISSING: f64 = 3.0;
/// The launch-and-brake table's pedal ramps between full throttle, full brake and coasting
/// over this distance (m).
pub const RAMP_M: f64 = 10.0;

/// What a probe's pedal follows.
#[derive(Debug, Clone, PartialEq)]
pub enum ProbePedal {
    /// The PI speed hold at this speed (m/s): closed loop, the game's robot drives the same law.
    Demo(f64),
    /// The profile hold ([`ProfileHold`](crate::drive::profile::ProfileHold)) following k
    /// times a speed profile: closed loop, the game's robot drives the same law.
    Profile {
        /// The scale k.
        k: f64,
        /// The speed profile (m/s) at the track's samples, plus the finish: the stock car's
        /// limit, the same for every car driven.
        speed: Vec<f64>,
    },
    /// A pedal over the lap fraction, open loop.
    Table(PolicyTable),
}

/// A lap driven for calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct Probe {
    /// Its name in reports (`demo 15`, `launch-brake`, `fast 0.8`, `lap 3`).
    pub name: String,
    /// Its pedal.
    pub pedal: ProbePedal,
    /// The lap fraction up to which it is compared (1: the whole lap).
    pub window: f64,
}

impl Probe {
    /// Its lap in cdbo's simulator, traced.
    pub fn drive(&self, sim: &Simulator) -> LapResult {
        match &self.pedal {
            ProbePedal::Demo(v) => sim.lap(&mut SpeedHold::new(*v)),
            ProbePedal::Profile { k, speed } => sim.lap(&mut crate::drive::profile::ProfileHold {
                profile: speed,
                length: sim.track.length,
                k: *k,
            }),
            ProbePedal::Table(t) => sim.lap(&mut t.clone()),
        }
    }

    /// Its pedal for the game's robot on a track of `length` metres as cdbo reads it.
    pub fn game_pedal(&self, length: f64) -> crate::torcs::GamePedal {
        match &self.pedal {
            ProbePedal::Demo(v) => crate::torcs::GamePedal::Demo(*v),
            ProbePedal::Profile { k, speed } => crate::torcs::GamePedal::Profile {
                k: *k,
                length,
                speed: speed.clone(),
            },
            ProbePedal::Table(t) => crate::torcs::GamePedal::Table(t.points().to_vec()),
        }
    }
}

/// The probes for `car` on `track` (module documentation): demos at 10, 15 and 20 m/s, the
/// launch-and-brake table and the fast table.
pub fn probes(track: &Track, car: &Car) -> Result<Vec<Probe>> {
    let sim = Simulator::new(track.clone(), car);
    let derated = Simulator::new(track.clone(), &FAST_MARGIN.apply(car));
    let completes = |p: &Probe| p.drive(&sim).completed && p.drive(&derated).completed;
    let mut out: Vec<Probe> = DEMO_SPEEDS
        .map(|v| Probe {
            name: format!("demo {v}"),
            pedal: ProbePedal::Demo(v),
            window: 1.0,
        })
        .into_iter()
        .filter(completes)
        .collect();
    let limit = crate::limit::limit_lap(track, car);
    let brake = first_braking_point(&limit.speed);
    let n = (limit.speed.len() - 1) as f64;
    let xb = (brake as f64 / n).min(LAUNCH_M / track.length);
    let ramp = RAMP_M / track.length;
    let xe = (xb + BRAKE_M / track.length).min(1.0 - 1e-3 - ramp);
    let table = PolicyTable::new(vec![
        (0.0, 1.0),
        (xb, 1.0),
        (xb + ramp, -1.0),
        (xe, -1.0),
        (xe + ramp, 0.0),
    ])?;
    out.push(Probe {
        name: "launch-brake".into(),
        pedal: ProbePedal::Table(table),
        window: (xe + COAST_M / track.length).min(1.0),
    });
    let profile = crate::ceiling::profile(track, car, None);
    for k in FAST_PROFILE {
        let probe = Probe {
            name: format!("fast {k}"),
            pedal: ProbePedal::Profile {
                k,
                speed: profile.speed.clone(),
            },
            window: 1.0,
        };
        if completes(&probe) {
            out.push(probe);
            break;
        }
    }
    Ok(out)
}

/// The sample where a limit speed profile first falls: its first braking point.
fn first_braking_point(speed: &[f64]) -> usize {
    (1..speed.len())
        .find(|&i| speed[i] < speed[i - 1])
        .unwrap_or(speed.len().max(1) - 1)
        .saturating_sub(1)
}

/// One observed lap of a probe.
#[derive(Debug, Clone, PartialEq)]
pub struct Observed {
    /// The probe driven.
    pub probe: Probe,
    /// What was logged along it.
    pub samples: Vec<Sample>,
    /// Whether it completed.
    pub completed: bool,
    /// Its lap time (s), when it completed and its time is known.
    pub lap_time_s: Option<f64>,
}

impl Observed {
    /// A lap of cdbo's simulator or the game, from its trace.
    pub fn of_lap(probe: Probe, lap: &LapResult) -> Observed {
        Observed {
            probe,
            samples: lap.trace.iter().map(Sample::of).collect(),
            completed: lap.completed,
            lap_time_s: lap.lap_time_s,
        }
    }

    /// A logged lap (`--log`): its pedal replayed as an open-loop table over the lap.
    pub fn of_log(lap: &LoggedLap, length: f64, file: &str) -> Result<Observed> {
        let table = PolicyTable::new(lap.pedal_table(length))
            .map_err(|e| Error::parse(file, format!("lap {}", lap.lap), e.to_string()))?;
        Ok(Observed {
            probe: Probe {
                name: format!("lap {}", lap.lap),
                pedal: ProbePedal::Table(table),
                window: 1.0,
            },
            samples: lap.samples.clone(),
            completed: lap.completed(length),
            lap_time_s: lap.lap_time_s(length),
        })
    }

    /// The lap as a [`LoggedLap`] numbered `lap` (to write with [`log::write`](crate::sim::log::write)).
    pub fn logged(&self, lap: i64) -> LoggedLap {
        LoggedLap {
            lap,
            line: 0,
            samples: self.samples.clone(),
        }
    }
}

/// A track and the laps observed on it.
#[derive(Debug, Clone)]
pub struct TrackLaps {
    /// The track (as cdbo reads it).
    pub track: Track,
    /// The laps.
    pub laps: Vec<Observed>,
}

/// How one of cdbo's laps compares with an observed one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LapComparison {
    /// Mean square of the scaled residuals over the stations.
    pub cost: f64,
    /// Stations both laps reached.
    pub stations: usize,
    /// Stations only one of them reached.
    pub one_sided: usize,
    /// Sum of squared speed differences (m²/s²).
    pub speed_sq: f64,
    /// Whether the observed lap completed.
    pub observed_completed: bool,
    /// Whether cdbo's lap completed.
    pub sim_completed: bool,
    /// (cdbo − observed) / observed lap time, when both completed and the observed time is known.
    pub lap_time_error: Option<f64>,
}

/// A cursor reading samples at increasing stations, linear in distance in between.
struct Reader<'a> {
    samples: &'a [Sample],
    i: usize,
    end: f64,
}

impl<'a> Reader<'a> {
    fn new(samples: &'a [Sample]) -> Reader<'a> {
        let end = samples.iter().map(|s| s.distance_m).fold(0.0, f64::max);
        Reader { samples, i: 0, end }
    }

    /// The mean of (speed, lateral, yaw rate, pedal) over [s − STATION_M, s], the samples
    /// linear in distance in between, if the lap reached s.
    fn mean(&mut self, s: f64) -> Option<[f64; 4]> {
        let p = self.samples;
        if p.is_empty() || s > self.end {
            return None;
        }
        let lo = (s - STATION_M).max(p[0].distance_m);
        if s <= lo || p.len() < 2 {
            return self.at(s);
        }
        let v = |q: &Sample| [q.speed, q.lateral, q.yaw_rate, q.pedal];
        while self.i + 1 < p.len() && p[self.i + 1].distance_m < lo {
            self.i += 1;
        }
        let mut sum = [0.0; 4];
        let mut covered = 0.0;
        let mut j = self.i;
        while j + 1 < p.len() && p[j].distance_m < s {
            let (a, b) = (&p[j], &p[j + 1]);
            let (d0, d1) = (a.distance_m.max(lo), b.distance_m.min(s));
            let span = b.distance_m - a.distance_m;
            if d1 > d0 && span > 0.0 {
                let (va, vb) = (v(a), v(b));
                let f = |d: f64, k: usize| va[k] + (vb[k] - va[k]) * (d - a.distance_m) / span;
                for (k, total) in sum.iter_mut().enumerate() {
                    *total += 0.5 * (f(d0, k) + f(d1, k)) * (d1 - d0);
                }
                covered += d1 - d0;
            }
            j += 1;
        }
        if covered <= 0.0 {
            return self.at(s);
        }
        Some(sum.map(|x| x / covered))
    }

    /// (speed, lateral, yaw rate, pedal) at station `s`, if the lap reached it.
    fn at(&mut self, s: f64) -> Option<[f64; 4]> {
        let p = self.samples;
        if p.is_empty() || s > self.end {
            return None;
        }
        while self.i + 1 < p.len() && p[self.i + 1].distance_m < s {
            self.i += 1;
        }
        let a = &p[self.i];
        let b = &p[(self.i + 1).min(p.len() - 1)];
        let span = b.distance_m - a.distance_m;
        let t = if span > 0.0 {
            ((s - a.distance_m) / span).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let mix = |u: f64, v: f64| u + (v - u) * t;
        Some([
            mix(a.speed, b.speed),
            mix(a.lateral, b.lateral),
            mix(a.yaw_rate, b.yaw_rate),
            mix(a.pedal, b.pedal),
        ])
    }
}

/// Compares cdbo's lap `sim` of a probe with the observed lap `obs` on a track of `length`
/// metres (module documentation, step 2).
pub fn compare(obs: &Observed, sim: &LapResult, length: f64) -> LapComparison {
    residuals(obs, sim, length).0
}

/// [`compare`], and the lap's residual vector r: four entries per station up to the window
/// (speed, lateral offset, yaw rate, pedal, each scaled), the station's bounded speed and three
/// zeros where only one lap reached it, zeros where neither did, all divided by the square
/// root of the stations counted, so that |r|² is the lap's cost. Its length depends on the
/// observed lap alone.
fn residuals(obs: &Observed, sim: &LapResult, length: f64) -> (LapComparison, Vec<f64>) {
    let ours: Vec<Sample> = sim.trace.iter().map(Sample::of).collect();
    let (mut a, mut b) = (Reader::new(&obs.samples), Reader::new(&ours));
    let window = obs.probe.window * length;
    // A completed lap reached every station up to the finish, its last sample or not.
    if obs.completed {
        a.end = a.end.max(window);
    }
    if sim.completed {
        b.end = b.end.max(window);
    }
    let sg = SIGMA;
    // An open-loop table's pedal is the same in both laps: only where the steps fall between
    // two driver steps differs, which says nothing about the car.
    let pedal_weight = match obs.probe.pedal {
        ProbePedal::Demo(_) => 1.0 / sg.pedal,
        ProbePedal::Profile { .. } => 1.0 / sg.pedal,
        ProbePedal::Table(_) => 0.0,
    };
    let (mut sum, mut speed_sq, mut stations, mut one_sided) = (0.0, 0.0, 0usize, 0usize);
    let mut vector = Vec::new();
    let mut s = 0.0;
    while s <= window {
        let r = match (a.mean(s), b.mean(s)) {
            (Some(o), Some(c)) => {
                stations += 1;
                let r = [
                    (c[0] - o[0]) / sg.speed,
                    (c[1] - o[1]) / sg.lateral,
                    (c[2] - o[2]) / sg.yaw_rate,
                    (c[3] - o[3]) * pedal_weight,
                ];
                speed_sq += (r[0] * sg.speed).powi(2);
                r
            }
            (Some(o), None) | (None, Some(o)) => {
                one_sided += 1;
                [(o[0].abs() / sg.speed).min(MISSING), 0.0, 0.0, 0.0]
            }
            (None, None) => [0.0; 4],
        };
        sum += r.iter().map(|v| v * v).sum::<f64>();
        vector.extend(r);
        s += STATION_M;
    }
    let counted = stations + one_sided;
    let norm = 1.0 / (counted.max(1) as f64).sqrt();
    vector.iter_mut().for_each(|v| *v *= norm);
    let lap_time_error = match (sim.lap_time_s, obs.lap_time_s) {
        (Some(c), Some(o)) if obs.completed && o > 0.0 => Some((c - o) / o),
        _ => None,
    };
    let comparison = LapComparison {
        cost: if counted > 0 {
            sum / counted as f64
        } else {
            0.0
        },
        stations,
        one_sided,
        speed_sq,
        observed_completed: obs.completed,
        sim_completed: sim.completed,
        lap_time_error,
    };
    (comparison, vector)
}

/// Every observed lap of every track against cdbo's lap of the same probe with `car`, in
/// order.
pub fn compare_all(car: &Car, tracks: &[TrackLaps]) -> Vec<Vec<LapComparison>> {
    drive_all(car, tracks, compare)
}

/// The residual vector of `car` against every observed lap: the laps' [`residuals`] in order,
/// each divided by the square root of the number of laps, so that |r|² is [`total_cost`].
fn residual_vector(car: &Car, tracks: &[TrackLaps]) -> Vec<f64> {
    let laps: Vec<Vec<f64>> = drive_all(car, tracks, |o, l, len| residuals(o, l, len).1)
        .into_iter()
        .flatten()
        .collect();
    let norm = 1.0 / (laps.len().max(1) as f64).sqrt();
    laps.into_iter().flatten().map(|v| v * norm).collect()
}

/// `each` of every observed lap against cdbo's lap of the same probe with `car`, in order
/// (laps run on threads of their own; the results do not depend on it).
fn drive_all<T: Send>(
    car: &Car,
    tracks: &[TrackLaps],
    each: fn(&Observed, &LapResult, f64) -> T,
) -> Vec<Vec<T>> {
    std::thread::scope(|scope| {
        let handles: Vec<Vec<_>> = tracks
            .iter()
            .map(|t| {
                t.laps
                    .iter()
                    .map(|obs| {
                        scope.spawn(move || {
                            let mut sim = Simulator::new(t.track.clone(), car);
                            sim.config.trace = true;
                            each(obs, &obs.probe.drive(&sim), t.track.length)
                        })
                    })
                    .collect()
            })
            .collect();
        handles
            .into_iter()
            .map(|laps| {
                laps.into_iter()
                    .map(|h| h.join().expect("a calibration lap panicked"))
                    .collect()
            })
            .collect()
    })
}

/// The total cost: the mean over all laps of their costs.
pub fn total_cost(comparisons: &[Vec<LapComparison>]) -> f64 {
    let costs: Vec<f64> = comparisons.iter().flatten().map(|c| c.cost).collect();
    if costs.is_empty() {
        0.0
    } else {
        costs.iter().sum::<f64>() / costs.len() as f64
    }
}

/// Agreement on one track.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Agreement {
    /// The track.
    pub track: String,
    /// RMS speed difference over the stations both laps reached, every lap (m/s).
    pub rms_speed_mps: f64,
    /// Mean |lap-time error| over the laps both completed, as a fraction.
    pub lap_time_error: Option<f64>,
    /// Laps whose completion agrees.
    pub completion_agree: usize,
    /// Laps compared.
    pub laps: usize,
    /// The mean cost of its laps.
    pub cost: f64,
    /// Each lap's comparison, in the order of the observed laps.
    pub per_lap: Vec<LapComparison>,
}

/// Agreement per track of `car` against the observed laps.
pub fn agreement(car: &Car, tracks: &[TrackLaps]) -> Vec<Agreement> {
    compare_all(car, tracks)
        .iter()
        .zip(tracks)
        .map(|(cs, t)| {
            let stations: usize = cs.iter().map(|c| c.stations).sum();
            let speed_sq: f64 = cs.iter().map(|c| c.speed_sq).sum();
            let errors: Vec<f64> = cs.iter().filter_map(|c| c.lap_time_error).collect();
            Agreement {
                track: t.track.name.clone(),
                rms_speed_mps: (speed_sq / stations.max(1) as f64).sqrt(),
                lap_time_error: (!errors.is_empty())
                    .then(|| errors.iter().map(|e| e.abs()).sum::<f64>() / errors.len() as f64),
                completion_agree: cs
                    .iter()
                    .filter(|c| c.observed_completed == c.sim_completed)
                    .count(),
                laps: cs.len(),
                cost: total_cost(std::slice::from_ref(cs)),
                per_lap: cs.clone(),
            }
        })
        .collect()
}

/// What to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitConfig {
    /// Indices ([`Scales::NAMES`]) of the scales to fit; the others stay at `start`'s.
    pub free: Vec<usize>,
    /// Where the fit starts.
    pub start: Scales,
    /// Cost evaluations at most (each drives every observed lap once), the scan's
    /// 1 + [`SCAN_POINTS`] per free scale included (least squares gets at least one).
    pub max_evaluations: usize,
    /// The forward-difference step of the least-squares Jacobian, in log-scale (0.02 ≈ 2 %):
    /// wide enough to see past the cost's steps at the scale of a driver step.
    pub difference_step: f64,
    /// Whether to scan each scale coarsely first ([`SCAN_POINTS`]).
    pub scan: bool,
}

/// The fit's default budget of cost evaluations. Six scales from the stock car cross a long
/// valley where drag trades with rolling resistance: measured on the six-scale recovery
/// (`tests/calibrate.rs`), least squares stops in 238 evaluations with every scale within
/// 2.5 % (COBYLA, the fit it replaced, stopped at 300 with drag 5 % short).
pub const DEFAULT_EVALUATIONS: usize = 300;

impl Default for FitConfig {
    fn default() -> Self {
        FitConfig {
            free: (0..Scales::NAMES.len()).collect(),
            start: Scales::ONE,
            max_evaluations: DEFAULT_EVALUATIONS,
            difference_step: 0.02,
            scan: true,
        }
    }
}

/// The fitted scales.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fit {
    /// The best scales found.
    pub scales: Scales,
    /// The cost at the start.
    pub cost_start: f64,
    /// The cost at the best scales.
    pub cost: f64,
    /// Cost evaluations made.
    pub evaluations: usize,
}

/// Fits the scales over `base` to the observed laps (module documentation, step 3).
pub fn fit(base: &Car, tracks: &[TrackLaps], cfg: &FitConfig) -> Result<Fit> {
    if cfg.free.is_empty() || cfg.free.iter().any(|&i| i >= Scales::NAMES.len()) {
        return Err(Error::invalid_value(
            "the scales to fit",
            format!("{:?}", cfg.free),
            format!("a non-empty subset of {}", Scales::NAMES.join(", ")),
        ));
    }
    if tracks.iter().all(|t| t.laps.is_empty()) {
        return Err(Error::invalid_value(
            "the observed laps",
            0,
            "at least one lap",
        ));
    }
    let scales_at = |x: &[f64], start: Scales| {
        let mut s = start;
        for (k, &i) in cfg.free.iter().enumerate() {
            let (lo, hi) = Scales::BOUNDS[i];
            s.set(i, x[k].exp().clamp(lo, hi));
        }
        s
    };
    // |r|², the total cost, by the same residuals least squares fits below.
    let cost = |s: &Scales| {
        residual_vector(&s.apply(base), tracks)
            .iter()
            .map(|v| v * v)
            .sum::<f64>()
    };
    let cost_start = cost(&cfg.start);
    // The coarse scan: one scale at a time over SCAN_POINTS log-spaced values of its bounds.
    let (mut start, mut start_cost, mut evaluations) = (cfg.start, cost_start, 1usize);
    for &i in cfg.free.iter().filter(|_| cfg.scan) {
        let (lo, hi) = Scales::BOUNDS[i];
        for k in 0..SCAN_POINTS {
            let t = k as f64 / (SCAN_POINTS - 1) as f64;
            let mut s = start;
            s.set(i, (lo.ln() + t * (hi.ln() - lo.ln())).exp());
            let c = cost(&s);
            evaluations += 1;
            if c < start_cost {
                (start, start_cost) = (s, c);
            }
        }
    }
    let bounds: Vec<(f64, f64)> = cfg
        .free
        .iter()
        .map(|&i| (Scales::BOUNDS[i].0.ln(), Scales::BOUNDS[i].1.ln()))
        .collect();
    let x0: Vec<f64> = cfg.free.iter().map(|&i| start.get(i).ln()).collect();
    let found = least_squares::minimize(
        |x| residual_vector(&scales_at(x, start).apply(base), tracks),
        &x0,
        &bounds,
        &least_squares::Settings {
            h: cfg.difference_step,
            h_min: cfg.difference_step / 8.0,
            max_evaluations: cfg.max_evaluations.saturating_sub(evaluations).max(1),
            // No scale moves by 0.01 %: the cost is piecewise flat at the scale of a driver
            // step, so a tolerance on it would stop early.
            x_tol: 1e-4,
        },
    );
    let (scales, c, evaluations) = if found.cost < start_cost {
        (
            scales_at(&found.x, start),
            found.cost,
            evaluations + found.evaluations,
        )
    } else {
        (start, start_cost, evaluations + found.evaluations)
    };
    Ok(Fit {
        scales,
        cost_start,
        cost: c,
        evaluations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_braking_point_is_where_the_speed_first_falls() {
        let v = [0.0, 10.0, 20.0, 30.0, 25.0, 18.0, 18.0, 25.0];
        assert_eq!(first_braking_point(&v), 3);
        assert_eq!(first_braking_point(&[0.0, 1.0]), 0);
    }
}
