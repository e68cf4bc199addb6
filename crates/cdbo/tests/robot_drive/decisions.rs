//! The robot's pedal, speed hold, PI steering, gearbox, launch clutch, traction control and ABS
//! against the Rust, on every driver step of the demonstration's lap and a learned policy's.

use crate::common::builtin;
use crate::{Agree, Calls, LEARNED, harness, lap, written};
use cdbo::car::Car;
use cdbo::drive::demo::{self, SpeedHold};
use cdbo::drive::steering::{self, PiSteering};
use cdbo::drive::{Observation, Pedal, pedal_command, pi_control, run_up_pedal};
use cdbo::geometry;
use cdbo::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use cdbo::policy::{PolicyTable, RkhsPolicy};
use cdbo::sim::Simulator;
use cdbo::track::builtin::DEFAULT;
use cdbo::vehicle::SLIP_SPEED_FLOOR;
use cdbo::vehicle::aids::abs::abs_brake;
use cdbo::vehicle::aids::launch::{LaunchCar, launch_clutch};
use cdbo::vehicle::aids::traction::traction_throttle;
use cdbo::vehicle::powertrain::{DOWNSHIFT_MARGIN, Gearbox, THROTTLE_LEVELS};

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
    // A flying lap's run-up: the floor below, at and above its speed.
    for (a, speed) in [
        (-1.0, 0.0),
        (-0.3, 9.5),
        (0.2, 9.0),
        (-1.0, 10.0),
        (-0.6, 10.4),
        (-1.0, 30.0),
    ] {
        let floored = run_up_pedal(a, speed);
        calls.check(
            "run-up",
            "run_up_pedal",
            &[a, speed],
            &[floored],
            Agree::Exactly,
        );
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
    let table_args = written(&table_args);
    let rkhs_args = [&policy, &fit].map(|rkhs| {
        let mut args = vec![rkhs.lengthscale, rkhs.kernels() as f64];
        args.extend(&rkhs.weights);
        written(&args)
    });

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
            let policies = [(&policy, &learned_pedal), (&fit, &fit_pedal)];
            for ((rkhs, pedal), first) in policies.into_iter().zip(&rkhs_args) {
                let (x, raw) = (&[p.x], rkhs.raw(p.x));
                calls.check_after(&at, "rkhs", first, x, &[raw], Agree::Exactly);
                let o1 = pedal.raw(p.x);
                calls.check_after(&at, "rkhs", first, x, &[o1], Agree::Within(1e-12));
            }
            let action = table.action(p.x);
            calls.check_after(&at, "table", &table_args, &[p.x], &[action], Agree::Exactly);

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
