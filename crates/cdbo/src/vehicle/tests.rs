use super::step::RearWheels;
use super::*;
use crate::car::DiffKind;

/// A level straight's frame.
fn level() -> Frame {
    let t = crate::track::Track::from_pieces(
        "straight",
        "test",
        &[crate::track::Piece::flat(500.0, 0.0)],
        vec![],
    );
    *t.frame(0)
}

/// The car mirrored: steering, lateral velocity, yaw rate, roll moment and the rear wheels
/// swapped left for right give the mirrored step, to the last bits (the Ackermann wheel,
/// the wheels' loads and the rear wheels' yaw moment take the right sides), for a limited
/// slip, a spool and a free differential, under drive and under the brakes.
#[test]
fn a_left_hand_turn_mirrors_a_right_hand_one() {
    for kind in [DiffKind::LimitedSlip, DiffKind::Spool, DiffKind::Free] {
        let mut car = Car::spirit_300();
        car.differential.kind = kind;
        let v = Vehicle::new(&car);
        let frame = level();
        for (throttle, brake) in [(0.8, 0.0), (0.0, 0.6)] {
            let mut left = v.at_rest(0.0, 0.0, 0.0);
            left.vx = 30.0;
            left.vy = 0.4;
            left.yaw_rate = 0.5;
            left.roll = 2000.0;
            left.omega = [30.0 / v.radius[0], 31.0 / v.radius[1], 32.0 / v.radius[1]];
            left.yaw_sin_cos = left.yaw.sin_cos();
            v.shift(&mut left, throttle);
            let mut right = left;
            right.vy = -left.vy;
            right.yaw_rate = -left.yaw_rate;
            right.roll = -left.roll;
            right.omega = [left.omega[0], left.omega[2], left.omega[1]];
            for _ in 0..50 {
                v.step(&mut left, &v.controls(0.1, throttle, brake), &frame, 0.004);
                v.step(
                    &mut right,
                    &v.controls(-0.1, throttle, brake),
                    &frame,
                    0.004,
                );
            }
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(1.0);
            assert!(close(left.vx, right.vx), "{kind:?}: {left:?} {right:?}");
            assert!(close(left.vy, -right.vy), "{kind:?}: {left:?} {right:?}");
            assert!(close(left.yaw_rate, -right.yaw_rate), "{kind:?}");
            assert!(close(left.roll, -right.roll), "{kind:?}");
            assert!(close(left.omega[1], right.omega[2]), "{kind:?}");
            assert!(close(left.omega[2], right.omega[1]), "{kind:?}");
            assert!(left.yaw_rate > 0.0 && left.roll > 0.0, "{kind:?}: {left:?}");
        }
    }
}

/// A wheel takes the surface under its centre: on a straight 12 m wide with a 2 m border
/// of friction 0.4 on the left and a sand side of 0.6 on the right, a car whose centre is
/// 5.5 m left of the centre line has its left wheels (0.7 to 0.8 m further out) on the
/// border and its right ones on the road; turned 90° to the left, its front wheels are on
/// the border and its rear ones on the road; 6.5 m right, its right wheels are on the
/// side; on the centre line, or on a road without verges, all four are on the road.
#[test]
fn each_wheel_takes_the_surface_under_it() {
    use crate::track::{Piece, Surface, Track, Verge};
    let border = Surface {
        friction: 0.4,
        rolling_resistance: Some(0.05),
        ..Surface::PLAIN
    };
    let sand = Surface {
        friction: 0.6,
        ..Surface::PLAIN
    };
    let piece = Piece {
        verges: [
            Verge {
                border_width: 2.0,
                border,
                ..Verge::NONE
            },
            Verge {
                side_width: 5.0,
                side: sand,
                ..Verge::NONE
            },
        ],
        ..Piece::flat(500.0, 0.0)
    };
    let t = Track::from_pieces("verges", "test", &[piece], vec![]);
    let frame = *t.frame(100);
    let v = Vehicle::new(&Car::spirit_300());
    let at = |y: f64, yaw: f64| {
        let mut s = v.at_rest(100.0, y, yaw);
        s.yaw_sin_cos = yaw.sin_cos();
        v.wheel_ground(&s, &frame)
            .map(|w| w.map(|g| (g.friction, g.rolling)))
    };
    let (road, rr) = (1.0, v.rolling);
    assert_eq!(at(0.0, 0.0), None);
    assert_eq!(
        at(5.5, 0.0),
        Some([(0.4, 0.05), (road, rr), (0.4, 0.05), (road, rr)])
    );
    assert_eq!(
        at(5.0, std::f64::consts::FRAC_PI_2),
        Some([(0.4, 0.05), (0.4, 0.05), (road, rr), (road, rr)])
    );
    assert_eq!(
        at(-6.5, 0.0),
        Some([(road, rr), (0.6, rr), (road, rr), (0.6, rr)])
    );
    let plain = Track::from_pieces("plain", "test", &[Piece::flat(500.0, 0.0)], vec![]);
    let mut s = v.at_rest(100.0, 5.5, 0.0);
    s.yaw_sin_cos = (0.0, 1.0);
    assert!(v.wheel_ground(&s, plain.frame(100)).is_none());
}

/// The reserve's wheels keep off slippery ground and raised kerbs, and nothing else: on a
/// straight 12 m wide with a flat kerb 1.5 m wide as grippy as the road then grass (0.4) on
/// the left, and a raised kerb 1 m wide then run-off asphalt on the right, a car heading
/// along the road with its wheels y_w out from its centre is too near once y + y_w + r
/// passes 6 + 1.5 on the left, and once −y + y_w passes 6 on the right (a wheel on the
/// kerb, whatever the reserve), to the millimetre; past the kerb, on the asphalt, it is
/// not; without verges, never.
#[test]
fn the_reserve_keeps_the_wheels_off_grass_and_raised_kerbs() {
    use crate::track::{Piece, Surface, Track, Verge};
    let grass = Surface {
        friction: 0.4,
        ..Surface::PLAIN
    };
    let piece = Piece {
        verges: [
            Verge {
                border_width: 1.5,
                side_width: 5.0,
                side: grass,
                ..Verge::NONE
            },
            Verge {
                border_width: 1.0,
                kerb_height: 0.1,
                side_width: 5.0,
                ..Verge::NONE
            },
        ],
        ..Piece::flat(500.0, 0.0)
    };
    let t = Track::from_pieces("verges", "test", &[piece], vec![]);
    let frame = *t.frame(100);
    let v = Vehicle::new(&Car::spirit_300());
    let wheel = v.car.axles.half_track[0].max(v.car.axles.half_track[1]);
    let near = |frame: &Frame, y: f64, reserve: f64| {
        let mut s = v.at_rest(100.0, y, 0.0);
        s.yaw_sin_cos = (0.0, 1.0);
        v.wheel_near_slippery(&s, frame, reserve, 0.8)
    };
    for reserve in [0.0, 0.25, 1.0] {
        let left = 7.5 - wheel - reserve;
        assert!(!near(&frame, left - 1e-3, reserve), "r = {reserve}");
        assert!(near(&frame, left + 1e-3, reserve), "r = {reserve}");
        let right = 6.0 - wheel;
        assert!(!near(&frame, -right + 1e-3, reserve), "r = {reserve}");
        assert!(near(&frame, -right - 1e-3, reserve), "r = {reserve}");
        assert!(near(&frame, -right - 0.99, reserve), "r = {reserve}");
    }
    // Every wheel past the raised kerb, on the asphalt beyond it.
    assert!(!near(&frame, -(7.0 + wheel + 0.1), 0.25));
    let plain = Track::from_pieces("plain", "test", &[Piece::flat(500.0, 0.0)], vec![]);
    assert!(!near(plain.frame(100), 7.0, 0.25));
}

/// The rolling resistance turns against the yaw as simuv2's `car.cpp` has it. One 4 ms
/// step of a car yawing at 0.6 rad/s on a road of c_rr = 0.01 loses R·L/2·dt/I_z more yaw
/// rate than on a road without rolling resistance, R = c_rr·(F_zf + F_zr) its rolling
/// resistance; a yaw slower than R·L/(2·I_z) loses r·dt, dying away over a second.
#[test]
fn the_rolling_resistance_turns_against_the_yaw() {
    let v = Vehicle::new(&Car::spirit_300());
    let (speed, c_rr, dt) = (30.0, 0.01, 0.004);
    let yaw_rate_after = |rolling: f64, yaw_rate: f64| {
        let mut frame = level();
        frame.rolling_resistance = Some(rolling);
        let mut s = v.at_rest(0.0, 0.0, 0.0);
        s.vx = speed;
        s.yaw_rate = yaw_rate;
        s.omega = [
            speed / v.radius[0],
            speed / v.radius[1],
            speed / v.radius[1],
        ];
        v.step(&mut s, &v.controls(0.0, 0.0, 0.0), &frame, dt);
        s.yaw_rate
    };
    let down = v.downforce_per_v2(speed);
    let loads = v.static_load[0] + v.static_load[1] + (down[0] + down[1]) * speed * speed;
    let turning = 0.5 * c_rr * loads * v.car.wheelbase * v.inv_yaw_inertia;
    let (fast, slow) = (0.6, 0.5 * turning);
    assert!(turning < fast, "{turning}");
    let lost = yaw_rate_after(0.0, fast) - yaw_rate_after(c_rr, fast);
    assert!(
        (lost - turning * dt).abs() < 1e-12,
        "{lost} against {}",
        turning * dt
    );
    let lost = yaw_rate_after(0.0, slow) - yaw_rate_after(c_rr, slow);
    assert!(
        (lost - slow * dt).abs() < 1e-12,
        "{lost} against {}",
        slow * dt
    );
}

/// The slipping launch clutch blends the engine's speed with the wheels' at the game's own
/// 2 ms step, whatever cdbo's: pulling away at half throttle with the clutch 70 % open
/// (τ = 0.3), the engine's speed after 0.15 s at steps of 2 and 4 ms agrees within 1 %
/// (blending by τ⁴ once per 4 ms step instead left it 23 % higher).
#[test]
fn the_launch_clutch_blends_at_the_games_step() {
    let v = Vehicle::new(&Car::spirit_300());
    let frame = level();
    let engine_after = |dt: f64| {
        let mut s = v.at_rest(0.0, 0.0, 0.0);
        s.clutch = 0.7;
        for _ in 0..(0.15 / dt).round() as usize {
            v.step(&mut s, &v.controls(0.0, 0.5, 0.0), &frame, dt);
        }
        s.engine_speed
    };
    let (fine, coarse) = (engine_after(GAME_STEP), engine_after(2.0 * GAME_STEP));
    assert!(fine > 1.05 * v.car.tickover, "{fine}: the engine revs");
    assert!(
        (coarse / fine - 1.0).abs() < 0.01,
        "{coarse} against {fine}"
    );
}

/// The lateral load transfer takes the roll moment up: the axles' transfers ΔF_a at ±y_a
/// give back M (Σ 2·ΔF_a·y_a = M), shared as the rates in roll times the tracks.
#[test]
fn the_wheels_take_up_the_roll_moment() {
    let car = Car::spirit_300();
    let v = Vehicle::new(&car);
    let (y, k) = (car.axles.half_track, car.axles.roll_rate);
    let moment = 2.0 * (v.roll_share[0] * y[0] + v.roll_share[1] * y[1]);
    assert!((moment - 1.0).abs() < 1e-12, "{moment}");
    let ratio = v.roll_share[0] / v.roll_share[1];
    assert!((ratio - k[0] * y[0] / (k[1] * y[1])).abs() < 1e-12);
}

/// The rear wheels stepped 4 ms as [`Vehicle::step`] steps them, with the brakes off, under
/// the drive torque `drive` at the axle (N·m), each under `load` on ground of `friction` and
/// moving at (v_t, v_l) = `velocity` (m/s, v_t > 0): their forces (Fₓ and Fᵧ, left and right).
fn step_rear(
    v: &Vehicle,
    s: &mut State,
    drive: f64,
    load: f64,
    (vt, vl): (f64, f64),
    friction: f64,
) -> ([f64; 2], [f64; 2]) {
    let diff = v.differential(s, drive);
    let (tyre, r) = (&v.tyres[1], v.radius[1]);
    let fmax = tyre.wheel_max_force(load, friction);
    let sy = -vl / vt.hypot(vl);
    let forces = diff.omega.map(|w| tyre.forces((w * r - vt) / vt, sy, fmax));
    let rear = RearWheels {
        forces,
        fmax: [fmax; 2],
        inv_denom: [1.0 / vt; 2],
        inv_axle: 1.0 / vt,
    };
    v.rear_wheels(s, 0.0, &diff, &rear, 0.004)
}

/// Through a spool the rear wheels turn as one; through a limited slip under a drive
/// torque T below its locking torque their speed ratio ends within ρ_s·(1 − T/T_lock);
/// through a free one, on a slippery road, the drive spins both up alike.
#[test]
fn the_differential_holds_the_rear_wheels_as_its_kind() {
    let r = Car::spirit_300().rear_tyre.radius;
    let spun = |kind: DiffKind, drive: f64, omega: [f64; 2], friction: f64| {
        let mut car = Car::spirit_300();
        car.differential.kind = kind;
        let v = Vehicle::new(&car);
        let mut s = v.at_rest(0.0, 0.0, 0.0);
        s.vx = 30.0;
        s.omega = [30.0 / r, omega[0], omega[1]];
        step_rear(&v, &mut s, drive, 3000.0, (30.0, 0.0), friction);
        [s.omega[1], s.omega[2]]
    };
    let w = spun(DiffKind::Spool, 500.0, [30.0 / r, 33.0 / r], 1.0);
    assert_eq!(w[0], w[1]);
    let diff = Car::spirit_300().differential;
    let drive = 600.0;
    let w = spun(DiffKind::LimitedSlip, drive, [30.0 / r, 36.0 / r], 1.0);
    let ratio = (w[0] - w[1]).abs() / (w[0].abs() + w[1].abs());
    assert!(
        ratio <= diff.slip_max * (1.0 - drive / diff.lock_torque) + 1e-12,
        "{ratio}"
    );
    // Both wheels on a road of friction 0.05, from rolling.
    let w = spun(DiffKind::Free, 800.0, [30.0 / r, 30.0 / r], 0.05);
    assert!(w[0] > 30.0 / r && (w[0] - w[1]).abs() < 1e-9, "{w:?}");
}

/// A wheel sliding at slip angle α slips sideways by sin α, as simuv2's `wheel.cpp` has it
/// (s_y = sin(atan2(v_l, v_t))): at α = 0.38 rad the tyre's lateral force is the one at
/// s_y = 0.371, 2 % short of what tan α = 0.4 would give.
#[test]
fn a_wheel_slips_sideways_by_the_sine_of_its_slip_angle() {
    let car = Car::spirit_300();
    let v = Vehicle::new(&car);
    let r = car.rear_tyre.radius;
    let (vt, vl, load) = (30.0, -12.0, 3000.0);
    let mut s = v.at_rest(0.0, 0.0, 0.0);
    s.vx = vt;
    s.omega = [vt / r; 3];
    let (_, fy) = step_rear(&v, &mut s, 0.0, load, (vt, vl), 1.0);
    let tyre = &v.tyres[1];
    let fmax = tyre.wheel_max_force(load, 1.0);
    let alpha = (-vl / vt).atan();
    let by = |sy: f64| tyre.forces(0.0, sy, fmax).fy;
    assert!((fy[0] - by(alpha.sin())).abs() < 1e-9 * fmax, "{fy:?}");
    assert!((by(alpha.tan()) - by(alpha.sin())).abs() > 1e-3 * fmax);
}

/// Between the table's speeds the downforce per v² is the car's within 0.1 %, and a car
/// without a ride height keeps its constant.
#[test]
fn the_downforce_table_follows_the_car() {
    let car = crate::car::tests::on_springs();
    let v = Vehicle::new(&car);
    for speed in [0.3, 7.77, 31.1, 55.55, 89.9, 149.0] {
        let exact = car.downforce(speed).map(|f| f / (speed * speed));
        let table = v.downforce_per_v2(speed);
        for k in 0..2 {
            assert!(
                (table[k] - exact[k]).abs() < 1e-3 * exact[k],
                "{speed}: {table:?} vs {exact:?}"
            );
        }
    }
    let plain = Vehicle::new(&Car::spirit_300());
    assert_eq!(
        plain.downforce_per_v2(42.0),
        Car::spirit_300().downforce(1.0)
    );
}

/// Over a crest of radius R the road's push per unit of weight, n = cos φ·cos β − v²/(g·R),
/// reaches 0 at v² = g·R·cos φ·cos β, the speed at which a body on a curve of radius R loses
/// contact: a car without downforce, sliding sideways at 0.5 m/s on the crest's top, feels
/// its tyres' side force at 0.99 times that speed and none at 1.01 times it (its wheels carry
/// no load), while on a level road it feels the same force at both speeds.
#[test]
fn over_a_crest_the_wheels_lose_their_load_at_the_closed_form_speed() {
    let mut car = Car::spirit_300();
    car.clift = [0.0; 2];
    car.wings = [crate::car::Wing::default(); 2];
    car.ride = None;
    let v = Vehicle::new(&car);
    let r = 100.0;
    let mut crest = level();
    crest.vertical_curvature = -1.0 / r;
    let take_off = (G * r * crest.cos_pitch * crest.cos_banking).sqrt();
    // The change of the sideways speed over one step, sliding at 0.5 m/s and rolling freely.
    let side = |frame: &Frame, speed: f64| {
        let mut s = v.at_rest(0.0, 0.0, 0.0);
        (s.vx, s.vy) = (speed, 0.5);
        v.set_wheel_speeds(&mut s, [speed; 3]);
        v.step(&mut s, &v.controls(0.0, 0.0, 0.0), frame, 0.004);
        s.vy - 0.5
    };
    for k in [0.99, 1.01] {
        assert!(
            side(&level(), k * take_off) < -0.01,
            "level road at {k} × {take_off} m/s"
        );
    }
    assert!(side(&crest, 0.99 * take_off) < -1e-4);
    assert_eq!(side(&crest, 1.01 * take_off), 0.0);
}
