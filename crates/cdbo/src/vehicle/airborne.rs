//! The body's heave over a crest: the car leaves the ground where the road falls away faster
//! than gravity and the wings can pull it down, flies, and lands, as TORCS's simuv2 moves it.
//!
//! In simuv2 the body is a mass on its four springs (`car.cpp` integrates its height under
//! the wheels' loads, gravity and the wings; `susp.cpp`: a spring's force is
//! F = max(0, F₀ + k·(x₀ − x)), never pulling; `wheel.cpp`: past the suspension's course x_max,
//! the `max_extend` of the wheel's travel, its load is 0). On the ground the springs push the
//! body along the road's vertical curve with the load the quasi-static model gives
//! ([`super`]): m·g·n + D, n = cos φ·cos β + vₓ²·κ_v/g the road's push per unit of the weight
//! and D the downforce. Over a crest (κ_v < 0) that load falls, and where it would be
//! negative no spring can hold the body to the road: the body rises, the springs lengthen to
//! their free length, and the wheels' loads are 0. car1-trb1's springs (a wheel rate of
//! 1.17 MN/m under some 2.8 kN) are free 2.4 mm above their static length, well inside
//! their 0.2 m course, so the travel's stop never comes into it and the car leaves the
//! ground where the quasi-static load reaches 0: at v² = g·R·cos φ over a crest of radius R
//! without wings.
//!
//! In the air the body's gap d above the place the road would hold it at, along the road's
//! normal, moves under gravity, the wings and the road falling away beneath it:
//! d̈ = −(m·g·n + D)/m, the negative of the load the road would need per unit mass. No wheel
//! carries a load, so no tyre grips and nothing rolls; the body flies on at its speed, its
//! yaw rate and the wheels' spins their own. Once the gap closes (d ≤ 0) the car lands:
//! the springs and dampers take the landing's vertical speed, and the loads are the
//! quasi-static ones again from that step on. Integrated semi-implicitly at the step:
//! ḋ ← ḋ + dt·d̈, d ← d + dt·ḋ.
//!
//! Approximations: the body heaves as one (simuv2's pitch and roll would lift one axle
//! before the other), the springs' free 2.4 mm and the landing's bounce are left out, and
//! the gap is measured at the car's station along the road's normal, not along the vertical.
//! On the ground (d = ḋ = 0 and the quasi-static load positive) nothing here is computed.

/// The body's height above the road's hold, while the car is in the air (module
/// documentation); zero on the ground.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Heave {
    /// The gap d between the body and the place the road would hold it at (m).
    gap: f64,
    /// Its rate ḋ (m/s).
    rate: f64,
}

impl Heave {
    /// Whether the car is in the air: its body above the road's hold.
    #[inline]
    pub fn in_air(&self) -> bool {
        self.gap > 0.0
    }

    /// The gap d above the road's hold (m), 0 on the ground.
    pub fn gap(&self) -> f64 {
        self.gap
    }

    /// Advances the heave by `dt` under `support`, the load per unit mass the road would
    /// need to hold the body to it, g·n + D/m (m/s²): the body leaves the ground, or stays
    /// in the air, while the road cannot hold it; it lands where the gap closes. Returns
    /// whether the car is in the air after the step (its wheels without load).
    #[inline]
    pub fn step(&mut self, support: f64, dt: f64) -> bool {
        if !self.in_air() && support >= 0.0 {
            return false;
        }
        self.rate -= dt * support;
        self.gap += dt * self.rate;
        if self.gap <= 0.0 {
            *self = Heave::default();
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

    /// On the ground, held by a road that can hold it, the body stays on it to the last bit.
    #[test]
    fn a_held_body_stays_on_the_ground() {
        let mut h = Heave::default();
        for support in [G, 0.0, 0.1, 30.0] {
            assert!(!h.step(support, 0.004));
            assert_eq!(h, Heave::default());
        }
    }

    /// Thrown up at 1 m/s on level ground (support g), the body lands after 2·ḋ/g, within a
    /// step, and its highest gap is ḋ²/(2g) within a step's rise.
    #[test]
    fn a_thrown_body_lands_after_its_ballistic_time() {
        let dt = 0.001;
        let mut h = Heave {
            gap: 0.0,
            rate: 1.0,
        };
        // The first step takes it up.
        h.gap = dt * h.rate;
        let (mut t, mut top) = (dt, 0.0f64);
        while h.step(G, dt) {
            t += dt;
            top = top.max(h.gap());
        }
        let want = 2.0 / G;
        assert!((t - want).abs() <= 2.0 * dt, "{t} against {want}");
        assert!((top - 0.5 / G).abs() < 2.0 * dt, "{top}");
    }
}
