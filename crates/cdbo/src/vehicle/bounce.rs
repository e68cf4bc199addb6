//! The wheels' bounce over a rough road and the road's kinks, as TORCS's simuv2 moves each
//! wheel up and down (`wheel.cpp`: `SimWheelUpdateRide`, `SimWheelUpdateForce`; `susp.cpp`:
//! `SimSuspUpdate`).
//!
//! The ground under a wheel stands h above the smooth surface ([`crate::track::Bumps`]): a
//! rough road's bumps ([`crate::track::Roughness`]) and the road's kinks
//! ([`crate::track::Frame::kinks`]). TORCS's heights are linear on steps of a few metres: at a
//! step's end the grade changes at once, and simuv2's wheel meets the change as a step in the
//! ground's vertical speed, v·Δgrade, which the suspension turns into a load transient a
//! tenth of a second long, front wheels first. The car's quasi-static load takes the grade's
//! changes spread over [`crate::track::VERTICAL_WINDOW_M`]; the wheel meets the rest here.
//! Measured against the game's laps: at these kinks the game's car1-trb1 jolts (its yaw rate
//! away and back by 0.2 to 0.5 rad/s within 0.1 s: 13 of 17 such jolts on the 20 learned
//! policies' laps within 4 m of a kink past the random place's 90th percentile), and replayed
//! from the game's logs cdbo's car with the kinks parts from it by 20 % less in yaw rate on
//! the road and 32 % less under braking (docs/results/torcs.md).
//! At simuv2's own step Δt = 2 ms ([`SIMUV2_STEP`]), each wheel with e its suspension's
//! extension past the quasi-static length (m, at the wheel), u its speed towards the body
//! (simuv2's `rel_vel`), b the rise of the body's corner above it and F_qs the load the car's
//! quasi-static model gives the wheel ([`super`]):
//!
//! - e ← e − u·Δt, and where that puts the wheel below the ground, e ← b − h and u ← 0 (the
//!   ground pushes the wheel up: `max_extend`);
//! - the damper moves at v = β·(e′ − e)/Δt (e′ the extension before, positive in bump; β the
//!   bellcrank's ratio) and the wheel's load is F = max(0, max(0, F_qs − k·e) + β·D(v)), the
//!   spring's force never negative and the damper at best cancelling it; k = K·β² the wheel
//!   rate, D the [`crate::car::Damper`];
//! - u ← u − Δt·F/m_w (the load pushes the wheel back down; m_w its mass);
//! - the body's corner, a quarter of the body of mass m_c = F₀/g (F₀ the wheel's static
//!   load), rises on what the load carries past F_qs: b̈ = (F − F_qs)/m_c, so that over time
//!   the load's mean is F_qs again, as simuv2's body heaves.
//!
//! simuv2's tyre gives F·μ·λ(F) times its slip's shape at every step, λ its load sensitivity,
//! so over cdbo's step the wheel grips as the mean of F·λ(F) over the sub-steps: the wheel's
//! surface friction is scaled by mean(F·λ(F)) / (F_qs·λ(F_qs)) ([`step`]). On Aalborg's
//! roughest road (R = 1.5 cm at λ = 0.7 m) car1-trb1 keeps 94 % of its grip at 20 m/s and 88 %
//! at 60 to 80 m/s; on grass (5 cm at 0.5 m) its wheels would be in the air a third of the time and
//! keep 80 %, but the game's verges cost nothing measurable, so only the road's roughness is
//! laid under the wheels ([`super`], docs/results/torcs.md, "The road's roughness").
//!
//! Approximations: each corner rises on its own where simuv2 moves the body as one (heave,
//! pitch and roll), and the bumps are met at the car's speed along the centre line from the
//! lap's start rather than from each segment's (the same wavelengths, other phases). On smooth
//! ground with the wheel settled (e = b = ḃ = 0) the load is F_qs to the last bit and nothing
//! is computed: a track without a rough road drives on the quasi-static loads alone.

use super::tyre::TyreModel;
use crate::car::{Damper, G, Ride};
use crate::track::Bumps;

/// simuv2's step (s): `RCM_MAX_DT_SIMU`.
pub const SIMUV2_STEP: f64 = 0.002;

/// One wheel's vertical state past its quasi-static one (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Bounce {
    /// The suspension's extension past its quasi-static length, e (m).
    extension: f64,
    /// The wheel's speed towards the body, u (m/s).
    wheel_speed: f64,
    /// The body corner's rise, b (m).
    rise: f64,
    /// Its speed, ḃ (m/s).
    rise_speed: f64,
}

impl Bounce {
    /// Whether the wheel rests at its quasi-static place: e = b = ḃ = 0.
    #[inline]
    pub fn settled(&self) -> bool {
        self.extension == 0.0 && self.rise == 0.0 && self.rise_speed == 0.0
    }
}

/// What moves a wheel up and down: its suspension, its mass and its share of the body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    /// Wheel rate k = K·β² (N/m).
    pub rate: f64,
    /// The bellcrank's ratio β.
    pub bellcrank: f64,
    /// The damper.
    pub damper: Damper,
    /// 1 / the wheel's mass m_w (1/kg).
    pub inv_wheel_mass: f64,
    /// 1 / the body's mass over the wheel, m_c = F₀/g (1/kg).
    pub inv_body_mass: f64,
}

impl Corner {
    /// A front (`axle` 0) or rear (1) wheel of a car with this suspension.
    pub fn of(ride: &Ride, axle: usize) -> Corner {
        Corner {
            rate: ride.rate[axle],
            bellcrank: ride.bellcrank[axle],
            damper: ride.dampers[axle],
            inv_wheel_mass: 1.0 / ride.wheel_mass[axle],
            inv_body_mass: G / ride.load[axle],
        }
    }
}

/// One of simuv2's steps `dt` with the ground `h` above the smooth surface under the wheel:
/// the wheel's load F (N) (module documentation).
#[inline]
fn substep(state: &mut Bounce, corner: &Corner, load: f64, h: f64, dt: f64, inv_dt: f64) -> f64 {
    let before = state.extension;
    let mut e = before - state.wheel_speed * dt;
    let room = state.rise - h;
    if e > room {
        e = room;
        state.wheel_speed = 0.0;
    }
    state.extension = e;
    let v = corner.bellcrank * (before - e) * inv_dt;
    let spring = (load - corner.rate * e).max(0.0);
    let f = (spring + corner.bellcrank * corner.damper.force(v)).max(0.0);
    state.wheel_speed -= dt * f * corner.inv_wheel_mass;
    state.rise_speed += dt * (f - load) * corner.inv_body_mass;
    state.rise += dt * state.rise_speed;
    f
}

/// Below these the wheel has settled after rough ground (m, m, m/s): a micrometre, a
/// micrometre and a micrometre per second, a thousandth of a newton of the spring.
const SETTLED_M: f64 = 1e-6;
const SETTLED_M_PER_S: f64 = 1e-6;

/// Advances one wheel over cdbo's step `dt` at simuv2's, the wheel loaded `load` (N, F_qs) by
/// the quasi-static model, over `bumps` met at `speed` (m/s), and returns the scale of its
/// surface's friction: mean(F·λ(F)) / (F_qs·λ(F_qs)) over the sub-steps (1 where F_qs = 0).
#[inline]
pub fn step(
    state: &mut Bounce,
    corner: &Corner,
    load: f64,
    bumps: &Bumps,
    speed: f64,
    dt: f64,
    tyre: &TyreModel,
) -> f64 {
    let n = (dt * (1.0 / SIMUV2_STEP)).round().max(1.0);
    let h_dt = dt / n;
    let inv_h_dt = n / dt;
    let mut grip = 0.0;
    for j in 1..=n as usize {
        let h = bumps.height(speed * h_dt * j as f64);
        let f = substep(state, corner, load, h, h_dt, inv_h_dt);
        grip += tyre.wheel_max_force(f, 1.0);
    }
    if !bumps.any()
        && state.extension.abs() < SETTLED_M
        && state.rise.abs() < SETTLED_M
        && state.rise_speed.abs() < SETTLED_M_PER_S
    {
        *state = Bounce::default();
    }
    let smooth = tyre.wheel_max_force(load, 1.0);
    if smooth > 0.0 { grip / n / smooth } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::car::tests::on_springs;
    use crate::track::Roughness;

    /// car1-trb1's front corner and tyre ([`on_springs`]).
    fn front() -> (Corner, TyreModel, f64) {
        let car = on_springs();
        let ride = car.ride.unwrap();
        let corner = Corner::of(&ride, 0);
        (corner, TyreModel::new(&car.front_tyre), ride.load[0])
    }

    /// On smooth ground a settled wheel carries its quasi-static load to the last bit, and
    /// stays settled, whatever the load.
    #[test]
    fn on_smooth_ground_a_settled_wheel_carries_its_load() {
        let (corner, tyre, _) = front();
        let mut state = Bounce::default();
        for load in [0.0, 1234.5, 2932.0, 7000.25] {
            let scale = step(&mut state, &corner, load, &Bumps::NONE, 30.0, 0.004, &tyre);
            assert_eq!(scale, 1.0);
            assert!(state.settled());
        }
    }

    /// A bump of height h met in one 2 ms step pushes the wheel up by h: the spring carries
    /// k·h more and the damper, at β·h/Δt in bump, β·D(β·h/Δt) more (closed form); the wheel
    /// is then pushed back down at −Δt·F/m_w and the body's corner up at Δt·(F − F_qs)/m_c.
    #[test]
    fn a_bump_loads_the_spring_and_the_damper_as_simuv2() {
        let (corner, tyre, load) = front();
        let (a, k, speed) = (0.02, 2.0, 30.0);
        let bumps = Bumps {
            amplitude: a,
            wavenumber: k,
            ..Bumps::NONE
        };
        let mut state = Bounce::default();
        let scale = step(&mut state, &corner, load, &bumps, speed, SIMUV2_STEP, &tyre);
        let h = a * (k * speed * SIMUV2_STEP).sin();
        let v = corner.bellcrank * h / SIMUV2_STEP;
        let f = load + corner.rate * h + corner.bellcrank * corner.damper.force(v);
        let want = tyre.wheel_max_force(f, 1.0) / tyre.wheel_max_force(load, 1.0);
        assert!((scale - want).abs() < 1e-12, "{scale} against {want}");
        assert!((state.extension + h).abs() < 1e-15);
        assert!((state.wheel_speed + SIMUV2_STEP * f * corner.inv_wheel_mass).abs() < 1e-9);
        assert!((state.rise_speed - SIMUV2_STEP * (f - load) * corner.inv_body_mass).abs() < 1e-12);
        // The damper's curve: slow below the threshold, fast past it, capped at 10 m/s.
        let d = corner.damper.bump;
        assert!(v > d.threshold && v < 10.0);
        assert!((d.force(v) - (d.fast * v + (d.slow - d.fast) * d.threshold)).abs() < 1e-9);
        assert_eq!(d.force(20.0), d.force(10.0));
    }

    /// Over grass (R = 5 cm at λ = 0.5 m) at 30 m/s the wheel hops: its load swings between 0
    /// and several times F_qs, while the body's corner, rising on the extra load, keeps its
    /// mean at F_qs (∫(F − F_qs)·dt = m_c·Δḃ, bounded); the tyre's grip, concave in the load,
    /// falls to between 0.7 and 0.9 of the smooth ground's.
    #[test]
    fn over_grass_the_load_keeps_its_mean_and_the_grip_falls() {
        let (corner, tyre, load) = front();
        let bumps = Roughness::from_file(0.05, 0.5).plain(0.0, 0.1);
        let mut state = Bounce::default();
        let (steps, dt) = (1500, 0.002);
        let (mut sum, mut airborne, mut top) = (0.0, 0, 0.0f64);
        for j in 1..=steps {
            let h = bumps.height(30.0 * dt * j as f64);
            let f = substep(&mut state, &corner, load, h, dt, 1.0 / dt);
            sum += f;
            airborne += usize::from(f == 0.0);
            top = top.max(f);
        }
        let mean = sum / steps as f64;
        assert!(
            (mean / load - 1.0).abs() < 0.02,
            "mean load {mean} against {load}"
        );
        assert!(
            airborne > steps / 10 && top > 2.0 * load,
            "{airborne} {top}"
        );
        let mut state = Bounce::default();
        let grip: f64 = (0..500)
            .map(|i| {
                let at = Bumps {
                    along: 30.0 * 0.004 * i as f64,
                    ..bumps
                };
                step(&mut state, &corner, load, &at, 30.0, 0.004, &tyre)
            })
            .sum::<f64>()
            / 500.0;
        assert!((0.7..0.9).contains(&grip), "grip {grip}");
    }

    /// Over a crest's kink (the grade falling by 2 % at once) at 30 m/s the ground drops away
    /// at 0.6 m/s: the stiff race car's wheel leaves it for a moment (its grip below half the
    /// smooth road's within 0.2 s), then carries its load again as the body follows the new
    /// grade; in a dip's kink it is loaded instead (its grip past 1.5 times). Before the kink,
    /// on the straight grade, nothing moves.
    #[test]
    fn a_kink_unloads_the_wheel_for_a_moment() {
        let (corner, tyre, load) = front();
        let (speed, dt, grade) = (30.0, 0.004, 0.02);
        let ride = |sign: f64| -> Vec<f64> {
            let mut state = Bounce::default();
            (0..500)
                .map(|i| {
                    // The kink at 3 m: the ground k = ∓g·(x − 3) past it, level before.
                    let x = speed * dt * i as f64 - 3.0;
                    let bumps = Bumps {
                        kink: -sign * grade * x.max(0.0),
                        kink_slope: if x >= 0.0 { -sign * grade } else { 0.0 },
                        ..Bumps::NONE
                    };
                    step(&mut state, &corner, load, &bumps, speed, dt, &tyre)
                })
                .collect()
        };
        let crest = ride(1.0);
        // 3 m at 0.12 m a step: the first 25 steps stand before the kink.
        assert!(crest[..25].iter().all(|&g| g == 1.0), "{:?}", &crest[..25]);
        let low = crest[25..75].iter().copied().fold(f64::INFINITY, f64::min);
        assert!(low < 0.5, "lowest grip {low}");
        assert!(
            crest[400..].iter().all(|g| (g - 1.0).abs() < 0.01),
            "{:?}",
            &crest[400..410]
        );
        let dip = ride(-1.0);
        let high = dip[25..75].iter().copied().fold(0.0, f64::max);
        assert!(high > 1.5, "highest grip {high}");
    }
}
