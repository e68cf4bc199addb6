//! Engine, clutch and automatic gearbox.
//!
//! Wheel torque at throttle a in gear i: T_w = T_e(ω_e)·(a·(1 + K) − K)·gᵢ·g_f with engine
//! speed ω_e = ω_wheel·gᵢ·g_f (efficiency 1, as TORCS's simuv2 drives the wheels) and the
//! engine brake K = c·(ω_e − ω_idle)/(ω_max − ω_idle) of simuv2's `engine.cpp`: at part
//! throttle the engine's net torque falls with its speed and turns negative, and a closed
//! throttle brakes. Below idle the clutch slips and the engine delivers a·T_e(ω_idle); above
//! the rev limiter it delivers nothing. The gearbox shifts up when the next gear gives more
//! wheel torque at the same road speed *at the current throttle* (or at the rev limiter), and
//! down when the lower gear would still be below its own up-shift speed at that throttle by
//! the margin [`DOWNSHIFT_MARGIN`]; while coasting or braking it keeps the full-throttle
//! points, ready to accelerate. Each shift cuts the drive for the car's `shift time`. At part
//! throttle the engine brake makes the net torque fall with engine speed and vanish near the
//! red line, so a gearbox with full-throttle points would hold a low gear there for ever (the
//! "gear trap": 2.7 km of first gear at 8000 rpm on e-track-2 at a = 0.2).

use crate::car::Car;

/// Hysteresis between the up-shift speed of gear i−1 and the down-shift into it.
pub const DOWNSHIFT_MARGIN: f64 = 0.85;

/// Gearbox state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gearbox {
    /// Current gear, 0-based (0 = first).
    pub gear: usize,
    /// Time left in the current shift (s); no drive while positive.
    pub shifting: f64,
}

/// Throttle levels of the shift map: a = k / (LEVELS − 1), k = 0 … LEVELS − 1.
pub const THROTTLE_LEVELS: usize = 11;

/// Shift points of a car, computed once.
#[derive(Debug, Clone, PartialEq)]
pub struct ShiftMap {
    /// Engine speed at which to leave gear i for gear i+1 (rad/s) at each throttle level:
    /// `upshift[i][k]` at a = k / ([`THROTTLE_LEVELS`] − 1).
    pub upshift: Vec<[f64; THROTTLE_LEVELS]>,
}

impl ShiftMap {
    /// The lowest engine speed in each gear at which the next gear gives more wheel torque,
    /// T_e(ω·r)·(a(1 + K) − K)·gᵢ₊₁ > T_e(ω)·(a(1 + K) − K)·gᵢ with r = gᵢ₊₁/gᵢ and K of each
    /// engine speed, with the next gear's engine at or above idle; the rev limiter (less
    /// 0.5 %) where it never does; the last gear's is the rev limiter.
    pub fn new(car: &Car) -> ShiftMap {
        let g = &car.gears;
        let net = |w: f64, a: f64| {
            let w = w.max(car.tickover);
            car.part_throttle_torque(car.engine_torque(w), a, w)
        };
        let upshift = (0..g.len())
            .map(|i| {
                std::array::from_fn(|k| {
                    if i + 1 == g.len() {
                        return car.rev_limiter;
                    }
                    let a = k as f64 / (THROTTLE_LEVELS - 1) as f64;
                    let ratio = g[i + 1] / g[i];
                    let steps = 400;
                    (0..=steps)
                        .map(|j| {
                            car.tickover
                                + (car.rev_limiter - car.tickover) * j as f64 / steps as f64
                        })
                        .find(|&w| {
                            w * ratio >= car.tickover
                                && net(w * ratio, a) * g[i + 1] > net(w, a) * g[i]
                        })
                        .unwrap_or(car.rev_limiter)
                        .min(car.rev_limiter * 0.995)
                })
            })
            .collect();
        ShiftMap { upshift }
    }

    /// The engine speed at which to leave `gear` at `throttle`, linear between the levels;
    /// a throttle of 0 or less (coasting, braking) takes the full-throttle point.
    #[inline]
    pub fn upshift(&self, gear: usize, throttle: f64) -> f64 {
        let row = &self.upshift[gear];
        if throttle <= 0.0 || throttle >= 1.0 {
            return row[THROTTLE_LEVELS - 1];
        }
        let f = throttle * (THROTTLE_LEVELS - 1) as f64;
        let k = (f as usize).min(THROTTLE_LEVELS - 2);
        let t = f - k as f64;
        row[k] + (row[k + 1] - row[k]) * t
    }
}

/// The full-throttle torque curve with O(1) look-up: the speed range is cut into buckets,
/// each knowing the first curve segment it overlaps; values equal [`Car::engine_torque`].
#[derive(Debug, Clone, PartialEq)]
pub struct EngineMap {
    curve: Vec<(f64, f64)>,
    rev_limiter: f64,
    buckets_per_rad_s: f64,
    /// For each bucket, the number of curve points at or below its lower edge.
    first: Vec<usize>,
}

impl EngineMap {
    /// Buckets of the speed range up to the rev limiter.
    const BUCKETS: usize = 512;

    /// The map of a car's curve.
    pub fn new(car: &Car) -> EngineMap {
        let width = car.rev_limiter / Self::BUCKETS as f64;
        let first = (0..=Self::BUCKETS)
            .map(|b| {
                car.torque_curve
                    .partition_point(|&(w, _)| w <= b as f64 * width)
            })
            .collect();
        EngineMap {
            curve: car.torque_curve.clone(),
            rev_limiter: car.rev_limiter,
            buckets_per_rad_s: 1.0 / width,
            first,
        }
    }

    /// Full-throttle torque at engine speed ω (N·m), 0 at and above the rev limiter.
    #[inline(always)]
    pub fn torque(&self, omega: f64) -> f64 {
        if !(omega >= 0.0 && omega < self.rev_limiter) {
            return if omega < 0.0 { self.curve[0].1 } else { 0.0 };
        }
        let c = &self.curve;
        let mut i = self.first[(omega * self.buckets_per_rad_s) as usize];
        while i < c.len() && c[i].0 <= omega {
            i += 1;
        }
        crate::interp::linear_at(c, i, omega)
    }
}

impl Gearbox {
    /// Standing in first gear.
    pub fn new() -> Gearbox {
        Gearbox {
            gear: 0,
            shifting: 0.0,
        }
    }

    /// Chooses the gear for a driven-wheel speed ω (rad/s) and the throttle in [0, 1]; starts
    /// a shift when it changes. Nothing while a shift is under way; else up when the engine
    /// speed ω·gᵢ·g_f reaches the up-shift point of gear i at this throttle, down when the
    /// lower gear's ω·gᵢ₋₁·g_f is below [`DOWNSHIFT_MARGIN`] times its up-shift point. The
    /// TORCS robot's `drive::gear_update` (`torcs-robot/drive.hpp`) is the same arithmetic,
    /// checked against this by `tests/robot_drive.rs`.
    pub fn update(&mut self, car: &Car, map: &ShiftMap, wheel_omega: f64, throttle: f64) {
        if self.shifting > 0.0 {
            return;
        }
        // The gear's total ratio first, as the TORCS robot is handed it (drive.hpp).
        let fd = car.final_drive;
        let engine = |gear: usize| wheel_omega * (car.gears[gear] * fd);
        if self.gear + 1 < car.gears.len() && engine(self.gear) >= map.upshift(self.gear, throttle)
        {
            self.gear += 1;
            self.shifting = car.shift_time;
        } else if self.gear > 0
            && engine(self.gear - 1) < DOWNSHIFT_MARGIN * map.upshift(self.gear - 1, throttle)
        {
            self.gear -= 1;
            self.shifting = car.shift_time;
        }
    }

    /// Total ratio engine → wheel in the current gear.
    #[inline]
    pub fn ratio(&self, car: &Car) -> f64 {
        car.gears[self.gear] * car.final_drive
    }

    /// Drive torque at the driven wheels (N·m) for a throttle in [0, 1], the engine brake
    /// included, and the engine speed.
    #[inline]
    pub fn wheel_torque(
        &self,
        car: &Car,
        engine_map: &EngineMap,
        throttle: f64,
        wheel_omega: f64,
    ) -> (f64, f64) {
        let ratio = self.ratio(car);
        let engine = (wheel_omega * ratio).max(car.tickover);
        if self.shifting > 0.0 {
            return (0.0, engine);
        }
        let torque = car.part_throttle_torque(engine_map.torque(engine), throttle, engine);
        (torque * ratio, engine)
    }
}

impl Default for Gearbox {
    fn default() -> Self {
        Gearbox::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn upshift_points_maximise_wheel_torque() {
        let car = Car::spirit_300();
        let map = ShiftMap::new(&car);
        assert_eq!(map.upshift.len(), car.gears.len());
        for i in 0..car.gears.len() - 1 {
            let w = map.upshift(i, 1.0);
            let ratio = car.gears[i + 1] / car.gears[i];
            // Just past the point the next gear is better, just before it the current one is.
            assert!(
                car.engine_torque(w * ratio) * car.gears[i + 1]
                    >= car.engine_torque(w) * car.gears[i] * 0.999
                    || w >= car.rev_limiter * 0.99
            );
            assert!(
                w > 6000.0 * std::f64::consts::PI / 30.0,
                "gear {i} shifts at {} rpm",
                w * 30.0 / std::f64::consts::PI
            );
        }
    }

    #[test]
    fn part_throttle_shifts_up_where_the_next_gear_pulls_harder() {
        let car = Car::spirit_300();
        let map = ShiftMap::new(&car);
        let net = |w: f64, a: f64| car.part_throttle_torque(car.engine_torque(w), a, w);
        for i in 0..car.gears.len() - 1 {
            let ratio = car.gears[i + 1] / car.gears[i];
            for k in 1..THROTTLE_LEVELS - 1 {
                let a = k as f64 / (THROTTLE_LEVELS - 1) as f64;
                let w = map.upshift(i, a);
                assert_eq!(w, map.upshift[i][k]);
                // Earlier than at full throttle: the engine brake eats the top of the range.
                assert!(w <= map.upshift(i, 1.0), "gear {i} a = {a}");
                // At the point the next gear pulls harder, one grid step before it does not.
                let step = (car.rev_limiter - car.tickover) / 400.0;
                if w < car.rev_limiter * 0.99 && w - step >= car.tickover / ratio {
                    assert!(net(w * ratio, a) * car.gears[i + 1] > net(w, a) * car.gears[i]);
                    let w0 = w - step;
                    assert!(
                        net(w0 * ratio, a) * car.gears[i + 1] <= net(w0, a) * car.gears[i],
                        "gear {i} a = {a}"
                    );
                }
            }
            // Between the levels the point is interpolated; coasting keeps full throttle's.
            let mid = map.upshift(i, 0.25);
            assert!((mid - 0.5 * (map.upshift[i][2] + map.upshift[i][3])).abs() < 1e-9);
            assert_eq!(map.upshift(i, 0.0), map.upshift(i, 1.0));
        }
        // The trap: at a = 0.2 in first gear the net torque vanishes below the full-throttle
        // up-shift point, so the car could never reach it; the part-throttle point lies below.
        let zero = (0..4000)
            .map(|j| car.tickover + j as f64 * 0.25)
            .find(|&w| net(w, 0.2) <= 0.0)
            .unwrap_or(car.rev_limiter);
        assert!(zero < map.upshift(0, 1.0), "{zero}");
        assert!(map.upshift(0, 0.2) < zero);
    }

    #[test]
    fn the_engine_brakes_as_simuv2s_does() {
        let car = Car::spirit_300();
        let full = 300.0;
        // At idle K = 0: the throttle scales the curve.
        let idle = car.part_throttle_torque(full, 0.4, car.tickover);
        assert!((idle - 0.4 * full).abs() < 1e-12);
        // At the highest speed K = c: a closed throttle brakes with c·T.
        let closed = car.part_throttle_torque(full, 0.0, car.revs_max);
        assert!((closed + car.engine_brake * full).abs() < 1e-12);
        // Halfway, K = c/2, and the net torque vanishes at a = K/(1 + K).
        let w = 0.5 * (car.tickover + car.revs_max);
        let k = 0.5 * car.engine_brake;
        assert!(car.part_throttle_torque(full, k / (1.0 + k), w).abs() < 1e-9);
        assert!(car.part_throttle_torque(full, 1.0, w) == full);
        // The wheels feel it through the gearbox, past the rev limiter nothing.
        let (map, g) = (EngineMap::new(&car), Gearbox::new());
        let ratio = g.ratio(&car);
        let (t, e) = g.wheel_torque(&car, &map, 0.0, w / ratio);
        assert!((e - w).abs() < 1e-9);
        assert!((t + k * map.torque(w) * ratio).abs() < 1e-9, "{t}");
        let (t, _) = g.wheel_torque(&car, &map, 0.0, 1.01 * car.rev_limiter / ratio);
        assert_eq!(t, 0.0);
    }

    #[test]
    fn the_engine_map_equals_the_curve() {
        let car = Car::spirit_300();
        let map = EngineMap::new(&car);
        for i in 0..20_000 {
            let w = i as f64 * 0.05 - 1.0;
            assert_eq!(map.torque(w), car.engine_torque(w), "at {w} rad/s");
        }
    }

    #[test]
    fn the_gearbox_climbs_and_descends_through_the_gears() {
        let car = Car::spirit_300();
        let map = ShiftMap::new(&car);
        let mut g = Gearbox::new();
        for v in 1..90 {
            g.shifting = 0.0;
            g.update(&car, &map, v as f64 / car.rear_tyre.radius, 1.0);
        }
        assert_eq!(g.gear, car.gears.len() - 1);
        for v in (1..90).rev() {
            g.shifting = 0.0;
            g.update(&car, &map, v as f64 / car.rear_tyre.radius, 1.0);
        }
        assert_eq!(g.gear, 0);
    }
}
