//! The robot's path tracker against the Rust, on every driver step of a tracked lap.

use crate::common::builtin;
use crate::{Agree, Calls, LEARNED, harness, lap, written};
use cdbo::car::Car;
use cdbo::drive::demo::SpeedHold;
use cdbo::drive::steering::Steering;
use cdbo::drive::tracker::{self, PathTracker, TrackerCar, TrackerInput};
use cdbo::geometry;
use cdbo::policy::RkhsPolicy;
use cdbo::sim::Simulator;
use cdbo::torcs::lap::cornering_tables;
use cdbo::track::builtin::DEFAULT;

/// The path tracker's steering in the robot is the Rust one: on every driver step of three laps
/// of the simulator steered by the tracker (the demonstration and the learned policy), rebuilt
/// from the recorded position, heading, speed and yaw rate, the C++ gives the same heading
/// error, curvature and steering command, bit for bit; the cornering stiffness the robot
/// interpolates in its tables (torcs/lap.rs `cornering_tables`) lies within 1e-4 of the
/// vehicle's.
#[test]
fn the_robots_tracker_is_the_rust_one_on_a_recorded_lap() {
    let Some(exe) = harness() else { return };
    let car = Car::spirit_300();
    let mut sim = Simulator::new(builtin(DEFAULT), &car);
    sim.config.trace = true;
    let tracker = PathTracker::new();
    sim.config.steering = Steering::Tracker(tracker.clone());
    let track = &sim.track;
    let demo = lap(&sim, &mut SpeedHold::new(15.0));
    let policy = RkhsPolicy::new(LEARNED.1.to_vec(), LEARNED.0).unwrap();
    let fast = lap(&sim, &mut policy.pedal());

    let mut calls = Calls::default();
    calls.check(
        "constants",
        "tracker_constants",
        &[],
        &[tracker::PATH_STEP, tracker::MIN_SPEED, tracker::DRIVER_STEP],
        Agree::Exactly,
    );
    let tables = cornering_tables(&sim.vehicle);
    let table_args = tables.clone().map(|t| {
        let mut args = vec![t.len() as f64];
        args.extend(t.iter().flat_map(|&(v, c)| [v, c]));
        written(&args)
    });
    let gains = [
        tracker.preview_time,
        tracker.preview_min,
        tracker.feedforward_time,
        tracker.yaw_rate_gain,
        tracker.yaw_rate_speed,
        tracker.yaw_step_gain,
    ];
    let tc = TrackerCar::of(&car);
    let chassis = [
        tc.mass,
        tc.wheelbase,
        tc.cg_to_front,
        tc.cg_to_rear,
        tc.steer_lock,
        tc.yaw_inertia,
    ];
    let law_args = written(&[&gains[..], &chassis[..]].concat());
    let (mut saturated, mut cornering, mut fastest) = (0, 0, 0.0_f64);
    for (name, trace) in [("demonstration", &demo), ("learned policy", &fast)] {
        let mut hint = 0;
        for p in trace.iter() {
            let at = format!("{name} at t = {} s", p.t);
            let proj = track.project(p.pos_x, p.pos_y, hint);
            hint = proj.index;
            assert_eq!(proj.lateral.to_bits(), p.lateral.to_bits(), "{at}");
            let yaw = p.heading_error + track.sample(proj.index).heading;
            // The simulator's first driver step reads the car's (sin ψ, cos ψ) before its
            // gearbox first synchronises them with ψ (Vehicle::at_rest leaves them (0, 0)):
            // there every bearing is 0.
            let (sin, cos) = if p.t == 0.0 {
                (0.0, 0.0)
            } else {
                yaw.sin_cos()
            };
            let v = tracker::tracker_speed(p.speed);
            calls.check(&at, "tracker_speed", &[p.speed], &[v], Agree::Exactly);
            let (behind, ahead) = (
                track.point_at(proj.s - tracker::PATH_STEP),
                track.point_at(proj.s + tracker::PATH_STEP),
            );
            let (dx, dy) = (ahead.0 - behind.0, ahead.1 - behind.1);
            let bearing = geometry::bearing(dx, dy, (sin, cos));
            calls.check(
                &at,
                "bearing",
                &[dx, dy, sin, cos],
                &[bearing],
                Agree::Exactly,
            );
            let sf = proj.s + tracker.feedforward_time * v;
            let points =
                [-tracker::PATH_STEP, 0.0, tracker::PATH_STEP].map(|ds| track.point_at(sf + ds));
            let kappa = tracker::curvature(points[0], points[1], points[2]);
            let args: Vec<f64> = points.iter().flat_map(|&(x, y)| [x, y]).collect();
            calls.check(&at, "curvature", &args, &[kappa], Agree::Exactly);
            let friction = track.frame(proj.index).friction;
            let stiffness = sim.vehicle.cornering_stiffness(v, friction);
            for (k, first) in table_args.iter().enumerate() {
                let exact = stiffness[k] / friction;
                let tol = Agree::Within(1e-4 * exact);
                calls.check_after(&at, "table", first, &[v], &[exact], tol);
                let linear = cdbo::interp::linear(&tables[k], v);
                calls.check_after(&at, "table", first, &[v], &[linear], Agree::Exactly);
            }
            let input = TrackerInput {
                lateral_error: p.lateral,
                heading_error: -bearing,
                curvature: kappa,
                speed: v,
                yaw_rate: p.yaw_rate,
                cornering_stiffness: stiffness,
            };
            let delta = tracker.law(&tc, &input);
            // The replay is the simulator's steering (up to the rounding of the rebuilt yaw).
            assert!(
                (delta - p.steer).abs() < 1e-9,
                "{at}: {delta} vs {}",
                p.steer
            );
            let args = [
                p.lateral,
                -bearing,
                kappa,
                v,
                p.yaw_rate,
                stiffness[0],
                stiffness[1],
            ];
            calls.check_after(
                &at,
                "tracker_law",
                &law_args,
                &args,
                &[delta],
                Agree::Exactly,
            );
            saturated += usize::from(delta.abs() == car.steer_lock);
            cornering += usize::from(kappa.abs() > 0.01);
            fastest = fastest.max(p.speed);
        }
    }
    // The lock, which a smooth lap does not reach: 5 m off the path either side at 15 m/s.
    for e in [5.0, -5.0] {
        let input = TrackerInput {
            lateral_error: e,
            heading_error: 0.0,
            curvature: 0.0,
            speed: 15.0,
            yaw_rate: 0.0,
            cornering_stiffness: sim.vehicle.cornering_stiffness(15.0, 1.0),
        };
        let delta = tracker.law(&tc, &input);
        let mut args = [&gains[..], &chassis[..]].concat();
        args.extend([e, 0.0, 0.0, 15.0, 0.0]);
        args.extend(input.cornering_stiffness);
        calls.check(
            &format!("e = {e} m"),
            "tracker_law",
            &args,
            &[delta],
            Agree::Exactly,
        );
        saturated += usize::from(delta == -e.signum() * car.steer_lock);
    }
    // The yaw-rate loop's one-step bound, which the Spirit 300 never reaches: the same states
    // on tyres three times as stiff (as car1-trb1's at speed) bind it from 10 m/s up.
    let unbounded = PathTracker {
        yaw_step_gain: f64::INFINITY,
        ..tracker.clone()
    };
    let mut bound = 0;
    for p in fast.iter().filter(|p| p.speed > 10.0).step_by(10) {
        let input = TrackerInput {
            lateral_error: 0.2,
            heading_error: 0.01,
            curvature: 0.005,
            speed: p.speed,
            yaw_rate: p.yaw_rate,
            cornering_stiffness: sim
                .vehicle
                .cornering_stiffness(p.speed, 1.0)
                .map(|c| 3.0 * c),
        };
        let delta = tracker.law(&tc, &input);
        bound += usize::from(delta != unbounded.law(&tc, &input));
        let mut args = [&gains[..], &chassis[..]].concat();
        args.extend([0.2, 0.01, 0.005, p.speed, p.yaw_rate]);
        args.extend(input.cornering_stiffness);
        let at = format!("stiff tyres at {} m/s", p.speed);
        calls.check(&at, "tracker_law", &args, &[delta], Agree::Exactly);
    }
    assert!(bound > 10, "{bound} states bound");
    // The states span the law: corners, a fast lap, the lock.
    assert!(cornering > 1000, "{cornering} steps in corners");
    assert!(fastest > 25.0, "{fastest} m/s");
    assert!(saturated >= 2, "{saturated} steps at the lock");
    let n = calls.run(&exe);
    assert!(n > 7 * (demo.len() + fast.len()), "{n} calls");
}
