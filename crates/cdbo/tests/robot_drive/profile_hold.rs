//! The robot's profile hold (the calibration's fast probe) against the Rust, on every driver step
//! of the probe's lap.

use crate::common::builtin;
use crate::{Agree, Calls, harness, lap};
use cdbo::calibrate::ProbePedal;
use cdbo::car::Car;
use cdbo::drive::profile::ProfileHold;
use cdbo::drive::{Observation, Pedal, pedal_command};
use cdbo::sim::Simulator;
use cdbo::track::builtin::DEFAULT;

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
