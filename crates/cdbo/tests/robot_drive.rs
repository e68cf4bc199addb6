//! The TORCS robot's decisions against cdbo's Rust, without TORCS.
//!
//! The robot's pure functions (`torcs-robot/drive.hpp`, embedded as
//! [`cdbo::torcs::ROBOT_HEADER`]) are compiled with `g++ -std=c++17` and the robot's own
//! flags into the harness `torcs-robot/tests/harness.cpp`, which answers one line per call.
//! The calls replay states recorded from two laps of cdbo's simulator on the default track
//! (the 15 m/s demonstration, and a policy learned by `cdbo race`): at every driver step the
//! policy's action (RKHS and table), the speed hold, the steering's look-ahead, bearing and
//! PI law, the gearbox, the launch clutch, the traction control and the ABS, each given the state the Rust controller had
//! (integrals, gear, time left in a shift), and the answers must equal the Rust definitions
//! bit for bit (within 1e-12 of the simulator's O(1) form of the RKHS policy). Skips with a
//! message where `g++` is missing.
//!
//! A third test replays two laps held on a line (the minimum-curvature line plus a policy's
//! line): the line's table the robot interpolates, the path's points and both steering laws
//! aiming at the path.
//!
//! A new function of the header (a second policy action, a path-tracking steering law) is
//! checked by a line in the harness's table and a `Calls::check` here.

mod common;

use std::path::PathBuf;
use std::process::Command;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};

use cdbo::calibrate::ProbePedal;
use cdbo::car::Car;
use cdbo::drive::demo::{self, SpeedHold};
use cdbo::drive::profile::ProfileHold;
use cdbo::drive::steering::{self, PiSteering, Steering};
use cdbo::drive::tracker::{self, PathTracker, TrackerCar, TrackerInput};
use cdbo::drive::{Observation, Pedal, pedal_command, pi_control};
use cdbo::experiment::race::BaseLine;
use cdbo::geometry;
use cdbo::policy::actions::PolicyDriver;
use cdbo::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use cdbo::policy::{Policy, PolicyTable, RkhsPolicy};
use cdbo::sim::lap::held_offset;
use cdbo::sim::{Simulator, TracePoint};
use cdbo::torcs::lap::cornering_tables;
use cdbo::torcs::line::LineTable;
use cdbo::torcs::{ROBOT_CXXFLAGS, ROBOT_HEADER, ROBOT_HEADER_NAME};
use cdbo::track::builtin::DEFAULT;
use cdbo::vehicle::SLIP_SPEED_FLOOR;
use cdbo::vehicle::aids::abs::abs_brake;
use cdbo::vehicle::aids::launch::{LaunchCar, launch_clutch};
use cdbo::vehicle::aids::traction::traction_throttle;
use cdbo::vehicle::powertrain::{DOWNSHIFT_MARGIN, Gearbox, THROTTLE_LEVELS};
use common::builtin;

/// The harness's source, compiled beside the header.
const HARNESS: &str = include_str!("../../../torcs-robot/tests/harness.cpp");
/// A learned policy: the best of `cdbo race --json` (CDBO on the default track, seed 0, 300
/// laps, 24.28 m/s with the rear axle's two wheels), its length-scale 1/29 and its 30 weights.
const LEARNED: (f64, [f64; 30]) = (
    0.034482758620689655,
    [
        0.7337174661007538,
        -0.43694042717594433,
        0.5201826057195019,
        -0.11801068406926697,
        0.09298255826485324,
        -0.06984606353310813,
        0.060475129724434626,
        0.07126463206502902,
        0.0259215183139601,
        0.03310894339182879,
        0.20151611797424623,
        0.02139022189118771,
        -0.032601245046369076,
        0.023931743413441394,
        -0.010326615824044563,
        -0.02276569741592198,
        0.06798864616173275,
        -0.009139452303147715,
        0.0007214249764117531,
        0.1374604199664775,
        0.31369075676239644,
        0.03037078288592783,
        -0.0059686177094644965,
        -0.08026028734180894,
        0.11866791284155351,
        0.5081091629164485,
        0.03954852323972051,
        0.027909705986782656,
        0.10983929994869644,
        -0.0796284654677915,
    ],
);

/// The compiled harness (built once for the tests here), or `None` (with a message) where
/// there is no `g++`.
fn harness() -> Option<PathBuf> {
    static HARNESS_EXE: OnceLock<Option<PathBuf>> = OnceLock::new();
    let exe = HARNESS_EXE.get_or_init(|| {
        if Command::new("g++").arg("--version").output().is_err() {
            return None;
        }
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("robot_drive");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(ROBOT_HEADER_NAME), ROBOT_HEADER).unwrap();
        std::fs::write(dir.join("harness.cpp"), HARNESS).unwrap();
        let exe = dir.join("harness");
        let out = Command::new("g++")
            .arg("-std=c++17")
            .args(ROBOT_CXXFLAGS)
            .arg("-o")
            .arg(&exe)
            .arg(dir.join("harness.cpp"))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "the harness did not compile:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        Some(exe)
    });
    if exe.is_none() {
        eprintln!("skipping: g++ is not installed (apt-get install g++)");
    }
    exe.clone()
}

/// How closely the C++ must agree.
#[derive(Debug, Clone, Copy)]
enum Agree {
    /// The same bits.
    Exactly,
    /// Within this absolute difference.
    Within(f64),
}

/// Calls to the harness and the answers the Rust definitions give.
#[derive(Default)]
struct Calls {
    input: String,
    expected: Vec<(String, Vec<f64>, Agree)>,
}

impl Calls {
    /// Calls `name` with `args`; the answer must be `expected`.
    fn check(&mut self, what: &str, name: &str, args: &[f64], expected: &[f64], agree: Agree) {
        self.input.push_str(name);
        for a in args {
            self.input.push_str(&format!(" {a:?}"));
        }
        self.input.push('\n');
        self.expected
            .push((format!("{what}: {name} {args:?}"), expected.to_vec(), agree));
    }

    /// Runs the harness on every call and compares; returns the number of calls. Each run
    /// has an input file of its own (the tests run in parallel).
    fn run(&self, exe: &PathBuf) -> usize {
        static RUNS: AtomicUsize = AtomicUsize::new(0);
        let input = exe.with_extension(format!("in{}", RUNS.fetch_add(1, Ordering::Relaxed)));
        std::fs::write(&input, &self.input).unwrap();
        let out = Command::new(exe)
            .stdin(std::fs::File::open(&input).unwrap())
            .output()
            .unwrap();
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(out.status.success(), "the harness failed: {text}");
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), self.expected.len());
        for (line, (what, expected, agree)) in lines.iter().zip(&self.expected) {
            let got: Vec<f64> = line.split(' ').map(|v| v.parse().unwrap()).collect();
            assert_eq!(got.len(), expected.len(), "{what}: {line}");
            for (g, e) in got.iter().zip(expected) {
                let ok = match agree {
                    Agree::Exactly => g.to_bits() == e.to_bits(),
                    Agree::Within(tol) => (g - e).abs() <= *tol,
                };
                assert!(ok, "{what}: C++ {got:?}, Rust {expected:?}");
            }
        }
        self.expected.len()
    }
}

/// A lap of the simulator with its trace.
fn lap(sim: &Simulator, pedal: &mut dyn Pedal) -> Vec<TracePoint> {
    let r = sim.lap(pedal);
    assert!(r.completed, "{:?}", r.failure);
    r.trace
}

#[test]
fn the_robots_decisions_are_the_rust_ones_on_recorded_laps() {
    let Some(exe) = harness() else { return };
    let car = Car::spirit_300();
    let mut sim = Simulator::new(builtin(DEFAULT), &car);
    sim.config.trace = true;
    let track = &sim.track;
    let demo = lap(&sim, &mut SpeedHold::new(15.0));
    // The learned policy, and the demonstration's fit (the policy learning starts from).
    let pairs: Vec<(f64, f64)> = demo.iter().map(|p| (p.x, p.pedal)).collect();
    let fit = RkhsPolicy::fit(&pairs, 30, default_lengthscale(30), DEFAULT_RIDGE).unwrap();
    let policy = RkhsPolicy::new(LEARNED.1.to_vec(), LEARNED.0).unwrap();
    let fast = lap(&sim, &mut policy.pedal());
    let table = PolicyTable::new(policy.table(201)).unwrap();
    let (learned_pedal, fit_pedal) = (policy.pedal(), fit.pedal());

    let mut calls = Calls::default();
    // The pedal's value as a step applies it, at the edges.
    for v in [f64::NAN, -3.0, -1.0, -0.25, -0.0, 0.0, 0.7, 1.0, 2.5] {
        let a = pedal_command(v);
        calls.check("pedal", "pedal_command", &[v], &[a], Agree::Exactly);
    }
    // The tables at their own points, where the segment changes (there a value far below
    // its neighbour's tells the two sides apart), and beyond their ends.
    let steep = PolicyTable::new(vec![(0.0, 1.0), (0.5, 1e-17), (0.75, -0.5)]).unwrap();
    for t in [&table, &steep] {
        let mut args = vec![t.points().len() as f64];
        args.extend(t.points().iter().flat_map(|&(x, a)| [x, a]));
        for x in t.points().iter().map(|&(x, _)| x).chain([-0.5, 1.5]) {
            let args = [&args[..], &[x]].concat();
            calls.check("table", "table", &args, &[t.action(x)], Agree::Exactly);
        }
    }
    let mut table_args = vec![table.points().len() as f64];
    table_args.extend(table.points().iter().flat_map(|&(x, a)| [x, a]));

    // The gearbox as the robot is handed it (torcs/lap.rs): total ratios and the shift map.
    let map = sim.vehicle.shift_map();
    let ratios: Vec<f64> = car.gears.iter().map(|g| g * car.final_drive).collect();
    let gears = [ratios.len() as f64]
        .into_iter()
        .chain(ratios.iter().copied())
        .chain([THROTTLE_LEVELS as f64])
        .chain(map.upshift.iter().flatten().copied())
        .chain([DOWNSHIFT_MARGIN, car.shift_time])
        .collect::<Vec<f64>>();
    let steer = PiSteering::new();
    let dt = sim.config.dt * sim.config.driver_every as f64;
    let (mut upshifts, mut downshifts, mut top_gear, mut slipping, mut easing) = (0, 0, 0, 0, 0);
    let (mut braking, thresholds) = (0, sim.vehicle.aid_threshold());
    for (lap, trace) in [("demonstration", &demo), ("learned policy", &fast)] {
        let (mut hold, mut hold_integral) = (SpeedHold::new(15.0), 0.0);
        let (mut steer_integral, mut hint) = (0.0, 0);
        let (mut gearbox, mut launch_time) = (Gearbox::new(), 0.0);
        let mut last_t = trace[0].t;
        for (i, p) in trace.iter().enumerate() {
            let at = format!("{lap} at t = {} s", p.t);
            // The policies at the recorded lap fraction: the direct sum bit for bit, the
            // simulator's O(1) form within 1e-12.
            for (rkhs, pedal) in [(&policy, &learned_pedal), (&fit, &fit_pedal)] {
                let mut args = vec![rkhs.lengthscale, rkhs.kernels() as f64];
                args.extend(&rkhs.weights);
                args.push(p.x);
                let raw = rkhs.raw(p.x);
                calls.check(&at, "rkhs", &args, &[raw], Agree::Exactly);
                calls.check(&at, "rkhs", &args, &[pedal.raw(p.x)], Agree::Within(1e-12));
            }
            let args = [&table_args[..], &[p.x]].concat();
            calls.check(&at, "table", &args, &[table.action(p.x)], Agree::Exactly);

            // The demonstrator's speed hold on the recorded speeds, its integral carried.
            let step = p.t - last_t;
            last_t = p.t;
            let before = hold_integral;
            let e = 15.0 - p.speed;
            let a = pi_control(demo::KP, demo::KI, 1.0, &mut hold_integral, e, step);
            let live = hold.pedal(&Observation {
                x: p.x,
                speed: p.speed,
                time: p.t,
            });
            assert_eq!(a.to_bits(), live.to_bits(), "{at}: the speed hold");
            let recorded = if std::ptr::eq(trace, &demo) {
                a
            } else {
                pedal_command(learned_pedal.raw(p.x))
            };
            assert_eq!(
                recorded.to_bits(),
                p.pedal.to_bits(),
                "{at}: the recorded pedal"
            );
            let args = [before, 15.0, p.speed, step];
            calls.check(
                &at,
                "speed_hold",
                &args,
                &[a, hold_integral],
                Agree::Exactly,
            );

            // The steering, from the recorded position, speed and heading: the car's yaw is
            // the recorded heading error off the road's heading where it projects.
            let proj = track.project(p.pos_x, p.pos_y, hint);
            hint = proj.index;
            let yaw = p.heading_error + track.sample(proj.index).heading;
            let (sin, cos) = yaw.sin_cos();
            let d = steer.lookahead(p.speed);
            let args = [steer.lookahead_time, steer.lookahead_min, p.speed];
            calls.check(&at, "lookahead", &args, &[d], Agree::Exactly);
            let (tx, ty) = track.point_at(proj.s + d);
            let (dx, dy) = (tx - p.pos_x, ty - p.pos_y);
            let e = geometry::bearing(dx, dy, (sin, cos));
            calls.check(&at, "bearing", &[dx, dy, sin, cos], &[e], Agree::Exactly);
            let before = steer_integral;
            let (wheelbase, lock) = (car.wheelbase, car.steer_lock);
            let delta =
                steering::steering_law(e, d, wheelbase, steer.ki, lock, &mut steer_integral, dt);
            // The replay is the simulator's steering (up to the rounding of the rebuilt yaw).
            assert!(
                (delta - p.steer).abs() < 1e-12,
                "{at}: {delta} vs {}",
                p.steer
            );
            let args = [before, e, d, wheelbase, steer.ki, lock, dt];
            calls.check(
                &at,
                "steering_law",
                &args,
                &[delta, steer_integral],
                Agree::Exactly,
            );

            // The gearbox on the rolling wheels' spin at the recorded speed and throttle, the
            // shift's time counted down by the driver step as the robot does.
            let throttle = p.pedal.max(0.0);
            let w = p.speed / car.rear_tyre.radius;
            gearbox.shifting = (gearbox.shifting - step).max(0.0);
            let (gear, shifting) = (gearbox.gear, gearbox.shifting);
            let point = map.upshift(gear, throttle);
            gearbox.update(&car, map, w, throttle);
            upshifts += usize::from(gearbox.gear > gear);
            downshifts += usize::from(gearbox.gear < gear);
            top_gear = top_gear.max(gearbox.gear);
            let mut args = vec![gear as f64, shifting];
            args.extend(&gears);
            args.extend([w, throttle]);
            let out = [gearbox.gear as f64, gearbox.shifting, point];
            calls.check(&at, "gear_update", &args, &out, Agree::Exactly);

            // The launch clutch in the gear chosen, with the recorded engine speed.
            let engine = LaunchCar {
                engine_speed: p.rpm * std::f64::consts::PI / 30.0,
                red_line: car.rev_limiter,
                first_ratio: ratios[0],
                wheel_radius: car.rear_tyre.radius,
                speed_x: p.speed,
            };
            let before = launch_time;
            let c = launch_clutch(gearbox.gear, throttle, step, &mut launch_time, &engine);
            slipping += usize::from(c > 0.0 && c < 1.0);
            let mut args = vec![before, gearbox.gear as f64, throttle, step];
            args.extend([engine.engine_speed, engine.red_line, engine.first_ratio]);
            args.extend([engine.wheel_radius, engine.speed_x]);
            calls.check(
                &at,
                "launch_clutch",
                &args,
                &[c, launch_time],
                Agree::Exactly,
            );

            // Traction control on the recorded throttle, at slip speeds from −2 to 12 m/s
            // (the simulator's trace records none), 0.5 m/s apart step by step.
            let slip = -2.0 + 0.5 * (i % 29) as f64;
            let eased = traction_throttle(throttle, slip);
            easing += usize::from(eased < throttle && eased > 0.0);
            calls.check(
                &at,
                "traction_throttle",
                &[throttle, slip],
                &[eased],
                Agree::Exactly,
            );

            // ABS on the recorded brake (full brake where the pedal pushes), at the recorded
            // wheels' slides plus 0-0.3 step by step (the recorded laps hardly lock a wheel).
            let brake = if p.pedal < 0.0 { -p.pedal } else { 1.0 };
            let extra = 0.01 * (i % 31) as f64;
            let slide = |w: f64| -(w - p.speed) / p.speed.abs().max(SLIP_SPEED_FLOOR) + extra;
            let [front, rear_left, rear_right] = p.wheel_speeds;
            let slides = [slide(front), slide(0.5 * (rear_left + rear_right))];
            let eased = abs_brake(brake, slides, thresholds);
            braking += usize::from(eased < brake && eased > 0.0);
            let args = [brake, slides[0], slides[1], thresholds[0], thresholds[1]];
            calls.check(&at, "abs_brake", &args, &[eased], Agree::Exactly);
        }
    }
    // The states span the decisions: every gear both ways, a slipping clutch, a fast lap.
    assert_eq!(top_gear + 1, car.gears.len());
    assert!(
        upshifts >= 2 * top_gear && downshifts >= top_gear,
        "{upshifts} up, {downshifts} down"
    );
    assert!(slipping >= 10, "{slipping} steps with the clutch slipping");
    assert!(easing >= 100, "{easing} steps with the throttle eased");
    assert!(braking >= 100, "{braking} steps with the brake eased");
    let fastest = fast.iter().map(|p| p.speed).fold(0.0, f64::max);
    assert!(fastest > 25.0, "{fastest} m/s");

    let n = calls.run(&exe);
    assert!(n > 10 * (demo.len() + fast.len()), "{n} calls");
}

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
        args
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
            for (k, args) in table_args.iter().enumerate() {
                let args = [&args[..], &[v]].concat();
                let exact = stiffness[k] / friction;
                let tol = Agree::Within(1e-4 * exact);
                calls.check(&at, "table", &args, &[exact], tol);
                let linear = cdbo::interp::linear(&tables[k], v);
                calls.check(&at, "table", &args, &[linear], Agree::Exactly);
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
            let mut args = [&gains[..], &chassis[..]].concat();
            args.extend([-bearing, kappa, v, p.yaw_rate, stiffness[0], stiffness[1]]);
            args.insert(gains.len() + chassis.len(), p.lateral);
            calls.check(&at, "tracker_law", &args, &[delta], Agree::Exactly);
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

/// The profile hold (the calibration's fast probe) in the robot is the Rust one: on every
/// driver step of the fast probe's lap of the Spirit 300 in the simulator on the default track
/// (k times its crest-aware limit), the C++ gives the same target and pedal from
/// the recorded lap fraction and speed, bit for bit, and so at speeds 5 m/s either side of the
/// recorded one (the clamps); the recorded pedal is the Rust law's.
#[test]
fn the_robots_profile_hold_is_the_rust_one_on_a_recorded_lap() {
    let Some(exe) = harness() else { return };
    let car = Car::spirit_300();
    let mut sim = Simulator::new(builtin(DEFAULT), &car);
    sim.config.trace = true;
    let (k, profile) = cdbo::calibrate::probes(&sim.track, &car)
        .unwrap()
        .into_iter()
        .find_map(|p| match p.pedal {
            ProbePedal::Profile { k, speed } => Some((k, speed)),
            _ => None,
        })
        .expect("a fast probe");
    let mut hold = ProfileHold {
        profile: &profile,
        length: sim.track.length,
        k,
    };
    let mut driver = hold;
    let trace = lap(&sim, &mut driver);

    let mut calls = Calls::default();
    calls.check(
        "constants",
        "profile_constants",
        &[],
        &[
            cdbo::drive::profile::TRACKER_GAIN,
            cdbo::drive::profile::PREVIEW_S,
            cdbo::drive::profile::TRACKER_FLOOR_MPS,
        ],
        Agree::Exactly,
    );
    let n = profile.len() - 1;
    let mut table = vec![n as f64];
    table.extend(&profile);
    calls.check(
        "the profile",
        "profile_table",
        &table,
        &[n as f64],
        Agree::Exactly,
    );
    let (mut full, mut braking, mut between, mut floor) = (0, 0, 0, 0);
    for p in &trace {
        let at = format!("t = {} s", p.t);
        let obs = Observation {
            x: p.x,
            speed: p.speed,
            time: p.t,
        };
        let a = hold.pedal(&obs);
        assert_eq!(pedal_command(a).to_bits(), p.pedal.to_bits(), "{at}");
        between += usize::from(a.abs() < 1.0);
        for speed in [p.speed, p.speed - 5.0, p.speed + 5.0] {
            let target = hold.target(p.x, speed);
            floor += usize::from(target == cdbo::drive::profile::TRACKER_FLOOR_MPS);
            let a = hold.pedal(&Observation { speed, ..obs });
            full += usize::from(a == 1.0);
            braking += usize::from(a == -1.0);
            let args = [k, sim.track.length, p.x, speed];
            calls.check(&at, "profile_hold", &args, &[target, a], Agree::Exactly);
        }
    }
    // The states span the law: full throttle, full brake, in between (on the lap), the floor.
    assert!(
        full > 100 && braking > 10 && between > 1000,
        "{full} {braking} {between}"
    );
    assert!(floor > 10, "{floor} steps at the floor");
    let n = calls.run(&exe);
    assert!(n > 3 * trace.len(), "{n} calls");
}

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

/// The harness refuses what it does not know: a misspelt call or a short line fails the
/// run instead of answering something.
#[test]
fn the_harness_refuses_unknown_and_short_calls() {
    let Some(exe) = harness() else { return };
    for (i, input) in [
        "no_such_function 1 2\n",
        "bearing 1 2 3\n",
        "lookahead 1 2 3 4\n",
    ]
    .iter()
    .enumerate()
    {
        let path = exe.with_extension(format!("bad{i}"));
        std::fs::write(&path, input).unwrap();
        let out = Command::new(&exe)
            .stdin(std::fs::File::open(&path).unwrap())
            .output()
            .unwrap();
        assert!(!out.status.success(), "{input:?} was answered");
        assert!(String::from_utf8_lossy(&out.stdout).starts_with("error"));
    }
}
