//! The physical limit: the quasi-steady-state (QSS) minimum lap time along the centre line.
//!
//! At every station sᵢ of the centre line (curvature κᵢ, grade φᵢ, banking βᵢ, road friction
//! μ_rᵢ) the car is treated as a point mass m with the axles' grip
//! F_max(v) = Σ_axles F_z·μ·μ_r·λ(F_z/2), F_z = n(v)·static load + downforce 0.645·Cl·A·v²,
//! where n(v) = 1 for [`limit_lap`] (flat, crest-blind: the yardstick every "% of the limit"
//! uses) and, with [`LimitOptions::crests`] ([`limit_lap_with`]), the road's push per unit of
//! the car's weight as the simulator's vehicle feels it
//! ([`Vehicle::step`](crate::vehicle::Vehicle::step)):
//! n(v) = cos φ·cos β + v²·κ_v/g, κ_v the road's vertical curvature
//! ([`Frame::vertical_curvature`](crate::track::Frame::vertical_curvature), negative over a
//! crest), each axle's load kept ≥ 0 as the vehicle keeps it.
//!
//! 1. **Cornering cap**: the largest v with m·(v²|κ| − g·sin β·sgn κ) ≤ F_max(v) (bisection);
//!    with the crests also on the road: the total load m·g·n(v) + 0.645·Cl·A·v² > 0, so over
//!    a crest (κ_v < 0) whose unloading outgrows the downforce
//!    v² < m·g·cos φ·cos β / (−m·κ_v − 0.645·Cl·A), and on a straight crest without downforce
//!    v < √(g·cos φ·cos β/−κ_v), the speed at which the car takes off.
//! 2. **Forward pass** from a standing start, v₀ = 0:
//!    v²ᵢ₊₁ = min(cap²ᵢ₊₁, v²ᵢ + 2·Δs·a⁺), with the acceleration
//!    a⁺ = min(F_engine(v), F_traction)·e/m − F_drag/m − c_rr·g·n − g·sin φ, where F_engine is the
//!    best gear's wheel force T_e(ω)·gᵢg_f/R below the limiter, F_traction the driven axle's
//!    grip (with longitudinal load transfer), and e = √(1 − (a_lat/a_lat,max)²) the friction
//!    ellipse; F_traction and F_max under the loads F_z above (n(v) at the station's speed).
//! 3. **Backward pass** from the finish: v²ᵢ = min(v²ᵢ, v²ᵢ₊₁ + 2·Δs·a⁻), with the deceleration
//!    a⁻ = min(F_max·e, F_brakes)/m + F_drag/m + c_rr·g·n + g·sin φ.
//! 4. T = Σ 2Δs/(vᵢ + vᵢ₊₁).
//!
//! It ignores rotating inertia, gear-shift time and the driver's reaction, and grants both
//! axles their full grip at once, so no lap of the simulator can beat it.
//!
//! [`line_limit`] drives the same QSS lap along a racing line ([`crate::line`]), on the line's
//! own curvature and arc length; its speed is the *centre line's* length over its lap time, so
//! that it compares with [`limit_lap`]'s, the reference every "% of the limit" uses.
//!
//! The crest-aware limit is the profile [the ceiling](crate::ceiling) tracks (a profile the
//! car cannot hold over a crest says nothing about the drive stack); the crest-blind
//! [`limit_lap`] stays the yardstick, the same for every run and every commit.

use serde::Serialize;

use crate::car::G;
use crate::car::{Car, Drive};
use crate::line::RacingLine;
use crate::track::Track;
use crate::vehicle::tyre::TyreModel;

/// The limit lap.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Limit {
    /// Minimum lap time (s).
    pub lap_time_s: f64,
    /// L / T (m/s).
    pub reward_mps: f64,
    /// The lap is a flying one ([`LimitOptions::flying`]): its profile wraps, the speed at
    /// the finish the speed at the start of the next lap.
    #[serde(skip)]
    pub flying: bool,
    /// Limit speed at each track sample (m/s), plus the finish.
    #[serde(skip)]
    pub speed: Vec<f64>,
    /// The lap's length L (m), R = L/T.
    #[serde(skip)]
    pub track_length: f64,
}

/// The limit lap along a racing line.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LineLimit {
    /// The lap on the line: its time T (s); its `reward_mps` is L/T with L the *centre
    /// line's* length, comparable with the centre line's limit; its `speed` is along the
    /// line's own samples ([`RacingLine::path`]).
    #[serde(flatten)]
    pub limit: Limit,
    /// The line's length (m).
    pub line_length_m: f64,
    /// The largest lateral offset of the line from the centre line (m).
    pub max_offset_m: f64,
    /// Distance kept from the car's centre to the road's edge (m).
    pub margin_m: f64,
    /// Quadratic programmes solved for the line.
    pub iterations: usize,
}

/// What the QSS model knows of the road besides its plan, curvature, grade and banking.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LimitOptions {
    /// The road's crests and dips load the car: the static loads scale by
    /// n(v) = cos φ·cos β + v²·κ_v/g, as in the simulator, and the car must not take off
    /// (module documentation). Off: n = 1, [`limit_lap`]'s crest-blind yardstick.
    pub crests: bool,
    /// The lap is flying: entered at the speed it ends with, and ending at a speed from
    /// which the next lap's first corner can be made (module documentation, step 2 and 3).
    /// Off: a standing lap from v₀ = 0 to a finish line with nothing beyond it.
    pub flying: bool,
}

impl LimitOptions {
    /// The crest-blind model of [`limit_lap`].
    pub const FLAT: LimitOptions = LimitOptions {
        crests: false,
        flying: false,
    };
    /// The crest-aware model.
    pub const CRESTS: LimitOptions = LimitOptions {
        crests: true,
        flying: false,
    };

    /// These options for a flying lap.
    pub fn flying(self) -> LimitOptions {
        LimitOptions {
            flying: true,
            ..self
        }
    }
}

/// The QSS limit lap of `car` along `line`, a racing line on `track`: [`limit_lap`] on
/// [`RacingLine::path`], its reward the centre line's length over the lap time.
pub fn line_limit(track: &Track, line: &RacingLine, car: &Car) -> LineLimit {
    line_limit_with(track, line, car, LimitOptions::FLAT)
}

/// [`line_limit`] under `options` ([`limit_lap_with`] on the line's path, whose heights and
/// so whose crests are the road's under the line).
pub fn line_limit_with(
    track: &Track,
    line: &RacingLine,
    car: &Car,
    options: LimitOptions,
) -> LineLimit {
    let path = line.path(track);
    let mut limit = limit_lap_with(&path, car, options);
    limit.reward_mps = track.length / limit.lap_time_s;
    limit.track_length = track.length;
    LineLimit {
        limit,
        line_length_m: path.length,
        max_offset_m: line.max_offset(),
        margin_m: line.margin_m,
        iterations: line.iterations,
    }
}

/// The QSS limit lap of `car` along `line` (as [`line_limit`]) with its speed profile read at
/// `track`'s own samples, for a speed tracker that knows the lap fraction x = s/L of the
/// centre line ([`crate::ceiling::ProfileTracker`]) while the car holds the line: at station s
/// the speed of the line's sample nearest u(s) = u_j + (s/h − j)·(u_{j+1} − u_j), the chord
/// length from p₀ at which the line crosses s (u_j = Σ_{i<j} |p_{i+1} − p_i|, h = L/N the
/// stations' spacing, j = ⌊s/h⌋).
pub fn line_limit_on_centre(track: &Track, line: &RacingLine, car: &Car) -> Limit {
    line_limit_on_centre_with(track, line, car, LimitOptions::FLAT)
}

/// [`line_limit_on_centre`] under `options`.
pub fn line_limit_on_centre_with(
    track: &Track,
    line: &RacingLine,
    car: &Car,
    options: LimitOptions,
) -> Limit {
    let along = line_limit_with(track, line, car, options).limit;
    let path = line.path(track);
    let n = line.points.len();
    let mut u = Vec::with_capacity(n + 1);
    u.push(0.0);
    for j in 0..n {
        let (p, q) = (line.points[j], line.points[(j + 1) % n]);
        u.push(u[j] + (q[0] - p[0]).hypot(q[1] - p[1]));
    }
    let h = track.length / n as f64;
    let last = along.speed.len() - 1;
    let speed = (0..=track.len())
        .map(|i| {
            let t = (i as f64 * track.ds).min(track.length) / h;
            let j = (t.floor() as usize).min(n - 1);
            let chord = u[j] + (t - j as f64) * (u[j + 1] - u[j]);
            along.speed[((chord / path.ds).round() as usize).min(last)]
        })
        .collect();
    Limit { speed, ..along }
}

/// Computes the QSS limit lap of `car` on `track`, crest-blind: the yardstick.
pub fn limit_lap(track: &Track, car: &Car) -> Limit {
    limit_lap_with(track, car, LimitOptions::FLAT)
}

/// Computes the QSS limit lap of `car` on `track` under `options`; with
/// [`LimitOptions::FLAT`] bit for bit [`limit_lap`], and on a road without grade, banking
/// or vertical curvature so is [`LimitOptions::CRESTS`] (n = 1 exactly).
pub fn limit_lap_with(track: &Track, car: &Car, options: LimitOptions) -> Limit {
    let n = track.len();
    let ds = track.ds;
    let m = car.mass;
    let tyres = [
        TyreModel::new(&car.front_tyre),
        TyreModel::new(&car.rear_tyre),
    ];
    let l = car.wheelbase;
    let static_load = car.static_axle_loads();
    let rolling = 0.5 * (car.front_tyre.rolling_resistance + car.rear_tyre.rolling_resistance);
    let grip = |axle: usize, fz: f64, friction: f64| tyres[axle].axle_max_force(fz, friction);
    // n(v) at station i: the road's push per unit of the car's weight (module documentation).
    let normal = |i: usize, v: f64| {
        if options.crests {
            let f = track.frame(i);
            f.cos_pitch * f.cos_banking + v * v * f.vertical_curvature / G
        } else {
            1.0
        }
    };
    // The axles' loads at speed v under the road's push n, each kept ≥ 0 as the vehicle's.
    let loads = |v: f64, n: f64| {
        let d = car.downforce(v);
        [
            (static_load[0] * n + d[0]).max(0.0),
            (static_load[1] * n + d[1]).max(0.0),
        ]
    };
    let total_grip = |v: f64, n: f64, friction: f64| {
        let fz = loads(v, n);
        grip(0, fz[0], friction) + grip(1, fz[1], friction)
    };
    let driven_radius = match car.drive {
        Drive::Front => car.front_tyre.radius,
        _ => car.rear_tyre.radius,
    };
    let engine_force = |v: f64| {
        car.gears
            .iter()
            .map(|g| {
                let ratio = g * car.final_drive;
                let w = v / driven_radius * ratio;
                if w > car.rev_limiter {
                    0.0
                } else {
                    car.engine_torque(w.max(car.tickover)) * ratio / driven_radius
                }
            })
            .fold(0.0, f64::max)
    };
    let traction = |v: f64, n: f64, friction: f64| {
        let fz = loads(v, n);
        let h = car.cg_height;
        // Driven-axle grip with the load it gains while accelerating at F/m: F = μ(F_z0 + F·h/L)
        // ⇒ F = μF_z0 / (1 − μh/L) (rear), F = μF_z0 / (1 + μh/L) (front); none off the road.
        match car.drive {
            Drive::Rear if fz[1] > 0.0 => {
                let mu = grip(1, fz[1], friction) / fz[1];
                mu * fz[1] / (1.0 - mu * h / l).max(0.1)
            }
            Drive::Front if fz[0] > 0.0 => {
                let mu = grip(0, fz[0], friction) / fz[0];
                mu * fz[0] / (1.0 + mu * h / l)
            }
            Drive::All => total_grip(v, n, friction),
            _ => 0.0,
        }
    };
    let brake_force = 2.0
        * (car.brake_torque(true) / car.front_tyre.radius
            + car.brake_torque(false) / car.rear_tyre.radius);
    let v_max = car.rev_limiter / (car.gears.last().copied().unwrap_or(1.0) * car.final_drive)
        * driven_radius;

    // 1. Cornering cap; the car keeps its wheels on the road (a total load > 0).
    let cap: Vec<f64> = (0..=n)
        .map(|i| {
            let c = track.sample(i);
            let need =
                |v: f64| v * v * c.curvature.abs() - G * c.banking.sin() * c.curvature.signum();
            let ok = |v: f64| {
                let nv = normal(i, v);
                let d = car.downforce(v);
                // The point mass's load, before either axle's is kept ≥ 0.
                let load = (static_load[0] + static_load[1]) * nv + d[0] + d[1];
                load > 0.0 && m * need(v) <= total_grip(v, nv, c.friction)
            };
            if ok(v_max) {
                return v_max;
            }
            let (mut lo, mut hi) = (0.0, v_max);
            for _ in 0..50 {
                let mid = 0.5 * (lo + hi);
                if ok(mid) { lo = mid } else { hi = mid }
            }
            lo
        })
        .collect();
    let ellipse = |v: f64, i: usize| {
        let c = track.sample(i);
        let lat = m * v * v * c.curvature.abs();
        let max = total_grip(v, normal(i, v), c.friction);
        (1.0 - (lat / max).powi(2)).max(0.0).sqrt()
    };

    let forward = |v: &mut [f64]| {
        for i in 0..n {
            let c = track.sample(i);
            let vi = v[i];
            let ni = normal(i, vi);
            let push = engine_force(vi).min(traction(vi, ni, c.friction) * ellipse(vi, i));
            let acc = push / m
                - car.drag(vi) / m
                - c.rolling_resistance.unwrap_or(rolling) * car.scales.rolling * G * ni.max(0.0)
                - G * c.grade;
            let next = (vi * vi + 2.0 * ds * acc).max(0.0).sqrt();
            v[i + 1] = next.min(cap[i + 1]);
        }
    };
    let backward = |v: &mut [f64]| {
        for i in (0..n).rev() {
            let c = track.sample(i);
            let vn = v[i + 1];
            let ni = normal(i, vn);
            let stop = (total_grip(vn, ni, c.friction) * ellipse(vn, i)).min(brake_force);
            let dec = stop / m
                + car.drag(vn) / m
                + c.rolling_resistance.unwrap_or(rolling) * car.scales.rolling * G * ni.max(0.0)
                + G * c.grade;
            let allowed = (vn * vn + 2.0 * ds * dec.max(0.0)).sqrt();
            v[i] = v[i].min(allowed);
        }
    };

    // 2. Forward pass from standing; a flying lap's again, from the speed the first ended
    // with.
    let mut v: Vec<f64> = vec![0.0; n + 1];
    for pass in 0..if options.flying { 2 } else { 1 } {
        if pass == 1 {
            v[0] = v[n].min(cap[0]);
        }
        forward(&mut v);
    }
    // 3. Backward pass from the finish; a flying lap's finish is its start, and the second
    // pass brakes the lap's end for the next lap's first corner.
    for pass in 0..if options.flying { 2 } else { 1 } {
        if pass == 1 {
            let closed = v[0].min(v[n]);
            (v[0], v[n]) = (closed, closed);
        }
        backward(&mut v);
    }
    // 4. Lap time.
    let lap_time: f64 = (0..n).map(|i| 2.0 * ds / (v[i] + v[i + 1]).max(1e-9)).sum();
    Limit {
        lap_time_s: lap_time,
        reward_mps: track.length / lap_time,
        flying: options.flying,
        track_length: track.length,
        speed: v,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::{Piece, Track};

    fn straight(length: f64) -> Track {
        Track::from_pieces("straight", "test", &[Piece::flat(length, 0.0)], vec![])
    }

    #[test]
    fn a_flat_circle_is_driven_at_the_grip_limit() {
        let r = 100.0;
        let p = Piece::flat(std::f64::consts::TAU * r, 1.0 / r);
        let t = Track::from_pieces("circle", "test", &[p], vec![]);
        let car = Car::spirit_300();
        let lim = limit_lap(&t, &car);
        // Past the launch the speed settles just below m v²/r = grip (with downforce): at the cap
        // the friction ellipse leaves nothing to overcome drag.
        let v = lim.speed[t.len() / 2];
        let tyres = [
            TyreModel::new(&car.front_tyre),
            TyreModel::new(&car.rear_tyre),
        ];
        let d = car.downforce(v);
        let weight = car.static_axle_loads();
        let loads = [weight[0] + d[0], weight[1] + d[1]];
        let grip: f64 = (0..2)
            .map(|k| loads[k] * tyres[k].mu * tyres[k].load_factor(loads[k] / 2.0))
            .sum();
        let lateral = car.mass * v * v / r;
        assert!(
            lateral <= grip && lateral > 0.97 * grip,
            "v {v}: {lateral} vs {grip}"
        );
        assert_eq!(lim.track_length, t.length);
        assert!((lim.reward_mps * lim.lap_time_s - std::f64::consts::TAU * r).abs() < 1e-9);
    }

    /// A straight: a 500 m level run-up, then a crest of constant vertical curvature
    /// −1/100 m over which the pitch falls from 0 to −0.2 rad (10 cm pieces linear in z), then
    /// 200 m down at that pitch.
    fn straight_crest() -> Track {
        let (kv, crest) = (-0.01, 20.0);
        let pieces_n = (crest / 0.1) as usize;
        let d = crest / pieces_n as f64;
        let mut pieces = vec![Piece::flat(500.0, 0.0)];
        let mut z = 0.0;
        for j in 0..pieces_n {
            let z1 = z + d * (kv * (j as f64 + 0.5) * d).tan();
            pieces.push(Piece {
                z0: z,
                z1,
                ..Piece::flat(d, 0.0)
            });
            z = z1;
        }
        let grade = (kv * crest).tan();
        pieces.push(Piece {
            z0: z,
            z1: z + 200.0 * grade,
            ..Piece::flat(200.0, 0.0)
        });
        Track::from_pieces("crest", "test", &pieces, vec![])
    }

    /// On level, unbanked roads the crest-aware limit is the crest-blind one bit for bit
    /// (n = 1 exactly).
    #[test]
    fn without_crests_the_crest_aware_limit_is_the_limit() {
        let car = Car::spirit_300();
        let r = 100.0;
        let circle = Track::from_pieces(
            "circle",
            "test",
            &[Piece::flat(std::f64::consts::TAU * r, 1.0 / r)],
            vec![],
        );
        for t in [straight(400.0), circle] {
            assert_eq!(
                limit_lap_with(&t, &car, LimitOptions::CRESTS),
                limit_lap(&t, &car)
            );
        }
    }

    /// Over a straight crest the crest-blind limit runs the run-up's speed over the top, where
    /// the car would take off; the crest-aware limit is slower, and keeps every station's
    /// speed below the closed-form take-off speed
    /// v² = m·g·cos φ·cos β / (−m·κ_v − 0.645·Cl·A) (the total load m·g·n(v) + downforce
    /// vanishing), reaching it (within 1 %) where it binds.
    #[test]
    fn the_car_keeps_its_wheels_on_a_crest() {
        let car = Car::spirit_300();
        let t = straight_crest();
        let (blind, aware) = (
            limit_lap(&t, &car),
            limit_lap_with(&t, &car, LimitOptions::CRESTS),
        );
        assert!(
            aware.lap_time_s > blind.lap_time_s,
            "{} s against {} s",
            aware.lap_time_s,
            blind.lap_time_s
        );
        let d = car.downforce(1.0);
        let take_off = |i: usize| {
            let f = t.frame(i);
            let lift = -car.mass * f.vertical_curvature - (d[0] + d[1]);
            (lift > 0.0).then(|| (car.mass * G * f.cos_pitch * f.cos_banking / lift).sqrt())
        };
        let crest: Vec<(usize, f64)> = (0..t.len())
            .filter_map(|i| take_off(i).map(|v| (i, v)))
            .collect();
        assert!(!crest.is_empty());
        let (mut closest, mut blind_over) = (0.0f64, 0.0f64);
        for &(i, cap) in &crest {
            assert!(
                aware.speed[i] <= cap * (1.0 + 1e-9),
                "station {i}: {} m/s over the take-off speed {cap} m/s",
                aware.speed[i]
            );
            closest = closest.max(aware.speed[i] / cap);
            blind_over = blind_over.max(blind.speed[i] / cap);
        }
        assert!(closest > 0.99, "{closest}");
        assert!(blind_over > 1.2, "{blind_over}");
        // Without downforce the take-off speed at the top is √(g/−κ_v) ≈ 31.3 m/s: the wings
        // hold the car down to a higher one, but not to the run-up's.
        let top = crest.iter().map(|&(_, v)| v).fold(f64::INFINITY, f64::min);
        assert!((31.3..45.0).contains(&top), "{top}");
    }

    #[test]
    fn a_straight_is_a_standing_start_acceleration_run() {
        let car = Car::spirit_300();
        let lim = limit_lap(&straight(400.0), &car);
        // A quarter mile in about 11-13 s for a 290 kW, 1440 kg car (ignoring inertia).
        assert!((9.0..13.0).contains(&lim.lap_time_s), "{}", lim.lap_time_s);
        assert_eq!(lim.speed[0], 0.0);
        assert!(lim.speed.windows(2).all(|w| w[1] >= w[0]));
    }

    /// A flying lap of a circle is driven at its cornering cap all the way round, the lap
    /// time 2πr over that speed; the standing lap is slower by its launch.
    #[test]
    fn a_flying_circle_is_the_cap_all_the_way_round() {
        let r = 100.0;
        let p = Piece::flat(std::f64::consts::TAU * r, 1.0 / r);
        let t = Track::from_pieces("circle", "test", &[p], vec![]);
        let car = Car::spirit_300();
        let standing = limit_lap(&t, &car);
        let flying = limit_lap_with(&t, &car, LimitOptions::FLAT.flying());
        let cap = flying.speed[t.len() / 2];
        assert!(flying.speed.iter().all(|&v| (v - cap).abs() < 1e-9 * cap));
        assert!((flying.lap_time_s - std::f64::consts::TAU * r / cap).abs() < 1e-6);
        assert!(flying.flying && !standing.flying);
        assert!(standing.lap_time_s > flying.lap_time_s + 1.0);
    }

    /// A flying lap crosses the line at the speed it ends with: on two 1 km straights joined
    /// by hairpins of radius 15 m, the line 20 m before the first, the flying lap's finish
    /// brakes for the hairpin past the line, where the standing lap ends flat out.
    #[test]
    fn a_flying_lap_brakes_before_the_line_for_the_next_laps_first_corner() {
        let r = 15.0;
        let hairpin = Piece::flat(std::f64::consts::PI * r, 1.0 / r);
        let pieces = [
            Piece::flat(20.0, 0.0),
            hairpin,
            Piece::flat(1000.0, 0.0),
            hairpin,
            Piece::flat(980.0, 0.0),
        ];
        let t = Track::from_pieces("hairpins", "test", &pieces, vec![]);
        let car = Car::spirit_300();
        let standing = limit_lap(&t, &car);
        let flying = limit_lap_with(&t, &car, LimitOptions::FLAT.flying());
        let n = t.len();
        assert_eq!(flying.speed[0], flying.speed[n]);
        assert_eq!(standing.speed[0], 0.0);
        assert!(
            flying.speed[n] < 0.5 * standing.speed[n],
            "{} {}",
            flying.speed[n],
            standing.speed[n]
        );
        // Past the first hairpin both laps are the same lap again.
        assert_eq!(flying.speed[n / 2], standing.speed[n / 2]);
        assert!(flying.lap_time_s < standing.lap_time_s);
    }
}
