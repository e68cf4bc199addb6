//! The body's heave over a crest: the car leaves the ground where the road falls away faster
//! than gravity, the wings and the springs can pull the body after it, flies, and lands, as
//! TORCS's simuv2 moves it.
//!
//! In simuv2 the body is a mass on its four springs (`car.cpp` integrates its height under
//! the wheels' loads, gravity and the wings; `susp.cpp`: a spring's force is
//! F = max(0, F₀ + k·(x₀ − x)), never pulling; `wheel.cpp`: past the suspension's course x_max,
//! the `max_extend` of the wheel's travel, its load is 0). On the ground the springs carry
//! the body along the road with the load the quasi-static model gives ([`super`]):
//! m·g·n + D, n = cos φ·cos β + vₓ²·κ_v/g the road's push per unit of the weight, κ_v the
//! vertical curvature over [`crate::track::VERTICAL_WINDOW_M`], and D the downforce. The
//! body leaves the road in two ways:
//!
//! - **The road curves away**: where that load would be negative no spring can hold the
//!   body to the road (at v² = g·R·cos φ over a crest of radius R without wings).
//! - **The road kinks away**: TORCS's heights are linear on steps of a few metres, so a
//!   crest is a run of kinks, at each of which the grade falls by Δφ at once and the ground
//!   drops away from the body at w = vₓ·Δφ. The wheels, light, follow it; the body, on
//!   springs of total rate K = Σ k carrying F, follows only as far as the springs' free
//!   length, F/K beyond their loaded one: with the energy F²/(2K) they hold they catch the
//!   body up to w_hold = F/√(K·m), F the load they carry, the quasi-static m·g·n + D: on a
//!   crest of kinks a few metres apart, closer than the springs' period, the body never
//!   settles back onto them between kinks, and they carry the smoothed curve's load. Past
//!   w_hold the springs run free and the body flies off at √(w² − w_hold²) (energy).
//!   car1-trb1's springs (wheel rates 119 kN/m, 5500 lbs/in with TORCS's pound a mass,
//!   times the bellcrank's 1.1²) run free 24 mm above their static length under some 2.8 kN
//!   a wheel, inside their 0.18 m of travel, so the travel's stop never comes into it;
//!   √(m/K) is 51 ms, and on a straight road at 43 m/s, with the wings' load (12 m/s² in
//!   all), they hold 0.6 m/s, less where the smoothed curve takes load off around a kink
//!   (by vₓ²·Δφ/W, W = [`crate::track::VERTICAL_WINDOW_M`]): a lone kink of about 1 % of
//!   grade throws the car. On G-Track 3 (kinks of 0.9, 1.8, 1.2 and 0.6 % every 4 m from
//!   1912 m) a policy the game's car leaves the road with flies at 1917 m for 0.07 s and
//!   at 1947 m for 0.09 s; the game's car, on the same inputs, holds its yaw rate still
//!   (in the air) over 1917 to 1924 m and 1950 to 1954 m. A car without springs
//!   ([`crate::car::Car::ride`]) leaves the road only where it curves away.
//!
//! In the air the body's gap d above the road, along its normal, moves under gravity and
//! the wings, d̈ = −(g·cos φ·cos β + D/m), while the road beneath turns away from it at each
//! step by its own change of grade: ḋ ← ḋ + vₓ·Δφ (the road's curve, kinks and all, here as
//! the stations' grades give it, in place of the quasi-static load's smoothed κ_v). No wheel
//! carries a load, so no tyre grips and nothing rolls; the body flies on at its speed, its
//! yaw rate and the wheels' spins their own. Once the gap closes (d ≤ 0) the car lands: the
//! springs and dampers take the landing's vertical speed, and the loads are the
//! quasi-static ones again from that step on. Integrated semi-implicitly at the step:
//! ḋ ← ḋ + vₓ·Δφ − dt·(g·cos φ·cos β + D/m), d ← d + dt·ḋ.
//!
//! Approximations: the body heaves as one (simuv2's pitch and roll would lift one axle
//! before the other), the landing's bounce is left out, the gap is measured along the
//! road's normal, each kink is met by springs at rest (where a kink follows another within
//! their period, 0.3 s for car1-trb1, simuv2's body may still be bouncing off the first),
//! and a kink is met where the car's station changes, within half a station's spacing of
//! its place. On the ground, with the road's grade unchanged since the
//! last step and the quasi-static load positive, nothing here is computed but that grade
//! kept.

use crate::car::G;
use crate::track::Frame;

/// The body's height above the road while the car is in the air (module documentation),
/// and the road's grade under it at the last step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Heave {
    /// The gap d between the body and the road (m), 0 on the ground.
    gap: f64,
    /// Its rate ḋ (m/s).
    rate: f64,
    /// (sin φ, cos φ) of the road's grade φ under the car at the last step; (0, 0) before
    /// the first, which then meets no kink.
    grade: (f64, f64),
    /// Whether the car is in the air.
    flying: bool,
}

/// What holds the body to the road at a step (module documentation), per unit mass.
#[derive(Debug, Clone, Copy)]
pub struct Hold {
    /// The quasi-static load per unit mass, g·n + D/m (m/s²), n with the smoothed κ_v.
    pub load: f64,
    /// The downforce per unit mass, D/m (m/s²).
    pub down: f64,
    /// √(m/K) of the car's springs (s), K their total rate; `None` without springs.
    pub springs: Option<f64>,
}

impl Heave {
    /// Whether the car is in the air.
    #[inline]
    pub fn in_air(&self) -> bool {
        self.flying
    }

    /// The gap d above the road (m), 0 on the ground.
    pub fn gap(&self) -> f64 {
        self.gap
    }

    /// Advances the heave by `dt` at forward speed `vx` on the road of `frame`, held by
    /// `hold`: the body leaves the ground, or stays in the air, while the road cannot hold
    /// it; it lands where the gap closes. Returns whether the car is in the air after the
    /// step (its wheels without load).
    #[inline]
    pub fn step(&mut self, frame: &Frame, vx: f64, hold: &Hold, dt: f64) -> bool {
        let (sin0, cos0) = self.grade;
        self.grade = (frame.sin_pitch, frame.cos_pitch);
        // sin Δφ of the grade's fall since the last step: positive where the road turns
        // down (over a crest).
        let fall = sin0 * frame.cos_pitch - cos0 * frame.sin_pitch;
        // Gravity and the wings across the road, per unit mass.
        let weight = || G * frame.cos_pitch * frame.cos_banking + hold.down;
        if !self.in_air() {
            if hold.load < 0.0 {
                // The road curves away faster than the body can fall: it rises off it at
                // the rate the smoothed curve's excess gives it over the step.
                self.flying = true;
                self.rate = -dt * hold.load;
                self.gap = dt * self.rate;
                return true;
            }
            let Some(springs) = hold.springs.filter(|_| fall > 0.0) else {
                return false;
            };
            // The springs meet the kink carrying the quasi-static load.
            let (w, caught) = (vx * fall, hold.load * springs);
            if w <= caught {
                return false;
            }
            // The road kinks away faster than the springs can pull the body after it: the
            // body flies off at what their energy leaves of w.
            self.flying = true;
            self.rate = (w * w - caught * caught).sqrt() - w;
        }
        self.rate += vx * fall - dt * weight();
        self.gap += dt * self.rate;
        if self.gap <= 0.0 {
            if hold.load < 0.0 {
                // The road's stations turn it in steps, but on the whole it still curves
                // away faster than the body falls: the body skims it, unloaded.
                (self.gap, self.rate) = (0.0, 0.0);
                return true;
            }
            *self = Heave {
                grade: self.grade,
                ..Heave::default()
            };
            return false;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::car::{Car, G};
    use crate::track::{Piece, Track};
    use crate::vehicle::{State, Vehicle};

    /// Where the crest starts (m): the road is level before it.
    const CREST_AT: f64 = 100.0;

    /// A straight road along x, level to [`CREST_AT`], then a crest of radius `radius` (m)
    /// falling away to the grade angle −`angle` (rad), then straight down at it: heights
    /// z = √(R² − u²) − R at u = x − x_c ≤ R·sin Φ, then on the tangent, on 10 cm pieces.
    fn crest(radius: f64, angle: f64) -> Track {
        let end = radius * angle.sin();
        let z = |x: f64| {
            let u = (x - CREST_AT).max(0.0);
            if u <= end {
                (radius * radius - u * u).sqrt() - radius
            } else {
                radius * (angle.cos() - 1.0) - angle.tan() * (u - end)
            }
        };
        let ds = 0.1;
        let pieces: Vec<Piece> = (0..4000)
            .map(|i| Piece {
                z0: z(i as f64 * ds),
                z1: z((i + 1) as f64 * ds),
                ..Piece::flat(ds, 0.0)
            })
            .collect();
        Track::from_pieces("crest", "test", &pieces, vec![])
    }

    /// The paper's car without lift or drag: nothing but gravity and the road holds it down,
    /// and its speed keeps in the air.
    fn wingless() -> Vehicle {
        let mut car = Car::spirit_300();
        car.clift = [0.0; 2];
        car.cx = 0.0;
        Vehicle::new(&car)
    }

    /// Steps the car by `dt` on the frame under it, steered by `steer` (rad) and coasting.
    fn drive(v: &Vehicle, t: &Track, s: &mut State, steer: f64, dt: f64) {
        let frame = t.frame(t.index_at(s.x));
        v.step(s, &v.controls(steer, 0.0, 0.0), frame, dt);
    }

    /// Over a crest of radius R the road holds a car without wings while m·V²/R ≤ m·g·cos φ
    /// (simuv2's body on its springs, V the speed along the road): 5 m into a crest of
    /// 100 m, at 1 % below that speed the car keeps its grip (steering one way or the other
    /// turns it differently), at 1 % above it its wheels carry no load (the steering turns
    /// nothing) and it is in the air.
    #[test]
    fn the_wheels_lose_their_load_at_the_crests_speed() {
        let (radius, v) = (100.0, wingless());
        let t = crest(radius, 0.3);
        let u: f64 = 5.0;
        let phi = (u / radius).asin();
        // The plan's speed vₓ = V·cos φ.
        let limit = (G * radius * phi.cos()).sqrt() * phi.cos();
        for (scale, flies) in [(0.99, false), (1.01, true)] {
            let vx = scale * limit;
            let start = v.under_way((CREST_AT + u, 0.0, 0.0), (vx, 0.0, 0.0), 0.0, 4);
            let (mut left, mut right) = (start, start);
            drive(&v, &t, &mut left, 0.1, 0.004);
            drive(&v, &t, &mut right, -0.1, 0.004);
            assert_eq!(left.heave.in_air(), flies, "at {vx} m/s");
            assert_eq!(left.yaw_rate == right.yaw_rate, flies, "at {vx} m/s");
            assert_eq!(left.vy == right.vy, flies, "at {vx} m/s");
        }
    }

    /// Over a crest of 100 m falling away to −0.2 rad at 50 m/s (V²/R = 25 m/s², past g),
    /// the car leaves the road where the crest starts and flies the ballistic arc
    /// z = −g·x²/(2v²) until it meets the road beyond, on the tangent z = z₁ − tan Φ·(x − x₁)
    /// (x₁ = R·sin Φ, z₁ = R·(cos Φ − 1)): g·x²/(2v²) − tan Φ·x + z₁ + tan Φ·x₁ = 0, its far
    /// root over v the flight's time, 1.84 s. cdbo's flight lasts that within 6 % (1.76 s at
    /// 2448145): its crest's curvature is spread over [`crate::track::VERTICAL_WINDOW_M`], of
    /// which the road holds the first metres' share before the car leaves it (2 % of the
    /// flight), and gravity along the road speeds the car up in the air where the ballistic
    /// arc keeps its horizontal speed. It leaves within 2 m of the crest's start.
    #[test]
    fn over_a_crest_the_car_flies_for_its_ballistic_time() {
        let (radius, angle, speed) = (100.0, 0.2, 50.0);
        let (v, t) = (wingless(), crest(radius, angle));
        let mut s = v.under_way((CREST_AT - 20.0, 0.0, 0.0), (speed, 0.0, 0.0), 0.0, 4);
        let dt = 0.004;
        let (mut time, mut took_off, mut landed) = (0.0, None, None);
        while landed.is_none() && time < 3.0 {
            drive(&v, &t, &mut s, 0.0, dt);
            time += dt;
            match (took_off, s.heave.in_air()) {
                (None, true) => took_off = Some((time, s.x, s.vx)),
                (Some(_), false) => landed = Some(time),
                _ => {}
            }
        }
        let (start, x, vx) = took_off.expect("the car leaves the road");
        let flight = landed.expect("the car lands") - start;
        assert!((x - CREST_AT).abs() < 2.0, "took off at {x} m");
        let (x1, z1, slope) = (
            radius * angle.sin(),
            radius * (angle.cos() - 1.0),
            angle.tan(),
        );
        let a = G / (2.0 * vx * vx);
        let c = z1 + slope * x1;
        let reach = (slope + (slope * slope - 4.0 * a * c).sqrt()) / (2.0 * a);
        let want = reach / vx;
        assert!(
            (flight / want - 1.0).abs() < 0.06,
            "flew {flight} s, ballistic {want} s"
        );
    }

    /// A straight road along x, level to 50 m, then straight down at the grade −`fall`: one
    /// kink at 50 m. Its frames before and after it.
    fn kink(fall: f64) -> (Frame, Frame) {
        let mut down = Piece::flat(100.0, 0.0);
        down.z1 = -100.0 * fall;
        let t = Track::from_pieces("kink", "test", &[Piece::flat(50.0, 0.0), down], vec![]);
        (*t.frame(t.index_at(25.0)), *t.frame(t.index_at(75.0)))
    }

    /// On the ground, held by a road that neither curves nor kinks away, the body stays on
    /// it, whatever its load, with or without springs.
    #[test]
    fn a_held_body_stays_on_the_ground() {
        let (level, _) = kink(0.0);
        for springs in [None, Some(0.016)] {
            let mut h = Heave::default();
            for load in [G, 0.0, 0.1, 30.0] {
                let hold = Hold {
                    load,
                    down: 0.0,
                    springs,
                };
                assert!(!h.step(&level, 40.0, &hold, 0.004));
                assert!(!h.in_air() && h.rate == 0.0 && h.gap == 0.0);
            }
        }
    }

    /// Over a kink where the grade falls by Δφ at 40 m/s, springs of √(m/K) = 16 ms under the
    /// weight g catch the body up to w_hold = g·√(m/K) = 0.157 m/s: at w = vₓ·Δφ 2 % below it
    /// the car stays on the ground, at twice it it flies off at √(w² − w_hold²) and lands
    /// after 2·√(w² − w_hold²)/(g·cos φ), within a step (1 ms); a car without springs meets
    /// the kink on the ground.
    #[test]
    fn a_kink_throws_the_body_past_what_the_springs_hold() {
        let (speed, springs, dt) = (40.0, 0.016, 0.001);
        let caught = G * springs;
        let flight = |w: f64, springs: Option<f64>| -> f64 {
            let (before, after) = kink(w / speed);
            let mut h = Heave::default();
            let hold = Hold {
                load: G,
                down: 0.0,
                springs,
            };
            assert!(!h.step(&before, speed, &hold, dt));
            let mut time = 0.0;
            while h.step(&after, speed, &hold, dt) {
                time += dt;
            }
            time
        };
        assert_eq!(flight(0.98 * caught, Some(springs)), 0.0);
        assert_eq!(flight(2.0 * caught, None), 0.0);
        let w = 2.0 * caught;
        let (_, after) = kink(w / speed);
        let rate = (w * w - caught * caught).sqrt();
        let want = 2.0 * rate / (G * after.cos_pitch);
        let got = flight(w, Some(springs));
        assert!((got - want).abs() <= 1.5 * dt, "{got} against {want}");
    }
}
