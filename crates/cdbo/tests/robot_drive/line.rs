//! The robot's line (its table, the path's points, both steering laws on the path) against the
//! simulator's, on every driver step of two laps held on a line.

use crate::common::builtin;
use crate::{Agree, Calls, harness, lap};
use cdbo::car::Car;
use cdbo::drive::demo::SpeedHold;
use cdbo::drive::steering::{self, PiSteering, Steering};
use cdbo::drive::tracker::{self, PathTracker, TrackerCar, TrackerInput};
use cdbo::drive::{Observation, Pedal};
use cdbo::experiment::race::BaseLine;
use cdbo::geometry;
use cdbo::policy::actions::PolicyDriver;
use cdbo::policy::{Policy, RkhsPolicy};
use cdbo::sim::Simulator;
use cdbo::sim::lap::held_offset;
use cdbo::torcs::line::LineTable;
use cdbo::track::builtin::DEFAULT;

/// A driver holding 15 m/s on a line of its own (a policy's line block).
struct SwingingDemo {
    hold: SpeedHold,
    line: PolicyDriver,
}

impl Pedal for SwingingDemo {
    fn pedal(&mut self, obs: &Observation) -> f64 {
        self.hold.pedal(obs)
    }

    fn line(&self, x: f64) -> f64 {
        self.line.line(x)
    }
}

/// The robot holds a line as the simulator does: on every driver step of two laps on
/// Ridgeway's minimum-curvature line with a policy's line on top (one steered by the path
/// tracker, one by the PI law), the line's table the robot is handed (torcs/line.rs
/// `LineTable`) gives, through the C++ `periodic_linear`, the Rust table's offset bit for bit
/// and lies within 1 cm of the simulator's offset; the path's points offset along the left
/// normal (`offset_left`) are the simulator's `Track::point_off` bit for bit; the steering
/// laws on the path (lateral error toMiddle − d(s) for the tracker, the look-ahead point on
/// the path for the PI law) are the recorded steering, bit for bit in the C++. The table's
/// line is the simulator's within 1e-5 m, and its steering within 1e-4 rad, on 99 % of the
/// steps; they part only within a station of where the simulator's line jumps (a step of the
/// road's width under the clamp; the lap's end, where a policy's d(x) jumps from d(1) to
/// d(0)), where the table's line ramps over one station: its steering there within 0.1 rad
/// off the lap's end.
#[test]
fn the_robots_line_is_the_rust_one_on_recorded_laps() {
    let Some(exe) = harness() else { return };
    let car = Car::spirit_300();
    let half_car = 0.5 * car.width;
    let mut sim = Simulator::new(builtin(DEFAULT), &car);
    sim.config.trace = true;
    let base = BaseLine::MinCurvature.line(&sim.track, &car).unwrap();
    sim.config.line = base.clone();
    let base = base.as_deref();
    let policy = Policy {
        pedal: RkhsPolicy::new(vec![0.0; 6], 0.2).unwrap(),
        line: Some(RkhsPolicy::new(vec![1.0, -1.5, 2.0, -1.0, 0.5, 1.0], 0.2).unwrap()),
        target: None,
    };
    let driver = || SwingingDemo {
        hold: SpeedHold::new(15.0),
        line: policy.driver(),
    };
    let tracker = PathTracker::new();
    let pi = PiSteering::new();
    let dt = sim.config.dt * sim.config.driver_every as f64;
    // Shared by the closures that find the path and steer on it.
    let calls = std::cell::RefCell::new(Calls::default());
    let (mut off_centre, mut steps) = (0, 0);
    let (mut d_errors, mut steer_errors, mut worst_steer) = (Vec::new(), Vec::new(), 0.0_f64);
    for steering in [Steering::Tracker(tracker.clone()), Steering::Pi(pi.clone())] {
        sim.config.steering = steering.clone();
        let trace = lap(&sim, &mut driver());
        let track = &sim.track;
        let held = driver();
        let table = LineTable::held(track, half_car, base, &held);
        // The table is sent once; each periodic_linear call reads it.
        let mut table_args = vec![table.offsets.len() as f64];
        table_args.extend(&table.offsets);
        table_args.push(table.length);
        let n = table.offsets.len() as f64;
        calls
            .borrow_mut()
            .check("the table", "line_table", &table_args, &[n], Agree::Exactly);
        let exact = |s: f64| {
            let s = track.wrap(s);
            held_offset(track, half_car, base, held.line(s / track.length), s)
        };
        // The offset at s, and the path's point there, as the robot finds them: the C++
        // interpolation of the table, then the point along the left normal.
        // (The C++ is asked on the robot's path, the table's.)
        let robot_path = |at: &str, s: f64, from_table: bool| {
            if !from_table {
                let d = exact(s);
                return (d, track.point_off(s, d));
            }
            let d = table.offset_at(s);
            let mut calls = calls.borrow_mut();
            calls.check(at, "periodic_linear", &[s], &[d], Agree::Exactly);
            let (x, y) = track.point_at(s);
            let (sin, cos) = track.heading_sin_cos(s);
            let point = track.point_off(s, d);
            let args = [x, y, sin, cos, d];
            calls.check(
                at,
                "offset_left",
                &args,
                &[point.0, point.1],
                Agree::Exactly,
            );
            (d, point)
        };
        let (mut hint, mut integral, mut table_integral) = (0, 0.0, 0.0);
        for p in &trace {
            let at = format!("{steering:?} at t = {} s", p.t);
            let proj = track.project(p.pos_x, p.pos_y, hint);
            hint = proj.index;
            let yaw = p.heading_error + track.sample(proj.index).heading;
            let (sin, cos) = if p.t == 0.0 {
                (0.0, 0.0)
            } else {
                yaw.sin_cos()
            };
            d_errors.push((table.offset_at(proj.s) - exact(proj.s)).abs());
            off_centre += usize::from(exact(proj.s).abs() > 1.0);
            steps += 1;
            // The steering on the simulator's line (checked against the record and the C++)
            // and on the table's (the robot's).
            let mut steer_on = |from_table: bool| -> f64 {
                let path = |s: f64| robot_path(&at, s, from_table);
                match &steering {
                    Steering::Tracker(t) => {
                        let v = tracker::tracker_speed(p.speed);
                        let (behind, ahead) = (
                            path(proj.s - tracker::PATH_STEP).1,
                            path(proj.s + tracker::PATH_STEP).1,
                        );
                        let (dx, dy) = (ahead.0 - behind.0, ahead.1 - behind.1);
                        let bearing = geometry::bearing(dx, dy, (sin, cos));
                        let sf = proj.s + t.feedforward_time * v;
                        let points = [-tracker::PATH_STEP, 0.0, tracker::PATH_STEP]
                            .map(|ds| path(sf + ds).1);
                        let kappa = tracker::curvature(points[0], points[1], points[2]);
                        let d = path(proj.s).0;
                        let stiffness = sim
                            .vehicle
                            .cornering_stiffness(v, track.frame(proj.index).friction);
                        let input = TrackerInput {
                            lateral_error: p.lateral - d,
                            heading_error: -bearing,
                            curvature: kappa,
                            speed: v,
                            yaw_rate: p.yaw_rate,
                            cornering_stiffness: stiffness,
                        };
                        let tc = TrackerCar::of(&car);
                        let delta = t.law(&tc, &input);
                        let mut args = vec![t.preview_time, t.preview_min];
                        args.extend([t.feedforward_time, t.yaw_rate_gain, t.yaw_rate_speed]);
                        args.extend([t.yaw_step_gain, tc.mass, tc.wheelbase, tc.cg_to_front]);
                        args.extend([tc.cg_to_rear, tc.steer_lock, tc.yaw_inertia]);
                        args.extend([p.lateral - d, -bearing, kappa, v]);
                        args.extend([p.yaw_rate, stiffness[0], stiffness[1]]);
                        if from_table {
                            let mut calls = calls.borrow_mut();
                            calls.check(&at, "tracker_law", &args, &[delta], Agree::Exactly);
                        }
                        delta
                    }
                    Steering::Pi(pi) => {
                        let la = pi.lookahead(p.speed);
                        let (tx, ty) = path(proj.s + la).1;
                        let e = geometry::bearing(tx - p.pos_x, ty - p.pos_y, (sin, cos));
                        let integral = if from_table {
                            &mut table_integral
                        } else {
                            &mut integral
                        };
                        let before = *integral;
                        let (wheelbase, lock) = (car.wheelbase, car.steer_lock);
                        let delta =
                            steering::steering_law(e, la, wheelbase, pi.ki, lock, integral, dt);
                        let args = [before, e, la, wheelbase, pi.ki, lock, dt];
                        let out = [delta, *integral];
                        if from_table {
                            let mut calls = calls.borrow_mut();
                            calls.check(&at, "steering_law", &args, &out, Agree::Exactly);
                        }
                        delta
                    }
                }
            };
            let delta = steer_on(false);
            assert!(
                (delta - p.steer).abs() < 1e-9,
                "{at}: {delta} vs {}",
                p.steer
            );
            let error = (steer_on(true) - p.steer).abs();
            steer_errors.push(error);
            // Across the lap's end a policy's line jumps from d(1) to d(0) in the simulator
            // and over one station of the table: the paths differ there.
            let reach = 2.0 * tracker::PATH_STEP + pi.lookahead(p.speed).max(10.0);
            if proj.s > reach && proj.s < track.length - reach {
                worst_steer = worst_steer.max(error);
            }
        }
    }
    let quantiles = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        let q = |f: f64| v[((v.len() - 1) as f64 * f) as usize];
        (q(0.5), q(0.99), q(1.0))
    };
    let (d50, d99, d_max) = quantiles(&mut d_errors);
    let (s50, s99, s_max) = quantiles(&mut steer_errors);
    eprintln!("line error: median {d50} m, 99 % {d99} m, max {d_max} m");
    eprintln!("steering error: median {s50} rad, 99 % {s99} rad, max {s_max} rad");
    assert!(
        d99 < 1e-5,
        "the table's line is {d99} m off on 1 % of the steps"
    );
    assert!(
        s99 < 1e-4,
        "the table's steering is {s99} rad off on 1 % of the steps"
    );
    assert!(
        worst_steer < 0.1,
        "the table's steering {worst_steer} rad off"
    );
    // The laps hold the line off the centre most of the way.
    assert!(
        off_centre > steps / 2,
        "{off_centre} of {steps} steps off centre"
    );
    let n = calls.into_inner().run(&exe);
    assert!(n > 5 * steps, "{n} calls");
}
