//! The robot's ABS, defined here for the robot's `drive::abs_brake`
//! (`torcs-robot/drive.hpp`), which `tests/robot_drive.rs` checks against it.
//!
//! The robot has one brake command for the four wheels and sets it once a driver step, at the
//! game's 50 Hz: it eases the pedal b by every axle k whose slide σₖ = −(ω̄ₖRₖ − vₓ)/max(|vₓ|, v₀)
//! passes the aid threshold σ*ₖ (half the car file's peak slip), by clamp(2 − σₖ/σ*ₖ, 0, 1),
//! and the game's brakes hold the result for the next ten 2 ms steps. cdbo's simulator brakes
//! a car the robot drives the same way ([`crate::vehicle::Vehicle::driver_brake`]).
//! Eased every 4 ms and per axle instead, as cdbo's vehicle eases another car's brakes, its
//! car1-trb1 braked from 62 m/s at 3 g where the game's brakes at 2.5 g, its rear wheels
//! slipping more, and it shifted down early (into second 150 m early) and coasted a gear too
//! low: the calibration's launch-and-brake probe cost 46 against the game's laps (0.18 with
//! the robot's ABS), and the fit bent the tyre and the aero to match it
//! (docs/results/torcs.md).

/// The brake command after ABS, b·Πₖ clamp(2 − σₖ/σ*ₖ, 0, 1) over the axles (front, rear)
/// whose slide σₖ passes a positive threshold σ*ₖ.
pub fn abs_brake(brake: f64, slides: [f64; 2], thresholds: [f64; 2]) -> f64 {
    let mut eased = brake;
    for (slide, threshold) in slides.into_iter().zip(thresholds) {
        if threshold > 0.0 && slide > threshold {
            eased *= (2.0 - slide / threshold).clamp(0.0, 1.0);
        }
    }
    eased
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Below its threshold an axle leaves the brake; past it, the brake falls linearly to
    /// nothing at twice the threshold; two sliding axles multiply; no threshold, no ABS.
    #[test]
    fn each_sliding_axle_eases_the_one_brake() {
        let th = [0.25, 0.5];
        assert_eq!(abs_brake(0.8, [0.25, -0.3], th), 0.8);
        assert_eq!(abs_brake(0.8, [0.375, 0.0], th), 0.8 * 0.5);
        assert_eq!(abs_brake(0.8, [0.0, 0.75], th), 0.8 * 0.5);
        assert_eq!(abs_brake(0.8, [0.375, 0.875], th), 0.8 * 0.5 * 0.25);
        assert_eq!(abs_brake(1.0, [0.5, 0.0], th), 0.0);
        assert_eq!(abs_brake(1.0, [0.75, 2.0], [0.0, 0.0]), 1.0);
        assert_eq!(abs_brake(0.0, [0.2, 0.3], th), 0.0);
    }
}
