//! The robot's launch clutch, defined here for the robot's `drive::launch_clutch`
//! (`torcs-robot/drive.hpp`), which `tests/robot_drive.rs` checks against it; cdbo's simulator
//! pulls away with it in a car the robot drives ([`crate::vehicle::Vehicle::clutch`]).
//!
//! cdbo's powertrain lets the clutch slip below idle with the engine giving its idle torque;
//! the game's engine gives no torque below idle and drives the wheels only while it turns
//! faster, so a standing car with the clutch closed barely creeps. As the game's own robots
//! do, the clutch starts open and closes over [`LAUNCH_TIME`] of throttle, sooner once the
//! engine passes half its red line with the car rolling; after first gear it stays closed.

/// The clutch's closing time over throttle while pulling away (s).
pub const LAUNCH_TIME: f64 = 2.0;
/// Added to the road speed when the clutch closes early (m/s).
pub const LAUNCH_SPEED: f64 = 5.0;

/// What the launch clutch reads of the game's car.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaunchCar {
    /// Engine speed ω (rad/s).
    pub engine_speed: f64,
    /// The engine's red line ω_red (rad/s).
    pub red_line: f64,
    /// Total ratio engine → wheel of first gear, g₁.
    pub first_ratio: f64,
    /// Radius R of a driven wheel (m).
    pub wheel_radius: f64,
    /// Forward speed vₓ (m/s).
    pub speed_x: f64,
}

/// The clutch command c ∈ [0, 1] (1 = open) in `gear` (0-based) for the throttle in [0, 1],
/// `dt` seconds after the last driver step; `launch_time` is the time with throttle in first
/// gear so far, updated.
///
/// After first gear c = 0. In it, t += dt while the throttle is open, the ramp is
/// r = clamp(1 − t/[`LAUNCH_TIME`], 0, 1), and c = r while ω ≤ ω_red/2 (or ω_red ≤ 0);
/// above, c = min(r, max(0, 1 − ρ·2(ω − ω_red/2)/ω_red)) with
/// ρ = ([`LAUNCH_SPEED`] + max(0, vₓ)) / |R·ω_red/g₁|, the road speed with a margin over
/// first gear's road speed at the red line.
pub fn launch_clutch(
    gear: usize,
    throttle: f64,
    dt: f64,
    launch_time: &mut f64,
    car: &LaunchCar,
) -> f64 {
    if gear != 0 {
        return 0.0;
    }
    if throttle > 0.0 {
        *launch_time += dt;
    }
    let ramp = (1.0 - *launch_time / LAUNCH_TIME).clamp(0.0, 1.0);
    let red = car.red_line;
    let above_half = car.engine_speed - 0.5 * red;
    if above_half <= 0.0 || red <= 0.0 {
        return ramp;
    }
    let wheel_speed_at_red = (car.wheel_radius * red / car.first_ratio).abs();
    let rolling = (LAUNCH_SPEED + car.speed_x.max(0.0)) / wheel_speed_at_red;
    ramp.min((1.0 - rolling * 2.0 * above_half / red).max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Standing, the clutch closes linearly over the throttle's time; a fast-turning engine
    /// on a rolling car closes it sooner; out of first gear it is closed; and the time only
    /// counts with the throttle open.
    #[test]
    fn the_clutch_closes_over_the_launch() {
        let idle = LaunchCar {
            engine_speed: 100.0,
            red_line: 700.0,
            first_ratio: 12.0,
            wheel_radius: 0.3,
            speed_x: 0.0,
        };
        let mut t = 0.0;
        assert_eq!(launch_clutch(0, 0.0, 0.5, &mut t, &idle), 1.0);
        assert_eq!(t, 0.0);
        assert_eq!(launch_clutch(0, 1.0, 0.5, &mut t, &idle), 0.75);
        assert_eq!(launch_clutch(0, 1.0, 1.0, &mut t, &idle), 0.25);
        assert_eq!(launch_clutch(0, 1.0, 1.0, &mut t, &idle), 0.0);
        // At 550 rad/s and 10 m/s: ρ = 15 / 17.5, c = 1 − ρ·2·200/700 ≈ 0.51 < the ramp.
        let revving = LaunchCar {
            engine_speed: 550.0,
            speed_x: 10.0,
            ..idle
        };
        let mut t = 0.0;
        let c = launch_clutch(0, 1.0, 0.02, &mut t, &revving);
        assert!(
            (c - (1.0 - 15.0 / 17.5 * 400.0 / 700.0)).abs() < 1e-15,
            "{c}"
        );
        assert_eq!(launch_clutch(1, 1.0, 0.02, &mut t, &revving), 0.0);
        assert_eq!(t, 0.02);
    }
}
