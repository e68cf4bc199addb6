//! The robot's traction control, defined here for the robot's `drive::traction_throttle`
//! (`torcs-robot/drive.hpp`), which `tests/robot_drive.rs` checks against it; cdbo's simulator
//! eases a car the robot drives by the same law, at every physics step (at the driver's steps,
//! as the robot does, it fitted the game's fast laps less well: docs/results/torcs.md).
//!
//! cdbo's vehicle eases another car's throttle inside its physics step, on the driven axle's
//! relative slip past the aid threshold ([`crate::vehicle::Vehicle::aid_threshold`]): eased to
//! nothing at twice it. The robot can only act at the game's 50 Hz driver steps, and there
//! that stiff band, fed the game's wheel speeds, cuts and restores the throttle step by step:
//! the engine's speed jumps by ±2000 rpm from one step to the next and a standing start in
//! car1-trb1 reaches 40 m 0.66 s later than with no traction control at all. The robot eases
//! the throttle as TORCS's berniw robots do (their `filterTCL`), on the driven wheels' slip
//! speed s = ωR − vₓ past [`TRACTION_SLIP`], over a wide range, so that one step's cut stays
//! small. Measured in the game (car1-trb1 on E-Track 2, full throttle from the start, the
//! tracker): 40 m in 3.79 s with the relative band, 3.15 s with none, 3.13 s with this law
//! (3.22 s with berniw's range of 5 m/s); 300 laps of the pattern search (tracker,
//! minimum-curvature line, seeds 0–2): best laps 129.61 s on average with this law, 130.86 s
//! with a range of 5 m/s, 131.24 s with the relative band.

/// The driven wheels' slip speed ωR − vₓ (m/s) past which the throttle eases (berniw's).
pub const TRACTION_SLIP: f64 = 2.0;
/// The slip speed (m/s) past [`TRACTION_SLIP`] that takes the whole throttle away (twice
/// berniw's).
pub const TRACTION_RANGE: f64 = 10.0;

/// The throttle a ∈ [0, 1] after traction control, for the driven wheels' slip speed
/// s = ωR − vₓ (m/s): a' = a − min(a, max(0, s − s₀)/Δs), s₀ = [`TRACTION_SLIP`],
/// Δs = [`TRACTION_RANGE`].
pub fn traction_throttle(throttle: f64, slip_speed: f64) -> f64 {
    let excess = (slip_speed - TRACTION_SLIP).max(0.0);
    throttle - throttle.min(excess / TRACTION_RANGE)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Up to the slip the throttle is untouched; past it, it loses 1/Δs per m/s, down to 0
    /// and never below; and no throttle stays none.
    #[test]
    fn the_throttle_eases_over_the_range_past_the_slip() {
        assert_eq!(traction_throttle(0.8, -3.0), 0.8);
        assert_eq!(traction_throttle(0.8, TRACTION_SLIP), 0.8);
        let one_more = traction_throttle(1.0, TRACTION_SLIP + 1.0);
        assert!(
            (one_more - (1.0 - 1.0 / TRACTION_RANGE)).abs() < 1e-15,
            "{one_more}"
        );
        assert_eq!(traction_throttle(0.3, TRACTION_SLIP + TRACTION_RANGE), 0.0);
        assert_eq!(traction_throttle(1.0, 100.0), 0.0);
        assert_eq!(traction_throttle(0.0, 10.0), 0.0);
    }
}
