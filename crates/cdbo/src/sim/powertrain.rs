//! Engine, clutch and automatic gearbox.
//!
//! Wheel torque at throttle a in gear i: T_w = T_e(ω_e)·(a·(1 + K) − K)·gᵢ·g_f with engine
//! speed ω_e = ω_wheel·gᵢ·g_f (efficiency 1, as TORCS's simuv2 drives the wheels) and the
//! engine brake K = c·(ω_e − ω_idle)/(ω_max − ω_idle) of simuv2's `engine.cpp`: at part
//! throttle the engine's net torque falls with its speed and turns negative, and a closed
//! throttle brakes. Below idle the clutch slips and the engine delivers a·T_e(ω_idle); above
//! the rev limiter it delivers nothing. The gearbox shifts up when the next gear gives
//! more wheel torque at the same road speed (or at the rev limiter) and down when the lower
//! gear would still be below its own up-shift speed; each shift cuts the drive for the car's
//! `shift time`.

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

/// Shift points of a car, computed once.
#[derive(Debug, Clone, PartialEq)]
pub struct ShiftMap {
    /// Engine speed at which to leave gear i for gear i+1 (rad/s).
    pub upshift: Vec<f64>,
}

impl ShiftMap {
    /// The engine speed in each gear above which the next gear gives more wheel torque.
    pub fn new(car: &Car) -> ShiftMap {
        let g = &car.gears;
        let upshift = (0..g.len())
            .map(|i| {
                if i + 1 == g.len() {
                    return car.rev_limiter;
                }
                let ratio = g[i + 1] / g[i];
                let steps = 400;
                (0..=steps)
                    .map(|k| {
                        car.tickover + (car.rev_limiter - car.tickover) * k as f64 / steps as f64
                    })
                    .find(|&w| {
                        car.engine_torque(w * ratio) * g[i + 1] > car.engine_torque(w) * g[i]
                    })
                    .unwrap_or(car.rev_limiter)
                    .min(car.rev_limiter * 0.995)
            })
            .collect();
        ShiftMap { upshift }
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
    #[inline]
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

    /// Chooses the gear for a driven-wheel speed ω (rad/s); starts a shift when it changes.
    pub fn update(&mut self, car: &Car, map: &ShiftMap, wheel_omega: f64) {
        if self.shifting > 0.0 {
            return;
        }
        let fd = car.final_drive;
        let engine = |gear: usize| wheel_omega * car.gears[gear] * fd;
        if self.gear + 1 < car.gears.len() && engine(self.gear) >= map.upshift[self.gear] {
            self.gear += 1;
            self.shifting = car.shift_time;
        } else if self.gear > 0
            && engine(self.gear - 1) < DOWNSHIFT_MARGIN * map.upshift[self.gear - 1]
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
            let w = map.upshift[i];
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
            g.update(&car, &map, v as f64 / car.rear_tyre.radius);
        }
        assert_eq!(g.gear, car.gears.len() - 1);
        for v in (1..90).rev() {
            g.shifting = 0.0;
            g.update(&car, &map, v as f64 / car.rear_tyre.radius);
        }
        assert_eq!(g.gear, 0);
    }
}
