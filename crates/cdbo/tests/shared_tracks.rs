//! The paper's real tracks, read from ../shared (the TORCS / Speed Dreams data, never copied).

mod common;

use cdbo::track::{Ends, Track, torcs};
use common::shared;

fn load(rel: &str) -> Track {
    let t = torcs::read(&shared(rel), Ends::MustMeet).unwrap_or_else(|e| panic!("{e}"));
    // The shared subset lacks objects.xml: that entity is skipped with a warning; every
    // surface must still be found.
    assert!(
        t.warnings.iter().all(|w| !w.contains("surface")),
        "{:?}",
        t.warnings
    );
    t
}

fn assert_closed(t: &Track) {
    assert!(
        t.closure.gap_m < 2.0,
        "{}: gap {} m",
        t.name,
        t.closure.gap_m
    );
    assert!(
        t.closure.heading_deg.abs() < 1.0,
        "{}: heading {}°",
        t.name,
        t.closure.heading_deg
    );
}

#[test]
fn forza_has_the_papers_length_and_width() {
    let t = load("torcs/tracks/road/forza/forza.xml");
    assert!((t.length - 5784.1).abs() < 0.5, "length {}", t.length);
    assert_eq!(t.samples[0].width, 11.0);
    assert_eq!(t.name, "Forza");
    assert_closed(&t);
}

#[test]
fn allondaz_has_the_papers_length_and_width() {
    let t = load("speed-dreams/tracks/road/allondaz/allondaz.xml");
    assert!((t.length - 6355.6).abs() < 0.5, "length {}", t.length);
    assert_eq!(t.samples[0].width, 12.0);
    assert_closed(&t);
}

#[test]
fn e_track_2_and_aalborg_match_torcs() {
    let t = load("torcs/tracks/road/e-track-2/e-track-2.xml");
    assert!((t.length - 5380.5).abs() < 0.5, "length {}", t.length);
    assert_closed(&t);
    let t = load("torcs/tracks/road/aalborg/aalborg.xml");
    assert!((t.length - 2587.5).abs() < 0.5, "length {}", t.length);
    assert_eq!(t.samples[0].width, 10.0);
    assert_closed(&t);
}

#[test]
fn monza_centre_line_is_closed_and_has_its_length() {
    let t = cdbo::track::csv::read(&shared("tracks/csv/Monza.csv")).unwrap();
    assert!((t.length - 5790.0).abs() < 10.0, "length {}", t.length);
    assert!(t.min_radius() > 5.0, "min radius {}", t.min_radius());
    eprintln!(
        "Monza: {} m, min radius {} m, min width {} m",
        t.length,
        t.min_radius(),
        t.min_width()
    );
}

#[test]
fn tracks_are_found_by_name_in_data_folders() {
    use cdbo::data_path::DataPath;
    let data = DataPath::with_env(&[shared("")], "");
    let t = cdbo::track::catalog::find("forza", &data).unwrap();
    assert!((t.length - 5784.1).abs() < 0.5);
    let t = cdbo::track::catalog::find("allondaz", &data).unwrap();
    assert!((t.length - 6355.6).abs() < 0.5);
    let t = cdbo::track::catalog::find("monza", &data).unwrap();
    assert!((t.length - 5790.0).abs() < 10.0);
    let e = cdbo::track::catalog::find("nowhere-ring", &data)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("nowhere-ring") && e.contains("ridgeway") && e.contains("shared"),
        "{e}"
    );
}

#[test]
fn spirit_300_from_its_files_equals_the_builtin_car() {
    use cdbo::car::{Car, Tyre, catalog, torcs};
    let car = torcs::read(
        &shared("speed-dreams/cars/models/sc-spirit-300/sc-spirit-300.xml"),
        None,
    )
    .unwrap();
    let builtin = Car::spirit_300();
    assert_eq!(car.name, "Spirit 300");
    // What the game's simuv2 adds to the paper's car (the built-in keeps the paper's
    // figures): the file's 70 l of fuel to the mass moved, the camber's grip (−3° front, −2°
    // rear: 1 + 0.05·sin(−18γ)), a yaw inertia from the body's size, the ride height.
    assert_eq!(car.mass, builtin.mass + 70.0);
    for (tyre, camber, base) in [
        (&car.front_tyre, -3.0f64, &builtin.front_tyre),
        (&car.rear_tyre, -2.0, &builtin.rear_tyre),
    ] {
        let grip = 1.0 + 0.05 * (-18f64 * camber.to_radians()).sin();
        assert!(
            (tyre.mu - base.mu * grip).abs() < 1e-9,
            "{} vs {}",
            tyre.mu,
            base.mu
        );
    }
    let yaw = 1440.0 * (1.90f64.powi(2) + (0.62f64 * 4.2).powi(2)) / 12.0;
    assert!(
        (car.yaw_inertia() - yaw).abs() < 1e-6 * yaw,
        "{}",
        car.yaw_inertia()
    );
    assert!(car.ride.is_some());
    for (a, b, what) in [
        (car.cg_height, builtin.cg_height, "cg"),
        (car.front_weight, builtin.front_weight, "front weight"),
        (car.wheelbase, builtin.wheelbase, "wheelbase"),
        (car.cx, builtin.cx, "cx"),
        (car.front_area, builtin.front_area, "area"),
        (car.peak_torque(), builtin.peak_torque(), "torque"),
        (car.rev_limiter, builtin.rev_limiter, "limiter"),
        (car.final_drive, builtin.final_drive, "final drive"),
        (car.shift_time, builtin.shift_time, "shift time"),
        (
            car.front_tyre.radius,
            builtin.front_tyre.radius,
            "front radius",
        ),
        (
            car.rear_tyre.radius,
            builtin.rear_tyre.radius,
            "rear radius",
        ),
        (
            car.front_tyre.dynamic_friction,
            builtin.front_tyre.dynamic_friction,
            "dyn friction",
        ),
        (
            car.brake_torque(true),
            builtin.brake_torque(true),
            "front brake",
        ),
        (
            car.brake_torque(false),
            builtin.brake_torque(false),
            "rear brake",
        ),
        (car.steer_lock, builtin.steer_lock, "steer lock"),
    ] {
        assert!(
            (a - b).abs() <= 1e-9 * b.abs().max(1.0),
            "{what}: {a} vs {b}"
        );
    }
    assert_eq!(car.gears, builtin.gears);
    // The category's curve runs on past the car's last point (above the limiter, unused).
    assert_eq!(
        car.torque_curve[..builtin.torque_curve.len()],
        builtin.torque_curve[..]
    );
    assert_eq!(
        car,
        Car {
            torque_curve: car.torque_curve.clone(),
            mass: car.mass,
            yaw_inertia_factor: car.yaw_inertia_factor,
            ride: car.ride,
            front_tyre: Tyre {
                mu: car.front_tyre.mu,
                skid: cdbo::car::torcs::SKID_FACTOR,
                ..builtin.front_tyre
            },
            rear_tyre: Tyre {
                mu: car.rear_tyre.mu,
                skid: cdbo::car::torcs::SKID_FACTOR,
                ..builtin.rear_tyre
            },
            // The game's car, as cdbo's robot drives it.
            torcs_robot: true,
            ..builtin
        }
    );
    let data = cdbo::data_path::DataPath::with_env(&[shared("")], "");
    assert_eq!(
        catalog::find("sc-spirit-300", &data).unwrap().mass,
        1440.0 + 70.0
    );
    let trb1 = catalog::find("car1-trb1", &data).unwrap();
    assert!(trb1.mass > 500.0 && !trb1.gears.is_empty());
    // Its wings (front 0.25 m² at 6°, rear 0.7 m² at 14°) add 1.23·A·sin α to the drag and four
    // times that to the downforce; the engine brakes with simuv2's default coefficient.
    let wings = 1.23 * (0.25 * 6f64.to_radians().sin() + 0.7 * 14f64.to_radians().sin());
    let body = 0.645 * 0.35 * 1.92;
    assert!(
        (trb1.drag(1.0) - body - wings).abs() < 1e-9,
        "{}",
        trb1.drag(1.0)
    );
    // The body's lift is simuv2's Cl·v²·h(Σ), h(Σ) = 2·exp(−3·(1.5·Σ)⁴), at the ride heights
    // (90 mm front, 105 mm rear under the wheels' loads without fuel) less what the 94 kg of
    // fuel compresses the springs (5500 lbs/in through a bellcrank of 1.1).
    assert_eq!(trb1.mass, 1150.0 + 94.0);
    let rate = 5500.0 * 0.453_592_37 / 0.0254 * 1.1 * 1.1;
    let fuel_load =
        |share: f64| 94.0 * 9.81 * share / 2.0 + 1150.0 * (9.81 - 9.80665) * share / 2.0;
    let sum = 2.0 * (0.090 - fuel_load(0.52) / rate) + 2.0 * (0.105 - fuel_load(0.48) / rate);
    let h = 2.0 * (-3.0 * (1.5 * sum).powi(4)).exp();
    let [front, rear] = trb1.downforce(1.0);
    let lift = (0.69 + 0.7) * h;
    // (within 0.1 %: at 1 m/s the downforce's own 3 N sink the car by some 10 µm more)
    assert!(
        (front + rear - lift - 4.0 * wings).abs() < 1e-3 * lift,
        "{} vs {}",
        front + rear,
        lift + 4.0 * wings
    );
    assert!((h - 1.45).abs() < 0.01, "{h}");
    assert!(rear > front, "the rear wing loads the rear axle");
    // Each wing's drag at its height (front 0.04 m, rear 0.99 m) pitches the body as simuv2's
    // car.cpp does, M_y −= Fₓ·z: it loads the front axle by Σ 1.23·A·sin α·z / L, L = 2.64 m
    // between the axles (196 N at 50 m/s).
    let pitch = 1.23
        * (0.25 * 6f64.to_radians().sin() * 0.04 + 0.7 * 14f64.to_radians().sin() * 0.99)
        / (1.22 + 1.42);
    assert!(
        (trb1.wing_pitch_per_v2() - pitch).abs() < 1e-12,
        "{}",
        trb1.wing_pitch_per_v2()
    );
    assert!((pitch * 2500.0 - 196.5).abs() < 0.1, "{}", pitch * 2500.0);
    assert_eq!(trb1.engine_brake, 0.33);
    assert!((trb1.revs_max - 10_000.0 * std::f64::consts::PI / 30.0).abs() < 1e-9);
}

/// A file missing from ../shared fails its test with its name and where to get it.
#[test]
fn a_missing_shared_file_is_named_with_where_to_get_it() {
    for (rel, source) in [
        ("torcs/tracks/road/nowhere/nowhere.xml", "torcs-data"),
        (
            "speed-dreams/tracks/road/nowhere/nowhere.xml",
            "Speed Dreams",
        ),
    ] {
        let panic = std::panic::catch_unwind(|| shared(rel)).unwrap_err();
        let message = panic.downcast_ref::<String>().unwrap();
        assert!(
            message.contains(&format!("../shared/{rel}")) && message.contains(source),
            "{message}"
        );
    }
}

/// car1-trb1 pulling away at a constant pedal round a 60 m circle runs wide until it leaves
/// the road; on a rough road (1 cm at λ = 1 m, as G-Track 1's) its wheels bounce and the tyres
/// grip less, so it leaves sooner and slower. Its suspension is read from its file (dampers
/// 400 / 300 lbs/in/s slow, 60 fast, 20 kg wheels); a road rough by less than
/// [`cdbo::track::FELT_ROUGHNESS_M`] drives as a smooth one, to the last bit.
#[test]
fn a_rough_road_takes_car1_trb1s_grip() {
    use cdbo::drive::ConstantPedal;
    use cdbo::sim::Simulator;
    use cdbo::track::{Piece, Roughness};
    let car = common::shared_car("car1-trb1");
    let ride = car.ride.unwrap();
    let lbs_in_s = 0.453_592_37 / 0.0254;
    assert!((ride.dampers[0].bump.slow - 400.0 * lbs_in_s).abs() < 1e-9);
    assert!((ride.dampers[1].rebound.slow - 400.0 * lbs_in_s).abs() < 1e-9);
    assert!((ride.dampers[0].bump.fast - 60.0 * lbs_in_s).abs() < 1e-9);
    assert_eq!(
        (ride.dampers[0].bump.threshold, ride.wheel_mass),
        (0.5, [20.0, 20.0])
    );
    assert_eq!(ride.bellcrank, [1.1, 1.1]);
    let lap = |roughness: Roughness, car: &cdbo::car::Car| {
        let circle = Piece {
            roughness,
            ..Piece::flat(2.0 * std::f64::consts::PI * 60.0, 1.0 / 60.0)
        };
        let track = Track::from_pieces("circle", "test", &[circle], vec![]);
        let mut sim = Simulator::new(track, car);
        sim.config.trace = true;
        sim.lap(&mut ConstantPedal(1.0))
    };
    let smooth = lap(Roughness::NONE, &car);
    let rough = lap(Roughness::from_file(0.01, 1.0), &car);
    let (s, r) = (smooth.failure.unwrap(), rough.failure.unwrap());
    let speed = |l: &cdbo::sim::LapResult| l.trace.last().unwrap().speed;
    assert!(r.distance_m < s.distance_m, "{r:?} against {s:?}");
    assert!(
        speed(&rough) < 0.99 * speed(&smooth),
        "{} against {}",
        speed(&rough),
        speed(&smooth)
    );
    let faint = lap(Roughness::from_file(0.0009, 1.0), &car);
    assert_eq!((faint.failure, faint.trace), (smooth.failure, smooth.trace));
}

/// The path tracker does not ring on car1-trb1 at speed: holding 25 m/s round Forza on the
/// centre line, the steering's second difference averages less than 1 mrad a driver step
/// (without the one-step bound on the yaw-rate gain, `drive::tracker::YAW_STEP_GAIN`, 170 mrad:
/// the steering alternated step by step, in the game too).
#[test]
fn the_tracker_does_not_ring_on_car1_trb1_at_speed() {
    let car = common::shared_car("car1-trb1");
    let track = common::shared_track("forza");
    let steering = cdbo::drive::steering::Steering::Tracker(Default::default());
    let venue = cdbo::venue::Venue::simulator(track, &car).steered(steering);
    let (demo, _) = venue.demonstrate(25.0).unwrap();
    assert!(demo.completed, "{:?}", demo.failure);
    let steer: Vec<f64> = demo.trace.iter().map(|p| p.steer).collect();
    let ring = steer
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
        .sum::<f64>()
        / (steer.len() - 2) as f64;
    assert!(ring < 1e-3, "{ring} rad a step");
}
